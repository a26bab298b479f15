"""`vworks.sweep`: many variants of one workcell, on this machine or on a Ray or Dask cluster.

The variants run in Rust (`_vworks.run_variants`): on this machine on Rust threads with the
GIL released; on a cluster in batches, one task per batch, each carrying the workcell's
files (so workers need no shared filesystem, only `pip install vworks`). Every backend
gives the same table, row for row.
"""

from __future__ import annotations

import itertools
import os
from typing import Any, Dict, Iterator, List, Mapping, Optional, Sequence, Tuple, Union, overload

from . import _vworks

Value = Union[float, int, str, bool]
Variant = List[Tuple[str, Value]]
#: One cell of a sweep table: a number, a text, or None where the table is empty (a
#: variable a variant leaves out, the cycle time of a robot that did not end, no clearance
#: measured).
Entry = Optional[Union[float, int, str]]

__all__ = ["SweepTable", "sweep", "variants_of"]


class SweepTable:
    """The table a sweep returns: one row per variant, in variant order, as plain Python
    values (numbers, strings, None where the table is empty); no pandas needed.

    ``table.columns`` are the names, ``table.rows`` the rows (tuples, in column order);
    ``len(table)`` counts the rows; ``table["end_time"]`` is a column as a list;
    ``table[i]`` is row ``i`` as a dict; iterating gives each row as a dict.
    ``to_pandas()`` makes a pandas DataFrame of it (None becomes NaN in numeric columns).
    Two tables are equal when their columns and rows are.
    """

    def __init__(self, columns: Sequence[str], rows: Sequence[Sequence[Entry]]) -> None:
        self._columns = list(columns)
        self._rows = [tuple(r) for r in rows]
        self._index = {name: i for i, name in enumerate(self._columns)}
        for r in self._rows:
            if len(r) != len(self._columns):
                raise ValueError(f"a row of {len(r)} values in a table of {len(self._columns)} columns")

    @property
    def columns(self) -> List[str]:
        """The column names: ``variant``, each variable, ``outcome``, ``end_time``,
        ``cycle_time.ROBOT`` per robot, ``collisions``, ``min_clearance``, ``error``."""
        return list(self._columns)

    @property
    def rows(self) -> List[Tuple[Entry, ...]]:
        """The rows, in variant order, each a tuple of values in column order."""
        return list(self._rows)

    def column(self, name: str) -> List[Entry]:
        """The column `name` as a list, in variant order; `KeyError` naming the columns if
        there is none of that name."""
        i = self._index.get(name)
        if i is None:
            raise KeyError(f"no column {name!r}; the columns are {', '.join(self._columns)}")
        return [r[i] for r in self._rows]

    def to_dicts(self) -> List[Dict[str, Entry]]:
        """The rows as dicts, column name to value, in variant order."""
        return [dict(zip(self._columns, r)) for r in self._rows]

    def to_pandas(self) -> Any:
        """The table as a pandas DataFrame with the same columns and rows (None is NaN in
        a numeric column). Needs pandas: `ImportError` saying what to install otherwise."""
        try:
            import pandas as pd  # type: ignore[import-untyped, import-not-found, unused-ignore]
        except ImportError as e:
            raise ImportError(
                "SweepTable.to_pandas needs pandas: pip install pandas (or 'vworks[pandas]')"
            ) from e
        return pd.DataFrame([list(r) for r in self._rows], columns=self._columns)

    def __len__(self) -> int:
        return len(self._rows)

    @overload
    def __getitem__(self, key: str) -> List[Entry]: ...
    @overload
    def __getitem__(self, key: int) -> Dict[str, Entry]: ...
    def __getitem__(self, key: Union[str, int]) -> Union[List[Entry], Dict[str, Entry]]:
        if isinstance(key, str):
            return self.column(key)
        if isinstance(key, bool) or not isinstance(key, int):
            raise TypeError(f"a sweep table is indexed by a column name or a row number, not {key!r}")
        return dict(zip(self._columns, self._rows[key]))

    def __iter__(self) -> Iterator[Dict[str, Entry]]:
        for r in self._rows:
            yield dict(zip(self._columns, r))

    def __eq__(self, other: object) -> bool:
        if not isinstance(other, SweepTable):
            return NotImplemented
        return self._columns == other._columns and self._rows == other._rows

    def __repr__(self) -> str:
        return f"<SweepTable of {len(self._rows)} variants: {', '.join(self._columns)}>"


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


def sweep(
    cell: Union[str, "os.PathLike[str]"],
    variables: Union[Mapping[Any, Sequence[Value]], Sequence[Mapping[str, Value]]],
    backend: str = "local",
    jobs: Optional[int] = None,
    until: Optional[float] = None,
    batch: Optional[int] = None,
) -> SweepTable:
    """Runs every variant of the workcell `cell` and returns the table, a `SweepTable`
    (plain Python values; `to_pandas()` for a DataFrame, with pandas installed).

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
        return SweepTable(columns, rows)
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
    return SweepTable(columns, rows)
