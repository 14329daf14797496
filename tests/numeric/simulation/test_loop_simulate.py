"""``Loop.simulate`` and ``Loop.stability_map``: any loop run in time.

Oracles:

* the loop's certified root counts (:meth:`symstab.Loop.classify`) on a grid
  of every example loop's plane, away from the boundary (cells whose
  spectral radius is within 1e-3 of 1 are undecidable in a finite run);
* python-control: the closed loop built from the plant ``G(s)`` sampled by
  ``control.c2d(..., "zoh")``, the environment ``VE(z)`` and ``z**-d``
  (``control.feedback``), whose largest pole modulus the run's growth per
  period must equal.

Measured (this revision): on 24 x 24 grids of the seven example loops every
cell agrees with the root counts; the growth per period agrees with
python-control's pole radius to 2e-5 and better.
"""

import dataclasses
import math

import numpy as np
import pytest

import symstab
from symstab.numeric.paper.simulate import stability_map
from symstab.numeric.simulation.simulator import Nonidealities

from conftest import PAPER_DELTA, REPO, assert_message_names
from oracles import python_control_parts

LOOPS = REPO / "examples" / "loops"
EXAMPLES = sorted(path.name for path in LOOPS.glob("*.toml"))

pytestmark = pytest.mark.usefixtures("loop_cache_dir")


def window(loop):
    """A grid around the stable set of the loop's plane at its default values."""
    lim = loop.limits()
    width = lim.x_max - lim.x_min
    return (np.linspace(lim.x_min - 0.2 * width, lim.x_max + 0.2 * width, 24),
            np.linspace(-0.1 * lim.y_max, 1.3 * lim.y_max, 24))


@pytest.mark.parametrize("file", EXAMPLES)
def test_simulated_maps_agree_with_the_root_counts(file):
    loop = symstab.load_loop(LOOPS / file)
    xs, ys = window(loop)
    found = loop.stability_map(xs, ys)
    x, y = loop.plane
    Y, X = np.meshgrid(ys, xs, indexing="ij")
    code = loop.classify(**{x: X, y: Y})
    assert found.stable.shape == (ys.size, xs.size) and 0 < found.stable.sum() < found.stable.size
    differ = np.argwhere((code == 1) != found.stable)
    decided = [(i, j) for i, j in differ
               if abs(loop.spectral_radius(**{x: xs[j], y: ys[i]}) - 1) > 1e-3]
    assert decided == [], f"{len(decided)} cells away from the boundary differ"
    assert (found.x, found.y) == (x, y) and found.at["d"] == loop.defaults["d"]


def python_control_radius(loop, values):
    """The largest closed-loop pole modulus, built by python-control from G(s) and VE(z)."""
    control = pytest.importorskip("control")
    sampled, environment, delay = python_control_parts(loop, values)
    closed = control.feedback(sampled, environment * delay)
    return float(np.max(np.abs(closed.poles())))


@pytest.mark.parametrize("file, scale", [("operator_arm.toml", 1.02), ("actuator_lag.toml", 1.02),
                                         ("paper.toml", 1.02), ("two_mass.toml", 1.1),
                                         ("operator_arm.toml", 0.7), ("frictionless.toml", 0.8)])
