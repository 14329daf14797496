"""Tests of the generated numeric kernels in ``symstab/_generated/``.

``symstab derive`` prints the float-safe forms of :mod:`symstab.codegen.float_forms`
as a NumPy module (``kernels.py``) and a C99 library
(``symstab_kernels.c`` / ``.h``).  The exact checker proves the *forms*
equal to the derivation; these tests measure what is left, the floating-point
evaluation of the printed code:

* the C library compiles warning-free under ``-Werror`` and its header's
  signatures are the ones the kernels are called with;
* C and NumPy agree to 1e-12 on a few thousand seeded random points;
* both kernels match 50-digit mpmath references -- the derivation's own
  (unrearranged) boundary :func:`symstab.numeric.paper.reference.boundary_point`, the
  definitions of the series functions (zoh_b1, ...) and ``characteristic_polynomial().numeric_coeffs``;
* the naive float evaluation of the derivation's C-coefficient form fails
  the same accuracy check at small delta, so that check can fail, and the
  rearranged forms are needed.

Notes
-----
Errors are relative to the reference value.  The mixed measure of
:func:`conftest.relative_error` (absolute where the reference is exactly 0)
matters only for the loop coefficients, one of which is the constant 1 and
one proportional to gamma (0 at gamma = 0).
"""

import ctypes
import functools
import math
import re
import shutil
import subprocess

import mpmath
import numpy as np
import pytest
import sympy as sp

import symstab
from symstab._generated import kernels as numpy_kernels
from symstab.codegen.float_forms import SERIES_FUNCTIONS
from symstab.numeric.paper.reference import boundary_point
from symstab.symbolic import model
from symstab.symbolic.boundary import boundary
from symstab.symbolic.theta_max import theta_max

from conftest import PAPER_DELTA, REPO, relative_error
from oracles import (
    first_principles_boundary_point,
    first_principles_chi,
    first_principles_chi_float,
)

GENERATED = REPO / "symstab" / "_generated"
C_SOURCE = GENERATED / "symstab_kernels.c"
C_HEADER = GENERATED / "symstab_kernels.h"

#: C vs NumPy: the same operations in the same order; only libm and NumPy's
#: own sin/cos/tan/expm1 (which may be SIMD) differ by an ulp or so.
C_VS_NUMPY_RTOL = 1e-12
#: Kernel vs the 50-digit reference of the boundary.
BOUNDARY_RTOL = 1e-10
#: The series functions (zoh_b1, zoh_b0, zoh_gap, decay_mean), both branches:
#: an alternating Horner sum dominated by its first term below the switch, a
#: difference that cancels at most a factor of about 4 above it (measured
#: at most 5.7 ulp, for zoh_gap just above its switch at 2).
SERIES_FUNCTION_RTOL = 16 * 2.0**-53
#: Loop coefficients vs the 30-digit coefficients, relative to the largest.
LOOP_RTOL = 1e-12


# --------------------------------------------------------------------------
# The C library: compile with -Werror, load with ctypes from the header
# --------------------------------------------------------------------------

_C_TYPES = {
    "double": ctypes.c_double,
    "int": ctypes.c_int,
    "double *": ctypes.POINTER(ctypes.c_double),
    "void": None,
}
_PROTOTYPE = re.compile(r"^(double|void) (symstab_\w+)\(([^)]*)\);$", re.MULTILINE)
_PARAMETER = re.compile(r"\s*(double|int)\s*(\*?)\s*\w+\s*")


def header_signatures(text):
    """``{name: (C return type, [C parameter types])}`` of the prototypes in ``text``.

    Types are spelled ``"double"``, ``"int"``, ``"double *"``, ``"void"``;
    a parameter of any other type raises, so the wrappers never guess.
    """
    signatures = {}
    for ret, name, params in _PROTOTYPE.findall(text):
        types = []
        for param in params.split(","):
            m = _PARAMETER.fullmatch(param)
            if m is None:
                raise ValueError(f"{name}: cannot map parameter {param.strip()!r} to ctypes")
            types.append(m[1] + (" *" if m[2] else ""))
        signatures[name] = (ret, types)
    return signatures


