"""Sweeps: one question asked of a loop at many parameter points, a chunk at a time.

A sweep is a table of rows, each a value of every swept parameter (a
device family, delays, cut-offs, uncertain values ...), and a question
asked at every row (:class:`Question`): the limits of the stable set in the
loop's plane (:meth:`symstab.Loop.limits`: the largest ``y``, the ``x``
where it is reached, the extent in ``x`` and the area), the best value
of one or two parameters for K_max, the Z-width or the passive K_max
(:meth:`symstab.Loop.design`), the D-decomposition's cells and stable
pieces (:meth:`symstab.Loop.region`), the limits of the robust set over a
box (:meth:`symstab.Loop.limits` with ``uncertain``), or the largest ``y``
a simulation with non-idealities accepts (:meth:`symstab.Loop.simulated_limit`).  The rows are cut into chunks;
each chunk is evaluated serially or as one task on a Dask cluster
(:mod:`dask.distributed`, an optional extra), and saved, complete, in a
folder as soon as it is done (:class:`ChunkStore`): an interrupted sweep
run again skips the chunks already saved.  Every row is evaluated by the
same code wherever it runs, so a cluster gives the serial numbers exactly.
"""

import dataclasses
import hashlib
import json
import pathlib

import numpy as np

from .._io import write_bytes

__all__ = ["QUESTIONS", "Question", "evaluate_rows", "ChunkStore", "run_sweep", "sweep_key"]

#: The questions a sweep asks.
QUESTIONS = {
    "limits": "the limits of the stable set in the plane (Loop.limits)",
    "design": "the best value of one or two parameters (Loop.design)",
    "region": "the D-decomposition of the plane: its cells, stable pieces and area (Loop.region)",
    "robust": "the limits of the set stable for every value of a box (Loop.limits, uncertain)",
    "simulated": "the largest y of a simulated run that stays small (Loop.simulated_limit)",
}
#: The options of a simulated row (Nonidealities' and the runs').
SIMULATION_KEYS = ("amplitude", "steps", "x0", "encoder_resolution", "force_limit",
                   "force_resolution")


