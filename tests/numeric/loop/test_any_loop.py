"""symstab.Loop: the general loop against python-control, mpmath and the paper's path.

The example loop files have their own tests (test_any_loop_examples.py);
here: the derivation (ZOH by residues and by the matrix exponential), the
paper's loop through the general path against today's numbers, the generic
polynomial classification, the kernel cache, and the refusals.
"""

import os
import warnings

import mpmath
import numpy as np
import pytest
import sympy as sp

import symstab
from symstab.numeric.engine.polynomial import DelayedPolynomial
from symstab.numeric.engine.roots import (
    MARGINAL,
    STABLE,
    UNSTABLE,
    classify_polynomials,
    root_counts,
    spectral_radius,
)
from symstab.numeric.loop.sampled_loop import Loop
from symstab.symbolic import model
from symstab.symbolic.discretize import numeric_zoh, zoh_pulse_transfer_function

from conftest import PAPER_B, PAPER_M, PAPER_T, REPO, assert_rel_close
from oracles import polyroots, python_control_closed_loop

control = pytest.importorskip("control")

PLANT = "1/(m*s**2 + b*s)"
ENVIRONMENT = "K + B*(z - 1)/(T*z) + M*(z - 1)**2/(T**2*z**2)"
DEVICE = dict(m=PAPER_M, b=PAPER_B, T=PAPER_T)


@pytest.fixture(scope="module")
def paper_loop():
    return Loop(PLANT, ENVIRONMENT)


def _physical(alpha, beta, gamma):
    return dict(K=alpha * PAPER_M / PAPER_T**2, B=beta * PAPER_M / PAPER_T, M=gamma * PAPER_M)


# -- the derivation ---------------------------------------------------------

def test_parameters_and_method(paper_loop):
    assert paper_loop.parameters == ("B", "K", "M", "b", "m", "T", "d")
    assert paper_loop.zoh_method == "residues"
    assert paper_loop.affine_parameters() == ("B", "K", "M")


def test_characteristic_polynomial_keeps_d_symbolic(paper_loop):
    chi = paper_loop.characteristic_polynomial()
    assert model.d in chi.free_symbols
    # At a concrete point its roots are python-control's closed-loop poles.
    alpha, beta, gamma, d = 0.01, 0.2, 0.5, 3
    values = dict(_physical(alpha, beta, gamma), **DEVICE, d=d)
    poly = sp.Poly(paper_loop.characteristic_polynomial(**values), model.z)
    ours = np.sort_complex(np.roots([float(c) for c in poly.all_coeffs()]))
    oracle = python_control_closed_loop(alpha=alpha, beta=beta, gamma=gamma, d=d,
                                        delta=PAPER_B * PAPER_T / PAPER_M, m=PAPER_M, T=PAPER_T)
    # VE(z) over its denominator T^2 z^2 (oracles.eq1_virtual_environment_tf):
    # the closed loop's poles are chi's d + 4 roots, none added at 0.
    theirs = np.sort_complex(oracle.poles())
    assert len(ours) == len(theirs) == d + 4
    np.testing.assert_allclose(ours, theirs, atol=1e-7)


def test_frictionless_mass_by_residues():
    """b = 0: G/s has a triple pole at 0; the textbook double-integrator ZOH is T^2 (z+1) / (2 m (z-1)^2)."""
    m, T, z = sp.Symbol("m", positive=True), model.T, model.z
    P = zoh_pulse_transfer_function(1 / (m * model.s**2))
    assert sp.simplify(P - T**2 * (z + 1) / (2 * m * (z - 1) ** 2)) == 0
    loop = Loop("1/(m*s**2)", ENVIRONMENT)
    assert loop.zoh_method == "residues"
    rng = np.random.default_rng(5)
    for _ in range(20):
        K, B, M = rng.uniform(0, 40), rng.uniform(0, 0.3), rng.uniform(-0.005, 0.02)
        d = int(rng.integers(0, 6))
        r = loop.spectral_radius(K=K, B=B, M=M, m=PAPER_M, T=PAPER_T, d=d)
        G = control.sample_system(control.tf([1], [PAPER_M, 0, 0]), PAPER_T, "zoh")
        zz = control.tf([1, 0], [1], PAPER_T)
        VE = K + B * (zz - 1) / (PAPER_T * zz) + M * (zz - 1) ** 2 / (PAPER_T**2 * zz**2)
        delay = control.tf([1], [1] + [0] * d, PAPER_T)
        oracle = max(abs(control.feedback(G, VE * delay).poles()))
        assert r == pytest.approx(oracle, rel=1e-7, abs=1e-7)


