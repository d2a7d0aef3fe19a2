"""Runs the docking Diagram with Drake's Simulator and records its outputs.

The record holds one sample at the end of every integration step (so the step that ends at an
impact's witness gives the state just before it) and, for each impact, one sample of the state
just after it at the same time (from the impact log; no step end sees that state). An event
with two impulses (an LZB impact, then an impact without collision) gives two samples after
it, the first also the state just before the second. With ``simulation.output_period`` the
step ends give way to the multiples of the period, interpolated within each step
(`_Grid`), so that the step is set by the accuracy and the events alone; the samples at
impacts and the last state stay. The simulation ends at
``simulation.duration`` or at capture (`CaptureMonitor`'s witness).

Integration: the scenario's ``simulator_config`` (Drake's `SimulatorConfig`), applied by
`drake_dock.systems.simulator.make_simulator`; the witness isolation window and LZB's accuracy
follow from it (`drake_dock.systems.simulator.tolerances`).
"""
from __future__ import annotations

import dataclasses
import math
import time as _time

import numpy as np

from pydrake.systems.analysis import Simulator, SimulatorStatus

from drake_dock.core.hybrid import Mode
from drake_dock.docking.geometry.scene import DockingScene
from drake_dock.docking.model.diagram import DiagramSpec, DockingDiagram, build_docking_diagram
from drake_dock.docking.model.initial_state import InitialState
from drake_dock.docking.model.outcome import OutcomeWatch, progress_fraction
from drake_dock.docking.model.plant import relative_kinetic_energy, set_initial_state
from drake_dock.errors import numerical_failure
from drake_dock.systems.contact_system import COUPLE_OUTPUT_SIZE, COUPLE_SLICES
from drake_dock.systems.impacts import enter_after
from drake_dock.systems.simulator import (collector_relaxed, make_simulator,
                                          make_witness_approach)

STEP, PRE_IMPACT, POST_IMPACT = 0, 1, 2


class Record:
    """Samples of a run (row k = sample k): its time, the contact system's continuous state,
    the sample's kind (STEP / PRE_IMPACT / POST_IMPACT), the contact modes and the inputs'
    generalized force then. Everything else of a sample (the couple outputs, the energy, the
    Stewart element's coordinates and force, the ring distance) is what one evaluation of the
    contact system at it gives, made for every sample when first asked (`derive`): a run
    records five references per step."""

    def __init__(self, dd=None, lean: bool = False):
        self.dd = dd
        self.t, self.states, self.kind, self.modes, self.tau = [], [], [], [], []
        self._derived = None
        # Lean (a campaign's): per step-end sample its `_small` values, from the evaluation the
        # run made there, so that `derive` without couples evaluates only the other samples
        # (after impacts, on an output grid) again; None for those.
        self.lean = lean
        self._small = [] if lean else None

    def append(self, t, state, kind, modes, tau, E=None):
        """A sample; ``E`` the contact system's evaluation at it where the run made one (a
        lean record keeps what `derive` reads of it)."""
        self.t.append(t)
        self.states.append(state)
        self.kind.append(kind)
        self.modes.append(modes)
        self.tau.append(tau)
        if self._small is not None:
            self._small.append(None if E is None else self._small_of(E, modes, state))
        self._derived = None

    def _small_of(self, E, modes, state) -> tuple:
        """(largest normal force, energy, bushings, ring distance) of a sample from its
        evaluation E."""
        contact = self.dd.contact
        return (E.lam_n.max(initial=0.0), contact.energy(E, modes), E.bushings.copy(),
                self.dd.capture.misalignment_of(state[:contact.nq])[0])

    @property
    def x(self) -> np.ndarray:
        """The plant's [q, v] per sample (N, nq + nv)."""
        n = self.dd.contact.nq + self.dd.contact.nv
        return np.array([x[:n] for x in self.states]).reshape(len(self.t), n)

    def derive(self, couples: bool = True) -> dict:
        """Per sample, by one evaluation of the contact system: ``couples`` (N, pairs,
        COUPLE_OUTPUT_SIZE) its couple outputs (left out with ``couples`` False: the largest
        part), ``lambda_n_max`` (N,) the largest normal force, ``energy`` (N, energy names),
        ``bushings`` (N, bushings, 12: deflection, roll-pitch-yaw, force on the APDS frame,
        world), ``ring_distance`` (N,); a lean record's step-end samples without couples from
        the values it kept."""
        if self._derived is None or (couples and "couples" not in self._derived):
            contact = self.dd.contact
            n = len(self.t)
            kept = self._small if self._small is not None else [None] * n
            C = np.zeros((n, len(contact.pairs), COUPLE_OUTPUT_SIZE)) if couples else None
            small = []
            for k in range(n):
                v = kept[k]
                if v is None or couples:
                    E = contact.engine.evaluate(self.t[k], self.states[k], self.modes[k],
                                                self.tau[k])
                    if couples:
                        C[k] = contact.couple_table_of(E)
                    if v is None:
                        v = self._small_of(E, self.modes[k], self.states[k])
                small.append(v)
            lam, energy, bush, ring = zip(*small) if small else ((),) * 4
            self._derived = dict(
                lambda_n_max=np.array(lam, dtype=float),
                energy=np.array(energy, dtype=float).reshape(-1, len(contact.energy_names)),
                bushings=np.array(bush, dtype=float).reshape(-1, contact.engine.nbush, 12),
                ring_distance=np.array(ring, dtype=float))
            if couples:
                self._derived["couples"] = C
        return self._derived

    @property
    def couples(self) -> np.ndarray:
        return self.derive()["couples"]

    @property
    def energy(self) -> np.ndarray:
        return self.derive(False)["energy"]

    @property
    def ring_distance(self) -> np.ndarray:
        return self.derive(False)["ring_distance"]

    @property
    def bushings(self) -> np.ndarray:
        return self.derive(False)["bushings"]


