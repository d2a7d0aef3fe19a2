"""Smoke tests of the command line, as a user runs it."""
import json
import os
import re
import subprocess
import sys

import pytest
from pathlib import Path

from drake_dock.cli import STUDIES
from drake_dock.docking.report.out_dir import MARKER, atomic_directory

EXE = [sys.executable, "-m", "drake_dock.cli"]


def _run(args, **kw):
    return subprocess.run(EXE + args, capture_output=True, text=True, timeout=600, **kw)


def test_short_run_writes_outputs(tmp_path):
    """A short run (before the first impact ends): every file is written, nothing else left;
    each file written is named in `drake-dock run --help`."""
    out = tmp_path / "paper"
    r = _run(["run", "--out", str(out), "--duration", "0.005"])
    assert r.returncode == 0, r.stderr
    # The printed wall time separates the kernels, the simulation (cost.json's) and the outputs.
    kernels, simulation, outputs = map(float, re.search(
        r"wall time: kernels ([0-9.]+) s .*, simulation ([0-9.]+) s, outputs ([0-9.]+) s",
        r.stdout).groups())
    cost = json.loads((out / "cost.json").read_text())
    assert simulation == pytest.approx(cost["wall_time_s"], abs=0.051)
    assert kernels >= 0 and outputs > 0
    helped = _run(["run", "--help"]).stdout
    for p in out.iterdir():
        if p.name != MARKER:
            assert (p.name if p.suffix != ".png" else "*.png") in helped, p.name
    summary = json.loads((out / "summary.json").read_text())
    assert summary["initial_ring_distance_m"] > summary["first_contact_ring_distance_m"]
    assert summary["captured"] is False and summary["end_time_s"] == 0.005
    assert "[" in r.stderr and "100%" in r.stderr            # the progress bar
    html = (out / "replay.html").read_text()
    assert "<html" in html.lower() and len(html) > 100_000
    assert (out / "initial_configuration.png").stat().st_size > 10_000
    assert (out / "timeseries.npz").stat().st_size > 1_000
    assert not [p for p in tmp_path.iterdir() if p.name.startswith(".")]  # no temp left


def test_bad_input_exits_2_and_leaves_previous_output(tmp_path):
    bad = tmp_path / "bad.yaml"
    bad.write_text("bodies: {chaser: {mass: -1.0}}\n")
    out = tmp_path / "out"
    with atomic_directory(out) as tmp:                 # a previous drake_dock output
        (tmp / "keep.txt").write_text("previous")
    r = _run(["run", str(bad), "--out", str(out)])
    assert r.returncode == 2
    assert "bodies.chaser.mass" in r.stderr
    assert (out / "keep.txt").read_text() == "previous"
    assert sorted(os.listdir(out)) == [MARKER, "keep.txt"]
    r = _run(["run", str(tmp_path / "nope.yaml"), "--out", str(tmp_path / "new")])
    assert r.returncode == 2 and not (tmp_path / "new").exists()
    assert "nope.yaml" in r.stderr


BAD = {
    "interpenetration": ("initial: {approach_travel: -0.01}\n", "initial.approach_travel"),
    "zero closing speed": ("initial: {chaser_speed: 0}\n", "initial.chaser_speed"),
    "capture beyond the start": ("simulation: {capture_distance: 0.5}\n",
                                 "simulation.capture_distance"),
    "nan": ("initial: {chaser_speed: .nan}\n", "initial.chaser_speed"),
    "negative mass": ("bodies: {target: {mass: -5.0}}\n", "bodies.target.mass"),
    "unknown key": ("contact: {friction: 0.2}\n", "contact.friction"),
}


@pytest.mark.parametrize("case", sorted(BAD))
def test_bad_input_one_paragraph_exit_2_no_output(tmp_path, case):
    text, field = BAD[case]
    bad = tmp_path / "bad.yaml"
    bad.write_text(text)
    out = tmp_path / "out"
    r = _run(["run", str(bad), "--out", str(out), "--no-progress"])
    assert r.returncode == 2, r.stderr
    msg = r.stderr.strip()
    assert field in msg and "not allowed" in msg
    assert "\n\n" not in msg and "Traceback" not in msg      # one paragraph
    assert not out.exists()
    assert not list(tmp_path.glob(".out*"))


