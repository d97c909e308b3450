"""The study driver: draw the design, evaluate it chunk by chunk on a runner, stream the rows."""

from __future__ import annotations

import functools
import hashlib
import json
import math
import os
import re
import sys
import time
from pathlib import Path
from typing import Any, Sequence

import numpy as np

from .. import _core
from ..errors import ParameterError
from ..scene import Scene
from .kernels import get_kernel, metric_units
from .runners import RunnerError, Task, _Failure, check_picklable, evaluate_batch, resolve_runner
from .sampling import as_sampler, design
from .spec import Correlation, Criterion, Tolerance, check_criteria, expand
from .storage import _columns_of_records, open_store, to_table

__all__ = ["run"]


@functools.lru_cache(maxsize=1)
def _field_units() -> dict[str, str]:
    return {str(f["path"]): str(f["unit"]) for f in _core.scene_fields()}


def field_unit(path: str) -> str:
    """The SI unit of the scene field at the dotted ``path`` (docs/scene.md; a list index
    ``[3]`` reads as the list's items), ``"-"`` for none, ``"?"`` for a path the schema does not
    list."""
    units = _field_units()
    p = re.sub(r"\[\d+\]", "[]", path)
    for candidate in (p, p.removesuffix("[]"), re.sub(r"\[\]$", "", p)):
        if candidate in units:
            return units[candidate]
    return "?"

def _kernel_id(kernel: Any) -> str:
    fn = getattr(kernel, "fn", None)
    if fn is not None:
        return f"{type(kernel).__name__}({getattr(fn, '__module__', '')}.{getattr(fn, '__qualname__', repr(fn))})"
    return repr(kernel)


def _positive(name: str, value: Any) -> int:
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or value < 1:
        raise ParameterError(f"{name} must be a positive integer, got {value!r}")
    return int(value)


