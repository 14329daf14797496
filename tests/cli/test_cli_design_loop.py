"""``symstab design --loop``: the search of a third parameter, as ``design`` searches the virtual mass.

Oracles: an independent dense scan of :meth:`symstab.Loop.limits` over the
parameter (nested grids, no golden section: ``oracles.dense_maximum``), and, on the paper's
loop file, ``symstab design`` of the paper's options at the same device
(the optimum M = gamma m).  Bad input is one line and exit status 2 before
the search.
"""

import json
import math
import re

import pytest

import symstab

from conftest import PAPER_DELTA, PAPER_M, PAPER_T, REPO
from conftest import run_cli as run
from conftest import run_cli_json as run_json
from oracles import dense_maximum

LOOPS = REPO / "examples" / "loops"

pytestmark = pytest.mark.usefixtures("loop_cache_dir")


def shared_json(shared_cli_run, *args):
    """``symstab ARGS --format json`` run once per session (a search takes seconds): its output."""
    status, out, err = shared_cli_run(*args, "--format", "json")
    assert status == 0, err
    return json.loads(out)


def dense_scan(loop, name, low, high, **values):
    """The largest y_max over ``name`` in [low, high]: ``oracles.dense_maximum``'s seven
    nested 11-point grids.

    A plane the decomposition does not resolve is skipped (as design skips it).
    """
    def y_max(value):
        try:
            lim = loop.limits(**{**values, name: value})
        except ValueError:
            return -math.inf
        return -math.inf if lim.empty else lim.y_max

    return dense_maximum(y_max, low, high)


@pytest.mark.parametrize("file, extra", [("paper.toml", ["--set", "d=10"]),
                                         ("frictionless.toml", [])])
def test_design_finds_the_best_mass_of_a_dense_scan(shared_cli_run, file, extra):
    out = shared_json(shared_cli_run, "design", "--loop", LOOPS / file, *extra)
    search = out["search"]
    assert search["over"] == "M" and search["nominal"] == 0.0
    loop = symstab.load_loop(LOOPS / file)
    values = {**out["inputs"]["values"]}
    low, high = search["range"]
    at, value = dense_scan(loop, "M", low, high, **values)
    assert search["y_max"] == pytest.approx(value, rel=1e-4)
    assert search["y_max"] >= value * (1 - 1e-6)       # the search is no worse than the scan
    nominal = loop.limits(**values).y_max
    assert search["y_max_nominal"] == pytest.approx(nominal, rel=1e-9)
    assert search["gain"] == pytest.approx(search["y_max"] / nominal, rel=1e-12)
    assert out["limits"]["y_max"] == search["y_max"]


def test_design_of_the_paper_file_is_the_paper_design_at_the_same_device(shared_cli_run):
    """paper.toml at d = 10: the best M is gamma m of ``symstab design --d 10`` and K_max the same.

    (``--delta`` of the paper's device with ``--d 10``: the same search, in Table I's
    variables; the runs are shared with the tests above and test_cli_numeric's.)"""
    loop = shared_json(shared_cli_run, "design", "--loop", LOOPS / "paper.toml", "--set", "d=10")
    paper = shared_json(shared_cli_run, "design", "--delta", str(PAPER_DELTA), "--d", "10")["best"]
    search = loop["search"]
    # design's gamma range times m: the same scan points, the same search.
    assert search["range"] == pytest.approx([PAPER_M * (-1 - 11 * PAPER_DELTA + 1e-3), 3 * PAPER_M],
                                            rel=1e-12)
    assert search["best"] == pytest.approx(paper["gamma"] * PAPER_M, rel=1e-5)
    assert search["y_max"] == pytest.approx(paper["alpha_max"] * PAPER_M / PAPER_T**2, rel=1e-6)
    assert search["gain"] == pytest.approx(paper["gain"], rel=1e-6)


def test_the_table_names_the_optimum_the_value_there_and_at_the_nominal_value(capsys):
    status, out, err = run(capsys, "design", "--loop", LOOPS / "paper.toml", "--set", "d=10",
                           "--set", "M=0.005")
    assert status == 0, err
    assert "searching M in [" in err and "kg m^2" in err
    rows = {line.strip().split("  ")[0]: line for line in out.splitlines() if "  " in line.strip()}
    assert "M (best)" in rows and "kg m^2" in rows["M (best)"]
    assert "K_max" in rows and "N m/rad" in rows["K_max"]
    assert "K_max at M = 0.005" in rows and "gain" in rows


