"""One evaluation of the contact dynamics, with the MultibodyPlant as calculator on a scratch
context: the frames' poses and twists, the couples (Eq. 47), the contact rows W (Eq. 11) from
Drake's Jacobians, the free acceleration, and the constraint forces of the contact set's modes
(Eq. 48-52)."""
from __future__ import annotations

import math

import numpy as np
from pydrake.multibody.math import SpatialForce
from pydrake.multibody.tree import JacobianWrtVariable, MultibodyForces

from drake_dock.core.constraints import (SLIDE, STICK, ContactRow, friction_power,
                                         solve_given_modes)
from drake_dock.core.couple import evaluate_couple, float_pose, float_vec
from drake_dock.core.hybrid import Mode
from drake_dock.core.kernels.constraints import raise_status
from drake_dock.core.kernels.couples import DRIFT_REL as KERNEL_DRIFT_REL
from drake_dock.core.kernels.couples import GAP as KERNEL_GAP
from drake_dock.core.kernels.couples import ROW
from drake_dock.core.kernels.engine import evaluate as engine_evaluate
from drake_dock.core.kernels.solve import OK as ENGINE_OK
from drake_dock.errors import DriftError, SingularCoupleError
from drake_dock.systems import engine
from drake_dock.systems.contact_types import Evaluation
from drake_dock.systems.engine import ModePack, Poses
from drake_dock.systems.far_pairs import FarPairs
from drake_dock.systems.handovers import HandoverLinks

KV = JacobianWrtVariable.kV


def _floating_body_indices(plant):
    from pydrake.multibody.tree import BodyIndex
    return [BodyIndex(i) for i in range(1, plant.num_bodies())]


def frame_list(pairs):
    """The distinct frames of the pairs, and per pair the indices of its two frames."""
    frames = []
    for p in pairs:
        for f in (p.frame1, p.frame2):
            if all(f is not g for g in frames):
                frames.append(f)
    index = [(next(i for i, g in enumerate(frames) if g is p.frame1),
              next(i for i, g in enumerate(frames) if g is p.frame2)) for p in pairs]
    return frames, index


def near_pairs(modes) -> tuple:
    """The indices of the pairs that are not far under ``modes``, ascending (`ModesIndex`, kept
    on sealed modes), which `PlantEvaluator.key`, `PlantEvaluator.evaluate` and the tracked
    count share."""
    return modes.index().near


