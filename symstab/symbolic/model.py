"""The haptic loop as SymPy objects: one definition of every symbol and block.

The device is a mass ``m`` with viscous friction ``b``, G(s) = 1/(m s^2 + b s).
Its position is sampled every ``T`` seconds, fed to the discrete virtual
environment VE(z) of the paper's eq. (1), and the resulting force waits
``d`` samples (Td = d T) before a zero-order hold applies it to the device.

Everything else in :mod:`symstab` builds on the objects defined here; no other
module creates these symbols.  Table I of the paper maps the physical
parameters to dimensionless ones::

    delta = b T / m      alpha = K_w T^2 / m     beta = B_w T / m
    gamma = M_w / m      d = Td / T              Gamma = exp(delta)

``Gamma`` is kept as a symbol of its own: delta and exp(delta) are
algebraically independent, so an identity that holds with ``Gamma`` free holds
a fortiori with ``Gamma = exp(delta)``, and polynomial work stays polynomial.
"""

import sympy as sp

__all__ = [
    "s", "z", "theta",
    "m", "b", "T", "Td", "K_w", "B_w", "M_w",
    "alpha", "beta", "gamma", "delta", "Gamma", "d",
    "plant", "zero_order_hold", "virtual_environment",
    "dimensionless_substitution", "dimensionless_values",
]

# Transform variables.
s = sp.Symbol("s")
z = sp.Symbol("z")
#: Angle on the unit circle, z = exp(j theta).
theta = sp.Symbol("theta", real=True)

# Physical parameters (SI units; rotational devices use kg m^2 and N m s/rad).
m = sp.Symbol("m", positive=True)
b = sp.Symbol("b", positive=True)
T = sp.Symbol("T", positive=True)
Td = sp.Symbol("T_d", nonnegative=True)
K_w = sp.Symbol("K_w", real=True)
B_w = sp.Symbol("B_w", real=True)
M_w = sp.Symbol("M_w", real=True)

# Dimensionless parameters of Table I.
alpha = sp.Symbol("alpha", real=True)
beta = sp.Symbol("beta", real=True)
gamma = sp.Symbol("gamma", real=True)
delta = sp.Symbol("delta", positive=True)
Gamma = sp.Symbol("Gamma", positive=True)
#: Loop delay in samples, Td = d T.
d = sp.Symbol("d", integer=True, nonnegative=True)


def plant():
    """Return the device transfer function G(s) = 1 / (m s^2 + b s)."""
    return 1 / (m * s**2 + b * s)


def zero_order_hold():
    """Return the zero-order hold (1 - exp(-T s)) / s."""
    return (1 - sp.exp(-T * s)) / s


def virtual_environment():
    """Return VE(z) of eq. (1): spring, backward-difference damper and mass.

    ``VE(z) = K_w + B_w (z - 1)/(T z) + M_w (z - 1)^2/(T^2 z^2)``.
    """
    return K_w + B_w * (z - 1) / (T * z) + M_w * (z - 1) ** 2 / (T**2 * z**2)


def dimensionless_substitution():
    """Return the substitution that writes physical symbols in Table I's terms.

    Applying it to an expression in ``b, K_w, B_w, M_w, T_d`` leaves an
    expression in ``delta, alpha, beta, gamma, d`` (and ``m, T`` where they
    do not cancel).
    """
    return {
        b: delta * m / T,
        K_w: alpha * m / T**2,
        B_w: beta * m / T,
        M_w: gamma * m,
        Td: d * T,
    }


def dimensionless_values(*, m, b, T, K_w=0.0, B_w=0.0, M_w=0.0, Td=0.0):
    """Map physical parameter values to Table I's dimensionless values.

    Parameters
    ----------
    m : float
        Effective mass (kg, or kg m^2 for a rotary device), ``m > 0``.
    b : float
        Viscous friction (N s/m or N m s/rad), ``b >= 0``.
    T : float
        Sample period (s), ``T > 0``.
    K_w, B_w, M_w : float, optional
        Virtual stiffness, damping and mass (any finite real).
    Td : float, optional
        Loop delay (s); must be a whole number of sample periods.

    Returns
    -------
    dict
        Keys ``alpha, beta, gamma, delta, d`` (``d`` an ``int``).

    Raises
    ------
    ValueError
        If a parameter is out of range, not finite, or ``Td / T`` is not a
        non-negative integer.

    Examples
    --------
    >>> v = dimensionless_values(m=0.0128, b=0.0324, T=1e-3, Td=40e-3)
    >>> round(v["delta"], 6), v["d"]
    (0.002531, 40)
    """
    from .._validate import check_delay_samples, check_real

    m = check_real("m", m, low=0.0, low_open=True)
    b = check_real("b", b, low=0.0)
    T = check_real("T", T, low=0.0, low_open=True)
    K_w = check_real("K_w", K_w)
    B_w = check_real("B_w", B_w)
    M_w = check_real("M_w", M_w)
    Td = check_real("Td", Td, low=0.0)
    return {
        "alpha": K_w * T**2 / m,
        "beta": B_w * T / m,
        "gamma": M_w / m,
        "delta": b * T / m,
        "d": check_delay_samples(Td / T, name="Td / T"),
    }