def test_a_parameter_at_zero_that_the_closed_form_divides_by_is_its_limit():
    """b = 0 in 1/(m s**2 + b s): the closed form is 0/0 there; the loop takes the limit.

    It was refused ("not defined at b = 0"), while a robust box holding
    b = 0 inside it was certified; a box ending at 0 could not be asked for.
    """
    from symstab import load_loop

    loop = load_loop(str(REPO / "examples" / "loops" / "paper.toml"))
    G = control.sample_system(control.tf([1], [PAPER_M, 0, 0]), PAPER_T, "zoh")
    zz = control.tf([1, 0], [1], PAPER_T)
    rng = np.random.default_rng(11)
    for _ in range(8):
        K, B, M, d = rng.uniform(0, 60), rng.uniform(0, 1.5), rng.uniform(-0.005, 0.02), 10
        r = loop.spectral_radius(K=K, B=B, M=M, b=0.0, m=PAPER_M, T=PAPER_T, d=d)
        VE = K + B * (zz - 1) / (PAPER_T * zz) + M * (zz - 1) ** 2 / (PAPER_T**2 * zz**2)
        delay = control.tf([1], [1] + [0] * d, PAPER_T)
        oracle = max(abs(control.feedback(G, VE * delay).poles()))
        assert r == pytest.approx(oracle, rel=1e-7, abs=1e-7)
    robust = loop.robust_region("B", "K", uncertain={"b": (0.0, 0.0324)}, strips=8, d=10, M=0.0,
                                m=PAPER_M, T=PAPER_T)
    assert robust.area > 0


def test_a_grid_through_the_limit_and_a_plant_written_with_a_common_factor():
    """From a review: a grid over b through 0 mixed the realisation's padded P_n with the
    closed form's (a ragged array), and the limit was taken of the plant as written, so
    (s + 10)/(s + 10) let m = 0 through as another plant and refused b = 0."""
    G = control.sample_system(control.tf([1], [PAPER_M, 0, 0]), PAPER_T, "zoh")
    zz = control.tf([1, 0], [1], PAPER_T)
    VE = 30.0 + 0.4 * (zz - 1) / (PAPER_T * zz)
    oracle = max(abs(control.feedback(G, VE * control.tf([1], [1, 0, 0, 0], PAPER_T)).poles()))
    for plant in ("1/(m*s**2 + b*s)", "(s + 10)/(m*s**3 + (b + 10*m)*s**2 + 10*b*s)"):
        loop = Loop(plant, ENVIRONMENT)
        radii = loop.spectral_radius(K=30.0, B=0.4, M=0.0, b=np.array([0.0, 0.0324]),
                                     m=PAPER_M, T=PAPER_T, d=3)
        assert radii[0] == pytest.approx(oracle, rel=1e-7), plant
        with pytest.raises(ValueError, match="order drops"):
            loop.spectral_radius(K=30.0, B=0.4, M=0.0, b=0.0324, m=0.0, T=PAPER_T, d=3)


def test_numeric_zoh_matches_python_control():
    """The matrix-exponential path against scipy's (through python-control)."""
    num, den, T = [2.0, 3.0, 50.0], [0.01, 0.3, 40.0, 100.0, 0.0], 1e-3
    p_n, p_d = numeric_zoh(num, den, T)
    oracle = control.sample_system(control.tf(num, den), T, "zoh")
    o_num, o_den = np.array(oracle.num[0][0]), np.array(oracle.den[0][0])
    ours_num = np.array([float(c) for c in p_n])
    ours_num = ours_num[np.argmax(ours_num != 0):]
    np.testing.assert_allclose([float(c) for c in p_d], o_den / o_den[0], rtol=1e-9)
    np.testing.assert_allclose(ours_num, o_num / o_den[0], rtol=1e-7)


def _python_control_radius(den, K, B, d):
    """Spectral radius of the loop with G = 1 / den(s) and VE = K + B (z - 1) / (T z), by python-control."""
    G = control.sample_system(control.tf([1], den), PAPER_T, "zoh")
    zz = control.tf([1, 0], [1], PAPER_T)
    VE = K + B * (zz - 1) / (PAPER_T * zz)
    delay = control.tf([1], [1] + [0] * d, PAPER_T)
    return max(abs(control.feedback(G, VE * delay).poles()))


@pytest.mark.parametrize("k_h", [100.0, 0.5])     # underdamped (a complex pair), overdamped
def test_a_quadratic_factor_by_residues(k_h):
    """An operator's arm (mass-spring-damper to ground): poles written with a square root."""
    loop = Loop("1/((m + m_h)*s**2 + (b + b_h)*s + k_h)", "K + B*(z - 1)/(T*z)")
    assert loop.zoh_method == "residues"
    assert any(not p.exp.is_integer for p in loop.pulse_transfer_function().atoms(sp.Pow))
    values = dict(m=PAPER_M, m_h=0.05, b=PAPER_B, b_h=1.0, k_h=k_h, T=PAPER_T)
    for K, B, d in ((300.0, 0.5, 0), (2000.0, 2.0, 2), (50.0, 0.1, 10)):
        oracle = _python_control_radius([PAPER_M + 0.05, PAPER_B + 1.0, k_h], K, B, d)
        assert loop.spectral_radius(K=K, B=B, d=d, **values) == pytest.approx(oracle, rel=1e-8)


