"""The nonsmooth law of a couple in an LZB impact, apart from the integration (as Siconos keeps
its `MultipleImpactNSL` apart from the integrator): the loading curve of Eq. (28) and, at each
maximal compression, how the couple unloads under each restitution law (Eq. 36, 54). The rules
are stated in `drake_dock.core.lzb.solve`'s docstring."""
from __future__ import annotations

import dataclasses


def stored_energy(kappa, eta, x):
    """Energy stored at indentation x on the loading curve: Eq. (28) integrated,
    E = kappa x^(eta+1) / (eta+1)."""
    return kappa * max(x, 0.0) ** (eta + 1) / (eta + 1)


def indentation(kappa, eta, E):
    """The indentation at which the loading curve stores the energy E (inverse of
    `stored_energy`)."""
    return ((eta + 1) * max(E, 0.0) / kappa) ** (1.0 / (eta + 1))


@dataclasses.dataclass(frozen=True)
class Unloading:
    """How a couple expands after a maximal compression: from indentation ``x_start`` (None:
    where it is) at dx/dtau = -``rate`` u_n, until x reaches ``x_end``."""

    x_start: float | None
    x_end: float
    rate: float = 1.0


def paper(kappa, eta, e, E, work, wc_open) -> Unloading:
    """Eq. (54): E' = E - (1 - e^2) W; x jumps to the loading curve at E' and unloads on it
    to zero."""
    return Unloading(indentation(kappa, eta, E - (1.0 - e * e) * work), 0.0)


def mono(kappa, eta, e, E, work, wc_open) -> Unloading:
    """Unloads on the loading curve; ends when (1 - e^2) W_c is left (W_r = e^2 W_c, Eq. 36),
    W_c being the compression work since the contact began."""
    return Unloading(None, indentation(kappa, eta, (1.0 - e * e) * wc_open))


def bi(kappa, eta, e, E, work, wc_open) -> Unloading:
    """A stiffer unloading branch, dE = -(1/e^2) delta dP: dx/dtau = -u_n / e^2, to zero."""
    return Unloading(None, 0.0, 1.0 / (e * e))


UNLOADING = {"paper": paper, "mono": mono, "bi": bi}
LAWS = tuple(UNLOADING)
