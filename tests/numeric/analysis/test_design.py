"""``Loop.design``: the parameter values that maximise K_max, the Z-width or the passive K_max.

Oracles: an independent dense scan of the same target (nested grids, no
optimiser: ``oracles.dense_maximum``) over :meth:`symstab.Loop.limits` and
:meth:`symstab.Loop.passive_region`; closed-form functions with a known
maximum for the search itself; ``best_virtual_mass``'s published numbers
(README: gain 5.82 at d = 0, best gamma about 2.003; gain 4.14 at
T_d = 40 ms).
"""

import math

import numpy as np
import pytest

import symstab
from symstab.numeric.analysis.design import maximize_box, maximize_scalar

from conftest import PAPER_DELTA, REPO, assert_message_names
from oracles import dense_maximum

LOOPS = REPO / "examples" / "loops"

pytestmark = pytest.mark.usefixtures("loop_cache_dir")


def target_of(loop, maximize, name, **values):
    """The design's target at one value of ``name``, computed here from the engine's answers."""
    def f(value):
        try:
            if maximize == "passive":
                found = loop.passive_region(**{**values, name: value})
            else:
                found = loop.limits(**{**values, name: value})
        except ValueError:
            return -math.inf
        if found.y_max is None:
            return -math.inf
        return found.area if maximize == "area" else found.y_max
    return f


@pytest.mark.parametrize("file, maximize, name, window, values", [
    ("paper.toml", "area", "M", (-0.001, 0.03), {"d": 10}),
    ("frictionless.toml", "area", "M", (-0.005, 0.03), {}),
    ("operator_arm.toml", "y_max", "M", (-0.03, 0.15), {}),
    ("lowpass_velocity.toml", "passive", "f_c", (5.0, 400.0), {"d": 5}),
    ("lowpass_velocity.toml", "y_max", "f_c", (5.0, 400.0), {"d": 5}),
])
def test_design_finds_the_optimum_of_a_dense_scan(file, maximize, name, window, values):
    """The acceptance: the optimum of an independent dense scan of the same target, to 1e-4."""
    loop = symstab.load_loop(LOOPS / file)
    # K_max and the passive K_max rise with the velocity filter's cut-off (issue 20): the
    # best f_c is the range's top, a point of the first grid, and grids zoomed further
    # into it only evaluate it again (a passive answer takes 0.3 s); two are enough, and
    # the design's scan of 5 points holds it as its scan of 17 did.
    n, levels = (5, 2) if name == "f_c" else (None, 7)
    found = loop.design(over={name: window}, maximize=maximize, n=n, **values)
    at, value = dense_maximum(target_of(loop, maximize, name, **values), *window,
                              levels=levels)
    assert found.value == pytest.approx(value, rel=1e-4)
    # The optimum is where the engine says the value is (not a stale number).
    assert target_of(loop, maximize, name, **values)(found.best[name]) == found.value
    nominal = target_of(loop, maximize, name, **values)(loop.defaults[name])
    assert found.value_nominal == nominal
    if nominal > 0 and math.isfinite(nominal):
        assert found.gain == pytest.approx(found.value / nominal, rel=1e-12)


def test_a_narrow_band_of_stable_values_in_a_wide_range_is_found():
    """actuator_lag: the stable virtual masses lie in about (-0.013, 0.017) kg.  Over
    M in [-1, 10] kg the 17-point scan (step 0.69 kg) held only the nominal M = 0 with a
    stable point; ``design --loop --range=-1:10`` said "no M has a stable point" while
    its own table showed K_max at M = 0.  The scan now includes the nominal value and
    zooms into a short run of stable values."""
    loop = symstab.load_loop(LOOPS / "actuator_lag.toml")
    wide = loop.design(over={"M": (-1.0, 10.0)})
    _, value = dense_maximum(target_of(loop, "y_max", "M"), -0.0129, 0.0384)
    assert wide.best is not None, wide.message
    assert wide.value == pytest.approx(value, rel=1e-4)
    # The scan is laid over the masses Stodola's condition leaves (issue 40, item 1), not
    # over all of [-1, 10]: its step is far below 11 / 16.
    assert wide.spacing["M"] < 0.01


