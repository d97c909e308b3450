"""Tolerance-study throughput: samples/s of the dynamic kernel (0.5 s runs) and of the LTCA
kernel (physical preset, 8 times as many samples) on 1 and 2 workers
for threads, processes and Dask; scheduling overhead per task; memory of a 100 000-sample
study with a cheap kernel streamed to Parquet.

    python benches/study_throughput.py                # everything (a few minutes on 2 cores)
    python benches/study_throughput.py --part memory  # one part: dynamic, ltca, overhead, memory

Rates are medians over interleaved rounds (runner A, B, C, A, B, C, ...); pools and clusters
are started and warmed up before timing (their start-up time is printed separately).
"""

from __future__ import annotations

import argparse
import concurrent.futures
import json
import multiprocessing
import os
import statistics
import subprocess
import sys
import tempfile
import time
from typing import Any

import rvdyn
from rvdyn.study import FunctionKernel, MonteCarlo, Tolerance

SCENE = rvdyn.Scene.paper("rated")
TOLS = [Tolerance("cycloid.d_rrp", tol=1e-5), Tolerance("cycloid.d_rp", tol=1e-5),
        Tolerance("pin_errors.radius", tol=5e-6, dist="uniform")]


def noop(scene: rvdyn.Scene) -> dict[str, float]:
    """A kernel doing nothing (scheduling overhead)."""
    return {"y": 0.0}


def cheap(scene: rvdyn.Scene) -> dict[str, float]:
    """A cheap kernel: a few numbers from the scene (memory of large studies)."""
    r = scene["pin_errors.radius"]
    return {"d_sum": scene["cycloid.d_rrp"] + scene["cycloid.d_rp"], "r_max": max(r), "r_min": min(r)}


class Serial:
    """The samples one after the other in this process (the baseline of the overhead)."""

    def map(self, fn: Any, items: Any) -> list[Any]:
        return [fn(i) for i in items]


def _runners(workers: int, serial: bool = False) -> dict[str, tuple[Any, float, Any]]:
    """name -> (runner, start-up seconds, closer)."""
    out: dict[str, tuple[Any, float, Any]] = {}
    if serial:
        out["serial"] = (Serial(), 0.0, lambda: None)
    out["threads"] = (workers, 0.0, lambda: None)
    t = time.perf_counter()
    ex = concurrent.futures.ProcessPoolExecutor(workers, mp_context=multiprocessing.get_context("spawn"))
    list(ex.map(_warm, range(workers)))
    out["processes"] = (ex, time.perf_counter() - t, ex.shutdown)
    try:
        from distributed import Client, LocalCluster
    except ImportError:
        return out
    t = time.perf_counter()
    cluster = LocalCluster(n_workers=workers, threads_per_worker=1, processes=True, dashboard_address=None,
                           silence_logs=40)
    client = Client(cluster)
    client.run(_warm, 0)
    out["dask"] = (client, time.perf_counter() - t, lambda: (client.close(), cluster.close()))
    return out


def _warm(_: Any) -> int:
    import rvdyn.study  # noqa: F401 - import cost outside the timing

    return os.getpid()


def _timed(runner: Any, kernel: Any, n: int, seed: int, scene: Any = None, **kw: Any) -> float:
    t = time.perf_counter()
    table = rvdyn.study(SCENE if scene is None else scene, kernel, TOLS, samples=MonteCarlo(n), seed=seed,
                        runner=runner, **kw)
    wall = time.perf_counter() - t
    assert (table["error"] == "").all(), table["error"].unique()
    return wall


def part_dynamic(n: int, rounds: int, t_end: float) -> dict[str, Any]:
    return _part_kernel("dynamic", f"dynamic t_end {t_end} s", n, rounds, None, {"t_end": t_end})


def part_ltca(n: int, rounds: int) -> dict[str, Any]:
    """The LTCA kernel (its defaults) on the physical preset, as in benches/study_physical.py."""
    return _part_kernel("ltca", "ltca physical", n, rounds, rvdyn.Scene.physical("rated"), {})


def _part_kernel(kernel: str, label: str, n: int, rounds: int, scene: Any, options: dict[str, Any]) -> dict[str, Any]:
    res: dict[str, Any] = {}
    for workers in (1, 2):
        runners = _runners(workers)
        for runner, _, _ in runners.values():
            _timed(runner, FunctionKernel(noop, ("y",)), 4, 0)
        walls: dict[str, list[float]] = {name: [] for name in runners}
        for r in range(rounds):
            for name, (runner, _, _) in runners.items():
                walls[name].append(_timed(runner, kernel, n, r, scene, kernel_options=options))
        for name, (_, startup, close) in runners.items():
            close()
            med = statistics.median(walls[name])
            res[f"{name}/{workers}"] = {"samples_per_s": n / med, "wall_s": walls[name], "startup_s": startup}
            print(f"{label}, {name:9s} {workers} worker(s): {n / med:6.2f} samples/s "
                  f"(walls {', '.join(f'{w:.2f}' for w in walls[name])} s; start-up {startup:.2f} s)", flush=True)
    for name in ("threads", "processes", "dask"):
        if f"{name}/1" in res and f"{name}/2" in res:
            s = res[f"{name}/2"]["samples_per_s"] / res[f"{name}/1"]["samples_per_s"]
            res[f"{name}/scaling"] = s
            print(f"  {name}: 2 workers / 1 worker = {s:.2f}x")
    return res


