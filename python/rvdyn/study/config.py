"""``rvdyn study spec.toml``: a tolerance study described in a TOML file.

Format (SI units; every table but ``tolerances`` optional)::

    [scene]
    preset = "rated"                 # rvdyn.Scene.paper(preset), or: file = "scene.toml"
    changes = { initial = "steady" } # dotted paths -> values, applied to the scene (a nested
                                     # table such as friction.pin = 0.1 changes that field only)

    [kernel]
    name = "dynamic"                 # or "ltca" (options torque, points, ...)
    t_end = 0.5                      # other keys are the kernel's options

    [sampling]
    method = "lhs"                   # "lhs" (Latin hypercube) or "mc" (Monte Carlo)
    samples = 1000
    seed = 1

    [[tolerances]]
    path = "cycloid.d_rrp"
    tol = 1e-5                       # or lower = ..., upper = ...
    dist = "normal"                  # band = 6 sigma; or "uniform"

    [[correlations]]
    paths = ["cycloid.d_rp", "cycloid.d_rrp"]
    rho = 0.5                        # or matrix = [[1, 0.5], [0.5, 1]]

    [[criteria]]
    metric = "peak_pin_force"
    max = 2.0e5

    [runner]
    kind = "processes"               # "threads", "processes", "dask", "ray"
    workers = 2
    address = "tcp://scheduler:8786" # Dask scheduler or Ray address (kind dask / ray)

    [output]
    dir = "study-out"                # results.parquet/, statistics.json, PNG figures
    chunk_size = 1000
    batch_size = 1

Relative file paths are relative to the spec file.
"""

from __future__ import annotations

import json
import math
import sys
from pathlib import Path
from typing import Any

import numpy as np

from ..errors import ParameterError, SceneError
from ..scene import Scene

__all__ = ["load_spec", "run_spec"]

_SECTIONS = {"scene", "kernel", "sampling", "tolerances", "correlations", "criteria", "runner", "output"}


def _toml(path: Path) -> dict[str, Any]:
    if sys.version_info >= (3, 11):
        import tomllib
    else:  # Python 3.10
        try:
            import tomli as tomllib  # type: ignore[import-not-found, unused-ignore]
        except ImportError:
            raise ParameterError("reading spec.toml on Python 3.10 needs tomli: pip install tomli") from None
    try:
        text = path.read_text(encoding="utf-8")
    except OSError as exc:
        raise ParameterError(f"cannot read study spec {str(path)!r}: {exc.strerror}") from None
    try:
        return dict(tomllib.loads(text))
    except tomllib.TOMLDecodeError as exc:
        raise ParameterError(f"study spec {str(path)!r} is not valid TOML: {exc}") from None


def _keys(section: str, d: Any, allowed: set[str]) -> dict[str, Any]:
    if not isinstance(d, dict):
        raise ParameterError(f"[{section}] must be a table")
    extra = set(d) - allowed
    if extra:
        raise ParameterError(f"[{section}]: unknown keys {sorted(extra)} (known: {sorted(allowed)})")
    return d


_RUNNER_KINDS = ("threads", "processes", "dask", "ray")


def _check_runner(d: dict[str, Any]) -> None:
    """Refuse a [runner] table that cannot work, before a cluster starts or a sample runs."""
    kind = d.get("kind", "threads")
    if kind not in _RUNNER_KINDS:
        raise ParameterError(f"[runner] kind must be 'threads', 'processes', 'dask' or 'ray', got {kind!r}")
    workers = d.get("workers")
    if workers is not None and (isinstance(workers, bool) or not isinstance(workers, int) or workers < 1):
        raise ParameterError(f"[runner] workers must be a positive integer (the number of worker threads or "
                             f"processes), got {workers!r}; leave it out for the default")
    address = d.get("address")
    if address is not None and (not isinstance(address, str) or not address):
        raise ParameterError(f"[runner] address must be a string such as \"tcp://scheduler:8786\" or "
                             f"\"ray://head:10001\", got {address!r}")


def _runner(d: dict[str, Any]) -> Any:
    _check_runner(d)
    kind = d.get("kind", "threads")
    workers = d.get("workers")
    address = d.get("address")
    suffix = "" if workers is None else f":{workers}"
    if kind in ("threads", "processes"):
        return f"{kind}{suffix}"
    if kind == "dask":
        if address:
            return str(address)
        try:
            from distributed import Client, LocalCluster  # type: ignore[import-untyped, import-not-found, unused-ignore]
        except ImportError:
            raise ParameterError("[runner] kind = 'dask' needs Dask: pip install 'rvdyn[dask]'") from None
        cluster = LocalCluster(n_workers=workers or 2, threads_per_worker=1,  # type: ignore[no-untyped-call, unused-ignore]
                               processes=True, dashboard_address=None)
        return Client(cluster)  # type: ignore[no-untyped-call, unused-ignore]
    return str(address) if address else f"ray{suffix}"  # kind == "ray"


