"""Tests of symstab.numeric.paper.device: the Device conversions at the edges of floating point.

The issue's cases: ``Device(T=1e200).alpha(1)`` raised OverflowError (or
returned inf), b = 0 (a frictionless device) was refused, and a conversion
that underflowed to 0 went on silently.
"""

import numpy as np
import pytest

from symstab import PAPER_DEVICE, Device


def test_frictionless_device_has_delta_zero_and_converts_both_ways():
    dev = Device(m=0.5, b=0.0, T=2e-3)
    assert dev.delta == 0.0
    # alpha = K_w T^2 / m by hand: 100 * 4e-6 / 0.5.
    assert dev.alpha(100.0) == pytest.approx(8e-4, rel=1e-15)
    assert dev.stiffness(8e-4) == pytest.approx(100.0, rel=1e-15)


@pytest.mark.parametrize("kwargs, message", [
    (dict(m=1.0, b=1.0, T=1e200), r"delta = b T / m must be .* <= 1e\+06, got 1e\+200"),
    (dict(m=1e-300, b=1.0, T=1e-3), r"delta = b T / m must be"),
    (dict(m=1.0, b=-1.0, T=1e-3), r"^b must be a finite real number >= 0"),
])
def test_device_refuses_a_delta_out_of_range_naming_it(kwargs, message):
    with pytest.raises(ValueError, match=message):
        Device(**kwargs)


@pytest.mark.parametrize("method, value, name", [
    ("alpha", 1.0, "alpha = K_w T"), ("stiffness", 1.0, "K_w = alpha m"),
    ("beta", 1e300, "beta = B_w T / m"),
])
def test_conversions_that_overflow_raise_naming_the_quantity(method, value, name):
    dev = Device(m=1.0, b=0.0, T=1e200)
    with pytest.raises(ValueError, match=name):
        getattr(dev, method)(value)


def test_conversion_that_underflows_to_zero_raises_but_zero_stays_zero():
    dev = Device(m=1.0, b=1e-3, T=1e-300)
    with pytest.raises(ValueError, match="alpha = K_w T"):
        dev.alpha(1.0)
    assert dev.alpha(0.0) == 0.0
    with pytest.raises(ValueError, match="alpha = K_w T"):
        dev.alpha(np.array([0.0, 1.0]))


def test_conversions_do_not_warn(recwarn):
    with pytest.raises(ValueError):
        Device(m=1.0, b=0.0, T=1e200).alpha(1.0)
    assert not [w for w in recwarn if issubclass(w.category, RuntimeWarning)]
    assert PAPER_DEVICE.beta(0.0128) == pytest.approx(1e-3, rel=1e-15)
