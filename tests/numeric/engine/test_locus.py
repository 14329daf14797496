"""Root locus (symstab.numeric.engine.locus): tracked poles, crossings, counts.

Oracles: python-control's poles of the closed loop (``Loop.closed_loop``),
mpmath's ``polyroots`` of the paper's characteristic polynomial at 30
digits, the certified root counts (argument principle) at every path point,
the D-decomposition (the arc of ``Loop.boundary``, the first-principles
boundary point of eq. (7) at 30 digits, ``Loop.stable_intervals``), and a
brute-force search over permutations for the assignment.
"""

import itertools

import mpmath
import numpy as np
import pytest

import symstab
from symstab.numeric.engine import locus as locus_module
from symstab.numeric.engine.locus import ON_CIRCLE, locus
from symstab.numeric.paper.paper_loop import paper_locus
from symstab.numeric.paper.stability import unstable_root_counts

from conftest import PAPER_DELTA, REPO
from oracles import first_principles_boundary_point, loop_coefficients_mp

PAPER = REPO / "examples" / "loops" / "paper.toml"
TUSTIN = REPO / "examples" / "loops" / "tustin_damper.toml"


pytestmark = pytest.mark.usefixtures("loop_cache_dir")


@pytest.fixture(scope="module")
def paper_loop():
    return symstab.load_loop(PAPER)


@pytest.fixture(scope="module")
def tustin_loop():
    return symstab.load_loop(TUSTIN)


@pytest.fixture(scope="module")
def k_path(paper_loop):
    """K from -5 to 3000 N/m at B = 0.1 N s/m, d = 40: a z = 1 crossing and four pairs."""
    return locus(paper_loop, "K", np.linspace(-5.0, 3000.0, 401), B=0.1)


def _hausdorff(a, b):
    """Largest distance from a point of one set to the nearest of the other."""
    a, b = np.asarray(a, dtype=complex), np.asarray(b, dtype=complex)
    d = np.abs(a[:, None] - b[None, :])
    return max(d.min(axis=1).max(), d.min(axis=0).max())


# --------------------------------------------------------------------------
# The assignment


@pytest.mark.parametrize("n", [1, 2, 3, 4, 5, 6])
def test_assignment_is_the_cheapest_permutation(n):
    rng = np.random.default_rng(n)
    for _ in range(25):
        cost = rng.random((n, n))
        if n > 2:
            cost[0] = cost[1]          # ties must not break it
        column = locus_module._assignment(cost)
        assert sorted(column) == list(range(n))
        best = min(sum(cost[i, p[i]] for i in range(n)) for p in itertools.permutations(range(n)))
        assert sum(cost[i, column[i]] for i in range(n)) == pytest.approx(best, abs=1e-12)


# --------------------------------------------------------------------------
# The poles themselves


@pytest.mark.parametrize("index", [0, 3, 80, 250, 400])
def test_poles_are_the_roots_of_the_loops_polynomial(paper_loop, k_path, index):
    """mpmath's roots of the same coefficients at 50 digits: the tracking loses no pole."""
    K = float(k_path.values[index])
    coefficients = paper_loop.coefficients(K=K, B=0.1)
    with mpmath.workdps(50):
        roots = [complex(r) for r in mpmath.polyroots([mpmath.mpf(float(c)) for c in coefficients],
                                                      maxsteps=500, extraprec=200)]
    assert _hausdorff(k_path.poles[index], roots) < 1e-11


@pytest.mark.parametrize("alpha", [0.0001, 0.05, 0.2])
def test_poles_are_python_controls_poles(alpha):
    """The loop built by python-control (c2d of the plant, eq. (1), the delay) has these poles.

    python-control's poles of this loop are good to about 1e-5 next to the
    plant's double pole at z = 1 (mpmath's roots of its own polynomial
    differ from them by that much), hence the tolerance.
    """
    control = pytest.importorskip("control")
    from oracles import python_control_closed_loop

    path = paper_locus(parameter="alpha", values=[alpha, 2 * alpha], beta=0.0078125, gamma=0.0,
                       d=40, delta=PAPER_DELTA)
    loop = python_control_closed_loop(alpha=alpha, beta=0.0078125, gamma=0.0, d=40,
                                      delta=PAPER_DELTA, m=0.0128, T=1e-3)
    reference = control.poles(loop)
    # Every pole of python-control's loop is one of the locus's; a pole of
    # the locus it lacks can only be at z = 0 (a transfer-function algebra
    # that cancels z against z; the oracle's VE over T^2 z^2 keeps it).
    nearest = np.min(np.abs(reference[:, None] - path.poles[0][None, :]), axis=1)
    assert nearest.max() < 1e-4
    unmatched = np.min(np.abs(path.poles[0][:, None] - reference[None, :]), axis=1) > 1e-4
    assert len(reference) + unmatched.sum() == path.poles.shape[1]
    assert np.all(np.abs(path.poles[0][unmatched]) < 1e-12)