#: What the wrappers below call; the header must declare exactly this.
EXPECTED_SIGNATURES = {
    "symstab_zoh_b1": ("double", ["double"]),
    "symstab_zoh_b0": ("double", ["double"]),
    "symstab_zoh_gap": ("double", ["double"]),
    "symstab_decay_mean": ("double", ["double"]),
    "symstab_sin_multiple": ("double", ["int", "double"]),
    "symstab_cos_multiple": ("double", ["int", "double"]),
    "symstab_boundary": ("void", ["double", "double", "int", "double"] + ["double *"] * 2),
    "symstab_loop_coefficients": ("void", ["double"] * 4 + ["double *"] * 7),
    "symstab_plant_step_coefficients": ("void", ["double"] + ["double *"] * 4),
    "symstab_plant_step": ("void", ["double"] * 4 + ["double *"] * 2),
    "symstab_environment_force": ("double", ["double"] * 6),
}


class CKernels:
    """Python-callable wrappers of the loaded C library (scalars only)."""

    def __init__(self, lib):
        self.lib = lib

    def series_function(self, name, delta):
        return getattr(self.lib, f"symstab_{name}")(float(delta))

    @staticmethod
    def _outputs(n):
        # NaN-initialised, so an output the C code forgets to write is caught.
        return [ctypes.c_double(math.nan) for _ in range(n)]

    def multiple(self, name, k, x):
        return getattr(self.lib, f"symstab_{name}")(int(k), float(x))

    def boundary(self, theta, gamma, d, delta):
        out = self._outputs(2)
        self.lib.symstab_boundary(float(theta), float(gamma), int(d), float(delta),
                                  *(ctypes.byref(x) for x in out))
        return tuple(x.value for x in out)

    def loop_coefficients(self, alpha, beta, gamma, delta):
        out = self._outputs(7)
        self.lib.symstab_loop_coefficients(float(alpha), float(beta), float(gamma), float(delta),
                                           *(ctypes.byref(x) for x in out))
        return tuple(x.value for x in out)


def _c_compiler():
    for name in ("cc", "gcc"):
        path = shutil.which(name)
        if path:
            return path
    return None


@pytest.fixture(scope="session")
def c_kernels(tmp_path_factory):
    """The generated C compiled with ``-Werror`` into a shared library, loaded.

    A compiler warning fails every test that uses the library: the generated
    C must be warning-free under ``-std=c99 -Wall -Wextra -pedantic``.
    """
    compiler = _c_compiler()
    if compiler is None:
        pytest.skip("no C compiler found on PATH (tried cc, gcc); the C kernels are not tested")
    library = tmp_path_factory.mktemp("c_kernels") / "libsymstab_kernels.so"
    command = [compiler, "-std=c99", "-O2", "-Wall", "-Wextra", "-pedantic", "-Werror",
               "-fPIC", "-shared", f"-I{GENERATED}", str(C_SOURCE), "-o", str(library), "-lm"]
    proc = subprocess.run(command, capture_output=True, text=True, timeout=120)
    if proc.returncode != 0:
        pytest.fail(f"compiling the generated C failed ({' '.join(command)}):\n"
                    f"{proc.stdout}{proc.stderr}")
    lib = ctypes.CDLL(str(library))
    for name, (ret, params) in header_signatures(C_HEADER.read_text(encoding="utf-8")).items():
        function = getattr(lib, name)
        function.restype = _C_TYPES[ret]
        function.argtypes = [_C_TYPES[p] for p in params]
    return CKernels(lib)


def test_header_declares_the_called_signatures():
    """The header's prototypes are the ones the ctypes wrappers assume."""
    assert header_signatures(C_HEADER.read_text(encoding="utf-8")) == EXPECTED_SIGNATURES


def test_c_compiles_warning_free_and_exports_the_kernels(c_kernels):
    """Compiled with -Werror (by the fixture); every declared kernel is exported."""
    for name in EXPECTED_SIGNATURES:
        assert hasattr(c_kernels.lib, name), name


def test_header_parser_rejects_unknown_types():
    """A prototype the wrappers cannot type must raise, not be guessed."""
    with pytest.raises(ValueError, match="float"):
        header_signatures("void symstab_f(float x);\n")


# --------------------------------------------------------------------------
# C vs NumPy on random points
# --------------------------------------------------------------------------

N_RANDOM = 3000


