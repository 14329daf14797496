"""``Loop.margins``: how far a stable point is from instability.

Oracles, written here: the open loop ``L = VE z**-d P`` built by python-control
(``control.c2d`` of the plant, ``oracles.python_control_parts``) on a fine
grid refined by scipy's bounded scalar minimisation of ``|1 + L|`` (the
modulus margin, 1e-8 relative); python-control's ``stability_margins`` (the
gain and phase margins, where it is right) and the poles of its closed loop
(the parameter and delay margins).
"""

import math
import warnings

import control
import mpmath
import numpy as np
import pytest
import scipy.optimize

import symstab
from symstab.numeric.engine.polynomial import DelayedPolynomial
from symstab.numeric.engine.roots import circle_minimum

from conftest import REPO
from oracles import first_crossing, fractional_delay_oracle, polyroots, python_control_parts

LOOPS = REPO / "examples" / "loops"

pytestmark = pytest.mark.usefixtures("loop_cache_dir")

#: The paper's device with a spring and a damper (N m/rad, N m s/rad).
WALL = dict(m=0.0128, b=0.0324, T=1e-3, K=100.0, B=1.0, M=0.0)


def _paper():
    return symstab.load_loop(LOOPS / "paper.toml")


def _open_loop(loop, point):
    plant, environment, delay = python_control_parts(loop, point)
    return environment * delay * plant


def _refined_minimum(L):
    """min |1 + L(exp(j theta))| on [0, pi]: a grid, then a bounded minimisation at its best points."""
    def f(theta):
        return abs(1 + complex(L(np.exp(1j * theta))))

    grid = np.linspace(1e-9, np.pi, 20001)
    values = np.abs(1 + L(np.exp(1j * grid)))
    step = grid[1] - grid[0]
    best = []
    for k in np.argsort(values)[:5]:
        lo, hi = max(grid[k] - step, 0.0), min(grid[k] + step, np.pi)
        found = scipy.optimize.minimize_scalar(f, bounds=(lo, hi), method="bounded",
                                               options={"xatol": 1e-13})
        best.append((found.fun, found.x))
    return min(best)


def _radius_mp(loop, point):
    """The closed loop's spectral radius: python-control's coefficients, mpmath's roots (40 digits)."""
    plant, environment, delay = python_control_parts(loop, point)
    num = np.polymul(environment.num[0][0], plant.num[0][0])
    den = np.polymul(np.polymul(environment.den[0][0], plant.den[0][0]), delay.den[0][0])
    size = max(len(num), len(den))
    chi = np.pad(den, (size - len(den), 0)) + np.pad(num, (size - len(num), 0))
    with mpmath.workdps(40):
        return max(abs(r) for r in polyroots([mpmath.mpf(float(c)) for c in chi], maxsteps=200,
                                             extraprec=80))


def _radius(L):
    """The largest closed-loop pole modulus of 1 + L (python-control)."""
    return float(np.max(np.abs(control.poles(control.feedback(1, L)))))


POINTS = [
    ("paper.toml", dict(WALL, d=0)),
    ("paper.toml", dict(WALL, d=3)),
    ("paper.toml", dict(m=0.0128, b=0.0324, T=1e-3, K=3.0, B=0.2, M=0.0, d=10)),
    ("paper.toml", dict(m=0.0128, b=0.0324, T=1e-3, K=2.0, B=0.1, M=0.004, d=40)),
    ("lowpass_velocity.toml", {}),
    ("operator_arm.toml", {}),
    ("two_mass.toml", {}),
    # A phase crossover in the scan's first step (B < 0: python-control's gain margin 5.246
    # at 1.15 rad/s), and an integrator whose |N(1)| is at the rounding of the cosine
    # series (a root at theta = 0 that is the pole of L, not a crossing): both once missed.
    ("lowpass_velocity.toml", dict(d=0, K=0.003242528441583091, B=-0.006174615573211431)),
    ("paper.toml", dict(K=0.03, B=1.0, M=0.0, d=1)),
]