def test_poles_are_mpmath_roots_at_30_digits():
    values = np.array([0.0, 0.2, 0.5, 1.0, 2.0])
    path = paper_locus(parameter="beta", values=values, alpha=0.5, gamma=1.0, d=1,
                       delta=PAPER_DELTA)
    with mpmath.workdps(30):
        for k, beta in enumerate(values):
            coefficients = loop_coefficients_mp(alpha=0.5, beta=float(beta), gamma=1.0, d=1,
                                                delta=PAPER_DELTA)
            roots = [complex(r) for r in mpmath.polyroots(coefficients, maxsteps=200,
                                                          extraprec=60)]
            assert _hausdorff(path.poles[k], roots) < 1e-10


def test_columns_are_continuous(k_path):
    """From each point to the next, a column goes to the nearest pole (or nearly so).

    At a breakaway (two real poles meeting and leaving as a pair) both
    members of the pair are about equally near: hence the factor 1.5.
    """
    poles = k_path.poles
    tracked = np.abs(np.diff(poles, axis=0))
    nearest = np.min(np.abs(poles[1:, None, :] - poles[:-1, :, None]), axis=2)
    assert np.all(tracked <= 1.5 * nearest + 1e-12)


# --------------------------------------------------------------------------
# Counts against the certified count


def _assert_counts_agree(counts, certified):
    decided = (counts >= 0) & (certified >= 0)
    assert decided.sum() >= 0.95 * len(counts)
    np.testing.assert_array_equal(counts[decided], certified[decided])


def test_counts_are_the_certified_counts_along_K(paper_loop, k_path):
    certified = paper_loop.unstable_root_counts(K=k_path.values, B=0.1)
    _assert_counts_agree(k_path.unstable_counts(), certified)
    assert k_path.unstable_counts()[-1] == 8


def test_counts_are_the_certified_counts_along_B_of_the_tustin_damper(tustin_loop):
    path = locus(tustin_loop, "B", np.linspace(-0.1, 2.0, 301), K=300.0)
    certified = tustin_loop.unstable_root_counts(B=path.values, K=300.0)
    _assert_counts_agree(path.unstable_counts(), certified)
    assert [(c.kind, c.direction) for c in path.crossings] == [("z = -1", "in"), ("pair", "in")]


@pytest.mark.parametrize("parameter, values, fixed, gamma, d", [
    ("beta", np.linspace(-0.5, 3.0, 500), {"alpha": 0.5}, 1.0, 1),
    ("alpha", np.linspace(3.0, -1.0, 400), {"beta": 0.5}, 1.0, 10),
    ("alpha", np.linspace(-0.2, 6.0, 300), {"beta": 1.0}, 0.0, 0),
])
def test_paper_counts_are_the_certified_counts(parameter, values, fixed, gamma, d):
    path = paper_locus(parameter=parameter, values=values, gamma=gamma, d=d, delta=PAPER_DELTA,
                       **fixed)
    certified = unstable_root_counts(**{parameter: values}, **fixed, gamma=gamma, d=d,
                                     delta=PAPER_DELTA)
    _assert_counts_agree(path.unstable_counts(), certified)


def test_crossings_add_up_to_the_certified_change(paper_loop, k_path):
    """Between two path points the certified count changes by the crossings' +-2 and +-1."""
    certified = paper_loop.unstable_root_counts(K=k_path.values, B=0.1)
    first, last = 1, len(k_path.values) - 1       # K = -5 would do too; start after K = 0
    first = int(np.flatnonzero(k_path.values > 1e-3)[0])
    change = sum(c.change for c in k_path.crossings
                 if k_path.values[first] < c.value <= k_path.values[last])
    assert certified[last] - certified[first] == change == 8


