"""The numeric sub-commands: boundary, limits, classify, design.

The numbers are checked against the library called directly and, where it
matters, against an independent oracle (python-control's poles for
``classify``); the rest checks what a user sees: units echoed, formats
parseable, bad input one line and exit status 2 with nothing written.
"""

import csv
import io
import json

import numpy as np
import pytest

import symstab

from conftest import PAPER_B, PAPER_DELTA, PAPER_M, PAPER_T
from conftest import run_cli as run
from oracles import fractional_delay_radius, python_control_closed_loop


def test_limits_physical_echoes_units_and_matches_the_library(capsys):
    status, out, _ = run(capsys, "limits", "--Td", "0.04", "--Mw", "0.0128", "--format", "json")
    assert status == 0
    data = json.loads(out)
    assert data["inputs"]["d"] == 40 and data["inputs"]["gamma"] == pytest.approx(1.0)
    assert data["inputs"]["units"]["K_w"] == "N m/rad"
    lim = symstab.limits(gamma=1.0, d=40, delta=PAPER_DELTA)
    assert data["limits"]["alpha_max"] == pytest.approx(lim.alpha_max, rel=1e-12)
    status, out, _ = run(capsys, "limits", "--Td", "0.04", "--Mw", "0.0128")
    assert "m = 0.0128 kg m^2" in out and "Td = 0.04 s (d = 40)" in out
    k_max = lim.alpha_max * PAPER_M / PAPER_T**2
    line = next(line for line in out.splitlines() if "K_max" in line)
    assert f"{k_max:.10g}" in line and "N m/rad" in line


def test_a_fractional_Td_gives_the_paper_loops_limits_at_that_delay(capsys):
    """Issue 43: --Td 0.0405 (40.5 samples) was refused; it is the paper's loop at Td = 40.5 ms.

    The cross-check of the plumbing is the library's PAPER_LOOP at Td = 0.0405 s.
    """
    data = json.loads(run(capsys, "limits", "--Td", "0.0405", "--format", "json")[1])
    assert data["inputs"]["d"] == 40.5 and data["inputs"]["Td"] == pytest.approx(0.0405)
    k_max = symstab.PAPER_LOOP.limits("B", "K", Td=0.0405).y_max
    assert data["limits"]["alpha_max"] * PAPER_M / PAPER_T**2 == pytest.approx(k_max, rel=1e-12)
    status, out, err = run(capsys, "limits", "--Td", "0.0405")
    assert status == 0, err
    assert "delay Td = 40.5 ms (d = 40.5 samples)" in out
    # The passive set at 40.5 samples too (it was "not computed at a fractional delay").
    passive = symstab.PAPER_LOOP.passive_region("B", "K", Td=0.0405).y_max
    assert f"passive K_max = {passive:.10g} N m/rad" in out
    line = next(line for line in out.splitlines() if "K_max" in line)
    assert f"{k_max:.10g}" in line


def test_classify_at_a_fractional_Td_agrees_with_the_sampled_state_space(capsys):
    """The radius of the paper's loop at Td = 40.5 ms against an expm of the continuous plant."""
    data = json.loads(run(capsys, "classify", "--Td", "0.0405", "--Kw", "1.28,3.84",
                          "--Bw", "0.064", "--format", "json")[1])
    # The paper's mass and K + B (z - 1) / (T z), written out: ((K T + B) z - B) / (T z).
    radii = [fractional_delay_radius([1.0], [PAPER_M, PAPER_B, 0.0],
                                     [K * PAPER_T + 0.064, -0.064], [PAPER_T, 0.0], PAPER_T,
                                     40, 0.5) for K in (1.28, 3.84)]
    assert [r["spectral radius"] for r in data["rows"]] == pytest.approx(radii, rel=1e-12)
    assert [r["verdict"] for r in data["rows"]] == ["stable", "unstable"]
    assert data["inputs"]["d"] == 40.5


