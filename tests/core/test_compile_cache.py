"""The compiled kernels' cache is keyed per module: a module's key follows its source and those
of the modules it imports (numba checks only a kernel's own file), and no other. The parallel
compile caches every kernel (each is compiled by some module's warm()) so that another process
loads them without compiling; concurrent writers of one function's signatures leave an index
that loads each of them. A kernel of the package is compiled once per argument types, not once
per constant it is called with."""
import os
import shutil
import subprocess
import sys
import textwrap

from numba import njit
from numba.core.registry import CPUDispatcher

from drake_dock.core.kernels import compile_cache as cc
from drake_dock.core.kernels import prepare

ROOT = cc._PACKAGE.parent
K = "drake_dock.core.kernels."


def _tree(root, files):
    for name, text in files.items():
        path = root / name
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_text(textwrap.dedent(text))
    return root / "drake_dock"


def test_a_key_follows_the_module_and_what_it_imports_and_nothing_else(tmp_path):
    pkg = _tree(tmp_path, {
        "drake_dock/__init__.py": "", "drake_dock/core/__init__.py": "",
        "drake_dock/core/base.py": "X = 1\n", "drake_dock/core/other.py": "Y = 2\n",
        "drake_dock/core/kernels/__init__.py": "",
        "drake_dock/core/kernels/leaf.py": "from drake_dock.core import base\n",
        "drake_dock/core/kernels/mid.py": "from drake_dock.core.kernels.leaf import base\n",
        "drake_dock/core/kernels/top.py": "def warm():\n    from . import mid\n",
        "drake_dock/core/kernels/alone.py": "import drake_dock.core.other\n"})
    names = ["leaf", "mid", "top", "alone"]

    def keys():
        return {n: cc.module_key(K + n, pkg) for n in names}
    assert cc.dependencies(K + "top", pkg) == [
        "drake_dock.core.base", K + "leaf", K + "mid", K + "top"]
    assert prepare.units(pkg) == ["top"]
    before = keys()
    for edited, changed in [("core/base.py", {"leaf", "mid", "top"}),
                            ("core/other.py", {"alone"}),
                            ("core/kernels/mid.py", {"mid", "top"}),
                            ("core/kernels/top.py", {"top"})]:
        path = pkg / edited
        path.write_text(path.read_text() + "# edited\n")
        after = keys()
        assert {n for n in names if after[n] != before[n]} == changed, edited
        path.write_text(path.read_text().replace("# edited\n", ""))
        assert keys() == before                                   # same bytes, same keys


def test_an_edit_of_the_real_tree_changes_the_keys_of_the_modules_that_import_it(tmp_path):
    pkg = tmp_path / "drake_dock"
    shutil.copytree(cc._PACKAGE, pkg, ignore=shutil.ignore_patterns("__pycache__"))
    names = prepare.kernel_modules(pkg)
    assert set(prepare.units(pkg)) <= set(names)

    def keys():
        return {n: cc.module_key(K + n, pkg) for n in names}
    before = keys()
    assert before == {n: cc.module_key(K + n) for n in names}     # same bytes, same keys
    for edited, first in [("core/kernels/lzb_phases.py", "lzb_phases"),
                          ("core/patches.py", "jets")]:
        path = pkg / edited
        path.write_text(path.read_text() + "\n")
        after = keys()
        importers = {n for n in names if any(d.endswith(edited[:-3].replace("/", "."))
                                             for d in cc.dependencies(K + n, pkg))}
        assert first in importers
        assert {n for n in names if after[n] != before[n]} == importers
        assert importers != set(names)                 # some modules keep their cache
        path.write_text(path.read_text()[:-1])


def test_the_kernels_are_cached_in_their_module_directory_under_its_key():
    from drake_dock.core.kernels import couples, lzb
    for module, fn in [("couples", couples.evaluate_one), ("lzb", lzb.lzb_impact)]:
        key = cc.module_key(K + module)
        assert fn._cache.cache_path == str(cc.cache_dir() / f"{module}-{key}")
        assert fn._cache._impl.locator.get_source_stamp() == key


def _python(code, cache, **kw):
    env = dict(os.environ, NUMBA_CACHE_DIR=str(cache), PYTHONPATH=str(ROOT))
    return subprocess.run([sys.executable, "-c", textwrap.dedent(code)], env=env, cwd=ROOT,
                          capture_output=True, text=True, check=True, **kw)


