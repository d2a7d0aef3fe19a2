"""Output safety: `--out` is written only if it is new, an empty directory or a previous
drake_dock output; anything else is refused with exit 2 before simulating, naming the path, and
left as it was. Replacing a previous output is atomic. Failures are one paragraph, typed."""
import json
import os
from pathlib import Path

import pytest

from drake_dock.cli import main
from drake_dock.docking.report.out_dir import MARKER, atomic_directory, check_destination
from drake_dock.errors import InputError, NumericalError

BOOM = "simulated although the destination is refused"


@pytest.fixture
def no_simulation(monkeypatch):
    """Any simulation or study fails the test: refusals come before them."""
    def boom(*args, **kwargs):
        raise AssertionError(BOOM)
    monkeypatch.setattr("drake_dock.run.simulate", boom)
    monkeypatch.setattr("drake_dock.studies.speed_accuracy.run_study", boom)
    monkeypatch.setattr("drake_dock.studies.stability.run_stability", boom)


def _refused(capsys, argv, path):
    """main(argv) exits 2 with one paragraph naming ``path``; returns the message."""
    rc = main(argv)
    err = capsys.readouterr().err
    assert rc == 2, err
    assert BOOM not in err and "Traceback" not in err and "\n\n" not in err.strip()
    msg = " ".join(err.split())
    assert "--out" in msg and str(path) in msg, msg
    return msg


def _user_dir(path: Path) -> Path:
    path.mkdir(parents=True, exist_ok=True)
    (path / "thesis.tex").write_text("years of work")
    return path


def _intact(path: Path):
    assert sorted(os.listdir(path)) == ["thesis.tex"]
    assert (path / "thesis.tex").read_text() == "years of work"


def _siblings(path: Path):
    """Hidden entries next to ``path``: temporary or moved-aside directories."""
    return [p.name for p in path.parent.iterdir() if p.name.startswith(".")]


@pytest.mark.parametrize("command", [["run"], ["study", "speed-accuracy", "--quick"],
                                     ["study", "stability", "--quick"]])
def test_directory_holding_a_user_file_is_refused_and_kept(tmp_path, capsys, no_simulation,
                                                           command):
    out = _user_dir(tmp_path / "results")
    msg = _refused(capsys, command + ["--out", str(out)], out)
    assert "not a drake_dock output" in msg
    _intact(out)
    assert _siblings(out) == []


def test_current_directory_and_its_parents_are_refused(tmp_path, capsys, no_simulation,
                                                       monkeypatch):
    work = _user_dir(tmp_path / "work")
    monkeypatch.chdir(work)
    _refused(capsys, ["run", "--out", "."], work)
    _refused(capsys, ["run", "--out", ".."], tmp_path)
    _refused(capsys, ["run", "--out", ""], work)
    _intact(work)
    empty = tmp_path / "empty"               # even empty: it is where the user stands
    empty.mkdir()
    monkeypatch.chdir(empty)
    _refused(capsys, ["run", "--out", "."], empty)
    assert empty.is_dir()


def test_home_directory_is_refused_even_with_a_marker(tmp_path, capsys, no_simulation,
                                                      monkeypatch):
    home = _user_dir(tmp_path / "home")
    monkeypatch.setenv("HOME", str(home))
    assert Path("~").expanduser() == home
    msg = _refused(capsys, ["run", "--out", str(home)], home)
    assert "home directory" in msg
    _intact(home)
    (home / MARKER).write_text(json.dumps({"producer": "drake_dock", "entries": ["thesis.tex"]}))
    _refused(capsys, ["run", "--out", str(home)], home)
    assert (home / "thesis.tex").read_text() == "years of work"


def test_existing_file_is_refused_and_kept(tmp_path, capsys, no_simulation):
    f = tmp_path / "results"
    f.write_text("a file")
    _refused(capsys, ["run", "--out", str(f)], f)
    assert f.read_text() == "a file"
    assert sorted(os.listdir(tmp_path)) == ["results"]


def test_symbolic_link_to_a_user_directory_is_refused(tmp_path, capsys, no_simulation):
    target = _user_dir(tmp_path / "data")
    link = tmp_path / "results"
    link.symlink_to(target)
    _refused(capsys, ["run", "--out", str(link)], link)
    _intact(target)
    assert link.is_symlink()


