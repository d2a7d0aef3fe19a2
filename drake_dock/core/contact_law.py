"""The contact parameters shared by all couples: one dataclass for the contact system and for the
scenario's ``contact:`` field (the YAML keys are its field names). No ``from __future__ import annotations`` here: Drake's
``yaml_load_typed`` reads the fields' types as objects."""
import dataclasses
import math

from drake_dock.core.lzb.solve import LAWS
from drake_dock.errors import InputError


@dataclasses.dataclass
class ContactLaw:
    """Friction mu (sliding) and mu_s (static; unset means mu_s = mu), energetic restitution e,
    the LZB stiffness K and exponent eta of Eq. (28), and the multiple-impact law of Sect. 6
    ("paper", "mono" or "bi"; `drake_dock.core.lzb.solve`). The paper does not give these
    values (docs/model.md); the defaults are the example's."""

    mu: float = 0.1
    mu_s: float | None = None
    restitution: float = 0.1
    stiffness: float = 1.0e9
    eta: float = 1.5
    impact_law: str = "paper"

    @property
    def static_mu(self) -> float:
        """The static friction coefficient: mu_s, which defaults to mu."""
        return self.mu if self.mu_s is None else self.mu_s

    def validate(self, where: str = "contact") -> "ContactLaw":
        """Raises `InputError` naming ``<where>.<field>`` for a value out of its range."""
        _at_least(f"{where}.mu", self.mu, 0.0, ">= 0")
        if self.mu_s is not None:
            _at_least(f"{where}.mu_s", self.mu_s, 0.0, ">= 0")
            if self.mu_s < self.mu:
                raise InputError(f"{where}.mu_s", self.mu_s, f">= {where}.mu = {self.mu!r}",
                                 "static friction below sliding friction")
        _at_least(f"{where}.restitution", self.restitution, 0.0, "0 <= e <= 1")
        if self.restitution > 1:
            raise InputError(f"{where}.restitution", self.restitution, "0 <= e <= 1")
        for name in ("stiffness", "eta"):
            value = getattr(self, name)
            if _finite(f"{where}.{name}", value) <= 0:
                raise InputError(f"{where}.{name}", value, "> 0")
        if self.impact_law not in LAWS:
            raise InputError(f"{where}.impact_law", self.impact_law, f"one of {', '.join(LAWS)}")
        return self


def _finite(field, v) -> float:
    if not isinstance(v, (int, float)) or isinstance(v, bool) or not math.isfinite(v):
        raise InputError(field, v, "a finite number")
    return float(v)


def _at_least(field, v, low, allowed):
    if _finite(field, v) < low:
        raise InputError(field, v, allowed)
