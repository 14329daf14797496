"""The theory of the loop the paper's simulator runs: its linear part, a :class:`symstab.Loop`.

:func:`linear_theory` builds, for the non-idealities of a run of
:func:`symstab.numeric.paper.simulate.simulate`, the loop whose root count the run
is compared with: the velocity filter and the actuator lag are linear and
in it, exactly as the simulator has them; encoder quantization and friction
are not, and are named as left out.  A loop file's own simulation
(:meth:`symstab.Loop.simulate`) needs none: its theory is its own root count.
"""

import dataclasses
import functools
import math

import numpy as np

from ..._resources import chunk_slices
from ..._validate import check_array, check_box, check_loop, check_real, delay_samples
from ..simulation.simulator import Nonidealities

__all__ = ["LinearTheory", "linear_theory", "paper_simulated_loop", "fractional_start"]


#: The simulated loop's linear part as loop expressions, in physical units;
#: the paper's simulator runs these loops (in Table I's units).
#: The environment is the paper's force law with its velocity filter:
#: the damper and the mass act on the backward difference
#: ``(z - 1)/(T z)`` passed through the filter ``v_f[k] = a v_f[k-1] +
#: (1 - a) v[k]``, i.e. ``(1 - a) z/(z - a)`` with ``a = exp(-2 pi f_c T)``
#: (the environment of ``examples/loops/lowpass_velocity.toml``, with the mass
#: term differencing the filtered velocity as the simulator does).  The
#: actuator's first-order lag is part of the plant, ``tau = 1/(2 pi f_a)``.
_IDEAL_ENVIRONMENT = "K + B*(z - 1)/(T*z) + M*(z - 1)**2/(T**2*z**2)"
_FILTERED_ENVIRONMENT = ("K + (B + M*(z - 1)/(T*z))*(1 - exp(-2*pi*f_c*T))*(z - 1)"
                         "/(T*(z - exp(-2*pi*f_c*T)))")
#: The device, with and without viscous friction (b = 0 cancels a pole of
#: 1/(m s**2 + b s), so the frictionless plant is its own expression).
_PLANTS = {(False, False): "1/(m*s**2 + b*s)", (False, True): "1/(m*s**2)",
           (True, False): "1/((tau*s + 1)*(m*s**2 + b*s))", (True, True): "1/((tau*s + 1)*m*s**2)"}


