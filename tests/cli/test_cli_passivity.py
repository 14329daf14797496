"""``symstab limits`` reports the passive K_max beside the stable one (issue 12, part 3).

Oracle: Colgate and Schenkel's closed form for the virtual wall at d = 0,
``b > K T/2 + |B|``, so the passive ``K_max = 2 b / T`` at ``B = 0``
(``alpha_max = 2 delta`` in Table I's units), and the passive area is the
triangle's ``2 b**2 / T``; for a loop file the same through the file's units.
"""

import json

import pytest

from conftest import PAPER_B, PAPER_DELTA, PAPER_T, REPO
from conftest import run_cli as run

# The session's loop cache: operator_arm (8 s to derive) is read, not derived
# again, and nothing is written to ~/.cache.
pytestmark = pytest.mark.usefixtures("loop_cache_dir")


def test_paper_limits_give_the_wall_passive_k_max_in_both_units(capsys):
    status, out, _ = run(capsys, "limits", "--d", "0", "--format", "json")
    assert status == 0
    data = json.loads(out)
    passive = data["passive"]
    assert passive["alpha_max"] == pytest.approx(2 * PAPER_DELTA, rel=1e-9)
    assert abs(passive["beta_at_alpha_max"]) < 1e-9 * PAPER_DELTA
    assert passive["area"] == pytest.approx(2 * PAPER_DELTA**2, rel=1e-9)
    assert passive["K_max"] == pytest.approx(2 * PAPER_B / PAPER_T, rel=1e-9)
    # The stable limits are unchanged and come first.
    assert data["limits"]["alpha_max"] > passive["alpha_max"]
    status, out, _ = run(capsys, "limits", "--d", "0")
    lines = out.splitlines()
    first_k_max = next(line for line in lines if "K_max" in line)
    assert "alpha_max" in first_k_max            # the table's stable row
    passive_line = next(line for line in lines if line.startswith("passive K_max"))
    assert f"{2 * PAPER_B / PAPER_T:.6g}"[:5] in passive_line and "N m/rad" in passive_line


def test_dimensionless_limits_without_damping_say_so(capsys):
    status, out, _ = run(capsys, "limits", "--delta", "0", "--d", "1")
    assert status == 0
    assert "passive set (Colgate-Schenkel): none, the device has no damping" in out


def test_empty_passive_set_is_a_note(capsys):
    # gamma > delta at d = 0: no passive point (theta = 0 and pi together need gamma <= delta).
    status, out, _ = run(capsys, "limits", "--delta", str(PAPER_DELTA), "--d", "0", "--gamma", "0.1",
                         "--format", "json")
    assert status == 0
    data = json.loads(out)
    assert data["passive"]["alpha_max"] is None
    assert any("no passive point" in note for note in data["notes"])


def test_loop_limits_give_the_passive_y_max(capsys):
    path = str(REPO / "examples" / "loops" / "paper.toml")
    status, out, _ = run(capsys, "limits", "--loop", path, "--set", "d=0", "--set", "M=0",
                         "--format", "json")
    assert status == 0
    data = json.loads(out)
    passive = data["passive"]
    b, T = data["inputs"]["values"]["b"], data["inputs"]["values"]["T"]
    assert passive["y_max"] == pytest.approx(2 * b / T, rel=1e-9)
    assert passive["area"] == pytest.approx(2 * b**2 / T, rel=1e-9) and passive["bounded"]
    status, out, _ = run(capsys, "limits", "--loop", path, "--set", "d=0", "--set", "M=0")
    line = next(line for line in out.splitlines() if line.startswith("passive K_max"))
    assert "N m/rad at B =" in line and "stable K_max =" in line


def test_loop_the_theorem_does_not_cover_is_a_note_not_an_error(capsys):
    path = str(REPO / "examples" / "loops" / "operator_arm.toml")
    status, out, err = run(capsys, "limits", "--loop", path, "--format", "json")
    assert status == 0
    data = json.loads(out)
    assert "1/(m*s**2 + b*s)" in data["passive"]["error"]
    assert data["limits"]["y_max"] > 0


def test_tiny_damping_keeps_its_passive_set(capsys):
    # Closed form at d = 0: alpha_max = 2 delta, area 2 delta**2 (was "no passive point" for delta <= 1e-6).
    status, out, _ = run(capsys, "limits", "--delta", "1e-6", "--d", "0", "--format", "json")
    assert status == 0
    passive = json.loads(out)["passive"]
    assert passive["alpha_max"] == pytest.approx(2e-6, rel=1e-9)
    assert passive["area"] == pytest.approx(2e-12, rel=1e-9)
    # A loop file: b = 1e-12 N s/m gives K_max = 2 b / T (the file's defaults K, B no longer set the unit).
    path = str(REPO / "examples" / "loops" / "paper.toml")
    status, out, _ = run(capsys, "limits", "--loop", path, "--set", "b=1e-12", "--set", "d=0",
                         "--set", "M=0", "--format", "json")
    assert status == 0
    data = json.loads(out)
    assert data["passive"]["y_max"] == pytest.approx(2e-12 / data["inputs"]["values"]["T"], rel=1e-9)
