"""The simulated K_max (``simulated_limit``) and the design target ``maximize="simulated"``.

Oracles: python-control's closed-loop poles of the same loop
(``oracles.simulated_loop_radius``, c2d + feedback): an accepted run's loop
is stable, the next value above is not (ideal loop, any amplitude), and an
amplitude bound is a decay of ``rho ** (3/4 steps)``; an independent dense
scan of the same target (``oracles.dense_maximum``) for the design.
"""

import math

import numpy as np
import pytest

import symstab
from symstab.numeric.simulation.simulated_limit import simulated_limit
from symstab.numeric.simulation.simulator import Nonidealities

from conftest import REPO, assert_message_names
from oracles import dense_maximum, simulated_loop_radius

LOOPS = REPO / "examples" / "loops"
#: lowpass_velocity.toml's device.
DEVICE = {"m": 0.0128, "b": 0.0324, "T": 1e-3}

pytestmark = pytest.mark.usefixtures("loop_cache_dir")


@pytest.fixture(scope="module")
def lowpass():
    return symstab.load_loop(LOOPS / "lowpass_velocity.toml")


def radius(found, dy=0.0, *, d, f_c):
    return simulated_loop_radius(found.y_max + dy, found.x_at_y_max, d=d, f_c=f_c, **DEVICE)


def test_an_ideal_loop_is_accepted_up_to_the_python_control_unit_circle(lowpass):
    """With an amplitude as large as the start, a run is accepted when it does not grow: the
    simulated K_max is where python-control's largest pole crosses the unit circle."""
    found = simulated_limit(lowpass, x="B", y="K", amplitude=1.0, steps=3000, d=2, f_c=100.0)
    assert found.y_max is not None and not found.at_top
    assert radius(found, d=2, f_c=100.0) < 1.0
    assert radius(found, 2 * found.resolution, d=2, f_c=100.0) > 1.0
    assert found.resolution < 2e-4 * found.y_max          # "about 1e-4 of K_max"


def test_the_amplitude_is_a_decay_the_poles_predict(lowpass):
    """Accepted at 1e-3 of the start: the slowest mode decays to about 1e-3 over the first
    three quarters of the run (within a factor of ten for the modes' weights); 1e-6 of
    the start needs faster decay, so a smaller K_max."""
    steps = 3000
    loose = simulated_limit(lowpass, x="B", y="K", amplitude=1.0, steps=steps, d=2, f_c=100.0)
    found = simulated_limit(lowpass, x="B", y="K", amplitude=1e-3, steps=steps, d=2, f_c=100.0)
    tight = simulated_limit(lowpass, x="B", y="K", amplitude=1e-6, steps=steps, d=2, f_c=100.0)
    decay = radius(found, d=2, f_c=100.0) ** (0.75 * steps)
    assert 1e-4 < decay < 1e-2
    assert radius(found, 2 * found.resolution, d=2, f_c=100.0) ** (0.75 * steps) > 1e-4
    assert tight.y_max < found.y_max < loose.y_max


def test_a_limit_cycle_above_the_amplitude_is_refused(lowpass):
    """A force limit bounds the unstable loop: every run of the window settles into a limit
    cycle, which a large amplitude accepts (up to the window's top, and says so) and a small
    one refuses."""
    saturated = Nonidealities(force_limit=0.1)
    run = dict(x="B", y="K", steps=3000, x0=0.01, nonideal=saturated, d=2, f_c=100.0)
    bounded = simulated_limit(lowpass, amplitude=1.0, **run)
    assert bounded.at_top and bounded.y_max == pytest.approx(1.25 * bounded.linear.y_max)
    # Above the linear K_max the run settles into a cycle of 1.5e-4 (measured): refused
    # below that amplitude.
    small = simulated_limit(lowpass, amplitude=1e-5, **run)
    assert not small.at_top and small.y_max < bounded.linear.y_max


def test_no_accepted_run_says_why(lowpass):
    found = simulated_limit(lowpass, x="B", y="K", amplitude=1e-300, steps=200, d=2, f_c=100.0)
    assert found.y_max is None and "1e-300" in found.reason


@pytest.mark.parametrize("kwargs, error, name", [
    ({"amplitude": 0.0}, ValueError, "amplitude"),
    ({"amplitude": "1"}, TypeError, "amplitude"),
    ({"amplitude": 1.0, "n": 2}, ValueError, "n"),
    ({"amplitude": 1.0, "refine": -1}, ValueError, "refine"),
    ({"amplitude": 1.0, "K": 3.0}, TypeError, "K"),
    ({"amplitude": 1.0, "nonideal": Nonidealities(velocity_cutoff=50.0)}, ValueError,
     "nonideal.velocity_cutoff"),
])
def test_bad_input_names_the_parameter(lowpass, kwargs, error, name):
    with pytest.raises(error) as excinfo:
        simulated_limit(lowpass, x="B", y="K", steps=200, **kwargs)
    assert_message_names(excinfo, name)


