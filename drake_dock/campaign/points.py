"""Sample points: the unit cube (scipy.stats.qmc) mapped to scenario values.

Each varied field takes one dimension per component (a ``choice`` one in all), in sorted path
order. The samplers:

- ``sobol``: a scrambled Sobol' sequence seeded by the plan's seed; sample i is the sequence's
  point i whatever the number of samples (a campaign can be extended).
- ``edges``: the same points through the arcsine law u -> (1 - cos(pi u)) / 2, whose density
  grows towards both ends of every range (Monte Carlo weighted towards the range edges, as in
  docking-mechanism practice).
- ``lhs``: a Latin hypercube of all the samples (sample i's point depends on ``samples``).
- ``uniform``: independent pseudo-random points, sample i's from its own seed.

Every sample has a seed of its own, derived from the plan's seed and its index
(`sample_seed`). A value is the lower end plus u times the range (``uniform``), the normal
quantile of u (``normal``), or choice number floor(u n) (``choice``).
"""
from __future__ import annotations

import math

import numpy as np
from scipy.stats import norm, qmc

from drake_dock.campaign.plan import Field

U_MIN = 1e-12    # the normal quantile is taken at u clipped to [U_MIN, 1 - U_MIN]


def sample_seed(plan_seed: int, sample: int) -> int:
    """The seed of one sample: 63 bits from numpy's SeedSequence of (plan seed, sample)."""
    state = np.random.SeedSequence(plan_seed, spawn_key=(sample,)).generate_state(1, np.uint64)
    return int(state[0] >> np.uint64(1))


def _sobol(d: int, seed: int, upto: int) -> np.ndarray:
    m = max(int(math.ceil(math.log2(max(upto, 2)))), 1)
    return qmc.Sobol(d, scramble=True, rng=seed).random_base2(m)


def unit_points(sampler: str, seed: int, d: int, samples: list[int], total: int) -> np.ndarray:
    """The unit-cube points (len(samples), d) of the given sample indices."""
    idx = np.asarray(samples, dtype=int)
    if d == 0 or idx.size == 0:
        return np.zeros((idx.size, d))
    if sampler in ("sobol", "edges"):
        u = _sobol(d, seed, int(idx.max()) + 1)[idx]
        return 0.5 * (1.0 - np.cos(np.pi * u)) if sampler == "edges" else u
    if sampler == "lhs":
        return qmc.LatinHypercube(d, rng=seed).random(total)[idx]
    return np.array([np.random.default_rng(sample_seed(seed, int(i))).random(d) for i in idx])


def _component(kind: str, spec, u: float) -> float:
    if kind == "uniform":
        lo, hi = spec
        return float(lo + u * (hi - lo))
    mean, sd = spec
    return float(norm.ppf(min(max(u, U_MIN), 1.0 - U_MIN), loc=mean, scale=sd))


def field_value(f: Field, u: np.ndarray):
    """The value of field ``f`` at its slice ``u`` of a unit point: a number or a list."""
    kind = f.dist.kind
    entries = getattr(f.dist, kind)
    if kind == "choice":
        pick = entries[min(int(u[0] * len(entries)), len(entries) - 1)]
        return [float(x) for x in pick] if f.size else float(pick[0])
    values = [_component(kind, spec, float(x)) for spec, x in zip(entries, u)]
    return values if f.size else values[0]


def sample_values(fields: list[Field], point: np.ndarray) -> dict:
    """{path: value} of one sample from its unit point."""
    out, k = {}, 0
    for f in fields:
        out[f.path] = field_value(f, point[k:k + f.dims])
        k += f.dims
    return out


def sample_specs(plan, fields: list[Field], samples: list[int]) -> list[tuple]:
    """(sample, seed, {path: value}) for each index in ``samples``."""
    d = sum(f.dims for f in fields)
    points = unit_points(plan.sampler, plan.seed, d, samples, plan.samples)
    return [(int(i), sample_seed(plan.seed, int(i)), sample_values(fields, p))
            for i, p in zip(samples, points)]