def test_the_growth_per_period_is_the_python_control_pole_radius(file, scale):
    """Just above the top of the stable set (growing) and inside it (decaying)."""
    loop = symstab.load_loop(LOOPS / file)
    lim = loop.limits()
    x, y = loop.plane
    values = {**loop.defaults, x: lim.x_at_y_max, y: scale * lim.y_max}
    radius = python_control_radius(loop, values)
    steps = 8000
    run = loop.simulate(steps=steps, record=True, **values)
    assert not run.diverged
    # The envelope's growth over the last half: max |x| over a window of 400 periods.
    x_abs = np.abs(run.positions)
    early, late = x_abs[steps // 2 - 400:steps // 2].max(), x_abs[steps - 400:].max()
    measured = (late / early) ** (1 / (steps // 2))
    assert measured == pytest.approx(radius, abs=1e-4)
    assert bool(run.stable) == (radius < 1)


def test_encoder_quantization_keeps_a_stable_loop_bounded_and_saturation_holds_an_unstable_one():
    loop = symstab.load_loop(LOOPS / "operator_arm.toml")
    quantized = loop.simulate(x0=0.01, steps=4000,
                              nonideal=Nonidealities(encoder_resolution=1e-6))
    assert quantized.stable and not quantized.diverged
    unstable = {"K": 3000.0}
    assert loop.classify(**unstable) == -1
    assert not loop.simulate(x0=0.01, steps=4000, **unstable).stable
    held = loop.simulate(x0=0.01, steps=4000, nonideal=Nonidealities(force_limit=5.0),
                         record=True, **unstable)
    assert not held.diverged
    # The force is at most 5 N: the position never exceeds what 5 N can hold against the
    # arm's spring (k_h = 100 N/m) by much.
    assert np.max(np.abs(held.positions)) < 0.2


def test_a_force_limit_holds_an_unstable_paper_loop_and_a_loose_one_changes_nothing():
    """The paper's simulator clips its command in the device's units."""
    alpha, beta = np.linspace(0.001, 0.02, 9), np.linspace(-0.005, 0.05, 9)
    ideal = stability_map(alpha=alpha, beta=beta, gamma=0.0, d=5, delta=None,
                          device=symstab.PAPER_DEVICE, steps=6000)
    # A limit the stable runs never reach (they start at x0 = 1 rad and decay).
    loose = stability_map(alpha=alpha, beta=beta, gamma=0.0, d=5, delta=None,
                          device=symstab.PAPER_DEVICE, steps=6000,
                          nonideal=Nonidealities(force_limit=1e3))
    # The stable runs are the same runs; an unstable one grows into the limit and is
    # held there (bounded: the verdict does not call it growing).
    assert np.array_equal(ideal.growth[ideal.stable], loose.growth[ideal.stable])
    assert np.all(loose.stable[ideal.stable]) and not np.any(loose.growth == np.inf)
    assert np.array_equal(ideal.alpha, alpha) and ideal.gamma == 0.0 and ideal.d == 5
    unstable = dict(alpha=0.05, beta=0.0, gamma=0.0, d=5, delta=None,
                    device=symstab.PAPER_DEVICE, steps=6000, x0=0.01)
    assert symstab.simulate(**unstable).diverged
    assert not symstab.simulate(**unstable, nonideal=Nonidealities(force_limit=0.01)).diverged


@pytest.mark.parametrize("limit, quantum", [(5.0, None), (None, 0.7), (5.0, 0.7)])
def test_the_dac_rounds_and_clips_the_command_not_the_environment_s_own_force(limit, quantum):
    """An environment that feeds its force back (a low-pass, VE = K z/(z - r)) keeps
    Ve_d(z) f = Ve_n(z) x_s with the DAC on: only the command sent is rounded to the
    force quantum and clipped to the limit.  The reference is written here from the
    difference equations, with python-control's c2d for the plant."""
    control = pytest.importorskip("control")
    m, b, T, K, r, d = 0.0128, 0.0324, 1e-3, 40.0, 0.6, 1
    loop = symstab.Loop("1/(m*s**2 + b*s)", "K*z/(z - r)",
                        values={"m": m, "b": b, "T": T, "K": K, "r": r, "d": d})
    steps = 300
    run = loop.simulate(steps=steps, record=True,
                        nonideal=Nonidealities(force_limit=limit, force_resolution=quantum))
    sampled = control.c2d(control.tf([1.0], [m, b, 0.0]), T, "zoh")
    num = np.trim_zeros(np.asarray(sampled.num[0][0], dtype=float), "f")
    den = np.asarray(sampled.den[0][0], dtype=float)
    b1, b2 = num / den[0]
    a1, a2 = den[1:] / den[0]
    x = [1.0 - 2 * 0.01, 1.0 - 0.01, 1.0]        # y[-2], y[-1], y[0]
    u = [0.0, 0.0]                                # u[-2], u[-1]
    f_prev, line, sent = K / (1 - r) * 1.0, [0.0] * (d + 1), set()   # at rest at x0 = 1
    for k in range(steps):
        f = K * x[-1] + r * f_prev                # f[k] = K x[k] + r f[k-1]
        f_prev = f
        command = f if quantum is None else quantum * round(f / quantum)
        command = command if limit is None else min(max(command, -limit), limit)
        sent.add(command)
        line[k % (d + 1)] = command
        u.append(-line[(k - d) % (d + 1)])
        x.append(b1 * u[-1] + b2 * u[-2] - a1 * x[-1] - a2 * x[-2])
    # Two computations of the sampled plant (the loop's residues, python-control's
    # matrix exponential) differ in their last bits; over 300 periods that grows to
    # 1.3e-12 of max |x| = 1 (measured, with the quantum).
    np.testing.assert_allclose(run.positions, x[2:], rtol=1e-9, atol=1e-11)
    # The DAC did act: the commands are its levels, and the run is not the linear one.
    if limit is not None:
        assert max(sent) == limit
    if quantum is not None:
        assert all(c == quantum * round(c / quantum) or abs(c) == limit for c in sent)
    linear = loop.simulate(steps=steps, record=True)
    assert np.max(np.abs(run.positions - linear.positions)) > 1e-3


@pytest.mark.parametrize("file, quantum", [("lowpass_velocity.toml", 1e-3),
                                           ("operator_arm.toml", 0.05),
                                           ("two_mass.toml", 1e-3)])
def test_a_force_quantum_moves_a_stable_loop_by_at_most_half_of_it_times_the_pulse_response(
        file, quantum):
    """Rounding adds at most q/2 to each command: the quantized run stays within q/2 times
    the l1 norm of the closed loop's force-pulse response of the unquantized run, which
    is the verdict's floor.  The response is python-control's: the plant sampled by
    c2d, the delay and the environment closed by ``feedback``."""
    control = pytest.importorskip("control")
    loop = symstab.load_loop(LOOPS / file)
    values = dict(loop.defaults)
    assert loop.classify(**values) == 1
    steps = 3000
    exact = loop.simulate(steps=steps, x0=0.01, record=True, **values)
    quantized = loop.simulate(steps=steps, x0=0.01, record=True,
                              nonideal=Nonidealities(force_resolution=quantum), **values)
    sampled, environment, delay = python_control_parts(loop, values)
    # The position per force added to the command sent (before the delay).
    pulse = control.feedback(sampled * delay, environment)
    T = float(values["T"])
    # A unit force for one period (impulse_response would scale it by 1 / T).
    unit = np.zeros(steps + 1)
    unit[0] = 1.0
    h = control.forced_response(pulse, T=np.arange(steps + 1) * T, U=unit).outputs
    bound = quantum / 2 * np.sum(np.abs(h[1:]))
    assert float(quantized.floor) == pytest.approx(bound, rel=1e-6)
    departure = np.max(np.abs(quantized.positions - exact.positions))
    assert 0 < departure <= bound
    assert quantized.stable


def test_a_force_quantum_map_agrees_with_the_root_counts_away_from_the_boundary():
    """The floor is given only where the linear loop is stable: an unstable cell's growth
    is not hidden, and a stable cell's quantization cycle is not called growth (without
    the floor, 543 of these 1 515 stable cells were: the last quarter of a limit cycle
    exceeds the third as often as not)."""
    loop = symstab.load_loop(LOOPS / "paper.toml")
    bs, ks = np.linspace(-0.02, 0.3, 20), np.linspace(0.0, 6.0, 20)
    K, B = np.meshgrid(ks, bs, indexing="ij")
    found = loop.simulate(K=K, B=B, d=5, steps=6000, x0=0.01,
                          nonideal=Nonidealities(force_resolution=1e-3))
    code = loop.classify(K=K, B=B, d=5)
    assert 0 < np.sum(code == 1) < code.size and np.any(code == -1)
    differ = np.argwhere((code == 1) != found.stable)
    decided = [(i, j) for i, j in differ
               if abs(loop.spectral_radius(K=ks[i], B=bs[j], d=5) - 1) > 1e-3]
    assert decided == []
    assert np.all(found.stable[code == 1])
    # Where the linear loop is not stable there is no floor.
    assert np.all(found.floor[code != 1] == 0) and np.all(found.floor[code == 1] > 0)


def test_a_force_quantum_with_friction_is_refused_by_name():
    with pytest.raises(ValueError) as excinfo:
        Nonidealities(force_resolution=1e-3, coulomb_friction=0.01)
    assert_message_names(excinfo, "force_resolution")
    assert "coulomb_friction" in str(excinfo.value)


def test_a_loop_map_has_no_paper_names():
    loop = symstab.load_loop(LOOPS / "frictionless.toml")
    found = loop.stability_map([0.05], [20.0], steps=100)
    with pytest.raises(AttributeError, match="x_values"):
        _ = found.beta


@pytest.mark.parametrize("nonideal, name", [
    (Nonidealities(velocity_cutoff=50.0), "velocity_cutoff"),
    (Nonidealities(actuator_bandwidth=100.0), "actuator_bandwidth"),
    ("none", "nonideal"),
])
def test_what_a_loop_does_not_model_is_refused_by_name(nonideal, name):
    loop = symstab.load_loop(LOOPS / "paper.toml")
    with pytest.raises((TypeError, ValueError)) as excinfo:
        loop.simulate(steps=100, nonideal=nonideal)
    assert_message_names(excinfo, "nonideal" if name == "nonideal" else f"nonideal.{name}")


def test_a_plant_with_direct_feed_through_is_refused():
    loop = symstab.Loop("(s + 1)/(s + 2)", "K", values={"K": 1.0, "T": 1e-3, "d": 1})
    with pytest.raises(ValueError, match="direct feed-through"):
        loop.simulate(steps=100)


@pytest.mark.parametrize("kwargs, name", [({"steps": 3}, "steps"), ({"x0": 0.0}, "x0"),
                                          ({"x0": math.inf}, "x0"), ({"K": "a"}, "K"),
                                          ({"progress": 5}, "progress")])
def test_bad_simulation_input_names_the_parameter(kwargs, name):
    loop = symstab.load_loop(LOOPS / "paper.toml")
    with pytest.raises((TypeError, ValueError)) as excinfo:
        loop.simulate(**kwargs)
    assert_message_names(excinfo, name)


@pytest.mark.parametrize("nonideal", [None, Nonidealities(force_resolution=1e-3)])
def test_the_paper_loop_simulated_as_a_loop_agrees_with_the_paper_simulator(nonideal):
    """PAPER_LOOP's simulation and the paper's simulator (a state-space step of its own)
    give the same verdicts on a grid across the stable set, away from the boundary; with
    a force quantum too (the paper's simulator scales it to its units)."""
    loop = symstab.load_loop(LOOPS / "paper.toml")
    device = symstab.PAPER_DEVICE
    assert device.delta == pytest.approx(PAPER_DELTA, rel=1e-12)
    top = symstab.limits(gamma=0.0, d=10, delta=PAPER_DELTA)
    alpha = np.linspace(0.05, 1.3, 8) * top.alpha_max
    beta = np.linspace(top.beta_left - 0.2 * top.beta_right, 1.2 * top.beta_right, 8)
    paper = stability_map(alpha=alpha, beta=beta, gamma=0.0, d=10, delta=None, device=device,
                          nonideal=nonideal)
    found = loop.stability_map(device.damping(beta), device.stiffness(alpha), d=10, M=0.0,
                               nonideal=nonideal)
    assert 0 < found.stable.sum() < found.stable.size
    differ = np.argwhere(paper.stable != found.stable)
    decided = [(i, j) for i, j in differ if abs(symstab.spectral_radius(
        alpha=alpha[i], beta=beta[j], gamma=0.0, d=10, delta=PAPER_DELTA) - 1) > 1e-3]
    assert decided == []
    if nonideal is not None:
        # The quantum's floor (rad) is the same in both units: the scaling is right.
        a, b = alpha[:3], beta[4]
        assert symstab.classify(alpha=a, beta=b, gamma=0.0, d=10, delta=PAPER_DELTA).tolist() \
            == [1, 1, 1]
        paper = symstab.simulate(alpha=a, beta=b, gamma=0.0, d=10, delta=None, device=device,
                                 nonideal=nonideal, steps=4000)
        found = loop.simulate(K=device.stiffness(a), B=device.damping(b), d=10, M=0.0,
                              nonideal=nonideal, steps=4000)
        assert np.all(paper.floor > 0)
        np.testing.assert_allclose(paper.floor, found.floor, rtol=1e-9)


@pytest.mark.parametrize("B, K", [(-0.05, 26.25), (0.1125, 35.0), (1.25, 61.25)])
def test_a_saturated_unstable_loop_s_bounded_cycle_is_a_limit_cycle_not_stable(B, K):
    """Issue 40, item 4: 38 such cells of a map were called stable (and the rest of the
    cycles unstable, by whether a sampled peak of the last quarter exceeded the third's).
    Oracles: python-control's closed-loop poles (the linear loop is unstable, so the run
    cannot be decaying to rest) and the run's own trajectory (bounded; its swing, half of
    max - min, the same over the last three quarters)."""
    loop = symstab.load_loop(LOOPS / "paper.toml")
    values = {**loop.defaults, "d": 10, "B": B, "K": K}
    assert python_control_radius(loop, values) > 1.001
    steps = 6000
    run = loop.simulate(steps=steps, x0=0.01, nonideal=Nonidealities(force_limit=0.05),
                        record=True, **values)
    quarters = run.positions[1:].reshape(4, steps // 4)
    swing = (quarters.max(axis=1) - quarters.min(axis=1)) / 2
    assert np.all(np.abs(run.positions) < 1.0)                  # bounded
    assert swing[3] > 0.01 * 0.01                               # not at rest
    assert 0.999 * swing[1] <= swing[3] <= 1.001 * swing[2]     # not decaying, not growing
    assert run.limit_cycle and not run.stable and not run.diverged and run.bounded
    # A stable cell of the same loop and limit stays stable; the ideal loop has no cycle.
    inside = loop.simulate(steps=steps, x0=0.01, nonideal=Nonidealities(force_limit=0.05),
                           **{**values, "B": 0.6, "K": 26.25})
    assert inside.stable and not inside.limit_cycle
    ideal = loop.simulate(steps=steps, x0=0.01, **values)
    assert not ideal.limit_cycle and not ideal.stable


def test_a_map_of_a_saturated_loop_calls_its_cycles_limit_cycles_where_the_count_is_unstable():
    """The map's classes against the certified root counts: at the cells the count calls
    unstable the saturated run is a limit cycle (bounded: python-control's poles say the
    linear loop grows), never stable; where the count is stable, the run is stable."""
    loop = symstab.load_loop(LOOPS / "paper.toml")
    xs, ys = np.linspace(-0.05, 1.9, 7), np.linspace(8.75, 70.0, 5)
    found = loop.stability_map(xs, ys, steps=6000, x0=0.01, d=10,
                               nonideal=Nonidealities(force_limit=0.05))
    Y, X = np.meshgrid(ys, xs, indexing="ij")
    code = loop.classify(B=X, K=Y, d=10)
    assert np.all(found.limit_cycle[code == -1]) and not np.any(found.stable[code == -1])
    assert np.all(found.stable[code == 1]) and not np.any(found.limit_cycle[code == 1])
    assert np.count_nonzero(code == -1) >= 8


@pytest.mark.parametrize("field", ["encoder_resolution", "force_resolution"])
def test_a_quantum_double_precision_cannot_hold_is_refused_by_name(field):
    """Issue 40, item 6: a subnormal quantum (1e-320) overflowed every quotient above 1.8e-12
    and each run read "diverged (unstable)".  Refused: the smallest normal double."""
    with pytest.raises(ValueError) as excinfo:
        Nonidealities(**{field: 1e-320})
    assert_message_names(excinfo, field)
    assert f">= {float(np.finfo(float).tiny)!r}" in str(excinfo.value)


def test_a_quantum_far_below_a_value_s_precision_leaves_it_as_it_is():
    """From the smallest normal quantum on, a value whose quotient overflows is rounded to
    itself (the quantum is far below its last bit), not to inf: the stable loop from x0 = 100
    with a quantum of 1e-307 is the ideal loop's run, to the bit (it was "diverged")."""
    loop = symstab.load_loop(LOOPS / "paper.toml")
    ideal = loop.simulate(d=10, x0=100.0, steps=400, record=True)
    fine = loop.simulate(d=10, x0=100.0, steps=400, record=True,
                         nonideal=Nonidealities(encoder_resolution=1e-307))
    assert not fine.diverged
    np.testing.assert_array_equal(fine.positions, ideal.positions)


def test_a_friction_double_precision_cannot_step_is_refused_before_the_run():
    """The sub-step adds gamma_f F to the state: past 1e300 that overflows.  Refused with the
    bound on this plant (1e300 over its largest gamma_f, computed here from the plant's
    exact sub-step: a mass m with viscous b, gamma_f[1] = (1 - exp(-b h / m)) / b), before
    a period is run; below the bound a huge friction holds the mass (1e200: at x0)."""
    loop = symstab.load_loop(LOOPS / "paper.toml")
    m, b, h = loop.defaults["m"], loop.defaults["b"], loop.defaults["T"] / 20
    bound = 1e300 / (-math.expm1(-b * h / m) / b)
    calls = []
    with pytest.raises(ValueError) as excinfo:
        loop.simulate(d=10, x0=0.01, progress=calls.append,
                      nonideal=Nonidealities(coulomb_friction=1.01 * bound))
    assert_message_names(excinfo, "coulomb_friction")
    assert f"from 0 to {bound:.3g}" in str(excinfo.value) and calls == []
    held = loop.simulate(d=10, x0=0.01, steps=400, record=True,
                         nonideal=Nonidealities(coulomb_friction=1e200))
    assert held.stable and np.all(held.positions >= 0.01) and np.all(held.positions < 0.0101)


def test_the_paper_simulator_refuses_a_quantum_that_its_units_make_subnormal():
    """The paper's simulator runs in Table I's units, its forces times T^2 / m (7.8e-5 for the
    paper's device): 3e-308 N m is a normal double, its run's quantum is not."""
    scale = symstab.PAPER_DEVICE.T**2 / symstab.PAPER_DEVICE.m
    with pytest.raises(ValueError) as excinfo:
        symstab.simulate(alpha=0.01, beta=0.1, gamma=0.0, d=10, delta=None, steps=100,
                         device=symstab.PAPER_DEVICE,
                         nonideal=Nonidealities(force_resolution=3e-308))
    assert_message_names(excinfo, "force_resolution")
    assert f">= {float(np.finfo(float).tiny) / scale!r}" in str(excinfo.value)


# --------------------------------------------------------------------------
# Friction compensation: an option of the loop simulator


def test_friction_compensation_is_an_option_of_the_loop_simulator():
    """``compensation=`` of simulate_loop: none at F_c = 0 (the same run, bit for bit), a
    different run otherwise, on a loop file and on a spring alone (an environment that keeps
    no sample, whose estimate is the simulator's own)."""
    from symstab.numeric.simulation.simulator import FrictionCompensation, simulate_loop

    loop = symstab.load_loop(LOOPS / "paper.toml")
    friction = Nonidealities(coulomb_friction=0.01)
    at = {"K": 30.0, "B": 1.0, "d": 10}
    plain = simulate_loop(loop, steps=400, x0=0.01, nonideal=friction, record=True, **at)
    zero = simulate_loop(loop, steps=400, x0=0.01, nonideal=friction, record=True,
                         compensation=FrictionCompensation(0.0), **at)
    np.testing.assert_array_equal(zero.positions, plain.positions)
    compensated = simulate_loop(loop, steps=400, x0=0.01, nonideal=friction, record=True,
                                compensation=FrictionCompensation(0.01, pole=0.5), **at)
    assert not np.array_equal(compensated.positions, plain.positions)
    spring = symstab.Loop("1/(m*s**2)", "K", values={"m": 1.0, "K": 0.5, "T": 1e-3, "d": 1})
    pushed = simulate_loop(spring, steps=100, x0=0.01, record=True,
                           compensation=FrictionCompensation(1e-3))
    free = simulate_loop(spring, steps=100, x0=0.01, record=True)
    assert not np.array_equal(pushed.positions, free.positions)


@pytest.mark.parametrize("cutoff", [None, 50.0])
def test_friction_compensation_of_a_loop_is_the_paper_simulators(cutoff):
    """Issue 41, item 3: ``Nonidealities(friction_compensation=True)`` compensates any loop's
    Coulomb friction on the simulator's backward difference (every loop refused it), or on
    that difference filtered with the ``compensation=`` option's pole.  Oracle: the paper's
    simulator, another path to the same device (its loop in Table I's units, forces times
    T^2/m, its own switch and velocity filter), from the same state: paper.toml, and
    lowpass_velocity.toml with the filter's pole.  Unfiltered it is the run with the option
    ``FrictionCompensation(F_c, 0.0)`` given explicitly, bit for bit, and not the
    uncompensated run; filtered, not the run on the unfiltered estimate."""
    from symstab.numeric.simulation.simulator import FrictionCompensation

    device, friction = symstab.PAPER_DEVICE, 0.004
    alpha, beta = np.array([0.001, 0.004, 0.008]), np.array([[0.05], [0.15]])
    compensated = Nonidealities(coulomb_friction=friction, friction_compensation=True)
    common = dict(steps=300, x0=0.01, v0=-2e-4, record=True)
    paper = symstab.simulate(alpha=alpha, beta=beta, gamma=0.0, d=6, delta=None, device=device,
                             nonideal=dataclasses.replace(compensated, velocity_cutoff=cutoff),
                             **common)
    at = dict(K=device.stiffness(alpha), B=device.damping(beta), m=device.m, b=device.b,
              T=device.T, d=6, start="state", **common)
    if cutoff is None:
        loop, option = symstab.load_loop(LOOPS / "paper.toml"), {}
        at["M"] = 0.0
    else:
        loop = symstab.load_loop(LOOPS / "lowpass_velocity.toml")
        at["f_c"] = cutoff
        option = {"compensation": FrictionCompensation(
            friction, math.exp(-2 * math.pi * cutoff * device.T))}
    run = loop.simulate(nonideal=compensated, **option, **at)
    np.testing.assert_allclose(run.positions, paper.positions, rtol=1e-9, atol=1e-14)
    np.testing.assert_array_equal(run.stable, paper.stable)
    np.testing.assert_array_equal(run.limit_cycle, paper.limit_cycle)
    friction_only = Nonidealities(coulomb_friction=friction)
    if cutoff is None:
        explicit = loop.simulate(nonideal=friction_only,
                                 compensation=FrictionCompensation(friction, 0.0), **at)
        np.testing.assert_array_equal(explicit.positions, run.positions)
        other = loop.simulate(nonideal=friction_only, **at)
    else:
        other = loop.simulate(nonideal=compensated, **at)
    assert np.max(np.abs(other.positions - run.positions)) > 1e-5


@pytest.mark.parametrize("start", ["samples", "state"])
def test_a_run_starts_from_the_samples_or_from_the_driven_mass_state(start):
    """Before the delayed force arrives the mass moves freely, ``x(t) = x0 + c (1 - exp(-b t /
    m))``: from the mass's state (position x0, velocity v0 / T) ``c = v0 m / (b T)``; from the
    sampled history ``x0 - k v0`` (x(-T) = x0 - v0) ``c = v0 / (exp(b T / m) - 1)``."""
    loop = symstab.load_loop(LOOPS / "paper.toml")
    m, b, T, d, x0, v0 = 0.0128, 0.0324, 1e-3, 8, 0.01, 3e-4
    run = loop.simulate(steps=40, x0=x0, v0=v0, record=True, start=start, K=20.0, B=0.5,
                        m=m, b=b, T=T, d=d)
    c = v0 * m / (b * T) if start == "state" else v0 / math.expm1(b * T / m)
    free = x0 - c * np.expm1(-b * T / m * np.arange(d + 1))
    np.testing.assert_allclose(run.positions[:d + 1], free, rtol=1e-13)
    assert not np.allclose(run.positions[d + 2], x0 - c * math.expm1(-b * T / m * (d + 2)))


def test_start_and_overflow_are_checked_and_an_overflow_may_diverge():
    """``overflow="diverge"`` runs a point whose equations overflow as diverged (the paper's
    rule); by default it is refused before the run, as a wrong ``start`` or ``overflow``."""
    loop = symstab.load_loop(LOOPS / "paper.toml")
    run = loop.simulate(steps=400, overflow="diverge", K=[20.0, 1e308], B=[0.5, 1e308], d=1)
    assert run.diverged.tolist() == [False, True] and run.stable.tolist() == [True, False]
    calls = []
    with pytest.raises(ValueError, match="overflows or underflows"):
        loop.simulate(steps=40, K=[20.0, 1e308], B=[0.5, 1e308], progress=calls.append)
    assert calls == []
    for kwargs, name in (({"start": "rest"}, "start"), ({"overflow": "ignore"}, "overflow")):
        with pytest.raises(ValueError) as excinfo:
            loop.simulate(steps=40, **kwargs)
        assert_message_names(excinfo, name)
    lag = symstab.Loop("1/((tau*s + 1)*(m*s**2 + b*s))", "K", values={
        "m": 0.0128, "b": 0.0324, "tau": 1e-3, "T": 1e-3, "d": 1, "K": 10.0})
    with pytest.raises(ValueError) as excinfo:
        lag.simulate(steps=40, start="state")
    assert_message_names(excinfo, "start")


def test_the_equations_are_computed_a_chunk_at_a_time(monkeypatch):
    """Peak traced memory per point of a 200 x 200 grid at d = 40 in chunks of 256 KiB: the
    result's 11 floats (88 bytes) a point and the chunks.  The difference equations of every
    point at once took 160 bytes a point; a chunk at a time they stay within the chunks.
    And the run in chunks is the run in one, bit for bit."""
    import tracemalloc

    from symstab import _resources
    from symstab.numeric.simulation import simulator as module

    loop = symstab.load_loop(LOOPS / "paper.toml")
    B, K = np.meshgrid(np.linspace(0.0, 2.0, 200), np.linspace(0.0, 50.0, 200))
    whole = loop.simulate(steps=48, B=B[:5], K=K[:5], d=40)
    monkeypatch.setattr(module, "chunk_slices",
                        lambda n, size: _resources.chunk_slices(n, size, budget=256 * 1024))
    tracemalloc.start()
    try:
        loop.simulate(steps=48, B=B, K=K, d=40)
        _, peak = tracemalloc.get_traced_memory()
    finally:
        tracemalloc.stop()
    assert peak < 120 * B.size + 2 * 256 * 1024, peak
    chunked = loop.simulate(steps=48, B=B[:5], K=K[:5], d=40)    # three chunks
    np.testing.assert_array_equal(chunked.amplitude, whole.amplitude)


@pytest.mark.parametrize("compensation, error, name", [
    ((0.01, 0.0), TypeError, "compensation"),
    ("compensation(-1)", ValueError, "compensation.coulomb"),
    ("compensation(0.01, 1.0)", ValueError, "compensation.pole"),
])
def test_a_wrong_compensation_is_refused_by_name(compensation, error, name):
    from symstab.numeric.simulation.simulator import FrictionCompensation, simulate_loop

    loop = symstab.load_loop(LOOPS / "paper.toml")
    with pytest.raises(error) as excinfo:
        if isinstance(compensation, str):
            compensation = eval(compensation, {"compensation": FrictionCompensation})
        simulate_loop(loop, steps=100, compensation=compensation)
    assert_message_names(excinfo, name)


def _fields(run):
    return [np.asarray(getattr(run, name)).tobytes() for name in
            ("amplitude", "diverged", "stable", "floor", "limit_cycle")]


@pytest.mark.parametrize("d", [3, 40])
def test_blocks_of_periods_change_no_bit_of_a_run(monkeypatch, d):
    """Blocks of up to d periods (the vectorised engine) = one period at a time, bit for bit.

    Oracle: the same runs with blocks of one period (``_BLOCK_MAX = 1``),
    the engine's other path; diverging, quantized, saturated, compensated
    and force-quantized runs, the overflow checks inside the blocks.
    """
    from symstab.numeric.simulation import simulator
    from symstab.numeric.simulation.simulator import FrictionCompensation

    lowpass = symstab.load_loop(LOOPS / "lowpass_velocity.toml")
    paper = symstab.load_loop(LOOPS / "paper.toml")
    B = np.linspace(-0.2, 0.4, 7)[:, None]
    quantum = simulator.PAPER_ENCODER_RESOLUTION

    def runs():
        return [lowpass.simulate(B=B, K=np.linspace(-500, 5e4, 9), f_c=300.0, d=d, steps=3001),
                lowpass.simulate(B=B, K=np.linspace(0, 400, 9), f_c=100.0, d=d, steps=1203,
                                 x0=0.01, nonideal=Nonidealities(encoder_resolution=quantum,
                                                                 force_limit=0.05)),
                paper.simulate(M=0.0, K=np.linspace(0, 60, 9), B=0.05, d=d, steps=805, x0=0.01,
                               compensation=FrictionCompensation(1e-3, 0.5),
                               nonideal=Nonidealities(coulomb_friction=1e-3,
                                                      encoder_resolution=quantum)),
                paper.simulate(M=0.0, K=np.linspace(-10, 900, 9), B=0.05, d=d, steps=805,
                               nonideal=Nonidealities(force_resolution=1e-4))]

    blocks = runs()
    assert any(run.diverged.any() for run in blocks) and any(run.stable.any() for run in blocks)
    monkeypatch.setattr(simulator, "_BLOCK_MAX", 1)
    for blocked, one in zip(blocks, runs(), strict=True):
        assert _fields(blocked) == _fields(one)
