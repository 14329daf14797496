"""The theory of the loop the simulator runs (:func:`symstab.numeric.paper.simulate_theory.linear_theory`).

Oracles: python-control (the plant through ``c2d(..., "zoh")``, the
simulator's filter written as transfer functions) and the loop file of the
same device, ``examples/loops/lowpass_velocity.toml``.
"""

import numpy as np
import pytest

import symstab
from symstab.numeric.engine.roots import MARGINAL, STABLE, UNSTABLE
from symstab.numeric.paper.simulate_theory import linear_theory
from symstab.numeric.simulation.simulator import Nonidealities

from conftest import REPO
from oracles import simulated_loop_radius as oracle_radius

DEV = symstab.PAPER_DEVICE


@pytest.fixture(autouse=True)
def _kernels_in_a_temporary_folder(loop_cache_dir):
    """The linear loops' kernels are generated: never into ~/.cache."""


def test_the_filter_is_the_loop_files_filter():
    """lowpass_velocity.toml's environment is the simulator's filter, to the last digits."""
    from_file = symstab.load_loop(REPO / "examples" / "loops" / "lowpass_velocity.toml")
    for f_c, d in ((50.0, 40), (100.0, 10), (300.0, 0)):
        theory = linear_theory(gamma=0.0, d=d, device=DEV, nonideal=Nonidealities(velocity_cutoff=f_c))
        values = {**theory.values, "K": np.array([0.0, 30.0, -5.0]), "B": np.array([1.0, 0.0, 0.3])}
        ours = theory.loop.coefficients(**values)
        values.pop("M")
        theirs = from_file.coefficients(**values)
        # The mass term's 1/z (it differences the filtered velocity) puts
        # one more power of z under the environment: at M = 0 a root at 0.
        assert np.all(ours[:, -1] == 0)
        ours, theirs = ours[:, :-1], theirs
        ours, theirs = ours / ours[:, :1], theirs / theirs[:, :1]
        np.testing.assert_allclose(ours, theirs, rtol=1e-13, atol=1e-14)


@pytest.mark.parametrize("f_c, f_a, gamma, d", [
    (100.0, None, 0.0, 10), (50.0, None, 0.3, 4), (None, 200.0, 0.0, 10),
    (30.0, 500.0, -0.2, 2),
])
def test_classify_and_radius_match_python_control(f_c, f_a, gamma, d):
    theory = linear_theory(gamma=gamma, d=d, device=DEV,
                           nonideal=Nonidealities(velocity_cutoff=f_c, actuator_bandwidth=f_a))
    rng = np.random.default_rng(18)
    Kw, Bw = rng.uniform(0, 80, 40), rng.uniform(-0.2, 2.5, 40)
    codes = theory.classify(DEV.alpha(Kw), DEV.beta(Bw))
    decided = 0
    for K, B, code in zip(Kw, Bw, codes, strict=True):
        r = oracle_radius(K, B, d=d, f_c=f_c, f_a=f_a, M=DEV.mass(gamma))
        assert theory.spectral_radius(DEV.alpha(K), DEV.beta(B)) == pytest.approx(r, abs=1e-9)
        if abs(r - 1) > 1e-6:
            assert code == (STABLE if r < 1 else UNSTABLE), (K, B, r)
            decided += 1
    assert decided >= 35 and STABLE in codes and UNSTABLE in codes


def test_non_linear_elements_are_left_out_and_named():
    theory = linear_theory(gamma=0.0, d=10, device=DEV, nonideal=Nonidealities(
        encoder_resolution=1e-5, coulomb_friction=0.01, friction_compensation=True))
    assert theory.loop is None and theory.label == "ideal loop"
    assert theory.description == ("ideal loop; its linear part only: encoder quantization, "
                                  "Coulomb friction and friction compensation left out")
    # The ideal loop's theory is the paper's: same codes as symstab.classify.
    alpha, beta = DEV.alpha(np.array([10.0, 70.0])), DEV.beta(np.array([0.5, 0.5]))
    np.testing.assert_array_equal(theory.classify(alpha, beta),
                                  symstab.classify(alpha=alpha, beta=beta, gamma=0.0, d=10,
                                                   delta=DEV.delta))


def test_refusals_name_the_parameter():
    with pytest.raises(ValueError, match="velocity_cutoff"):
        linear_theory(gamma=0.0, d=1, device=DEV, nonideal=Nonidealities(velocity_cutoff=600.0))
    with pytest.raises(ValueError, match="nonideal needs a device"):
        linear_theory(gamma=0.0, d=1, delta=0.1, nonideal=Nonidealities(velocity_cutoff=50.0))
    with pytest.raises(TypeError, match="nonideal must be"):
        linear_theory(gamma=0.0, d=1, device=DEV, nonideal={"velocity_cutoff": 50.0})
    with pytest.raises(ValueError, match="delay d"):
        linear_theory(gamma=0.0, d=-1, device=DEV, nonideal=Nonidealities(velocity_cutoff=50.0))
    assert MARGINAL == 0
