"""A sweep of 200 certified regions: serial against a two-worker Dask LocalCluster, in one run.

    python benchmarks/bench_sweep.py [--rows 200] [--chunk 5] [--workers 2]

The rows are the paper's loop (examples/loops/paper.toml) at d = 1 .. 40 and
five viscous frictions b; each is ``Loop.limits`` (a certified region).
Both runs start from an empty chunk store; the loop's derivation is warmed
up in the serial process first, and the cluster is started and each worker
answers one row before its clock starts (both printed apart, and the
speed-up with them).  Prints both times, the speed-up
(target: at least 1.6x on 2 workers) and whether the tables are identical.
"""

import argparse
import os
import pathlib
import tempfile
import time

import numpy as np

import symstab
from symstab.cli.sweep import local_cluster
from symstab.cli.sweep_store import ChunkStore, Question, run_sweep

from _timing import fmt

ROOT = pathlib.Path(__file__).resolve().parent.parent


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--rows", type=int, default=200)
    parser.add_argument("--chunk", type=int, default=5)
    parser.add_argument("--workers", type=int, default=2)
    args = parser.parse_args()
    from dask.distributed import Client

    loop = symstab.load_loop(ROOT / "examples" / "loops" / "paper.toml")
    d = np.arange(1, 41, dtype=float)
    b = np.linspace(0.0162, 0.0648, max(1, args.rows // d.size))
    rows = np.column_stack([m.ravel() for m in np.meshgrid(d, b, indexing="ij")])[:args.rows]
    names = ("d", "b")
    loop.limits(d=1, b=0.0324)      # warm-up: the derivation and kernels, here
    print(f"{os.cpu_count()} CPUs; {len(rows)} rows (d = 1 .. 40, {b.size} b), chunks of "
          f"{args.chunk}")
    with tempfile.TemporaryDirectory() as tmp:
        n_chunks = -(-len(rows) // args.chunk)
        start = time.perf_counter()
        serial, _, _ = run_sweep(loop, Question("limits", "B", "K"), names, rows, chunk=args.chunk,
                                 store=ChunkStore(pathlib.Path(tmp) / "serial", "s", n_chunks))
        t_serial = time.perf_counter() - start
        start = time.perf_counter()
        cluster = local_cluster(args.workers)      # symstab sweep's own
        client = Client(cluster)
        t_start = time.perf_counter() - start
        # Each worker's first row imports symstab and rebuilds the loop's kernels (the
        # serial process did that before its clock started): timed apart, like the start-up.
        start = time.perf_counter()
        client.run(_warm, str(ROOT / "examples" / "loops" / "paper.toml"))
        t_warm = time.perf_counter() - start
        try:
            start = time.perf_counter()
            found, _, _ = run_sweep(loop, Question("limits", "B", "K"), names, rows, chunk=args.chunk,
                                    store=ChunkStore(pathlib.Path(tmp) / "dask", "d", n_chunks),
                                    client=client)
            t_dask = time.perf_counter() - start
        finally:
            client.close()
            cluster.close()
    print(f"  serial                          {fmt(t_serial)} ({fmt(t_serial / len(rows))} a row)")
    print(f"  LocalCluster of {args.workers} workers         {fmt(t_dask)} (apart: its start-up "
          f"{fmt(t_start)}, the workers' first row {fmt(t_warm)})")
    print(f"  speed-up {t_serial / t_dask:.2f}x (with the start-up and first rows "
          f"{t_serial / (t_dask + t_start + t_warm):.2f}x; target >= 1.6x on 2 workers); tables "
          f"identical: {np.array_equal(serial, found, equal_nan=True)}")


def _warm(path):
    """On a worker: import symstab and answer one row (the kernels load or build)."""
    import symstab

    symstab.load_loop(path).limits(d=1, b=0.0324)


if __name__ == "__main__":
    main()
