"""The plant over one sample period, exactly: the simulator's step, derived.

The device ``m x'' + b x' = f`` in state form ``(x, v)`` is
``A = [[0, 1], [0, -b/m]]``, ``B = [0, 1/m]``.  Under a force held constant
over one period (the zero-order hold) the state advances exactly as

    (x, v)(k+1) = Phi (x, v)(k) + Gamma_u f(k),
    Phi = exp(A T),   Gamma_u = integral_0^T exp(A s) ds B,

computed here by SymPy's matrix exponential and integral.  In Table I's
units -- position as it is, ``v T`` for the velocity and ``f T**2 / m`` for
the force -- the step depends on ``delta`` alone; :func:`dimensionless_step`
returns it, and :mod:`symstab.codegen.float_forms` rewrites it with ``expm1`` for
floating point (proved equal by ``symstab derive``).
"""

import dataclasses
import functools

import sympy as sp

from . import model

__all__ = ["PlantStep", "exact_step", "dimensionless_step"]


@dataclasses.dataclass(frozen=True)
class PlantStep:
    """``state(k+1) = Phi state(k) + Gamma_u force(k)``."""

    Phi: sp.Matrix
    Gamma_u: sp.Matrix


@functools.lru_cache(maxsize=None)
def exact_step():
    """The exact one-period step of ``m x'' + b x' = f`` in physical units."""
    m, b, T = model.m, model.b, model.T
    A = sp.Matrix([[0, 1], [0, -b / m]])
    B = sp.Matrix([0, 1 / m])
    tau = sp.Symbol("tau", nonnegative=True)
    Phi = sp.simplify((A * T).exp())
    Gamma_u = sp.simplify(sp.integrate((A * tau).exp() * B, (tau, 0, T)))
    return PlantStep(Phi=Phi, Gamma_u=Gamma_u)


@functools.lru_cache(maxsize=None)
def dimensionless_step():
    """The step for the state ``(x, v T)`` and the force ``f T**2 / m``.

    Returns
    -------
    PlantStep
        Entries in ``delta`` and ``Gamma = exp(delta)`` only.
    """
    step = exact_step()
    scale = sp.diag(1, model.T)                     # (x, v) -> (x, v T)
    Phi = scale * step.Phi * scale.inv()
    Gamma_u = scale * step.Gamma_u * model.m / model.T**2
    sub = model.dimensionless_substitution()

    def clean(e):
        e = sp.simplify(sp.simplify(e.subs(sub)).rewrite(sp.exp))
        e = sp.simplify(e.subs(sp.exp(-model.delta), 1 / model.Gamma).subs(sp.exp(model.delta), model.Gamma))
        if e.has(model.m) or e.has(model.T):
            raise AssertionError(f"plant step did not become dimensionless: {e}")
        return e

    return PlantStep(Phi=Phi.applyfunc(clean), Gamma_u=Gamma_u.applyfunc(clean))
