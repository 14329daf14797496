"""``map --loop --uncertain``: the probability of stability of every cell, from the command line.

Oracles: the library's map (tested against an independent python-control
sampling in tests/numeric/analysis/test_probability.py) at the values the options
name, whatever unit they are written in; the root counts where nothing
varies.  Bad input is one line, exit status 2, before any work, and nothing
is written.
"""

import numpy as np
import pytest

import symstab

from conftest import REPO
from conftest import run_cli as run

LOOPS = REPO / "examples" / "loops"
PAPER = LOOPS / "paper.toml"
GRID = ("--x-range=-0.05,0.2,6", "--y-range=0.5,3,5")

pytestmark = pytest.mark.usefixtures("loop_cache_dir")


def test_the_map_is_the_library_s_at_the_values_given_in_any_unit(capsys, tmp_path):
    out = tmp_path / "p.npz"
    status, text, err = run(capsys, "map", "--loop", PAPER, "--set", "d=10", "--uncertain",
                            "b=16.2:48.6 g*m^2/s", "--samples", "300", "--seed", "7", *GRID,
                            "--out", out)
    assert status == 0, err
    lines = text.splitlines()
    assert lines[0].startswith("map --loop --uncertain: the probability that each cell is stable")
    assert "300 draws of b ~ uniform(0.0162, 0.0486) N m s/rad (seed 7)" in text
    loop = symstab.load_loop(PAPER)
    xs, ys = np.linspace(-0.05, 0.2, 6), np.linspace(0.5, 3, 5)
    found = loop.stability_probability(xs, ys, uncertain={"b": (0.0162, 0.0486)}, samples=300,
                                       seed=7, d=10)
    assert 0 < np.count_nonzero((found.probability > 0) & (found.probability < 1))
    with np.load(out) as f:
        np.testing.assert_array_equal(f["probability"], found.probability.T)   # (x, y)
        np.testing.assert_array_equal(f["standard_error"], found.standard_error.T)
        assert int(f["samples"]) == 300 and int(f["seed"]) == 7
        assert str(f["uncertain"][0]) == "b ~ uniform(0.0162, 0.0486) N m s/rad"
        assert str(f["x_name"]) == "B" and str(f["y_unit"]) == "N m/rad"
    assert (tmp_path / "p.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_a_delay_drawn_and_the_csv(capsys, tmp_path):
    out = tmp_path / "p.csv"
    status, text, err = run(capsys, "map", "--loop", PAPER, "--uncertain", "d=5:15",
                            "--samples", "100", "--x-range=0.75,1.5,2", "--y-range=25,40,2",
                            "--out", out, "--no-png")
    assert status == 0, err
    assert "d ~ the integers 5 to 15, equally likely" in text
    rows = np.loadtxt(out, delimiter=",", skiprows=1)
    assert open(out).readline().strip() == \
        "B [N m s/rad],K [N m/rad],probability,standard_error,marginal"
    assert rows.shape == (4, 5) and np.count_nonzero((rows[:, 2] > 0) & (rows[:, 2] < 1)) >= 3
    # Each delay is equally likely: the expected probability is the fraction of the eleven
    # delays at which the cell is stable; 100 draws are within 3 standard errors of it.
    loop = symstab.load_loop(PAPER)
    for B, K, p, _error, _marginal in rows:
        expected = np.mean([loop.classify(B=B, K=K, d=d) == symstab.STABLE
                            for d in range(5, 16)])
        assert abs(p - expected) <= 3 * np.sqrt(expected * (1 - expected) / 100) + 1e-12


def test_a_delay_in_time_drawn_is_the_library_s(capsys, tmp_path):
    """``--uncertain Td=5ms:15ms`` draws the delay in time (the file's d = 40 not kept beside
    it): the library's map with ``uncertain={"Td": (0.005, 0.015)}``."""
    out = tmp_path / "p.npz"
    status, text, err = run(capsys, "map", "--loop", PAPER, "--uncertain", "Td=5ms:15ms",
                            "--samples", "40", "--x-range=0.75,1.5,2", "--y-range=25,40,2",
                            "--out", out, "--no-png")
    assert status == 0, err
    found = symstab.load_loop(PAPER).stability_probability(
        np.linspace(0.75, 1.5, 2), np.linspace(25, 40, 2), uncertain={"Td": (0.005, 0.015)},
        samples=40, seed=0)
    with np.load(out) as f:
        np.testing.assert_array_equal(f["probability"], found.probability.T)
    assert np.count_nonzero((found.probability > 0) & (found.probability < 1)) >= 1


@pytest.mark.parametrize("args, needle", [
    (["--uncertain", "b=0.01:0.02"], "--uncertain needs a loop file"),
    (["--loop", PAPER, *GRID, "--uncertain", "K=1:2"], "K is an axis"),
    (["--loop", PAPER, *GRID, "--uncertain", "q=1:2"], "--uncertain q: not a parameter"),
    (["--loop", PAPER, *GRID, "--uncertain", "b"], "expected NAME=LO:HI"),
    (["--loop", PAPER, *GRID, "--uncertain", "b=0.05:0.01"], "LO < HI"),
    (["--loop", PAPER, *GRID, "--uncertain", "b=0.01:nan"], "--uncertain b must be LO:HI"),
    (["--loop", PAPER, *GRID, "--uncertain", "b=1:2 Hz"], "Hz"),
    (["--loop", PAPER, *GRID, "--uncertain", "d=-1:3"], "--uncertain d: the delay in samples, >= 0"),
    (["--loop", PAPER, *GRID, "--uncertain", "Td=3ms:2ms"], "--uncertain Td: LO:HI must have LO < HI"),
    (["--loop", PAPER, *GRID, "--uncertain", "b=0.01:0.02", "--uncertain", "b=0.01:0.03"],
     "given twice"),
    (["--loop", PAPER, *GRID, "--uncertain", "b=0.01:0.02", "--samples", "0"], "samples"),
    (["--loop", PAPER, *GRID, "--uncertain", "b=0.01:0.02", "--seed", "-1"], "seed"),
    (["--loop", PAPER, *GRID, "--samples", "10"], "--samples counts the draws of --uncertain"),
    (["--loop", PAPER, *GRID, "--uncertain", "b=0.01:0.02", "--simulate"], "give one of them"),
    (["--loop", PAPER, *GRID, "--uncertain", "b=0.01:0.02", "--steps", "100"], "drop --steps"),
    (["--loop", LOOPS / "lowpass_velocity.toml", *GRID, "--uncertain", "f_c=100:600"],
     "--uncertain f_c"),
])
def test_bad_input_is_one_line_before_any_work(capsys, tmp_path, monkeypatch, args, needle):
    monkeypatch.chdir(tmp_path)
    status, out, err = run(capsys, "map", *args, "--out", "p.npz")
    assert status == 2, err
    assert err.count("\n") == 1 and needle in err, err
    assert out == "" and list(tmp_path.iterdir()) == []
