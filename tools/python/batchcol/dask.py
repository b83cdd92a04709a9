"""Batches larger than one machine: batchcol.collide() on the chunks of Dask arrays, on a dask.distributed cluster.

    from dask.distributed import Client
    import batchcol, batchcol.dask
    client = Client("tcp://scheduler:8786")          # or Client(LocalCluster(...))
    r = batchcol.dask.collide(shapes, a, b, t_a, q_a, t_b, q_b, level="distance")   # Dask or NumPy arrays
    distance, collide = r.compute("distance", "collide")
    r = batchcol.dask.collide_chunks(shapes, [dask.delayed(load)(path) for path in files])  # one task per chunk

Each chunk of pairs runs batchcol.collide() on a worker (with threads=0 it uses all the worker's cores through
TBB). The ShapeTable is sent once per worker, not once per chunk, as a worker plugin (the scheduler hands it to
every worker that joins, replacements of dead workers included): it pickles as the exact fields of its shapes. Results are Dask arrays with the fields of batchcol.Results (vector fields are
XYZ of three Dask arrays). A worker that dies mid-job is replaced by its nanny and Dask runs its chunks again
elsewhere: chunks computed from Dask arrays (generated or read by tasks) are recomputed; NumPy inputs are put into
the graph as data, so they survive a worker's loss too (but travel through the scheduler: for large batches, build
Dask arrays that load or generate their chunks on the workers).
"""

import uuid
import weakref

import numpy as np
import dask
import dask.array as da
from distributed import WorkerPlugin, default_client, get_worker

from . import XYZ
from . import collide as _collide

_LEVELS = ("boolean", "distance", "witness", "penetration")
_VECTOR_FIELDS = ("witness_a", "witness_b", "normal", "direction")


def _fields(level):
    """(name, dtype, is_vector) of the result fields `level` computes, as batchcol.Results leaves them."""
    rank = _LEVELS.index(level) if level in _LEVELS else 0
    fields = [("status", np.uint8, False), ("collide", np.bool_, False)]
    if rank >= 1:
        fields.append(("distance", np.float64, False))
    if rank >= 2:
        fields += [(name, np.float64, True) for name in ("witness_a", "witness_b", "normal")]
    fields += [("direction", np.float64, True), ("iterations", np.int32, False)]
    return fields


class _TablePlugin(WorkerPlugin):
    """Carries a ShapeTable to every worker once: the scheduler keeps the plugin and gives it to each worker that
    joins, including one that replaces a dead worker, and Dask's memory manager never moves or drops it (a
    scattered table's extra replicas are dropped whenever no task waits for them, and fetched again later)."""

    def __init__(self, name, shapes):
        self.name = name
        self.shapes = shapes

    def setup(self, worker):
        tables = worker.__dict__.setdefault("_batchcol_tables", {})
        tables[self.name] = self.shapes
        setups = worker.__dict__.setdefault("_batchcol_table_setups", {})
        setups[self.name] = setups.get(self.name, 0) + 1  # for the tests: how often this worker received it

    def teardown(self, worker):
        worker.__dict__.get("_batchcol_tables", {}).pop(self.name, None)


def _send_table(client, shapes):
    """Registers the table on every worker (now and later); returns its name. Unregistered with the results."""
    name = "batchcol-table-" + uuid.uuid4().hex
    client.register_worker_plugin(_TablePlugin(name, shapes), name=name)
    return name


def _release_table(client, name):
    try:
        client.unregister_worker_plugin(name)
    except Exception:  # the client or cluster may be gone already: nothing left to release
        pass


def _collide_chunk(table, shape_a, shape_b, translation_a, quaternion_a, translation_b, quaternion_b, options):
    """One chunk on a worker: a dict of plain arrays (their buffers are the chunk's Results, no extra copy)."""
    shapes = get_worker()._batchcol_tables[table] if isinstance(table, str) else table
    r = _collide(shapes, shape_a, shape_b, translation_a, quaternion_a, translation_b, quaternion_b, **options)
    out = {}
    for name, _, vector in _fields(r.level):
        value = getattr(r, name)
        if vector:
            for axis, component in zip("xyz", value):
                out[name + "_" + axis] = component
        else:
            out[name] = value
    return out


class DaskResults:
    """Dask arrays of the results of batchcol.dask.collide(). `parts` are the per-chunk tasks (dicts of arrays),
    `table` the name of the ShapeTable on the workers (released from them when this object is collected)."""

    def __init__(self, parts, rows, level, table=None, client=None):
        self.parts = parts
        self.table = table
        self.level = level
        if client is not None and table is not None:
            release = weakref.finalize(self, _release_table, client, table)
            release.atexit = False  # at exit the cluster goes away anyway; a call into a closing client could block
        # Fields the level does not compute are empty, as in batchcol.Results.
        for name, dtype, vector in _fields("penetration"):
            empty = da.empty((0,), dtype=dtype)
            setattr(self, name, XYZ(empty, empty, empty) if vector else empty)
        for name, dtype, vector in _fields(level):
            def column(key):
                return da.concatenate([da.from_delayed(part[key], shape=(n,), dtype=dtype)
                                       for part, n in zip(parts, rows)]) if parts else da.empty((0,), dtype=dtype)
            value = XYZ(*(column(name + "_" + axis) for axis in "xyz")) if vector else column(name)
            setattr(self, name, value)

    def __len__(self):
        n = self.status.shape[0]
        if n != n:  # NaN: chunks of unknown size (collide_chunks without rows)
            raise TypeError("the number of pairs is unknown until computed")
        return int(n)

    def compute(self, *names, **kwargs):
        """NumPy arrays of the named fields (all when none are named), computed together: each chunk runs once."""
        names = names or tuple(name for name, _, _ in _fields(self.level))
        return dask.compute(*(getattr(self, name) for name in names), **kwargs)


