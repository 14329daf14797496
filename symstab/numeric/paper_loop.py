"""The paper's loop as a :class:`~symstab.Loop`: ``PAPER_LOOP``.

The plant ``G(s) = 1/(m s**2 + b s)`` and the environment of eq. (1),
``VE(z) = K + B (z - 1)/(T z) + M (z - 1)**2/(T**2 z**2)``, are those of
:mod:`symstab.symbolic.model` (with ``K_w, B_w, M_w`` named ``K, B, M``); the
device is :data:`~symstab.numeric.units.PAPER_DEVICE` in its rotary units
(Section IV: kg m^2, N m s/rad), the delay the experiments' ``Td = 40 ms``
(``d = 40``) and the plane ``(B, K)``.  The paper's dimensionless functions
(:func:`symstab.limits`, :func:`symstab.classify`, ...) are this loop in
Table I's variables; ``PAPER_LOOP`` is the same loop in physical units, on
the same engine as any loop of the user's.

``PAPER_LOOP`` is built on first use (the derivation takes about a second),
not on ``import symstab``.
"""

import functools

import sympy as sp

from ..symbolic import model
from .units import PAPER_DEVICE

__all__ = ["PAPER_LOOP", "paper_loop", "PAPER_NAMES"]

#: Names of the environment's parameters in the loop: ``K_w, B_w, M_w`` of
#: the model are ``K, B, M`` (as in ``examples/loops/paper.toml``).
PAPER_NAMES = {"K_w": "K", "B_w": "B", "M_w": "M"}
#: The delay of the paper's experiments (Section VI), in samples of 1 ms.
_PAPER_DELAY = 40


@functools.lru_cache(maxsize=1)
def paper_loop():
    """The paper's loop as a :class:`~symstab.Loop` (built once, then shared).

    Returns
    -------
    Loop
        Parameters ``B, K, M, b, m, T, d`` with the defaults of
        :data:`~symstab.numeric.units.PAPER_DEVICE`, ``d = 40``, ``K = 2``,
        ``B = 0.1`` and ``M = 0``; rotary units; the plane ``(B, K)``.

    Examples
    --------
    >>> loop = paper_loop()
    >>> loop.plane, loop.units["K"]
    (('B', 'K'), 'N m/rad')
    """
    from .any_loop import Loop

    rename = {getattr(model, name): sp.Symbol(new) for name, new in PAPER_NAMES.items()}
    environment = model.virtual_environment().subs(rename)
    device = PAPER_DEVICE
    units = device.units(rotary=True)
    return Loop(
        model.plant(), environment, name="paper", plane=("B", "K"),
        description="the paper's device and environment (Mashayekhi et al. 2025, eq. (1), Section IV)",
        values={"m": device.m, "b": device.b, "T": device.T, "d": _PAPER_DELAY,
                "K": 2.0, "B": 0.1, "M": 0.0},
        units={"m": "kg m^2", "b": "N m s/rad", "T": "s",
               "K": units["K_w"], "B": units["B_w"], "M": units["M_w"]})


def __getattr__(name):
    if name == "PAPER_LOOP":
        return paper_loop()
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