def test_boundary_at_a_fractional_Td_is_the_paper_loops_decomposition(capsys):
    """Eq. (7) is for whole d: at Td / T = 40.5 the rows are PAPER_LOOP's D-decomposition."""
    data = json.loads(run(capsys, "boundary", "--Td", "0.0405", "--n", "3", "--format",
                          "json")[1])
    curve = symstab.PAPER_LOOP.boundary(x="B", y="K", n=3, Td=0.0405)
    assert [r["K_w [N m/rad]"] for r in data["rows"]] == pytest.approx(curve.y_values, rel=1e-9)
    assert [r["alpha"] for r in data["rows"]] == pytest.approx(
        np.asarray(curve.y_values) * PAPER_T**2 / PAPER_M, rel=1e-9)
    assert data["inputs"]["d"] == 40.5


def test_linear_units(capsys):
    _, out, _ = run(capsys, "limits", "--linear", "--d", "1")
    assert "N/m" in out and "N m/rad" not in out


def test_limits_reports_the_minimum_stiffness(capsys):
    status, out, _ = run(capsys, "limits", "--delta", str(PAPER_DELTA), "--gamma", "1.5",
                         "--beta", "-0.5")
    assert status == 0
    (lo, hi), = symstab.StabilityRegion(gamma=1.5, d=0, delta=PAPER_DELTA).alpha_intervals(-0.5)
    assert lo > 1.0
    assert f"a minimum is needed: alpha > {lo:.10g}" in out


def test_limits_of_an_empty_region_is_a_message_not_an_error(capsys):
    status, out, err = run(capsys, "limits", "--delta", str(PAPER_DELTA), "--d", "5",
                           "--gamma", "2.2", "--format", "json")
    assert status == 0 and err == ""
    data = json.loads(out)
    assert data["limits"]["alpha_max"] is None and data["limits"]["z_width"] == 0.0
    assert "empty" in data["notes"][0]


def test_boundary_csv_parses_and_lies_on_the_library_curve(capsys):
    status, out, err = run(capsys, "boundary", "--d", "10", "--n", "7", "--format", "csv")
    assert status == 0
    assert "Td = 0.01 s" in err  # the echo goes to stderr with CSV
    rows = list(csv.DictReader(io.StringIO(out)))
    assert len(rows) == 7
    assert list(rows[0]) == ["theta [rad]", "alpha", "beta", "K_w [N m/rad]", "B_w [N m s/rad]"]
    curve = symstab.boundary_curve(gamma=0.0, d=10, delta=PAPER_DELTA, n=7, segments=False)
    np.testing.assert_allclose([float(r["alpha"]) for r in rows], curve.alpha, rtol=1e-9, atol=0)
    np.testing.assert_allclose([float(r["K_w [N m/rad]"]) for r in rows],
                               curve.alpha * PAPER_M / PAPER_T**2, rtol=1e-9, atol=0)


def test_classify_agrees_with_python_control(capsys):
    kw, bw = [1.0, 3.0, 10.0, 4.0], [0.2, 0.2, 0.2, 0.05]
    status, out, _ = run(capsys, "classify", "--Td", "0.01", "--Kw", ",".join(map(str, kw)),
                         "--Bw", ",".join(map(str, bw)), "--format", "json")
    assert status == 0
    rows = json.loads(out)["rows"]
    for row, k, b in zip(rows, kw, bw, strict=True):
        alpha, beta = k * PAPER_T**2 / PAPER_M, b * PAPER_T / PAPER_M
        poles = python_control_closed_loop(alpha=alpha, beta=beta, gamma=0.0, d=10,
                                           delta=PAPER_DELTA, m=PAPER_M, T=PAPER_T).poles()
        radius = float(np.max(np.abs(poles)))
        assert row["spectral radius"] == pytest.approx(radius, rel=1e-8)
        assert row["verdict"] == ("stable" if radius < 1 else "unstable")


def test_design_finds_a_gain_over_no_virtual_mass(shared_cli_run):
    # The same run as test_cli_first_hour's and test_cli_design_loop's (shared: a search).
    status, out, err = shared_cli_run("design", "--delta", str(PAPER_DELTA), "--d", "10",
                                      "--format", "json")
    assert status == 0 and "searching" in err
    best = json.loads(out)["best"]
    assert best["gain"] > 1
    assert best["alpha_max_gamma0"] == pytest.approx(
        symstab.limits(gamma=0.0, d=10, delta=PAPER_DELTA).alpha_max, rel=1e-9)


