"""What the commands write: tables, CSV and JSON, files written atomically, PNGs.

Every command checks its output paths before any long work
(:func:`check_outputs`) and writes its files atomically
(:func:`write_output`): a failed or interrupted run leaves none behind.
:func:`emit` prints a command's rows as a table (with the echo of the
inputs and the notes), CSV (the echo and notes on stderr) or JSON.
:func:`quiet_when_unread` makes a command stop quietly when the reader of
its output goes (``symstab limits --format json | head -1``).
"""

import csv
import functools
import io
import json
import math
import os
import pathlib
import select
import sys
import tempfile

import numpy as np

__all__ = ["FORMATS", "BYTES_PER_ROW", "check_outputs", "check_files", "write_output", "emit",
           "number_text", "interval_texts", "quiet_when_unread", "EXIT_UNREAD"]


FORMATS = ("table", "csv", "json")
#: Memory per printed row: the row as Python objects (a tuple of up to six
#: floats) and its text.  Measured with tracemalloc on 100000 rows of five
#: columns: 900 bytes (JSON), 800 (table), 390 (CSV).
BYTES_PER_ROW = 1000


# --------------------------------------------------------------------------
# Output paths: one check for every command, before the work starts


def _probe_folder(folder):
    """Raise OSError unless a file can be created in the existing ``folder``.

    An anonymous temporary file, gone when closed: the only test that also
    holds for root and for read-only file systems (``os.access`` does not).
    """
    with tempfile.TemporaryFile(dir=folder):
        pass


def check_outputs(outputs):
    """Check the output paths of a command before it runs; return them as Paths.

    Parameters
    ----------
    outputs : iterable of (str, path-like or None, str)
        ``(flag, path, kind)`` with ``kind`` ``"file"`` (written atomically
        into an existing folder) or ``"dir"`` (created with its parents if
        missing).  Entries whose path is None are skipped.

    Returns
    -------
    dict
        ``{flag: pathlib.Path}`` of the checked entries.

    Raises
    ------
    ValueError
        Naming the flag and the user's path: a file that is a directory or a device, a
        directory that is a file, a missing or unwritable folder, or two
        outputs that name the same file (after resolving ``..`` and links).
    """
    checked, seen = {}, {}
    for flag, path, kind in outputs:
        if path is None:
            continue
        if kind not in ("file", "dir"):
            raise ValueError(f"kind must be 'file' or 'dir', got {kind!r}")
        path = pathlib.Path(path)
        if kind == "file":
            if path.is_dir():
                raise ValueError(f"{flag} {path} is a directory, expected a file name")
            if path.exists() and not path.is_file():
                raise ValueError(f"{flag} {path} is not a regular file (a device or a pipe): "
                                 f"the atomic write would replace it; give a file name")
            folder = path.parent
            if not folder.exists():
                raise ValueError(f"{flag} {path}: folder {folder} does not exist")
            if not folder.is_dir():
                raise ValueError(f"{flag} {path}: {folder} is not a folder")
        else:
            if path.exists() and not path.is_dir():
                raise ValueError(f"{flag} must be a directory, got file {path}")
            folder = path
            while not folder.exists():   # created at the first write
                folder = folder.parent
            if not folder.is_dir():
                raise ValueError(f"{flag} {path}: {folder} is a file, not a folder")
        try:
            _probe_folder(folder)
        except OSError as exc:
            raise ValueError(f"{flag} {path}: cannot write in folder {folder} "
                             f"({exc.strerror or exc})") from None
        key = os.path.realpath(path)
        if key in seen and "file" in (kind, seen[key][1]):
            raise ValueError(f"{seen[key][0]} and {flag} name the same file {path}; "
                             "give them different paths")
        seen.setdefault(key, (flag, kind))
        checked[flag] = path
    return checked


def check_files(pairs):
    """:func:`check_outputs` of ``(flag, path)`` pairs that are all files."""
    return check_outputs([(flag, path, "file") for flag, path in pairs])


def write_output(path, data, flag):
    """Write ``data`` (bytes or str) to ``path`` atomically; errors name ``flag`` and ``path``.

    The bytes go to a temporary file in the same folder, renamed into place
    (:func:`symstab.proof.derive.write_bytes`), which is removed on any failure,
    Ctrl-C and SIGTERM included.
    """
    from .._io import write_bytes

    if isinstance(data, str):
        data = data.encode("utf-8")
    try:
        return write_bytes(path, data)
    except OSError as exc:
        raise OSError(f"cannot write {flag} {path}: {exc.strerror or exc}") from None


