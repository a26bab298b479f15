"""`vworks.sweep`: many variants of one workcell, on this machine or on a Ray or Dask cluster.

The variants run in Rust (`_vworks.run_variants`): on this machine on Rust threads with the
GIL released; on a cluster in batches, one task per batch, each carrying the workcell's
files (so workers need no shared filesystem, only `pip install vworks`). Every backend
gives the same table, row for row.
"""

from __future__ import annotations

import itertools
import os
from typing import Any, Dict, List, Mapping, Optional, Sequence, Tuple, Union

from . import _vworks

Value = Union[float, int, str, bool]
Variant = List[Tuple[str, Value]]

__all__ = ["sweep", "variants_of"]


def _paths(key: Union[str, Sequence[str]]) -> List[str]:
    if isinstance(key, str):
        return [key]
    paths = list(key)
    if not paths or not all(isinstance(p, str) for p in paths):
        raise ValueError(f"a variable is a path or a tuple of paths that take the same value, not {key!r}")
    return paths


def variants_of(
    variables: Union[Mapping[Any, Sequence[Value]], Sequence[Mapping[str, Value]]],
) -> Tuple[List[str], List[Variant]]:
    """The variable columns and the variants of `variables`.

    - a mapping from a path (or a tuple of tied paths, which take the same value) to its
      values: every combination, the last variable changing fastest (as `vworks sweep`'s
      "product");
    - or a list of mappings, one variant each.
    """
    if isinstance(variables, Mapping):
        keys = [_paths(k) for k in variables]
        values = [list(v) for v in variables.values()]
        for k, v in zip(keys, values):
            if not v:
                raise ValueError(f"`{k[0]}` has no values")
        out = []
        for combo in itertools.product(*values):
            out.append([(p, value) for paths, value in zip(keys, combo) for p in paths])
        return [k[0] for k in keys], out
    names: List[str] = []
    out = []
    for variant in variables:
        if not isinstance(variant, Mapping):
            raise ValueError(f"a list of variants holds mappings of path to value, not {variant!r}")
        for p in variant:
            if p not in names:
                names.append(p)
        out.append([(p, v) for p, v in variant.items()])
    return names, out


def _check_batch(batch: Any) -> Optional[int]:
    """`batch` as given, if it is None or a whole number of variants from 1 up."""
    if batch is None:
        return None
    if isinstance(batch, bool) or not isinstance(batch, int):
        raise TypeError(f"batch must be a whole number of variants per task (an int), not {batch!r}")
    if batch < 1:
        raise ValueError(f"batch must be 1 or more variants per task, not {batch}")
    return batch


def _batches(variants: List[Variant], size: int) -> List[Tuple[int, List[Variant]]]:
    return [(i, variants[i : i + size]) for i in range(0, len(variants), size)]


def _run_batch(
    cell: str,
    files: Dict[str, bytes],
    batch: List[Variant],
    variables: List[str],
    until: Optional[float],
    offset: int,
) -> Tuple[List[str], List[List[Any]]]:
    """One task on a worker: the batch's rows (workers import vworks; nothing else)."""
    from vworks import _vworks as native

    return native.run_variants(cell, batch, variables, jobs=1, until=until, files=files, offset=offset)


def _frame(columns: List[str], rows: List[List[Any]]) -> Any:
    try:
        import pandas as pd  # type: ignore[import-untyped, import-not-found, unused-ignore]
    except ImportError as e:  # pragma: no cover - pandas is a test dependency
        raise ImportError("vworks.sweep returns a pandas DataFrame: pip install vworks[pandas]") from e
    return pd.DataFrame(rows, columns=columns)


def sweep(
    cell: Union[str, "os.PathLike[str]"],
    variables: Union[Mapping[Any, Sequence[Value]], Sequence[Mapping[str, Value]]],
    backend: str = "local",
    jobs: Optional[int] = None,
    until: Optional[float] = None,
    batch: Optional[int] = None,
) -> Any:
    """Runs every variant of the workcell `cell` and returns the table as a pandas DataFrame.

    `variables` maps dotted paths into the workcell (``"robot.r2.base.xyz.0"``,
    ``"params.speed"``; a tuple of paths for tied values) to lists of values, whose product
    is swept, or is a list of dicts, one per variant. Values are what the workcell file
    accepts there: SI numbers, strings with units, bools.

    The columns: ``variant``, each variable, ``outcome``, ``end_time`` (s),
    ``cycle_time.ROBOT`` (s) per robot, ``collisions``, ``min_clearance`` (m), ``error``.

    `backend`: ``"local"`` (Rust threads, `jobs` of them, default one per core),
    ``"ray"`` (tasks on the Ray cluster `ray.init()` connected to; started locally if
    none) or ``"dask"`` (tasks on the current `dask.distributed` client). `batch`: variants
    per task, an int from 1 up (default: about four tasks per worker); a TypeError or
    ValueError otherwise. `until` stops each run (s). Ctrl-C stops a local sweep's runs
    and raises KeyboardInterrupt.
    """
    batch = _check_batch(batch)
    cell = os.fspath(cell)
    names, variants = variants_of(variables)
    if backend == "local":
        columns, rows = _vworks.run_variants(cell, variants, names, jobs=jobs, until=until)
        return _frame(columns, rows)
    files = _vworks.cell_files(cell)
    if backend == "ray":
        try:
            import ray  # type: ignore[import-untyped, import-not-found, unused-ignore]
        except ImportError as e:
            raise ImportError("backend='ray' needs Ray: pip install 'vworks[ray]'") from e
        if not ray.is_initialized():
            ray.init()
        cpus: Any = ray.cluster_resources()  # type: ignore[no-untyped-call, unused-ignore]
        workers = max(1, int(cpus.get("CPU", 1)))
        size = batch or max(1, -(-len(variants) // (4 * workers)))
        task: Any = ray.remote(_run_batch)
        files_ref = ray.put(files)
        refs: List[Any] = [task.remote(cell, files_ref, b, names, until, i) for i, b in _batches(variants, size)]
        results: List[Tuple[List[str], List[List[Any]]]] = ray.get(refs)
    elif backend == "dask":
        try:
            from dask.distributed import get_client  # type: ignore[import-untyped, import-not-found, unused-ignore]
        except ImportError as e:
            raise ImportError("backend='dask' needs Dask: pip install 'vworks[dask]'") from e
        try:
            client = get_client()
        except ValueError as e:
            raise RuntimeError(
                "backend='dask' runs on the current dask.distributed client: start one first, "
                "e.g. Client(LocalCluster()) or Client('tcp://scheduler:8786')"
            ) from e
        dask_client: Any = client
        workers = max(1, sum(dask_client.nthreads().values()))
        size = batch or max(1, -(-len(variants) // (4 * workers)))
        files_future = dask_client.scatter(files, broadcast=True)
        futures: List[Any] = [
            dask_client.submit(_run_batch, cell, files_future, b, names, until, i, pure=False)
            for i, b in _batches(variants, size)
        ]
        results = dask_client.gather(futures)
    else:
        raise ValueError(f"backend is 'local', 'ray' or 'dask', not {backend!r}")
    columns = results[0][0] if results else ["variant", *names]
    rows = [row for _, part in results for row in part]
    return _frame(columns, rows)
