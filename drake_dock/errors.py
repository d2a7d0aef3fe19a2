"""Typed errors of drake_dock. Every error names what failed, the value and what was allowed
(input), or the time and the couple (numerical failure)."""
from __future__ import annotations

import contextlib


class DrakeDockError(Exception):
    """Base class of every error raised on purpose by drake_dock."""


MISSING = type("Missing", (), {"__repr__": lambda self: "missing"})()   # a value not given


class InputError(DrakeDockError, ValueError):
    """A bad input value: names the field and the value, then the reason (``why``, when it says
    more than the allowed range), then the allowed range: "--out = '/home/me' is not allowed:
    a non-empty directory that is not a drake_dock output; allowed: a new path, ..."."""

    def __init__(self, field: str, value, allowed: str, why: str = ""):
        self.field = field
        self.value = value
        self.allowed = allowed
        shown = repr(value)
        if len(shown) > 200:          # a whole file read as one value, say
            shown = shown[:200] + "..."
        if value is MISSING:
            msg = f"{field} is missing: {why + '; ' if why else ''}{allowed}"
        elif why:
            msg = f"{field} = {shown} is not allowed: {why}; allowed: {allowed}"
        else:
            msg = f"{field} = {shown} is not allowed: {allowed}"
        super().__init__(msg)


class NumericalError(DrakeDockError, RuntimeError):
    """A numerical failure, reported with the simulation time and the couples involved."""

    def __init__(self, message: str, *, time: float | None = None, couples=()):
        self.time = time
        self.couples = tuple(couples)
        where = []
        if time is not None:
            where.append(f"t = {time:.9g} s")
        if self.couples:
            where.append("couples " + ", ".join(map(str, self.couples)))
        super().__init__(message + (f" [{'; '.join(where)}]" if where else ""))


class SeekingError(NumericalError):
    """The closest couple of a pair could not be found (Newton did not converge)."""


class DriftError(NumericalError):
    """The integrated couple drifted from the closest-point conditions beyond tolerance."""


class ZenoError(NumericalError):
    """More impacts than ``max_impacts``: an impact sequence that does not end."""


class PainleveError(NumericalError):
    """No consistent contact mode, or several (Painleve inconsistency or indeterminacy)."""


class PainleveInconsistency(PainleveError):
    """No consistent contact mode: the rigid model with this friction has no solution (the
    contact system resolves it by an impact without collision unless told to stop)."""


class SingularContactError(NumericalError):
    """The constraint equations of the contact set are singular (redundant or degenerate
    contact Jacobian); the rigid model cannot distribute the contact forces."""


class SingularCoupleError(NumericalError):
    """The tracking Jacobian J of a couple is singular (Eq. 39 fails or the couple is not
    isolated): the couple must end, be handed over or be re-sought."""


@contextlib.contextmanager
def numerical_failure(what: str, where):
    """Any failure but drake_dock's typed errors becomes a `NumericalError` at ``where() ->
    (time, couples)``, naming the exception: Drake's integrator (a step below its minimum,
    ...), the arithmetic of extreme values (overflow, NaN: Drake refuses non-finite states; a
    C++ failure inside a Python callback arrives as SystemExit carrying its message)."""
    try:
        yield
    except DrakeDockError:
        raise
    except (Exception, SystemExit) as e:
        if isinstance(e, SystemExit) and not isinstance(e.code, str):
            raise
        time, couples = where()
        raise NumericalError(f"{what} failed ({type(e).__name__}: {e})", time=time,
                             couples=couples) from e
