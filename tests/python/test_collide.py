"""batchcol.collide on NumPy arrays: same results as the C++ CLI, zero copy, clear errors, thread invariance."""

import csv
import json
import pickle
import subprocess
import threading

import numpy as np
import pytest

import batchcol
from conftest import every_shape, random_pairs

LEVELS = ("boolean", "distance", "witness", "penetration")


def same(x, y):
    """Bitwise-equal float arrays (NaN where the other has NaN)."""
    x, y = np.asarray(x), np.asarray(y)
    return x.shape == y.shape and x.dtype == y.dtype and np.array_equal(x.view(np.uint8), y.view(np.uint8))


def same_results(r, s):
    return all(same(getattr(r, f), getattr(s, f)) for f in ("status", "collide", "distance", "iterations")) and all(
        same(u, v) for f in ("witness_a", "witness_b", "normal", "direction")
        for u, v in zip(getattr(r, f), getattr(s, f)))


def write_batch_file(path, n, seed):
    shapes = [description for _, description in every_shape()]
    a, b, t_a, q_a, t_b, q_b = random_pairs(n, len(shapes), seed)
    pairs = [{"a": int(a[i]), "b": int(b[i]),
              "pose_a": {"translation": t_a[i].tolist(), "quaternion": q_a[i].tolist()},
              "pose_b": {"translation": t_b[i].tolist(), "quaternion": q_b[i].tolist()}} for i in range(n)]
    path.write_text(json.dumps({"shapes": shapes, "pairs": pairs, "tolerance": 1e-10}))


@pytest.mark.parametrize("level", LEVELS)
def test_equals_cli_query_on_the_same_batch_file(tmp_path, cli, level):
    batch = tmp_path / "batch.json"
    write_batch_file(batch, 400, seed=11)
    out = tmp_path / "out.csv"
    subprocess.run([cli, "query", str(batch), "--query", level, "--threads", "2", "--out", str(out)], check=True)
    rows = list(csv.DictReader(out.open()))
    f = batchcol.load_batch_file(str(batch))
    assert f["options"] == {"tolerance": 1e-10}
    r = batchcol.collide(f["shapes"], f["shape_a"], f["shape_b"], f["translation_a"], f["quaternion_a"],
                         f["translation_b"], f["quaternion_b"], level=level, tolerance=1e-10, copy=False)
    assert len(rows) == len(r) == 400

    def column(name):  # the CLI prints 17 significant digits (exact for doubles) and empty fields for NaN / absent
        return np.array([float(row[name]) if row[name] else np.nan for row in rows])

    assert [batchcol.STATUS[s] for s in r.status] == [row["status"] for row in rows]
    assert np.array_equal(r.collide, column("collide").astype(bool))
    assert np.array_equal(r.iterations, column("iterations").astype(np.int32))
    if level == "boolean":
        assert r.distance.size == 0 and np.isnan(column("distance")).all()
    else:
        assert same(r.distance, column("distance"))
    if level in ("witness", "penetration"):
        for name, prefix in (("witness_a", "pa"), ("witness_b", "pb"), ("normal", "n")):
            for axis, values in zip("xyz", getattr(r, name)):
                assert same(values, column(f"{prefix}_{axis}")), (name, axis)
    else:
        assert all(v.size == 0 for v in r.witness_a)
    # Sanity of the comparison itself: the batch mixes colliding and separated pairs.
    assert 0 < r.collide.sum() < len(r)


def test_inputs_with_contiguous_columns_are_viewed_and_results_are_views(table):
    a, b, t_a, q_a, t_b, q_b = random_pairs(1000, len(table))
    before = [x.copy() for x in (t_a, q_a, t_b, q_b)]
    r = batchcol.collide(table, a, b, t_a, q_a, t_b, q_b, level="witness", copy=False)  # copy=False: no copy made
    for x, y in zip((t_a, q_a, t_b, q_b), before):
        assert np.array_equal(x, y)  # inputs are read, never written
    # The transpose of a (3, N) C-contiguous array has contiguous columns too.
    r2 = batchcol.collide(table, a, b, np.ascontiguousarray(t_a.T).T, q_a, t_b, q_b, level="witness", copy=False)
    assert same_results(r, r2)
    # Results: every field is a view of one engine buffer, owned by the Results object.
    for name in ("status", "collide", "distance", "iterations"):
        assert getattr(r, name).base is r and not getattr(r, name).flags.owndata
    for name in ("witness_a", "witness_b", "normal", "direction"):
        x, y, z = getattr(r, name)
        assert x.base is r and y.base is r and z.base is r
    # Two reads of a field share memory: the same buffer, not two copies.
    assert np.shares_memory(r.distance, r.distance)
    assert r.distance.__array_interface__["data"][0] == r.distance.__array_interface__["data"][0]
    # The buffers outlive the Results object's last Python name.
    distance = r.distance
    expected = distance.copy()
    del r
    assert same(distance, expected)


