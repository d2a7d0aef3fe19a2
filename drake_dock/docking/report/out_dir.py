"""Output directories: where drake_dock may write, atomic replacement, and arrays written to the
bytes (`npz_bytes`).

Everything is written into a temporary sibling directory, which replaces the destination in one
rename only when complete. A failed run leaves no directory, or the previous complete one
untouched.

The destination must be a new path, an empty directory or a previous drake_dock output: a
directory holding the marker file `MARKER` (written into every output, listing the entries
written) and nothing else. Anything else (a file, a directory with other files, a symbolic link
to something that is not an output, the current directory or one of its parents, the home
directory or one of its parents, a place that cannot be written) is refused with `InputError`
naming the path (`check_destination`), before anything is simulated and again by
`atomic_directory` itself. Only directories drake_dock created, or previous outputs carrying
the marker, are ever removed.
"""
from __future__ import annotations

import contextlib
import io
import json
import os
import shutil
import tempfile
from pathlib import Path

import numpy as np

from drake_dock import __version__
from drake_dock.errors import InputError

MARKER = ".drake_dock_output"
ALLOWED = (f"a new path, an empty directory or a previous drake_dock output (a directory "
           f"holding {MARKER} and only what drake_dock wrote with it)")
PRODUCER = "drake_dock"


def _refuse(path, why):
    raise InputError("--out", str(path), ALLOWED, why)


def _entries(root: Path) -> list[str]:
    """Every file and directory under ``root``, as sorted relative POSIX paths."""
    out = []
    for dirpath, dirnames, filenames in os.walk(root):
        rel = Path(dirpath).relative_to(root)
        out += [(rel / n).as_posix() for n in dirnames + filenames]
    return sorted(out)


def _marker(root: Path) -> dict | None:
    m = root / MARKER
    try:
        if m.is_symlink() or not m.is_file() or m.stat().st_size > 1_000_000:
            return None
        data = json.loads(m.read_text())
    except (OSError, ValueError):
        return None
    ok = isinstance(data, dict) and data.get("producer") == PRODUCER \
        and isinstance(data.get("entries"), list)
    return data if ok else None


def foreign_entries(path) -> list[str] | None:
    """None if ``path`` is not a drake_dock output (no valid marker); otherwise the entries
    under it that drake_dock did not write (empty for an untouched previous output)."""
    root = Path(path)
    if root.is_symlink() or not root.is_dir():
        return None
    data = _marker(root)
    if data is None:
        return None
    ours = set(map(str, data["entries"])) | {MARKER}
    return [e for e in _entries(root) if e not in ours]


def is_previous_output(path) -> bool:
    """A directory holding a valid marker and only the entries it lists."""
    return foreign_entries(path) == []


def _protected(dest: Path):
    """The current directory, the home directory and their parents."""
    for name, get in (("the current directory", Path.cwd), ("the home directory", Path.home)):
        try:
            p = get().resolve()
        except (OSError, RuntimeError, KeyError):
            continue
        if dest == p or dest in p.parents:
            _refuse(dest, f"{name} or one of its parents: replacing it would delete it")


def _probe_writable(dest: Path):
    """The nearest existing ancestor of ``dest`` must be a directory where a directory can be
    created and removed (a real probe: permissions, read-only file systems, ...)."""
    parent = dest.parent
    while not os.path.lexists(parent) and parent != parent.parent:
        parent = parent.parent
    if not parent.is_dir():
        _refuse(dest, f"{parent} is not a directory")
    try:
        os.rmdir(tempfile.mkdtemp(prefix=".drake_dock-probe-", dir=parent))
    except OSError as e:
        _refuse(dest, f"cannot write in {parent}: {e.strerror or e}")


def check_destination(path) -> Path:
    """Returns the resolved destination for an output directory, or raises `InputError` naming
    the path when writing there could destroy data or cannot succeed (module docstring)."""
    given = Path(path)
    try:
        dest = given.resolve()
    except (OSError, RuntimeError) as e:
        _refuse(given, f"the path cannot be resolved: {e}")
    if given.is_symlink() and not is_previous_output(dest):
        _refuse(given, f"a symbolic link to {dest}, which is not a drake_dock output")
    _protected(dest)
    if os.path.lexists(dest):
        if dest.is_symlink() or not dest.is_dir():
            _refuse(dest, "an existing file, not a directory")
        try:
            empty = not any(os.scandir(dest))
        except OSError as e:
            _refuse(dest, f"the directory cannot be read: {e.strerror or e}")
        foreign = foreign_entries(dest)
        if not empty and foreign is None:
            _refuse(dest, f"a non-empty directory that is not a drake_dock output (no {MARKER});"
                          " drake_dock replaces only its own outputs: choose a new path")
        if foreign:
            shown = ", ".join(foreign[:5]) + (", ..." if len(foreign) > 5 else "")
            _refuse(dest, f"a drake_dock output holding files drake_dock did not write "
                          f"({shown}); move them or choose a new path")
    _probe_writable(dest)
    return dest


def _write_marker(tmp: Path, kind: str):
    entries = _entries(tmp)
    (tmp / MARKER).write_text(json.dumps(
        {"producer": PRODUCER, "version": __version__, "kind": kind, "entries": entries},
        indent=1) + "\n")


def _remove_previous(old: Path):
    """Removes a destination moved aside: a previous output entirely, an empty directory;
    anything else (only possible if it changed during the run) is left where it is."""
    if is_previous_output(old):
        shutil.rmtree(old, ignore_errors=True)
    else:
        with contextlib.suppress(OSError):
            os.rmdir(old)


def _swap(tmp: Path, dest: Path):
    dest = check_destination(dest)    # again: the destination may have changed meanwhile
    if not os.path.lexists(dest):
        os.rename(tmp, dest)
        return
    old = tmp.with_name(tmp.name.replace(".tmp-", ".old-", 1))
    os.rename(dest, old)
    try:
        os.rename(tmp, dest)
    except OSError:
        os.rename(old, dest)
        raise
    _remove_previous(old)


@contextlib.contextmanager
def atomic_directory(dest, kind: str = "run"):
    """Yields a temporary directory next to ``dest``; on success the marker is written into
    it and it replaces ``dest`` (`check_destination` first, and again before the swap); on
    failure it is removed with the parents this call created, and ``dest`` is untouched."""
    dest = check_destination(dest)
    created = []
    p = dest.parent
    while not os.path.lexists(p):
        created.append(p)
        p = p.parent
    dest.parent.mkdir(parents=True, exist_ok=True)
    tmp = Path(tempfile.mkdtemp(prefix=f".{dest.name}.tmp-", dir=dest.parent))
    umask = os.umask(0)
    os.umask(umask)
    os.chmod(tmp, 0o777 & ~umask)      # mkdtemp makes it private; a result dir is not
    try:
        yield tmp
        _write_marker(tmp, kind)
        _swap(tmp, dest)
    except BaseException:
        if os.path.lexists(tmp):
            shutil.rmtree(tmp, ignore_errors=True)
        for d in created:              # innermost first; only if still empty
            with contextlib.suppress(OSError):
                os.rmdir(d)
        raise


def npz_bytes(arrays: dict) -> bytes:
    """np.savez_compressed into memory. Zip entries carry a fixed timestamp, so equal arrays
    give equal bytes (bitwise reproducible files)."""
    buf = io.BytesIO()
    np.savez_compressed(buf, **arrays)
    return buf.getvalue()
