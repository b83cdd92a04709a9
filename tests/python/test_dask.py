"""batchcol.dask on a LocalCluster of 2 worker processes on loopback: the same bits as one process, the table on
every worker once, and a worker killed mid-job recovered by Dask with complete, identical results."""

import os
import signal
import time

import dask
import numpy as np
import pytest

import batchcol
import batchcol.dask

da = pytest.importorskip("dask.array")
distributed = pytest.importorskip("distributed")


@pytest.fixture(scope="module")
def client():
    cluster = distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True, host="127.0.0.1",
                                       dashboard_address=":0")
    c = distributed.Client(cluster)
    c.wait_for_workers(2)
    yield c
    c.close()
    cluster.close()


@pytest.fixture(scope="module")
def gjk_table():
    """Shapes whose pairs run GJK (and EPA at 'penetration'), so chunks take long enough to kill a worker mid-job."""
    rng = np.random.default_rng(8)
    t = batchcol.ShapeTable()
    for k in range(3):
        t.add(batchcol.Shape.convex(rng.uniform(-0.2, 0.2, (40, 3))))
    t.add(batchcol.Shape.ellipsoid(0.1, 0.2, 0.15))
    t.add(batchcol.Shape.cone(0.1, 0.2))
    t.add(batchcol.Shape.sphere(0.1))
    return t


def lazy_pairs(n, chunk, shape_count, seed):
    """Pair arrays as Dask arrays generated chunk by chunk on the workers (recomputable when a worker dies)."""
    rs = da.random.RandomState(seed)
    a = rs.randint(0, shape_count, n, chunks=chunk).astype(np.uint32)
    b = rs.randint(0, shape_count, n, chunks=chunk).astype(np.uint32)
    t_a = rs.uniform(-1, 1, (n, 3), chunks=(chunk, 3))
    t_b = t_a + rs.uniform(-0.3, 0.3, (n, 3), chunks=(chunk, 3))
    q = [rs.normal(size=(n, 4), chunks=(chunk, 4)) for _ in range(2)]
    q = [x / da.linalg.norm(x, axis=1, keepdims=True) for x in q]
    return a, b, t_a, q[0], t_b, q[1]


def same(x, y):
    x, y = np.asarray(x), np.asarray(y)
    return x.shape == y.shape and x.dtype == y.dtype and np.array_equal(x.view(np.uint8), y.view(np.uint8))


def check_equal_to_one_process(client, table, arrays, result):
    local = [np.asarray(x) for x in client.compute(list(arrays), sync=True)]
    want = batchcol.collide(table, *local, level=result.level, threads=2, invalid="status")
    names = [name for name in ("status", "collide", "distance", "iterations", "witness_a", "witness_b", "normal",
                               "direction")]
    got = result.compute(*names)
    for name, value in zip(names, got):
        expected = getattr(want, name)
        if isinstance(expected, tuple):
            assert all(same(u, v) for u, v in zip(value, expected)), name
        else:
            assert same(value, expected), name
    return want


@pytest.mark.parametrize("level", ["boolean", "witness"])
def test_two_workers_equal_one_process_and_table_sent_once_per_worker(client, gjk_table, level):
    arrays = lazy_pairs(30_000, 3_750, len(gjk_table), seed=1)
    result = batchcol.dask.collide(gjk_table, *arrays, level=level, threads=1)
    assert len(result) == 30_000 and len(result.parts) == 8
    want = check_equal_to_one_process(client, gjk_table, arrays, result)
    assert 0 < want.collide.sum() < len(want)
    # Each worker received the table exactly once for the 8 chunks (and the second compute() inside
    # check_equal_to_one_process ran them all again without sending it again).
    received = client.run(lambda dask_worker: dask_worker._batchcol_table_setups.get(result.table, 0))
    assert sorted(received.values()) == [1, 1]
    # No chunk task carries the table in its arguments: they name it.
    graph = dict(result.status.__dask_graph__())
    assert not any(isinstance(arg, batchcol.ShapeTable) for task in graph.values() if isinstance(task, tuple)
                   for arg in task)


