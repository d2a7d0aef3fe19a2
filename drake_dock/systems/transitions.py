"""The contact system's events: every transition due at a state (module docstring of
`drake_dock.systems.contact_system`), with the decisions made by `drake_dock.core.hybrid`."""
from __future__ import annotations

import numpy as np

from drake_dock.core import handover, hybrid
from drake_dock.core.couple import point_curve_side
from drake_dock.core.hybrid import Mode
from drake_dock.core.kernels import constraints as compiled_constraints
from drake_dock.core.patches import posed
from drake_dock.core.relations import relation
from drake_dock.core.seeking import contact_couple, seek_couple
from drake_dock.errors import (DriftError, InputError, PainleveInconsistency, SeekingError,
                               SingularCoupleError)
from drake_dock.systems import handover_links, impacts
from drake_dock.systems.contact_types import read_only
from drake_dock.systems.evaluation import Kinematics
from drake_dock.systems.handover_links import applied


def _reseek(p, c, margin, R2, conditioning_min) -> bool:
    """A couple c of pair p that is not far is sought again: at a domain end, with J singular,
    or (a point-curve pair) on the curve's convex side, Body 2 turned by R2."""
    return margin.min() <= 0.0 or c.conditioning <= conditioning_min or (
        relation(p.kind).along_d and point_curve_side(p.patch2, R2, c.u[0], c.n) <= 0.0)


def couples_of(ev, kin, u, states, which, t, strict=False):
    """The couples (`CoupleRow`) of the pairs ``which`` of the `RigidContactSystem` ``ev`` at
    u with their states' sigma; a point-curve couple whose point lies on its curve raises
    `SingularCoupleError`; with ``strict``, a couple in contact that projected by more than
    ``drift_tol`` of its span raises `DriftError`."""
    sigma = np.array([st.sigma for st in states])
    couples = ev.engine.couples(kin, u, sigma, which)
    for i, c in couples.items():
        if relation(ev.pairs[i].kind).along_d and np.isnan(c.gap):
            raise SingularCoupleError("point-curve couple: the point lies on the curve "
                                      "(|d| = 0), its normal is undefined", time=t,
                                      couples=[ev.pairs[i].name])
        if strict and states[i].mode.in_contact:
            rel = np.abs(c.drift) / ev.engine.model.spans[i, :len(c.drift)]
            if rel.max() > ev.options.drift_tol:
                raise DriftError(f"couple drift {rel.max():.3e} of the domain span "
                                 f"exceeds drift_tol = {ev.options.drift_tol:g}", time=t,
                                 couples=[ev.pairs[i].name])
    return couples


