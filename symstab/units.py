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

from ._validate import check_array, check_delay, check_delay_samples, check_real

__all__ = ["Device", "PAPER_DEVICE"]


@dataclasses.dataclass(frozen=True)
class Device:
    """A 1-DOF haptic device sampled every ``T`` seconds.

    Parameters
    ----------
    m : float
        Effective mass (kg, or kg m^2 for a rotary device), ``m > 0``.
    b : float
        Viscous friction (N s/m, or N m s/rad), ``b > 0``.
    T : float
        Sample period (s), ``T > 0``.

    Raises
    ------
    TypeError, ValueError
        For a non-real, non-finite or out-of-range parameter.

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
        object.__setattr__(self, "b", check_real("b", self.b, low=0.0, low_open=True))
        object.__setattr__(self, "T", check_real("T", self.T, low=0.0, low_open=True))

    @property
    def delta(self):
        """``b T / m``."""
        return self.b * self.T / self.m

    # physical -> dimensionless
    def delay_samples(self, Td):
        """``d = Td / T`` as an int; ``Td`` must be a whole number of samples."""
        Td = check_real("Td", Td, low=0.0)
        return check_delay_samples(Td / self.T, name="Td / T")

    def alpha(self, K_w):
        """``alpha = K_w T**2 / m`` for a stiffness ``K_w`` (N/m or N m/rad)."""
        return _as_float(check_array("K_w", K_w) * self.T**2 / self.m)

    def beta(self, B_w):
        """``beta = B_w T / m`` for a damping ``B_w`` (N s/m or N m s/rad)."""
        return _as_float(check_array("B_w", B_w) * self.T / self.m)

    def gamma(self, M_w):
        """``gamma = M_w / m`` for a virtual mass ``M_w`` (kg or kg m^2)."""
        return _as_float(check_array("M_w", M_w) / self.m)

    # dimensionless -> physical
    def delay(self, d):
        """``Td = d T`` (s)."""
        return check_delay(d) * self.T

    def stiffness(self, alpha):
        """``K_w = alpha m / T**2``."""
        return _as_float(check_array("alpha", alpha) * self.m / self.T**2)

    def damping(self, beta):
        """``B_w = beta m / T``."""
        return _as_float(check_array("beta", beta) * self.m / self.T)

    def mass(self, gamma):
        """``M_w = gamma m``."""
        return _as_float(check_array("gamma", gamma) * self.m)

    def units(self, rotary=True):
        """Unit strings of ``K_w, B_w, M_w`` (rotary: N m/rad, N m s/rad, kg m^2)."""
        if rotary:
            return {"K_w": "N m/rad", "B_w": "N m s/rad", "M_w": "kg m^2", "Td": "s"}
        return {"K_w": "N/m", "B_w": "N s/m", "M_w": "kg", "Td": "s"}


#: The paper's device (Sections IV and VI): m = 0.0128 kg m^2,
#: b = 0.0324 N m s/rad, T = 1 ms.
PAPER_DEVICE = Device(m=0.0128, b=0.0324, T=1e-3)


def _as_float(x):
    x = np.asarray(x, dtype=float)
    return float(x) if x.ndim == 0 else x
