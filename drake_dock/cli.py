"""drake-dock simulates the capture-phase contact between two spacecraft carrying androgynous
peripheral docking systems (APDS): a scenario in; the outcome, the loads at the docking ring,
the energy ledger, figures and a 3D replay out.

outcomes of a run (the first that holds ends it):
  captured   the latches can engage: the rings within simulation.capture_distance axially,
             capture_lateral across and capture_tilt_deg in tilt
  missed     the chaser passes beside the target (ring centres over 2 R apart across the
             axis) or beyond its ring plane (over simulation.capture_distance behind it and
             over capture_lateral off the axis, or over a petal height H behind it)
  rebound    the rings separate: their distance above its start and growing, with no
             thrust still to act (a couple may still graze)
  jammed     the distance to capture has not fallen by 1 mm in simulation.jam_time while
             no thrust is to act; the reason names the couples that hold the rings
  timeout    simulation.duration reached

exit codes:
  0    success: the outputs are written and `wrote DIR` is printed
  2    bad input: the message gives the field, the value, the reason and what is allowed;
       found before anything is simulated (--out included)
  3    numerical failure: the message names the time and the couples
  130  stopped by Ctrl-C: a run writes nothing; a campaign keeps its finished samples and the
       same command runs the rest
On failure nothing is written at --out (a previous output there is left as it was).

examples:
  drake-dock run --out out/paper_example              (the paper's example)
  drake-dock run models/idss_box_corner.yaml --out out/box_corner
  drake-dock study conditions --quick --out out/conditions
"""
from __future__ import annotations

import argparse
import sys
import textwrap
import time
import warnings
from pathlib import Path

from drake_dock import __version__
from drake_dock.docking.scenario.models_dir import MODELS_DIR, PAPER_EXAMPLE
from drake_dock.errors import MISSING, DrakeDockError, InputError

FUNNEL = MODELS_DIR / "apds_funnel.yaml"

RUN_EPILOG = """files written into DIR:
  summary.json      the outcome and its reason, capture time, final misalignment, peak loads
                    at the target ring, Stewart stroke and force, contact forces, relative
                    kinetic energy at contact, energy ledger, impacts, the couples in plain words
  cost.json         what the run cost the solver (wall time, evaluations, time shares)
  timeseries.npz    the sampled motion, couples, forces and energies (compressed)
  *.png             the paper's Figs. 6-9, couple forces, energy ledger, interface loads and
                    the initial configuration
  replay.html       a 3D replay in one page (open it in a browser)
  drake.log         what Drake logged during the run, when it logged anything that matters
DIR must be a new path, an empty directory or a previous drake_dock output; it is replaced
atomically. The run prints a summary and `wrote DIR`; exit codes: 0 success, 2 bad input,
3 numerical failure (`drake-dock --help`)."""

# The studies: name -> what it does (`drake-dock study` lists them).
STUDIES = {
    "speed-accuracy": "drake_dock against Drake's compliant contact (point and hydroelastic, "
                      "SAP and RK3): wall time against accuracy on the paper's example and an "
                      "off-nominal condition",
    "stability": "five cases where methods fail: step size, unequal stiffness, Painleve "
                 "friction, grazing contact, Zeno bounces",
    "conditions": "60 seeded conditions and 16 corners of the IDSS initial-contact box, each "
                  "run to its outcome and checked for interpenetration",
    "roll": "the coaxial approach over the whole relative-roll range, each run to its outcome",
    "examples": "the named off-axis scenarios of models/ and the base scenario in free drift "
                "at slow closing rates, each run to its outcome and checked for "
                "interpenetration",
    "funnel": "the capture range (the largest lateral offset that captures) over the petal "
              "tips' clearance and the post-contact thrust (default scenario: "
              "models/apds_funnel.yaml)",
    "crosscheck": "IDSS-box conditions run by drake_dock and by Drake's compliant contact, "
                  "outcomes and capture times compared (default scenario: "
                  "models/apds_funnel.yaml)",
}
STUDY_USAGE = "drake-dock study NAME [SCENARIO.yaml] --out DIR [--quick]"


