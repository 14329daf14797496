"""Time `symstab derive` and the exact identity checker (run by hand).

    python benchmarks/bench_derive.py [--runs 3]

1. A full `symstab derive` (every step and every identity proof) in a fresh
   process each run, so no cache carries over; reports the median and the
   figure against the 30 s budget of the core issue.
2. The obvious alternative to the exact checker, ``sympy.simplify`` of the
   difference, on the same identities, side by side: the printed C4 of
   eq. (27) against the derived C4 (small), and the printed alpha of eq. (7)
   with the printed C's against the derived alpha (large); simplify is
   stopped after a time limit.
"""

import argparse
import multiprocessing
import statistics
import subprocess
import sys
import tempfile
import time


def _identities():
    from symstab import boundary, coefficients
    from symstab.paper_checks._common import with_printed_coefficients
    from symstab.paper_checks.printed import PRINTED_COEFFICIENTS, printed

    return {
        "C4, eq. (27)": (PRINTED_COEFFICIENTS["C4"], coefficients()["C4"]),
        "alpha, eq. (7)": (with_printed_coefficients(printed("eq7.alpha").expr), boundary().alpha),
    }


def _simplify_worker(name, queue):
    import sympy as sp

    lhs, rhs = _identities()[name]
    start = time.perf_counter()
    zero = sp.simplify(lhs - rhs)
    queue.put((time.perf_counter() - start, zero == 0))


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=3)
    parser.add_argument("--simplify-limit", type=float, default=120.0)
    args = parser.parse_args()

    times = []
    for _ in range(args.runs):
        with tempfile.TemporaryDirectory() as out:
            start = time.perf_counter()
            subprocess.run([sys.executable, "-m", "symstab", "derive", "--out", out],
                           check=True, capture_output=True)
            times.append(time.perf_counter() - start)
    median = statistics.median(times)
    print(f"symstab derive (fresh process, {args.runs} runs): median {median:.1f} s "
          f"(min {min(times):.1f}, max {max(times):.1f}); budget 30 s -> {median / 30:.2f} of it")

    from symstab import check_identity

    for name, (lhs, rhs) in _identities().items():
        exact = []
        for _ in range(5):
            start = time.perf_counter()
            result = check_identity(lhs, rhs)
            exact.append(time.perf_counter() - start)
        fast = statistics.median(exact)
        print(f"{name}: exact checker median {fast * 1e3:.0f} ms (verdict {result.equal})", end="; ")
        queue = multiprocessing.Queue()
        proc = multiprocessing.Process(target=_simplify_worker, args=(name, queue))
        proc.start()
        proc.join(args.simplify_limit)
        if proc.is_alive():
            proc.terminate()
            print(f"sympy.simplify: no answer within {args.simplify_limit:.0f} s "
                  f"(ratio > {args.simplify_limit / fast:.0f}x)")
        else:
            seconds, zero = queue.get()
            print(f"sympy.simplify {seconds:.1f} s, reduced to zero: {zero} "
                  f"(ratio {seconds / fast:.1f}x)")


if __name__ == "__main__":
    main()
