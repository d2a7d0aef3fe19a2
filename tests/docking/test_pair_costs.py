"""What each pair type cost in a run (`cost_by_pair_type` in cost.json): the types partition
the declared pairs as the functions that declare them do, all seeking time is attributed to a
pair, and a pair's tracked evaluations agree with the statuses recorded at the samples."""
import collections

import numpy as np
import pytest

from drake_dock.docking.pairs import (CHASER_APDS, R_MATCHED, TARGET_APDS, apds_pairs,
                                      corner_pairs, cost_by_pair_type, edge_pairs, pair_type,
                                      side_edge_pairs, tip_surface_pairs)
from drake_dock.docking.apds import apds_patches
from drake_dock.docking.results import run_cost, timeseries
from drake_dock.docking.scenario import load_scenario
from drake_dock.docking.simulate import simulate


def test_pair_types_partition_the_complete_set(geom):
    P = apds_patches(geom)
    C, T = ("C", CHASER_APDS), ("T", TARGET_APDS)
    expect = collections.Counter()
    for p in edge_pairs(P, C, T) + edge_pairs(P, T, C):      # 6 sides, 3 tips, 1 face each
        expect[p.kind + ("face" if "rim" in p.name else "tip" if "tip" in p.name else "side")] += 1
    got = collections.Counter(pair_type(p.name) for p in apds_pairs(geom, "complete"))
    assert got["ring inside circle / guide side"] == expect["CCside"] == 12
    assert got["ring inside circle / tip arc"] == expect["CCtip"] == 6
    assert got["ring outside circle / ring face"] == expect["CSface"] == 2
    assert got["petal corner / ring inside circle"] == len(corner_pairs(P, C, T)) * 2
    assert got["tip arc / guide surface"] == (len(tip_surface_pairs(P, C, T, R_MATCHED))
                                              + len(tip_surface_pairs(P, T, C, R_MATCHED.T)))
    sides = side_edge_pairs(P, R_MATCHED)
    assert got["guide side / guide side"] == 6 + sum("tip" not in p.name for p in sides)
    assert got["guide side / tip arc"] == sum("tip" in p.name for p in sides)
    assert got["petal corner / tip land"] == 12
    assert sum(got.values()) == len(apds_pairs(geom, "complete"))
    assert all(pair_type(p.name) != p.name for p in apds_pairs(geom, "complete"))


@pytest.fixture(scope="module")
def complete_run():
    r = simulate(load_scenario(data="contact: {pairs: complete}"))
    ts = timeseries(r)
    return r, ts, run_cost(r, ts)


def test_seeking_time_is_all_attributed_to_pairs(complete_run):
    r, _, s = complete_run
    sh = s["time_shares"]
    seeking = sh["shares"]["seeking"] * sh["wall_time"]
    assert sum(sh["seek_time_per_pair"].values()) == pytest.approx(seeking, rel=1e-9)
    cost = s["cost_by_pair_type"]
    assert sum(c["seek_time_s"] for c in cost.values()) == pytest.approx(seeking, rel=1e-9)
    assert sum(c["seeks"] for c in cost.values()) == sum(sh["seeks_per_pair"].values())


def test_tracked_evaluations_agree_with_the_recorded_statuses(complete_run):
    """A pair recorded tracked or in contact at some sample was tracked in evaluations; a pair
    far at every sample and every event in between was never tracked (statuses: 0 far)."""
    r, ts, s = complete_run
    counts = s["time_shares"]["tracked_evaluations_per_pair"]
    ever = (ts["status"] > 0).any(axis=0)
    names = ts["couple_names"].tolist()
    assert ever.any() and not ever.all()
    for j, name in enumerate(names):
        assert counts[name] <= r.evaluations
        if ever[j]:
            assert counts[name] > 0, name
    assert np.count_nonzero([counts[n] for n in names]) >= np.count_nonzero(ever)
