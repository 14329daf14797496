"""The z = 1 line of a plant with an integrator is exactly K = 0; one without keeps its end.

``P_d(1)`` is summed at 30 digits; for a pole at z = 1 that sum kept 1e-30
of its terms, and the line z = 1 of the paper's loop came out at K = 3.8e-26
N/m (T = 0.25 ms), printed as the end of the stable interval.
"""

import pytest

import symstab

VE = "K + B*(z - 1)/(T*z)"
DEVICE = dict(m=0.0128, b=0.0324)


@pytest.fixture(autouse=True)
def _kernels_in_a_temporary_folder(loop_cache_dir):
    """The loops' kernels are generated: never into ~/.cache."""


@pytest.mark.parametrize("T", [1e-4, 2.5e-4, 5e-4, 1e-3, 2e-3])
@pytest.mark.parametrize("d", [0, 4])
def test_integrator_puts_the_z1_line_exactly_at_zero(T, d):
    loop = symstab.Loop("1/(m*s**2 + b*s)", VE, values=dict(DEVICE, T=T, d=d))
    (lo, hi), = loop.stable_intervals("K", B=0.5)
    assert lo == 0.0 and hi > 0
    c0, cx, cy = loop.boundary("B", "K", n=4).lines["z = 1"]
    assert c0 == 0.0 and cx == 0.0 and cy != 0.0


def test_a_spring_in_the_plant_keeps_its_z1_line():
    # G = 1/(m s^2 + b s + k): no integrator, the z = 1 line is K = -k (the
    # total stiffness K + k must be positive), found to the digits of c2d.
    k = 3.0
    loop = symstab.Loop("1/(m*s**2 + b*s + k)", VE, values=dict(DEVICE, k=k, T=2.5e-4, d=0))
    (lo, hi), = loop.stable_intervals("K", B=0.5)
    assert lo == pytest.approx(-k, rel=1e-9) and hi > 0
    c0, cx, cy = loop.boundary("B", "K", n=4).lines["z = 1"]
    assert c0 != 0.0 and -c0 / cy == pytest.approx(-k, rel=1e-9)
