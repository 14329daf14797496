"""The numeric API end to end at the extremes of delta = b T / m.

Before the exp(-delta) kernels, delta >~ 357 gave NaN boundaries that the
library read as "the stable region is empty" (``limits(gamma=0, d=0,
delta=400)``, ``symstab design --delta 400`` printing alpha_max -inf with
exit 0), delta >~ 709 wrong verdicts, and delta = 0 (a frictionless device)
was refused.  The oracle here is python-control's closed loop (c2d of the
plant, feedback), with m = T = 1 and b = delta.
"""

import json
import math

import numpy as np
import pytest

import symstab

from conftest import run_cli
from oracles import python_control_closed_loop


def _python_control_stable(alpha, beta, gamma, d, delta):
    loop = python_control_closed_loop(alpha=alpha, beta=beta, gamma=gamma, d=d, delta=delta,
                                      m=1.0, T=1.0)
    radius = float(np.max(np.abs(loop.poles())))
    assert abs(radius - 1) > 1e-9, "probe too close to the boundary for the oracle"
    return radius < 1


@pytest.mark.parametrize("delta", [400.0, 710.0, 1e4])
@pytest.mark.parametrize("d", [0, 3])
def test_limits_at_large_delta_bracket_python_controls_edge(delta, d):
    lim = symstab.limits(gamma=0.0, d=d, delta=delta)
    assert not lim.empty, lim.message
    assert math.isfinite(lim.alpha_max) and lim.alpha_max > 0
    # Just below the top, the middle of the widest stable beta run is stable
    # (straight below the top is no probe: at delta = 1e4, d = 0 the top is
    # the corner on beta = -delta, and the line below it runs along the edge);
    # just above, nothing is.
    below = lim.alpha_max * (1 - 1e-3)
    lo, hi = max(lim.region.beta_intervals(below), key=lambda run: run[1] - run[0])
    assert _python_control_stable(below, 0.5 * (lo + hi), 0.0, d, delta)
    for beta in (lim.beta_at_alpha_max, 0.5 * (lo + hi)):
        assert not _python_control_stable(lim.alpha_max * (1 + 1e-3), beta, 0.0, d, delta)


@pytest.mark.parametrize("delta", [0.0, 400.0, 710.0, 1e4])
def test_boundary_curve_is_finite_and_starts_at_minus_delta(delta):
    curve = symstab.boundary_curve(gamma=0.5, d=2, delta=delta, n=200, segments=False)
    assert not curve.empty, curve.message
    assert np.all(np.isfinite(curve.alpha)) and np.all(np.isfinite(curve.beta))
    assert curve.beta[0] == -delta and curve.alpha[0] == 0.0
    # Points just inside the arc's start are stable by python-control, and
    # on the arc's peak the boundary separates stable from unstable.
    k = int(np.argmax(curve.alpha))
    a, b = curve.alpha[k], curve.beta[k]
    assert _python_control_stable(a * (1 - 1e-3), b, 0.5, 2, delta)
    assert not _python_control_stable(a * (1 + 1e-3), b, 0.5, 2, delta)


@pytest.mark.parametrize("d", [0, 4])
def test_frictionless_device_limits_match_python_control(d):
    lim = symstab.limits(gamma=0.0, d=d, delta=0.0)
    assert not lim.empty, lim.message
    beta = lim.beta_at_alpha_max
    assert _python_control_stable(lim.alpha_max * (1 - 1e-3), beta, 0.0, d, 1e-300)
    assert not _python_control_stable(lim.alpha_max * (1 + 1e-3), beta, 0.0, d, 1e-300)


def test_design_at_delta_400_from_the_command_line(capsys):
    # In this process: the command's parsing and output are what is tested, not a fresh
    # interpreter (a subprocess re-imported the package for each run).
    status, out, err = run_cli(capsys, "design", "--delta", "400", "--d", "0", "--format", "json")
    assert status == 0, err
    result = json.loads(out)
    best = result["best"]
    assert math.isfinite(best["alpha_max"]) and best["alpha_max"] > 0
    assert math.isfinite(best["gain"]) and best["gain"] > 0


@pytest.mark.parametrize("delta", [0.0, 800.0])
def test_simulation_at_extreme_delta_agrees_with_python_control(delta):
    """simulate(delta=800) called every point diverged (Gamma overflowed in the plant step)."""
    from symstab.numeric.paper.simulate import simulate

    scale = 1.0 if delta < 1 else 400.0
    alphas = np.array([0.1, 0.4, 5.0]) * scale
    run = simulate(alpha=alphas, beta=0.5, gamma=0.0, d=1, delta=delta)
    oracle_delta = delta if delta > 0 else 1e-300
    expected = [_python_control_stable(a, 0.5, 0.0, 1, oracle_delta) for a in alphas]
    assert run.stable.tolist() == expected
    assert True in expected and False in expected
