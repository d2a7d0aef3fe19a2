"""Compiled kernels (numba, `@njit(cache=True)`) of the per-evaluation contact mathematics over
plain arrays: the patches' jets by kind code and parameters (`jets`), and every tracked couple
of a contact system in one call (`couples`: Eq. 47, the projection, the contact frame, gap,
normal velocity and the Eq. 52 bias terms), the seek of Sect. 5.1 (`seek`), and the constraint
solve and mode selection of Eq. 48-52 (`constraints`, with the solve in `solve` and the start
of sliding in `slide_start`). `compile_cache` keys the compiled code's cache per module and
chooses its directory (importing this package applies it before any kernel is defined);
`prepare` compiles the kernels before a run needs them, in parallel, with a line per module.

The pure-Python modules (`drake_dock.core.patches`, `drake_dock.core.couple`,
`drake_dock.core.seeking`, `drake_dock.core.constraints`) stay the reference the kernels are
tested against (tests/core/test_kernels.py, tests/core/test_kernels_seek.py,
tests/core/test_kernels_constraints.py) and the path for patches that no kernel describes."""
from drake_dock.core.kernels import compile_cache

compile_cache.configure()
