"""``symstab sweep SPEC.toml``: one question asked of a loop at many parameter points, on Dask.

The spec (TOML) names the loop file (relative to the spec), the question
(``limits``; ``design`` with a ``[design]`` table: ``over = {NAME = [LO,
HI]}``, one or two parameters, and ``maximize``, K_max, the Z-width or the
passive K_max; ``region``, the D-decomposition's cells, stable pieces and
area; ``robust`` with ``[robust] uncertain = {NAME = [LO, HI]}`` and
``strips``, the limits of the set stable over the box, the delay in it as
``d`` or ``Td`` (every delay of the range where it is in seconds or an end
is fractional; not swept as well); ``simulated`` with
``[simulated] amplitude`` and optionally ``steps``, ``x0``,
``encoder_resolution``, ``force_limit``, ``force_resolution`` in SI, the
largest y a simulated run accepts), optionally the plane, the rows per chunk, and the points:
either ``[grid]``, every combination of the values given for each parameter
(a list, or ``{from = LO, to = HI, points = N}``; ``unit = "..."`` converts
them, else they are in the loop file's unit), or ``[random]``, ``samples``
rows drawn uniformly from ``NAME = [LO, HI]`` (whole delays for ``d`` with
whole ends) with ``seed``.  The delay is ``d`` in samples (40.5: a fraction
of a period more) or ``Td`` in time (``unit = "ms"``; ``Td / T`` samples at
each row, so a grid of ``T`` with the loop file's ``Td`` holds the delay in
seconds), not both.  Every row's inputs and answers go to one table (CSV or NPZ, the
units in the header); the chunks are evaluated on a Dask cluster (a
``LocalCluster`` on this machine's cores, or ``--scheduler ADDRESS``) or,
with ``--serial``, here, and saved as they finish in ``OUT.parts/``: run
the same command again after an interruption (Ctrl-C or SIGTERM) and the
saved chunks are not recomputed; an interruption before the first chunk is
saved leaves no folder.  Once the table is written the folder is removed.
The spec is data: nothing in it is run.
"""

import io
import logging
import math
import os
import pathlib
import shutil
import sys

import numpy as np

from .._signals import Terminated, exit_status
from .loop_options import check_corners, convert_sets, load_loop_file
from .options import add_command
from .output import check_files, write_output

__all__ = ["register", "run", "MAX_ROWS", "local_cluster", "check_scheduler", "read_spec"]

#: The most rows a sweep has (each is a certified region, about 0.1 to 1 s).
MAX_ROWS = 1_000_000
#: The largest spec read.
_MAX_SPEC_BYTES = 1 << 20
_KEYS = {"loop", "question", "plane", "chunk", "grid", "random", "design", "robust",
         "simulated"}
#: ``[design] maximize``'s words (those of ``symstab design --maximize``).
_TARGETS = {"y_max": "y_max", "K_max": "y_max", "area": "area", "Z-width": "area",
            "passive": "passive"}
#: The tables that go with a question: their keys, and what they must hold.
_SECTIONS = (
    ("design", "over, maximize", "over = {NAME = [LO, HI]}, the one or two parameters searched, "
     "and optionally maximize"),
    ("robust", "uncertain, strips", "uncertain = {NAME = [LO, HI]}, the box of uncertain "
     "values, and optionally strips"),
    ("simulated", "amplitude, steps, ...", "amplitude, the largest |x| accepted at the end of a "
     "run, and optionally steps, x0, encoder_resolution, force_limit, force_resolution"))
#: Seconds a ``--scheduler`` may take to answer, by default.
_CONNECT_TIMEOUT = 10.0
#: Rows per chunk by default: a task long enough to hide the cluster's overhead.
_DEFAULT_CHUNK = 10


