"""The audit: every check of the paper, its verdict, and the report.

A check is a function registered with :func:`check`; it returns an
:class:`Outcome` whose verdict is one of :data:`VERDICTS`:

``confirmed``
    the printed form equals the derivation (proved by the exact checker where
    possible, otherwise high-precision numerics over a stated sample), or the
    number is reproduced within the paper's rounding;
``erratum``
    the printed form is wrong; the outcome states the corrected form, and the
    evidence shows the corrected form is confirmed;
``approximation``
    the printed form is an approximation; the evidence quantifies its error;
``not-reproduced``
    a number the derivation does not give within rounding, with both numbers;
``not-checkable``
    experimental, figure-only or notation-only content, with the reason and
    the theory value where one exists.

The check modules (``eq_*.py``, ``claims.py``, ``open_questions.py``) only
call :mod:`symstab` and read :mod:`paper_checks.printed`; no formula is
derived here.

The checks are independent, so :func:`run_audit` runs them in worker
processes (two by default).  A module whose checks share expensive results
(a region classified by root counting, an exact theta_max) keeps them in
:class:`paper_checks._common.Memo` caches and lists the calls in a
``prefetch()`` function: those calls run first, one task each, and the
module's checks then start with every result cached, so no result is
computed twice and the order of the checks does not matter.
"""

import collections
import concurrent.futures
import dataclasses
import importlib
import json
import sys

from .outcome import VERDICTS, Outcome

__all__ = [
    "VERDICTS", "Outcome", "Finding", "check", "registered", "run_audit",
    "render_report", "to_json", "CHECK_MODULES", "warm_caches",
]


#: Modules whose import registers checks, in report order (in this package:
#: ``symstab.paper_checks`` once installed).
CHECK_MODULES = (
    ".eq_model",
    ".eq_boundary",
    ".eq_theta_max",
    ".eq_limits",
    ".claims",
    ".open_questions",
)


@dataclasses.dataclass(frozen=True)
class Finding:
    """One row of the report."""

    id: str
    kind: str
    where: str
    claim: str
    verdict: str
    evidence: str
    corrected: str = ""


_REGISTRY = {}


def check(id, *, kind, where, claim):
    """Register the decorated function as the check ``id``.

    Parameters
    ----------
    id : str
        ``eqN``, ``eqN.part`` or ``claim:<short_name>``.
    kind : {"equation", "claim"}
    where : str
        Where in the paper (equation number, section, lines).
    claim : str
        What the paper states, in one line.
    """
    if kind not in ("equation", "claim"):
        raise ValueError(f"kind must be 'equation' or 'claim', got {kind!r}")
    if (kind == "claim") != id.startswith("claim:"):
        raise ValueError(f"claim ids start with 'claim:', equation ids with 'eq': {id!r}")

    def register(func):
        if id in _REGISTRY:
            raise ValueError(f"check {id!r} registered twice")
        _REGISTRY[id] = (kind, where, claim, func)
        return func

    return register


def registered():
    """Import every check module and return ``{id: (kind, where, claim, func)}``."""
    for name in CHECK_MODULES:
        importlib.import_module(name, __package__)
    return dict(_REGISTRY)


def _selected(ids):
    checks = registered()
    if ids is not None:
        unknown = sorted(set(ids) - set(checks))
        if unknown:
            raise ValueError(f"unknown check ids: {', '.join(unknown)}")
        checks = {k: v for k, v in checks.items() if k in set(ids)}
    return checks


def _finding(cid, entry, outcome):
    kind, where, claim, _ = entry
    return Finding(cid, kind, where, claim, outcome.verdict, outcome.evidence, outcome.corrected)