STATS = """
    import importlib
    from numba.core.registry import CPUDispatcher
    from drake_dock.core.kernels import prepare
    hits = misses = 0
    for name in prepare.kernel_modules():
        for d in vars(importlib.import_module("drake_dock.core.kernels." + name)).values():
            if isinstance(d, CPUDispatcher):
                hits += sum(d.stats.cache_hits.values())
                misses += sum(d.stats.cache_misses.values())
    print(hits, misses)
"""


def _kernels():
    """(module, dispatcher) of every kernel defined in the kernels package that has machine
    code of its own (one inlined where it is called, ``inline="always"``, has none, nor a cache
    index)."""
    import importlib
    for name in prepare.kernel_modules():
        for value in vars(importlib.import_module(K + name)).values():
            if (isinstance(value, CPUDispatcher) and value.py_func.__module__ == K + name
                    and value.targetoptions.get("inline") != "always"):
                yield name, value


SUBSET = ["small_linalg", "solve", "bushing"]     # solve waits for small_linalg's owner


def test_the_parallel_compile_caches_its_units_and_another_process_loads_them(tmp_path):
    """Three units compiled from nothing in 2 processes (one waits for another's module):
    each is marked done, and a second process loads their kernels without compiling. (All
    twelve take a minute; `test_every_kernel_is_compiled_by_some_warm` covers the rest.)"""
    out = _python(textwrap.dedent(f"""
        import sys
        from drake_dock.core.kernels import prepare
        assert prepare.missing({SUBSET}) == {SUBSET}
        prepare.prepare(sys.stdout, jobs=2, names={SUBSET})
        assert prepare.missing({SUBSET}) == []
    """) + textwrap.dedent(STATS), tmp_path).stdout
    assert f"compiling the numba kernels, {len(SUBSET)} modules in 2 processes" in out
    assert all(f"  {u}: " in out for u in SUBSET)
    hits, misses = map(int, out.split()[-2:])    # this process loaded them, compiled none
    assert hits > 0 and misses == 0
    out = _python(f"from drake_dock.core.kernels import prepare\nprepare.warm({SUBSET})\n"
                  + textwrap.dedent(STATS), tmp_path).stdout
    hits, misses = map(int, out.split()[-2:])
    assert hits > 0 and misses == 0


def test_a_cancelled_preparation_stops_its_workers_and_marks_nothing(tmp_path):
    """`Preparation.cancel` (a run that fails on its input while the kernels compile) kills
    the workers at once: the units they were compiling stay missing."""
    out = _python("""
        import time
        from drake_dock.core.kernels import prepare
        names = ["engine", "seek"]     # seek first (engine waits for it): more than 10 s
        p = prepare.Preparation.start(None, 2, names)
        time.sleep(1.0)
        workers = list(p._workers)
        t0 = time.perf_counter()
        p.cancel()
        print(len(workers), all(w.poll() is not None for w in workers),
              time.perf_counter() - t0 < 5.0, *sorted(prepare.missing(names)))
    """, tmp_path).stdout
    assert out.split() == ["2", "True", "True", "engine", "seek"]


def test_every_kernel_is_compiled_by_some_warm():
    """Every kernel of the kernels package has its cache index in the package's cache, written
    no later than the last unit's warm() (`prepare`, which the install runs; here it first
    compiles what the cache lacks). A kernel that no warm() reaches (a new module without
    warm(), a kernel no warm() calls, a signature no warm() covers) is compiled in the middle
    of a run, by this suite's runs among others: it has no index, or a later one."""
    if prepare.missing():
        subprocess.run([sys.executable, "-m", "drake_dock.core.kernels"], cwd=ROOT,
                       env=dict(os.environ, PYTHONPATH=str(ROOT)), capture_output=True,
                       check=True)
    done = max(prepare._marker(u).stat().st_mtime for u in prepare.units())
    cold, late = [], []
    for name, fn in _kernels():
        index = list((cc.cache_dir() / f"{name}-{cc.module_key(K + name)}").glob(
            f"{name}.{fn.py_func.__qualname__}-{fn.py_func.__code__.co_firstlineno}.py*.nbi"))
        label = f"{name}.{fn.py_func.__qualname__}"
        if not index:
            cold.append(label)
        elif max(p.stat().st_mtime for p in index) > done:
            late.append(label)
    assert not cold, f"kernels no module's warm() compiles: {cold}"
    assert not late, f"kernels compiled after the warm() of every unit: {late}"


