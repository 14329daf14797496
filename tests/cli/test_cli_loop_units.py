"""``--loop`` with units: ``--set`` converted like the file's values, bounds checked, echo as used.

The oracle of each conversion is the same command with the value written in
SI.  Every test here failed before the conversion (the unit was a label,
``--set`` took its number as SI, a bound was not a key a loop file could
have, ``--linear`` was refused without saying why).
"""

import math
import re

import pytest

import symstab

from conftest import REPO, manual_text
from conftest import run_cli as run
from conftest import run_cli_json as run_json

pytestmark = pytest.mark.usefixtures("loop_cache_dir")

PAPER = REPO / "examples" / "loops" / "paper.toml"
LOWPASS = str(REPO / "examples" / "loops" / "lowpass_velocity.toml")


@pytest.fixture
def paper_ms(tmp_path):
    """The paper's loop file with T written as 1 ms."""
    text = PAPER.read_text(encoding="utf-8")
    old = 'T = { value = 1e-3, unit = "s" }'
    assert old in text
    path = tmp_path / "paper_ms.toml"
    path.write_text(text.replace(old, 'T = { value = 1, unit = "ms" }'), encoding="utf-8")
    return str(path)


def _radius(capsys, *args):
    out = run_json(capsys, "classify", *args)
    return [row["spectral radius"] for row in out["rows"]], out


def test_set_is_in_the_files_unit(capsys, paper_ms):
    """--set T=0.5 in a file that gives T in ms is 0.5 ms, as --set T=5e-4 is in the SI file."""
    ours, out = _radius(capsys, "--loop", paper_ms, "--set", "T=0.5", "--set", "K=1,3,10",
                        "--set", "d=4")
    reference, _ = _radius(capsys, "--loop", PAPER, "--set", "T=5e-4", "--set", "K=1,3,10",
                           "--set", "d=4")
    assert ours == pytest.approx(reference, rel=1e-12)
    assert out["inputs"]["values"]["T"] == 5e-4 and out["inputs"]["units"]["T"] == "s"
    assert out["inputs"]["as_written"]["T"] == {"value": 0.5, "unit": "ms"}


@pytest.mark.parametrize("given, si", [
    (["--set", "T=0.5ms"], ["--set", "T=5e-4"]),
    (["--set", "T=500 us"], ["--set", "T=5e-4"]),
    (["--set", "K=1,3,10 kN m/rad"], ["--set", "K=1000,3000,10000"]),
    (["--set", "B=20 N mm s/rad"], ["--set", "B=0.02"]),
    (["--set", "M=64 kg cm^2"], ["--set", "M=0.0064"]),
])
def test_set_with_a_unit_is_converted(capsys, given, si):
    base = ["--loop", PAPER, "--set", "d=4"]
    base_k = [] if any(a.startswith("K=") for a in given) else ["--set", "K=1,3"]
    ours, _ = _radius(capsys, *base, *base_k, *given)
    reference, _ = _radius(capsys, *base, *base_k, *si)
    assert ours == pytest.approx(reference, rel=1e-12)


def test_the_echo_shows_the_value_as_written_and_as_used(capsys, paper_ms):
    status, out, err = run(capsys, "classify", "--loop", paper_ms, "--set", "K=2,3",
                           "--set", "B=0.3 kN mm s/rad")
    assert status == 0, err
    values = next(line for line in out.splitlines() if line.startswith("values: "))
    assert "T = 1 ms (0.001 s)" in values
    assert "B = 0.3 kN mm s/rad (0.3 N m s/rad) (--set)" in values
    assert "K = [2, 3] N m/rad (--set)" in values      # already in SI: shown once


@pytest.mark.parametrize("setting, match", [
    ("T=3kg", r"--set T: parameter 'T' has unit 'kg'.*a time"),
    ("K=3 kg", r"--set K: unit 'kg' is kg, and K is in N m/rad"),
    ("K=3 furlongs_per_parsec", r"--set K: parameter 'K': unit 'furlongs_per_parsec' is not a unit "
                                r"a loop file may name"),
    ("d=4 ms", r"--set d: parameter 'd' has unit 'ms'"),
])
def test_set_with_a_unit_of_the_wrong_dimension_is_refused_in_one_line(capsys, setting, match):
    status, out, err = run(capsys, "classify", "--loop", PAPER, "--set", setting)
    assert status == 2 and out == ""
    assert err.count("\n") == 1 and re.search(match, err), err