@pytest.mark.parametrize("args, needle", [
    (["--loop", LOOPS / "lowpass_velocity.toml"], "no mass term: give --over NAME=LO:HI"),
    (["--loop", LOOPS / "lowpass_velocity.toml", "--over", "f_c"], "give its range, --over f_c=LO:HI (in Hz)"),
    (["--loop", LOOPS / "paper.toml", "--over", "Q"], "--over Q: not a parameter"),
    (["--loop", LOOPS / "paper.toml", "--over", "d"], "whole number of samples"),
    (["--loop", LOOPS / "paper.toml", "--over", "K"], "axis"),
    (["--loop", LOOPS / "paper.toml", "--range", "1"], "--range must be LO:HI"),
    (["--loop", LOOPS / "paper.toml", "--range", "a:b"], "--range must be LO:HI"),
    (["--loop", LOOPS / "paper.toml", "--range", "0:inf"], "--range must be LO:HI"),
    (["--loop", LOOPS / "paper.toml", "--range=0.02:0.01"], "LO < HI"),
    (["--over", "M"], "--over needs a loop file"),
    (["--range", "0:1"], "--range needs a loop file"),
    (["--loop", LOOPS / "paper.toml", "--over", "M=0:1 s"], "--over M: unit 's' is"),
    (["--loop", LOOPS / "paper.toml", "--over", "M=0:1", "--range", "0:2"], "drop --range"),
    (["--loop", LOOPS / "paper.toml", "--over", "M", "--over", "b", "--range", "0:2"],
     "--range is the range of a single --over"),
    (["--loop", LOOPS / "paper.toml", "--over", "M=0:1", "--over", "M=1:2"], "given twice"),
    (["--loop", LOOPS / "paper.toml", "--over", "M=0:1", "--over", "b=1:2", "--over", "m=1:2"],
     "one or two parameters"),
    (["--maximize", "speed"], "--maximize must be K_max"),
    (["--loop", LOOPS / "paper.toml", "--maximize", "B_max"], "the plane's y is K"),
    (["--points", "2"], "--points must be an integer from 3"),
    # From an attack on the inputs: each ran a search and exited 0, or failed after it.
    (["--loop", LOOPS / "two_mass.toml", "--maximize", "passive"], "passive"),
    (["--loop", LOOPS / "paper.toml", "--over", "T=-1:0"], "--over T"),
    (["--loop", LOOPS / "lowpass_velocity.toml", "--over", "f_c=10:1000 Hz"], "f_c"),
    (["--loop", LOOPS / "lowpass_velocity.toml", "--over", "T=1:20 ms"], "f_c"),
    (["--loop", LOOPS / "paper.toml", "--over", "M=-1e308:1e308"], "HI - LO must be finite"),
    (["--loop", LOOPS / "paper.toml", "--over", "M=0:1", "--over", "b=0.01:1", "--points", "50"],
     "2500 scan points, above 2000"),
    (["--loop", LOOPS / "paper.toml", "--x", "K", "--y", "B", "--maximize", "K_max"],
     "the plane's y is B"),
    (["--gamma", "1"], "--gamma: design searches the virtual mass"),
    (["--loop", LOOPS / "paper.toml", "--x", "B", "--y", "M"], "mass term M is an axis"),
    (["--loop", LOOPS / "frictionless.toml", "--at", "1e300"], "1e+300"),
    (["--loop", LOOPS / "paper.toml", "--over", "T=0.2:4 ms", "--delay", "10 kg"], "--delay"),
    (["--loop", LOOPS / "paper.toml", "--over", "T=0.2:4 ms", "--delay", "10ms", "--d", "3"],
     "drop --d"),
    (["--delay", "10ms"], "--delay needs a loop file"),
    (["--loop", LOOPS / "paper.toml", "--over", "T=0.2:4 ms", "--delay", "10ms", "--set",
      "Td=3ms"], "drop --d / --set d / --set Td"),
    (["--png", "/nonexistent/x.png"], "--png"),
    # The simulated target: its options only with it, with a loop file, checked first.
    (["--loop", LOOPS / "paper.toml", "--amplitude", "1e-3"], "add --maximize simulated"),
    (["--encoder-resolution", "1e-5"], "give --loop"),
    (["--loop", LOOPS / "lowpass_velocity.toml", "--over", "f_c=20:400", "--noise-limit",
      "0.01"], "--noise-limit needs --encoder-resolution"),
    (["--loop", LOOPS / "lowpass_velocity.toml", "--over", "f_c=20:400", "--noise-at", "1",
      "2"], "--noise-at needs --encoder-resolution"),
    (["--loop", LOOPS / "lowpass_velocity.toml", "--over", "f_c=20:400",
      "--encoder-resolution", "1e-5", "--noise-limit", "0.01 N m"],
     "which is in N (its stiffness in N/m)"),
    (["--loop", LOOPS / "lowpass_velocity.toml", "--over", "f_c=20:400",
      "--encoder-resolution", "1e-5", "--noise-limit", "0"], "--noise-limit must be"),
    (["--loop", LOOPS / "lowpass_velocity.toml", "--encoder-resolution", "1e-5",
      "--noise-limit", "0.01", "--over", "f_c=20:400", "--over", "m=0.01:0.02"],
     "searched over one parameter"),
    (["--loop", LOOPS / "lowpass_velocity.toml", "--over", "f_c=20:400",
      "--encoder-resolution", "1e-5", "--noise-at", "1 kg", "2"], "--noise-at B"),
    (["--maximize", "simulated", "--amplitude", "1e-3"], "give --loop FILE"),
    (["--loop", LOOPS / "paper.toml", "--maximize", "simulated"], "needs --amplitude"),
    (["--loop", LOOPS / "paper.toml", "--maximize", "simulated", "--amplitude", "0"],
     "--amplitude"),
    (["--loop", LOOPS / "paper.toml", "--maximize", "simulated", "--amplitude", "1e-3",
      "--paper-encoder"], "--paper-encoder"),
    (["--loop", LOOPS / "paper.toml", "--maximize", "simulated", "--amplitude", "1e-3",
      "--velocity-cutoff", "50"], "--velocity-cutoff"),
    (["--loop", LOOPS / "paper.toml", "--maximize", "simulated", "--amplitude", "1e-3",
      "--steps", "1000000000"], "steps"),
    (["--loop", LOOPS / "paper.toml", "--maximize", "simulated", "--amplitude", "1e-3",
      "--force-limit", "-1"], "--force-limit must be"),
    # From a review: 0 was taken for "not given" and the flag ignored (exit 0); the paper
    # simulator's options were accepted without a loop file and ignored.
    (["--loop", LOOPS / "paper.toml", "--x0", "0", "--points", "3"], "--x0"),
    (["--loop", LOOPS / "paper.toml", "--steps", "0", "--points", "3"], "--steps"),
    (["--loop", LOOPS / "paper.toml", "--amplitude", "0", "--points", "3"], "--amplitude"),
    (["--coulomb", "0.1"], "--coulomb"),
    (["--loop", LOOPS / "paper.toml", "--coulomb", "0.1"], "add --maximize simulated"),
    (["--loop", LOOPS / "actuator_lag.toml", "--maximize", "simulated", "--amplitude", "1e-3",
      "--coulomb", "0.1", "--stiction", "0.05"], "--stiction must be"),
    (["--velocity-cutoff", "50"], "--velocity-cutoff"),
    (["--friction-compensation", "--coulomb", "0.1"], "--friction-compensation"),
])
def test_bad_search_input_is_one_line_before_the_search(capsys, args, needle):
    status, out, err = run(capsys, "design", *args)
    assert status == 2 and out == "", err
    assert err.count("\n") == 1 and needle in err, err
    assert "searching" not in err