@pytest.mark.parametrize("plant, den", [
    ("1/(m*s**2 + 0.25*b*s)", [PAPER_M, 0.25 * PAPER_B, 0]),
    ("1/((0.5*tau*s + 1)*(m*s**2 + b*s))", np.polymul([0.5 * 0.01, 1], [PAPER_M, PAPER_B, 0])),
    ("1/(m*s**2 + 0.1*b*s)", [PAPER_M, 0.1 * PAPER_B, 0]),
])
def test_a_decimal_in_the_plant_is_its_exact_rational(plant, den):
    """issue 40 item 13: a decimal in the denominator crashed SymPy's factoring (PolyElement * PolyElement)."""
    loop = Loop(plant, "K + B*(z - 1)/(T*z)")
    decimals = {str(c) for c in loop.plant.atoms(sp.Rational) if not c.is_Integer}
    assert decimals <= {"1/4", "1/2", "1/10"} and decimals and not loop.plant.atoms(sp.Float)
    values = dict(m=PAPER_M, b=PAPER_B, T=PAPER_T, tau=0.01)
    values = {k: v for k, v in values.items() if k in loop.parameters}
    for K, B, d in ((300.0, 0.5, 0), (50.0, 0.1, 3)):
        oracle = _python_control_radius(list(den), K, B, d)
        assert loop.spectral_radius(K=K, B=B, d=d, **values) == pytest.approx(oracle, rel=1e-8)


@pytest.mark.parametrize("plant, values, rhp, negative", [
    ("1/(m*s**2 + b*s)", dict(m=-0.2, b=PAPER_B), True, True),        # issue 40 item 8
    ("1/(m*s**2 + b*s)", dict(m=PAPER_M, b=-0.5), True, False),       # negative friction
    ("1/((m + m_h)*s**2 + (b + b_h)*s + k_h)", dict(m=PAPER_M, m_h=0.05, b=PAPER_B, b_h=-1.0,
                                                    k_h=100.0), True, False),  # a growing pair
    ("-1/(m*s**2 + b*s)", dict(m=PAPER_M, b=PAPER_B), False, True),   # positive feedback
])
def test_a_plant_that_is_not_a_physical_devices_warns_naming_its_values(plant, values, rhp,
                                                                        negative):
    """Poles and gain against python-control: a warning exactly when one is in the open RHP
    or the high-frequency gain is negative, naming the plant's values; none for the device."""
    from symstab import NonPhysicalPlantWarning

    loop = Loop(plant, "K + B*(z - 1)/(T*z)")
    s = sp.Symbol("s")
    num, den = sp.fraction(sp.together(sp.sympify(plant, locals={"s": s}).subs(values)))
    G = control.tf([float(c) for c in sp.Poly(num, s).all_coeffs()],
                   [float(c) for c in sp.Poly(den, s).all_coeffs()])
    assert (max(G.poles().real) > 1e-9) == rhp
    assert (G.num[0][0][0] * G.den[0][0][0] < 0) == negative
    given = ", ".join(f"{n} = {values[n]:g}" for n in sorted(values))
    with pytest.warns(NonPhysicalPlantWarning) as record:
        loop.classify(K=1.0, B=0.1, T=PAPER_T, d=1, **values)
    (warning,) = record
    text = str(warning.message)
    assert f"at {given} has " in text and "\n" not in text
    assert ("open right half plane" in text) == rhp
    assert ("negative high-frequency gain" in text) == negative
    physical = {**values, **{k: abs(v) for k, v in values.items()}}
    with warnings.catch_warnings():
        warnings.simplefilter("error", NonPhysicalPlantWarning)
        Loop(plant.lstrip("-"), "K + B*(z - 1)/(T*z)").classify(K=1.0, B=0.1, T=PAPER_T, d=1,
                                                                 **physical)


def test_a_loop_built_again_warns_again_though_it_shares_the_plant_s_numbers():
    """The models of one loop share its derivation and its plant at numbers (computed once
    per process); the warning of a non-physical plant is each model's, not computed once."""
    from symstab import NonPhysicalPlantWarning

    point = dict(K=1.0, B=0.1, T=PAPER_T, d=1, m=-0.2, b=PAPER_B)
    for _ in range(2):
        with pytest.warns(NonPhysicalPlantWarning, match="m = -0.2"):
            Loop("1/(m*s**2 + b*s)", "K + B*(z - 1)/(T*z)").classify(**point)


@pytest.mark.parametrize("name", ["e", "exp"])
def test_a_parameter_named_like_an_mpmath_name_keeps_its_value(name):
    """``e`` once shadowed Euler's number in the plant's mpmath function (K_max of a gain-49 plant for 7 e)."""
    loop = Loop(f"exp(1)*{name}/(m*s**2 + b*s)", "K + B*(z - 1)/(T*z)")
    values = dict(m=PAPER_M, b=PAPER_B, T=PAPER_T, **{name: 7.0})
    for K, B, d in ((0.5, 0.01, 0), (3.0, 0.02, 2), (0.2, 0.005, 10)):
        oracle = _python_control_radius([PAPER_M / (7 * np.e), PAPER_B / (7 * np.e), 0], K, B, d)
        assert loop.spectral_radius(K=K, B=B, d=d, **values) == pytest.approx(oracle, rel=1e-8)


def test_the_sample_period_in_the_plant():
    """``T`` in the plant (a lag of one sample period) was an argument twice: a SyntaxError."""
    loop = Loop("1/(m*s*(T*s + 1))", "K + B*(z - 1)/(T*z)")
    for K, B, d in ((30.0, 0.5, 0), (200.0, 2.0, 2), (5.0, 0.1, 10)):
        oracle = _python_control_radius([PAPER_M * PAPER_T, PAPER_M, 0], K, B, d)
        assert loop.spectral_radius(K=K, B=B, d=d, m=PAPER_M, T=PAPER_T) == \
            pytest.approx(oracle, rel=1e-8)


