"""The complete D-decomposition (symstab.numeric.engine.decomposition) against outside oracles.

The acceptance of the "whole picture" issue, for the paper's loop at
(gamma = 1, d = 40) and for every example loop of ``examples/loops``:

* the stable polygons agree with a classification by the closed loop's
  poles on a 100 x 100 grid (200 x 200 until issue 41: 4x the CPU, in the
  eigenvalues) everywhere except the grid cells a boundary branch passes
  through (the poles are numpy's companion eigenvalues, what
  python-control's ``TransferFunction.poles`` computes; python-control
  itself classifies a 10 x 10 subgrid);
* the stable area agrees with a seeded Monte-Carlo estimate of 5 000 points
  within three of its standard errors;
* the certified count of every cell agrees with numpy's roots at the
  cell's interior point;
* every pair of neighbouring cells obeys the crossing rule.
"""

import glob
import os

import numpy as np
import pytest

from symstab.numeric.engine.decomposition import Cell, decompose
from symstab.numeric.loop.files import load_loop
from symstab.numeric.paper.region import StabilityRegion
from symstab.numeric.paper.stability import loop_coefficients

from oracles import python_control_closed_loop

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__)))))
EXAMPLES = sorted(glob.glob(os.path.join(ROOT, "examples", "loops", "*.toml")))
# The paper's device, typed here (the oracles do not read it from the library).
M, B_DEV, T = 0.0128, 0.0324, 1e-3
DELTA = B_DEV * T / M


def _outside(rows):
    """Roots outside the unit circle of each coefficient row, by companion eigenvalues."""
    rows = np.asarray(rows, dtype=float)
    rows = rows / rows[:, :1]
    n = rows.shape[1] - 1
    out = np.empty(len(rows), dtype=int)
    for start in range(0, len(rows), 1000):     # 1000 companions of degree 45: 16 MB
        part = rows[start:start + 1000]
        companion = np.zeros((len(part), n, n))
        companion[:, 0, :] = -part[:, 1:]
        companion[:, np.arange(1, n), np.arange(n - 1)] = 1.0
        out[start:start + 1000] = np.sum(np.abs(np.linalg.eigvals(companion)) > 1.0, axis=1)
    return out


def _crossed(decomposition, xs, ys):
    """The grid cells (pixels around the grid points) that a branch passes through."""
    dx, dy = xs[1] - xs[0], ys[1] - ys[0]
    crossed = np.zeros((len(ys), len(xs)), dtype=bool)
    for branch in decomposition.branches:
        pts = branch.points
        for a, b in zip(pts[:-1], pts[1:], strict=True):
            if not (np.all(np.isfinite(a)) and np.all(np.isfinite(b))):
                continue
            # The part of the segment inside the grid (Liang-Barsky).
            lo, hi = 0.0, 1.0
            for p0, p1, edge0, edge1 in ((a[0], b[0], xs[0] - dx, xs[-1] + dx),
                                         (a[1], b[1], ys[0] - dy, ys[-1] + dy)):
                if p1 == p0:
                    if not edge0 <= p0 <= edge1:
                        lo, hi = 1.0, 0.0
                    continue
                t0, t1 = sorted(((edge0 - p0) / (p1 - p0), (edge1 - p0) / (p1 - p0)))
                lo, hi = max(lo, t0), min(hi, t1)
            if lo > hi:
                continue
            span = (hi - lo) * max(abs(b[0] - a[0]) / dx, abs(b[1] - a[1]) / dy)
            t = np.linspace(lo, hi, int(span * 4) + 2)
            px, py = a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1])
            i = np.rint((py - ys[0]) / dy).astype(int)
            j = np.rint((px - xs[0]) / dx).astype(int)
            ok = (i >= 0) & (i < len(ys)) & (j >= 0) & (j < len(xs))
            crossed[i[ok], j[ok]] = True
    return crossed


def _paper_case():
    region = StabilityRegion(gamma=1.0, d=40, delta=DELTA)
    found = region.decomposition((-0.008, 0.045), (-0.0002, 0.0018))

    def rows(x, y):
        return loop_coefficients(alpha=y, beta=x, gamma=1.0, d=40, delta=DELTA).reshape(-1, 45)

    def python_control(x, y):
        closed = python_control_closed_loop(alpha=y, beta=x, gamma=1.0, d=40, delta=DELTA, m=M, T=T)
        return int(np.sum(np.abs(closed.poles()) > 1.0))

    return found, rows, python_control


def _example_case(path):
    loop = load_loop(path)
    found = loop.region()
    x, y = found.x, found.y

    def rows(xv, yv):
        c = loop.coefficients(**{x: xv, y: yv})
        return c.reshape(-1, c.shape[-1])

    def python_control(xv, yv):
        return int(np.sum(np.abs(loop.closed_loop(**{x: xv, y: yv}).poles()) > 1.0))

    return found, rows, python_control


CASES = ["paper-gamma1-d40"] + [os.path.basename(p)[:-5] for p in EXAMPLES]


