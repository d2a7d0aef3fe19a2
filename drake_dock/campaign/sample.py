"""One campaign sample: the base scenario with the sample's values, simulated to its outcome,
reduced to a plain row (a dict of numbers and strings, which pickles; Drake's Diagrams,
Simulators and Contexts do not).

A process keeps the last few Diagrams it built (`diagram_for`), each under its `DiagramSpec`
(exactly what the Diagram reads of a scenario), and the scenes of those specs (`scene_for`); it
reuses one for every sample of the same spec, its scene serving the sample's placement too; a
run on a reused Diagram gives bitwise the same row as on a fresh one (tests/campaign). Any
failure of a sample (a typed error of drake_dock, a value out of range, anything else) is its
row's ``outcome: error`` with the message in ``error``; it never stops the campaign.
"""
from __future__ import annotations

import collections
import copy
import math
import time

import numpy as np

from drake_dock.campaign.plan import set_field
from drake_dock.docking.geometry.scene import DockingScene
from drake_dock.docking.model.diagram import DiagramSpec, build_docking_diagram
from drake_dock.docking.model.simulate import simulate
from drake_dock.docking.placement.place import PlacementCache, place
from drake_dock.docking.report.results import (energy_ledger, final_misalignment, momenta,
                                               momentum_reference_point, relative,
                                               thrust_impulses, timeseries)
from drake_dock.docking.scenario.validation import validate
from drake_dock.errors import DrakeDockError, NumericalError
from drake_dock.systems.simulator import collector_relaxed

# The row's columns after the sample, its seed and the varied inputs (`Field.columns`).
RESULT_COLUMNS = {
    "outcome": str, "reason": str, "capture_time": float, "end_time": float,
    "peak_contact_force": float, "peak_stewart_stroke": float, "peak_stewart_force": float,
    "final_axial": float, "final_lateral": float, "final_tilt_deg": float, "impacts": int,
    "momentum_drift": float, "energy_closure": float, "wall_time": float, "error": str}
ERROR = "error"
CACHE_SIZE = 4
_DIAGRAMS: collections.OrderedDict = collections.OrderedDict()
_SCENES: collections.OrderedDict = collections.OrderedDict()


def _kept(cache: collections.OrderedDict, key, make):
    """``cache[key]``, made by ``make()`` where missing; the last CACHE_SIZE keys stay."""
    value = cache.pop(key, None) or make()
    cache[key] = value
    while len(cache) > CACHE_SIZE:
        cache.popitem(last=False)
    return value


def diagram_for(spec: DiagramSpec):
    """This process's Diagram of ``spec``: built once per spec, kept for the last CACHE_SIZE
    specs."""
    return _kept(_DIAGRAMS, spec, lambda: build_docking_diagram(spec))


def scene_for(scenario) -> DockingScene:
    """This process's `DockingScene` of ``scenario`` (its geometry and contact set): made once
    per key, kept for the last CACHE_SIZE keys, so that a sample's `DiagramSpec` finds its
    cached Diagram without making a scene of its own."""
    key = DockingScene.key_of(scenario.geometry, scenario.contact.pairs)
    return _kept(_SCENES, key, lambda: DockingScene.of(scenario))


def sample_scenario(base, values: dict):
    """A copy of the base scenario with the sample's {dotted path: value}, validated."""
    s = copy.deepcopy(base)
    for path, value in values.items():
        set_field(s, path, value)
    return validate(s)


def input_columns(values: dict) -> dict:
    """The varied inputs as flat columns: path, or path[k] per component of a vector."""
    out = {}
    for path, v in values.items():
        if isinstance(v, list):
            out.update({f"{path}[{k}]": float(x) for k, x in enumerate(v)})
        else:
            out[path] = float(v)
    return out


def stewart_peaks(ts: dict) -> tuple[float, float]:
    """The largest translational deflection (m) of the Stewart element and the largest force
    (N) it exerts on the target APDS, over the recorded samples of a `timeseries` (the values
    of `drake_dock.docking.model.plant.stewart_history`, from the states the timeseries
    evaluates)."""
    stroke = np.array([np.linalg.norm(x) for x in ts["stewart_x"]])
    force = np.array([np.linalg.norm(f) for f in ts["stewart_force_W"]])
    return float(stroke.max(initial=0.0)), float(force.max(initial=0.0))


