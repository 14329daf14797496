"""Fixtures, shared command runs and assertion helpers for the symstab tests.

The oracles (first principles, python-control, the mpmath references) are in
``oracles.py``; here are the session fixtures (the derivation, the generated
code, the ``audit`` and ``derive`` runs shared by the xdist workers under a
file lock), :func:`run_symstab`, the paper's device and the assertion
helpers.  It applies to every test folder below ``tests/``.
"""

import json
import os
import pathlib
import re
import shutil
import subprocess
import sys

# One BLAS thread per process, set before NumPy loads: the suite runs on two
# xdist workers on two cores, and two workers each spinning two OpenBLAS
# threads made one degree-1000 eigenvalue test take 128 s instead of 5 s.
for _name in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_name, "1")

try:
    import fcntl
except ImportError:  # Windows: no shared runs between xdist workers
    fcntl = None

import mpmath
import pytest
from hypothesis import settings

from symstab.symbolic.boundary import boundary
from symstab.symbolic.loop import characteristic_polynomial

REPO = pathlib.Path(__file__).resolve().parents[1]

#: The manual: the README and the pages of the documentation site (docs/),
#: whose user guide holds what the README said before it became short.
MANUAL = (REPO / "README.md",
          *sorted(path for path in (REPO / "docs").rglob("*.md")
                  if not path.is_relative_to(REPO / "docs" / "_build")
                  and not path.is_relative_to(REPO / "docs" / "derivations")))


def manual_text():
    """The manual's text, the README first, then the docs' pages, each whole."""
    return "\n\n".join(path.read_text(encoding="utf-8") for path in MANUAL)

# Hypothesis: the "ci" profile (the default) draws a bounded number of
# examples, the same ones on every run (derandomized, no example database),
# so that the suite costs the same every time; HYPOTHESIS_PROFILE=thorough
# draws many more, at random, for a hunt before a release.  A test sets its
# own health-check suppressions, not its number of examples.
settings.register_profile("ci", max_examples=15, derandomize=True, deadline=None,
                          database=None)
settings.register_profile("thorough", max_examples=500, deadline=None)
settings.load_profile(os.environ.get("HYPOTHESIS_PROFILE", "ci"))

# The paper's device (Section IV-A): T = 1 ms, m = 0.0128 kg m^2, b = 0.0324 N m s/rad.
PAPER_M = 0.0128
PAPER_B = 0.0324
PAPER_T = 1e-3
#: delta = b T / m of the paper's device (Table I): 0.00253125.
PAPER_DELTA = PAPER_B * PAPER_T / PAPER_M


# --------------------------------------------------------------------------
# Assertion helpers
# --------------------------------------------------------------------------

def relative_error(actual, expected):
    """|actual - expected| / |expected| (absolute error when expected == 0)."""
    expected_abs = abs(expected)
    err = abs(actual - expected)
    return err / expected_abs if expected_abs != 0 else err


def assert_rel_close(actual, expected, rtol, label=""):
    """Assert ``actual`` equals ``expected`` to relative tolerance ``rtol``."""
    err = relative_error(actual, expected)
    assert err <= rtol, (
        f"{label}: got {mpmath.nstr(actual, 20)}, expected {mpmath.nstr(expected, 20)}; "
        f"relative error {mpmath.nstr(err, 3)} > {mpmath.nstr(rtol, 3)}")


def assert_message_names(excinfo, name):
    """Assert an exception message names ``name`` as a whole word."""
    message = str(excinfo.value)
    assert re.search(rf"(?<![\w]){re.escape(name)}(?![\w])", message), (
        f"message does not name {name!r}: {message!r}")


# --------------------------------------------------------------------------
# Fixtures
# --------------------------------------------------------------------------

@pytest.fixture(scope="session")
def loop():
    return characteristic_polynomial()


@pytest.fixture(scope="session")
def bd():
    return boundary()


@pytest.fixture(scope="session")
def derivation():
    """derivation_steps(), built once per xdist worker (about 4 s)."""
    from symstab.proof.derive import derivation_steps

    return derivation_steps()


@pytest.fixture(scope="session")
def rendered_files(tmp_path_factory, request):
    """``render(derivation_steps())``, ``{file name: text}``, computed once per session.

    By :func:`run_once_per_session`: the worker that renders builds the
    derivation; the other reads the texts and builds it only if one of its
    tests asks for :func:`derivation` itself.
    """
    from symstab.proof.derive import render

    return run_once_per_session(tmp_path_factory, "rendered_files",
                                lambda folder: render(request.getfixturevalue("derivation")))


#: The file hand-edited for the drift tests, and the edit.
EDITED_FILE = "04_boundary.tex"
EDIT = "% a hand edit\n"


def run_symstab(*args, env_extra=None, cwd=None, timeout=300):
    """Run ``python -m symstab ...`` in a subprocess (no shell)."""
    env = dict(os.environ)
    env.update(env_extra or {})
    return subprocess.run([sys.executable, "-m", "symstab", *args], capture_output=True,
                          text=True, env=env, cwd=cwd, timeout=timeout)


