"""3-vectors and 3x3 rotations in plain floats (tuples and nested lists).

The couple evaluation and the seek's Newton work on one point at a time: a few hundred
operations on 3-vectors, each several times cheaper in plain floats than the same numpy call.
"""
from __future__ import annotations


def dot(a, b):
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


def cross(a, b):
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


def add(a, b):
    return (a[0] + b[0], a[1] + b[1], a[2] + b[2])


def sub(a, b):
    return (a[0] - b[0], a[1] - b[1], a[2] - b[2])


def mul(a, s):
    return (a[0] * s, a[1] * s, a[2] * s)


def axpy(s, a, b):
    """s a + b."""
    return (s * a[0] + b[0], s * a[1] + b[1], s * a[2] + b[2])


def rot(R, a):
    """R a for R as three rows."""
    r0, r1, r2 = R
    return (r0[0] * a[0] + r0[1] * a[1] + r0[2] * a[2], r1[0] * a[0] + r1[1] * a[1]
            + r1[2] * a[2], r2[0] * a[0] + r2[1] * a[1] + r2[2] * a[2])


def rot_t(R, a):
    """R^T a for R as three rows."""
    r0, r1, r2 = R
    return (r0[0] * a[0] + r1[0] * a[1] + r2[0] * a[2], r0[1] * a[0] + r1[1] * a[1]
            + r2[1] * a[2], r0[2] * a[0] + r1[2] * a[1] + r2[2] * a[2])