def run(scene: Scene, kernel: Any = "dynamic", tolerances: Sequence[Tolerance | dict[str, Any]] = (),
        samples: Any = 100, *, seed: int | None = 0, runner: Any = None, out: str | Path | None = None,
        correlations: Sequence[Correlation | dict[str, Any]] = (),
        criteria: Sequence[Criterion | dict[str, Any]] = (), kernel_options: dict[str, Any] | None = None,
        chunk_size: int = 1000, batch_size: int = 1, retries: int = 2, resume: bool = True,
        retry_failed: bool = False, threads_per_worker: int = 1, as_numpy: bool = False,
        load: bool = True, progress: bool = False, connect_timeout: float = 10.0) -> Any:
    """Run a tolerance study and return its table (one row per sample).

    scene: the nominal :class:`rvdyn.Scene`. kernel: ``"dynamic"`` (a dynamic run reduced to
    :data:`rvdyn.study.DYNAMIC_METRICS`; ``kernel_options`` e.g. ``{"t_end": 0.5}``), ``"ltca"``
    (:class:`rvdyn.study.LtcaKernel`, :data:`rvdyn.study.LTCA_METRICS`; options ``torque``,
    ``points``, ``twist_points``, ``crank_angle``, ``window``, ``bearings``: with it also
    :data:`rvdyn.study.LTCA_BEARING_METRICS`), a kernel object, or a picklable top-level
    function ``f(scene) -> dict``.
    tolerances: :class:`Tolerance` s (or dicts) over dotted scene paths; correlations:
    :class:`Correlation` groups. samples: a count (Monte Carlo), ``MonteCarlo(n)``,
    ``LatinHypercube(n)`` or ``"lhs:N"``. seed: the design depends on it alone.
    runner: None (threads, one per CPU), an int (threads), ``"processes:N"``, a Dask address,
    ``"ray"``, or any object with ``map`` (executor, ``dask.distributed.Client``,
    ``ray.util.multiprocessing.Pool``). criteria: checked against the kernel's metrics.

    out: a folder; rows are written there chunk by chunk (``chunk_size`` samples, one Parquet
    part each) and an interrupted study with the same inputs resumes where it stopped
    (``retry_failed=True`` reruns the failed samples too). batch_size: samples per task (raise
    it for cheap kernels on a cluster). retries: Dask retries of a task whose worker died.
    threads_per_worker: native threads of each worker process (RAYON_NUM_THREADS etc.).
    connect_timeout: seconds to wait for a cluster given by address.

    Returns a pandas DataFrame (a numpy structured array without pandas or with
    ``as_numpy=True``); with ``load=False`` and ``out``, the folder path instead.
    Columns: ``sample``, the toleranced values, the metrics (NaN if the sample failed),
    ``error`` ("" or the failure message).
    """
    if not isinstance(scene, Scene):
        raise ParameterError(f"scene must be an rvdyn.Scene, got {type(scene).__name__}")
    try:
        import scipy  # type: ignore[import-untyped, import-not-found, unused-ignore]  # noqa: F401
    except ImportError:
        raise ImportError("rvdyn.study needs SciPy: pip install 'rvdyn[study]'") from None
    chunk_size = _positive("chunk_size", chunk_size)
    batch_size = _positive("batch_size", batch_size)
    threads_per_worker = _positive("threads_per_worker", threads_per_worker)
    if isinstance(retries, bool) or not isinstance(retries, int) or retries < 0:
        raise ParameterError(f"retries must be an integer >= 0, got {retries!r}")
    if isinstance(connect_timeout, bool) or not (isinstance(connect_timeout, (int, float))
                                                 and math.isfinite(connect_timeout) and connect_timeout > 0):
        raise ParameterError(f"connect_timeout must be a time > 0 s, got {connect_timeout!r}")
    k = get_kernel(kernel, **(kernel_options or {}))
    layout = expand(scene, tolerances, correlations)
    metrics = getattr(k, "metrics", None)
    crits = check_criteria(criteria, metrics)
    sampler = as_sampler(samples)
    x = design(layout, sampler, seed)
    n = x.shape[0]

    fingerprint = hashlib.sha256()
    fingerprint.update(scene.to_json().encode())
    fingerprint.update(_kernel_id(k).encode())
    fingerprint.update(json.dumps(layout.columns).encode())
    fingerprint.update(np.ascontiguousarray(x).tobytes())
    meta = {"version": 1, "fingerprint": fingerprint.hexdigest(), "samples": n, "seed": seed,
            "sampler": repr(sampler), "kernel": _kernel_id(k), "inputs": layout.columns,
            "metrics": list(metrics) if metrics is not None else None,
            "tolerances": [repr(t) for t in layout.tolerances],
            # Input values are in the SI unit of their scene field (docs/scene.md); the metrics'
            # units are the kernel's.
            "input_paths": {v.column: v.path for v in layout.variables},
            "input_units": {v.column: field_unit(v.path) for v in layout.variables},
            "metric_units": metric_units(k),
            "correlations": [{"columns": [layout.variables[c].column for c in cols],
                              "matrix": (chol @ chol.T).round(15).tolist()} for cols, chol in layout.groups],
            "criteria": [{"metric": c.metric, "min": None if c.min is None else float(c.min),
                          "max": None if c.max is None else float(c.max)} for c in crits],
            "scene": json.loads(scene.to_json())}
    task = Task(scene, k, layout, threads_per_worker, os.getpid())
    mapper = resolve_runner(runner, retries=retries, timeout=connect_timeout)
    try:
        if not mapper.in_process and not mapper.is_dask:  # Dask pickles with cloudpickle
            check_picklable(task)
        store = open_store(out, meta, resume=resume)
        done = store.done(failed=not retry_failed)
        pending = np.array([i for i in range(n) if i not in done], dtype=np.int64)
        fn = functools.partial(evaluate_batch, task)
        metric_names: list[str] | None = list(metrics) if metrics is not None else None
        start = time.perf_counter()
        for c0 in range(0, len(pending), chunk_size):
            ids = pending[c0:c0 + chunk_size]
            batches = [[(int(i), x[i].tolist()) for i in ids[b:b + batch_size]] for b in range(0, len(ids), batch_size)]
            results = mapper.run(fn, batches)
            records: list[tuple[int, dict[str, float], str]] = []
            for batch, res in zip(batches, results):
                if isinstance(res, _Failure):
                    records += [(sid, {}, res.message) for sid, _ in batch]
                else:
                    records += res
            if metric_names is None:
                metric_names = []
            for r in records:
                metric_names += [m for m in r[1] if m not in metric_names]
            store.write(_columns_of_records(records, x[ids], layout.columns, metric_names))
            if results and all(isinstance(r, _Failure) for r in results):
                where = f"; the rows so far are in {str(out)!r}: run again to resume (retry_failed=True " \
                        "reruns the lost samples)" if out is not None else ""
                hint = ""
                if "BrokenProcessPool" in results[0].message:
                    hint = ("; a process pool also breaks when the main script lacks "
                            "`if __name__ == '__main__':` (worker processes import it)")
                raise RunnerError(f"the runner lost every task of samples {int(ids[0])}..{int(ids[-1])} "
                                  f"({results[0].message}){where}{hint}")
            if progress:
                done_now = c0 + len(ids)
                rate = done_now / max(time.perf_counter() - start, 1e-9)
                print(f"study: {done_now}/{len(pending)} samples ({rate:.3g}/s)", file=sys.stderr)
    finally:
        mapper.close()
    if out is not None and not load:
        return Path(out)
    cols = store.columns()
    metric_cols = [c for c in cols if c not in layout.columns and c not in ("sample", "error")]
    return to_table(cols, as_numpy=as_numpy, inputs=layout.columns, metrics=metric_cols)

