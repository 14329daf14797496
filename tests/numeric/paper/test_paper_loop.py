"""PAPER_LOOP: the paper's loop as a Loop, on the same engine as the dimensionless functions.

Oracles: python-control's poles of the sampled loop (c2d of the plant,
the delay as z**-d, eq. (1) as a transfer function in z).
"""

import mpmath
import numpy as np
import pytest

import symstab
from symstab.numeric.paper.paper_loop import paper_loop


def _control_count(K, B, M, d, m=0.0128, b=0.0324, T=1e-3):
    control = pytest.importorskip("control")
    plant = control.c2d(control.tf([1.0], [m, b, 0.0]), T, "zoh")
    z = control.tf([1.0, 0.0], [1.0], T)
    env = K + B * (z - 1) / (T * z) + M * (z - 1) ** 2 / (T**2 * z**2)
    delay = control.tf([1.0], [1.0] + [0.0] * d, T)
    return int(np.sum(np.abs(control.poles(control.feedback(plant * delay * env, 1))) > 1))


def test_paper_loop_is_a_loop_of_the_paper_device():
    loop = symstab.PAPER_LOOP
    assert isinstance(loop, symstab.Loop)
    assert loop is paper_loop()
    assert loop.plane == ("B", "K")
    device = symstab.PAPER_DEVICE
    assert (loop.defaults["m"], loop.defaults["b"], loop.defaults["T"]) == (device.m, device.b, device.T)
    assert loop.units["K"] == device.units(rotary=True)["K_w"]
    assert "PAPER_LOOP" in symstab.__all__


@pytest.mark.parametrize("d, K, B, M", [(0, 300.0, 0.5, 0.0), (5, 40.0, 0.05, 0.002),
                                        (40, 3.0, 0.01, 0.0), (40, 6.0, 0.01, 0.0),
                                        (40, 2.0, 0.1, 0.001)])
def test_counts_match_python_control_and_the_dimensionless_path(d, K, B, M):
    expected = _control_count(K, B, M, d)
    loop = symstab.PAPER_LOOP
    assert loop.unstable_root_counts(K=K, B=B, M=M, d=d) == expected
    device = symstab.PAPER_DEVICE
    dimensionless = symstab.numeric.paper.stability.unstable_root_counts(
        alpha=device.alpha(K), beta=device.beta(B), gamma=device.gamma(M), d=d, delta=device.delta)
    assert dimensionless == expected
    assert loop.classify(K=K, B=B, M=M, d=d) == (symstab.STABLE if expected == 0 else symstab.UNSTABLE)


def test_spectral_radius_matches_50_digit_roots_of_the_symbolic_polynomial():
    """python-control's poles are off by 1.4e-8 here (degree 44); the oracle is mpmath at 50 digits
    on the coefficients of the symbolic characteristic polynomial evaluated at 30 digits."""
    from oracles import coefficients_at

    device = symstab.PAPER_DEVICE
    for d, K, B in [(40, 3.0, 0.01), (3, 100.0, 0.2)]:
        c = coefficients_at(alpha=device.alpha(K), beta=device.beta(B), gamma=0.0, d=d,
                            delta=device.delta)
        with mpmath.workdps(50):
            expected = max(abs(r) for r in mpmath.polyroots([mpmath.mpf(x) for x in c],
                                                            maxsteps=500, extraprec=500))
        got = symstab.PAPER_LOOP.spectral_radius(K=K, B=B, d=d)
        assert abs(got - float(expected)) < 1e-12


def _exact_count(K, B, d):
    """Roots outside at 50 digits of the symbolic polynomial evaluated at 30 digits (an oracle
    independent of the kernels and of the root engine)."""
    from oracles import coefficients_at

    device = symstab.PAPER_DEVICE
    c = coefficients_at(alpha=device.alpha(K), beta=device.beta(B), gamma=0.0, d=d, delta=device.delta)
    with mpmath.workdps(50):
        roots = mpmath.polyroots([mpmath.mpf(x) for x in c], maxsteps=500, extraprec=500)
    return sum(1 for r in roots if abs(r) > 1)


