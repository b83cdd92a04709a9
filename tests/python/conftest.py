"""Shared fixtures of the batchcol pytest suite: a table with every shape type, random pair batches, the CLI."""

import os

import numpy as np
import pytest

import batchcol

DATA_DIR = os.environ.get("BATCHCOL_TEST_DATA_DIR", os.path.join(os.path.dirname(__file__), "..", "data"))


def every_shape():
    """One or two shapes of each type (meshes from tests/data), with their batch-file descriptions."""
    rng = np.random.default_rng(3)
    hull = rng.uniform(-0.15, 0.15, (30, 3))
    mesh = os.path.join(DATA_DIR, "tetrahedronIrregular.ascii.stl")
    return [
        (batchcol.Shape.sphere(0.1), {"type": "sphere", "radius": 0.1}),
        (batchcol.Shape.capsule(0.05, 0.2).inflated(0.01),
         {"type": "capsule", "radius": 0.05, "half_length": 0.2, "inflation": 0.01}),
        (batchcol.Shape.box(0.1, 0.2, 0.15), {"type": "box", "half_extents": [0.1, 0.2, 0.15]}),
        (batchcol.Shape.cylinder(0.1, 0.2), {"type": "cylinder", "radius": 0.1, "half_length": 0.2}),
        (batchcol.Shape.cone(0.1, 0.2), {"type": "cone", "radius": 0.1, "half_length": 0.2}),
        (batchcol.Shape.ellipsoid(0.1, 0.2, 0.05), {"type": "ellipsoid", "radii": [0.1, 0.2, 0.05]}),
        (batchcol.Shape.convex(hull), {"type": "convex", "vertices": hull.tolist()}),
        (batchcol.Shape.mesh(mesh), {"type": "mesh", "file": mesh}),
        (batchcol.Shape.triangle([0, 0, 0], [0.3, 0, 0], [0, 0.2, 0.05]),
         {"type": "triangle", "vertices": [[0, 0, 0], [0.3, 0, 0], [0, 0.2, 0.05]]}),
        (batchcol.Shape.halfspace([0, 0, 1], -0.3), {"type": "halfspace", "normal": [0, 0, 1], "offset": -0.3}),
    ]


@pytest.fixture(scope="session")
def table():
    t = batchcol.ShapeTable()
    for shape, _ in every_shape():
        t.add(shape)
    return t


def random_unit_quaternions(rng, n):
    q = rng.normal(size=(n, 4))
    return q / np.linalg.norm(q, axis=1, keepdims=True)


def random_pairs(n, shape_count, seed=1, order="F"):
    """n pairs of random shapes 0..shape_count-1, about half overlapping; arrays in `order`."""
    rng = np.random.default_rng(seed)
    a = rng.integers(0, shape_count, n).astype(np.uint32)
    b = rng.integers(0, shape_count, n).astype(np.uint32)
    t_a = rng.uniform(-1, 1, (n, 3))
    direction = rng.normal(size=(n, 3))
    direction /= np.linalg.norm(direction, axis=1, keepdims=True)
    t_b = t_a + direction * rng.uniform(0, 0.5, (n, 1))
    q_a, q_b = random_unit_quaternions(rng, n), random_unit_quaternions(rng, n)
    arrays = [np.asarray(x, order=order) for x in (t_a, q_a, t_b, q_b)]
    return a, b, arrays[0], arrays[1], arrays[2], arrays[3]


@pytest.fixture(scope="session")
def cli():
    path = os.environ.get("BATCHCOL_CLI")
    if not path or not os.path.exists(path):
        pytest.skip("BATCHCOL_CLI does not name the built batchcol binary (ctest sets it)")
    return path
