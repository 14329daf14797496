"""What a stable point costs: the force noise of the position sensor's quantization.

A haptic loop reads its position through an encoder of resolution ``q``: the
sampled position is ``x + e`` with ``e`` the rounding error, uniform on
``[-q/2, q/2]`` and, while the device moves across many counts a sample,
white with variance ``q**2 / 12`` (the classical quantization-noise model;
at rest it is neither).  The force the environment renders is ``F = VE
z**-d (x + e)`` and the device moves by ``x = -P F``, so the error reaches
the force through the closed loop::

    F_e = VE z**-d / (1 + L) e,    |VE z**-d / (1 + L)| = |Ve_n P_d / chi|

on the unit circle (``chi`` the loop's characteristic polynomial), and its
RMS is ``sigma_F = (q / sqrt(12)) ||Ve_n P_d / chi||_2``.  The H2 norm is
exact, not a truncated impulse response: ``sum h[k]**2`` by Åström's
recursion on the coefficients (:func:`h2_norm`).  Beside it, the environment's own ``||VE||_2``
(what the same noise would give with the device held still: the open loop),
infinite for an environment with a pole on the unit circle.

A higher velocity-filter cut-off raises K_max (the stable set grows) and the
force noise: :func:`force_noise` is the cost side of that trade-off.
"""

import dataclasses
import math

import numpy as np

from ..._resources import check_memory
from ..._validate import check_real

__all__ = ["ForceNoise", "force_noise", "force_noise_rms", "h2_norm", "H2_MAX_DEGREE"]


@dataclasses.dataclass(frozen=True)
class ForceNoise:
    """The force noise of the encoder's quantization at a stable point.

    Made by :func:`symstab.numeric.analysis.noise.force_noise`.

    Attributes
    ----------
    point : dict
        The parameters' values.
    encoder_resolution : float
        ``q``, in the position's unit.
    sensor_rms : float
        ``q / sqrt(12)``, the RMS of the rounding error.
    closed_loop_gain : float
        ``||VE z**-d / (1 + L)||_2``: the force RMS per unit RMS of sensor noise.
    open_loop_gain : float
        ``||VE||_2`` (inf for an environment with a pole on the circle).
    rms : float
        The force RMS, ``sensor_rms * closed_loop_gain`` (the force's unit).
    open_loop_rms : float
        ``sensor_rms * open_loop_gain``.
    """

    point: dict
    encoder_resolution: float
    sensor_rms: float
    closed_loop_gain: float
    open_loop_gain: float
    rms: float
    open_loop_rms: float

    def __repr__(self):
        return (f"ForceNoise(rms {self.rms:.6g} with an encoder of {self.encoder_resolution:.6g} "
                f"(closed-loop gain {self.closed_loop_gain:.6g}; the environment alone "
                f"{self.open_loop_rms:.6g}))")


#: The highest degree of an H2 norm: the Lyapunov equation is O(n**3) (21 s and
#: 0.6 GB at degree 2000 measured; 5 min and 1.8 GB at 4000).
H2_MAX_DEGREE = 2000


