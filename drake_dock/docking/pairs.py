"""The contact pairs of the docking scene (`contact.pairs`): the 12 pairs of Sect. 2.2 and 8.1
(`paper`) and the edges, faces and corners the motion reaches off the axis (`complete`), with
the facing of the two APDSes they are declared at and the hand-overs among them."""
from __future__ import annotations

import dataclasses
import math
import re

import numpy as np

from drake_dock.core.handover import SurfaceEdge
from drake_dock.core.patches import Patch
from drake_dock.docking.apds import (PAIR_SETS, ApdsGeometry, apds_patches, azimuth_span,
                                      petal_edges, side_phi, spans_within)
from drake_dock.docking.rotations import rot_x, rot_z
from drake_dock.errors import InputError

TARGET_APDS = "target_apds"
CHASER_APDS = "chaser_apds"

# Sect. 2.2: guide side n_i of the target faces n_j of the chaser.
CC_SIDE_PAIRS = ((1, 5), (2, 4), (3, 3), (4, 2), (5, 1), (6, 6))


@dataclasses.dataclass(frozen=True)
class PairSpec:
    """A potential contact pair. Body 1 carries the curve (Sect. 4.3), or the point of a
    point-curve or point-surface pair; the normal of its couple points from Body 2 to Body 1
    (Definition 2)."""

    name: str
    kind: str            # "CC", "CS", or "PC" / "PS" (a point on Body 1)
    body1: str
    patch1: Patch
    body2: str
    patch2: Patch
    # The orientation of the couple's normal where the scene knows it (`ContactPair.sigma`):
    # +1 for a ring's outside circle against the other ring's face, which is solid on one side
    # only. None: taken from the side the patches are on when the pair becomes potential.
    sigma: float | None = None
    description: str = ""   # in plain words (`describe_pair`), set by `apds_pairs`


APDS_WORDS = {TARGET_APDS: "target", CHASER_APDS: "chaser"}


def feature_words(P, patch) -> str:
    """The feature of the APDS patches ``P`` (`apds.apds_patches`) that ``patch`` is, in plain
    words: "ring inside circle", "petal 3 tip arc", "guide side 5 (petal 3)", ... Petal k
    carries guide surface k, guide sides 2k - 1 and 2k and tip arc k; corner i is where guide
    side i meets its tip arc."""
    named = {id(P.ring): "ring inside circle", id(P.rim): "ring outside circle",
             id(P.face): "ring face"}
    for i, side in P.sides.items():
        named[id(side)] = f"guide side {i} (petal {(i + 1) // 2})"
    for k in P.surfaces:
        named[id(P.surfaces[k])] = f"petal {k} guide surface"
        named[id(P.tips[k])] = f"petal {k} tip arc"
    for k, land in P.lands.items():
        named[id(land)] = f"petal {k} tip land"
    for corners in (P.corners, P.corner_points):
        for i, c in corners.items():
            named[id(c)] = f"petal {(i + 1) // 2} corner at guide side {i}"
    return named[id(patch)]


def describe_pair(P, pair: PairSpec) -> str:
    """A pair in plain words from its bodies and patches: "chaser ring inside circle / target
    petal 3 tip arc" (body 1's feature first)."""
    return (f"{APDS_WORDS[pair.body1]} {feature_words(P, pair.patch1)} / "
            f"{APDS_WORDS[pair.body2]} {feature_words(P, pair.patch2)}")


