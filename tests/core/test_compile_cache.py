"""The compiled kernels' cache directory is keyed by the sources of drake_dock/core: a change
in any module a kernel calls (not only in the kernel's own file, which is all numba checks)
gives a new directory, so stale machine code is never loaded."""
import shutil

from drake_dock.core.kernels import compile_cache


def test_the_key_follows_every_core_source(tmp_path):
    root = tmp_path / "core"
    shutil.copytree(compile_cache._CORE, root,
                    ignore=shutil.ignore_patterns("__pycache__"))
    key = compile_cache.source_key(root)
    assert key == compile_cache.source_key(compile_cache._CORE)   # same bytes, same key
    patches = root / "patches.py"                                  # a module kernels call
    patches.write_bytes(patches.read_bytes() + b"\n")
    assert compile_cache.source_key(root) != key
    patches.write_bytes(patches.read_bytes()[:-1])
    assert compile_cache.source_key(root) == key
    (root / "kernels" / "extra.py").write_text("X = 1\n")          # a new module
    assert compile_cache.source_key(root) != key


def test_the_kernels_are_cached_under_the_key():
    from numba.core import config
    where = compile_cache.cache_dir()
    assert where.name == compile_cache.PREFIX + compile_cache.source_key()
    assert config.CACHE_DIR == str(where)
