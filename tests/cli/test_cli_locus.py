"""``symstab locus``: the crossings table, its JSON, the PNG, and bad input.

Oracles: the stable intervals of the D-decomposition
(``Loop.stable_intervals``, which finds crossings without tracking poles),
python-control's poles on both sides of a crossing, and the certified
counts.  Bad input is one line ``symstab locus: error: ...``, exit status 2,
and no PNG.
"""

import numpy as np
import pytest

import symstab

from conftest import PAPER_M, PAPER_T, REPO
from conftest import run_cli as run
from conftest import run_cli_json as run_json

PAPER = str(REPO / "examples" / "loops" / "paper.toml")
TUSTIN = str(REPO / "examples" / "loops" / "tustin_damper.toml")


pytestmark = pytest.mark.usefixtures("loop_cache_dir")


def test_the_example_finds_K_max_of_the_D_decomposition(capsys):
    """`symstab locus --Td 0.04 --Bw 0.1 --Kw 0:30`: one pair out at the top of the stable K."""
    data = run_json(capsys, "locus", "--Td", "0.04", "--Bw", "0.1", "--Kw", "0:30")
    loop = symstab.load_loop(PAPER)      # rotary units, as the device options
    (_, top), = loop.stable_intervals("K", B=0.1, d=40)
    crossings = data["crossings"]
    assert [(c["kind"], c["direction"]) for c in crossings] == [("pair", "out")]
    assert crossings[0]["value"] == pytest.approx(top, rel=1e-9)
    assert crossings[0]["parameter_value"] == pytest.approx(top * PAPER_T**2 / PAPER_M, rel=1e-9)
    assert [s["unstable_poles"] for s in data["stretches"]] == [0, 2]
    assert data["certified_agree"] is True


def test_poles_leave_the_circle_at_the_crossing(capsys):
    """python-control: all poles inside 5 % below the printed K, two outside 5 % above.

    (python-control's poles next to z = 1 are good to some 1e-5 only: a
    closer point would be inside its rounding.)
    """
    control = pytest.importorskip("control")
    data = run_json(capsys, "locus", "--Td", "0.04", "--Bw", "0.1", "--Kw", "0:30")
    K = data["crossings"][0]["value"]
    loop = symstab.load_loop(PAPER)
    below = np.abs(control.poles(loop.closed_loop(K=K * 0.95, B=0.1)))
    above = np.abs(control.poles(loop.closed_loop(K=K * 1.05, B=0.1)))
    assert below.max() < 1 and np.count_nonzero(above > 1) == 2


def test_table_lists_each_crossing_once(capsys):
    status, out, err = run(capsys, "locus", "--Td", "0.04", "--Bw", "0.1", "--Kw=-5:3000:401")
    assert status == 0, err
    lines = out.splitlines()
    header = next(k for k, line in enumerate(lines) if line.lstrip().startswith("K_w [N m/rad]"))
    rows = [line.split() for line in lines[header + 2:header + 7]]
    assert [r[2:6] for r in rows] == [["z", "=", "1", "in"]] + [["pair", "out"] + r[4:6]
                                                                for r in rows[1:]]
    assert rows[0][0] == "0"                      # K = 0 to within rounding, printed as 0
    assert [r[-1] for r in rows] == ["0", "2", "4", "6", "8"]
    # Open: K = 0 has the pole at z = 1, 2.9536 a pair on the circle.
    assert "stable along the path: K_w in (0, 2.95362954" in out


def test_dimensionless_path_along_beta(capsys):
    """β from -0.5 to 3 at α = 0.5, γ = 1, d = 1: in at one end of the stable β, out at the other."""
    from symstab.numeric.paper.stability import unstable_root_counts

    data = run_json(capsys, "locus", "--delta", "0.0025", "--d", "1", "--gamma", "1",
                    "--alpha", "0.5", "--beta=-0.5:3:351")
    values = [c["value"] for c in data["crossings"]]
    assert [c["direction"] for c in data["crossings"]] == ["in", "out"]
    inside = unstable_root_counts(alpha=0.5, beta=np.mean(values), gamma=1.0, d=1, delta=0.0025)
    outside = unstable_root_counts(alpha=0.5, beta=values[1] + 0.01, gamma=1.0, d=1, delta=0.0025)
    assert (inside, outside) == (0, 2)


