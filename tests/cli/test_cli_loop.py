"""``--loop FILE`` and ``--set NAME=VALUE`` on boundary, limits, classify, design and map.

The paper's loop file (``examples/loops/paper.toml``, rotary units: kg m^2,
N m s/rad, N m/rad, as the paper's device options) must give the numbers of
today's paper commands (converted from alpha, beta by K_w = alpha m / T^2 and
B_w = beta m / T); the boundary is checked against the derivation's
alpha(theta), beta(theta) at 30 digits and the root counts against
python-control's poles.  Bad input is one line ``symstab <cmd>: error:`` and
exit status 2 with nothing written; an interrupted map leaves no file.
"""

import math

import numpy as np
import pytest

import symstab
from symstab.cli import commands as cli

from conftest import PAPER_DELTA, PAPER_M, PAPER_T, REPO
from conftest import run_cli as run
from conftest import run_cli_json as run_json
from oracles import python_control_closed_loop

PAPER = str(REPO / "examples" / "loops" / "paper.toml")


pytestmark = pytest.mark.usefixtures("loop_cache_dir")


def stiffness(alpha):
    return alpha * PAPER_M / PAPER_T**2


def damping(beta):
    return beta * PAPER_M / PAPER_T


# --------------------------------------------------------------------------
# The paper's loop file gives today's numbers


def test_limits_of_the_paper_file_are_todays_K_max(capsys):
    """K_max at Td = 40 ms (the file's d = 40) as `symstab limits --Td 40e-3 --linear`."""
    loop = run_json(capsys, "limits", "--loop", PAPER)
    paper = run_json(capsys, "limits", "--Td", "40e-3", "--linear")["limits"]
    lim = loop["limits"]
    assert (lim["x"], lim["y"]) == ("B", "K")
    assert loop["inputs"]["values"]["d"] == 40 and loop["inputs"]["units"]["K"] == "N m/rad"
    assert lim["y_max"] == pytest.approx(stiffness(paper["alpha_max"]), rel=1e-6)
    assert lim["x_at_y_max"] == pytest.approx(damping(paper["beta_at_alpha_max"]), rel=1e-6)
    assert lim["x_max"] == pytest.approx(damping(paper["beta_right"]), rel=1e-6)
    # Loop.limits brackets the left tip (a cusp at K = 0, B = -b) by the
    # existence of a stable K on a line, and integrates the area with the
    # trapezoid rule on 201 lines: they agree to 3.3e-5 and 2.9e-5 only
    # (measured), hence the looser tolerance.
    assert lim["x_min"] == pytest.approx(damping(paper["beta_left"]), rel=1e-4)
    area = paper["z_width"] * (PAPER_M / PAPER_T) * (PAPER_M / PAPER_T**2)
    assert lim["area"] == pytest.approx(area, rel=1e-4)


def test_limits_text_names_the_units_of_the_file(capsys):
    status, out, _ = run(capsys, "limits", "--loop", PAPER, "--d", "10", "--at", "0.3")
    assert status == 0
    assert "d = 10 samples (--set)" in out and "plane: x = B [N m s/rad], y = K [N m/rad]" in out
    line = next(line for line in out.splitlines() if line.strip().startswith("K_max"))
    k_max = stiffness(symstab.limits(gamma=0.0, d=10, delta=PAPER_DELTA).alpha_max)
    assert float(line.split()[1]) == pytest.approx(k_max, rel=1e-6) and "N m/rad" in line
    # Open at both ends: each end has a pole on the unit circle.
    assert "stable K at B = 0.3 N m s/rad: (0, " in out


def test_classify_gives_todays_radius_and_python_controls_pole_count(capsys):
    kw, bw = [1.0, 3.0, 10.0, 40.0], [0.2, 0.2, 0.2, 0.05]
    loop = run_json(capsys, "classify", "--loop", PAPER, "--set", "d=10",
                    "--set", "K=" + ",".join(map(str, kw)), "--set", "B=" + ",".join(map(str, bw)))
    paper = run_json(capsys, "classify", "--Td", "0.01", "--linear",
                     "--Kw", ",".join(map(str, kw)), "--Bw", ",".join(map(str, bw)))
    assert len(loop["rows"]) == 4
    verdicts = set()
    for row, today, k, b in zip(loop["rows"], paper["rows"], kw, bw, strict=True):
        assert (row["K [N m/rad]"], row["B [N m s/rad]"]) == (k, b)
        assert row["spectral radius"] == pytest.approx(today["spectral radius"], rel=1e-6)
        assert row["verdict"] == today["verdict"]
        poles = python_control_closed_loop(alpha=k * PAPER_T**2 / PAPER_M,
                                           beta=b * PAPER_T / PAPER_M, gamma=0.0, d=10,
                                           delta=PAPER_DELTA, m=PAPER_M, T=PAPER_T).poles()
        assert row["unstable poles"] == int(np.sum(np.abs(poles) > 1))
        verdicts.add(row["verdict"])
    assert verdicts == {"stable", "unstable"}


