"""The contact pairs of the docking scene (`contact.pairs`): the 12 pairs of Sect. 2.2 and 8.1
(`paper`) and the edges, faces and corners the motion reaches off the axis (`complete`), with
the facing of the two APDSes they are declared at. Each pair carries its family, set by the
function that declares it; the hand-overs among the pairs are declared with them."""
from __future__ import annotations

import dataclasses
import math

import numpy as np

from drake_dock.core.handover import SurfaceEdge
from drake_dock.core.patches import Patch
from drake_dock.docking.geometry.apds import (apds_patches, azimuth_span, side_phi,
                                              spans_within)
from drake_dock.docking.geometry.rotations import rot_x, rot_z
from drake_dock.docking.scenario.dimensions import PAIR_SETS, ApdsGeometry
from drake_dock.errors import InputError

TARGET_APDS = "target_apds"
CHASER_APDS = "chaser_apds"

# Sect. 2.2: guide side n_i of the target faces n_j of the chaser.
CC_SIDE_PAIRS = ((1, 5), (2, 4), (3, 3), (4, 2), (5, 1), (6, 6))

# The pair families, in plain words (Body 1's feature / Body 2's), each set by the functions
# below that declare its pairs.
SIDE_SIDE = "guide side / guide side"
RING_SURFACE = "ring inside circle / guide surface"
RING_SIDE = "ring inside circle / guide side"
RING_TIP = "ring inside circle / tip arc"
RIM_FACE = "ring outside circle / ring face"
TIP_SURFACE = "tip arc / guide surface"
CORNER_RING = "petal corner / ring inside circle"
SIDE_TIP = "guide side / tip arc"
TIP_TIP = "tip arc / tip arc"
CORNER_SURFACE = "petal corner / guide surface"
CORNER_LAND = "petal corner / tip land"
RIM_SIDE = "ring outside circle / guide side"
RIM_SURFACE = "ring outside circle / guide surface"
FAMILIES = (SIDE_SIDE, RING_SURFACE, RING_SIDE, RING_TIP, RIM_FACE, TIP_SURFACE, CORNER_RING,
            SIDE_TIP, TIP_TIP, CORNER_SURFACE, CORNER_LAND, RIM_SIDE, RIM_SURFACE)


@dataclasses.dataclass(frozen=True)
class PairSpec:
    """A potential contact pair of the family ``family`` (`FAMILIES`). Body 1 carries the curve
    (Sect. 4.3), or the point of a point-curve or point-surface pair; the normal of its couple
    points from Body 2 to Body 1 (Definition 2)."""

    name: str
    family: str
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


@dataclasses.dataclass(frozen=True)
class PairHandover:
    """A hand-over (`drake_dock.core.handover`): ``edge_pair`` (C-C) and ``surface_pair`` (C-S)
    share their curve on Body 1, and the edge pair's curve on Body 2 is the boundary ``edge``
    of the surface pair's surface."""

    edge_pair: PairSpec
    surface_pair: PairSpec
    edge: SurfaceEdge


@dataclasses.dataclass
class PairSet:
    """Pairs and the hand-overs among them, as declared together."""

    pairs: list = dataclasses.field(default_factory=list)
    handovers: list = dataclasses.field(default_factory=list)

    def __add__(self, other: "PairSet") -> "PairSet":
        return PairSet(self.pairs + other.pairs, self.handovers + other.handovers)


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


