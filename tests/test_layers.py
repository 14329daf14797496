"""The package is laid out by layer, and no layer imports a layer above it.

From the bottom: the private base (``_io``, ``_lazy``, ``_memo``, ``_progress``,
``_project``, ``_resources``, ``_signals``, ``_validate``, ``_workers``,
``_generated``), ``symbolic`` (the derivation in SymPy),
``codegen`` (float-safe forms, printers, generated kernels), ``proof``
(the identity checker, every proof obligation, the derivation files),
``numeric`` (the numeric API on the kernels, in rooms of their own order:
``engine`` < ``loop`` < ``simulation`` < ``analysis`` < ``paper``), and the
front ends (``cli``, ``figures``, ``reproduce``).  ``paper_checks`` sits between the library and
the front ends: the front ends may import it, the library may not.  Imports
are read from the source (static, lazy ones inside functions included).

Besides the layers: no import cycle (strongly connected components of the
module graph of symstab and of paper_checks), no private name imported
from another module (:data:`PRIVATE_IMPORTS_ALLOWED` lists the few left, each
with its reason) nor reached on another module's object, no two library
modules of one file name, and the command line one module per command.
"""

import ast
import functools
import pathlib

import pytest

import symstab

PACKAGE = pathlib.Path(symstab.__file__).resolve().parent


@functools.lru_cache(maxsize=None)
def _tree(path):
    """The module's syntax tree, parsed once for all the checks below."""
    return ast.parse(path.read_text(encoding="utf-8"))

#: Rank of each layer; a module may import its own rank or lower.
RANK = {"base": 0, "symbolic": 1, "codegen": 2, "proof": 3, "numeric": 4, "front": 5}
#: ``drawing`` imports nothing of symstab (it draws what it is handed): the results'
#: ``plot()`` methods, in any layer, hand themselves to it.
_BASE = {"_io", "_lazy", "_memo", "_progress", "_project", "_resources", "_signals", "_validate", "_workers",
         "_generated", "drawing"}
_FRONT = {"cli", "figures", "reproduce", "__main__"}


def _layer(parts):
    """Layer of a module given its path parts below ``symstab``."""
    head = parts[0]
    if head in _BASE:
        return "base"
    if head in _FRONT:
        return "front"
    if head in RANK:
        return head
    raise AssertionError(f"symstab/{'/'.join(parts)} is in no layer: put it in one")


def _modules():
    for path in sorted(PACKAGE.rglob("*.py")):
        parts = path.relative_to(PACKAGE).with_suffix("").parts
        if parts == ("__init__",) or "_generated" in parts:
            continue
        yield path, parts


def _imports(path, parts):
    """(line, absolute module path below symstab or 'paper_checks...') of every import."""
    tree = _tree(path)
    package = list(parts[:-1]) if parts[-1] != "__init__" else list(parts[:-1])
    for node in ast.walk(tree):
        if isinstance(node, ast.ImportFrom):
            if node.level:
                base = package[: len(package) - (node.level - 1)] if node.level > 1 else package
                target = base + (node.module.split(".") if node.module else [])
                names = [a.name for a in node.names] if not node.module else [None]
                for name in names:
                    yield node.lineno, ["symstab"] + target + ([name] if name else [])
            elif node.module:
                yield node.lineno, node.module.split(".")
        elif isinstance(node, ast.Import):
            for alias in node.names:
                yield node.lineno, alias.name.split(".")


MODULES = list(_modules())


@pytest.mark.parametrize("path, parts", MODULES, ids=["/".join(p) for _, p in MODULES])
def test_no_layer_imports_a_layer_above(path, parts):
    own = _layer(parts)
    for line, target in _imports(path, parts):
        if target[0] == "paper_checks":
            assert own == "front", (f"symstab/{'/'.join(parts)}.py:{line} imports {'.'.join(target)}: "
                                    f"only the front ends may use paper_checks")
            continue
        if target[0] != "symstab" or len(target) < 2:
            continue
        theirs = _layer(target[1:])
        assert RANK[theirs] <= RANK[own], (
            f"symstab/{'/'.join(parts)}.py:{line} ({own}) imports {'.'.join(target)} ({theirs}), "
            f"a layer above it")


