"""The paper's loop as a :class:`~symstab.Loop`: ``PAPER_LOOP``.

The plant ``G(s) = 1/(m s**2 + b s)`` and the environment of eq. (1),
``VE(z) = K + B (z - 1)/(T z) + M (z - 1)**2/(T**2 z**2)``, are those of
:mod:`symstab.symbolic.model` (with ``K_w, B_w, M_w`` named ``K, B, M``); the
device is :data:`~symstab.numeric.paper.device.PAPER_DEVICE` in its rotary units
(Section IV: kg m^2, N m s/rad), the delay the experiments' ``Td = 40 ms``
(``d = 40``) and the plane ``(B, K)``.  The paper's dimensionless functions
(:func:`symstab.limits`, :func:`symstab.classify`, ...) are this loop in
Table I's variables; ``PAPER_LOOP`` is the same loop in physical units, on
the same engine as any loop of the user's.

``PAPER_LOOP`` is built on first use (the derivation takes about a second),
not on ``import symstab``.
"""

import dataclasses
import functools

import numpy as np
import sympy as sp

from ..._generated import kernels
from ..._validate import check_loop, check_real
from ...symbolic import model
from ..engine.results import PAPER_PLANE
from .device import PAPER_DEVICE

__all__ = ["PAPER_LOOP",  # noqa: F822 (built on first use by __getattr__ below)
           "paper_loop", "PAPER_NAMES", "paper_point", "paper_arc", "closed_form_arc",
           "closed_form_polynomial", "paper_limits",
           "paper_passive_region", "paper_locus"]

#: Names of the environment's parameters in the loop: ``K_w, B_w, M_w`` of
#: the model are ``K, B, M`` (as in ``examples/loops/paper.toml``).
PAPER_NAMES = {"K_w": "K", "B_w": "B", "M_w": "M"}
#: The delay of the paper's experiments (Section VI), in samples of 1 ms.
_PAPER_DELAY = 40


def _environment():
    """Eq. (1)'s VE(z) with ``K_w, B_w, M_w`` named ``K, B, M`` (:data:`PAPER_NAMES`)."""
    rename = {getattr(model, name): sp.Symbol(new) for name, new in PAPER_NAMES.items()}
    return model.virtual_environment().subs(rename)


def closed_form_arc(x, y, values):
    """Eq. (7)'s arc in the plane ``(B, K)`` (either way round): ``theta -> (x, y)``.

    The generated kernel (``symstab._generated.kernels.boundary``) at
    ``gamma = M/m``, ``delta = b T/m``, scaled by ``K = alpha m/T**2``,
    ``B = beta m/T``.  It keeps its digits on the whole of (0, pi) (to
    about 2e-13 of the point's size, against the 50-digit solve of the
    printed model): next to theta = 0, where the loop's coefficients cancel
    (``z = 1`` is a root of the plant's denominator and of the
    environment's terms in B and M), and next to pi, where the sines of
    ``(d + 1) theta`` are taken of the exact product.

    Parameters
    ----------
    x, y : str
        The plane (``"B", "K"`` or ``"K", "B"``).
    values : dict
        ``m``, ``T``, ``d``, ``M`` and (but for the frictionless loop) ``b``.

    Returns
    -------
    callable or None
        ``theta -> (x, y)``; None for another plane.
    """
    if {x, y} != {"B", "K"}:
        return None
    m, T, d = float(values["m"]), float(values["T"]), int(values["d"])
    gamma, delta = float(values["M"]) / m, float(values.get("b", 0.0)) * T / m

    def arc(theta):
        theta = np.asarray(theta, dtype=float)
        alpha, beta = kernels.boundary(theta, gamma, d, delta)
        B, K = beta * (m / T), alpha * (m / T**2)
        return (B, K) if x == "B" else (K, B)

    return arc


def closed_form_polynomial(values, d):
    """Eq. (5)'s chi in Table I's variables: the roots of the paper's loop at ``values``.

    :func:`~symstab.numeric.paper.stability.paper_polynomial` at ``alpha = K T**2/m``,
    ``beta = B T/m``, ``gamma = M/m``, ``delta = b T/m`` (0 for the
    frictionless loop): the generated kernel, divided by ``delta**2
    exp(delta)``, exact next to ``z = 1`` and finite up to ``delta = 1e6``,
    which the loop's own coefficients are not (``exp(-b T/m)`` underflows).
    A value out of Table I's ranges is a ValueError in Table I's names.

    Parameters
    ----------
    values : dict of ndarray
        ``K, B, M, m, T`` and (but for the frictionless loop) ``b``, arrays
        that broadcast together.
    d : int
        The delay in samples.
    """
    from .stability import paper_polynomial

    m, T = values["m"], values["T"]
    with np.errstate(over="ignore", under="ignore"):
        table_one = dict(alpha=values["K"] * (T**2 / m), beta=values["B"] * (T / m),
                         gamma=values["M"] / m, delta=values.get("b", 0.0) * (T / m))
    try:
        return paper_polynomial(**table_one, d=d)
    except ValueError as exc:
        if np.all(m == 1.0) and np.all(T == 1.0):
            raise       # paper_point: the values are Table I's variables themselves
        raise ValueError(f"{exc} (the paper's loop in Table I's variables: alpha = K T^2/m, "
                         f"beta = B T/m, gamma = M/m, delta = b T/m)") from None


