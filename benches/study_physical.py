"""The tolerance study of the physical preset: `Scene.physical("rated")`, the "ltca" kernel,
Monte Carlo seed 11 over the two profile modifications (normal, band +-10 um = 6 sigma) and the
24 pin radii (uniform +-5 um), rows streamed to Parquet, on 2 workers.

    python benches/study_physical.py                      # 10 000 samples, processes:2
    python benches/study_physical.py --runner dask --samples 10000
    python benches/study_physical.py --runner threads:2 --samples 2000

Runners: "threads:2", "processes:2", "dask" (a LocalCluster of 2 single-threaded worker
processes, started here; its start-up is timed separately) and "ray" (Ray on 2 CPUs). Prints the
wall time of the study alone, samples/s, the yield for TE <= 1 arcmin (both directions) with its
Wilson interval, the three largest standardised regression coefficients of the forward TE and
the peak pin force, and the peak RSS of this process.
"""

from __future__ import annotations

import argparse
import math
import resource
import tempfile
import time
from typing import Any

import rvdyn
from rvdyn.study import Criterion, MonteCarlo, Tolerance, describe, src, yield_rate

ARCMIN = math.radians(1.0 / 60.0)
TOLERANCES = [
    Tolerance("cycloid.d_rrp", tol=1e-5),
    Tolerance("cycloid.d_rp", tol=1e-5),
    Tolerance("pin_errors.radius", tol=5e-6, dist="uniform"),
]
CRITERIA = [Criterion("te_pp_forward", max=ARCMIN), Criterion("te_pp_reverse", max=ARCMIN)]


def start(runner: str) -> tuple[Any, Any, float]:
    """The runner object (and what to close) with its start-up time [s]."""
    t0 = time.perf_counter()
    if runner == "dask":
        from dask.distributed import Client, LocalCluster

        cluster = LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None)
        client = Client(cluster)
        return client, (client, cluster), time.perf_counter() - t0
    if runner == "ray":
        import ray
        from ray.util.multiprocessing import Pool

        ray.init(num_cpus=2, include_dashboard=False, log_to_driver=False)
        pool = Pool(2)
        return pool, (pool, ray), time.perf_counter() - t0
    return runner, None, 0.0


def stop(handles: Any) -> None:
    if handles is None:
        return
    a, b = handles
    if hasattr(b, "shutdown"):  # ray
        a.terminate()
        b.shutdown()
    else:
        a.close()
        b.close()


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--samples", type=int, default=10_000)
    ap.add_argument("--runner", default="processes:2")
    ap.add_argument("--seed", type=int, default=11)
    args = ap.parse_args()
    runner, handles, startup = start(args.runner)
    try:
        with tempfile.TemporaryDirectory() as out:
            t0 = time.perf_counter()
            table = rvdyn.study(rvdyn.Scene.physical("rated"), "ltca", TOLERANCES, MonteCarlo(args.samples),
                                seed=args.seed, runner=runner, out=out, batch_size=20, resume=False)
            wall = time.perf_counter() - t0
    finally:
        stop(handles)
    y = yield_rate(table, CRITERIA)
    errors = int((table["error"].fillna("").astype(str) != "").sum()) if "error" in table else 0
    print(f"runner {args.runner}: {args.samples} samples in {wall:.1f} s ({args.samples / wall:.1f} samples/s),"
          f" start-up {startup:.1f} s, {errors} error rows")
    print(f"yield TE <= 1 arcmin: {y.rate.value:.5f} [{y.rate.low:.5f}, {y.rate.high:.5f}] ({y.method})")
    for metric in ("te_pp_forward", "peak_pin_force"):
        try:
            s = src(table, metric)
        except rvdyn.ParameterError as e:  # too few samples for a regression: keep the rest
            print(f"SRC {metric}: skipped ({e})")
            continue
        top = ", ".join(f"{n} {v:+.3f}" for n, v in s.top(3))
        print(f"SRC {metric}: {top} (R^2 {s.r2:.3f})")
    for metric, stats in describe(table, ["te_pp_forward", "peak_pin_force"]).items():
        print(metric, {k: (round(v.value, 9), round(v.low, 9), round(v.high, 9)) if hasattr(v, "value") else v
                       for k, v in stats.items()})
    print(f"peak RSS {resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024:.0f} MiB (driver), "
          f"{resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss / 1024:.0f} MiB (largest worker process)")


if __name__ == "__main__":
    main()