@pytest.mark.parametrize("cut_off", ["f_c=3000", "f_c=3kHz"])
def test_a_cut_off_above_nyquist_is_refused_like_the_simulators(capsys, tmp_path, cut_off):
    """The file's bound below = "1/(2*T)": --set f_c=3000 at T = 0.25 ms, as map --velocity-cutoff 3000."""
    out_file = tmp_path / "map.npz"
    status, out, err = run(capsys, "map", "--loop", LOWPASS, "--set", "T=0.25ms", "--set", cut_off,
                           "--x-range=0,1,3", "--y-range=0,1,3", "--out", out_file)
    assert status == 2 and out == "" and not out_file.exists()
    assert err.count("\n") == 1 and err.startswith("symstab map: error: --set T=..., --set f_c=...: ")
    status, _, simulator = run(capsys, "map", "--velocity-cutoff", "3000", "--T", "0.00025",
                               "--out", tmp_path / "paper.npz")
    assert status == 2
    wording = simulator.strip().split(" must be ", 1)[1]   # "a finite real number > 0 and < 2000, got 3000.0"
    assert f"f_c must be {wording} Hz" in err


def test_a_cut_off_below_nyquist_is_accepted(capsys):
    out = run_json(capsys, "classify", "--loop", LOWPASS, "--set", "T=0.25ms", "--set", "f_c=1999",
                   "--set", "d=1")
    assert out["inputs"]["values"]["f_c"] == 1999.0


def test_linear_with_a_loop_is_refused_saying_why(capsys):
    status, out, err = run(capsys, "limits", "--loop", PAPER, "--linear")
    assert status == 2 and err.count("\n") == 1
    assert "rotary by default" in err and "units of the loop file" in err and "drop --linear" in err


def test_the_help_says_what_set_does_with_units(capsys):
    status, out, _ = run(capsys, "classify", "--help")
    assert status == 0
    text = " ".join(out.split())
    assert "in the unit the file gives NAME" in text and "--set T=0.5ms" in text
    assert "checked against the file's bounds" in text


def test_locus_takes_its_set_and_its_path_in_the_files_units(capsys, tmp_path):
    """K in kN m/rad: --set K=0:0.03 is the SI file's K = 0:30 N m/rad, and T = 1 ms is 0.001 s."""
    text = PAPER.read_text(encoding="utf-8")
    for old, new in (('T = { value = 1e-3, unit = "s" }', 'T = { value = 1, unit = "ms" }'),
                     ('K = { value = 2.0, unit = "N m/rad" }', 'K = { value = 2.0, unit = "kN m/rad" }')):
        assert old in text
        text = text.replace(old, new)
    path = tmp_path / "paper_mm.toml"
    path.write_text(text, encoding="utf-8")
    status, ours, err = run(capsys, "locus", "--loop", path, "--set", "B=100 N mm s/rad", "--set",
                            "K=0:0.03:50", "--set", "d=4")
    assert status == 0, err
    status, reference, err = run(capsys, "locus", "--loop", PAPER, "--set", "B=0.1", "--set",
                                 "K=0:30:50", "--set", "d=4")
    assert status == 0, err
    assert "path: K from 0 to 30 N m/rad (50 points)" in ours
    assert ours.split("\npath: ", 1)[1] == reference.split("\npath: ", 1)[1]


def test_one_rule_for_the_units_of_the_device_options_in_the_help_and_the_readme(capsys):
    """--m 0.2 echoed kg m^2 while the README called the device's K N/m: the rule is stated once (the manual's command-line page)."""
    from symstab.cli.options import UNITS_RULE

    status, out, _ = run(capsys, "limits", "--help")
    assert status == 0 and " ".join(UNITS_RULE.split()) in " ".join(out.split())
    readme = " ".join(manual_text().replace("`", "").split())
    assert ("The device options are rotary by default, as the paper's device is a paddle "
            "(m and M_w in kg m², b and B_w in N m s/rad, K_w in N m/rad); --linear reads and "
            "prints the same numbers as a sliding mass's (kg, N s/m, N/m)") in readme
    assert "--linear does not apply to it and is refused with --loop" in readme
    status, out, _ = run(capsys, "limits", "--m", "0.2", "--format", "table")
    assert status == 0 and "m = 0.2 kg m^2" in out and "N m/rad" in out
    status, out, _ = run(capsys, "limits", "--m", "0.2", "--linear")
    assert status == 0 and "m = 0.2 kg," in out and "N m/rad" not in out and "N/m" in out