def apds_pairs(g: ApdsGeometry, which: str = "paper", P=None) -> PairSet:
    """The contact pairs of the set ``which`` (`PAIR_SETS`) and their hand-overs, on the
    patches ``P`` of ``g`` (`apds_patches`, made here where None). ``paper``: the 12 pairs of
    Sect. 2.2 and 8.1, six guide side vs guide side (C-C, Body 1 = the chaser's side, as in
    Sect. 3.2), three chaser-ring vs target-surface and three target-ring vs chaser-surface
    (C-S, Body 1 = the ring). ``complete`` adds, for each APDS against the other (`edge_pairs`):
    the ring's inside circle vs each guide side and each tip arc (C-C), the ring's outside
    circle vs the other ring's face (C-S), the tip arcs vs the guide surfaces they can face
    (C-S, `tip_surface_pairs`), the other APDS's petal corners vs the ring's inside circle
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
    P = apds_patches(g) if P is None else P
    C, T = ("C", CHASER_APDS), ("T", TARGET_APDS)
    out = PairSet([PairSpec(f"cc_T{i}_C{j}", SIDE_SIDE, "CC", CHASER_APDS, P.sides[j],
                            TARGET_APDS, P.sides[i]) for i, j in CC_SIDE_PAIRS])
    ring_surfaces = {C: ring_surface_pairs(P, C, T), T: ring_surface_pairs(P, T, C)}
    out.pairs += [*ring_surfaces[C].values(), *ring_surfaces[T].values()]
    if which == "complete":
        out += edge_pairs(P, C, T, ring_surfaces[C]) + edge_pairs(P, T, C, ring_surfaces[T])
        tips = tip_surface_pairs(P, C, T, R_MATCHED)
        out.pairs += [*tips, *tip_surface_pairs(P, T, C, R_MATCHED.T)]
        out.pairs += corner_pairs(P, C, T) + corner_pairs(P, T, C)
        out.pairs += side_edge_pairs(P, R_MATCHED)
        tip_tips = tip_tip_pairs(P, R_MATCHED)
        out += PairSet(tip_tips, tip_handovers(P, tip_tips, tips))
        out.pairs += (corner_surface_pairs(P, C, T, R_MATCHED)
                      + corner_surface_pairs(P, T, C, R_MATCHED.T))
        out.pairs += corner_land_pairs(P, C, T, R_MATCHED) + corner_land_pairs(P, T, C,
                                                                              R_MATCHED.T)
        if g.Rp <= g.Rs:
            out += rim_petal_pairs(P, C, T) + rim_petal_pairs(P, T, C)
    described = {id(p): dataclasses.replace(p, description=describe_pair(P, p))
                 for p in out.pairs}
    return PairSet([described[id(p)] for p in out.pairs],
                   [PairHandover(described[id(h.edge_pair)], described[id(h.surface_pair)],
                                 h.edge) for h in out.handovers])


def ring_surface_pairs(P, one, other) -> dict:
    """{k: pair} of APDS ``one``'s ring inside circle (Body 1) against APDS ``other``'s guide
    surface k, cs_<X>ring_<Y><k> (C-S; the paper's cs_Cring_T<k> and cs_Tring_C<k>)."""
    (x, b1), (y, b2) = one, other
    return {k: PairSpec(f"cs_{x}ring_{y}{k}", RING_SURFACE, "CS", b1, P.ring, b2,
                        P.surfaces[k]) for k in (1, 2, 3)}


def edge_pairs(P, one, other, surfaces: dict) -> PairSet:
    """The pairs of APDS ``one``'s ring (Body 1) against APDS ``other``'s petal edges and face;
    ``one`` and ``other`` are (letter, body). Names: cc_<X>ring_<Y><i> (inside circle vs guide
    side i), cc_<X>ring_<Y>tip<k> (vs tip arc k), cs_<X>rim_<Y>face (outside circle vs face).
    The ring's inside circle passes between guide surface k (``surfaces[k]``, its pair with the
    ring: `ring_surface_pairs`) and its edges, sides 2k - 1 and 2k and tip arc k
    (`apds.petal_edges`): a hand-over each."""
    (x, b1), (y, b2) = one, other
    sides = {i: PairSpec(f"cc_{x}ring_{y}{i}", RING_SIDE, "CC", b1, P.ring, b2, P.sides[i])
             for i in range(1, 7)}
    tips = {k: PairSpec(f"cc_{x}ring_{y}tip{k}", RING_TIP, "CC", b1, P.ring, b2, P.tips[k])
            for k in (1, 2, 3)}
    face = PairSpec(f"cs_{x}rim_{y}face", RIM_FACE, "CS", b1, P.rim, b2, P.face, sigma=1.0)
    handovers = [PairHandover(tips[k] if key == "tip" else sides[key], surfaces[k], edge)
                 for k in (1, 2, 3) for key, edge in P.edges[k].items()]
    return PairSet([*sides.values(), *tips.values(), face], handovers)


def rim_petal_pairs(P, one, other) -> PairSet:
    """APDS ``one``'s ring outside circle (Body 1) against APDS ``other``'s guide sides
    (cc_<X>rim_<Y><i>, C-C) and guide surfaces (cs_<X>rim_<Y><k>, C-S): declared where the
    petals stand on the ring's inside circle (Rp <= Rs), so that the other ring's annulus is
    solid to them. A tilted, offset ring meets a petal near its root with its rim there (docs/
    model.md, "Facing and the contact pairs"). The rim passes between guide surface k and its
    sides: a hand-over each."""
    (x, b1), (y, b2) = one, other
    sides = {i: PairSpec(f"cc_{x}rim_{y}{i}", RIM_SIDE, "CC", b1, P.rim, b2, P.sides[i])
             for i in range(1, 7)}
    surfaces = {k: PairSpec(f"cs_{x}rim_{y}{k}", RIM_SURFACE, "CS", b1, P.rim, b2,
                            P.surfaces[k]) for k in (1, 2, 3)}
    handovers = [PairHandover(sides[key], surfaces[k], edge) for k in (1, 2, 3)
                 for key, edge in P.edges[k].items() if key != "tip"]
    return PairSet([*sides.values(), *surfaces.values()], handovers)


def corner_pairs(P, one, other) -> list[PairSpec]:
    """APDS ``other``'s six petal corners (Body 1, `petal_corner`) against APDS ``one``'s
    ring inside circle (Body 2), pc_<Y>corner<i>_<X>ring (point-curve, kind "PC"; X the ring's
    APDS, Y the corner's): corner i is where guide side i meets its tip arc."""
    (x, b_ring), (y, b_corner) = one, other
    return [PairSpec(f"pc_{y}corner{i}_{x}ring", CORNER_RING, "PC", b_corner, P.corners[i],
                     b_ring, P.ring) for i in range(1, 7)]


def tip_tip_pairs(P, R, reach=None) -> list[PairSpec]:
    """The chaser's tip arcs against the target's tip arcs they can reach, cc_Ctip<j>_Ttip<k>
    (C-C, Body 1 the chaser's arc): those whose `azimuth_span`s at the matched facing (R:
    chaser frame to target frame) come within ``reach`` (`SIDE_REACH` where None), a petal tip
    over a petal tip at a large relative roll (docs/model.md). An infinite ``reach`` gives
    every candidate (`reach.reach_sweep`)."""
    within = (() if reach is None else (reach,))
    return [PairSpec(f"cc_Ctip{j}_Ttip{k}", TIP_TIP, "CC", CHASER_APDS, P.tips[j], TARGET_APDS,
                     P.tips[k]) for j in (1, 2, 3) for k in (1, 2, 3)
            if spans_within(azimuth_span(P.tips[j], R), azimuth_span(P.tips[k]), *within)]


def tip_handovers(P, tip_tips, tip_surfaces) -> list[PairHandover]:
    """A chaser tip arc j passes between target tip arc k and target guide surface k: for each
    tip-tip pair (`tip_tip_pairs`), a hand-over with the pair of the same tip arc and surface
    k among ``tip_surfaces`` (`tip_surface_pairs` of the chaser's tips), which the facing
    rules declare for every tip-tip pair: `InputError` where one is missing."""
    surfaces = {(id(p.patch1), id(p.patch2)): p for p in tip_surfaces}
    out = []
    for pair in tip_tips:
        k = next(k for k, tip in P.tips.items() if tip is pair.patch2)
        surface = surfaces.get((id(pair.patch1), id(P.surfaces[k])))
        if surface is None:
            raise InputError("geometry", pair.name, "a geometry whose tip arcs face the guide "
                             "surfaces next to the tips they reach", f"no {TIP_SURFACE} pair "
                             f"of the chaser's tip arc on target surface {k} to hand over to")
        out.append(PairHandover(pair, surface, P.edges[k]["tip"]))
    return out


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
                out.append(PairSpec(f"ps_{x}corner{i}_{y}{k}", CORNER_SURFACE, "PS", b1,
                                    P.corner_points[i], b2, P.surfaces[k]))
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
                out.append(PairSpec(f"ps_{x}corner{i}_{y}tip{k}", CORNER_LAND, "PS", b1,
                                    P.corner_points[i], b2, P.lands[k]))
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
                out.append(PairSpec(f"cs_{x}tip{j}_{y}{k}", TIP_SURFACE, "CS", b1, P.tips[j],
                                    b2, P.surfaces[k]))
    return out


def side_edge_pairs(P, R, reach=None) -> list[PairSpec]:
    """The guide sides against the other APDS's petal edges they can reach, other than their
    paper partners (C-C, Body 1 the side): chaser side j vs target side i, cc_T<i>_C<j>, and
    side j vs tip arc k, cc_<X><j>_<Y>tip<k>; those whose `azimuth_span`s at the matched
    facing (R: chaser frame to target frame) are `spans_within` ``reach`` (`SIDE_REACH` where
    None; docs/model.md). An infinite ``reach`` gives every candidate (`reach.reach_sweep`)."""
    within = (() if reach is None else (reach,))
    turn = {"C": (CHASER_APDS, R), "T": (TARGET_APDS, np.eye(3))}
    span = {(x, c): azimuth_span(c, turn[x][1]) for x in turn for c in (*P.sides.values(),
                                                                         *P.tips.values())}
    out = [PairSpec(f"cc_T{i}_C{j}", SIDE_SIDE, "CC", CHASER_APDS, P.sides[j], TARGET_APDS,
                    P.sides[i])
           for j in range(1, 7) for i in range(1, 7) if (i, j) not in CC_SIDE_PAIRS
           and spans_within(span["C", P.sides[j]], span["T", P.sides[i]], *within)]
    for x, y in (("C", "T"), ("T", "C")):
        out += [PairSpec(f"cc_{x}{j}_{y}tip{k}", SIDE_TIP, "CC", turn[x][0], P.sides[j],
                         turn[y][0], P.tips[k]) for j in range(1, 7) for k in (1, 2, 3)
                if spans_within(span[x, P.sides[j]], span[y, P.tips[k]], *within)]
    return out


# Matched facing (docs/model.md): the chaser's APDS frame is the target's turned by pi about a
# transverse axis and by 240 deg about the docking axis, so that the pairs of Sect. 2.2 face.
R_MATCHED = rot_z(math.radians(240.0)) @ rot_x(math.pi)
