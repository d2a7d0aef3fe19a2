"""The contact parameters (drake_dock.core.contact_law): mu_s defaults to mu, and out-of-range
values are refused naming the field. Runs without Drake."""
import pytest

from drake_dock.core.contact_law import ContactLaw
from drake_dock.errors import InputError


def test_static_friction_defaults_to_sliding_friction():
    assert ContactLaw(mu=0.3).static_mu == 0.3
    assert ContactLaw(mu=0.3, mu_s=0.5).static_mu == 0.5


@pytest.mark.parametrize("kwargs, field, allowed", [
    (dict(mu=-0.1), "law.mu", ">= 0"),
    (dict(mu=0.3, mu_s=0.2), "law.mu_s", ">= law.mu = 0.3"),
    (dict(restitution=1.5), "law.restitution", "0 <= e <= 1"),
    (dict(stiffness=0.0), "law.stiffness", "> 0"),
    (dict(eta=float("nan")), "law.eta", "a finite number"),
    (dict(impact_law="elastic"), "law.impact_law", "one of paper, mono, bi"),
])
def test_out_of_range_values_are_named(kwargs, field, allowed):
    with pytest.raises(InputError) as e:
        ContactLaw(**kwargs).validate("law")
    assert e.value.field == field and e.value.allowed == allowed
