"""``simulate --loop`` and ``map --loop --simulate``: a loop file run in time.

Oracles: the loop's certified root counts (``symstab classify --loop``, the
same cells), python-control's closed-loop poles for the growth of one
trajectory, and the paper's own simulator (``symstab map`` of the paper's
device options) on the same grid.  Bad input is one line, exit status 2,
before the run.
"""

import numpy as np
import pytest

import symstab

from conftest import REPO
from conftest import run_cli as run

LOOPS = REPO / "examples" / "loops"
PAPER = LOOPS / "paper.toml"

pytestmark = pytest.mark.usefixtures("loop_cache_dir")


def test_map_simulate_agrees_with_the_root_counts_and_the_paper_simulator(capsys, tmp_path):
    grid_k, grid_b = "0.5,40,8", "-0.05,1.2,9"
    out = tmp_path / "loop.npz"
    status, text, err = run(capsys, "map", "--loop", PAPER, "--set", "d=10", "--simulate",
                            f"--x-range={grid_b}", f"--y-range={grid_k}", "--out", out)
    assert status == 0, err
    assert text.splitlines()[0].startswith("map --loop --simulate: every cell simulated")
    assert "0 of the 72 cells that are not marginal differ from the root counts" in text
    paper = tmp_path / "paper.npz"
    status, _, err = run(capsys, "map", "--d", "10", f"--Kw={grid_k}", f"--Bw={grid_b}",
                         "--out", paper, "--no-png")
    assert status == 0, err
    with np.load(out) as f, np.load(paper) as g:
        simulated, code = f["simulated_stable"], f["code"]     # (B, K)
        assert 0 < simulated.sum() < simulated.size
        np.testing.assert_array_equal(simulated, code == symstab.STABLE)
        np.testing.assert_array_equal(simulated, g["stable"].T)  # the paper's map is (K_w, B_w)
        assert int(f["steps"]) == 12000 + 800 * 10
    assert (tmp_path / "loop.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_simulate_loop_prints_the_verdict_and_the_root_count_and_writes_the_trajectory(
        capsys, tmp_path):
    out = tmp_path / "t.csv"
    status, text, err = run(capsys, "simulate", "--loop", LOOPS / "operator_arm.toml",
                            "--set", "K=1500", "--steps", "3000", "--out", out)
    assert status == 0, err
    loop = symstab.load_loop(LOOPS / "operator_arm.toml")
    radius = loop.spectral_radius(K=1500.0)
    assert radius > 1
    assert "simulated 3000 periods from x0 = 1 (ideal loop): unstable" in text
    assert f"spectral radius {radius:.12g} -> unstable" in text
    rows = np.loadtxt(out, delimiter=",", skiprows=1)
    assert rows.shape == (3001, 3) and rows[1, 1] == pytest.approx(1e-3)
    late, early = np.abs(rows[2600:, 2]).max(), np.abs(rows[1100:1500, 2]).max()
    assert (late / early) ** (1 / 1500) == pytest.approx(radius, abs=1e-4)


def test_a_saturated_unstable_loop_is_called_bounded_not_stable(capsys):
    status, text, err = run(capsys, "simulate", "--loop", LOOPS / "operator_arm.toml",
                            "--set", "K=3000", "--force-limit", "5", "--steps", "4000")
    assert status == 0, err
    assert "force limit 5" in text and "bounded, not decaying (a limit cycle" in text
    assert "-> unstable" in text


