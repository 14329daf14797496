"""Coulomb friction with stiction on the driven mass of any loop (``Nonidealities.coulomb_friction``).

Oracles: the loop's own pulse transfer function (friction 0: the state
space in which friction acts must step like ``P(z)``, derived by residues);
the paper's simulator (its own state-space step of the same friction
model, written for the paper's plant alone); and an event-driven
integration by scipy of the physics written out by hand
(:func:`oracles.coulomb_friction_run`), which the sub-steps approach as
they are refined.
"""


import numpy as np
import pytest

import symstab
from symstab.numeric.paper.simulate import simulate
from symstab.numeric.simulation.simulator import Nonidealities

import oracles
from conftest import REPO

LOOPS = REPO / "examples" / "loops"


@pytest.mark.parametrize("file", sorted(p.stem for p in LOOPS.glob("*.toml")))
def test_without_friction_the_state_space_steps_like_the_pulse_transfer_function(file):
    loop = symstab.load_loop(LOOPS / f"{file}.toml")
    plain = loop.simulate(steps=300, record=True)
    spaced = loop.simulate(steps=300, record=True, nonideal=Nonidealities(coulomb_friction=0.0))
    scale = np.max(np.abs(plain.positions))
    np.testing.assert_allclose(spaced.positions, plain.positions, rtol=0, atol=1e-11 * scale)


@pytest.mark.parametrize("coulomb, stiction", [(1e-4, 1e-4), (2e-4, 5e-4), (2e-3, 3e-3)])
def test_the_paper_loop_with_friction_runs_as_the_paper_simulator(coulomb, stiction):
    device = symstab.PAPER_DEVICE
    loop = symstab.load_loop(LOOPS / "paper.toml")
    top = symstab.limits(gamma=0.0, d=10, delta=device.delta)
    alpha = np.array([0.2, 0.5, 0.9, 1.1]) * top.alpha_max
    beta = np.array([0.3, 0.5, 0.5, 0.5]) * top.beta_right
    nonideal = Nonidealities(coulomb_friction=coulomb, stiction=stiction, substeps=20)
    paper = simulate(alpha=alpha, beta=beta, gamma=0.0, d=10, delta=None, device=device,
                     x0=0.01, v0=0.0, nonideal=nonideal, record=True, steps=2000)
    found = loop.simulate(K=device.stiffness(alpha), B=device.damping(beta), M=0.0, d=10,
                          x0=0.01, v0=0.0, nonideal=nonideal, record=True, steps=2000)
    assert paper.stable.tolist() == found.stable.tolist() == [True, True, True, False]
    scale = np.max(np.abs(paper.positions), axis=0)
    assert np.all(np.abs(found.positions - paper.positions) <= 1e-11 * scale)


def _two_mass(m1, m2, b1, k_t, c_t):
    """Motor m1 (friction, force, position) and handle m2 on a spring-damper: x1 v1 x2 v2."""
    def rhs(y, u, friction):
        x1, v1, x2, v2 = y
        coupling = k_t * (x1 - x2) + c_t * (v1 - v2)
        return [v1, (u - b1 * v1 - coupling - friction) / m1, v2, coupling / m2]

    return {"rhs": rhs, "velocity": lambda y: y[1], "position": lambda y: y[0],
            "net": lambda y, u: u - k_t * (y[0] - y[2]) - c_t * (y[1] - y[3]) - b1 * y[1],
            "stop": lambda y: np.array([y[0], 0.0, y[2], y[3]]),
            "start": lambda x0: np.array([x0, 0.0, x0, 0.0])}


def _lagged_mass(m, b, tau):
    """A mass behind a first-order force lag: x v F."""
    def rhs(y, u, friction):
        x, v, force = y
        return [v, (force - b * v - friction) / m, (u - force) / tau]

    return {"rhs": rhs, "velocity": lambda y: y[1], "position": lambda y: y[0],
            "net": lambda y, u: y[2] - b * y[1],
            "stop": lambda y: np.array([y[0], 0.0, y[2]]),
            "start": lambda x0: np.array([x0, 0.0, 0.0])}


@pytest.mark.parametrize("file, model", [
    ("two_mass", lambda v: _two_mass(v["m1"], v["m2"], v["b1"], v["k_t"], v["c_t"])),
    ("actuator_lag", lambda v: _lagged_mass(v["m"], v["b"], v["tau"])),
])
def test_stick_slip_converges_to_the_event_driven_integration(file, model):
    loop = symstab.load_loop(LOOPS / f"{file}.toml")
    values = dict(loop.defaults)
    coulomb, stiction, x0, steps = 0.05, 0.08, 0.01, 150
    reference = oracles.coulomb_friction_run(
        model(values), K=values["K"], B=values["B"], T=values["T"], d=values["d"],
        steps=steps, x0=x0, coulomb=coulomb, stiction=stiction)
    # The reference sticks and slips: it ends held, within stiction / K of 0.
    assert np.all(reference[-20:] == reference[-1]) and 0 < abs(reference[-1]) <= stiction / values["K"]
    errors = []
    for substeps in (20, 400):
        run = loop.simulate(steps=steps, x0=x0, v0=0.0, record=True, nonideal=Nonidealities(
            coulomb_friction=coulomb, stiction=stiction, substeps=substeps))
        errors.append(np.max(np.abs(run.positions - reference)) / x0)
    # The sub-steps decide sticking and reversals at their ends: first order.
    assert errors[1] <= errors[0] / 5
    assert errors[1] <= 2e-3


LAGGED = "1/((tau*s + 1)*(m*s**2 + b*s))"
ENVIRONMENT = "K + B*(z - 1)/(T*z)"
VALUES = {"m": 0.0128, "b": 0.0324, "tau": 1.6e-4, "T": 1e-3, "d": 1, "K": 100.0, "B": 0.5}


