"""Where numba caches the compiled kernels, under keys per module, so that the JIT cost is paid
once per machine and an edit recompiles only what it touched.

The kernels are compiled with ``cache=True``: the first run compiles them and writes the machine
code to the cache; later runs load it. `configure` (run when the kernels package is imported,
before any kernel is decorated) puts `KeyedLocator` first in numba's cache locators. It places
the kernels of module M (a file of this package) in ``<base>/drake_dock/M-<key>``, with the key
as numba's source stamp:

- the key (`module_key`) is a digest of numba's version, the optimisation level and the sources
  of M and of every drake_dock module M imports, transitively (`dependencies`, read with `ast`;
  a package's ``__init__`` counts when a name is imported from it). numba checks only a
  function's own file, so without the key a kernel whose callee in another module changed would
  load stale machine code; with it an edit gives new keys to the modules it touched and to
  those that import them, and to no other;
- the base directory is, in order, ``NUMBA_CACHE_DIR`` if set (numba's own variable); the
  ``__pycache__`` next to the kernel sources if writable (an editable or user install); else
  ``$XDG_CACHE_HOME/drake_dock/numba`` (default ``~/.cache/drake_dock/numba``).

Concurrent writers (the parallel compile, `drake_dock.core.kernels.prepare`, or two runs at
once): numba writes each index and data file whole (a temporary file, then ``os.replace``), but
adding a signature to a function's index reads the index, numbers the new data file after the
entries it read, and writes both: two processes adding different signatures of one function at
once could leave an entry naming the other's machine code (numba issue #10128 shows the same
race for gufuncs). `configure` makes that step hold an exclusive ``flock`` on the directory's
``index.lock``. A directory holds one key only, so a data file's name keeps its meaning.

One machine code per argument types: numba types a constant argument of a call between kernels
as a literal (``Literal[int](3)``, ``Literal[bool](True)``) and compiles the callee again for
each constant it is called with (a record's field getter once per field, the seek's Newton
solve once per iteration limit). `configure` makes a kernel of this package type its callers'
arguments without their literal values (`_unliteral`): each callee is compiled once per
argument types, which takes about a sixth off the compile (docs/performance.md, "Compiled
kernels") and leaves the results bit for bit (no kernel branches on a constant's type).

``python -m drake_dock.core.kernels`` compiles (or loads) every kernel and prints the directory.
"""
from __future__ import annotations

import ast
import contextlib
import functools
import hashlib
import os
import pathlib
import tempfile

import numba
from numba.core import caching, config, types
from numba.core.dispatcher import Dispatcher
from numba.core.caching import _CacheLocator

try:
    import fcntl
except ImportError:          # not POSIX: no lock (the parallel compile is for POSIX machines)
    fcntl = None

_HERE = pathlib.Path(__file__).resolve().parent
_CORE = _HERE.parent
_PACKAGE = _CORE.parent                     # drake_dock/
PACKAGE = "drake_dock.core.kernels"
# numba's optimisation level for the kernels, unless NUMBA_OPT is set: 1 compiles them in about
# 3/4 of the time of numba's default 3, runs them as fast and gives the same bits
# (docs/performance.md, "Compiled kernels"). 0 would leave some uncacheable.
OPT = 1
_base = None          # the base directory, set by `configure`


def user_cache_dir() -> pathlib.Path:
    """``$XDG_CACHE_HOME/drake_dock/numba`` (default ``~/.cache/drake_dock/numba``)."""
    base = os.environ.get("XDG_CACHE_HOME") or os.path.join(os.path.expanduser("~"), ".cache")
    return pathlib.Path(base) / "drake_dock" / "numba"


def _writable(path: pathlib.Path) -> bool:
    try:
        path.mkdir(parents=True, exist_ok=True)
    except OSError:
        return False
    return os.access(path, os.W_OK)


