"""Tests of ``symstab derive --loop`` (:mod:`symstab.proof.loop_derive`).

* The files are deterministic (two runs, two hash seeds: the same bytes) and
  carry no date, version or path.
* The generated code is tested by numbers: the C library (compiled with the
  system compiler, ``-Werror``) against the NumPy module, the plant's pulse
  transfer function against python-control's ``c2d``, and the polynomial
  assembled from the C kernels against :meth:`symstab.Loop.coefficients`.
* ``--check`` reports a hand-edited, a missing and a stale extra file; a bad
  loop file is one error line and exit 2, with nothing written; a file of the
  user's is never overwritten.
* The proofs that the paper's loop built by :class:`symstab.Loop` is today's
  derivation run in ``symstab derive`` and fail for another loop.
"""

import contextlib
import ctypes
import importlib.util
import io
import json
import math
import os
import re
import shutil
import subprocess
import sys

import numpy as np
import pytest
import sympy as sp

from symstab.cli import commands as cli
from symstab.codegen.loop_kernels import _digest
from symstab.numeric.loop.files import load_loop, parse_loop_text
from symstab.proof import loop_derive
from symstab.proof.identity import check_identity

from conftest import REPO, hash_seed_other_than_ours

PAPER_FILE = REPO / "examples" / "loops" / "paper.toml"

#: A plant whose denominator is an irreducible cubic: the numeric (matrix
#: exponential) path.  A spring and a damper as environment.  The units are
#: those that make G(s) force to displacement (loop files' units are checked).
NUMERIC_LOOP = """\
name = "spring-device"
description = "A third-order device: a mass on a spring with friction and an elastic ground"
plant = "1/(m*s**3 + b*s**2 + k*s + c)"
environment = "K + B*(z - 1)/(T*z)"
plane = ["B", "K"]

[parameters]
m = { value = 0.0128, unit = "N s^3/m" }
b = { value = 0.0324, unit = "N s^2/m" }
k = { value = 50.0, unit = "N s/m" }
c = { value = 10.0, unit = "N/m" }
T = { value = 1e-3, unit = "s" }
d = { value = 3, unit = "samples" }
"""

#: The flags the generated C must compile under without a warning (a slope
#: kernel's unused parameters are cast to void).
C_FLAGS = ["-std=c99", "-O2", "-Wall", "-Wextra", "-pedantic", "-Werror", "-fPIC", "-shared"]


@pytest.fixture(scope="module")
def cache_dir(session_cache_dir):
    """The session's cache (conftest): a loop another module derived is read here."""
    return session_cache_dir


@pytest.fixture(autouse=True)
def _cache(cache_dir, monkeypatch):
    monkeypatch.setenv("SYMSTAB_CACHE_DIR", str(cache_dir))


def run_cli(*argv):
    """``symstab.cli.commands.main(argv)`` in this process: (status, stdout, stderr)."""
    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        status = cli.main(list(argv))
    return status, out.getvalue(), err.getvalue()


@pytest.fixture(scope="module")
def paper_folder(tmp_path_factory, cache_dir):
    folder = tmp_path_factory.mktemp("paper") / "out"
    status, _, err = run_cli("derive", "--loop", str(PAPER_FILE), "--out", str(folder))
    assert status == 0, err
    return folder


@pytest.fixture(scope="module")
def paper_compiled(tmp_path_factory, paper_folder):
    """The C kernels of ``paper_folder``, compiled once for the module's three tests of them."""
    return _compile(paper_folder, tmp_path_factory.mktemp("paper_c"))


@pytest.fixture(scope="module")
def example_derived(tmp_path_factory, cache_dir):
    """``derived(path)``: ``symstab derive --loop path`` run and its C compiled, once per file.

    Returns ``(output folder, the compiled C functions)``; the complex-pair
    test and the every-example test share operator_arm's.
    """
    done = {}

    def derived(path):
        if path not in done:
            base = tmp_path_factory.mktemp(path.stem)
            folder = base / "out"
            status, _, err = run_cli("derive", "--loop", str(path), "--out", str(folder))
            assert status == 0, err
            done[path] = folder, _compile(folder, base)
        return done[path]

    return derived


@pytest.fixture(scope="module")
def numeric_file(tmp_path_factory):
    path = tmp_path_factory.mktemp("numeric") / "spring.toml"
    path.write_text(NUMERIC_LOOP, encoding="utf-8")
    return path


@pytest.fixture(scope="module")
def numeric_folder(numeric_file, cache_dir):
    folder = numeric_file.parent / "out"
    status, _, err = run_cli("derive", "--loop", str(numeric_file), "--out", str(folder))
    assert status == 0, err
    return folder


def _files(folder):
    return {p.name: p.read_bytes() for p in sorted(folder.iterdir())}


# --------------------------------------------------------------------------
# Files: what is written, deterministic, checked


def test_derive_loop_writes_the_loop_files(paper_folder):
    expected = loop_derive.loop_files(load_loop(PAPER_FILE))
    assert sorted(expected) == [
        "01_loop.json", "01_loop.tex", "02_zoh.json", "02_zoh.tex",
        "03_characteristic_polynomial.json", "03_characteristic_polynomial.tex",
        "04_affine_parameters.json", "04_affine_parameters.tex",
        "05_kernel_forms.json", "05_kernel_forms.tex",
        "paper_kernels.c", "paper_kernels.h", "paper_kernels.py"]
    assert _files(paper_folder) == {k: v.encode("utf-8") for k, v in expected.items()}
    for name, text in expected.items():
        assert loop_derive.is_generated(paper_folder / name), name
        if name.endswith(".json"):
            data = json.loads(text)
            assert data["step"] == name[:-5] and data["generated_by"] == "symstab derive --loop"


def test_derive_loop_is_byte_identical_in_another_process_and_hash_seed(paper_folder, tmp_path,
                                                                       cache_dir):
    out = tmp_path / "again"
    env = dict(os.environ, PYTHONHASHSEED=hash_seed_other_than_ours(),
               SYMSTAB_CACHE_DIR=str(cache_dir))
    proc = subprocess.run([sys.executable, "-m", "symstab", "derive", "--loop", str(PAPER_FILE),
                           "--out", str(out)], capture_output=True, text=True, env=env,
                          cwd=tmp_path, timeout=300)
    assert proc.returncode == 0, proc.stderr
    assert _files(out) == _files(paper_folder)


