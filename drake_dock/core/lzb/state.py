"""The state of one LZB impact in contact space (Sect. 6): the named slices of the integrated
vector and the event log (the phases of the couples are the kernel's,
`drake_dock.core.kernels.lzb_phases`)."""
from __future__ import annotations

import dataclasses


@dataclasses.dataclass
class ImpactEvent:
    """A phase event: ``kind`` is one of 'max_compression', 'recompression', 'end',
    're_impact' (a separated couple loads again), 'lock', 'release' (e = 0), 'stick', 'slip',
    'slip_reversal'; ``impulse`` is the total normal impulse (N s) so far."""

    impulse: float
    kind: str
    couple: int


class StateLayout:
    """Named slices of the state y = [x, u, P, W_comp, W_exp, W_fric] of s couples with nu
    contact-space components (nu = 3s with friction: normal, then the tangential pairs; s
    without): indentations x (s), relative velocities u = W^T v (nu, Eq. 11), impulses P (nu),
    per couple the compression and expansion works (Eq. 30-31) and the friction dissipation."""

    def __init__(self, s: int, nu: int):
        self.s, self.nu = s, nu
        self.size = 4 * s + 2 * nu
        self.x = slice(0, s)
        self.u = slice(s, s + nu)
        self.un = slice(s, 2 * s)
        self.ut = slice(2 * s, s + nu)          # the tangential pairs (empty without friction)
        self.P = slice(s + nu, s + 2 * nu)
        self.w_comp = slice(s + 2 * nu, 2 * s + 2 * nu)
        self.w_exp = slice(2 * s + 2 * nu, 3 * s + 2 * nu)
        self.w_fric = slice(3 * s + 2 * nu, 4 * s + 2 * nu)