def _loop_and_point(file, values):
    loop = symstab.load_loop(LOOPS / file)
    point = {**loop.defaults, **values}
    assert loop.is_stable(**point), (file, point)
    return loop, point


@pytest.mark.parametrize("file, values", POINTS)
def test_the_modulus_margin_is_python_control_s_refined_minimum(file, values):
    loop, point = _loop_and_point(file, values)
    found = loop.margins(**point)
    value, theta = _refined_minimum(_open_loop(loop, point))
    assert found.modulus == pytest.approx(value, rel=1e-8)
    # The certified bracket holds the oracle's minimum (a grid and a local
    # minimiser can only be above the true minimum, never below it).
    assert found.modulus_lower <= value * (1 + 1e-12)
    assert found.modulus_lower >= found.modulus * (1 - 2e-9)
    assert found.modulus_theta == pytest.approx(theta, abs=1e-3)
    assert found.modulus_frequency == pytest.approx(theta / (2 * math.pi * point["T"]), abs=0.2)


def test_python_control_misses_the_modulus_margin_of_the_paper_s_device():
    """Issue 44: at d = 0, K = 100 N m/rad, B = 1 N m s/rad python-control reports a stability
    margin of 0.74189 at 126.4 rad/s; |1 + L| is 0.73960 at 119.5 rad/s."""
    loop, point = _loop_and_point("paper.toml", dict(WALL, d=0))
    # The open loop as a python-control user writes it, VE(z) by arithmetic on z: from
    # this form python-control's stability margin misses the minimum (from the
    # coefficients of python_control_parts it finds it; the form changes its answer).
    T = point["T"]
    z = control.tf([1, 0], [1], T)
    L = (point["K"] + point["B"] * (z - 1) / (T * z)) * control.c2d(
        control.tf([1], [point["m"], point["b"], 0]), T, "zoh")
    _, _, sm, _, _, wms = control.stability_margins(L)
    assert sm == pytest.approx(0.741885, abs=1e-6) and wms == pytest.approx(126.43, abs=0.01)
    found = loop.margins(**point)
    assert found.modulus == pytest.approx(0.7395975, abs=1e-7)
    assert found.modulus_theta / point["T"] == pytest.approx(119.52, abs=0.01)
    # python-control's value is not the minimum: |1 + L| at our frequency is below it.
    assert abs(1 + complex(L(np.exp(1j * found.modulus_theta)))) < sm - 2e-3


def _crossings(f, L):
    """Where ``f(L(exp(j theta)))`` changes sign in (0, pi): a fine grid, then scipy's brentq."""
    def g(theta):
        return f(complex(L(np.exp(1j * theta))))

    grid = np.linspace(1e-6, np.pi - 1e-6, 200001)
    values = f(L(np.exp(1j * grid)))
    change = np.flatnonzero(np.sign(values[:-1]) * np.sign(values[1:]) < 0)
    return [scipy.optimize.brentq(g, grid[k], grid[k + 1], xtol=1e-15) for k in change]


@pytest.mark.parametrize("file, values", POINTS)
def test_gain_and_phase_margins_are_every_crossing_of_python_control_s_open_loop(file, values):
    """Every phase crossover (Im L = 0, Re L < 0) and gain crossover (|L| = 1) in (0, pi),
    found on a fine grid of python-control's frequency response; the ends theta = 0 and pi
    (where L is real too) are checked at the point itself."""
    loop, point = _loop_and_point(file, values)
    found = loop.margins(**point)
    L = _open_loop(loop, point)
    phase = [t for t in _crossings(np.imag, L) if complex(L(np.exp(1j * t))).real < 0]
    inside = [c for c in found.gain if 0 < c.theta < math.pi]
    assert [c.theta for c in inside] == pytest.approx(phase, abs=1e-9)
    assert [c.margin for c in inside] == pytest.approx(
        [-1 / complex(L(np.exp(1j * t))).real for t in phase], rel=1e-7)
    at_pi = complex(L(-1.0)).real
    assert any(c.theta == math.pi for c in found.gain) == (at_pi < 0)
    gain = _crossings(lambda v: np.abs(v) - 1, L)
    assert [c.theta for c in found.phase] == pytest.approx(gain, abs=1e-9)
    assert [c.margin for c in found.phase] == pytest.approx(
        [math.degrees(np.angle(-complex(L(np.exp(1j * t))))) for t in gain], abs=1e-6)