# --------------------------------------------------------------------------
# A reader that goes: ``symstab ... | head -1``

#: The exit status of a command whose reader closed its output: a shell's
#: status of a Unix tool killed by SIGPIPE (128 + 13), as ``yes`` gets in
#: ``yes | head -1``.
EXIT_UNREAD = 141


def quiet_when_unread(run):
    """``run(args)``, stopping quietly with :data:`EXIT_UNREAD` when its output's reader goes.

    A Unix tool whose reader goes is killed by SIGPIPE: no message, status
    141 in the shell.  Python ignores SIGPIPE (a socket's peer that goes
    must not kill the process) and raises ``BrokenPipeError`` instead; a
    command has nothing to say to a reader that is gone, so stdout (and
    stderr, if its reader is gone too) is pointed at the null device, which
    also keeps the interpreter's last flush from complaining at exit, and
    the status is that of the tool killed by the signal.  Killing the
    process with SIGPIPE itself would skip the cleanup of its files
    (:func:`write_output`).  A broken pipe that is not stdout's (a
    worker's, a socket's) is an error as before.

    Parameters
    ----------
    run : callable
        A command's ``run(args)``, returning its exit status.

    Returns
    -------
    callable
        ``run`` that returns :data:`EXIT_UNREAD` when its reader has gone,
        with stdout flushed before it returns.
    """
    @functools.wraps(run)
    def wrapped(args):
        try:
            status = run(args)
            # Flushed here, not at exit, so that a reader gone is found while it can be answered.
            sys.stdout.flush()
            return status
        except BrokenPipeError:
            if not _unread(sys.stdout):
                raise
            for stream in (sys.stdout, sys.stderr):
                if _unread(stream):
                    null = os.open(os.devnull, os.O_WRONLY)
                    os.dup2(null, stream.fileno())
                    os.close(null)
            return EXIT_UNREAD

    return wrapped


def _unread(stream):
    """Whether ``stream`` is a pipe or socket whose reader has gone (poll: error or hang-up)."""
    try:
        fd = stream.fileno()
        poll = select.poll()
    except (AttributeError, OSError, ValueError):   # not a file (captured), or no poll()
        return False
    poll.register(fd, select.POLLOUT)
    return any(events & (select.POLLERR | select.POLLHUP) for _, events in poll.poll(0))


# --------------------------------------------------------------------------
# Tables, CSV and JSON


def number_text(x):
    """A cell of a table or CSV: "" for None, integers as such, floats to 10 digits, "nan"."""
    if x is None:
        return ""
    if isinstance(x, (int, np.integer)) and not isinstance(x, bool):
        return str(int(x))
    if isinstance(x, str):
        return x
    x = float(x)
    return "nan" if math.isnan(x) else f"{x:.10g}"


def _end_text(value):
    # -0.0 (an end computed as -c0/c1 with c0 = 0) is the end 0.
    return "-inf" if value == -math.inf else "inf" if value == math.inf else f"{value + 0.0:.10g}"


def _listed(words):
    return words[0] if len(words) == 1 else ", ".join(words[:-1]) + " and " + words[-1]