def test_output_has_no_dates_versions_or_paths(paper_folder, numeric_folder, numeric_file):
    import importlib.metadata
    import platform

    versions = {importlib.metadata.version(p) for p in ("sympy", "mpmath", "numpy", "symstab")}
    versions.add(platform.python_version())
    for folder in (paper_folder, numeric_folder):
        for name, data in _files(folder).items():
            text = data.decode("utf-8")
            assert not re.search(r"\b(19|20)\d\d-\d\d-\d\d\b", text), name
            assert not re.search(r"\b\d\d:\d\d:\d\d\b", text), name
            for v in versions:
                assert v not in text, (name, v)
            for path in (str(REPO), str(folder), str(numeric_file), "/tmp", "/home"):
                assert path not in text, (name, path)


def test_numpy_module_is_the_module_the_loop_runs_on():
    """The kernels written are those :class:`symstab.Loop` generates and caches (same hash)."""
    for text in (PAPER_FILE.read_text(encoding="utf-8"), NUMERIC_LOOP,
                 NUMERIC_LOOP.replace('"K + B*(z - 1)/(T*z)"', '"K + 2*B*(z - 1)/(T*(z + 1))"')):
        loop = parse_loop_text(text)
        module = loop._kernels[0]
        assert _digest(loop.kernels()) == module.__symstab_digest__


def test_check_passes_then_reports_edited_missing_and_extra_files(tmp_path, paper_folder):
    folder = tmp_path / "copy"
    shutil.copytree(paper_folder, folder)
    argv = ("derive", "--loop", str(PAPER_FILE), "--out", str(folder), "--check")
    status, out, _ = run_cli(*argv)
    assert status == 0 and "13 files" in out
    edited = folder / "paper_kernels.c"
    edited.write_text(edited.read_text(encoding="utf-8").replace("*num2 = M;", "*num2 = -M;"),
                      encoding="utf-8")
    (folder / "02_zoh.json").unlink()
    (folder / "05_old_step.tex").write_text("% generated by `symstab derive --loop`\n")
    (folder / "notes.txt").write_text("the user's: not ours, not drift\n")
    status, out, _ = run_cli(*argv)
    assert status == 1
    named = sorted(re.findall(r"^drift: (\S+) differs", out, re.MULTILINE))
    assert named == sorted(str(folder / n) for n in ("paper_kernels.c", "02_zoh.json",
                                                     "05_old_step.tex"))
    assert f"symstab derive --loop {PAPER_FILE} --out {folder}" in out
    status, out, _ = run_cli("derive", "--loop", str(PAPER_FILE), "--out",
                             str(tmp_path / "absent"), "--check")
    assert status == 1 and out.count("drift:") == 13
    assert not (tmp_path / "absent").exists()


def test_default_out_is_the_loop_name_in_the_current_folder(tmp_path, monkeypatch, numeric_file):
    monkeypatch.chdir(tmp_path)
    status, out, err = run_cli("derive", "--loop", str(numeric_file))
    assert status == 0, err
    # "spring-device": the name as a C identifier names the folder and the files.
    folder = tmp_path / "spring_device_derivation"
    assert sorted(os.listdir(tmp_path)) == ["spring_device_derivation"]
    assert {"spring_device_kernels.c", "spring_device_kernels.h",
            "spring_device_kernels.py"} <= set(os.listdir(folder))
    # A second run overwrites its own files.
    assert run_cli("derive", "--loop", str(numeric_file))[0] == 0


def test_a_file_of_the_users_is_never_overwritten(tmp_path):
    folder = tmp_path / "out"
    folder.mkdir()
    mine = folder / "paper_kernels.c"
    mine.write_text("int main(void) { return 0; }\n")
    status, out, err = run_cli("derive", "--loop", str(PAPER_FILE), "--out", str(folder))
    assert status == 2 and out == ""
    assert err.count("\n") == 1 and err.startswith("symstab derive: error: --out")
    assert str(mine) in err
    assert mine.read_text() == "int main(void) { return 0; }\n"
    assert os.listdir(folder) == ["paper_kernels.c"]


_BAD_FILES = {
    "missing": None,
    "not_toml": "plant = \n",
    "improper_plant": 'plant = "s**2/(m*s + b)"\nenvironment = "K"\n',
    "not_rational": 'plant = "1/(m*s**2 + sin(s))"\nenvironment = "K"\n',
    "unknown_key": 'plant = "1/(m*s**2)"\nenvironment = "K"\ncolour = "red"\n',
    "c_keyword_parameter": 'plant = "1/(m*s**2)"\nenvironment = "int + B*(z - 1)/(T*z)"\n',
}


