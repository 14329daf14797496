"""``simulate`` and ``map`` compare the run with the theory of the loop simulated.

The velocity filter and the actuator lag are linear: the root count printed,
the map's comparison and the boundary drawn are those of the loop with them
(issue 18, item 4: they were the ideal loop's).  The oracle is python-control:
the paper's plant (with the lag) discretised by ``control.c2d(..., "zoh")``,
the environment built from the simulator's difference equations as transfer
functions, the delay, and the closed loop's poles.
"""

import numpy as np
import pytest

from symstab.numeric.engine.roots import MARGINAL, STABLE
from symstab.numeric.paper.device import PAPER_DEVICE

from conftest import run_cli
from oracles import simulated_loop_radius as oracle_radius

DEV = PAPER_DEVICE
#: The window of the README's map (d = 10), on a small grid.
GRID = ["--Td", "0.01", "--Kw", "0,70,16", "--Bw=-0.1,2,16"]


@pytest.fixture(autouse=True)
def _kernels_in_a_temporary_folder(loop_cache_dir):
    """The filtered and lagged loops' kernels are generated: never into ~/.cache."""


def _radius(text):
    (line,) = [line for line in text.splitlines() if line.startswith("theory (")]
    return line, float(line.split("spectral radius ")[1].split()[0])


def test_simulate_prints_the_filtered_loops_theory(capsys):
    # K_w = 35, B_w = 1.5 at d = 10: the ideal loop is stable (radius 0.996),
    # the loop with the 100 Hz filter that is simulated is not (1.0029).
    status, out, err = run_cli(capsys, "simulate", "--Td", "0.01", "--Kw", "35", "--Bw", "1.5",
                               "--velocity-cutoff", "100", "--steps", "4000")
    assert status == 0, err
    line, radius = _radius(out)
    assert line.startswith("theory (linear loop with the 100 Hz velocity filter): ")
    assert radius == pytest.approx(oracle_radius(35.0, 1.5, d=10, f_c=100.0), abs=1e-9)
    assert line.endswith("-> unstable")
    assert "4000 periods from x0 = 0.01: unstable" in out or "diverged (unstable)" in out


def test_simulate_prints_the_lagged_loops_theory(capsys):
    status, out, err = run_cli(capsys, "simulate", "--Td", "0.01", "--Kw", "30", "--Bw", "1",
                               "--actuator-bandwidth", "200", "--Mw", "0.002", "--steps", "400")
    assert status == 0, err
    line, radius = _radius(out)
    assert line.startswith("theory (linear loop with the 200 Hz actuator lag): ")
    assert radius == pytest.approx(oracle_radius(30.0, 1.0, d=10, f_a=200.0, M=0.002), abs=1e-9)


def test_filter_and_lag_together_with_a_virtual_mass(capsys):
    status, out, err = run_cli(capsys, "simulate", "--Td", "0.004", "--Kw", "20", "--Bw", "0.4",
                               "--Mw", "-0.003", "--velocity-cutoff", "50",
                               "--actuator-bandwidth", "300", "--steps", "400")
    assert status == 0, err
    line, radius = _radius(out)
    assert line.startswith("theory (linear loop with the 50 Hz velocity filter and the 300 Hz "
                           "actuator lag): ")
    assert radius == pytest.approx(oracle_radius(20.0, 0.4, d=4, f_c=50.0, f_a=300.0, M=-0.003),
                                   abs=1e-9)


def test_non_linear_elements_are_named_as_left_out(capsys):
    status, out, err = run_cli(capsys, "simulate", "--Td", "0.01", "--Kw", "30", "--Bw", "1",
                               "--velocity-cutoff", "50", "--paper-encoder", "--coulomb", "0.01",
                               "--steps", "400")
    assert status == 0, err
    line, radius = _radius(out)
    assert line.startswith("theory (linear loop with the 50 Hz velocity filter; its linear part "
                           "only: encoder quantization and Coulomb friction left out): ")
    assert radius == pytest.approx(oracle_radius(30.0, 1.0, d=10, f_c=50.0), abs=1e-9)