def test_classify_one_point_echoes_every_value_with_its_unit(capsys):
    status, out, _ = run(capsys, "classify", "--loop", PAPER, "--set", "K=300", "--d", "0")
    assert status == 0
    assert "K = 300 N m/rad (--set)" in out and "m = 0.0128 kg m^2" in out and "d = 0 samples" in out
    radius = symstab.spectral_radius(alpha=300 * PAPER_T**2 / PAPER_M, beta=0.1 * PAPER_T / PAPER_M,
                                     gamma=0.0, d=0, delta=PAPER_DELTA)
    row = out.split("\n\n")[1].splitlines()[2].split()
    assert float(row[0]) == 300.0 and float(row[1]) == pytest.approx(radius, rel=1e-6)
    assert row[-1] == ("stable" if radius < 1 else "unstable")


def test_a_marginal_verdict_gives_no_pole_count(capsys):
    """K = 0: a pole at z = 1 exactly; the verdict is marginal and no count is printed beside it."""
    (row,) = run_json(capsys, "classify", "--loop", PAPER, "--set", "K=0")["rows"]
    assert row["verdict"] == "marginal" and row["unstable poles"] is None


def test_a_huge_stiffness_is_decided_not_lost_in_rounding(capsys):
    """K = 1e300: the delayed part's leading 1 is exact against its own part (chi kept structured).

    The dense polynomial called it a pole at infinity (marginal); the
    structured count gives 41 poles outside, which the argument principle
    at 60 digits on the same coefficients confirms (60-digit roots by
    mpmath.polyroots agree, in 80 s).
    """
    from oracles import roots_outside_unit_circle_mp

    (row,) = run_json(capsys, "classify", "--loop", PAPER, "--set", "K=1e300")["rows"]
    loop = symstab.load_loop(PAPER)
    coefficients = loop.coefficients(K=1e300)
    assert row["verdict"] == "unstable"
    # n=8192: the grid the oracle's own doubling reaches from 1024 on these
    # coefficients (the phase of chi turns fast near its roots); starting
    # there spares the three coarser passes it would refuse.
    assert row["unstable poles"] == roots_outside_unit_circle_mp(
        [float(c) for c in coefficients], n=8192) == 41


def test_boundary_lies_on_the_derived_curve_and_names_its_lines(capsys):
    from symstab.numeric.paper.curves import minus_one_line
    from symstab.numeric.paper.reference import boundary_point

    data = run_json(capsys, "boundary", "--loop", PAPER, "--set", "d=10", "--n", "40")
    rows = data["rows"]
    assert len(rows) == 40
    checked = 0
    for row in rows:
        theta, b, k = row["theta [rad]"], row["B [N m s/rad]"], row["K [N m/rad]"]
        if b is None:
            continue
        alpha, beta = boundary_point(theta, gamma=0.0, d=10, delta=PAPER_DELTA)
        assert k == pytest.approx(stiffness(float(alpha)), rel=1e-6)
        assert b == pytest.approx(damping(float(beta)), rel=1e-6)
        checked += 1
    assert checked >= 38
    lines = data["lines"]
    # z = 1: K = 0 (a pole at z = 1 whenever the spring is off).
    one = lines["z = 1"]
    assert one["cx"] == 0 and abs(one["c0"] / one["cy"]) < 1e-9
    # z = -1: alpha + 2 beta = c of the derivation, in N m/rad and N m s/rad.
    c0, cx, cy = (lines["z = -1"][k] for k in ("c0", "cx", "cy"))
    # alpha + 2 beta = c is K + (2 / T) B = c m / T**2.
    assert cx / cy == pytest.approx(2 / PAPER_T, rel=1e-9)
    c = minus_one_line(gamma=0.0, d=10, delta=PAPER_DELTA)
    assert -c0 / cy == pytest.approx(stiffness(c), rel=1e-6)
    assert any(n.startswith("line z = -1: ") and n.endswith(" B") for n in data["notes"])
    # The piece of K = 0 that closes the stable set: from the arc's start at
    # beta = -delta (B = -b) to where the first-principles arc returns to alpha = 0.
    from oracles import first_principles_boundary_point, first_principles_theta_max

    (segment,) = data["segments"]
    assert segment["root"] == "z=1" and segment["K0"] == segment["K1"] == 0
    assert segment["B0"] == pytest.approx(damping(-PAPER_DELTA), rel=1e-12)
    theta_max = first_principles_theta_max(0.0, 10, PAPER_DELTA)
    beta_end = first_principles_boundary_point(theta_max, 0.0, 10, PAPER_DELTA)[1]
    assert segment["B1"] == pytest.approx(damping(float(beta_end)), rel=1e-9)
    assert any(n.startswith("boundary segment (z=1): (B [N m s/rad], K [N m/rad]) from ")
               for n in data["notes"])


