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

Each declared pair is in one `Mode` (`drake_dock.core.hybrid`; its value is the status code of
the couple's output port):
- FAR (0): not tracked. Its last sought distance d_c and the relative pose then are kept; a
  conservative bound of the relative travel of patch 1 since then (|delta(X21 c1)| +
  |delta R21|_2 r1, c1 and r1 a bounding sphere of patch 1, |delta R21|_2 = 2 sin(theta / 2)
  for the rotation angle theta since then) is compared with a clearance; when it is reached
  the pair is sought again (Sect. 5.1). One witness serves all far pairs: the smallest
  clearance left.
- TRACKED (1, a potential contact): its couple is interior to both domains, isolated (the
  Jacobian of Eq. 40 is regular) and nearer than ``track_distance``; u* is continuous state
  integrated with Eq. (47), projected on the closest-point conditions at each evaluation (one
  Newton step; the projection is fed back with rate ``drift_feedback`` and must stay below
  ``drift_tol``). Its gap witness triggers the impact.
- SLIDING (2) or STICKING (3): in contact, constrained (Eq. 48-51).

Transitions, each triggered by a witness of the table `drake_dock.systems.witnesses` and
decided by a function of `drake_dock.core.hybrid`:
- gap reaches zero (TRACKED): LZB impact of every couple within ``impact_gap_tol`` that is
  approaching, together with the couples in contact that are not separating. Zeno guard: an impact whose approach
  speed is below ``zeno_speed`` is plastic (e = 0), so that a decaying bounce sequence ends in
  persistent contact after finitely many impacts. Couples closed at the end of an impact enter
  the contact set; the others, and the couples in contact left out of the impact, are TRACKED.
- lambda_n reaches zero, the sliding velocity reaches zero or reverses, the sticking force
  reaches the static cone: the modes of the contact set are selected again (`select_contact_modes`).
- a couple reaches a declared edge of its surface, or an edge couple's hand-over guard
  reaches zero (its curve passes over the surface): the couple is handed to the linked pair
  with its mode (`Handover`, `drake_dock.core.handover`; docs/model.md, "Hand-over between an
  edge and a surface");
- a couple reaches any other end of its domain, or its Jacobian turns singular (Eq. 39
  fails): the pair is sought again; if the new couple is interior and isolated the pair
  continues with it (a hand-over within the pair, only when not in contact), otherwise it
  becomes far (a contact that runs off a patch end ends there). A contact couple whose Jacobian turns singular raises
  `SingularCoupleError`.
- a pair sought while its patches cross each other (only possible past a patch end, where the
  model has no contact) stays far and is sought again after half ``track_distance`` of travel.

The parts: `contact_types` (pairs, options, pair state, one evaluation, the port layout),
`evaluation` (one evaluation with the plant as calculator), `transitions` (the events),
`witnesses` (the witness table), `far_pairs` (travel bounds), `outputs` (couple ports), `memo`
and `profiling`.
"""
from __future__ import annotations

import copy
import math
from time import perf_counter

import numpy as np
from pydrake.common.value import AbstractValue
from pydrake.systems.framework import (EventStatus, LeafSystem, UnrestrictedUpdateEvent,
                                       ValueProducer)

from drake_dock.core.contact_law import ContactLaw
from drake_dock.core.hybrid import Mode
from drake_dock.core.kernels import model as K
from drake_dock.core.relations import relation
from drake_dock.errors import (DriftError, InputError, NumericalError, SingularCoupleError,
                               ZenoError)
from drake_dock.systems import witnesses
from drake_dock.systems.contact_types import (COUPLE_FIELDS, COUPLE_OUTPUT_SIZE, COUPLE_SLICES,
                                              ContactModes, ContactOptions, ContactPair,
                                              Handover, PairState)
from drake_dock.systems.engine import Engine, frame_list
from drake_dock.systems.evaluation import Evaluation
from drake_dock.systems.far_pairs import FarPairs
from drake_dock.systems.handover_links import HandoverLinks
from drake_dock.systems.memo import Memo
from drake_dock.systems.profiling import Timing
from drake_dock.systems.reseek import reseek_far
from drake_dock.systems.transitions import Transitions
from drake_dock.systems.witness_source import WitnessPredictions
from drake_dock.systems.witnesses import FAR_WITNESS, WitnessFunctions

__all__ = ["COUPLE_FIELDS", "COUPLE_OUTPUT_SIZE", "COUPLE_SLICES", "FAR_WITNESS", "ContactLaw",
           "ContactModes", "ContactOptions", "ContactPair", "DriftError", "Handover", "Mode",
           "PairState", "RigidContactSystem", "Timing", "ZenoError", "check_pairs"]


def check_pairs(plant, pairs, energy_scale):
    """Checks the system's arguments: a ValueError names the argument and what it must be."""
    if not (math.isfinite(energy_scale) and energy_scale > 0):
        raise ValueError(f"energy_scale: must be finite and > 0, got {energy_scale}")
    if not plant.is_finalized():
        raise ValueError("plant: must be finalized")
    if plant.time_step() != 0.0:
        raise ValueError(f"plant: must be continuous (time_step = {plant.time_step()})")
    names = [p.name for p in pairs]
    if len(set(names)) != len(names):
        raise ValueError(f"pairs: names must be unique, got {names}")
    for p in pairs:
        try:
            want = relation(p.kind).dims
        except ValueError as e:
            raise ValueError(f"pairs[{p.name}]: {e}") from None
        if (p.patch1.dim, p.patch2.dim) != want:
            raise ValueError(f"pairs[{p.name}]: kind {p.kind!r} needs patch dims {want}, "
                             f"got ({p.patch1.dim}, {p.patch2.dim})")
        if relation(p.kind).along_d and p.sigma not in (None, 1.0):
            raise InputError(f"pairs[{p.name}].sigma", p.sigma,
                             "None or +1 (a point-curve couple's n is along d = p - c(s))")


class RigidContactSystem(WitnessFunctions, WitnessPredictions, LeafSystem):
    """See the module docstring. ``plant`` is a finalized continuous-time MultibodyPlant of free
    bodies (it need not be part of the diagram; `drake_dock.systems.engine` says what it may
    hold); ``pairs`` the declared `ContactPair`s; ``wrench_bodies`` names bodies that get an
    input port ``<body>_wrench`` (6-vector [torque, force], world frame, applied at the body
    origin), or holds (port name, body) for a further such port (the wrenches on a body add
    up; their work is the ``input_work`` integral). ``dampers`` is a sequence of (name,
    bushing): the work of each LinearBushingRollPitchYaw element's damping is integrated as
    continuous state and appended to the ``energy`` output under its name (for an energy
    ledger). The energy integrals are state in units of ``energy_scale`` (J): Drake's error
    control compares every state's absolute error with the accuracy, so that integrals in
    joules of a run with kJ of kinetic energy, not its motion, would set the step (the docking
    diagram passes the chaser's kinetic energy; the ``energy`` output is in joules).
    ``handovers`` are the declared `Handover`s between edge pairs and surface pairs
    (`drake_dock.core.handover`). ``followers`` are `FollowerForce`s added to the inputs'
    generalized force from the state (their work is part of ``input_work``)."""

    #: evaluations kept for reuse (`Memo`)
    eval_memo_size = 4

    def __init__(self, plant, pairs, law: ContactLaw = ContactLaw(),
                 options: ContactOptions = ContactOptions(), wrench_bodies=(), dampers=(),
                 energy_scale: float = 1.0, handovers=(), followers=()):
        super().__init__()
        check_pairs(plant, pairs, energy_scale)
        law.validate("law")
        self.plant, self.pairs, self.law, self.options = plant, list(pairs), law, options
        self.energy_scale = float(energy_scale)
        self.followers = tuple(followers)
        self.frames, self.fidx = frame_list(self.pairs)
        self.spans = [np.concatenate([p.patch1.span, p.patch2.span]) for p in self.pairs]
        self.far = FarPairs(self.pairs, self.fidx)
        self.links = HandoverLinks(self.pairs, handovers)
        self.engine = ev = Engine(plant, self.pairs, law, options, self.frames, self.fidx,
                                  self.links, self.far, dampers, self.energy_scale)
        self.nq, self.nv, self.nu, self.ie = ev.nq, ev.nv, ev.nu, ev.ie
        # The point-curve pairs: their side witness (`witnesses`).
        self.side_pairs = frozenset(i for i, p in enumerate(self.pairs)
                                    if relation(p.kind).along_d)
        self.timing = Timing([p.name for p in pairs])
        self.transitions = Transitions(self, self.timing)

        # State: x = [q, v, u*, friction loss, work of plant forces, work of inputs,
        #             work of each damper].
        self.energy_names = ["kinetic", "potential", "friction_loss", "plant_work",
                             "input_work", "impact_loss"] + list(ev.damper_names)
        self.DeclareContinuousState(ev.nx)
        self._mode_index = self.DeclareAbstractState(AbstractValue.Make(
            ContactModes([PairState() for _ in pairs]).seal()))
        self._gf_port = self.DeclareVectorInputPort("generalized_force", self.nv)
        self._wrench_ports = {}
        for b in wrench_bodies:
            name, b = (f"{b}_wrench", b) if isinstance(b, str) else b
            body = plant.GetBodyByName(b)
            self._wrench_ports[name] = (int(body.floating_velocities_start_in_v()),
                                        self.DeclareVectorInputPort(name, 6))
        self._wrenches = tuple(self._wrench_ports.values())
        self._cache = self.DeclareCacheEntry(
            "contact evaluation", ValueProducer(
                allocate=lambda: AbstractValue.Make(None), calc=self._calc_eval),
            prerequisites_of_calc={self.all_sources_ticket()})
        self.DeclareVectorOutputPort("state", self.nq + self.nv, self._out_state,
                                     prerequisites_of_calc={self.xc_ticket()})
        self.DeclareVectorOutputPort("generalized_contact_force", self.nv, self._out_gf)
        self.DeclareVectorOutputPort("energy", len(self.energy_names), self._out_energy)
        self.DeclareVectorOutputPort("first_contact_time", 1, self._out_first_contact,
                                     prerequisites_of_calc={self.all_state_ticket()})
        self._couple_ports = [
            self.DeclareVectorOutputPort(f"couple_{p.name}", COUPLE_OUTPUT_SIZE,
                                         lambda c, o, i=i: self._out_couple(c, o, i))
            for i, p in enumerate(pairs)]
        self.DeclareInitializationUnrestrictedUpdateEvent(
            lambda context, state: self._on_event(context, None, state))
        if options.reseek_early > 0:
            self.DeclarePerStepUnrestrictedUpdateEvent(self._on_step)
        self._rest = {}                 # held armed witnesses -> their joint rest (`_rest_witness`)
        self._w, self._w_far, self._w_joint = witnesses.declare(
            self, pairs, self._witness_value, self._far_value, self._joint_value,
            UnrestrictedUpdateEvent(self._on_event))
        # Evaluations by (time, state, modes, inputs); event results by (time, state,
        # mode_changes).
        self._evaluations = Memo(self.eval_memo_size)
        self._events = Memo(1)

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

    def set_modes(self, context, modes: ContactModes):
        """Writes sealed ``modes`` into a context (a logger's scratch context: the state just
        after an impact)."""
        context.get_mutable_abstract_state(self._mode_index).set_value(modes)

    def get_couple_output_port(self, name):
        return self._couple_ports[[p.name for p in self.pairs].index(name)]

    def couple_slice(self, i) -> slice:
        return slice(int(self.engine.uoff[i]), int(self.engine.uoff[i + 1]))

    @property
    def evaluations(self) -> int:
        """The number of evaluations computed (not reused) so far."""
        return self.engine.evaluations

    def eval(self, context) -> Evaluation:
        return self._cache.Eval(context)

    # ------------------------------------------------------------------ evaluation
    def input_force(self, context, x=None, modes=None) -> np.ndarray:
        """The inputs' generalized force: the ``generalized_force`` input plus each body
        wrench [torque, force] (world frame, at the body's origin), which is a free body's
        generalized force, plus the follower forces where they act (at the state ``x``, the
        context's continuous state when None, after the first impact of ``modes``, the
        context's modes when None)."""
        gf = self._gf_port
        tau = gf.Eval(context).copy() if gf.HasValue(context) else np.zeros(self.nv)
        for j, port in self._wrenches:
            if port.HasValue(context):
                tau[j:j + 6] += port.Eval(context)
        if self.followers:
            tc = self.first_contact_time(self.get_modes(context) if modes is None else modes)
            since = context.get_time() - tc if math.isfinite(tc) else -math.inf
            q = context.get_continuous_state_vector().CopyToVector() if x is None else x
            for f in self.followers:
                f.add_to(tau, q, since)
        return tau

    @staticmethod
    def first_contact_time(modes) -> float:
        """The time of the first impact (s; every contact starts with one), +inf before it."""
        return modes.impacts[0].t if modes.impacts else math.inf

    def _calc_eval(self, context, value):
        value.set_value(self._lookup(context))

    def _lookup(self, context) -> Evaluation:
        t, modes = context.get_time(), self.get_modes(context)
        x = context.get_continuous_state_vector().CopyToVector()
        return self._evaluation_at(t, x, modes, self.input_force(context, x, modes))

    def _evaluation_at(self, t, x, modes, tau) -> Evaluation:
        """The evaluation at (t, x, modes, tau), from the memo when Drake asked for it before
        (every derivative's path: no closure)."""
        key = (t, x.tobytes(), modes_key(modes), tau.tobytes())
        E = self._evaluations.find(key)
        return self._evaluations.put(key, self._evaluate(t, x, modes, tau)) if E is None else E

    def _evaluate(self, t, x, modes, tau) -> Evaluation:
        t0 = perf_counter()
        E = self.engine.evaluate(t, x, modes, tau)
        self.timing.contact_dynamics += perf_counter() - t0
        self.timing.count_tracked_epoch(modes.index())
        if E.needs_report:
            check_evaluation(self, E, t)
        return E

    def DoCalcTimeDerivatives(self, context, derivatives):
        derivatives.SetFromVector(self._lookup(context).xdot)

    # ------------------------------------------------------------------ outputs
    def _out_state(self, context, out):
        out.SetFromVector(context.get_continuous_state_vector().CopyToVector()[:self.nq + self.nv])

    def _out_gf(self, context, out):
        out.SetFromVector(self._cache.Eval(context).contact_force)

    def energy(self, E, modes) -> np.ndarray:
        """[kinetic, potential (gravity and the bushings' springs), friction loss, work of the
        plant's forces, work of the inputs, impact loss, work of each damper] (J,
        `energy_names`) at the evaluation E under ``modes``."""
        w = E.x[self.ie:] * self.energy_scale
        return np.concatenate([[E.kinetic_energy, E.potential_energy, w[0], w[1], w[2],
                                modes.impact_loss], w[3:]])

    def _out_energy(self, context, out):
        out.SetFromVector(self.energy(self._cache.Eval(context), self.get_modes(context)))

    def _out_first_contact(self, context, out):
        """The time of the first impact (s; every contact starts with one), +inf before it."""
        out.SetFromVector([self.first_contact_time(self.get_modes(context))])

    def _out_couple(self, context, out, i):
        out.SetFromVector(self.couple_table(context)[i])

    def couple_table(self, context) -> np.ndarray:
        """All couples' outputs at once, row i the value of port ``couple_<pairs[i].name>``
        (for loggers: one call instead of one port evaluation per couple)."""
        return self._cache.Eval(context).couple_table

    def couple_table_of(self, E) -> np.ndarray:
        """`couple_table` of the evaluation E."""
        return E.couple_table

    # ------------------------------------------------------------------ events
    def _on_step(self, context, state):
        """Per-step event: far pairs whose travel bound has used ``reseek_early`` of their
        clearance, or will within ``reseek_horizon`` (`Evaluation.due_pairs`), are sought
        again at the start of this step (`reseek_far`); a
        couple that drifted beyond ``drift_tol`` (a tracked one is sought again, one in contact
        projected) takes an event with every other transition due, as at a witness event.
        The clearance witness stays the guarantee; sought a little early, a pair needs no
        isolated event."""
        E = self._cache.Eval(context)
        if E.drifting < 0 and not E.due:
            return EventStatus.DidNothing()
        if E.drifting < 0:
            x = context.get_continuous_state_vector().CopyToVector()
            done = reseek_far(self.transitions, context.get_time(), x,
                              self.get_modes(context), E)
            if done is not None:
                state.get_mutable_continuous_state().get_mutable_vector().SetFromVector(done[0])
                state.get_mutable_abstract_state(self._mode_index).set_value(done[1])
                return EventStatus.Succeeded()
        return self._on_event(context, None, state, early=self.options.reseek_early,
                              due=frozenset(E.due_pairs.tolist()) if E.due else ())

    def _on_event(self, context, event, state, early=1.0, due=()):
        x = context.get_continuous_state_vector().CopyToVector()
        t, modes = context.get_time(), self.get_modes(context)
        if event is None and modes.mode_changes == 0:
            self._evaluations.clear()           # a run starts: nothing of another is reused
        x_new, modes_new = self._events.get(
            (t, x.tobytes(), modes.mode_changes),
            lambda: self.transitions.resolve(t, x, modes, self.input_force(context),
                                             lambda: self._cache.Eval(context), early, due))
        state.get_mutable_continuous_state().get_mutable_vector().SetFromVector(x_new)
        state.get_mutable_abstract_state(self._mode_index).set_value(copy.deepcopy(modes_new))
        self.tell_event(context, t, x_new, modes_new)
        return EventStatus.Succeeded()


def modes_key(modes) -> tuple:
    """What an evaluation reads of the modes, as a hashable key (kept on their index): per pair
    not far its mode, sigma and held sliding direction; the far pairs' data by the events and
    reseeks that set them (within one run)."""
    derived = modes.index().derived
    key = derived.get("key")
    if key is None:
        pairs = modes.pairs
        key = derived["key"] = (
            tuple((i, int(pairs[i].mode), pairs[i].sigma,
                   None if pairs[i].slide_dir is None else np.asarray(pairs[i].slide_dir,
                                                                      float).tobytes())
                  for i in modes.index().near), modes.mode_changes, modes.reseeks)
    return key



def check_evaluation(system, E, t):
    """The typed error of an evaluation that reports one (`engine.evaluate`'s status): a
    point-curve couple's point on its curve, a bushing at its gimbal lock, a constraint solve
    that is singular or not finite. (A couple that drifted beyond ``drift_tol`` is projected
    again at the next step's start, `_on_step`; at an event it raises `DriftError` if the
    projection does not bring it back, `Transitions.couples_of`.)"""
    sc, pairs = E.sc, system.pairs
    bad = int(sc[K.S_BAD_PC])
    if bad >= 0:
        raise SingularCoupleError("point-curve couple: the point lies on the curve (|d| = 0), "
                                  "its normal is undefined", time=t, couples=[pairs[bad].name])
    if int(sc[K.S_BUSH]) != 0:
        raise NumericalError("a bushing (LinearBushingRollPitchYaw) is at its gimbal lock "
                             "(pitch +-90 deg) or not finite", time=t,
                             couples=[p.name for i, p in enumerate(pairs)
                                      if E.modes.pairs[i].mode.in_contact])
    status = int(sc[K.S_STATUS])
    if status != 0:            # solve.OK
        from drake_dock.core.kernels.constraints import raise_status
        rows = [i for i in E.modes.index().near if E.modes.pairs[i].mode.in_contact]
        codes = [0 if E.modes.pairs[i].mode == Mode.STICKING else 1 for i in rows]
        raise_status(status, float(sc[K.S_COND]), codes, [pairs[i].name for i in rows], t)
