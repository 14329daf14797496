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