@pytest.mark.parametrize("file, values", POINTS[:2])
def test_gain_and_phase_margins_are_python_control_s_where_it_is_right(file, values):
    """Where python-control's stability_margins uses its polynomial method (no warning that
    it falls back to a frequency grid, which misses crossings near pi), the lists agree."""
    loop, point = _loop_and_point(file, values)
    found = loop.margins(**point)
    T = point["T"]
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        gm, pm, _, wpc, wgc, _ = control.stability_margins(_open_loop(loop, point),
                                                           returnall=True)
    inside = [c for c in found.gain if 0 < c.theta < math.pi]
    assert [c.margin for c in inside] == pytest.approx(list(gm), rel=1e-6)
    assert [c.theta / T for c in inside] == pytest.approx(list(wpc), rel=1e-6)
    assert [c.margin for c in found.phase] == pytest.approx(list(pm), abs=1e-6)
    assert [c.theta / T for c in found.phase] == pytest.approx(list(wgc), rel=1e-6)


@pytest.mark.parametrize("file, values", POINTS[:4] + POINTS[5:6])
def test_parameter_margins_end_where_python_control_s_poles_reach_the_circle(file, values):
    loop, point = _loop_and_point(file, values)
    found = loop.margins(**point)
    assert [p.name for p in found.parameters] == list(loop.plane)
    for p in found.parameters:
        assert p.low < p.value < p.high
        for end in (p.low, p.high):
            if not math.isfinite(end):
                continue
            step = 1e-6 * max(abs(end), abs(p.value))
            inward = end + step if end == p.low else end - step
            outward = end - step if end == p.low else end + step
            assert _radius(_open_loop(loop, {**point, p.name: inward})) < 1, (p.name, end)
            assert _radius(_open_loop(loop, {**point, p.name: outward})) >= 1 - 1e-9, (p.name, end)


@pytest.mark.parametrize("file, values", POINTS[:2])
def test_the_delay_margin_is_the_first_delay_python_control_calls_unstable(file, values):
    loop, point = _loop_and_point(file, values)
    found = loop.margins(**point)
    assert found.delay is not None and found.delay_seconds == found.delay * point["T"]
    radii = [_radius(_open_loop(loop, {**point, "d": point["d"] + k}))
             for k in range(1, found.delay + 1)]
    assert all(r < 1 for r in radii[:-1]) and radii[-1] >= 1


def test_the_delay_margin_of_random_points_is_python_control_s_first_unstable_delay():
    """The search starts where a gain crossover's phase margin is used up by the delay (every
    whole delay before it is stable, by the argument principle): python-control's poles at
    every delay up to the margin check that claim at random points (short delays, where
    its poles are reliable)."""
    loop = _paper()
    rng = np.random.default_rng(7)
    checked = 0
    while checked < 12:
        point = {**loop.defaults, "d": int(rng.integers(0, 3)), "M": 0.0,
                 "K": float(rng.uniform(1.0, 400.0)), "B": float(rng.uniform(0.0, 2.0))}
        if not loop.is_stable(**point):
            continue
        found = loop.margins(delay_limit=14, **point)
        if found.delay is None:
            continue
        radii = [_radius(_open_loop(loop, {**point, "d": point["d"] + k}))
                 for k in range(1, found.delay + 1)]
        assert all(r < 1 for r in radii[:-1]) and radii[-1] > 1 - 1e-9, (point, radii)
        checked += 1


