"""The manual stays true: the examples of the README and of the docs' pages run, the audit table matches the report."""

import doctest
import importlib
import re

import pytest

from conftest import MANUAL, REPO


def _table(text):
    return dict(re.findall(r"^\| \**([a-z-]+)\** \| \**(\d+)\** \|$", text, flags=re.M))


def test_readme_audit_summary_matches_the_report():
    readme = (REPO / "README.md").read_text(encoding="utf-8")
    block = re.search(r"<!-- audit-summary.*?-->(.*?)<!-- /audit-summary -->", readme, re.S).group(1)
    report = (REPO / "paper_checks" / "REPORT.md").read_text(encoding="utf-8")
    summary = report.split("## Summary", 1)[1].split("##", 1)[0]
    assert _table(block) == _table(summary) and len(_table(block)) == 6


def test_readme_python_examples_run(monkeypatch):
    monkeypatch.chdir(REPO)
    readme = (REPO / "README.md").read_text(encoding="utf-8")
    parser = doctest.DocTestParser()
    test = parser.get_doctest(readme, {}, "README.md", str(REPO / "README.md"), 0)
    assert len(test.examples) >= 6
    runner = doctest.DocTestRunner(optionflags=doctest.NORMALIZE_WHITESPACE)
    runner.run(test)
    assert runner.failures == 0


#: The docs' pages with Python examples, each run as one doctest of its own.
EXAMPLE_PAGES = [path for path in MANUAL[1:] if ">>> " in path.read_text(encoding="utf-8")]


def test_the_pages_moved_from_the_readme_keep_their_examples():
    names = {path.relative_to(REPO / "docs").as_posix() for path in EXAMPLE_PAGES}
    assert {"getting_started.md", "guide/paper.md", "guide/any_loop.md", "guide/regions.md"} <= names


@pytest.mark.parametrize("page", EXAMPLE_PAGES, ids=lambda p: p.relative_to(REPO / "docs").as_posix())
def test_docs_python_examples_run(page, monkeypatch, session_cache_dir):
    """Each page's ``>>>`` examples, top to bottom in one namespace, from the repository's root."""
    monkeypatch.chdir(REPO)
    text = page.read_text(encoding="utf-8")
    test = doctest.DocTestParser().get_doctest(text, {}, page.name, str(page), 0)
    assert len(test.examples) >= 1
    runner = doctest.DocTestRunner(optionflags=doctest.NORMALIZE_WHITESPACE)
    runner.run(test)
    assert runner.failures == 0


@pytest.mark.parametrize("module", ["symstab.numeric.paper.device", "symstab.numeric.paper.curves", "symstab.numeric.paper.stability",
                                    "symstab.numeric.paper.region", "symstab.symbolic.model", "symstab.symbolic.theta_max",
                                    "symstab.numeric.loop.sampled_loop", "symstab.numeric.engine.decomposition",
                                    "symstab.numeric.paper.theta_bounds", "symstab.numeric.analysis.passivity",
                                    "symstab.numeric.engine.locus", "symstab.numeric.loop.plane",
                                    "symstab.numeric.analysis.robust", "symstab.numeric.analysis.design",
                                    "symstab.numeric.analysis.probability",
                                    "symstab.numeric.simulation.simulator",
                                    "symstab.numeric.simulation.simulated_limit",
                                    "symstab.symbolic.discretize", "symstab.numeric.analysis.delays"])
def test_docstring_examples_run(module):
    mod = importlib.import_module(module)
    failures, tried = doctest.testmod(mod, optionflags=doctest.NORMALIZE_WHITESPACE)
    assert tried > 0 and failures == 0


def _readme_commands():
    """The ``symstab`` command lines of the manual's console and bash blocks (README and docs), as argument lists."""
    import shlex

    commands = []
    blocks = [block for path in MANUAL
              for block in re.findall(r"```(?:console|bash)\n(.*?)```", path.read_text(encoding="utf-8"), re.S)]
    for block in blocks:
        for line in block.splitlines():
            for part in line.removeprefix("$ ").split("&&"):
                words = shlex.split(part, comments=True)
                if words[:1] == ["symstab"]:
                    commands.append(words[1:])
    return commands


def test_readme_console_examples_write_only_under_the_ignored_out_folder():
    """The README's and the docs' pages' commands.  They left map.npz, map.png, locus.png, tustin.png and operator_arm_derivation/
    in the checkout (issue 18).  Every file a README command writes -- its
    ``--out``, ``--png``, ``--report``, ``--json``, the PNG that ``map`` writes beside
    its ``--out``, the folder ``derive --loop`` writes -- is under ``out/``, which
    .gitignore ignores; ``reproduce`` writes the ignored ``reproduction/``."""
    import pathlib

    from symstab.cli import commands as cli

    assert "/out/" in (REPO / ".gitignore").read_text(encoding="utf-8").splitlines()
    parser = cli.build_parser()
    written = []
    for words in _readme_commands():
        args = parser.parse_args(words)
        paths = {flag: getattr(args, flag, None) for flag in ("out", "png", "report", "json")}
        if args.command == "map" and paths["png"] is None and "--no-png" not in words:
            paths["png"] = str(pathlib.Path(paths["out"]).with_suffix(".png"))
        if args.command == "derive" and getattr(args, "loop", None) and paths["out"] is None:
            paths["out"] = "<loop name>_derivation"   # the current folder
        for flag, path in paths.items():
            if path is None or (args.command == "reproduce" and path == "reproduction"):
                continue
            written.append((" ".join(["symstab", *words]), flag, path))
    assert len(written) >= 12
    outside = [w for w in written if pathlib.PurePath(w[2]).parts[0] != "out"]
    assert not outside, outside
