"""Scene bulk API: add / set_poses / remove from arrays, all-or-nothing on bad rows, collide results as views."""

import numpy as np
import pytest

import batchcol
from conftest import random_unit_quaternions


@pytest.fixture()
def balls():
    t = batchcol.ShapeTable()
    t.add(batchcol.Shape.sphere(0.1))
    t.add(batchcol.Shape.box(0.1, 0.1, 0.1))
    return t


def brute_force_sphere_pairs(positions, radius=0.1):
    d = np.linalg.norm(positions[:, None, :] - positions[None, :, :], axis=2)
    i, j = np.nonzero(np.triu(d <= 2 * radius, k=1))
    return set(zip(i.tolist(), j.tolist()))


def test_bulk_add_and_collide_find_exactly_the_touching_balls(balls):
    rng = np.random.default_rng(2)
    n = 400
    positions = rng.uniform(0, 2, (n, 3))
    scene = batchcol.Scene(balls)
    q = np.zeros((n, 4))
    q[:, 0] = 1
    handles = scene.add(0, positions, q)
    assert handles.dtype == np.uint64 and len(scene) == n and scene.contains(handles).all()
    r = scene.collide(level="distance")
    index = {int(h): k for k, h in enumerate(handles)}
    found = {tuple(sorted((index[int(a)], index[int(b)])))
             for a, b in zip(r.object_a[r.colliding], r.object_b[r.colliding])}
    assert found == brute_force_sphere_pairs(positions) and len(found) > 0
    # Views of the scene's result buffers, kept alive by the SceneResults / Results objects.
    assert r.object_a.base is r and r.colliding.base is r and r.pairs.distance.base is r.pairs
    assert len(r.pairs) == len(r) >= len(found)
    gaps = np.linalg.norm(positions[[index[int(a)] for a in r.object_a]] -
                          positions[[index[int(b)] for b in r.object_b]], axis=1) - 0.2
    assert np.allclose(r.pairs.distance, gaps, atol=1e-12)


def test_set_poses_and_remove_in_bulk(balls):
    rng = np.random.default_rng(4)
    n = 200
    scene = batchcol.Scene(balls)
    handles = scene.add(rng.integers(0, 2, n), rng.uniform(0, 1, (n, 3)), random_unit_quaternions(rng, n),
                        group=1, mask=0xFFFFFFFF)
    moved = rng.uniform(5, 6, (n, 3))
    turned = random_unit_quaternions(rng, n)
    scene.set_poses(handles, moved, turned)
    t, q = scene.poses(handles)
    assert np.array_equal(t, moved) and np.allclose(q, turned, atol=1e-15)
    scene.remove(handles[::2])
    assert len(scene) == n // 2
    assert not scene.contains(handles[::2]).any() and scene.contains(handles[1::2]).all()
    r1 = scene.collide(level="witness", threads=1)
    r2 = scene.collide(level="witness", threads=2)
    assert np.array_equal(r1.object_a, r2.object_a) and np.array_equal(r1.pairs.distance, r2.pairs.distance, equal_nan=True)


def test_bad_rows_raise_and_leave_the_scene_unchanged(balls):
    scene = batchcol.Scene(balls)
    t = np.zeros((3, 3))
    q = np.tile([1.0, 0, 0, 0], (3, 1))
    h = scene.add([0, 1, 0], t, q)
    bad = t.copy()
    bad[2, 0] = np.nan
    with pytest.raises(ValueError, match="Scene.add: row 2: .*(no object added)"):
        scene.add(0, bad, q)
    assert len(scene) == 3
    with pytest.raises(ValueError, match="Scene.add: row 1: .*shape index 7 is out of range"):
        scene.add([0, 7, 0], t, q)
    with pytest.raises(ValueError, match="Scene.set_poses: row 2: .*(no pose changed)"):
        scene.set_poses(h, t + 1.0, np.array([[1.0, 0, 0, 0], [1.0, 0, 0, 0], [2.0, 0, 0, 0]]))
    assert np.array_equal(scene.poses(h)[0], t)
    scene.remove(h[:1])
    with pytest.raises(ValueError, match=r"Scene.remove: handles\[0\] is not an object of this scene"):
        scene.remove(h)
    assert len(scene) == 2
    with pytest.raises(ValueError, match="translation must have shape"):
        scene.add(0, np.zeros((3, 2)), q)
    with pytest.raises(ValueError, match=r"group\[0\] = -1 is outside"):
        scene.add(0, t, q, group=-1)
