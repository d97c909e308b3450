"""Study tables: in memory, or streamed to a Parquet folder in chunks (resumable).

Columns: ``sample`` (int64 id, 0..n-1), one float64 column per toleranced variable (the value
the scene got, field units), one float64 column per metric (NaN for a failed sample) and
``error`` (the failure message, "" for a sample that ran).

On disk (``out="study.parquet"``) the table is a folder: ``_meta.json`` (what the study is,
checked on resume; inputs with their scene paths, metrics with their units, correlations,
criteria) and ``part-<seq>.parquet`` files, one per chunk, each written to a temporary name
then renamed, so a crash never leaves a partial part. Every part has every column (a metric
first seen in a later chunk is added to the earlier parts, NaN-filled), so pandas and pyarrow,
which take a folder's columns from one part, read the folder as one table
(``pandas.read_parquet(path)``); :func:`read` sorts it by sample id, keeping the newest row of
a sample that was run again.
"""

from __future__ import annotations

import json
import os
from pathlib import Path
from typing import Any, Sequence

import numpy as np

from ..errors import ParameterError

__all__ = ["MemoryStore", "ParquetStore", "open_store", "read", "to_table", "have_pandas"]

# The leading underscore keeps pandas and pyarrow, which skip such files, from reading it as
# a part of the table.
META = "_meta.json"


def have_pandas() -> bool:
    try:
        import pandas  # type: ignore[import-untyped, import-not-found, unused-ignore]  # noqa: F401
    except ImportError:
        return False
    return True


def _columns_of_records(records: Sequence[tuple[int, dict[str, float], str]], inputs: np.ndarray,
                        input_names: Sequence[str], metrics: Sequence[str]) -> dict[str, np.ndarray]:
    cols: dict[str, np.ndarray] = {"sample": np.array([r[0] for r in records], dtype=np.int64)}
    for j, name in enumerate(input_names):
        cols[name] = np.ascontiguousarray(inputs[:, j], dtype=np.float64)
    for m in metrics:
        cols[m] = np.array([r[1].get(m, np.nan) for r in records], dtype=np.float64)
    cols["error"] = np.array([r[2] for r in records], dtype=object)
    return cols


class MemoryStore:
    """Keeps the chunks in memory (no ``out``)."""

    def __init__(self) -> None:
        self.parts: list[dict[str, np.ndarray]] = []

    def done(self, failed: bool = True) -> set[int]:
        return set()

    def write(self, cols: dict[str, np.ndarray]) -> None:
        self.parts.append(cols)

    def columns(self) -> dict[str, np.ndarray]:
        return _concat(self.parts)