def test_map_is_todays_root_count_classification(capsys, tmp_path):
    grid_k, grid_b = "0,2500,9", "-2,12,8"
    out = tmp_path / "loop.npz"
    status, text, err = run(capsys, "map", "--loop", PAPER, "--set", "d=1", f"--x-range={grid_b}",
                            f"--y-range={grid_k}", "--out", out, "--no-png")
    assert status == 0, err
    assert "wrote " + str(out) in text
    # It counts roots where map of the paper's loop simulates: its first line says so.
    assert text.splitlines()[0] == ("map --loop: root counts of the linear loop (add --simulate "
                                    "to simulate every cell)")
    paper = tmp_path / "paper.npz"
    status, simulated, err = run(capsys, "map", "--d", "1", "--linear", f"--Kw={grid_k}",
                                 f"--Bw={grid_b}", "--steps", "20", "--out", paper, "--no-png")
    assert status == 0, err
    assert "root counts" not in simulated.splitlines()[0]
    with np.load(out) as f, np.load(paper) as g:
        assert (str(f["x_name"]), str(f["y_name"]), str(f["y_unit"])) == ("B", "K", "N m/rad")
        np.testing.assert_array_equal(f["x"], g["B_w"])
        np.testing.assert_array_equal(f["y"], g["K_w"])
        code, today = f["code"], g["exact_code"].T   # today's map is (K_w, B_w)
        stable = f["stable"]
    decided = (code != symstab.MARGINAL) & (today != symstab.MARGINAL)
    assert decided.sum() >= 60 and 0 < stable.sum() < stable.size
    np.testing.assert_array_equal(code[decided], today[decided])
    np.testing.assert_array_equal(stable, code == symstab.STABLE)