def test_concurrent_writers_of_one_function_leave_an_index_that_loads_each(tmp_path):
    kinds = ["1", "1.0", "True", "1j"]           # four signatures of frames.add
    code = """
        import sys, time
        from numba.core import caching
        from drake_dock.core.kernels import frames
        save_index = caching.IndexDataCacheFile._save_index

        def slow(self, overloads):      # widens the window between reading and writing
            time.sleep(0.5)
            save_index(self, overloads)
        caching.IndexDataCacheFile._save_index = slow
        x = {kind}
        time.sleep(max(0.0, float(sys.argv[1]) - time.time()))    # start together
        frames.add((x, x, x), (x, x, x))
    """
    import time
    start = f"{time.time() + 3.0}"
    env = dict(os.environ, NUMBA_CACHE_DIR=str(tmp_path), PYTHONPATH=str(ROOT))
    procs = [subprocess.Popen([sys.executable, "-c", textwrap.dedent(code.format(kind=k)),
                               start], env=env, cwd=ROOT) for k in kinds]
    assert [p.wait() for p in procs] == [0] * len(kinds)
    out = _python(f"""
        from drake_dock.core.kernels import frames
        for x in [{", ".join(kinds)}]:
            assert frames.add((x, x, x), (x, x, x)) == (x + x,) * 3
        print(sum(frames.add.stats.cache_hits.values()),
              sum(frames.add.stats.cache_misses.values()))
    """, tmp_path).stdout
    assert out.split() == [str(len(kinds)), "0"]


def test_a_unit_starts_after_the_owners_of_its_modules():
    order, after = prepare.schedule(prepare.units())
    assert sorted(order) == prepare.units()
    assert {"solve", "bushing"} <= after["engine"] and "constraints" not in after["engine"]
    assert "solve" in after["constraints"] and "engine" in after["calculators"]
    # A unit waits for the owner of each module it holds: of the units holding the module, the
    # one with the fewest modules (ties by name).
    deps = {n: prepare._kernel_deps(n) for n in order}
    for a, bs in after.items():
        owners = {min((u for u in order if d in deps[u]), key=lambda u: (len(deps[u]), u))
                  for d in deps[a]} - {a}
        assert bs == owners


def _callee_called_with_two_constants(module: str):
    """A kernel of ``module`` called by another with the constants 2 and 3; its signatures."""
    def shift(x, k):
        return x + k
    shift.__module__ = module
    shift = njit(shift)

    @njit
    def caller(x):
        return shift(x, 2) * shift(x, 3)
    assert caller(1.0) == 12.0                  # (1 + 2) (1 + 3)
    return [tuple(str(a) for a in sig) for sig in shift.signatures]


def test_a_kernel_of_the_package_is_compiled_once_per_argument_types_not_per_constant():
    # numba's own rule, for a function outside the package: one machine code per constant.
    assert _callee_called_with_two_constants("elsewhere") == [
        ("float64", "Literal[int](2)"), ("float64", "Literal[int](3)")]
    # A kernel of the package: one, for the constants' type.
    assert _callee_called_with_two_constants(f"{cc.PACKAGE}.probe") == [("float64", "int64")]


def test_a_kernel_that_numba_cannot_cache_is_warned_of_by_its_file_not_raised():
    # numba's check before it saves a machine code: one with dynamic globals (as NUMBA_OPT=0
    # leaves some) is not saved, and numba warns naming the kernel's file from its locator.
    import types as pytypes
    import warnings
    from numba.core.errors import NumbaWarning
    from drake_dock.core.kernels import couples
    impl = couples.evaluate_one._cache._impl
    cres = pytypes.SimpleNamespace(lifted=(), library=pytypes.SimpleNamespace(
        has_dynamic_globals=True), fndesc=pytypes.SimpleNamespace(qualname="evaluate_one"))
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        assert impl.check_cachable(cres) is False
    assert [w.filename for w in caught if issubclass(w.category, NumbaWarning)] == [
        couples.__file__]