#: The rooms of ``symstab.numeric`` in their order: a room may import its own
#: rank or lower.  ``paper`` (Table I's plane) is above every general room,
#: so nothing general leans on the paper.
NUMERIC_RANK = {"engine": 0, "loop": 1, "simulation": 2, "analysis": 3, "paper": 4}

#: Modules whose functions may import upward, and what: ``Loop``'s question
#: methods are pass-throughs to the module functions of the rooms above
#: (inside the method, never at module level), as python-control's
#: ``TransferFunction`` methods are.
FACADES = {("numeric", "loop", "sampled_loop"): {"simulation", "analysis"}}


def _room(parts):
    """The room of a numeric module (``parts`` below ``symstab``), or None outside numeric."""
    if parts[0] != "numeric" or len(parts) < 3:
        return None
    if parts[1] not in NUMERIC_RANK:
        raise AssertionError(f"symstab/{'/'.join(parts)}.py is in no room of numeric: "
                             f"put it in one of {sorted(NUMERIC_RANK)}")
    return parts[1]


def _nested_imports(path):
    """Line numbers of the imports inside a function body (lazy ones)."""
    tree = _tree(path)
    lines = set()
    for node in ast.walk(tree):
        if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
            lines |= {inner.lineno for inner in ast.walk(node)
                      if isinstance(inner, (ast.Import, ast.ImportFrom))}
    return lines


NUMERIC_MODULES = [(path, parts) for path, parts in MODULES if _room(parts)]


@pytest.mark.parametrize("path, parts", NUMERIC_MODULES, ids=["/".join(p) for _, p in NUMERIC_MODULES])
def test_numeric_rooms_import_downwards(path, parts):
    """engine < loop < simulation < analysis < paper; only front ends import the paper's room."""
    own = _room(parts)
    lazy = _nested_imports(path)
    allowed_up = FACADES.get(tuple(parts), set())
    for line, target in _imports(path, parts):
        if target[:2] != ["symstab", "numeric"] or len(target) < 3 or target[2] not in NUMERIC_RANK:
            continue
        theirs = target[2]
        if NUMERIC_RANK[theirs] <= NUMERIC_RANK[own]:
            continue
        assert theirs in allowed_up and line in lazy, (
            f"symstab/{'/'.join(parts)}.py:{line} ({own}) imports {'.'.join(target)} ({theirs}), "
            f"a room above it")


def test_only_front_ends_import_the_papers_room():
    for path, parts in MODULES:
        if _layer(parts) == "front" or _room(parts) == "paper":
            continue
        for line, target in _imports(path, parts):
            assert target[:3] != ["symstab", "numeric", "paper"], (
                f"symstab/{'/'.join(parts)}.py:{line} imports {'.'.join(target)}: only the front "
                f"ends, paper_checks and symstab/__init__.py use the paper's room")


def test_numeric_holds_only_rooms():
    """``symstab/numeric/`` has no module of its own: old paths are deprecated aliases."""
    flat = sorted(p.name for p in (PACKAGE / "numeric").glob("*.py") if p.name != "__init__.py")
    assert flat == []
    rooms = sorted(p.name for p in (PACKAGE / "numeric").iterdir() if (p / "__init__.py").exists())
    assert rooms == sorted(NUMERIC_RANK)


def test_no_two_library_modules_share_a_file_name():
    """``forms.py`` twice was two things of one name; CLI modules are named after their commands."""
    seen = {}
    for _, parts in MODULES:
        if parts[0] == "cli" or parts[-1] == "__init__":
            continue
        seen.setdefault(parts[-1], []).append("/".join(parts))
    assert {stem: where for stem, where in seen.items() if len(where) > 1} == {}


def test_every_layer_is_a_folder_and_every_module_in_one():
    folders = {p.name for p in PACKAGE.iterdir() if p.is_dir() and not p.name.startswith("__")}
    assert {"symbolic", "codegen", "proof", "numeric", "cli", "_generated"} <= folders
    for _, parts in MODULES:
        _layer(parts)


