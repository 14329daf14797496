"""The documentation site (docs/): every public name has a page, the notebooks are stored clean, the build is clean.

The site is built with ``sphinx-build -W --keep-going -n`` (nitpicky, warnings
are errors); that build also executes the derivation notebooks of
``derivations/`` (myst-nb, ``nb_execution_mode = "force"``, a cell that raises
fails the build), so it is the one run of the notebooks per test run: each
walks through one derivation step by calling :mod:`symstab` and
:mod:`paper_checks` and asserts the audit's verdicts as it goes; ``08`` walks
one loop of ``examples/loops/`` through :class:`symstab.Loop` against
python-control's poles; ``09`` answers the velocity filter's cut-off question.
The notebooks are stored without outputs (the tests below only need the
standard library); the built pages hold them.
"""

import json
import os
import pathlib
import re
import subprocess
import sys

import pytest

import symstab

from conftest import REPO, run_once_per_session

DOCS = REPO / "docs"
DERIVATIONS = REPO / "derivations"

#: The notebooks, one per derivation step, in order; then any loop and the cut-off.
EXPECTED = (
    "01_zoh_plant.ipynb",
    "02_characteristic_polynomial.ipynb",
    "03_unit_circle_split.ipynb",
    "04_boundary_and_coefficients.ipynb",
    "05_theta_max.ipynb",
    "06_small_theta_limits.ipynb",
    "07_code_generation.ipynb",
    "08_any_loop.ipynb",
    "09_cutoff.ipynb",
)

KERNELSPEC = {"name": "python3", "display_name": "Python 3", "language": "python"}


def _autosummary_names(page):
    """The names listed in the autosummary blocks of a page (MyST's ``{eval-rst}`` blocks)."""
    text = page.read_text(encoding="utf-8")
    names = []
    for block in re.findall(r"\.\. autosummary::\n((?:   .*\n|\n)*)", text):
        names += [line.strip() for line in block.splitlines()
                  if line.strip() and not line.strip().startswith(":")]
    return names


def test_every_public_name_has_a_page_in_the_reference():
    """python-control's doc/test_sphinxdocs.py idea: a name of ``symstab.__all__`` without a page fails."""
    listed = _autosummary_names(DOCS / "reference" / "api.md")
    assert len(listed) == len(set(listed)), "a name is listed twice"
    missing = sorted(set(symstab.__all__) - set(listed))
    assert not missing, f"not in docs/reference/api.md: {missing}"
    unknown = sorted(set(listed) - set(symstab.__all__))
    assert not unknown, f"listed in docs/reference/api.md but not in symstab.__all__: {unknown}"


def test_the_reference_documents_the_library_modules_recursively():
    assert set(_autosummary_names(DOCS / "reference" / "modules.md")) == {
        "symstab.symbolic", "symstab.codegen", "symstab.proof", "symstab.numeric", "symstab.drawing",
        "symstab.figures", "symstab.reproduce", "symstab.cli"}


def test_the_derivations_are_sources_of_the_site():
    """docs/derivations is the repository's notebooks folder (a link), not a copy."""
    link = DOCS / "derivations"
    assert link.is_symlink() and link.resolve() == DERIVATIONS.resolve()
    assert "derivations/*" in (DOCS / "derivations.md").read_text(encoding="utf-8")


# --------------------------------------------------------------------------
# The notebooks, as stored


def _load(name):
    with open(DERIVATIONS / name, encoding="utf-8") as fh:
        return json.load(fh)


def test_the_notebooks_exist_in_order():
    found = tuple(sorted(path.name for path in DERIVATIONS.glob("*.ipynb")))
    assert found == EXPECTED