def test_numeric_path_for_a_cubic_factor():
    """An irreducible cubic is left to the matrix exponential, and says so."""
    loop = Loop("1/(m*s**3 + b*s**2 + k*s + c)", "K + B*(z - 1)/(T*z)")
    assert loop.zoh_method == "matrix exponential"
    with pytest.raises(ValueError, match="numerically"):
        loop.pulse_transfer_function()
    values = dict(m=PAPER_M, b=PAPER_B, k=50.0, c=10.0, T=PAPER_T)
    for K, B, d in ((30.0, 0.5, 0), (200.0, 2.0, 2), (5.0, 0.1, 10)):
        oracle = _python_control_radius([PAPER_M, PAPER_B, 50.0, 10.0], K, B, d)
        assert loop.spectral_radius(K=K, B=B, d=d, **values) == pytest.approx(oracle, rel=1e-8)


def test_control_transfer_function_as_plant():
    G = control.tf([1], [PAPER_M, PAPER_B, 0])
    loop = Loop(G, "K + B*(z - 1)/(T*z)")
    assert loop.zoh_method == "matrix exponential"
    ours = Loop(PLANT, "K + B*(z - 1)/(T*z)")
    for K, B, d in ((300.0, 0.5, 0), (3.0, 0.1, 40)):
        assert loop.spectral_radius(K=K, B=B, T=PAPER_T, d=d) == pytest.approx(
            ours.spectral_radius(K=K, B=B, d=d, **DEVICE), rel=1e-10)


# -- the paper's loop through the general path --------------------------------

def test_paper_loop_spectral_radius_and_classification_match_today(paper_loop):
    rng = np.random.default_rng(11)
    alpha, beta = rng.uniform(-0.001, 0.02, 2000), rng.uniform(-0.01, 0.4, 2000)
    delta = PAPER_B * PAPER_T / PAPER_M
    for gamma, d in ((0.0, 0), (0.5, 4), (1.0, 10)):
        values = dict(_physical(alpha, beta, gamma), **DEVICE, d=d)
        ours = paper_loop.classify(**values)
        today = symstab.classify(alpha=alpha, beta=beta, gamma=gamma, d=d, delta=delta)
        r = symstab.spectral_radius(alpha=alpha, beta=beta, gamma=gamma, d=d, delta=delta)
        both = (ours != MARGINAL) & (today != MARGINAL) & (np.abs(r - 1) > 1e-9)
        assert np.array_equal(ours[both], today[both])
        assert np.mean(ours == STABLE) > 0.05 and np.mean(ours == UNSTABLE) > 0.05
        np.testing.assert_allclose(paper_loop.spectral_radius(**values), r, rtol=1e-9)


@pytest.mark.parametrize("d, gamma", [(40, 0.0), (10, 1.0), (0, 0.5)])
def test_paper_loop_limits_match_today(paper_loop, d, gamma):
    """K_max at T_d = 40 ms and the rest of Limits, through the general path."""
    delta = PAPER_B * PAPER_T / PAPER_M
    today = symstab.limits(gamma=gamma, d=d, delta=delta)
    ours = paper_loop.limits("B", "K", M=gamma * PAPER_M, d=d, **DEVICE)
    assert_rel_close(ours.y_max, today.alpha_max * PAPER_M / PAPER_T**2, 1e-7, "K_max")
    assert_rel_close(ours.x_at_y_max, today.beta_at_alpha_max * PAPER_M / PAPER_T, 1e-3,
                     "B at K_max")
    assert_rel_close(ours.x_max, today.beta_right * PAPER_M / PAPER_T, 1e-7, "B_max")
    # The left edge B = -b is a corner where two roots meet at z = 1: the
    # general polynomial resolves it to about 1e-4 (the paper's kernel
    # factors (z - 1)(z - r) and does better).
    assert_rel_close(ours.x_min, today.beta_left * PAPER_M / PAPER_T, 1e-4, "B_min")
    assert_rel_close(ours.area, today.z_width * PAPER_M**2 / PAPER_T**3, 1e-3, "area")


def test_paper_loop_stable_intervals_against_python_control(paper_loop):
    """Endpoints of the stable K interval agree with a bisection on python-control's loop.

    python-control builds the closed loop; its poles come from eigenvalues,
    which at d = 40 miss the modulus by 1e-5, so the roots of its
    denominator are found by mpmath at 40 digits instead.
    """
    delta = PAPER_B * PAPER_T / PAPER_M

    def stable(K, B, d):
        cl = python_control_closed_loop(alpha=K * PAPER_T**2 / PAPER_M, beta=B * PAPER_T / PAPER_M,
                                        gamma=0.0, d=d, delta=delta, m=PAPER_M, T=PAPER_T)
        den = np.trim_zeros(np.asarray(cl.den[0][0], dtype=float), "b")   # drop the pole at 0
        with mpmath.workdps(40):
            roots = polyroots([mpmath.mpf(float(c)) for c in den], maxsteps=400, extraprec=400)
            return max(abs(r) for r in roots) < 1

    for B, d in ((0.3, 40), (1.0, 10), (5.0, 0)):
        (lo, hi), = paper_loop.stable_intervals("K", B=B, M=0.0, d=d, **DEVICE)
        assert lo == 0.0
        assert stable(0.5 * hi, B, d) and not stable(2 * hi, B, d)
        # The end to 1e-6: python-control's loop changes verdict between hi (1 -+ 1e-6),
        # what fifty bisection steps from (hi / 2, 2 hi) proved at fifty times the cost.
        assert stable(hi * (1 - 1e-6), B, d) and not stable(hi * (1 + 1e-6), B, d)


