"""Tests of the ``symstab`` command line, run as ``python -m symstab``."""

import pytest

from symstab.cli import commands as cli

from conftest import EDITED_CODE_FILE, EDITED_FILE, REPO, run_symstab


def _assert_one_line_error(result, *needles, prefix="symstab: error:"):
    assert result.returncode == 2
    assert "Traceback" not in result.stderr
    lines = result.stderr.strip().splitlines()
    assert len(lines) == 1, result.stderr
    assert lines[0].startswith(prefix), lines[0]
    for needle in needles:
        assert needle in lines[0]


def test_derive_out_pointing_to_a_file_exits_2(tmp_path):
    target = tmp_path / "not_a_dir.txt"
    target.write_text("keep me\n")
    result = run_symstab("derive", "--out", str(target), cwd=tmp_path)
    _assert_one_line_error(result, "--out", str(target), prefix="symstab derive: error:")
    assert target.read_text() == "keep me\n"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["not_a_dir.txt"]


@pytest.mark.parametrize("args, needle, prefix", [
    (["derive", "--bogus"], "--bogus", "symstab derive: error:"),
    (["limits", "--d"], "--d", "symstab limits: error:"),
    (["--bogus"], "unrecognized arguments: --bogus", "symstab: error:"),
    (["frobnicate"], "frobnicate", "symstab: error:"),
])
def test_bad_command_line_exits_2_with_one_line(tmp_path, args, needle, prefix):
    result = run_symstab(*args, cwd=tmp_path)
    _assert_one_line_error(result, needle, prefix=prefix)
    assert list(tmp_path.iterdir()) == []


def test_help_exits_0(tmp_path):
    result = run_symstab("derive", "--help", cwd=tmp_path)
    assert result.returncode == 0 and "--check" in result.stdout


def test_check_exits_1_and_names_only_the_edited_file(derive_subprocess_runs):
    (returncode, stdout, stderr), (out_dir, _) = derive_subprocess_runs["check_edited"]
    assert returncode == 1, stderr
    assert "Traceback" not in stderr
    named = [line for line in stdout.splitlines() if line.startswith("drift:")]
    assert len(named) == 1
    assert str(out_dir / EDITED_FILE) in named[0]
    assert "symstab derive" in named[0]


def test_derive_writes_into_out(derive_subprocess_runs, rendered_files):
    (returncode, stdout, _), (out_dir, code_dir) = derive_subprocess_runs["seed1"]
    assert returncode == 0
    assert f"wrote {len(rendered_files)} files to {out_dir} and " in stdout
    assert f" to {code_dir} " in stdout


def test_check_exits_1_and_names_only_the_edited_generated_file(derive_subprocess_runs):
    (returncode, stdout, stderr), (_, code_dir) = derive_subprocess_runs["check_edited_code"]
    assert returncode == 1, stderr
    named = [line for line in stdout.splitlines() if line.startswith("drift:")]
    assert len(named) == 1
    assert str(code_dir / EDITED_CODE_FILE) in named[0]
    assert f"--codegen-out {code_dir}" in named[0]


def test_check_exits_0_on_fresh_output(tmp_path, rendered_files, generated_code, capsys):
    from symstab.proof import derive

    derive.write(tmp_path / "derivations", rendered_files)
    derive.write(tmp_path / "code", generated_code)
    assert cli.main(["derive", "--out", str(tmp_path / "derivations"),
                     "--codegen-out", str(tmp_path / "code"), "--check"]) == 0
    assert "match a fresh derivation" in capsys.readouterr().out


def test_check_reports_a_stray_generated_file(tmp_path, rendered_files, generated_code, capsys):
    from symstab.proof import derive

    derive.write(tmp_path / "derivations", rendered_files)
    derive.write(tmp_path / "code", generated_code)
    (tmp_path / "code" / "old_kernels.py").write_text("# a former kernel\n")
    assert cli.main(["derive", "--out", str(tmp_path / "derivations"),
                     "--codegen-out", str(tmp_path / "code"), "--check"]) == 1
    assert "old_kernels.py" in capsys.readouterr().out


def test_committed_kernels_match_a_fresh_generation(generated_code):
    from symstab.proof import derive

    committed = REPO / "symstab" / "_generated"
    stale = derive.check(committed, generated_code, owned=("*.py", "*.c", "*.h"))
    assert stale == [], f"generated code drifted: {stale}; run `symstab derive`"


def test_check_on_missing_directory_exits_1(tmp_path, capsys):
    assert cli.main(["derive", "--out", str(tmp_path / "absent"), "--check"]) == 1
    assert capsys.readouterr().out.count("drift:") >= 2
    assert not (tmp_path / "absent").exists()