def apds_pairs(g: ApdsGeometry, which: str = "paper") -> list[PairSpec]:
    """The contact pairs of the set ``which`` (`PAIR_SETS`). ``paper``: the 12 pairs of Sect.
    2.2 and 8.1, six guide side vs guide side (C-C, Body 1 = the chaser's side, as in Sect. 3.2),
    three chaser-ring vs target-surface and three target-ring vs chaser-surface (C-S, Body 1 =
    the ring). ``complete`` adds, for each APDS against the other (`edge_pairs`): the ring's
    inside circle vs each guide side and each tip arc (C-C), the ring's outside circle vs
    the other ring's face (C-S), the tip arcs vs the guide surfaces they can face (C-S,
    `tip_surface_pairs`), the other APDS's petal corners vs the ring's inside circle
    (point-curve, `corner_pairs`), the guide sides vs the non-partner sides and tip arcs
    they reach (C-C, `side_edge_pairs`), the tip arcs vs the other APDS's tip arcs they reach
    (C-C, `tip_tip_pairs`), the petal corners vs the other APDS's guide surfaces
    they reach (point-surface, `corner_surface_pairs`), the petal corners vs the other APDS's
    tip lands (`corner_land_pairs`), and, where the petals stand on the ring's inside circle
    (petal_root_radius <= Rs), the ring's outside circle vs the other APDS's guide sides and
    surfaces (`rim_petal_pairs`). A rim meets the other ring only on its face (the ring solid's
    outer edge is chamfered: docs/model.md, "APDS geometry"). Each pair carries its
    ``description`` in plain words (`describe_pair`)."""
    if which not in PAIR_SETS:
        raise InputError("contact.pairs", which, f"one of {', '.join(PAIR_SETS)}")
    P = apds_patches(g)
    pairs = [PairSpec(f"cc_T{i}_C{j}", "CC", CHASER_APDS, P.sides[j], TARGET_APDS, P.sides[i])
             for i, j in CC_SIDE_PAIRS]
    pairs += [PairSpec(f"cs_Cring_T{k}", "CS", CHASER_APDS, P.ring, TARGET_APDS, P.surfaces[k])
              for k in (1, 2, 3)]
    pairs += [PairSpec(f"cs_Tring_C{k}", "CS", TARGET_APDS, P.ring, CHASER_APDS, P.surfaces[k])
              for k in (1, 2, 3)]
    if which == "complete":
        pairs += edge_pairs(P, ("C", CHASER_APDS), ("T", TARGET_APDS))
        pairs += edge_pairs(P, ("T", TARGET_APDS), ("C", CHASER_APDS))
        pairs += tip_surface_pairs(P, ("C", CHASER_APDS), ("T", TARGET_APDS), R_MATCHED)
        pairs += tip_surface_pairs(P, ("T", TARGET_APDS), ("C", CHASER_APDS), R_MATCHED.T)
        pairs += corner_pairs(P, ("C", CHASER_APDS), ("T", TARGET_APDS))
        pairs += corner_pairs(P, ("T", TARGET_APDS), ("C", CHASER_APDS))
        pairs += side_edge_pairs(P, R_MATCHED)
        pairs += tip_tip_pairs(P, R_MATCHED)
        pairs += corner_surface_pairs(P, ("C", CHASER_APDS), ("T", TARGET_APDS), R_MATCHED)
        pairs += corner_surface_pairs(P, ("T", TARGET_APDS), ("C", CHASER_APDS), R_MATCHED.T)
        pairs += corner_land_pairs(P, ("C", CHASER_APDS), ("T", TARGET_APDS), R_MATCHED)
        pairs += corner_land_pairs(P, ("T", TARGET_APDS), ("C", CHASER_APDS), R_MATCHED.T)
        if g.Rp <= g.Rs:
            pairs += rim_petal_pairs(P, ("C", CHASER_APDS), ("T", TARGET_APDS))
            pairs += rim_petal_pairs(P, ("T", TARGET_APDS), ("C", CHASER_APDS))
    return [dataclasses.replace(p, description=describe_pair(P, p)) for p in pairs]


def scenario_pairs(scenario) -> list[PairSpec]:
    """The pairs of the scenario's contact set (`contact.pairs`)."""
    return apds_pairs(scenario.geometry, scenario.contact.pairs)


def edge_pairs(P, one, other) -> list[PairSpec]:
    """The pairs of APDS ``one``'s ring (Body 1) against APDS ``other``'s petal edges and face;
    ``one`` and ``other`` are (letter, body). Names: cc_<X>ring_<Y><i> (inside circle vs guide
    side i), cc_<X>ring_<Y>tip<k> (vs tip arc k), cs_<X>rim_<Y>face (outside circle vs face)."""
    (x, b1), (y, b2) = one, other
    out = [PairSpec(f"cc_{x}ring_{y}{i}", "CC", b1, P.ring, b2, P.sides[i]) for i in range(1, 7)]
    out += [PairSpec(f"cc_{x}ring_{y}tip{k}", "CC", b1, P.ring, b2, P.tips[k]) for k in (1, 2, 3)]
    out.append(PairSpec(f"cs_{x}rim_{y}face", "CS", b1, P.rim, b2, P.face, sigma=1.0))
    return out