@dataclasses.dataclass(frozen=True)
class Question:
    """What a sweep asks at every row, and the columns of its answer.

    Attributes
    ----------
    kind : str
        A key of :data:`QUESTIONS`.
    x, y : str
        The plane.
    over : tuple of (str, float, float)
        ``design``: the parameters searched and their ranges (SI);
        ``robust``: the box (``d``: the delays in samples, whole ends each whole
        delay, a fractional end every delay; ``Td``: every delay, in seconds).
    maximize : str
        ``design``: ``"y_max"``, ``"area"`` or ``"passive"``.
    strips : int
        ``robust``: the strips across the plane.
    simulation : tuple of (str, float)
        ``simulated``: ``amplitude`` (required), ``steps``, ``x0`` and the
        non-idealities (:data:`SIMULATION_KEYS`), in SI.
    """

    kind: str
    x: str
    y: str
    over: tuple = ()
    maximize: str = "y_max"
    strips: int = 64
    simulation: tuple = ()

    def __post_init__(self):
        if self.kind not in QUESTIONS:
            raise ValueError(f"question must be one of {', '.join(QUESTIONS)}, got {self.kind!r}")
        if self.kind == "design" and not 1 <= len(self.over) <= 2:
            raise ValueError("design searches one or two parameters: give over")
        if self.kind == "design" and self.maximize not in ("y_max", "area", "passive"):
            raise ValueError(f"maximize must be y_max, area or passive, got {self.maximize!r}")
        if self.kind == "robust" and not self.over:
            raise ValueError("robust needs the box: give over (name, low, high)")
        if self.kind == "simulated" and "amplitude" not in dict(self.simulation):
            raise ValueError("simulated needs the accepted amplitude: give simulation "
                             "(('amplitude', A), ...)")

    def columns(self):
        """The answer's columns: ``(name, the parameter whose unit it has, or "area")``."""
        x, y = self.x, self.y
        limits = ((f"{y}_max", y), (f"{x}_at_{y}_max", x), (f"{x}_min", x), (f"{x}_max", x),
                  ("area", "area"))
        if self.kind == "limits":
            return limits
        if self.kind == "region":
            return (("cells", "count"), ("stable_pieces", "count"), ("area", "area"))
        if self.kind == "robust":
            return limits + (("marginal_area", "area"), ("nominal_area", "area"))
        if self.kind == "simulated":
            return ((f"simulated_{y}_max", y), (f"{x}_at_simulated_{y}_max", x),
                    (f"linear_{y}_max", y))
        target = {"y_max": (f"{y}_max", y), "area": ("area", "area"),
                  "passive": (f"passive_{y}_max", y)}[self.maximize]
        return tuple((f"best_{name}", name) for name, _, _ in self.over) + (
            (target[0] + "_at_best", target[1]), (target[0] + "_at_nominal", target[1]))

    def answer(self, loop, values):
        """The answer's numbers at one row (NaN: none) and why there is none (or empty)."""
        if self.kind in ("limits", "robust"):
            extra = {} if self.kind == "limits" else {
                "uncertain": {name: (low, high) for name, low, high in self.over},
                "strips": self.strips}
            found = loop.limits(self.x, self.y, **extra, **values)
            numbers = [found.y_max, found.x_at_y_max, found.x_min, found.x_max, found.area]
            if self.kind == "robust":
                region = found.region
                numbers += [region.marginal_area,
                            region.nominal.area if region.nominal is not None else None]
            return [np.nan if v is None else float(v) for v in numbers], found.reason
        if self.kind == "region":
            found = loop.region(self.x, self.y, **values)
            reason = found.limits().reason if not found.stable else (
                "unbounded: the stable set reaches the window's " + ", ".join(found.unbounded)
                if found.unbounded else "")
            return [float(len(found.cells)), float(len(found.stable)), found.area], reason
        if self.kind == "simulated":
            from ..numeric.simulation.simulator import Nonidealities

            options = dict(self.simulation)
            nonideal = Nonidealities(**{k: v for k, v in options.items()
                                        if k not in ("amplitude", "steps", "x0")})
            steps = options.get("steps")
            found = loop.simulated_limit(self.x, self.y, amplitude=options["amplitude"],
                                         nonideal=nonideal, x0=options.get("x0"),
                                         steps=None if steps is None else int(steps), **values)
            numbers = (found.y_max, found.x_at_y_max, found.linear.y_max)
            return [np.nan if v is None else float(v) for v in numbers], found.reason
        found = loop.design(over={name: (low, high) for name, low, high in self.over},
                            maximize=self.maximize, x=self.x, y=self.y, **values)
        best = [np.nan if found.best is None else float(found.best[name])
                for name, _, _ in self.over]
        value = [np.nan if v is None or not np.isfinite(v) else float(v)
                 for v in (found.value, found.value_nominal)]
        return best + value, found.message


def evaluate_rows(loop, question, names, rows):
    """Answer ``question`` at every row: ``(values (n, k), reasons (n,))``.

    Parameters
    ----------
    loop : symstab.Loop
    question : Question
    names : tuple of str
        The swept parameters, the columns of ``rows``.
    rows : ndarray, shape (n, len(names))
        Their values in SI (``d`` in samples, ``Td`` in seconds).

    Returns
    -------
    (ndarray, list of str)
        The answers (NaN where there is none: an empty stable set) and why
        (empty text where there is an answer).
    """
    out = np.full((len(rows), len(question.columns())), np.nan)
    reasons = []
    for i, row in enumerate(rows):
        values = {n: int(v) if n == "d" and float(v).is_integer() else float(v)
                  for n, v in zip(names, row, strict=True)}
        out[i], reason = question.answer(loop, values)
        reasons.append(reason)
    return out, reasons


def sweep_key(*parts):
    """A digest of what determines a sweep's numbers (the loop's text, the question, the rows)."""
    digest = hashlib.sha256()
    for part in parts:
        data = part.tobytes() if isinstance(part, np.ndarray) else str(part).encode("utf-8")
        digest.update(len(data).to_bytes(8, "little") + data)
    return digest.hexdigest()


