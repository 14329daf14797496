"""Every public function documents every parameter (after python-control's docstrings_test).

For each name in ``symstab.__all__`` that is a function, a class or a
class's public method, the docstring must exist, and each parameter of its
signature (``self``, ``cls`` and ``*args``/``**kwargs`` collectors apart)
must appear in its numpydoc ``Parameters`` section (a dataclass's in its
``Attributes``), by name or in a shared
entry such as ``alpha, beta, gamma : float``.  A ``**values``-style
collector must be named in the section as ``**values``.

A method that passes through to a module function (its docstring says
"See :func:`symstab....`", python-control's ``LTI.step_response``) is
documented there: its parameters are looked up in that function's
section (and its own, for a parameter it keeps alone), and the function
is checked as well.
"""

import importlib
import inspect
import re

import pytest

import symstab


def _public_callables():
    seen = set()
    for name in symstab.__all__:
        obj = getattr(symstab, name)
        if inspect.isclass(obj):
            if obj.__module__.startswith("symstab") and obj not in seen:
                seen.add(obj)
                yield name, obj
                for attr, member in vars(obj).items():
                    if attr.startswith("_") or not inspect.isfunction(member):
                        continue
                    yield f"{name}.{attr}", member
        elif inspect.isfunction(obj) and obj not in seen:
            seen.add(obj)
            yield name, obj


def _documented(doc, section="Parameters"):
    """Names listed in a section (Parameters, Attributes) of a numpydoc docstring."""
    match = re.search(r"(?:^|\n)\s*" + section + r"\n\s*-+\n(.*?)(\n\s*\n\s*[A-Z][a-z]+\n\s*-+\n|\Z)",
                      doc, re.S)
    if not match:
        return set()
    names = set()
    for line in match.group(1).splitlines():
        head = re.match(r"\s*([*\w][\w, *]*?)\s*(:|$)", line)
        if head and not line.startswith(" " * 8):
            for part in head.group(1).split(","):
                names.add(part.strip())
    return names


#: The "See :func:`...`" of a pass-through method's docstring.
SEE = re.compile(r"^See :func:`(symstab\.[\w.]+)`", re.M)


def _target(doc):
    """The module function a pass-through's docstring names, or None."""
    match = SEE.search(doc or "")
    if not match:
        return None
    module, _, name = match.group(1).rpartition(".")
    return getattr(importlib.import_module(module), name)


def _with_targets(callables):
    """``callables`` and the module functions their pass-throughs name, each once."""
    out = dict(callables)
    for obj in list(out.values()):
        target = _target(inspect.getdoc(obj))
        if target is not None:
            out.setdefault(f"{target.__module__}.{target.__name__}", target)
    return out.items()


CALLABLES = sorted(_with_targets(_public_callables()), key=lambda item: item[0])


@pytest.mark.parametrize("name, obj", CALLABLES, ids=[n for n, _ in CALLABLES])
def test_every_parameter_is_documented(name, obj):
    doc = inspect.getdoc(obj)
    assert doc, f"{name} has no docstring"
    target = obj.__init__ if inspect.isclass(obj) else obj
    # An exception or warning takes its message (a built-in exception's constructor).
    if inspect.isclass(obj) and (target is object.__init__ or issubclass(obj, BaseException)
                                 and "__init__" not in vars(obj)):
        return
    try:
        signature = inspect.signature(target)
    except (TypeError, ValueError):
        return
    wanted = []
    for p in signature.parameters.values():
        if p.name in ("self", "cls"):
            continue
        if p.kind is p.VAR_POSITIONAL:
            continue
        wanted.append(f"**{p.name}" if p.kind is p.VAR_KEYWORD else p.name)
    if not wanted:
        return
    documented = _documented(doc)
    see = _target(doc)
    if see is not None:
        assert see is not obj and callable(see), f"{name}: names no function to see"
        documented |= _documented(inspect.getdoc(see) or "")
    if inspect.isclass(obj):
        # A dataclass documents its fields as Attributes.
        documented |= _documented(doc, "Attributes")
        documented |= _documented(inspect.getdoc(obj.__init__) or "")
    missing = [w for w in wanted if w not in documented]
    assert not missing, f"{name}: parameters not documented: {', '.join(missing)}"