def test_the_test_folders_are_the_layers():
    """The tests mirror the package: ``tests/<layer>/`` for each layer folder, no other folder.

    The front ends' tests (``cli``, ``figures``, ``reproduce``) are in
    ``tests/cli``; the tests about the whole project (README, notebooks,
    layers, docstrings, the audit) at the top of ``tests/``.
    """
    tests = pathlib.Path(__file__).resolve().parent
    folders = {p.name for p in tests.iterdir() if p.is_dir() and not p.name.startswith((".", "_"))}
    layers = {p.name for p in PACKAGE.iterdir() if p.is_dir() and (p / "__init__.py").exists()
              and not p.name.startswith("_")}
    assert folders == layers == {"symbolic", "codegen", "proof", "numeric", "cli"}
    rooms = {p.name for p in (tests / "numeric").iterdir() if p.is_dir() and not p.name.startswith("_")}
    assert rooms == set(NUMERIC_RANK)
    assert sorted(p.name for p in (tests / "numeric").glob("*.py")) == []


def test_no_public_name_shadows_a_submodule():
    """``symstab.boundary`` is the function, and there is no module of that name to hide."""
    submodules = {p.stem for p in PACKAGE.glob("*.py")} | {
        p.name for p in PACKAGE.iterdir() if p.is_dir() and (p / "__init__.py").exists()}
    clash = sorted(name for name in symstab.__all__ if name in submodules)
    assert clash == []
    for layer in ("symbolic", "codegen", "proof", "numeric", "cli"):
        package = __import__(f"symstab.{layer}", fromlist=["__all__"])
        inner = {p.stem for p in (PACKAGE / layer).glob("*.py")}
        exported = set(getattr(package, "__all__", ()))
        assert not (exported & inner), f"symstab.{layer} exports a name that hides a submodule"


def test_paper_checks_uses_the_library_and_no_front_end():
    """No cycle: the front ends use paper_checks, so it must not use them."""
    root = PACKAGE.parent / "paper_checks"
    if not root.is_dir():
        pytest.skip("paper_checks is not installed beside the package")
    for path in sorted(root.glob("*.py")):
        tree = _tree(path)
        for node in ast.walk(tree):
            module = node.module if isinstance(node, ast.ImportFrom) else None
            names = [a.name for a in node.names] if isinstance(node, ast.Import) else [module or ""]
            for name in names:
                parts = (name or "").split(".")
                if parts[0] == "symstab" and len(parts) > 1:
                    assert parts[1] not in _FRONT, f"{path.name} imports a front end ({name})"


def test_every_public_name_still_works():
    """The names of symstab.__all__ before the layout, each still importable from symstab."""
    before = [
        "boundary", "coefficients", "pulse_transfer_function", "dimensionless_pulse_transfer_function",
        "IdentityResult", "check_identity", "assert_identity", "small_theta_limits",
        "characteristic_polynomial", "dimensionless_values", "closed_form_d0", "newton_form_gamma0",
        "theta_max", "theta_max_newton", "unit_circle_split", "Device", "PAPER_DEVICE",
        "BoundaryCurve", "arc_end_angle", "boundary_curve", "STABLE", "MARGINAL", "UNSTABLE",
        "classify", "is_stable", "spectral_radius", "StabilityRegion", "Limits", "limits",
        "BestVirtualMass", "best_virtual_mass", "Loop", "LoopBoundary", "LoopLimits", "load_loop",
    ]
    missing = [name for name in before if not hasattr(symstab, name) or name not in symstab.__all__]
    assert missing == []
    assert callable(symstab.boundary) and callable(symstab.theta_max)


# --------------------------------------------------------------------------
# No import cycle, no private name across modules

#: Private names a module may still take from another module of symstab or
#: paper_checks: ``{(importer, "source.name"): reason}``.  Keep it short: a
#: name another module needs is public, with a docstring, in one home.
PRIVATE_IMPORTS_ALLOWED = {}