@pytest.fixture(scope="module", params=CASES)
def case(request):
    if request.param == "paper-gamma1-d40":
        return _paper_case()
    return _example_case(os.path.join(ROOT, "examples", "loops", request.param + ".toml"))


def test_stable_polygons_match_the_poles_on_a_100_by_100_grid(case):
    found, rows, python_control = case
    xs = np.linspace(*found.x_range, 100)
    ys = np.linspace(*found.y_range, 100)
    gx, gy = np.meshgrid(xs, ys)
    crossed = _crossed(found, xs, ys)
    # The poles of the points away from every branch: the others are never compared.
    unstable = np.full(gx.shape, -1)
    unstable[~crossed] = _outside(rows(gx[~crossed], gy[~crossed]))
    inside = found.contains(gx, gy)
    wrong = (inside != (unstable == 0)) & ~crossed
    assert not wrong.any(), (f"{int(wrong.sum())} grid points away from every branch disagree, "
                             f"e.g. at {gx[wrong][0]:.6g}, {gy[wrong][0]:.6g}")
    # The region is not trivially empty or full: both verdicts occur off the boundary.
    assert inside[~crossed].any() and (~inside[~crossed]).any()
    # python-control itself on a 10 x 10 subgrid.
    for i in range(5, 100, 10):
        for j in range(5, 100, 10):
            if not crossed[i, j]:
                assert (python_control(gx[i, j], gy[i, j]) == 0) == inside[i, j], (gx[i, j], gy[i, j])


def test_area_matches_monte_carlo(case):
    found, rows, _ = case
    rng = np.random.default_rng(20261130)
    n = 5000
    x = rng.uniform(*found.x_range, n)
    y = rng.uniform(*found.y_range, n)
    stable = _outside(rows(x, y)) == 0
    box = (found.x_range[1] - found.x_range[0]) * (found.y_range[1] - found.y_range[0])
    p = stable.mean()
    estimate, error = box * p, box * np.sqrt(p * (1 - p) / n)
    assert abs(found.area - estimate) <= 3 * error, (found.area, estimate, error)


def test_every_cell_count_matches_numpy_roots(case):
    found, rows, _ = case
    assert found.cells
    for cell in found.cells:
        assert cell.count >= 0, cell
        coefficients = rows(np.array([cell.point[0]]), np.array([cell.point[1]]))[0]
        expected = int(np.sum(np.abs(np.roots(coefficients)) > 1.0))
        assert cell.count == expected, cell
        assert cell.contains(*cell.point)


def test_crossing_rule_holds_and_the_stable_set_is_closed(case):
    found, _, _ = case
    assert found.mismatches == ()
    assert found.unbounded == ()
    assert len(found.stable) >= 1


def test_segments_of_the_schur_cohn_triangle_are_exact():
    """z**2 + x z + y: stable on the triangle |y| < 1, |x| < 1 + y (Jury's conditions).

    Its sides on z = 1 (1 + x + y = 0) and z = -1 (1 - x + y = 0) meet at
    (0, -1), a corner of the two lines (their crossing, not two roundings
    of it), and reach the arc y = 1 at x = -2 and 2.
    """
    ends = [np.array([1.0, 1.0]), np.array([1.0, -1.0]), np.array([1.0, 1.0])]
    found = decompose([1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0], ends,
                      x_range=(-3.0, 3.0), y_range=(-2.0, 2.0))
    one, minus_one = found.segments
    assert (one.root, one.x1, one.y1) == ("z=1", 0.0, -1.0)           # the lines' crossing
    assert (minus_one.root, minus_one.x0, minus_one.y0) == ("z=-1", 0.0, -1.0)
    near = dict(abs=1e-15)                                            # on the arc
    assert (one.x0, one.y0) == (pytest.approx(-2.0, **near), pytest.approx(1.0, **near))
    assert (minus_one.x1, minus_one.y1) == (pytest.approx(2.0, **near), pytest.approx(1.0, **near))


def test_paper_limits_from_the_region_match_the_line_engine():
    """Loop.limits, now read from the polygons, against the paper's independent line engine."""
    import symstab

    loop = load_loop(os.path.join(ROOT, "examples", "loops", "paper.toml"))
    for gamma, d in ((0.0, 0), (1.0, 10), (0.0, 40)):
        today = symstab.limits(gamma=gamma, d=d, delta=DELTA)
        ours = loop.limits(M=gamma * M, d=d)
        assert abs(ours.y_max / (today.alpha_max * M / T**2) - 1) < 1e-9
        assert abs(ours.x_max / (today.beta_right * M / T) - 1) < 1e-8
        assert abs(ours.x_min / (today.beta_left * M / T) - 1) < 1e-8