_ARGUMENTS = ("shape_a", "shape_b", "translation_a", "quaternion_a", "translation_b", "quaternion_b")


def _collide_loaded_chunk(shapes, chunk, options):
    """A chunk given as one task's output: a tuple of the six pair arguments, or a dict with their names."""
    if isinstance(chunk, dict):
        missing = [name for name in _ARGUMENTS if name not in chunk]
        if missing:
            raise ValueError(f"a chunk dict lacks {missing}")
        chunk = tuple(chunk[name] for name in _ARGUMENTS)
    if len(chunk) != 6:
        raise ValueError(f"a chunk must hold the 6 pair arguments {_ARGUMENTS}, got {len(chunk)} values")
    return _collide_chunk(shapes, *chunk, options)


def collide_chunks(shapes, chunks, *, client=None, rows=None, **options):
    """batchcol.collide() on chunks that are each one task's output (a Dask delayed object or a Future holding a
    tuple or dict of the six pair arguments), e.g. one task per file that loads its pairs on a worker. Each chunk's
    collide runs where its chunk is (no transfer of the inputs). `rows` gives the pairs per chunk when known
    (otherwise the result arrays have unknown chunk sizes, as Dask allows). Options as in collide()."""
    client = client or default_client()
    options.setdefault("invalid", "status")
    if "out" in options:
        raise ValueError("out is not supported by batchcol.dask")
    level = options.get("level", "witness")
    if level not in _LEVELS:
        raise ValueError(f"level must be one of {_LEVELS}, got {level!r}")
    chunks = list(chunks)
    if rows is None:
        rows = [np.nan] * len(chunks)
    elif len(rows) != len(chunks):
        raise ValueError(f"rows has {len(rows)} entries for {len(chunks)} chunks")
    table = _send_table(client, shapes)
    run = dask.delayed(_collide_loaded_chunk, pure=False)
    return DaskResults([run(table, chunk, options) for chunk in chunks], list(rows), level, table, client)


def _column_count(name):
    return 4 if name.startswith("quaternion") else 3


def _blocks(value, name, bounds):
    """Per-chunk pieces of one argument: Dask blocks, NumPy slices (graph data) or a repeated int index."""
    if isinstance(value, (int, np.integer)):
        return [value] * (len(bounds) - 1)
    if isinstance(value, da.Array):
        row_chunks = tuple(np.diff(bounds))
        if value.ndim == 2:
            value = value.rechunk((row_chunks, -1))
        else:
            value = value.rechunk((row_chunks,))
        return list(value.to_delayed().ravel())
    value = np.asarray(value)
    return [dask.delayed(value[lo:hi], pure=False) for lo, hi in zip(bounds[:-1], bounds[1:])]


def collide(shapes, shape_a, shape_b, translation_a, quaternion_a, translation_b, quaternion_b, *, client=None,
            chunk_pairs=None, **options):
    """batchcol.collide() over Dask (or NumPy) arrays, chunk by chunk on the cluster of `client` (the default
    client when None). Chunks follow the first Dask argument's row chunks, or `chunk_pairs` rows when given
    (default 1,000,000 for NumPy inputs). Keyword options are those of batchcol.collide(); invalid="status" is the
    default here, since one bad pair should not cost a cluster job (pass invalid="raise" to fail instead)."""
    client = client or default_client()
    options.setdefault("invalid", "status")
    if "out" in options:
        raise ValueError("out is not supported by batchcol.dask.collide")
    args = {"shape_a": shape_a, "shape_b": shape_b, "translation_a": translation_a, "quaternion_a": quaternion_a,
            "translation_b": translation_b, "quaternion_b": quaternion_b}
    for name, value in args.items():
        if name.startswith(("translation", "quaternion")):
            columns = _column_count(name)
            if len(getattr(value, "shape", ())) != 2 or value.shape[1] != columns:
                raise ValueError(f"{name} must have shape (N, {columns}), got {getattr(value, 'shape', None)}")
    n = translation_a.shape[0]
    for name, value in args.items():
        if not isinstance(value, (int, np.integer)) and value.shape[0] != n:
            raise ValueError(f"{name} has {value.shape[0]} rows, expected {n} (one per pair)")
    if chunk_pairs is None:
        first = next((v for v in args.values() if isinstance(v, da.Array)), None)
        bounds = np.concatenate([[0], np.cumsum(first.chunks[0])]) if first is not None else None
        chunk_pairs = 1_000_000
    else:
        if chunk_pairs < 1:
            raise ValueError(f"chunk_pairs must be >= 1, got {chunk_pairs}")
        bounds = None
    if bounds is None:
        bounds = np.unique(np.append(np.arange(0, n, chunk_pairs), n))
    level = options.get("level", "witness")
    if level not in _LEVELS:
        raise ValueError(f"level must be one of {_LEVELS}, got {level!r}")
    table = _send_table(client, shapes)  # once per worker, not once per chunk
    pieces = [_blocks(value, name, bounds) for name, value in args.items()]
    chunk = dask.delayed(_collide_chunk, pure=False)
    parts = [chunk(table, *(p[k] for p in pieces), options) for k in range(len(bounds) - 1)]
    return DaskResults(parts, [int(r) for r in np.diff(bounds)], level, table, client)