def test_the_paper_loop_file_and_the_device_options_label_the_same_quantities_alike(capsys):
    """The same device, given as paper.toml or by the paper's options: the same units and numbers.

    K_max printed N/m from paper.toml and N m/rad from ``symstab limits``;
    the file now gives the paddle's rotary units (Section IV), as
    :data:`symstab.PAPER_LOOP` does.
    """
    status, loop, err = run(capsys, "limits", "--loop", PAPER)
    assert status == 0, err
    status, paper, err = run(capsys, "limits", "--Td", "0.04")
    assert status == 0, err
    for loop_name, paper_name, unit in (("K_max", "K_max", "N m/rad"),
                                        ("B at K_max", "B_w at K_max", "N m s/rad"),
                                        ("B_min", "B_left", "N m s/rad"),
                                        ("B_max", "B_right", "N m s/rad")):
        found = re.search(rf"(?m)^\s*{re.escape(loop_name)}\s+(\S+)\s+(.+?)\s{{2,}}", loop)
        assert found and found.group(2) == unit, (loop_name, loop)
        ours = float(found.group(1))
        # The meaning column follows the unit.
        found = re.search(rf"(?m)\s{re.escape(paper_name)}\s+(\S+)\s+(.+?)\s{{2,}}", paper)
        assert found and found.group(2) == unit, (paper_name, paper)
        assert ours == pytest.approx(float(found.group(1)), rel=1e-6, abs=1e-9)
    assert "plane: x = B [N m s/rad], y = K [N m/rad]" in loop
    assert "m = 0.0128 kg m^2" in loop and "m = 0.0128 kg m^2" in paper


@pytest.mark.parametrize("unit", ["N m/deg^2", "N m/rad^2", "N m rad", "N mm/arcmin^2"])
def test_set_with_an_angle_to_another_power_is_refused(capsys, unit):
    """issue 40 item 7: pint takes an angle as a number; K=2 N m/deg^2 was used as 6565.6 N m/rad."""
    status, out, err = run(capsys, "classify", "--loop", PAPER, "--set", f"K=2 {unit}")
    assert status == 2 and out == "" and err.count("\n") == 1, err
    assert err.startswith(f"symstab classify: error: --set K: parameter 'K' has unit {unit!r}")
    assert "K is in N m/rad (an angle to the power -1)" in err


@pytest.mark.parametrize("unit, factor", [("N m/deg", 180 / math.pi), ("kN m/deg", 18e4 / math.pi),
                                          ("N m/turn", 1 / (2 * math.pi)), ("N m", 1.0)])
def test_set_with_an_angle_to_the_parameters_power_is_converted(capsys, unit, factor):
    """2 N m/deg is 2*180/pi N m/rad, by hand; a unit without an angle is SI's reading (rad = 1)."""
    out = run_json(capsys, "classify", "--loop", PAPER, "--set", f"K=2 {unit}")
    assert out["inputs"]["values"]["K"] == pytest.approx(2 * factor, rel=1e-15)
    assert out["inputs"]["units"]["K"] == "N m/rad"


@pytest.mark.parametrize("setting, shown", [
    ("d=-1 samples", "'-1 samples'"), ("d=1e6", "'1e6'"), ("K=1e999 N m/rad", "'1e999 N m/rad'"),
])
def test_a_refused_set_value_is_shown_as_written(capsys, setting, shown):
    """issue 40 item 16: --set "d=5.1 ms" said 'got 5.1', dropping the unit."""
    status, out, err = run(capsys, "classify", "--loop", PAPER, "--set", setting)
    assert status == 2 and out == "" and err.count("\n") == 1, err
    assert err.startswith(f"symstab classify: error: --set {setting}: ") and err.endswith(
        f", got {shown}\n"), err


# --------------------------------------------------------------------------
# A fractional delay (issue 43): d = 40.5 samples, or Td in a unit of time


def _paper_with(tmp_path, delay):
    """The paper's loop file with its ``d = ...`` line replaced by ``delay``."""
    text = PAPER.read_text(encoding="utf-8")
    old = 'd = { value = 40, unit = "samples" }'
    assert old in text
    path = tmp_path / "paper_delay.toml"
    path.write_text(text.replace(old, delay), encoding="utf-8")
    return str(path)


@pytest.fixture(scope="module")
def k_max_at_40_5():
    """The library's PAPER_LOOP at Td = 40.5 ms: the cross-check of the CLI's plumbing."""
    import symstab

    return symstab.PAPER_LOOP.limits("B", "K", Td=0.0405).y_max


