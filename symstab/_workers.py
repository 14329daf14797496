"""Process pools for the main job, stopped at once on Ctrl-C and SIGTERM.

In the base layer because both ``symstab reproduce`` (a front end) and
``paper_checks.audit`` (which the front ends use) run their work on them.
"""

import concurrent.futures
import contextlib
import multiprocessing
import os
import signal
import time

__all__ = ["default_workers", "check_workers", "worker_pool"]


def default_workers():
    """Worker processes used by default: the cores, at most two.

    The main job was sized for two cores; more workers only add start-up
    and duplicated symbolic work.
    """
    return max(1, min(2, os.cpu_count() or 1))


def max_workers():
    """The most worker processes a run may ask for: four per core, at least 8.

    Each worker imports SymPy and holds its caches (about 200 MB); a
    million of them once filled the memory and left thousands behind.
    """
    return max(8, 4 * (os.cpu_count() or 1))


def check_workers(workers):
    """``workers`` if it is a whole number from 1 to :func:`max_workers`, else a clear error."""
    limit = max_workers()
    if isinstance(workers, bool) or not isinstance(workers, int) or not 1 <= workers <= limit:
        raise ValueError(f"workers must be an integer from 1 to {limit} (four per core, at "
                         f"least 8), got {workers!r}")
    return workers


def _worker_init():
    # Ctrl-C reaches the whole process group: the parent alone decides
    # (and stops the workers), so a worker neither prints a traceback nor
    # runs the parent's SIGTERM handler, which a forked child inherits.
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    signal.signal(signal.SIGTERM, signal.SIG_DFL)


def _stop_workers(pool):
    """Cancel what is queued and end the workers now, without waiting for their tasks."""
    processes = list((getattr(pool, "_processes", None) or {}).values())
    for process in processes:
        with contextlib.suppress(Exception):
            process.terminate()
    deadline = time.monotonic() + 1.0
    for process in processes:
        process.join(max(0.0, deadline - time.monotonic()))
        if process.is_alive():
            with contextlib.suppress(Exception):
                process.kill()
            process.join(1.0)
    pool.shutdown(wait=False, cancel_futures=True)


@contextlib.contextmanager
def worker_pool(workers):
    """A process pool whose workers are stopped at once if the block fails.

    ``concurrent.futures`` waits for running tasks on the way out of a
    ``with`` block, also after Ctrl-C (a minute and more here); this pool
    terminates its workers instead on any exception, KeyboardInterrupt and
    SIGTERM included.  Workers are forked where the platform allows it, so
    that they inherit what the parent has already derived and cached.

    Parameters
    ----------
    workers : int
        Number of worker processes, ``>= 1``.
    """
    methods = multiprocessing.get_all_start_methods()
    context = multiprocessing.get_context("fork" if "fork" in methods else None)
    pool = concurrent.futures.ProcessPoolExecutor(max_workers=workers, mp_context=context,
                                                  initializer=_worker_init)
    try:
        yield pool
    except BaseException:
        _stop_workers(pool)
        raise
    pool.shutdown(wait=True)