@functools.lru_cache(maxsize=1)
def paper_loop():
    """The paper's loop as a :class:`~symstab.Loop` (built once, then shared).

    Returns
    -------
    Loop
        Parameters ``B, K, M, b, m, T, d`` with the defaults of
        :data:`~symstab.numeric.paper.device.PAPER_DEVICE`, ``d = 40``, ``K = 2``,
        ``B = 0.1`` and ``M = 0``; rotary units; the plane ``(B, K)``.

    Examples
    --------
    >>> loop = paper_loop()
    >>> loop.plane, loop.units["K"]
    (('B', 'K'), 'N m/rad')
    """
    from ..loop.sampled_loop import Loop

    environment = _environment()
    device = PAPER_DEVICE
    units = device.units(rotary=True)
    return Loop(
        model.plant(), environment, name="paper", plane=("B", "K"),
        description="the paper's device and environment (Mashayekhi et al. 2025, eq. (1), Section IV)",
        values={"m": device.m, "b": device.b, "T": device.T, "d": _PAPER_DELAY,
                "K": 2.0, "B": 0.1, "M": 0.0},
        units={"m": "kg m^2", "b": "N m s/rad", "T": "s",
               "K": units["K_w"], "B": units["B_w"], "M": units["M_w"]},
        arc=closed_form_arc, polynomial=closed_form_polynomial)


@functools.lru_cache(maxsize=1)
def frictionless_paper_loop():
    """The paper's loop with ``b = 0``: plant ``1/(m s**2)`` (``delta = 0``).

    :class:`~symstab.Loop` refuses ``1/(m s**2 + b s)`` at ``b = 0`` (its
    pulse transfer function has a double pole at z = 1 there, not the
    limit of the simple ones), so the frictionless device is its own loop.
    """
    from ..loop.sampled_loop import Loop

    environment = _environment()
    return Loop(model.plant().subs(model.b, 0), environment, name="paper-frictionless",
                plane=("B", "K"), values={"m": 1.0, "T": 1.0, "d": 0, "K": 0.0, "B": 0.0, "M": 0.0},
                arc=closed_form_arc, polynomial=closed_form_polynomial)


def paper_point(*, gamma, d, delta):
    """The loop and values that are the paper's dimensionless point ``(gamma, d, delta)``.

    With ``m = T = 1`` Table I's variables are the loop's own parameters:
    ``alpha = K T**2/m = K``, ``beta = B T/m = B``, ``gamma = M/m = M`` and
    ``delta = b T/m = b``; the plane ``(B, K)`` is the paper's
    ``(beta, alpha)``.

    Returns
    -------
    (Loop, dict)
        :func:`paper_loop` (or :func:`frictionless_paper_loop` at
        ``delta = 0``) and the values of its parameters other than ``B, K``.
    """
    gamma, d, delta = check_loop(gamma, d, delta)
    if delta == 0:
        return frictionless_paper_loop(), {"m": 1.0, "T": 1.0, "M": gamma, "d": d}
    return paper_loop(), {"m": 1.0, "T": 1.0, "b": delta, "M": gamma, "d": d}


def paper_arc(*, gamma, d, delta):
    """The paper's arc in Table I's plane: ``source(theta) -> (beta, alpha, det)``.

    :meth:`Loop.arc <symstab.Loop.arc>` of :func:`paper_point`'s loop in
    the plane ``(B, K) = (beta, alpha)``: eq. (7)'s closed form (the
    generated kernel, :func:`closed_form_arc`), with the determinant's sign
    from the loop's Cramer solve.

    Examples
    --------
    >>> beta, alpha, det = paper_arc(gamma=0.0, d=0, delta=0.00253125)(np.array([1.0]))
    >>> bool(alpha[0] > 0)
    True
    """
    loop, values = paper_point(gamma=gamma, d=d, delta=delta)
    return loop.arc("B", "K", **values)


def paper_limits(*, gamma, d, delta):
    """:meth:`Loop.limits <symstab.Loop.limits>` of the paper's loop, in Table I's plane.

    The limits of the ``(B, K)`` plane of :func:`paper_point`, renamed
    ``(beta, alpha)``, with ``at`` the paper's ``gamma, d, delta``, so
    Table I's names apply.

    Examples
    --------
    >>> lim = paper_limits(gamma=0.0, d=0, delta=0.00253125)
    >>> round(lim.alpha_max, 4), round(lim.beta_right, 4)
    (0.6897, 2.0034)
    """
    loop, values = paper_point(gamma=gamma, d=d, delta=delta)
    found = loop.limits("B", "K", **values)
    return dataclasses.replace(found, x=PAPER_PLANE[0], y=PAPER_PLANE[1],
                               at={"gamma": values["M"], "d": values["d"], "delta": float(delta)})