def test_a_wide_range_finds_the_narrow_band_of_stable_masses(capsys):
    """actuator_lag over M in [-1, 10] kg: it said "no M in [-1, 10] kg has a stable point"
    while its own table showed K_max at M = 0 (the 17-point scan stepped over the band of
    stable masses, about (-0.013, 0.017) kg).  Now the optimum is the default range's."""
    wide = run_json(capsys, "design", "--loop", LOOPS / "actuator_lag.toml", "--range=-1:10")
    default = run_json(capsys, "design", "--loop", LOOPS / "actuator_lag.toml")
    assert wide["search"]["best"] is not None, wide.get("notes")
    assert wide["search"]["y_max"] == pytest.approx(default["search"]["y_max"], rel=1e-4)
    assert wide["search"]["best"] == pytest.approx(default["search"]["best"], rel=1e-4)


def test_a_delay_held_in_time_is_fractional_samples_of_each_T(capsys):
    """--delay 2ms and --set Td=2ms with --over T both hold the delay in seconds: d = 2 ms / T
    samples at each T (0.70 at the best, where the former ceil took 1).  Oracle: the
    engine's K_max at the best T with the delay given as Td; the table's note says d."""
    common = ["design", "--loop", LOOPS / "two_mass.toml", "--over", "T=2.5:3.2 ms",
              "--points", "5"]
    held = run_json(capsys, *common, "--delay", "2ms")["search"]
    loop = symstab.load_loop(LOOPS / "two_mass.toml")
    best = held["best"]
    assert held["delay"] == pytest.approx(0.002, rel=1e-12)
    assert held["best_d"] == pytest.approx(0.002 / best, rel=1e-12) and held["best_d"] < 1
    assert held["value"] == pytest.approx(loop.limits(T=best, Td=0.002).y_max, rel=1e-9)
    status, out, err = run(capsys, *common, "--set", "Td=2ms")
    assert status == 0, err
    assert f"d = 0.002 s / T samples; at the best T = {best:.6g} s, d = " \
           f"{held['best_d']:.6g}" in out


