"""Array copies for the kernels, element by element, with a shape check of constant text.

numba lowers the assignment of an array into part of another (``a[i:j] = b``, ``R[k] = M``,
``a[idx] = b``) with a shape check whose error message is formatted at run time: that compiles
numba's string formatting in every process that compiles such an assignment and links it into
each kernel holding one, about a tenth of the kernels' compile (docs/performance.md, "Compiled
kernels"). The kernels copy arrays with these functions instead; a scalar assigned to a slice
(``a[:] = 0.0``) has no such check and stays as it is.
"""
from __future__ import annotations

from numba import njit


@njit(cache=True)
def copy1(dst, src):
    """dst[i] = src[i] for the 1-d arrays dst and src of one length."""
    if dst.shape[0] != src.shape[0]:
        raise ValueError("copy1: dst and src differ in length")
    for i in range(src.shape[0]):
        dst[i] = src[i]


@njit(cache=True)
def copy2(dst, src):
    """dst[i, j] = src[i, j] for the 2-d arrays dst and src of one shape."""
    if dst.shape[0] != src.shape[0] or dst.shape[1] != src.shape[1]:
        raise ValueError("copy2: dst and src differ in shape")
    for i in range(src.shape[0]):
        for j in range(src.shape[1]):
            dst[i, j] = src[i, j]
