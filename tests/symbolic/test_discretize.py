"""Tests of symstab.symbolic.discretize: Z[ZOH G(s)] by residues, against eq. (4)."""

import mpmath
import numpy as np
import pytest
import sympy as sp

from symstab.symbolic import model
from symstab.symbolic.discretize import (
    dimensionless_pulse_transfer_function,
    pulse_transfer_function,
    z_transform_by_residues,
)

from conftest import PAPER_B, PAPER_M, PAPER_T, assert_rel_close
from oracles import eq4_pulse_transfer_function

s, z, T = model.s, model.z, model.T
a = sp.Symbol("a", positive=True)
q = sp.exp(-a * T)

#: Standard z-transform table: F(s) -> Z[f(kT)].
Z_TABLE = [
    (1 / s, z / (z - 1)),
    (1 / s**2, T * z / (z - 1) ** 2),
    (1 / (s + a), z / (z - q)),
    (1 / (s + a) ** 2, T * z * q / (z - q) ** 2),
    (1 / (s * (s + a)), z * (1 - q) / (a * (z - 1) * (z - q))),
    (1 / (s**2 * (s + a)), T * z / (a * (z - 1) ** 2) - z * (1 - q) / (a**2 * (z - 1) * (z - q))),
]


def _numeric_equal(lhs, rhs, symbols, points):
    f = sp.lambdify(symbols, lhs - rhs, modules="mpmath")
    g = sp.lambdify(symbols, abs(lhs) + abs(rhs), modules="mpmath")
    with mpmath.workdps(40):
        for p in points:
            p = [mpmath.mpmathify(x) for x in p]
            assert abs(f(*p)) <= mpmath.mpf(10) ** -32 * g(*p), p


_TABLE_POINTS = [(0.7, 0.1, 1.3 + 0.4j), (2.5, 0.03, -0.6 + 1.1j), (0.2, 1.0, 2.0)]


@pytest.mark.parametrize("F, expected", Z_TABLE, ids=[str(F) for F, _ in Z_TABLE])
def test_z_transform_by_residues_matches_table(F, expected):
    result = z_transform_by_residues(F)
    _numeric_equal(result, expected, (a, T, z), _TABLE_POINTS)


@pytest.mark.parametrize("F", [1 / (s * (s + a)), 1 / (s**2 * (s + 2) * (s + a))])
def test_z_transform_by_residues_is_the_sampled_series(F):
    # Z[f(kT)] = sum_k f(kT) z^-k, with f the inverse Laplace transform of F.
    t = sp.Symbol("t", positive=True)
    f = sp.lambdify((t, a), sp.inverse_laplace_transform(F, s, t), modules="mpmath")
    Z = sp.lambdify((z, a, T), z_transform_by_residues(F), modules="mpmath")
    with mpmath.workdps(30):
        aa, TT, zz = mpmath.mpf("0.8"), mpmath.mpf("0.25"), mpmath.mpc(1.6, 0.9)
        series = mpmath.nsum(lambda k: f(k * TT, aa) * zz ** (-k) if k > 0 else 0, [0, mpmath.inf])
        assert_rel_close(series, Z(zz, aa, TT), mpmath.mpf(10) ** -20, "series")


@pytest.mark.parametrize("F", [s / (s + 1), sp.Integer(1), (s**2 + 1) / (s**2 + 3 * s + 2)])
def test_z_transform_by_residues_rejects_non_strictly_proper(F):
    with pytest.raises(ValueError, match="strictly proper"):
        z_transform_by_residues(F)


def test_pulse_transfer_function_equals_printed_eq4():
    m, b = model.m, model.b
    derived = pulse_transfer_function()
    printed = eq4_pulse_transfer_function(z, m, b, T)
    X = sp.Symbol("X", positive=True)  # X = exp(b T / m)
    diff = (derived - printed).subs(sp.exp(b * T / m), X)
    assert not diff.has(sp.exp)
    assert sp.cancel(sp.together(diff)) == 0


def test_pulse_transfer_function_equals_printed_eq4_numerically():
    m, b = model.m, model.b
    f = sp.lambdify((z, m, b, T), pulse_transfer_function(), modules="mpmath")
    with mpmath.workdps(40):
        for zz, mm, bb, TT in [(mpmath.mpc(0.3, 0.9), PAPER_M, PAPER_B, PAPER_T),
                               (mpmath.mpf(-2), 1.5, 0.4, 0.01), (mpmath.expj(2.0), 0.01, 3.0, 1e-4)]:
            mm, bb, TT = mpmath.mpf(mm), mpmath.mpf(bb), mpmath.mpf(TT)
            printed = eq4_pulse_transfer_function(zz, mm, bb, TT, exp=mpmath.exp)
            assert_rel_close(f(zz, mm, bb, TT), printed, mpmath.mpf(10) ** -30, "eq. (4)")