def test_the_passive_target_holds_a_delay_in_time(capsys):
    """--maximize passive with --delay 1.5ms: d = 1.5 ms / T samples at each T, fractional
    between the whole ones (it was refused).  Oracle: the engine's passive K_max at the best T
    with the delay given as Td, and at a T where the delay is 2.5 samples, below it."""
    held = run_json(capsys, "design", "--loop", LOOPS / "paper.toml", "--over", "T=0.5:1 ms",
                    "--delay", "1.5ms", "--maximize", "passive", "--set", "M=0", "--points",
                    "3")["search"]
    loop = symstab.load_loop(LOOPS / "paper.toml")
    best = held["best"]
    assert held["best_d"] == pytest.approx(0.0015 / best, rel=1e-12)
    assert held["value"] == pytest.approx(loop.passive_region(T=best, Td=0.0015, M=0.0).y_max,
                                          rel=1e-9)
    assert held["value"] > loop.passive_region(T=0.0006, Td=0.0015, M=0.0).y_max


def test_over_takes_a_range_with_a_unit_and_two_parameters(capsys, tmp_path):
    """--over f_c=0.02:0.2 kHz is f_c in [20, 200] Hz; a second --over searches a box; --png
    draws the evaluations; --maximize area is the Z-width."""
    common = ["design", "--loop", LOOPS / "lowpass_velocity.toml", "--set", "d=2"]
    hertz = run_json(capsys, *common, "--over", "f_c=20:200", "--points", "5")
    kilohertz = run_json(capsys, *common, "--over", "f_c=0.02:0.2 kHz", "--points", "5")
    assert kilohertz["search"]["range"] == pytest.approx([20.0, 200.0], rel=1e-12)
    assert kilohertz["search"]["best"] == pytest.approx(hertz["search"]["best"], rel=1e-9)
    png = tmp_path / "design.png"
    loop = symstab.load_loop(LOOPS / "lowpass_velocity.toml")
    status, out, err = run(capsys, *common, "--over", "f_c=20:200", "--over", "b=0.01:0.05",
                           "--points", "3", "--maximize", "area", "--png", png)
    assert status == 0, err
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    rows = {cells[0]: cells[1:] for cells in (re.split(r"\s{2,}", line.strip())
                                              for line in out.splitlines()) if len(cells) > 2}
    assert "f_c (best)" in rows and "b (best)" in rows and "area" in rows
    best_f_c, best_b, area = (float(rows[k][0]) for k in ("f_c (best)", "b (best)", "area"))
    assert loop.limits(d=2, f_c=best_f_c, b=best_b).area == pytest.approx(area, rel=1e-6)


