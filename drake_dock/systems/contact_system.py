"""The rigid contact system: a Drake LeafSystem that simulates a MultibodyPlant's bodies with
the paper's contact model (Sect. 5-7): analytic couples tracked by Eq. (47), acceleration-level
constraints with Coulomb friction (Eq. 48-52) and LZB impacts (Sect. 6) triggered by witness
functions. Generic over the plant and the declared pairs; the docking scene is one user.

Design (docs/model.md, "Hybrid simulation: witness functions and modes"): the system owns the
state. A continuous-time MultibodyPlant has no constraints and no velocity jumps, so this
system holds x = [q, v, u*, energy integrals] and uses the plant as a calculator on its own
scratch context (mass matrix, force elements, Jacobians). The plant's bodies, force elements and
gravity are the model; `state` is an output in the plant's layout, so poses can be sent to
SceneGraph by MultibodyPositionToGeometryPose.

Each declared pair is in one of three states:
- ``far``: not tracked. Its last sought distance d_c and the relative pose then are kept; a
  conservative bound of the relative travel of patch 1 since then (|delta(X21 c1)| +
  |delta R21|_2 r1, c1 and r1 a bounding sphere of patch 1, |delta R21|_2 = 2 sin(theta / 2)
  for the rotation angle theta since then) is compared with a clearance; when it is reached
  the pair is sought again (Sect. 5.1). One witness serves all far pairs: the smallest
  clearance left.
- ``tracked`` (a potential contact): its couple is interior to both domains, isolated (the
  Jacobian of Eq. 40 is regular) and nearer than ``track_distance``; u* is continuous state
  integrated with Eq. (47), projected on the closest-point conditions at each evaluation (one
  Newton step; the projection is fed back with rate ``drift_feedback`` and must stay below
  ``drift_tol``). Its gap witness triggers the impact.
- ``contact``: tracked and constrained, sticking or sliding.

Documented transitions:
- gap reaches zero (tracked): LZB impact of every couple within ``impact_gap_tol`` that is
  approaching, together with the couples in contact. Zeno guard: an impact whose approach
  speed is below ``zeno_speed`` is plastic (e = 0), so that a decaying bounce sequence ends in
  persistent contact after finitely many impacts. Couples closed at the end of an impact enter
  the contact set; the others separate.
- lambda_n reaches zero, the sliding velocity reaches zero or reverses, the sticking force
  reaches the static cone: the modes of the contact set are selected again (`select_modes`).
- a couple reaches the end of its domain, or its Jacobian turns singular (Eq. 39 fails): the
  pair is sought again; if the new couple is interior and isolated the pair continues with it
  (a hand-over within the pair, only when not in contact), otherwise it becomes far (a contact
  that runs off a patch end ends there). A contact couple whose Jacobian turns singular raises
  `SingularCoupleError`.
- a pair sought while its patches cross each other (only possible past a patch end, where the
  model has no contact) stays far and is sought again after half ``track_distance`` of travel.
"""
from __future__ import annotations

import copy
import dataclasses
import math
from time import perf_counter as _perf

import numpy as np
from pydrake.common.value import AbstractValue
from pydrake.multibody.tree import JacobianWrtVariable, MultibodyForces
from pydrake.multibody.math import SpatialForce
from pydrake.systems.framework import (EventStatus, LeafSystem, UnrestrictedUpdateEvent,
                                       ValueProducer, WitnessFunctionDirection)

from drake_dock.core.constraints import (DETACH, SLIDE, STICK, ContactRow, select_modes,
                                         solve_given_modes)
from drake_dock.core.couple import (closest_point_conditions, evaluate_couple, float_pose,
                                    float_vec)
from drake_dock.core.patches import posed
from drake_dock.core.seeking import seek_couple
from drake_dock.core.tracking import SingularCoupleError
from drake_dock.errors import InputError, NumericalError, SeekingError
from drake_dock.core.lzb.solve import solve_lzb

FAR, TRACKED, CONTACT = 0, 1, 2
FAR_WITNESS = "far pairs clearance"   # the one witness of all far pairs (`_w_clear`)
STATUS_NAMES = {FAR: "far", TRACKED: "tracked", CONTACT: "contact"}
_KV = JacobianWrtVariable.kV

# Layout of each couple's output port.
COUPLE_FIELDS = (("status", 1), ("gap", 1), ("vn", 1), ("lambda_n", 1), ("lambda_t", 2),
                 ("vt", 2), ("u", 3), ("p1", 3), ("p2", 3), ("frame", 9))
COUPLE_SLICES = {}
_o = 0
for _name, _size in COUPLE_FIELDS:
    COUPLE_SLICES[_name] = slice(_o, _o + _size)
    _o += _size
COUPLE_OUTPUT_SIZE = _o
# Output status codes: 0 far, 1 tracked, 2 sliding, 3 sticking.


class DriftError(NumericalError):
    """The integrated couple drifted from the closest-point conditions beyond tolerance."""


class ZenoError(NumericalError):
    """More impacts than ``max_impacts``: an impact sequence that does not end."""


@dataclasses.dataclass
class ContactPair:
    """A declared pair: ``patch1`` (a curve) on ``frame1``, ``patch2`` (a curve for "CC", a
    surface for "CS") on ``frame2``; the couple's normal points from body 2 to body 1.
    ``sigma`` (+-1) fixes the orientation of n (Definition 2) when the scene knows it (a body
    that starts resting on a plane); by default it is taken when the pair becomes potential,
    from the side the patches are on."""

    name: str
    kind: str
    frame1: object
    patch1: object
    frame2: object
    patch2: object
    sigma: float | None = None


@dataclasses.dataclass
class ContactLaw:
    """Contact parameters shared by the pairs: friction mu (sliding) and mu_s (static), and the
    LZB parameters restitution e, stiffness K and exponent eta (Eq. 28, 36)."""

    mu: float = 0.0
    mu_s: float | None = None
    restitution: float = 0.0
    stiffness: float = 1e9
    eta: float = 1.5
    impact_law: str = "paper"


@dataclasses.dataclass
class ContactOptions:
    baumgarte: float = 20.0          # omega (rad/s) of the constraint stabilisation
    drift_feedback: float = 50.0     # 1/s, feedback of the couple projection into u*
    drift_tol: float = 1e-3          # largest projection step, relative to the domain span
    track_distance: float = 0.02     # m: nearer interior isolated couples are tracked
    reseek_floor: float = 1e-4       # m: smallest relative travel between two re-seeks
    reseek_early: float = 0.9        # far pairs are sought again at the first step start where
                                     # this fraction of their clearance is used (0: never)
    conditioning_min: float = 1e-6   # |det J| / prod(row norms) below which J is singular
    v_slip: float = 1e-6             # m/s: a couple slower than this may stick
    zeno_speed: float = 1e-3         # m/s: the Zeno guard (see the module docstring)
    impact_gap_tol: float = 1e-8     # m: couples this near join an impact
    impact_rtol: float = 1e-10       # LZB's impulse-domain integration (`solve_lzb`); the
                                     # docking diagram sets 1e-2 x the simulation accuracy
    seek_rtol: float = 1e-7          # a seek's Newton ends when a step shortens the distance
                                     # by less than this fraction, for pairs farther than
                                     # track_distance (`seek_couple`): their distance only sets
                                     # the clearance, which keeps track_distance / 2 in hand
    max_impacts: int = 10000


