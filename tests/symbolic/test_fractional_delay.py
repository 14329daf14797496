"""The zero-order hold with a fractional input delay (issue 43, item 1: the first step).

Oracle, written here: the state-space discretisation with the delay inside the
period (Åström and Wittenmark, sec. 2.3), ``x[k+1] = Phi x[k] + Gamma0 u[k] +
Gamma1 u[k-1]``, ``Phi = exp(A T)``, ``Gamma0 = int_0^((1-eps) T) exp(A s) ds B``,
``Gamma1 = exp(A (1-eps) T) int_0^(eps T) exp(A s) ds B``, each integral from
Van Loan's block exponential (scipy ``expm``), the realisation from scipy's
``tf2ss``; the pulse transfer function ``C (z I - Phi)^-1 (Gamma0 + Gamma1 / z)``
compared on and off the unit circle.
"""

import functools

import numpy as np
import pytest
import scipy.linalg
import scipy.signal
import sympy as sp

from symstab.symbolic.discretize import (
    fractional_delay_identities,
    fractional_zoh_pulse_transfer_function,
    numeric_fractional_zoh,
    numeric_zoh,
)

m, b, k, tau, T, eps, s, z = sp.symbols("m b k tau T epsilon s z", positive=True)

#: Plants of the example loops' kinds: a damped mass (the paper's), a frictionless one
#: (a triple pole of G / s at 0), a spring (a complex pair), an actuator lag (three poles).
PLANTS = {
    "damped mass": (1 / (m * s**2 + b * s), {m: 0.0128, b: 0.0324}),
    "frictionless mass": (1 / (m * s**2), {m: 0.2}),
    "spring, complex pair": (1 / (m * s**2 + b * s + k), {m: 0.2, b: 2.0, k: 4.0e4}),
    "actuator lag": (1 / ((m * s**2 + b * s) * (tau * s + 1)), {m: 0.0128, b: 0.0324,
                                                                  tau: 2e-3}),
}


def _integral(A, B, tau_):
    """``int_0^tau exp(A s) ds B`` and ``exp(A tau)``: Van Loan's block exponential."""
    n = A.shape[0]
    block = np.zeros((n + 1, n + 1))
    block[:n, :n], block[:n, n:] = A, B
    E = scipy.linalg.expm(block * tau_)
    return E[:n, n:], E[:n, :n]


def state_space_pulse(G, values, period, fraction, points):
    """The oracle: ``C (z I - Phi)^-1 (Gamma0 + Gamma1 / z)`` at ``points``."""
    num, den = sp.fraction(sp.together(G.subs(values)))
    A, B, C, _ = scipy.signal.tf2ss([float(c) for c in sp.Poly(num, s).all_coeffs()],
                                    [float(c) for c in sp.Poly(den, s).all_coeffs()])
    Phi = scipy.linalg.expm(A * period)
    gamma0, _ = _integral(A, B, (1 - fraction) * period)
    early, _ = _integral(A, B, fraction * period)
    _, rest = _integral(A, B, (1 - fraction) * period)
    gamma1 = rest @ early
    out = []
    for point in points:
        solved = np.linalg.solve(point * np.eye(A.shape[0]) - Phi, gamma0 + gamma1 / point)
        out.append((C @ solved).item())
    return np.array(out)


@functools.cache
def derived(name, period=1e-3):
    """The plant's fractional pulse at its values and ``period``, a function of ``(z, eps)``:
    derived once for the fractions tested."""
    G, values = PLANTS[name]
    P = fractional_zoh_pulse_transfer_function(G, eps, s=s, z=z, T=T)
    return sp.lambdify((z, eps), P.subs({**values, T: period}), "mpmath")


