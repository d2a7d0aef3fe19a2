"""Where numba caches the compiled kernels, so that the JIT cost is paid once per machine.

The kernels are compiled with ``cache=True``: the first run compiles them (several seconds) and
writes the machine code to a cache keyed by source file and CPU; later runs load it. The cache
directory is, in order:

1. ``NUMBA_CACHE_DIR`` if it is set (numba's own variable);
2. the ``__pycache__`` directories next to the kernel sources, if they are writable (an
   editable or user install);
3. otherwise (a read-only install) ``$XDG_CACHE_HOME/drake_dock/numba``, by default
   ``~/.cache/drake_dock/numba``.

Inside it the kernels go to ``drake_dock-<key>``, where the key is a digest of the sources of
``drake_dock/core`` and numba's version (`source_key`): numba checks only a kernel's own file,
so without the key a kernel whose callee in another module changed would load stale machine
code. `configure` sets ``NUMBA_CACHE_DIR`` to that directory before numba is imported;
`cache_dir` says which directory is in use. ``python -m drake_dock.core.kernels`` compiles (or loads)
every kernel once and prints the directory.
"""
from __future__ import annotations

import hashlib
import importlib.metadata
import os
import pathlib

_HERE = pathlib.Path(__file__).resolve().parent
_CORE = _HERE.parent
PREFIX = "drake_dock-"


def user_cache_dir() -> pathlib.Path:
    """``$XDG_CACHE_HOME/drake_dock/numba`` (default ``~/.cache/drake_dock/numba``)."""
    base = os.environ.get("XDG_CACHE_HOME") or os.path.join(os.path.expanduser("~"), ".cache")
    return pathlib.Path(base) / "drake_dock" / "numba"


def _writable(path: pathlib.Path) -> bool:
    probe = path / "__pycache__"
    try:
        probe.mkdir(exist_ok=True)
    except OSError:
        return False
    return os.access(probe, os.W_OK)


def source_key(root: pathlib.Path = _CORE) -> str:
    """A digest of every Python source under ``root`` (their paths and bytes) and of numba's
    version: it changes whenever a kernel or a module a kernel calls changes."""
    digest = hashlib.sha256(importlib.metadata.version("numba").encode())
    for path in sorted(root.rglob("*.py")):
        digest.update(path.relative_to(root).as_posix().encode() + b"\0" + path.read_bytes())
    return digest.hexdigest()[:16]


def configure() -> None:
    """Sets ``NUMBA_CACHE_DIR`` (and numba's config, in case numba was imported before) to
    ``drake_dock-<source_key()>`` inside the directory of the module docstring's rules."""
    base = os.environ.get("NUMBA_CACHE_DIR")
    if base and pathlib.Path(base).name.startswith(PREFIX):
        base = str(pathlib.Path(base).parent)      # set by this function in a parent process
    if not base:
        base = str(_HERE / "__pycache__") if _writable(_HERE) else str(user_cache_dir())
    path = pathlib.Path(base) / f"{PREFIX}{source_key()}"
    try:
        path.mkdir(parents=True, exist_ok=True)
    except OSError:
        pass                               # numba then compiles without caching
    os.environ["NUMBA_CACHE_DIR"] = str(path)
    from numba.core import config      # numba reads the variable once, at its import
    config.CACHE_DIR = str(path)


def cache_dir() -> pathlib.Path:
    """The directory the compiled kernels are cached in."""
    env = os.environ.get("NUMBA_CACHE_DIR")
    return pathlib.Path(env) if env else _HERE / "__pycache__"


def warm() -> None:
    """Compiles (or loads from the cache) every kernel by evaluating the kernels once."""
    from drake_dock.core.kernels import constraints, cover, lzb, seek, tracked
    tracked.warm()
    lzb.warm()
    constraints.warm()
    seek.warm()
    cover.warm()