@dataclasses.dataclass
class PairState:
    status: int = FAR
    sigma: float = 1.0
    stick: bool = False
    slide_dir: np.ndarray | None = None
    clearance: float = 0.0
    ref_X21: tuple | None = None     # pose of frame 1 in frame 2 at the last seek
    distance: float = math.inf       # distance at the last seek


@dataclasses.dataclass
class ContactModes:
    """The abstract state: per pair status and mode, and the impact log."""

    pairs: list
    impacts: list = dataclasses.field(default_factory=list)   # dicts: t, couples, impulses
    impact_loss: float = 0.0
    mode_changes: int = 0

    def __deepcopy__(self, memo):
        """Copies that events may change: the pair states are copied (their arrays are
        replaced, never written in place); the impact log's entries are never changed once
        logged, so the log is copied as a list of the same entries (Drake clones the abstract
        state at every event; a deep copy of the growing log dominated event handling)."""
        return ContactModes([dataclasses.replace(st) for st in self.pairs], list(self.impacts),
                            self.impact_loss, self.mode_changes)


@dataclasses.dataclass
class Timing:
    """Where a run's wall time goes (cumulative, seconds; reset with `reset`): seeking (Sect. 5.1,
    the hierarchical grid and Newton, per pair with the number of seeks), contact dynamics
    (every derivative evaluation: couple tracking, Eq. 47, the constraint forces) and impacts
    (LZB and the mode selection at events). Only the declared pairs are ever searched."""

    pairs: list
    seeking: float = 0.0
    contact_dynamics: float = 0.0
    impacts: float = 0.0
    seeks: dict = dataclasses.field(default_factory=dict)

    def reset(self):
        self.seeking = self.contact_dynamics = self.impacts = 0.0
        self.seeks = {}

    def shares(self, wall_time: float) -> dict:
        """The three parts and the rest (Drake's integrator, witnesses, logging) as fractions of
        ``wall_time``, with the pairs declared and the seeks per pair."""
        parts = {"seeking": self.seeking, "contact_dynamics": self.contact_dynamics,
                 "impacts": self.impacts}
        out = {k: v / wall_time for k, v in parts.items()}
        out["other"] = max(0.0, 1.0 - sum(out.values()))
        return {"wall_time": wall_time, "shares": out, "pairs_declared": len(self.pairs),
                "seeks_per_pair": {n: self.seeks.get(n, 0) for n in self.pairs}}


@dataclasses.dataclass
class _Eval:
    q: np.ndarray
    v: np.ndarray
    qdot: np.ndarray
    vdot: np.ndarray
    udot: np.ndarray
    evals: list            # CoupleEval or None per pair
    lam_n: np.ndarray
    lam_t: np.ndarray
    contact_force: np.ndarray
    friction_power: float
    applied_power: float
    external_power: float
    bound: np.ndarray      # relative travel bound per far pair (NaN until asked: `_bound`)
    witness: dict          # witness values computed at this evaluation (`_witness`)
    poses: list
    extra_power: np.ndarray
    modes: object = None   # the ContactModes this evaluation was made with
    xdot: np.ndarray = None  # the state's time derivative


def _bounding_sphere(patch, n=41):
    pts = patch.position(patch.grid(n))
    c = 0.5 * (pts.min(axis=0) + pts.max(axis=0))
    r = float(np.linalg.norm(pts - c, axis=1).max())
    return c, 1.02 * r + 1e-9