def test_out_reuses_the_engine_buffers_in_place(table):
    a, b, t_a, q_a, t_b, q_b = random_pairs(500, len(table))
    r = batchcol.collide(table, a, b, t_a, q_a, t_b, q_b, level="distance")
    view = r.distance
    address = view.__array_interface__["data"][0]
    moved = np.asfortranarray(t_b + 0.05)
    again = batchcol.collide(table, a, b, t_a, q_a, moved, q_b, level="distance", out=r)
    assert again is r and r.distance.__array_interface__["data"][0] == address
    assert same(view, batchcol.collide(table, a, b, t_a, q_a, moved, q_b, level="distance").distance)
    with pytest.raises(ValueError, match="out must be a Results of 500 pairs at level 'witness'"):
        batchcol.collide(table, a, b, t_a, q_a, t_b, q_b, level="witness", out=r)


def test_c_ordered_poses_are_copied_once_unless_copy_is_false(table):
    a, b, t_a, q_a, t_b, q_b = random_pairs(300, len(table))
    c_order = [np.ascontiguousarray(x) for x in (t_a, q_a, t_b, q_b)]
    assert same_results(batchcol.collide(table, a, b, *c_order), batchcol.collide(table, a, b, t_a, q_a, t_b, q_b))
    with pytest.raises(ValueError, match=r"translation_a cannot be viewed without a copy.*asfortranarray"):
        batchcol.collide(table, a, b, c_order[0], q_a, t_b, q_b, copy=False)
    # int64 indices (NumPy's default) are converted; only uint32 is viewed.
    with pytest.raises(ValueError, match="shape_a cannot be viewed without a copy"):
        batchcol.collide(table, a.astype(np.int64), b, t_a, q_a, t_b, q_b, copy=False)
    assert same_results(batchcol.collide(table, a.astype(np.int64), b, t_a, q_a, t_b, q_b),
                        batchcol.collide(table, a, b, t_a, q_a, t_b, q_b))


def test_bad_arguments_raise_value_errors_naming_them(table):
    a, b, t_a, q_a, t_b, q_b = random_pairs(50, len(table))
    call = lambda **kw: batchcol.collide(table, kw.get("a", a), kw.get("b", b), kw.get("t_a", t_a),  # noqa: E731
                                         kw.get("q_a", q_a), kw.get("t_b", t_b), kw.get("q_b", q_b),
                                         **kw.get("options", {}))
    cases = [
        (dict(t_b=t_b.astype(np.float32)), "translation_b must be a float64 array, got dtype float32"),
        (dict(q_a=q_a[:, :3]), r"quaternion_a must have shape \(N, 4\), got \(50, 3\)"),
        (dict(q_b=q_b[:40]), "quaternion_b has 40 rows, expected 50"),
        (dict(t_a=t_a[:, 0]), r"translation_a must have shape \(N, 3\), got \(50,\)"),
        (dict(a=a.astype(np.float64)), "shape_a must be an array of integer shape indices, got dtype float64"),
        (dict(b=b[:10]), "shape_b has 10 entries, expected 50"),
        (dict(a=np.full(50, -1)), r"shape_a\[0\] = -1 is negative"),
        (dict(options=dict(level="fast")), "fast"),
        (dict(options=dict(tolerance=-1.0)), "tolerance must be a finite number >= 0"),
        (dict(options=dict(invalid="ignore")), "invalid must be 'raise' or 'status'"),
    ]
    for kwargs, message in cases:
        with pytest.raises(ValueError, match=message):
            call(**kwargs)