def test_unwritable_destination_is_refused_before_simulating(tmp_path, capsys, no_simulation):
    f = tmp_path / "notes.txt"
    f.write_text("not a directory")
    out = f / "results"
    msg = _refused(capsys, ["run", "--out", str(out)], out)
    assert "not a directory" in msg
    assert f.read_text() == "not a directory"
    if Path("/proc").is_dir():               # a file system where nothing can be created
        _refused(capsys, ["run", "--out", "/proc/drake_dock_results"], "/proc")


@pytest.mark.skipif(os.geteuid() == 0, reason="root writes into read-only directories")
def test_read_only_parent_is_refused(tmp_path, capsys, no_simulation):
    parent = tmp_path / "locked"
    parent.mkdir()
    parent.chmod(0o500)
    try:
        _refused(capsys, ["run", "--out", str(parent / "results")], parent)
    finally:
        parent.chmod(0o700)
    assert os.listdir(parent) == []


def test_force_is_no_way_around(tmp_path, capsys, no_simulation):
    out = _user_dir(tmp_path / "results")
    with pytest.raises(SystemExit) as e:
        main(["run", "--out", str(out), "--force"])
    assert e.value.code == 2
    _intact(out)


def _previous_output(out: Path):
    with atomic_directory(out) as tmp:
        (tmp / "old.txt").write_text("previous run")
        (tmp / "figs").mkdir()
        (tmp / "figs" / "a.png").write_bytes(b"png")
    return out


def test_previous_output_is_replaced_atomically(tmp_path):
    out = _previous_output(tmp_path / "results")
    assert (out / MARKER).is_file()
    with atomic_directory(out) as tmp:
        (tmp / "new.txt").write_text("this run")
        # While the new output is written, the previous one is whole where it was.
        assert (out / "old.txt").read_text() == "previous run"
        assert not (out / "new.txt").exists()
    assert sorted(os.listdir(out)) == [MARKER, "new.txt"]
    assert json.loads((out / MARKER).read_text())["entries"] == ["new.txt"]
    assert _siblings(out) == []


def test_failed_write_leaves_previous_output_and_no_temporary(tmp_path):
    out = _previous_output(tmp_path / "results")
    with pytest.raises(RuntimeError):
        with atomic_directory(out) as tmp:
            (tmp / "new.txt").write_text("half")
            raise RuntimeError("figure failed")
    assert (out / "old.txt").read_text() == "previous run"
    assert _siblings(out) == []
    with pytest.raises(RuntimeError):                # and parents it made are removed
        with atomic_directory(tmp_path / "a" / "b" / "results"):
            raise RuntimeError("figure failed")
    assert sorted(os.listdir(tmp_path)) == ["results"]


def test_run_replaces_its_previous_output(tmp_path, capsys):
    """The command line over a previous output (a short run): replaced, nothing left over."""
    out = _previous_output(tmp_path / "results")
    rc = main(["run", "--out", str(out), "--duration", "0.005", "--no-progress"])
    assert rc == 0, capsys.readouterr().err
    names = set(os.listdir(out))
    assert {"summary.json", "timeseries.npz", "replay.html", MARKER} <= names
    assert not {"old.txt", "figs"} & names
    assert _siblings(out) == []
    marker = json.loads((out / MARKER).read_text())
    assert marker["producer"] == "drake_dock" and set(marker["entries"]) == names - {MARKER}


def test_previous_output_with_a_user_file_added_is_refused(tmp_path, capsys, no_simulation):
    out = _previous_output(tmp_path / "results")
    (out / "figs" / "my_notes.txt").write_text("mine")
    msg = _refused(capsys, ["run", "--out", str(out)], out)
    assert "figs/my_notes.txt" in msg
    assert (out / "figs" / "my_notes.txt").read_text() == "mine"
    assert (out / "old.txt").is_file()


def test_atomic_directory_refuses_by_itself(tmp_path):
    out = _user_dir(tmp_path / "results")
    with pytest.raises(InputError) as e:
        with atomic_directory(out):
            pytest.fail("entered")
    assert e.value.field == "--out" and str(out) in str(e.value)
    _intact(out)
    assert _siblings(out) == []