def test_boundary_points_put_a_root_on_the_circle(paper_loop):
    curve = paper_loop.boundary("B", "K", n=50, M=0.0, d=5, **DEVICE)
    assert set(curve.lines) == {"z = 1", "z = -1"}
    for theta, B, K in list(zip(curve.theta, curve.x_values, curve.y_values, strict=True))[::7]:
        coefficients = paper_loop.coefficients(K=K, B=B, M=0.0, d=5, **DEVICE)
        roots = np.roots(coefficients)
        target = np.exp(1j * theta)
        assert np.min(np.abs(roots - target)) < 1e-6
    c0, cx, cy = curve.lines["z = 1"]
    assert c0 == 0.0 and cx == 0.0 and cy > 0     # the line K = 0


def test_closed_loop_poles_are_the_characteristic_roots(paper_loop):
    values = dict(K=300.0, B=0.5, M=0.002, d=3, **DEVICE)
    cl = paper_loop.closed_loop(**values)
    assert cl.dt == PAPER_T
    oracle = python_control_closed_loop(alpha=300.0 * PAPER_T**2 / PAPER_M, beta=0.5 * PAPER_T / PAPER_M,
                                        gamma=0.002 / PAPER_M, d=3, delta=PAPER_B * PAPER_T / PAPER_M,
                                        m=PAPER_M, T=PAPER_T)
    theirs = oracle.poles()
    np.testing.assert_allclose(np.sort_complex(cl.poles()), np.sort_complex(theirs), atol=1e-8)


# -- generic polynomials --------------------------------------------------------

def _mp_outside(coefficients):
    """Roots outside the circle, the smallest | |z| - 1 | and the largest |z|, at 40 digits."""
    with mpmath.workdps(40):
        roots = polyroots([mpmath.mpf(float(c)) for c in coefficients], maxsteps=200,
                          extraprec=200)
        return (sum(1 for r in roots if abs(r) > 1), min(abs(abs(r) - 1) for r in roots),
                max(abs(r) for r in roots))


def test_dense_root_counts_against_mpmath():
    """Never a wrong count; marginal only where the coefficients cannot decide.

    Degree 40 from random roots has coefficients up to 1e10 times its values
    on the circle, and some of those are rightly left marginal.
    """
    rng = np.random.default_rng(3)
    checked, marginal = 0, 0
    for degree in (1, 2, 5, 9, 20):
        for _ in range(15):
            roots = rng.uniform(0.3, 1.6, degree) * np.exp(1j * rng.uniform(0, np.pi, degree))
            c = np.real(np.poly(np.concatenate([roots, np.conj(roots)])))
            outside, gap, exact = _mp_outside(c)
            if gap < 1e-9:
                continue
            count = root_counts(DelayedPolynomial.from_dense(c[None, :]))[0]
            code = classify_polynomials(c)
            expected = STABLE if outside == 0 else UNSTABLE
            if count == -1:
                # Schur-Cohn may still decide it with a safe margin.
                assert degree == 20 and code in (MARGINAL, expected)
                marginal += 1
                continue
            assert count == outside
            assert code == expected
            r = spectral_radius(DelayedPolynomial.from_dense(c[None, :]))[0]
            assert r == pytest.approx(float(exact), rel=1e-8)
            checked += 1
    assert checked > 50 and marginal <= 5


def test_a_root_on_the_circle_is_marginal():
    c = np.real(np.poly([np.exp(0.7j), np.exp(-0.7j), 0.5]))
    assert root_counts(DelayedPolynomial.from_dense(c[None, :]))[0] == -1
    assert classify_polynomials(c) == MARGINAL
    # A vanishing leading coefficient is a root at infinity: marginal too.
    assert classify_polynomials([0.0, 1.0, 0.2]) == MARGINAL


# -- kernels on disk -------------------------------------------------------------

def test_kernels_are_cached_by_the_hash_of_their_expressions(tmp_path, monkeypatch):
    monkeypatch.setenv("SYMSTAB_CACHE_DIR", str(tmp_path / "k"))
    first = Loop(PLANT, "K + B*(z - 1)/(T*z) + 0.5*M*(z - 1)**2/(T**2*z**2)")
    r1 = first.spectral_radius(K=300.0, B=0.5, M=0.001, d=2, **DEVICE)
    path = first.kernel_file()
    assert path and os.path.dirname(path) == str(tmp_path / "k" / "loops")
    text = open(path, encoding="utf-8").read()
    assert "do not edit" in text and "import numpy" in text
    again = Loop(PLANT, "K + B*(z - 1)/(T*z) + 0.5*M*(z - 1)**2/(T**2*z**2)")
    again.spectral_radius(K=300.0, B=0.5, M=0.001, d=2, **DEVICE)
    assert again.kernel_file() == path
    other = Loop(PLANT, "K + B*(z - 1)/(T*z) + 0.25*M*(z - 1)**2/(T**2*z**2)")
    r2 = other.spectral_radius(K=300.0, B=0.5, M=0.002, d=2, **DEVICE)
    assert other.kernel_file() != path
    assert r1 == pytest.approx(r2, rel=1e-12)     # 0.5 * 0.001 == 0.25 * 0.002


