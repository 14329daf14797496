"""Tests of symstab.symbolic.unit_circle: chi(exp(j theta)) split into Re and Im."""

import functools

import mpmath
import numpy as np
import pytest
import sympy as sp

from symstab.symbolic import model
from symstab.symbolic.unit_circle import on_unit_circle, unit_circle_split

from conftest import assert_rel_close
from oracles import chi_mp, delta_of_z, loop_coefficients_mp

ARGS = (model.theta, model.alpha, model.beta, model.gamma, model.d, model.delta, model.Gamma)


@functools.lru_cache(maxsize=None)
def _split_functions():
    real, imag = unit_circle_split()
    return (sp.lambdify(ARGS, real, modules="mpmath"), sp.lambdify(ARGS, imag, modules="mpmath"),
            sp.lambdify(ARGS, on_unit_circle(), modules="mpmath"))


def _points(seed, n):
    rng = np.random.default_rng(seed)
    return [dict(theta=rng.uniform(-3.1, 3.1), alpha=rng.uniform(-1, 5), beta=rng.uniform(-2, 3),
                 gamma=rng.uniform(-0.9, 2.5), d=int(rng.integers(0, 13)),
                 delta=10 ** rng.uniform(-4, 0)) for _ in range(n)]


POINTS = _points(7, 20)


def _evaluate(point):
    f_re, f_im, f_on = _split_functions()
    p = {k: (v if k == "d" else mpmath.mpf(v)) for k, v in point.items()}
    args = (p["theta"], p["alpha"], p["beta"], p["gamma"], p["d"], p["delta"], mpmath.exp(p["delta"]))
    return p, f_re(*args), f_im(*args), f_on(*args)


@pytest.mark.parametrize("point", POINTS)
def test_split_is_chi_at_exp_j_theta(point):
    with mpmath.workdps(40):
        p, re, im, on = _evaluate(point)
        coeffs = loop_coefficients_mp(**{k: p[k] for k in ("alpha", "beta", "gamma", "d", "delta")})
        chi, size = chi_mp(mpmath.expj(p["theta"]), coeffs)
        tol = mpmath.mpf(10) ** -32 * size
        assert abs(mpmath.mpc(re, im) - chi) <= tol
        assert abs(on - chi) <= tol


@pytest.mark.parametrize("point", POINTS[:8])
def test_split_is_eq2_cleared_of_denominators(point):
    """Re + j Im = Gamma delta^2 (z - 1)(z - 1/Gamma) z^(d+2) Delta(z) on the circle."""
    with mpmath.workdps(40):
        p, re, im, _ = _evaluate(point)
        zz, G = mpmath.expj(p["theta"]), mpmath.exp(p["delta"])
        expected = (G * p["delta"] ** 2 * (zz - 1) * (zz - 1 / G) * zz ** (p["d"] + 2)
                    * delta_of_z(zz, **{k: p[k] for k in ("alpha", "beta", "gamma", "d", "delta")}))
        assert_rel_close(mpmath.mpc(re, im), expected, mpmath.mpf(10) ** -28, "Re + j Im")


@pytest.mark.parametrize("point", POINTS[:8])
def test_real_part_even_and_imaginary_part_odd_in_theta(point):
    with mpmath.workdps(40):
        _, re, im, _ = _evaluate(point)
        _, re_m, im_m, _ = _evaluate({**point, "theta": -point["theta"]})
        scale = abs(re) + abs(im) + 1
        assert abs(re - re_m) <= mpmath.mpf(10) ** -35 * scale
        assert abs(im + im_m) <= mpmath.mpf(10) ** -35 * scale


def test_parts_are_real_trig_polynomials_affine_in_the_gains():
    for part in unit_circle_split():
        assert not part.has(sp.I)
        assert not part.has(sp.exp)
        assert sp.Poly(part, model.alpha, model.beta, model.gamma).total_degree() == 1
        assert part.has(model.d)
