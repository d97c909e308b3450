"""Parallel sweep throughput: the same 8 runs on 1 and on 2 threads (BENCHMARKS.md, "Sweep").

Run: ``python benches/sweep_throughput.py`` (about 30 s). Each run is 1 s simulated of the rated
default scene with a different load torque (a grid over ``load.torque``), default integrator,
pin channels. Throughput = runs per second of wall time (best of 2).
"""

from __future__ import annotations

import json
import os
import sys
import time
from pathlib import Path

import numpy as np

from rvdyn import Scene, sweep

OUT = Path(__file__).parent / "results"


def main() -> int:
    base = Scene.paper("rated")
    grid = {"load.torque": list(np.linspace(1e4, 4.4e4, 8))}
    walls = {}
    for threads in (1, 2):
        best = float("inf")
        for _ in range(2):
            start = time.perf_counter()
            out = sweep(base, 1.0, grid=grid, threads=threads, channels=["motion", "pins"])
            best = min(best, time.perf_counter() - start)
            assert all(not isinstance(o, Exception) for o in out)
        walls[threads] = best
        print(f"{threads} thread(s): {len(out)} runs in {best:.2f} s = {len(out) / best:.2f} runs/s", flush=True)
    ratio = walls[1] / walls[2]
    print(f"throughput 2 threads / 1 thread = {ratio:.2f} (cores on this machine: {os.cpu_count()})")
    OUT.mkdir(exist_ok=True)
    (OUT / "sweep_throughput.json").write_text(json.dumps({"wall_1_thread_s": walls[1], "wall_2_threads_s": walls[2],
                                                           "ratio": ratio, "runs": 8, "cpus": os.cpu_count()}, indent=2))
    return 0


if __name__ == "__main__":
    import argparse

    # No options: --help describes the run instead of starting it (it rewrites benches/results).
    argparse.ArgumentParser(description=__doc__).parse_args()
    sys.exit(main())
