"""The one crossing-direction rule (symstab.numeric.engine.arcs.crossing_change) against the two it replaced.

``old_region_rule`` and ``old_loop_rule`` are the bodies of
``StabilityRegion._crossing_change`` and ``any_loop._crossing_changes`` as
they were before the rule moved to arcs.py (commit abfdc40), kept here as
references: on the crossings the one line engine
(:mod:`symstab.numeric.engine.intervals`) finds on the paper's lines and on every
example loop's lines, the new rule gives the same verdict wherever the old
one decided, and decides where it did.
"""

import glob
import os

import numpy as np
import pytest

import symstab
from symstab.numeric.engine import intervals
from symstab.numeric.engine.arcs import crossing_change
from symstab.numeric.engine.polynomial import DelayedPolynomial
from symstab.numeric.paper.paper_loop import paper_point
from symstab.numeric.paper.stability import loop_coefficients

EXAMPLES = sorted(glob.glob(os.path.join(os.path.dirname(__file__), "..", "..", "..", "examples",
                                         "loops", "*.toml")))


def old_region_rule(gamma, d, delta, axis, theta, alpha, beta):
    base = loop_coefficients(alpha=0.0, beta=0.0, gamma=gamma, d=d, delta=delta)
    d_alpha = loop_coefficients(alpha=1.0, beta=0.0, gamma=gamma, d=d, delta=delta) - base
    d_beta = loop_coefficients(alpha=0.0, beta=1.0, gamma=gamma, d=d, delta=delta) - base
    used = np.flatnonzero((base != 0) | (d_alpha != 0) | (d_beta != 0))
    powers = (d + 4 - used).astype(float)
    base, d_alpha, d_beta = base[used], d_alpha[used], d_beta[used]
    c = base + alpha[:, None] * d_alpha + beta[:, None] * d_beta
    moving = d_alpha if axis == "beta" else d_beta
    z = np.exp(1j * theta)
    high = powers > 3
    start = powers[high].min() if high.any() else 0.0
    near = powers - np.where(high, start, 0.0)
    z_power = np.where(high, np.exp(1j * theta * start)[:, None], 1.0)
    for k in range(1, int(near.max()) + 1):
        z_power = np.where(near >= k, z_power * z[:, None], z_power)
    z_slope = np.sum(c * powers * z_power, axis=1)
    partial = np.sum(moving * z_power, axis=1)
    radial = -np.real(partial * np.conj(z_slope))
    scale = np.sum(np.abs(c * powers), axis=1) * np.sum(np.abs(moving))
    noise = 2e-15 * (1.0 + powers.max() * theta) * scale
    sign = np.where(np.abs(radial) > noise, np.sign(radial), 0.0)
    multiplicity = np.where((theta > 0) & (theta < np.pi), 2.0, 1.0)
    return multiplicity * sign


def _on_circle(c, theta):
    z = np.exp(1j * np.asarray(theta))
    out = np.zeros_like(z)
    for ck in c:
        out = out * z + ck
    return out


def old_loop_rule(a0, a1, p, theta):
    z = np.exp(1j * theta)
    chi_slope = _on_circle(np.polyder(a0), theta) + p * _on_circle(np.polyder(a1), theta)
    with np.errstate(all="ignore"):
        velocity = -_on_circle(a1, theta) / chi_slope
        radial = (np.conj(z) * velocity).real
    size = np.where((theta == 0) | (theta == np.pi), 1.0, 2.0)
    clear = np.isfinite(radial) & (np.abs(radial) > 1e-8 * np.abs(velocity))
    return np.where(clear, size * np.sign(radial), np.nan)


@pytest.mark.parametrize("gamma, d, delta", [(0.0, 0, 0.00253125), (1.5, 3, 0.00253125),
                                             (0.0, 10, 0.00253125), (-0.5, 40, 0.01)])
@pytest.mark.parametrize("axis", ["beta", "alpha"])
def test_region_rule_is_the_old_one(gamma, d, delta, axis):
    """The crossings of the paper's lines (the line engine's, on PAPER_LOOP) decided as before."""
    loop, point = paper_point(gamma=gamma, d=d, delta=delta)
    values = np.linspace(-0.2, 0.8, 23) if axis == "beta" else np.linspace(-0.5, 3.0, 23)
    free, across = ("K", "B") if axis == "beta" else ("B", "K")
    base, (slope, sideways), ends = loop.affine_parts((free, across), point, structured=True)
    base, sideways, slope = polynomials = tuple(x.flat() for x in (base, sideways, slope))
    line, p, theta = intervals._crossings(polynomials, values, (ends[0], ends[2], ends[1]),
                                          polynomials)
    on_line = values[line]
    alpha, beta = (p, on_line) if axis == "beta" else (on_line, p)
    old = old_region_rule(gamma, d, delta, axis, theta, alpha, beta)
    new = crossing_change(base.combine([on_line, p], [sideways, slope]), slope, theta)
    assert len(new) > 20
    np.testing.assert_array_equal(np.where(np.isnan(new), 0.0, new), old)


@pytest.mark.parametrize("path", EXAMPLES, ids=os.path.basename)
def test_loop_rule_is_the_old_one(path):
    loop = symstab.load_loop(path)
    decided = 0
    for name in loop.plane:
        base, (slope,), (base_ends, slope_ends) = loop.affine_parts((name,), {})
        zero = np.zeros_like(base)
        polynomials = tuple(DelayedPolynomial.from_dense(r[None, :]) for r in (base, zero, slope))
        _, p, theta = intervals._crossings(polynomials, np.zeros(1),
                                           (tuple(base_ends), (0.0, 0.0), tuple(slope_ends)),
                                           (base, zero, slope))
        old = old_loop_rule(base, slope, p, theta)
        new = crossing_change(DelayedPolynomial.from_dense(base[None, :] + p[:, None] * slope),
                              DelayedPolynomial.from_dense(slope), theta)
        both = np.isfinite(old) & np.isfinite(new)
        np.testing.assert_array_equal(new[both], old[both])
        # Decided by one and not the other only within the old rule's
        # tolerance (a radial velocity below 1e-8 of the velocity).
        assert np.array_equal(np.isfinite(new), np.isfinite(old))
        decided += int(both.sum())
    assert decided > 0