@pytest.mark.parametrize("name", EXPECTED)
def test_notebook_is_stored_clean(name):
    nb = _load(name)
    assert nb["nbformat"] == 4
    assert nb["metadata"].get("kernelspec") == KERNELSPEC
    code = [cell for cell in nb["cells"] if cell["cell_type"] == "code"]
    assert code, f"{name} has no code cells"
    for index, cell in enumerate(nb["cells"]):
        if cell["cell_type"] != "code":
            continue
        assert cell.get("outputs") == [], f"{name}: cell {index} has stored outputs"
        assert cell.get("execution_count") is None, f"{name}: cell {index} has an execution count"
    assert nb["cells"][0]["cell_type"] == "markdown", f"{name} does not open with prose"


# --------------------------------------------------------------------------
# The build


@pytest.fixture(scope="session")
def site(tmp_path_factory, session_cache_dir):
    """The site built as the README says, into a temporary folder: (exit status, log, html folder).

    Built once for the session, also under xdist (``conftest.run_once_per_session``):
    two builds would cost a minute more and write the same autosummary stubs into
    ``docs/`` at once.  Its tests are collected first (``conftest._FIRST``), so the
    build starts with the run.  The ``docs`` extra (in the ``test`` extra from
    Python 3.11 on, as Sphinx 9 needs it) is the toolchain; without it the build
    is skipped, saying so.
    """
    for module in ("sphinx", "myst_nb", "numpydoc", "sphinxarg", "pydata_sphinx_theme", "ipykernel"):
        pytest.importorskip(module, reason='the docs build needs the docs extra: pip install ".[docs]"')

    def build(out):
        html = out / "html"
        command = [sys.executable, "-m", "sphinx", "-W", "--keep-going", "-n", "-b", "html",
                   "-d", str(out / "doctrees"), str(DOCS), str(html)]
        env = {**os.environ, "SYMSTAB_CACHE_DIR": str(session_cache_dir)}
        done = subprocess.run(command, cwd=REPO, env=env, capture_output=True, text=True,
                              timeout=900)
        return [done.returncode, done.stdout + done.stderr, str(html)]

    status, log, html = run_once_per_session(tmp_path_factory, "site", build)
    return status, log, pathlib.Path(html)


@pytest.mark.slow
def test_the_docs_build_without_a_warning(site):
    status, log, html = site
    assert status == 0, log[-5000:]
    # Sphinx's own warnings ("path: WARNING: ..."), not the kernels' stderr lines.
    assert not re.findall(r"^.*: WARNING: .*$", log, re.M), log[-5000:]
    for page in ("index", "getting_started", "guide/regions", "reference/api", "reference/cli",
                 "reference/generated/symstab.Loop", "changelog", "citing"):
        assert (html / f"{page}.html").is_file(), page
    # The math is typeset by the site's own copy of MathJax: the pages need no network.
    assert (html / "_static" / "mathjax" / "tex-chtml.js").is_file()
    page = (html / "derivations" / "04_boundary_and_coefficients.html").read_text(encoding="utf-8")
    assert "_static/mathjax/tex-chtml.js" in page and "cdn.jsdelivr" not in page


@pytest.mark.slow
@pytest.mark.parametrize("name", EXPECTED)
def test_the_built_notebook_pages_hold_their_outputs_and_no_error(site, name):
    """Each notebook ran in the build, top to bottom: every code cell has its output area, none an error."""
    status, log, html = site
    assert status == 0, log[-5000:]
    page = (html / "derivations" / name.replace(".ipynb", ".html")).read_text(encoding="utf-8")
    cells = len([cell for cell in _load(name)["cells"] if cell["cell_type"] == "code"])
    assert page.count('class="cell docutils container"') == cells
    assert 'class="cell_output docutils container"' in page
    assert "traceback" not in page.lower()


@pytest.mark.slow
def test_the_regions_page_draws_its_figure_at_build_time(site):
    status, log, html = site
    assert status == 0, log[-5000:]
    page = (html / "guide" / "regions.html").read_text(encoding="utf-8")
    images = re.findall(r'<img [^>]*src="([^"]+\.png)"', page)
    assert images and all((html / "guide" / src).is_file() for src in images)