def test_loop_file_form(capsys):
    data = run_json(capsys, "locus", "--loop", TUSTIN, "--set", "K=300", "--set", "B=-0.1:2:201")
    loop = symstab.load_loop(TUSTIN)
    intervals = loop.stable_intervals("B", K=300.0)
    assert [(c["kind"], c["direction"]) for c in data["crossings"]] == [("z = -1", "in"),
                                                                         ("pair", "in")]
    assert data["crossings"][1]["value"] == pytest.approx(intervals[0][0], rel=1e-9)
    assert data["inputs"]["values"]["K"] == 300.0


def test_png_is_written_and_deterministic(capsys, tmp_path):
    first, second = tmp_path / "a.png", tmp_path / "b.png"
    for path in (first, second):
        status, out, err = run(capsys, "locus", "--Td", "0.04", "--Bw", "0.1", "--Kw", "0:30:101",
                               "--png", path)
        assert status == 0, err
        assert f"wrote {path}" in out
    data = first.read_bytes()
    assert data[:8] == b"\x89PNG\r\n\x1a\n"
    assert data == second.read_bytes()


@pytest.mark.parametrize("args, message", [
    (["--Bw", "0.1", "--Kw", "30"], "exactly one of --Kw and --Bw must be a range"),
    (["--Bw", "0:1", "--Kw", "0:30"], "exactly one of --Kw and --Bw"),
    (["--Bw", "0.1"], "once each"),
    (["--Bw", "0.1", "--Kw", "0:30:1"], "N must be from 2"),
    (["--Bw", "0.1", "--Kw", "5:5"], "LOW != HIGH"),
    (["--Bw", "0.1", "--Kw", "0:nan"], "finite"),
    (["--Bw", "0.1", "--Kw", "a:b"], "numbers"),
    (["--Bw", "x", "--Kw", "0:30"], "--Bw must be a number"),
    (["--delta", "0.1", "--Bw", "0.1", "--alpha", "0:1"], "--Bw needs a physical device"),
    (["--Bw", "0.1", "--Kw", "0:30", "--set", "K=1"], "--set needs a loop file"),
    (["--Bw", "0.1", "--Kw", "0:30", "--d", "40.5"], "give a fractional delay in seconds with --Td"),
    (["--loop", PAPER, "--Kw", "0:30"], "--Kw is an option of the paper's device"),
    (["--loop", PAPER, "--set", "K=1"], "give the path"),
    (["--loop", PAPER, "--set", "K=0:1", "--set", "B=0:1"], "already"),
    (["--loop", PAPER, "--set", "d=0:3"], "not a path"),
    (["--loop", PAPER, "--set", "Q=0:3"], "not a parameter"),
    (["--loop", PAPER, "--set", "K=0:3", "--set", "K=1"], "twice"),
    (["--loop", PAPER, "--set", "K=0:3", "--d", "2", "--set", "d=3"], "delay once"),
    (["--loop", str(REPO / "no_such.toml"), "--set", "K=0:3"], "no_such.toml"),
])
def test_bad_input_is_one_line_and_no_png(capsys, tmp_path, args, message):
    png = tmp_path / "locus.png"
    status, out, err = run(capsys, "locus", *args, "--png", png)
    assert status == 2
    assert err.count("\n") == 1 and err.startswith("symstab locus: error: "), err
    assert message in err
    assert out == ""
    assert not png.exists()


def test_png_folder_is_checked_first(capsys, tmp_path):
    status, out, err = run(capsys, "locus", "--Bw", "0.1", "--Kw", "0:30",
                           "--png", tmp_path / "missing" / "x.png")
    assert status == 2 and "does not exist" in err and out == ""


def test_help_names_the_path_syntax(capsys):
    status, out, _ = run(capsys, "locus", "--help")
    assert status == 0
    assert "LOW:HIGH" in out and "--set" in out and "example:" in out


@pytest.mark.parametrize("where", [["--d", "1000", "--beta", "0.001", "--alpha", "0:0.000001:3"],
                                   ["--loop", PAPER, "--set", "d=1000", "--set", "K=0:1:3"]])
def test_a_locus_over_the_memory_limit_is_one_line_before_any_progress(capsys, tmp_path,
                                                                         monkeypatch, where):
    # 1004 poles: one point's distance matrices alone are about 92 MiB.  The
    # "tracking ... poles" progress line came before the refusal (two lines).
    monkeypatch.setenv("SYMSTAB_MEMORY_LIMIT", "16M")
    png = tmp_path / "locus.png"
    status, out, err = run(capsys, "locus", *where, "--png", png)
    assert status == 2
    assert err.count("\n") == 1 and err.startswith("symstab locus: error: "), err
    assert "memory limit of 16 MiB" in err and "1004 poles" in err
    assert out == "" and not png.exists()