_ROOTS = {"symstab": PACKAGE, "paper_checks": PACKAGE.parent / "paper_checks"}


def _module_names():
    """``{dotted name: path}`` of every module of symstab (generated kernels included) and paper_checks."""
    out = {}
    for root, folder in _ROOTS.items():
        if not folder.is_dir():
            continue
        for path in sorted(folder.rglob("*.py")):
            parts = path.relative_to(folder).with_suffix("").parts
            if parts[-1] == "__init__":
                parts = parts[:-1]
            out[".".join((root,) + parts)] = path
    return out


MODULE_NAMES = _module_names()


def _package_of(name, path):
    """The package a relative import of module ``name`` starts from."""
    return name if path.name == "__init__.py" else name.rpartition(".")[0]


def _module_of(dotted):
    """The longest prefix of ``dotted`` that is one of our modules, or None."""
    parts = dotted.split(".")
    for k in range(len(parts), 0, -1):
        candidate = ".".join(parts[:k])
        if candidate in MODULE_NAMES:
            return candidate
    return None


def _imports_of(name, path):
    """``(line, imported module, imported name or None)`` of every import in module ``name``.

    Module-level imports and those inside functions; relative ones resolved.
    ``from package import x`` where ``x`` is a submodule imports the
    submodule (not the package's ``__init__``), and its name is None.
    """
    tree = _tree(path)
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            for alias in node.names:
                target = _module_of(alias.name)
                if target is not None:
                    yield node.lineno, target, None, alias.asname
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                base = _package_of(name, path).split(".")
                base = base[: len(base) - (node.level - 1)]
                source = ".".join(base + ([node.module] if node.module else []))
            else:
                source = node.module or ""
            if _module_of(source) is None:
                continue
            for alias in node.names:
                child = f"{source}.{alias.name}"
                if child in MODULE_NAMES:
                    yield node.lineno, child, None, alias.asname or alias.name
                else:
                    yield node.lineno, _module_of(source), alias.name, None


def _graph():
    edges = {name: set() for name in MODULE_NAMES}
    for name, path in MODULE_NAMES.items():
        for _, target, _, _ in _imports_of(name, path):
            if target != name:
                edges[name].add(target)
    return edges


def _cycles(edges):
    """The strongly connected components of more than one module (iterative Tarjan), sorted."""
    index, low, on_stack, stack, found = {}, {}, set(), [], []
    counter = 0
    for start in sorted(edges):
        if start in index:
            continue
        work = [(start, iter(sorted(edges[start])))]
        index[start] = low[start] = counter
        counter += 1
        stack.append(start)
        on_stack.add(start)
        while work:
            node, children = work[-1]
            for child in children:
                if child not in index:
                    index[child] = low[child] = counter
                    counter += 1
                    stack.append(child)
                    on_stack.add(child)
                    work.append((child, iter(sorted(edges[child]))))
                    break
                if child in on_stack:
                    low[node] = min(low[node], index[child])
            else:
                work.pop()
                if work:
                    parent = work[-1][0]
                    low[parent] = min(low[parent], low[node])
                if low[node] == index[node]:
                    component = []
                    while True:
                        member = stack.pop()
                        on_stack.discard(member)
                        component.append(member)
                        if member == node:
                            break
                    if len(component) > 1:
                        found.append(sorted(component))
    return sorted(found)


def test_the_cycle_finder_finds_cycles():
    """The finder on a made-up graph: a 3-cycle, a 2-cycle, a self-contained chain."""
    edges = {"a": {"b"}, "b": {"c"}, "c": {"a", "d"}, "d": {"e"}, "e": {"d"}, "f": {"a"}, "g": set()}
    assert _cycles(edges) == [["a", "b", "c"], ["d", "e"]]


