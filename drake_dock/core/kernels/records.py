"""Typed records of arrays (NamedTuples) carried across the Python/compiled boundary in three
flat buffers.

numba unboxes every argument of a call from Python; a record of twenty arrays passed as a
NamedTuple costs about 0.2 us per array, a plain array about 0.08 us. A record therefore
crosses the boundary packed (`pack`): its float64 fields in one buffer, its int64 fields in
another, and a header (one row per field: start, stop, number of dimensions, shape, whether
float) that the compiled side reads back into the same NamedTuple of views (`f1`, `f2`, `f3`,
`i1`, `i2` by field, in each record's own unpacking function next to its definition) and the
Python side with `views`. Boolean fields are stored as int64 (0 or 1).
"""
from __future__ import annotations

from typing import NamedTuple

import numpy as np
from numba import njit

# Header columns.
START, STOP, NDIM, D0, D1, D2, FLOAT = range(7)


class Packed(NamedTuple):
    """A record in flat buffers: ``f`` (float64), ``i`` (int64), ``h`` (int64 (fields, 7):
    start, stop, number of dimensions, up to three dimensions, 1 for a float field)."""

    f: np.ndarray
    i: np.ndarray
    h: np.ndarray


def pack(record) -> Packed:
    """The `Packed` form of a NamedTuple of arrays (float64, int64 or bool fields, up to three
    dimensions)."""
    floats, ints, head = [], [], []
    nf = ni = 0
    for name, value in zip(record._fields, record):
        a = np.asarray(value)
        if a.ndim > 3:
            raise ValueError(f"{type(record).__name__}.{name}: at most 3 dimensions, got "
                             f"{a.ndim}")
        shape = tuple(a.shape) + (0,) * (3 - a.ndim)
        if a.dtype.kind == "f":
            flat = np.ascontiguousarray(a, dtype=np.float64).ravel()
            start, nf = nf, nf + flat.size
            floats.append(flat)
            is_float = 1
        elif a.dtype.kind in "iub":
            flat = np.ascontiguousarray(a, dtype=np.int64).ravel()
            start, ni = ni, ni + flat.size
            ints.append(flat)
            is_float = 0
        else:
            raise ValueError(f"{type(record).__name__}.{name}: float, int or bool array, got "
                             f"{a.dtype}")
        head.append((start, start + flat.size, a.ndim, *shape, is_float))
    f = np.concatenate(floats) if floats else np.zeros(0)
    i = np.concatenate(ints) if ints else np.zeros(0, dtype=np.int64)
    return Packed(f, i, np.array(head, dtype=np.int64).reshape(-1, 7))


def copy(p: Packed) -> Packed:
    """A copy of the buffers (the header is shared: it never changes)."""
    return Packed(p.f.copy(), p.i.copy(), p.h)


def views(p: Packed, record_type):
    """The packed record p as a ``record_type`` of numpy views into its buffers (writing a
    view writes the buffer)."""
    out = []
    for k in range(len(record_type._fields)):
        a, b, nd, d0, d1, d2, is_float = p.h[k].tolist()
        buf = p.f if is_float else p.i
        out.append(buf[a:b].reshape((d0, d1, d2)[:nd]))
    return record_type(*out)


@njit(cache=True)
def f1(p, k):
    """Float field k of a packed record, one-dimensional."""
    return p.f[p.h[k, 0]:p.h[k, 1]]


@njit(cache=True)
def f2(p, k):
    return p.f[p.h[k, 0]:p.h[k, 1]].reshape((p.h[k, 3], p.h[k, 4]))


@njit(cache=True)
def f3(p, k):
    return p.f[p.h[k, 0]:p.h[k, 1]].reshape((p.h[k, 3], p.h[k, 4], p.h[k, 5]))


@njit(cache=True)
def i1(p, k):
    """Integer field k of a packed record, one-dimensional."""
    return p.i[p.h[k, 0]:p.h[k, 1]]


@njit(cache=True)
def i2(p, k):
    return p.i[p.h[k, 0]:p.h[k, 1]].reshape((p.h[k, 3], p.h[k, 4]))