@pytest.fixture(scope="session")
def generated_code(tmp_path_factory):
    """codegen.generated_files(), ``{file name: text}``, built once per session."""
    from symstab.codegen.generator import generated_files

    return run_once_per_session(tmp_path_factory, "generated_code",
                                lambda folder: generated_files())


#: The generated-code file hand-edited for the codegen drift test.
EDITED_CODE_FILE = "symstab_kernels.c"


def _copy_files(folder, files, edited=None):
    folder.mkdir(parents=True)
    for name, text in files.items():
        (folder / name).write_text(text, encoding="utf-8", newline="\n")
    if edited is not None:
        with open(folder / edited, "a", encoding="utf-8", newline="\n") as fh:
            fh.write("/* a hand edit */\n" if edited.endswith((".c", ".h")) else EDIT)


def hash_seed_other_than_ours():
    """A PYTHONHASHSEED for a subprocess that differs from this process's."""
    ours = os.environ.get("PYTHONHASHSEED")
    return "2" if ours == "1" else "1"


def _main_in_process(argv):
    """``symstab.cli.commands.main(argv)`` here, as ``(returncode, stdout, stderr)``."""
    import contextlib
    import io

    from symstab.cli import commands as cli

    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        code = cli.main(argv)
    return code, out.getvalue(), err.getvalue()


def run_once_per_session(tmp_path_factory, name, produce):
    """``produce(folder)`` run once for the whole test session, also under pytest-xdist.

    A session fixture is built once per xdist worker.  For a whole command
    run that is one run too many: the first worker to get here runs it into
    a folder shared by the workers (the xdist idiom: the parent of the
    worker's base temporary folder) and writes its JSON result there, under
    a file lock; the others wait and read it.  Without xdist, or without
    ``fcntl`` (Windows), it simply runs.
    """
    base = tmp_path_factory.getbasetemp()
    if os.environ.get("PYTEST_XDIST_WORKER") is None or fcntl is None:
        folder = base / name
        folder.mkdir()
        return produce(folder)
    root = base.parent
    done = root / f"{name}.json"
    with open(root / f"{name}.lock", "w") as lock:
        fcntl.flock(lock, fcntl.LOCK_EX)
        if done.is_file():
            return json.loads(done.read_text(encoding="utf-8"))
        folder = root / name
        if folder.exists():   # a worker failed here before: start again
            shutil.rmtree(folder)
        folder.mkdir()
        result = produce(folder)
        done.write_text(json.dumps(result), encoding="utf-8")
        return result


@pytest.fixture(scope="session")
def derive_subprocess_runs(tmp_path_factory, rendered_files, generated_code):
    """``symstab derive`` runs shared by the session: one subprocess, two in-process.

    ``seed1`` is the subprocess ``python -m symstab derive`` writing a fresh
    derivation and fresh kernels, under a PYTHONHASHSEED other than this
    process's (:func:`hash_seed_other_than_ours`), so comparing its files
    with the in-process ones tests that the output does not depend on the
    hash seed.  ``check_edited`` runs ``derive --check`` (``cli.main``, in
    process: the proofs are cached there, a subprocess would redo them)
    on a copy of the in-process output in which :data:`EDITED_FILE` was
    edited by hand, ``check_edited_code`` on one in which
    :data:`EDITED_CODE_FILE` was.  Built once per session
    (:func:`run_once_per_session`).

    Returns ``{name: ((returncode, stdout, stderr), (derivations dir, code dir))}``.
    """
    def produce(base):
        _copy_files(base / "edited", rendered_files, EDITED_FILE)
        _copy_files(base / "edited_code_ok", generated_code)
        _copy_files(base / "fresh", rendered_files)
        _copy_files(base / "edited_code", generated_code, EDITED_CODE_FILE)
        out, code = base / "seed1", base / "seed1_code"
        proc = subprocess.run([sys.executable, "-m", "symstab", "derive", "--out", str(out),
                               "--codegen-out", str(code)], cwd=base,
                              env=dict(os.environ, PYTHONHASHSEED=hash_seed_other_than_ours()),
                              capture_output=True, text=True, timeout=900)
        runs = {"seed1": ((proc.returncode, proc.stdout, proc.stderr), (str(out), str(code)))}
        for name, (out, code) in {"check_edited": (base / "edited", base / "edited_code_ok"),
                                  "check_edited_code": (base / "fresh", base / "edited_code")}.items():
            result = _main_in_process(["derive", "--out", str(out), "--codegen-out", str(code),
                                       "--check"])
            runs[name] = (result, (str(out), str(code)))
        return runs

    runs = run_once_per_session(tmp_path_factory, "derive_runs", produce)
    return {name: (tuple(result), tuple(pathlib.Path(p) for p in dirs))
            for name, (result, dirs) in runs.items()}


