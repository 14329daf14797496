"""``symstab margins``: the margins of one stable point, from the paper's options or a loop file.

The numbers are :meth:`symstab.Loop.margins`' (tests/numeric/analysis/test_margins.py
checks them against python-control and mpmath); here: that the command
computes them at the point its options name (the paper's physical options
are the same point as the loop file's values), says where they are in Hz,
and refuses a point that is not stable in one line with exit 2.
"""

import math

import pytest

import symstab

from conftest import REPO, run_cli, run_cli_json

PAPER = REPO / "examples" / "loops" / "paper.toml"

pytestmark = pytest.mark.usefixtures("loop_cache_dir")


def test_the_paper_options_and_the_loop_file_give_the_same_margins(capsys):
    paper = run_cli_json(capsys, "margins", "--Td", "0.003", "--Kw", "100", "--Bw", "1")
    loop = run_cli_json(capsys, "margins", "--loop", PAPER, "--set", "K=100", "--set", "B=1",
                        "--set", "d=3")
    expected = symstab.load_loop(PAPER).margins(K=100.0, B=1.0, d=3)
    for found in (paper["margins"], loop["margins"]):
        assert found["modulus"] == pytest.approx(expected.modulus, rel=1e-9)
        assert [g["margin"] for g in found["gain"]] == pytest.approx(
            [c.margin for c in expected.gain], rel=1e-9)
        assert [p["margin"] for p in found["phase"]] == pytest.approx(
            [c.margin for c in expected.phase], rel=1e-9)
        assert found["delay"] == expected.delay == 5
    # The loop file's parameter margins are in its units; the paper's options' in Table I's.
    assert [p["name"] for p in loop["margins"]["parameters"]] == ["B", "K"]
    assert [p["high"] for p in loop["margins"]["parameters"]] == pytest.approx(
        [p.high for p in expected.parameters], rel=1e-9)
    rows = {row["margin"]: row for row in paper["rows"]}
    # Hz at the device's sample period, 1 ms.
    assert rows["modulus min|1+L|"]["frequency [Hz]"] == pytest.approx(
        expected.modulus_theta / (2 * math.pi * 1e-3), rel=1e-9)


def test_the_table_names_each_margin_and_says_the_delay_is_in_whole_samples(capsys):
    status, out, err = run_cli(capsys, "margins", "--loop", PAPER, "--set", "K=3",
                               "--set", "B=0.2", "--set", "d=10")
    assert status == 0, err
    for text in ("modulus min|1+L|", "certified >=", "phase crossover", "gain crossover",
                 "K [N m/rad] up to", "B [N m s/rad] down to", "unstable at d = 53",
                 "whole samples"):
        assert text in out, text


@pytest.mark.parametrize("args, message", [
    (["--Td", "0.04", "--Kw", "100", "--Bw", "1"], "margins need a stable point"),
    (["--loop", PAPER, "--set", "K=0", "--set", "d=0"], "marginal"),
    (["--Td", "0.04", "--Kw", "1,2", "--Bw", "1"], "--Kw takes one value here"),
    (["--loop", PAPER, "--set", "K=1,2"], "one"),
    (["--loop", PAPER, "--x", "K"], "unrecognized arguments: --x"),
])
def test_a_point_that_is_not_one_stable_point_is_one_line_and_exit_2(capsys, args, message):
    status, out, err = run_cli(capsys, "margins", *args)
    assert status == 2 and out == ""
    assert err.count("\n") == 1 and message in err, err


def test_map_margin_writes_the_library_s_map_and_its_figure(capsys, tmp_path):
    import numpy as np

    out = tmp_path / "m.npz"
    status, printed, err = run_cli(capsys, "map", "--loop", PAPER, "--set", "d=40",
                                   "--set", "M=0.004", "--x-range=-0.05,0.6,12",
                                   "--y-range=0,9,10", "--margin", "modulus", "--out", out)
    assert status == 0, err
    assert (tmp_path / "m.png").stat().st_size > 0
    with np.load(out) as data:
        margin, lower = data["margin"], data["lower"]
    found = symstab.load_loop(PAPER).margin_map(np.linspace(-0.05, 0.6, 12),
                                                np.linspace(0, 9, 10), d=40, M=0.004)
    # The file is (x, y), as every map file; the result is (y, x).
    assert np.array_equal(margin, found.values.T, equal_nan=True)
    assert np.array_equal(lower, found.lower.T, equal_nan=True)
    assert np.isnan(margin).any() and np.isfinite(margin).any()
    assert f"{int(np.isfinite(margin).sum())} of 120 cells stable" in printed


@pytest.mark.parametrize("extra, message", [
    (["--simulate"], "--margin maps a margin of the linear loop"),
    (["--uncertain", "b=0.02:0.04"], "give one of them"),
    (["--margin", "phase"], "invalid choice: 'phase'"),
])
def test_map_margin_refuses_what_it_does_not_map(capsys, tmp_path, extra, message):
    args = ["map", "--loop", PAPER, "--x-range=0,0.2,3", "--y-range=0,2,3",
            "--out", tmp_path / "m.csv"]
    if "--margin" not in extra:
        args += ["--margin", "modulus"]
    status, out, err = run_cli(capsys, *args, *extra)
    assert status == 2 and message in err, err
    assert not list(tmp_path.iterdir())