# --------------------------------------------------------------------------
# Crossings where the path meets the D-decomposition


def _arc_meets(boundary, x_value):
    """(y, theta) where the boundary arc crosses x = x_value (linear interpolation)."""
    x = boundary.x_values - x_value
    ok = np.isfinite(x[:-1]) & np.isfinite(x[1:])
    k = np.flatnonzero(ok & (np.sign(x[:-1]) * np.sign(x[1:]) < 0))
    t = x[k] / (x[k] - x[k + 1])
    y = boundary.y_values[k] + t * (boundary.y_values[k + 1] - boundary.y_values[k])
    theta = boundary.theta[k] + t * (boundary.theta[k + 1] - boundary.theta[k])
    return y, theta


def test_every_arc_crossing_of_the_path_is_a_pair_crossing(paper_loop, k_path):
    boundary = paper_loop.boundary("B", "K", n=40000, B=0.1)
    y, theta = _arc_meets(boundary, 0.1)
    inside = (y > k_path.values[0]) & (y < k_path.values[-1])
    pairs = [c for c in k_path.crossings if c.kind == "pair"]
    assert len(pairs) == inside.sum() == 4
    np.testing.assert_allclose([c.value for c in pairs], np.sort(y[inside]), rtol=1e-5)
    np.testing.assert_allclose([c.angle for c in pairs], theta[inside][np.argsort(y[inside])],
                               rtol=1e-4)


def test_the_z_equals_one_crossing_is_on_the_line(paper_loop, k_path):
    c0, cx, cy = paper_loop.boundary("B", "K", n=2, B=0.1).lines["z = 1"]
    on_line = -(c0 + cx * 0.1) / cy
    real = [c for c in k_path.crossings if c.kind != "pair"]
    assert [(c.kind, c.direction) for c in real] == [("z = 1", "in")]
    assert abs(real[0].value - on_line) < 1e-12 * np.ptp(k_path.values)
    assert real[0].z == 1.0 + 0.0j or abs(real[0].z - 1.0) < 1e-9


def test_stable_interval_ends_are_crossings(paper_loop):
    path = locus(paper_loop, "K", np.linspace(0.5, 30.0, 201), B=0.1, d=5)
    (lo, hi), = paper_loop.stable_intervals("K", B=0.1, d=5)
    assert [c.direction for c in path.crossings] == ["out"]
    assert path.crossings[0].value == pytest.approx(hi, rel=1e-9)


@pytest.mark.parametrize("parameter, values, fixed, gamma, d, n_pairs", [
    ("alpha", np.linspace(1e-6, 0.3, 301), 0.0078125, 0.0, 40, 4),
    ("beta", np.linspace(-0.5, 3.0, 301), 0.5, 1.0, 1, 2),
    ("alpha", np.linspace(3.0, 0.01, 301), 0.5, 1.0, 10, 1),
])
def test_pair_crossings_are_points_of_eq7(parameter, values, fixed, gamma, d, n_pairs):
    """At the crossing angle, the D-decomposition (30 digits) gives back the path's point."""
    other = "beta" if parameter == "alpha" else "alpha"
    path = paper_locus(parameter=parameter, values=values, gamma=gamma, d=d, delta=PAPER_DELTA,
                       **{other: fixed})
    pairs = [c for c in path.crossings if c.kind == "pair"]
    assert len(pairs) == n_pairs
    with mpmath.workdps(30):
        for c in pairs:
            point = dict(zip(("alpha", "beta"),
                             first_principles_boundary_point(c.angle, gamma, d, PAPER_DELTA),
                             strict=True))
            assert float(point[other]) == pytest.approx(fixed, rel=1e-7)
            assert float(point[parameter]) == pytest.approx(c.value, rel=1e-7)