def register(subparsers):
    """Add ``symstab sweep`` to the sub-commands."""
    p = add_command(
        subparsers, "sweep", help="ask a loop a question at many parameter points (on Dask)",
        description="Evaluate a question -- the limits of a loop's stable set (K_max, the B "
                    "where it is reached, the B range, the area), a design, its "
                    "D-decomposition's cells, the robust limits over a box or the simulated "
                    "K_max -- at every row of a grid or of random draws "
                    "of its parameters, given in a TOML spec; the chunks run on a Dask cluster "
                    "(pip install '.[sweep]') and are saved as they finish, so a run that is "
                    "interrupted resumes where it stopped.",
        example="symstab sweep examples/sweeps/paper_delays.toml --out out/sweep.csv",
        func=run)
    p.add_argument("spec", help="the sweep's TOML spec")
    p.add_argument("--out", required=True, help="the table: .csv or .npz")
    g = p.add_mutually_exclusive_group()
    g.add_argument("--scheduler", metavar="ADDRESS",
                   help="a running Dask scheduler (default: a LocalCluster on this machine)")
    g.add_argument("--workers", type=int, metavar="N",
                   help="workers of the LocalCluster (default: the machine's cores)")
    g.add_argument("--serial", action="store_true", help="evaluate here, one chunk after another")
    p.add_argument("--connect-timeout", type=float, metavar="SECONDS",
                   help=f"how long the scheduler at --scheduler may take to answer (default "
                        f"{_CONNECT_TIMEOUT:g})")


def run(args):
    out = pathlib.Path(args.out)
    if out.suffix not in (".csv", ".npz"):
        raise ValueError(f"--out must end in .csv or .npz, got {args.out!r}")
    check_files([("--out", out)])
    if args.workers is not None and not 1 <= args.workers <= 256:
        raise ValueError(f"--workers must be an integer from 1 to 256, got {args.workers}")
    if args.connect_timeout is not None:
        if args.scheduler is None:
            raise ValueError("--connect-timeout goes with --scheduler ADDRESS")
        if not 0 < args.connect_timeout <= 3600:
            raise ValueError(f"--connect-timeout must be a number of seconds > 0 and <= 3600, "
                             f"got {args.connect_timeout:g}")
    plan = read_spec(args.spec)
    client_of = None if args.serial else _client_factory(args)
    from .._progress import progress_printer
    from .sweep_store import ChunkStore, run_sweep, sweep_key

    rows, chunk = plan["rows"], plan["chunk"]
    n_chunks = math.ceil(len(rows) / chunk)
    parts = out.with_name(out.name + ".parts")
    key = sweep_key(plan["loop_text"], repr(plan["question"]), ",".join(plan["names"]), rows,
                    chunk)
    loop = plan["loop"]
    client = cluster = store = None
    try:
        # The cluster first: an address that does not answer is refused before a folder is made.
        where = None
        if client_of is not None:
            client, cluster, where = client_of()
        store = ChunkStore(parts, key, n_chunks)
        question = plan["question"]
        print(f"sweep {args.spec}: {question.kind} of loop {loop.name} in the ({question.x}, "
              f"{question.y}) plane at {len(rows)} points ({plan['how']}), {n_chunks} chunks of "
              f"{chunk}; saved as they finish in {parts}")
        if where is not None:
            print(f"on {where}")
        values, reasons, loaded = run_sweep(
            loop, plan["question"], plan["names"], rows, chunk=chunk, store=store,
            client=client, progress=progress_printer("sweeping", n_chunks))
    except Exception:
        # An error, not an interruption: a folder with no chunk saved goes
        # (it would only stand in the way of the corrected sweep).
        if store is not None and not store.done():
            shutil.rmtree(parts, ignore_errors=True)
        raise
    except (KeyboardInterrupt, Terminated) as exc:
        # Ctrl-C or SIGTERM: both say what is saved and how to resume.
        return _interrupted(exc, store, parts, n_chunks)
    finally:
        if client is not None:
            client.close()
        if cluster is not None:
            cluster.close()
    if loaded:
        print(f"resumed: {loaded} of {n_chunks} chunks were saved by an earlier run and not "
              f"evaluated again")
    write_output(out, _table(plan, values, reasons, out.suffix), "--out")
    # The table holds every chunk now: the folder kept for a resume goes.
    shutil.rmtree(parts, ignore_errors=True)
    answered = int(np.count_nonzero(np.all(np.isfinite(values), axis=1)))
    print(f"{answered} of {len(rows)} points answered in full (the others' reasons are in the "
          f"table); wrote {out}")
    return 0


def _interrupted(exc, store, parts, n_chunks):
    """Say what an interrupted sweep saved and how to resume; the exit status (128 + signal).

    A folder holding no chunk goes, as after an error: there is nothing in it to resume.
    """
    saved = len(store.done()) if store is not None else 0
    if saved:
        what = (f"{saved} of {n_chunks} chunks saved in {parts}; the same command resumes "
                f"there")
    else:
        if store is not None:
            shutil.rmtree(parts, ignore_errors=True)
        what = f"no chunk of {n_chunks} was saved yet (nothing to resume)"
    print(f"{chr(10) if sys.stderr.isatty() else ''}symstab sweep: interrupted: {what}",
          file=sys.stderr)
    return exit_status(exc)