def test_friction_behind_a_lag_needs_the_loop_s_actuator():
    """Without ``actuator`` the lag would sit between friction and the mass: refused, not guessed."""
    loop = symstab.Loop(LAGGED, ENVIRONMENT, values=VALUES)
    with pytest.raises(ValueError, match=r"nonideal\.coulomb_friction.*relative degree 3.*actuator"):
        loop.simulate(steps=100, nonideal=Nonidealities(coulomb_friction=0.01))
    loop.simulate(steps=100)                        # the loop itself is fine
    lagged = symstab.Loop(LAGGED, ENVIRONMENT, values=VALUES, actuator="1/(tau*s + 1)")
    assert lagged.simulate(steps=100, nonideal=Nonidealities(coulomb_friction=0.01)).steps == 100


@pytest.mark.parametrize("actuator, match", [
    ("1/(k*s + 1)", "k is not a parameter of the plant"),
    ("s + 1", "must be proper"),
    ("1/(tau*s + 1)**2", "relative degree 1"),
    ("exp(s)", "rational function"),
    (3, "must be a string"),
])
def test_a_wrong_actuator_is_refused_by_name(actuator, match):
    with pytest.raises((TypeError, ValueError), match=match) as excinfo:
        symstab.Loop(LAGGED, ENVIRONMENT, values=VALUES, actuator=actuator)
    assert "actuator" in str(excinfo.value)


def test_the_loop_file_s_actuator_is_read_and_travels_with_the_loop():
    import pickle

    loop = symstab.load_loop(LOOPS / "actuator_lag.toml")
    assert str(loop.actuator) == "1/(s*tau + 1)"
    assert str(pickle.loads(pickle.dumps(loop)).actuator) == str(loop.actuator)
    text = (LOOPS / "actuator_lag.toml").read_text().replace(
        'actuator = "1/(tau*s + 1)"', 'actuator = "__import__(\'os\')"')
    with pytest.raises(ValueError, match="actuator"):
        symstab.numeric.loop.files.parse_loop_text(text)


def test_points_with_different_plants_run_as_each_alone():
    """Per-point state spaces (a mass of each size) give each point's own run."""
    loop = symstab.load_loop(LOOPS / "two_mass.toml")
    nonideal = Nonidealities(coulomb_friction=0.05, stiction=0.08, substeps=10)
    m1 = np.array([0.002, 0.004, 0.008])
    together = loop.simulate(m1=m1, steps=300, x0=0.01, record=True, nonideal=nonideal)
    for k, value in enumerate(m1):
        alone = loop.simulate(m1=value, steps=300, x0=0.01, record=True, nonideal=nonideal)
        scale = np.max(np.abs(alone.positions))
        np.testing.assert_allclose(together.positions[:, k], alone.positions, rtol=0,
                                   atol=1e-12 * scale)
    assert len({together.positions[-1, k] for k in range(3)}) == 3


@pytest.mark.parametrize("coulomb", [1e10, 70.0, 5.0])
def test_friction_stops_the_mass_where_the_physics_does_never_behind_its_start(coulomb):
    """Issue 40, item 5: a sub-step that stopped the mass went on pushing it back for the rest
    of the sub-step (Coulomb 1e10 on the paper's loop: "held at rest at x = -976.5", from
    x0 = 0.01 moving forward).  Oracle: the paper's mass (m, viscous b) sliding from rest
    position 0 at v0 under friction F alone, solved by hand, m v' = -b v - F:
    t* = (m/b) log(1 + b v0 / F), x(t*) = (m/b)(v0 + F/b)(1 - exp(-b t*/m)) - F t*/b,
    at 40 digits (the floats cancel).  The sub-step's stop treats the forces besides
    friction as constant over the stop: its error, relative, is at most b v0 / F.  With
    1e10 the stop falls 2.6e-9 of the way into the first sub-step, with 70 a third of the
    way, with 5 in the sixth."""
    import mpmath

    from symstab.numeric.simulation.friction import StatePlant

    loop = symstab.load_loop(LOOPS / "paper.toml")
    m, b, v0 = loop.defaults["m"], loop.defaults["b"], 0.1
    space = loop.friction_spaces(20, **loop.defaults)[0][0]
    state = np.zeros((space.phi.shape[0], 1))
    state[1] = v0
    plant = StatePlant(space, state, np.array([False]), substeps=20, coulomb=coulomb,
                       stiction=coulomb)
    periods = [plant.step(np.zeros(1))[0] for _ in range(3)]
    with mpmath.workdps(40):
        M, B, V, F = map(mpmath.mpf, (m, b, v0, coulomb))
        stop = M / B * mpmath.log1p(B * V / F)
        exact = float(M / B * (V + F / B) * -mpmath.expm1(-B * stop / M) - F * stop / B)
    assert abs(periods[0] - exact) <= b * v0 / coulomb * exact
    assert periods[1] == periods[2] == periods[0] and plant.state[1, 0] == 0.0   # held


def test_a_huge_friction_holds_the_loop_s_mass_where_it_started():
    """The command line's case: the paper's loop at d = 10 from x0 = 0.01, moving forward
    at x0 / 100 a period.  The mass cannot travel further than it would coast without
    friction in the first sub-step, nor go back: it stays in [x0, x0 + v0 / 20]."""
    loop = symstab.load_loop(LOOPS / "paper.toml")
    run = loop.simulate(d=10, x0=0.01, steps=400, record=True,
                        nonideal=Nonidealities(coulomb_friction=1e10))
    assert np.all(run.positions >= 0.01) and np.all(run.positions <= 0.01 + 1e-4 / 20)
    assert run.stable and not run.diverged