def studies_text() -> str:
    """The list printed by `drake-dock study` alone."""
    width = max(map(len, STUDIES)) + 2
    lines = [f"usage: {STUDY_USAGE}", "", "studies:"]
    for name, what in STUDIES.items():
        wrapped = textwrap.wrap(what, 96 - width - 2)
        lines.append(f"  {name:<{width}}{wrapped[0]}")
        lines += [" " * (width + 2) + w for w in wrapped[1:]]
    lines += ["", "Each writes its files (CSV, figures, summary) into DIR and prints its summary "
              "lines;", "--quick runs a few points only. docs/studies.md describes each "
              "study's files."]
    return "\n".join(lines)


class ProgressBar:
    """A text progress bar on a stream (stderr): redrawn in place on a terminal, otherwise
    printed at every tenth of the run."""

    def __init__(self, stream=None, width=40):
        self.stream, self.width = stream or sys.stderr, width
        self.tty = hasattr(self.stream, "isatty") and self.stream.isatty()
        self.last = -1

    def __call__(self, t, t_end, fraction=None):
        """``fraction``: how far the run is (the rings' way towards capture or the time
        towards the timeout, `drake_dock.docking.model.outcome.progress_fraction`); t / t_end if
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


def _wrap(text) -> str:
    return textwrap.fill(text, width=92)


def _parser() -> argparse.ArgumentParser:
    raw = argparse.RawDescriptionHelpFormatter
    doc = __doc__.split("\n\n", 1)
    parser = argparse.ArgumentParser(prog="drake-dock", description=doc[0],
                                     epilog=doc[1], formatter_class=raw)
    parser.add_argument("--version", action="version", version=f"drake-dock {__version__}")
    sub = parser.add_subparsers(dest="command", required=True, metavar="COMMAND")
    run_p = sub.add_parser(
        "run", help="simulate one scenario and write its outputs", formatter_class=raw,
        description=_wrap("Simulates a docking scenario until its outcome (captured, "
                          "rebound, jammed or timeout; `drake-dock --help`) with a progress "
                          "bar on stderr, prints a summary and writes the outputs into DIR."),
        epilog=RUN_EPILOG)
    run_p.add_argument("scenario", nargs="?", default=str(PAPER_EXAMPLE),
                       help="scenario YAML; absent sections and fields take their defaults "
                            "(docs/scenario.md; default: the paper's example)")
    run_p.add_argument("--out", metavar="DIR", help=OUT_HELP)
    run_p.add_argument("--duration", type=float, default=None,
                       help="override simulation.duration, the timeout (s)")
    run_p.add_argument("--no-progress", action="store_true", help="no progress bar")
    run_p.add_argument("--print-scenario", action="store_true",
                       help="print the full scenario the run would use (every field, defaults "
                            "filled in, --duration applied) as YAML, and exit without "
                            "simulating")
    study_p = sub.add_parser(
        "study", help="run a study (`drake-dock study` lists them)", formatter_class=raw,
        description="Runs a study and writes its files into DIR.",
        epilog=studies_text())
    study_p.add_argument("which", nargs="?", choices=list(STUDIES), metavar="NAME",
                         help="the study (" + ", ".join(STUDIES) + "); absent: list them")
    study_p.add_argument("scenario", nargs="?", default=None,
                         help="scenario YAML (default: the paper's example; speed-accuracy: "
                              "the paper's example and an off-nominal condition; funnel and "
                              "crosscheck: models/apds_funnel.yaml)")
    study_p.add_argument("--out", metavar="DIR", help=OUT_HELP)
    study_p.add_argument("--quick", action="store_true",
                         help="a few points only (for CI)")
    camp_p = sub.add_parser(
        "campaign", help="run a seeded campaign of samples around a scenario on Dask",
        formatter_class=raw,
        description=_wrap("Runs a seeded campaign (a plan: a base scenario and the ranges of "
                          "its varied fields) on a local Dask cluster or a running scheduler, "
                          "one row per sample, and writes its rows, summary, figures and worst "
                          "samples into DIR (docs/campaigns.md). Ctrl-C stops it (exit 130); "
                          "the same command runs the rest."))
    camp_p.add_argument("plan", help="campaign plan YAML (e.g. models/idss_envelope.yaml)")
    camp_p.add_argument("--out", required=True, metavar="DIR",
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
    return parser


def start_kernels(stream=None):
    """Starts compiling the numba kernels that their cache lacks (a first run after an install
    or an update: in parallel worker processes, with a line per module on ``stream``, stderr by
    default) while a run or a study imports the simulation and reads its input; its
    ``finish()`` loads them all, before the simulation, so that a run's wall time and its
    progress bar are the simulation's, and returns the seconds the kernels held it up
    (`drake_dock.core.kernels.prepare.Preparation`)."""
    from drake_dock.core.kernels.prepare import Preparation
    return Preparation.start(stream or sys.stderr)


def _need_out(out, what):
    if out is None:
        raise InputError("--out", MISSING, f"give a directory for {what} (--out DIR: a new "
                         f"path, an empty directory or a previous drake_dock output)")


def main(argv=None) -> int:
    args = _parser().parse_args(argv)
    try:
        if args.command == "study":
            if args.which is None:
                print(studies_text())
                return 0
            return _with_kernels(args, _study)
        if args.command == "campaign":
            return _campaign(args)
        return _with_kernels(args, _run_command)
    except (KeyboardInterrupt, ImportError) as e:   # Ctrl-C before a command's own handling
        if not _by_ctrl_c(e):
            raise
        print(_error("interrupted", "stopped by Ctrl-C"), file=sys.stderr)
        return 130


def _by_ctrl_c(e) -> bool:
    """Whether the exception ``e`` is Ctrl-C or follows from it: Ctrl-C inside an extension
    module's initialisation (pydrake's, during an import) surfaces as an ImportError from
    KeyboardInterrupt."""
    seen = set()
    while e is not None and id(e) not in seen:
        if isinstance(e, KeyboardInterrupt):
            return True
        seen.add(id(e))
        e = e.__cause__ or e.__context__
    return False


def _start_kernels_or_none():
    """`start_kernels`, or None where they cannot start (the command starts them again, inside
    its error mapping, or goes without)."""
    try:
        return start_kernels()
    except Exception:  # noqa: BLE001 - reported where they are started again
        return None


def _with_kernels(args, command) -> int:
    """``command(args, kernels)`` (a run or a study), the kernels compiling meanwhile where
    it has outputs to write (`start_kernels`; None otherwise); Ctrl-C is exit 130."""
    kernels = None
    if not getattr(args, "print_scenario", False) and args.out is not None:
        kernels = _start_kernels_or_none()
    try:
        return command(args, kernels)
    except (KeyboardInterrupt, ImportError) as e:   # the output directory is written whole or
        if not _by_ctrl_c(e):                       # not at all
            raise
        print(_error("interrupted", f"stopped by Ctrl-C; nothing written to {args.out}"
                     if args.out else "stopped by Ctrl-C"), file=sys.stderr)
        return 130
    finally:
        if kernels is not None:
            kernels.cancel()            # a command that failed or stopped before it needed them


def _run_command(args, kernels) -> int:
    # Imported here so that `--help` stays fast.
    from drake_dock.docking.report.out_dir import check_destination
    from drake_dock.docking.scenario.loading import load_scenario
    from drake_dock.docking.scenario.loading import scenario_yaml
    from drake_dock.docking.scenario.validation import validate
    from drake_dock.run import format_summary, run

    def scenario():
        s = load_scenario(args.scenario)
        if args.duration is not None:
            if not args.duration > 0:
                raise InputError("--duration", args.duration, "> 0 s")
            s.simulation.duration = args.duration
            validate(s)
        return s
    if args.print_scenario:
        return _guarded(lambda: [scenario_yaml(scenario()).rstrip("\n")], None)
    bar = None if args.no_progress else ProgressBar()

    def work():
        _need_out(args.out, "the run's outputs")
        check_destination(args.out)
        scenario_ = scenario()
        seconds = (kernels or start_kernels()).finish()
        t0 = time.perf_counter()
        out = run(scenario_, args.out, progress=bar, full=True, name=Path(args.scenario).stem)
        outputs = time.perf_counter() - t0 - out.cost["wall_time_s"]
        return [format_summary(out.summary, out.cost),
                f"wall time: kernels {seconds:.1f} s (compiled after an install or an update, "
                f"loaded from the cache after), simulation {out.cost['wall_time_s']:.1f} s, "
                f"outputs {outputs:.1f} s"]
    try:
        return _guarded(work, args.out, None if bar is None else bar.close)
    except KeyboardInterrupt:
        if bar is not None:
            bar.close()
        raise                           # `main` says so


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
        if _by_ctrl_c(e):
            raise KeyboardInterrupt from e      # the caller says so
        kind = "I/O error" if isinstance(e, OSError) else "internal error"
        return _failed(3, f"{kind} ({type(e).__name__})", str(e)[:2000] or repr(e), caught,
                       finish)
    if finish is not None:
        finish()
    for w in caught:
        warnings.showwarning(w.message, w.category, w.filename, w.lineno)
    for line in lines:
        print(line)
    if out is not None:
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


def _study(args, kernels) -> int:
    from drake_dock.docking.report.out_dir import check_destination
    from drake_dock.docking.scenario.loading import load_scenario
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
    elif args.which == "examples":
        from drake_dock.studies.examples import ExamplesPlan as Plan
        from drake_dock.studies.examples import run_examples as run_plan
        from drake_dock.studies.examples import summary_lines as lines
        from drake_dock.studies.examples import write_examples as write
    elif args.which == "funnel":
        from drake_dock.studies.funnel import FunnelPlan as Plan
        from drake_dock.studies.funnel import run_funnel as run_plan
        from drake_dock.studies.funnel import summary_lines as lines
        from drake_dock.studies.funnel import write_funnel as write
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
        _need_out(args.out, f"the {args.which} study's files")
        check_destination(args.out)
        plan = Plan.quick() if args.quick else Plan.full()

        def log(s):
            print(s, flush=True)
        if args.which == "speed-accuracy":
            scenes = study_scenes(args.scenario)
            (kernels or start_kernels()).finish()
            result = run_study(scenes, plan, log)
        else:
            default = FUNNEL if args.which in ("funnel", "crosscheck") else PAPER_EXAMPLE
            scenario = load_scenario(args.scenario or default)
            (kernels or start_kernels()).finish()
            result = run_plan(scenario, plan, log)
        write(result, args.out)
        return lines(result)
    return _guarded(work, args.out)


def _campaign(args) -> int:
    import io
    from drake_dock.campaign.campaign import interrupted_text, run_campaign, summary_lines
    from drake_dock.campaign.progress import CampaignProgress
    bar = CampaignProgress(io.StringIO() if args.no_progress else None)

    # The local workers load the kernels that this process compiles while it reads the plan (a
    # scheduler's workers are elsewhere, with their own caches).
    kernels = None if args.scheduler else _start_kernels_or_none()

    def work():
        return summary_lines(run_campaign(args.plan, args.out, workers=args.workers,
                                          scheduler=args.scheduler, resume=args.resume,
                                          progress=bar,
                                          ready=None if kernels is None else kernels.finish))
    try:
        return _guarded(work, args.out, bar.close)
    except KeyboardInterrupt:
        bar.close()
        print(_error("interrupted", interrupted_text(args.out)), file=sys.stderr)
        return 130
    finally:
        if kernels is not None:
            kernels.cancel()


if __name__ == "__main__":
    sys.exit(main())