@pytest.mark.parametrize("delay, written", [
    ('d = { value = 40.5, unit = "samples" }', None),
    ("d = 40.5", None),
    ('Td = { value = 40.5, unit = "ms" }', {"value": 40.5, "unit": "ms"}),
    ("Td = 0.0405", {"value": 0.0405, "unit": "s"}),
])
def test_a_loop_file_takes_a_fractional_delay_in_samples_or_in_time(capsys, tmp_path,
                                                                     k_max_at_40_5, delay, written):
    out = run_json(capsys, "limits", "--loop", _paper_with(tmp_path, delay))
    assert out["limits"]["y_max"] == pytest.approx(k_max_at_40_5, rel=1e-12)
    assert out["inputs"]["values"]["d"] == 40.5        # a number in the JSON, in samples
    assert out["inputs"].get("as_written", {}).get("Td") == written


@pytest.mark.parametrize("setting", ["Td=40.5ms", "Td=0.0405 s", "d=40.5"])
def test_set_takes_a_fractional_delay_in_samples_or_in_time(capsys, k_max_at_40_5, setting):
    out = run_json(capsys, "limits", "--loop", PAPER, "--set", setting)
    assert out["limits"]["y_max"] == pytest.approx(k_max_at_40_5, rel=1e-12)
    assert out["inputs"]["values"]["d"] == 40.5 and "Td" not in out["inputs"]["values"]


def test_the_echo_shows_a_delay_in_time_and_in_samples(capsys, tmp_path):
    status, out, err = run(capsys, "classify", "--loop", PAPER, "--set", "Td=40.5ms")
    assert status == 0, err
    assert "Td = 40.5 ms (d = 40.5 samples) (--set)" in out
    # --set d replaces the file's Td: the echo no longer names it.
    path = _paper_with(tmp_path, 'Td = { value = 40.5, unit = "ms" }')
    status, out, err = run(capsys, "classify", "--loop", path, "--set", "d=40")
    assert status == 0, err
    assert "d = 40 samples (--set)" in out and "Td" not in out


@pytest.mark.parametrize("args, message", [
    (["--set", "Td=40.5ms", "--set", "d=40"], "give the delay once"),
    (["--set", "Td=40.5 kg"], "--set Td: parameter 'Td' has unit 'kg': Td is the loop delay"),
    (["--set", "d=5.1 ms"], "the delay d is a number of samples"),
    # Without a unit Td is in the file's unit for it, SI here: 40.5 s.
    (["--set", "Td=40.5"], "--set Td: delay Td / T must be from 0 to 10000 samples"),
    (["--set", "Td=-1ms"], "Td must be a finite real number >= 0"),
    (["--set", "Td=40.5ms", "--set", "T=1e-3,2e-3"], "a delay in time needs one sample period T"),
    (["--set", "d=nan"], "d must be a finite number"),
    (["--d", "40.5"], "give a fractional delay in seconds with --Td"),
])
def test_a_bad_delay_is_refused_in_one_line(capsys, args, message):
    status, out, err = run(capsys, "classify", "--loop", PAPER, *args)
    assert status == 2 and out == "" and err.count("\n") == 1, err
    assert err.startswith("symstab classify: error: ") and message in err, err


def test_a_loop_file_with_both_d_and_td_is_refused(capsys, tmp_path):
    path = _paper_with(tmp_path, 'd = 40\nTd = { value = 40.5, unit = "ms" }')
    status, out, err = run(capsys, "limits", "--loop", path)
    assert status == 2 and out == "" and err.count("\n") == 1, err
    assert "give the delay once, d (in samples) or Td (in seconds)" in err


def test_margins_at_a_fractional_delay_are_the_loops(capsys):
    """--set Td=40.5ms: the exact delay margin and the whole one, both the library's at 40.5."""
    found = symstab.load_loop(PAPER).margins(K=1.0, B=0.1, d=40.5)
    margins = run_json(capsys, "margins", "--loop", PAPER, "--set", "Td=40.5ms", "--set", "K=1",
                       "--set", "B=0.1")["margins"]
    assert margins["point"]["d"] == 40.5
    assert margins["modulus"] == pytest.approx(found.modulus, rel=1e-12)
    assert margins["exact_delay"]["margin"] == pytest.approx(found.exact_delay.margin, rel=1e-12)
    assert margins["delay"] == found.delay