@dataclasses.dataclass(frozen=True)
class LinearTheory:
    """The root-counting theory of the loop :func:`simulate` runs: its linear part.

    Built by :func:`linear_theory`.  Points are given as the simulator takes
    them (``alpha``, ``beta``; ``gamma`` and ``d`` are fixed here).  Without
    a velocity filter or an actuator lag, at a whole delay, the linear part
    is the paper's loop and the paper's functions answer
    (:func:`symstab.numeric.paper.stability.classify`, the boundary of
    :func:`~symstab.numeric.paper.paper_loop.paper_point`'s loop); with
    either, or at a fractional delay, a :class:`symstab.Loop` of the paper's
    plant (with the lag) and the environment on the filtered velocity, in
    the device's physical units (Table I's, ``m = T = 1``, without a
    device).

    Attributes
    ----------
    loop : symstab.Loop or None
        The linear loop (None: the paper's loop, answered in closed form).
    values : dict
        The loop's values besides its plane ``(B, K)`` (physical units).
    device : symstab.numeric.paper.device.Device or None
    gamma, d, delta
        The point's virtual mass ratio, delay (samples: an int, or a float
        with a fraction of a period) and ``b T / m``.
    label : str
        What the theory is of, e.g. "linear loop with the 100 Hz velocity filter".
    left_out : tuple of str
        The non-linear elements of the simulation the theory leaves out
        (encoder quantization, Coulomb friction, friction compensation).
    """

    loop: object
    values: dict
    device: object
    gamma: float
    d: object
    delta: float
    label: str
    left_out: tuple

    @property
    def description(self):
        """:attr:`label`, and when non-linear elements are on, that they are left out.

        For example "linear loop with the 50 Hz velocity filter; its linear
        part only: encoder quantization and Coulomb friction left out".
        """
        if not self.left_out:
            return self.label
        names = list(self.left_out)
        names = ", ".join(names[:-1]) + " and " + names[-1] if len(names) > 1 else names[0]
        return f"{self.label}; its linear part only: {names} left out"

    def _physical(self, alpha, beta):
        return {"K": np.asarray(self.device.stiffness(alpha), dtype=float),
                "B": np.asarray(self.device.damping(beta), dtype=float)}

    def classify(self, alpha, beta):
        """Stable (1), marginal (0) or unstable (-1) at each ``(alpha, beta)``, certified.

        Parameters
        ----------
        alpha, beta : float or array_like
            Broadcast together.

        Returns
        -------
        int or ndarray of int8
        """
        from .stability import classify

        if self.loop is None:
            return classify(alpha=alpha, beta=beta, gamma=self.gamma, d=self.d, delta=self.delta)
        alpha, beta = np.broadcast_arrays(check_array("alpha", alpha), check_array("beta", beta))
        if alpha.ndim == 0:
            return self.loop.classify(**self._physical(alpha, beta), **self.values)
        flat_alpha, flat_beta = alpha.ravel(), beta.ravel()
        out = np.empty(flat_alpha.size, dtype=np.int8)
        # A chunk at a time: a point's coefficients take 8 (d + 16) bytes.
        for part in chunk_slices(flat_alpha.size, 64 * (math.ceil(self.d) + 16)):
            out[part] = self.loop.classify(**self._physical(flat_alpha[part], flat_beta[part]),
                                           **self.values)
        return out.reshape(alpha.shape)

    def spectral_radius(self, alpha, beta):
        """Largest modulus of the closed-loop poles at one ``(alpha, beta)``.

        Parameters
        ----------
        alpha, beta : float

        Returns
        -------
        float
        """
        from .stability import spectral_radius

        if self.loop is None:
            return float(spectral_radius(alpha=alpha, beta=beta, gamma=self.gamma, d=self.d,
                                         delta=self.delta))
        return float(self.loop.spectral_radius(**self._physical(alpha, beta), **self.values))

    def boundary(self, window):
        """The theory's D-decomposition in the ``(beta, alpha)`` plane, to draw in ``window``.

        The loop's arc sampled for the window
        (:meth:`symstab.Loop.boundary`, :func:`~symstab.numeric.engine.decomposition.window_arc`)
        and its lines; the paper's loop, without a filter or a lag, is
        :func:`~symstab.numeric.paper.paper_loop.paper_point`'s, in Table I's
        variables.

        Parameters
        ----------
        window : ((float, float), (float, float))
            ``((beta0, beta1), (alpha0, alpha1))``.

        Returns
        -------
        (beta, alpha, lines)
            The arc's points (NaN between branches and far from the window)
            and the straight lines ``{"z = 1": (c0, c_beta, c_alpha), ...}``
            (``c0 + c_beta beta + c_alpha alpha = 0``).
        """
        (b0, b1), (a0, a1) = check_box("window", window, ("beta", "alpha"))
        if self.loop is None:
            from .paper_loop import paper_point

            loop, point = paper_point(gamma=self.gamma, d=self.d, delta=self.delta)
            curve = loop.boundary(x="B", y="K", window=((b0, b1), (a0, a1)), **point)
            return curve.x_values, curve.y_values, curve.lines
        dev = self.device
        # B = beta m / T and K = alpha m / T**2: the lines' slopes scale alike.
        sx, sy = dev.m / dev.T, dev.m / dev.T**2
        curve = self.loop.boundary(x="B", y="K", window=((b0 * sx, b1 * sx), (a0 * sy, a1 * sy)),
                                   **self.values)
        lines = {label: (c0, cb * sx, ck * sy) for label, (c0, cb, ck) in curve.lines.items()}
        return curve.x_values / sx, curve.y_values / sy, lines