@pytest.fixture(scope="module")
def random_points():
    """Seeded random points: delta log-uniform in [1e-6, 1], d in 0..200,
    gamma in [-0.9, 3], theta in (1e-4, 3.1), alpha in [-1, 5], beta in [-2, 3]."""
    rng = np.random.default_rng(20240607)
    return dict(
        delta=10 ** rng.uniform(-6.0, 0.0, N_RANDOM),
        d=rng.integers(0, 201, N_RANDOM),
        gamma=rng.uniform(-0.9, 3.0, N_RANDOM),
        theta=rng.uniform(1e-4, 3.1, N_RANDOM),
        alpha=rng.uniform(-1.0, 5.0, N_RANDOM),
        beta=rng.uniform(-2.0, 3.0, N_RANDOM),
    )


def _mixed_error(actual, expected):
    """Vectorised :func:`conftest.relative_error`: absolute only where expected == 0."""
    actual, expected = np.broadcast_arrays(np.asarray(actual, float), np.asarray(expected, float))
    err = np.abs(actual - expected)
    nonzero = expected != 0
    err[nonzero] /= np.abs(expected[nonzero])
    return err


def _assert_all_below(errors, rtol, points, label):
    """Assert ``errors <= rtol`` everywhere; on failure name the worst point."""
    k = int(np.argmax(errors))
    where = ", ".join(f"{name}={np.asarray(v)[k]!r}" for name, v in points.items())
    assert errors[k] <= rtol, (f"{label}: {np.count_nonzero(errors > rtol)} of {errors.size} points "
                               f"exceed {rtol:g}; worst {errors[k]:.3g} at {where}")


@pytest.mark.parametrize("name", [f.__name__ for f in SERIES_FUNCTIONS])
def test_c_series_functions_match_numpy(c_kernels, random_points, name):
    delta = np.concatenate([random_points["delta"], [0.0, 1.0, 2.0, 400.0, 710.0, 1e4, 1e6]])
    c = np.array([c_kernels.series_function(name, x) for x in delta])
    _assert_all_below(_mixed_error(c, getattr(numpy_kernels, name)(delta)), C_VS_NUMPY_RTOL,
                      {"delta": delta}, f"{name}, C vs NumPy")


def test_c_boundary_matches_numpy(c_kernels, random_points):
    """alpha and beta agree on random points, anywhere in (0, 3.1).

    The points are not restricted to the arc, so some lie near a root of
    alpha or beta, where the relative difference of two float evaluations
    grows as 1 / |value| (worst measured 5e-14 at |alpha| ~ 1e-4).
    """
    p = random_points
    numpy_alpha = np.empty(N_RANDOM)
    numpy_beta = np.empty(N_RANDOM)
    for d in np.unique(p["d"]):
        # d is a Python int in the kernel's contract: vectorise per delay.
        m = p["d"] == d
        numpy_alpha[m], numpy_beta[m] = numpy_kernels.boundary(p["theta"][m], p["gamma"][m],
                                                               int(d), p["delta"][m])
    c_alpha, c_beta = np.array([c_kernels.boundary(t, g, d, dl) for t, g, d, dl in
                                zip(p["theta"], p["gamma"], p["d"], p["delta"], strict=True)]).T
    where = {k: p[k] for k in ("theta", "gamma", "d", "delta")}
    _assert_all_below(_mixed_error(c_alpha, numpy_alpha), C_VS_NUMPY_RTOL, where, "alpha, C vs NumPy")
    _assert_all_below(_mixed_error(c_beta, numpy_beta), C_VS_NUMPY_RTOL, where, "beta, C vs NumPy")


def test_c_loop_coefficients_match_numpy(c_kernels, random_points):
    p = random_points
    args = [p[k] for k in ("alpha", "beta", "gamma", "delta")]
    numpy_c = numpy_kernels.loop_coefficients(*args)
    c_c = np.array([c_kernels.loop_coefficients(*point) for point in zip(*args, strict=True)]).T
    where = {k: p[k] for k in ("alpha", "beta", "gamma", "delta")}
    for k in range(7):
        # c2 is the constant 1 (a scalar in NumPy): broadcast before comparing.
        _assert_all_below(_mixed_error(c_c[k], numpy_c[k]), C_VS_NUMPY_RTOL, where,
                          f"c{k}, C vs NumPy")


# --------------------------------------------------------------------------
# The boundary against the derivation at 50 digits
# --------------------------------------------------------------------------

DELTAS = (1e-6, 1e-5, 1e-4, PAPER_DELTA, 0.03, 0.3, 0.51, 0.99, 1.0)
DELAYS = (0, 1, 5, 40, 200)
GAMMAS = (-0.5, 0.0, 1.0, 2.0)
N_THETA = 6
THETA_MIN = 1e-4