def _impulse_response(H, n):
    """First n coefficients of H(z) = sum_k h_k z^-k, by long division."""
    num, den = sp.fraction(sp.cancel(sp.together(H)))
    num = [mpmath.mpf(str(sp.N(c, 40))) for c in sp.Poly(num, z).all_coeffs()]
    den = [mpmath.mpf(str(sp.N(c, 40))) for c in sp.Poly(den, z).all_coeffs()]
    lag = len(den) - len(num)
    num = [mpmath.mpf(0)] * lag + num  # both in powers z^-k after dividing by z^deg(den)
    h = []
    for k in range(n):
        acc = num[k] if k < len(num) else mpmath.mpf(0)
        for j in range(1, min(k, len(den) - 1) + 1):
            acc -= den[j] * h[k - j]
        h.append(acc / den[0])
    return h


@pytest.mark.parametrize("mm, bb, TT", [(PAPER_M, PAPER_B, PAPER_T), (0.3, 0.7, 0.1), (2.0, 0.05, 0.5)])
def test_pulse_response_is_sampled_step_response_difference(mm, bb, TT):
    # ZOH equivalent: h[k] = y_step(kT) - y_step((k-1)T), y_step of G(s)/s.
    with mpmath.workdps(40):
        mm, bb, TT = mpmath.mpf(mm), mpmath.mpf(bb), mpmath.mpf(TT)

        def step(t):
            return (t - mm / bb * (1 - mpmath.exp(-bb * t / mm))) / bb if t > 0 else mpmath.mpf(0)

        H = pulse_transfer_function().subs({model.m: sp.Float(str(mm), 40), model.b: sp.Float(str(bb), 40),
                                            T: sp.Float(str(TT), 40)})
        h = _impulse_response(H, 12)
        for k, hk in enumerate(h):
            expected = step(k * TT) - step((k - 1) * TT)
            assert abs(hk - expected) <= mpmath.mpf(10) ** -25 * max(abs(expected), step(TT)), k


def test_pulse_transfer_function_matches_python_control_c2d():
    import control

    m_, b_, T_ = 0.05, 0.2, 2e-3
    G = control.c2d(control.tf([1], [m_, b_, 0]), T_, "zoh")
    f = sp.lambdify((z, model.m, model.b, T), pulse_transfer_function(), modules="numpy")
    for zz in [0.5 + 0.5j, np.exp(1j * 0.3), -1.2, 3.0 + 0j]:
        assert_rel_close(f(zz, m_, b_, T_), complex(G(zz)), 1e-9, f"z={zz}")


def test_dimensionless_pulse_transfer_function_is_scaled_eq4():
    # (m / T^2) Z[ZOH G] with b = delta m / T, Gamma = exp(delta): eq. (4) scaled.
    derived = dimensionless_pulse_transfer_function()
    assert derived.free_symbols == {z, model.delta, model.Gamma}
    f = sp.lambdify((z, model.delta, model.Gamma), derived, modules="mpmath")
    with mpmath.workdps(40):
        for zz, dl, mm, TT in [(mpmath.mpc(0.2, 1.1), "0.00253125", "0.0128", "0.001"),
                               (mpmath.expj(1.0), "0.7", "3", "0.01"), (mpmath.mpf(-0.5), "1e-4", "1", "1")]:
            dl, mm, TT = mpmath.mpf(dl), mpmath.mpf(mm), mpmath.mpf(TT)
            printed = mm / TT**2 * eq4_pulse_transfer_function(zz, mm, dl * mm / TT, TT, exp=mpmath.exp)
            assert_rel_close(f(zz, dl, mpmath.exp(dl)), printed, mpmath.mpf(10) ** -28, "scaled eq. (4)")


def test_dimensionless_pulse_transfer_function_has_the_documented_denominator():
    num, den = sp.fraction(dimensionless_pulse_transfer_function())
    delta, Gamma = model.delta, model.Gamma
    assert sp.expand(den - delta**2 * (z - 1) * (Gamma * z - 1)) == 0
    assert sp.Poly(num, z).degree() == 1
