"""DelayedPolynomial: chi = z**shift D + N kept structured; dense form and evaluation against numpy."""

import numpy as np
import pytest

from symstab.numeric.engine.polynomial import DelayedPolynomial
from symstab.symbolic.loop_assembly import shift_to_one


def test_dense_and_evaluation_agree_with_numpy():
    rng = np.random.default_rng(3)
    delayed, direct = rng.normal(size=(4, 3)), rng.normal(size=(4, 2))
    chi = DelayedPolynomial(delayed, direct, 5)
    dense = chi.dense()
    assert dense.shape == (4, 8)
    z = np.array([0.3 + 0.9j, -1.2, 2.0j])
    value, slope = chi(z)
    for k in range(4):
        assert np.allclose(value[k], np.polyval(dense[k], z), rtol=1e-13)
        assert np.allclose(slope[k], np.polyval(np.polyder(dense[k]), z), rtol=1e-12)


def test_overlapping_parts_add_up():
    chi = DelayedPolynomial([1.0, 2.0], [3.0, 4.0, 5.0], 1)     # z**2 + 2z + 3z**2 + 4z + 5
    assert chi.dense().tolist() == [4.0, 6.0, 5.0]
    assert float(chi.leading()) == 4.0


def test_on_radius_scales_the_roots():
    rng = np.random.default_rng(5)
    chi = DelayedPolynomial(rng.normal(size=3), rng.normal(size=3), 30)
    for radius in (0.5, 1.7):
        scaled = chi.on_radius(radius)
        moduli = np.sort(np.abs(np.roots(chi.dense())))
        scaled_moduli = np.sort(np.abs(np.roots(scaled.dense())))
        assert np.allclose(scaled_moduli * radius, moduli, rtol=1e-9)


def test_combine_is_the_affine_family():
    base = DelayedPolynomial([1.0, 0.5], [0.2], 4, near_one=([1.0, 1.5], [0.0, 0.0]))
    slope = DelayedPolynomial([0.0, 1.0], [1.0], 4, near_one=([0.0, 1.0], [0.0, 0.0]))
    x = np.array([0.0, 2.0])
    chi = base.combine([x], [slope])
    assert np.allclose(chi.dense(), base.dense()[None, :] + x[:, None] * slope.dense()[None, :])
    assert np.allclose(chi.near_one[0], shift_to_one(chi.delayed, dtype=float))


def test_shift_to_one_is_exact_for_integers():
    # (z - 1)**2 (z + 2) = w**2 (w + 3)
    assert shift_to_one([1, 0, -3, 2], dtype=object).tolist() == [1, 3, 0, 0]


@pytest.mark.parametrize("bad", [([], [1.0], 0), ([1.0], [1.0], 1.5), ([1.0], [1.0], True)])
def test_bad_structure_is_refused(bad):
    with pytest.raises(ValueError):
        DelayedPolynomial(*bad)
