"""``drake-dock``: a thin command line over `drake_dock.run.run`."""
from __future__ import annotations

import argparse
import sys

from drake_dock.errors import DrakeDockError
from drake_dock.scenario import PAPER_EXAMPLE


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(prog="drake-dock", description=__doc__)
    sub = parser.add_subparsers(dest="command", required=True)
    run_p = sub.add_parser("run", help="set up and run a docking scenario")
    run_p.add_argument("scenario", nargs="?", default=str(PAPER_EXAMPLE),
                       help="scenario YAML (default: the paper's example)")
    run_p.add_argument("--out", required=True, help="output directory (replaced atomically)")
    args = parser.parse_args(argv)
    # Imported here so that `--help` stays fast.
    from drake_dock.run import format_summary, run
    from drake_dock.scenario import load_scenario
    try:
        scenario = load_scenario(args.scenario)
        summary = run(scenario, args.out)
    except DrakeDockError as e:
        print(f"drake-dock: error: {e}", file=sys.stderr)
        return 2
    print(format_summary(summary))
    print(f"wrote {args.out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
