"""The APDS's dimensions (Sect. 8.2) and the contact sets a scenario may name: the parts of the
scenario that the geometry reads. Plain Python and numpy (no Drake), so that the geometry, the
placement and the checks, which read only these, run without Drake. No ``from __future__ import
annotations`` here: Drake's ``yaml_load_typed`` reads the fields' types as objects."""
import dataclasses
import math
import typing

import numpy as np

from drake_dock.errors import InputError

# The contact sets a docking scene names (`contact.pairs`; `drake_dock.docking.geometry.pairs`):
# the paper's 12 pairs, or those and the edge and face pairs they leave out.
PAIR_SETS = ("paper", "complete")


@dataclasses.dataclass
class ApdsGeometry:
    """Dimensions of an APDS (Sect. 8.2). Lengths in m, angles in degrees."""

    R: float = 0.6          # outer radius of the guide ring
    Rs: float = 0.4         # radius of the inside circle of the ring (passage radius)
    H: float = 0.2          # petal height
    alpha1_deg: float = 45.0  # cone angle between generatrix and ring plane
    alpha2_deg: float = 30.0  # angle of an auxiliary plane with its radius line
    # Radius of the petals' roots on the ring face (m), Rs <= petal_root_radius <= R; null:
    # R, the paper's petals, which stand on the ring's outside circle. At Rs they stand on
    # the ring's inside circle and pass through the other ring's passage, so that the rings
    # can meet face to face (docs/model.md, "APDS geometry").
    petal_root_radius: typing.Optional[float] = None
    # The petals' sides start this far inside their 60-degree sectors (deg; the paper's 0):
    # a petal spans [delta, 60 - delta] deg at its root, so that the two APDS's petals,
    # interleaved, keep 2 delta apart there (docs/model.md, "APDS geometry").
    petal_inset_deg: float = 0.0

    def validate(self, prefix: str = "geometry") -> "ApdsGeometry":
        names = ("R", "Rs", "H", "alpha1_deg", "alpha2_deg", "petal_inset_deg")
        if self.petal_root_radius is not None:
            names += ("petal_root_radius",)
        for name in names:
            v = getattr(self, name)
            if not isinstance(v, (int, float)) or isinstance(v, bool) or not math.isfinite(v):
                raise InputError(f"{prefix}.{name}", v, "a finite number")
        if self.R <= 0:
            raise InputError(f"{prefix}.R", self.R, "R > 0 m")
        for name in ("alpha1_deg", "alpha2_deg"):
            v = getattr(self, name)
            if not 0.0 < v < 90.0:
                raise InputError(f"{prefix}.{name}", v, "0 < angle < 90 deg")
        if not 0.0 < self.Rs < self.R:
            raise InputError(f"{prefix}.Rs", self.Rs, f"0 < Rs < R = {self.R} m")
        Rp, root = self.Rp, (f"{prefix}.petal_root_radius" if self.petal_root_radius
                             is not None else f"{prefix}.R")
        if self.petal_root_radius is not None and not self.Rs <= Rp <= self.R:
            raise InputError(root, Rp, f"Rs = {self.Rs} <= petal_root_radius <= R = {self.R} m, "
                             "or null (R)", "a petal rooted inside the passage would leave its "
                             "root edge free, which the contact set does not model")
        if not 0.0 <= self.petal_inset_deg < 30.0:
            raise InputError(f"{prefix}.petal_inset_deg", self.petal_inset_deg,
                             "0 <= inset < 30 deg")
        cot1 = 1.0 / math.tan(math.radians(self.alpha1_deg))
        h_max = Rp / cot1
        if not 0.0 < self.H < h_max:
            raise InputError(f"{prefix}.H", self.H,
                             f"0 < H < Rp tan(alpha1) = {h_max:.6g} m (H cot(alpha1) < Rp, the "
                             f"petal root radius)", "the petal would reach the axis")
        a2 = math.radians(self.alpha2_deg)
        arg = Rp * math.sin(a2) / (Rp - self.H * cot1)
        # The two sides of a petal must not meet below zeta = H: theta_end < pi/6 - inset.
        half = math.pi / 6 - self.inset
        if arg >= 1.0 or math.asin(arg) - a2 >= half:
            limit = Rp * (1.0 - math.sin(a2) / math.sin(a2 + half)) / cot1
            raise InputError(f"{prefix}.H", self.H,
                             f"H < {limit:.6g} m for Rp = {Rp}, alpha1 = {self.alpha1_deg},"
                             f" alpha2 = {self.alpha2_deg}, petal_inset_deg = "
                             f"{self.petal_inset_deg}", "the petal's sides would cross")
        return self

    # Derived quantities ---------------------------------------------------------------------
    @property
    def Rp(self) -> float:
        """The petals' root radius (m): ``petal_root_radius``, or R (the paper's)."""
        return self.R if self.petal_root_radius is None else float(self.petal_root_radius)

    @property
    def inset(self) -> float:
        """``petal_inset_deg`` in rad."""
        return math.radians(self.petal_inset_deg)

    @property
    def tip_radius(self) -> float:
        """The radius of the petal tips' arcs, Rp - H cot(alpha1) (m)."""
        return self.Rp - self.H / math.tan(self.alpha1)

    @property
    def alpha1(self) -> float:
        return math.radians(self.alpha1_deg)

    @property
    def alpha2(self) -> float:
        return math.radians(self.alpha2_deg)

    @property
    def theta_end(self) -> float:
        """Angular extent of a guide side, arcsin(R sin a2 / (R - H cot a1)) - a2 (rad)."""
        return self.theta_1(self.H)

    def theta_1(self, zeta):
        """Eq. (13): angular inset of the petal's sides at height zeta."""
        rho = self.Rp - np.asarray(zeta, dtype=float) / math.tan(self.alpha1)
        return np.arcsin(self.Rp * math.sin(self.alpha2) / rho) - self.alpha2