@pytest.mark.parametrize("root", sorted(_ROOTS))
def test_no_import_cycle(root):
    """No module of ``root`` imports itself through others (imports inside functions included).

    A package ``__init__`` that re-exports its children is no cycle: a child
    that imports a sibling reaches it directly, not through the package.
    """
    if not _ROOTS[root].is_dir():
        pytest.skip(f"{root} is not installed beside the package")
    cycles = [c for c in _cycles(_graph()) if any(m.split(".")[0] == root for m in c)]
    for cycle in cycles:
        print("import cycle: " + " <-> ".join(cycle))
    assert cycles == [], f"{len(cycles)} import cycle(s): " + "; ".join(
        " <-> ".join(c) for c in cycles)


def _private_imports():
    """``(importer, line, source module, name)`` of every private name taken from another module.

    ``from .x import _y`` (single or parenthesised, at any depth), and
    ``module._y`` on a module imported as a name (``from . import x``,
    ``import a.b as x``).  A private module (``from . import _common``) is a
    module, not a private name; dunders are not private.
    """
    def private(text):
        return text.startswith("_") and not (text.startswith("__") and text.endswith("__"))

    found = []
    for name, path in MODULE_NAMES.items():
        tree = _tree(path)
        aliases = {}
        for line, target, imported, alias in _imports_of(name, path):
            if imported is not None and private(imported) and target != name:
                found.append((name, line, target, imported))
            elif imported is None and alias is not None and target != name:
                aliases[alias] = target
        for node in ast.walk(tree):
            if (isinstance(node, ast.Attribute) and isinstance(node.value, ast.Name)
                    and node.value.id in aliases and private(node.attr)):
                found.append((name, node.lineno, aliases[node.value.id], node.attr))
    return sorted(set(found))


def test_no_private_name_is_imported_across_modules():
    """A name used by another module is public (documented, in one home), not ``_private``."""
    found = _private_imports()
    offenders = [(importer, line, source, imported) for importer, line, source, imported in found
                 if (importer, f"{source}.{imported}") not in PRIVATE_IMPORTS_ALLOWED]
    for importer, line, source, imported in offenders:
        print(f"{importer}:{line} imports {source}.{imported}")
    stale = sorted(set(PRIVATE_IMPORTS_ALLOWED) - {(i, f"{s}.{n}") for i, _, s, n in found})
    assert stale == [], f"allowlist entries no longer needed: {stale}"
    assert offenders == [], f"{len(offenders)} private name(s) imported across modules"


def test_the_cli_is_one_module_per_command_over_shared_modules():
    """Each command is a module with ``register`` and ``run``; none imports another command.

    ``symstab.cli.commands`` builds the parser from
    :func:`~symstab.cli.commands.command_modules`; what two commands share
    lives in a shared module of ``symstab/cli/``.
    """
    from symstab.cli import commands

    modules = commands.command_modules()
    names = {module.__name__ for module in modules}
    assert len(names) == len(modules) == len(commands.COMMAND_NAMES)
    for module in modules:
        assert callable(module.register) and callable(module.run), module.__name__
    parser_commands = set(commands.build_parser()._subparsers._group_actions[0].choices)
    assert parser_commands == {name.rpartition(".")[2] for name in names}
    crossing = sorted(f"{name} imports {target} (line {line})"
                      for name in names
                      for line, target, _, _ in _imports_of(name, MODULE_NAMES[name])
                      if target in names and target != name)
    assert crossing == [], crossing


def _matplotlib_imports(path, parts):
    """``[(line, module)]`` of the imports of matplotlib in one module (lazy ones included)."""
    return [(line, ".".join(target)) for line, target in _imports(path, parts)
            if target[0] == "matplotlib"]


#: The front ends that compute what is drawn and leave the drawing to :mod:`symstab.drawing`.
COMPUTING_FRONT_ENDS = [(path, parts) for path, parts in MODULES
                        if parts[0] == "cli" or parts == ("figures",)]


@pytest.mark.parametrize("path, parts", COMPUTING_FRONT_ENDS,
                         ids=["/".join(p) for _, p in COMPUTING_FRONT_ENDS])
def test_the_cli_and_the_figures_draw_nothing_themselves(path, parts):
    """The commands and the figures compute; :mod:`symstab.drawing` draws every PNG."""
    found = _matplotlib_imports(path, parts)
    assert found == [], (f"symstab/{'/'.join(parts)}.py imports matplotlib "
                         f"({', '.join(f'{m} on line {n}' for n, m in found)}): draw in "
                         f"symstab/drawing.py")