def _grid():
    """(delta, d, gamma) combinations of the reference grid.

    theta_max costs 0.25 s at d <= 5, 0.45 s at d = 40 and 1.8 s at d = 200
    (a scan of 16 (d+1) points at 70 digits), so the full 9 x 5 x 4 grid takes
    100 s.  Every (delta, d) pair is kept, with the gammas rotated so that
    every (delta, gamma) and every (d, gamma) pair still occurs: two gammas per
    pair, one at d = 200.  About 40 s.
    """
    out = []
    for i, delta in enumerate(DELTAS):
        for j, d in enumerate(DELAYS):
            picks = [(i + j) % 4] if d == 200 else [(i + j) % 4, (i + j + 2) % 4]
            out += [(delta, d, GAMMAS[k]) for k in picks]
    return out


GRID = _grid()
GRID_IDS = [f"delta={delta:g}-d={d}-gamma={gamma:g}" for delta, d, gamma in GRID]


@functools.lru_cache(maxsize=None)
def _theta_max(delta, d, gamma):
    """theta_max, computed once per point (shared by the tests below)."""
    return theta_max(gamma=gamma, d=d, delta=delta)


def _arc_end_or_skip(delta, d, gamma):
    t_end = _theta_max(delta, d, gamma)
    if math.isnan(t_end):
        pytest.skip("no arc: alpha < 0 just after theta = 0")
    return t_end


def _kernel_boundaries(c_kernels):
    """``{name: f(theta, gamma, d, delta) -> (alpha, beta)}``, NumPy and C."""
    return {"numpy": numpy_kernels.boundary, "C": c_kernels.boundary}


@pytest.mark.parametrize("delta, d, gamma", GRID, ids=GRID_IDS)
def test_boundary_matches_derivation_at_50_digits(c_kernels, delta, d, gamma):
    """alpha and beta of both kernels to 1e-10 relative on the arc.

    theta runs over a geometric grid from 1e-4 up to, but excluding,
    theta_max: alpha(theta_max) = 0, so its relative error is unbounded for
    any floating-point evaluation (the condition number of a function at a
    root is infinite); the absolute error there is tested separately.
    """
    t_end = _arc_end_or_skip(delta, d, gamma)
    # [:-1] drops theta_max itself: alpha = 0 there, relative error is meaningless.
    thetas = np.geomspace(THETA_MIN, t_end, N_THETA + 1)[:-1]
    failures = []
    for theta in thetas:
        ref = boundary_point(float(theta), gamma=gamma, d=d, delta=delta, dps=50)
        for kernel, f in _kernel_boundaries(c_kernels).items():
            for name, value, expected in zip(("alpha", "beta"), f(theta, gamma, d, delta), ref,
                                             strict=True):
                err = relative_error(mpmath.mpf(float(value)), expected)
                if not err <= BOUNDARY_RTOL:
                    failures.append(f"{kernel} {name} at theta={theta!r}: {float(value)!r} vs "
                                    f"{mpmath.nstr(expected, 17)}, relative error {float(err):.3g}")
    assert not failures, "\n".join(failures)


#: Angles of the whole half circle, dense at both ends (issue 19's acceptance).
CIRCLE = np.unique(np.concatenate([np.geomspace(1e-6, 0.1, 25), np.linspace(0.1, np.pi - 0.1, 40),
                                   np.pi - np.geomspace(1e-6, 0.1, 25)]))
#: Norm-wise relative error of (alpha, beta) on the whole half circle.
CIRCLE_RTOL = 1e-12


@pytest.mark.parametrize("gamma, d, delta", [(0.0, 0, 0.1), (-0.5, 1, 2.0), (1.5, 10, 2.0),
                                             (0.0, 40, 0.1), (-0.5, 200, 0.00253125),
                                             (1.0, 1000, 20.0), (0.5, 5, 1e-6)])