@pytest.fixture
def drawn(monkeypatch):
    """The lines of each figure saved, by label: {label: (x, y)}."""
    from matplotlib.figure import Figure

    seen = []
    savefig = Figure.savefig

    def record(fig, *args, **kwargs):
        seen.append({line.get_label(): (np.asarray(line.get_xdata(), dtype=float),
                                        np.asarray(line.get_ydata(), dtype=float))
                     for line in fig.axes[0].get_lines()})
        return savefig(fig, *args, **kwargs)

    monkeypatch.setattr(Figure, "savefig", record)
    return seen


def test_map_agrees_with_the_filtered_loop_and_draws_its_boundary(tmp_path, capsys, drawn):
    out = tmp_path / "m.npz"
    status, text, err = run_cli(capsys, "map", *GRID, "--velocity-cutoff", "100",
                                "--out", out)
    assert status == 0, err
    data = np.load(out)
    code, simulated = data["exact_code"], data["stable"]
    decided = code != MARGINAL
    # Every cell the theory decides, the simulation decides alike (the ideal
    # loop's count differed on 11 % of this grid).
    assert np.array_equal(simulated[decided], (code == STABLE)[decided])
    assert (f"0 of the {int(decided.sum())} cells that are not marginal differ from the "
            f"root-counting classification of the linear loop with the 100 Hz velocity filter"
            in text)
    assert str(data["theory"]) == "linear loop with the 100 Hz velocity filter"
    # The codes are the filtered loop's, by python-control, off the boundary.
    Kw, Bw = data["K_w"], data["B_w"]
    checked = 0
    for i, K in enumerate(Kw):
        for j, B in enumerate(Bw):
            r = oracle_radius(float(K), float(B), d=10, f_c=100.0)
            if abs(r - 1) > 1e-6:
                assert code[i, j] == (STABLE if r < 1 else -1), (K, B, r, code[i, j])
                checked += 1
    assert checked >= 200
    # The boundary drawn is where the filtered loop has a pole on the circle.
    (lines,) = drawn
    (label,) = [name for name in lines if name.startswith("boundary")]
    assert label == "boundary of the linear loop with the 100 Hz velocity filter (D-decomposition)"
    x, y = lines[label]
    inside = np.isfinite(x) & np.isfinite(y) & (y > 1) & (y < 70) & (x > -0.1) & (x < 2)
    points = np.flatnonzero(inside)
    assert points.size > 50
    for k in points[:: max(1, points.size // 25)]:
        assert oracle_radius(float(y[k]), float(x[k]), d=10, f_c=100.0) == pytest.approx(1, abs=1e-6)


def test_ideal_map_still_names_the_ideal_loop(tmp_path, capsys):
    status, text, err = run_cli(capsys, "map", "--Td", "0.01", "--Kw", "0,70,5", "--Bw=-0.1,2,4",
                                "--steps", "400", "--out", tmp_path / "m.csv", "--no-png")
    assert status == 0, err
    assert "differ from the root-counting classification of the ideal loop" in text


def test_ideal_map_draws_the_paper_loops_boundary_and_its_z_equal_one_line(tmp_path, capsys,
                                                                            drawn):
    """The ideal map's boundary is the paper's loop's (python-control: a pole on the circle)."""
    from oracles import python_control_closed_loop

    delta = PAPER_DEVICE.delta
    status, _, err = run_cli(capsys, "map", "--delta", str(delta), "--d", "5",
                             "--alpha", "0,0.05,12", "--beta=-0.01,0.3,12", "--steps", "400",
                             "--out", tmp_path / "m.npz")
    assert status == 0, err
    (lines,) = drawn
    assert "root z = 1" in lines                 # alpha = 0, drawn as for any loop
    x, y = lines["boundary of the ideal loop, eq. (7)"]
    inside = np.flatnonzero(np.isfinite(x) & (y > 1e-3) & (y < 0.05) & (x > -0.01) & (x < 0.3))
    assert inside.size > 50
    for k in inside[:: max(1, inside.size // 20)]:
        poles = python_control_closed_loop(alpha=float(y[k]), beta=float(x[k]), gamma=0.0, d=5,
                                           delta=delta, m=1.0, T=1.0).poles()
        assert np.min(np.abs(np.abs(poles) - 1.0)) <= 1e-7, (x[k], y[k])
