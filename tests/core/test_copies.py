"""The kernels' array copies against numpy's slice assignment."""
import numpy as np
import pytest
from numba import njit

from drake_dock.core.kernels import copies

# Compiled here without the cache: signatures beyond the kernels' own leave the package's cache
# index as the units' warm() wrote it (`test_every_kernel_is_compiled_by_some_warm`).
copy1, copy2 = njit(copies.copy1.py_func), njit(copies.copy2.py_func)


def test_copies_match_numpy_slice_assignment_on_views_of_every_dtype():
    rng = np.random.default_rng(7)
    for dtype in (np.float64, np.int64, np.bool_):
        src = rng.normal(size=(4, 5)).astype(dtype)
        got, want = np.zeros((6, 7), dtype), np.zeros((6, 7), dtype)
        copy2(got[1:5, 2:], src)
        want[1:5, 2:] = src
        copy1(got[5, ::2], src[0, :4])
        want[5, ::2] = src[0, :4]
        assert np.array_equal(got, want)


def test_copies_refuse_shapes_that_differ():
    with pytest.raises(ValueError, match="copy1"):
        copy1(np.zeros(3), np.zeros(4))
    with pytest.raises(ValueError, match="copy2"):
        copy2(np.zeros((2, 3)), np.zeros((3, 2)))