def _dotted(changes: dict[str, Any], prefix: str = "") -> dict[str, Any]:
    """``changes`` as dotted paths to values. TOML reads ``{ friction.pin = 0.1 }`` as the
    nested ``{friction: {pin: 0.1}}``, which as a whole table would reset the table's other
    fields; nested tables are therefore opened down to their values, except a table with a
    ``kind`` (a variant such as ``load`` or ``drive``), which replaces the field whole."""
    out: dict[str, Any] = {}
    for key, value in changes.items():
        path = f"{prefix}{key}"
        if isinstance(value, dict) and "kind" not in value and value:
            out.update(_dotted(value, path + "."))
        else:
            out[path] = value
    return out


def load_spec(path: str | Path) -> dict[str, Any]:
    """Read and check a study spec; returns the arguments of :func:`rvdyn.study.run` plus
    ``"output"`` (folder), ``"criteria"``. A value of the wrong type anywhere in the spec is a
    :class:`rvdyn.ParameterError` naming the spec."""
    try:
        return _load_spec(path)
    except ParameterError:
        raise  # already names the spec or its field
    except (TypeError, ValueError, KeyError) as exc:
        raise ParameterError(f"study spec {str(path)!r}: {type(exc).__name__}: {exc}") from None


def _load_spec(path: str | Path) -> dict[str, Any]:
    from .sampling import LatinHypercube, MonteCarlo
    from .spec import check_criteria, expand

    p = Path(path)
    spec = _toml(p)
    extra = set(spec) - _SECTIONS
    if extra:
        raise ParameterError(f"study spec: unknown sections {sorted(extra)} (known: {sorted(_SECTIONS)})")
    base = p.parent
    sc = _keys("scene", spec.get("scene", {}), {"preset", "file", "changes"})
    if "file" in sc:
        scene = Scene.load(base / sc["file"])
    else:
        try:
            scene = Scene.paper(sc.get("preset", "rated"))
        except (SceneError, ValueError) as exc:
            raise ParameterError(f"[scene] preset: {exc}") from None
    if sc.get("changes"):
        scene = scene.replace(**_dotted(_keys("scene.changes", sc["changes"], set(sc["changes"]))))
    kern = spec.get("kernel", {"name": "dynamic"})
    if not isinstance(kern, dict):
        raise ParameterError(f"[kernel] must be a table (e.g. [kernel] name = \"ltca\"), got {kern!r}")
    kern = dict(kern)
    kname = kern.pop("name", "dynamic")
    samp = _keys("sampling", spec.get("sampling", {}), {"method", "samples", "seed"})
    method = samp.get("method", "lhs")
    n = samp.get("samples", 100)
    if method not in ("lhs", "mc"):
        raise ParameterError(f"[sampling] method must be 'lhs' or 'mc', got {method!r}")
    sampler = (LatinHypercube if method == "lhs" else MonteCarlo)(n)
    tols = spec.get("tolerances")
    if not tols or not isinstance(tols, list):
        raise ParameterError("study spec: give at least one [[tolerances]] entry")
    corrs = spec.get("correlations", [])
    if not isinstance(corrs, list):
        raise ParameterError("study spec: correlations must be [[correlations]] tables (paths, rho or matrix)")
    crits = spec.get("criteria", [])
    if not isinstance(crits, list):
        raise ParameterError("study spec: criteria must be [[criteria]] tables (metric, max, min)")
    # Tolerances, correlations and criteria are checked now, before a cluster starts or a sample runs.
    expand(scene, tols, corrs)
    check_criteria(crits, None)
    runner = _keys("runner", spec.get("runner", {}), {"kind", "workers", "address"})
    _check_runner(runner)
    output = _keys("output", spec.get("output", {}), {"dir", "chunk_size", "batch_size"})
    outdir = Path(output.get("dir", "study-out"))
    if not outdir.is_absolute():
        outdir = base / outdir
    return {"scene": scene, "kernel": kname, "kernel_options": kern, "tolerances": tols,
            "correlations": corrs, "criteria": crits,
            "samples": sampler, "seed": samp.get("seed", 0), "runner_spec": runner, "output": outdir,
            "chunk_size": output.get("chunk_size", 1000), "batch_size": output.get("batch_size", 1)}


