"""The derivation of a loop, cached on disk as data that is read back without evaluation.

Deriving a loop (the ZOH by residues, the loop polynomial, which parameters
enter it affinely) takes seconds to tens of seconds in SymPy and gives the
same expressions every time for the same plant and environment.
:class:`DerivationCache` keeps them in the loops' cache folder
(:func:`cache_dir`, shared with the generated kernels), one JSON file per
derivation, named by a hash of exactly its inputs: the plant and the
environment as SymPy builds them (``srepr``: structure and assumptions), the
layout version :data:`LAYOUT`, the SymPy version, and the source of the
modules that derive (:data:`DERIVING_MODULES`), so an edit of the derivation
is a new file.

An entry is data, never code: an expression is stored as a tree of SymPy
class names from a fixed allow-list (:data:`NODES`) and read back by
building each node from its class and its children
(:func:`expression_from_tree`): no ``eval``, ``exec``, ``sympify``,
``parse_expr`` or pickle touches the file, and a symbol must be one of the
loop's.  A tree is written only if reading it back gives the very
expression it came from (``srepr`` equal), so a derivation from the cache
is the derivation.  A file that is not valid JSON, names another key, fails
its checksum or holds a node outside the allow-list is ignored and derived
again (and rewritten); where the folder cannot be written, nothing is
cached.  Nor is a well-formed entry trusted blindly: the loop checks each
polynomial it reads at one point against an independent computation (the
ZOH by the matrix exponential at 30 digits, the environment as parsed, the
loop polynomial as their product; ``LoopModel._derived``) and derives again
what disagrees.  The affine decisions are protected by the checksum only.
"""

import functools
import hashlib
import json
import os
import pathlib
import tempfile

import sympy as sp

__all__ = ["CACHE_ENV", "LAYOUT", "NODES", "DERIVING_MODULES", "cache_dir", "derivation_key",
           "expression_tree", "expression_from_tree", "DerivationCache"]

CACHE_ENV = "SYMSTAB_CACHE_DIR"
#: Bumped when what is cached or how it is stored changes (part of the key).
LAYOUT = "loop-derivation-1"
#: The modules whose source is part of the key: they derive what is cached.
DERIVING_MODULES = ("loop_assembly.py", "discretize.py", "derivation_cache.py")

#: The classes an entry may name, by their ``__name__``: arithmetic and the
#: elementary functions a pulse transfer function is written with.
NODES = {cls.__name__: cls for cls in (
    sp.Add, sp.Mul, sp.Pow, sp.exp, sp.log, sp.sin, sp.cos, sp.tan, sp.sinh, sp.cosh, sp.tanh,
    sp.Abs, sp.re, sp.im)}
#: Constants, by their ``srepr``.
_CONSTANTS = {"pi": sp.pi, "E": sp.E, "I": sp.I, "oo": sp.oo, "-oo": -sp.oo, "zoo": sp.zoo,
              "nan": sp.nan}


def cache_dir():
    """The folder of symstab's caches (it may not exist yet).

    ``$SYMSTAB_CACHE_DIR``, else ``$XDG_CACHE_HOME/symstab``, else
    ``~/.cache/symstab``.

    Returns
    -------
    pathlib.Path
    """
    if os.environ.get(CACHE_ENV):
        return pathlib.Path(os.environ[CACHE_ENV])
    base = os.environ.get("XDG_CACHE_HOME") or os.path.join(os.path.expanduser("~"), ".cache")
    return pathlib.Path(base) / "symstab"


@functools.lru_cache(maxsize=None)
def _source_digest():
    here = pathlib.Path(__file__).resolve().parent
    h = hashlib.sha256()
    for name in DERIVING_MODULES:
        h.update(name.encode())
        h.update((here / name).read_bytes())
    return h.hexdigest()


