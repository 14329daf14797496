"""Tests of symstab.proof.necessity: the necessary conditions hold at numbers, and
a changed derivation makes the proofs (and ``symstab derive``) fail."""

import numpy as np
import pytest
import sympy as sp

from symstab.proof import derive, necessity
from symstab.symbolic import model
from symstab.symbolic.loop import LoopPolynomial, characteristic_polynomial

from oracles import first_principles_chi_float


def _roots(alpha, beta, gamma, d, delta):
    """Closed-loop poles from the printed eqs. (1), (2), (4) (first principles)."""
    return np.roots(first_principles_chi_float(alpha, beta, gamma, d, delta))


def _conditions():
    return {c.name: c for c in necessity.necessary_conditions()}


def _evaluate(expr, *, gamma=0.0, delta):
    # Exact inputs: Gamma delta - 2 Gamma + delta + 2 ~ delta**3 / 6 cancels digits.
    gamma, delta = sp.Rational(gamma), sp.Rational(delta)
    values = {model.gamma: gamma, model.delta: delta, model.Gamma: sp.exp(delta)}
    return float(sp.sympify(expr).subs(values).evalf(40))


RNG_POINTS = [(-0.3, 0.2, 0.5, 0, 0.05), (-1e-3, -0.4, -0.75, 1, 0.3), (-2.0, 1.5, 1.0, 5, 1e-3),
              (-0.05, 0.0, 2.2, 10, 0.7), (-1e-6, 0.01, 0.0, 40, 2.5e-3)]


@pytest.mark.parametrize("alpha, beta, gamma, d, delta", RNG_POINTS)
def test_negative_alpha_has_a_real_root_above_one(alpha, beta, gamma, d, delta):
    roots = _roots(alpha, beta, gamma, d, delta)
    real = roots[np.abs(roots.imag) <= 1e-9 * np.maximum(1.0, np.abs(roots))].real
    assert np.any(real > 1.0), roots


@pytest.mark.parametrize("beta, gamma, d, delta", [(0.2, 0.5, 0, 0.05), (-0.4, 1.0, 3, 0.3)])
def test_zero_alpha_has_a_root_at_one(beta, gamma, d, delta):
    roots = _roots(0.0, beta, gamma, d, delta)
    assert np.min(np.abs(roots - 1.0)) < 1e-6


@pytest.mark.parametrize("gamma, d, delta", [(0.0, 0, 0.05), (0.5, 1, 0.3), (-0.5, 4, 1.0),
                                            (1.5, 7, 0.01), (2.0, 10, 2.5e-3)])
def test_minus_one_line_agrees_with_the_numeric_line_and_the_roots(gamma, d, delta):
    from symstab.numeric.paper.curves import minus_one_line

    label = "even" if d % 2 == 0 else "odd"
    objects = {name: expr for name, _, expr in _conditions()["minus_one_line"].objects}
    c = _evaluate(objects[f"minus_one_line_{label}_d"], gamma=gamma, delta=delta)
    assert c == pytest.approx(minus_one_line(gamma=gamma, d=d, delta=delta), rel=1e-9)
    # On the line z = -1 is a root; a step across it to the forbidden side
    # ((-1)**d (alpha + 2 beta - c) > 0) gives a real root < -1.
    alpha = 0.1
    on_line = _roots(alpha, (c - alpha) / 2, gamma, d, delta)
    assert np.min(np.abs(on_line + 1.0)) < 1e-6 * max(1.0, abs(c))
    step = (-1) ** d * 0.01 * max(1.0, abs(c))
    beyond = _roots(alpha, (c - alpha + step) / 2, gamma, d, delta)
    real = beyond[np.abs(beyond.imag) <= 1e-9 * np.maximum(1.0, np.abs(beyond))].real
    assert np.any(real < -1.0), beyond


@pytest.mark.parametrize("delta", [1e-3, 0.05, 0.5, 2.0])
def test_gamma_bound_is_the_root_product_and_exceeds_two(delta):
    objects = {name: expr for name, _, expr in _conditions()["gamma_bound"].objects}
    gamma_max = _evaluate(objects["gamma_max"], delta=delta)
    # First principles: Gamma delta**2 / (Gamma - 1 - delta), Gamma = exp(delta).
    expected = np.exp(delta) * delta**2 / (np.expm1(delta) - delta)
    assert gamma_max == pytest.approx(expected, rel=1e-9)
    assert gamma_max > 2.0
    for gamma in (gamma_max, -gamma_max, 1.01 * gamma_max):
        for alpha, beta, d in ((0.01, 0.0, 0), (0.3, 0.5, 3), (1e-3, 0.05, 10)):
            roots = _roots(alpha, beta, gamma, d, delta)
            assert np.prod(np.abs(roots)) == pytest.approx(abs(gamma) / gamma_max, rel=1e-6)
            assert np.max(np.abs(roots)) >= 1.0 - 1e-9


@pytest.mark.parametrize("gamma, d, delta", [(0.0, 0, 0.05), (1.0, 1, 0.3), (0.0, 2, 0.01),
                                            (-0.5, 5, 0.2), (1.0, 10, 2.5e-3)])