def module_file(name: str, package: pathlib.Path = _PACKAGE) -> pathlib.Path | None:
    """The source of the drake_dock module ``name`` (dotted) in the package directory
    ``package``, or None when it is not one."""
    parts = name.split(".")
    if parts[0] != "drake_dock":
        return None
    base = package.joinpath(*parts[1:])
    if (base / "__init__.py").is_file():
        return base / "__init__.py"
    if len(parts) > 1 and base.with_name(base.name + ".py").is_file():
        return base.with_name(base.name + ".py")
    return None


def _imports(name: str, package: pathlib.Path) -> set[str]:
    """The drake_dock modules that module ``name``'s source imports (anywhere in the file)."""
    path = module_file(name, package)
    here = name if path.name == "__init__.py" else name.rsplit(".", 1)[0]
    st = path.stat()
    return _parsed_imports(str(path), st.st_mtime_ns, st.st_size, here, package)


def _statements(nodes):
    """The statements ``nodes`` and those nested in them (imports are statements: expressions
    are not walked, which makes it quick)."""
    for node in nodes:
        yield node
        for field in ("body", "orelse", "finalbody", "handlers", "cases"):
            yield from _statements(getattr(node, field, None) or [])


@functools.lru_cache(maxsize=None)
def _parsed_imports(path: str, mtime_ns: int, size: int, here: str,
                    package: pathlib.Path) -> frozenset[str]:
    """`_imports` of the file as it is at (mtime_ns, size): parsed once per version."""
    found = set()
    for node in _statements(ast.parse(pathlib.Path(path).read_bytes(), filename=path).body):
        if isinstance(node, ast.Import):
            found.update(a.name for a in node.names)
        elif isinstance(node, ast.ImportFrom):
            mod = node.module or ""
            if node.level:
                base = here.split(".")[:len(here.split(".")) - node.level + 1]
                mod = ".".join(base + ([mod] if mod else []))
            for a in node.names:      # a submodule, or a name of the module
                found.add(f"{mod}.{a.name}" if module_file(f"{mod}.{a.name}", package) else mod)
    return frozenset(m for m in found if module_file(m, package) is not None)


def dependencies(name: str, package: pathlib.Path = _PACKAGE) -> list[str]:
    """Module ``name`` and every drake_dock module it imports, transitively, sorted."""
    seen, todo = {name}, [name]
    while todo:
        for m in _imports(todo.pop(), package) - seen:
            seen.add(m)
            todo.append(m)
    return sorted(seen)


def opt_level() -> str:
    """numba's optimisation level for the kernels: ``NUMBA_OPT`` if set, else `OPT`."""
    return os.environ.get("NUMBA_OPT") or str(OPT)


def module_key(name: str, package: pathlib.Path = _PACKAGE) -> str:
    """A digest of numba's version, `opt_level` and the sources (names and bytes) of
    `dependencies`: it changes when the module or a module it imports changes."""
    digest = hashlib.sha256(f"numba {numba.__version__} "
                            f"opt {opt_level()} unliteral".encode())
    for dep in dependencies(name, package):
        digest.update(dep.encode() + b"\0" + module_file(dep, package).read_bytes() + b"\0")
    return digest.hexdigest()[:16]


@functools.lru_cache(maxsize=None)
def _key(name: str) -> str:
    return module_key(name)             # once per process: the sources do not change under it


def cache_dir() -> pathlib.Path:
    """The directory holding the kernels' module directories ``<module>-<key>``."""
    if _base is None:
        configure()
    return _base / "drake_dock"


def module_cache_dir(name: str) -> pathlib.Path:
    """Where the kernels of module ``name`` (short, e.g. ``couples``) are cached."""
    return cache_dir() / f"{name}-{_key(f'{PACKAGE}.{name}')}"