def test_numpy_inputs_and_explicit_chunks(client, gjk_table):
    rng = np.random.default_rng(3)
    n = 5_000
    t_a = rng.uniform(-1, 1, (n, 3))
    t_b = t_a + rng.uniform(-0.3, 0.3, (n, 3))
    q = np.tile([1.0, 0, 0, 0], (n, 1))
    result = batchcol.dask.collide(gjk_table, 5, 0, t_a, q, t_b, q, level="distance", chunk_pairs=1_300, threads=1)
    assert [p.key for p in result.parts] and len(result.parts) == 4
    (distance,) = result.compute("distance")
    want = batchcol.collide(gjk_table, 5, 0, t_a, q, t_b, q, level="distance")
    assert same(distance, want.distance)
    with pytest.raises(ValueError, match="quaternion_a must have shape"):
        batchcol.dask.collide(gjk_table, 5, 0, t_a, q[:, :3], t_b, q, client=client)


def worker_pids(client):
    return client.run(os.getpid)


def test_worker_killed_mid_job_is_recovered_with_identical_results(client, gjk_table):
    arrays = lazy_pairs(160_000, 4_000, len(gjk_table), seed=2)
    result = batchcol.dask.collide(gjk_table, *arrays, level="penetration", threads=1)
    futures = client.compute(result.parts)
    distributed.wait(futures, return_when="FIRST_COMPLETED")
    pids = worker_pids(client)
    busy = [address for address, keys in client.processing().items() if keys]
    assert busy, "no worker was running a chunk"
    done_at_kill = sum(f.done() for f in futures)
    os.kill(pids[busy[0]], signal.SIGKILL)
    killed = busy[0]
    assert done_at_kill < len(futures), "the job finished before the kill: make it longer"
    parts = client.gather(futures)  # Dask reruns the lost chunks (and their lost inputs) on the other worker
    deadline = time.time() + 60
    while time.time() < deadline:  # the nanny restarts the killed worker
        now = worker_pids(client)
        if len(now) == 2 and pids[busy[0]] not in now.values():
            break
        time.sleep(0.2)
    else:
        pytest.fail("the killed worker was not replaced")
    # The replacement received the table from the scheduler when it joined.
    received = client.run(lambda dask_worker: dask_worker._batchcol_table_setups.get(result.table, 0))
    assert killed not in received and sorted(received.values()) == [1, 1]
    local = [np.asarray(x) for x in client.compute(list(arrays), sync=True)]
    want = batchcol.collide(gjk_table, *local, level="penetration", threads=2, invalid="status")
    assert sum(len(p["status"]) for p in parts) == len(want) == 160_000
    for name in ("status", "collide", "distance", "iterations"):
        assert same(np.concatenate([p[name] for p in parts]), getattr(want, name)), name
    for name in ("witness_a", "normal"):
        for axis, values in zip("xyz", getattr(want, name)):
            assert same(np.concatenate([p[name + "_" + axis] for p in parts]), values), (name, axis)


def make_chunk(seed, n):
    """One chunk made by one task on a worker, as a loader of one file would: the six pair arguments as a dict."""
    rng = np.random.default_rng(seed)
    t_a = rng.uniform(-1, 1, (n, 3))
    q = rng.normal(size=(n, 4))
    q /= np.linalg.norm(q, axis=1, keepdims=True)
    return {"shape_a": rng.integers(0, 6, n), "shape_b": rng.integers(0, 6, n), "translation_a": t_a,
            "quaternion_a": q, "translation_b": t_a + rng.uniform(-0.3, 0.3, (n, 3)), "quaternion_b": q[::-1].copy()}


def test_collide_chunks_runs_one_task_per_loaded_chunk(client, gjk_table):
    sizes = [3000, 1000, 2500]
    loaders = [dask.delayed(make_chunk)(k, n) for k, n in enumerate(sizes)]
    result = batchcol.dask.collide_chunks(gjk_table, loaders, level="distance", threads=1)
    with pytest.raises(TypeError, match="unknown"):
        len(result)  # no rows given: chunk sizes are known once computed
    status, distance = result.compute("status", "distance")
    want = [batchcol.collide(gjk_table, **make_chunk(k, n), level="distance", threads=1) for k, n in enumerate(sizes)]
    assert same(distance, np.concatenate([w.distance for w in want]))
    assert same(status, np.concatenate([w.status for w in want]))
    futures = [client.submit(make_chunk, k, n, pure=False) for k, n in enumerate(sizes)]
    result = batchcol.dask.collide_chunks(gjk_table, futures, rows=sizes, level="boolean", threads=1)
    assert len(result) == sum(sizes)
    (collide,) = result.compute("collide")
    assert same(collide, np.concatenate([w.collide for w in want]))
    bad = [client.submit(lambda: (1, 2, 3))]
    with pytest.raises(ValueError, match="a chunk must hold the 6 pair arguments"):
        batchcol.dask.collide_chunks(gjk_table, bad, rows=[1]).compute("status")
