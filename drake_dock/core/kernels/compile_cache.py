"""Where numba caches the compiled kernels, so that the JIT cost is paid once per machine.

The kernels are compiled with ``cache=True``: the first run compiles them (several seconds) and
writes the machine code to a cache keyed by source file and CPU; later runs load it. The cache
directory is, in order:

1. ``NUMBA_CACHE_DIR`` if it is set (numba's own variable);
2. the ``__pycache__`` directories next to the kernel sources, if they are writable (an
   editable or user install);
3. otherwise (a read-only install) ``$XDG_CACHE_HOME/drake_dock/numba``, by default
   ``~/.cache/drake_dock/numba``.

`configure` sets ``NUMBA_CACHE_DIR`` for case 3 before numba is imported; `cache_dir` says which
directory is in use. ``python -m drake_dock.core.kernels`` compiles (or loads)
every kernel once and prints the directory.
"""
from __future__ import annotations

import os
import pathlib

_HERE = pathlib.Path(__file__).resolve().parent


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


def configure() -> None:
    """Sets ``NUMBA_CACHE_DIR`` to the user cache directory when it is not set and the package
    directory is not writable (and numba's config, in case numba was imported before)."""
    if os.environ.get("NUMBA_CACHE_DIR") or _writable(_HERE):
        return
    path = user_cache_dir()
    path.mkdir(parents=True, exist_ok=True)
    os.environ["NUMBA_CACHE_DIR"] = str(path)
    from numba.core import config      # numba reads the variable once, at its import
    config.CACHE_DIR = str(path)


def cache_dir() -> pathlib.Path:
    """The directory the compiled kernels are cached in."""
    env = os.environ.get("NUMBA_CACHE_DIR")
    return pathlib.Path(env) if env else _HERE / "__pycache__"


def warm() -> None:
    """Compiles (or loads from the cache) every kernel by evaluating the kernels once."""
    from drake_dock.core.kernels import cover, seek, tracked
    tracked.warm()
    seek.warm()
    cover.warm()