@dataclasses.dataclass
class RunResult:
    scenario: object
    dd: DockingDiagram
    initial: InitialState
    record: Record
    impacts: list              # the contact system's impact log
    mode_changes: int
    captured: bool
    capture_time: float | None
    end_time: float
    wall_time: float           # seconds in Simulator.Initialize + AdvanceTo (build excluded)
    evaluations: int
    timing: dict | None = None  # `Timing.shares`: seeking / contact dynamics / impacts / other
    outcome: str = "timeout"   # `drake_dock.docking.model.outcome.OUTCOMES`
    reason: str = ""
    # At the end of a run that is not captured: the couples in contact (`Holding`), and the
    # kinetic energy left in the centre-of-mass frame (J).
    holding: list = dataclasses.field(default_factory=list)
    relative_kinetic_energy: float = math.nan

    @property
    def scene(self):
        """The run's `DockingScene` (its Diagram's): the pairs its couples are named after."""
        return self.dd.scene


@dataclasses.dataclass(frozen=True)
class Holding:
    """A couple in contact at the end of a run: its name, the angle of its normal to the
    docking axis (deg; 0: the couple pushes the rings apart along the axis, 90: sideways) and
    its normal force (N)."""

    couple: str
    normal_angle_deg: float
    force_N: float

    def describe(self) -> str:
        return f"{self.couple} ({self.normal_angle_deg:.3g} deg from the axis, {self.force_N:.4g} N)"


def docking_simulator(dd: DockingDiagram, state: InitialState, config,
                      witness_accuracy: float | None = None) -> Simulator:
    """The Simulator of a docking diagram (`make_simulator` with ``config``, a
    `SimulatorConfig`): ``state`` placed (`set_initial_state`) and copied into the contact
    system, which owns the state."""
    def set_state(root):
        pc = dd.dp.plant.CreateDefaultContext()
        set_initial_state(dd.dp, pc, state)
        dd.contact.set_from_plant_context(dd.contact.GetMyMutableContextFromRoot(root), pc)
    return make_simulator(dd.diagram, config, set_state, witness_accuracy=witness_accuracy)