def _client_factory(args):
    """A callable giving ``(client, cluster or None, description)``; refuses a missing Dask now."""
    import importlib

    try:
        importlib.import_module("dask.distributed")
    except ImportError:
        raise ValueError("symstab sweep runs on Dask: pip install '.[sweep]' (dask.distributed), "
                         "or give --serial") from None

    def make():
        from dask.distributed import Client

        if args.scheduler is not None:
            timeout = args.connect_timeout or _CONNECT_TIMEOUT
            check_scheduler(args.scheduler, timeout)
            return (Client(args.scheduler, timeout=timeout), None,
                    f"the Dask scheduler at {args.scheduler}")
        n = args.workers or os.cpu_count() or 1
        cluster = local_cluster(n)
        return Client(cluster), cluster, f"a Dask LocalCluster of {n} worker process(es)"

    return make


def check_scheduler(address, timeout):
    """Refuse, in ``timeout`` seconds, an ``address`` where no Dask scheduler answers.

    Dask's ``Client(address, timeout=...)`` bounds the TCP connection, not
    the handshake after it: a listener that accepts and never answers held
    it for ever, and one that answers with other bytes than Dask's was read
    as frame lengths ("Unable to allocate 3.01 EiB").  Here the whole
    exchange -- connection, handshake and the scheduler's identity -- has
    one deadline, and anything but a scheduler's answer is one
    ``ValueError`` naming the address.

    Parameters
    ----------
    address : str
        The scheduler's address (``tcp://HOST:PORT``), as ``--scheduler`` gives it.
    timeout : float
        Seconds for the whole exchange.

    Raises
    ------
    ValueError
        Naming ``--scheduler ADDRESS``: not an address, no connection, no
        answer in time, an answer not in Dask's protocol, or another Dask
        server than a scheduler (a worker).
    """
    import asyncio

    from distributed.comm import connect
    from distributed.comm.addressing import parse_address, parse_host_port
    from distributed.comm.registry import get_backend

    where = f"--scheduler {address}"
    try:
        scheme, location = parse_address(address)
        get_backend(scheme)
        if scheme in ("tcp", "tls"):
            parse_host_port(location)
    except ValueError as exc:
        raise ValueError(f"{where} is not a scheduler's address such as tcp://HOST:PORT: "
                         f"{exc}") from None

    async def identity():
        comm = await connect(address, timeout=timeout)
        try:
            await comm.write({"op": "identity", "reply": True})
            return await comm.read()
        finally:
            comm.abort()

    try:
        answer = asyncio.run(asyncio.wait_for(identity(), timeout))
    except asyncio.TimeoutError:
        raise ValueError(f"{where}: no answer in {timeout:g} s (is a Dask scheduler there? "
                         f"--connect-timeout waits longer)") from None
    except OSError as exc:
        raise ValueError(f"{where}: cannot connect: {' '.join(str(exc).split())}") from None
    except Exception as exc:
        # The peer's bytes, read as Dask's frames: any error is theirs, not ours.
        raise ValueError(f"{where}: the answer is not Dask's protocol (is it a Dask "
                         f"scheduler?): {type(exc).__name__}") from None
    if not isinstance(answer, dict) or answer.get("type") != "Scheduler":
        kind = answer.get("type") if isinstance(answer, dict) else None
        raise ValueError(f"{where}: not a Dask scheduler"
                         f"{f' (a {kind})' if isinstance(kind, str) else ''}")


def local_cluster(n_workers):
    """A Dask ``LocalCluster`` of ``n_workers`` single-threaded worker processes, quiet.

    Its log lines are not for the user (on Ctrl-C the workers stop with the
    command and the scheduler logs, at ERROR, the data they held; a task's
    failure reaches the sweep as its exception), nor are the errors of its
    event loop's own tasks (interrupted in ``client.scatter``, the
    scheduler's replication fails on the workers gone and asyncio printed
    its traceback), and the workers'
    statistical profiler is off: sampling the stack every
    10 ms took about a tenth of their time on this package's Python-heavy
    rows (measured: 200 regions on two workers, 13.0 s with it, 11.6 s
    without).

    A Ctrl-C while the processes start stops the command as it would a
    second later (the cluster is closed, then KeyboardInterrupt).
    """
    import dask
    from dask.distributed import LocalCluster

    def start():
        with dask.config.set({"distributed.worker.profile.enabled": False}):
            cluster = LocalCluster(n_workers=n_workers, threads_per_worker=1, processes=True,
                                   dashboard_address=None, silence_logs=logging.CRITICAL)
        cluster.loop.asyncio_loop.set_exception_handler(_unreported)
        return cluster

    return _starting_children(start)