def test_a_force_quantum_s_limit_cycle_is_bounded_and_the_map_agrees_with_the_root_counts(
        capsys, tmp_path):
    """A DAC of 1 mN on the 50 Hz filtered loop: a stable point cycles within the quantum's
    bound; on a map every cell not marginal agrees with the root counts."""
    status, text, err = run(capsys, "simulate", "--loop", LOOPS / "lowpass_velocity.toml",
                            "--set", "K=1", "--force-resolution", "0.003", "--steps", "8000")
    assert status == 0, err
    assert "(force quantum 0.003 (SI units of the loop file)): bounded" in text
    assert "-> stable" in text
    out = tmp_path / "q.npz"
    status, text, err = run(capsys, "map", "--loop", LOOPS / "lowpass_velocity.toml",
                            "--simulate", "--force-resolution", "1e-3", "--x-range=0,0.2,5",
                            "--y-range=0.5,6,5", "--steps", "4000", "--out", out, "--no-png")
    assert status == 0, err
    with np.load(out) as f:
        simulated, code = f["simulated_stable"], f["code"]
    assert 0 < simulated.sum() < simulated.size
    np.testing.assert_array_equal(simulated[code != symstab.MARGINAL],
                                  code[code != symstab.MARGINAL] == symstab.STABLE)


def test_a_saturated_map_s_limit_cycles_are_their_own_class_in_the_files_and_the_png(
        capsys, tmp_path):
    """Issue 40, item 4: with a force limit the cells whose certified count is unstable
    settle into bounded cycles; they were written and drawn stable (38 of them on this
    grid at the default horizon).  The oracle is the certified count (``code``): a
    limit cycle exactly where it is -1, stable exactly where it is 1."""
    grid = ["--set", "d=10", "--x-range=-0.05,1.9,7", "--y-range=8.75,70,5",
            "--force-limit", "0.05", "--steps", "6000"]
    out = tmp_path / "map.csv"
    status, text, err = run(capsys, "map", "--loop", PAPER, "--simulate", *grid, "--out", out)
    assert status == 0, err
    rows = np.genfromtxt(out, delimiter=",", names=True)
    assert rows.dtype.names[2:] == ("code", "stable", "simulated_stable",
                                    "simulated_limit_cycle", "growth")
    unstable = rows["code"] == -1
    assert unstable.sum() >= 8
    np.testing.assert_array_equal(rows["simulated_limit_cycle"] == 1, unstable)
    np.testing.assert_array_equal(rows["simulated_stable"] == 1, rows["code"] == 1)
    assert f"{int(unstable.sum())} bounded limit cycles" in text
    assert "0 of the 35 cells that are not marginal differ from the root counts" in text
    npz = tmp_path / "map.npz"
    status, _, err = run(capsys, "map", "--loop", PAPER, "--simulate", *grid, "--out", npz,
                         "--no-png")
    assert status == 0, err
    with np.load(npz) as f:
        np.testing.assert_array_equal(f["simulated_limit_cycle"], f["code"] == -1)
    # The paper's own map (its device options) writes the same class.
    paper = tmp_path / "paper.npz"
    status, _, err = run(capsys, "map", "--d", "10", "--Kw=8.75,70,5", "--Bw=-0.05,1.9,7",
                         "--force-limit", "0.05", "--steps", "6000", "--out", paper, "--no-png")
    assert status == 0, err
    with np.load(paper) as g:                                   # (K_w, B_w)
        np.testing.assert_array_equal(g["limit_cycle"].T, unstable.reshape(7, 5))
    # The PNG shades the cycles in a colour of their own.
    from matplotlib.image import imread

    from symstab.cli.map import LIMIT_CYCLE_COLOR

    pixels = (imread(tmp_path / "map.png")[..., :3] * 255).round()
    colour = [int(LIMIT_CYCLE_COLOR[i:i + 2], 16) for i in (1, 3, 5)]
    assert np.count_nonzero(np.all(np.abs(pixels - colour) <= 1, axis=-1)) > 1000


def test_friction_holds_the_mass_and_the_verdict_says_so(capsys):
    """Two masses, friction on the motor: it ends held within stiction / K of zero."""
    status, text, err = run(capsys, "simulate", "--loop", LOOPS / "two_mass.toml",
                            "--coulomb", "0.05", "--stiction", "0.08", "--steps", "2000")
    assert status == 0, err
    assert "Coulomb friction 0.05, stiction 0.08, 20 sub-steps a period" in text
    held = float(text.split("held at rest by friction at x = ")[1].split(")")[0])
    assert 0 < abs(held) <= 0.08 / 100.0
    assert "-> stable" in text


