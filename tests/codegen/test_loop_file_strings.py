"""A loop file is data: no string in it runs, whatever it holds.

Loop files are exchanged between colleagues.  Their strings (name,
description, units, parameter names, plant, environment, plane) reach
generated Python and C, file names, LaTeX and the terminal; each must be
refused with one line (exit status 2) or shown literally, and nothing in it
may run.  The attack of issue 18 (a ``name`` with a newline broke out of the
comment header of the loop's cached kernel module, which was then imported)
is here as a test, with the tampered cache file and a hypothesis fuzz of
every string field through ``classify``, ``limits`` and ``derive --loop``.
"""

import ast
import contextlib
import io
import json
import os
import pathlib
import shlex
import sys
import tempfile

import pytest
from hypothesis import HealthCheck, event, given, settings
from hypothesis import strategies as st

if sys.version_info >= (3, 11):
    import tomllib
else:   # pragma: no cover - Python 3.10
    import tomli as tomllib

from symstab.cli import commands as cli
from symstab.codegen.generator import comment_text, docstring_text, one_line
from symstab.codegen.loop_kernels import c_source, environment_kernels, numpy_source
from symstab.numeric.engine.roots import STABLE
from symstab.numeric.loop.files import load_loop, parse_loop_text
from symstab.symbolic.loop_assembly import NAME_PATTERN

from conftest import REPO

pytestmark = pytest.mark.usefixtures("loop_cache_dir")

PAPER_FILE = REPO / "examples" / "loops" / "paper.toml"
#: The paper's plant and a spring-damper: small, so a command takes a second.
PLANT = "1/(m*s**2 + b*s)"
#: What every payload below tries to create in the current folder.
MARKER = "RAN_MARKER"


def toml_string(text):
    """``text`` as a TOML basic string (quotes, backslashes and control characters escaped)."""
    out = []
    for c in text:
        if c in '"\\':
            out.append("\\" + c)
        elif ord(c) < 0x20 or ord(c) == 0x7F:
            out.append(f"\\u{ord(c):04x}")
        else:
            out.append(c)
    return '"' + "".join(out) + '"'


def loop_text(*, name=None, description=None, plant=PLANT, stiffness="K", unit="N/m",
              plane=("B", "K")):
    """A loop file: the paper's plant, a spring ``stiffness`` and a damper ``B``."""
    lines = []
    if name is not None:
        lines.append(f"name = {toml_string(name)}")
    if description is not None:
        lines.append(f"description = {toml_string(description)}")
    lines.append(f"plant = {toml_string(plant)}")
    lines.append(f"environment = {toml_string(f'{stiffness} + B*(z - 1)/(T*z)')}")
    if plane is not None:
        lines.append(f"plane = [{', '.join(toml_string(p) for p in plane)}]")
    lines += ["", "[parameters]", 'm = { value = 0.0128, unit = "kg" }',
              'b = { value = 0.0324, unit = "N s/m" }', 'T = { value = 1e-3, unit = "s" }',
              'd = { value = 1, unit = "samples" }', 'B = { value = 0.5, unit = "N s/m" }',
              f"{toml_string(stiffness)} = "
              + (f"{{ value = 300.0, unit = {toml_string(unit)} }}" if unit is not None
                 else "300.0")]
    return "\n".join(lines) + "\n"


def run_in(folder, *argv):
    """``symstab ARGV`` in this process with ``folder`` as the current folder."""
    out, err = io.StringIO(), io.StringIO()
    here = os.getcwd()
    os.chdir(folder)
    try:
        with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
            status = cli.main([str(a) for a in argv])
    finally:
        os.chdir(here)
    return status, out.getvalue(), err.getvalue()


def assert_refused_in_one_line(result, command):
    status, out, err = result
    assert status == 2, (status, out, err)
    assert out == "" and err.count("\n") == 1 and err.endswith("\n"), (out, err)
    assert err.startswith(f"symstab {command}: error: "), err


