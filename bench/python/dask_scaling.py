"""Pairs/s of batchcol.dask on a LocalCluster of 1 and 2 worker processes (threads 1 each), and the scheduling
overhead per chunk (issue #17).

    PYTHONPATH=build/python /usr/bin/python3 bench/python/dask_scaling.py [--pairs 20000000] [--chunk 500000]

Pairs: random GJK pairs (three 40-point hulls, an ellipsoid, a cone, a sphere; about 58% colliding), boolean
level. Each chunk's six input arrays are made by one task on a worker (as when a task loads one file of pairs) and
persisted before the clock starts; batchcol.dask.collide_chunks then runs each chunk where its inputs are, and only
the sums of the results come back. (Generating the six inputs as separate Dask arrays scatters one chunk's inputs
over both workers: the transfers made 2 workers slower than 1 in a first run.) The same pairs through batchcol.collide() in this process with threads=1 (first
1,000,000) give the engine's own rate. Overhead per chunk: the same cluster on chunks of 10 pairs (the engine's
time is then negligible), wall time / chunks.
"""

import argparse
import resource
import time

import dask
import numpy as np
from distributed import Client, LocalCluster, wait

import batchcol
import batchcol.dask


def table():
    rng = np.random.default_rng(8)
    t = batchcol.ShapeTable()
    for _ in range(3):
        t.add(batchcol.Shape.convex(rng.uniform(-0.2, 0.2, (40, 3))))
    t.add(batchcol.Shape.ellipsoid(0.1, 0.2, 0.15))
    t.add(batchcol.Shape.cone(0.1, 0.2))
    t.add(batchcol.Shape.sphere(0.1))
    return t


def make_chunk(seed, n, shape_count):
    """One chunk of pairs, made on a worker: the six pair arguments, poses in Fortran order (viewed by collide)."""
    rng = np.random.default_rng(seed)
    a = rng.integers(0, shape_count, n).astype(np.uint32)
    b = rng.integers(0, shape_count, n).astype(np.uint32)
    t_a = rng.uniform(-1, 1, (n, 3))
    t_b = t_a + rng.uniform(-0.3, 0.3, (n, 3))
    q = [rng.normal(size=(n, 4)) for _ in range(2)]
    q = [x / np.linalg.norm(x, axis=1, keepdims=True) for x in q]
    return tuple(np.asfortranarray(x) if x.ndim == 2 else x for x in (a, b, t_a, q[0], t_b, q[1]))


def chunk_futures(client, pairs_total, chunk, shape_count, seed):
    sizes = [min(chunk, pairs_total - lo) for lo in range(0, pairs_total, chunk)]
    futures = [client.submit(make_chunk, seed * 1_000_003 + k, n, shape_count, pure=False) for k, n in enumerate(sizes)]
    wait(futures)
    return futures, sizes


def cpu_seconds():
    """User + system CPU time of the calling process (all its threads: TBB's included)."""
    usage = resource.getrusage(resource.RUSAGE_SELF)
    return usage.ru_utime + usage.ru_stime


def timed_job(client, shapes, chunks):
    futures, sizes = chunks
    start = time.perf_counter()
    r = batchcol.dask.collide_chunks(shapes, futures, rows=sizes, level="boolean", threads=1, client=client)
    colliding, iterations = dask.compute(r.collide.sum(), r.iterations.astype(np.int64).sum())
    return time.perf_counter() - start, int(colliding), int(iterations)


def main():
    p = argparse.ArgumentParser()
    p.add_argument("--pairs", type=int, default=20_000_000)
    p.add_argument("--chunk", type=int, default=500_000)
    p.add_argument("--tiny-chunks", type=int, default=1000)
    args = p.parse_args()
    shapes = table()
    answers = set()
    for workers in (1, 2):
        with LocalCluster(n_workers=workers, threads_per_worker=1, processes=True, host="127.0.0.1",
                          dashboard_address=":0") as cluster, Client(cluster) as client:
            chunks = chunk_futures(client, args.pairs, args.chunk, len(shapes), seed=1)
            before = client.run(cpu_seconds)
            seconds, colliding, iterations = timed_job(client, shapes, chunks)
            after = client.run(cpu_seconds)
            cpu = [after[w] - before[w] for w in after]
            answers.add((colliding, iterations))
            # On a shared machine the workers wait for a core part of the time: their CPU seconds say how much of
            # the wall time they actually ran.
            print(f"{workers} worker(s) x 1 thread: {args.pairs} pairs in {len(chunks[1])} chunks: "
                  f"{seconds:.2f} s, {args.pairs / seconds / 1e6:.3f} M pairs/s ({colliding} colliding); worker CPU "
                  f"{' + '.join(f'{c:.2f}' for c in cpu)} s = {sum(cpu) / seconds:.2f} cores busy on average, "
                  f"{args.pairs / sum(cpu) / 1e6:.3f} M pairs per worker CPU second")
            if workers == 2:
                tiny = chunk_futures(client, 10 * args.tiny_chunks, 10, len(shapes), seed=2)
                timed_job(client, shapes, tiny)  # warm-up: imports and the table on both workers
                seconds, _, _ = timed_job(client, shapes, tiny)
                print(f"scheduling overhead: {args.tiny_chunks} chunks of 10 pairs on 2 workers in {seconds:.2f} s: "
                      f"{seconds / args.tiny_chunks * 1e3:.2f} ms wall per chunk "
                      f"(2 workers x wall / chunks: {2 * seconds / args.tiny_chunks * 1e3:.2f} ms)")
                local = make_chunk(7, 1_000_000, len(shapes))
    start = time.perf_counter()
    batchcol.collide(shapes, *local, level="boolean", threads=1)
    seconds = time.perf_counter() - start
    print(f"one process, batchcol.collide, threads 1: 1000000 pairs in {seconds:.2f} s, {1 / seconds:.3f} M pairs/s")
    assert len(answers) == 1, "1 and 2 workers disagree"


if __name__ == "__main__":
    main()
