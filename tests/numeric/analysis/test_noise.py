"""``Loop.force_noise``: the force RMS that the encoder's quantization renders at a stable point.

Oracles, written here: the closed loop ``VE z**-d / (1 + VE z**-d P)`` built by
python-control (``c2d`` of the plant) and its impulse response summed by scipy
(``dimpulse``, until the tail is below 1e-17 of the sum); a simulation with the
package's quantizer (``Nonidealities(encoder_resolution=q)``) against the same
run without it, the force rebuilt here from eq. (1) of the paper, over 256
loops that differ by 1e-6 in K, so that their rounding errors are independent
draws.
"""

import math

import numpy as np
import pytest
import scipy.signal

import symstab
from symstab import Nonidealities
from symstab.numeric.analysis.noise import h2_norm

from conftest import REPO
from oracles import impulse_norm, python_control_parts

LOOPS = REPO / "examples" / "loops"

pytestmark = pytest.mark.usefixtures("loop_cache_dir")

#: The paper's encoder: 4096 lines, 16384 counts a turn (rad).
Q = 2 * math.pi / 16384


@pytest.mark.parametrize("file, values", [
    ("paper.toml", dict(K=100.0, B=1.0, d=0)),
    ("paper.toml", dict(K=3.0, B=0.2, d=10)),
    ("lowpass_velocity.toml", {}),
    ("two_mass.toml", {}),
])
def test_the_closed_loop_gain_is_python_control_s_impulse_response_summed(file, values):
    loop = symstab.load_loop(LOOPS / file)
    point = {**loop.defaults, **values}
    found = loop.force_noise(encoder_resolution=Q, **point)
    plant, environment, delay = python_control_parts(loop, point)
    H = environment * delay / (1 + environment * delay * plant)
    T = point["T"]
    expected = impulse_norm(H.num[0][0], H.den[0][0], T)
    assert found.closed_loop_gain == pytest.approx(expected, rel=1e-7)
    assert found.open_loop_gain == pytest.approx(
        impulse_norm(environment.num[0][0], environment.den[0][0], T), rel=1e-9)
    assert found.rms == pytest.approx(Q / math.sqrt(12) * expected, rel=1e-7)


def test_h2_norm_of_a_first_order_lag_and_of_an_unstable_one():
    assert h2_norm([1.0, 0.0], [1.0, -0.9]) == pytest.approx(1 / math.sqrt(1 - 0.81), rel=1e-13)
    assert h2_norm([1.0], [1.0, -1.0]) == math.inf
    assert h2_norm([2.0], [4.0]) == 0.5
    # Refused before its O(n**3) work: a delay of 2001 samples.
    with pytest.raises(ValueError, match="degree 2001 is beyond 2000"):
        h2_norm([1.0], [1.0] + [0.0] * 2001)


def test_a_simulation_with_the_encoder_renders_the_predicted_force_noise():
    """256 runs of the paper's device at K = 30 N m/rad, B = 0.1 N m s/rad, d = 0 from 1e7
    counts: while the device moves across many counts a sample the rounding error is white,
    and the force it adds (quantized run minus ideal run, eq. (1) applied to the positions
    read) has the predicted RMS."""
    loop = symstab.load_loop(LOOPS / "paper.toml")
    n, steps, window = 256, 1500, slice(100, 1500)
    at = dict(B=0.1, d=0, M=0.0)
    K = 30.0 * (1 + 1e-6 * np.arange(n))
    predicted = loop.force_noise(encoder_resolution=Q, K=30.0, **at)
    ideal = loop.simulate(steps=steps, x0=1e7 * Q, record=True, K=K, **at)
    read = loop.simulate(steps=steps, x0=1e7 * Q, record=True, K=K, **at,
                         nonideal=Nonidealities(encoder_resolution=Q))
    x, xq = ideal.positions.reshape(steps + 1, n), read.positions.reshape(steps + 1, n)
    measured = np.rint(xq / Q) * Q
    # Many counts a sample to the window's end: the model's hypothesis holds there.
    assert np.abs(np.diff(x[: window.stop + 1], axis=0)).min(axis=1)[-10:].max() > 20 * Q
    error = measured - xq
    assert np.std(error[window]) == pytest.approx(Q / math.sqrt(12), rel=0.01)
    T, B = loop.defaults["T"], at["B"]
    force = np.stack([scipy.signal.lfilter([k + B / T, -B / T], [1.0], measured[:, j] - x[:, j])
                      for j, k in enumerate(K)], axis=1)
    rms = math.sqrt(float(np.mean(force[window] ** 2)))
    assert rms == pytest.approx(predicted.rms, rel=0.03)


def test_an_unstable_point_has_no_force_noise_and_the_resolution_is_checked():
    loop = symstab.load_loop(LOOPS / "paper.toml")
    with pytest.raises(ValueError, match="the force noise needs a stable point"):
        loop.force_noise(encoder_resolution=Q, K=100.0, B=1.0, d=40)
    for bad in (0.0, -1e-3, math.nan):
        with pytest.raises(ValueError, match="encoder_resolution"):
            loop.force_noise(encoder_resolution=bad, K=100.0, B=1.0, d=0)