def assert_only_data(path):
    """The generated Python module at ``path`` only defines: a docstring, imports, __all__, defs."""
    tree = ast.parse(path.read_text(encoding="utf-8"))
    for node in tree.body:
        ok = (isinstance(node, ast.Expr) and isinstance(node.value, ast.Constant)
              and isinstance(node.value.value, str)
              or isinstance(node, ast.Import) and [a.name for a in node.names] == ["numpy"]
              or isinstance(node, ast.Assign) and [t.id for t in node.targets] == ["__all__"]
              or isinstance(node, ast.FunctionDef))
        assert ok, f"{path.name}: line {node.lineno}: {ast.dump(node)[:200]}"
    doc = ast.get_docstring(tree)
    assert doc is not None
    return doc


# --------------------------------------------------------------------------
# The attack of issue 18


ATTACK = 'x\nimport os; os.system("touch PWNED")\n#'


def test_a_name_that_breaks_out_of_the_kernel_header_runs_nothing(tmp_path):
    """issue 18: this file made ``classify --loop`` create PWNED (the name escaped its comment)."""
    path = tmp_path / "evil.toml"
    path.write_text(loop_text(name=ATTACK), encoding="utf-8")
    result = run_in(tmp_path, "classify", "--loop", path)
    assert not (tmp_path / "PWNED").exists()
    assert_refused_in_one_line(result, "classify")
    assert "name" in result[2] and "letters, digits" in result[2]
    assert sorted(os.listdir(tmp_path)) == ["evil.toml"]


@pytest.mark.parametrize("title", [
    ATTACK.replace("PWNED", MARKER),
    f'"""\nimport os; os.system("touch {MARKER}")\n"""',
    f"'''\\\n__import__('os').system('touch {MARKER}')\r#",
    "*/ int x; /* ??/\n\\",
])
def test_a_title_is_a_string_literal_and_an_escaped_comment(tmp_path, title, monkeypatch):
    """Below the name check: whatever the title holds, the module text only defines kernels."""
    monkeypatch.chdir(tmp_path)
    loop = parse_loop_text(loop_text())
    kernels, _ = environment_kernels(loop)
    text = numpy_source(kernels, title=title)
    module = tmp_path / "module.py"
    module.write_text(text, encoding="utf-8")
    assert assert_only_data(module) == title   # shown literally
    assert text.splitlines()[1] == f"# {one_line(title)}"
    exec(compile(text, str(module), "exec"), {})
    assert not (tmp_path / MARKER).exists()
    c_text = c_source(kernels, title=title, prefix="symstab_x_", command="symstab derive --loop")
    head = c_text.split("#include", 1)[0].splitlines()
    assert all(line.startswith("//") and not line.endswith("\\") for line in head if line)
    assert head[1] == f"// {comment_text(title, 'c')}" and "*/" not in head[1]


def test_comment_and_docstring_escapes():
    assert one_line("a\nb\r\x1b\u202e\té") == "a\\nb\\r\\x1b\\u202e\\té"
    assert comment_text("*/ \\ ??/", "c") == "* / \\x5c ? ?/"
    assert docstring_text('"""\\') == '\\"\\"\\"\\\\'
    with pytest.raises(ValueError, match="language"):
        comment_text("x", "sh")


def test_a_tampered_cache_file_is_not_imported(tmp_path, monkeypatch, loop_cache_dir):
    """A cache file that differs from the text symstab generates is rewritten, never run."""
    monkeypatch.chdir(tmp_path)
    text = loop_text(name="tampered_cache_test")
    loop = parse_loop_text(text)
    assert loop.classify() == STABLE   # writes the cache file
    path = pathlib.Path(loop.kernel_file())
    original = path.read_bytes()
    sys.modules.pop(loop._kernels[0].__name__)
    path.write_bytes(original + f"\nopen({MARKER!r}, 'w').close()\n".encode())
    again = parse_loop_text(text)
    assert again.classify() == STABLE
    assert not (tmp_path / MARKER).exists()
    assert path.read_bytes() == original
    assert again.kernel_file() == str(path)