def _unreported(loop, context):
    """The LocalCluster's event loop's exception handler: its own tasks' errors are not shown."""


def _starting_children(start):
    """``start()``, which starts processes that must not answer a terminal's Ctrl-C.

    A terminal's Ctrl-C reaches the whole process group; the command, not
    each worker, answers it (the cluster is closed with the command).  The
    workers were started with SIGINT ignored, which they inherit, but a
    Ctrl-C arriving meanwhile was then discarded: the sweep ran to its end.
    Here SIGINT is blocked instead, in this thread while ``start()`` runs:
    the threads it starts (Dask's event loop, which spawns the workers)
    inherit the mask, and processes keep it across fork and exec (spawn,
    forkserver and fork alike).  Other threads of this process (the BLAS
    pool) do not block it and may take the signal: meanwhile a handler only
    notes that it came.  Once ``start()`` is done the signal is raised again
    under the handler that was in place (KeyboardInterrupt), and what
    ``start()`` returned is closed.
    """
    import signal
    import threading

    # Handlers are set in the main thread only, Windows has no mask, and a handler set
    # outside Python (None) could not be put back.
    if (threading.current_thread() is not threading.main_thread()
            or not hasattr(signal, "pthread_sigmask") or signal.getsignal(signal.SIGINT) is None):
        return start()
    from multiprocessing import resource_tracker

    # Started now, before the mask: started at the first worker's spawn, in Dask's
    # thread, it unblocks SIGINT there (SIG_UNBLOCK, not the mask it found), and every
    # worker spawned after it answered Ctrl-C with a traceback.
    resource_tracker.ensure_running()
    arrived = []
    before = signal.signal(signal.SIGINT, lambda signum, frame: arrived.append(signum))
    mask = signal.pthread_sigmask(signal.SIG_BLOCK, {signal.SIGINT})
    started = None
    try:
        started = start()
    finally:
        try:
            signal.signal(signal.SIGINT, before)
            signal.pthread_sigmask(signal.SIG_SETMASK, mask)
            if arrived:
                signal.raise_signal(signal.SIGINT)
        except BaseException:
            if started is not None:
                started.close()
            raise
    return started


def read_spec(path):
    """The sweep of the spec at ``path``: its loop, plane, question, rows (SI) and chunk size."""
    path = pathlib.Path(path)
    spec = _read_toml(path)
    where = f"the sweep spec {path}"
    if not isinstance(spec.get("loop"), str):
        raise ValueError(f"{where}: loop = \"FILE\", the loop file (relative to the spec), is "
                         f"required")
    loop_path = (path.parent / spec["loop"])
    loop = load_loop_file(str(loop_path))
    try:
        loop_text = loop_path.read_text(encoding="utf-8")
    except OSError as exc:
        raise ValueError(f"{where}: cannot read {loop_path}: {exc.strerror or exc}") from None
    question = _question(where, loop, spec)
    x, y, over = question.x, question.y, question.over
    chunk = spec.get("chunk", _DEFAULT_CHUNK)
    if isinstance(chunk, bool) or not isinstance(chunk, int) or not 1 <= chunk <= 10_000:
        raise ValueError(f"{where}: chunk must be an integer from 1 to 10000 (rows per task), "
                         f"got {chunk!r}")
    names, rows, how = _points(where, loop, spec, question)
    # The first row asked of the loop now: a value out of its domain is refused before the run.
    from ..numeric.loop.quantities import FileParameters, check_bounds

    known = getattr(loop, "file_parameters", None) or FileParameters({})
    columns = {n: rows[:, k] for k, n in enumerate(names)}
    check_bounds(known, {**loop.defaults, **columns}, skip=(x, y),
                 where=lambda bad: f"{where}: a point's " + ", ".join(bad))
    # The box's corners asked of the loop now: a value outside its domain is refused before
    # the run, not in the middle of it.
    box = {n: (rows[:, k].min(), rows[:, k].max()) for k, n in enumerate(names)}
    box.update({name: (low, high) for name, low, high in over})
    if "d" in box:
        box["d"] = tuple(int(v) if float(v).is_integer() else float(v) for v in box["d"])
    check_corners(loop, loop.defaults, x, y, box, where)
    return {"loop": loop, "loop_text": loop_text, "question": question,
            "names": tuple(names), "rows": rows, "chunk": chunk, "how": how}