def paper_passive_region(*, gamma, d, delta, x_range=None, y_range=None):
    """The passive set of the paper's loop in the ``(beta, alpha)`` plane.

    In Table I's units (``alpha = K_w T**2 / m``, ``beta = B_w T / m``,
    ``gamma = M_w / m``, ``delta = b T / m``) Colgate and Schenkel's
    condition (:mod:`symstab.numeric.analysis.passivity`) multiplied by ``T / m`` reads

        delta > 1/(2 (1 - cos theta)) Re{(1 - e^{-j theta}) h(theta) e^{-j theta d}}

    with ``h = alpha + beta (1 - e^{-j theta}) + gamma (1 - e^{-j theta})**2``
    (``T**2 VE / m``), for ``theta`` in [0, pi]; and ``alpha >= 0`` (no
    negative static stiffness).  That is :meth:`Loop.passive_region
    <symstab.Loop.passive_region>` of :func:`paper_point`'s loop and values,
    with the plane's names changed.

    Parameters
    ----------
    gamma : float
        ``M_w / m``.
    d : int
        Delay in samples.
    delta : float
        ``b T / m``, > 0 (with no damping the passive set has no interior).
    x_range, y_range : (float, float), optional
        The window of beta and alpha; by default the polygon's bounding box
        with a 5 % margin (an unbounded set: its finite vertices' box grown
        by its own size).

    Returns
    -------
    symstab.numeric.analysis.passivity.PassiveRegion
        ``x = "beta"``, ``y = "alpha"``; ``y_max`` is the passive
        ``alpha_max``.

    Raises
    ------
    TypeError, ValueError
        If a parameter is of the wrong kind or out of range.

    Examples
    --------
    >>> r = paper_passive_region(gamma=0.0, d=0, delta=0.002)
    >>> round(r.y_max, 12), round(r.area, 12)     # alpha <= 2 delta, |beta| <= delta
    (0.004, 8e-06)
    """
    gamma, d, delta = check_loop(gamma, d, delta)
    if delta <= 0:
        raise ValueError(f"delta must be > 0 for a passive set with an interior, got {delta!r}")
    loop, values = paper_point(gamma=gamma, d=d, delta=delta)
    found = loop.passive_region("B", "K", x_range=x_range, y_range=y_range, **values)
    return found.renamed(*PAPER_PLANE)


#: The paper's locus paths, and the loop parameter each is (with ``m = T = 1``).
_PAPER_PATHS = {"alpha": "K", "beta": "B"}


def paper_locus(*, parameter, values, gamma, d, delta, alpha=None, beta=None):
    """The closed-loop poles of the paper's loop along a line of the (beta, alpha) plane.

    :func:`~symstab.numeric.engine.locus.locus` of :func:`paper_point`'s loop along
    ``K`` (alpha) or ``B`` (beta), with the path and the fixed values named
    in Table I's variables.

    Parameters
    ----------
    parameter : {"alpha", "beta"}
        The parameter that varies.
    values : array_like, shape (n,)
        Its values, ``n >= 2``, strictly increasing or strictly decreasing.
    gamma : float
        ``M_w / m``.
    d : int
        Delay in samples.
    delta : float
        ``b T / m``.
    alpha, beta : float, optional
        The fixed one of the two (the other is ``parameter``).

    Returns
    -------
    symstab.numeric.engine.locus.Locus
        ``fixed`` holds the other of alpha, beta and gamma, d, delta.

    Raises
    ------
    TypeError, ValueError
        For an out-of-range value, a missing or doubly given parameter, or
        a locus that would not fit in the memory limit.

    Examples
    --------
    >>> path = paper_locus(parameter="alpha", values=[0.0001, 0.001], beta=0.0078,
    ...                    gamma=0.0, d=40, delta=0.0025)
    >>> [(c.kind, c.direction) for c in path.crossings]
    [('pair', 'out')]
    """
    from ..engine.locus import check_path, locus

    if parameter not in _PAPER_PATHS:
        raise ValueError(f"parameter must be 'alpha' or 'beta', got {parameter!r}")
    other = "beta" if parameter == "alpha" else "alpha"
    given = {"alpha": alpha, "beta": beta}
    if given[parameter] is not None:
        raise ValueError(f"{parameter} is the path's parameter: give its values as values, "
                         f"not as {parameter}=")
    if given[other] is None:
        raise TypeError(f"paper_locus along {parameter} needs the fixed {other}=")
    fixed_value = check_real(other, given[other])
    values = check_path(parameter, values)      # errors name alpha or beta, not K or B
    loop, point = paper_point(gamma=gamma, d=d, delta=delta)
    found = locus(loop, _PAPER_PATHS[parameter], values, **point, **{_PAPER_PATHS[other]: fixed_value})
    fixed = {other: fixed_value, "gamma": point["M"], "d": point["d"], "delta": float(delta)}
    return dataclasses.replace(found, parameter=parameter, fixed=fixed)


def __getattr__(name):
    if name == "PAPER_LOOP":
        return paper_loop()
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