def test_unwritable_cache_compiles_in_memory(tmp_path, monkeypatch):
    blocker = tmp_path / "file"
    blocker.write_text("not a folder")
    monkeypatch.setenv("SYMSTAB_CACHE_DIR", str(blocker))
    loop = Loop(PLANT, "K + B*(z - 1)/(T*z) + 0.125*M*(z - 1)**2/(T**2*z**2)")
    assert loop.classify(K=300.0, B=0.5, M=0.0, d=0, **DEVICE) == STABLE
    assert loop.kernel_file() is None


# -- refusals --------------------------------------------------------------------

@pytest.mark.parametrize("plant, environment, match", [
    ("s/(m*s + b)*s", ENVIRONMENT, "proper"),
    ("exp(-s*tau)/(m*s**2)", ENVIRONMENT, "rational"),
    (PLANT, "K*z**2/(z - 1)", "proper"),
    (PLANT, "K*z**(-d)", "delay d"),
    ("1/(m*s**2 + b*s*z)", ENVIRONMENT, "must not contain z"),
    (PLANT, "K + B*s", "must not contain s"),
    ("0", ENVIRONMENT, "zero"),
    # Zero only once exp's rules are applied (a quick value at a point cannot say so).
    (PLANT, "exp(K)*exp(B) - exp(K + B)", "zero"),
    (PLANT, "K - K*(z - 1)/(z - 1)", "zero"),
    (PLANT, "K +* B", "not a valid expression"),
    # Only arithmetic is parsed: no attribute, subscript, call or conditional.
    ("1/(m*s**2) + 0*exp.eval.__globals__['__builtins__']", ENVIRONMENT, "not allowed"),
    ("1/(m*s**2) if True else 0", ENVIRONMENT, "not allowed"),
    ("__import__('os')", ENVIRONMENT, "not allowed"),
    (PLANT, "sin(z)", "not allowed"),
    # Sizes SymPy would take forever on are refused before any algebra.
    ("1/s**1000", ENVIRONMENT, "above the limit 100"),
    (PLANT, "K*2**(10**10)", "power inside an exponent"),
    # Exponents past the limit by a product or by powers of powers: hours of algebra.
    ("(s + 1)**(100*100)/(m*s**2 + b*s)", ENVIRONMENT, "exponent 10000 is above the limit"),
    (PLANT, "K + B*(((z - 1)/z)**100)**100", "exponent 10000 is above the limit"),
    ("exp(exp(exp(exp(exp(exp(0))))))/(m*s**2 + b*s)", ENVIRONMENT, "exp\\(\\) inside exp"),
    # A RecursionError traceback: chains as deep as they are long.
    ("1+" * 5000 + PLANT, ENVIRONMENT, "above the limit of 2000"),
    ("-" * 1900 + PLANT, ENVIRONMENT, "nested too deeply"),
    ("1+" * 980 + PLANT, ENVIRONMENT, "nested too deeply"),
    # Names that Loop's methods take as arguments.
    (PLANT, "K + x_range", "argument of Loop's methods"),
    (PLANT, "K + x*B", "argument of Loop's methods"),
])

def test_bad_loops_are_refused(plant, environment, match):
    with pytest.raises(ValueError, match=match):
        Loop(plant, environment)


def test_a_loop_string_cannot_run_code(tmp_path):
    """The parser builds SymPy objects from the syntax tree: nothing is evaluated."""
    marker = tmp_path / "ran"
    attack = (f"1/(m*s**2) + 0*exp.eval.__globals__['__builtins__']['__import__']('os')"
              f".system('touch {marker}')")
    with pytest.raises(ValueError, match="not allowed"):
        Loop(attack, "K")
    assert not marker.exists()


def test_values_beyond_double_precision_are_an_error_not_an_empty_set(paper_loop):
    # At T = 1e-30 the plant's closed form cancels 60 digits (it was refused at 30 fixed
    # digits); with the digits it needs, K_max is the dimensionless alpha_max times m / T**2.
    found = paper_loop.limits("B", "K", M=0.0, m=PAPER_M, b=PAPER_B, T=1e-30, d=0)
    reference = symstab.limits(gamma=0.0, d=0, delta=PAPER_B * 1e-30 / PAPER_M)
    assert found.y_max == pytest.approx(reference.alpha_max * PAPER_M / 1e-60, rel=1e-12)
    assert found.area == pytest.approx(reference.z_width * PAPER_M**2 / 1e-90, rel=1e-9)
    with pytest.raises(ValueError, match="overflows or underflows"):
        paper_loop.stable_intervals("K", B=0.1, M=0.0, m=PAPER_M, b=PAPER_B, T=1e-300, d=0)
    with pytest.raises(ValueError, match="overflows or underflows"):
        paper_loop.stable_intervals("K", B=0.1, M=0.0, m=PAPER_M, b=PAPER_B, T=1e300, d=0)