def measure(result) -> dict:
    """The row's result columns of a finished run (RESULT_COLUMNS but wall_time), from its
    timeseries without the per-couple arrays (`timeseries(..., couples=False)`): the numbers
    of `summary` that a row holds, computed as `summary` computes them."""
    ts = timeseries(result, couples=False)
    s = result.scenario
    params = [getattr(s.bodies, n) for n in ts["body_names"]]
    masses = [p.mass for p in params]
    about = momentum_reference_point(s, ts)
    P, _, sP, _ = momenta(ts, masses, [p.inertia for p in params], about)
    J, _ = thrust_impulses(result, ts, about)
    stroke, force = stewart_peaks(ts)
    fm = final_misalignment(ts)
    lam = ts["lambda_n_max"]
    row = {"outcome": result.outcome, "reason": result.reason,
           "capture_time": result.capture_time, "end_time": result.end_time,
           "peak_contact_force": float(lam.max()) if lam.size and lam.max() > 0 else 0.0,
           "peak_stewart_stroke": stroke, "peak_stewart_force": force,
           "final_axial": fm["axial_m"], "final_lateral": fm["lateral_m"],
           "final_tilt_deg": fm["tilt_deg"], "impacts": len(result.impacts),
           "momentum_drift": relative(np.linalg.norm(P - P[0] - J, axis=1).max(), sP),
           "energy_closure": energy_ledger(ts, masses)["closure_error_relative"],
           "error": None}
    for name, v in row.items():
        if isinstance(v, float) and not math.isfinite(v):
            raise NumericalError(f"the sample's {name} is not finite (an overflow of extreme "
                                 f"inputs)", time=result.end_time)
    return row


def failed(message: str, reason: str) -> dict:
    """The result columns of a sample that ended in an error."""
    row = dict.fromkeys(RESULT_COLUMNS)
    row.update(outcome=ERROR, reason=reason, error=message)
    return row


def scenario_row(scenario, *, reuse: bool = True) -> dict:
    """The result columns (`measure`) of a run of ``scenario``: on this process's cached
    Diagram of its `DiagramSpec` (``reuse``, `diagram_for`) or a fresh one, placed on that
    Diagram's scene."""
    spec = DiagramSpec.of(scenario, scene=scene_for(scenario) if reuse else None)
    dd = diagram_for(spec) if reuse else build_docking_diagram(spec)
    return measure(simulate(scenario, place(scenario, PlacementCache(dd.scene)), dd=dd,
                            lean=True))


def run_sample(base, spec, *, reuse: bool = True) -> dict:
    """The row of one sample ``spec = (sample, seed, {path: value})`` (`scenario_row`), with
    Python's cyclic collector relaxed throughout (`collector_relaxed`). ``reuse``: run on this
    process's cached Diagram (`diagram_for`); otherwise build a fresh one."""
    sample, seed, values = spec
    row = {"sample": int(sample), "seed": int(seed), **input_columns(values)}
    t0 = time.perf_counter()
    try:
        with collector_relaxed():   # the placement and the row's reduction too, not the run only
            row.update(scenario_row(sample_scenario(base, values), reuse=reuse))
    except DrakeDockError as e:
        _DIAGRAMS.clear()            # nothing of a failed run is kept
        _SCENES.clear()
        row.update(failed(str(e), f"{type(e).__name__}"))
    except Exception as e:  # noqa: BLE001 - a sample's failure is its row, never the campaign's
        _DIAGRAMS.clear()
        _SCENES.clear()
        row.update(failed(f"internal error ({type(e).__name__}): {e}"[:2000],
                          f"{type(e).__name__}"))
    row["wall_time"] = time.perf_counter() - t0
    return row


def run_batch(base, specs) -> list[dict]:
    """The rows of a batch of samples, in order (the Dask task)."""
    return [run_sample(base, spec) for spec in specs]