class ParquetStore:
    """A folder of Parquet parts (needs pyarrow: ``pip install 'rvdyn[study]'``)."""

    def __init__(self, path: str | Path, meta: dict[str, Any], resume: bool = True):
        try:
            import pyarrow  # type: ignore[import-untyped, import-not-found, unused-ignore]  # noqa: F401
        except ImportError:
            raise ParameterError(f"out={str(path)!r}: writing a study needs pyarrow: pip install 'rvdyn[study]'") from None
        self.path = Path(path)
        if self.path.exists() and not self.path.is_dir():
            raise ParameterError(f"out={str(path)!r} exists and is not a study folder")
        meta_file = self.path / META
        if meta_file.exists():
            old = json.loads(meta_file.read_text(encoding="utf-8"))
            if not resume:
                raise ParameterError(f"out={str(path)!r} already holds a study; pass resume=True to continue it "
                                     "or choose another path")
            if old.get("fingerprint") != meta["fingerprint"]:
                raise ParameterError(f"out={str(path)!r} holds a different study (scene, kernel, tolerances, "
                                     "samples or seed differ); choose another path")
            meta = old
        else:
            self.path.mkdir(parents=True, exist_ok=True)
            tmp = meta_file.with_suffix(".tmp")
            tmp.write_text(json.dumps(meta, indent=1), encoding="utf-8")
            os.replace(tmp, meta_file)
        self.meta = meta
        self._seq = max((self._seq_of(p) for p in self._parts()), default=-1) + 1
        self._names: list[str] = []  # the columns of every part, in order
        for part in self._parts():
            self._names = _merge_names(self._names, _part_names(part))

    @staticmethod
    def _seq_of(p: Path) -> int:
        return int(p.stem.split("-")[1])

    def _parts(self) -> list[Path]:
        return sorted(self.path.glob("part-*.parquet"), key=self._seq_of)

    def done(self, failed: bool = True) -> set[int]:
        """Sample ids on disk (with ``failed=False``: only those that ran without error)."""
        import pyarrow.parquet as pq  # type: ignore[import-untyped, import-not-found, unused-ignore]

        ids: set[int] = set()
        latest: dict[int, bool] = {}
        for p in self._parts():
            t = pq.read_table(p, columns=["sample", "error"])
            for sid, err in zip(t.column("sample").to_pylist(), t.column("error").to_pylist()):
                latest[int(sid)] = not err
        for sid, ok in latest.items():
            if ok or failed:
                ids.add(sid)
        return ids

    def write(self, cols: dict[str, np.ndarray]) -> None:
        """Write a chunk as a new part. Every part carries every column (a metric a part's
        samples did not give is NaN there): pyarrow and pandas take a folder's columns from one
        part, and dropped the metric columns of a study whose first chunk had failed."""
        names = _merge_names(self._names, list(cols))
        grew = names != self._names
        self._names = names
        if grew:
            for part in self._parts():  # a metric seen for the first time: add it to the parts so far
                if _part_names(part) != names:
                    self._write(_read_part(part), part.name)
        self._write(cols, f"part-{self._seq:06d}.parquet")
        self._seq += 1

    def _write(self, cols: dict[str, np.ndarray], name: str) -> None:
        import pyarrow as pa  # type: ignore[import-untyped, import-not-found, unused-ignore]
        import pyarrow.parquet as pq  # type: ignore[import-untyped, import-not-found, unused-ignore]

        n = len(cols["sample"])
        arrays = {}
        for k in self._names:
            v = cols.get(k)
            if k == "error":
                arrays[k] = pa.array([""] * n if v is None else [str(e) for e in v], type=pa.string())
            else:
                arrays[k] = pa.array(np.full(n, np.nan) if v is None else v)
        final = self.path / name
        tmp = self.path / f".{name}.tmp"
        pq.write_table(pa.table(arrays), tmp)
        os.replace(tmp, final)

    def columns(self) -> dict[str, np.ndarray]:
        return _concat([_read_part(p) for p in self._parts()])


def _part_names(part: Path) -> list[str]:
    import pyarrow.parquet as pq  # type: ignore[import-untyped, import-not-found, unused-ignore]

    return list(pq.read_schema(part).names)


def _read_part(part: Path) -> dict[str, np.ndarray]:
    import pyarrow.parquet as pq  # type: ignore[import-untyped, import-not-found, unused-ignore]

    t = pq.read_table(part)
    return {name: (np.array(t.column(name).to_pylist(), dtype=object) if name == "error"
                   else t.column(name).to_numpy()) for name in t.column_names}


def _merge_names(names: list[str], new: list[str]) -> list[str]:
    """``names`` with the columns of ``new`` it lacks, inserted before ``error`` (the last column)."""
    extra = [k for k in new if k not in names]
    if not extra:
        return names
    if "error" in names:
        i = names.index("error")
        return names[:i] + [k for k in extra if k != "error"] + names[i:]
    return names + [k for k in extra if k != "error"] + (["error"] if "error" in extra else [])