def rim_petal_pairs(P, one, other) -> list[PairSpec]:
    """APDS ``one``'s ring outside circle (Body 1) against APDS ``other``'s guide sides
    (cc_<X>rim_<Y><i>, C-C) and guide surfaces (cs_<X>rim_<Y><k>, C-S): declared where the
    petals stand on the ring's inside circle (Rp <= Rs), so that the other ring's annulus is
    solid to them. A tilted, offset ring meets a petal near its root with its rim there (docs/
    model.md, "Facing and the contact pairs")."""
    (x, b1), (y, b2) = one, other
    out = [PairSpec(f"cc_{x}rim_{y}{i}", "CC", b1, P.rim, b2, P.sides[i]) for i in range(1, 7)]
    out += [PairSpec(f"cs_{x}rim_{y}{k}", "CS", b1, P.rim, b2, P.surfaces[k]) for k in (1, 2, 3)]
    return out


def corner_pairs(P, one, other) -> list[PairSpec]:
    """APDS ``other``'s six petal corners (Body 1, `petal_corner`) against APDS ``one``'s
    ring inside circle (Body 2), pc_<Y>corner<i>_<X>ring (point-curve, kind "PC"; X the ring's
    APDS, Y the corner's): corner i is where guide side i meets its tip arc."""
    (x, b_ring), (y, b_corner) = one, other
    return [PairSpec(f"pc_{y}corner{i}_{x}ring", "PC", b_corner, P.corners[i], b_ring, P.ring)
            for i in range(1, 7)]


def tip_tip_pairs(P, R) -> list[PairSpec]:
    """The chaser's tip arcs against the target's tip arcs they can reach, cc_Ctip<j>_Ttip<k>
    (C-C, Body 1 the chaser's arc): those whose `azimuth_span`s at the matched facing (R:
    chaser frame to target frame) come within `SIDE_REACH`, a petal tip over a petal tip at
    a large relative roll (docs/model.md)."""
    return [PairSpec(f"cc_Ctip{j}_Ttip{k}", "CC", CHASER_APDS, P.tips[j], TARGET_APDS,
                     P.tips[k]) for j in (1, 2, 3) for k in (1, 2, 3)
            if spans_within(azimuth_span(P.tips[j], R), azimuth_span(P.tips[k]))]


def corner_surface_pairs(P, one, other, R) -> list[PairSpec]:
    """APDS ``one``'s six petal corners (Body 1, the bare `corner_point`s) against the guide
    surfaces of APDS ``other`` they can reach, ps_<X>corner<i>_<Y><k> (point-surface, kind
    "PS"); R turns ``other``'s frame into ``one``'s at the matched facing. A guide side whose
    petal lies across a non-partner petal at a large relative roll crosses that petal's face,
    and the crossing starts at the side's corner (docs/model.md); corner i reaches surface k
    when its azimuth comes within `SIDE_REACH` of the surface's span at its root."""
    (x, b1), (y, b2) = one, other
    out = []
    for i in range(1, 7):
        c = P.corner_points[i].p
        for k in (1, 2, 3):
            if spans_within((math.atan2(c[1], c[0]), 0.0), _root_span(P.surfaces[k], R)):
                out.append(PairSpec(f"ps_{x}corner{i}_{y}{k}", "PS", b1, P.corner_points[i],
                                    b2, P.surfaces[k]))
    return out


# A corner comes over a tip arc of the other APDS at the relative roll equal to their gap about
# the axis (2 theta_end = 37.18 deg for the nearest tip); the next tip lies exactly 60 deg away,
# the end of the scenario's roll range (|roll| < 60 deg), which it does not reach.
LAND_REACH = math.radians(60.0 - 0.5)


