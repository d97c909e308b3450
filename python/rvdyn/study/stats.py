"""Statistics of a study table: summaries with bootstrap confidence intervals, yield against
pass criteria, sensitivity rankings.

* Bias-corrected and accelerated (BCa) bootstrap intervals (Efron & Tibshirani 1993, *An
  Introduction to the Bootstrap*, ch. 14) via :func:`scipy.stats.bootstrap` for the mean, the
  standard deviation and percentiles (the percentile bootstrap under-covers tail percentiles
  at a few dozen samples: ~83 % for a nominal 95 % p95 at n = 64).
* Yield = fraction of samples meeting every criterion, with the Wilson score interval (Wilson
  1927), with or without continuity correction, or the exact Clopper-Pearson interval
  (Clopper & Pearson 1934) from :meth:`scipy.stats.binomtest(...).proportion_ci`. A failed
  sample counts as not passing; a sample the runner lost is left out (with a warning).
* Standardised regression coefficients SRC_i = b_i s_i / s_y of the linear least-squares fit of
  the metric on the inputs (Saltelli et al. 2008, *Global Sensitivity Analysis: The Primer*,
  Wiley, sec. 1.2.5): for a linear model with independent inputs SRC_i^2 is the share of the
  output variance due to input i and sum SRC_i^2 = R^2; with R^2 well below 1 the ranking is
  only indicative (use Sobol indices).
* Sobol first-order and total indices from a Saltelli design (Saltelli et al. 2010, Comput.
  Phys. Commun. 181, 259-270) via :func:`scipy.stats.sobol_indices` (SciPy >= 1.11),
  independent inputs only.
"""

from __future__ import annotations

import inspect
import math
import warnings
from dataclasses import dataclass
from typing import Any, Sequence

import numpy as np

from ..errors import ParameterError
from .spec import Criterion, check_criteria

__all__ = ["columns", "describe", "yield_rate", "src", "sobol", "Interval", "YieldResult", "Sensitivity"]

_RESERVED = ("sample", "error")
# Top-level numeric scene fields (a tolerance on one gives an undotted input column).
_TOP_LEVEL_FIELDS = frozenset({"density", "cranks"})


def columns(table: Any) -> dict[str, np.ndarray]:
    """The table's columns as numpy arrays (DataFrame or structured array)."""
    if hasattr(table, "dtype") and getattr(table.dtype, "names", None):
        return {k: np.asarray(table[k]) for k in table.dtype.names}
    if hasattr(table, "columns") and hasattr(table, "__getitem__"):
        return {str(k): np.asarray(table[k]) for k in table.columns}
    if isinstance(table, dict):
        return {str(k): np.asarray(v) for k, v in table.items()}
    raise ParameterError(f"expected a study table (DataFrame or structured array), got {type(table).__name__}")


def _metric(cols: dict[str, np.ndarray], name: str) -> np.ndarray:
    if name not in cols or name in _RESERVED:
        raise ParameterError(f"unknown metric {name!r}; the table has {[c for c in cols if c not in _RESERVED]}")
    return np.asarray(cols[name], dtype=float)


def _is_input(name: str) -> bool:
    # Input columns are scene paths: dotted, or a top-level numeric scene field.
    return "." in name or name in _TOP_LEVEL_FIELDS


def input_names(table: Any) -> list[str]:
    """Names of the toleranced input columns (``table.attrs["inputs"]`` of a DataFrame or
    ``dtype.metadata["inputs"]`` of a structured array, else the columns named by a scene
    path)."""
    attrs = getattr(table, "attrs", None)
    if isinstance(attrs, dict) and "inputs" in attrs:
        return list(attrs["inputs"])
    meta = getattr(getattr(table, "dtype", None), "metadata", None)  # a read-only mapping
    if meta is not None and "inputs" in meta:
        return list(meta["inputs"])
    return [c for c in columns(table) if c not in _RESERVED and _is_input(c)]


def metric_names(table: Any) -> list[str]:
    """Names of the metric columns."""
    attrs = getattr(table, "attrs", None)
    if isinstance(attrs, dict) and "metrics" in attrs:
        return list(attrs["metrics"])
    meta = getattr(getattr(table, "dtype", None), "metadata", None)
    if meta is not None and "metrics" in meta:
        return list(meta["metrics"])
    return [c for c in columns(table) if c not in _RESERVED and not _is_input(c)]


