"""``limits --loop --uncertain``: the robust limits from the command line.

Oracle: the library's robust limits (tested against python-control's poles
in tests/numeric/analysis/test_robust.py) at the values the options name, in any
unit.  Bad input is one line, exit status 2, before any work, and nothing
is written.
"""

import json

import pytest

control = pytest.importorskip("control")

import symstab

from conftest import REPO
from conftest import run_cli as run

PAPER = REPO / "examples" / "loops" / "paper.toml"

pytestmark = pytest.mark.usefixtures("loop_cache_dir")


def test_robust_limits_are_the_library_s_in_any_unit(capsys, tmp_path):
    png = tmp_path / "robust.png"
    status, text, err = run(capsys, "limits", "--loop", PAPER, "--set", "d=10", "--set", "M=0",
                            "--uncertain", "b=16.2:64.8 g*m^2/s", "--strips", "16",
                            "--png", png, "--at", "1.0", "--format", "json")
    assert status == 0, err
    found = json.loads(text)
    lim = symstab.load_loop(PAPER).limits("B", "K", uncertain={"b": (0.0162, 0.0648)},
                                          strips=16, d=10, M=0.0)
    assert found["limits"]["y_max"] == lim.y_max and found["limits"]["area"] == lim.area
    assert found["robust"]["uncertain"] == {"b": [0.0162, 0.0648]}
    assert found["robust"]["nominal_area"] > lim.area
    assert found["at"]["intervals"] == [list(r) for r in lim.intervals_at(1.0)]
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_robust_limits_over_delays_and_the_empty_set(capsys):
    status, text, err = run(capsys, "limits", "--loop", PAPER, "--set", "M=0",
                            "--uncertain", "d=9:11", "--strips", "8")
    assert status == 0, err
    assert "stable for every d in [9, 11]" in text
    status, text, err = run(capsys, "limits", "--loop", PAPER, "--set", "d=10",
                            "--uncertain", "M=0:0.019", "--strips", "8")
    assert status == 0, err
    assert "the robust set is empty" in text and "no common point" in text


def test_robust_limits_over_a_continuum_of_delays(capsys):
    """``--uncertain Td=1.5ms:2.5ms`` (or a unit after HI, or ``d=1.5:2.5`` in samples) is the
    library's robust set for every delay of the range."""
    lim = symstab.load_loop(PAPER).limits("B", "K", uncertain={"Td": (0.0015, 0.0025)},
                                          strips=4, M=0.0)
    for option in ("Td=1.5ms:2.5ms", "Td=1.5:2.5 ms", "d=1.5:2.5"):
        status, text, err = run(capsys, "limits", "--loop", PAPER, "--set", "M=0",
                                "--uncertain", option, "--strips", "4", "--format", "json")
        assert status == 0, err
        found = json.loads(text)
        assert found["limits"]["y_max"] == pytest.approx(lim.y_max, rel=1e-12)
        assert found["limits"]["area"] == pytest.approx(lim.area, rel=1e-12)
    assert found["robust"]["uncertain"] == {"d": [1.5, 2.5]}
    status, text, err = run(capsys, "limits", "--loop", PAPER, "--set", "M=0",
                            "--uncertain", "Td=1.5ms:2.5ms", "--strips", "4")
    assert status == 0, err
    assert "stable for every Td in [0.0015, 0.0025] s" in text
    assert "2 piece(s) of a continuum of delays" in err


def test_a_box_ending_at_zero_is_certified_and_the_strip_count_explained(capsys):
    """b in [0, 0.0324]: refused as "not defined at b = 0" (a box holding 0 inside worked).

    Its robust K_max cannot exceed the nominal one at b = 0, taken here from
    python-control's poles (a bisection on K at the B of the robust K_max).
    And the note said "92 strips" after announcing 64: it says why now.
    """
    status, text, err = run(capsys, "limits", "--loop", PAPER, "--set", "d=10", "--set", "M=0",
                            "--uncertain", "b=0:0.0324", "--strips", "8", "--format", "json")
    assert status == 0, err
    found = json.loads(text)
    B = found["limits"]["x_at_y_max"]
    G = control.sample_system(control.tf([1], [0.0128, 0, 0]), 1e-3, "zoh")
    z = control.tf([1, 0], [1], 1e-3)

    def stable(K):
        loop = control.feedback(G, (K + B * (z - 1) / (1e-3 * z)) * control.tf([1], [1] + [0] * 10,
                                                                                 1e-3))
        return max(abs(loop.poles())) < 1

    # Stable at the robust K_max, unstable above: the nominal K_max at b = 0 is not below it.
    # (A bisection followed until issue 41; it only ever raised lo from K_max, so that
    # y_max <= lo held whatever it found.)
    lo, hi = found["limits"]["y_max"], 100.0
    assert stable(lo) and not stable(hi)
    assert found["limits"]["y_max"] <= lo
    status, text, err = run(capsys, "limits", "--loop", PAPER, "--set", "d=10", "--set", "M=0",
                            "--uncertain", "b=0:0.0324", "--strips", "8")
    assert status == 0, err
    assert "8 strips asked for," in text and "after halving those where the set has" in text


