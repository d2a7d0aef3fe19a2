"""Smoke tests of the command line, as a user runs it."""
import json
import os
import subprocess
import sys
from pathlib import Path

EXE = [sys.executable, "-m", "drake_dock.cli"]


def _run(args, **kw):
    return subprocess.run(EXE + args, capture_output=True, text=True, timeout=600, **kw)


def test_run_writes_outputs(tmp_path):
    out = tmp_path / "paper"
    r = _run(["run", "--out", str(out)])
    assert r.returncode == 0, r.stderr
    summary = json.loads((out / "summary.json").read_text())
    assert summary["initial_ring_distance_m"] > summary["first_contact_ring_distance_m"]
    html = (out / "replay.html").read_text()
    assert "<html" in html.lower() and len(html) > 100_000
    assert (out / "initial_configuration.png").stat().st_size > 10_000
    assert not [p for p in tmp_path.iterdir() if p.name.startswith(".")]  # no temp left


def test_bad_input_exits_2_and_leaves_previous_output(tmp_path):
    bad = tmp_path / "bad.yaml"
    bad.write_text("bodies: {chaser: {mass: -1.0}}\n")
    out = tmp_path / "out"
    out.mkdir()
    (out / "keep.txt").write_text("previous")
    r = _run(["run", str(bad), "--out", str(out)])
    assert r.returncode == 2
    assert "bodies.chaser.mass" in r.stderr
    assert (out / "keep.txt").read_text() == "previous"
    assert sorted(os.listdir(out)) == ["keep.txt"]
    r = _run(["run", str(tmp_path / "nope.yaml"), "--out", str(tmp_path / "new")])
    assert r.returncode == 2 and not (tmp_path / "new").exists()
    assert "nope.yaml" in r.stderr
