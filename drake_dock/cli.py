"""``drake-dock``: a thin command line over `drake_dock.run.run`.

Exit codes: 0 success; 2 bad input (the message names the field, the value and the allowed
range), ``--out`` included, before anything is simulated; 3 numerical failure (the message
names the time and the couples). On failure no output directory is written, or the previous
complete one is left untouched. ``--out`` must be a new path, an empty directory or a previous
drake_dock output (`drake_dock.output.check_destination`).
"""
from __future__ import annotations

import argparse
import sys
import textwrap

from drake_dock.errors import DrakeDockError, InputError
from drake_dock.scenario import PAPER_EXAMPLE


class ProgressBar:
    """A text progress bar on a stream (stderr): redrawn in place on a terminal, otherwise
    printed at every tenth of the run."""

    def __init__(self, stream=sys.stderr, width=40):
        self.stream, self.width = stream, width
        self.tty = hasattr(stream, "isatty") and stream.isatty()
        self.last = -1

    def __call__(self, t, t_end):
        frac = min(max(t / t_end, 0.0), 1.0)
        step = int(frac * (100 if self.tty else 10))
        if step == self.last:
            return
        self.last = step
        n = int(frac * self.width)
        line = f"[{'#' * n}{'.' * (self.width - n)}] {frac:4.0%}  t = {t:.4f} s"
        if self.tty:
            self.stream.write("\r" + line)
        else:
            self.stream.write(line + "\n")
        self.stream.flush()

    def close(self):
        if self.tty and self.last >= 0:
            self.stream.write("\n")
            self.stream.flush()


OUT_HELP = ("output directory: a new path, an empty directory or a previous drake_dock output, "
            "replaced atomically (anything else is refused)")


def _error(kind, e) -> str:
    # Paths and names are never split (no breaks inside words or at hyphens).
    return textwrap.fill(f"drake-dock: {kind}: {e}", width=100, break_long_words=False,
                         break_on_hyphens=False)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(prog="drake-dock", description=__doc__.splitlines()[0])
    sub = parser.add_subparsers(dest="command", required=True)
    run_p = sub.add_parser("run", help="simulate a docking scenario and write its outputs")
    run_p.add_argument("scenario", nargs="?", default=str(PAPER_EXAMPLE),
                       help="scenario YAML (default: the paper's example)")
    run_p.add_argument("--out", required=True, help=OUT_HELP)
    run_p.add_argument("--duration", type=float, default=None,
                       help="override simulation.duration (s)")
    run_p.add_argument("--no-progress", action="store_true", help="no progress bar")
    study_p = sub.add_parser("study", help="run a study")
    study_p.add_argument("which", choices=["speed-accuracy", "stability"],
                         help="speed-accuracy: drake_dock against Drake's compliant contact; "
                              "stability: the five cases where methods fail")
    study_p.add_argument("scenario", nargs="?", default=str(PAPER_EXAMPLE),
                         help="scenario YAML (default: the paper's example)")
    study_p.add_argument("--out", required=True, help=OUT_HELP)
    study_p.add_argument("--quick", action="store_true",
                         help="a few points only (for CI)")
    args = parser.parse_args(argv)
    if args.command == "study":
        return _study(args)
    # Imported here so that `--help` stays fast.
    from drake_dock.output import check_destination
    from drake_dock.run import format_summary, run
    from drake_dock.scenario import load_scenario
    bar = None if args.no_progress else ProgressBar()

    def work():
        check_destination(args.out)
        scenario = load_scenario(args.scenario)
        if args.duration is not None:
            if not args.duration > 0:
                raise InputError("--duration", args.duration, "> 0 s")
            scenario.simulation.duration = args.duration
        return [format_summary(run(scenario, args.out, progress=bar))]
    try:
        return _guarded(work, args.out)
    finally:
        if bar is not None:
            bar.close()


def _guarded(work, out) -> int:
    """Runs ``work() -> lines``; maps the typed errors to the exit codes."""
    try:
        lines = work()
    except InputError as e:
        print(_error("bad input", e), file=sys.stderr)
        return 2
    except DrakeDockError as e:
        print(_error("numerical failure", e), file=sys.stderr)
        return 3
    for line in lines:
        print(line)
    print(f"wrote {out}")
    return 0


def _study(args) -> int:
    from drake_dock.output import check_destination
    from drake_dock.scenario import load_scenario
    if args.which == "stability":
        from drake_dock.stability import StabilityPlan as Plan
        from drake_dock.stability import run_stability as run_plan
        from drake_dock.stability import summary_lines as lines
        from drake_dock.stability import write_stability as write
    else:
        from drake_dock.study import StudyPlan as Plan
        from drake_dock.study import run_study as run_plan
        from drake_dock.study import speedup_lines as lines
        from drake_dock.study import write_study as write

    def work():
        check_destination(args.out)
        scenario = load_scenario(args.scenario)
        result = run_plan(scenario, Plan.quick() if args.quick else Plan.full(),
                          log=lambda s: print(s, flush=True))
        write(result, args.out)
        return lines(result)
    return _guarded(work, args.out)


if __name__ == "__main__":
    sys.exit(main())