def test_the_matplotlib_finder_finds_lazy_imports(tmp_path):
    source = ("import numpy\n\ndef draw():\n    from matplotlib.patches import Patch\n"
              "    import matplotlib.pyplot as plt\n")
    path = tmp_path / "fake.py"
    path.write_text(source, encoding="utf-8")
    assert _matplotlib_imports(path, ("cli", "fake")) == [(4, "matplotlib.patches"),
                                                          (5, "matplotlib.pyplot")]


# --------------------------------------------------------------------------
# No private attribute reached on another module's object

#: Private attribute names that are a third party's protocol, not our privacy:
#: mpmath's number internals, namedtuple's API, CPython's own.
PROTOCOL_ATTRIBUTES = {"_mpf_", "_mpc_", "_mpi_", "_asdict", "_replace", "_fields", "_make",
                       "_exit", "_getframe", "_current_frames", "_subparsers", "_group_actions",
                       "_print"}

#: ``{(module, attribute): reason}`` of the reaches left, each with its reason.
PRIVATE_ATTRIBUTES_ALLOWED = {
    ("symstab.symbolic.derivation_cache", "_prec"): "a SymPy Float's binary precision, which the "
    "cache must store to give back the same Float (SymPy has no public accessor)",
    ("symstab.symbolic.derivation_cache", "_new"): "sympy.Float._new rebuilds a Float from its "
    "mpf tuple and precision without rounding through a decimal string",
}


def _defined_private_names(tree):
    """Private names a module defines itself: functions, classes, ``x._y = ...`` and class bodies."""
    names = set()
    for node in ast.walk(tree):
        if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef, ast.ClassDef)):
            names.add(node.name)
        elif isinstance(node, ast.Attribute) and isinstance(node.ctx, ast.Store):
            names.add(node.attr)
        elif isinstance(node, ast.Name) and isinstance(node.ctx, ast.Store):
            names.add(node.id)
        elif isinstance(node, ast.AnnAssign) and isinstance(node.target, ast.Name):
            names.add(node.target.id)
    return names


def _private_attribute_reaches():
    """``(module, line, expression)`` of every ``obj._name`` that reaches into another module.

    ``self._x`` and ``cls._x`` are the object's own; ``other._x`` where this
    module defines ``_x`` (its own class's attribute, read on a second
    instance) is too.  Anything else is a reach into another module's
    private state: make the name public, documented, in its home.
    """
    found = []
    for name, path in MODULE_NAMES.items():
        if "_generated" in name.split("."):
            continue
        tree = _tree(path)
        own = _defined_private_names(tree)
        for node in ast.walk(tree):
            if not isinstance(node, ast.Attribute):
                continue
            attr = node.attr
            if not attr.startswith("_") or (attr.startswith("__") and attr.endswith("__")):
                continue
            if attr in PROTOCOL_ATTRIBUTES or attr in own:
                continue
            if isinstance(node.value, ast.Name) and node.value.id in {"self", "cls"}:
                continue
            found.append((name, node.lineno, ast.unparse(node)))
    return sorted(set(found))


def test_no_private_attribute_is_reached_across_modules():
    found = _private_attribute_reaches()
    offenders = [(m, line, expr) for m, line, expr in found
                 if (m, expr.rpartition(".")[2]) not in PRIVATE_ATTRIBUTES_ALLOWED]
    for module, line, expr in offenders:
        print(f"{module}:{line} reaches {expr}")
    assert offenders == [], f"{len(offenders)} private attribute(s) reached across modules"


