"""What a new user meets first on the command line (issue 13).

``symstab`` alone and ``--version``; a description and an example in every
``--help``; ``derive`` outside a source checkout and from another folder;
``design`` echoing only the inputs it uses; ``limits`` naming its beta range
for what it is; ``map`` drawn and stored in the units of its grid.  Most
commands run in-process (:func:`symstab.cli.commands.main` with capsys); what needs
an installed copy without a checkout runs ``python -m symstab`` on a copy of
the package in a temporary folder.
"""

import importlib.metadata
import json
import os
import pathlib
import shlex
import shutil
import subprocess
import sys

import numpy as np
import pytest

import symstab
from symstab.cli import commands as cli
from symstab.numeric.paper.simulate_theory import linear_theory
from symstab.numeric.simulation.simulator import Nonidealities

from conftest import PAPER_DELTA, PAPER_M, PAPER_T, REPO
from oracles import python_control_closed_loop

#: Every sub-command; a new one must be added here (and gets its --help checked).
COMMANDS = ("derive", "audit", "figures", "reproduce", "boundary", "limits", "classify",
            "margins", "design", "simulate", "map", "locus", "sweep")


def _main(capsys, *args):
    status = cli.main(list(args))
    out, err = capsys.readouterr()
    return status, out, err


# --------------------------------------------------------------------------
# symstab alone, symstab --version


def test_version_prints_the_package_metadata_version(tmp_path):
    result = subprocess.run([sys.executable, "-m", "symstab", "--version"], cwd=tmp_path,
                            capture_output=True, text=True, timeout=120)
    assert result.returncode == 0, result.stderr
    assert result.stdout == f"symstab {importlib.metadata.version('symstab')}\n"
    assert result.stderr == ""


def test_version_without_metadata_falls_back_to_the_checkout(monkeypatch, capsys):
    import tomllib

    def not_installed(name):
        raise importlib.metadata.PackageNotFoundError(name)

    monkeypatch.setattr(importlib.metadata, "version", not_installed)
    with open(REPO / "pyproject.toml", "rb") as fh:
        version = tomllib.load(fh)["project"]["version"]
    status, out, _ = _main(capsys, "--version")
    assert status == 0
    assert out.startswith(f"symstab {version} (source checkout") and "not installed" in out
    # An installed copy without metadata and without a checkout says so.
    from symstab import _project

    monkeypatch.setattr(_project, "project_root", lambda *args: None)
    assert cli.package_version().startswith("unknown")
    assert _project.version() == "0+unknown"


def test_no_command_prints_the_usage_and_every_command(capsys):
    """Chosen: exit status 2 (a usage error, as argparse), the help on stderr, one error line last."""
    status, out, err = _main(capsys)
    assert status == 2 and out == ""
    lines = err.rstrip("\n").splitlines()
    assert lines[0].startswith("usage: symstab")
    listed = {line.split()[0] for line in lines if line.startswith("    ") and line.split()}
    assert listed >= set(COMMANDS)
    assert lines[-1].startswith("symstab: error: no command given")
    assert "Traceback" not in err


def test_the_command_list_is_the_one_this_file_checks(capsys):
    parser = cli.build_parser()
    sub = next(a for a in parser._actions if a.dest == "command")
    assert tuple(sub.choices) == COMMANDS


# --------------------------------------------------------------------------
# --help: what the command computes, and an example


@pytest.mark.parametrize("command", COMMANDS)
def test_help_has_a_description_and_an_example_that_parses(capsys, command):
    status, out, _ = _main(capsys, command, "--help")
    assert status == 0
    paragraphs = out.split("\n\n")
    assert paragraphs[0].startswith(f"usage: symstab {command}")
    description = " ".join(paragraphs[1].split())
    # A sentence, not the first option group.
    assert not description.endswith(":") and ":\n" not in paragraphs[1], paragraphs[1]
    assert len(description) > 40 and description.endswith("."), description
    examples = [line for line in out.splitlines() if line.startswith(f"  symstab {command} ")]
    assert len(examples) == 1, out
    assert out.splitlines()[out.splitlines().index(examples[0]) - 1] == "example:"
    words = shlex.split(examples[0])
    assert words[:2] == ["symstab", command]
    args = cli.build_parser().parse_args(words[1:])   # raises SystemExit if it does not parse
    assert args.command == command


# --------------------------------------------------------------------------
# derive: outside a checkout, and from another folder


def _installed_copy(tmp_path):
    """The package under test copied where no checkout holds it; returns (site, empty cwd)."""
    site, cwd = tmp_path / "site", tmp_path / "cwd"
    shutil.copytree(pathlib.Path(symstab.__file__).parent, site / "symstab",
                    ignore=shutil.ignore_patterns("__pycache__"))
    cwd.mkdir()
    return site, cwd


