"""Compiled kernels (numba, `@njit(cache=True)`) of the per-evaluation contact mathematics over
plain arrays: the patches' jets by kind code and parameters (`jets`), and every tracked couple
of a contact system in one call (`couples`: Eq. 47, the projection, the contact frame, gap,
normal velocity and the Eq. 52 bias terms), the seek of Sect. 5.1 (`seek`), and the constraint
solve and mode selection of Eq. 48-52 (`constraints`, with the solve in `solve` and the start
of sliding in `slide_start`). `compile_cache` keys the compiled code's cache per module and
chooses its directory (importing this package applies it before any kernel is defined);
`prepare` compiles the kernels before a run needs them, in parallel, with a line per module.

`drake_dock.core.couple` and `drake_dock.core.seeking` are the couple kernels' and the seek's
Python interfaces (they pack a pair's patches and poses and raise the typed errors), and
`drake_dock.core.constraints` states the law the compiled constraints solve and holds its
records; the tests check the kernels against closed forms and references that share nothing
with them (tests/core/test_kernels_seek.py, test_kernels_constraints.py).
``NUMBA_DISABLE_JIT=1`` runs the kernels as Python, for debugging."""
from drake_dock.core.kernels import compile_cache

compile_cache.configure()
