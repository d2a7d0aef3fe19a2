"""What each pair type cost in a run (`cost_by_pair_type` in cost.json): a pair's type is the
family its declaring function gives it, which names the features its patches are; the families
partition the declared pairs as the functions that declare them do; a name the scene does not
declare is refused; all seeking time is attributed to a pair, and a pair's tracked evaluations
agree with the statuses recorded at the samples."""
import collections
import re

import numpy as np
import pytest

from drake_dock.docking.geometry.apds import apds_patches
from drake_dock.docking.geometry.pairs import (CHASER_APDS, FAMILIES, R_MATCHED, TARGET_APDS,
                                               corner_pairs, edge_pairs, feature_words,
                                               ring_surface_pairs, side_edge_pairs,
                                               tip_surface_pairs)
from drake_dock.docking.geometry.scene import DockingScene
from drake_dock.docking.model.simulate import simulate
from drake_dock.docking.placement.place import place
from drake_dock.docking.report.cost import cost_by_pair_type, run_cost
from drake_dock.docking.report.results import timeseries
from drake_dock.docking.scenario.loading import load_scenario
from drake_dock.errors import InputError


def _feature(P, patch) -> str:
    """The kind of feature a patch is, from its plain words (`feature_words`, which knows the
    patches by identity): "petal 3 tip arc" -> "tip arc", "petal 2 corner at guide side 3" ->
    "petal corner", "guide side 5 (petal 3)" -> "guide side"."""
    words = feature_words(P, patch)
    if " corner at " in words:
        return "petal corner"
    return re.sub(r"\s*\(petal \d\)|petal \d |\s\d", "", words).strip()


@pytest.mark.parametrize("funnel", [False, True])
def test_a_pairs_family_names_the_features_of_its_patches(geom, funnel):
    """Each pair's family (set by its generator) is "Body 1's feature / Body 2's feature" as
    the patches themselves say (`feature_words`), and is one of `FAMILIES`; the funnel
    geometry (petals on the inside circle) adds the rim's pairs."""
    import dataclasses
    g = dataclasses.replace(geom, Rs=0.55, petal_root_radius=0.55, H=0.15,
                            petal_inset_deg=8.0) if funnel else geom
    scene = DockingScene(g, "complete")
    for p in scene.pairs:
        assert p.family in FAMILIES, p.name
        assert p.family == (f"{_feature(scene.patches, p.patch1)} / "
                            f"{_feature(scene.patches, p.patch2)}"), p.name
    assert {p.family for p in scene.pairs} == set(FAMILIES if funnel else FAMILIES[:-2])


def test_pair_types_partition_the_complete_set(geom):
    P = apds_patches(geom)
    C, T = ("C", CHASER_APDS), ("T", TARGET_APDS)
    expect = collections.Counter()
    for one, other in ((C, T), (T, C)):                     # 6 sides, 3 tips, 1 face each
        for p in edge_pairs(P, one, other, ring_surface_pairs(P, one, other)).pairs:
            expect[p.kind + ("face" if "rim" in p.name else "tip" if "tip" in p.name
                             else "side")] += 1
    got = collections.Counter(p.family for p in DockingScene(geom, "complete").pairs)
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
    assert sum(got.values()) == len(DockingScene(geom, "complete").pairs)


def test_a_name_the_scene_does_not_declare_is_refused(geom):
    """The cost of a run's time shares reads each pair's family from the scene: a pair name
    the scene does not declare (a paper scene asked about a complete set's pair) is an
    `InputError` naming it, not a type of its own."""
    shares = {k: {"cc_Cring_T1": 1} for k in ("seeks_per_pair", "screens_per_pair",
                                              "seek_time_per_pair",
                                              "tracked_evaluations_per_pair")}
    with pytest.raises(InputError, match="cc_Cring_T1"):
        cost_by_pair_type(shares, DockingScene(geom, "paper"))
    cost = cost_by_pair_type(shares, DockingScene(geom, "complete"))
    assert cost == {"ring inside circle / guide side": {
        "pairs": 1, "seeks": 1, "screens": 1, "seek_time_s": 1, "tracked_evaluations": 1}}


@pytest.fixture(scope="module")
def complete_run():
    s = load_scenario(data="contact: {pairs: complete}")
    r = simulate(s, place(s))
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