def _read_toml(path):
    """The spec file's TOML table, its size and keys checked."""
    from ..numeric.loop.files import tomllib

    try:
        with open(path, "rb") as fh:
            data = fh.read(_MAX_SPEC_BYTES + 1)
    except OSError as exc:
        raise ValueError(f"cannot read the sweep spec {str(path)!r}: {exc.strerror or exc}") from None
    if len(data) > _MAX_SPEC_BYTES:
        raise ValueError(f"the sweep spec {str(path)!r} is larger than {_MAX_SPEC_BYTES} bytes")
    try:
        spec = tomllib.loads(data.decode("utf-8"))
    except (UnicodeDecodeError, tomllib.TOMLDecodeError) as exc:
        raise ValueError(f"the sweep spec {str(path)!r} is not TOML: {exc}") from None
    unknown = sorted(set(spec) - _KEYS)
    if unknown:
        raise ValueError(f"the sweep spec {path}: unknown key {unknown[0]!r} (the keys are "
                         f"{', '.join(sorted(_KEYS))})")
    return spec


def _question(where, loop, spec):
    """The spec's :class:`~symstab.cli.sweep_store.Question`: its kind, plane and section."""
    from .sweep_store import QUESTIONS, Question

    kind = spec.get("question", "limits")
    if kind not in QUESTIONS:
        raise ValueError(f"{where}: question must be one of {', '.join(QUESTIONS)}, got "
                         f"{kind!r}")
    plane = spec.get("plane", loop.plane)
    if (not isinstance(plane, (list, tuple)) or len(plane) != 2
            or not all(isinstance(n, str) for n in plane)):
        raise ValueError(f"{where}: plane must be two parameter names, e.g. [\"B\", \"K\"]")
    x, y = plane
    try:
        loop.check_plane((x, y))
    except (TypeError, ValueError) as exc:
        raise ValueError(f"{where}: plane: {exc}") from None
    for section, keys, holds in _SECTIONS:
        if kind == section and section not in spec:
            raise ValueError(f"{where}: question = \"{section}\" needs a [{section}] table and "
                             f"there is none: give one holding {holds}")
        if section in spec and kind != section:
            raise ValueError(f"{where}: [{section}] ({keys}) goes with question = "
                             f"\"{section}\", and only with it (the question is {kind!r})")
    over, maximize, strips, simulation = (), "y_max", 64, ()
    if kind == "design":
        over, maximize = _design(where, loop, x, y, spec["design"])
    elif kind == "robust":
        over, strips = _robust(where, loop, x, y, spec["robust"])
    elif kind == "simulated":
        simulation = _simulated(where, loop, y, spec["simulated"])
    return Question(kind, x, y, over=over, maximize=maximize, strips=strips,
                    simulation=simulation)


def _points(where, loop, spec, question):
    """``(names, rows, how)`` of the spec's [grid] or [random], none searched or uncertain."""
    if ("grid" in spec) == ("random" in spec):
        raise ValueError(f"{where}: give the points as [grid] or as [random], one of them")
    table = spec.get("grid", spec.get("random"))
    if not isinstance(table, dict):
        raise ValueError(f"{where}: [grid] or [random] must be a table")
    x, y = question.x, question.y
    if "grid" in spec:
        names, rows, how = _grid(where, loop, x, y, table)
    else:
        names, rows, how = _random(where, loop, x, y, table)
    if not names:
        raise ValueError(f"{where}: sweep at least one parameter")
    if "d" in names and "Td" in names:
        raise ValueError(f"{where}: give the delay once: d (in samples) or Td (in time)")
    if question.kind == "robust":
        _check_robust_delay(where, loop, names, question.over)
    searched = [name for name, _, _ in question.over if name in names]
    if searched:
        what, section = (("uncertain", "[robust] uncertain") if question.kind == "robust"
                         else ("searched", "[design] over"))
        raise ValueError(f"{where}: {searched[0]} is swept and {what}: give it in [grid] or "
                         f"[random], or in {section}, not both")
    return names, rows, how


