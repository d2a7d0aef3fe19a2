"""Compiling the kernels before a run needs them: once, in parallel, with a line per module.

A unit is a module of this package with a top-level ``warm()`` (found in the sources: there is
no list to keep up to date). Its ``warm()`` compiles or loads the module's kernels, and those of
the kernel modules it calls, by evaluating them once on a small case with the argument types of
a run. `warm` runs every unit in this process. `prepare` (``python -m drake_dock.core.kernels``;
``drake-dock run`` and ``study`` take it in two halves, `Preparation`) first compiles the units
whose cache is missing (no ``warm.done`` in their module's cache directory,
`compile_cache.module_cache_dir`, whose key covers everything the unit compiles) in up to
``jobs`` worker processes (``python -m drake_dock.core.kernels --worker``, each taking one unit
after another), a line per unit with its time, then loads every unit here.

Order (`schedule`): each kernel module is owned by the unit with the fewest kernel modules that
holds it, and a unit starts after the owners of the modules it holds (`engine` after `solve`,
which owns the constraint solve that `constraints` calls too): common callees are then compiled
once, by their owner, and loaded by the others, and two units that share only an owner's
modules compile side by side. Among the units free to start, the one heading the longest chain
of waiting units goes first, a unit's length being the kernel source lines of the modules it
owns (a rough measure of its compile time, which is mostly that of the modules it compiles: a
unit that holds many modules but owns few, such as `calculators`, links the others' code from
the cache and is among the quicker ones; `bench/cold_start.py` prints each unit's time).

`Preparation` splits `prepare` in two around the caller's own start-up: `Preparation.start` sets
the missing units compiling in the workers (a thread here feeds them), `Preparation.finish`
loads each unit here as soon as it is compiled (while the others compile), then the rest.
``drake-dock run`` and ``drake-dock study`` start it before they import the simulation and
read their input.
"""
from __future__ import annotations

import ast
import contextlib
import importlib
import os
import queue
import select
import signal
import subprocess
import sys
import threading
import time

from drake_dock.core.kernels import compile_cache as cc

MARKER = "warm.done"


def kernel_modules(package=cc._PACKAGE) -> list[str]:
    """The modules of the kernels package (short names), infrastructure aside."""
    here = package / "core" / "kernels"
    return sorted(p.stem for p in here.glob("*.py")
                  if p.stem not in ("__init__", "__main__", "compile_cache", "prepare"))


def units(package=cc._PACKAGE) -> list[str]:
    """The kernel modules that define a top-level ``warm()``."""
    here = package / "core" / "kernels"

    def has_warm(name):
        tree = ast.parse((here / f"{name}.py").read_bytes())
        return any(isinstance(n, ast.FunctionDef) and n.name == "warm" for n in tree.body)
    return [m for m in kernel_modules(package) if has_warm(m)]


def _kernel_deps(name: str, package=cc._PACKAGE) -> set[str]:
    """The kernel modules (short names) that unit ``name`` imports, itself included."""
    prefix, kernels = cc.PACKAGE + ".", set(kernel_modules(package))
    return {d[len(prefix):] for d in cc.dependencies(prefix + name, package)
            if d.startswith(prefix) and d[len(prefix):] in kernels}


def schedule(names: list[str], package=cc._PACKAGE):
    """(the units ``names`` in the order they are started when free to, {unit: the units
    among ``names`` it starts after}): see the module docstring."""
    deps = {n: _kernel_deps(n, package) for n in names}
    # Each kernel module's owner: the unit with the fewest kernel modules that holds it.
    owner = {}
    for n in sorted(names, key=lambda n: (len(deps[n]), n)):
        for d in deps[n]:
            owner.setdefault(d, n)
    after = {a: {owner[d] for d in deps[a]} - {a} for a in names}
    here = package / "core" / "kernels"

    def length(n):  # the kernel source lines of the modules unit n owns (compiles)
        return sum((here / f"{m}.py").read_bytes().count(b"\n") for m in deps[n]
                   if owner[m] == n)

    def path(n):    # its length and that of the longest chain of units waiting for it
        return length(n) + max((path(a) for a in names if n in after[a]), default=0)
    return sorted(names, key=lambda n: (-path(n), n)), after


def _marker(name: str):
    return cc.module_cache_dir(name) / MARKER


