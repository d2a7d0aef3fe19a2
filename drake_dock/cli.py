"""``drake-dock``: a thin command line over `drake_dock.run.run`.

Exit codes: 0 success; 2 bad input (the message names the field, the value and the allowed
range), found before anything is simulated, ``--out`` included; 3 numerical failure (the
message names the time and the couples). Any other error is reported in one paragraph too
(exit 3, "internal error"), never as a traceback. On failure no output directory is written, or
the previous complete one is left untouched. ``--out`` must be a new path, an empty directory
or a previous drake_dock output (`drake_dock.docking.output.check_destination`).
"""
from __future__ import annotations

import argparse
import sys
import textwrap
import warnings

from drake_dock import __version__
from drake_dock.errors import DrakeDockError, InputError
from drake_dock.docking.scenario import MODELS_DIR, PAPER_EXAMPLE

FUNNEL = MODELS_DIR / "apds_funnel.yaml"


class ProgressBar:
    """A text progress bar on a stream (stderr): redrawn in place on a terminal, otherwise
    printed at every tenth of the run."""

    def __init__(self, stream=None, width=40):
        self.stream, self.width = stream or sys.stderr, width
        self.tty = hasattr(self.stream, "isatty") and self.stream.isatty()
        self.last = -1

    def __call__(self, t, t_end, fraction=None):
        """``fraction``: how far the run is (the rings' way towards capture or the time
        towards the timeout, `drake_dock.docking.outcome.progress_fraction`); t / t_end if
        not given."""
        frac = min(max(t / t_end if fraction is None else fraction, 0.0), 1.0)
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

    def note(self, text):
        """A line of its own below the bar (the output writing, say)."""
        self.close()
        self.last = -1
        self.stream.write(text + "\n")
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
    parser.add_argument("--version", action="version", version=f"drake-dock {__version__}")
    sub = parser.add_subparsers(dest="command", required=True)
    run_p = sub.add_parser("run", help="simulate a docking scenario and write its outputs")
    run_p.add_argument("scenario", nargs="?", default=str(PAPER_EXAMPLE),
                       help="scenario YAML (default: the paper's example)")
    run_p.add_argument("--out", required=True, help=OUT_HELP)
    run_p.add_argument("--duration", type=float, default=None,
                       help="override simulation.duration (s)")
    run_p.add_argument("--no-progress", action="store_true", help="no progress bar")
    study_p = sub.add_parser("study", help="run a study")
    study_p.add_argument("which",
                         choices=["speed-accuracy", "stability", "conditions", "roll",
                                  "crosscheck"],
                         help="speed-accuracy: drake_dock against Drake's compliant contact; "
                              "stability: the five cases where methods fail; conditions: "
                              "seeded conditions in the IDSS initial-contact box; roll: the "
                              "coaxial approach over the whole relative-roll range; "
                              "crosscheck: IDSS-box conditions run by drake_dock and by "
                              "Drake's compliant contact, outcomes compared")
    study_p.add_argument("scenario", nargs="?", default=None,
                         help="scenario YAML (default: the paper's example; speed-accuracy: "
                              "the paper's example and an off-nominal condition; crosscheck: "
                              "models/apds_funnel.yaml)")
    study_p.add_argument("--out", required=True, help=OUT_HELP)
    study_p.add_argument("--quick", action="store_true",
                         help="a few points only (for CI)")
    camp_p = sub.add_parser("campaign", help="run a seeded campaign of samples around a "
                            "scenario on Dask (docs/campaigns.md)")
    camp_p.add_argument("plan", help="campaign plan YAML (e.g. models/idss_envelope.yaml)")
    camp_p.add_argument("--out", required=True,
                        help="campaign directory: a new path, an empty directory, or a "
                             "campaign of the same plan, whose missing samples are run")
    camp_p.add_argument("--workers", type=int, default=None,
                        help="local worker processes (default: one per core)")
    camp_p.add_argument("--scheduler", default=None,
                        help="address of a running Dask scheduler (tcp://HOST:8786) instead "
                             "of a local cluster")
    camp_p.add_argument("--resume", action="store_true",
                        help="DIR must hold a campaign of this plan; run its missing samples")
    camp_p.add_argument("--no-progress", action="store_true", help="no progress bar")
    args = parser.parse_args(argv)
    if args.command == "study":
        return _study(args)
    if args.command == "campaign":
        return _campaign(args)
    # Imported here so that `--help` stays fast.
    from drake_dock.docking.output import check_destination
    from drake_dock.run import format_summary, run
    from drake_dock.docking.scenario import load_scenario, validate
    bar = None if args.no_progress else ProgressBar()

    def work():
        check_destination(args.out)
        scenario = load_scenario(args.scenario)
        if args.duration is not None:
            if not args.duration > 0:
                raise InputError("--duration", args.duration, "> 0 s")
            scenario.simulation.duration = args.duration
            validate(scenario)
        return [format_summary(run(scenario, args.out, progress=bar))]
    return _guarded(work, args.out, None if bar is None else bar.close)