def test_boundary_on_the_whole_circle_matches_first_principles(c_kernels, gamma, d, delta):
    """(alpha, beta) of both kernels to 1e-12 of their size for theta in [1e-6, pi - 1e-6].

    The reference is the first-principles solve of Delta(exp(j theta)) = 0
    (the printed eqs. (1), (2), (4)) at 50 digits.  Next to pi the sines of
    (d + 1) theta and (2d + 1) theta / 2 are small and their arguments
    large: rounding the products before the sine cost up to 1.2e-9 here
    (gamma = 0, d = 40, delta = 0.1, theta = pi - 1e-6).
    """
    failures = []
    for kernel, f in _kernel_boundaries(c_kernels).items():
        worst, where = 0.0, None
        for theta in CIRCLE:
            alpha, beta = f(float(theta), gamma, d, delta)
            with mpmath.workdps(50):
                ra, rb = first_principles_boundary_point(float(theta), gamma, d, delta)
                err = float(max(abs(alpha - ra), abs(beta - rb)) / max(abs(ra), abs(rb)))
            if err > worst:
                worst, where = err, theta
        if not worst <= CIRCLE_RTOL:
            failures.append(f"{kernel}: relative error {worst:.3g} at theta = {where!r}")
    assert not failures, "\n".join(failures)


@pytest.mark.parametrize("name", ["sin_multiple", "cos_multiple"])
def test_multiple_angle_helpers_match_mpmath(c_kernels, name):
    """sin(k x), cos(k x) of both kernels to 2 ulp of their value (plus 1e-16 k x ulp absolute).

    The helpers carry k x exactly; the naive float product loses the digits
    of k x's rounding, relative to the value where sin(k x) is small.
    """
    function = {"sin_multiple": mpmath.sin, "cos_multiple": mpmath.cos}[name]
    ks = [1, 2, 7, 41, 2001, 20001]
    xs = [1e-9, 0.3, 1.5, np.pi / 2 - 1e-7, np.pi - 1e-3, np.pi - 1e-6, np.pi - 1e-9, np.pi]
    naive = {"sin_multiple": np.sin, "cos_multiple": np.cos}[name]
    naive_worst = 0.0
    for k in ks:
        for x in xs:
            with mpmath.workdps(50):
                want = function(k * mpmath.mpf(float(x)))
            bound = 2 * 2.0**-52 * abs(want) + 1e-32 * k * x
            for kernel, got in (("numpy", getattr(numpy_kernels, name)(k, x)),
                                ("C", c_kernels.multiple(name, k, x))):
                assert abs(got - want) <= bound, (kernel, k, x, got, want)
            naive_worst = max(naive_worst, float(abs(naive(k * x) - want) / bound))
    # The check can fail: the naive product misses the bound by orders of magnitude.
    assert naive_worst > 1e3


@pytest.mark.parametrize("delta, d, gamma", GRID, ids=GRID_IDS)
def test_alpha_vanishes_at_theta_max(c_kernels, delta, d, gamma):
    """|alpha(theta_max)| <= 1e-12 max alpha on the arc, for both kernels.

    At the root only the absolute error means anything; it should be about
    1e-16 times the size of the terms of alpha, i.e. of max alpha.
    """
    t_end = _arc_end_or_skip(delta, d, gamma)
    if t_end == float(mpmath.pi):
        pytest.skip("alpha does not return to 0 before theta = pi")
    # The peak only sets the scale: a dense grid of the kernel itself will do.
    arc = np.linspace(0.0, t_end, 4001)[1:-1]
    peak = float(np.max(numpy_kernels.boundary(arc, gamma, d, delta)[0]))
    assert peak > 0
    for kernel, f in _kernel_boundaries(c_kernels).items():
        alpha_end = float(f(t_end, gamma, d, delta)[0])
        assert abs(alpha_end) <= 1e-12 * peak, (
            f"{kernel}: alpha(theta_max={t_end!r}) = {alpha_end:.3g}, max alpha on the arc {peak:.3g}")


# --------------------------------------------------------------------------
# The series functions against their definitions, delta from 0 to 1e6
# --------------------------------------------------------------------------

SERIES_POINTS = np.unique(np.concatenate([
    [0.0, 1e-300, 1e-20, 1e-8],
    np.geomspace(1e-6, 1e6, 600),
    # Both sides of the switches from the Taylor polynomial to expm1.
    [np.nextafter(x, 0.0) for x in (1.0, 2.0)], [1.0, 2.0],
    1.0 + 1e-3 * np.arange(-20, 21), 2.0 + 1e-3 * np.arange(-20, 21),
]))