def test_a_coarse_path_finds_the_crossings_between_its_points():
    """Two crossings (in and out) between the only two points: found by halving the step."""
    fine = paper_locus(parameter="beta", values=np.linspace(-0.5, 3.0, 500), alpha=0.5,
                       gamma=1.0, d=1, delta=PAPER_DELTA)
    coarse = paper_locus(parameter="beta", values=[-0.5, 1.0, 3.0], alpha=0.5, gamma=1.0, d=1,
                         delta=PAPER_DELTA)
    assert [(c.kind, c.direction) for c in fine.crossings] == [("pair", "in"), ("pair", "out")]
    assert [(c.kind, c.direction) for c in coarse.crossings] == [("pair", "in"), ("pair", "out")]
    np.testing.assert_allclose([c.value for c in coarse.crossings],
                               [c.value for c in fine.crossings], rtol=1e-9)


def test_a_reversed_path_reverses_the_crossings(paper_loop):
    forward = locus(paper_loop, "K", np.linspace(0.5, 400.0, 201), B=0.1)
    backward = locus(paper_loop, "K", np.linspace(400.0, 0.5, 201), B=0.1)
    assert [c.direction for c in forward.crossings] == ["out", "out"]
    assert [c.direction for c in backward.crossings] == ["in", "in"]
    np.testing.assert_allclose([c.value for c in backward.crossings][::-1],
                               [c.value for c in forward.crossings], rtol=1e-9)


def test_marginal_points_are_minus_one(paper_loop):
    """At K = 0 the plant's integrator puts a pole on z = 1: marginal, as the certified count says."""
    path = locus(paper_loop, "K", [0.0, 1.0], B=0.1)
    assert path.unstable_counts()[0] == -1
    assert paper_loop.unstable_root_counts(K=0.0, B=0.1) == -1
    assert abs(np.abs(path.poles[0]).max() - 1.0) <= ON_CIRCLE


# --------------------------------------------------------------------------
# Bad input


@pytest.mark.parametrize("values, message", [
    ([1.0], "at least two"),
    ([[0.0, 1.0]], "at least two"),
    ([0.0, 1.0, 1.0], "strictly"),
    ([0.0, 2.0, 1.0], "strictly"),
    ([0.0, np.nan], "values"),
])
def test_bad_paths_are_refused(paper_loop, values, message):
    with pytest.raises(ValueError, match=message):
        locus(paper_loop, "K", values, B=0.1)


def test_bad_parameters_are_refused(paper_loop):
    with pytest.raises(ValueError, match="delay"):
        locus(paper_loop, "d", [1.0, 2.0])
    with pytest.raises(ValueError, match="not a parameter"):
        locus(paper_loop, "Q", [1.0, 2.0])
    with pytest.raises(TypeError, match="unknown parameter"):
        locus(paper_loop, "K", [1.0, 2.0], Q=1.0)
    with pytest.raises(ValueError, match="single value"):
        locus(paper_loop, "K", [1.0, 2.0], B=[0.1, 0.2])
    with pytest.raises(ValueError, match="path's parameter"):
        locus(paper_loop, "K", [1.0, 2.0], K=3.0)
    with pytest.raises(ValueError, match="'alpha' or 'beta'"):
        paper_locus(parameter="gamma", values=[0.0, 1.0], gamma=0.0, d=0, delta=0.1, alpha=0.1)
    with pytest.raises(TypeError, match="beta"):
        paper_locus(parameter="alpha", values=[0.0, 1.0], gamma=0.0, d=0, delta=0.1)
    with pytest.raises(ValueError, match="delay d"):
        paper_locus(parameter="alpha", values=[0.0, 1.0], gamma=0.0, d=-1, delta=0.1, beta=0.1)


def test_memory_limit_is_checked_first(paper_loop, monkeypatch):
    monkeypatch.setenv("SYMSTAB_MEMORY_LIMIT", "1M")
    with pytest.raises(ValueError, match="memory limit"):
        locus(paper_loop, "K", np.linspace(0.0, 30.0, 5000), B=0.1)