def test_a_long_delay_margin_is_decided_at_40_digits():
    """d = 10 with 43 samples of margin: at d + k ~ 50 python-control's poles lose the circle
    (a pole near z = 1: its radius at d = 49 came out 1.0024, 40 digits say 0.99914), so the
    last stable and the first unstable delay are decided by mpmath's roots of
    python-control's coefficients."""
    loop, point = _loop_and_point(*POINTS[2])
    found = loop.margins(**point)
    assert found.delay == 43
    assert _radius_mp(loop, {**point, "d": point["d"] + found.delay - 1}) < 1
    assert _radius_mp(loop, {**point, "d": point["d"] + found.delay}) > 1


def test_a_loop_with_the_nyquist_curve_outside_the_circle_at_pi_loses_stability_at_once():
    """|L(-1)| > 1: the end z = -1 of chi = z**(d + k) D + N does not turn with k, so a
    stable loop is unstable one sample later however far its phase margins' delay is (the
    search once started there and said 13)."""
    T = 1e-3
    loop = symstab.Loop("1/(s + 1)", "c*(z - exp(-T))/(z + 0.0793)",
                        values=dict(T=T, d=0, c=-1.0721 / (1 - math.exp(-T))))
    found = loop.margins(delay_limit=20)
    assert found.delay == 1
    point = dict(loop.defaults)
    assert _radius(_open_loop(loop, point)) < 1
    assert _radius(_open_loop(loop, {**point, "d": 1})) > 1


def test_a_long_delay_with_many_equal_minima_keeps_a_positive_bound():
    """d = 8001 with a flat |1 + L| = 0.5: thousands of minima of one depth are no marginal
    point (the halving once gave up and said lower = 0)."""
    loop = symstab.Loop("1/(s + 1)", "c*(z - exp(-T))/z",
                        values=dict(T=1e-3, d=8001, c=0.5 / (1 - math.exp(-1e-3))))
    found = loop.margins(delay_limit=1)
    assert found.modulus == pytest.approx(0.5, rel=1e-12)
    assert 0.5 * (1 - 2e-9) <= found.modulus_lower <= 0.5


def test_no_delay_margin_within_the_limit_is_said():
    loop, point = _loop_and_point("paper.toml", dict(WALL, K=1.0, B=0.05, d=0))
    found = loop.margins(delay_limit=2, **point)
    assert found.delay is None and found.delay_limit == 2
    assert "stable up to 2 samples more (d = 2)" in repr(found)


def test_at_the_largest_delay_accepted_the_delay_margin_is_not_examined(monkeypatch):
    """At d = SYMSTAB_MAX_DELAY no longer delay is evaluated: "stable up to 0 samples more"
    read as a margin of none; it says the margin was not examined, and why."""
    monkeypatch.setenv("SYMSTAB_MAX_DELAY", "3")
    loop, point = _loop_and_point("paper.toml", dict(WALL, K=1.0, B=0.05, d=3))
    found = loop.margins(**point)
    assert found.delay is None and found.delay_limit == 0
    assert found.delay_note == ("not examined: d is the largest delay accepted "
                                "(SYMSTAB_MAX_DELAY)")
    assert "not examined" in repr(found)


@pytest.mark.parametrize("values, message", [
    (dict(WALL, d=40), "unstable (2 poles outside the unit circle)"),
    (dict(WALL, K=0.0, B=1.0, d=0), "marginal"),
])
def test_a_point_that_is_not_stable_has_no_margins(values, message):
    with pytest.raises(ValueError, match=r"margins need a stable point") as excinfo:
        _paper().margins(**values)
    assert message in str(excinfo.value)