def test_k_max_sits_between_a_stable_and_an_unstable_point():
    """python-control's poles are not accurate enough here (at K_max (1 - 1e-3) its degree-44
    closed loop shows two poles outside, with the radius 1e-5 inside): 50-digit roots instead."""
    limits = symstab.PAPER_LOOP.limits(d=40)
    K, B = limits.y_max, limits.x_at_y_max
    assert _exact_count(K * (1 - 1e-6), B, 40) == 0
    assert _exact_count(K * (1 + 1e-6), B, 40) > 0


@pytest.mark.parametrize("delta", [1e-6, 1e-10, 1e-14, 1e-18, 1e-300])
def test_coefficients_at_a_tiny_damping_match_the_first_principles_polynomial(delta):
    """The plant's closed form cancels 2 log10(1 / delta) digits (its (exp(-delta) - 1 + delta) /
    delta**2): at 30 fixed digits delta = 1e-14 gave P_n = (0.49895, 0.50093), not (0.5, 0.5),
    and limits 2.5e-3 off.  Oracle: eqs. (1), (2), (4) at 60 digits (tests/oracles.py)."""
    from symstab.numeric.paper.paper_loop import paper_point

    from oracles import first_principles_chi

    loop, values = paper_point(gamma=0.3, d=2, delta=delta)
    got = loop.coefficients(K=0.4, B=0.7, **values)
    with mpmath.workdps(60):
        expected = np.array([float(c) for c in first_principles_chi(0.4, 0.7, 0.3, 2, delta)])
    assert np.max(np.abs(got - expected)) <= 4e-16 * np.max(np.abs(expected)), (got, expected)


@pytest.mark.parametrize("delta", [1e-6, 1e-14, 1e-30, 1e-100])
def test_the_pole_next_to_z_1_keeps_its_digits_in_powers_of_z_minus_1(delta):
    """P_d(w + 1) = w (w + 1 - exp(-delta)) at m = T = 1: its middle coefficient is 1 - exp(-delta),
    the pole's distance from z = 1 that the root count needs.  Shifted at a fixed 30 digits it was
    1.4e-2 off at delta = 1e-30 and 0 (a double pole at z = 1) from 1e-35 on.  Oracle: mpmath's
    expm1."""
    from symstab.numeric.paper.paper_loop import paper_point

    loop, _ = paper_point(gamma=0.0, d=0, delta=delta)
    names = dict(b=delta, m=1.0)
    near_one = loop._plant_cache(tuple(names[n] for n in loop.plant_names), 1.0)[3]
    assert near_one[0] == 1.0
    assert near_one[1] == pytest.approx(float(-mpmath.expm1(-mpmath.mpf(delta))), rel=1e-15, abs=0)


def test_counts_are_eq_5s_closed_form_and_refuse_out_of_range_values_in_table_one_names():
    # PAPER_LOOP counts the roots of eq. (5)'s kernel (Loop(polynomial=...)):
    # a value beyond Table I's ranges is refused naming both systems.
    with pytest.raises(ValueError, match=r"alpha must be .*alpha = K T\^2/m"):
        symstab.PAPER_LOOP.classify(K=1e300, B=0.1, d=0)
    with pytest.raises(TypeError, match="polynomial must be callable"):
        symstab.Loop("1/(m*s**2 + b*s)", "K", polynomial=3.0)


def test_a_pickled_paper_loop_keeps_its_closed_form():
    import pickle

    again = pickle.loads(pickle.dumps(symstab.PAPER_LOOP))
    with pytest.raises(ValueError, match=r"alpha = K T\^2/m"):
        again.classify(K=1e300, B=0.1, d=0)
    assert int(again.unstable_root_counts(K=6.0, B=0.01, d=40)) == _control_count(6.0, 0.01, 0.0, 40)