def linear_theory(*, gamma, d, delta=None, device=None, nonideal=None):
    """The linear part of the loop :func:`simulate` runs, to compare a run with.

    The velocity filter and the actuator lag are linear: they are in the
    theory exactly as the simulator has them (the filter's difference
    equation is the simulator's; the lag is the continuous first-order lag,
    which the simulator steps exactly).  Encoder quantization, Coulomb friction and its
    compensation are not linear: they are left out and named in
    :attr:`LinearTheory.left_out`.

    Parameters
    ----------
    gamma, d, delta, device, nonideal
        As in :func:`simulate` (``delta`` may be None with a device).

    Returns
    -------
    LinearTheory

    Raises
    ------
    TypeError, ValueError
        As :func:`simulate` for the same arguments.

    Examples
    --------
    >>> from symstab import PAPER_DEVICE
    >>> theory = linear_theory(gamma=0.0, d=10, device=PAPER_DEVICE,
    ...                        nonideal=Nonidealities(velocity_cutoff=100.0))
    >>> theory.label
    'linear loop with the 100 Hz velocity filter'
    """
    from .device import Device

    nonideal = Nonidealities() if nonideal is None else nonideal
    if not isinstance(nonideal, Nonidealities):
        raise TypeError(f"nonideal must be a symstab.numeric.paper.simulate.Nonidealities or None, "
                        f"got {type(nonideal).__name__}")
    if device is not None and not isinstance(device, Device):
        raise TypeError(f"device must be a symstab.Device or None, got {type(device).__name__}")
    gamma = check_real("gamma", gamma)
    d = delay_samples(d)
    fractional_start(d, nonideal)
    if device is None:
        if not nonideal.ideal:
            raise ValueError("nonideal needs a device (physical units)")
        if delta is None:
            raise TypeError("delta must be a real number (or None with a device), got None")
        gamma, _, delta = check_loop(gamma, math.floor(d), delta)
    else:
        nonideal.check(device.T)
        delta = device.delta
    left_out = tuple(name for name, on in (
        ("encoder quantization", nonideal.encoder_resolution is not None),
        ("force quantization", nonideal.force_resolution is not None),
        ("force saturation", nonideal.force_limit is not None),
        ("Coulomb friction", nonideal.coulomb_friction is not None),
        ("friction compensation", nonideal.friction_compensation)) if on)
    filtered = nonideal.velocity_cutoff is not None
    lagged = nonideal.actuator_bandwidth is not None
    if not (filtered or lagged) and isinstance(d, int):
        return LinearTheory(None, {}, device, gamma, d, delta, "ideal loop", left_out)
    if device is None:
        # Table I's units: the loop's K, B, M are alpha, beta, gamma.
        device = Device(m=1.0, b=delta, T=1.0)
    parts = []
    if filtered:
        parts.append(f"the {nonideal.velocity_cutoff:g} Hz velocity filter")
    if lagged:
        parts.append(f"the {nonideal.actuator_bandwidth:g} Hz actuator lag")
    values = {"m": device.m, "T": device.T, "d": d, "M": float(device.mass(gamma))}
    if device.b != 0:
        values["b"] = device.b
    if filtered:
        values["f_c"] = float(nonideal.velocity_cutoff)
    if lagged:
        values["tau"] = 1.0 / (2 * math.pi * nonideal.actuator_bandwidth)
    loop = paper_simulated_loop(filtered, lagged, device.b == 0)
    return LinearTheory(loop, values, device, gamma, d, delta,
                        "linear loop with " + " and ".join(parts) if parts else "ideal loop",
                        left_out)


def fractional_start(d, nonideal):
    """Where a run of the paper's loop at the delay ``d`` starts: ``"state"``, or ``"samples"``.

    At a whole delay the device starts on its state space from ``(x0, v0 /
    T)``.  A fractional one (``d = 40.5``) is carried by the loop's
    fractional plant, whose difference equations start from the sampled
    history ``x0 - k v0`` (:meth:`symstab.Loop.simulate`'s ``start``): the
    same position and velocity, seen by the samples; Coulomb friction,
    which needs the state space, is refused there.

    Raises
    ------
    ValueError
        For Coulomb friction at a fractional delay.
    """
    if isinstance(d, int):
        return "state"
    if nonideal is not None and nonideal.coulomb_friction is not None:
        raise ValueError(f"nonideal.coulomb_friction is simulated at a whole delay only (the "
                         f"device on its state space), got d = {d!r} samples")
    return "samples"




@functools.lru_cache(maxsize=None)
def paper_simulated_loop(filtered, lagged, frictionless):
    """The paper's loop as the simulator runs it: a :class:`symstab.Loop`, derived once per process.

    The device (``frictionless``: ``b = 0``), behind its actuator lag
    (``lagged``, declared as the loop's actuator, so friction acts after
    it), with the environment on the filtered velocity (``filtered``).
    :func:`symstab.numeric.paper.simulate.simulate` runs it in Table I's units;
    :func:`linear_theory` counts its roots in physical ones.
    """
    from ..loop.sampled_loop import Loop

    return Loop(_PLANTS[lagged, frictionless],
                _FILTERED_ENVIRONMENT if filtered else _IDEAL_ENVIRONMENT,
                name="simulated_linear_part", plane=("B", "K"),
                actuator="1/(tau*s + 1)" if lagged else None)
