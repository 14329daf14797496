"""``Loop.simulate(delays=...)``: a delay that varies from period to period by whole samples.

Oracles:

* the fixed-delay run (its own, block-wise engine): a constant sequence
  ``delta_k = d`` is that run to the last bit, recorded or not, with the
  non-idealities a varying delay keeps;
* the closed loop written out here in plain NumPy from python-control's
  coefficients (``control.c2d`` of ``G(s)``, ``VE(z)``), ``u[k] = -f[k -
  delta_k]``, with the run's initial conditions: equal to 1e-12 of the
  trajectory's size;
* with a fraction of a period every delay shares, the same loop by hand on
  the plant of the state space (Van Loan's block exponential, SciPy: the
  command held over a period arrives ``eps T`` late inside it).
"""

import numpy as np
import pytest

import symstab
from symstab.numeric.simulation.simulator import Nonidealities

from conftest import REPO, assert_message_names, run_cli
from oracles import _held_input_integral, _realisation, loop_coefficients, python_control_parts

LOOPS = REPO / "examples" / "loops"

pytestmark = pytest.mark.usefixtures("loop_cache_dir")


@pytest.fixture(scope="module")
def paper():
    return symstab.load_loop(LOOPS / "paper.toml")


@pytest.mark.parametrize("d, nonideal", [
    (0, None), (1, None), (7, None), (40, None),
    (3, Nonidealities(encoder_resolution=1e-4, force_limit=0.5)),
    (2, Nonidealities(coulomb_friction=0.01, friction_compensation=True, substeps=4)),
])
def test_a_constant_sequence_is_the_fixed_delay_run_to_the_last_bit(paper, d, nonideal):
    # Stable, growing and (K = 60) diverging points; the friction run on its state space.
    values = {"K": np.array([1.0, 4.0, 60.0]), "B": 0.05, "M": 0.001}
    steps, x0 = 1200, 0.01
    for record in (True, False):
        fixed = paper.simulate(d=d, steps=steps, x0=x0, nonideal=nonideal, record=record,
                               **values)
        varying = paper.simulate(delays=np.full(steps, d), x0=x0, nonideal=nonideal,
                                 record=record, **values)
        if record:
            assert np.array_equal(fixed.positions, varying.positions)
        assert np.array_equal(fixed.amplitude, varying.amplitude)
        for flag in ("stable", "diverged", "limit_cycle"):
            assert np.array_equal(getattr(fixed, flag), getattr(varying, flag))
        assert fixed.delays is None and np.array_equal(varying.delays, np.full(steps, d))


def python_control_coefficients(loop, values):
    """``(P_n, P_d, Ve_n, Ve_d)`` of python-control (``c2d`` of ``G(s)``, ``VE(z)``), highest first."""
    sampled, environment, _ = python_control_parts(loop, {**values, "d": 0})
    return tuple(np.asarray(c, dtype=float) for c in (
        sampled.num[0][0], sampled.den[0][0], environment.num[0][0], environment.den[0][0]))


def closed_loop_by_hand(coefficients, delays, x0, v0):
    """The positions ``x[0..steps]`` of the loop with delay ``delays[k]`` at period ``k``.

    ``P(z) = P_n / P_d`` and ``VE(z) = Ve_n / Ve_d`` (``coefficients``,
    highest power first), each divided by its leading denominator
    coefficient; ``f[k]`` from the sampled ``x[k]``, the plant's input
    ``u[k] = -f[k - delta_k]`` (0 before the start), ``x[k+1]`` from
    ``u[k], u[k-1], ...``.  The start: ``x[-i] = x0 - i v0``, the
    environment at rest at ``x0`` (its past samples ``x0``, past forces
    ``VE(1) x0``).
    """
    p_num, p_den, e_num, e_den = coefficients
    p_num, p_den, e_num, e_den = p_num / p_den[0], p_den / p_den[0], e_num / e_den[0], \
        e_den / e_den[0]
    n, m = len(p_den) - 1, len(e_den) - 1
    p_num = np.concatenate([np.zeros(n + 1 - len(p_num)), p_num])
    e_num = np.concatenate([np.zeros(m + 1 - len(e_num)), e_num])
    x = {-i: x0 - i * v0 for i in range(n + 1)}
    resting = e_num.sum() / e_den.sum() * x0
    f = {-i: resting for i in range(1, m + 1)}
    u = {}
    for k in range(len(delays)):
        f[k] = sum(e_num[j] * (x[k - j] if k - j >= 0 else x0) for j in range(m + 1)) \
            - sum(e_den[j] * f[k - j] for j in range(1, m + 1))
        u[k] = -f[k - delays[k]] if k - delays[k] >= 0 else 0.0
        x[k + 1] = sum(p_num[j] * u.get(k + 1 - j, 0.0) for j in range(1, n + 1)) \
            - sum(p_den[j] * x[k + 1 - j] for j in range(1, n + 1))
    return np.array([x[k] for k in range(len(delays) + 1)])