def derivation_key(plant, environment):
    """The hash that names the cached derivation of a loop.

    Parameters
    ----------
    plant, environment : sympy.Expr
        As the loop holds them (parsed, with its real symbols).

    Returns
    -------
    str
        40 hexadecimal digits.
    """
    h = hashlib.sha256()
    for part in (LAYOUT, sp.__version__, _source_digest(), sp.srepr(plant),
                 sp.srepr(environment)):
        h.update(part.encode("utf-8"))
        h.update(b"\0")
    return h.hexdigest()[:40]


def expression_tree(expr):
    """``expr`` as a JSON-able tree of allowed class names, numbers and symbol names.

    Parameters
    ----------
    expr : sympy.Expr

    Returns
    -------
    list
        ``["Symbol", name]``, ``["Integer", digits]``, ``["Rational", p, q]``,
        ``["Float", sign, mantissa (hex), exponent, bits, precision]``,
        ``["Constant", srepr]`` or ``[class name, child, ...]``.

    Raises
    ------
    ValueError
        For a node outside :data:`NODES` (the expression is then not cached).
    """
    if isinstance(expr, sp.Symbol) and type(expr) is sp.Symbol:
        return ["Symbol", expr.name]
    if isinstance(expr, sp.Integer):
        return ["Integer", str(int(expr))]
    if isinstance(expr, sp.Rational):
        return ["Rational", str(expr.p), str(expr.q)]
    if isinstance(expr, sp.Float):
        sign, man, exp, bc = expr._mpf_
        return ["Float", int(sign), hex(int(man)), int(exp), int(bc), int(expr._prec)]
    if expr.is_Atom and sp.srepr(expr) in _CONSTANTS:
        return ["Constant", sp.srepr(expr)]
    name = type(expr).__name__
    if NODES.get(name) is not type(expr):
        raise ValueError(f"cannot store a {name} in the derivation cache")
    return [name] + [expression_tree(a) for a in expr.args]


def _number_text(text, what):
    if not isinstance(text, str) or not text.lstrip("-").isdigit() or len(text) > 10000:
        raise ValueError(f"derivation cache: a {what} must be decimal digits")
    return int(text)


def expression_from_tree(tree, symbols):
    """The expression of an :func:`expression_tree`, built node by node, never evaluated as text.

    Parameters
    ----------
    tree : list
    symbols : dict
        ``{name: sympy.Symbol}``: the only symbols the tree may name.

    Returns
    -------
    sympy.Expr

    Raises
    ------
    ValueError
        For anything but the nodes, numbers and symbols allowed.
    """
    if not isinstance(tree, list) or not tree or not isinstance(tree[0], str):
        raise ValueError("derivation cache: a node must be a list starting with its kind")
    kind, rest = tree[0], tree[1:]
    if kind == "Symbol":
        if len(rest) != 1 or not isinstance(rest[0], str) or rest[0] not in symbols:
            raise ValueError(f"derivation cache: unknown symbol {rest!r}")
        return symbols[rest[0]]
    if kind == "Integer" and len(rest) == 1:
        return sp.Integer(_number_text(rest[0], "integer"))
    if kind == "Rational" and len(rest) == 2:
        return sp.Rational(_number_text(rest[0], "numerator"), _number_text(rest[1], "denominator"))
    if kind == "Float" and len(rest) == 5 and all(isinstance(v, int) and not isinstance(v, bool)
                                                 for v in rest[:1] + rest[2:]):
        sign, man, exp, bc, prec = rest
        if (sign not in (0, 1) or not isinstance(man, str) or not man.startswith("0x")
                or not 0 < prec <= 4096 or not 0 <= bc <= 4096 or abs(exp) > 10**6):
            raise ValueError("derivation cache: a malformed float")
        mantissa = int(man, 16)
        if mantissa.bit_length() != bc or (mantissa and not mantissa % 2):
            raise ValueError("derivation cache: a malformed float")
        return sp.Float._new((sign, mantissa, exp, bc), prec)
    if kind == "Constant" and len(rest) == 1 and rest[0] in _CONSTANTS:
        return _CONSTANTS[rest[0]]
    if kind in NODES and rest:
        return NODES[kind](*[expression_from_tree(a, symbols) for a in rest])
    raise ValueError(f"derivation cache: node {kind!r} is not allowed")