def test_the_simulated_target_names_what_it_simulated(capsys, tmp_path):
    """--maximize simulated: the simulated K_max at the best value with the certified one
    beside it (the simulation accepts less), the runs and the amplitude in a note, a PNG."""
    png = tmp_path / "design.png"
    status, out, err = run(capsys, "design", "--loop", LOOPS / "lowpass_velocity.toml",
                           "--set", "d=2", "--over", "f_c=50:400", "--points", "3",
                           "--maximize", "simulated", "--amplitude", "1e-3", "--steps", "2000",
                           "--encoder-resolution", "1e-5", "--png", png)
    assert status == 0, err
    assert "whose simulated run settles below 0.001" in err
    rows = {line.strip().split("  ")[0]: line.split() for line in out.splitlines()
            if "  " in line.strip()}
    simulated, linear = float(rows["simulated K_max"][2]), float(rows["K_max"][1])
    assert 0.9 * linear < simulated < linear
    assert "encoder quantum 1e-05" in out and "2000 periods per run" in out
    assert "the values searched within 1% of the best are f_c from" in out
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    found = run_json(capsys, "design", "--loop", LOOPS / "lowpass_velocity.toml",
                     "--set", "d=2", "--over", "f_c=50:400", "--points", "3",
                     "--maximize", "simulated", "--amplitude", "1e-3", "--steps", "2000",
                     "--encoder-resolution", "1e-5")
    assert found["search"]["maximize"] == "simulated"
    # The encoder is the simulator's quantizer here: no force noise unless asked for
    # (--noise-limit or --noise-at).
    assert "noise" not in found["search"] and "force noise" not in out
    assert found["search"]["value"] == pytest.approx(simulated, rel=1e-9)
    assert found["search"]["simulated"]["steps"] == 2000
    # With non-idealities the runs start at 0.01, as simulate and map --simulate do, and
    # the library's default is the same start.
    assert found["search"]["simulated"]["x0"] == 0.01
    assert found["search"]["simulated"]["at_top"] is False
    loop = symstab.load_loop(LOOPS / "lowpass_velocity.toml")
    from symstab.numeric.simulation.simulator import Nonidealities

    library = loop.design(over={"f_c": (50.0, 400.0)}, n=3, maximize="simulated",
                          amplitude=1e-3, steps=2000,
                          nonideal=Nonidealities(encoder_resolution=1e-5), d=2)
    assert library.value == pytest.approx(simulated, rel=1e-9)


def test_a_band_of_masses_between_four_scan_points_is_found(capsys):
    """Issue 40, item 1: d = 40 from M = 0.5 over M in [-0.5, 0.5] with 4 points printed
    "no value of M in [-0.5, 0.5] has a stable point" (exit 0), yet M = 0 has K_max 4.959.
    Oracle: the published best virtual mass at T_d = 40 ms (README: gamma about 1.0, gain
    4.14 over K_max at M = 0)."""
    found = run_json(capsys, "design", "--loop", LOOPS / "paper.toml", "--set", "d=40",
                     "--set", "M=0.5", "--over", "M=-0.5:0.5", "--points", "4")
    search = found["search"]
    assert search["best"] is not None, found.get("notes")
    assert search["best"] == pytest.approx(1.0 * PAPER_M, rel=1e-2)
    at_zero = symstab.load_loop(LOOPS / "paper.toml").limits(d=40, M=0.0).y_max
    assert search["y_max"] / at_zero == pytest.approx(4.14, abs=5e-3)


def test_a_noise_budget_in_millinewtons_is_the_library_s_design(capsys, tmp_path):
    """--noise-limit 30mN is 0.03 N of the loop's force (its K is in N/m): the optimum is
    Loop.design's with that budget, the table says the budget binds and lists the Pareto
    front, the JSON carries it, and --png draws the front beside the search."""
    loop = symstab.load_loop(LOOPS / "lowpass_velocity.toml")
    q = 2 * math.pi / 16384
    args = ["design", "--loop", LOOPS / "lowpass_velocity.toml", "--set", "d=5",
            "--over", "f_c=20:450", "--points", "9", "--encoder-resolution", str(q),
            "--noise-at", "500 mN s/m", "5", "--noise-limit"]
    out = run_json(capsys, *args, "30mN", "--png", tmp_path / "budget.png")
    found = loop.design(over={"f_c": (20.0, 450.0)}, encoder_resolution=q, noise_limit=0.03,
                        noise_at={"B": 0.5, "K": 5.0}, n=9, d=5)
    noise = out["search"]["noise"]
    assert noise["noise_limit"] == 0.03 and noise["at"] == {"B": 0.5, "K": 5.0}
    assert out["search"]["best"] == found.best["f_c"] and noise["best"] == found.best_noise
    assert noise["binds"] is True
    assert [[row["f_c"], row["target"], row["noise"]] for row in noise["pareto"]] == \
        found.pareto.tolist()
    assert (tmp_path / "budget.png").stat().st_size > 0
    status, text, _ = run(capsys, *args, "0.03")
    assert status == 0
    assert re.search(r"force noise at the best +0\.0\d+ +N ", text), text
    assert "the noise budget binds: at the best value the force noise reaches 0.03 N" in text
    assert re.search(r"f_c \[Hz\] +K_max +force noise \[N\]\n", text), text