def run_spec(path: str | Path, out: str | Path | None = None, samples: int | None = None, plots: bool = True,
             progress: bool = True) -> dict[str, Any]:
    """Run the study of a spec file: writes ``results.parquet/`` (the table),
    ``statistics.json`` (summary, yield, sensitivity) and, with ``plots``, a histogram per
    metric and a sensitivity bar chart per metric into the output folder. Returns the
    statistics: ``failed`` counts every row with an error, ``lost`` those the runner lost
    (left out of the yield and summaries, with a ``RunnerFailureWarning``)."""
    from . import stats
    from .driver import run
    from .sampling import as_sampler

    args = load_spec(path)
    outdir = Path(out) if out is not None else args["output"]
    sampler = args["samples"] if samples is None else type(args["samples"])(as_sampler(samples).n)
    runner = _runner(args["runner_spec"])
    created = not outdir.exists()
    outdir.mkdir(parents=True, exist_ok=True)
    try:
        table = run(args["scene"], args["kernel"], args["tolerances"], sampler, seed=args["seed"], runner=runner,
                    out=outdir / "results.parquet", correlations=args["correlations"], criteria=args["criteria"],
                    kernel_options=args["kernel_options"], chunk_size=args["chunk_size"],
                    batch_size=args["batch_size"], progress=progress)
    except BaseException:
        # A spec refused before any sample ran leaves no empty output folder behind.
        if created and outdir.is_dir() and not any(outdir.iterdir()):
            outdir.rmdir()
        raise
    finally:
        if not isinstance(runner, str):
            cluster = getattr(runner, "cluster", None)
            runner.close()
            if cluster is not None:
                cluster.close()
    from .runners import RUNNER_FAILED

    summary = stats.describe(table)
    errors = table["error"][table["error"] != ""]
    lost = sum(1 for e in errors if str(e).startswith(RUNNER_FAILED))
    result: dict[str, Any] = {"samples": int(len(table)), "failed": int(len(errors)), "lost": lost,
                              "first_error": str(next(iter(errors))) if len(errors) else None,
                              "metrics": {m: {k: (v.__dict__ if isinstance(v, stats.Interval) else v)
                                              for k, v in e.items()} for m, e in summary.items()}}
    if args["criteria"]:
        y = stats.yield_rate(table, args["criteria"])
        result["yield"] = {"passed": y.passed, "n": y.n, "rate": y.rate.__dict__, "method": y.method,
                           "criteria": [c.label() for c in y.criteria]}
    result["sensitivity"] = {}
    for m in stats.metric_names(table):
        try:
            s = stats.src(table, m)
        except ParameterError as exc:
            result["sensitivity"][m] = {"error": str(exc)}
            if plots:
                _plots(table, m, None, args["criteria"], outdir)  # the histogram all the same
            continue
        result["sensitivity"][m] = {"method": "standardised regression coefficients", "r2": s.r2,
                                    "ranking": [[n, v] for n, v in zip(s.names, s.values)]}
        if plots:
            _plots(table, m, s, args["criteria"], outdir)
    # Strict JSON: a statistic that is not finite (a constant metric's R^2) is null.
    (outdir / "statistics.json").write_text(json.dumps(_finite_or_null(result), indent=1, default=float,
                                                       allow_nan=False), encoding="utf-8")
    return result


def _finite_or_null(v: Any) -> Any:
    """``v`` with every float that is not finite replaced by None (JSON has no NaN)."""
    if isinstance(v, dict):
        return {k: _finite_or_null(x) for k, x in v.items()}
    if isinstance(v, (list, tuple)):
        return [_finite_or_null(x) for x in v]
    if isinstance(v, (float, np.floating)):
        return float(v) if math.isfinite(v) else None
    return v


def _plots(table: Any, metric: str, sens: Any, criteria: Any, outdir: Path) -> None:
    import matplotlib

    if "matplotlib.pyplot" not in sys.modules:
        matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from .plots import plot_histogram, plot_sensitivity

    if sens is None:
        fig, ax = plt.subplots(figsize=(6.5, 4.5))
        plot_histogram(table, metric, criteria, ax=ax)
        fig.tight_layout()
        fig.savefig(outdir / f"{metric}.png", dpi=110)
        plt.close(fig)
        return
    fig, axes = plt.subplots(1, 2, figsize=(12, 4.5))
    plot_histogram(table, metric, criteria, ax=axes[0])
    plot_sensitivity(sens, ax=axes[1])
    fig.tight_layout()
    fig.savefig(outdir / f"{metric}.png", dpi=110)
    plt.close(fig)
