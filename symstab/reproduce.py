"""``symstab reproduce``: derivation, audit and figures in one run.

Stages, each reported with its time:

1. **derive** -- every derivation step and the generated kernels, rebuilt
   from the model; written to ``OUT/derivations`` and ``OUT/generated``,
   and compared with the committed copies (the drift check: the package's
   own ``symstab/_generated`` and, in a source checkout, ``derivations/
   generated``);
2. **audit** and **figures** -- the audit's checks and the figures share
   one pool of worker processes (two by default: the machine this was
   built for has two cores), forked after the derivation so that they start
   with its symbolic results cached: ``OUT/REPORT.md``, ``OUT/audit.json``
   and ``OUT/figures/*.png``;
3. **index** -- ``OUT/index.md`` links the report and every figure, with a
   line per figure on what the paper shows and what symstab finds.

Ctrl-C (SIGINT) and SIGTERM stop the workers at once, remove the temporary
folder and leave ``OUT`` as it was, print ``symstab reproduce: interrupted``
and exit with status 130 and 143 (128 + the signal number).
"""

import concurrent.futures
import contextlib
import io
import multiprocessing
import os
import pathlib
import signal
import sys
import tempfile
import threading
import time

__all__ = ["reproduce", "render_index", "worker_pool", "default_workers"]

#: Figures in decreasing cost (measured: the limits of Figs. 11 and 12 take
#: longest), so that the longest tasks start first and the audit's many
#: short checks fill the workers at the end.
_ORDER = ("fig12", "fig11", "fig10", "fig8", "fig6", "fig7", "fig4", "fig5", "fig3")


def default_workers():
    """Worker processes used by default: the cores, at most two.

    The main job was sized for two cores; more workers only add start-up
    and duplicated symbolic work.
    """
    return max(1, min(2, os.cpu_count() or 1))


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


def _figure_task(name):
    from . import figures

    plt = figures.pyplot()
    start = time.perf_counter()
    result = getattr(figures, name)()
    buf = io.BytesIO()
    result.figure.savefig(buf, format="png", metadata={"Software": None})
    plt.close(result.figure)
    result.figure = None
    return result, buf.getvalue(), time.perf_counter() - start


def _derive(out, log):
    from . import codegen, derive
    from ._project import project_root

    files = derive.render(derive.derivation_steps())
    code = codegen.generated_files()
    derive.write(out / "derivations", files)
    derive.write(out / "generated", code)
    package_code = pathlib.Path(__file__).parent / "_generated"
    drift = [f"symstab/_generated/{pathlib.Path(p).name}"
             for p in derive.check(package_code, code, owned=codegen.OWNED)]
    root = project_root()
    checkout = None if root is None else root / "derivations" / "generated"
    if checkout is not None and checkout.is_dir():
        drift += derive.check(checkout, files)
        where = "the installed package's symstab/_generated and derivations/generated"
    else:
        where = ("the installed package's symstab/_generated (no derivations/generated here: "
                 "not a source checkout)")
    for path in drift:
        log(f"  drift: {path} differs from a fresh derivation; run `symstab derive`")
    return drift, where


def render_index(results, verdicts, drift, where):
    """The text of ``index.md`` (no times or dates: the same run gives the same bytes)."""
    counts = {}
    for v in verdicts:
        counts[v] = counts.get(v, 0) + 1
    lines = [
        "# symstab reproduction of Mashayekhi et al., IEEE Trans. Haptics 2025",
        "",
        "Generated by `symstab reproduce`; do not edit.",
        "",
        "## Derivation",
        "",
        f"Every derivation step is in [derivations/](derivations/) and the generated kernels in "
        f"[generated/](generated/). Drift check against {where}: "
        + ("**no drift**." if not drift else f"**{len(drift)} file(s) differ**: "
           + ", ".join(f"`{p}`" for p in drift) + "."),
        "",
        "## Audit",
        "",
        f"[REPORT.md](REPORT.md) ([audit.json](audit.json)): {len(verdicts)} checks: "
        + ", ".join(f"{n} {v}" for v, n in counts.items()) + ".",
        "",
        "## Figures",
        "",
        "| figure | what the paper shows | what symstab finds |",
        "| --- | --- | --- |",
    ]
    for r in results:
        lines.append(f"| [{r.title}](figures/{r.name}.png) | {r.paper} | {r.symstab} |")
    return "\n".join(lines) + "\n"


class _Interrupted(BaseException):
    """SIGINT or SIGTERM, raised in the main thread so that the cleanup runs.

    A BaseException, like KeyboardInterrupt, so that no ``except Exception``
    on the way swallows it.
    """

    def __init__(self, signum):
        super().__init__(signum)
        self.signum = signum


def _on_signal(signum, frame):
    # One signal is enough: a second one must not cut the cleanup short.
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    signal.signal(signal.SIGTERM, signal.SIG_IGN)
    raise _Interrupted(signum)