def part_overhead(n: int, rounds: int) -> dict[str, Any]:
    res: dict[str, Any] = {}
    runners = _runners(2, serial=True)
    for runner, _, _ in runners.values():  # imports (pandas, scipy) and first calls outside the timing
        _timed(runner, FunctionKernel(noop, ("y",)), 4, 0)
    cases = [(name, b) for name in runners for b in (1, 50)]
    walls: dict[tuple[str, int], list[float]] = {c: [] for c in cases}
    for r in range(rounds):
        for name, b in cases:
            walls[(name, b)].append(_timed(runners[name][0], FunctionKernel(noop, ("y",)), n, r, batch_size=b))
    for name, b in cases:
        per = statistics.median(walls[(name, b)]) / n
        res[f"{name}/batch{b}"] = per
        print(f"overhead, no-op kernel, {'1 (serial)' if name == 'serial' else '2 workers'}, {name:9s} batch {b:3d}: "
              f"{per * 1e6:8.1f} us per sample", flush=True)
    for _, _, close in runners.values():
        close()
    return res


_MEMORY_CHILD = """
import resource, sys, tempfile, time, os, json
sys.path.insert(0, {bench_dir!r})


def hwm():
    # Peak RSS of this process [KiB]: VmHWM (reset by exec, unlike ru_maxrss, which Linux
    # carries over from the forking parent).
    try:
        with open("/proc/self/status") as f:
            for line in f:
                if line.startswith("VmHWM:"):
                    return int(line.split()[1])
    except OSError:
        pass
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss


import study_throughput as b
import rvdyn
from rvdyn.study import FunctionKernel, MonteCarlo
base = hwm()
with tempfile.TemporaryDirectory() as d:
    t = time.perf_counter()
    path = rvdyn.study(b.SCENE, FunctionKernel(b.cheap, ("d_sum", "r_max", "r_min")), b.TOLS,
                       samples=MonteCarlo({n}), seed=0, runner=2, out=os.path.join(d, "s.parquet"),
                       chunk_size=5000, batch_size=100, load={load})
    wall = time.perf_counter() - t
    size = sum(os.path.getsize(os.path.join(d, "s.parquet", f)) for f in os.listdir(os.path.join(d, "s.parquet")))
peak = hwm()
print(json.dumps({{"n": {n}, "load": {load}, "baseline_MiB": base / 1024, "peak_MiB": peak / 1024,
                  "wall_s": wall, "disk_MiB": size / 2**20}}))
"""


def part_memory(sizes: list[int]) -> dict[str, Any]:
    res: dict[str, Any] = {}
    bench_dir = os.path.dirname(os.path.abspath(__file__))
    for n in sizes:
        for load in (False, True):
            code = _MEMORY_CHILD.format(bench_dir=bench_dir, n=n, load=load)
            out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
            d = json.loads(out.stdout.strip().splitlines()[-1])
            res[f"{n}/{'table' if load else 'disk'}"] = d
            print(f"memory, cheap kernel, {n:7d} samples ({27} inputs), table {'returned' if load else 'left on disk'}: "
                  f"peak RSS {d['peak_MiB']:.0f} MiB (after imports {d['baseline_MiB']:.0f} MiB), "
                  f"{d['wall_s']:.1f} s, {n / d['wall_s']:.0f} samples/s, Parquet {d['disk_MiB']:.1f} MiB", flush=True)
    return res


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--part", choices=("all", "dynamic", "ltca", "overhead", "memory"), default="all")
    ap.add_argument("--samples", type=int, default=12, help="dynamic samples per timing (default 12)")
    ap.add_argument("--rounds", type=int, default=2, help="interleaved rounds (default 2)")
    ap.add_argument("--t-end", type=float, default=0.5, help="dynamic run length [s] (default 0.5)")
    ap.add_argument("--json", default=None, help="also write the numbers to this JSON file")
    args = ap.parse_args()
    print(f"rvdyn {rvdyn.__version__}, {os.cpu_count()} CPUs, Python {sys.version.split()[0]}", flush=True)
    res: dict[str, Any] = {}
    if args.part in ("all", "dynamic"):
        res["dynamic"] = part_dynamic(args.samples, args.rounds, args.t_end)
    if args.part in ("all", "ltca"):
        res["ltca"] = part_ltca(8 * args.samples, args.rounds)
    if args.part in ("all", "overhead"):
        res["overhead"] = part_overhead(1000, args.rounds)
    if args.part in ("all", "memory"):
        res["memory"] = part_memory([10_000, 100_000])
    if args.json:
        with open(args.json, "w", encoding="utf-8") as f:
            json.dump(res, f, indent=1)


if __name__ == "__main__":
    main()