def own_coefficients(loop, values):
    """``(P_n, P_d, Ve_n, Ve_d)`` of the loop's own difference equations (monic), highest first."""
    (a, b, c, e), _, _ = loop.difference_equations(d=0, **values)
    return np.concatenate([[0.0], b]), np.concatenate([[1.0], a]), e, np.concatenate([[1.0], c])


# python-control's c2d numerator is within 2e-12 (relative) of the exact one
# on the paper's plant, but 6e-12 on the two-mass plant (its tf from the
# state space cancels; 8e-11 on the operator's arm): there the closed loop by
# hand takes the loop's own coefficients (checked against python-control's
# poles in test_loop_simulate.py) and checks the delay line of a fourth-order
# plant, each of its four past inputs with its own delay.
@pytest.mark.parametrize("file, point, source", [
    ("paper.toml", {"K": 3.0, "B": 0.05, "M": 0.002}, "control"),  # Ve_d = z**2: no feedback
    ("tustin_damper.toml", {}, "control"),                         # Ve_d = z + 1: fed back
    ("two_mass.toml", {}, "own"),
])
def test_the_run_is_the_closed_loop_written_out_by_hand(file, point, source):
    pytest.importorskip("control")
    loop = symstab.load_loop(LOOPS / file)
    values = {**{k: v for k, v in loop.defaults.items() if k != "d"}, **point}
    coefficients = (python_control_coefficients if source == "control" else own_coefficients)(
        loop, values)
    delays = np.random.default_rng(5).integers(0, 6, size=90)
    run = loop.simulate(delays=delays, record=True, x0=0.3, v0=0.01, **values)
    expected = closed_loop_by_hand(coefficients, delays, 0.3, 0.01)
    np.testing.assert_allclose(run.positions, expected, rtol=0,
                               atol=1e-12 * np.max(np.abs(expected)))
    # The delay varies: the fixed run at any one of its delays is another trajectory.
    fixed = loop.simulate(d=int(delays[0]), steps=90, record=True, x0=0.3, v0=0.01, **values)
    assert np.max(np.abs(fixed.positions - expected)) > 1e-6 * np.max(np.abs(expected))


def state_space_coefficients(loop, values, eps):
    """``(N_eps, z P_d, Ve_n, Ve_d)``: the plant whose command arrives ``eps T`` late, by hand.

    ``x[k+1] = Phi x[k] + Gamma0 w[k] + Gamma1 w[k-1]`` (tests/oracles.py's
    realisation and exponentials), so ``P = C adj(zI - Phi) (Gamma0 z +
    Gamma1) / (z det(zI - Phi))``, with ``adj(zI - Phi) = sum_k z**(n-1-k)
    B_k``, ``B_0 = I``, ``B_k = Phi B_{k-1} + c_k I`` (``c_k`` the
    characteristic polynomial's: Faddeev-LeVerrier), so that ``C B_k g`` is
    computed from ``C`` and ``g`` themselves, with no difference of
    determinants (which would cost the digits of a small ``C g``).
    """
    plant_num, plant_den, env_num, env_den = loop_coefficients(loop, values)
    A, B, C, _ = _realisation(plant_num, plant_den)
    T = float(values["T"])
    Phi, _ = _held_input_integral(A, B, T)
    late, gamma0 = _held_input_integral(A, B, (1 - eps) * T)
    gamma1 = late @ _held_input_integral(A, B, eps * T)[1]
    char = np.poly(Phi)
    adjugate, term = [], np.eye(len(Phi))
    for c in char[1:]:
        adjugate.append(term)
        term = Phi @ term + c * np.eye(len(Phi))
    n0, n1 = (np.array([(C @ b @ g).item() for b in adjugate]) for g in (gamma0, gamma1))
    numerator = np.concatenate([n0, [0.0]]) + np.concatenate([[0.0], n1])
    return (numerator, np.concatenate([char, [0.0]]), np.asarray(env_num, float),
            np.asarray(env_den, float))


@pytest.mark.parametrize("file, point", [
    ("paper.toml", {"K": 3.0, "B": 0.05, "M": 0.002}),
    ("tustin_damper.toml", {}),
])
def test_a_shared_fraction_is_the_state_space_loop_by_hand(file, point):
    """Delays 0.5 to 5.5 samples (a fixed half sample, whole ones varying): the plant carries
    the half, as a fixed delay's; the run is the loop by hand on the state space's plant."""
    loop = symstab.load_loop(LOOPS / file)
    values = {**{k: v for k, v in loop.defaults.items() if k != "d"}, **point}
    delays = np.random.default_rng(5).integers(0, 6, size=90) + 0.5
    run = loop.simulate(delays=delays, record=True, x0=0.3, v0=0.01, **values)
    expected = closed_loop_by_hand(state_space_coefficients(loop, values, 0.5),
                                   delays.astype(int), 0.3, 0.01)
    np.testing.assert_allclose(run.positions, expected, rtol=0,
                               atol=1e-12 * np.max(np.abs(expected)))
    assert np.array_equal(run.delays, delays)
    law = loop.simulate(delays=("uniform", 0.5, 5.5), steps=90, seed=2, **values)
    assert np.all(law.delays % 1 == 0.5) and law.delays.min() >= 0.5 and law.delays.max() <= 5.5