def _guarded(work, out, finish=None) -> int:
    """Runs ``work() -> lines``; maps the typed errors to the exit codes. Anything else (a
    bug, an I/O error while writing) is one paragraph too, never a traceback. Warnings raised
    meanwhile (numpy's overflow, say) are shown after a success, and only summed up in the
    paragraph of a failure. ``finish()`` (the progress bar's) runs before any of it."""
    caught = []
    try:
        with warnings.catch_warnings(record=True) as caught:
            lines = work()
    except InputError as e:
        return _failed(2, "bad input", e, caught, finish)
    except DrakeDockError as e:
        return _failed(3, "numerical failure", e, caught, finish)
    except Exception as e:  # noqa: BLE001 - the last resort of a command line
        kind = "I/O error" if isinstance(e, OSError) else "internal error"
        return _failed(3, f"{kind} ({type(e).__name__})", str(e)[:2000] or repr(e), caught,
                       finish)
    if finish is not None:
        finish()
    for w in caught:
        warnings.showwarning(w.message, w.category, w.filename, w.lineno)
    for line in lines:
        print(line)
    print(f"wrote {out}")
    return 0


def _failed(code, kind, e, caught, finish) -> int:
    if finish is not None:
        finish()
    text = str(e)
    notes = list(dict.fromkeys(str(w.message).split("\n")[0] for w in caught))
    if notes:
        text += f" (after {len(caught)} warnings: {'; '.join(notes[:3])})"
    print(_error(kind, text), file=sys.stderr)
    return code


def _study(args) -> int:
    from drake_dock.docking.output import check_destination
    from drake_dock.docking.scenario import load_scenario
    if args.which == "conditions":
        from drake_dock.studies.conditions import ConditionsPlan as Plan
        from drake_dock.studies.conditions import run_conditions as run_plan
        from drake_dock.studies.conditions import summary_lines as lines
        from drake_dock.studies.conditions import write_conditions as write
    elif args.which == "roll":
        from drake_dock.studies.roll import RollPlan as Plan
        from drake_dock.studies.roll import run_rolls as run_plan
        from drake_dock.studies.roll import summary_lines as lines
        from drake_dock.studies.roll import write_rolls as write
    elif args.which == "crosscheck":
        from drake_dock.studies.crosscheck import CrosscheckPlan as Plan
        from drake_dock.studies.crosscheck import run_crosscheck as run_plan
        from drake_dock.studies.crosscheck import summary_lines as lines
        from drake_dock.studies.crosscheck import write_crosscheck as write
    elif args.which == "stability":
        from drake_dock.studies.stability import StabilityPlan as Plan
        from drake_dock.studies.stability import run_stability as run_plan
        from drake_dock.studies.stability import summary_lines as lines
        from drake_dock.studies.stability import write_stability as write
    else:
        from drake_dock.studies.speed_accuracy import StudyPlan as Plan
        from drake_dock.studies.speed_accuracy import run_study, study_scenes
        from drake_dock.studies.speed_accuracy import speedup_lines as lines
        from drake_dock.studies.speed_accuracy import write_study as write

    def work():
        check_destination(args.out)
        plan = Plan.quick() if args.quick else Plan.full()

        def log(s):
            print(s, flush=True)
        if args.which == "speed-accuracy":
            result = run_study(study_scenes(args.scenario), plan, log)
        else:
            default = FUNNEL if args.which == "crosscheck" else PAPER_EXAMPLE
            result = run_plan(load_scenario(args.scenario or default), plan, log)
        write(result, args.out)
        return lines(result)
    return _guarded(work, args.out)


def _campaign(args) -> int:
    import io
    from drake_dock.campaign.campaign import interrupted_text, run_campaign, summary_lines
    from drake_dock.campaign.progress import CampaignProgress
    bar = CampaignProgress(io.StringIO() if args.no_progress else None)

    def work():
        return summary_lines(run_campaign(args.plan, args.out, workers=args.workers,
                                          scheduler=args.scheduler, resume=args.resume,
                                          progress=bar))
    try:
        return _guarded(work, args.out, bar.close)
    except KeyboardInterrupt:
        bar.close()
        print(_error("interrupted", interrupted_text(args.out)), file=sys.stderr)
        return 130


if __name__ == "__main__":
    sys.exit(main())