def _ran_rows(cols: dict[str, np.ndarray]) -> np.ndarray:
    """Mask of the rows the runner did not lose; warns (:class:`RunnerFailureWarning`) when it lost
    some: those samples were never evaluated, so they are neither passing nor failing parts."""
    from .runners import RUNNER_FAILED, RunnerFailureWarning

    n = len(next(iter(cols.values()))) if cols else 0
    if "error" not in cols:
        return np.ones(n, dtype=bool)
    errors = [str(e) for e in cols["error"]]
    lost = np.array([e.startswith(RUNNER_FAILED) for e in errors], dtype=bool)
    if lost.any():
        first = errors[int(np.argmax(lost))]
        warnings.warn(f"{int(lost.sum())} of {n} samples were lost by the runner, not evaluated ({first[:200]}); "
                      "the statistics (yield, summaries) leave them out: run the study again with the same "
                      "out= and retry_failed=True to evaluate them", RunnerFailureWarning, stacklevel=3)
    return ~lost


@dataclass(frozen=True)
class Interval:
    """An estimate with its confidence interval [low, high] at ``confidence``."""

    value: float
    low: float
    high: float
    confidence: float


def _rng_kw(fn: Any, seed: int | None) -> dict[str, Any]:
    key = "rng" if "rng" in inspect.signature(fn).parameters else "random_state"
    return {key: np.random.default_rng(seed)}


def _summary_stat(qs: Sequence[float]) -> Any:
    def stat(a: np.ndarray, axis: int = -1) -> np.ndarray:
        n = a.shape[axis]
        std = np.std(a, axis=axis, ddof=1) if n > 1 else np.zeros(np.delete(a.shape, axis))
        return np.stack([np.mean(a, axis=axis), std, *np.percentile(a, list(qs), axis=axis)])
    return stat


#: Fewest samples with a finite value for a bootstrap interval (BCa's jackknife of the standard
#: deviation needs subsamples of two): below it every interval is NaN.
MIN_BOOTSTRAP_SAMPLES = 3