def test_every_stable_point_lies_beyond_the_minimum_damping_line(gamma, d, delta):
    objects = {name: expr for name, _, expr in _conditions()["minimum_damping"].objects}
    start = _evaluate(objects["minimum_damping_start"], delta=delta)
    slope = _evaluate(objects["minimum_damping_slope"].subs(model.d, d), delta=delta)
    assert start == pytest.approx(-delta, rel=1e-12)
    # First principles: 2 chi'(1) - n chi(1) > 0 from the roots' log derivative.
    assert slope == pytest.approx(d / 2 + 1 / delta - 1 / -np.expm1(-delta), rel=1e-9, abs=1e-12)
    if d >= 2:
        assert slope > 0
    # A window around the start (-delta, 0), where the line is the binding bound.
    stable = []
    for beta in np.linspace(-delta - 0.05, -delta + 0.1, 31):
        for alpha in np.linspace(1e-4, 0.05, 25):
            if np.max(np.abs(_roots(alpha, beta, gamma, d, delta))) < 1.0:
                stable.append((beta, alpha))
    assert len(stable) > 20          # the check is not vacuous
    for beta, alpha in stable:
        assert beta > start + slope * alpha


def test_gamma_max_tends_to_two():
    objects = {name: expr for name, _, expr in _conditions()["gamma_bound"].objects}
    assert objects["gamma_max_small_delta"] == 2


def test_the_theorems_hold_for_symbolic_d():
    conditions = _conditions()
    assert set(conditions) == {"alpha_positive", "minimum_damping", "minus_one_line", "gamma_bound"}
    objects = dict((name, expr) for c in conditions.values() for name, _, expr in c.objects)
    assert objects["leading_exponent"] == model.d + 4
    assert not objects["chi_at_1"].has(model.d)
    for name, _, lhs, rhs in necessity.proofs():
        assert derive.check_identity(lhs, rhs).equal is True, name


@pytest.mark.parametrize("expression, order", [
    (model.Gamma - 1, 1), (model.Gamma - 1 - model.delta, 2), (model.delta**2 * model.Gamma, 0)])
def test_positive_for_positive_delta_proves(expression, order):
    assert necessity.positive_for_positive_delta(expression).order == order


@pytest.mark.parametrize("expression, match", [
    (model.delta - 1, "delta = 0"),                           # negative near 0
    (model.Gamma - 1 - 2 * model.delta, "order 1"),           # f(0) = 0, f'(0) = -1
    (model.Gamma - 1 - model.delta - model.delta**3, "not 0"),   # negative above delta = 0.6
    (model.alpha * model.Gamma, "depends on"),
])
def test_positive_for_positive_delta_refuses(expression, match):
    with pytest.raises(necessity.ProofFailed, match=match):
        necessity.positive_for_positive_delta(expression)


def _perturbed(*, delayed=None, direct=None):
    chi = characteristic_polynomial()
    z = model.z
    return LoopPolynomial(
        delayed=sp.Poly(delayed(chi.delayed.as_expr()) if delayed else chi.delayed.as_expr(), z),
        direct=sp.Poly(direct(chi.direct.as_expr()) if direct else chi.direct.as_expr(), z))


@pytest.mark.parametrize("perturbation, match", [
    # The leading coefficient turns negative: a_n > 0 no longer holds.
    (dict(delayed=lambda p: -p), "leading coefficient"),
    # The constant term is no longer proportional to gamma's positive factor.
    (dict(direct=lambda p: p - 3 * model.gamma * (model.Gamma - model.delta - 1)), "g = a_0 / gamma"),
    # chi(1) gains a beta term: 2 chi'(1) - n chi(1) is no longer d-free in beta.
    (dict(direct=lambda p: p + model.beta * model.delta**2), "scale"),
])
def test_a_changed_polynomial_fails_a_sign(monkeypatch, perturbation, match):
    monkeypatch.setattr(necessity, "characteristic_polynomial", lambda: _perturbed(**perturbation))
    with pytest.raises(necessity.ProofFailed, match=match):
        necessity.necessary_conditions()


def test_a_changed_polynomial_fails_symstab_derive(monkeypatch):
    """chi(1) gains a gamma term (every sign still holds): derive's identity check fails."""
    perturbed = _perturbed(direct=lambda p: p + model.gamma * model.delta**3 * model.z)
    assert necessity._conditions(perturbed)      # the signs alone do not see it
    monkeypatch.setattr(necessity, "characteristic_polynomial", lambda: perturbed)
    proofs = dict((name, (lhs, rhs)) for name, _, lhs, rhs in necessity.proofs())
    assert derive.check_identity(*proofs["necessity_chi_at_1_is_alpha_q"]).equal is False
    with pytest.raises(AssertionError, match="necessity_chi_at_1_is_alpha_q"):
        derive.derivation_steps()


def test_the_derivation_writes_the_necessity_step(rendered_files):
    import json

    data = json.loads(rendered_files["08_necessity.json"])
    names = [obj["name"] for obj in data["objects"]]
    for theorem in ("alpha_positive_theorem", "minus_one_line_theorem", "gamma_bound_theorem"):
        assert theorem in names
    proved = json.loads(rendered_files["07_proofs.json"])
    assert {"necessity_chi_at_1_is_alpha_q", "necessity_chi_at_minus_1_even_d",
            "necessity_chi_at_minus_1_odd_d", "necessity_constant_term_is_gamma_g"} <= \
        {obj["name"] for obj in proved["objects"]}
