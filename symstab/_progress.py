"""The progress bar of long runs (a region, a map, a sweep, a design search)."""

import sys
import time


def _in_a_notebook(stream):
    """True when ``stream`` is a Jupyter kernel's (ipykernel's output stream is no terminal)."""
    return type(stream).__module__.startswith("ipykernel.")


def _notebook_bar(label, total, min_seconds):
    """tqdm's notebook bar (``tqdm.auto``) as a ``(done)`` callback, or None without tqdm."""
    try:
        from tqdm.auto import tqdm
    except ImportError:
        return None
    bar = tqdm(total=total, desc=label, delay=min_seconds, leave=True)

    def update(done):
        bar.update(done - bar.n)
        if done >= total:
            bar.close()

    return update


def progress_printer(label, total, stream=None, min_seconds=2.0):
    """A callback ``(done)`` that draws a bar once a run takes longer than ``min_seconds``.

    The bar is drawn on ``stream`` (default ``sys.stderr``) only when it is
    a terminal or a Jupyter notebook's: redrawn with carriage returns, it
    would be noise in a log file or a pipe (and a second "line" before an
    error message there).  In a notebook it is tqdm's widget when tqdm is
    installed (``tqdm.auto``), else the same text bar (the notebook honours
    carriage returns).
    """
    stream = sys.stderr if stream is None else stream
    start = time.perf_counter()
    state = {"last": 0.0}
    isatty = getattr(stream, "isatty", None)
    if _in_a_notebook(stream):
        widget = _notebook_bar(label, total, min_seconds)
        if widget is not None:
            return widget
    elif not (isatty is not None and isatty()):
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
