"""A fractional loop delay (d + eps) T against a state-space oracle (issue 43, item 1).

The oracle (:func:`oracles.fractional_delay_radius`) discretises each loop's
plant from the physics, independently of symstab's modified z-transform: a
realisation of ``G(s)``, the held command arriving ``eps T`` into the period
(Van Loan's block exponential gives ``Phi``, ``Gamma0`` and ``Gamma1``), the
environment as a discrete state space and the whole samples of delay as a
shift register; its spectral radius is the largest eigenvalue modulus of the
closed loop's state matrix.  The loops' coefficients at numbers come from
their expressions substituted by SymPy (:func:`oracles.loop_coefficients`).

Checked here:

* ``Loop.spectral_radius`` at ``d = d + eps`` and at ``Td = (d + eps) T``
  equals the oracle's radius to a relative 1e-9, for ``symstab.PAPER_LOOP``
  and every loop of ``examples/loops/`` (eps = 0, 0.25, 0.5, 0.999; d = 0,
  1, 3, 10 and the loop's own), at its defaults, at a second stable point
  and at an unstable one;
* at eps = 0 the oracle is python-control's integer-delay loop;
* ``Loop.classify`` agrees with the oracle's radius (< 1 stable) off the
  boundary;
* the paper's K_max is continuous in the delay across a whole sample and
  decreases with it, and the oracle confirms it is the edge of the stable set
  at fractional delays.
"""

import numpy as np
import pytest

import symstab

from conftest import REPO
from oracles import (
    fractional_delay_radius,
    loop_coefficients,
    python_control_parts,
)

EXAMPLES = {path.stem: path for path in sorted((REPO / "examples" / "loops").glob("*.toml"))}
LOOPS = ("PAPER_LOOP", *EXAMPLES)
FRACTIONS = (0.0, 0.25, 0.5, 0.999)
DELAYS = (0, 1, 3, 10)
#: The default point, a second stable one (B and K halved: stable at the loop's
#: own d for every loop) and an unstable one (K 30 times the default's: unstable at
#: the loop's own d for every loop; 10 times is not enough for tustin_damper at d = 1,
#: whose dominant root is the damper's, near z = -1).
POINTS = {"default": (1.0, 1.0), "stable": (0.5, 0.5), "unstable": (1.0, 30.0)}
#: symstab's radius vs the oracle's.  Both are double-precision eigenvalue
#: moduli of simple dominant roots; measured agreement is 3e-13 or better
#: (2e-14 but for actuator_lag) on every loop, point and delay here.
RADIUS_RTOL = 1e-9
#: Radii this close to 1 are left to the certified classification.
BOUNDARY_BAND = 1e-6
@pytest.fixture(scope="session")
def loops():
    """Every loop checked: the paper's and the examples', loaded once."""
    out = {"PAPER_LOOP": symstab.PAPER_LOOP}
    out.update((name, symstab.load_loop(path)) for name, path in EXAMPLES.items())
    return out


def _point(loop, kind):
    """The loop's defaults with its plane's ``(B, K)`` scaled as :data:`POINTS` says."""
    scale_b, scale_k = POINTS[kind]
    values = dict(loop.defaults)
    values["B"] *= scale_b
    values["K"] *= scale_k
    return values


def _cases(loop):
    """``(d, eps)`` pairs checked for a loop: :data:`DELAYS` and its own d, by :data:`FRACTIONS`."""
    delays = sorted({*DELAYS, int(loop.defaults["d"])})
    return [(d, eps) for d in delays for eps in FRACTIONS]


def _oracle_radius(loop, values, d, eps):
    return fractional_delay_radius(*loop_coefficients(loop, values), float(values["T"]), d, eps)


def _radius_differences(loop, kind):
    """``(delay given, symstab's radius, the oracle's)`` wherever they differ by more than RADIUS_RTOL."""
    values = _point(loop, kind)
    rest = {k: v for k, v in values.items() if k != "d"}
    T = float(values["T"])
    wrong = []
    for d, eps in _cases(loop):
        expected = _oracle_radius(loop, values, d, eps)
        for given in ({"d": d + eps}, {"Td": (d + eps) * T}):
            actual = float(loop.spectral_radius(**rest, **given))
            if not abs(actual - expected) <= RADIUS_RTOL * expected:
                wrong.append((given, actual, expected))
    return wrong