def _run_copy(site, cwd, *args):
    env = dict(os.environ, PYTHONPATH=str(site))
    return subprocess.run([sys.executable, "-m", "symstab", *args], cwd=cwd, env=env,
                          capture_output=True, text=True, timeout=300)


def test_project_root_is_the_checkout_and_none_for_an_installed_copy(tmp_path):
    assert cli.project_root() == REPO
    site, _ = _installed_copy(tmp_path)
    assert cli.project_root(site / "symstab") is None


def test_derive_check_outside_a_checkout_checks_the_installed_kernels(tmp_path):
    """Was: every file reported as drift (the files were simply not there), exit 1, 50 s."""
    site, cwd = _installed_copy(tmp_path)
    result = _run_copy(site, cwd, "derive", "--check")
    assert result.returncode == 0, result.stdout + result.stderr
    lines = result.stdout.splitlines()
    assert len(lines) == 2, result.stdout
    assert lines[0].startswith("no source checkout above ") and str(site / "symstab") in lines[0]
    assert f"4 files in {site / 'symstab' / '_generated'} match" in lines[1]
    assert "drift" not in result.stdout and "Traceback" not in result.stderr
    assert list(cwd.iterdir()) == []

    # The check is a real one: an edited installed kernel is drift, and the
    # advice is not to run a derive that cannot write there.
    edited = site / "symstab" / "_generated" / "symstab_kernels.c"
    edited.write_text(edited.read_text() + "/* a hand edit */\n")
    result = _run_copy(site, cwd, "derive", "--check")
    assert result.returncode == 1
    drift = [line for line in result.stdout.splitlines() if line.startswith("drift:")]
    assert drift == [f"drift: {edited} differs from a fresh derivation; reinstall symstab"]


def test_derive_outside_a_checkout_refuses_to_write_without_out(tmp_path):
    """Was: derivations/ and symstab/_generated/ written into the current folder."""
    site, cwd = _installed_copy(tmp_path)
    before = {p: p.read_bytes() for p in (site / "symstab" / "_generated").iterdir()}
    for args, missing in ((["derive"], "--out and --codegen-out"),
                          (["derive", "--out", "d"], "--codegen-out")):
        result = _run_copy(site, cwd, *args)
        assert result.returncode == 2
        lines = result.stderr.strip().splitlines()
        assert len(lines) == 1 and lines[0].startswith("symstab derive: error: not in a source "
                                                       "checkout"), result.stderr
        assert f"give {missing} " in lines[0]
        assert list(cwd.iterdir()) == []
    assert {p: p.read_bytes() for p in (site / "symstab" / "_generated").iterdir()} == before


def test_derive_check_from_another_folder_compares_with_the_checkout(
        tmp_path, monkeypatch, capsys, rendered_files, generated_code):
    """Was: the default paths were relative to the current folder: all drift."""
    from symstab.codegen import generator as codegen
    from symstab.proof import derive

    # The session's derivation, not a second one of its own.
    monkeypatch.setattr(derive, "derivation_steps", lambda: None)
    monkeypatch.setattr(derive, "render", lambda steps: rendered_files)
    monkeypatch.setattr(codegen, "generated_files", lambda: generated_code)
    monkeypatch.chdir(tmp_path)
    status, out, _ = _main(capsys, "derive", "--check")
    assert status == 0, out
    assert (f"{len(rendered_files) + len(generated_code)} files in "
            f"{REPO / 'derivations' / 'generated'} and {REPO / 'symstab' / '_generated'} match") in out
    assert list(tmp_path.iterdir()) == []


# --------------------------------------------------------------------------
# design echoes only what was given


def test_design_does_not_echo_a_virtual_mass_it_searches_over(capsys, shared_cli_run):
    status, out, err = _main(capsys, "design", "--Td", "0.01")
    assert status == 0
    echo = out.split("\n\n")[0]
    assert "Td = 0.01 s (d = 10)" in echo
    assert "M_w" not in echo and "gamma" not in echo, echo
    status, out, _ = shared_cli_run("design", "--delta", str(PAPER_DELTA), "--d", "10",
                                    "--format", "json")
    data = json.loads(out)
    assert "gamma" not in data["inputs"] and "M_w" not in data["inputs"]
    assert data["inputs"]["d"] == 10
    # --gamma 1 was "ignored" in a note while the nominal row showed alpha_max at gamma = 1
    # under the label "gamma = 0" (gain 1.87 instead of 5.82): it is refused now.
    status, out, err = _main(capsys, "design", "--delta", str(PAPER_DELTA), "--d", "10",
                             "--gamma", "1")
    assert status == 2 and out == "" and "--gamma: design searches the virtual mass" in err