def test_a_range_without_a_stable_point_says_so():
    loop = symstab.load_loop(LOOPS / "paper.toml")
    found = loop.design(over={"M": (1.0, 2.0)}, d=10)
    assert found.best is None and found.value is None and found.gain is None
    assert "no value of M in [1, 2] has a stable point in the (B, K) plane" in found.message
    assert np.all(found.samples[:, 1] == -np.inf)


def test_two_parameters_find_the_optimum_of_a_dense_scan():
    """M and the velocity filter's cut-off together (the simulator's filtered environment)."""
    loop = symstab.Loop("1/(m*s**2 + b*s)",
                        "K + (B + M*(z - 1)/(T*z))*(1 - exp(-2*pi*f_c*T))*(z - 1)"
                        "/(T*(z - exp(-2*pi*f_c*T)))", plane=("B", "K"),
                        values={"m": 0.0128, "b": 0.0324, "T": 1e-3, "d": 2, "K": 1.0,
                                "B": 0.1, "M": 0.0, "f_c": 50.0})
    box = {"M": (-0.005, 0.025), "f_c": (20.0, 200.0)}
    found = loop.design(over=box, n=5)
    # K_max rises with the cut-off in the linear model (issue 20: 60 N/m at 20 Hz, 148 at
    # 100 Hz, 196 at 400 Hz for the paper's device at d = 5): the best f_c is the range's
    # top, and the best M there is the dense scan's over M at that cut-off.
    assert found.at_edge == ("f_c",) and found.best["f_c"] == pytest.approx(200.0, rel=1e-6)
    _, value = dense_maximum(target_of(loop, "y_max", "M", f_c=200.0), *box["M"])
    assert found.value == pytest.approx(value, rel=1e-4)
    # ... and no point of an independent 4 x 4 grid of the box is better.
    grid = [target_of(loop, "y_max", "M", f_c=v)(u)
            for u in np.linspace(*box["M"], 4) for v in np.linspace(*box["f_c"], 4)]
    assert found.value >= max(grid)


def test_best_virtual_mass_keeps_its_published_numbers(best_d0, best_d40):
    """README: gain 5.82 at d = 0 (best gamma about 2.003) and 4.14 at T_d = 40 ms (gamma
    about 1.0); the ratio of alpha_max at gamma = 0 is the paper's 0.6897.  (The searches
    are conftest's session fixtures, shared with test_region's.)"""
    zero = best_d0
    assert zero.d == 0 and zero.delta == PAPER_DELTA
    assert round(zero.gain, 2) == 5.82 and round(zero.gamma, 3) == 2.003
    assert zero.alpha_max_gamma0 == pytest.approx(0.68967, abs=1e-5)
    forty = best_d40
    assert forty.d == 40 and forty.delta == PAPER_DELTA
    assert round(forty.gain, 2) == 4.14 and round(forty.gamma, 1) == 1.0


# The search itself, on functions with a known maximum.

def test_the_scalar_search_finds_a_band_narrower_than_its_step():
    """A stable band 1e-3 wide around the nominal value 0.5 in [0, 100]: step 6.25."""
    def f(x):
        return 1 - (x - 0.5004)**2 if 0.5 <= x <= 0.501 else -math.inf
    x, value, seen = maximize_scalar(f, 0.0, 100.0, include=[0.5])
    assert x == pytest.approx(0.5004, abs=1e-8)
    assert len(seen) < 120


def test_the_scalar_search_keeps_the_best_point_at_a_cliff():
    """A maximum at the edge where the target vanishes: the best point seen is feasible."""
    def f(x):
        return x if x <= 0.7 else -math.inf
    x, value, _ = maximize_scalar(f, 0.0, 1.0)
    assert value == x and 0.7 - 1e-6 < x <= 0.7


def test_the_box_search_finds_an_interior_maximum():
    p, value, _ = maximize_box(lambda p: -(p[0] - 0.31)**2 - 3 * (p[1] + 1.2)**2,
                               ((0.0, 1.0), (-2.0, 2.0)))
    assert p[0] == pytest.approx(0.31, abs=1e-5) and p[1] == pytest.approx(-1.2, abs=1e-5)