def test_a_high_degree_locus_fits_a_limit_its_degree_cubed_did_not(monkeypatch):
    """d = 400 (404 poles) under a 128 MiB limit: 8 degree**3 bytes (528 MB) once refused it.

    The working set is degree**2 a point (distances, companion matrices);
    tracemalloc's peak is measured, and the poles are numpy's roots of the
    30-digit first-principles coefficients.
    """
    import tracemalloc

    monkeypatch.setenv("SYMSTAB_MEMORY_LIMIT", "128M")
    values = [1e-7, 1e-6]
    tracemalloc.start()
    try:
        path = paper_locus(parameter="alpha", values=values, beta=0.001, gamma=0.0, d=400,
                           delta=PAPER_DELTA)
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert peak < 128 * 2**20
    for k, alpha in enumerate(values):
        with mpmath.workdps(30):
            coefficients = [float(c) for c in loop_coefficients_mp(
                alpha=alpha, beta=0.001, gamma=0.0, d=400, delta=PAPER_DELTA)]
        assert _hausdorff(path.poles[k], np.roots(coefficients)) < 1e-10
    # What cannot fit is still refused: one point's distance matrices alone are 15 MB.
    monkeypatch.setenv("SYMSTAB_MEMORY_LIMIT", "8M")
    with pytest.raises(ValueError, match="memory limit of 8 MiB"):
        paper_locus(parameter="alpha", values=values, beta=0.001, gamma=0.0, d=400,
                    delta=PAPER_DELTA)


def test_a_stable_window_between_two_unstable_points_is_found():
    """γ = 1, d = 0, β = -0.25: stable only for α in (1.097, 2.146); a path of two points
    on either side, both unstable, still finds the way in and out (by halving its step)."""
    kw = dict(parameter="alpha", beta=-0.25, gamma=1.0, d=0, delta=0.0025)
    fine = paper_locus(values=np.linspace(0.5, 3.0, 400), **kw)
    coarse = paper_locus(values=[0.5, 3.0], **kw)
    assert list(coarse.unstable_counts()) == [2, 2]
    assert [c.direction for c in fine.crossings] == [c.direction for c in coarse.crossings] \
        == ["in", "out"]
    np.testing.assert_allclose([c.value for c in coarse.crossings],
                               [c.value for c in fine.crossings], rtol=1e-9)
    certified = unstable_root_counts(alpha=np.mean([c.value for c in coarse.crossings]),
                                     beta=-0.25, gamma=1.0, d=0, delta=0.0025)
    assert certified == 0


def test_continued_roots_are_the_eigenvalues(paper_loop):
    """From degree 64 on the path's roots are continued by Newton's steps: the same sets."""
    values = np.linspace(0.0, 200.0, 31)     # 61 until issue 41: half the CPU
    coefficients = paper_loop.coefficients(K=values, B=0.1, d=100)
    assert coefficients.shape[1] - 1 >= locus_module._CONTINUATION_DEGREE
    continued = locus_module._roots_along(coefficients)
    eigenvalues = locus_module._roots(coefficients)
    assert max(_hausdorff(a, b) for a, b in zip(continued, eigenvalues, strict=True)) < 1e-10
    path = locus(paper_loop, "K", values, B=0.1, d=100)
    _assert_counts_agree(path.unstable_counts(),
                         paper_loop.unstable_root_counts(K=values, B=0.1, d=100))
    (_, top), = paper_loop.stable_intervals("K", B=0.1, d=100)
    assert path.crossings[0].value == pytest.approx(top, rel=1e-9)


def test_continuation_falls_back_where_roots_collide():
    """Two roots that converge together (a double root) are refused, not kept twice."""
    c = np.poly([0.5, 0.5 + 1e-9, -0.3])
    assert locus_module._continued(c, np.array([0.49, 0.51, -0.3])) is None
    # Two starts that both converge to the simple root 0.5 (0.9 is missed).
    c = np.poly([0.5, 0.9, -0.3])
    assert locus_module._continued(c, np.array([0.5, 0.52, -0.3])) is None
    z = locus_module._continued(np.poly([0.5, 0.7, -0.3]), np.array([0.49, 0.71, -0.31]))
    np.testing.assert_allclose(np.sort_complex(z), [-0.3, 0.5, 0.7], atol=1e-14)


@pytest.mark.parametrize("values", [[0.2, 0.1, 0.3], [0.1], "ab"])
def test_paper_locus_errors_name_the_papers_parameter(values):
    """paper_locus runs on the loop's K and B; its errors still say alpha or beta."""
    with pytest.raises((TypeError, ValueError), match=r"values \(of alpha\)"):
        paper_locus(parameter="alpha", values=values, beta=0.1, gamma=0.0, d=0, delta=0.1)