def missing(names: list[str] | None = None) -> list[str]:
    """The units (of ``names``, default all) whose kernels are not all in the cache."""
    return [n for n in (units() if names is None else names) if not _marker(n).is_file()]


def compile_unit(name: str) -> float:
    """Runs unit ``name``'s ``warm()`` in this process (compiling what the cache lacks) and
    marks it done; returns the seconds it took."""
    t0 = time.perf_counter()
    importlib.import_module(f"{cc.PACKAGE}.{name}").warm()
    seconds = time.perf_counter() - t0
    _marker(name).parent.mkdir(parents=True, exist_ok=True)
    _marker(name).write_text(f"{seconds:.2f}\n")
    return seconds


def _say(stream, text: str) -> None:
    if stream is not None:
        stream.write(text + "\n")
        stream.flush()


def warm(names: list[str] | None = None, stream=None) -> None:
    """Compiles or loads the units ``names`` (default all) in this process, in `schedule`
    order, with a line per unit on ``stream`` if given."""
    order, _ = schedule(units() if names is None else names)
    t0 = time.perf_counter()
    for i, name in enumerate(order):
        seconds = compile_unit(name)
        _say(stream, f"  {name}: {seconds:.1f} s ({i + 1} of {len(order)}, "
                     f"{time.perf_counter() - t0:.0f} s so far)")


def _workers(jobs: int) -> list[subprocess.Popen]:
    """``jobs`` processes ``python -m drake_dock.core.kernels --worker`` on this process's
    drake_dock sources and cache base: each compiles the units named on its stdin, one a line,
    and answers each with a line "NAME SECONDS" (the numba it warmed up and the kernels it
    compiled serve its next unit). Each runs in a session of its own: Ctrl-C at a terminal
    reaches this process only, which stops them (`Preparation.cancel`), even while they are
    still importing numba."""
    path = os.pathsep.join([str(cc._PACKAGE.parent)] + [p for p in [os.environ.get(
        "PYTHONPATH")] if p])
    env = dict(os.environ, NUMBA_CACHE_DIR=str(cc.cache_dir().parent), PYTHONPATH=path)
    return [subprocess.Popen([sys.executable, "-m", cc.PACKAGE, "--worker"], env=env,
                             stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True,
                             start_new_session=True)
            for _ in range(jobs)]