def test_the_simulated_design_finds_the_optimum_of_a_dense_scan():
    """The paper's loop at d = 1 over the virtual mass, encoder-free runs accepted below
    1e-3: design's optimum against nested grids of the same target (no optimiser)."""
    loop = symstab.load_loop(LOOPS / "paper.toml")
    settings = {"amplitude": 1e-3, "steps": 3000, "d": 1}
    found = loop.design(over={"M": (0.0, 0.03)}, maximize="simulated", **settings)

    def target(M):
        s = simulated_limit(loop, x="B", y="K", M=M, **settings)
        return -math.inf if s.y_max is None else s.y_max

    best, value = dense_maximum(target, 0.0, 0.03, points=11, levels=4)
    assert found.value >= value * (1 - 1e-3)
    assert found.best["M"] == pytest.approx(best, rel=0.05)
    # The simulation accepts less than the certified set: an amplitude to reach.
    assert found.value < found.limits.linear.y_max
    assert found.gain > 1


def test_design_checks_the_simulation_before_the_scan():
    """A wrong setting is the caller's error, raised before any evaluation (each takes
    seconds), not a value without an answer."""
    loop = symstab.load_loop(LOOPS / "paper.toml")
    calls = []
    cases = [
        ({"maximize": "simulated"}, TypeError, "amplitude"),
        ({"maximize": "simulated", "amplitude": -1.0}, ValueError, "amplitude"),
        ({"maximize": "y_max", "amplitude": 1.0}, TypeError, "amplitude"),
        ({"maximize": "area", "nonideal": Nonidealities()}, TypeError, "nonideal"),
        # A compensated friction passes (a loop's run compensates it): the next check speaks.
        ({"maximize": "simulated", "amplitude": 1.0, "x0": 0.0,
          "nonideal": Nonidealities(coulomb_friction=0.01, friction_compensation=True)},
         ValueError, "x0"),
        ({"maximize": "simulated", "amplitude": 1.0, "x0": 0.0}, ValueError, "x0"),
        ({"maximize": "simulated", "amplitude": 1.0, "steps": 10**9}, ValueError, "steps"),
    ]
    for kwargs, error, name in cases:
        with pytest.raises(error) as excinfo:
            loop.design(over={"M": (0.0, 0.03)}, n=3, progress=calls.append, **kwargs)
        assert_message_names(excinfo, name)
    # Friction behind a lag the loop does not declare as its actuator.
    lagged = symstab.Loop("1/((tau*s + 1)*(m*s**2 + b*s))", "K + B*(z - 1)/(T*z)",
                          values={"m": 0.0128, "b": 0.0324, "tau": 1.6e-4, "T": 1e-3, "d": 1,
                                  "K": 100.0, "B": 0.5}, plane=("B", "K"))
    with pytest.raises(ValueError) as excinfo:
        lagged.design(over={"tau": (1e-4, 1e-3)}, n=3, progress=calls.append,
                      maximize="simulated", amplitude=1.0,
                      nonideal=Nonidealities(coulomb_friction=0.01))
    assert_message_names(excinfo, "nonideal.coulomb_friction")
    assert "relative degree 3" in str(excinfo.value)
    assert calls == []



def test_a_compensated_friction_has_the_limit_of_the_compensated_runs():
    """Issue 41, item 3: ``Nonidealities(friction_compensation=True)`` in simulated_limit (the
    design's simulated target; every loop refused it).  With no refinement the limit is the
    highest accepted cell of the first grid, which is run here with the compensation given
    explicitly, ``FrictionCompensation(F_c, 0.0)`` (the simulator's backward difference);
    the same grid uncompensated has another best cell."""
    from symstab.numeric.simulation.simulator import FrictionCompensation

    loop = symstab.load_loop(LOOPS / "paper.toml")
    at = {"M": 0.0, "d": 5}
    found = simulated_limit(loop, x="B", y="K", amplitude=3e-3, steps=400, x0=0.01, n=(3, 5),
                            refine=0, nonideal=Nonidealities(coulomb_friction=1.0,
                                                             friction_compensation=True), **at)
    linear = found.linear
    xs = np.union1d(np.linspace(linear.x_min, linear.x_max, 3), [linear.x_at_y_max])
    ys = np.linspace(0.0, 4 * found.resolution, 5)
    B, K = np.meshgrid(xs, ys)

    def best(**compensation):
        run = loop.simulate(steps=400, x0=0.01, B=B, K=K, nonideal=Nonidealities(
            coulomb_friction=1.0), **compensation, **at)
        accepted = run.bounded & (run.amplitude[3] <= 3e-3)
        row = np.flatnonzero(accepted.any(axis=1)).max()
        return float(ys[row]), float(xs[np.flatnonzero(accepted[row])[0]])

    assert (found.y_max, found.x_at_y_max) == best(compensation=FrictionCompensation(1.0, 0.0))
    assert best() != (found.y_max, found.x_at_y_max)


def test_a_loop_without_a_stable_stiffness_has_no_simulated_limit(lowpass):
    """A negative mass and damping: the certified set has no K above 0 (its top is K = 0),
    so there is no window; the reason is said and nothing is simulated."""
    unstable = {"m": -0.0128, "b": -0.0324, "d": 2, "f_c": 100.0}
    with pytest.warns(symstab.NonPhysicalPlantWarning, match="negative high-frequency gain"):
        assert not lowpass.limits("B", "K", **unstable).y_max > 0
    found = simulated_limit(lowpass, x="B", y="K", amplitude=1.0, steps=200, **unstable)
    assert found.y_max is None and found.runs == 0 and "not above 0" in found.reason