class ChunkStore:
    """The finished chunks of one sweep, one complete file each, in ``folder``.

    ``folder/sweep.json`` holds the sweep's key (:func:`sweep_key`); a
    folder that holds another sweep's chunks is refused, not mixed in.
    A chunk is written atomically (:func:`symstab.proof.derive.write_bytes`),
    so a file there is always whole, also after an interruption.
    """

    def __init__(self, folder, key, n_chunks):
        self.folder = pathlib.Path(folder)
        manifest = self.folder / "sweep.json"
        if manifest.exists():
            try:
                kept = json.loads(manifest.read_text(encoding="utf-8"))
            except (OSError, ValueError):
                kept = None
            if not isinstance(kept, dict) or kept.get("key") != key:
                raise ValueError(f"{self.folder} holds the chunks of another sweep (or not a "
                                 f"sweep's): remove it, or write this sweep elsewhere")
        else:
            self.folder.mkdir(parents=True, exist_ok=True)
            write_bytes(manifest, json.dumps({"key": key, "chunks": n_chunks}).encode())
        self.n_chunks = n_chunks

    def path(self, index):
        return self.folder / f"chunk-{index:06d}.npz"

    def done(self):
        """The indices of the chunks saved."""
        return {i for i in range(self.n_chunks) if self.path(i).exists()}

    def save(self, index, values, reasons):
        import io

        buf = io.BytesIO()
        np.savez(buf, values=values, reasons=np.array(reasons, dtype=str))
        write_bytes(self.path(index), buf.getvalue())

    def load(self, index):
        with np.load(self.path(index)) as f:
            return f["values"], [str(r) for r in f["reasons"]]


def run_sweep(loop, question, names, rows, *, chunk, store, client=None, progress=None):
    """Evaluate every row, a chunk at a time, serially or on ``client``; the whole table.

    Parameters
    ----------
    loop, question, names, rows
        As :func:`evaluate_rows`.
    chunk : int
        Rows per chunk (a task on the cluster; a file in the store).
    store : ChunkStore
        Where finished chunks are saved; those already there are loaded,
        not evaluated again.
    client : dask.distributed.Client, optional
        Evaluate the chunks on its cluster (default: here, one after another).
    progress : callable, bool or None, optional
        Called with the number of chunks finished (saved ones included);
        True draws a bar (:func:`symstab._validate.check_progress`).

    Returns
    -------
    (ndarray, list of str, int)
        The answers and reasons of every row, in the rows' order, and the
        number of chunks loaded from the store rather than evaluated.
    """
    from .._progress import progress_printer
    from .._validate import check_progress

    slices = [slice(i, min(i + chunk, len(rows))) for i in range(0, len(rows), chunk)]
    progress = check_progress(progress, lambda: progress_printer("chunks", len(slices)))
    values = np.full((len(rows), len(question.columns())), np.nan)
    reasons = [""] * len(rows)
    done = store.done()

    def keep(index, result):
        part = slices[index]
        values[part], reasons[part] = result[0], result[1]

    for index in sorted(done):
        keep(index, store.load(index))
    finished = len(done)
    if progress is not None:
        progress(finished)
    todo = [i for i in range(len(slices)) if i not in done]
    if client is None:
        for index in todo:
            result = evaluate_rows(loop, question, names, rows[slices[index]])
            store.save(index, *result)
            keep(index, result)
            finished += 1
            if progress is not None:
                progress(finished)
    elif todo:
        from dask.distributed import as_completed

        shared = client.scatter(loop, broadcast=True)
        delay = next((n for n in ("d", "Td") if n in names), None)
        if delay is not None:
            # A row's cost grows with its delay: the longest go first, so that no long chunk
            # is left to run alone at the end while the other workers wait.
            column = list(names).index(delay)
            todo.sort(key=lambda i: -rows[slices[i], column].max())
        futures = {client.submit(evaluate_rows, shared, question, names, rows[slices[i]],
                                 pure=False): i for i in todo}
        try:
            for future in as_completed(futures):
                index = futures[future]
                result = future.result()
                store.save(index, *result)
                keep(index, result)
                finished += 1
                if progress is not None:
                    progress(finished)
        finally:
            for future in futures:
                future.cancel()
    return values, reasons, len(done)