def test_a_uniform_sequence_is_numpy_s_draw_from_its_seed_the_same_for_every_point(paper):
    run = paper.simulate(delays=("uniform", 3, 6), seed=11, steps=400, K=[1.0, 2.0], B=0.05)
    assert np.array_equal(run.delays, np.random.default_rng(11).integers(3, 7, size=400))
    again = paper.simulate(delays=("uniform", 3, 6), seed=11, steps=400, K=[1.0, 2.0], B=0.05)
    assert np.array_equal(run.amplitude, again.amplitude)
    first = paper.simulate(delays=run.delays, K=1.0, B=0.05)
    assert np.array_equal(first.amplitude, run.amplitude[:, 0])
    # Without steps: the default horizon of the longest delay, 12000 + 800 d_max.
    assert paper.simulate(delays=("uniform", 0, 1), K=1.0, B=0.05).steps == 12800


@pytest.mark.parametrize("kwargs, error, name", [
    ({"delays": [1, 2, -1] * 4}, ValueError, "delays"),
    ({"delays": [1.0, np.nan] * 5}, ValueError, "delays"),
    ({"delays": [1, 2.5] * 5}, ValueError, "delays"),
    ({"delays": [[1, 2]] * 5}, ValueError, "delays"),
    ({"delays": [1, 2] * 5, "steps": 12}, ValueError, "delays"),
    ({"delays": [True] * 10}, TypeError, "delays"),
    ({"delays": "uniform:1:2"}, TypeError, "delays"),
    ({"delays": ("uniform", 5, 2)}, ValueError, "delays"),
    ({"delays": ("normal", 1, 2)}, ValueError, "delays"),
    ({"delays": ("uniform", 1, 2.5)}, ValueError, "delays"),
    ({"delays": [1.5, 2.25] * 5}, ValueError, "delays"),
    ({"delays": ("uniform", 1, 2), "seed": -1}, ValueError, "seed"),
    ({"delays": [1, 2] * 5, "seed": 3}, ValueError, "seed"),
    ({"seed": 3}, ValueError, "seed"),
    ({"delays": [1, 2] * 5, "d": 40.5}, TypeError, "d"),
    ({"delays": [1, 2] * 5, "Td": 0.04}, TypeError, "Td"),
    ({"delays": [1, 2] * 5, "nonideal": Nonidealities(force_resolution=1e-3)}, ValueError,
     "nonideal.force_resolution"),
])
def test_bad_delays_are_refused_naming_the_parameter(paper, kwargs, error, name):
    with pytest.raises(error) as excinfo:
        paper.simulate(K=1.0, B=0.05, **kwargs)
    assert_message_names(excinfo, name)


def test_a_delay_beyond_the_limit_is_refused_naming_it(paper, monkeypatch):
    monkeypatch.setenv("SYMSTAB_MAX_DELAY", "20")
    for delays in ([1, 21] * 5, ("uniform", 1, 21)):
        with pytest.raises(ValueError) as excinfo:
            paper.simulate(delays=delays, K=1.0, B=0.05)
        assert_message_names(excinfo, "delays")
        assert "SYMSTAB_MAX_DELAY" in str(excinfo.value)


def test_the_cli_simulates_a_uniform_delay_and_refuses_bad_ones_in_one_line(capsys, tmp_path):
    out = tmp_path / "x.csv"
    args = ("simulate", "--loop", LOOPS / "paper.toml", "--steps", 400)
    # Whole samples, and whole samples around a fixed half sample (the plant's).
    for low, high in ((2, 5), (2.5, 4.5)):
        status, text, _ = run_cli(capsys, *args, "--delays", f"uniform:{low}:{high}", "--seed",
                                  4, "--out", out)
        assert status == 0 and f"delay uniform on {low}..{high} samples, drawn with seed 4" in text
        run = symstab.load_loop(LOOPS / "paper.toml").simulate(
            delays=("uniform", low, high), seed=4, steps=400, record=True)
        assert np.array_equal(np.loadtxt(out, delimiter=",", skiprows=1)[:, 2], run.positions)
    for bad, named in ((("--delays", "uniform:5:2"), "--delays"), (("--delays", "u:1:2"), "--delays"),
                       (("--delays", "uniform:1.5:2.25"), "--delays"),
                       (("--delays", "uniform:1:x"), "--delays"),
                       (("--seed", 3), "--seed"), (("--delays", "uniform:1:2", "--d", 3), "--delays")):
        status, text, err = run_cli(capsys, *args, *bad)
        assert status == 2 and text == "" and len(err.strip().splitlines()) == 1 and named in err