@pytest.mark.parametrize("case", sorted(_BAD_FILES))
def test_a_bad_loop_file_is_one_line_and_exit_2_with_nothing_written(case, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    path = tmp_path / f"{case}.toml"
    if _BAD_FILES[case] is not None:
        path.write_text(_BAD_FILES[case], encoding="utf-8")
    before = sorted(os.listdir(tmp_path))
    status, out, err = run_cli("derive", "--loop", str(path))
    assert status == 2, (out, err)
    lines = err.splitlines()
    assert len(lines) == 1 and lines[0].startswith("symstab derive: error: "), err
    if case == "c_keyword_parameter":
        assert "'int'" in lines[0]
    else:
        assert str(path) in lines[0]
    assert sorted(os.listdir(tmp_path)) == before


def test_codegen_out_is_refused_with_loop(tmp_path):
    status, _, err = run_cli("derive", "--loop", str(PAPER_FILE), "--codegen-out", str(tmp_path))
    assert status == 2 and err.count("\n") == 1 and "--codegen-out" in err
    assert os.listdir(tmp_path) == []


# --------------------------------------------------------------------------
# The generated code, by numbers


def _compile(folder, tmp_path):
    compiler = shutil.which("cc") or shutil.which("gcc")
    if compiler is None:
        pytest.skip("no C compiler found on PATH (tried cc, gcc)")
    (source,) = folder.glob("*_kernels.c")
    library = tmp_path / (source.stem + ".so")
    command = [compiler, *C_FLAGS, f"-I{folder}", str(source), "-o", str(library), "-lm"]
    proc = subprocess.run(command, capture_output=True, text=True, timeout=120)
    if proc.returncode != 0:
        pytest.fail(f"compiling the generated C failed ({' '.join(command)}):\n{proc.stderr}")
    lib = ctypes.CDLL(str(library))
    header = source.with_suffix(".h").read_text(encoding="utf-8")
    functions = {}
    for name, params in re.findall(r"^void (symstab_\w+)\(([^)]*)\);$", header, re.MULTILINE):
        params = [p.strip() for p in params.split(",")]
        if name.endswith("_step"):
            continue      # the loop's step takes arrays: test_the_c_step_of_every_example_loop
        n_in = sum(1 for p in params if re.fullmatch(r"double \w+", p))
        n_out = sum(1 for p in params if re.fullmatch(r"double \*\w+", p))
        assert n_in + n_out == len(params), params
        function = getattr(lib, name)
        function.restype = None
        function.argtypes = [ctypes.c_double] * n_in + [ctypes.POINTER(ctypes.c_double)] * n_out

        def call(*args, _f=function, _n=n_out):
            out = [ctypes.c_double(math.nan) for _ in range(_n)]
            _f(*(float(a) for a in args), *(ctypes.byref(x) for x in out))
            return np.array([x.value for x in out])

        functions[name] = call
    # The helpers of one double (exprel_k), called by the kernels.
    for name in re.findall(r"^double (symstab_\w+)\(double x\);$", header, re.MULTILINE):
        function = getattr(lib, name)
        function.restype, function.argtypes = ctypes.c_double, [ctypes.c_double]
        functions[name] = function
    return functions


def _numpy_module(folder):
    (path,) = folder.glob("*_kernels.py")
    spec = importlib.util.spec_from_file_location(f"generated_{path.stem}", path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def _paper_points(n, seed):
    """Physical points of the paper's loop: a light device, 0.1 to 2 ms, delta from 1e-3 to 1."""
    rng = np.random.default_rng(seed)
    for _ in range(n):
        m = 10 ** rng.uniform(-2.5, 0)
        T = 10 ** rng.uniform(-4, -2.7)
        b = 10 ** rng.uniform(-3, 0) * m / T
        yield dict(m=m, b=b, T=T, K=rng.uniform(-50, 3000), B=rng.uniform(-1, 5),
                   M=rng.uniform(-0.01, 0.05))


def _assemble(delayed, direct, d):
    """Coefficients of z**d delayed(z) + direct(z), highest power first."""
    n = d + len(delayed) - 1
    out = np.zeros(n + 1)
    out[: len(delayed)] += delayed
    out[n + 1 - len(direct):] += direct
    return out


def test_c_and_numpy_environment_kernels_agree(paper_folder, paper_compiled):
    c = paper_compiled
    numpy_module = _numpy_module(paper_folder)
    for point in _paper_points(40, seed=11):
        args = (point["B"], point["K"], point["M"], point["T"])
        for name in ("environment", "environment_slope_B", "environment_slope_K",
                     "environment_slope_M"):
            expected = np.array(getattr(numpy_module, name)(*args), dtype=float)
            np.testing.assert_allclose(c[f"symstab_paper_{name}"](*args), expected,
                                       rtol=1e-15, atol=0, err_msg=name)


def test_c_pulse_transfer_function_matches_eq4_and_python_control(paper_compiled):
    """The residue-path kernel against eq. (4) at 50 digits and python-control's ``c2d``.

    The coefficients as derived cancel about log10(4 / delta**2) digits
    (6.6 at delta = 1e-3): 1e-8 relative against eq. (4).  python-control
    (``c2d(..., 'zoh')``, then the transfer function of the state space)
    is itself off by up to 4.8e-9 relative at these points (measured
    against eq. (4)), so it is held to 1e-7, at delta from 0.05 to 1.
    """
    import mpmath

    control = pytest.importorskip("control")
    c = paper_compiled
    rng = np.random.default_rng(3)
    for k in range(40):
        m, T = 10 ** rng.uniform(-2.5, 0), 10 ** rng.uniform(-4, -2.7)
        delta = 10 ** rng.uniform(-3, 0) if k % 2 else 10 ** rng.uniform(-1.3, 0)
        b = delta * m / T
        out = c["symstab_paper_pulse_transfer_function"](b, m, T)
        num, den = out[:2] / out[2], out[2:] / out[2]
        with mpmath.workdps(50):
            # eq. (4): ((e - 1 + bT/m) z + 1 - (1 + bT/m) e) / ((b^2/m) (z - 1)(z - e))
            mb, mm, mT = (mpmath.mpf(x) for x in (b, m, T))
            e, x = mpmath.exp(-mb * mT / mm), mb * mT / mm
            scale = mb**2 / mm
            eq4_num = [float((e - 1 + x) / scale), float((1 - (1 + x) * e) / scale)]
            eq4_den = [1.0, float(-(1 + e)), float(e)]
        np.testing.assert_allclose(num, eq4_num, rtol=1e-8)
        np.testing.assert_allclose(den, eq4_den, rtol=1e-13)
        if delta >= 0.05:
            sampled = control.c2d(control.tf([1.0], [m, b, 0.0]), T, "zoh")
            ref_num, ref_den = (np.trim_zeros(np.asarray(x[0][0], dtype=float), "f")
                                for x in (sampled.num, sampled.den))
            np.testing.assert_allclose(num, ref_num / ref_den[0], rtol=1e-7)
            np.testing.assert_allclose(den, ref_den / ref_den[0], rtol=1e-7)


def _second_order_zoh_mp(a, b, c, T):
    """``Z[ZOH 1/(a s^2 + b s + c)]`` by hand at 40 digits: (P_n, P_d), P_d monic.

    ``G(s)/s = 1/(c s) + sum_i r_i/(s - p_i)`` with ``r_i = 1/(p_i a (p_i - p_j))``, so
    ``P(z) = 1/c + sum_i r_i (z - 1)/(z - q_i)``, ``q_i = exp(p_i T)``, over
    ``(z - q_1)(z - q_2)``; complex arithmetic, the real parts returned (and the
    imaginary ones checked to vanish).
    """
    import mpmath

    with mpmath.workdps(40):
        a, b, c, T = (mpmath.mpf(x) for x in (a, b, c, T))
        root = mpmath.sqrt(mpmath.mpc(b * b - 4 * a * c))
        p1, p2 = (-b + root) / (2 * a), (-b - root) / (2 * a)
        r1, r2 = 1 / (p1 * a * (p1 - p2)), 1 / (p2 * a * (p2 - p1))
        q1, q2 = mpmath.exp(p1 * T), mpmath.exp(p2 * T)
        coefficients = [-(q1 + q2) / c - r1 * (1 + q2) - r2 * (1 + q1),
                        q1 * q2 / c + r1 * q2 + r2 * q1, 1, -(q1 + q2), q1 * q2]
        for x in coefficients:
            assert abs(mpmath.im(x)) <= mpmath.mpf(10) ** -30 * max(1, abs(x))
        # The printed residues cancel digits for a pole near 0 and for close poles.
        closeness = min(abs(p1), abs(p2)) * T * abs(p1 - p2) * T
        return np.array([float(mpmath.re(x)) for x in coefficients]), float(closeness)


def test_c_pulse_transfer_function_of_a_complex_pair_matches_mpmath_and_python_control(
        example_derived):
    """operator_arm's plant (m + m_h) s^2 + (b + b_h) s + k_h: its poles are written with a
    square root, imaginary for a complex pair, so the kernel runs in C99 complex arithmetic
    (it was left out of the C file).  Against the residues by hand at 40 digits (both
    regimes, complex and real poles) and python-control's c2d.

    As derived, P_n's coefficients cancel about log10(1 / (|p| T |p_1 - p_2| T)) digits,
    p the pole nearest 0 (measured: error * |p| T * |p_1 - p_2| T <= 1.9e-14 over 300
    points, seeds 5 to 7); P_d is exact to rounding.  python-control is held to 1e-7
    where |p| T >= 0.05, as for the paper's kernel.
    """
    control = pytest.importorskip("control")
    folder, compiled = example_derived(REPO / "examples" / "loops" / "operator_arm.toml")
    assert "#include <complex.h>" in (folder / "operator_arm_kernels.c").read_text(encoding="utf-8")
    c = compiled["symstab_operator_arm_pulse_transfer_function"]
    rng = np.random.default_rng(5)
    regimes, compared = set(), 0
    for _ in range(100):
        m, m_h = 0.0128 * rng.uniform(0.3, 3), 0.05 * rng.uniform(0.3, 3)
        b, b_h = 0.0324 * rng.uniform(0.3, 3), rng.uniform(0.01, 3)
        k_h, T = 10 ** rng.uniform(0, 4), 10 ** rng.uniform(-4, -2.5)
        got = c(b, b_h, k_h, m, m_h, T)
        want, closeness = _second_order_zoh_mp(m + m_h, b + b_h, k_h, T)
        regimes.add((b + b_h) ** 2 < 4 * (m + m_h) * k_h)
        np.testing.assert_allclose(got[:2], want[:2], rtol=1e-13 / closeness)
        np.testing.assert_allclose(got[2:], want[2:], rtol=1e-13, atol=1e-15)
        pole = np.min(np.abs(np.roots([m + m_h, b + b_h, k_h]))) * T
        if pole >= 0.05:
            sampled = control.c2d(control.tf([1.0], [m + m_h, b + b_h, k_h]), T, "zoh")
            ref_num, ref_den = (np.trim_zeros(np.asarray(x[0][0], dtype=float), "f")
                                for x in (sampled.num, sampled.den))
            np.testing.assert_allclose(got[:2], ref_num / ref_den[0], rtol=1e-7)
            np.testing.assert_allclose(got[2:], ref_den / ref_den[0], rtol=1e-7)
            compared += 1
    assert regimes == {True, False}      # complex pairs and real poles, one kernel
    assert compared >= 10


def test_c_kernels_assemble_the_loops_polynomial(paper_compiled):
    """z**d Ve_d P_d + Ve_n P_n from the C kernels equals ``Loop.coefficients``.

    Loop.coefficients evaluates the plant at 30 digits; the C prints its
    coefficients as derived, which cancel ~log10(4 / delta**2) digits (at
    most 6.6 here, delta >= 1e-3): 1e-8 relative leaves room for that.
    """
    c = paper_compiled
    loop = load_loop(PAPER_FILE)
    for k, point in enumerate(_paper_points(30, seed=7)):
        d = k % 5
        ve = c["symstab_paper_environment"](point["B"], point["K"], point["M"], point["T"])
        plant = c["symstab_paper_pulse_transfer_function"](point["b"], point["m"], point["T"])
        ve_n, ve_d, p_n, p_d = ve[:3], ve[3:], plant[:2], plant[2:]
        lead = p_d[0]
        ours = _assemble(np.convolve(ve_d, p_d / lead), np.convolve(ve_n, p_n / lead), d)
        theirs = loop.coefficients(d=d, **point)
        assert theirs.shape == ours.shape
        # Each coefficient against the size of the terms it is made of.
        scale = _assemble(np.convolve(np.abs(ve_d), np.abs(p_d / lead)),
                          np.convolve(np.abs(ve_n), np.abs(p_n / lead)), d)
        assert np.all(np.abs(ours - theirs) <= 1e-8 * scale), (point, d, ours, theirs)


def test_numeric_path_loop_derivation_and_kernels(numeric_folder, tmp_path):
    """An irreducible cubic plant: matrix exponential, no plant kernel, numbers at the values.

    The polynomial written at the file's values is checked against the one
    built from python-control's ``c2d`` of the plant.
    """
    control = pytest.importorskip("control")
    zoh = json.loads((numeric_folder / "02_zoh.json").read_text(encoding="utf-8"))
    # The whole-sample plant's and the fractional one's: both numeric.
    assert [o["srepr"] for o in zoh["objects"]] == ["'matrix exponential'"] * 2
    header = (numeric_folder / "spring_device_kernels.h").read_text(encoding="utf-8")
    assert "pulse_transfer_function" not in header
    assert "computed numerically" in header

    import sympy as sp

    steps = json.loads((numeric_folder / "03_characteristic_polynomial.json").read_text("utf-8"))
    objects = {o["name"]: eval(o["srepr"], vars(sp).copy()) for o in steps["objects"]}  # noqa: S307
    assert set(objects) == {"chi", "chi_at_values", "delayed_part", "direct_part", "chi_fractional"}
    m, b, k, c, T = 0.0128, 0.0324, 50.0, 10.0, 1e-3
    sampled = control.c2d(control.tf([1.0], [m, b, k, c]), T, "zoh")
    p_n = np.trim_zeros(np.asarray(sampled.num[0][0], dtype=float), "f")
    p_d = np.asarray(sampled.den[0][0], dtype=float)
    p_n, p_d = p_n / p_d[0], p_d / p_d[0]
    symbols = {str(x): x for x in objects["direct_part"].free_symbols}
    for B, K in ((0.0, 0.0), (0.3, 100.0), (-1.0, 2500.0)):
        # VE = K + B (z - 1) / (T z) = (K T z + B z - B) / (T z)
        ve_n, ve_d = np.array([K * T + B, -B]), np.array([T, 0.0])
        direct = [float(c.subs({symbols["B"]: B, symbols["K"]: K})) for c in objects["direct_part"]]
        # python-control's c2d of this cubic is good to about 1e-7 in P_n and
        # 1e-9 in P_d (against a 50-digit residue sum, which the 30-digit
        # matrix exponential matches to 20 digits): that is the tolerance.
        np.testing.assert_allclose(direct, np.convolve(ve_n, p_n), rtol=3e-7,
                                   atol=1e-12 * np.max(np.abs(np.convolve(ve_n, p_n))) + 1e-300)
        np.testing.assert_allclose([float(c) for c in objects["delayed_part"]],
                                   np.convolve(ve_d, p_d), rtol=1e-9, atol=1e-18)
    c = _compile(numeric_folder, tmp_path)
    numpy_module = _numpy_module(numeric_folder)
    for B, K, T in ((0.3, 100.0, 1e-3), (-2.0, 1e4, 2.5e-4)):
        np.testing.assert_allclose(c["symstab_spring_device_environment"](B, K, T),
                                   np.array(numpy_module.environment(B, K, T), dtype=float),
                                   rtol=1e-15, atol=0)


# --------------------------------------------------------------------------
# The paper's loop through the general path: the proofs


PROOF_NAMES = ("paper_loop_delayed_part", "paper_loop_direct_part", "paper_loop_plane_determinant",
               "paper_loop_boundary_real_part", "paper_loop_boundary_imag_part")


def test_paper_loop_proofs_are_proved_in_symstab_derive(rendered_files):
    data = json.loads(rendered_files["07_proofs.json"])
    found = {o["name"]: o["description"] for o in data["objects"]}
    for name in PROOF_NAMES:
        assert name in found, name
        assert found[name].endswith("[proved: difference is the zero rational function]"), name
    # The common factor and the Table I scales, derived by hand:
    # b = delta m / T gives Ve_d P_d = T^2 z^2 b^2 (...) = m^2 delta^2 (...);
    # beta = B T / m, alpha = K T^2 / m.
    assert "= (m**2) * today's delayed part" in found["paper_loop_delayed_part"]
    assert "= (m**2) * today's direct part" in found["paper_loop_direct_part"]
    assert "= (-T**3*m**2) * D" in found["paper_loop_plane_determinant"]
    assert "B = (m/T) beta(theta), K = (m/T**2) alpha(theta)" in found["paper_loop_boundary_real_part"]


def test_the_paper_loop_proofs_fail_for_another_loop():
    """The same statements for a Tustin damper instead of eq. (1)'s backward difference."""
    tustin = "K + 2*B*(z - 1)/(T*(z + 1)) + M*(z - 1)**2/(T**2*z**2)"
    wrong = {name: (lhs, rhs) for name, _, lhs, rhs in
             loop_derive._against_the_paper(loop_derive.PAPER_PLANT, tustin)}
    for name in ("paper_loop_delayed_part", "paper_loop_direct_part",
                 "paper_loop_boundary_real_part"):
        assert check_identity(*wrong[name]).equal is False, name


PI_LOOP = """\
name = "filtered_damper"
plant = "1/(m*s**2 + b*s)"
environment = "K + B*(1 - exp(-2*pi*f_c*T))*(z - 1)/(T*(z - exp(-2*pi*f_c*T)))"

[parameters]
m = 0.0128
b = 0.0324
f_c = 50.0
T = 1e-3
"""


@pytest.mark.parametrize("source", ["pi"] + sorted(p.name for p in PAPER_FILE.parent.glob("*.toml")))
def test_every_example_loop_compiles_and_its_c_matches_numpy(source, tmp_path, example_derived):
    """Every shipped example, and a loop with pi (printed M_PI, which strict C99 lacks)."""
    if source == "pi":
        path = tmp_path / "pi.toml"
        path.write_text(PI_LOOP, encoding="utf-8")
    else:
        path = PAPER_FILE.parent / source
    folder, c = example_derived(path)
    numpy_module = _numpy_module(folder)
    loop = load_loop(path)
    stem = loop_derive.c_name(loop)
    rng = np.random.default_rng(1)
    fractional, helpers, _ = loop_derive.fractional_plant_kernel(loop)
    for helper in helpers:
        for x in (-30.0, -2.5, -2.0, -1.0, -1e-3, 0.0, 1e-3, 1.0, 1.999, 2.0, 3.0, 50.0):
            expected = getattr(numpy_module, helper.name)(x)
            np.testing.assert_allclose(c[f"symstab_{stem}_{helper.name}"](x), expected,
                                       rtol=4e-16, atol=0, err_msg=f"{helper.name}({x})")
    for kernel in loop.kernels() + ([fractional] if fractional is not None else []):
        names = [str(symbol) for symbol, _, _ in kernel.args]
        for _ in range(5):
            args = [loop.defaults.get(n, 1.0) * rng.uniform(0.5, 2.0) if n != "eps"
                    else rng.uniform(0.0, 1.0) for n in names]
            expected = np.array(getattr(numpy_module, kernel.name)(*args), dtype=float)
            np.testing.assert_allclose(c[f"symstab_{stem}_{kernel.name}"](*args),
                                       np.broadcast_to(expected, expected.shape), rtol=1e-14,
                                       atol=1e-300, err_msg=kernel.name)


# --------------------------------------------------------------------------
# The loop's step in C, for every example loop


@pytest.mark.parametrize("file", sorted(p.name for p in (REPO / "examples" / "loops").glob("*.toml"))
                         + ["static spring"])
def test_the_c_step_of_every_example_loop_compiles_strictly_and_runs_as_numpy(file, tmp_path):
    """The generated C step (complex poles and the matrix exponential included: its
    coefficients are arguments) compiles with -std=c99 -Wall -Wextra -pedantic -Werror,
    and the loop closed on it, with a delay line here, gives the positions of
    ``Loop.simulate`` to 1e-12 of their size."""
    compiler = shutil.which("cc") or shutil.which("gcc")
    if compiler is None:
        pytest.skip("no C compiler found on PATH (tried cc, gcc)")
    if file == "static spring":
        # An environment without history (Ve_d of degree 0): the C step's unused
        # history arguments must not warn.
        from symstab import Loop

        loop = Loop("1/(m*s**2 + b*s)", "K", name="static_spring",
                    values={"m": 0.0128, "b": 0.0324, "T": 1e-3, "d": 2, "K": 30.0})
    else:
        loop = load_loop(REPO / "examples" / "loops" / file)
    folder = tmp_path / "out"
    folder.mkdir()
    for name, text in loop_derive.kernel_files(loop).items():
        (folder / name).write_text(text, encoding="utf-8")
    stem = loop_derive.c_name(loop)
    library = tmp_path / f"{stem}.so"
    command = [compiler, *C_FLAGS, f"-I{folder}", str(folder / f"{stem}_kernels.c"), "-o",
               str(library), "-lm"]
    proc = subprocess.run(command, capture_output=True, text=True, timeout=120)
    assert proc.returncode == 0, proc.stderr
    lib = ctypes.CDLL(str(library))
    array = ctypes.POINTER(ctypes.c_double)
    environment_step = getattr(lib, f"symstab_{stem}_environment_step")
    environment_step.argtypes = [array] * 4 + [ctypes.c_double, array]
    plant_step = getattr(lib, f"symstab_{stem}_plant_step")
    plant_step.argtypes = [array] * 4 + [ctypes.c_double, ctypes.c_double, array]

    def buffer(values):
        values = np.ascontiguousarray(values, dtype=float).ravel()
        return values, values.ctypes.data_as(array)

    (a, b, c, e), d, _ = loop.difference_equations()
    steps, x0 = 400, 1.0
    run = loop.simulate(steps=steps, x0=x0, record=True)
    n, m = a.shape[-1], c.shape[-1]
    coefficients = [buffer(p) for p in (a, b, c, e)]
    # The start of Loop.simulate: earlier positions x0 - k v0 with v0 = x0 / 100, no
    # force applied yet, the sampled history at x0 and the environment at rest there:
    # its force VE(1) x0 (VE from the loop's expression, at its values).
    y_past = buffer([x0 - k * x0 / 100 for k in range(1, n + 1)])
    u_past, s_past = buffer(np.zeros(n)), buffer(np.full(m, x0))
    at_rest = loop.environment.subs({sp.Symbol(k, real=True): v for k, v in loop.defaults.items()
                                     if k != "d"}).subs(sp.Symbol("z"), 1)
    f_past = buffer(np.full(m, float(at_rest) * x0))
    force, x_next = ctypes.c_double(), ctypes.c_double()
    line = np.zeros(d + 1)
    x, positions = x0, [x0]
    for k in range(steps):
        environment_step(coefficients[2][1], coefficients[3][1], s_past[1], f_past[1], x,
                         ctypes.byref(force))
        line[k % (d + 1)] = force.value
        held = -line[(k - d) % (d + 1)]
        plant_step(coefficients[0][1], coefficients[1][1], y_past[1], u_past[1], x, held,
                   ctypes.byref(x_next))
        x = x_next.value
        positions.append(x)
    expected = np.asarray(run.positions)
    scale = np.maximum(np.abs(expected), 1e-300)
    assert np.all(np.abs(np.array(positions) - expected) <= 1e-12 * np.maximum(scale, 1e-6 * x0))


# --------------------------------------------------------------------------
# Parameter names that C's headers or keywords own (issue 40 item 3)


#: Every parameter is named as something of <math.h>, <complex.h> or a C
#: keyword: HUGE_VAL and INFINITY compiled as macros (and read garbage), NAN,
#: M_PI, pow and exp did not compile.  The plant's poles are a complex pair
#: (its kernel runs in <complex.h> arithmetic, where I and complex are macros);
#: the environment calls exp() and pow() and prints pi as M_PI.
C_NAMES_LOOP = """\
name = "c_names"
plant = "1/(I*s**2 + complex*s + y0)"
environment = "HUGE_VAL*bool + NAN*exp(-pi*INFINITY*T)*(z - 1)/(T*z) + M_PI*pow*exp*arg_exp*(z - 1)**2/(T**2*z**2)"

[parameters]
I = 0.0628
complex = 1.03
y0 = 100.0
HUGE_VAL = 300.0
NAN = 0.5
INFINITY = 50.0
M_PI = 0.001
pow = 2.0
exp = 0.1
bool = 3.0
arg_exp = 0.7
T = 1e-3
d = 1
"""


def test_parameters_named_as_c_macros_functions_and_keywords_compile_and_compute(tmp_path):
    """Each such name is ``arg_<name>`` in C (``arg_arg_exp`` where ``arg_exp`` is taken),
    said in the kernel's comment; the C kernels equal the NumPy module and SymPy's own
    evaluation of the derived expressions (30 digits), and the plant's python-control's c2d."""
    control = pytest.importorskip("control")
    path = tmp_path / "c_names.toml"
    path.write_text(C_NAMES_LOOP, encoding="utf-8")
    folder = tmp_path / "out"
    status, _, err = run_cli("derive", "--loop", str(path), "--out", str(folder))
    assert status == 0, err
    header = (folder / "c_names_kernels.h").read_text(encoding="utf-8")
    for name in ("HUGE_VAL", "NAN", "INFINITY", "M_PI", "pow", "bool", "I", "complex", "y0"):
        assert f" * arg_{name}: parameter {name} (the argument {name}, renamed in C" in header
    assert " * arg_arg_exp: parameter exp (the argument exp, renamed in C" in header
    assert " * arg_exp: parameter arg_exp\n" in header
    c = _compile(folder, tmp_path)
    numpy_module = _numpy_module(folder)
    loop = load_loop(path)
    rng = np.random.default_rng(3)
    kernels = loop.kernels() + [loop_derive.plant_kernel(loop)]
    assert kernels[-1].complex_arithmetic
    for kernel in kernels:
        names = [str(symbol) for symbol, _, _ in kernel.args]
        for _ in range(3):
            args = [loop.defaults[n] * rng.uniform(0.5, 2.0) for n in names]
            got = c[f"symstab_c_names_{kernel.name}"](*args)
            sub = {symbol: sp.Float(repr(a), 30)
                   for (symbol, _, _), a in zip(kernel.args, args, strict=True)}
            exact = np.array([float(sp.re(sp.sympify(expr).replace(
                lambda e: isinstance(e, sp.Function) and type(e).__name__ == "RealPart",
                lambda e: e.args[0]).xreplace(sub).evalf(30))) for _, expr, _ in kernel.outputs])
            np.testing.assert_allclose(got, exact, rtol=1e-9, atol=1e-12, err_msg=kernel.name)
            if kernel.name == "pulse_transfer_function":
                value = dict(zip(names, args, strict=True))
                sampled = control.c2d(control.tf([1.0], [value["I"], value["complex"],
                                                         value["y0"]]), value["T"], "zoh")
                ref_num, ref_den = (np.trim_zeros(np.asarray(x[0][0], dtype=float), "f")
                                    for x in (sampled.num, sampled.den))
                np.testing.assert_allclose(got, np.concatenate([ref_num, ref_den]) / ref_den[0],
                                           rtol=1e-7)
            else:
                expected = np.array(getattr(numpy_module, kernel.name)(*args), dtype=float)
                np.testing.assert_allclose(got, np.broadcast_to(expected, got.shape),
                                           rtol=1e-14, atol=1e-300, err_msg=kernel.name)


@pytest.mark.parametrize("name", ["int", "double", "_Reserved", "__x", "numpy", "x0"])
def test_a_parameter_named_as_a_keyword_or_reserved_is_refused(name):
    """What C cannot rename (a keyword of C and Python, a leading _) is refused, naming it."""
    text = C_NAMES_LOOP.replace("bool", name)
    with pytest.raises(ValueError, match=re.escape(repr(name))):
        parse_loop_text(text)


# --------------------------------------------------------------------------
# The plant with a fractional delay: derivation and kernel


def _fractional_reference(loop, values, eps, dps=40):
    """``(N_eps, z P_d)`` of the derivation at ``values`` and ``eps``, by mpmath at ``dps`` digits."""
    import mpmath

    plant = loop_derive.fractional_plant(loop, "eps")
    by_name = {str(x): x for c in plant.numerator + plant.denominator
               for x in sp.sympify(c).free_symbols}
    with mpmath.workdps(dps):
        at = {by_name[n]: sp.Float(mpmath.mpf(v), dps) for n, v in values.items() if n in by_name}
        at[plant.symbol] = sp.Float(mpmath.mpf(eps), dps)
        return tuple([mpmath.mpf(sp.N(sp.sympify(c).xreplace(at), dps)) for c in part]
                     for part in (plant.numerator, plant.denominator))


def _normwise_error(got, reference):
    """``max |got - reference| / max |reference|``: the polynomial's error on its own scale."""
    scale = max(abs(c) for c in reference)
    return float(max(abs(float(g) - r) for g, r in zip(got, reference, strict=True)) / scale)


FRACTIONS = (0.0, 0.25, 0.5, 0.999)


@pytest.mark.parametrize("file", sorted(p.name for p in PAPER_FILE.parent.glob("*.toml")))
def test_the_fractional_plant_kernel_of_every_example_against_mpmath_and_van_loan(file,
                                                                                  example_derived):
    """At the file's values and eps in FRACTIONS: the NumPy kernel against the derivation at 40
    digits (the coefficients, on each polynomial's scale: measured at most 6.7e-16, actuator_lag),
    and P_eps(z0) against the state space's (Van Loan's exponential, SciPy)."""
    from oracles import fractional_plant_response

    path = PAPER_FILE.parent / file
    loop = load_loop(path)
    kernel, _, why = loop_derive.fractional_plant_kernel(loop)
    module = _numpy_module(example_derived(path)[0])
    if kernel is None:
        assert not hasattr(module, "fractional_plant")
        # Said in the files, with how P_eps is computed instead.
        assert why.split(":")[0] in (example_derived(path)[0] / "05_kernel_forms.tex").read_text()
        return
    names = [str(x) for x, _, _ in kernel.args[:-1]]
    values = {n: loop.defaults[n] for n in names}
    plant = {str(x): x for x in loop.plant.free_symbols}
    num, den = sp.fraction(sp.together(loop.plant.subs(
        {plant[n]: v for n, v in values.items() if n in plant})))
    num, den = ([float(c) for c in sp.Poly(p, sp.Symbol("s")).all_coeffs()] for p in (num, den))
    z0 = 1.3 + 0.4j
    for eps in FRACTIONS:
        out = np.array(module.fractional_plant(*values.values(), eps), dtype=float)
        n_eps, z_p_d = out[: len(kernel.outputs) - len(den) - 1], out[len(kernel.outputs) - len(den) - 1:]
        reference = _fractional_reference(loop, values, eps)
        assert _normwise_error(n_eps, reference[0]) <= 7e-16, eps
        assert _normwise_error(z_p_d, reference[1]) <= 7e-16, eps
        expected = fractional_plant_response(num, den, values["T"], eps, z0)
        assert abs(np.polyval(n_eps, z0) / np.polyval(z_p_d, z0) - expected) <= 1e-10 * abs(expected)


def test_the_paper_plants_fractional_kernel_keeps_its_digits_from_delta_1e_8_to_100(paper_folder,
                                                                                    paper_compiled):
    """N_eps is O(delta^2) out of O(1) terms as derived (at delta = 1e-8 the printed form has
    no correct digit); the kernel's exprel form keeps them.  Measured on this grid against the
    derivation at 40 digits: at most 5.5e-16 of each polynomial's scale for delta <= 10, and
    2.8e-15 up to delta = 100 (the condition of exp(delta) itself, delta u); C as NumPy."""
    module = _numpy_module(paper_folder)
    c = paper_compiled["symstab_paper_fractional_plant"]
    loop = load_loop(PAPER_FILE)
    m, T = 0.0128, 1e-3
    worst_small, worst_large = 0.0, 0.0
    for delta in 10.0 ** np.arange(-8, 2.01, 0.5):
        for eps in FRACTIONS:
            values = {"b": delta * m / T, "m": m, "T": T}
            out = np.array(module.fractional_plant(values["b"], m, T, eps), dtype=float)
            np.testing.assert_allclose(c(values["b"], m, T, eps), out, rtol=1e-14, atol=0)
            reference = _fractional_reference(loop, values, eps)
            error = max(_normwise_error(out[:3], reference[0]),
                        _normwise_error(out[3:], reference[1]))
            if delta <= 10:
                worst_small = max(worst_small, error)
            else:
                worst_large = max(worst_large, error)
    assert worst_small <= 6e-16 and worst_large <= 3e-15, (worst_small, worst_large)


def test_exprel_helpers_against_mpmath_on_both_branches():
    """exprel_k's Taylor branch (|x| < 2) and expm1 branch, k = 1 to 6, against mpmath."""
    import mpmath

    from symstab.codegen.loop_kernels import numpy_source
    from symstab.codegen.residue_forms import exprel, helper_kernels

    x = sp.Symbol("x")
    kernels = helper_kernels([exprel(k)(x) for k in range(1, 7)])
    namespace = {}
    exec(numpy_source(kernels, title="exprel"), namespace)
    points = np.concatenate([np.linspace(-40, 60, 101), np.linspace(-2.5, 2.5, 201),
                             [-2.0, -1e-12, 0.0, 1e-12, 2.0]])
    worst = {}
    for k in range(1, 7):
        got = namespace[f"exprel{k}"](points)
        with mpmath.workdps(40):
            # exprel_k(x) = 1F1(1; k + 1; x) / k!: another formulation than the helpers'.
            exact = [mpmath.hyp1f1(1, k + 1, mpmath.mpf(p)) / mpmath.factorial(k)
                     for p in points]
            worst[k] = max(float(abs(g - e) / e) for g, e in zip(got, exact, strict=True))
    # Measured (relative): 2.4e-16, 1.9e-16, 3.7e-16, 6.8e-16, 2.3e-15, 4.8e-15 for k = 1 .. 6;
    # the closed form just above the switch cancels log10(e^2 / (2^k exprel_k(2))) digits,
    # more for larger k (k = 6: 1.8 digits).
    measured = {1: 2.5e-16, 2: 2e-16, 3: 3.8e-16, 4: 7e-16, 5: 2.3e-15, 6: 4.8e-15}
    assert all(worst[k] <= measured[k] for k in worst), worst


def test_the_fractional_derivation_is_in_the_files(paper_folder, numeric_folder):
    """02_zoh: P_eps with epsilon and its two limits proved; 03: chi with d and epsilon; on the
    matrix-exponential path, how P_eps is computed."""
    zoh = json.loads((paper_folder / "02_zoh.json").read_text(encoding="utf-8"))
    found = {o["name"]: o for o in zoh["objects"]}
    assert "epsilon" in found["fractional_pulse_transfer_function"]["srepr"]
    for name in ("fractional_at_zero", "fractional_at_one"):
        assert "[proved: " in found[name]["description"] and found[name]["srepr"] == "Integer(0)"
    chi = json.loads((paper_folder / "03_characteristic_polynomial.json").read_text(encoding="utf-8"))
    chi = {o["name"]: o for o in chi["objects"]}["chi_fractional"]["srepr"]
    assert "Symbol('d'" in chi and "Symbol('epsilon')" in chi
    numeric = json.loads((numeric_folder / "02_zoh.json").read_text(encoding="utf-8"))
    found = {o["name"]: o for o in numeric["objects"]}
    assert "matrix exponential at 30 digits" in found["fractional_pulse_transfer_function"]["description"]
    assert "fractional_plant" not in (numeric_folder / "spring_device_kernels.h").read_text()


def test_a_parameter_named_eps_moves_the_kernels_argument():
    loop = parse_loop_text(PI_LOOP.replace("m*s**2 + b*s", "m*s**2 + eps*s").replace(
        "b = 0.0324", "eps = 0.0324"))
    kernel, _, _ = loop_derive.fractional_plant_kernel(loop)
    assert [str(x) for x, _, _ in kernel.args] == ["eps", "m", "T", "eps_"]
    assert str(loop_derive.fractional_plant(loop).symbol) == "epsilon"