@contextlib.contextmanager
def _signals_raise():
    """SIGINT and SIGTERM raise :class:`_Interrupted` in this block.

    Only in the main thread (elsewhere Python does not allow handlers, and
    the block runs with the signals as they are).
    """
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    previous = {sig: signal.signal(sig, _on_signal) for sig in (signal.SIGINT, signal.SIGTERM)}
    try:
        yield
    finally:
        for sig, handler in previous.items():
            signal.signal(sig, handler)


@contextlib.contextmanager
def _signals_deferred():
    """Hold SIGINT and SIGTERM back until the block is done (it must not be cut in two)."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    held = {signal.SIGINT, signal.SIGTERM}
    signal.pthread_sigmask(signal.SIG_BLOCK, held)
    try:
        yield
    finally:
        signal.pthread_sigmask(signal.SIG_UNBLOCK, held)


def reproduce(out_dir, *, workers=2, log=None):
    """Run every stage into ``out_dir``; return ``(index path, drifted files)``.

    Everything is built in a temporary folder beside ``out_dir`` and moved
    into it only when every stage has succeeded, so a failure leaves
    ``out_dir`` as it was.  ``log(line)`` receives progress lines (default:
    print to stderr).

    On Ctrl-C (SIGINT) or SIGTERM, when called from the main thread, the
    worker processes are stopped and the temporary folder removed at once;
    then ``symstab reproduce: interrupted`` goes to stderr and ``SystemExit``
    ends the program with status 130 or 143 (128 + the signal number), as
    the command line promises.
    """
    from .figures import require_matplotlib

    log = log or (lambda line: print(line, file=sys.stderr, flush=True))
    out = pathlib.Path(out_dir)
    if out.exists() and not out.is_dir():
        raise ValueError(f"--out must be a directory, got file {out}")
    if isinstance(workers, bool) or not isinstance(workers, int) or workers < 1:
        raise ValueError(f"workers must be an integer >= 1, got {workers!r}")
    require_matplotlib()
    try:
        import paper_checks.audit  # noqa: F401
    except ImportError as exc:  # pragma: no cover - packaging problem
        raise ValueError(f"the paper_checks package is not installed ({exc})") from None
    parent = out.resolve().parent
    parent.mkdir(parents=True, exist_ok=True)
    try:
        with _signals_raise(), \
                tempfile.TemporaryDirectory(dir=parent, prefix=f".{out.name}.") as tmp:
            index, drift = _run(pathlib.Path(tmp), workers, log)
            with _signals_deferred():
                for path in sorted(pathlib.Path(tmp).rglob("*")):
                    if path.is_file():
                        target = out / path.relative_to(tmp)
                        target.parent.mkdir(parents=True, exist_ok=True)
                        os.replace(path, target)
    except _Interrupted as stop:
        print("symstab reproduce: interrupted", file=sys.stderr, flush=True)
        raise SystemExit(128 + stop.signum) from None
    log(f"reproduced into {out}: index.md, REPORT.md, figures/")
    return out / index.name, drift


def _run(out, workers, log):
    from paper_checks import audit

    from . import figures
    from .derive import write, write_bytes

    total = time.perf_counter()
    timings = []
    log("[1/3] derive: derivation steps, proofs and generated kernels ...")
    start = time.perf_counter()
    drift, where = _derive(out, log)
    timings.append(("derive", time.perf_counter() - start))
    log(f"      done in {timings[-1][1]:.1f} s ({'no drift' if not drift else f'{len(drift)} drifted'})")
    log(f"[2/3] audit and {len(_ORDER)} figures, {workers} worker processes ...")
    start = time.perf_counter()
    results = {}
    audit.registered()  # import the checks before the workers fork: they inherit them
    with worker_pool(workers) as pool:
        # The figures first: they are the longest tasks, and the audit's
        # many short checks then fill the gaps at the end.
        futures = {pool.submit(_figure_task, name): name for name in _ORDER}
        findings = audit.run_audit(executor=pool)
        verdicts = [f.verdict for f in findings]
        write(out, {"REPORT.md": audit.render_report(findings), "audit.json": audit.to_json(findings)})
        log(f"      audit: {len(verdicts)} checks ({time.perf_counter() - start:.0f} s)")
        for future in concurrent.futures.as_completed(futures):
            result, png, seconds = future.result()
            write_bytes(out / "figures" / f"{result.name}.png", png)
            results[futures[future]] = result
            timings.append((result.name, seconds))
            log(f"      {result.name}.png ({seconds:.1f} s)")
    timings.append(("audit and figures (wall)", time.perf_counter() - start))
    ordered = [results[f.__name__] for f in figures.FIGURES]
    log("[3/3] index ...")
    write(out, {"index.md": render_index(ordered, verdicts, drift, where)})
    timings.append(("total", time.perf_counter() - total))
    log("timings: " + ", ".join(f"{name} {seconds:.1f} s" for name, seconds in timings))
    return out / "index.md", drift