def _check_robust_delay(where, loop, names, over):
    """A robust sweep's delay, given once and, in seconds, over a fixed period (as the robust
    region takes it: :func:`symstab.numeric.analysis.robust.robust_region`), checked when the
    spec is read, not at each row."""
    uncertain = [name for name, _, _ in over]
    delays = [name for name in uncertain if name in ("d", "Td")]
    if len(delays) > 1:
        raise ValueError(f"{where}: [robust] uncertain: give the delay range once, as d "
                         f"(samples) or Td (seconds)")
    swept = [name for name in names if name in ("d", "Td")]
    if delays and swept:
        raise ValueError(f"{where}: the delay is swept ({swept[0]}) and uncertain "
                         f"([robust] uncertain {delays[0]}): give it in one of them")
    given = delays or swept or [n for n in ("d", "Td") if n in loop.defaults][:1]
    if "T" in uncertain and given == ["Td"]:
        raise ValueError(f"{where}: [robust] uncertain T with the delay in seconds (Td): its "
                         f"fraction of a period would vary over the box; give the delay in "
                         f"samples, d")


def _design(where, loop, x, y, table):
    """``(over, maximize)`` of the spec's ``[design]`` table, the ranges in SI."""
    if not isinstance(table, dict):
        raise ValueError(f"{where}: [design] must be a table")
    extra = sorted(set(table) - {"over", "maximize"})
    if extra:
        raise ValueError(f"{where}: [design]: unknown key {extra[0]!r} (over, maximize)")
    maximize = table.get("maximize", "y_max")
    if maximize not in _TARGETS:
        raise ValueError(f"{where}: [design] maximize must be one of {', '.join(_TARGETS)} (the "
                         f"simulated target is not swept), got {maximize!r}")
    over = table.get("over")
    if not isinstance(over, dict) or not 1 <= len(over) <= 2:
        raise ValueError(f"{where}: [design] over = {{NAME = [LO, HI]}} names one or two "
                         f"parameters to search")
    if "d" in over:
        raise ValueError(f"{where}: [design] over d: the delay is a whole number of "
                         f"samples; sweep it in [grid] instead")
    return _ranges(where, "[design] over", loop, x, y, over, strict=True), _TARGETS[maximize]


def _robust(where, loop, x, y, table):
    """``(box, strips)`` of the spec's ``[robust]`` table, the box in SI."""
    if not isinstance(table, dict):
        raise ValueError(f"{where}: [robust] must be a table")
    extra = sorted(set(table) - {"uncertain", "strips"})
    if extra:
        raise ValueError(f"{where}: [robust]: unknown key {extra[0]!r} (uncertain, strips)")
    strips = table.get("strips", 64)
    if isinstance(strips, bool) or not isinstance(strips, int) or not 1 <= strips <= 100_000:
        raise ValueError(f"{where}: [robust] strips must be an integer from 1 to 100000, got "
                         f"{strips!r}")
    uncertain = table.get("uncertain")
    if not isinstance(uncertain, dict) or not uncertain:
        raise ValueError(f"{where}: [robust] uncertain = {{NAME = [LO, HI]}} names the box")
    box = _ranges(where, "[robust] uncertain", loop, x, y, uncertain, strict=False)
    return box, strips


def _simulated(where, loop, y, table):
    """The ``[simulated]`` table's options, in SI (the position's unit for the amplitude)."""
    from ..numeric.simulation.simulator import Nonidealities

    if not isinstance(table, dict):
        raise ValueError(f"{where}: [simulated] must be a table")
    from .sweep_store import SIMULATION_KEYS

    extra = sorted(set(table) - set(SIMULATION_KEYS))
    if extra:
        raise ValueError(f"{where}: [simulated]: unknown key {extra[0]!r} "
                         f"({', '.join(SIMULATION_KEYS)})")
    if "amplitude" not in table:
        raise ValueError(f"{where}: [simulated] amplitude, the largest |x| accepted at the end "
                         f"of a run, is required")
    options = []
    for key in SIMULATION_KEYS:
        if key not in table:
            continue
        value = table[key]
        if isinstance(value, bool) or not isinstance(value, (int, float)) \
                or not math.isfinite(value) or value <= 0 and key != "x0":
            what = "a finite number" if key == "x0" else "a positive number"
            raise ValueError(f"{where}: [simulated] {key} must be {what}, got {value!r}")
        if key == "steps" and (not float(value).is_integer() or not 10 <= value <= 10_000_000):
            raise ValueError(f"{where}: [simulated] steps must be a whole number from 10 to "
                             f"10000000, got {value!r}")
        options.append((key, float(value)))
    from ..numeric.simulation.simulator import X0_MAX, X0_MIN

    x0 = dict(options).get("x0")
    if x0 is not None and not X0_MIN <= abs(x0) <= X0_MAX:
        raise ValueError(f"{where}: [simulated] x0 must be from {X0_MIN:g} to {X0_MAX:g} in "
                         f"size, got {x0!r}")
    try:
        Nonidealities(**{k: v for k, v in options if k not in ("amplitude", "steps", "x0")})
    except (TypeError, ValueError) as exc:
        raise ValueError(f"{where}: [simulated]: {exc}") from None
    return tuple(options)