def describe(table: Any, metrics: Sequence[str] | None = None, percentiles: Sequence[float] = (5.0, 50.0, 95.0),
             confidence: float = 0.95, n_resamples: int = 1000, seed: int | None = 0) -> dict[str, dict[str, Any]]:
    """Per metric: ``n`` (samples with a finite value), ``failed`` (samples without one: the
    analysis failed, or returned an infinite or undefined value), ``mean``, ``std`` (ddof 1) and
    each percentile ``"p<q>"`` as :class:`Interval` s with bias-corrected and accelerated (BCa)
    bootstrap intervals (Efron & Tibshirani 1993, ch. 14; :func:`scipy.stats.bootstrap`), all
    statistics from the same ``n_resamples`` resamples.

    Degenerate data: with fewer than :data:`MIN_BOOTSTRAP_SAMPLES` values every interval is
    ``[nan, nan]``; with all values equal every interval is ``[v, v]`` (each resample is the same
    data). A statistic whose BCa interval is undefined (its jackknife values all equal, as for
    the median of an integer-valued metric such as ``loaded_pins_min``) gets the percentile
    interval of the same resamples. Rows lost by the runner (``error`` starting with
    ``"runner failed"``) are left out, with a :class:`rvdyn.study.RunnerFailureWarning`; their
    count is ``lost``."""
    from scipy import stats  # type: ignore[import-untyped, import-not-found, unused-ignore]

    cols = columns(table)
    if not 0 < confidence < 1:
        raise ParameterError(f"confidence must lie in (0, 1), got {confidence}")
    for q in percentiles:
        if not 0 <= q <= 100:
            raise ParameterError(f"percentiles must lie in [0, 100], got {q}")
    if isinstance(n_resamples, bool) or not isinstance(n_resamples, int) or n_resamples < 1:
        raise ParameterError(f"n_resamples must be a positive integer, got {n_resamples!r}")
    names = list(metrics) if metrics is not None else metric_names(table)
    keys = ["mean", "std"] + [f"p{q:g}" for q in percentiles]
    stat = _summary_stat(percentiles)
    ran = _ran_rows(cols)
    out: dict[str, dict[str, Any]] = {}
    for name in names:
        v = _metric(cols, name)[ran]
        x = v[np.isfinite(v)]
        entry: dict[str, Any] = {"n": int(len(x)), "failed": int(len(v) - len(x)), "lost": int(len(ran) - ran.sum())}
        out[name] = entry
        if len(x) == 0:
            continue
        value = stat(x)
        if len(x) < MIN_BOOTSTRAP_SAMPLES:
            low = high = np.full(len(keys), np.nan)
        elif np.ptp(x) == 0:
            low = high = value
        else:
            with warnings.catch_warnings(), np.errstate(all="ignore"):
                # BCa is undefined for a statistic whose jackknife values are all equal: SciPy
                # warns and gives NaN, replaced below by the percentile interval.
                warnings.simplefilter("ignore", stats.DegenerateDataWarning)
                warnings.simplefilter("ignore", RuntimeWarning)
                res = stats.bootstrap((x,), stat, n_resamples=n_resamples, confidence_level=confidence,
                                      method="BCa", vectorized=True, batch=max(1, int(2e6 // len(x))),
                                      **_rng_kw(stats.bootstrap, seed))
            low = np.array(res.confidence_interval.low, dtype=float)
            high = np.array(res.confidence_interval.high, dtype=float)
            bad = ~(np.isfinite(low) & np.isfinite(high))
            if bad.any():
                alpha = 100.0 * (1.0 - confidence) / 2.0
                dist = np.asarray(res.bootstrap_distribution)[bad]
                low[bad] = np.percentile(dist, alpha, axis=-1)
                high[bad] = np.percentile(dist, 100.0 - alpha, axis=-1)
        for k, key in enumerate(keys):
            entry[key] = Interval(float(value[k]), float(low[k]), float(high[k]), confidence)
    return out


@dataclass(frozen=True)
class YieldResult:
    """Yield: ``passed`` of ``n`` samples meet every criterion; ``rate`` with its interval."""

    passed: int
    n: int
    rate: Interval
    method: str
    criteria: tuple[Criterion, ...]


def yield_rate(table: Any, criteria: Sequence[Criterion | dict[str, Any]], confidence: float = 0.95,
               method: str = "wilson") -> YieldResult:
    """Fraction of samples meeting all ``criteria`` with a binomial confidence interval:
    ``method="wilson"`` (score interval), ``"wilsoncc"`` (score interval with continuity
    correction) or ``"exact"`` (Clopper-Pearson). Samples whose analysis failed count as not
    passing. Samples the runner lost (``error`` starting with ``"runner failed"``: the worker
    died, the pool broke) were never evaluated: they are left out of ``n``, with a
    :class:`rvdyn.study.RunnerFailureWarning`."""
    from scipy import stats  # type: ignore[import-untyped, import-not-found, unused-ignore]

    if method not in ("wilson", "exact", "wilsoncc"):
        raise ParameterError(f"method must be 'wilson', 'wilsoncc' or 'exact', got {method!r}")
    if not 0 < confidence < 1:
        raise ParameterError(f"confidence must lie in (0, 1), got {confidence}")
    cols = columns(table)
    crits = check_criteria(criteria, metric_names(table))
    if not crits:
        raise ParameterError("yield needs at least one criterion")
    if len(cols["sample"]) == 0:
        raise ParameterError("yield of an empty table")
    ran = _ran_rows(cols)
    n = int(ran.sum())
    if n == 0:
        raise ParameterError("yield: the runner lost every sample (each error starts with 'runner failed'); "
                             "run the study again with the same out= and retry_failed=True")
    ok = np.ones(n, dtype=bool)
    for c in crits:
        ok &= c.passes(_metric(cols, c.metric)[ran])
    k = int(ok.sum())
    ci = stats.binomtest(k, n).proportion_ci(confidence_level=confidence, method=method)
    return YieldResult(k, n, Interval(k / n, float(ci.low), float(ci.high), confidence), method, tuple(crits))


@dataclass(frozen=True)
class Sensitivity:
    """A sensitivity ranking of ``metric``: ``names`` with their ``values`` (largest |value|
    first), the method and the fit's R^2 (SRC) or the total indices (Sobol)."""

    metric: str
    method: str
    names: tuple[str, ...]
    values: tuple[float, ...]
    r2: float = math.nan
    total: tuple[float, ...] = ()
    #: Sobol only: per name, the bootstrap confidence interval of the first-order and of the
    #: total index, ``(first_low, first_high, total_low, total_high)``.
    intervals: tuple[tuple[float, float, float, float], ...] = ()

    def top(self, k: int = 3) -> list[tuple[str, float]]:
        return list(zip(self.names, self.values))[:k]


def src(table: Any, metric: str, inputs: Sequence[str] | None = None) -> Sensitivity:
    """Standardised regression coefficients of ``metric`` on the ``inputs`` (default: every
    toleranced column that varies), ranked by magnitude; failed samples are left out."""
    cols = columns(table)
    y = _metric(cols, metric)
    names = list(inputs) if inputs is not None else input_names(table)
    for nme in names:
        if nme not in cols:
            raise ParameterError(f"unknown input column {nme!r}")
    ok = np.isfinite(y)
    x = np.column_stack([np.asarray(cols[c], dtype=float) for c in names])[ok] if names else np.zeros((ok.sum(), 0))
    y = y[ok]
    sx = x.std(axis=0, ddof=1) if len(y) > 1 else np.zeros(x.shape[1])
    keep = sx > 0
    names = [nm for nm, kp in zip(names, keep) if kp]
    x, sx = x[:, keep], sx[keep]
    sy = float(y.std(ddof=1)) if len(y) > 1 else 0.0
    if len(y) <= len(names) + 1:
        raise ParameterError(f"SRC of {metric!r} needs more samples that ran ({len(y)}) than inputs + 1 "
                             f"({len(names) + 1})")
    if sy == 0:
        return Sensitivity(metric, "src", tuple(names), tuple(0.0 for _ in names), math.nan)
    a = np.column_stack([np.ones(len(y)), (x - x.mean(axis=0)) / sx])
    coef, *_ = np.linalg.lstsq(a, (y - y.mean()) / sy, rcond=None)
    b = coef[1:]
    fit = a @ coef
    r2 = 1.0 - float(np.sum(((y - y.mean()) / sy - fit) ** 2)) / float(np.sum(((y - y.mean()) / sy) ** 2))
    order = np.argsort(-np.abs(b), kind="stable")
    return Sensitivity(metric, "src", tuple(names[i] for i in order), tuple(float(b[i]) for i in order), r2)


def sobol(scene: Any, kernel: Any, tolerances: Sequence[Any], n: int, metric: str, *, seed: int | None = 0,
          runner: Any = None, kernel_options: dict[str, Any] | None = None, batch_size: int = 1,
          confidence: float | None = 0.95, n_resamples: int = 999) -> Sensitivity:
    """First-order Sobol indices of ``metric`` (ranked; ``total`` holds the total indices in
    the same order) from a Saltelli design of ``n`` base samples (a power of 2): the kernel
    runs n (d + 2) times on ``runner``. ``intervals`` holds bootstrap confidence intervals at
    level ``confidence`` (None: none) from ``n_resamples`` resamples (SciPy's BCa bootstrap of
    the Saltelli design; ``seed`` fixes the design, the indices and the resamples, so a seeded
    call repeats to the last digit; ``seed=None`` varies the interval ends by about
    1/sqrt(n_resamples) between calls). Independent tolerances only.

    Every run of the design is needed (SciPy would read a missing output as 0 and report no
    sensitivity at all): a sample that fails (its kernel raised, or returned a metric that is
    not finite) raises :class:`rvdyn.study.RunnerError` with the number of failed samples and
    the first error, as soon as the batch of runs that holds it has finished. A ``metric``
    that the kernel does not give is a :class:`rvdyn.ParameterError` listing the metrics it
    gives: before any run when the kernel declares its metrics, else after the first batch."""
    from scipy import stats  # type: ignore[import-untyped, import-not-found, unused-ignore]

    from .kernels import get_kernel
    from .runners import RunnerError, Task, _Failure, evaluate_batch, resolve_runner
    from .spec import expand
    import functools
    import os

    if isinstance(n, bool) or not isinstance(n, int) or n < 2 or n & (n - 1):
        raise ParameterError(f"sobol: n must be a power of 2 >= 2, got {n!r}")
    if confidence is not None and not 0 < confidence < 1:
        raise ParameterError(f"sobol: confidence must lie in (0, 1) or be None, got {confidence!r}")
    if isinstance(batch_size, bool) or not isinstance(batch_size, (int, np.integer)) or batch_size < 1:
        raise ParameterError(f"sobol: batch_size must be a positive integer, got {batch_size!r}")
    k = get_kernel(kernel, **(kernel_options or {}))
    layout = expand(scene, tolerances)
    metrics = getattr(k, "metrics", None)
    if metrics is not None and metric not in metrics:
        raise ParameterError(f"sobol: unknown metric {metric!r}; the kernel gives {list(metrics)}")
    keep = [j for j, v in enumerate(layout.variables) if v.upper > v.lower]
    dists = [layout.variables[j].scipy_dist() for j in keep]
    if not dists:
        raise ParameterError("sobol: every tolerance band is zero")
    # A zero-width band is a fixed offset: its variable stays at nominal + lower in every
    # sample, as in study() and design() (Variable.ppf of a zero-width band).
    fixed = np.array([v.nominal + 0.5 * (v.lower + v.upper) for v in layout.variables])
    mapper = resolve_runner(runner)
    task = Task(scene, k, layout, 1, os.getpid())
    fn = functools.partial(evaluate_batch, task)

    total_runs = n * (len(keep) + 2)
    runs = [0]
    failed: list[str] = []
    checked = [metrics is not None]

    def run_rows(batches: list[list[tuple[int, list[float]]]], out: np.ndarray) -> None:
        for batch, res in zip(batches, mapper.run(fn, batches)):
            if isinstance(res, _Failure):
                failed.extend(res.message for _ in batch)
                continue
            for sid, m, err in res:
                if err:
                    failed.append(err)
                    continue
                if metric not in m:
                    raise ParameterError(f"sobol: unknown metric {metric!r}; the kernel gives {sorted(m)}")
                checked[0] = True
                out[sid] = m[metric]

    def func(xs: np.ndarray) -> np.ndarray:
        full = np.tile(fixed[:, None], (1, xs.shape[1]))
        full[keep] = xs
        rows = full.T
        batches = [[(i, rows[i].tolist()) for i in range(b, min(b + batch_size, len(rows)))]
                   for b in range(0, len(rows), batch_size)]
        out = np.full(len(rows), np.nan)
        if not checked[0]:  # one batch first: a misspelled metric costs one batch, not n (d + 2) runs
            run_rows(batches[:1], out)
            batches = batches[1:]
        run_rows(batches, out)
        runs[0] += len(rows)
        if failed:
            raise RunnerError(
                f"sobol: {len(failed)} of the {runs[0]} samples run so far (of {total_runs}) failed; the first: "
                f"{failed[0]}. Sobol indices need every run of the Saltelli design: narrow the tolerances to "
                "the range where the kernel works, or fix the kernel (rvdyn.study(...) records each failure "
                "as a row and src() ranks the samples that ran)")
        return out[None, :]

    try:
        res = stats.sobol_indices(func=func, n=n, dists=dists, **_rng_kw(stats.sobol_indices, seed))
    finally:
        mapper.close()
    first = np.asarray(res.first_order).ravel()
    total = np.asarray(res.total_order).ravel()
    names = [layout.variables[j].column for j in keep]
    order = np.argsort(-np.abs(first), kind="stable")
    intervals: tuple[tuple[float, float, float, float], ...] = ()
    if confidence is not None and np.all(np.isfinite(first)) and np.all(np.isfinite(total)):
        # SciPy's SobolResult.bootstrap (BCa over the Saltelli design's rows) takes no
        # generator and draws from NumPy's global RandomState: seed that from ``seed`` for
        # the call and put the caller's state back.
        saved = np.random.get_state() if seed is not None else None
        try:
            if seed is not None:
                np.random.seed(np.random.SeedSequence([int(seed), 0x50B01]).generate_state(1)[0])
            boot = res.bootstrap(confidence_level=confidence, n_resamples=n_resamples)
        finally:
            if saved is not None:
                np.random.set_state(saved)
        f_ci = boot.first_order.confidence_interval
        t_ci = boot.total_order.confidence_interval
        lo_f, hi_f = np.asarray(f_ci.low).ravel(), np.asarray(f_ci.high).ravel()
        lo_t, hi_t = np.asarray(t_ci.low).ravel(), np.asarray(t_ci.high).ravel()
        intervals = tuple((float(lo_f[i]), float(hi_f[i]), float(lo_t[i]), float(hi_t[i])) for i in order)
    return Sensitivity(metric, "sobol", tuple(names[i] for i in order), tuple(float(first[i]) for i in order),
                       total=tuple(float(total[i]) for i in order), intervals=intervals)
