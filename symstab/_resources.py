"""Resource limits, in one place: memory, delay, grid and step counts.

Every entry point that allocates in proportion to its input estimates the
memory first and refuses, with a :class:`ValueError` that names the limit and
how to raise it, what would not fit; grid work is cut into chunks of
:data:`CHUNK_BYTES` so that peak memory does not grow with the grid.

The limits come from environment variables, read at each call so that a
test or a user can change them without re-importing:

``SYMSTAB_MEMORY_LIMIT``
    Largest single working set, in bytes or with a suffix ``K``, ``M``,
    ``G`` (powers of 1024); default ``2G``.
``SYMSTAB_MAX_DELAY``
    Largest loop delay ``d`` in samples; default 10000.  Classification is
    O(d) per point and the region engine a little more, so larger delays are
    slow rather than impossible.
``SYMSTAB_MAX_STEPS``
    Most sampling periods of one simulation; default 10 million (a period
    costs tens of microseconds, so that is minutes per point).  The
    simulator's default horizon is always allowed
    (:func:`symstab.numeric.paper.simulate.max_steps`).
"""

import os

__all__ = [
    "MEMORY_LIMIT_ENV", "MAX_DELAY_ENV", "MAX_STEPS_ENV", "CHUNK_BYTES",
    "memory_limit", "max_delay", "max_steps", "format_bytes", "check_memory", "chunk_slices",
]

MEMORY_LIMIT_ENV = "SYMSTAB_MEMORY_LIMIT"
MAX_DELAY_ENV = "SYMSTAB_MAX_DELAY"
MAX_STEPS_ENV = "SYMSTAB_MAX_STEPS"
_DEFAULT_MEMORY_LIMIT = 2 * 2**30
_DEFAULT_MAX_DELAY = 10_000
_DEFAULT_MAX_STEPS = 10_000_000
#: Working set of one chunk of grid work (bytes).
CHUNK_BYTES = 32 * 2**20
_SUFFIXES = {"": 1, "K": 2**10, "M": 2**20, "G": 2**30, "T": 2**40}


def _env_int(name, default, parse):
    text = os.environ.get(name, "").strip()
    if not text:
        return default
    try:
        value = parse(text)
    except ValueError:
        value = 0
    if value <= 0:
        raise ValueError(f"environment variable {name} must be a positive whole number, got {text!r}")
    return value


def _parse_bytes(text):
    number, suffix = text.upper().rstrip("IB"), ""
    if number and number[-1] in _SUFFIXES:
        number, suffix = number[:-1], number[-1]
    return int(float(number) * _SUFFIXES[suffix])


def memory_limit():
    """The largest working set symstab allocates at once, in bytes."""
    return _env_int(MEMORY_LIMIT_ENV, _DEFAULT_MEMORY_LIMIT, _parse_bytes)


def max_delay():
    """The largest loop delay ``d`` (samples) accepted."""
    return _env_int(MAX_DELAY_ENV, _DEFAULT_MAX_DELAY, int)


def max_steps():
    """The most sampling periods of one simulation (before the default-horizon floor)."""
    return _env_int(MAX_STEPS_ENV, _DEFAULT_MAX_STEPS, int)


def format_bytes(n):
    """``n`` bytes as a short human-readable string (``'1.5 GiB'``)."""
    for unit, size in (("TiB", 2**40), ("GiB", 2**30), ("MiB", 2**20), ("KiB", 2**10)):
        if n >= size:
            return f"{n / size:.3g} {unit}"
    return f"{int(n)} B"


def check_memory(what, nbytes):
    """Raise :class:`ValueError` when ``what`` would need more than the memory limit.

    Parameters
    ----------
    what : str
        What is being allocated, as the user would name it ("a 3000 x 3000
        grid at d = 10").
    nbytes : int or float
        The estimate, in bytes.
    """
    limit = memory_limit()
    if nbytes > limit:
        raise ValueError(
            f"{what} needs about {format_bytes(nbytes)}, more than the memory limit of "
            f"{format_bytes(limit)}; use a smaller problem or raise the limit with "
            f"{MEMORY_LIMIT_ENV} (e.g. {MEMORY_LIMIT_ENV}=8G)")


def chunk_slices(n_items, bytes_per_item, budget=CHUNK_BYTES):
    """Slices that cut ``range(n_items)`` into chunks of about ``budget`` bytes.

    Each chunk holds at least one item, so an item larger than the budget is
    a chunk of its own (check it with :func:`check_memory` first).
    """
    step = max(1, int(budget // max(1, bytes_per_item)))
    return [slice(start, min(start + step, n_items)) for start in range(0, n_items, step)]