def _series_reference(name, x):
    """The definition at 40 digits plus the digits it cancels; the limit at 0."""
    if x == 0.0:
        return {"zoh_b1": mpmath.mpf(1) / 2, "zoh_b0": mpmath.mpf(1) / 2,
                "zoh_gap": mpmath.mpf(1) / 6, "decay_mean": mpmath.mpf(1)}[name]
    with mpmath.workdps(40 + int(3 * max(0.0, -math.log10(x)))):
        x = mpmath.mpf(float(x))
        e = mpmath.exp(-x)
        return {"zoh_b1": (x - 1 + e) / x**2,
                "zoh_b0": (1 - e - x * e) / x**2,
                "zoh_gap": (x * (1 + e) - 2 * (1 - e)) / x**3,
                "decay_mean": (1 - e) / x}[name]


@pytest.mark.parametrize("kernel", ["numpy", "C"])
@pytest.mark.parametrize("name", [f.__name__ for f in SERIES_FUNCTIONS])
def test_series_functions_match_definition_from_0_to_1e6(request, kernel, name):
    """Both branches within 16 ulp of the definition (measured at most 5.7)."""
    if kernel == "numpy":
        values = getattr(numpy_kernels, name)(SERIES_POINTS)
    else:
        c = request.getfixturevalue("c_kernels")
        values = np.array([c.series_function(name, x) for x in SERIES_POINTS])
    errors = np.array([float(relative_error(mpmath.mpf(float(v)), _series_reference(name, x)))
                       for v, x in zip(values, SERIES_POINTS, strict=True)])
    _assert_all_below(errors, SERIES_FUNCTION_RTOL, {"delta": SERIES_POINTS}, f"{kernel} {name}")


# --------------------------------------------------------------------------
# Loop coefficients against the 30-digit characteristic polynomial
# --------------------------------------------------------------------------

def _loop_points():
    """A few dozen seeded points, with delta = 1e-6 and the overlapping d = 0, 1, 2."""
    rng = np.random.default_rng(7)
    points = []
    for k in range(36):
        points.append(dict(
            alpha=float(rng.uniform(-1.0, 5.0)), beta=float(rng.uniform(-2.0, 3.0)),
            gamma=float(rng.uniform(-0.9, 3.0)),
            d=int(k if k < 3 else rng.integers(0, 201)),
            delta=1e-6 if k % 4 == 0 else float(10 ** rng.uniform(-6.0, 0.0))))
    return points


LOOP_POINTS = _loop_points()


def assemble(coefficients, d):
    """Place the kernel's c0..c6 in the length-(d+5) vector, highest power first.

    c0..c2 are the coefficients of z^(d+4), z^(d+3), z^(d+2); c3..c6 those of
    z^3..z^0.  For d < 2 the two groups overlap and add.
    """
    out = np.zeros(d + 5)
    out[:3] += coefficients[:3]
    out[-4:] += coefficients[3:]
    return out


@pytest.mark.parametrize("kernel", ["numpy", "C"])
@pytest.mark.parametrize("point", LOOP_POINTS,
                         ids=[f"d={p['d']}-delta={p['delta']:.3g}" for p in LOOP_POINTS])
def test_loop_coefficients_match_characteristic_polynomial(request, loop, kernel, point):
    """Every coefficient of chi / (delta^2 Gamma) within 1e-12 of the largest one."""
    args = [point[k] for k in ("alpha", "beta", "gamma", "delta")]
    if kernel == "numpy":
        values = [float(c) for c in numpy_kernels.loop_coefficients(*args)]
    else:
        values = request.getfixturevalue("c_kernels").loop_coefficients(*args)
    actual = assemble(np.array(values), point["d"])
    expected = loop.numeric_coeffs(**point) / (point["delta"] ** 2 * math.exp(point["delta"]))
    errors = np.abs(actual - expected) / np.max(np.abs(expected))
    k = int(np.argmax(errors))
    assert errors[k] <= LOOP_RTOL, (
        f"{kernel}: coefficient {k} (of z^{point['d'] + 4 - k}) is {actual[k]!r}, expected "
        f"{expected[k]!r}; error {errors[k]:.3g} of the largest coefficient at {point}")


# --------------------------------------------------------------------------
# Why the rearranged forms: the naive C-coefficient form fails the same check
# --------------------------------------------------------------------------

@functools.lru_cache(maxsize=None)
def _naive_alpha():
    """alpha of the derivation, Gamma -> exp(delta), evaluated in NumPy floats."""
    args = (model.theta, model.gamma, model.d, model.delta)
    return sp.lambdify(args, boundary().alpha.subs(model.Gamma, sp.exp(model.delta)),
                       modules="numpy")


