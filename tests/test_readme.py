"""The README stays true: its examples run, its audit table matches the report."""

import doctest
import importlib
import re

import pytest

from conftest import REPO


def _table(text):
    return dict(re.findall(r"^\| \**([a-z-]+)\** \| \**(\d+)\** \|$", text, flags=re.M))


def test_readme_audit_summary_matches_the_report():
    readme = (REPO / "README.md").read_text(encoding="utf-8")
    block = re.search(r"<!-- audit-summary.*?-->(.*?)<!-- /audit-summary -->", readme, re.S).group(1)
    report = (REPO / "paper_checks" / "REPORT.md").read_text(encoding="utf-8")
    summary = report.split("## Summary", 1)[1].split("##", 1)[0]
    assert _table(block) == _table(summary) and len(_table(block)) == 6


def test_readme_python_examples_run(monkeypatch, tmp_path):
    # The README builds loops, whose kernels go to the cache: keep it out of ~/.cache.
    monkeypatch.setenv("SYMSTAB_CACHE_DIR", str(tmp_path))
    monkeypatch.chdir(REPO)
    readme = (REPO / "README.md").read_text(encoding="utf-8")
    parser = doctest.DocTestParser()
    test = parser.get_doctest(readme, {}, "README.md", str(REPO / "README.md"), 0)
    assert len(test.examples) >= 6
    runner = doctest.DocTestRunner(optionflags=doctest.NORMALIZE_WHITESPACE)
    runner.run(test)
    assert runner.failures == 0


@pytest.mark.parametrize("module", ["symstab.numeric.units", "symstab.numeric.curves", "symstab.numeric.stability",
                                    "symstab.numeric.region", "symstab.symbolic.model", "symstab.symbolic.theta_max",
                                    "symstab.numeric.any_loop", "symstab.numeric.decomposition",
                                    "symstab.numeric.theta_bounds", "symstab.numeric.passivity",
                                    "symstab.numeric.locus"])
def test_docstring_examples_run(module, monkeypatch, tmp_path):
    monkeypatch.setenv("SYMSTAB_CACHE_DIR", str(tmp_path))
    mod = importlib.import_module(module)
    failures, tried = doctest.testmod(mod, optionflags=doctest.NORMALIZE_WHITESPACE)
    assert tried > 0 and failures == 0