class _Recorder:
    """The record of a run: ``period`` None, a sample at every step end; else at the multiples
    of ``period`` (`_Grid`)."""

    def __init__(self, dd: DockingDiagram, period: float | None = None, lean: bool = False):
        self.dd = dd
        self.record = Record(dd, lean)
        self.n_impacts = 0
        self._scratch = dd.diagram.CreateDefaultContext()
        self.grid = None if period is None else _Grid(self, period)

    def _sample_of(self, root):
        contact = self.dd.contact
        cc = contact.GetMyContextFromRoot(root)
        return (root.get_time(), cc.get_continuous_state_vector().CopyToVector(),
                contact.get_modes(cc), contact.input_force(cc))

    def _append(self, root, kind, E=None):
        t, x, modes, tau = self._sample_of(root)
        self.record.append(t, x, kind, modes, tau, E)

    def _step_end_evaluation(self, root):
        """The contact system's evaluation at a step's end (the root context), for a lean
        record: the one the step's end asks for anyway (the witnesses and the step control
        read it); None otherwise."""
        if not self.record.lean:
            return None
        contact = self.dd.contact
        return contact.eval(contact.GetMyContextFromRoot(root))

    def start(self, sim):
        """After `Simulator.Initialize`: the first sample (and the grid's first step start)."""
        if self.grid is None:
            return self.sample(sim.get_context())
        self._append(sim.get_context(), STEP)
        self.grid.start(sim)

    def sample(self, root, last: bool = False):
        """A step end (``last``: the run's end). Impacts logged since the last step end
        happened at that step end's time: it becomes the pre-impact sample and the logged
        post-impact state follows it."""
        if self.grid is not None:
            return self.grid.step_end(root, last)
        contact = self.dd.contact
        modes = contact.get_modes(contact.GetMyContextFromRoot(root))
        new = modes.impacts[self.n_impacts:]
        r = self.record
        if new and r.t and r.t[-1] == new[0].t and r.kind[-1] == STEP:
            r.kind[-1] = PRE_IMPACT
        self.impacts_since(root, modes)
        if not r.t or root.get_time() > r.t[-1] or new:
            self._append(root, STEP, self._step_end_evaluation(root))

    def impacts_since(self, root, modes):
        """The post-impact samples of the impacts logged since the last call."""
        new = modes.impacts[self.n_impacts:]
        for imp in new:
            self._post_impact(root, imp, modes)
        self.n_impacts = len(modes.impacts)
        return new

    def _post_impact(self, root, imp, modes):
        s = self._scratch
        s.SetTimeStateAndParametersFrom(root)
        s.SetTime(imp.t)
        contact = self.dd.contact
        enter_after(contact, contact.GetMyMutableContextFromRoot(s), imp, modes.mode_changes)
        self._append(s, POST_IMPACT)


class _Grid:
    """The samples at the multiples k T of the output period T (k >= 1; the first sample is
    the initial state). Each is the cubic Hermite interpolant of the step that holds it,
    between the step's start (the state the event there left, `ContactModes.x_after`, or the
    last step's end) and its end, with the contact system's derivatives there (fourth order
    in the step, as accurate as the integration between the samples), under the step's modes.
    A step end is kept only where it is needed: the state just before an impact logged at its
    time (a PRE_IMPACT sample, the post-impact ones after it) and the last state of the run.
    (Drake's own dense output cannot serve: witness isolation integrates a step again from its
    start, and appending that step to the dense output fails.)"""

    def __init__(self, rec: _Recorder, period: float):
        self.rec, self.period = rec, float(period)
        self.k = 1                       # the next multiple of the period to sample
        self.last = None                 # the last step end: (t, x, modes, tau)

    def start(self, sim):
        self.last = self.rec._sample_of(sim.get_context())

    def step_end(self, root, last):
        rec, r = self.rec, self.rec.record
        end = rec._sample_of(root)
        t0, x0, modes0, tau0 = self.last
        modes = end[2]
        if modes.impacts[rec.n_impacts:]:
            # The impacts took place at the last step end (the start of this step): the state
            # before them, then after each.
            if not r.t or t0 > r.t[-1]:
                r.append(t0, x0, PRE_IMPACT, modes0, tau0)
            elif r.kind[-1] == STEP:
                r.kind[-1] = PRE_IMPACT
            rec.impacts_since(root, modes)
        if modes.x_after is not None and modes.x_after is not modes0.x_after:
            x0 = modes.x_after           # an event at t0 started this step
        self._interpolate(root, t0, x0, end)
        self.last = end
        if last and (not r.t or end[0] > r.t[-1]):
            r.append(end[0], end[1], STEP, end[2], end[3])

    def _interpolate(self, root, t0, x0, end):
        """The multiples of the period in (t0, t1], the step that ended now."""
        t1, x1, modes, _ = end
        h = t1 - t0
        if not h > 0.0 or self.k * self.period > t1:
            return
        rec, s = self.rec, self.rec._scratch
        contact = rec.dd.contact
        sc = contact.GetMyMutableContextFromRoot(s)
        s.SetTimeStateAndParametersFrom(root)

        def derivative(t, x):
            s.SetTime(t)
            sc.SetContinuousState(x)
            return contact.eval(sc).xdot

        f0, f1 = derivative(t0, x0), derivative(t1, x1)
        while self.k * self.period <= t1:
            tk = self.k * self.period
            self.k += 1
            if tk <= t0:
                continue
            a = (tk - t0) / h
            h00, h10 = (1 + 2 * a) * (1 - a) ** 2, a * (1 - a) ** 2
            h01, h11 = a * a * (3 - 2 * a), a * a * (a - 1)
            s.SetTime(tk)
            sc.SetContinuousState(h00 * x0 + h10 * h * f0 + h01 * x1 + h11 * h * f1)
            t, x, m, tau = rec._sample_of(s)
            rec.record.append(t, x, STEP, m, tau)