def test_schur_cohn_triangle_of_a_quadratic():
    """chi(z) = z**2 + x z + y, worked by hand.

    The z = 1 line is 1 + x + y = 0, the z = -1 line 1 - x + y = 0, and the
    arc is y = 1, x = -2 cos(theta): it ends on the two lines.  Five cells:
    the stable triangle |x| < 1 + y < 2 (area 4), above the arc a complex
    pair outside (2), left and right one real root outside (1 each), below
    both lines two real roots outside (2).
    """
    base, ax, ay = np.array([1.0, 0.0, 0.0]), np.array([0.0, 1.0, 0.0]), np.array([0.0, 0.0, 1.0])
    ends = [np.array([1.0, 1.0]), np.array([1.0, -1.0]), np.array([1.0, 1.0])]
    found = decompose(base, ax, ay, ends, x_range=(-3, 3), y_range=(-2, 2))
    (stable,) = found.stable
    assert abs(stable.area - 4.0) < 1e-9
    assert sorted(c.count for c in found.cells) == [0, 1, 1, 2, 2]
    assert abs(sum(c.area for c in found.cells) - 24.0) < 1e-9
    assert found.mismatches == ()
    assert found.extreme("y", 1)[0] == pytest.approx(1.0, abs=1e-12)   # along the whole arc
    assert found.extreme("x", -1)[0] == pytest.approx(-2.0, abs=1e-12)


def test_window_validation_names_the_parameter():
    loop = load_loop(os.path.join(ROOT, "examples", "loops", "paper.toml"))
    with pytest.raises(ValueError, match="x_range"):
        loop.region(x_range=(1.0, 0.0))
    with pytest.raises(ValueError, match="y_range"):
        loop.region(y_range=(0.0, float("nan")))
    with pytest.raises(ValueError, match="x_range"):
        StabilityRegion(gamma=0.0, d=0, delta=DELTA).decomposition((0.0, 1.0, 2.0), (0, 1))
    assert isinstance(Cell, type)


# --------------------------------------------------------------------------
# Found by an attack on the first version


def test_a_piece_ending_tangentially_on_a_line_still_cuts_the_plane():
    """A biproper plant: the arc ends on z = -1 along it; the point below the arc is unstable."""
    import control

    from symstab import Loop

    loop = Loop("(s + a)/(s + p)", "K + B*(z-1)/(T*z)",
                values=dict(a=10.0, p=100.0, T=1e-3, d=0, B=0.0, K=1.0))
    found = loop.region("B", "K", x_range=(-2, 2), y_range=(-50, 50))
    B, K = 0.0937, -6.387
    poles = np.abs(control.poles(loop.closed_loop(B=B, K=K)))
    assert int(found.count_at(B, K)) == int(np.sum(poles > 1)) == 2
    assert found.mismatches == ()


def test_a_window_edge_on_the_sets_own_boundary_is_not_unbounded():
    loop = load_loop(os.path.join(ROOT, "examples", "loops", "paper.toml"))
    whole = loop.limits()
    for window in (dict(y_range=(0.0, 10.0)), dict(x_range=(-0.0324, 1.0))):
        lim = loop.limits(**window)
        assert lim.area == pytest.approx(whole.area, rel=1e-6), window
        assert lim.x_min == pytest.approx(-0.0324, rel=1e-9)


def test_a_window_too_coarse_for_the_stable_set_is_refused():
    """gamma = 0, d = 4: a stable set 0.3 wide in a window 2e4 wide cannot be drawn by its chords."""
    region = StabilityRegion(gamma=0.0, d=4, delta=DELTA)
    fine = region.decomposition((-1.0, 1.0), (-1.0, 1.0)).area
    with pytest.raises(ValueError, match="narrow the window"):
        region.decomposition((-1e4, 1e4), (-1e4, 1e4))
    # Monte-Carlo in the fine window's stable bounding box agrees with it.
    rng = np.random.default_rng(7)
    n = 20000
    x, y = rng.uniform(-0.01, 0.33, n), rng.uniform(0.0, 0.03, n)
    rows = loop_coefficients(alpha=y, beta=x, gamma=0.0, d=4, delta=DELTA)
    p = np.mean(_outside(rows) == 0)
    box = 0.34 * 0.03
    assert abs(fine - box * p) <= 3 * box * np.sqrt(p * (1 - p) / n)


def test_a_long_delay_finds_its_small_stable_set():
    """d = 500: the stable set is 1e-6 of the arc's reach; the first window must still find it
    (it found nothing and then hung in a window of the whole arc)."""
    import symstab

    loop = load_loop(os.path.join(ROOT, "examples", "loops", "paper.toml"))
    ours = loop.limits(d=500)
    today = symstab.limits(gamma=0.0, d=500, delta=DELTA)
    assert ours.y_max == pytest.approx(today.alpha_max * M / T**2, rel=1e-9)
    assert ours.x_max == pytest.approx(today.beta_right * M / T, rel=1e-8)


def test_a_window_with_too_many_crossings_is_refused_quickly():
    base, ax, ay, ends = _paper_basis(0.0, 500)
    with pytest.raises(ValueError, match="too many pieces"):
        decompose(base, ax, ay, ends, x_range=(-5875.0, 5610.0), y_range=(-1.12e7, 1.14e7))


def _paper_basis(gamma, d):
    """The (B, K) basis of the paper's loop file (as Loop.region builds it)."""
    loop = load_loop(os.path.join(ROOT, "examples", "loops", "paper.toml"))
    base, (ax, ay), ends = loop.affine_parts(("B", "K"), {"d": d, "M": gamma * M})
    return base, ax, ay, ends