def test_unreadable_file_exit_2(tmp_path):
    bad = tmp_path / "locked.yaml"
    bad.write_text("contact: {mu: 0.2}\n")
    bad.chmod(0)
    out = tmp_path / "out"
    # Root reads a mode-0 file: then a directory stands for the unreadable file.
    target = tmp_path if os.access(bad, os.R_OK) else bad
    r = _run(["run", str(target), "--out", str(out), "--no-progress"])
    assert r.returncode == 2
    assert "scenario file" in r.stderr and "Traceback" not in r.stderr
    assert not out.exists()


def test_binary_scenario_file_exit_2(tmp_path):
    bad = tmp_path / "scenario.yaml"
    bad.write_bytes(bytes(range(256)) * 4)
    out = tmp_path / "out"
    r = _run(["run", str(bad), "--out", str(out), "--no-progress"])
    assert r.returncode == 2, r.stderr
    assert "scenario file" in r.stderr and "UTF-8" in r.stderr and "Traceback" not in r.stderr
    assert not out.exists()


def test_help_is_written_for_users():
    """The top-level help says what each command does, the outcomes and the exit codes, in the
    words the rest of the tool uses (the outcomes of `drake_dock.docking.model.outcome`)."""
    from drake_dock.docking.model.outcome import OUTCOMES
    r = _run(["--help"])
    assert r.returncode == 0
    text = r.stdout
    assert "thin command line" not in text and "``" not in text
    for command in ("run", "study", "campaign"):
        assert f"\n    {command} " in text, command
    for outcome in OUTCOMES:
        assert f"\n  {outcome} " in text, outcome
    for code in ("0", "2", "3", "130"):
        assert f"\n  {code} " in text, code


def test_study_alone_lists_the_studies():
    """`drake-dock study` alone lists the studies and exits 0; each listed name is accepted by
    `drake-dock study NAME` (which then asks for --out, exit 2, not argparse's choice error)."""
    r = _run(["study"])
    assert r.returncode == 0, r.stderr
    listed = [line.split()[0] for line in r.stdout.split("studies:")[1].splitlines()
              if line.startswith("  ") and not line.startswith("    ")]
    assert listed == list(STUDIES)
    for name in listed:
        r = _run(["study", name])
        assert r.returncode == 2 and r.stderr.startswith("drake-dock: bad input: --out is "
                                                         "missing"), r.stderr


def test_input_errors_lead_with_their_reason(tmp_path):
    """The reason of a refusal comes right after the value, before the rules of what is
    allowed; an empty scenario file says so."""
    user = tmp_path / "results"
    user.mkdir()
    (user / "notes.txt").write_text("mine")
    r = _run(["run", "--out", str(user), "--no-progress"])
    msg = " ".join(r.stderr.split())
    assert r.returncode == 2
    after = msg.index(f"{user}'") + len(str(user))
    assert msg.index("not a drake_dock output") < after + 60 < msg.index("; allowed:")
    empty = tmp_path / "empty.yaml"
    empty.write_text("# nothing yet\n")
    r = _run(["run", str(empty), "--out", str(tmp_path / "out"), "--no-progress"])
    msg = " ".join(r.stderr.split())
    assert r.returncode == 2 and "holds no YAML content (empty, or only comments)" in msg
    assert "NoneType" not in msg and not (tmp_path / "out").exists()


@pytest.mark.parametrize("command", [["run"], ["study", "stability"]])
def test_a_command_that_fails_on_its_input_stops_the_compile(tmp_path, command):
    """With an empty kernel cache a run (or a study) starts compiling in worker processes
    before it reads its scenario; a bad scenario ends it (exit 2) and its workers with it: no
    unit is marked compiled after it has returned (the first units take about 4 s, the wait is
    6 s)."""
    import time

    from drake_dock.core.kernels import prepare
    if prepare.cores() < 2:
        pytest.skip("one core: the kernels compile in the run's own process, no workers")
    empty = tmp_path / "empty.yaml"
    empty.write_text("# nothing yet\n")
    cache = tmp_path / "numba"
    r = _run(command + [str(empty), "--out", str(tmp_path / "out")]
             + (["--no-progress"] if command == ["run"] else []),
             env=dict(os.environ, NUMBA_CACHE_DIR=str(cache)))
    assert r.returncode == 2 and "compiling the numba kernels" in r.stderr
    assert "holds no YAML content" in " ".join(r.stderr.split())
    marked = sorted(cache.rglob("warm.done"))      # a unit may finish before the input fails
    time.sleep(6.0)
    assert sorted(cache.rglob("warm.done")) == marked