def run_audit(ids=None, progress=None, *, workers=None, executor=None):
    """Run the checks (all, or those in ``ids``) and return the findings.

    The findings are in report order however the checks were scheduled,
    and the same whatever the number of workers.

    Parameters
    ----------
    ids : iterable of str, optional
        Only these checks.
    progress : callable, optional
        Called with ``(index, total, id)`` as each check starts (one worker)
        or finishes (several).
    workers : int, optional
        Worker processes; 1 runs every check here, in order.  Default: the
        cores, at most two (:func:`symstab._workers.default_workers`).
    executor : concurrent.futures.Executor, optional
        Run the checks in this pool (whose workers are shared with other
        work, as in ``symstab reproduce``) instead of a new one.
    """
    from symstab._workers import check_workers, default_workers, worker_pool

    checks = _selected(ids)
    if executor is not None:
        return _run_parallel(checks, progress, executor)
    workers = default_workers() if workers is None else check_workers(workers)
    if workers == 1 or len(checks) < 2:
        findings = []
        for n, (cid, entry) in enumerate(checks.items(), 1):
            if progress is not None:
                progress(n, len(checks), cid)
            findings.append(_finding(cid, entry, entry[3]()))
        return findings
    warm_caches()
    with worker_pool(min(workers, len(checks))) as pool:
        return _run_parallel(checks, progress, pool)


def warm_caches():
    """Derive here what the checks of both workers need (about 3 s), before workers fork.

    Forked workers inherit these cached results instead of each deriving
    them again: the same wall time on idle cores, less CPU time on busy
    ones.  Workers that are spawned (no fork on the platform) derive them
    themselves.
    """
    import multiprocessing

    if "fork" not in multiprocessing.get_all_start_methods():
        return
    from symstab.numeric.paper.paper_loop import paper_loop
    from symstab.numeric.paper.reference import boundary_point
    from symstab.symbolic.boundary import coefficients
    from symstab.symbolic.loop import characteristic_polynomial
    from symstab.symbolic.small_theta import small_theta_limits
    from symstab.symbolic.theta_max import closed_form_d0, newton_form_gamma0

    characteristic_polynomial()
    coefficients()
    small_theta_limits()
    # Each worker built these again (about 2 s of CPU each, measured per worker):
    # the theta_max forms, the paper's Loop, and the 30-digit boundary functions.
    closed_form_d0()
    newton_form_gamma0()
    paper_loop()
    boundary_point(1.0, gamma=0.0, d=0, delta=0.1)


def _prefetch_task(name, args):
    from ._common import Memo

    registered()  # a worker forked or spawned before the check modules were imported
    return Memo.registry[name].compute(args)


def _check_task(cid, cached):
    from ._common import Memo

    func = registered()[cid][3]
    Memo.fill(cached)
    return func()


def _run_parallel(checks, progress, executor, in_flight=None):
    """Run ``checks`` as tasks of ``executor``: the prefetches first, then their users.

    At most ``in_flight`` tasks (default: one more than the workers) are
    queued at once, so that the checks released when their module's
    prefetches are done go ahead of the checks that need none: the longest
    chains then start early instead of forming the tail.
    """
    waiting = {}       # module -> its checks, released when its prefetches are done
    calls = {}         # (name, args) -> the modules that wait for it
    needs = {}         # module -> the (name, args) its prefetch lists
    for module in dict.fromkeys(entry[3].__module__ for entry in checks.values()):
        prefetch = getattr(sys.modules[module], "prefetch", None)
        if prefetch is None:
            continue
        waiting[module] = [cid for cid, entry in checks.items() if entry[3].__module__ == module]
        for memo, args in prefetch():
            calls.setdefault((memo.name, args), set()).add(module)
            needs.setdefault(module, []).append((memo.name, args))
    waited = {cid for cids in waiting.values() for cid in cids}
    ready = collections.deque(("prefetch", name, args) for name, args in calls)
    ready.extend(("check", cid) for cid in checks if cid not in waited)
    limit = in_flight or (getattr(executor, "_max_workers", None) or 2) + 1
    pending, cached, outcomes = {}, {}, {}

    def snapshot(cid):
        # A new dict of the values this check's module needs, built here and
        # never touched again: a process pool pickles a task's arguments
        # later, in its feeder thread, so handing it ``cached`` itself (which
        # this loop keeps filling) raced ("dictionary changed size during
        # iteration").
        values = {}
        for name, args in needs.get(checks[cid][3].__module__, ()) if cid in waited else ():
            values.setdefault(name, {})[args] = cached[name][args]
        return values

    def submit():
        while ready and len(pending) < limit:
            task = ready.popleft()
            if task[0] == "prefetch":
                future = executor.submit(_prefetch_task, task[1], task[2])
            else:
                future = executor.submit(_check_task, task[1], snapshot(task[1]))
            pending[future] = task

    def release_done_modules():
        for module in list(waiting):
            if not any(module in mods for key, mods in calls.items()
                       if key[0] not in cached or key[1] not in cached[key[0]]):
                ready.extendleft(("check", cid) for cid in reversed(waiting.pop(module)))

    release_done_modules()
    submit()
    while pending:
        done, _ = concurrent.futures.wait(pending, return_when=concurrent.futures.FIRST_COMPLETED)
        for future in done:
            task = pending.pop(future)
            if task[0] == "prefetch":
                cached.setdefault(task[1], {})[task[2]] = future.result()
                release_done_modules()
                continue
            outcomes[task[1]] = future.result()
            if progress is not None:
                progress(len(outcomes), len(checks), task[1])
        submit()
    return [_finding(cid, entry, outcomes[cid]) for cid, entry in checks.items()]


