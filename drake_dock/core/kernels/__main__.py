"""``python -m drake_dock.core.kernels``: compiles (or loads) the kernels and prints the cache
directory."""
import time

from drake_dock.core.kernels.compile_cache import cache_dir, warm

t0 = time.perf_counter()
warm()
print(f"kernels ready in {time.perf_counter() - t0:.2f} s; numba cache: {cache_dir()}")
