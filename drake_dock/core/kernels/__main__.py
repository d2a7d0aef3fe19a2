"""``python -m drake_dock.core.kernels [--jobs N]``: compiles the kernels that the cache lacks,
in N processes (default: one per core) with a line per module and its time, loads them all and
prints the cache directory. ``--worker`` is a worker's command: it compiles the modules named on
its stdin, one a line, and answers each with a line "NAME SECONDS"
(`drake_dock.core.kernels.prepare`), and ends without the interpreter's teardown: freeing what
the compiler built takes up to a second or two, and the run that waits for the workers would
wait for it."""
import argparse
import contextlib
import os
import sys

from drake_dock.core.kernels import prepare
from drake_dock.core.kernels.compile_cache import cache_dir


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(prog="python -m drake_dock.core.kernels",
                                 description=__doc__.split("\n\n")[0])
    ap.add_argument("--jobs", type=int, default=None,
                    help="worker processes (default: one per core; 1 compiles in this process)")
    ap.add_argument("--worker", action="store_true", help=argparse.SUPPRESS)
    args = ap.parse_args(argv)
    if args.worker:
        prepare.serve(sys.stdin, sys.stdout)
        with contextlib.suppress(OSError, ValueError):
            sys.stdout.flush()
            sys.stderr.flush()
        os._exit(0)     # the cache and the answers are written (module docstring)
    seconds = prepare.prepare(sys.stdout, jobs=args.jobs)
    print(f"kernels ready in {seconds:.2f} s; numba cache: {cache_dir()}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
