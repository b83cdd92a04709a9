"""batchcol: batched collision queries between convex shapes, on NumPy arrays.

    import numpy as np, batchcol
    shapes = batchcol.ShapeTable()
    ball = shapes.add(batchcol.Shape.sphere(0.1))
    n = 1000
    t_a = np.zeros((n, 3), order="F")                  # Fortran order: viewed, not copied
    t_b = np.asfortranarray(np.random.rand(n, 3))
    q = np.zeros((n, 4), order="F"); q[:, 0] = 1.0     # quaternions [w, x, y, z]
    r = batchcol.collide(shapes, ball, ball, t_a, q, t_b, q, level="distance")
    r.distance, r.collide                              # views of the engine's result buffers

Copies: pose arguments are (N, 3) / (N, 4) float64 arrays. The engine stores each component contiguously
(structure of arrays), so arrays whose columns are contiguous (numpy.asfortranarray, or the transpose of a (3, N)
C-contiguous array) are read in place; a C-ordered (N, 3) array is copied once into that layout (copy=False makes
that an error instead). Shape indices are viewed when they are a contiguous uint32 array, otherwise checked and
converted. Other dtypes are refused (no silent change of precision). Results are never copied: every field is an
array over the engine's buffers that keeps the Results alive; vector fields are XYZ(x, y, z) of three 1-D arrays
(numpy.stack(r.normal, axis=1) makes an (N, 3) copy). The GIL is released while the engine runs.

Errors: bad arguments raise ValueError naming the argument; pairs with invalid input (shape index out of range,
NaN pose, non-unit quaternion) raise ValueError naming the first of them, unless invalid="status" asks for the
engine's per-pair status (3 = invalid_input) instead. Conventions as in C++: metres, normal from a to b, signed
distance negative when overlapping, results bitwise identical for any thread count.
"""

from ._batchcol import (  # noqa: F401
    XYZ,
    Derivatives,
    Results,
    Scene,
    SceneResults,
    Shape,
    ShapeTable,
    collide,
    differentiate,
    load_batch_file,
    load_mesh_points,
)

#: Names of the status codes in Results.status.
STATUS = ("converged", "max_iterations", "degenerate", "invalid_input")
CONVERGED, MAX_ITERATIONS, DEGENERATE, INVALID_INPUT = range(4)

#: Names of the codes in Derivatives.status (C++ DerivativeStatus).
DERIVATIVE_STATUS = ("smooth", "zero_curvature", "nonsmooth", "singular", "partial_samples", "no_witness")

__all__ = [
    "XYZ", "Derivatives", "Results", "Scene", "SceneResults", "Shape", "ShapeTable", "collide", "differentiate",
    "load_batch_file", "load_mesh_points", "STATUS", "CONVERGED", "MAX_ITERATIONS", "DEGENERATE", "INVALID_INPUT",
    "DERIVATIVE_STATUS",
]