# --------------------------------------------------------------------------
# limits: the leftmost beta of the region is not the paper's beta_min


def _stable_by_python_control(alpha, beta, gamma):
    loop = python_control_closed_loop(alpha=alpha, beta=beta, gamma=gamma, d=0, delta=PAPER_DELTA,
                                      m=PAPER_M, T=PAPER_T)
    return bool(np.all(np.abs(loop.poles()) < 1))


def test_limits_names_the_ends_of_the_region_beta_left_and_beta_right(capsys):
    status, out, _ = _main(capsys, "limits", "--delta", str(PAPER_DELTA), "--gamma", "1.5",
                           "--format", "json")
    assert status == 0
    lim = json.loads(out)["limits"]
    assert {"beta_left", "beta_right"} <= set(lim) and not {"beta_min", "beta_max"} & set(lim)
    left, right, alpha_max = lim["beta_left"], lim["beta_right"], lim["alpha_max"]
    # What the names say, by python-control's poles: something is stable just
    # right of beta_left (the CLI's own interval there), nothing just left of it.
    width = right - left
    status, out, _ = _main(capsys, "limits", "--delta", str(PAPER_DELTA), "--gamma", "1.5",
                           "--beta", repr(left + 0.01 * width), "--format", "json")
    (lo, hi), = json.loads(out)["alpha_intervals"]["intervals"]
    assert _stable_by_python_control((lo + hi) / 2, left + 0.01 * width, 1.5)
    assert not any(_stable_by_python_control(a, left - 0.01 * width, 1.5)
                   for a in np.linspace(0, 1.2 * alpha_max, 121))
    # ... and it is not the paper's beta_min = -delta, which the table says.
    assert left < -10 * PAPER_DELTA
    status, out, _ = _main(capsys, "limits", "--delta", str(PAPER_DELTA), "--gamma", "1.5")
    rows = {line.split()[0] for line in out.splitlines() if line.startswith(" ") and line.split()}
    assert {"beta_left", "beta_right"} <= rows and not {"beta_min", "beta_max"} & rows
    assert "the paper's beta_min = -delta = -0.00253125 is where the boundary arc starts" in out


def test_limits_beta_left_is_minus_delta_without_virtual_mass(capsys):
    """The paper (Sec. IV, after [15], [24]): the region starts at beta = -b T / m for gamma = 0."""
    status, out, _ = _main(capsys, "limits", "--delta", str(PAPER_DELTA), "--format", "json")
    data = json.loads(out)
    assert data["limits"]["beta_left"] == pytest.approx(-PAPER_DELTA, rel=1e-8)
    # Nothing to tell apart (the notes are the passive set's, beside the stable one).
    assert not any("beta_min" in note for note in data.get("notes", []))


def test_limits_help_documents_every_json_key(capsys):
    _, out, _ = _main(capsys, "limits", "--delta", str(PAPER_DELTA), "--format", "json")
    keys = set(json.loads(out)["limits"]) - {"message"}
    _, text, _ = _main(capsys, "limits", "--help")
    table = text.split("quantities")[1].split("\n\n")[0]
    documented = {line.split()[0] for line in table.splitlines()[1:]
                  if line.startswith("  ") and not line.startswith("   ")}
    assert keys == documented


# --------------------------------------------------------------------------
# map: in the units of the grid, with its non-idealities


GRID = ["--Td", "0.01", "--Kw", "0,70,5", "--Bw=-0.1,2,4", "--steps", "400"]


def test_map_stores_Kw_and_Bw_with_units_beside_alpha_and_beta(tmp_path, capsys):
    out = tmp_path / "m.npz"
    status, _, err = _main(capsys, "map", *GRID, "--paper-encoder", "--out", str(out), "--no-png")
    assert status == 0, err
    with np.load(out) as z:
        np.testing.assert_array_equal(z["K_w"], np.linspace(0, 70, 5))
        np.testing.assert_array_equal(z["B_w"], np.linspace(-0.1, 2, 4))
        np.testing.assert_allclose(z["alpha"], z["K_w"] * PAPER_T**2 / PAPER_M, rtol=1e-14)
        np.testing.assert_allclose(z["beta"], z["B_w"] * PAPER_T / PAPER_M, rtol=1e-14)
        assert str(z["K_w_unit"]) == "N m/rad" and str(z["B_w_unit"]) == "N m s/rad"
        assert "encoder quantum 1.454e-05 rad" in str(z["nonidealities"])

    csv_out = tmp_path / "m.csv"
    status, _, _ = _main(capsys, "map", *GRID, "--linear", "--out", str(csv_out), "--no-png")
    lines = csv_out.read_text().splitlines()
    assert lines[0] == "alpha,beta,K_w [N/m],B_w [N s/m],stable,limit_cycle,exact_stable,growth"
    rows = np.array([[float(v) for v in line.split(",")[:4]] for line in lines[1:]])
    assert len(rows) == 20
    np.testing.assert_allclose(rows[:, 2], rows[:, 0] * PAPER_M / PAPER_T**2, rtol=1e-11, atol=1e-9)
    np.testing.assert_allclose(rows[:, 3], rows[:, 1] * PAPER_M / PAPER_T, rtol=1e-11)
    assert sorted(set(rows[:, 3])) == pytest.approx(np.linspace(-0.1, 2, 4))