def interval_texts(runs, codes, name, unit="", *, stable_ends="boundary"):
    """Stable intervals as text, open at every end that is not stable, and what those ends are.

    A stable set is open: an interval's end is on the boundary, where a pole
    is on the unit circle (marginal), so "[0, ...]" would call a point stable
    that is not.  The ends are printed as computed, and exact where they are
    exact (the z = 1 line of a plant with an integrator is K = 0).

    Parameters
    ----------
    runs : list of (float, float)
        The stable intervals, increasing; an end may be infinite.
    codes : list of (int, int)
        The classification (:data:`symstab.numeric.paper.stability.MARGINAL`,
        ``UNSTABLE`` or ``STABLE``) of each finite end (ignored for infinite ones).
    name, unit : str
        The parameter along the intervals, and its unit.
    stable_ends : {"boundary", "closed"}
        What an end classified stable is: a computed boundary point, stable
        only by its rounding ("boundary", the default), or a stable end of
        the range searched (a path's end: "closed", printed with a bracket).

    Returns
    -------
    (str, str or None, list)
        ``"(0, 108.8220385) N/m"`` (or ``"none"``), the note on the ends
        (None without finite ends) and, per interval, the kind of each end
        (``"marginal"``, ``"unstable"``, ``"boundary"``, ``"stable"`` or
        ``"infinite"``) for JSON.
    """
    from ..numeric.engine.roots import MARGINAL, STABLE, UNSTABLE

    if stable_ends not in ("boundary", "closed"):
        raise ValueError(f"stable_ends must be 'boundary' or 'closed', got {stable_ends!r}")
    suffix = f" {unit}" if unit else ""
    if not runs:
        return "none", None, []
    closed = [tuple(stable_ends == "closed" and code == STABLE and not math.isinf(value)
                    for value, code in zip(run, pair, strict=True))
              for run, pair in zip(runs, codes, strict=True)]
    text = ", ".join(f"{'[' if shut[0] else '('}{_end_text(lo)}, {_end_text(hi)}"
                     f"{']' if shut[1] else ')'}"
                     for (lo, hi), shut in zip(runs, closed, strict=True)) + suffix
    kinds, found = [], {"marginal": [], "unstable": [], "boundary": []}
    for (lo, hi), pair in zip(runs, codes, strict=True):
        row = []
        for value, code in zip((lo, hi), pair, strict=True):
            if math.isinf(value):
                row.append("infinite")
                continue
            if stable_ends == "closed" and code == STABLE:
                row.append("stable")
                continue
            # A finite end the root count calls stable is on the boundary to
            # within the rounding of the end itself: not stable either.
            kind = "marginal" if code == MARGINAL else "unstable" if code == UNSTABLE else "boundary"
            row.append(kind)
            if _end_text(value) not in found[kind]:
                found[kind].append(_end_text(value))
        kinds.append(row)
    said = {"marginal": "marginal (a pole on the unit circle)", "unstable": "unstable",
            "boundary": "on the boundary to within rounding"}
    parts = [f"{said[kind]} at {name} = {_listed(values)}{suffix}"
             for kind, values in found.items() if values]
    note = ("open intervals: their ends are not stable; " + "; ".join(parts)) if parts else None
    return text, note, kinds


def emit(setup, fmt, columns, rows, *, result=None, notes=(), out=None, json_rows=True):
    """Print ``rows`` (tuples matching ``columns``) in ``fmt``.

    ``result`` is the JSON payload besides the rows; ``notes`` are lines
    printed after a table (and kept in JSON as "notes").
    """
    out = out or sys.stdout
    if fmt == "json":
        payload = {"inputs": setup.as_dict(), **(result or {})}
        if rows and json_rows:
            payload["rows"] = [dict(zip(columns, (None if isinstance(v, float) and math.isnan(v)
                                                  else v for v in row), strict=True))
                               for row in rows]
        if notes:
            payload["notes"] = list(notes)
        json.dump(_plain(payload), out, indent=1, sort_keys=False)
        out.write("\n")
        return
    if fmt == "csv":
        for line in setup.echo:
            print(line, file=sys.stderr)
        for line in notes:
            print(line, file=sys.stderr)
        buf = io.StringIO()
        writer = csv.writer(buf, lineterminator="\n")
        writer.writerow(columns)
        for row in rows:
            writer.writerow([number_text(v) for v in row])
        out.write(buf.getvalue())
        return
    for line in setup.echo:
        print(line, file=out)
    if rows:
        cells = [list(columns)] + [[number_text(v) for v in row] for row in rows]
        widths = [max(len(r[i]) for r in cells) for i in range(len(columns))]
        print(file=out)
        for k, r in enumerate(cells):
            print("  ".join(c.rjust(w) for c, w in zip(r, widths, strict=True)).rstrip(), file=out)
            if k == 0:
                print("  ".join("-" * w for w in widths), file=out)
    if notes:
        print(file=out)
        for line in notes:
            print(line, file=out)


def _plain(x):
    if isinstance(x, dict):
        return {k: _plain(v) for k, v in x.items()}
    if isinstance(x, (list, tuple)):
        return [_plain(v) for v in x]
    if isinstance(x, np.generic):
        x = x.item()
    if isinstance(x, float) and not math.isfinite(x):
        return None if math.isnan(x) else ("inf" if x > 0 else "-inf")
    return x