def corner_land_pairs(P, one, other, R) -> list[PairSpec]:
    """APDS ``one``'s six bare petal corners (Body 1) against the tip lands of APDS ``other``
    (`apds.tip_land`) they come over within the scenario's roll range, ps_<X>corner<i>_<Y>tip<k>
    (point-surface); R turns ``other``'s frame into ``one``'s at the matched facing. Two tips
    meeting coaxially touch along an arc, a line contact with no isolated couple: it is carried
    by the two corners at the ends of the overlap, each on the other's tip land (docs/model.md,
    "Tip on tip")."""
    (x, b1), (y, b2) = one, other
    out = []
    for i in range(1, 7):
        c = P.corner_points[i].p
        for k in (1, 2, 3):
            if spans_within((math.atan2(c[1], c[0]), 0.0), azimuth_span(P.tips[k], R),
                            LAND_REACH):
                out.append(PairSpec(f"ps_{x}corner{i}_{y}tip{k}", "PS", b1, P.corner_points[i],
                                    b2, P.lands[k]))
    return out


def _root_span(surface, R):
    """(mid azimuth, half width) of a guide surface's root (zeta = 0) turned by R."""
    lo, hi = surface.lower.copy(), surface.upper.copy()
    hi[1] = lo[1]
    a, b = (math.atan2(p[1], p[0]) for p in (R @ surface.position(lo),
                                            R @ surface.position(hi)))
    half = 0.5 * ((b - a + math.pi) % (2 * math.pi) - math.pi)
    return a + half, abs(half)


def tip_surface_pairs(P, one, other, R) -> list[PairSpec]:
    """APDS ``one``'s tip arcs (Body 1) against the guide surfaces of APDS ``other`` they can
    face, cs_<X>tip<j>_<Y><k> (C-S); R turns ``other``'s frame into ``one``'s at the matched
    facing. Tip arc j faces surface k when their mid-directions are less than 90 deg apart
    about the axis at the matched facing: the two petals next to the gap it enters, reached at
    a relative roll near +-60 deg; the third petal is 180 deg away (docs/model.md)."""
    (x, b1), (y, b2) = one, other
    out = []
    for j in (1, 2, 3):
        a = side_phi(2 * j - 1) + math.pi / 6
        for k in (1, 2, 3):
            b = side_phi(2 * k - 1) + math.pi / 6
            w = R @ np.array([math.cos(b), math.sin(b), 0.0])
            if w[0] * math.cos(a) + w[1] * math.sin(a) > 0.0:
                out.append(PairSpec(f"cs_{x}tip{j}_{y}{k}", "CS", b1, P.tips[j], b2,
                                    P.surfaces[k]))
    return out


def side_edge_pairs(P, R) -> list[PairSpec]:
    """The guide sides against the other APDS's petal edges they can reach, other than their
    paper partners (C-C, Body 1 the side): chaser side j vs target side i, cc_T<i>_C<j>, and
    side j vs tip arc k, cc_<X><j>_<Y>tip<k>; those whose `azimuth_span`s at the matched
    facing (R: chaser frame to target frame) are `spans_within` reach (docs/model.md)."""
    turn = {"C": (CHASER_APDS, R), "T": (TARGET_APDS, np.eye(3))}
    span = {(x, c): azimuth_span(c, turn[x][1]) for x in turn for c in (*P.sides.values(),
                                                                         *P.tips.values())}
    out = [PairSpec(f"cc_T{i}_C{j}", "CC", CHASER_APDS, P.sides[j], TARGET_APDS, P.sides[i])
           for j in range(1, 7) for i in range(1, 7) if (i, j) not in CC_SIDE_PAIRS
           and spans_within(span["C", P.sides[j]], span["T", P.sides[i]])]
    for x, y in (("C", "T"), ("T", "C")):
        out += [PairSpec(f"cc_{x}{j}_{y}tip{k}", "CC", turn[x][0], P.sides[j], turn[y][0],
                         P.tips[k]) for j in range(1, 7) for k in (1, 2, 3)
                if spans_within(span[x, P.sides[j]], span[y, P.tips[k]])]
    return out