class PlantEvaluator:
    """The contact dynamics of ``pairs`` for a finalized continuous-time ``plant``. The state is
    x = [q, v, u*, energy integrals]; pair i's couple is u*[uoff[i]:uoff[i + 1]]. ``inputs``
    arguments are (generalized force or None, [(body, world wrench [torque, force])])."""

    def __init__(self, plant, pairs, law, options, extra_powers=(), energy_scale=1.0,
                 handovers=()):
        self.plant, self.pairs, self.law, self.options = plant, list(pairs), law, options
        self.extra_powers = list(extra_powers)
        self.energy_scale = energy_scale
        self.mu_s = law.static_mu
        self.ctx = plant.CreateDefaultContext()
        self.nq, self.nv = plant.num_positions(), plant.num_velocities()
        dims = [p.patch1.dim + p.patch2.dim for p in pairs]
        self.uoff = np.concatenate([[0], np.cumsum(dims)]).astype(int)
        self.nu = int(self.uoff[-1])
        self.ie = self.nq + self.nv + self.nu       # start of the energy integrals in x
        self.spans = [np.concatenate([p.patch1.span, p.patch2.span]) for p in pairs]
        # Per pair, (lower, upper, span) of its bounded parameters (u = (u1, u2)), in floats
        # for the domain-end witness.
        self.bounded = [[(float(lo), float(hi), float(hi - lo)) if not per else None
                         for lo, hi, per in zip(np.concatenate([p.patch1.lower, p.patch2.lower]),
                                                np.concatenate([p.patch1.upper, p.patch2.upper]),
                                                p.patch1.periodic + p.patch2.periodic)]
                        for p in pairs]
        self.frames, self.fidx = frame_list(pairs)
        # The tracked couples in one compiled call per evaluation, where every patch has a
        # kernel description (else, or with options.compiled off, the Python path).
        self.kernel = None
        if options.compiled:
            from drake_dock.core.kernels.tracked import TrackedCouples
            kernel = TrackedCouples([(p.kind, p.patch1, p.patch2, f)
                                     for p, f in zip(self.pairs, self.fidx)])
            self.kernel = kernel if kernel.supported else None
        # The pairs the kernel leaves to the Python path.
        self._in_python = frozenset(self.kernel.python) if self.kernel else frozenset()
        # The constraint solve (Eq. 48-52) compiled, or in Python with options.compiled off.
        self.solver = None
        if options.compiled:
            from drake_dock.core.kernels import constraints as solver
            self.solver = solver
        # The whole evaluation in one compiled call when every body moves freely and the
        # kernels describe every pair (`drake_dock.systems.engine`).
        self.engine = None
        if self.kernel is not None and options.engine:
            bodies = engine.free_bodies(plant, self.frames, self.ctx)
            if bodies is not None:
                self.engine = (bodies, engine.couple_set(self.kernel))
                self._body_v = {plant.get_body(i).index(): int(j) for i, j in zip(
                    _floating_body_indices(plant), bodies.vs)}
        self.far = FarPairs(pairs, self.fidx)
        # The point-curve pairs: their side witness (`witnesses`).
        self.side_pairs = frozenset(i for i, p in enumerate(self.pairs) if p.kind == "PC")
        self.links = HandoverLinks(self.pairs, handovers)
        self.evaluations = 0
        self._far_index = {}     # `_far_entries`, by the set of pairs not far
        self._zero_v = np.zeros(self.nv)         # never written
        self._world = plant.world_frame()
        self._no_forces = MultibodyForces(plant)  # never written
        self._forces_fe = MultibodyForces(plant)
        self._forces_in = MultibodyForces(plant)

    def couple_slice(self, i) -> slice:
        return slice(self.uoff[i], self.uoff[i + 1])

    def set_scratch(self, q, v):
        self.plant.SetPositions(self.ctx, q)
        self.plant.SetVelocities(self.ctx, v)
        return self.ctx

    def frame_kinematics(self, ctx):
        """The frames' world poses (R, p) and twists (w, v)."""
        poses, twists = [], []
        for f in self.frames:
            X = f.CalcPoseInWorld(ctx)
            V = f.CalcSpatialVelocityInWorld(ctx)
            poses.append((X.rotation().matrix(), X.translation()))
            twists.append((V.rotational(), V.translational()))
        return poses, twists

    def couple(self, i, u, poses, twists, sigma, time, strict):
        """Pair i's couple at u (Eq. 47); with ``strict`` (a couple in contact), `DriftError`
        when its projection step exceeds ``drift_tol`` of the domain span."""
        p = self.pairs[i]
        a, b = self.fidx[i]
        try:
            ev = evaluate_couple(p.kind, p.patch1, poses[a], twists[a], p.patch2, poses[b],
                                 twists[b], u, sigma)
        except SingularCoupleError as e:
            raise SingularCoupleError(str(e), time=time, couples=[p.name]) from None
        rel = np.abs(ev.drift) / self.spans[i]
        if strict and rel.max() > self.options.drift_tol:
            raise DriftError(f"couple drift {rel.max():.3e} of the domain span exceeds "
                             f"drift_tol = {self.options.drift_tol:g}", time=time,
                             couples=[p.name])
        return ev

    def couples(self, t, u, poses, twists, modes, near):
        """The couples of the pairs ``near`` that are not far (`CoupleEval` or None per pair)
        and the couples' rate u*' = Eq. (47) + drift_feedback x projection; `DriftError` as
        `couple` for a couple in contact. A tracked couple that drifts further is sought again
        at the next step's start (`drifting`)."""
        k, fb = len(self.pairs), self.options.drift_feedback
        evals = [None] * k
        udot = np.zeros(self.nu)
        tracked = near
        near = near if self.kernel is None else [i for i in near if i in self._in_python]
        if near:
            # The couples work in plain floats: the frames' poses and twists converted once.
            fposes = [float_pose(X) for X in poses]
            ftwists = [(float_vec(w), float_vec(v)) for w, v in twists]
            for i in near:
                sl = self.couple_slice(i)
                ev = evals[i] = self.couple(i, u[sl], fposes, ftwists, modes.pairs[i].sigma, t,
                                            modes.pairs[i].mode.in_contact)
                udot[sl] = ev.udot + fb * ev.drift
        if self.kernel is None:
            return evals, udot
        active = np.zeros(k, dtype=np.bool_)
        active[list(tracked)] = True
        active[self.kernel.python] = False
        if not active.any():
            return evals, udot
        python_udot = udot
        sigma = modes.index().sigma
        out, udot = self.kernel.evaluate(np.array([X[0] for X in poses]),
                                         np.array([X[1] for X in poses]),
                                         np.array([V[0] for V in twists]),
                                         np.array([V[1] for V in twists]), u, sigma, active,
                                         drift_feedback=fb)
        for i in self.kernel.pc.tolist():
            if active[i] and math.isnan(out[i, KERNEL_GAP]):
                raise SingularCoupleError("point-curve couple: the point lies on the curve "
                                          "(|d| = 0), its normal is undefined", time=t,
                                          couples=[self.pairs[i].name])
        rel = out[:, KERNEL_DRIFT_REL]
        over = [i for i in np.flatnonzero(rel > self.options.drift_tol).tolist()
                if modes.pairs[i].mode.in_contact]
        if over:
            i = over[0]
            raise DriftError(f"couple drift {rel[i]:.3e} of the domain span exceeds "
                             f"drift_tol = {self.options.drift_tol:g}", time=t,
                             couples=[self.pairs[i].name])
        for i in np.flatnonzero(active).tolist():
            evals[i] = self.kernel.couple_eval(out, i)
        for i in near:
            sl = self.couple_slice(i)
            udot[sl] = python_udot[sl]
        return evals, udot

    def row(self, i, ev, poses, ctx):
        """Pair i's `ContactRow` (`row_arrays`)."""
        W, bn, bt = self.row_arrays(i, ev, poses, ctx)
        return ContactRow(self.pairs[i].name, W[:, 0], W[:, 1:], bn, bt, ev.gap, ev.vn, ev.vt,
                          self.law.mu, self.mu_s)

    def row_arrays(self, i, ev, poses, ctx):
        """W (nv, 3), the columns W^3, W^1, W^2 of Eq. (11) from Drake's point Jacobians, and the
        bias terms bn, bt (Eq. 52)."""
        p = self.pairs[i]
        a, b = self.fidx[i]
        world = self._world
        R1, o1 = poses[a]
        R2, o2 = poses[b]
        s1, s2 = (ev.p1 - o1) @ R1, (ev.p2 - o2) @ R2     # the points in their frames
        plant = self.plant
        J = (plant.CalcJacobianTranslationalVelocity(ctx, KV, p.frame1, s1, world, world)
             - plant.CalcJacobianTranslationalVelocity(ctx, KV, p.frame2, s2, world, world))
        ab = (plant.CalcBiasTranslationalAcceleration(ctx, KV, p.frame1, s1, world, world)
              - plant.CalcBiasTranslationalAcceleration(ctx, KV, p.frame2, s2, world, world))
        D = np.array([ev.n, ev.ta, ev.tb]).T          # columns n, ta, tb
        W = J.T @ D
        b = D.T @ ab.ravel()
        return W, ev.bias_n + b[0], ev.bias_t + b[1:]

    def solve(self, t, Minv, a0, row_pairs, evals, smodes, dirs, poses, ctx):
        """The constraint solve for the modes of the contact set (Eq. 48-52): v', lambda_n (per
        row), lambda_t and the generalized contact force; compiled (one call) or in Python."""
        omega = self.options.baumgarte
        if self.solver is None:
            rows = [self.row(i, evals[i], poses, ctx) for i in row_pairs]
            sol = solve_given_modes(Minv, a0, rows, smodes, dirs, omega=omega, time=t)
            return sol.vdot, sol.lam_n, sol.lam_t, sol.generalized_force
        kc = len(row_pairs)
        if kc == 0:
            return a0, np.zeros(0), np.zeros((0, 2)), np.zeros_like(a0)
        S = self.solver
        W, bias = np.empty((kc, self.nv, 3)), np.empty((kc, 3))
        gap, vn, sdirs = np.empty(kc), np.empty(kc), np.zeros((kc, 2))
        codes = np.empty(kc, np.int64)
        for j, i in enumerate(row_pairs):
            ev = evals[i]
            W[j], bias[j, 0], bias[j, 1:] = self.row_arrays(i, ev, poses, ctx)
            gap[j], vn[j] = ev.gap, ev.vn
            codes[j] = S.CODE[smodes[j]]
            if dirs[j] is not None:
                sdirs[j] = dirs[j]
        return S.solve_packed(Minv, a0, W, bias, gap, vn, np.full(kc, self.law.mu),
                              np.full(kc, self.mu_s), codes,
                              sdirs, omega, time=t, names=[self.pairs[i].name for i in row_pairs])

    def free_acceleration(self, ctx, v, inputs):
        """M, M^-1, a0 = M^-1 tau (every force but contact), and the power of the plant's
        force elements and of the inputs. Drake's inverse dynamics at zero acceleration gives
        C(q, v) v - tau for any set of forces."""
        zero = self._zero_v
        ID = self.plant.CalcInverseDynamics
        bias = ID(ctx, zero, self._no_forces)
        fe = self._forces_fe     # set, not added, by CalcForceElementsContribution
        self.plant.CalcForceElementsContribution(ctx, fe)
        tau_el = bias - ID(ctx, zero, fe)
        tau_in = np.zeros(self.nv)
        generalized, wrenches = inputs
        if generalized is not None:
            tau_in += generalized
        wf = self._forces_in
        for k, (body, w) in enumerate(wrenches):
            if k == 0:
                wf.SetZero()
            body.AddInForce(ctx, np.zeros(3), SpatialForce(w[:3], w[3:]), self._world, wf)
        if wrenches:
            tau_in += bias - ID(ctx, zero, wf)
        M = self.plant.CalcMassMatrix(ctx)
        Minv = np.linalg.inv(M)
        return M, Minv, Minv @ (tau_el + tau_in - bias), float(tau_el @ v), float(tau_in @ v)

    def _far_entries(self, tracked: tuple):
        """The indices in x of the far pairs' u* for the pairs ``tracked`` not far, built once
        per such set (one numpy assignment per evaluation instead of one per far pair)."""
        hit = self._far_index.get(tracked)
        if hit is None:
            if len(self._far_index) > 256:
                self._far_index.clear()
            keep = set(tracked)
            base = self.nq + self.nv
            hit = self._far_index[tracked] = np.array(
                [base + k for i in range(len(self.pairs)) if i not in keep
                 for k in range(self.uoff[i], self.uoff[i + 1])], dtype=np.intp)
        return hit

    def key(self, t, x, modes, inputs, near=None) -> tuple:
        """Everything an evaluation depends on: time, the continuous state (the bodies' and the
        tracked couples' u*; a far pair's u* and its far-pair data are not used), the modes of
        the pairs that are not far (``near``, `near_pairs`), and the inputs."""
        near = near_pairs(modes) if near is None else near
        x = x[:self.ie].copy()
        pairs = modes.pairs
        sig = [(i, pairs[i].mode, pairs[i].sigma, None if pairs[i].slide_dir is None
                else np.asarray(pairs[i].slide_dir, dtype=float).tobytes()) for i in near]
        x[self._far_entries(near)] = 0.0
        generalized, wrenches = inputs
        key = [t, x.tobytes(), tuple(sig)]
        if generalized is not None:
            key.append(generalized.tobytes())
        key += [w.tobytes() for _, w in wrenches]
        return tuple(key)

    def evaluate(self, t, x, modes, inputs, near=None) -> Evaluation:
        """The evaluation at time t, state x, `ContactModes` modes and inputs (``near``: the
        pairs not far, `near_pairs`)."""
        self.evaluations += 1
        near = near_pairs(modes) if near is None else near
        if self.engine is not None and not any(i in self._in_python for i in near):
            return self._evaluate_engine(t, x, modes, inputs, near)
        q, v, u = x[:self.nq], x[self.nq:self.nq + self.nv], x[self.nq + self.nv:self.ie]
        ctx = self.set_scratch(q, v)
        poses, twists = self.frame_kinematics(ctx)
        k = len(self.pairs)
        evals, udot = self.couples(t, u, poses, twists, modes, near)
        row_pairs, smodes, dirs = [], [], []
        for i in near:
            st, ev = modes.pairs[i], evals[i]
            if st.mode.in_contact:
                row_pairs.append(i)
                if st.mode == Mode.STICKING:
                    smodes.append(STICK)
                    dirs.append(None)
                else:
                    smodes.append(SLIDE)
                    s = math.hypot(*ev.vt)
                    dirs.append(ev.vt / s if s > self.options.v_slip or st.slide_dir is None
                                else st.slide_dir)
        M, Minv, a0, p_plant, p_in = self.free_acceleration(ctx, v, inputs)
        vdot, lam_rn, lam_rt, gf = self.solve(t, Minv, a0, row_pairs, evals, smodes, dirs, poses,
                                              ctx)
        lam_n, lam_t = np.zeros(k), np.zeros((k, 2))
        for j, i in enumerate(row_pairs):
            lam_n[i], lam_t[i] = lam_rn[j], lam_rt[j]
        qdot = self.plant.MapVelocityToQDot(ctx, v)
        E = Evaluation(q, v, qdot, vdot, udot, evals, lam_n, lam_t, gf,
                       friction_power(lam_rt, [evals[i].vt for i in row_pairs]), p_plant, p_in,
                       np.full(k, np.nan), {},
                       poses, np.array([f(q, v) for _, f in self.extra_powers], dtype=float),
                       modes)
        E.xdot = np.concatenate([qdot, E.vdot, udot, np.array(
            [E.friction_power, E.applied_power, E.external_power, *E.extra_power])
            / self.energy_scale])
        return E

    def _input_force(self, inputs):
        """The generalized force of the inputs on free bodies: a body's wrench [torque, force]
        (world frame, at its origin) is its generalized force."""
        generalized, wrenches = inputs
        tau = np.zeros(self.nv) if generalized is None else np.array(generalized, dtype=float)
        for body, w in wrenches:
            j = self._body_v[body.index()]
            tau[j:j + 6] += w
        return tau

    def _mode_pack(self, modes, near):
        """`engine.ModePack` of the modes, kept on their index (computed once when sealed)."""
        derived = modes.index().derived
        pack = derived.get("engine")
        if pack is None or (pack[0] is not near and pack[0] != near):
            pack = derived["engine"] = (near, ModePack(len(self.pairs), near, modes.pairs,
                                                       self.kernel.pc.tolist()))
        return pack[1]

    def _evaluate_engine(self, t, x, modes, inputs, near) -> Evaluation:
        """`evaluate` in one compiled call (`drake_dock.core.kernels.engine`); the plant gives
        its force elements' generalized force."""
        q, v, u = x[:self.nq], x[self.nq:self.nq + self.nv], x[self.nq + self.nv:self.ie]
        ctx = self.set_scratch(q, v)
        fe = self._forces_fe     # set, not added, by CalcForceElementsContribution
        self.plant.CalcForceElementsContribution(ctx, fe)
        tau_el = self.plant.CalcGeneralizedForces(ctx, fe)
        pack = self._mode_pack(modes, near)
        k, F = len(self.pairs), len(self.frames)
        R, o = np.empty((F, 3, 3)), np.empty((F, 3))
        w, vf = np.empty((F, 3)), np.empty((F, 3))
        out = np.zeros((k, ROW))
        xdot = np.empty(self.ie + 3 + len(self.extra_powers))
        gf, lam_n, lam_t = np.empty(self.nv), np.empty(k), np.empty((k, 2))
        opt = self.options
        status, cond, bad_pc, bad_drift, fpow, p_el, p_in = engine_evaluate(
            *self.engine, q, v, u, modes.index().sigma, pack.active, pack.rows, pack.codes,
            pack.held_dir, pack.has_dir, tau_el, self._input_force(inputs), self.law.mu,
            self.mu_s, opt.baumgarte, opt.v_slip, opt.drift_feedback, opt.drift_tol,
            self.energy_scale, R, o, w, vf, out, xdot, lam_n, lam_t, gf)
        if bad_pc >= 0:
            raise SingularCoupleError("point-curve couple: the point lies on the curve "
                                      "(|d| = 0), its normal is undefined", time=t,
                                      couples=[self.pairs[bad_pc].name])
        if bad_drift >= 0:
            raise DriftError(f"couple drift {out[bad_drift, KERNEL_DRIFT_REL]:.3e} of the domain "
                             f"span exceeds drift_tol = {opt.drift_tol:g}", time=t,
                             couples=[self.pairs[bad_drift].name])
        if status != ENGINE_OK:
            raise_status(status, cond, pack.codes, [self.pairs[i].name for i in pack.rows], t)
        evals = [None] * k
        couple_eval = self.kernel.couple_eval
        for i in near:
            evals[i] = couple_eval(out, i)
        extra = np.array([f(q, v) for _, f in self.extra_powers], dtype=float)
        xdot[self.ie + 3:] = extra / self.energy_scale
        nqv = self.nq + self.nv
        return Evaluation(q, v, xdot[:self.nq], xdot[self.nq:nqv], xdot[nqv:self.ie], evals,
                          lam_n, lam_t, gf, fpow, p_el, p_in, np.full(k, np.nan), {},
                          Poses(R, o), extra, modes, xdot)

    def bound(self, E, i, st):
        """The travel bound of far pair i at the evaluation E, computed when a witness or an
        output asks for it (derivative evaluations do not need it): all far pairs' at once."""
        if math.isnan(E.bound[i]):
            pairs = E.modes.pairs
            if pairs[i] is not st:      # not E's own state of pair i
                return self.far.bound(i, E.poses, st)
            index = E.modes.index()
            E.bound[index.far] = self.far.bounds_of(index, pairs, E.poses)
        return E.bound[i]


def drifting(ev: PlantEvaluator, E, states) -> bool:
    """Whether a tracked couple (not in contact) of the evaluation E projected by more than
    ``drift_tol`` of its domain span: it is sought again (`Transitions.resolve`)."""
    return any(c is not None and not states[i].mode.in_contact
               and (np.abs(c.drift) / ev.spans[i]).max() > ev.options.drift_tol
               for i, c in enumerate(E.evals))