def _couples_in_play(dd: DockingDiagram, root) -> list:
    """The pairs tracked or in contact (not far) in the root context's state."""
    try:
        modes = dd.contact.get_modes(dd.contact.GetMyContextFromRoot(root))
        return [p.name for p, st in zip(dd.contact.pairs, modes.pairs) if st.mode != Mode.FAR]
    except Exception:  # noqa: BLE001 - only a detail of an error report
        return []


def _scene_of(scenario, state):
    """The state's `DockingScene` where it is the scenario's (its geometry and pair set), else
    None (`DiagramSpec.of` makes the scenario's)."""
    scene = state.scene
    if scene is not None and scene.key == DockingScene.key_of(scenario.geometry,
                                                              scenario.contact.pairs):
        return scene
    return None


def simulate(scenario, state: InitialState, *, dd: DockingDiagram | None = None,
             progress=None, duration: float | None = None,
             witness_approach: bool = True, lean: bool = False) -> RunResult:
    """Runs the scenario from ``state`` (`drake_dock.docking.placement.place.place` finds the
    scenario's own) on ``dd`` (built when not given) until a named outcome
    (`drake_dock.docking.model.outcome`), ``simulation.duration`` (or ``duration``) being the
    timeout; ``progress(t, t_end, fraction)`` is called after each step. Raises the contact
    system's typed errors (`NumericalError`), and any other failure of the integration as a
    `NumericalError` with the time and the couples in play. ``witness_approach`` shortens the
    steps before predicted witness zeros (`drake_dock.systems.stepping.WitnessApproach`); off,
    Drake's plain isolation is used. ``lean`` (a campaign's): the record keeps of each
    step-end sample, besides its state, the values that `Record.derive` gives without couples,
    read from the evaluation the run made there (`Record`). A Diagram built here is built on the
    state's scene (`InitialState.scene`) where that is the scenario's, so the scene is made
    once."""
    with numerical_failure("the Diagram's set-up", lambda: (0.0, ())):
        dd = dd or build_docking_diagram(DiagramSpec.of(scenario, scene=_scene_of(scenario,
                                                                                  state)))
        rec = _Recorder(dd, scenario.simulation.output_period, lean)
        sim = docking_simulator(dd, state, scenario.simulator_config)
    t_end = scenario.simulation.duration if duration is None else duration

    sp = scenario.simulation
    approach = make_witness_approach(sim, [dd.contact, dd.capture], scenario.simulator_config) \
        if witness_approach else None

    watch = None
    ended = []

    def driven(root) -> bool:
        """Whether post-contact thrust acts now or later."""
        if dd.thrust is None:
            return False
        tc = float(dd.contact.GetOutputPort("first_contact_time").Eval(
            dd.contact.GetMyContextFromRoot(root))[0])
        return dd.thrust.schedule.still_to_act(root.get_time() - tc if math.isfinite(tc)
                                               else -math.inf)

    def monitor(root):
        from pydrake.systems.framework import EventStatus
        rec.sample(root)
        if approach is not None:
            approach(root)
        t = root.get_time()
        cap = dd.capture.GetMyContextFromRoot(root)
        pose = dd.capture.misalignment(cap)
        d, to_go = pose[0], dd.capture.rule.to_go(*pose)
        if progress is not None:
            progress(t, t_end, progress_fraction(t, t_end, to_go, watch.d_start,
                                                 sp.capture_distance))
        end = watch.update(t, d, pose[1], to_go, driven(root))
        if end is not None:
            ended.append(end)
            return EventStatus.ReachedTermination(dd.capture, end[0])
        return EventStatus.Succeeded()

    evals0 = dd.contact.evaluations
    dd.contact.timing.reset()
    wall0 = _time.perf_counter()
    root = sim.get_context()
    with numerical_failure("the simulation",
                            lambda: (root.get_time(), _couples_in_play(dd, root))):
        sim.Initialize()
        rec.start(sim)
        watch = OutcomeWatch.of(dd.capture.distance(dd.capture.GetMyContextFromRoot(root)),
                                sp, scenario.geometry)
        sim.set_monitor(monitor)
        try:
            with collector_relaxed():
                status = sim.AdvanceTo(t_end)
        finally:
            # The monitor refers to the simulator (the step control): a cycle through Drake's
            # C++ that Python's collector cannot see would keep the run's record alive.
            sim.clear_monitor()
            if approach is not None:
                approach.close()
    wall = _time.perf_counter() - wall0
    rec.sample(root, last=True)
    terminated = status.reason() == SimulatorStatus.ReturnReason.kReachedTerminationCondition
    if ended:
        outcome, reason = ended[0]
    elif terminated:
        outcome, reason = "captured", dd.capture.rule.describe()
    else:
        outcome, reason = "timeout", f"simulation.duration {t_end:g} s reached"
    captured = outcome == "captured"
    modes = dd.contact.get_modes(dd.contact.GetMyContextFromRoot(root))
    holding, ke_rel = [], math.nan
    if not captured:
        holding, ke_rel = _holding(dd, root)
        if outcome in ("jammed", "timeout"):
            reason += (f"; held by {', '.join(h.describe() for h in holding) or 'no couple'}"
                       f"; relative kinetic energy {ke_rel:.4g} J")
    return RunResult(scenario, dd, state, rec.record, list(modes.impacts), modes.mode_changes,
                     captured, root.get_time() if captured else None, root.get_time(), wall,
                     dd.contact.evaluations - evals0, dd.contact.timing.shares(wall),
                     outcome, reason, holding, ke_rel)