def test_a_parameter_name_is_an_ascii_identifier():
    with pytest.raises(ValueError, match=r"parameter 'κ'.*ASCII"):
        parse_loop_text(loop_text(stiffness="κ"))
    assert "K_spring" in parse_loop_text(loop_text(stiffness="K_spring", plane=None)).parameters


@pytest.mark.parametrize("field, value", [
    ("description", "two\nlines"), ("description", "a bell \x07"), ("description", "\u202eevil"),
    ("description", "x" * 201), ("name", ""), ("name", "-rf"), ("name", ".hidden"),
    ("name", "with space"), ("name", "a/b"), ("name", "é"), ("name", "x" * 65),
])
def test_a_name_or_description_that_is_not_plain_text_is_refused(field, value):
    with pytest.raises(ValueError, match=rf"evil.toml: {field} "):
        parse_loop_text(loop_text(**{field: value}), source="evil.toml")


def test_a_name_or_description_that_is_not_a_string_is_refused():
    text = loop_text().replace("plant =", "name = 3\nplant =", 1)
    with pytest.raises(ValueError, match="'name' must be a string"):
        parse_loop_text(text)


def test_without_a_name_the_file_stem_made_a_word_is_the_name(tmp_path):
    path = tmp_path / "my loop (v2) $(x).toml"
    path.write_text(loop_text(), encoding="utf-8")
    assert load_loop(path).name == "my_loop_v2_x"
    assert NAME_PATTERN.fullmatch(load_loop(path).name)


def test_derive_check_names_the_command_quoted_for_a_shell(tmp_path):
    path = tmp_path / f"paper $(touch {MARKER}).toml"
    path.write_text(PAPER_FILE.read_text(encoding="utf-8"), encoding="utf-8")
    out = tmp_path / "no such folder"
    status, text, _ = run_in(tmp_path, "derive", "--loop", path, "--out", out, "--check")
    assert status == 1
    command = text.splitlines()[0].split("run `", 1)[1].rstrip("`")
    assert shlex.split(command) == ["symstab", "derive", "--loop", str(path), "--out", str(out)]


# --------------------------------------------------------------------------
# Fuzz: every string field, through classify, limits and derive --loop


#: Pieces that end a comment, a string or a line, run a shell, format,
#: or mean something to LaTeX, C or a terminal; each tries to create MARKER.
FRAGMENTS = [
    "\n", "\r\n", "\r", '"', "'", "\\", "#", '"""', "'''", f"$(touch {MARKER})",
    f"`touch {MARKER}`", "{}", "{0}", "{name}", "%", "%s", "%(x)s", "*/", "/*", "//", "??/",
    "\\input{/etc/hostname}", f"\\write18{{touch {MARKER}}}", "$x^2$", "&", "_", "~", "^",
    "é", "Ω", "\u00a0", "😀", "\u202e", "\u2028", "\x1b[2J", "\x00", "\t",
    f"\nimport os; os.system('touch {MARKER}')\n#",
    f'"""\nimport os; os.system("touch {MARKER}")\n"""',
    "__import__('os').environ.__setitem__('SYMSTAB_FUZZ_RAN', '1')",
]
nasty = st.lists(st.one_of(st.sampled_from(FRAGMENTS), st.text(max_size=4)),
                 max_size=4).map("".join)
printable = nasty.map(lambda t: "".join(c for c in t if c.isprintable()))
identifier = st.from_regex(r"[A-Za-z][A-Za-z0-9_]{0,8}", fullmatch=True)