def test_the_reach_finder_finds_reaches(tmp_path):
    """The finder on made-up modules: a reach, its own attribute, self, a protocol name."""
    source = ("class A:\n    def __init__(self):\n        self._mine = 1\n"
              "    def same(self, other):\n        return other._mine\n"
              "def reach(loop, x):\n    return loop._environment_parts, x._mpf_, len(x)\n")
    tree = ast.parse(source)
    own = _defined_private_names(tree)
    reaches = [ast.unparse(n) for n in ast.walk(tree) if isinstance(n, ast.Attribute)
               and n.attr.startswith("_") and n.attr not in own | PROTOCOL_ATTRIBUTES
               and not (n.attr.startswith("__") and n.attr.endswith("__"))]
    assert reaches == ["loop._environment_parts"]


@pytest.mark.parametrize("package", ["numeric", "codegen"])
def test_a_moved_module_still_imports_with_a_warning(package):
    """The old flat paths are the new modules, one release long, with a DeprecationWarning."""
    import importlib
    import sys

    moved = importlib.import_module(f"symstab.{package}").MOVED
    for old, new in sorted(moved.items()):
        sys.modules.pop(f"symstab.{package}.{old}", None)
        with pytest.warns(DeprecationWarning, match=new.replace(".", r"\.")):
            module = importlib.import_module(f"symstab.{package}.{old}")
        assert module is importlib.import_module(new)
        assert not (PACKAGE / package / f"{old}.py").exists()


# --------------------------------------------------------------------------
# Short functions, and Loop a facade

#: The most lines of code a function of symstab may have (outside
#: ``_generated``): docstrings, comments and blank lines not counted.  A longer
#: algorithm is a few named steps, each with its docstring and its test.
MAX_CODE_LINES = 80

#: The most lines ``Loop``'s class body may have, docstrings included: the
#: model and its pass-throughs, the questions computed in module functions.
MAX_LOOP_LINES = 500


def _code_lines(lines, node):
    """Lines of ``node`` that are code: not blank, not a comment, not in a docstring."""
    docstrings = set()
    for inner in ast.walk(node):
        body = getattr(inner, "body", None)
        if (isinstance(inner, (ast.FunctionDef, ast.AsyncFunctionDef, ast.ClassDef)) and body
                and isinstance(body[0], ast.Expr) and isinstance(body[0].value, ast.Constant)
                and isinstance(body[0].value.value, str)):
            docstrings |= set(range(body[0].lineno, body[0].end_lineno + 1))
    return sum(1 for i in range(node.lineno, node.end_lineno + 1)
               if i not in docstrings and lines[i - 1].strip()
               and not lines[i - 1].strip().startswith("#"))


def _long_functions(path, limit):
    source = path.read_text(encoding="utf-8")
    lines = source.split("\n")
    return [(node.name, node.lineno, _code_lines(lines, node))
            for node in ast.walk(ast.parse(source))
            if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef))
            and _code_lines(lines, node) > limit]


def test_no_function_is_over_80_lines_of_code():
    found = [f"symstab/{'/'.join(parts)}.py:{line} {name} ({count} lines of code)"
             for path, parts in MODULES for name, line, count in _long_functions(path, MAX_CODE_LINES)]
    assert found == []


def test_the_line_counter_counts_code_only(tmp_path):
    """A docstring, comments and blank lines are not code; statements are."""
    body = "\n".join(f"    x{i} = {i}" for i in range(MAX_CODE_LINES - 1))
    # f: its def line and 79 statements, 80 lines of code; g: one more.
    source = (f'def f():\n    """Doc.\n\n    More doc.\n    """\n    # a comment\n\n{body}\n'
              f"def g():\n{body}\n    return x0\n")
    path = tmp_path / "m.py"
    path.write_text(source, encoding="utf-8")
    assert [(name, count) for name, _, count in _long_functions(path, MAX_CODE_LINES)] == [
        ("g", MAX_CODE_LINES + 1)]


def test_loop_is_a_facade():
    """``Loop``: the model, its evaluation and pass-throughs, under 500 lines."""
    path = PACKAGE / "numeric" / "loop" / "sampled_loop.py"
    (node,) = [n for n in ast.parse(path.read_text(encoding="utf-8")).body
               if isinstance(n, ast.ClassDef) and n.name == "Loop"]
    assert node.end_lineno - node.lineno + 1 < MAX_LOOP_LINES