def h2_norm(num, den, *, stable=False):
    """``sqrt(sum h[k]**2)`` of a stable, proper discrete transfer function ``num / den``.

    By Åström's recursion for the integral of ``|num / den|**2`` on the unit
    circle (K. J. Åström, E. I. Jury and R. G. Agniel, "A numerical method
    for the evaluation of complex integrals", IEEE Trans. Automatic Control
    15(4), 1970; Åström, *Introduction to Stochastic Control Theory*, 1970,
    ch. 5): the Schur-Cohn reduction of ``den`` carries ``num`` along, and
    the sum of squares is ``sum_k beta_k b_k / a_0`` over its steps.  It
    works on the coefficients themselves, in O(n**2): a Lyapunov equation on
    the companion form of a loop's ``chi``, whose roots crowd next to
    ``z = 1``, lost seven digits where this loses none (the lowpass loop's
    closed-loop gain: 1e-7 against mpmath's 40-digit impulse response, this
    1e-13).

    Parameters
    ----------
    num, den : array_like
        Coefficients, highest power first, ``len(num) <= len(den)``.
    stable : bool
        ``den`` is known to have its roots inside the unit circle (a certified
        verdict): its roots are not computed again.

    Returns
    -------
    float
        Exact up to rounding; inf where ``den`` has a root on or outside the
        unit circle.

    Raises
    ------
    ValueError
        Above degree :data:`H2_MAX_DEGREE` (the delay in samples, for a
        loop), or a transfer function that is not proper.

    Examples
    --------
    >>> round(h2_norm([1.0, 0.0], [1.0, -0.5]), 12)   # h[k] = 0.5**k: sum 1 / (1 - 0.25)
    1.154700538379
    """
    num, den = np.trim_zeros(np.asarray(num, float), "f"), np.trim_zeros(np.asarray(den, float), "f")
    if len(num) > len(den):
        raise ValueError("h2_norm needs a proper transfer function (deg num <= deg den)")
    if len(den) == 1:
        return abs(float(num[-1] / den[0])) if len(num) else 0.0
    if len(den) - 1 > H2_MAX_DEGREE:
        raise ValueError(f"the H2 norm of degree {len(den) - 1} is beyond {H2_MAX_DEGREE} (its "
                         f"recursion is O(n**2) in Python steps of O(n)): use a shorter delay")
    check_memory(f"the H2 norm of degree {len(den) - 1}", 64 * len(den))
    if not stable and np.max(np.abs(np.roots(den))) >= 1:
        return math.inf
    a = den / den[0]
    b = np.concatenate([np.zeros(len(a) - len(num)), num / den[0]])
    total = 0.0
    for k in range(len(a) - 1, 0, -1):
        alpha, beta = a[k] / a[0], b[k] / a[0]
        total += beta * b[k]
        reflected = a[k:0:-1]
        a, b = a[:k] - alpha * reflected, b[:k] - beta * reflected
        if not a[0] > 0:
            # The Schur-Cohn test fails: a root on or outside the circle after all.
            return math.inf
    total += b[0] * b[0] / a[0]
    return float(math.sqrt(max(0.0, total)))


def force_noise(loop, *, encoder_resolution, **values):
    """The RMS force that the encoder's quantization error renders at a stable point.

    Parameters
    ----------
    loop : symstab.Loop
        The loop.
    encoder_resolution : float
        The position quantum ``q`` (the position's unit, m or rad), > 0.
    **values
        A single value of every parameter (or its default), ``d`` included.

    Returns
    -------
    ForceNoise

    Raises
    ------
    ValueError
        At a point that is not stable, or for a resolution that is not a
        positive number.

    Examples
    --------
    >>> from symstab import Loop
    >>> loop = Loop("1/(m*s**2 + b*s)", "K + B*(z - 1)/(T*z)",
    ...             values=dict(m=0.0128, b=0.0324, T=1e-3, d=0, K=100.0, B=1.0))
    >>> found = force_noise(loop, encoder_resolution=2 * 3.141592653589793 / 16384)
    >>> round(found.rms, 4), round(found.open_loop_rms, 4)
    (0.1683, 0.1646)
    """
    from .margins import stable_point

    q = check_real("encoder_resolution", encoder_resolution, low=0.0, low_open=True)
    point = stable_point(loop, values, "the force noise")
    num, chi, ve_n, ve_d = loop.evaluation.noise_path(point)
    sensor = q / math.sqrt(12.0)
    closed, open_ = h2_norm(num, chi, stable=True), h2_norm(ve_n, ve_d)
    return ForceNoise(point=point, encoder_resolution=q, sensor_rms=sensor,
                      closed_loop_gain=closed, open_loop_gain=open_, rms=sensor * closed,
                      open_loop_rms=sensor * open_)


def force_noise_rms(loop, encoder_resolution, values):
    """:attr:`ForceNoise.rms` at a point, ``inf`` where the loop is not stable there.

    The measure of a noise budget (:func:`symstab.numeric.analysis.design.design`
    with ``noise_limit``): a rendered point that is unstable or marginal
    has no bounded force noise, so it meets no budget.  Only the closed
    loop's norm is computed.

    Parameters
    ----------
    loop : symstab.Loop
    encoder_resolution : float
        ``q`` (checked by the caller), > 0.
    values : dict
        A single value of every parameter (or its default).

    Returns
    -------
    float
    """
    from ..engine.roots import STABLE
    from .margins import classified_point

    point, code = classified_point(loop, values)
    if code != STABLE:
        return math.inf
    num, chi, _, _ = loop.evaluation.noise_path(point)
    return encoder_resolution / math.sqrt(12.0) * h2_norm(num, chi, stable=True)