def test_friction_compensation_of_a_loop_file_is_the_library_s(capsys, tmp_path):
    """--friction-compensation with --loop was refused ("a general loop has no velocity
    estimate"); every loop with friction now compensates with the simulator's backward
    difference.  Oracle: the library's run with the same non-idealities, and the run without
    compensation, which must differ (the flag is not dropped)."""
    common = ["simulate", "--loop", LOOPS / "two_mass.toml", "--coulomb", "0.05",
              "--steps", "2000"]
    status, text, err = run(capsys, *common, "--friction-compensation", "--out",
                            tmp_path / "on.csv")
    assert status == 0, err
    assert "Coulomb friction 0.05, compensated on the backward-difference velocity" in text
    status, _, err = run(capsys, *common, "--out", tmp_path / "off.csv")
    assert status == 0, err
    loop = symstab.load_loop(LOOPS / "two_mass.toml")
    Nonidealities = symstab.numeric.paper.simulate.Nonidealities
    for name, compensate in (("on", True), ("off", False)):
        shown = np.loadtxt(tmp_path / f"{name}.csv", delimiter=",", skiprows=1)[:, 2]
        run_ = loop.simulate(steps=2000, x0=0.01, record=True, nonideal=Nonidealities(
            coulomb_friction=0.05, friction_compensation=compensate))
        np.testing.assert_allclose(shown, np.ravel(run_.positions), rtol=1e-12, atol=0)
    assert not np.array_equal(np.loadtxt(tmp_path / "on.csv", delimiter=",", skiprows=1),
                              np.loadtxt(tmp_path / "off.csv", delimiter=",", skiprows=1))


def test_friction_behind_an_undeclared_lag_is_refused_before_the_run(capsys, tmp_path,
                                                                    monkeypatch):
    text = (LOOPS / "actuator_lag.toml").read_text()
    lagged = tmp_path / "lagged.toml"
    lagged.write_text(text.replace('actuator = "1/(tau*s + 1)"', ""))
    (tmp_path / "work").mkdir()
    monkeypatch.chdir(tmp_path / "work")
    status, out, err = run(capsys, "simulate", "--loop", lagged, "--coulomb", "0.01")
    assert status == 2 and err.count("\n") == 1, err
    assert ("--coulomb: Coulomb friction acts on the driven mass, whose position per force has "
            "relative degree 2; the plant has relative degree 3") in err
    assert out == "" and list((tmp_path / "work").iterdir()) == []


def test_map_simulates_friction_on_the_loop_s_mass(capsys, tmp_path):
    out = tmp_path / "f.npz"
    status, text, err = run(capsys, "map", "--loop", LOOPS / "actuator_lag.toml", "--simulate",
                            "--coulomb", "0.02", "--x-range=0.2,1,3", "--y-range=50,400,3",
                            "--steps", "1000", "--out", out, "--no-png")
    assert status == 0, err
    loop = symstab.load_loop(LOOPS / "actuator_lag.toml")
    with np.load(out) as f:
        assert "Coulomb friction 0.02" in str(f["nonidealities"])
        B, K = np.meshgrid(f["x"], f["y"], indexing="ij")
        # 1000 periods (was 3000): the same verdicts, not symmetric in B and K.
        run_ = loop.simulate(B=B, K=K, steps=1000, x0=0.01,
                             nonideal=symstab.numeric.paper.simulate.Nonidealities(coulomb_friction=0.02))
        np.testing.assert_array_equal(f["simulated_stable"], run_.stable)