# The pair types of the names above, for the cost of each type in a run's time shares.
PAIR_TYPES = (
    (re.compile(r"cc_T\d_C\d$"), "guide side / guide side"),
    (re.compile(r"cs_[CT]ring_[CT]\d$"), "ring inside circle / guide surface"),
    (re.compile(r"cc_[CT]ring_[CT]\d$"), "ring inside circle / guide side"),
    (re.compile(r"cc_[CT]ring_[CT]tip\d$"), "ring inside circle / tip arc"),
    (re.compile(r"cs_[CT]rim_[CT]face$"), "ring outside circle / ring face"),
    (re.compile(r"cs_[CT]tip\d_[CT]\d$"), "tip arc / guide surface"),
    (re.compile(r"pc_[CT]corner\d_[CT]ring$"), "petal corner / ring inside circle"),
    (re.compile(r"cc_[CT]\d_[CT]tip\d$"), "guide side / tip arc"),
    (re.compile(r"cc_[CT]rim_[CT]rim$"), "ring outside circle / ring outside circle"),
    (re.compile(r"ps_[CT]corner\d_[CT]\d$"), "petal corner / guide surface"),
    (re.compile(r"cc_Ctip\d_Ttip\d$"), "tip arc / tip arc"),
    (re.compile(r"ps_[CT]corner\d_[CT]tip\d$"), "petal corner / tip land"),
    (re.compile(r"cc_[CT]rim_[CT]\d$"), "ring outside circle / guide side"),
    (re.compile(r"cs_[CT]rim_[CT]\d$"), "ring outside circle / guide surface"))


def pair_type(name: str) -> str:
    """The type of the pair named ``name`` (`PAIR_TYPES`), or the name itself."""
    return next((t for rx, t in PAIR_TYPES if rx.match(name)), name)


def cost_by_pair_type(time_shares: dict) -> dict:
    """{pair type: pairs declared, seeks, screenings, wall time of both (s), evaluations with
    a pair tracked} from a run's time shares (`drake_dock.systems.profiling.Timing.shares`)."""
    out = {}
    for name, seeks in time_shares["seeks_per_pair"].items():
        row = out.setdefault(pair_type(name), {"pairs": 0, "seeks": 0, "screens": 0,
                                               "seek_time_s": 0.0, "tracked_evaluations": 0})
        row["pairs"] += 1
        row["seeks"] += seeks
        row["screens"] += time_shares["screens_per_pair"][name]
        row["seek_time_s"] += time_shares["seek_time_per_pair"][name]
        row["tracked_evaluations"] += time_shares["tracked_evaluations_per_pair"][name]
    return out


def pair_handovers(g: ApdsGeometry, pairs) -> list:
    """(edge pair, surface pair, `SurfaceEdge`) of each hand-over among ``pairs``
    (`drake_dock.core.handover`): a ring's inside circle passes between guide surface k
    (cs_<X>ring_<Y>k) and its sides 2k - 1, 2k (cc_<X>ring_<Y><i>) and its tip arc
    (cc_<X>ring_<Y>tip<k>), `petal_edges`; a chaser tip arc j between target surface k
    (cs_Ctip<j>_T<k>) and its tip arc (cc_Ctip<j>_Ttip<k>); a ring's outside circle between
    guide surface k (cs_<X>rim_<Y>k) and its sides (cc_<X>rim_<Y><i>)."""
    names = {p.name for p in pairs}
    out = []
    for j in (1, 2, 3):
        for k in (1, 2, 3):
            # A chaser tip arc over target tip arc k and target guide surface k.
            if {f"cc_Ctip{j}_Ttip{k}", f"cs_Ctip{j}_T{k}"} <= names:
                out.append((f"cc_Ctip{j}_Ttip{k}", f"cs_Ctip{j}_T{k}",
                            petal_edges(g, k)["tip"]))
    for x, y in (("C", "T"), ("T", "C")):
        for k in (1, 2, 3):
            for key, edge in petal_edges(g, k).items():
                e = f"cc_{x}ring_{y}{'tip' + str(k) if key == 'tip' else key}"
                if {e, f"cs_{x}ring_{y}{k}"} <= names:
                    out.append((e, f"cs_{x}ring_{y}{k}", edge))
                # A ring's outside circle between guide surface k and its sides.
                if key != "tip" and {f"cc_{x}rim_{y}{key}", f"cs_{x}rim_{y}{k}"} <= names:
                    out.append((f"cc_{x}rim_{y}{key}", f"cs_{x}rim_{y}{k}", edge))
    return out


# Matched facing (docs/model.md): the chaser's APDS frame is the target's turned by pi about a
# transverse axis and by 240 deg about the docking axis, so that the pairs of Sect. 2.2 face.
R_MATCHED = rot_z(math.radians(240.0)) @ rot_x(math.pi)
