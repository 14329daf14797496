"""The exact delay margin (:func:`symstab.numeric.analysis.delays.delay_margin`) against an oracle.

The oracle is the loop's spectral radius at a fractional delay from a
state-space discretisation with Van Loan's block exponential
(:func:`oracles.fractional_delay_oracle`, SciPy, nothing of symstab's
derivation): its first crossing of 1 along the delay, found on a grid of the
delay and bisected (:func:`oracles.first_crossing`), is the margin; each switch's side is checked just before
and after it.
"""

import math

import numpy as np
import pytest

import symstab

from conftest import REPO
from oracles import first_crossing, fractional_delay_oracle

LOOPS = REPO / "examples" / "loops"


@pytest.mark.parametrize("file, values", [
    ("paper.toml", dict(K=2.0, B=0.1, M=0.0, d=40)),
    ("paper.toml", dict(K=100.0, B=1.0, M=0.0, d=0.25)),
    ("actuator_lag.toml", {}),
    ("two_mass.toml", {}),
])
def test_the_delay_margin_is_the_oracles_first_crossing(file, values):
    loop = symstab.load_loop(LOOPS / file)
    point = {**loop.defaults, **values}
    found = loop.delay_margin(**point)
    at = fractional_delay_oracle(loop, point)
    expected = first_crossing(at, float(point["d"]), stop=float(point["d"]) + 200)
    assert found.switches[0].samples == pytest.approx(expected, rel=1e-6)
    assert found.margin == pytest.approx(expected - point["d"], rel=1e-6)
    assert found.seconds == pytest.approx(found.margin * point["T"], rel=1e-15)
    # The crossing root's angle: the oracle's largest root there.
    assert found.switches[0].theta == pytest.approx(at(expected)[1], rel=1e-4, abs=1e-6)
    assert not found.switches[0].stable_after


def test_the_tustin_dampers_stability_switches_back_and_forth():
    """Its pole at z = -1 leaves a root there that follows the plant's sampling zero: stable at
    d = 1, unstable from 1.00021, stable again from 2.00021 (the side flips with d's parity)."""
    loop = symstab.load_loop(LOOPS / "tustin_damper.toml")
    point = dict(loop.defaults)
    found = loop.delay_margin(limit=3, **point)
    at = fractional_delay_oracle(loop, point)
    assert [s.stable_after for s in found.switches] == [False, True, False]
    for switch in found.switches:
        before, after = at(switch.samples - 1e-6)[0], at(switch.samples + 1e-6)[0]
        assert (before < 1 < after) if not switch.stable_after else (after < 1 < before)
        assert switch.theta == pytest.approx(math.pi, rel=1e-12)
        assert switch.frequency == pytest.approx(1 / (2 * point["T"]), rel=1e-12)
    expected = first_crossing(at, 1.0, step=1e-5, stop=1.001)
    assert found.switches[0].samples == pytest.approx(expected, rel=1e-6)


def test_margins_hold_the_exact_margin_below_the_whole_one():
    loop = symstab.load_loop(LOOPS / "paper.toml")
    found = loop.margins(K=100.0, B=1.0, d=0)
    exact = loop.delay_margin(K=100.0, B=1.0, d=0)
    assert found.exact_delay.margin == exact.margin
    # The whole-sample margin is the first whole delay past the exact one (no window between).
    assert found.delay == math.ceil(exact.margin)
    assert found.as_dict()["exact_delay"]["margin"] == exact.margin


def test_none_found_up_to_the_limit_is_said():
    loop = symstab.load_loop(LOOPS / "paper.toml")
    found = loop.delay_margin(K=100.0, B=1.0, d=0, limit=3)
    assert found.margin is None and found.switches == () and found.limit == 3
    assert "stable up to 3 samples more" in repr(found)


@pytest.mark.parametrize("kwargs, error, message", [
    (dict(limit=-1.0), ValueError, "limit must be"),
    (dict(limit=1e9), ValueError, "limit must be at most"),
    (dict(step=0.0), ValueError, "step must be"),
    (dict(step=2.0), ValueError, "step must be"),
    (dict(K=1e4), ValueError, "the delay margin needs a stable point"),
    (dict(K=np.array([1.0, 2.0])), ValueError, "K must be a single value"),
    (dict(d=-1.0), ValueError, "d must be a finite real number >= 0"),
])
def test_bad_input_names_the_parameter(kwargs, error, message):
    loop = symstab.load_loop(LOOPS / "paper.toml")
    with pytest.raises(error, match=message):
        loop.delay_margin(**{**dict(K=100.0, B=1.0, d=0), **kwargs})