@pytest.mark.parametrize("args, needle", [
    (["limits", "--m", "0"], "m must be"),
    (["limits", "--m", "-1"], "m must be"),
    (["limits", "--T", "0"], "T must be"),
    (["limits", "--b", "nan"], "b must be"),
    (["limits", "--Td", "-0.001"], "Td must be a finite real number >= 0"),
    (["limits", "--Td", "nan"], "Td must be a finite real number >= 0"),
    (["limits", "--Td", "1e3"], "delay Td / T must be from 0 to 10000 samples"),
    (["limits", "--d", "40.5"], "whole number of samples, got '40.5': give a fractional delay "
                                "in seconds with --Td"),
    # Issue 43: where the paper's loop cannot take a fractional delay, one line naming the command.
    (["simulate", "--Td", "0.0405", "--alpha", "1e-4", "--beta", "0.005", "--coulomb", "1e-3"],
     "--coulomb is simulated at a whole delay only"),
    (["map", "--Td", "0.0405", "--alpha", "0,1e-3,3", "--beta", "0,0.01,3", "--out", "m.npz",
      "--coulomb", "1e-3"], "--coulomb is simulated at a whole delay only"),
    (["limits", "--d", "2.5"], "delay d"),
    (["limits", "--d", "-1"], "delay d"),
    (["limits", "--gamma", "nan"], "gamma"),
    (["limits", "--delta", "-1"], "delta"),
    (["limits", "--delta", "0.1", "--Td", "0.04"], "--delta"),
    (["limits", "--delta", "0.1", "--Mw", "0.01"], "--Mw"),
    (["limits", "--Td", "0.01", "--d", "10"], "--Td"),
    (["limits", "--gamma", "1", "--Mw", "0.01"], "--Mw"),
    (["boundary", "--n", "1"], "n must be"),
    (["classify", "--alpha", "1"], "damping"),
    (["classify", "--alpha", "1,x", "--beta", "0"], "--alpha"),
    # A NaN was refused later as "K must be a finite real number": a name the user never typed.
    (["classify", "--delta", "0.0025", "--alpha", "nan", "--beta", "0.5"], "--alpha"),
    (["classify", "--delta", "0.0025", "--alpha", "0.1", "--beta", "1,inf"], "--beta"),
    (["simulate", "--delta", "0.0025", "--alpha", "nan", "--beta", "0.5"], "--alpha"),
    (["classify", "--alpha", "1,2", "--beta", "0,1,2"], "same length"),
    (["classify", "--delta", "0.1", "--Kw", "1", "--beta", "0"], "--Kw"),
    (["limits", "--format", "xml"], "--format"),
])
def test_bad_input_is_one_line_and_exit_2(capsys, tmp_path, monkeypatch, args, needle):
    monkeypatch.chdir(tmp_path)
    status, out, err = run(capsys, *args)
    assert status == 2
    lines = err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith(f"symstab {args[0]}: error:"), err
    assert needle in lines[0]
    assert "Traceback" not in err and out == ""
    assert list(tmp_path.iterdir()) == []


def test_paper_device_is_the_default():
    assert (PAPER_M, PAPER_B, PAPER_T) == (symstab.PAPER_DEVICE.m, symstab.PAPER_DEVICE.b,
                                           symstab.PAPER_DEVICE.T)


# --------------------------------------------------------------------------
# simulate and map


def test_simulate_writes_the_trajectory_and_agrees_with_the_radius(capsys, tmp_path):
    out = tmp_path / "traj.csv"
    status, text, _ = run(capsys, "simulate", "--Td", "0.01", "--Kw", "30", "--Bw", "0.5",
                          "--steps", "3000", "--out", str(out))
    assert status == 0
    radius = symstab.spectral_radius(alpha=30 * PAPER_T**2 / PAPER_M, beta=0.5 * PAPER_T / PAPER_M,
                                     gamma=0.0, d=10, delta=PAPER_DELTA)
    assert radius < 1 and ": stable;" in text
    data = np.loadtxt(out, delimiter=",", skiprows=1)
    assert data.shape == (3001, 3) and data[0, 2] == 1.0
    # The envelope's decay per period is the spectral radius (the max over a
    # window of an oscillation is off by a phase, hence the per-period root).
    tail = np.abs(data[-500:, 2]).max() / np.abs(data[-1000:-500, 2]).max()
    assert tail ** (1 / 500) == pytest.approx(radius, rel=1e-3)