def test_a_box_of_zero_width_is_the_nominal_set(capsys):
    """``--uncertain b=LO:LO``: the nominal set (the line engine's), certified the robust way."""
    status, text, err = run(capsys, "limits", "--loop", PAPER, "--set", "d=10", "--set", "M=0",
                            "--uncertain", "b=0.0324:0.0324", "--strips", "64",
                            "--format", "json")
    assert status == 0, err
    found = json.loads(text)
    loop = symstab.load_loop(PAPER)
    (lo, hi), = loop.stable_intervals("K", B=found["limits"]["x_at_y_max"], d=10, M=0.0)
    assert found["limits"]["y_max"] == pytest.approx(hi, rel=1e-6)
    assert found["limits"]["area"] == pytest.approx(found["robust"]["nominal_area"], rel=1e-3)


@pytest.mark.parametrize("args, message", [
    (("--uncertain", "b=0.05:0.01"), "LO <= HI"),
    (("--uncertain", "K=1:2"), "axis"),
    (("--uncertain", "q=1:2"), "not a parameter"),
    (("--uncertain", "b=0.01:0.05", "--strips", "0"), "--strips"),
    (("--uncertain", "b=0.01:0.05", "--png", "x.txt"), "--png"),
    (("--strips", "8"), "--uncertain"),
    (("--png", "x.png"), "--uncertain"),
    (("--uncertain", "d=-1.5:3"), "--uncertain d: the delay in samples, >= 0"),
    (("--uncertain", "d=1:2 ms"), "--uncertain d: the delay in samples"),
    (("--uncertain", "Td=-1ms:2ms"), "--uncertain Td must be a finite real number >= 0"),
    (("--uncertain", "Td=nan:2ms"), "--uncertain Td: 'nan ms' is not a number"),
    (("--uncertain", "Td=3ms:2ms"), "--uncertain Td: LO:HI must have LO <= HI"),
    (("--uncertain", "Td=2ms"), "--uncertain Td must be LO:HI"),
    (("--uncertain", "Td=1ms:1e6ms"), "SYMSTAB_MAX_DELAY"),
    (("--uncertain", "d=1.5:1e9"), "SYMSTAB_MAX_DELAY"),
    (("--uncertain", "Td=1:2 kg"), "--uncertain Td"),
    (("--uncertain", "Td=1ms:2ms", "--uncertain", "T=0.0009:0.0011"), "over an uncertain T"),
    (("--uncertain", "Td=1ms:2ms", "--uncertain", "d=1:2"), "give the delay once"),
    (("--set", "d=10", "--uncertain", "Td=1ms:2ms"), "give the delay once"),
    (("--set", "b=0.03", "--uncertain", "b=0.01:0.05"), "also given by --set"),
    (("--set", "d=10", "--uncertain", "d=8:12"), "also given by --set"),
    # Refused by the library, before any work: still one line, naming the option.
    (("--uncertain", "b=1e308:1.7e308", "--png", "x.png"), "--uncertain: b in [1e+308"),
])
def test_bad_options_are_one_line(capsys, tmp_path, args, message):
    args = [a.replace("x.png", str(tmp_path / "x.png")) for a in args]
    delay = () if any(a.startswith(("d=", "Td=")) for a in args) else ("--set", "d=10")
    status, text, err = run(capsys, "limits", "--loop", PAPER, *delay, *args)
    assert status == 2
    assert message in err and len(err.strip().splitlines()) == 1
    assert not list(tmp_path.iterdir())


def test_uncertain_needs_a_loop_file(capsys):
    status, _, err = run(capsys, "limits", "--uncertain", "b=0.01:0.05")
    assert status == 2 and "--uncertain needs a loop file" in err