@pytest.mark.parametrize("d", [0, 5, 40])
@pytest.mark.parametrize("theta", [1e-3, 1e-2, 0.1])
def test_naive_form_loses_digits_where_kernel_does_not(c_kernels, d, theta):
    """At delta = 1e-6 the C-coefficient form cancels ~log10(1/delta^2) digits.

    Its relative error exceeds 1e-6 (so the 1e-10 check above can fail),
    while both kernels stay within that check's bound.
    """
    gamma, delta = 0.5, 1e-6
    expected = boundary_point(theta, gamma=gamma, d=d, delta=delta, dps=50)[0]
    naive = float(_naive_alpha()(theta, gamma, d, delta))
    assert relative_error(mpmath.mpf(naive), expected) > 1e-6
    for kernel, f in _kernel_boundaries(c_kernels).items():
        value = float(f(theta, gamma, d, delta)[0])
        assert relative_error(mpmath.mpf(value), expected) <= BOUNDARY_RTOL, kernel


# --------------------------------------------------------------------------
# The simulator's kernels: plant step and environment force, C vs NumPy
# --------------------------------------------------------------------------

def _c_call(function, args, n_out):
    """Call a void C kernel with NaN-initialised outputs; return them."""
    out = [ctypes.c_double(math.nan) for _ in range(n_out)]
    function(*(float(a) for a in args), *(ctypes.byref(x) for x in out))
    return tuple(x.value for x in out)


@pytest.fixture(scope="module")
def simulator_points():
    """Seeded: delta log-uniform in [1e-6, 5], states, forces and environments."""
    rng = np.random.default_rng(20250101)
    n = N_RANDOM
    return dict(
        delta=10 ** rng.uniform(-6.0, np.log10(5.0), n),
        position=rng.uniform(-10.0, 10.0, n), velocity=rng.uniform(-1.0, 1.0, n),
        force=rng.uniform(-1.0, 1.0, n),
        x_k=rng.uniform(-5.0, 5.0, n), x_km1=rng.uniform(-5.0, 5.0, n),
        x_km2=rng.uniform(-5.0, 5.0, n),
        alpha=rng.uniform(-1.0, 5.0, n), beta=rng.uniform(-2.0, 3.0, n),
        gamma=rng.uniform(-0.9, 3.0, n),
    )


def test_c_plant_step_coefficients_match_numpy(c_kernels, simulator_points):
    delta = simulator_points["delta"]
    c = np.array([_c_call(c_kernels.lib.symstab_plant_step_coefficients, (x,), 4) for x in delta]).T
    numpy_c = numpy_kernels.plant_step_coefficients(delta)
    for k, name in enumerate(("phi01", "phi11", "gamma0", "gamma1")):
        _assert_all_below(_mixed_error(c[k], numpy_c[k]), C_VS_NUMPY_RTOL, {"delta": delta},
                          f"{name}, C vs NumPy")


def test_c_plant_step_matches_numpy(c_kernels, simulator_points):
    p = simulator_points
    args = [p[k] for k in ("position", "velocity", "force", "delta")]
    c = np.array([_c_call(c_kernels.lib.symstab_plant_step, point, 2)
                  for point in zip(*args, strict=True)]).T
    numpy_c = numpy_kernels.plant_step(*args)
    where = {k: p[k] for k in ("position", "velocity", "force", "delta")}
    for k, name in enumerate(("position_next", "velocity_next")):
        _assert_all_below(_mixed_error(c[k], numpy_c[k]), C_VS_NUMPY_RTOL, where,
                          f"{name}, C vs NumPy")


def test_c_environment_force_matches_numpy(c_kernels, simulator_points):
    """Same expression, same order: equal to 1e-12 relative (measured: bit for bit)."""
    p = simulator_points
    names = ("x_k", "x_km1", "x_km2", "alpha", "beta", "gamma")
    args = [p[k] for k in names]
    function = c_kernels.lib.symstab_environment_force
    c = np.array([function(*(float(a) for a in point)) for point in zip(*args, strict=True)])
    _assert_all_below(_mixed_error(c, numpy_kernels.environment_force(*args)), C_VS_NUMPY_RTOL,
                      {k: p[k] for k in names}, "force, C vs NumPy")


# --------------------------------------------------------------------------
# Dense grids, zeros of alpha and beta included


@pytest.mark.parametrize("gamma, d, delta", [(0.0, 0, PAPER_DELTA), (1.0, 10, PAPER_DELTA),
                                             (0.5, 200, 1e-6), (-0.5, 5, 1.0),
                                             (0.0, 0, 400.0), (1.0, 3, 710.0), (0.5, 10, 1e4)])