def _concat(parts: list[dict[str, np.ndarray]]) -> dict[str, np.ndarray]:
    """Concatenate parts (missing metric columns are NaN), sort by sample id, keep the newest
    row of each id."""
    names: list[str] = []
    for p in parts:
        names += [k for k in p if k not in names]
    cols: dict[str, np.ndarray] = {}
    for name in names:
        pieces = []
        for p in parts:
            n = len(p["sample"])
            if name in p:
                pieces.append(p[name])
            elif name == "error":
                pieces.append(np.array([""] * n, dtype=object))
            else:
                pieces.append(np.full(n, np.nan))
        if not pieces:
            continue
        cols[name] = np.concatenate(pieces) if pieces else np.array([])
    if not cols:
        return {"sample": np.zeros(0, dtype=np.int64), "error": np.zeros(0, dtype=object)}
    ids = cols["sample"]
    # Newest row per id: scan from the end, keep first occurrence, then order by id.
    rev = ids[::-1]
    _, first = np.unique(rev, return_index=True)
    keep = len(ids) - 1 - first
    order = keep[np.argsort(ids[keep], kind="stable")]
    return {k: v[order] for k, v in cols.items()}


def to_table(cols: dict[str, np.ndarray], as_numpy: bool = False, inputs: Sequence[str] | None = None,
             metrics: Sequence[str] | None = None) -> Any:
    """A pandas DataFrame (when pandas is installed and not ``as_numpy``; ``attrs`` holds the
    ``inputs`` and ``metrics`` column names) or a numpy structured array, columns in order, whose
    ``dtype.metadata`` holds the same names."""
    if not as_numpy and have_pandas():
        import pandas as pd  # type: ignore[import-untyped, import-not-found, unused-ignore]

        df = pd.DataFrame({k: (v.astype(str) if k == "error" else v) for k, v in cols.items()})
        if inputs is not None:
            df.attrs["inputs"] = list(inputs)
        if metrics is not None:
            df.attrs["metrics"] = [m for m in metrics if m in df.columns]
        return df
    n = len(cols["sample"])
    width = max([len(str(e)) for e in cols.get("error", [])] + [1])
    fields = [(k, np.int64 if k == "sample" else (f"U{width}" if k == "error" else np.float64)) for k in cols]
    # The column roles travel with the array (a metric named like a scene path, e.g. "density",
    # was otherwise taken for an input).
    meta = {k: list(v) for k, v in (("inputs", inputs), ("metrics", metrics)) if v is not None}
    if "metrics" in meta:
        meta["metrics"] = [m for m in meta["metrics"] if m in cols]
    arr = np.zeros(n, dtype=np.dtype(fields, metadata=meta) if meta else np.dtype(fields))
    for k, v in cols.items():
        arr[k] = v.astype(str) if k == "error" else v
    return arr


def open_store(out: str | Path | None, meta: dict[str, Any], resume: bool = True) -> MemoryStore | ParquetStore:
    """The store for ``out`` (None: in memory)."""
    if out is None:
        return MemoryStore()
    if not isinstance(out, (str, os.PathLike)):
        raise ParameterError(f"out must be a folder path (or None), got {out!r}")
    return ParquetStore(out, meta, resume=resume)


def read(path: str | Path, as_numpy: bool = False) -> Any:
    """Read a study folder written by :func:`rvdyn.study.run` as one table sorted by sample id:
    a pandas DataFrame (or, with ``as_numpy`` or without pandas, a numpy structured array) with
    the columns ``sample`` (int), one per input (its scene path; the value in that field's SI
    unit, docs/scene.md), one per metric (float; units in ``read_meta(path)["metric_units"]``;
    NaN where the sample failed) and ``error`` (str, ``""`` for a sample that ran). The column
    roles are in ``DataFrame.attrs["inputs"]``/``["metrics"]`` (``dtype.metadata`` for the
    array). Raises ParameterError for a folder without ``_meta.json``."""
    p = Path(path)
    if not (p / META).exists():
        raise ParameterError(f"{str(p)!r} is not a study folder (no {META})")
    store = ParquetStore.__new__(ParquetStore)
    store.path = p
    meta = read_meta(p)
    cols = store.columns()
    inputs = list(meta.get("inputs") or [])
    metrics = [c for c in cols if c not in inputs and c not in ("sample", "error")]
    return to_table(cols, as_numpy=as_numpy, inputs=inputs, metrics=metrics)


def read_meta(path: str | Path) -> dict[str, Any]:
    """The ``_meta.json`` of a study folder."""
    return dict(json.loads((Path(path) / META).read_text(encoding="utf-8")))