@pytest.mark.parametrize("kwargs, exception, message", [
    (dict(K=np.array([1.0, 2.0])), ValueError, "K must be a single value"),
    (dict(parameters=("b",)), ValueError, "'b' does not enter"),
    (dict(rtol=0.0), ValueError, "rtol"),
    (dict(delay_limit=0), ValueError, "delay_limit"),
    (dict(delay_limit=1.5), TypeError, "delay_limit"),
    (dict(d=-1.5), ValueError, "d must be a finite real number >= 0"),
    (dict(d=True), TypeError, "d must be a real number"),
    (dict(foo=1.0), TypeError, "unknown parameter"),
    (dict(K="abc"), TypeError, "K"),
    (dict(parameters=("K", "K")), ValueError, "each name once"),
    (dict(parameters=5), TypeError, "parameters must be parameter names"),
])
def test_bad_input_names_the_parameter(kwargs, exception, message):
    with pytest.raises(exception, match=message):
        _paper().margins(**{**dict(WALL, d=0), **kwargs})


def test_circle_minimum_is_zero_at_a_root_on_the_circle():
    """z**2 + 1 = z**2 (1 + z**-2): a root at z = j; no positive lower bound can hold."""
    lower, upper, theta = circle_minimum(DelayedPolynomial([1.0], [1.0], shift=2))
    assert float(lower) == 0.0 and float(upper) < 1e-6
    assert float(theta) == pytest.approx(math.pi / 2, abs=1e-6)


def test_the_margins_print_and_serialise():
    loop, point = _loop_and_point("paper.toml", dict(WALL, d=0))
    found = loop.margins(**point)
    text = repr(found)
    assert "modulus margin" in text and "phase margin (deg)" in text and "8 samples" in text
    data = found.as_dict()
    assert data["delay"] == 8 and data["modulus"] == found.modulus
    assert [g["margin"] for g in data["gain"]] == [c.margin for c in found.gain]
    assert found.gain_margin == pytest.approx(23.2043, rel=1e-5)
    assert found.phase_margin == pytest.approx(43.9345, rel=1e-5)
    assert "<table" in found._repr_html_()


# --------------------------------------------------------------------------
# Margin maps


def test_a_margin_map_is_python_control_s_minimum_where_stable_and_nan_elsewhere():
    loop = _paper()
    xs, ys = np.linspace(-0.05, 2.0, 7), np.linspace(10.0, 600.0, 6)
    at = dict(m=0.0128, b=0.0324, T=1e-3, M=0.0, d=2)
    found = loop.margin_map(xs, ys, **at)
    assert found.values.shape == (6, 7) and (found.x, found.y) == ("B", "K")
    stable = np.isfinite(found.values)
    assert 0 < stable.sum() < stable.size
    for i, K in enumerate(ys):
        for j, B in enumerate(xs):
            point = {**loop.defaults, **at, "B": float(B), "K": float(K)}
            L = _open_loop(loop, point)
            if _radius(L) < 1:
                assert found.values[i, j] == pytest.approx(_refined_minimum(L)[0], rel=1e-8)
                assert found.lower[i, j] <= found.values[i, j]
            else:
                assert np.isnan(found.values[i, j]) and np.isnan(found.lower[i, j])


