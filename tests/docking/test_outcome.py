"""How a run ends: the outcome rules on hand-made ring-distance histories, a timeout through
the command line, and a slow approach that runs to a named outcome with a progress bar that
follows the rings."""
import json
import re

import numpy as np
import pytest
import yaml

from drake_dock.cli import main
from drake_dock.docking.outcome import JAM_DISTANCE, OutcomeWatch, progress_fraction
from drake_dock.docking.scenario import PAPER_EXAMPLE


def feed(watch, ts, ds, contact):
    for t, d, c in zip(ts, ds, contact):
        end = watch.update(t, d, c)
        if end:
            return t, end[0]
    return None


def test_steady_approach_has_no_outcome():
    ts = np.linspace(0, 10, 1001)
    assert feed(OutcomeWatch(0.1, 2.0), ts, 0.1 - 0.009 * ts, [True] * len(ts)) is None


def test_stalled_rings_are_jammed_after_jam_time():
    ts = np.linspace(0, 10, 1001)
    ds = np.maximum(0.1 - 0.05 * ts, 0.02)          # reach 0.02 m at t = 1.6 s, then stall
    t, outcome = feed(OutcomeWatch(0.1, 2.0), ts, ds, [True] * len(ts))
    # The last millimetre of progress ends at the stall (t = 1.6 s) or one mm before it.
    assert outcome == "jammed" and 1.6 - JAM_DISTANCE / 0.05 + 2.0 - 0.011 <= t <= 3.611


def test_separating_rings_rebound_only_without_contact():
    ts = np.linspace(0, 2, 201)
    ds = 0.1 - 0.1 * ts + 0.1 * ts ** 2               # back above 0.1 m after t = 1 s
    assert feed(OutcomeWatch(0.1, 5.0), ts, ds, [True] * len(ts)) is None
    t, outcome = feed(OutcomeWatch(0.1, 5.0), ts, ds, [False] * len(ts))
    assert outcome == "rebound" and 1.0 < t <= 1.02


def test_progress_is_the_further_of_way_and_time():
    assert progress_fraction(1.0, 10.0, 0.05, 0.1, 0.0) == pytest.approx(0.5)
    assert progress_fraction(8.0, 10.0, 0.05, 0.1, 0.0) == pytest.approx(0.8)


def test_timeout_is_a_named_outcome(tmp_path, capsys):
    assert main(["run", str(PAPER_EXAMPLE), "--out", str(tmp_path / "o"), "--duration", "0.02"
                 ]) == 0
    s = json.loads((tmp_path / "o" / "summary.json").read_text())
    assert s["outcome"] == "timeout" and not s["captured"] and s["end_time_s"] == 0.02
    # The bar, then the writing of the outputs, then Drake's log lines: none between.
    lines = capsys.readouterr().err.splitlines()
    bar = [k for k, line in enumerate(lines) if line.startswith("[")]
    writing = [k for k, line in enumerate(lines) if "writing the outputs" in line]
    assert bar and writing == [bar[-1] + 1]
    assert not any(":drake:" in line for line in lines[:writing[0]])


def test_slow_approach_ends_named_with_a_progress_bar_on_the_rings(tmp_path, capsys):
    data = yaml.safe_load(PAPER_EXAMPLE.read_text())
    data["initial"]["chaser_speed"] = 0.05
    f = tmp_path / "slow.yaml"
    f.write_text(yaml.safe_dump(data))
    assert main(["run", str(f), "--out", str(tmp_path / "o")]) == 0
    err = capsys.readouterr().err
    s = json.loads((tmp_path / "o" / "summary.json").read_text())
    assert s["outcome"] in ("captured", "jammed")
    assert s["end_time_s"] < data["simulation"]["duration"]
    assert s["momentum_drift_relative"]["linear"] < 1e-9
    # The bar follows the rings: its last reading is their way towards capture.
    shown = [int(p) for p in re.findall(r"\]\s+(\d+)%", err)]
    assert shown == sorted(shown)
    ts = np.load(tmp_path / "o" / "timeseries.npz")
    d = ts["ring_distance"]
    way = (d[0] - d[-1]) / (d[0] - s["capture_distance_m"])
    assert shown[-1] == pytest.approx(100 * way, abs=10.5)