def _checksum(payload):
    return hashlib.sha256(json.dumps(payload, sort_keys=True).encode("utf-8")).hexdigest()


class DerivationCache:
    """The cached derivation of one loop: named expression lists and decisions.

    Parameters
    ----------
    plant, environment : sympy.Expr
        The loop's, as parsed: they make the key (:func:`derivation_key`).
    symbols : dict
        ``{name: sympy.Symbol}`` of the loop (``s``, ``z`` and ``T``
        included): the symbols an entry may name.

    Notes
    -----
    :meth:`get` returns what :meth:`put` stored, in this process or an
    earlier one; every :meth:`put` rewrites the file atomically.
    """

    MISSING = object()

    def __init__(self, plant, environment, symbols):
        self.key = derivation_key(plant, environment)
        self._symbols = dict(symbols)
        self.path = cache_dir() / "derivations" / f"loop_{self.key}.json"
        self._payload, self._values = self._read()

    def _read(self):
        try:
            document = json.loads(self.path.read_text(encoding="utf-8"))
            payload = document["payload"]
            if (document.get("key") != self.key or not isinstance(payload, dict)
                    or document.get("checksum") != _checksum(payload)):
                return {}, {}
            # Everything is read back now: one bad node discards the whole entry.
            return payload, {name: self._decode(entry) for name, entry in payload.items()}
        except (OSError, ValueError, KeyError, TypeError, AttributeError, RecursionError):
            return {}, {}

    def _decode(self, entry):
        if not isinstance(entry, list) or len(entry) != 2:
            raise ValueError("derivation cache: an entry is [kind, value]")
        kind, value = entry
        if kind == "bool" and isinstance(value, bool):
            return value
        if kind == "none" and value is None:
            return None
        if kind == "lists" and isinstance(value, list) and all(isinstance(v, list) for v in value):
            return tuple([expression_from_tree(t, self._symbols) for t in v] for v in value)
        raise ValueError(f"derivation cache: an entry of kind {kind!r}")

    def get(self, name):
        """The value stored under ``name``, or :attr:`MISSING`.

        Parameters
        ----------
        name : str

        Returns
        -------
        bool, None, tuple of lists of sympy.Expr, or MISSING
        """
        return self._values.get(name, self.MISSING)

    def put(self, name, value):
        """Store ``value`` (a bool, None, or a sequence of lists of expressions) under ``name``.

        A value whose expressions do not come back identical from their
        trees, or hold a node outside :data:`NODES`, is not stored.

        Parameters
        ----------
        name : str
        value : bool, None or sequence of lists of sympy.Expr
        """
        if isinstance(value, bool):
            entry = ["bool", value]
        elif value is None:
            entry = ["none", None]
        else:
            try:
                trees = [[expression_tree(e) for e in part] for part in value]
            except (ValueError, RecursionError):
                return
            entry = ["lists", trees]
            try:
                back = self._decode(entry)
            except (ValueError, RecursionError):
                return
            if [[sp.srepr(e) for e in part] for part in value] != [
                    [sp.srepr(e) for e in part] for part in back]:
                return
            value = back
        self._payload[name] = entry
        self._values[name] = value
        document = {"key": self.key, "layout": LAYOUT, "payload": self._payload,
                    "checksum": _checksum(self._payload)}
        folder = self.path.parent
        try:
            folder.mkdir(parents=True, exist_ok=True)
            fd, tmp = tempfile.mkstemp(dir=folder, prefix=f".{self.path.name}.", suffix=".tmp")
            try:
                with os.fdopen(fd, "w", encoding="utf-8") as f:
                    # dumps, not dump: the same text by the C encoder (dump streams through
                    # the pure-Python one, about 7 times slower on a 200 kB entry).
                    f.write(json.dumps(document, sort_keys=True))
                os.replace(tmp, self.path)
            except BaseException:
                pathlib.Path(tmp).unlink(missing_ok=True)
                raise
        except OSError:
            pass   # an unwritable cache: the derivation is simply not kept
