"""The hybrid decisions of a declared pair (Sect. 5-7), as small pure functions on numbers.

A pair is in one `Mode`: FAR (not tracked), TRACKED (a potential contact, its couple u*
integrated with Eq. 47), SLIDING or STICKING (in contact, Eq. 48-51). The contact system
(`drake_dock.systems`) evaluates the couples and calls these functions at its events; each
function states its rule in one line or cites the equation it implements.
"""
from __future__ import annotations

import enum
import math

import numpy as np

from drake_dock.core.constraints import DETACH, STICK, SLIDE

CLOSED_RTOL = 1e-6   # a normal velocity below this fraction of the approach speed is closed


class Mode(enum.IntEnum):
    """The mode of a pair; its value is also the status code of the couple's output port."""

    FAR = 0
    TRACKED = 1
    SLIDING = 2
    STICKING = 3

    @property
    def in_contact(self) -> bool:
        return self >= Mode.SLIDING

    @classmethod
    def of_selection(cls, m: str) -> Mode:
        """The pair's mode for the mode `select_contact_modes` chose for its couple."""
        return {DETACH: cls.TRACKED, SLIDE: cls.SLIDING, STICK: cls.STICKING}[m]


# ---------------------------------------------------------------------------- seeking
# A couple of a pair whose side is declared (`drake_dock.core.relations.Relation.sigma`) found up to this far (m) on the
# wrong side at a seek is a contact that came about between two seeks (the tracked and far
# couples next to it moved on): it is tracked and takes part in the event's impact and modes.
DECLARED_DEPTH = 1e-4


def patches_cross(gap: float, distance: float, sigma: float, gap_tol: float) -> bool:
    """Rule: the contact-form couple is not the closest one (|g| > d) or lies on the wrong side of
    n (sigma g < 0), beyond ``gap_tol``: the patches cross each other past a patch end."""
    return abs(gap) > distance + gap_tol or sigma * gap < -gap_tol


def intersecting(distance: float, finish_failed: bool, gap_tol: float) -> bool:
    """Rule: an interior, isolated couple at a distance within ``gap_tol`` whose contact-form
    finish failed (no contact-form couple inside the domain near it): a curve passes through
    the other patch, the patches cross each other."""
    return finish_failed and distance <= gap_tol


def after_seek(distance: float, usable: bool, crossing: bool, was_contact: bool,
               track_distance: float, reseek_floor: float,
               carried: bool = False) -> tuple[Mode, float | None]:
    """The mode after a seek and, for a FAR pair, its clearance (the relative travel after which
    it is sought again; None for a tracked pair).

    Rule: a couple that is interior, isolated and finished on the contact form (``usable``,
    `drake_dock.core.seeking.contact_couple`), not crossing and nearer than
    ``track_distance`` is TRACKED, unless the pair has just left a contact (a contact that runs
    off a patch end ends there). A FAR pair keeps half ``track_distance`` in hand (a crossing
    pair, or a ``carried`` one, whose couple lies on an edge where a linked pair carries it
    (`drake_dock.core.handover`): half ``track_distance``), and never less than half its
    distance or ``reseek_floor``."""
    if usable and not crossing and not carried and distance < track_distance \
            and not was_contact:
        return Mode.TRACKED, None
    if crossing or carried:
        return Mode.FAR, 0.5 * track_distance
    if distance >= track_distance:
        return Mode.FAR, max(distance - 0.5 * track_distance, 0.5 * distance, reseek_floor)
    return Mode.FAR, max(0.5 * distance, reseek_floor)


# ---------------------------------------------------------------------------- impacts
def impact_hits(modes, gap, vn, gap_tol: float) -> list[int]:
    """Rule: the TRACKED couples within ``gap_tol`` of contact and approaching (v_n < 0)."""
    return [i for i, m in enumerate(modes)
            if m == Mode.TRACKED and gap[i] <= gap_tol and vn[i] < 0.0]


def impact_set(hit, modes, vn) -> list[int]:
    """The couples of an impact: those hit, then the couples in contact that are not separating
    beyond round-off (v_n <= CLOSED_RTOL x the closing speed of the hit couples)."""
    closing = -min(vn[i] for i in hit)
    return list(hit) + [i for i, m in enumerate(modes)
                        if m.in_contact and i not in hit and vn[i] <= CLOSED_RTOL * closing]


def zeno_restitution(approach: float, restitution: float, zeno_speed: float) -> float:
    """The Zeno guard: an impact slower than ``zeno_speed`` is plastic (e = 0), so that a
    decaying bounce sequence ends in persistent contact after finitely many impacts."""
    return restitution if approach >= zeno_speed else 0.0


def closed_after_impact(vn_plus, approach: float) -> list[bool]:
    """Rule: a couple of the impact is closed at its end when v_n+ <= CLOSED_RTOL x the approach
    speed; the others separate."""
    return [vn <= CLOSED_RTOL * approach for vn in vn_plus]


def contact_candidates(modes, gap, vn, hit: bool, closed, gap_tol: float, v_slip: float):
    """The new modes and the candidates of the contact set (sorted), whose modes
    `select_contact_modes` then chooses (ties within its TIE_RTOL resolved against the modes
    being left).

    Rule: after an impact (``hit``) a couple in contact that is not in ``closed`` (the couples
    closed at its end) is TRACKED again; the candidates are ``closed``, the couples still in
    contact, and the TRACKED couples resting within ``gap_tol`` with |v_n| <= ``v_slip``."""
    modes = list(modes)
    cand = set(closed)
    for i, m in enumerate(modes):
        left_out = hit and i not in cand
        if m.in_contact and left_out:
            modes[i] = Mode.TRACKED
        if (modes[i].in_contact and not left_out) or (
                modes[i] == Mode.TRACKED and gap[i] <= gap_tol and abs(vn[i]) <= v_slip):
            cand.add(i)
    return modes, sorted(cand)


def modes_left(mode: Mode, lam_n: float, lam_t, mu_s: float) -> tuple:
    """The contact modes a couple is leaving (its witness crossed zero): both when lambda_n <= 0
    (Eq. 50-51), stick when the sticking force reaches the static cone |lambda_t| = mu_s
    lambda_n (Eq. 51)."""
    out = []
    if lam_n <= 0.0:
        out += [STICK, SLIDE]
    if mode == Mode.STICKING and mu_s * lam_n - math.hypot(*lam_t) <= 0.0:
        out.append(STICK)
    return tuple(out)


# ---------------------------------------------------------------------------- projection
def project_velocity(M, Minv, C, v):
    """(v+, kinetic energy removed): the M-orthogonal projection of v onto C^T v = 0 (the closed
    couples' normal rows and the sticking couples' tangential rows), the smallest change of
    kinetic energy, v+ = v - M^-1 C (C^T M^-1 C)^+ C^T v."""
    r = C.T @ v
    if not np.abs(r).max() > 0.0:
        return v, 0.0
    MinvC = Minv @ C
    dv = -MinvC @ np.linalg.lstsq(C.T @ MinvC, r, rcond=1e-10)[0]
    ke0 = 0.5 * v @ M @ v
    v = v + dv
    return v, ke0 - 0.5 * v @ M @ v