def test_map_writes_npz_and_png_matching_the_exact_classification(capsys, tmp_path):
    out = tmp_path / "m.npz"
    status, text, _ = run(capsys, "map", "--delta", str(PAPER_DELTA), "--d", "1",
                          "--alpha", "0.02,0.5,12", "--beta=0.05,1.2,12", "--out", str(out))
    assert status == 0
    with np.load(out) as f:
        stable, alpha, beta = f["stable"], f["alpha"], f["beta"]
    A, B = np.meshgrid(alpha, beta, indexing="ij")
    exact = symstab.classify(alpha=A, beta=B, gamma=0.0, d=1, delta=PAPER_DELTA) == symstab.STABLE
    assert stable.shape == (12, 12) and 0 < exact.sum() < 144
    # Where the simulation disagrees, a neighbouring cell has the other exact
    # verdict: the boundary passes next to it (or it is on alpha = 0, marginal).
    code = symstab.classify(alpha=A, beta=B, gamma=0.0, d=1, delta=PAPER_DELTA)
    padded = np.pad(exact, 1, mode="edge")
    mixed = np.zeros_like(exact)
    for da, db in ((0, 1), (2, 1), (1, 0), (1, 2)):
        mixed |= padded[da:da + 12, db:db + 12] != exact
    differ = (stable != exact) & (code != symstab.MARGINAL)
    assert not np.any(differ & ~mixed), np.argwhere(differ & ~mixed)
    assert (tmp_path / "m.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


@pytest.mark.parametrize("args, needle", [
    (["simulate", "--alpha", "0.1", "--beta", "0.1", "--velocity-cutoff", "600"], "--velocity-cutoff must be"),
    (["simulate", "--alpha", "0.1", "--beta", "0.1", "--encoder-resolution", "-1"], "--encoder-resolution must be"),
    (["simulate", "--alpha", "0.1", "--beta", "0.1", "--steps", "0"], "steps"),
    (["simulate", "--alpha", "0.1", "--beta", "0.1", "--coulomb", "0.1", "--stiction", "0.05"], "--stiction must be"),
    (["simulate", "--alpha", "0.1", "--beta", "0.1", "--force-resolution", "nan"],
     "--force-resolution must be"),
    (["simulate", "--delta", "0.1", "--alpha", "0.1", "--beta", "0.1", "--paper-encoder"], "physical"),
    (["map", "--alpha", "0,1,10", "--beta", "0,1,10", "--out", "m.txt"], "--out"),
    (["map", "--alpha", "0,1", "--beta", "0,1,10", "--out", "m.csv"], "--alpha"),
    (["map", "--alpha", "0,1,10", "--beta", "0,1,10", "--out", "missing/m.csv"], "folder"),
])
def test_simulation_bad_input_exits_2_and_writes_nothing(capsys, tmp_path, monkeypatch, args, needle):
    monkeypatch.chdir(tmp_path)
    status, out, err = run(capsys, *args)
    assert status == 2, err
    assert needle in err.strip().splitlines()[-1]
    assert list(tmp_path.iterdir()) == []


def test_margins_at_a_fractional_td_are_the_paper_loops(capsys):
    """--Td 0.0405: the paper's options give PAPER_LOOP's margins at 40.5 samples."""
    data = json.loads(run(capsys, "margins", "--Td", "0.0405", "--Kw", "1.28", "--Bw", "0.064",
                          "--format", "json")[1])
    expected = symstab.PAPER_LOOP.margins(K=1.28, B=0.064, Td=0.0405)
    assert data["margins"]["point"]["d"] == 40.5
    assert data["margins"]["modulus"] == pytest.approx(expected.modulus, rel=1e-12)
    assert data["margins"]["exact_delay"]["margin"] == pytest.approx(
        expected.exact_delay.margin, rel=1e-12)
