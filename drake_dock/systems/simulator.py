"""One Simulator set-up for every run (docking, small scenes, the compliant baseline): Drake's
`SimulatorConfig` applied to a system, the context's accuracy for witness isolation, the step
control of `drake_dock.systems.stepping`, and the tolerances derived from the configuration."""
from __future__ import annotations

import contextlib
import dataclasses
import gc

from pydrake.systems.analysis import ApplySimulatorConfig, Simulator, SimulatorConfig

from drake_dock.systems.stepping import WitnessApproach

IMPACT_RTOL_RANGE = (1e-12, 1e-8)

#: the first generation's threshold of Python's cyclic collector during a run
#: (`collector_relaxed`; Python's default is 700)
RUN_GC_THRESHOLD = 50_000


@dataclasses.dataclass(frozen=True)
class Tolerances:
    witness_accuracy: float   # the context's accuracy
    witness_window: float     # s: Drake isolates a witness zero to within it
    impact_rtol: float        # LZB's relative accuracy (`solve_lzb`'s rtol)


def tolerances(config: SimulatorConfig, witness_accuracy: float | None = None) -> Tolerances:
    """The tolerances a run derives from its ``config``:

    - the context's accuracy is ``config.accuracy`` unless ``witness_accuracy`` is given (a
      coarser one lets an integrator run tighter than the events are located);
    - Drake isolates a witness function's zero, under error-controlled integration, to a
      window of 1e-2 of the context's accuracy, in seconds (`Simulator`'s witness isolation);
    - LZB integrates each impact to a relative accuracy of 1e-2 of the context's accuracy,
      within `IMPACT_RTOL_RANGE`: its error in the post-impact velocities stays far below the
      integration error between impacts.
    """
    acc = config.accuracy if witness_accuracy is None else witness_accuracy
    lo, hi = IMPACT_RTOL_RANGE
    return Tolerances(acc, 0.01 * acc, min(hi, max(lo, 1e-2 * acc)))


def make_simulator(system, config: SimulatorConfig, set_state=None, *, context=None,
                   witness_accuracy: float | None = None) -> Simulator:
    """A `Simulator` of ``system`` (on ``context`` if given, as Drake's constructor) with
    ``config`` applied and the context's accuracy set (`tolerances`);
    ``set_state(root_context)`` writes the initial state first."""
    sim = Simulator(system) if context is None else Simulator(system, context)
    root = sim.get_mutable_context()
    if set_state is not None:
        set_state(root)
    ApplySimulatorConfig(config, sim)
    root.SetAccuracy(tolerances(config, witness_accuracy).witness_accuracy)
    return sim


def make_witness_approach(sim: Simulator, sources, config: SimulatorConfig, *,
                     witness_accuracy: float | None = None) -> WitnessApproach:
    """`WitnessApproach` for ``sim`` made by `make_simulator` with the same arguments: its step
    cap is ``config.max_step_size``, its window the witness isolation window."""
    return WitnessApproach(sim, sources, config.max_step_size,
                           tolerances(config, witness_accuracy).witness_window)


@contextlib.contextmanager
def collector_relaxed(threshold: int = RUN_GC_THRESHOLD):
    """Python's cyclic collector with its first generation's threshold raised to
    ``threshold`` (where it is lower) for the ``with`` block, restored after. A run allocates
    small objects at every evaluation, nearly all freed by reference counting; at the default
    threshold the collector runs about once a millisecond and scans, in its older generations,
    everything the process holds (a Dask worker's state too). A collector the user disabled or
    set higher (or to 0, Python's other way of disabling it) is left as it is; so is one that
    another run changed meanwhile (runs in threads: the last to leave does not restore a
    threshold it did not set)."""
    old = gc.get_threshold()
    relax = gc.isenabled() and 0 < old[0] < threshold
    if relax:
        gc.set_threshold(threshold, *old[1:])
    try:
        yield
    finally:
        if relax and gc.get_threshold()[0] == threshold:
            gc.set_threshold(*old)
