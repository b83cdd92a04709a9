"""batchcol.differentiate on NumPy arrays: the CLI's derivative columns, finite differences, options, errors."""

import csv
import subprocess

import numpy as np
import pytest

import batchcol
from conftest import every_shape, random_pairs
from test_collide import same as same_contiguous, write_batch_file


def same(x, y):
    """Bitwise-equal arrays; the derivative arrays are strided views, compared through contiguous copies."""
    return same_contiguous(np.ascontiguousarray(x), np.ascontiguousarray(y))


def load(path):
    f = batchcol.load_batch_file(str(path))
    return f, (f["shapes"], f["shape_a"], f["shape_b"], f["translation_a"], f["quaternion_a"], f["translation_b"],
               f["quaternion_b"])


@pytest.mark.parametrize("method", ("analytic", "smoothed0", "smoothed1"))
def test_equals_cli_query_derivative_columns(tmp_path, cli, method):
    batch = tmp_path / "batch.json"
    write_batch_file(batch, 300, seed=5)
    out = tmp_path / "out.csv"
    subprocess.run([cli, "query", str(batch), "--derivatives", method, "--samples", "6", "--noise", "0.02", "--seed",
                    "9", "--threads", "2", "--out", str(out)], check=True)
    rows = list(csv.DictReader(out.open()))
    _, args = load(batch)
    r, d = batchcol.differentiate(*args, method=method, samples=6, noise=0.02, seed=9, tolerance=1e-10)
    assert len(rows) == len(r) == len(d) == 300

    def column(name):  # 17 significant digits: exact for doubles; empty for NaN
        return np.array([float(row[name]) if row[name] else np.nan for row in rows])

    assert [batchcol.DERIVATIVE_STATUS[s] for s in d.status] == [row["d_status"] for row in rows]
    for side in "ab":
        g = getattr(d, f"distance_gradient_{side}")
        assert g.shape == (300, 6)
        for k in range(6):
            assert same(g[:, k], column(f"g_{side}{k}")), (side, k)
    for name, prefix in (("witness_a_wrt_a", "dpa_da"), ("witness_b_wrt_b", "dpb_db"), ("normal_wrt_a", "dn_da")):
        m = getattr(d, name)
        assert m.shape == (300, 3, 6)
        for row in range(3):
            for col in range(6):
                assert same(m[:, row, col], column(f"{prefix}_{row}{col}")), (name, row, col)
    if method == "smoothed0":
        assert same(d.smoothed_distance, column("s_distance"))
    else:
        assert d.smoothed_distance.size == 0
    # The comparison covers pairs with derivatives and pairs without (overlapping below penetration, halfspaces).
    assert 0 < (d.status == 5).sum() < 300


def test_distance_gradient_matches_central_differences_on_ellipsoids():
    table = batchcol.ShapeTable()
    e = table.add(batchcol.Shape.ellipsoid(0.1, 0.2, 0.15))
    rng = np.random.default_rng(4)
    n = 200
    t_a = np.zeros((n, 3))
    direction = rng.normal(size=(n, 3))
    t_b = direction / np.linalg.norm(direction, axis=1, keepdims=True) * rng.uniform(0.5, 0.8, (n, 1))
    q = rng.normal(size=(2, n, 4))
    q /= np.linalg.norm(q, axis=2, keepdims=True)
    _, d = batchcol.differentiate(table, e, e, t_a, q[0], t_b, q[1], tolerance=1e-12)
    assert (d.status == 0).all()
    h = 1e-6
    for k in range(3):  # translations of b: the linear part of d distance / d twist_b
        step = np.zeros(3)
        step[k] = h
        plus = batchcol.collide(table, e, e, t_a, q[0], t_b + step, q[1], level="distance", tolerance=1e-12)
        minus = batchcol.collide(table, e, e, t_a, q[0], t_b - step, q[1], level="distance", tolerance=1e-12)
        fd = (plus.distance - minus.distance) / (2 * h)
        # FD truncation ~h^2 * curvature ~1e-11, rounding ~1e-12 / h ~1e-6 is the floor here.
        assert np.max(np.abs(fd - d.distance_gradient_b[:, k])) < 1e-5, k
    # The rigid-motion identity: the two gradients cancel.
    assert np.max(np.abs(d.distance_gradient_a + d.distance_gradient_b)) < 1e-11


def test_gradients_only_and_thread_invariance(table):
    args = (table,) + random_pairs(500, len(table), seed=8)
    r, full = batchcol.differentiate(*args, threads=1)
    r2, grad = batchcol.differentiate(*args, jacobians=False, threads=2)
    assert same(r.distance, r2.distance)
    assert grad.witness_a_wrt_a.shape == (0, 3, 6) and grad.normal_wrt_b.shape == (0, 3, 6)
    given = full.status != 5
    assert given.sum() > 100
    assert np.array_equal(grad.status, np.where(given, 0, 5).astype(np.uint8))
    assert same(grad.distance_gradient_a, full.distance_gradient_a)
    assert same(grad.distance_gradient_b, full.distance_gradient_b)
    _, again = batchcol.differentiate(*args, method="smoothed1", samples=5, seed=3, threads=2)
    _, once = batchcol.differentiate(*args, method="smoothed1", samples=5, seed=3, threads=1)
    assert same(again.witness_b_wrt_a, once.witness_b_wrt_a)
    # Arrays are views that keep the Derivatives alive.
    g = full.distance_gradient_b
    del full
    assert g.shape == (500, 6) and np.isfinite(g[given]).all()


@pytest.mark.parametrize("options, field", [
    ({"method": "fancy"}, "method"),
    ({"method": "smoothed0", "samples": 0}, "samples"),
    ({"method": "smoothed1", "noise": -1.0}, "noise"),
    ({"method": "smoothed1", "noise": float("nan")}, "noise"),
    ({"method": "smoothed0", "noise_scale": "huge"}, "noise_scale"),
    ({"method": "smoothed1", "jacobians": False}, "jacobians"),
    ({"level": "distance"}, "level"),
    ({"invalid": "ignore"}, "invalid"),
])
def test_bad_options_raise_value_errors_naming_them(table, options, field):
    args = (table,) + random_pairs(10, len(table))
    with pytest.raises(ValueError, match=field):
        batchcol.differentiate(*args, **options)


def test_invalid_pairs_raise_or_are_statuses():
    table = batchcol.ShapeTable()
    table.add(every_shape()[0][0])
    t = np.asfortranarray(np.array([[0.0, 0, 0], [0, 0, 0]]))
    q = np.asfortranarray(np.array([[1.0, 0, 0, 0], [1, 0, 0, 0]]))
    t_b = np.asfortranarray(np.array([[0.5, 0, 0], [0.5, 0, 0]]))
    b = np.array([0, 7], dtype=np.uint32)  # pair 1: shape index out of range
    with pytest.raises(ValueError, match=r"shape_b\[1\]"):
        batchcol.differentiate(table, 0, b, t, q, t_b, q)
    r, d = batchcol.differentiate(table, 0, b, t, q, t_b, q, invalid="status")
    assert list(r.status) == [0, 3] and list(d.status) == [0, 5]
    assert d.distance_gradient_b[0, 0] == 1.0 and np.isnan(d.distance_gradient_b[1]).all()