def _holding(dd: DockingDiagram, root) -> tuple[list, float]:
    """The couples in contact in the root context, largest normal force first (`Holding`), and
    the relative kinetic energy (`relative_kinetic_energy`)."""
    contact = dd.contact
    cc = contact.GetMyContextFromRoot(root)
    table = contact.couple_table(cc)
    pc = dd.dp.plant.CreateDefaultContext()
    x = contact.GetOutputPort("state").Eval(cc)
    dd.dp.plant.SetPositionsAndVelocities(pc, x)
    axis = dd.dp.apds_frames["target_apds"].CalcPoseInWorld(pc).rotation().col(2)
    S = COUPLE_SLICES
    out = []
    for p, st, row in zip(contact.pairs, contact.get_modes(cc).pairs, table):
        if st.mode.in_contact:
            n = row[S["frame"]].reshape(3, 3)[:, 2]
            cos = min(abs(float(np.dot(n, axis))) / max(float(np.linalg.norm(n)), 1e-300), 1.0)
            out.append(Holding(p.name, math.degrees(math.acos(cos)),
                               float(row[S["lambda_n"]][0])))
    out.sort(key=lambda h: -h.force_N)
    return out, relative_kinetic_energy(dd.dp, pc)


__all__ = ["simulate", "docking_simulator", "RunResult", "Record", "STEP", "PRE_IMPACT",
           "POST_IMPACT", "COUPLE_OUTPUT_SIZE"]