def test_map_margin_delay_writes_the_exact_margins_at_a_fractional_delay(capsys, tmp_path):
    import numpy as np

    out = tmp_path / "d.csv"
    status, printed, err = run_cli(capsys, "map", "--loop", PAPER, "--set", "d=0.5",
                                   "--x-range=-0.05,2,5", "--y-range=10,600,4",
                                   "--margin", "delay", "--out", out, "--no-png")
    assert status == 0, err
    rows = np.genfromtxt(out, delimiter=",", skip_header=1)
    expected = symstab.load_loop(PAPER).margin_map(np.linspace(-0.05, 2, 5),
                                                   np.linspace(10, 600, 4), margin="delay",
                                                   d=0.5)
    # The file's 12 digits of the library's margins.
    assert np.allclose(rows[:, 2], expected.values.T.ravel(), rtol=1e-11, equal_nan=True)
    finite = expected.values[np.isfinite(expected.values)]
    assert "the exact delay margin in samples" in printed and "no stable cell" not in printed
    assert (f"delay margin from {finite.min():.4g} to {finite.max():.4g} samples "
            f"({finite.min():.4g} to {finite.max():.4g} ms)") in printed


def test_along_names_the_parameters_of_the_intervals(capsys):
    found = run_cli_json(capsys, "margins", "--loop", PAPER, "--set", "K=3", "--set", "B=0.2",
                         "--set", "d=10", "--along", "M")
    (interval,) = found["margins"]["parameters"]
    assert interval["name"] == "M" and interval["low"] < 0 < interval["high"]
    status, out, err = run_cli(capsys, "margins", "--loop", PAPER, "--along", "b")
    assert status == 2 and "'b' does not enter the loop's polynomial affinely" in err


def test_a_delay_range_gives_the_librarys_two_sets(capsys):
    data = run_cli_json(capsys, "margins", "--loop", PAPER, "--set", "K=2", "--set", "B=0.1",
                        "--delay-range", "40ms", "0.045")
    expected = symstab.load_loop(PAPER).delay_range(delay_range=(0.040, 0.045), K=2.0, B=0.1)
    found = data["delay_range"]
    assert found["samples"] == [40.0, 45.0]
    assert found["constant"] is True and found["varying"] is True
    assert found["gain_margin"] == pytest.approx(expected.gain_margin, rel=1e-12)


def test_a_reversed_delay_range_is_one_line(capsys):
    status, out, err = run_cli(capsys, "margins", "--loop", PAPER, "--delay-range", "45ms",
                               "40ms")
    assert status == 2 and out == "" and err.count("\n") == 1, err
    assert "--delay-range's TMAX must be" in err


def test_map_delay_range_writes_the_librarys_two_sets(capsys, tmp_path):
    import numpy as np

    out = tmp_path / "r.csv"
    status, printed, err = run_cli(capsys, "map", "--loop", PAPER, "--x-range=0.2,1,3",
                                   "--y-range=10,200,4", "--delay-range", "2ms", "0.004",
                                   "--out", out, "--no-png")
    assert status == 0, err
    rows = np.genfromtxt(out, delimiter=",", skip_header=1)
    expected = symstab.load_loop(PAPER).delay_range(np.linspace(0.2, 1, 3),
                                                    np.linspace(10, 200, 4),
                                                    delay_range=(0.002, 0.004))
    # The file is (x, y), the result (y, x).
    assert np.array_equal(rows[:, 2], expected.constant.T.ravel())
    assert np.array_equal(rows[:, 3], expected.varying.T.ravel())
    assert rows[:, 2].any() and not rows[:, 2].all()
    assert (f"{int(expected.constant.sum())} of 12 cells stable for every constant delay of 2 "
            f"to 4 samples") in printed


@pytest.mark.parametrize("extra, message", [
    (["--margin", "delay"], "give one of them"),
    (["--simulate"], "--delay-range maps the sets of a delay range of the linear loop"),
    (["--steps", "100"], "--steps is an option of the simulation"),
])
def test_map_delay_range_refuses_what_it_does_not_map(capsys, tmp_path, extra, message):
    status, out, err = run_cli(capsys, "map", "--loop", PAPER, "--x-range=0,0.2,3",
                               "--y-range=0,2,3", "--delay-range", "2ms", "4ms",
                               "--out", tmp_path / "m.csv", *extra)
    assert status == 2 and message in err and err.count("\n") == 1, err
    assert not list(tmp_path.iterdir())


@pytest.mark.parametrize("command", ["margins", "map"])
@pytest.mark.parametrize("ends, message", [
    (["1kg", "2ms"], "--delay-range: parameter 'Td' has unit 'kg': Td is the loop delay"),
    (["0", "1e9"], "at most 10000 (raise the limit with SYMSTAB_MAX_DELAY)"),
    (["nan", "2ms"], "--delay-range: Td must be a finite number"),
])
def test_a_bad_delay_range_is_one_line_before_any_work(capsys, tmp_path, command, ends,
                                                       message):
    grid = (["--x-range=0,1,3", "--y-range=0,2,3", "--out", tmp_path / "m.csv"]
            if command == "map" else [])
    status, out, err = run_cli(capsys, command, "--loop", PAPER, *grid, "--delay-range", *ends)
    assert status == 2 and out == "" and err.count("\n") == 1 and message in err, err
    assert not list(tmp_path.iterdir())