# A plain value is drawn more often than a nasty one (one_of weighs its
# branches alike), so that files with every field but one plain, whose
# strings must then be shown literally, come up too.
loop_strings = st.fixed_dictionaries({
    "name": st.one_of(st.none(), *[st.from_regex(NAME_PATTERN, fullmatch=True)] * 2, nasty),
    "description": st.one_of(st.none(), printable, printable, nasty),
    "stiffness": st.one_of(st.just("K"), st.just("K"), identifier, nasty),
    "unit": st.one_of(st.just("N/m"), st.just("N/m"), st.none(), nasty),
    "plant": st.one_of(*[st.just(PLANT)] * 4, nasty.map(lambda t: PLANT + t), nasty),
    "plane": st.one_of(st.none(), *[st.just(("B", "@stiffness"))] * 3,
                       st.tuples(nasty, nasty).map(tuple)),
})


@settings(suppress_health_check=[HealthCheck.function_scoped_fixture, HealthCheck.too_slow])
@given(strings=loop_strings)
def test_fuzz_every_string_field_is_refused_in_one_line_or_shown_literally(strings, tmp_path):
    if strings["plane"] == ("B", "@stiffness"):
        strings["plane"] = ("B", strings["stiffness"])
    text = loop_text(**strings)
    # The file says what the strategy drew (the test's own TOML writer is
    # right), unless the spring has the name of another parameter: a TOML
    # key given twice, which the loop file refuses too.
    if strings["stiffness"] in ("m", "b", "T", "d", "B"):
        with pytest.raises(tomllib.TOMLDecodeError):
            tomllib.loads(text)
    else:
        data = tomllib.loads(text)
        for key in ("name", "description", "plant"):
            assert data.get(key) == strings[key]
    folder = pathlib.Path(tempfile.mkdtemp(dir=tmp_path))
    path = folder / "fuzz.toml"
    path.write_text(text, encoding="utf-8")
    environment = dict(os.environ)
    extra = {"derive": ("--out", folder / "out"),
             # A file without a plane: limits is given one.
             "limits": ("--x=B", f"--y={strings['stiffness']}") if strings["plane"] is None else ()}
    runs = {command: run_in(folder, command, "--loop", path, *extra.get(command, ()))
            for command in ("classify", "limits", "derive")}
    assert dict(os.environ) == environment
    assert not list(folder.rglob(f"*{MARKER}*")), "a payload ran"
    accepted = {command: result[0] == 0 for command, result in runs.items()}
    event("accepted" if accepted["classify"] else "refused")
    if not accepted["classify"]:
        # One file, one verdict: refused when it is read, by every command.
        for command, result in runs.items():
            assert_refused_in_one_line(result, command)
        assert sorted(os.listdir(folder)) == ["fuzz.toml"]
        return
    assert all(accepted.values()), runs
    loop = load_loop(path)
    name = strings["name"] if strings["name"] is not None else "fuzz"
    assert loop.name == name and loop.description == (strings["description"] or "")
    assert runs["classify"][1].startswith(f"loop {name} ({path}): ")
    assert f"{strings['stiffness']} = 300" in runs["classify"][1]
    title = f"The loop {name}" + (f": {loop.description}" if loop.description else "")
    out = folder / "out"
    assert json.loads((out / "01_loop.json").read_text(encoding="utf-8"))["title"] == title
    assert (out / "01_loop.tex").read_text(encoding="utf-8").splitlines()[0] == f"% {title}"
    stem = [p for p in out.glob("*_kernels.py")]
    assert len(stem) == 1
    assert assert_only_data(stem[0]).startswith(f"NumPy kernels of the loop {name}: ")
    assert assert_only_data(pathlib.Path(loop.kernel_file())).startswith(
        f"NumPy kernels of the loop {name}: ")
    for c_file in out.glob("*_kernels.[ch]"):
        head = c_file.read_text(encoding="utf-8").splitlines()[:3]
        assert head[1].startswith(f"// C99 kernels of the loop {name} ") and head[2] == ""
    assert sorted(os.listdir(folder)) == ["fuzz.toml", "out"]
