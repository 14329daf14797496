"""The package looks after itself: its version, licence, citation and changelog agree."""

import importlib.metadata
import re
import subprocess
import sys

try:
    import tomllib
except ImportError:   # Python 3.10
    import tomli as tomllib

from conftest import REPO

PROJECT = tomllib.loads((REPO / "pyproject.toml").read_text(encoding="utf-8"))["project"]


def test_version_is_the_installed_metadata_s_in_a_fresh_interpreter():
    code = "import symstab; print(symstab.__version__)"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         timeout=60, cwd=REPO / "tests")
    assert out.returncode == 0, out.stderr
    assert out.stdout.strip() == importlib.metadata.version("symstab") == PROJECT["version"]


def test_the_licence_file_is_the_licence_pyproject_declares_and_is_shipped():
    text = (REPO / "LICENSE").read_text(encoding="utf-8")
    assert PROJECT["license"] == "BSD-3-Clause" and text.startswith("BSD 3-Clause License")
    assert PROJECT["license-files"] == ["LICENSE"]


def test_citation_names_this_version_and_the_paper():
    text = (REPO / "CITATION.cff").read_text(encoding="utf-8")
    assert re.search(r'^version: "([^"]+)"$', text, re.M).group(1) == PROJECT["version"]
    assert re.search(r'^license: (\S+)$', text, re.M).group(1) == PROJECT["license"]
    # The paper the README and the docs' "How to cite" cite, by the same DOI.
    doi = re.search(r'doi: "([^"]+)"', text).group(1)
    assert doi in (REPO / "README.md").read_text(encoding="utf-8")
    assert doi in (REPO / "docs" / "citing.md").read_text(encoding="utf-8")


def test_the_changelog_has_a_section_for_this_version():
    text = (REPO / "CHANGELOG.md").read_text(encoding="utf-8")
    assert re.search(rf"^## {re.escape(PROJECT['version'])}\b", text, re.M)