def test_bad_values_are_an_error_not_a_design_without_a_stable_point():
    """T = -1 ms, an unknown axis or a damping the loop has not were each reported as "no
    value has a stable point" (every evaluation failed and was skipped)."""
    loop = symstab.load_loop(LOOPS / "paper.toml")
    with pytest.raises(ValueError) as excinfo:
        loop.design(over={"M": (0.0, 0.03)}, n=3, T=-1e-3)
    assert_message_names(excinfo, "T")
    with pytest.raises(ValueError) as excinfo:
        loop.design(over={"M": (0.0, 0.03)}, n=3, x="B", y="Q")
    assert_message_names(excinfo, "Q")
    frictionless = symstab.load_loop(LOOPS / "frictionless.toml")
    with pytest.raises(ValueError) as excinfo:
        frictionless.design(over={"M": (0.0, 0.03)}, n=3, maximize="passive")
    assert_message_names(excinfo, "damping")


@pytest.mark.parametrize("kwargs, error, name", [
    ({"over": {"Q": (0, 1)}}, ValueError, "Q"),
    ({"over": {"d": (0, 1)}}, ValueError, "d"),
    ({"over": {"K": (0, 1)}}, ValueError, "K"),
    ({"over": {"M": (1, 0)}}, ValueError, "over['M']"),
    ({"over": {"M": (0, math.inf)}}, ValueError, "over['M']"),
    ({"over": {}}, TypeError, "over"),
    ({"over": {"M": (0, 1), "b": (0, 1), "m": (0, 1)}}, TypeError, "over"),
    ({"over": {"M": (0, 1)}, "maximize": "K_min"}, ValueError, "maximize"),
    ({"over": {"M": (0, 1)}, "n": 2}, ValueError, "n"),
    ({"over": {"M": (0, 1)}, "progress": 3}, TypeError, "progress"),
])
def test_bad_design_input_names_the_parameter(kwargs, error, name):
    loop = symstab.load_loop(LOOPS / "paper.toml")
    with pytest.raises(error) as excinfo:
        loop.design(**kwargs)
    assert_message_names(excinfo, name)


def test_the_sample_period_with_the_delay_held_in_seconds():
    """T searched with a 10 ms delay: d = 10 ms / T samples at each T, a fraction of a period
    included (was ceil(10 ms / T), the whole samples that cover it), against a dense scan of
    the engine's K_max with the delay given as Td.  K_max rises as T falls (the sawtooth of
    the whole-sample delay is gone): the best T is the range's low end, d = 20 there."""
    loop = symstab.load_loop(LOOPS / "paper.toml")
    delay, window = 0.01, (5e-4, 4e-3)
    found = loop.design(over={"T": window}, delay=delay, n=9, M=0.0)
    at, value = dense_maximum(lambda T: loop.limits(T=T, Td=delay, M=0.0).y_max, *window,
                              points=9, levels=2)
    assert found.value == pytest.approx(value, rel=1e-4)
    assert found.best_d == pytest.approx(delay / found.best["T"], rel=1e-12)
    assert found.at_edge == ("T",) and found.best_d == pytest.approx(20.0)
    with pytest.raises(TypeError, match="not both"):
        loop.design(over={"T": window}, delay=delay, d=3)


def test_an_interior_optimum_of_the_sample_period_with_the_delay_held():
    """two_mass (a 150 Hz transmission resonance) with the delay held at 2 ms: K_max against
    T peaks inside the range (385 N/m near T = 2.86 ms, d = 0.70 samples), where the whole
    samples that cover the delay (d = 1 there, the former ceil) give 257.  Oracle: a dense
    scan of the engine's K_max at Td = 2 ms.  The loop's Td among the values is the same
    held delay as ``delay``."""
    loop = symstab.load_loop(LOOPS / "two_mass.toml")
    delay, window = 0.002, (1.5e-3, 4e-3)
    found = loop.design(over={"T": window}, delay=delay, n=9)
    at, value = dense_maximum(lambda T: loop.limits(T=T, Td=delay).y_max, *window, points=9,
                              levels=6)
    assert found.value == pytest.approx(value, rel=1e-4)
    assert found.best["T"] == pytest.approx(at, rel=1e-3) and not found.at_edge
    assert 0 < found.best_d < 1 and found.delay == delay
    assert f"delay 0.002 s = {found.best_d:.6g} samples" in repr(found)
    assert found.as_dict()["delay"] == delay and found.as_dict()["best_d"] == found.best_d
    near = {"T": (found.best["T"] * 0.999, found.best["T"] * 1.001)}
    again = loop.design(over=near, Td=delay, n=3, rtol=1e-2)
    assert again.delay == delay and again.value == pytest.approx(found.value, rel=1e-5)


