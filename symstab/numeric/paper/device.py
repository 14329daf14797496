"""Physical and dimensionless units: the :class:`Device` value.

Table I of the paper::

    delta = b T / m      alpha = K_w T**2 / m     beta = B_w T / m
    gamma = M_w / m      d = Td / T               Gamma = exp(delta)

A :class:`Device` holds the three parameters of the hardware (m, b, T) and
converts the virtual environment (K_w, B_w, M_w) and the loop delay Td both
ways.  Every conversion accepts scalars or arrays.
"""

import dataclasses

import numpy as np

from ..._validate import (
    check_array,
    check_delay_samples,
    check_delta,
    check_real,
    delay_samples,
)

__all__ = ["Device", "PAPER_DEVICE"]


@dataclasses.dataclass(frozen=True)
class Device:
    """A 1-DOF haptic device sampled every ``T`` seconds.

    Parameters
    ----------
    m : float
        Effective mass (kg, or kg m^2 for a rotary device), ``m > 0``.
    b : float
        Viscous friction (N s/m, or N m s/rad), ``b >= 0``; 0 is a
        frictionless (or friction-compensated) device.
    T : float
        Sample period (s), ``T > 0``.

    Raises
    ------
    TypeError, ValueError
        For a non-real, non-finite or out-of-range parameter, or a device
        whose ``delta = b T / m`` is above ``DELTA_MAX`` (1e6).  A conversion
        whose result overflows (or a nonzero one that underflows to 0)
        raises :class:`ValueError` naming the quantity.

    Examples
    --------
    >>> dev = Device(m=0.0128, b=0.0324, T=1e-3)
    >>> round(dev.delta, 8), dev.delay_samples(Td=40e-3)
    (0.00253125, 40)
    >>> round(float(dev.stiffness(alpha=0.1)), 6)
    1280.0
    """

    m: float
    b: float
    T: float

    def __post_init__(self):
        object.__setattr__(self, "m", check_real("m", self.m, low=0.0, low_open=True))
        object.__setattr__(self, "b", check_real("b", self.b, low=0.0))
        object.__setattr__(self, "T", check_real("T", self.T, low=0.0, low_open=True))
        check_delta(float(_converted("delta = b T / m", self.b, lambda: self.b * self.T / self.m)),
                    name="delta = b T / m")

    @property
    def delta(self):
        """``b T / m``."""
        return self.b * self.T / self.m

    # physical -> dimensionless
    def delay_samples(self, Td):
        """``d = Td / T`` as an int.

        Parameters
        ----------
        Td : float
            Loop delay (s), a whole number of sample periods.
        """
        Td = check_real("Td", Td, low=0.0)
        return check_delay_samples(Td / self.T, name="Td / T")

    def alpha(self, K_w):
        """``alpha = K_w T**2 / m``.

        Parameters
        ----------
        K_w : float or array_like
            Virtual stiffness (N/m or N m/rad).
        """
        K_w = check_array("K_w", K_w)
        return _as_float(_converted("alpha = K_w T^2 / m", K_w, lambda: K_w * (self.T / self.m) * self.T))

    def beta(self, B_w):
        """``beta = B_w T / m``.

        Parameters
        ----------
        B_w : float or array_like
            Virtual damping (N s/m or N m s/rad).
        """
        B_w = check_array("B_w", B_w)
        return _as_float(_converted("beta = B_w T / m", B_w, lambda: B_w * (self.T / self.m)))

    def gamma(self, M_w):
        """``gamma = M_w / m``.

        Parameters
        ----------
        M_w : float or array_like
            Virtual virtual mass (kg or kg m^2).
        """
        M_w = check_array("M_w", M_w)
        return _as_float(_converted("gamma = M_w / m", M_w, lambda: M_w / self.m))

    # dimensionless -> physical
    def delay(self, d):
        """``Td = d T`` (s).

        Parameters
        ----------
        d : int or float
            Delay in samples (a fraction of a period too: ``40.5``).
        """
        return delay_samples(d) * self.T

    def stiffness(self, alpha):
        """``K_w = alpha m / T**2``.

        Parameters
        ----------
        alpha : float or array_like
            The dimensionless value (Table I).
        """
        alpha = check_array("alpha", alpha)
        return _as_float(_converted("K_w = alpha m / T^2", alpha, lambda: alpha * (self.m / self.T) / self.T))

    def damping(self, beta):
        """``B_w = beta m / T``.

        Parameters
        ----------
        beta : float or array_like
            The dimensionless value (Table I).
        """
        beta = check_array("beta", beta)
        return _as_float(_converted("B_w = beta m / T", beta, lambda: beta * (self.m / self.T)))

    def mass(self, gamma):
        """``M_w = gamma m``.

        Parameters
        ----------
        gamma : float or array_like
            The dimensionless value (Table I).
        """
        gamma = check_array("gamma", gamma)
        return _as_float(_converted("M_w = gamma m", gamma, lambda: gamma * self.m))

    def units(self, rotary=True):
        """Unit strings of ``K_w, B_w, M_w`` and ``Td``.

        Parameters
        ----------
        rotary : bool
            Rotary units (N m/rad, N m s/rad, kg m^2), else linear (N/m,
            N s/m, kg).
        """
        if rotary:
            return {"K_w": "N m/rad", "B_w": "N m s/rad", "M_w": "kg m^2", "Td": "s"}
        return {"K_w": "N/m", "B_w": "N s/m", "M_w": "kg", "Td": "s"}


def _converted(what, given, compute):
    """``compute()``, a unit conversion, or ValueError if it overflows or underflows.

    ``given`` is the input it was converted from: a nonzero input whose
    result is 0 (underflow) or whose result is not finite (overflow) cannot
    be represented.
    """
    with np.errstate(all="ignore"):
        given, result = np.asarray(given, dtype=float), np.asarray(compute(), dtype=float)
        bad = ~np.isfinite(result) | ((result == 0) & (given != 0))
    if np.any(bad):
        raise ValueError(f"{what} is not representable as a float for this device "
                         f"(m, b, T) and input: it overflows or underflows; "
                         f"use units in which the values are nearer 1")
    return result


def _as_float(x):
    x = np.asarray(x, dtype=float)
    return float(x) if x.ndim == 0 else x


#: The paper's device (Sections IV and VI): m = 0.0128 kg m^2,
#: b = 0.0324 N m s/rad, T = 1 ms.
PAPER_DEVICE = Device(m=0.0128, b=0.0324, T=1e-3)