def test_boundary_on_a_dense_grid_mixed_error(gamma, d, delta):
    """200 angles from 1e-4 to theta_max, where beta changes sign and alpha ends at 0.

    At a zero of alpha or beta no floating-point evaluation is relatively
    accurate (the condition number is infinite there: theta itself is rounded),
    so the bound is mixed: |error| <= 1e-10 |value| + 1e-14 max|value on the arc|.
    """
    # The angle range only says where to look (the 30-digit theta_max's
    # tolerance is absolute and fails beyond delta ~ 700); the oracle is
    # boundary_point.
    t_end = symstab.arc_end_angle(gamma=gamma, d=d, delta=delta)
    thetas = np.linspace(1e-4, t_end, 200)
    alpha, beta = numpy_kernels.boundary(thetas, gamma, d, delta)
    refs = [boundary_point(float(t), gamma=gamma, d=d, delta=delta, dps=50) for t in thetas]
    ra = np.array([float(a) for a, _ in refs])
    rb = np.array([float(b) for _, b in refs])
    for name, got, ref in (("alpha", alpha, ra), ("beta", beta, rb)):
        bound = 1e-10 * np.abs(ref) + 1e-14 * np.max(np.abs(ref))
        worst = int(np.argmax(np.abs(got - ref) - bound))
        assert np.all(np.abs(got - ref) <= bound), (
            f"{name} at theta = {thetas[worst]!r}: {got[worst]!r} vs {ref[worst]!r}")


# --------------------------------------------------------------------------
# delta = 0 (a frictionless device) and large delta: no overflow, no 0 / 0


def _first_principles_coefficients(alpha, beta, gamma, d, delta, dps=60):
    """chi(z) / (delta**2 Gamma) from eqs. (1), (2), (4) (tests/oracles.py), at ``dps`` digits."""
    return list(first_principles_chi_float(alpha, beta, gamma, d, delta, dps=dps))


EXTREME_DELTAS = (0.0, 1e-300, 400.0, 710.0, 1e4, 1e6)


@pytest.mark.parametrize("delta", EXTREME_DELTAS)
@pytest.mark.parametrize("kernel", ["numpy", "C"])
def test_loop_coefficients_at_extreme_delta_match_first_principles(request, kernel, delta):
    """Today's forms overflowed for delta > 709 and were 0 / 0 at delta = 0."""
    args = (0.1, 0.5, 0.7, delta)
    if kernel == "numpy":
        values = [float(c) for c in numpy_kernels.loop_coefficients(*args)]
    else:
        values = request.getfixturevalue("c_kernels").loop_coefficients(*args)
    actual = assemble(np.array(values), 3)
    expected = np.array(_first_principles_coefficients(*args[:3], 3, delta))
    assert np.all(np.isfinite(actual))
    errors = np.abs(actual - expected) / np.max(np.abs(expected))
    assert np.max(errors) <= LOOP_RTOL, f"{actual} vs {expected}"


@pytest.mark.parametrize("delta, d", [(0.0, 0), (0.0, 5), (400.0, 0), (710.0, 0), (1e4, 2), (1e6, 1)])
def test_classification_at_extreme_delta_matches_60_digit_roots(delta, d):
    """The issue's cases (delta = 400 and 710 called empty or unstable) and delta = 0.

    Points on a ray through the stable region's neighbourhood; the oracle is
    mpmath.polyroots of the first-principles polynomial at 60 digits.
    """
    alphas = np.array([0.05, 0.1, 0.5, 1.0, 2.0, 4.0])
    beta = 0.5
    codes = symstab.classify(alpha=alphas, beta=beta, gamma=0.0, d=d, delta=delta)
    radii = symstab.spectral_radius(alpha=alphas, beta=beta, gamma=0.0, d=d, delta=delta)
    with mpmath.workdps(60):
        for a, code, radius in zip(alphas, codes, radii, strict=True):
            roots = mpmath.polyroots(first_principles_chi(a, beta, 0.0, d, delta),
                                     maxsteps=200, extraprec=200)
            exact = max(abs(r) for r in roots)
            assert abs(exact - 1) > 1e-9, "test point too close to the boundary"
            assert code == (symstab.STABLE if exact < 1 else symstab.UNSTABLE), (a, exact)
            assert abs(radius - float(exact)) <= 1e-9, (a, radius, exact)