def _ranges(where, section, loop, x, y, table, *, strict):
    """``((name, low, high), ...)`` in SI of ``{NAME = [LO, HI] or {range, unit}}``.

    ``LO < HI`` if ``strict`` (``LO <= HI`` for ``d`` all the same), else ``LO <= HI``.
    """
    ranges = []
    for name, spec in table.items():
        _check_name(where, loop, x, y, name)
        unit = None
        if isinstance(spec, dict):
            extra = sorted(set(spec) - {"range", "unit"})
            if extra:
                raise ValueError(f"{where}: {section} {name}: unknown key {extra[0]!r} (range, "
                                 f"unit)")
            unit, spec = spec.get("unit"), spec.get("range")
        if not isinstance(spec, list) or len(spec) != 2:
            raise ValueError(f"{where}: {section} {name} must be [LO, HI] or "
                             f"{{range = [LO, HI], unit = \"...\"}}")
        low, high = _si(f"{where}: {section}", loop, name, spec, unit)
        less = strict and name != "d"     # whole delays: a range of one is a range
        if not (low < high if less else low <= high):
            raise ValueError(f"{where}: {section} {name} = [LO, HI] needs LO "
                             f"{'<' if less else '<='} HI, got {spec!r}")
        ranges.append((name, low, high))
    return tuple(ranges)


def _check_name(where, loop, x, y, name):
    if name not in loop.parameters and name != "Td":
        raise ValueError(f"{where}: {name!r} is not a parameter of the loop (its parameters: "
                         f"{', '.join(loop.parameters)})")
    if name in (x, y):
        raise ValueError(f"{where}: {name} is an axis of the ({x}, {y}) plane; the limits are "
                         f"read in it, not swept")


def _si(where, loop, name, values, unit):
    """``values`` (a list of numbers) in SI: from ``unit``, else from the loop file's unit."""
    if not all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in values):
        raise ValueError(f"{where}: {name} must be numbers, got {values!r}")
    if name == "d":
        if unit not in (None, "samples") or not all(math.isfinite(v) and v >= 0
                                                    for v in values):
            raise ValueError(f"{where}: d counts samples (a fraction of a period included), "
                             f">= 0, got {values!r}")
        return [float(v) for v in values]
    if unit is not None and not isinstance(unit, str):
        raise ValueError(f"{where}: the unit of {name} must be text, got {unit!r}")
    if not all(math.isfinite(v) for v in values):
        # TOML has nan and inf; the unit conversion would refuse them without naming the key.
        unit = unit or (getattr(loop, "file_parameters", None)
                        and loop.file_parameters.file_unit(name))
        raise ValueError(f"{where}: {name} must be finite numbers{f' in {unit}' if unit else ''}"
                         f", got {values!r}")
    converted, _ = convert_sets(loop, {name: (list(values), unit)}, flag=where + ":")
    out = [float(v) for v in converted[name]]
    if not all(math.isfinite(v) for v in out):
        raise ValueError(f"{where}: {name} must be finite numbers, got {values!r}")
    return out


