"""Loop files: a loop, its default values and their units, in a small TOML file.

::

    name = "paper"
    description = "The paper's device: a mass with viscous friction"
    plant = "1/(m*s**2 + b*s)"
    environment = "K + B*(z - 1)/(T*z) + M*(z - 1)**2/(T**2*z**2)"
    plane = ["B", "K"]              # optional: the default (x, y) plane
    actuator = "1"                  # optional: command to force on the mass
                                    # (where Coulomb friction acts)

    [parameters]
    m = { value = 0.0128, unit = "kg" }
    b = { value = 0.0324, unit = "N s/m" }
    T = { value = 1, unit = "ms" }  # converted: T = 0.001 s
    d = { value = 0, unit = "samples" }  # 40.5: a fraction of a period more
    # or the delay in time instead: Td = { value = 40.5, unit = "ms" }
    K = 300.0                       # a bare number: taken in SI, unchecked
    B = { value = 0.5, unit = "N s/m", min = 0 }   # a bound, checked

(``examples/loops/lowpass_velocity.toml`` bounds its filter's cut-off by the
Nyquist frequency: ``below = "1/(2*T)"``.)

:func:`load_loop` reads one into a :class:`symstab.Loop`; every mistake is
a :class:`ValueError` that names the file and the key.  Every value with a
unit is converted to SI with pint, its dimension checked against the loop,
and its bounds checked (:mod:`symstab.numeric.loop.quantities`); the loop holds
the SI values (``defaults``) and SI units (``units``), and what the file
wrote in ``loop.file_parameters``.

A loop file is data, exchanged between colleagues, and nothing in it is
run: the plant and the environment are built from their syntax tree
(numbers, parameter names, ``+ - * / **``, ``exp``, ``sqrt``), never
evaluated, a decimal in them being the exact rational it writes (``0.25`` is
1/4); ``name`` is a word of 1 to 64 ASCII letters, digits, ``_``, ``-``
and ``.`` (it becomes a file stem; without it the file's stem is used, made
such a word); ``description`` and every unit are one line of printable text;
a parameter's name is an ASCII identifier.  Anything else is refused.
"""

import pathlib
import re
import sys

if sys.version_info >= (3, 11):
    import tomllib
else:   # pragma: no cover - Python 3.10
    import tomli as tomllib

from .quantities import check_loop_units, read_parameters
from .sampled_loop import Loop

__all__ = ["load_loop", "parse_loop_text"]

#: The largest loop file read (a loop file is a few hundred bytes; this
#: stops ``/dev/zero`` or a wrong path from filling the memory).
MAX_FILE_BYTES = 1 << 20

_KEYS = {"name", "description", "plant", "environment", "plane", "parameters", "actuator"}


def _default_name(source):
    """A loop's name when its file gives none: the file's stem, made a word.

    The user did not write it, so it is not refused: the characters
    :data:`symstab.symbolic.loop_assembly.NAME_PATTERN` does not allow become ``_``.
    """
    stem = re.sub(r"[^A-Za-z0-9_.-]+", "_", pathlib.Path(source).stem).strip("_.-")[:64]
    return stem or "loop"


def parse_loop_text(text, *, source="<loop file>"):
    """Build a :class:`Loop` from the text of a loop file.

    Raises
    ------
    ValueError
        For invalid TOML, a missing or unknown key, a value that is not a
        finite number, or a plant or environment the loop refuses.
    """
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise ValueError(f"{source}: not valid TOML: {exc}") from None
    unknown = set(data) - _KEYS
    if unknown:
        raise ValueError(f"{source}: unknown key(s) {', '.join(sorted(unknown))}; "
                         f"allowed: {', '.join(sorted(_KEYS))}")
    for key in ("plant", "environment"):
        if not isinstance(data.get(key), str):
            raise ValueError(f"{source}: {key!r} must be given as a string")
    for key in ("name", "description", "actuator"):
        if key in data and not isinstance(data[key], str):
            raise ValueError(f"{source}: {key!r} must be a string, got {type(data[key]).__name__}")
    # Every value in SI, each unit read by pint (symstab.numeric.loop.quantities).
    values, units, file_values, bounds = read_parameters(data.get("parameters", {}),
                                                         source=source)
    # Td is in seconds by definition (Loop takes no unit for it): its unit
    # was checked to be a time and converted; the echo keeps it.
    units.pop("Td", None)
    plane = data.get("plane")
    if plane is not None and not (isinstance(plane, list) and len(plane) == 2
                                  and all(isinstance(p, str) for p in plane)):
        raise ValueError(f"{source}: 'plane' must be two parameter names, e.g. [\"B\", \"K\"]")
    try:
        loop = Loop(data["plant"], data["environment"], values=values, units=units,
                    name=data.get("name", _default_name(source)),
                    description=data.get("description", ""), plane=plane,
                    actuator=data.get("actuator"))
    except (TypeError, ValueError) as exc:
        raise ValueError(f"{source}: {exc}") from None
    # What the file wrote (units, bounds) beside the SI values the loop holds:
    # the CLI echoes it and converts --set with it.
    loop.file_parameters = check_loop_units(loop, file_values, bounds, source=source)
    return loop


def load_loop(path):
    """Read a loop file (TOML) into a :class:`Loop` with its default values in SI.

    The values the file gives with a unit are converted to SI (and their
    dimensions and bounds checked); ``loop.units`` names the SI units and
    ``loop.file_parameters`` keeps what the file wrote
    (:class:`symstab.numeric.loop.quantities.FileParameters`).

    Parameters
    ----------
    path : str or path-like

    Raises
    ------
    ValueError
        If the file cannot be read or is not a valid loop file (the message
        names the file).
    """
    path = pathlib.Path(path)
    try:
        with open(path, "rb") as fh:
            data = fh.read(MAX_FILE_BYTES + 1)
        if len(data) > MAX_FILE_BYTES:
            raise ValueError(f"loop file {str(path)!r} is larger than {MAX_FILE_BYTES} bytes: "
                             f"not a loop file")
        text = data.decode("utf-8")
    except OSError as exc:
        raise ValueError(f"cannot read loop file {str(path)!r}: {exc.strerror or exc}") from None
    except UnicodeDecodeError:
        raise ValueError(f"loop file {str(path)!r} is not UTF-8 text") from None
    return parse_loop_text(text, source=str(path))
