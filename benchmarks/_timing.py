"""Timing helpers shared by the benchmarks: readable durations and timed runs."""

import time

__all__ = ["fmt", "timed_runs"]


def fmt(seconds):
    """A time with a unit that keeps 3 significant digits readable."""
    for unit, scale in (("s", 1.0), ("ms", 1e-3), ("us", 1e-6), ("ns", 1e-9)):
        if abs(seconds) >= scale or unit == "ns":
            return f"{seconds / scale:.3g} {unit}"


def timed_runs(fn, runs, warmup=1):
    """Run ``fn`` ``warmup`` times untimed, then ``runs`` times; return the times."""
    for _ in range(warmup):
        fn()
    out = []
    for _ in range(runs):
        start = time.perf_counter()
        fn()
        out.append(time.perf_counter() - start)
    return out