def test_a_delay_margin_map_is_the_exact_delay_margin_per_point():
    """Every stable cell holds ``Loop.delay_margin``'s margin (the map's vectorised search is the
    point's), inf where none is found up to the limit; at three cells the state-space oracle's
    first crossing (independent of symstab's fractional derivation) to 1e-6."""
    loop = _paper()
    xs, ys = np.linspace(-0.05, 2.0, 6), np.linspace(10.0, 600.0, 5)
    at = dict(m=0.0128, b=0.0324, T=1e-3, M=0.0, d=0.5)
    found = loop.margin_map(xs, ys, margin="delay", delay_limit=12, **at)
    assert found.delay_limit == 12 and found.delay_step == 1 / 16
    assert np.isnan(found.values).any() and np.array_equal(found.lower, found.values,
                                                           equal_nan=True)
    cells = list(_numbered_cells(loop, found, at, lambda point: fractional_delay_oracle(
        loop, point)(point["d"])[0]))
    for i, j, point in cells:
        margin = loop.delay_margin(limit=12, every=False, **point).margin
        expected = math.inf if margin is None else margin
        assert found.values[i, j] == pytest.approx(expected, rel=1e-12), point
    finite = [cell for cell in cells if np.isfinite(found.values[cell[0], cell[1]])]
    assert len(finite) >= 3
    for i, j, point in finite[:: max(1, len(finite) // 3)][:3]:
        crossing = first_crossing(fractional_delay_oracle(loop, point), point["d"],
                                  stop=point["d"] + 13)
        assert found.values[i, j] == pytest.approx(crossing - point["d"], rel=1e-6), point


def test_a_gain_margin_map_is_python_control_s_gain_margin_per_point():
    loop = _paper()
    xs, ys = np.linspace(0.0, 2.0, 5), np.linspace(10.0, 600.0, 4)
    at = dict(m=0.0128, b=0.0324, T=1e-3, M=0.0, d=1)
    found = loop.margin_map(xs, ys, margin="gain", **at)
    for i, j, point in _numbered_cells(loop, found, at):
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            gm = control.stability_margins(_open_loop(loop, point))[0]
        assert found.values[i, j] == pytest.approx(gm, rel=1e-6), point


def _numbered_cells(loop, found, at, radius=None):
    """``(i, j, point)`` of each cell of a (B, K) margin map that holds a number; a NaN cell
    is checked not stable on the way by python-control's closed-loop poles (or by
    ``radius(point)``: a fractional delay's)."""
    radius = radius or (lambda point: _radius(_open_loop(loop, point)))
    for i, K in enumerate(found.y_values):
        for j, B in enumerate(found.x_values):
            point = {**loop.defaults, **at, "B": float(B), "K": float(K)}
            if np.isnan(found.values[i, j]):
                assert radius(point) >= 1 - 1e-9
                continue
            yield i, j, point


def test_a_margin_map_draws_its_contours_under_the_decomposition():
    loop = _paper()
    at = dict(d=10, M=0.0)
    found = loop.margin_map(np.linspace(-0.05, 0.5, 30), np.linspace(0.0, 6.0, 30), **at)
    drawn = found.plot(region=loop.region(**at), levels=8)
    assert drawn.artists["margin"] and drawn.artists["colorbar"] and drawn.artists["arc"]
    assert drawn.axes.get_xlabel() == "B" and "MarginMap(modulus margin" in repr(found)
    import matplotlib.pyplot as plt
    plt.close(drawn.figure)


@pytest.mark.parametrize("kwargs, exception, message", [
    (dict(margin="phase"), ValueError, "margin must be one of 'modulus', 'delay', 'gain'"),
    (dict(x_values=np.ones((2, 2))), ValueError, "must be 1-D and not empty"),
    (dict(B=0.1), TypeError, "B is an axis of the map"),
])
def test_bad_margin_map_input_names_the_parameter(kwargs, exception, message):
    args = {"x_values": [0.1, 0.2], "y_values": [1.0, 2.0], **kwargs}
    with pytest.raises(exception, match=message):
        _paper().margin_map(args.pop("x_values"), args.pop("y_values"), **args)


def test_a_gain_margin_map_is_drawn_on_a_log_scale():
    """A gain margin is a factor (1.01 to 106 over the paper's plane at d = 10): evenly spaced
    levels put nearly all of the stable set in the lowest band."""
    from matplotlib.colors import LogNorm

    found = _paper().margin_map(np.linspace(0.0, 0.9, 12), np.linspace(0.5, 25.0, 12),
                                margin="gain", d=10, M=0.0)
    drawn = found.plot()
    (filled,) = drawn.artists["margin"]
    assert isinstance(filled.norm, LogNorm)
    assert np.allclose(np.diff(np.log(filled.levels)), np.log(filled.levels[1] / filled.levels[0]))
    import matplotlib.pyplot as plt
    plt.close(drawn.figure)