def test_huge_values_of_a_benign_plant_need_no_extra_digits(paper_loop):
    """m = b = 1e100 is b T / m = T: K_max scales with m exactly (eq. (4): alpha = K T**2 / m).

    The plant's working digits used to start from the decades of the values
    (at m = b = 1e300: 2400 digits, then 4800, 12 s per plant); they start
    from the poles' |p T| now (30 digits here).  The scaled limits must be
    those at m = b = 1 to rounding.
    """
    from symstab.numeric.loop.sampled_loop import Loop

    loop = Loop(paper_loop.plant, paper_loop.environment, plane=("B", "K"))
    assert loop._cancelled_decades((1e300, 1e300), 1e-3) in (3, 4)      # |p T| = 1e-3
    assert loop._cancelled_decades((1e-14, 1.0), 1.0) in (14, 15)       # (b, m): |p T| = 1e-14
    found = paper_loop.limits("B", "K", M=0.0, m=1e100, b=1e100, T=1e-3, d=3)
    reference = paper_loop.limits("B", "K", M=0.0, m=1.0, b=1.0, T=1e-3, d=3)
    assert found.y_max == pytest.approx(reference.y_max * 1e100, rel=1e-12)
    assert found.x_at_y_max == pytest.approx(reference.x_at_y_max * 1e100, rel=1e-6)
    # At m = b = 1e300 the plane's window reaches K = 6e305 and its area 1e607: the set was
    # called empty (a silent wrong answer); it is refused, naming the limit.
    with pytest.raises(ValueError, match="beyond 1e\\+150.*overflow double precision"):
        paper_loop.limits("B", "K", M=0.0, m=1e300, b=1e300, T=1e-3, d=3)


def test_bad_calls_name_the_parameter(paper_loop):
    with pytest.raises(TypeError, match="missing value.*M"):
        paper_loop.classify(K=1.0, B=0.1, d=0, **DEVICE)
    with pytest.raises(TypeError, match="unknown parameter.*Q"):
        paper_loop.classify(K=1.0, B=0.1, M=0.0, Q=1.0, d=0, **DEVICE)
    with pytest.raises(ValueError, match="T must be"):
        paper_loop.classify(K=1.0, B=0.1, M=0.0, d=0, m=PAPER_M, b=PAPER_B, T=-1.0)
    with pytest.raises(ValueError, match="d must be"):
        paper_loop.classify(K=1.0, B=0.1, M=0.0, d=-1.5, **DEVICE)
    with pytest.raises(TypeError, match="delay once"):
        paper_loop.classify(K=1.0, B=0.1, M=0.0, d=1, Td=1e-3, **DEVICE)
    with pytest.raises(ValueError, match="'m' does not enter .* affinely"):
        paper_loop.stable_intervals("m", K=1.0, B=0.1, M=0.0, d=0, b=PAPER_B, T=PAPER_T)
    with pytest.raises(ValueError, match="'m' does not enter .* affinely"):
        paper_loop.stable_intervals("K", B=0.1, M=0.0, d=0, m=[PAPER_M, 2 * PAPER_M],
                                    b=PAPER_B, T=PAPER_T)
    with pytest.raises(ValueError, match="at most one parameter may be an array.*B, M"):
        paper_loop.stable_intervals("K", B=[0.1, 0.2], M=[0.0, 0.1], d=0, **DEVICE)
    with pytest.raises(ValueError, match="B must be a single value or a 1-D array"):
        paper_loop.stable_intervals("K", B=[[0.1, 0.2]], M=0.0, d=0, **DEVICE)
    squared = Loop(PLANT, "K**2 + B*(z - 1)/(T*z)")
    with pytest.raises(ValueError, match="'K' does not enter"):
        squared.limits("B", "K", d=0, **DEVICE)
    product = Loop(PLANT, "K*B + B*(z - 1)/(T*z) + K")
    with pytest.raises(ValueError, match="jointly"):
        product.limits("B", "K", d=0, **DEVICE)


def test_arrays_broadcast(paper_loop):
    K = np.linspace(0, 600, 7)[:, None]
    B = np.array([0.2, 0.5, 1.0])[None, :]
    codes = paper_loop.classify(K=K, B=B, M=0.0, d=0, **DEVICE)
    assert codes.shape == (7, 3)
    r = paper_loop.spectral_radius(K=K, B=B, M=0.0, d=0, **DEVICE)
    assert r.shape == (7, 3)
    assert np.array_equal(codes == STABLE, r < 1)


# -- the line engine's pieces ------------------------------------------------------

def _numpy_unstable(coefficients):
    """Roots outside the unit circle by numpy.roots (the companion matrix's eigenvalues)."""
    return int(np.sum(np.abs(np.roots(coefficients)) > 1))