def test_new_path_and_empty_directory_are_accepted(tmp_path):
    assert check_destination(tmp_path / "new" / "results") == tmp_path / "new" / "results"
    assert not (tmp_path / "new").exists()           # the check creates nothing
    empty = tmp_path / "empty"
    empty.mkdir()
    with atomic_directory(empty) as tmp:
        (tmp / "a.txt").write_text("a")
    assert sorted(os.listdir(empty)) == [MARKER, "a.txt"]
    link = tmp_path / "link"                         # a link to a previous output: followed
    link.symlink_to(empty)
    assert check_destination(link) == empty


def _one_paragraph_exit_3(capsys, rc, out):
    err = capsys.readouterr().err
    assert rc == 3, err
    text = err.strip()
    assert "Traceback" not in text and "\n\n" not in text and text.startswith("drake-dock: ")
    assert not out.exists() and _siblings(out) == []
    return " ".join(text.split())


def test_unexpected_exception_is_one_paragraph_exit_3(tmp_path, capsys, monkeypatch):
    def bug(*args, **kwargs):
        raise TypeError("unsupported operand\n\nsecond paragraph")
    monkeypatch.setattr("drake_dock.run.simulate", bug)
    out = tmp_path / "results"
    msg = _one_paragraph_exit_3(capsys, main(["run", "--out", str(out), "--no-progress"]), out)
    assert "internal error (TypeError)" in msg and "second paragraph" in msg


def test_numerical_failure_names_time_and_couples(tmp_path, capsys):
    """A real one: an accuracy no step can meet (Drake's minimum step is violated)."""
    scenario = tmp_path / "s.yaml"
    scenario.write_text("contact: {pairs: paper}\nsimulator_config: {accuracy: 1.0e-300}\n")
    out = tmp_path / "results"
    rc = main(["run", str(scenario), "--out", str(out), "--no-progress"])
    msg = _one_paragraph_exit_3(capsys, rc, out)
    assert "numerical failure" in msg and "t = " in msg and "couples cc_" in msg


def test_contact_system_refusal_at_t0_is_exit_2(tmp_path, capsys, monkeypatch):
    """The contact system refuses bodies that start interpenetrating (InputError naming the
    pair) while the simulator initializes: it stays a bad input, not a numerical failure."""
    def refuse(self, root):
        raise InputError("initial state of pair cc_T1_C5", "signed gap -0.001 m",
                         "signed gap >= -impact_gap_tol = -1e-08 m",
                         "the bodies start interpenetrating")
    monkeypatch.setattr("drake_dock.docking.model.simulate._Recorder.sample", refuse)
    out = tmp_path / "results"
    rc = main(["run", "--out", str(out), "--no-progress"])
    err = " ".join(capsys.readouterr().err.split())
    assert rc == 2 and "cc_T1_C5" in err and "interpenetrating" in err
    assert not out.exists()


def test_numerical_error_from_the_run_maps_to_exit_3(tmp_path, capsys, monkeypatch):
    def fail(*args, **kwargs):
        raise NumericalError("LZB impact did not end", time=0.0123, couples=["cc_T1_C5"])
    monkeypatch.setattr("drake_dock.run.simulate", fail)
    out = tmp_path / "results"
    msg = _one_paragraph_exit_3(capsys, main(["run", "--out", str(out), "--no-progress"]), out)
    assert "t = 0.0123 s" in msg and "cc_T1_C5" in msg


def test_drake_log_holds_what_drake_logged_that_matters(tmp_path, capsys, monkeypatch):
    """A warning Drake logs during a run goes into drake.log, off the terminal; the replay's
    Meshcat start-up line does not."""
    import logging

    import drake_dock.run as run_module
    real = run_module.timeseries

    def warned(result):
        logging.getLogger("drake").warning("a warning from Drake")
        return real(result)
    monkeypatch.setattr(run_module, "timeseries", warned)
    out = tmp_path / "results"
    assert main(["run", "--out", str(out), "--duration", "0.005", "--no-progress"]) == 0
    captured = capsys.readouterr()
    assert "a warning from Drake" not in captured.out + captured.err
    assert (out / "drake.log").read_text() == "WARNING: a warning from Drake\n"
