"""Smoke tests of the command line, as a user runs it."""
import json
import os
import subprocess
import sys

import pytest
from pathlib import Path

from drake_dock.docking.output import MARKER, atomic_directory

EXE = [sys.executable, "-m", "drake_dock.cli"]


def _run(args, **kw):
    return subprocess.run(EXE + args, capture_output=True, text=True, timeout=600, **kw)


def test_short_run_writes_outputs(tmp_path):
    """A short run (before the first impact ends): every file is written, nothing else left."""
    out = tmp_path / "paper"
    r = _run(["run", "--out", str(out), "--duration", "0.005"])
    assert r.returncode == 0, r.stderr
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