def test_line_engine_on_random_lines_agrees_with_numpy_roots():
    """Stable intervals of a0 + p a1: stable inside (numpy.roots), unstable just outside each end."""
    from symstab.numeric.engine.intervals import line_intervals

    rng = np.random.default_rng(17)
    checked = 0
    for degree in (1, 2, 5, 12, 30):
        for _ in range(6):
            a0 = rng.normal(size=degree + 1)
            a1 = rng.normal(size=degree + 1)
            a0[0] = abs(a0[0]) + 3.0          # a leading coefficient that stays away from 0
            a1[0] = 0.0
            runs = line_intervals(a0, a1)
            for lo, hi in runs:
                for p in np.linspace(lo, hi, 7)[1:-1] if np.isfinite(lo + hi) else []:
                    assert _numpy_unstable(a0 + p * a1) == 0, (degree, p, runs)
                    checked += 1
                for end, side in ((lo, -1), (hi, 1)):
                    if np.isfinite(end):
                        step = 1e-6 * max(1.0, abs(end))
                        outside = end + side * step
                        if not any(a < outside < b for a, b in runs):
                            assert _numpy_unstable(a0 + outside * a1) > 0, (degree, end, runs)
                            checked += 1
    assert checked > 50


def test_a_family_of_lines_is_its_lines_one_by_one():
    """Lines scanned and counted together give each line's own intervals (and numpy.roots agrees)."""
    from symstab.numeric.engine.intervals import family_intervals, line_intervals

    rng = np.random.default_rng(29)
    checked = 0
    for degree in (1, 3, 8, 20):
        for _ in range(4):
            a0, across, a1 = rng.normal(size=(3, degree + 1))
            a0[0] = abs(a0[0]) + 3.0
            across[0] = a1[0] = 0.0
            at = np.linspace(-1.5, 1.5, 9)
            together = family_intervals(a0, across, a1, at)
            for v, runs in zip(at, together, strict=True):
                alone = line_intervals(a0 + v * across, a1)
                assert len(runs) == len(alone), (degree, v, runs, alone)
                for got, want in zip(runs, alone, strict=True):
                    np.testing.assert_allclose(got, want, rtol=1e-9, atol=1e-12)
                for lo, hi in runs:
                    if np.isfinite(lo + hi):
                        p = 0.5 * (lo + hi)
                        assert _numpy_unstable(a0 + v * across + p * a1) == 0
                        checked += 1
    assert checked > 20


def test_loop_family_of_lines_equals_its_single_lines():
    """``stable_intervals`` with one parameter an array: the paper's vertical lines at d = 40."""
    loop = symstab.PAPER_LOOP
    values = {"M": 0.0064, "d": 40}
    dampings = np.array([-0.01, 0.0, 0.05, 0.2, 0.6])
    together = loop.stable_intervals("K", B=dampings, **values)
    assert len(together) == len(dampings)
    for B, runs in zip(dampings, together, strict=True):
        # One line is a family of one: the same arithmetic.
        assert runs == loop.stable_intervals("K", B=float(B), **values)
        assert runs == loop.stable_intervals("K", B=np.array([B]), **values)[0]
        for lo, hi in runs:
            assert lo == 0.0      # chi(1) = 0 at K = 0, exactly
            assert _numpy_unstable(loop.coefficients(K=0.5 * hi, B=B, **values)) == 0
    # K = 0 puts a root exactly at z = 1 for every B: no stable B (not an error).
    assert loop.stable_intervals("B", K=np.array([0.0, 1.0]), **values)[0] == []


def test_loop_line_at_a_long_delay_is_right():
    """The low-pass loop at d = 1000: stable K in (0, 0.0507...) by numpy.roots.

    The dense line engine this replaced called the line empty here (in 43
    s): a stable stretch missed, silently.
    """
    loop = symstab.load_loop(os.path.join(os.path.dirname(__file__), "..", "..", "..", "examples",
                                          "loops", "lowpass_velocity.toml"))
    runs = loop.stable_intervals("K", B=0.02, d=1000)
    assert len(runs) == 1
    lo, hi = runs[0]
    assert lo == pytest.approx(0.0, abs=1e-12)
    for k in (0.25 * hi, 0.5 * hi, hi * (1 - 1e-4)):
        assert _numpy_unstable(loop.coefficients(K=k, B=0.02, d=1000)) == 0
    assert _numpy_unstable(loop.coefficients(K=hi * (1 + 1e-4), B=0.02, d=1000)) > 0


def test_root_counts_next_to_the_circle_are_right_or_marginal():
    """Roots 1e-12 to 1e-3 from the circle: the certified count is mpmath's, or -1; never wrong."""
    rng = np.random.default_rng(23)
    decided = marginal = 0
    for _ in range(60):
        degree = int(rng.integers(2, 14))
        gap = 10.0 ** rng.uniform(-12, -3)
        radius = np.where(rng.random(degree) < 0.5, 1 - gap, 1 + gap)
        roots = radius * np.exp(1j * rng.uniform(0.01, np.pi - 0.01, degree))
        c = np.real(np.poly(np.concatenate([roots, np.conj(roots)])))
        outside, nearest, _ = _mp_outside(c)
        count = root_counts(DelayedPolynomial.from_dense(c[None, :]))[0]
        if count == -1:
            marginal += 1
            continue
        assert count == outside, (c.tolist(), count, outside, nearest)
        decided += 1
    assert decided >= 30, (decided, marginal)
