"""What a new user meets first on the command line (issue 13).

``symstab`` alone and ``--version``; ``derive`` outside a source checkout
and from another folder.  Most
commands run in-process (:func:`symstab.cli.main` with capsys); what needs
an installed copy without a checkout runs ``python -m symstab`` on a copy of
the package in a temporary folder.
"""

import importlib.metadata
import os
import pathlib
import shutil
import subprocess
import sys

import pytest

import symstab
from symstab import cli

from conftest import REPO

#: Every sub-command; a new one must be added here (and gets its --help checked).
COMMANDS = ("derive", "audit", "figures", "reproduce", "boundary", "limits", "classify",
            "design", "simulate", "map")


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
    monkeypatch.setattr(cli, "project_root", lambda *args: None)
    assert cli.package_version().startswith("unknown")


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
    from symstab import codegen, derive

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