@pytest.fixture
def drawn(monkeypatch):
    """The axes of every figure saved (labels, limits, title), in order."""
    from matplotlib.figure import Figure

    seen, savefig = [], Figure.savefig

    def record(fig, *args, **kwargs):
        ax = fig.axes[0]
        seen.append(dict(xlabel=ax.get_xlabel(), ylabel=ax.get_ylabel(), title=ax.get_title(),
                         xlim=ax.get_xlim(), ylim=ax.get_ylim()))
        return savefig(fig, *args, **kwargs)

    monkeypatch.setattr(Figure, "savefig", record)
    return seen


def test_map_png_is_drawn_in_the_units_of_the_grid_with_its_nonidealities(tmp_path, capsys, drawn):
    out = tmp_path / "m.npz"
    status, _, err = _main(capsys, "map", *GRID, "--paper-encoder", "--velocity-cutoff", "50",
                           "--out", str(out))
    assert status == 0, err
    assert (tmp_path / "m.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    (axes,) = drawn
    assert axes["xlabel"].startswith("$B_w$") and "N m s/rad" in axes["xlabel"]
    assert axes["ylabel"].startswith("$K_w$") and "N m/rad" in axes["ylabel"]
    assert axes["xlim"] == pytest.approx((-0.1, 2.0)) and axes["ylim"] == pytest.approx((0, 70))
    assert "encoder quantum 1.454e-05 rad" in axes["title"]
    assert "velocity filter 50 Hz" in axes["title"]


def test_map_png_of_a_dimensionless_grid_stays_dimensionless(tmp_path, capsys, drawn):
    status, _, err = _main(capsys, "map", "--delta", str(PAPER_DELTA), "--d", "10",
                           "--alpha", "0,0.006,4", "--beta=-0.01,0.16,3", "--steps", "400",
                           "--out", str(tmp_path / "m.csv"))
    assert status == 0, err
    (axes,) = drawn
    assert axes["xlabel"].startswith(r"$\beta") and axes["ylabel"].startswith(r"$\alpha")
    assert "ideal loop" in axes["title"]


def test_map_example_frames_the_stable_region(tmp_path, capsys, loop_cache_dir):
    """The example of ``symstab map --help`` (the README's): not 96 % empty."""
    _, text, _ = _main(capsys, "map", "--help")
    (example,) = [line for line in text.splitlines() if line.startswith("  symstab map ")]
    words = shlex.split(example)[1:]
    args = cli.build_parser().parse_args(words)
    (k_lo, k_hi), (b_lo, b_hi) = ([float(v) for v in grid.split(",")[:2]]
                                  for grid in (args.Kw, args.Bw))
    # The extent at this delay of the region mapped, in N m/rad and N m s/rad:
    # the loop with the example's velocity filter (its theory is what the map
    # compares with and draws).
    assert args.velocity_cutoff is not None
    theory = linear_theory(gamma=0.0, d=round(args.Td / PAPER_T), device=symstab.PAPER_DEVICE,
                           nonideal=Nonidealities(velocity_cutoff=args.velocity_cutoff))
    lim = theory.loop.limits(**theory.values)
    k_max, left, right = lim.y_max, lim.x_min, lim.x_max
    assert 0.6 * k_hi < k_max < k_hi and k_lo <= 0
    assert b_lo < left and right < b_hi and right - left > 0.6 * (b_hi - b_lo)
    # And the map itself: over a third of the cells stable.
    words[words.index("--out") + 1] = str(tmp_path / "map.npz")
    status, _, err = _main(capsys, *words, "--no-png")
    assert status == 0, err
    with np.load(tmp_path / "map.npz") as z:
        assert z["exact_stable"].mean() > 0.4 and z["stable"].mean() > 0.2