@pytest.mark.parametrize("name", PLANTS)
@pytest.mark.parametrize("fraction", [0.0, 0.25, 0.5, 0.999])
def test_the_fractional_pulse_is_the_state_space_one(name, fraction):
    G, values = PLANTS[name]
    period = 1e-3
    f = derived(name, period)
    points = [np.exp(1j * theta) for theta in (0.01, 0.3, 1.0, 2.5, np.pi)] + [1.7, -0.4 + 0.2j]
    found = np.array([complex(f(point, fraction)) for point in points])
    expected = state_space_pulse(G, values, period, fraction, points)
    # At z = -1 the pulse is 1e-4 of its largest value: the double-precision oracle's
    # cancellation there (about 1e-16 of the terms) is the absolute floor.
    np.testing.assert_allclose(found, expected, rtol=1e-9, atol=1e-13 * abs(expected).max())


@pytest.mark.parametrize("name", PLANTS)
def test_no_fraction_is_the_integer_delay_plant_and_a_whole_one_is_one_sample_more(name):
    """Exact: ``P_0 - P`` and ``P_1 - P / z`` cancel to 0 as rational functions (issue 43)."""
    G, _ = PLANTS[name]
    assert fractional_delay_identities(G, s=s, z=z, T=T) == (0, 0)


def test_a_broken_fraction_is_caught_by_both_oracles():
    """The oracle and the identities can fail: the hold's shift taken as eps instead of
    1 - eps differs from the state space and leaves the identities nonzero."""
    G, values = PLANTS["damped mass"]
    wrong = fractional_zoh_pulse_transfer_function(G, 1 - eps, s=s, z=z, T=T)
    f = sp.lambdify((z,), wrong.subs({**values, T: 1e-3, eps: 0.25}), "mpmath")
    points = [np.exp(0.3j), 1.7]
    found = np.array([complex(f(point)) for point in points])
    expected = state_space_pulse(G, values, 1e-3, 0.25, points)
    assert not np.allclose(found, expected, rtol=1e-6)


def test_a_plant_with_a_direct_feedthrough_is_refused():
    with pytest.raises(ValueError, match="strictly proper"):
        fractional_zoh_pulse_transfer_function((s + 1) / (s + 2), eps, s=s, z=z, T=T)


#: A plant whose poles SymPy does not write (an irreducible cubic): the numeric path.
CUBIC = (1 / (m * s**3 + b * s**2 + k * s + 1), {m: 1e-4, b: 0.02, k: 3.0})


@pytest.mark.parametrize("name", [*PLANTS, "cubic"])
@pytest.mark.parametrize("fraction", [0.0, 0.5, 0.999])
def test_the_matrix_exponential_path_is_the_state_space_one(name, fraction):
    G, values = CUBIC if name == "cubic" else PLANTS[name]
    num, den = sp.fraction(sp.together(G.subs(values)))
    num, den = ([float(c) for c in sp.Poly(p, s).all_coeffs()] for p in (num, den))
    top, bottom = numeric_fractional_zoh(num, den, 1e-3, fraction)
    points = [np.exp(1j * theta) for theta in (0.01, 0.3, 1.0, 2.5, np.pi)] + [1.7, -0.4 + 0.2j]
    found = np.array([complex(np.polyval([complex(c) for c in top], p)
                              / np.polyval([complex(c) for c in bottom], p)) for p in points])
    expected = state_space_pulse(G, values, 1e-3, fraction, points)
    np.testing.assert_allclose(found, expected, rtol=1e-9, atol=1e-13 * abs(expected).max())


def test_no_fraction_on_the_numeric_path_is_the_integer_plant_times_z_over_z():
    top, bottom = numeric_fractional_zoh([1.0], [0.0128, 0.0324, 0.0], 1e-3, 0.0)
    num, den = numeric_zoh([1.0], [0.0128, 0.0324, 0.0], 1e-3)
    assert top == [*num, 0] and bottom == [*den, 0]


@pytest.mark.parametrize("num, den, fraction, needle", [
    ([1.0, 1.0], [1.0, 2.0], 0.5, "strictly proper"),
    ([1.0], [1.0, 2.0, 0.0], 1.0, "0 <= eps < 1"),
    ([1.0], [1.0, 2.0, 0.0], -0.1, "0 <= eps < 1"),
])
def test_bad_numeric_fractional_plants_are_refused(num, den, fraction, needle):
    with pytest.raises(ValueError, match=needle):
        numeric_fractional_zoh(num, den, 1e-3, fraction)