class KeyedLocator(_CacheLocator):
    """numba's cache locator for the functions of this package's files: their module's
    directory `module_cache_dir`, its key as the source stamp."""

    def __init__(self, py_func, path: pathlib.Path):
        self._py_file = str(path)            # numba's warning of a kernel it cannot cache
        self._lineno = py_func.__code__.co_firstlineno
        self._stamp = _key(f"{PACKAGE}.{path.stem}")
        self._path = str(module_cache_dir(path.stem))

    def get_cache_path(self):
        return self._path

    def get_source_stamp(self):
        return self._stamp

    def get_disambiguator(self):
        return str(self._lineno)

    @classmethod
    def from_function(cls, py_func, py_file):
        path = pathlib.Path(py_file).resolve()
        if path.parent != _HERE:
            return None                      # not a kernel: numba's own locators
        self = cls(py_func, path)
        self.ensure_cache_path()
        return self


@contextlib.contextmanager
def _flock(path: str):
    """An exclusive lock on the file ``path`` while the block runs (none without fcntl)."""
    if fcntl is None:
        yield
        return
    fd = os.open(path, os.O_RDWR | os.O_CREAT, 0o644)
    try:
        fcntl.flock(fd, fcntl.LOCK_EX)
        yield
    finally:
        os.close(fd)                         # releases the lock


def _locked(save):
    """numba's ``IndexDataCacheFile.save`` holding `_flock` in the kernels' directories."""
    @functools.wraps(save)
    def locked_save(self, key, data):
        if not str(self._cache_path).startswith(str(cache_dir())):
            return save(self, key, data)
        with _flock(os.path.join(self._cache_path, "index.lock")):
            return save(self, key, data)
    locked_save.drake_dock_locked = True
    return locked_save


def _unliteral(get_call_template):
    """numba's ``Dispatcher.get_call_template`` typing a call to a kernel of this package with
    the arguments' types without their literal values (the module docstring)."""
    @functools.wraps(get_call_template)
    def call_template(self, args, kws):
        if getattr(self.py_func, "__module__", "").startswith(PACKAGE + "."):
            args = tuple(types.unliteral(a) for a in args)
            kws = {k: types.unliteral(v) for k, v in kws.items()}
        return get_call_template(self, args, kws)
    call_template.drake_dock_unliteral = True
    return call_template


def _choose_base() -> pathlib.Path:
    """The base directory of the module docstring's rules (a fresh temporary directory when
    none of them is writable: the kernels are then compiled in every process)."""
    env = os.environ.get("NUMBA_CACHE_DIR")
    for path in ([pathlib.Path(env)] if env else [_HERE / "__pycache__", user_cache_dir()]):
        if _writable(path / "drake_dock"):
            return path
    return pathlib.Path(tempfile.mkdtemp(prefix="drake_dock-numba-"))


def configure() -> None:
    """Chooses the base directory, sets ``NUMBA_OPT`` to `opt_level` (numba reads it again
    before it compiles), puts `KeyedLocator` first in numba's locators, locks the index
    updates and types the kernels' calls without literals (`_unliteral`). Idempotent."""
    global _base
    if _base is not None:
        return
    _base = _choose_base()
    os.environ["NUMBA_OPT"] = opt_level()
    classes = os.environ.get("NUMBA_CACHE_LOCATOR_CLASSES")
    if classes and "KeyedLocator" not in classes:   # it replaces numba's list: ours first there
        os.environ["NUMBA_CACHE_LOCATOR_CLASSES"] = f"{__name__}.KeyedLocator,{classes}"
    config.reload_config()
    impl = getattr(caching, "CacheImpl", None) or caching._CacheImpl
    if KeyedLocator not in impl._locator_classes:
        impl._locator_classes.insert(0, KeyedLocator)
    if not getattr(caching.IndexDataCacheFile.save, "drake_dock_locked", False):
        caching.IndexDataCacheFile.save = _locked(caching.IndexDataCacheFile.save)
    if not getattr(Dispatcher.get_call_template, "drake_dock_unliteral", False):
        Dispatcher.get_call_template = _unliteral(Dispatcher.get_call_template)