def _grid(where, loop, x, y, table):
    names, axes = [], []
    for name, spec in table.items():
        _check_name(where, loop, x, y, name)
        unit = None
        if isinstance(spec, dict):
            extra = sorted(set(spec) - {"from", "to", "points", "unit", "values"})
            if extra:
                raise ValueError(f"{where}: [grid] {name}: unknown key {extra[0]!r} (give "
                                 f"{{from, to, points}} or {{values}}, and unit)")
            unit = spec.get("unit")
            if "values" in spec:
                spec = spec["values"]
            else:
                low, high, n = spec.get("from"), spec.get("to"), spec.get("points")
                if (isinstance(n, bool) or not isinstance(n, int) or n < 1
                        or not all(isinstance(v, (int, float)) and not isinstance(v, bool)
                                   and math.isfinite(v) for v in (low, high))):
                    raise ValueError(f"{where}: [grid] {name} = {{from = LO, to = HI, points = N}} "
                                     f"needs two finite numbers and a whole N >= 1")
                if n > MAX_ROWS:
                    raise ValueError(f"{where}: [grid] {name} has {n} points, more than "
                                     f"{MAX_ROWS}")
                spec = list(np.linspace(low, high, n))
                if name == "d":
                    # A whole step gives whole delays (40, not 40.00000000000001).
                    spec = [round(v) if abs(v - round(v)) <= 1e-9 else v for v in spec]
        if not isinstance(spec, list) or not spec:
            raise ValueError(f"{where}: [grid] {name} must be a non-empty list of values or "
                             f"{{from, to, points}}")
        names.append(name)
        axes.append(_si(f"{where}: [grid]", loop, name, spec, unit))
    size = math.prod(len(a) for a in axes)
    if size > MAX_ROWS:
        raise ValueError(f"{where}: the grid has {size} points, more than {MAX_ROWS}")
    mesh = np.meshgrid(*[np.asarray(a) for a in axes], indexing="ij")
    rows = np.column_stack([m.ravel() for m in mesh]) if names else np.empty((0, 0))
    return names, rows, "a grid of " + " x ".join(f"{len(a)} {n}"
                                                  for n, a in zip(names, axes, strict=True))


def _random(where, loop, x, y, table):
    samples, seed = table.get("samples"), table.get("seed", 0)
    if isinstance(samples, bool) or not isinstance(samples, int) or not 1 <= samples <= MAX_ROWS:
        raise ValueError(f"{where}: [random] samples must be an integer from 1 to {MAX_ROWS}")
    if isinstance(seed, bool) or not isinstance(seed, int) or seed < 0:
        raise ValueError(f"{where}: [random] seed must be a non-negative integer, got {seed!r}")
    named = {k: v for k, v in table.items() if k not in ("samples", "seed")}
    ranges = {name: (int(low), int(high)) if name == "d" and float(low).is_integer()
              and float(high).is_integer() else (low, high)
              for name, low, high in _ranges(where, "[random]", loop, x, y, named, strict=True)}
    if not ranges:
        return [], np.empty((0, 0)), ""
    # The declared ranges' corners, not only the draws, within the loop's bounds and domain.
    check_corners(loop, loop.defaults, x, y, ranges, f"{where}: [random]")
    from ..numeric.analysis.probability import draw_values

    # The draws of the probability map's: one seeded generator, whole delays for d.
    draws = draw_values(loop, ranges, samples, seed, axes=(x, y))
    rows = np.column_stack([draws[n] for n in ranges])
    return list(ranges), rows, f"{samples} random draws of {', '.join(ranges)} (seed {seed})"


def _table(plan, values, reasons, suffix):
    """The table's bytes: every row's inputs and answers, the units in the names."""
    loop, question = plan["loop"], plan["question"]
    units = getattr(loop, "units", {}) or {}

    def unit_of(name):
        if name == "d":
            return "samples"
        if name == "Td":
            return "s"
        if name == "area":
            ux, uy = units.get(question.x, ""), units.get(question.y, "")
            return f"({ux})({uy})" if ux and uy else ""
        if name == "count":
            return ""
        return units.get(name, "")

    def label(name, of):
        unit = unit_of(of)
        return f"{name} [{unit}]" if unit else name

    inputs = [label(n, n) for n in plan["names"]]
    outputs = [label(name, of) for name, of in question.columns()]
    if suffix == ".npz":
        buf = io.BytesIO()
        np.savez(buf, inputs=plan["rows"], input_names=np.array(inputs),
                 answers=values, answer_names=np.array(outputs),
                 reasons=np.array(reasons, dtype=str), question=np.array(question.kind),
                 loop=np.array(loop.name))
        return buf.getvalue()
    buf = io.StringIO()
    buf.write(",".join(inputs + outputs + ["reason"]) + "\n")
    for row, answer, reason in zip(plan["rows"], values, reasons, strict=True):
        cells = [f"{v:.12g}" for v in row] + [f"{v:.12g}" for v in answer]
        reason = " ".join(reason.split()).replace('"', "'")
        buf.write(",".join(cells + [f'"{reason}"']) + "\n")
    return buf.getvalue()