def test_ctrl_c_during_the_compile_stops_the_run_and_its_workers(tmp_path):
    """Ctrl-C (SIGINT to the run's process group, as a terminal sends it) while the kernels
    compile: exit 130 with one line and no traceback from the run or its workers, nothing
    written, and no unit marked compiled after the run has returned."""
    import signal
    import time

    from drake_dock.core.kernels import prepare
    if prepare.cores() < 2:
        pytest.skip("one core: the kernels compile in the run's own process, no workers")
    cache, out = tmp_path / "numba", tmp_path / "out"
    proc = subprocess.Popen(EXE + ["run", "--out", str(out), "--no-progress"],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                            env=dict(os.environ, NUMBA_CACHE_DIR=str(cache)),
                            start_new_session=True)
    time.sleep(3.0)
    os.killpg(proc.pid, signal.SIGINT)
    _, err = proc.communicate(timeout=60)
    # 130, or an end by SIGINT itself after the line (a shell's $? is 130 either way): after a
    # Ctrl-C that lands in pydrake's module initialisation (the run imports it while the
    # kernels compile) the interpreter sometimes ends so, by CPython's unhandled-Ctrl-C flag
    # as far as can be told from outside.
    assert proc.returncode in (130, -signal.SIGINT), err
    assert "compiling the numba kernels" in err and "stopped by Ctrl-C" in err
    assert "Traceback" not in err and not out.exists()
    marked = sorted(cache.rglob("warm.done"))
    time.sleep(6.0)
    assert sorted(cache.rglob("warm.done")) == marked


def test_kernels_prepared_with_a_line_per_module_when_they_compile(monkeypatch):
    """The kernels are compiled (or loaded) before the run; when their cache lacks some (a
    first run after an install) a note and a line per module say so, and nothing otherwise."""
    import io

    from drake_dock import cli
    from drake_dock.core.kernels import prepare
    monkeypatch.setattr(prepare, "warm", lambda names=None, stream=None: None)
    monkeypatch.setattr(prepare, "compile_parallel",
                        lambda names, jobs, stream, *rest: [stream.write(f"  {n}: 1.0 s\n")
                                                            for n in names])
    monkeypatch.setattr(prepare, "cores", lambda: 2)
    monkeypatch.setattr(prepare, "_workers", lambda jobs: [])
    monkeypatch.setattr(prepare, "missing", lambda names=None: ["lzb", "seek"])
    cold = io.StringIO()
    cli.start_kernels(cold).finish()
    assert "compiling the numba kernels, 2 modules in 2 processes" in cold.getvalue()
    assert "  lzb: 1.0 s\n  seek: 1.0 s\n" in cold.getvalue()
    monkeypatch.setattr(prepare, "missing", lambda names=None: [])
    warm = io.StringIO()
    cli.start_kernels(warm).finish()
    assert warm.getvalue() == ""


def test_ctrl_c_inside_an_import_is_exit_130_with_one_line(monkeypatch, capsys):
    """Ctrl-C inside an extension module's initialisation surfaces as an ImportError from
    KeyboardInterrupt: the command line says "stopped by Ctrl-C" and exits 130, with no
    traceback; an ImportError of its own is not taken for one."""
    from drake_dock import cli

    def interrupted_import(args, kernels):
        try:
            raise KeyboardInterrupt
        except KeyboardInterrupt as k:
            raise ImportError("initialization failed") from k

    monkeypatch.setattr(cli, "_start_kernels_or_none", lambda: None)
    monkeypatch.setattr(cli, "_run_command", interrupted_import)
    assert cli.main(["run", "--out", "never-written"]) == 130
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "stopped by Ctrl-C" in err and "Traceback" not in err

    def broken_import(args, kernels):
        raise ImportError("no module named x")

    monkeypatch.setattr(cli, "_run_command", broken_import)
    with pytest.raises(ImportError):
        cli.main(["run", "--out", "never-written"])
    # Inside a command's error mapping it is Ctrl-C again, for the command to say so.
    with pytest.raises(KeyboardInterrupt):
        cli._guarded(lambda: interrupted_import(None, None), None)