@pytest.mark.parametrize("kind", POINTS)
@pytest.mark.parametrize("name", LOOPS)
def test_radius_matches_state_space_oracle(loops, name, kind):
    wrong = _radius_differences(loops[name], kind)
    assert not wrong, f"{name} at {kind}: (delay, symstab, oracle) {wrong}"


@pytest.mark.parametrize("name", LOOPS)
def test_oracle_at_whole_delay_is_python_control(loops, name):
    """At eps = 0 the state-space oracle is python-control's ``feedback(P, VE z**-d)``.

    Up to d = 10: beyond, python-control's polynomial arithmetic loses digits
    (about 1e-6 of the radius at d = 40), not the oracle.
    """
    control = pytest.importorskip("control")
    loop = loops[name]
    wrong = []
    for kind in POINTS:
        for d in DELAYS:
            values = dict(_point(loop, kind), d=d)
            plant, environment, delay = python_control_parts(loop, values)
            poles = control.poles(control.feedback(plant, environment * delay))
            expected = float(np.max(np.abs(poles)))
            actual = _oracle_radius(loop, values, d, 0.0)
            if not abs(actual - expected) <= RADIUS_RTOL * expected:
                wrong.append((kind, d, actual, expected))
    assert not wrong, f"{name}: (point, d, oracle, python-control) {wrong}"


def test_oracle_is_continuous_across_a_whole_sample(loops):
    """The oracle's own check: a delay of d + 1 - 1e-9 samples is d + 1 samples."""
    loop = loops["PAPER_LOOP"]
    values = dict(loop.defaults)
    for d in DELAYS:
        late = _oracle_radius(loop, values, d, 1 - 1e-9)
        assert abs(late - _oracle_radius(loop, values, d + 1, 0.0)) <= 1e-7 * late, d


@pytest.mark.parametrize("name", LOOPS)
def test_classification_agrees_with_oracle(loops, name):
    loop = loops[name]
    wrong, decided = [], 0
    for kind in POINTS:
        values = _point(loop, kind)
        rest = {k: v for k, v in values.items() if k != "d"}
        for d, eps in _cases(loop):
            radius = _oracle_radius(loop, values, d, eps)
            if abs(radius - 1) < BOUNDARY_BAND:
                continue
            decided += 1
            expected = 1 if radius < 1 else -1
            actual = int(loop.classify(**rest, d=d + eps))
            if actual != expected:
                wrong.append((kind, d + eps, actual, radius))
    assert decided >= len(POINTS) * len(_cases(loop)) - 2
    assert not wrong, f"{name}: (point, d, classify, oracle radius) {wrong}"


@pytest.fixture(scope="module")
def paper_limits():
    """The paper loop's (B, K) limits at delays about 40 samples, by delay."""
    return {d: symstab.PAPER_LOOP.limits("B", "K", d=d) for d in (39, 39.5, 39.999, 40, 40.001)}


def test_k_max_is_continuous_across_a_whole_sample(paper_limits):
    """K_max at 39.999 and 40.001 samples is K_max at 40 (relative 1e-3; it moves by about 5e-5)."""
    at_40 = paper_limits[40].y_max
    for d in (39.999, 40.001):
        assert abs(paper_limits[d].y_max - at_40) <= 1e-3 * at_40, d
    # And it moves the right way: less stiffness for more delay.
    assert paper_limits[39.999].y_max > at_40 > paper_limits[40.001].y_max


def test_k_max_decreases_with_the_delay(paper_limits):
    """5.19 at 39, 5.07 at 39.5, 4.96 at 40 samples: no jump at the whole sample."""
    k = [paper_limits[d].y_max for d in (39, 39.5, 40)]
    assert k[0] > k[1] > k[2]
    # Nearly linear over one sample: the half sample is within 5 % of the chord's middle.
    assert abs(k[1] - (k[0] + k[2]) / 2) <= 0.05 * (k[0] - k[2])


@pytest.mark.parametrize("d", (39.5, 39.999))
def test_k_max_is_the_oracle_stable_edge(paper_limits, d):
    """Just below K_max (at its B) the oracle's loop is stable, just above it unstable."""
    loop = symstab.PAPER_LOOP
    limits = paper_limits[d]
    whole = int(d)
    radii = []
    for scale in (1 - 1e-3, 1 + 1e-3):
        values = dict(loop.defaults, B=limits.x_at_y_max, K=scale * limits.y_max)
        radii.append(_oracle_radius(loop, values, whole, d - whole))
    assert radii[0] < 1 < radii[1], radii