class Transitions:
    """The transitions of the pairs of a `RigidContactSystem` ``ev`` (its engine's calculators),
    timed into ``timing``."""

    def __init__(self, ev, timing):
        self.ev, self.timing = ev, timing
        self.pairs, self.law, self.options = ev.pairs, ev.law, ev.options
        self.eng = ev.engine

    def resolve(self, t, x, modes, inputs, current, early=1.0, due=()):
        """All the transitions due at time t and state x from `ContactModes` ``modes``;
        returns (x, modes). ``inputs`` is the inputs' generalized force; ``current()`` gives
        the evaluation at (t, x, modes). Far pairs are sought again when their travel bound
        reaches ``early`` x their clearance, and the far pairs ``due`` in any case (those due
        at a step's start, `Evaluation.due_pairs`)."""
        ev, opt = self.ev, self.options
        modes = modes.working_copy()
        modes.mode_changes += 1
        q = x[:ev.nq]
        v = x[ev.nq:ev.nq + ev.nv].copy()
        u = x[ev.nq + ev.nv:ev.ie].copy()
        kin = self.eng.kinematics(q, v)
        poses = kin.poses
        initial = all(st.ref_X21 is None and st.mode == Mode.FAR for st in modes.pairs)
        # 1. Seeking: at initialisation, for far pairs whose clearance is used up, and for
        #    couples at a domain end or with a singular Jacobian; hand-overs between an edge
        #    pair and a surface pair. Every decision reads the pairs' states as the pass found
        #    them or as it leaves them, never half-way, so that it does not depend on the
        #    pairs' order: the couples are evaluated and the hand-overs applied first, then the
        #    pairs are sought, then the carried clearances are set.
        couples, handed = self._handovers(modes.pairs, kin, u, t)
        far = [i for i, st in enumerate(modes.pairs) if st.mode == Mode.FAR]
        travel = dict(zip(far, ev.far.bounds(far, poses, modes.pairs).tolist()))
        sought = []         # (pair, `seek`'s return) of each seek
        for i, st in enumerate(modes.pairs):
            if i in handed or i in handed.values():
                continue
            if initial or (st.mode == Mode.FAR and (travel[i] >= early * st.clearance
                                                    or i in due)):
                if not self.screen(i, poses, modes.pairs):
                    sought.append((i, self.seek(i, poses, modes.pairs, u, t, False, initial)))
                continue
            if st.mode == Mode.FAR:
                continue
            p, c = self.pairs[i], couples[i]
            margin = np.concatenate([p.patch1.margin(c.u[:p.patch1.dim]),
                                     p.patch2.margin(c.u[p.patch1.dim:])]) / ev.spans[i]
            if c.conditioning <= opt.conditioning_min and st.mode.in_contact:
                raise SingularCoupleError(
                    f"the Jacobian of a couple in contact turned singular (Eq. 39 fails; "
                    f"conditioning {c.conditioning:.2e})", time=t, couples=[p.name])
            drifted = (not st.mode.in_contact
                       and (np.abs(c.drift) / ev.spans[i]).max() > opt.drift_tol)
            if drifted or _reseek(p, c, margin, poses[ev.fidx[i][1]][0], opt.conditioning_min):
                sought.append((i, self.seek(i, poses, modes.pairs, u, t, st.mode.in_contact)))
        for i, after in sought:
            self.carry(i, after, modes.pairs)
        # 2. Impacts and 3. modes.
        impulses = impacts.EventImpulses(ev, t, modes)
        with self.timing.measure("impacts"):
            v = self.impacts_and_modes(t, modes, impulses, q, v, u, inputs, current, handed)
        x_new = x.copy()
        x_new[ev.nq:ev.nq + ev.nv] = v
        x_new[ev.nq + ev.nv:ev.ie] = u
        impulses.log(x, x_new)
        modes.x_after = read_only(x_new.copy())
        return x_new, modes.seal()

    def _handovers(self, states, kin, u, t) -> tuple[dict, dict]:
        """The couples of the pairs that are not far (written into u) and their hand-overs
        (`HandoverLinks.target` on the states the event found, `applied`), made (`hand_over`):
        returns ({pair: its couple}, {pair handed to: pair it continues})."""
        ev, due = self.ev, {}
        near = [i for i, st in enumerate(states) if st.mode != Mode.FAR]
        couples = couples_of(self.ev, kin, u, states, near, t)
        poses = kin.poses
        for i in near:
            c = couples[i]
            u[ev.couple_slice(i)] = c.u
            to = ev.links.target(i, c.u, c.n, poses[ev.fidx[i][1]][0], states)
            if to is not None and handover_links.accepts(ev, i, to, c.n, kin):
                due[i] = to
        handed = applied(due)
        for j, i in handed.items():
            self.hand_over(i, j, due[i][1], couples[i].n, kin, states, u)
        return couples, handed

    def screen(self, i, poses, states) -> bool:
        """The broad phase (``options.broad_phase``) for far pair i (`PairState` states[i]): when
        the least gap G of its covers (a lower bound of its distance) is at least
        ``track_distance``, a seek could only leave it far, so it is not sought; it keeps G as
        its distance, with the far pair's clearance of `hybrid.after_seek`. Returns whether
        the pair was screened so."""
        st, opt = states[i], self.options
        if not opt.broad_phase:
            return False
        with self.timing.measure("seeking", self.pairs[i].name):
            gap = self.ev.far.cover_gap(i, poses, below=opt.track_distance)
            if not gap >= opt.track_distance:
                return False
            st.ref_X21 = self.ev.far.reference(i, poses)
            st.distance = gap
            st.mode, st.clearance = hybrid.after_seek(gap, False, False, False,
                                                      opt.track_distance, opt.reseek_floor)
            st.slide_dir = None
            self.timing.count_screen(self.pairs[i].name)
        return True

    def hand_over(self, i, j, uj, n, kin, states, u):
        """Pair i's couple (normal n) continues as pair j's couple uj: j takes i's mode and the
        sigma that keeps n (`drake_dock.core.handover`); i is far, its nearest point carried
        by j (clearance half ``track_distance``, as `hybrid.after_seek` for a carried couple)."""
        ev = self.ev
        u[ev.couple_slice(j)] = uj
        raw = self.eng.couple(j, uj, kin.still(), 1.0, project=False)
        poses = kin.poses
        si, sj = states[i], states[j]
        sj.mode, sj.sigma, sj.slide_dir = si.mode, handover.carried_sigma(n, raw.n), None
        si.mode, si.clearance = hybrid.after_seek(abs(raw.gap), False, False, True,
                                                  self.options.track_distance,
                                                  self.options.reseek_floor, carried=True)
        si.slide_dir, si.ref_X21 = None, ev.far.reference(i, poses)
        si.distance = sj.distance = abs(raw.gap)

    def seek(self, i, poses, states, u, time, was_contact, initial=False):
        """Sect. 5.1 for pair i (its `PairState` states[i], its couple written into u), and the
        mode that follows (`hybrid.after_seek`). At the initial seek a pair with a declared
        ``sigma`` whose couple lies on the wrong side by more than ``impact_gap_tol`` is
        refused: the bodies start interpenetrating. A couple due to a linked pair leaves the
        pair far; whether that pair carries it is for `carry`, once the pass has set every
        pair's state: returns ``carry``'s argument."""
        name = self.pairs[i].name
        with self.timing.measure("seeking", name):
            try:
                return self._seek(i, poses, states, u, time, was_contact, initial)
            finally:
                self.timing.count_seek(name)

    def carry(self, i, after, states):
        """The far clearance of sought pair i whose couple is due to linked pairs (``after`` =
        (distance, crossing, was_contact, those pairs), `seek`'s return) that one of them
        carries, i.e. is not far (`hybrid.after_seek`)."""
        distance, crossing, was_contact, due = after
        if any(states[j].mode != Mode.FAR for j in due):
            opt, st = self.options, states[i]
            st.mode, st.clearance = hybrid.after_seek(distance, False, crossing, was_contact,
                                                      opt.track_distance, opt.reseek_floor,
                                                      carried=True)

    def _seek(self, i, poses, states, u, time, was_contact, initial):
        ev, opt, p, st = self.ev, self.options, self.pairs[i], states[i]
        a, b = ev.fidx[i]
        try:
            P1, P2 = posed(p.patch1, *poses[a]), posed(p.patch2, *poses[b])
            c = seek_couple(P1, P2, distance_rtol=opt.seek_rtol, rtol_beyond=opt.track_distance)
        except SeekingError as e:
            raise SeekingError(str(e), time=time, couples=[p.name]) from None
        st.ref_X21 = ev.far.reference(i, poses)
        st.distance = c.distance
        if not initial and c.distance >= opt.track_distance:
            # Beyond the tracking distance the pair stays far whatever its couple is; the
            # seek's distance, a global minimum, sets its clearance (`hybrid.after_seek`).
            u[ev.couple_slice(i)] = c.u
            st.mode, st.clearance = hybrid.after_seek(c.distance, False, False, was_contact,
                                                      opt.track_distance, opt.reseek_floor)
            st.slide_dir = None
            return c.distance, False, was_contact, []
        # Interior, isolated and finished on the contact form inside the domain, else not a
        # potential contact (docs/model.md, "Degenerate couples").
        f = contact_couple(p.kind, p.patch1, poses[a], p.patch2, poses[b], c,
                           conditioning_min=opt.conditioning_min)
        usable, uc = f.usable, f.u
        crossing = hybrid.intersecting(c.distance, f.finish_failed, opt.impact_gap_tol)
        if usable:
            raw = self.eng.couple(i, uc, Kinematics.at_rest(poses), 1.0, project=False)
            gap = raw.gap
            rel = relation(p.kind)
            sigma = rel.sigma(p.sigma, gap, p.patch1.radius if rel.point else 0.0)
            # A declared side (a ring face, solid on one side): a couple found a little on the
            # wrong side is a contact made between two seeks, not patches crossing past an end.
            crossing = hybrid.patches_cross(
                gap, c.distance, sigma,
                opt.impact_gap_tol if p.sigma is None or initial else hybrid.DECLARED_DEPTH)
        if initial and p.sigma is not None and (
                (usable and sigma * gap < -opt.impact_gap_tol)
                or (crossing and c.distance <= opt.impact_gap_tol)):
            # The scene declares the sides: a couple on the wrong side, or patches that
            # intersect, is a body started inside another.
            value = (f"signed gap {sigma * gap:.6g} m" if usable and sigma * gap < 0.0
                     else f"patches intersecting (distance {c.distance:.3g} m)")
            raise InputError(f"initial state of pair {p.name}", value,
                             f"signed gap >= -impact_gap_tol = {-opt.impact_gap_tol:g} m",
                             "the bodies start interpenetrating")
        u[ev.couple_slice(i)] = uc
        # A couple where a hand-over is due (on a declared edge of the surface, or an edge
        # couple over the face) is the linked pair's, not this pair's. One that is not usable
        # ends on its domain's bound from inside: on the edge within SEEK_EDGE_RTOL. Where a
        # linked pair holds a contact, a couple within SEEK_HELD_TOL of their edge is it.
        held = any(states[j].mode.in_contact for j, _ in (
            ev.links.of_edge.get(i, []) + ev.links.of_surface.get(i, [])))
        tol = max(handover.SEEK_HELD_TOL if held else 0.0,
                  0.0 if usable else handover.SEEK_EDGE_RTOL)
        due = [j for j, _ in ev.links.due(i, uc, sigma * raw.n if usable else None,
                                          poses[b][0], tol)]
        mode, clearance = hybrid.after_seek(c.distance, usable and not due, crossing,
                                            was_contact, opt.track_distance, opt.reseek_floor)
        if mode == Mode.TRACKED:
            st.sigma = sigma
        else:
            st.clearance = clearance
        st.mode, st.slide_dir = mode, None
        return c.distance, crossing, was_contact, due

    def impacts_and_modes(self, t, modes, impulses, q, v, u, inputs, current, handed=None):
        """2. The LZB impact of the couples hit (Sect. 6) and 3. the modes of the contact set
        (Eq. 48-52), then the velocity projection onto the new constraints; returns v. The
        impulses are solved into ``impulses`` (`EventImpulses`), which the caller logs.
        ``handed`` maps a pair handed a couple to the pair it continues, whose forces it
        takes; ``inputs`` is the inputs' generalized force."""
        handed = handed or {}
        ev, opt, eng = self.ev, self.options, self.eng
        states = modes.pairs
        evs = {}
        near = [i for i, st in enumerate(states) if st.mode != Mode.FAR]

        def evaluate_all(v):
            # A tracked couple that drifts is sought again; one in contact raises.
            kin = eng.kinematics(q, v)
            evs.clear()
            evs.update(couples_of(self.ev, kin, u, states, near, t, strict=True))
            return kin

        def gaps_and_rates():
            return ([evs[i].gap if i in evs else np.nan for i in range(len(states))],
                    [evs[i].vn if i in evs else np.nan for i in range(len(states))])

        # Modes the contact couples are leaving (their witness crossed zero).
        leaving = {}
        if any(st.mode.in_contact for st in states):
            E = current()
            src = {i: handed.get(i, i) for i, st in enumerate(states) if st.mode.in_contact}
            leaving = {i: hybrid.modes_left(st.mode, E.lam_n[src[i]], E.lam_t[src[i]], ev.law.static_mu)
                       for i, st in enumerate(states) if st.mode.in_contact}
        kin = evaluate_all(v)
        gap, vn = gaps_and_rates()
        hit = hybrid.impact_hits([st.mode for st in states], gap, vn, opt.impact_gap_tol)
        closed = []
        if hit:
            S = hybrid.impact_set(hit, [st.mode for st in states], vn)
            v, vn_plus, approach = impulses.lzb_impact(kin, evs, S, v)
            for i, c in zip(S, hybrid.closed_after_impact(vn_plus, approach)):
                if c:
                    closed.append(i)       # closed at the end of the impact: in contact
                else:
                    states[i].track()      # separating
            impulses.left(states)
            kin = evaluate_all(v)
            gap, vn = gaps_and_rates()
        new, cand = hybrid.contact_candidates([st.mode for st in states], gap, vn, bool(hit),
                                              closed, opt.impact_gap_tol, opt.v_slip)
        for st, m in zip(states, new):
            if m != st.mode:
                st.track()
        rows = [eng.row(i, evs[i], kin) for i in cand]
        M, Minv, a0 = eng.dynamics(q, v, inputs)[:3]
        select = compiled_constraints.select_contact_modes
        avoid = [() if hit else leaving.get(i, ()) for i in cand]
        try:
            sol = select(Minv, a0, rows, v_slip=opt.v_slip, omega=opt.baumgarte, time=t,
                         avoid=avoid)
        except PainleveInconsistency as paradox:
            if opt.painleve != "impact":
                raise
            # The impact without collision (`drake_dock.core.iwc`), then the modes again.
            v = impulses.without_collision(M, rows, v, paradox)
            kin = evaluate_all(v)
            rows = [eng.row(i, evs[i], kin) for i in cand]
            M, Minv, a0 = eng.dynamics(q, v, inputs)[:3]
            sol = select(Minv, a0, rows, v_slip=opt.v_slip, omega=opt.baumgarte, time=t,
                         avoid=[()] * len(cand))
        cons = []
        for j, i in enumerate(cand):
            st = states[i]
            st.mode = Mode.of_selection(sol.modes[j])
            st.slide_dir = (np.asarray(sol.dirs[j], dtype=float) if st.mode == Mode.SLIDING
                            else None)
            if st.mode.in_contact:
                cons.append(rows[j].Wn)
                if st.mode == Mode.STICKING:
                    cons += [rows[j].Wt[:, 0], rows[j].Wt[:, 1]]
        if cons:
            # The mode is entered at a witness's zero, located to within the integrator's
            # accuracy; the residual relative velocity (below v_slip or the impact tolerance) is
            # removed by the projection, and the energy it removes (of the order of the
            # residual squared) is booked with the impacts.
            v, removed = hybrid.project_velocity(M, Minv, np.column_stack(cons), v)
            modes.impact_loss += removed
        return v
