"""The progress bar of long runs (a region, a map, a sweep, a design search)."""

import sys
import time


def progress_printer(label, total, stream=None, min_seconds=2.0):
    """A callback ``(done)`` that draws a bar once a run takes longer than ``min_seconds``.

    The bar is drawn on ``stream`` (default ``sys.stderr``) only when it is
    a terminal: redrawn with carriage returns, it would be noise in a log
    file or a pipe (and a second "line" before an error message there).
    """
    stream = sys.stderr if stream is None else stream
    start = time.perf_counter()
    state = {"last": 0.0}
    isatty = getattr(stream, "isatty", None)
    if not (isatty is not None and isatty()):
        return lambda done: None

    def update(done):
        now = time.perf_counter() - start
        if now < min_seconds or (now - state["last"] < 0.2 and done < total):
            return
        state["last"] = now
        frac = done / total
        bar = "#" * int(30 * frac)
        eta = now / frac - now if frac > 0 else 0.0
        stream.write(f"\r{label} [{bar:<30}] {100 * frac:5.1f}%  {now:5.1f} s, ~{eta:4.0f} s left")
        if done >= total:
            stream.write("\n")
        stream.flush()

    return update