@pytest.mark.parametrize("args, needle", [
    (["simulate", "--loop", PAPER, "--velocity-cutoff", "50"],
     "a velocity filter written into the loop file's environment"),
    (["simulate", "--loop", PAPER, "--coulomb", "0.01", "--stiction", "0.005"],
     "--stiction must be"),
    (["map", "--loop", PAPER, "--x-range=0,1,3", "--y-range=0,1,3", "--out", "m.npz",
      "--coulomb", "0.01"], "--coulomb is an option of the simulation: add --simulate"),
    (["simulate", "--loop", PAPER, "--Kw", "3"], "--Kw is an option of the paper's device"),
    (["simulate", "--loop", PAPER, "--steps", "3"], "steps"),
    (["simulate", "--loop", PAPER, "--force-limit", "-1"], "--force-limit must be"),
    (["simulate", "--loop", PAPER, "--force-resolution", "0"], "--force-resolution must be"),
    (["simulate", "--loop", PAPER, "--force-resolution", "1e-3", "--coulomb", "0.01"],
     "--force-resolution with --coulomb"),
    # Issue 40, item 6: values double precision cannot step ran, and "diverged (unstable)".
    (["simulate", "--loop", PAPER, "--set", "d=10", "--force-resolution", "1e-320"],
     "--force-resolution must be a finite real number >= 2.2250738585072014e-308"),
    (["simulate", "--loop", PAPER, "--encoder-resolution", "1e-320"],
     "--encoder-resolution must be a finite real number >= 2.2250738585072014e-308"),
    (["simulate", "--loop", PAPER, "--coulomb", "1e306"],
     "--coulomb must be a real number from 0 to 2.56e+302 on this plant"),
    (["map", "--loop", PAPER, "--x-range=0,1,3", "--y-range=0,1,3", "--out", "m.npz",
      "--simulate", "--coulomb", "1e306"], "--coulomb must be a real number from 0 to 2.56e+302"),
    (["simulate", "--Td", "0.01", "--Kw", "2", "--Bw", "0.1", "--coulomb", "1e306"],
     "--coulomb must be a real number from 0 to 2.56e+305 on this plant"),
    (["map", "--Td", "0.01", "--Kw=0,2,3", "--Bw=0,1,3", "--out", "m.npz", "--coulomb", "1e306"],
     "--coulomb must be a real number from 0 to 2.56e+305 on this plant"),
    (["simulate", "--Kw", "3", "--Bw", "0.1", "--substeps", "5"], "drop --substeps"),
    (["map", "--loop", PAPER, "--x-range=0,1,3", "--y-range=0,1,3", "--out", "m.npz",
      "--steps", "100"], "--steps is an option of the simulation: add --simulate"),
    (["map", "--loop", PAPER, "--x-range=0,1,3", "--y-range=0,1,3", "--out", "m.npz",
      "--simulate", "--actuator-bandwidth", "100"], "written into the loop file's plant"),
    (["map", "--simulate", "--Kw=0,1,3", "--Bw=0,1,3", "--out", "m.npz"],
     "--simulate needs a loop file"),
    (["simulate", "--loop", LOOPS / "frictionless.toml", "--paper-encoder"],
     "--paper-encoder is the paper's encoder"),
    (["simulate", "--loop", PAPER, "--format", "json"], "--format json"),
    (["simulate", "--loop", PAPER, "--out", "t.npz"], "--out must end in .csv"),
    (["map", "--loop", PAPER, "--x-range=0,1,3", "--y-range=0,1,3", "--out", "m.npz",
      "--format", "csv"], "--format csv"),
])
def test_bad_simulation_input_is_one_line_before_the_run(capsys, tmp_path, monkeypatch, args,
                                                         needle):
    monkeypatch.chdir(tmp_path)
    status, out, err = run(capsys, *args)
    assert status == 2 and err.count("\n") == 1 and needle in err, err
    assert "simulated" not in out
    assert list(tmp_path.iterdir()) == []