def test_invalid_pairs_raise_naming_the_first_or_become_statuses(table):
    a, b, t_a, q_a, t_b, q_b = random_pairs(50, len(table))
    nan_pose = t_b.copy(order="F")
    nan_pose[7, 1] = np.nan
    with pytest.raises(ValueError, match=r"translation_b\[7\] = \[.*nan.*\] is not finite \(1 of 50 pairs"):
        batchcol.collide(table, a, b, t_a, q_a, nan_pose, q_b)
    far = a.copy()
    far[[3, 9]] = len(table)
    with pytest.raises(ValueError, match=r"shape_a\[3\] = 10 is out of range \(the table has 10 shapes\) \(2 of 50"):
        batchcol.collide(table, far, b, t_a, q_a, t_b, q_b)
    long_q = q_a.copy(order="F")
    long_q[4] *= 1.01
    with pytest.raises(ValueError, match=r"quaternion_a\[4\] = .* is not a finite unit quaternion"):
        batchcol.collide(table, a, b, t_a, long_q, t_b, q_b)
    r = batchcol.collide(table, far, b, t_a, q_a, nan_pose, q_b, invalid="status")
    assert set(np.flatnonzero(r.status == batchcol.INVALID_INPUT)) == {3, 7, 9}


def test_one_and_two_threads_give_identical_arrays(table):
    a, b, t_a, q_a, t_b, q_b = random_pairs(20000, len(table), seed=5)
    for level in LEVELS:
        for precision in ("double", "float"):
            one = batchcol.collide(table, a, b, t_a, q_a, t_b, q_b, level=level, precision=precision, threads=1)
            two = batchcol.collide(table, a, b, t_a, q_a, t_b, q_b, level=level, precision=precision, threads=2)
            assert same_results(one, two), (level, precision)


def test_pickled_table_gives_the_same_bits(table):
    copy = pickle.loads(pickle.dumps(table))
    assert len(copy) == len(table)
    assert [copy[i].type for i in range(len(copy))] == [table[i].type for i in range(len(table))]
    a, b, t_a, q_a, t_b, q_b = random_pairs(5000, len(table), seed=9)
    assert same_results(batchcol.collide(table, a, b, t_a, q_a, t_b, q_b),
                        batchcol.collide(copy, a, b, t_a, q_a, t_b, q_b))
    with pytest.raises(ValueError, match="not a batchcol.ShapeTable pickle"):
        table.__class__.__new__(table.__class__).__setstate__(("other", 1, []))


def test_shape_factories_validate_like_cpp():
    with pytest.raises(ValueError, match="radius must be > 0"):
        batchcol.Shape.sphere(-1.0)
    with pytest.raises(ValueError, match="fewer than 4|coplanar|4 non-coplanar|collinear"):
        batchcol.Shape.convex(np.zeros((4, 3)))
    with pytest.raises(ValueError, match="no-such-file.obj"):
        batchcol.Shape.mesh("no-such-file.obj")
    assert batchcol.Shape.capsule(0.1, 0.2).inflated(0.05).inflation == 0.05


def test_concurrent_calls_from_two_python_threads_match_one_call(table):
    # collide() releases the GIL (asserted by the next test), so two Python threads run the engine at once on one
    # shared table; each result equals a lone call's.
    a, b, t_a, q_a, t_b, q_b = random_pairs(20000, len(table), seed=13)
    want = batchcol.collide(table, a, b, t_a, q_a, t_b, q_b, threads=1)
    got = [None, None]

    def run(k):
        got[k] = batchcol.collide(table, a, b, t_a, q_a, t_b, q_b, threads=1)

    threads = [threading.Thread(target=run, args=(k,)) for k in range(2)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert all(same_results(want, g) for g in got)


def test_gil_is_released_and_the_table_cannot_grow_while_the_engine_reads_it(table):
    # add() may move the table's shapes; while a collide() runs with the GIL released it is refused. The table is
    # marked busy and unmarked with the GIL held, so this thread can see it busy only if it runs while the engine
    # does: the error below also proves that collide() releases the GIL.
    a, b, t_a, q_a, t_b, q_b = random_pairs(400_000, len(table), seed=17)
    grown = batchcol.ShapeTable()
    for k in range(len(table)):
        grown.add(table[k])
    errors = []
    worker = threading.Thread(target=lambda: batchcol.collide(grown, a, b, t_a, q_a, t_b, q_b, threads=1))
    worker.start()
    while worker.is_alive():
        try:
            grown.add(batchcol.Shape.sphere(0.1))
        except RuntimeError as e:
            errors.append(str(e))
            break
    worker.join()
    assert errors and "in use by a running collide()" in errors[0]
    grown.add(batchcol.Shape.sphere(0.1))  # allowed again once it returned