def test_a_held_delay_is_continuous_across_a_whole_sample():
    """Why no whole-sample pieces are searched: at T = 5 ms / 16 the delay is 16 samples, and
    just above it 15 samples and a fraction near 1; K_max is the same there (the modified
    z-transform at eps -> 1 is one more whole sample)."""
    loop = symstab.load_loop(LOOPS / "paper.toml")
    T = 0.005 / 16
    at = loop.limits(T=T, Td=0.005, M=0.0).y_max
    above = loop.limits(T=T * (1 + 1e-8), Td=0.005, M=0.0).y_max
    assert above == pytest.approx(at, rel=1e-6)


def test_the_passive_target_holds_a_delay_in_seconds():
    """A delay held in seconds is d = delay / T samples, fractional between whole ones: the
    passive set takes it (it was refused).  Oracle: the passive K_max at the best T with the
    delay given as Td, and at a T where it is 2.5 samples (below: a longer T, a longer
    delay's share)."""
    loop = symstab.load_loop(LOOPS / "paper.toml")
    found = loop.design(over={"T": (5e-4, 1e-3)}, maximize="passive", delay=1.5e-3, n=3, M=0.0)
    best = found.best["T"]
    assert found.value == pytest.approx(loop.passive_region(T=best, Td=1.5e-3, M=0.0).y_max,
                                        rel=1e-9)
    assert found.value > loop.passive_region(T=6e-4, Td=1.5e-3, M=0.0).y_max


def test_a_band_between_two_scan_points_is_bracketed_not_called_empty():
    """Issue 40, item 1: d = 5, M in [-1, 10] kg m^2 from M = 5 (step 0.69): the stable masses
    -0.013 < M < 0.016 lie between two scan points and design said "no value of M has a
    stable point" while K_max at M = 0 is finite.  Stodola's condition, linear in (B, K, M),
    brackets the band before the scan.  Oracle: a dense scan of the engine's K_max over a
    window holding the band, and K_max at M = 0."""
    loop = symstab.load_loop(LOOPS / "paper.toml")
    found = loop.design(over={"M": (-1.0, 10.0)}, d=5, M=5.0)
    assert found.best is not None, found.message
    _, value = dense_maximum(target_of(loop, "y_max", "M", d=5), -0.02, 0.03)
    assert found.value == pytest.approx(value, rel=1e-4)
    assert found.value >= loop.limits(d=5, M=0.0).y_max


def test_no_stable_value_is_said_with_its_proof():
    """M in [0.5, 1] at d = 40: Stodola's condition holds nowhere (proved, nothing scanned)."""
    loop = symstab.load_loop(LOOPS / "paper.toml")
    found = loop.design(over={"M": (0.5, 1.0)}, d=40, n=3)
    assert found.best is None and "proved" in found.message
    for M in np.linspace(0.5, 1.0, 5):
        assert loop.limits(d=40, M=M).y_max is None


def test_nothing_found_unproved_says_what_was_not_examined():
    """Issue 40, item 1: a parameter outside Stodola's linear bracket (T) with no stable
    point at the values evaluated: not "no value of T has a stable point" (a band between
    two scan points is not excluded) but what was evaluated and what was not examined.
    Oracle: the engine's limits at each value evaluated are empty."""
    loop = symstab.load_loop(LOOPS / "paper.toml")
    found = loop.design(over={"T": (5e-4, 1e-3)}, n=3, M=0.5)
    assert found.best is None
    assert "no value" not in found.message and "not examined" in found.message
    assert "values of T in [0.0005, 0.001] evaluated (steps of 0.00025)" in found.message
    for T in found.samples[:, 0]:
        assert loop.limits(T=T, M=0.5).y_max is None