def _cell(text):
    return " ".join(str(text).split()).replace("|", "\\|")


def render_report(findings):
    """Return REPORT.md as a string (deterministic)."""
    counts = {v: sum(f.verdict == v for f in findings) for v in VERDICTS}
    lines = [
        "# Audit of Mashayekhi et al., IEEE Trans. Haptics 2025",
        "",
        "Generated by `symstab audit`; do not edit. Each row compares one printed",
        "equation or numeric claim of the paper with symstab's derivation from",
        "G(s) = 1/(m s^2 + b s), the zero-order hold, the delay z^-d and VE(z) of eq. (1).",
        "Exact verdicts come from the identity checker (`symstab.proof.identity`: both sides",
        "written in w = e^{j theta/2}, E = e^{j d theta} with Gamma independent and",
        "compared as rational functions, cross-checked at 40 digits); numeric ones",
        "from mpmath evaluations of the derivation, and stability from certified counts",
        "of the roots outside the unit circle. The \"where\" column names the paper's",
        "equation and its section (Sec. I-VIII, Appendix A-E), or the section and figure",
        "of a claim. Symbols are spelled out in ASCII: alpha, beta, gamma, delta, theta;",
        "d is the delay in samples and Gamma = e^delta.",
        "",
        "## Summary",
        "",
        "| verdict | count |",
        "| --- | ---: |",
    ]
    lines += [f"| {v} | {counts[v]} |" for v in VERDICTS]
    lines += [f"| **total** | **{len(findings)}** |", ""]
    errata = [f for f in findings if f.verdict in ("erratum", "not-reproduced")]
    if errata:
        lines += ["## Errata and numbers not reproduced", ""]
        for f in errata:
            fix = _cell(f.corrected)
            if len(fix) > 160:
                fix = fix[:160] + " ... (in full in the table below)"
            lines.append(f"- **{f.id}** ({f.where}): {_cell(f.evidence)}"
                         + (f" Corrected: {fix}" if f.corrected else ""))
        lines.append("")
    for kind, title in (("equation", "Equations"), ("claim", "Numeric and qualitative claims")):
        rows = [f for f in findings if f.kind == kind]
        if not rows:
            continue
        lines += [f"## {title}", "",
                  "| id | where | claimed | verdict | evidence | corrected form |",
                  "| --- | --- | --- | --- | --- | --- |"]
        for f in rows:
            lines.append(f"| {f.id} | {_cell(f.where)} | {_cell(f.claim)} | {f.verdict} | "
                         f"{_cell(f.evidence)} | {_cell(f.corrected)} |")
        lines.append("")
    return "\n".join(lines)


def to_json(findings):
    """Return the findings as the JSON text of ``symstab audit --json``."""
    rows = []
    for f in findings:
        detail = f.evidence + (f" Corrected: {f.corrected}" if f.corrected else "")
        rows.append({"id": f.id, "kind": f.kind, "verdict": f.verdict, "detail": detail})
    return json.dumps(rows, indent=1, ensure_ascii=False) + "\n"
