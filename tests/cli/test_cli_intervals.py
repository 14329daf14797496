"""Stable intervals are printed open, with exact ends where they are exact, and say which ends are marginal.

The stable set is open: each end of a stable interval has a pole on the unit
circle (marginal), so "[0, ...]" called a point stable that is not.  The
paper's plant has an integrator, so its z = 1 line is exactly K = 0; the
30-digit sum of P_d(1) used to leave 1e-30 of its terms there (K =
3.8e-26 N/m at T = 0.25 ms).  Oracle for the other end: python-control's
closed-loop poles there have radius 1.
"""

import json
import re

import numpy as np
import pytest

from symstab.numeric.engine.roots import MARGINAL, STABLE, UNSTABLE

from conftest import REPO, run_cli

PAPER = REPO / "examples" / "loops" / "paper.toml"
#: The paper's device (paper.toml), in SI units.
M, B_DEV = 0.0128, 0.0324


@pytest.fixture(autouse=True)
def _kernels_in_a_temporary_folder(loop_cache_dir):
    """The loop's kernels are generated: never into ~/.cache."""


def python_control_radius(K, B, *, T, d, m=M, b=B_DEV):
    import control

    G = control.c2d(control.tf([1], [m, b, 0]), T, "zoh")
    z = control.tf([1, 0], [1], T)
    VE = K + B * (z - 1) / (T * z)
    delay = control.tf([1], [1] + [0] * d, T)
    return float(np.max(np.abs(control.poles(control.feedback(G, VE * delay)))))


@pytest.mark.parametrize("T, d", [("0.00025", 0), ("0.0005", 0), ("0.00025", 4)])
def test_loop_interval_is_open_with_an_exact_zero_end(capsys, T, d):
    status, out, err = run_cli(capsys, "limits", "--loop", PAPER, "--set", f"T={T}",
                               "--set", f"d={d}", "--at", "0.5")
    assert status == 0, err
    (line,) = [line for line in out.splitlines() if line.startswith("stable K at B = 0.5")]
    found = re.fullmatch(r"stable K at B = 0\.5 N m s/rad: \(0, ([0-9.]+)\) N m/rad", line)
    assert found, line
    top = float(found.group(1))
    assert python_control_radius(top, 0.5, T=float(T), d=d) == pytest.approx(1, abs=1e-7)
    assert (f"open intervals: their ends are not stable; marginal (a pole on the unit circle) "
            f"at K = 0 and {found.group(1)} N m/rad") in out
    data = json.loads(run_cli(capsys, "limits", "--loop", PAPER, "--set", f"T={T}", "--set",
                              f"d={d}", "--at", "0.5", "--format", "json")[1])
    assert data["limits"]["y_max"] > 0
    ((lo, hi),) = data["at"]["intervals"]
    assert lo == 0.0 and hi == pytest.approx(top, rel=1e-9)
    assert data["at"]["ends"] == [["marginal", "marginal"]]


def test_loop_z1_line_prints_k_equals_0(capsys):
    status, out, err = run_cli(capsys, "boundary", "--loop", PAPER, "--set", "T=0.00025",
                               "--n", "3")
    assert status == 0, err
    (line,) = [line for line in out.splitlines() if line.startswith("line z = 1:")]
    assert re.fullmatch(r"line z = 1: [0-9.e-]+ K = 0, i\.e\. K = 0", line), line
    data = json.loads(run_cli(capsys, "boundary", "--loop", PAPER, "--set", "T=0.00025",
                              "--n", "3", "--format", "json")[1])
    assert data["lines"]["z = 1"]["c0"] == 0.0 and data["lines"]["z = 1"]["cx"] == 0.0


def test_paper_device_interval_is_open_and_names_its_marginal_ends(capsys):
    status, out, err = run_cli(capsys, "limits", "--Td", "0.004", "--Bw", "0.5")
    assert status == 0, err
    found = re.search(r"stable K_w at B_w = 0\.5 N m s/rad: \(0, ([0-9.]+)\) N m/rad\n", out)
    assert found, out
    assert python_control_radius(float(found.group(1)), 0.5, T=1e-3, d=4) == pytest.approx(1, abs=1e-7)
    assert re.search(r"stable alpha at beta = 0\.0390625: \(0, [0-9.]+\)\n", out), out
    assert (f"marginal (a pole on the unit circle) at K_w = 0 and {found.group(1)} N m/rad"
            in out)
    assert "[" not in "".join(line for line in out.splitlines() if line.startswith("stable"))


def test_interval_texts_open_infinite_and_unstable_ends():
    from symstab.cli.output import interval_texts

    text, note, kinds = interval_texts([(-np.inf, -0.0), (1.5, 2.0), (3.0, np.inf)],
                                       [(None, MARGINAL), (UNSTABLE, STABLE), (MARGINAL, None)],
                                       "K", "N/m")
    assert text == "(-inf, 0), (1.5, 2), (3, inf) N/m"
    assert note == ("open intervals: their ends are not stable; marginal (a pole on the unit "
                    "circle) at K = 0 and 3 N/m; unstable at K = 1.5 N/m; on the boundary to "
                    "within rounding at K = 2 N/m")
    assert kinds == [["infinite", "marginal"], ["unstable", "boundary"], ["marginal", "infinite"]]
    assert interval_texts([], [], "K") == ("none", None, [])


def test_locus_path_ends_are_closed_where_stable_and_crossings_open(capsys):
    # From K_w = 0.5 (stable, an end of the path: closed) across the crossing
    # at 2.9536 (a pair on the unit circle: open) at d = 40, B_w = 0.1.
    status, out, err = run_cli(capsys, "locus", "--Td", "0.04", "--Bw", "0.1", "--Kw", "0.5:30")
    assert status == 0, err
    found = re.search(r"stable along the path: K_w in \[0\.5, ([0-9.]+)\) N m/rad\n", out)
    assert found, out
    top = float(found.group(1))
    # python-control's poles of this degree-43 loop carry about 2e-6: the
    # crossing is checked by the sign change of the radius 2 % either side.
    assert python_control_radius(0.98 * top, 0.1, T=1e-3, d=40) < 1
    assert python_control_radius(1.02 * top, 0.1, T=1e-3, d=40) > 1
    assert python_control_radius(top, 0.1, T=1e-3, d=40) == pytest.approx(1, abs=1e-5)
    assert (f"open intervals: their ends are not stable; marginal (a pole on the unit circle) "
            f"at K_w = {found.group(1)} N m/rad") in out
    status, out, err = run_cli(capsys, "locus", "--Td", "0.04", "--Bw", "0.1", "--Kw", "0.5:1")
    assert "stable along the path: K_w in [0.5, 1] N m/rad" in out
    assert "open intervals" not in out
