"""Tests of symstab.symbolic.model: symbols, G(s), the ZOH, VE(z) and Table I."""

import math

import numpy as np
import pytest
import sympy as sp

from symstab.symbolic import model
from symstab.symbolic.model import dimensionless_values

from conftest import PAPER_B, PAPER_DELTA, PAPER_M, PAPER_T, assert_message_names, assert_rel_close
from oracles import eq1_virtual_environment, eq1_virtual_environment_tf

# Symbols and blocks ---------------------------------------------------------

@pytest.mark.parametrize("symbol, assumption", [
    (model.delta, "positive"), (model.Gamma, "positive"), (model.m, "positive"),
    (model.T, "positive"), (model.theta, "real"), (model.alpha, "real"),
    (model.beta, "real"), (model.gamma, "real"), (model.d, "integer"), (model.d, "nonnegative"),
])
def test_symbol_assumptions(symbol, assumption):
    assert getattr(symbol, f"is_{assumption}") is True


def test_plant_is_mass_with_viscous_friction():
    s, m, b = model.s, model.m, model.b
    # m y'' + b y' = u  <=>  Y(s) (m s^2 + b s) = U(s)
    assert sp.cancel(model.plant() * (m * s**2 + b * s)) == 1


def test_zero_order_hold_has_dc_gain_T_and_unit_pulse_shape():
    s, T = model.s, model.T
    zoh = model.zero_order_hold()
    assert sp.limit(zoh, s, 0) == T
    # Inverse Laplace of (1 - e^{-Ts})/s is the pulse H(t) - H(t - T).
    t = sp.Symbol("t", positive=True)
    pulse = sp.inverse_laplace_transform(zoh, s, t)
    assert pulse.subs(t, T / 2) == 1
    assert pulse.subs(t, 2 * T) == 0


def test_virtual_environment_is_eq1():
    z, T = model.z, model.T
    printed = eq1_virtual_environment(z, model.K_w, model.B_w, model.M_w, T)
    assert sp.cancel(model.virtual_environment() - printed) == 0


@pytest.mark.parametrize("K_w, B_w, M_w, T", [(300.0, 0.5, 0.002, 1e-3), (0.7, -0.3, 1.9, 1.0),
                                             (2.0, 0.0, -0.5, 0.25), (1e4, 3.0, 0.0, 2.5e-4)])
def test_python_control_virtual_environment_is_eq1(K_w, B_w, M_w, T):
    """The oracle's VE(z) coefficients, written by hand, are the printed eq. (1) at complex z."""
    environment = eq1_virtual_environment_tf(K_w, B_w, M_w, T)
    assert environment.dt == T
    for z in (0.3 + 0.8j, -1.7 + 0.2j, 0.99j, 2.5, np.exp(0.01j)):
        expected = eq1_virtual_environment(z, K_w, B_w, M_w, T)
        assert complex(environment(z)) == pytest.approx(expected, rel=1e-12), z


def test_dimensionless_substitution_is_table_I():
    sub = model.dimensionless_substitution()
    m, T = model.m, model.T
    expected = {model.b: model.delta * m / T, model.K_w: model.alpha * m / T**2,
                model.B_w: model.beta * m / T, model.M_w: model.gamma * m, model.Td: model.d * T}
    assert set(sub) == set(expected)
    for key, value in expected.items():
        assert sp.simplify(sub[key] - value) == 0, key


def test_scaled_environment_depends_only_on_dimensionless_parameters():
    z = model.z
    scaled = (model.virtual_environment() * model.T**2 / model.m).subs(
        model.dimensionless_substitution())
    expected = model.alpha + model.beta * (z - 1) / z + model.gamma * (z - 1) ** 2 / z**2
    assert sp.cancel(scaled - expected) == 0


# dimensionless_values ---------------------------------------------------

def test_dimensionless_values_of_the_paper_device():
    v = dimensionless_values(m=PAPER_M, b=PAPER_B, T=PAPER_T, Td=40e-3)
    assert_rel_close(v["delta"], 0.00253125, 1e-14)
    assert v["d"] == 40 and type(v["d"]) is int
    assert v["alpha"] == 0.0 and v["beta"] == 0.0 and v["gamma"] == 0.0


def test_dimensionless_values_follow_table_I():
    m, b, T = 0.05, 0.2, 2e-3
    K_w, B_w, M_w = 3000.0, -1.5, 0.08
    v = dimensionless_values(m=m, b=b, T=T, K_w=K_w, B_w=B_w, M_w=M_w, Td=6e-3)
    assert_rel_close(v["alpha"], 3000.0 * 4e-6 / 0.05, 1e-14)   # 0.24
    assert_rel_close(v["beta"], -1.5 * 2e-3 / 0.05, 1e-14)      # -0.06
    assert_rel_close(v["gamma"], 0.08 / 0.05, 1e-14)            # 1.6
    assert_rel_close(v["delta"], 0.2 * 2e-3 / 0.05, 1e-14)      # 0.008
    assert v["d"] == 3


def test_dimensionless_values_allows_frictionless_device():
    assert dimensionless_values(m=1.0, b=0.0, T=1e-3)["delta"] == 0.0


_GOOD = dict(m=PAPER_M, b=PAPER_B, T=PAPER_T)


@pytest.mark.parametrize("name, value", [
    ("m", 0.0), ("m", -0.01), ("T", 0.0), ("T", -1e-3), ("b", -1e-6),
    ("m", math.nan), ("b", math.nan), ("T", math.inf), ("K_w", math.nan),
    ("B_w", math.inf), ("M_w", -math.inf), ("Td", -1e-3), ("Td", math.nan),
])
def test_dimensionless_values_rejects_bad_values_naming_them(name, value):
    with pytest.raises(ValueError) as excinfo:
        dimensionless_values(**{**_GOOD, name: value})
    assert_message_names(excinfo, name)


@pytest.mark.parametrize("Td", [1.5e-3, 40.5e-3, 1e-4])
def test_dimensionless_values_rejects_delay_not_a_whole_number_of_samples(Td):
    with pytest.raises(ValueError, match=r"Td / T"):
        dimensionless_values(**_GOOD, Td=Td)


@pytest.mark.parametrize("name, value", [
    ("m", "0.0128"), ("b", True), ("T", None), ("K_w", "1"), ("Td", False), ("M_w", 1j),
])
def test_dimensionless_values_rejects_wrong_kinds_with_type_error(name, value):
    with pytest.raises(TypeError) as excinfo:
        dimensionless_values(**{**_GOOD, name: value})
    assert_message_names(excinfo, name)


def test_dimensionless_values_rejects_unknown_keyword():
    with pytest.raises(TypeError):
        dimensionless_values(**_GOOD, K=1.0)


def test_dimensionless_values_is_keyword_only():
    with pytest.raises(TypeError):
        dimensionless_values(PAPER_M, PAPER_B, PAPER_T)


def test_dimensionless_values_accepts_numpy_scalars():
    v = dimensionless_values(m=np.float64(PAPER_M), b=np.float32(0.0324), T=np.float64(PAPER_T))
    assert_rel_close(v["delta"], PAPER_DELTA, 1e-6)