def test_map_csv_and_png_in_the_units_of_the_file(capsys, tmp_path, monkeypatch):
    from matplotlib.figure import Figure

    seen, savefig = [], Figure.savefig

    def record(fig, *args, **kwargs):
        ax = fig.axes[0]
        seen.append((ax.get_xlabel(), ax.get_ylabel(), ax.get_xlim(), ax.get_ylim(),
                     [t.get_text() for t in ax.get_legend().get_texts()]))
        return savefig(fig, *args, **kwargs)

    monkeypatch.setattr(Figure, "savefig", record)
    out = tmp_path / "m.csv"
    status, _, err = run(capsys, "map", "--loop", PAPER, "--d", "1", "--x-range=-2,12,5",
                         "--y-range=0,2500,4", "--out", out)
    assert status == 0, err
    lines = out.read_text().splitlines()
    assert lines[0] == "B [N m s/rad],K [N m/rad],code,stable" and len(lines) == 21
    rows = np.array([[float(v) for v in line.split(",")] for line in lines[1:]])
    code = symstab.classify(alpha=rows[:, 1] * PAPER_T**2 / PAPER_M,
                            beta=rows[:, 0] * PAPER_T / PAPER_M, gamma=0.0, d=1, delta=PAPER_DELTA)
    decided = (code != symstab.MARGINAL) & (rows[:, 2] != symstab.MARGINAL)
    np.testing.assert_array_equal(rows[decided, 2], code[decided])
    assert (tmp_path / "m.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    (xlabel, ylabel, xlim, ylim, legend), = seen
    assert (xlabel, ylabel) == ("B [N m s/rad]", "K [N m/rad]")
    assert xlim == pytest.approx((-2, 12)) and ylim == pytest.approx((0, 2500))
    assert "stable" in legend and any("D-decomposition" in t for t in legend)


def test_map_files_are_the_same_bytes_run_to_run(capsys, tmp_path):
    for name in ("a", "b"):
        status, _, err = run(capsys, "map", "--loop", PAPER, "--d", "1", "--x-range=-2,12,5",
                             "--y-range=0,2500,4", "--out", tmp_path / f"{name}.npz")
        assert status == 0, err
    for suffix in (".npz", ".png"):
        assert (tmp_path / f"a{suffix}").read_bytes() == (tmp_path / f"b{suffix}").read_bytes()


# --------------------------------------------------------------------------
# Written atomically: an interrupted map leaves nothing behind


def test_map_interrupted_while_classifying_writes_nothing(capsys, tmp_path, monkeypatch):
    from symstab.numeric.loop.sampled_loop import Loop

    def interrupted(self, **values):
        raise KeyboardInterrupt

    monkeypatch.setattr(Loop, "classify", interrupted)
    monkeypatch.chdir(tmp_path)
    status, _, err = run(capsys, "map", "--loop", PAPER, "--d", "1", "--x-range=0,1,3",
                         "--y-range=0,1,3", "--out", "m.npz")
    assert status == 130 and err.strip().splitlines()[-1] == "symstab map: interrupted"
    assert list(tmp_path.iterdir()) == []


def test_map_interrupted_while_writing_leaves_no_partial_file(capsys, tmp_path, monkeypatch):
    from symstab import _io

    def interrupted(path, mode):
        raise KeyboardInterrupt   # after the bytes are in the temporary file

    monkeypatch.setattr(_io.os, "chmod", interrupted)
    monkeypatch.chdir(tmp_path)
    status, _, err = run(capsys, "map", "--loop", PAPER, "--d", "1", "--x-range=0,1,3",
                         "--y-range=0,1,3", "--out", "m.csv", "--no-png")
    assert status == 130, err
    assert list(tmp_path.iterdir()) == []


# --------------------------------------------------------------------------
# Bad input: one line, exit 2, decided before the work, nothing written


L = ["--loop", PAPER]
MAP = ["--x-range=0,1,3", "--y-range=0,1,3", "--out", "m.npz"]


@pytest.mark.parametrize("args, needle", [
    (["limits", *L, "--Td", "0.04"], "--Td is an option of the paper's device; with --loop use --set Td=... (the delay in time"),
    (["limits", *L, "--gamma", "1"], "--set M="),
    (["limits", *L, "--m", "0.1"], "--set m="),
    (["limits", *L, "--linear"], "units of the loop file"),
    (["limits", *L, "--Bw", "0.1"], "--at X"),
    (["classify", *L, "--Kw", "1"], "--set K="),
    (["classify", *L, "--alpha", "1"], "--set K="),
    (["map", *L, "--Kw=0,1,3", *MAP], "--x-range"),
    (["map", *L, "--paper-encoder", *MAP], "simulation"),
    (["map", *L, "--steps", "100", *MAP], "simulation"),
    (["limits", *L, "--set", "K300"], "NAME=VALUE"),
    (["limits", *L, "--set", "=3"], "NAME=VALUE"),
    (["limits", *L, "--set", "Q=1"], "'Q' is not a parameter"),
    (["limits", *L, "--set", "m=abc"], "'abc' is not a number"),
    (["limits", *L, "--set", "m="], "must be a number"),
    (["limits", *L, "--set", "m=nan"], "finite"),
    (["limits", *L, "--set", "m=inf"], "finite"),
    (["limits", *L, "--set", "d=2.5 s"], "the delay d is a number of samples"),
    (["limits", *L, "--set", "d=-1"], "delay d"),
    (["limits", *L, "--set", "T=-1"], "T must be"),
    (["limits", *L, "--set", "T=0"], "T must be"),
    # The file bounds m above 0 (a zero mass made the plant's transfer function undefined).
    (["limits", *L, "--set", "m=0"], "m must be a finite real number > 0"),
    # Was "Array must not contain infs or NaNs" from the eigenvalues, after the work began.
    (["classify", *L, "--set", "T=1e300"], "overflows or underflows at"),
    # linspace of -1e308..1e308 is NaN: the grid, not K, is what is wrong.
    (["map", *L, "--x-range=0,1,10", "--y-range=-1e308,1e308,20", "--out", "m.npz"], "--y-range"),
    (["limits", *L, "--set", "T=1e300"], "T = 1e+300"),
    (["limits", *L, "--set", "m=1", "--set", "m=2"], "twice"),
    (["limits", *L, "--set", "d=1", "--d", "2"], "once"),
    (["limits", *L, "--set", "M=1,2"], "one value here"),
    (["limits", *L, "--set", "K=3"], "axis"),
    (["design", *L, "--set", "B=0.3"], "--at"),
    (["limits", *L, "--x", "B"], "--x NAME and --y NAME"),
    (["limits", *L, "--x", "Q", "--y", "K"], "--x Q"),
    (["limits", *L, "--x", "m", "--y", "K"], "affinely"),
    (["limits", *L, "--x", "K", "--y", "K"], "differ"),
    (["limits", *L, "--at", "nan"], "--at"),
    (["boundary", *L, "--n", "1"], "n must be"),
    (["classify", *L, "--set", "K=1,2", "--set", "B=1,2,3"], "same length"),
    (["classify", *L, "--set", "K=1,,2"], "empty"),
    (["classify", *L, "--set", "d=1,2"], "d takes one value"),
    (["map", *L, "--x-range=0,1,3", "--out", "m.npz"], "--y-range"),
    (["map", *L, "--x-range=0,1", "--y-range=0,1,3", "--out", "m.npz"], "--x-range"),
    (["map", *L, "--x-range=0,1,3", "--y-range=0,1,3", "--out", "m.txt"], "--out"),
    (["map", *L, *MAP, "--png", "missing/m.png"], "folder"),
    (["limits", "--set", "K=1"], "--set needs a loop file"),
    (["boundary", "--x", "B"], "--x needs a loop file"),
    (["map", "--alpha=0,1,3", "--beta=0,1,3", "--x-range=0,1,3", "--out", "m.npz"],
     "--x-range needs a loop file"),
    (["limits", "--loop", "missing.toml"], "missing.toml"),
])
def test_bad_input_is_one_line_and_exit_2(capsys, tmp_path, monkeypatch, args, needle):
    monkeypatch.chdir(tmp_path)
    status, out, err = run(capsys, *args)
    assert status == 2, err
    lines = err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith(f"symstab {args[0]}: error:"), err
    assert needle in lines[0], lines[0]
    assert "Traceback" not in err and out == ""
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize("text, needle", [
    ("plant = [", "not valid TOML"),
    ('plant = "1/(m*s**2 + b*s)"\nenvironment = "K*z**3"\n', "proper"),
    ('plant = "1/(m*s**2 + b*s)"\nenvironment = "K + B*(z - 1)/(T*z)"\nplane = ["B", "K"]\n'
     '[parameters]\nm = 1.0\nb = 0.1\nT = 1e-3\n', "no value for d"),
])
def test_a_bad_loop_file_is_one_line_naming_the_file(capsys, tmp_path, monkeypatch, text, needle):
    path = tmp_path / "in" / "bad.toml"
    path.parent.mkdir()
    path.write_text(text)
    work = tmp_path / "work"
    work.mkdir()
    monkeypatch.chdir(work)
    status, out, err = run(capsys, "limits", "--loop", path)
    assert status == 2 and out == ""
    (line,) = err.strip().splitlines()
    assert line.startswith("symstab limits: error:") and needle in line and "bad.toml" in line
    assert list(work.iterdir()) == []


def test_a_file_without_a_plane_asks_for_one(capsys, tmp_path):
    path = tmp_path / "noplane.toml"
    path.write_text('plant = "1/(m*s**2 + b*s)"\nenvironment = "K + B*(z - 1)/(T*z)"\n'
                    '[parameters]\nm = 0.0128\nb = 0.0324\nT = 1e-3\nd = 1\n')
    status, _, err = run(capsys, "limits", "--loop", path)
    assert status == 2 and "names no plane: give --x NAME --y NAME" in err
    assert "affine parameters: B, K" in err
    data = run_json(capsys, "limits", "--loop", path, "--x", "B", "--y", "K")
    k_max = stiffness(symstab.limits(gamma=0.0, d=1, delta=PAPER_DELTA).alpha_max)
    assert data["limits"]["y_max"] == pytest.approx(k_max, rel=1e-6)


def test_without_loop_the_paper_commands_are_unchanged(capsys):
    """No --loop: the output has no loop keys and today's inputs."""
    data = run_json(capsys, "limits", "--d", "1")
    assert "alpha_max" in data["limits"] and "loop" not in data["inputs"]
    assert math.isclose(data["inputs"]["delta"], PAPER_DELTA)


@pytest.mark.parametrize("command", ["boundary", "limits", "classify", "design", "map"])
def test_help_shows_a_loop_example_that_parses(capsys, command):
    import shlex

    status, out, _ = run(capsys, command, "--help")
    assert status == 0
    (line,) = [line for line in out.splitlines() if line.startswith(f"  example: symstab {command} ")]
    words = shlex.split(line.split("example:")[1])
    args = cli.build_parser().parse_args(words[1:])
    assert args.command == command and args.loop == "examples/loops/paper.toml"
    assert (REPO / args.loop).is_file()


def test_the_map_help_example_frames_the_stable_set(capsys, tmp_path, monkeypatch):
    import shlex

    _, out, _ = run(capsys, "map", "--help")
    (line,) = [line for line in out.splitlines() if line.startswith("  example: symstab map ")]
    words = shlex.split(line.split("example:")[1])[1:]
    words[words.index("--out") + 1] = str(tmp_path / "map.npz")
    monkeypatch.chdir(REPO)
    status, _, err = run(capsys, *words, "--no-png")
    assert status == 0, err
    with np.load(tmp_path / "map.npz") as f:
        assert 0.3 < f["stable"].mean() < 0.8
        stable = f["stable"]
        # The stable set does not touch the window's left, right or top edge.
        assert not stable[0].any() and not stable[-1].any() and not stable[:, -1].any()


def test_limits_says_why_a_stable_set_is_empty(capsys):
    """M = 2m is beyond |gamma| >= 2.0034, where no point is stable (proved): the CLI says why."""
    status, out, _ = run(capsys, "limits", "--loop", PAPER,
                             "--set", "M=0.0256", "--d", 40)
    assert status == 0
    note = next(line for line in out.splitlines()
                if line.startswith("the stable set of the (B, K) plane is empty"))
    assert "necessary condition" in note and "no point is stable" in note


# --------------------------------------------------------------------------
# A plant that is not a physical device's (issue 40 item 8)


@pytest.mark.parametrize("command", ["classify", "limits"])
def test_a_negative_mass_is_refused_by_the_example_files_bounds(capsys, command):
    """m = -0.2 gave exit 0, K_max -4.5e-67 and a stable area of 70506; paper.toml bounds m above 0."""
    status, out, err = run(capsys, command, "--loop", PAPER, "--set", "m=-0.2")
    assert status == 2 and out == "" and err.count("\n") == 1, err
    assert err.startswith(f"symstab {command}: error: --set m=...: m must be a finite real "
                          f"number > 0, got -0.2 kg m^2")


def test_every_example_file_bounds_its_physical_parameters():
    """m, b and the operator's, the lag's and the two masses' parameters: min or above 0."""
    physical = {"m", "b", "m_h", "b_h", "k_h", "tau", "m1", "m2", "b1", "k_t", "c_t"}
    for path in sorted((REPO / "examples" / "loops").glob("*.toml")):
        loop = symstab.load_loop(path)
        bounded = {b.name for b in loop.file_parameters.bounds if b.kind in ("min", "above")
                   and not b.expression.free_symbols and float(b.expression) == 0}
        assert physical & set(loop.parameters) <= bounded, path.name


@pytest.mark.parametrize("command", ["classify", "limits"])
def test_a_non_physical_plant_without_bounds_is_one_warning_line(capsys, tmp_path, command):
    """Without the bound the loop is analysed as given, with one line naming the values.

    The oracle: python-control's poles of 1/(m s^2 + b s) at m = -0.2 hold one at
    b/0.2 = 0.162 > 0."""
    control = pytest.importorskip("control")
    poles = control.tf([1.0], [-0.2, 0.0324, 0.0]).poles()
    assert max(poles.real) == pytest.approx(0.162, rel=1e-12)
    path = tmp_path / "unbounded.toml"
    path.write_text(open(PAPER, encoding="utf-8").read().replace(", above = 0", "")
                    .replace(", min = 0", ""), encoding="utf-8")
    status, out, err = run(capsys, command, "--loop", path, "--set", "m=-0.2")
    assert status == 0 and out
    assert err.count("\n") == 1, err
    assert err.startswith(f"symstab {command}: warning: the plant G(s) = 1/(b*s + m*s**2) at "
                          f"b = 0.0324, m = -0.2 has a pole in the open right half plane "
                          f"(s = 0.162) and a negative high-frequency gain")
    status, out, err = run(capsys, command, "--loop", path)
    assert status == 0 and err == ""
