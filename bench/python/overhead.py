"""Overhead of batchcol.collide() from Python against the same collide() called from C++ (issue #17: at most 5%).

    PYTHONPATH=build/python /usr/bin/python3 bench/python/overhead.py [--pairs 1000000] [--rounds 9] [--threads 2]

1M sphere-sphere pairs (the SIMD closed form: the fastest kernel, so the largest relative overhead), poses in
Fortran order (viewed, no copy). C++ times collide() on a PairBatchView of the very same NumPy buffers (same memory
pages: the difference is the binding alone) and, for reference, on a PairBatch copy (std::vector pages). Each round
runs every variant 3 times in a row and keeps the last 2 (the first warms the allocator for that variant's pattern:
interleaving single calls made fresh result buffers page-fault in some variants and not others); rounds alternate
so that a noisy machine affects every variant alike. Prints medians and minima over all kept runs.
"""

import argparse
import statistics
import time

import numpy as np

import batchcol
from batchcol import _batchcol


def main():
    p = argparse.ArgumentParser()
    p.add_argument("--pairs", type=int, default=1_000_000)
    p.add_argument("--rounds", type=int, default=9)
    p.add_argument("--threads", type=int, default=2)
    args = p.parse_args()
    n = args.pairs
    table = batchcol.ShapeTable()
    ball = table.add(batchcol.Shape.sphere(0.1))
    rng = np.random.default_rng(1)
    t_a = np.asfortranarray(rng.uniform(-1, 1, (n, 3)))
    t_b = np.asfortranarray(t_a + rng.uniform(-0.25, 0.25, (n, 3)))
    q = np.zeros((n, 4), order="F")
    q[:, 0] = 1.0
    index = np.full(n, ball, dtype=np.uint32)
    batch = (index, index, t_a, q, t_b, q)
    cpp = _batchcol._cpp_collide_seconds
    small = tuple(x[:1000] for x in batch)
    for _ in range(3):  # the binding's fixed cost per call, where the engine's time is small and steady
        py_small = []
        for _ in range(2001):
            start = time.perf_counter()
            batchcol.collide(table, *small, level="boolean", threads=args.threads, copy=False)
            py_small.append(time.perf_counter() - start)
        cpp_small = cpp(table, *small, "boolean", args.threads, 2001, False, False)
        print(f"1000 pairs, boolean: Python {statistics.median(py_small) * 1e6:.2f} us, C++ "
              f"{statistics.median(cpp_small) * 1e6:.2f} us (medians of 2001 calls): fixed cost per call "
              f"{(statistics.median(py_small) - statistics.median(cpp_small)) * 1e6:.2f} us")
    print(f"{n} sphere pairs, threads {args.threads}, {args.rounds} rounds x 2 kept runs per variant")
    for level in ("boolean", "witness"):
        out = batchcol.collide(table, *batch, level=level, threads=args.threads)

        def python(reuse):
            start = time.perf_counter()
            r = batchcol.collide(table, *batch, level=level, threads=args.threads, copy=False,
                                 out=out if reuse else None)
            seconds = time.perf_counter() - start
            del r  # freeing the results is outside the timing, as in C++ (its results die after the clock stops)
            return seconds

        variants = {
            "C++ new results": lambda: cpp(table, *batch, level, args.threads, 1, False, False)[0],
            "Python new Results": lambda: python(False),
            "C++ reused results": lambda: cpp(table, *batch, level, args.threads, 2, True, False)[1],
            "Python out=": lambda: python(True),
            "C++ on a PairBatch copy, reused results": lambda: cpp(table, *batch, level, args.threads, 2, True, True)[1],
        }
        rows = {k: [] for k in variants}
        for _ in range(args.rounds):
            for name, run in variants.items():
                rows[name] += [run() for _ in range(3)][1:]
        for stat in (statistics.median, min):
            v = {k: stat(x) for k, x in rows.items()}
            print(f"level {level}, {stat.__name__}: " + ", ".join(f"{k} {t * 1e3:.2f} ms" for k, t in v.items()))
            print(f"  Python / C++: new results {v['Python new Results'] / v['C++ new results']:.3f}, "
                  f"reused results {v['Python out='] / v['C++ reused results']:.3f}")


if __name__ == "__main__":
    main()