class RigidContactSystem(LeafSystem):
    """See the module docstring. ``plant`` is a finalized continuous-time MultibodyPlant (it
    need not be part of the diagram); ``pairs`` the declared `ContactPair`s; ``wrench_bodies``
    names bodies that get an input port ``<body>_wrench`` (6-vector [torque, force], world
    frame, applied at the body origin). ``extra_powers`` is a sequence of (name, f) with
    f(q, v) -> power (W); each is integrated as continuous state and appended to the
    ``energy`` output (e.g. the power of a damper, for an energy ledger). The energy integrals
    are state in units of ``energy_scale`` (J): Drake's error control compares every state's
    absolute error with the accuracy, so that integrals in joules of a run with kJ of kinetic
    energy, not its motion, would set the step (the docking diagram passes the chaser's
    kinetic energy; the ``energy`` output is in joules)."""

    def __init__(self, plant, pairs, law: ContactLaw = ContactLaw(),
                 options: ContactOptions = ContactOptions(), wrench_bodies=(),
                 extra_powers=(), energy_scale: float = 1.0):
        super().__init__()
        if not (math.isfinite(energy_scale) and energy_scale > 0):
            raise ValueError(f"energy_scale: must be finite and > 0, got {energy_scale}")
        self.energy_scale = float(energy_scale)
        if not plant.is_finalized():
            raise ValueError("plant: must be finalized")
        if plant.time_step() != 0.0:
            raise ValueError(f"plant: must be continuous (time_step = {plant.time_step()})")
        names = [p.name for p in pairs]
        if len(set(names)) != len(names):
            raise ValueError(f"pairs: names must be unique, got {names}")
        for p in pairs:
            want = (1, 1) if p.kind == "CC" else (1, 2) if p.kind == "CS" else None
            if want is None or (p.patch1.dim, p.patch2.dim) != want:
                raise ValueError(f"pairs[{p.name}]: kind {p.kind!r} needs patch dims {want}, "
                                 f"got ({p.patch1.dim}, {p.patch2.dim})")
        self.plant = plant
        self.pairs = list(pairs)
        self.law = law
        self.options = options
        self._ctx = plant.CreateDefaultContext()
        self.nq, self.nv = plant.num_positions(), plant.num_velocities()
        self._dims = [p.patch1.dim + p.patch2.dim for p in pairs]
        self._uoff = np.concatenate([[0], np.cumsum(self._dims)]).astype(int)
        self.nu = int(self._uoff[-1])
        self._spans = [np.concatenate([p.patch1.span, p.patch2.span]) for p in pairs]
        self._periodic = [np.array(p.patch1.periodic + p.patch2.periodic) for p in pairs]
        # Per pair, (lower, upper, span) of its bounded parameters (u = (u1, u2)), in floats
        # for the domain-end witness.
        self._bounded = [[(float(lo), float(hi), float(hi - lo)) if not per else None
                          for lo, hi, per in zip(np.concatenate([p.patch1.lower, p.patch2.lower]),
                                                 np.concatenate([p.patch1.upper, p.patch2.upper]),
                                                 p.patch1.periodic + p.patch2.periodic)]
                         for p in pairs]
        self._spheres = [_bounding_sphere(p.patch1) for p in pairs]
        self._sphere_c = np.array([c for c, _ in self._spheres]).reshape(-1, 3)
        self._sphere_r = np.array([r for _, r in self._spheres])
        frames = []
        for p in pairs:
            for f in (p.frame1, p.frame2):
                if all(f is not g for g in frames):
                    frames.append(f)
        self._frames = frames
        self._fidx = [(next(i for i, g in enumerate(frames) if g is p.frame1),
                       next(i for i, g in enumerate(frames) if g is p.frame2)) for p in pairs]
        self._mu_s = law.mu if law.mu_s is None else law.mu_s

        # State: x = [q, v, u*, friction loss, work of plant forces, work of inputs,
        #             integrals of extra_powers].
        self.ie = self.nq + self.nv + self.nu
        self.extra_powers = list(extra_powers)
        self.energy_names = ["kinetic", "potential", "friction_loss", "plant_work",
                             "input_work", "impact_loss"] + [n for n, _ in self.extra_powers]
        self.DeclareContinuousState(self.ie + 3 + len(self.extra_powers))
        self._mode_index = self.DeclareAbstractState(AbstractValue.Make(
            ContactModes([PairState() for _ in pairs])))
        self._gf_port = self.DeclareVectorInputPort("generalized_force", self.nv)
        self._wrench_ports = {}
        for b in wrench_bodies:
            body = plant.GetBodyByName(b)
            self._wrench_ports[b] = (body, self.DeclareVectorInputPort(f"{b}_wrench", 6))
        self._cache = self.DeclareCacheEntry(
            "contact evaluation", ValueProducer(
                allocate=lambda: AbstractValue.Make(None), calc=self._calc_eval),
            prerequisites_of_calc={self.all_sources_ticket()})
        self.DeclareVectorOutputPort("state", self.nq + self.nv, self._out_state,
                                     prerequisites_of_calc={self.xc_ticket()})
        self.DeclareVectorOutputPort("generalized_contact_force", self.nv, self._out_gf)
        self.DeclareVectorOutputPort("energy", len(self.energy_names), self._out_energy)
        self._couple_ports = [
            self.DeclareVectorOutputPort(f"couple_{p.name}", COUPLE_OUTPUT_SIZE,
                                         lambda c, o, i=i: self._out_couple(c, o, i))
            for i, p in enumerate(pairs)]
        self.DeclareInitializationUnrestrictedUpdateEvent(
            lambda context, state: self._on_event(context, None, state))
        ev = UnrestrictedUpdateEvent(self._on_event)
        if options.reseek_early > 0:
            self.DeclarePerStepUnrestrictedUpdateEvent(self._on_step)
        down = WitnessFunctionDirection.kPositiveThenNonPositive
        self._w = []
        for i, p in enumerate(pairs):
            self._w.append({
                "gap": self.MakeWitnessFunction(f"{p.name} gap", down,
                                                lambda c, i=i: self._witness(c, i, 'gap'), ev),
                "end": self.MakeWitnessFunction(f"{p.name} domain end", down,
                                                lambda c, i=i: self._witness(c, i, 'end'), ev),
                "cond": self.MakeWitnessFunction(f"{p.name} Eq. 39", down,
                                                 lambda c, i=i: self._witness(c, i, 'cond'), ev),
                "lambda": self.MakeWitnessFunction(f"{p.name} lambda_n", down,
                                                   lambda c, i=i: self._witness(c, i, 'lambda'), ev),
                "slip": self.MakeWitnessFunction(f"{p.name} slip", down,
                                                 lambda c, i=i: self._witness(c, i, 'slip'), ev),
                "cone": self.MakeWitnessFunction(f"{p.name} friction cone", down,
                                                 lambda c, i=i: self._witness(c, i, 'cone'), ev),
                "apex": self.MakeWitnessFunction(f"{p.name} gap rate", down,
                                                 lambda c, i=i: self._witness(c, i, 'apex'), ev)})
        # One witness for all far pairs: the smallest clearance left (`_w_clear`).
        self._w_far = self.MakeWitnessFunction(FAR_WITNESS, down,
                                               lambda c: self._witness(c, None, 'clear'), ev)
        self._memo = None
        self._eval_memo = {}
        # Reused by `_free_acceleration` (never written: the first two).
        self._zero_v = np.zeros(self.nv)
        self._world = plant.world_frame()
        self._no_forces = MultibodyForces(plant)
        self._forces_fe = MultibodyForces(plant)
        self._forces_in = MultibodyForces(plant)
        self._far_cache = {}
        self.evaluations = 0
        self.timing = Timing([p.name for p in pairs])

    # ------------------------------------------------------------------ user helpers
    def SetPositionsAndVelocities(self, context, q, v):
        x = context.get_mutable_continuous_state_vector()
        xv = x.CopyToVector()
        xv[:self.nq], xv[self.nq:self.nq + self.nv] = q, v
        x.SetFromVector(xv)

    def set_from_plant_context(self, context, plant_context):
        self.SetPositionsAndVelocities(context, self.plant.GetPositions(plant_context),
                                       self.plant.GetVelocities(plant_context))

    def get_modes(self, context) -> ContactModes:
        return context.get_abstract_state(self._mode_index).get_value()

    def get_couple_output_port(self, name):
        return self._couple_ports[[p.name for p in self.pairs].index(name)]

    # ------------------------------------------------------------------ evaluation
    def _frame_kinematics(self, ctx):
        poses, twists = [], []
        for f in self._frames:
            X = f.CalcPoseInWorld(ctx)
            V = f.CalcSpatialVelocityInWorld(ctx)
            poses.append((X.rotation().matrix(), X.translation()))
            twists.append((V.rotational(), V.translational()))
        return poses, twists

    def _couple(self, i, u, poses, twists, sigma, time):
        p = self.pairs[i]
        a, b = self._fidx[i]
        ev = evaluate_couple(p.kind, p.patch1, poses[a], twists[a], p.patch2, poses[b],
                             twists[b], u, sigma)
        rel = np.abs(ev.drift) / self._spans[i]
        if rel.max() > self.options.drift_tol:
            raise DriftError(f"couple drift {rel.max():.3e} of the domain span exceeds "
                             f"drift_tol = {self.options.drift_tol:g}", time=time,
                             couples=[p.name])
        return ev

    def _row(self, i, ev, poses, ctx):
        """W^3, W^1, W^2 (Eq. 11) from Drake's point Jacobians and the bias terms (Eq. 52)."""
        p = self.pairs[i]
        a, b = self._fidx[i]
        world = self._world
        R1, o1 = poses[a]
        R2, o2 = poses[b]
        s1, s2 = (ev.p1 - o1) @ R1, (ev.p2 - o2) @ R2     # the points in their frames
        plant = self.plant
        J = (plant.CalcJacobianTranslationalVelocity(ctx, _KV, p.frame1, s1, world, world)
             - plant.CalcJacobianTranslationalVelocity(ctx, _KV, p.frame2, s2, world, world))
        ab = (plant.CalcBiasTranslationalAcceleration(ctx, _KV, p.frame1, s1, world, world)
              - plant.CalcBiasTranslationalAcceleration(ctx, _KV, p.frame2, s2, world, world))
        D = np.array([ev.n, ev.ta, ev.tb]).T          # columns n, ta, tb
        W = J.T @ D
        b = D.T @ ab.ravel()
        return ContactRow(p.name, W[:, 0], W[:, 1:], ev.bias_n + b[0], ev.bias_t + b[1:],
                          ev.gap, ev.vn, ev.vt, self.law.mu, self._mu_s)

    def _set_scratch(self, q, v):
        self.plant.SetPositions(self._ctx, q)
        self.plant.SetVelocities(self._ctx, v)
        return self._ctx

    def _free_acceleration(self, context, ctx, v):
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
        if self._gf_port.HasValue(context):
            tau_in += self._gf_port.Eval(context)
        wf, any_in = self._forces_in, False
        for body, port in self._wrench_ports.values():
            if port.HasValue(context):
                w = port.Eval(context)
                if not any_in:
                    wf.SetZero()
                body.AddInForce(ctx, np.zeros(3), SpatialForce(w[:3], w[3:]),
                                self.plant.world_frame(), wf)
                any_in = True
        if any_in:
            tau_in += bias - ID(ctx, zero, wf)
        M = self.plant.CalcMassMatrix(ctx)
        Minv = np.linalg.inv(M)
        return M, Minv, Minv @ (tau_el + tau_in - bias), float(tau_el @ v), float(tau_in @ v)

    #: evaluations kept for reuse (see `_calc_eval`)
    eval_memo_size = 16

    def _eval_key(self, context):
        """Everything an evaluation depends on: time, the continuous state (the bodies' and the
        tracked couples' u*; a far pair's u* and its far-pair data are not used), the modes of
        the pairs that are not far, and the inputs."""
        modes = self.get_modes(context)
        x = context.get_continuous_state_vector().CopyToVector()[:self.ie]
        base = self.nq + self.nv
        sig = []
        for i, st in enumerate(modes.pairs):
            if st.status == FAR:
                x[base + self._uoff[i]:base + self._uoff[i + 1]] = 0.0
            else:
                sig.append((i, st.status, st.sigma, st.stick, None if st.slide_dir is None
                            else np.asarray(st.slide_dir, dtype=float).tobytes()))
        key = [context.get_time(), x.tobytes(), tuple(sig)]
        if self._gf_port.HasValue(context):
            key.append(self._gf_port.Eval(context).tobytes())
        for _, port in self._wrench_ports.values():
            if port.HasValue(context):
                key.append(port.Eval(context).tobytes())
        return tuple(key), modes

    def _calc_eval(self, context, value):
        """Drake's cache recomputes an evaluation whenever the context's state is written, even
        with the same values (the integrator restores a step's initial state before the step,
        and the witness isolation restores it before each re-integration): about a quarter of
        the requests in the docking example. The last few evaluations are kept by their full
        dependencies (`_eval_key`) and reused; one reused under other modes (a far pair sought
        again at a step start changes only far-pair data) gets those modes and fresh far-pair
        bounds and witness values."""
        t0 = _perf()
        try:
            key, modes = self._eval_key(context)
            hit = self._eval_memo.get(key)
            if hit is not None:
                if hit.modes is not modes:
                    hit = dataclasses.replace(hit, modes=modes, witness={},
                                              bound=np.full(len(self.pairs), np.nan))
                    self._eval_memo[key] = hit
                value.set_value(hit)
                return
            self._calc_eval_timed(context, value)
            if len(self._eval_memo) >= self.eval_memo_size:
                self._eval_memo.pop(next(iter(self._eval_memo)))
            self._eval_memo[key] = value.get_value()
        finally:
            self.timing.contact_dynamics += _perf() - t0

    def _calc_eval_timed(self, context, value):
        self.evaluations += 1
        t = context.get_time()
        x = context.get_continuous_state_vector().CopyToVector()
        q, v, u = x[:self.nq], x[self.nq:self.nq + self.nv], x[self.nq + self.nv:self.ie]
        modes = self.get_modes(context)
        ctx = self._set_scratch(q, v)
        poses, twists = self._frame_kinematics(ctx)
        # The couples work in plain floats: the frames' poses and twists converted once.
        fposes = [float_pose(X) for X in poses]
        ftwists = [(float_vec(w), float_vec(v)) for w, v in twists]
        k = len(self.pairs)
        evals = [None] * k
        udot = np.zeros(self.nu)
        bound = np.full(k, np.nan)
        rows, row_pairs, smodes, dirs = [], [], [], []
        for i, st in enumerate(modes.pairs):
            sl = slice(self._uoff[i], self._uoff[i + 1])
            if st.status == FAR:
                continue
            ev = self._couple(i, u[sl], fposes, ftwists, st.sigma, t)
            evals[i] = ev
            udot[sl] = ev.udot + self.options.drift_feedback * ev.drift
            if st.status == CONTACT:
                rows.append(self._row(i, ev, poses, ctx))
                row_pairs.append(i)
                if st.stick:
                    smodes.append(STICK)
                    dirs.append(None)
                else:
                    smodes.append(SLIDE)
                    s = math.hypot(*ev.vt)
                    dirs.append(ev.vt / s if s > self.options.v_slip or st.slide_dir is None
                                else st.slide_dir)
        M, Minv, a0, p_plant, p_in = self._free_acceleration(context, ctx, v)
        sol = solve_given_modes(Minv, a0, rows, smodes, dirs, omega=self.options.baumgarte,
                                time=t)
        lam_n, lam_t = np.zeros(k), np.zeros((k, 2))
        for j, i in enumerate(row_pairs):
            lam_n[i], lam_t[i] = sol.lam_n[j], sol.lam_t[j]
        qdot = self.plant.MapVelocityToQDot(ctx, v)
        E = _Eval(q, v, qdot, sol.vdot, udot, evals, lam_n, lam_t, sol.generalized_force,
                  sol.power_lost_to_friction(rows), p_plant, p_in, bound, {}, poses,
                  np.array([f(q, v) for _, f in self.extra_powers], dtype=float), modes)
        E.xdot = np.concatenate([qdot, E.vdot, udot, np.array(
            [E.friction_power, E.applied_power, E.external_power, *E.extra_power])
            / self.energy_scale])
        value.set_value(E)

    def _travel_bounds(self, idx, poses, pairs):
        """Travel bounds of the far pairs ``idx`` (their states in ``pairs``) at ``poses``, at
        once: |delta(X21 c1)| + |delta R21|_2 r1 (module docstring), inf for a pair never
        sought."""
        out = np.full(len(idx), math.inf)
        known = [k for k, i in enumerate(idx) if pairs[i].ref_X21 is not None]
        if not known:
            return out
        ids = [idx[k] for k in known]
        rel = {}
        for i in ids:
            ab = self._fidx[i]
            if ab not in rel:
                (R1, p1), (R2, p2) = poses[ab[0]], poses[ab[1]]
                rel[ab] = (R2.T @ R1, R2.T @ (p1 - p2))
        R21 = np.array([rel[self._fidx[i]][0] for i in ids])
        p21 = np.array([rel[self._fidx[i]][1] for i in ids])
        R0 = np.array([pairs[i].ref_X21[0] for i in ids])
        p0 = np.array([pairs[i].ref_X21[1] for i in ids])
        lin = np.einsum("kij,kj->ki", R21 - R0, self._sphere_c[ids]) + p21 - p0
        # |R21 - R0|_2 = |R0^T R21 - I|_2 = 2 sin(theta / 2) = sqrt(3 - tr(R0^T R21)).
        rot = np.sqrt(np.maximum(3.0 - np.einsum("kij,kij->k", R0, R21), 0.0))
        out[known] = np.sqrt(np.einsum("ki,ki->k", lin, lin)) + rot * self._sphere_r[ids]
        return out

    def _travel_bound(self, i, poses, st):
        pairs = [None] * len(self.pairs)
        pairs[i] = st
        return float(self._travel_bounds([i], poses, pairs)[0])

    def _bound(self, E, i, st):
        """The travel bound of far pair i at the evaluation E, computed when a witness or an
        output asks for it (derivative evaluations do not need it): all far pairs' at once."""
        if math.isnan(E.bound[i]):
            pairs = E.modes.pairs
            idx = [k for k, sk in enumerate(pairs) if sk.status == FAR and math.isnan(E.bound[k])]
            if pairs[i] is not st:      # not E's own state of pair i
                return self._travel_bound(i, E.poses, st)
            E.bound[idx] = self._travel_bounds(idx, E.poses, pairs)
        return E.bound[i]

    def eval(self, context) -> _Eval:
        return self._cache.Eval(context)

    def DoCalcTimeDerivatives(self, context, derivatives):
        derivatives.get_mutable_vector().SetFromVector(self._cache.Eval(context).xdot)

    # ------------------------------------------------------------------ outputs
    def _out_state(self, context, out):
        out.SetFromVector(context.get_continuous_state_vector().CopyToVector()[:self.nq + self.nv])

    def _out_gf(self, context, out):
        out.SetFromVector(self._cache.Eval(context).contact_force)

    def _out_energy(self, context, out):
        """[kinetic, potential (plant elements that implement it), friction loss, work of the
        plant's forces, work of the inputs, impact loss, integrals of extra_powers]
        (`energy_names`)."""
        E = self._cache.Eval(context)
        x = context.get_continuous_state_vector().CopyToVector()
        ctx = self._set_scratch(E.q, E.v)
        ke = 0.5 * E.v @ self.plant.CalcMassMatrix(ctx) @ E.v
        try:
            pe = self.plant.CalcPotentialEnergy(ctx)
        except RuntimeError:
            pe = math.nan
        w = x[self.ie:] * self.energy_scale
        out.SetFromVector(np.concatenate([[ke, pe, w[0], w[1], w[2],
                                           self.get_modes(context).impact_loss], w[3:]]))

    def _out_couple(self, context, out, i):
        y = np.zeros(COUPLE_OUTPUT_SIZE)
        self._couple_row(y, context.get_continuous_state_vector().CopyToVector(),
                         self._cache.Eval(context), self.get_modes(context).pairs[i], i)
        out.SetFromVector(y)

    def couple_table(self, context) -> np.ndarray:
        """All couples' outputs at once, row i the value of port ``couple_<pairs[i].name>``
        (for loggers: one call instead of one port evaluation per couple)."""
        E = self._cache.Eval(context)
        x = context.get_continuous_state_vector().CopyToVector()
        Y = np.zeros((len(self.pairs), COUPLE_OUTPUT_SIZE))
        for i, st in enumerate(self.get_modes(context).pairs):
            self._couple_row(Y[i], x, E, st, i)
        return Y

    _EYE = np.eye(3).ravel()

    def _couple_row(self, y, x, E, st, i):
        """Fills the zeroed row y of pair i (state x, evaluation E, pair state st)."""
        ev = E.evals[i]
        S = COUPLE_SLICES
        if ev is None:
            a, b = self._fidx[i]
            u = x[self.nq + self.nv + self._uoff[i]:self.nq + self.nv + self._uoff[i + 1]]
            y[S["gap"]] = st.distance - self._bound(E, i, st)
            y[S["u"]][:len(u)] = u
            r1, r2 = self._far_points(i, u)
            y[S["p1"]] = E.poses[a][0] @ r1 + E.poses[a][1]
            y[S["p2"]] = E.poses[b][0] @ r2 + E.poses[b][1]
            y[S["frame"]] = self._EYE
        else:
            y[S["status"]] = st.status + (1 if st.status == CONTACT and st.stick else 0)
            y[S["gap"]], y[S["vn"]] = ev.gap, ev.vn
            y[S["lambda_n"]], y[S["lambda_t"]] = E.lam_n[i], E.lam_t[i]
            y[S["vt"]] = ev.vt
            y[S["u"]][:len(ev.u)] = ev.u
            y[S["p1"]], y[S["p2"]] = ev.p1, ev.p2
            frame = y[S["frame"]].reshape(3, 3)     # columns ta, tb, n (CoupleEval.frame)
            frame[:, 0], frame[:, 1], frame[:, 2] = ev.ta, ev.tb, ev.n

    def _far_points(self, i, u):
        """The points of far pair i's last sought couple in the two body frames (they change
        only when the pair is sought again)."""
        key = u.tobytes()
        hit = self._far_cache.get(i)
        if hit is None or hit[0] != key:
            p = self.pairs[i]
            n1 = p.patch1.dim
            hit = self._far_cache[i] = (
                key, np.array(p.patch1.jet([float(c) for c in u[:n1]])[0]),
                np.array(p.patch2.jet([float(c) for c in u[n1:]])[0]))
        return hit[1], hit[2]

    # ------------------------------------------------------------------ witnesses
    def DoGetWitnessFunctions(self, context):
        out = []
        pairs = self.get_modes(context).pairs
        if any(st.status == FAR for st in pairs):
            out.append(self._w_far)
        for i, st in enumerate(pairs):
            w = self._w[i]
            if st.status == FAR:
                continue
            out += [w["end"], w["cond"]]
            if st.status == TRACKED:
                out += [w["gap"], w["apex"]]
            else:
                out += [w["lambda"], w["cone"] if st.stick else w["slip"]]
        return out

    _W_FUNCS = {"gap": "_w_gap", "end": "_w_end", "cond": "_w_cond", "lambda": "_w_lambda",
                "slip": "_w_slip", "cone": "_w_cone", "apex": "_w_apex", "clear": "_w_clear"}

    def witness_values(self, context) -> dict:
        """The values of the witnesses `DoGetWitnessFunctions` returns now, by description
        (used by `drake_dock.systems.stepping.WitnessApproach` to predict their zeros)."""
        out = {}
        pairs = self.get_modes(context).pairs
        if any(st.status == FAR for st in pairs):
            out[FAR_WITNESS] = self._witness(context, None, "clear")
        for i, st in enumerate(pairs):
            if st.status == FAR:
                continue
            elif st.status == TRACKED:
                kinds = ("end", "cond", "gap", "apex")
            else:
                kinds = ("end", "cond", "lambda", "cone" if st.stick else "slip")
            for k in kinds:
                out[f"{self.pairs[i].name} {k}"] = self._witness(context, i, k)
        return out

    def witness_rates(self, context) -> dict:
        """Time derivatives of the gap witnesses of the tracked couples, by description:
        g' = v_n (for `drake_dock.systems.stepping.WitnessApproach`)."""
        out = {}
        E = None
        for i, st in enumerate(self.get_modes(context).pairs):
            if st.status == TRACKED:
                E = E or self._cache.Eval(context)
                out[f"{self.pairs[i].name} gap"] = E.evals[i].vn
        return out

    def witness_second_rates(self, context, names) -> dict:
        """Second time derivatives of the gap witnesses ``names`` (of tracked couples), g'' =
        W^3 . v' + b_n (Eq. 52) at the evaluation's accelerations: a couple leaving an impact
        has no history in the new epoch from which `WitnessApproach` could predict its
        landing."""
        E = self._cache.Eval(context)
        ctx = self._set_scratch(E.q, E.v)
        out = {}
        for i, p in enumerate(self.pairs):
            if f"{p.name} gap" in names and E.evals[i] is not None:
                row = self._row(i, E.evals[i], E.poses, ctx)
                out[f"{p.name} gap"] = float(row.Wn @ E.vdot + row.bn)
        return out

    def witness_epoch(self, context) -> int:
        """Changes whenever an event has changed the state or the modes (a witness's history
        from before it is not continued by its values after it)."""
        return self.get_modes(context).mode_changes

    def _witness(self, context, i, kind):
        """The value of witness ``kind`` of pair i, kept on the evaluation (Drake evaluates
        every witness at both ends of every step, and `WitnessApproach` asks for them again:
        each is computed once per evaluation)."""
        E = self._cache.Eval(context)
        key = (i, kind)
        w = E.witness.get(key)
        if w is None:
            w = E.witness[key] = float(getattr(self, self._W_FUNCS[kind])(
                E, None if i is None else self.get_modes(context).pairs[i], i))
        return w

    def _w_gap(self, E, st, i):
        ev = E.evals[i]
        return 1.0 if ev is None else ev.gap

    def _w_apex(self, E, st, i):
        """The gap rate while the gap is not positive, else 1. Just after an impact the gap is
        at or below zero (the impact is isolated to within Drake's window), so the gap witness
        cannot trigger; a couple that closes again before its gap has become positive would be
        missed. This witness triggers if it turns back (v_n reaches zero) while the gap is still
        not positive. Once the gap is positive the gap witness takes over: the value jumps from
        v_n > 0 to 1 (no trigger) on the way out, and from 1 to v_n < 0 on the way back, at the
        gap's zero, together with the gap witness. (A rate witness active at every bounce's apex
        would cost an isolated event each.)"""
        ev = E.evals[i]
        return 1.0 if ev is None or ev.gap > 0.0 else ev.vn

    def _w_end(self, E, st, i):
        ev = E.evals[i]
        if ev is None:
            return 1.0
        # The smallest margin of a bounded parameter to its domain's ends, relative to the
        # span (periodic parameters have none).
        w = math.inf
        for a, b in zip(ev.u.tolist(), self._bounded[i]):
            if b is not None:
                w = min(w, (a - b[0]) / b[2], (b[1] - a) / b[2])
        return w

    def _w_cond(self, E, st, i):
        ev = E.evals[i]
        return 1.0 if ev is None else ev.conditioning - self.options.conditioning_min

    def _w_lambda(self, E, st, i):
        return E.lam_n[i] if st.status == CONTACT else 1.0

    def _w_slip(self, E, st, i):
        ev = E.evals[i]
        if st.status != CONTACT or st.stick or ev is None or st.slide_dir is None:
            return 1.0
        return ev.vt @ st.slide_dir

    def _w_cone(self, E, st, i):
        if st.status != CONTACT or not st.stick:
            return 1.0
        return self._mu_s * E.lam_n[i] - math.hypot(*E.lam_t[i])

    def _w_clear(self, E, st, i):
        """All far pairs' witness: the smallest clearance left, min (clearance - travel bound)
        (1 if no pair is far). Its event seeks again every far pair whose clearance is used up
        (`_resolve`)."""
        w = math.inf
        for k, sk in enumerate(E.modes.pairs):
            if sk.status == FAR:
                w = min(w, sk.clearance - self._bound(E, k, sk))
        return 1.0 if w == math.inf else w

    # ------------------------------------------------------------------ events
    def _on_step(self, context, state):
        """Per-step event: far pairs whose travel bound has used ``reseek_early`` of their
        clearance are sought again at the start of this step (with every other transition due,
        as at a witness event). The clearance witness stays the guarantee; sought a little
        early, a pair needs no isolated event (each cost about 30 derivative evaluations)."""
        modes = self.get_modes(context)
        E = self._cache.Eval(context)
        early = self.options.reseek_early
        if not any(st.status == FAR and st.ref_X21 is not None
                   and self._bound(E, i, st) >= early * st.clearance
                   for i, st in enumerate(modes.pairs)):
            return EventStatus.DidNothing()
        return self._on_event(context, None, state, early=early)

    def _on_event(self, context, event, state, early=1.0):
        x = context.get_continuous_state_vector().CopyToVector()
        key = (context.get_time(), x.tobytes(), self.get_modes(context).mode_changes)
        if self._memo is None or self._memo[0] != key:
            self._memo = (key,) + self._resolve(context, x, early)
        _, x_new, modes_new = self._memo
        state.get_mutable_continuous_state().get_mutable_vector().SetFromVector(x_new)
        state.get_mutable_abstract_state(self._mode_index).set_value(copy.deepcopy(modes_new))
        return EventStatus.Succeeded()

    def _seek(self, i, poses, modes, u, time, was_contact, initial=False):
        """Sect. 5.1 for pair i, and the status that follows (module docstring). At the
        initial seek a pair with a declared ``sigma`` whose couple lies on the wrong side by
        more than ``impact_gap_tol`` is refused: the bodies start interpenetrating."""
        t0 = _perf()
        try:
            self._seek_timed(i, poses, modes, u, time, was_contact, initial)
        finally:
            self.timing.seeking += _perf() - t0
            name = self.pairs[i].name
            self.timing.seeks[name] = self.timing.seeks.get(name, 0) + 1

    def _seek_timed(self, i, poses, modes, u, time, was_contact, initial):
        p = self.pairs[i]
        a, b = self._fidx[i]
        st = modes.pairs[i]
        P1, P2 = posed(p.patch1, *poses[a]), posed(p.patch2, *poses[b])
        try:
            c = seek_couple(P1, P2, distance_rtol=self.options.seek_rtol,
                            rtol_beyond=self.options.track_distance)
        except SeekingError as e:
            raise SeekingError(str(e), time=time, couples=[p.name]) from None
        R1, p1 = poses[a]
        R2, p2 = poses[b]
        st.ref_X21 = (R2.T @ R1, R2.T @ (p1 - p2))
        st.distance = c.distance
        _, _, cond = closest_point_conditions(p.kind, p.patch1, poses[a], p.patch2, poses[b],
                                              c.u, conditioning=True)
        isolated = cond > 10 * self.options.conditioning_min
        sl = slice(self._uoff[i], self._uoff[i + 1])
        uc = c.u
        if c.interior and isolated:
            # Finish on the contact form (the distance's gradient is flat at a tangent touch).
            for _ in range(20):
                F, Fu = closest_point_conditions(p.kind, p.patch1, poses[a], p.patch2,
                                                 poses[b], uc)
                uc = uc - np.linalg.solve(Fu, F)
                if np.abs(F).max() <= 1e-15 * (1.0 + np.abs(Fu).max()):
                    break
        u[sl] = uc
        opt = self.options
        crossing = False
        if c.interior and isolated:
            ev = evaluate_couple(p.kind, p.patch1, poses[a], (np.zeros(3),) * 2, p.patch2,
                                 poses[b], (np.zeros(3),) * 2, uc, 1.0, project=False)
            sigma = p.sigma if p.sigma is not None else (1.0 if ev.gap >= 0.0 else -1.0)
            # The patches cross each other (the contact-form couple is not the closest one,
            # or lies on the wrong side of a declared normal): past a patch end, where the
            # model has no contact. Such a pair is not made potential.
            crossing = (abs(ev.gap) > c.distance + opt.impact_gap_tol
                        or sigma * ev.gap < -opt.impact_gap_tol)
            if initial and p.sigma is not None and (sigma * ev.gap < -opt.impact_gap_tol or (
                    crossing and c.distance <= opt.impact_gap_tol)):
                # The scene declares the sides: a couple on the wrong side, or patches that
                # intersect, is a body started inside another.
                value = (f"signed gap {sigma * ev.gap:.6g} m" if sigma * ev.gap < 0.0
                         else f"patches intersecting (distance {c.distance:.3g} m)")
                raise InputError(f"initial state of pair {p.name}", value,
                                 f"signed gap >= -impact_gap_tol = {-opt.impact_gap_tol:g} m",
                                 "the bodies start interpenetrating")
        if c.interior and isolated and not crossing and c.distance < opt.track_distance \
                and not was_contact:
            st.sigma = sigma
            st.status = TRACKED
        else:
            st.status = FAR
            if crossing:
                st.clearance = 0.5 * opt.track_distance
            elif c.distance >= opt.track_distance:
                st.clearance = max(c.distance - 0.5 * opt.track_distance, 0.5 * c.distance,
                                   opt.reseek_floor)
            else:
                st.clearance = max(0.5 * c.distance, opt.reseek_floor)
        st.stick, st.slide_dir = False, None

    def _resolve(self, context, x, early=1.0):
        """All the transitions due at this state (module docstring); returns (x, modes). Far
        pairs are sought again when their travel bound reaches ``early`` x their clearance."""
        t = context.get_time()
        opt = self.options
        modes = copy.deepcopy(self.get_modes(context))
        modes.mode_changes += 1
        q = x[:self.nq]
        v = x[self.nq:self.nq + self.nv].copy()
        u = x[self.nq + self.nv:self.ie].copy()
        ctx = self._set_scratch(q, v)
        poses, twists = self._frame_kinematics(ctx)
        initial = all(st.ref_X21 is None and st.status == FAR for st in modes.pairs)
        # 1. Seeking: at initialisation, for far pairs whose clearance is used up, and for
        #    couples at a domain end or with a singular Jacobian.
        for i, st in enumerate(modes.pairs):
            sl = slice(self._uoff[i], self._uoff[i + 1])
            if initial or (st.status == FAR and self._travel_bound(i, poses, st)
                           >= early * st.clearance):
                self._seek(i, poses, modes, u, t, False, initial)
                continue
            if st.status == FAR:
                continue
            ev = evaluate_couple(self.pairs[i].kind, self.pairs[i].patch1,
                                 poses[self._fidx[i][0]], twists[self._fidx[i][0]],
                                 self.pairs[i].patch2, poses[self._fidx[i][1]],
                                 twists[self._fidx[i][1]], u[sl], st.sigma)
            u[sl] = ev.u
            p = self.pairs[i]
            margin = np.concatenate([p.patch1.margin(ev.u[:p.patch1.dim]),
                                     p.patch2.margin(ev.u[p.patch1.dim:])]) / self._spans[i]
            if ev.conditioning <= opt.conditioning_min and st.status == CONTACT:
                raise SingularCoupleError(
                    f"the Jacobian of a couple in contact turned singular (Eq. 39 fails; "
                    f"conditioning {ev.conditioning:.2e})", time=t, couples=[p.name])
            if margin.min() <= 0.0 or ev.conditioning <= opt.conditioning_min:
                self._seek(i, poses, modes, u, t, st.status == CONTACT)
        # 2. Impacts and 3. modes.
        n_impacts = len(modes.impacts)
        v = self._impacts_and_modes(context, t, modes, ctx, poses, twists, q, v, u)
        x_new = x.copy()
        x_new[self.nq:self.nq + self.nv] = v
        x_new[self.nq + self.nv:self.ie] = u
        if len(modes.impacts) > n_impacts:
            # The states just before and just after the impact (for loggers: a step-end
            # sample is the state before; this event's result is not seen by any step end).
            modes.impacts[-1].update(x_minus=x.copy(), x_plus=x_new.copy(),
                                     pairs_plus=copy.deepcopy(modes.pairs),
                                     impact_loss_plus=modes.impact_loss)
        return x_new, modes

    def _impacts_and_modes(self, *args):
        t0 = _perf()
        try:
            return self._impacts_and_modes_timed(*args)
        finally:
            self.timing.impacts += _perf() - t0

    def _impacts_and_modes_timed(self, context, t, modes, ctx, poses, twists, q, v, u):
        opt = self.options
        evs = {}

        def evaluate_all(v):
            self._set_scratch(q, v)
            ps, tw = self._frame_kinematics(ctx)
            for i, st in enumerate(modes.pairs):
                if st.status != FAR:
                    sl = slice(self._uoff[i], self._uoff[i + 1])
                    evs[i] = self._couple(i, u[sl], ps, tw, st.sigma, t)
            return ps

        # Modes the contact couples are leaving (their witness crossed zero): lambda_n, or
        # the sticking force reaching the static cone.
        leaving = {}
        if any(st.status == CONTACT for st in modes.pairs):
            E = self._cache.Eval(context)
            for i, st in enumerate(modes.pairs):
                if st.status == CONTACT:
                    out = []
                    if E.lam_n[i] <= 0.0:
                        out += [STICK, SLIDE]
                    if st.stick and self._mu_s * E.lam_n[i] - math.hypot(*E.lam_t[i]) <= 0.0:
                        out.append(STICK)
                    leaving[i] = tuple(out)
        poses = evaluate_all(v)
        M = self.plant.CalcMassMatrix(ctx)
        hit = [i for i, st in enumerate(modes.pairs) if st.status == TRACKED
               and evs[i].gap <= opt.impact_gap_tol and evs[i].vn < 0.0]
        candidates = set()
        if hit:
            if len(modes.impacts) >= opt.max_impacts:
                raise ZenoError(f"more than max_impacts = {opt.max_impacts} impacts",
                                time=t, couples=[self.pairs[i].name for i in hit])
            # The impact set: the couples hit and those in contact that are not separating
            # beyond round-off (1e-6 of the approach, the same test as after the impact).
            closing = -min(evs[i].vn for i in hit)
            S = hit + [i for i, st in enumerate(modes.pairs)
                       if st.status == CONTACT and i not in hit
                       and evs[i].vn <= 1e-6 * closing]
            rows = [self._row(i, evs[i], poses, ctx) for i in S]
            Wn = np.column_stack([r.Wn for r in rows])
            Wt = np.column_stack([r.Wt for r in rows])
            law = self.law
            approach = float(-min(r.vn for r in rows))
            # Zeno guard: an impact slower than zeno_speed is plastic.
            e = law.restitution if approach >= opt.zeno_speed else 0.0
            try:
                res = solve_lzb(M, Wn, v, law.stiffness, law.eta, e, Wt=Wt,
                                mu=law.mu, mu_s=self._mu_s, law=law.impact_law,
                                rtol=opt.impact_rtol)
            except NumericalError as err:
                import os
                if os.environ.get("DRAKE_DOCK_DUMP_LZB"):
                    np.savez(os.environ["DRAKE_DOCK_DUMP_LZB"], M=M, Wn=Wn, Wt=Wt, v=v, e=e)
                raise NumericalError(f"{err} (approach speed {approach:.3e} m/s)", time=t,
                                     couples=[self.pairs[i].name for i in S]) from None
            v = res.v_plus
            modes.impacts.append({"t": t, "couples": [self.pairs[i].name for i in S],
                                  "restitution": e,
                                  "normal_impulse": res.normal_impulse.tolist(),
                                  "tangential_impulse": res.tangential_impulse.tolist(),
                                  "energy_lost": res.kinetic_energy_minus
                                  - res.kinetic_energy_plus})
            modes.impact_loss += res.kinetic_energy_minus - res.kinetic_energy_plus
            vn_plus = Wn.T @ v
            for i, vn in zip(S, vn_plus):
                if vn <= 1e-6 * approach:
                    candidates.add(i)      # closed at the end of the impact: in contact
                else:
                    st = modes.pairs[i]    # separating
                    st.status, st.stick, st.slide_dir = TRACKED, False, None
            poses = evaluate_all(v)
        # Contact set: couples in contact, couples just held by the Zeno guard and resting
        # couples (closed and not moving apart).
        for i, st in enumerate(modes.pairs):
            if st.status == CONTACT and hit and i not in candidates:
                st.status, st.stick, st.slide_dir = TRACKED, False, None   # separating
            if (st.status == CONTACT and not (hit and i not in candidates)) or (
                    st.status == TRACKED and evs[i].gap <= opt.impact_gap_tol
                    and abs(evs[i].vn) <= opt.v_slip):
                candidates.add(i)
        cand = sorted(candidates)
        self._set_scratch(q, v)
        rows = [self._row(i, evs[i], poses, ctx) for i in cand]
        M, Minv, a0, _, _ = self._free_acceleration(context, ctx, v)
        sol = select_modes(Minv, a0, rows, v_slip=opt.v_slip, omega=opt.baumgarte, time=t,
                           avoid=[() if hit else leaving.get(i, ()) for i in cand])
        cons = []
        for j, i in enumerate(cand):
            st = modes.pairs[i]
            m = sol.modes[j]
            if m == DETACH:
                st.status, st.stick, st.slide_dir = TRACKED, False, None
            else:
                st.status = CONTACT
                st.stick = m == STICK
                st.slide_dir = None if st.stick else np.asarray(sol.dirs[j], dtype=float)
                cons.append(rows[j].Wn)
                if st.stick:
                    cons += [rows[j].Wt[:, 0], rows[j].Wt[:, 1]]
        if cons:
            # Velocity projection onto the constraints of the new modes (W^T v = 0 for the
            # closed couples, and their tangential rows when sticking): the mode is entered at
            # a witness's zero, located to within the integrator's accuracy, and the residual
            # relative velocity (below v_slip or the impact tolerance) is removed by the
            # M-orthogonal projection, the smallest change of kinetic energy. The energy it
            # removes (of the order of the residual squared) is booked with the impacts.
            C = np.column_stack(cons)
            r = C.T @ v
            if np.abs(r).max() > 0.0:
                MinvC = Minv @ C
                dv = -MinvC @ np.linalg.lstsq(C.T @ MinvC, r, rcond=1e-10)[0]
                ke0 = 0.5 * v @ M @ v
                v = v + dv
                modes.impact_loss += ke0 - 0.5 * v @ M @ v
        return v