def serve(lines, out) -> None:
    """A worker's loop: compiles each unit named in ``lines`` and writes "NAME SECONDS". Its
    parent owns it: Ctrl-C is the parent's to handle (a SIGINT sent here all the same is
    ignored), and a parent gone (its pipe closed) ends the loop quietly."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    try:
        for line in lines:
            out.write(f"{line.strip()} {compile_unit(line.strip()):.3f}\n")
            out.flush()
    except BrokenPipeError:
        with contextlib.suppress(OSError, ValueError, AttributeError):   # no flush at exit
            os.dup2(os.open(os.devnull, os.O_WRONLY), out.fileno())


def compile_parallel(names: list[str], jobs: int, stream=None, compiled=None,
                     workers: list | None = None) -> None:
    """Compiles the units ``names`` in ``jobs`` worker processes, in `schedule` order, with a
    line per unit on ``stream`` as each one finishes, and ``compiled(name)`` called then if
    given. A failed unit raises RuntimeError (the worker's traceback is on stderr); the workers
    (``workers`` if given, else `_workers` started here) end with this call (killing one ends
    it with that RuntimeError)."""
    idle = list(workers) if workers is not None else _workers(jobs)
    busy, done, t0 = {}, set(), time.perf_counter()
    try:
        order, after = schedule(names)
        while order or busy:
            for name in [n for n in order if not after[n] - done][:len(idle)]:
                order.remove(name)
                proc = idle.pop()
                busy[proc] = name
                try:
                    proc.stdin.write(name + "\n")
                    proc.stdin.flush()
                except OSError:             # the worker is gone (killed)
                    raise RuntimeError(f"compiling the kernels of {cc.PACKAGE}.{name} "
                                       f"failed: its worker process ended") from None
            ready, _, _ = select.select([p.stdout for p in busy], [], [])
            for proc in [p for p in busy if p.stdout in ready]:
                answer = proc.stdout.readline().split()
                name = busy.pop(proc)
                idle.append(proc)
                if len(answer) != 2:
                    raise RuntimeError(f"compiling the kernels of {cc.PACKAGE}.{name} failed "
                                       f"(see above)")
                done.add(name)
                _say(stream, f"  {name}: {float(answer[1]):.1f} s ({len(done)} of "
                             f"{len(names)}, {time.perf_counter() - t0:.0f} s so far)")
                if compiled is not None:
                    compiled(name)
    finally:
        for proc in idle + list(busy):
            with contextlib.suppress(OSError):
                proc.stdin.close()          # the worker's loop ends
            if proc in busy:
                proc.kill()
            proc.wait()
            proc.stdout.close()


def cores() -> int:
    """The cores this process may run on."""
    try:
        return len(os.sched_getaffinity(0))
    except AttributeError:
        return os.cpu_count() or 1


def prepare(stream=None, jobs: int | None = None, names: list[str] | None = None) -> float:
    """Compiles the missing units of ``names`` (default all) in up to ``jobs`` processes
    (default `cores`; in this process when one, or one unit, is missing), saying so on
    ``stream`` with a line per unit, then loads every unit here. Returns the seconds taken."""
    preparation = Preparation.start(stream, jobs, names)
    try:
        return preparation.finish()
    except BaseException:
        preparation.cancel()                # no worker outlives a failure or Ctrl-C
        raise


class Preparation:
    """`prepare` begun (`start`) and ended (`finish`) apart, so that the caller's own start-up
    runs while the workers compile (module docstring); `cancel` stops them."""

    def __init__(self, stream, jobs, names):
        self.stream, self.names, self.t0 = stream, names, time.perf_counter()
        self.todo = missing(names)
        self.jobs = max(1, min(jobs or cores(), len(self.todo))) if self.todo else 0
        self._compiled = queue.Queue()       # units compiled by the workers, then None
        self._failure = None
        self._workers = []
        self._thread = None
        self._waited = 0.0                   # s the caller spent in `start`

    @classmethod
    def start(cls, stream=None, jobs: int | None = None,
              names: list[str] | None = None) -> "Preparation":
        """Says what compiles (on ``stream``) and starts the workers on the missing units of
        ``names`` (default all) when more than one process compiles them."""
        self = cls(stream, jobs, names)
        t0 = self.t0
        if self.todo:
            n, j = len(self.todo), self.jobs
            _say(stream, f"drake-dock: compiling the numba kernels, {n} module"
                         f"{'s' if n > 1 else ''} in {j} process{'es' if j > 1 else ''} "
                         f"(after an install or an update only; later runs load them from "
                         f"the cache)")
        if self.jobs > 1:
            self._workers = _workers(self.jobs)
            self._thread = threading.Thread(target=self._compile, daemon=True,
                                            name="drake-dock kernels")
            self._thread.start()
        self._waited = time.perf_counter() - t0
        return self

    def _compile(self):
        try:
            compile_parallel(self.todo, self.jobs, self.stream, self._compiled.put,
                             self._workers)
        except BaseException as e:  # noqa: BLE001 - re-raised by `finish`
            self._failure = e
        finally:
            self._compiled.put(None)

    def finish(self) -> float:
        """Loads every unit here (each compiled one as soon as a worker is done with it, one
        process compiling: all here, a line per unit) and returns the seconds the caller
        spent in `start` and here (what the kernels held it up); a unit that failed to
        compile raises RuntimeError."""
        t0 = time.perf_counter()
        if self._thread is not None:
            for name in iter(self._compiled.get, None):
                importlib.import_module(f"{cc.PACKAGE}.{name}").warm()
            self._thread.join()
            if self._failure is not None:
                raise self._failure
        elif self.todo:
            warm(self.todo, self.stream)
        warm(self.names)
        if self.todo:
            _say(self.stream, f"drake-dock: kernels compiled in "
                              f"{time.perf_counter() - self.t0:.0f} s")
        return self._waited + time.perf_counter() - t0

    def cancel(self) -> None:
        """Stops the workers (their units left unmarked compile again next time) and waits for
        them and for the thread that fed them."""
        for proc in list(self._workers):
            with contextlib.suppress(OSError):
                proc.kill()
        if self._thread is not None:
            self._thread.join()
        for proc in self._workers:          # reaped by the thread's call, unless it never ran
            proc.wait()
            for pipe in (proc.stdin, proc.stdout):
                with contextlib.suppress(OSError):
                    pipe.close()