@pytest.fixture(scope="session")
def audit_run(tmp_path_factory):
    """``symstab audit --report --json`` run once per session, as a subprocess.

    Returns ``(CompletedProcess, report path, json path)``.
    """
    def produce(out):
        report, js = out / "REPORT.md", out / "audit.json"
        proc = subprocess.run([sys.executable, "-m", "symstab", "audit", "--report", str(report),
                               "--json", str(js)], capture_output=True, text=True, timeout=900)
        return [proc.args, proc.returncode, proc.stdout, proc.stderr, str(report), str(js)]

    args, returncode, stdout, stderr, report, js = run_once_per_session(
        tmp_path_factory, "audit", produce)
    return (subprocess.CompletedProcess(args, returncode, stdout, stderr),
            pathlib.Path(report), pathlib.Path(js))


#: Session fixtures that run a whole command.
_SHARED_RUNS = ("audit_run", "derive_subprocess_runs")
#: The longest of them, the docs build (a minute and more): its tests run first, so that
#: under xdist one worker starts it at once, not the last worker at the end of the run.
_FIRST = ("site",)


def pytest_collection_modifyitems(config, items):
    """Mark the tests that wait for a whole command run (audit, derive) slow; the docs first."""
    for item in items:
        if any(fixture in getattr(item, "fixturenames", ()) for fixture in _SHARED_RUNS):
            item.add_marker(pytest.mark.slow)
    items.sort(key=lambda item: not any(f in getattr(item, "fixturenames", ()) for f in _FIRST))


# --------------------------------------------------------------------------
# The paper's best virtual mass (seconds a delay), read by test_region and test_design
# --------------------------------------------------------------------------

def _best_virtual_mass_once(tmp_path_factory, d):
    """``best_virtual_mass(d=d)`` of the paper's device, searched once per session.

    The search takes seconds: one xdist worker runs it, the other reads its
    fields (JSON keeps a float's every bit) and rebuilds the same result.
    """
    import dataclasses

    from symstab import BestVirtualMass, best_virtual_mass

    fields = run_once_per_session(
        tmp_path_factory, f"best_virtual_mass_d{d}",
        lambda folder: dataclasses.asdict(best_virtual_mass(d=d, delta=PAPER_DELTA)))
    return BestVirtualMass(**fields)


@pytest.fixture(scope="session")
def best_d0(tmp_path_factory):
    """``best_virtual_mass(d=0)`` of the paper's device, once per session."""
    return _best_virtual_mass_once(tmp_path_factory, 0)


@pytest.fixture(scope="session")
def best_d40(tmp_path_factory):
    """``best_virtual_mass(d=40)`` of the paper's device, once per session."""
    return _best_virtual_mass_once(tmp_path_factory, 40)


# --------------------------------------------------------------------------
# Command runs in-process, and the loops' kernel cache
# --------------------------------------------------------------------------

def _shared_folder(tmp_path_factory, name):
    """A folder of this test session shared by its xdist workers (the parent of their bases)."""
    base = tmp_path_factory.getbasetemp()
    root = base.parent if os.environ.get("PYTEST_XDIST_WORKER") is not None else base
    folder = root / name
    folder.mkdir(exist_ok=True)
    return folder


@pytest.fixture(scope="session", autouse=True)
def session_cache_dir(tmp_path_factory):
    """symstab's cache (loop derivations, generated kernels) for the whole run, never ~/.cache.

    One folder for the session, shared by the xdist workers: a loop is
    derived once per run, not once per worker and per test (its cache
    entries are written atomically, so two workers deriving the same loop
    at once only both derive it).  A test of the cache itself sets its own
    folder.
    """
    folder = _shared_folder(tmp_path_factory, "symstab-cache")
    with pytest.MonkeyPatch.context() as mp:
        mp.setenv("SYMSTAB_CACHE_DIR", str(folder))
        yield folder


@pytest.fixture
def loop_cache_dir(session_cache_dir, monkeypatch):
    """The session's cache folder, set again for a test that changed the environment."""
    monkeypatch.setenv("SYMSTAB_CACHE_DIR", str(session_cache_dir))
    return session_cache_dir


def run_cli(capsys, *args):
    """``symstab ARGS`` in this process: (exit status, stdout, stderr)."""
    from symstab import cli

    status = cli.main([str(a) for a in args])
    out, err = capsys.readouterr()
    return status, out, err


@pytest.fixture(scope="session")
def shared_cli_run(tmp_path_factory):
    """``run(*args) -> (exit status, stdout, stderr)`` of ``symstab ARGS`` in-process, once.

    A command run that several tests read (a design search takes seconds)
    is run by the first test that asks for it and remembered for the
    session, keyed by its arguments; the later tests read the same output.
    Once for the session, also under xdist (:func:`run_once_per_session`):
    tests in different files that read one run may land on both workers.
    """
    import hashlib

    runs = {}

    def run(*args):
        key = tuple(str(a) for a in args)
        if key not in runs:
            name = "cli-run-" + hashlib.sha256("\0".join(key).encode()).hexdigest()[:16]
            runs[key] = tuple(run_once_per_session(
                tmp_path_factory, name, lambda folder: list(_main_in_process(list(key)))))
        return runs[key]

    return run


def run_cli_json(capsys, *args):
    """``symstab ARGS --format json``, which must succeed; its parsed output."""
    status, out, err = run_cli(capsys, *args, "--format", "json")
    assert status == 0, err
    return json.loads(out)
