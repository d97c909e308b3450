"""Per-call time of ``rvdyn.simulate`` for a 1 ms run of the rated default scene, from Python.

Prints the median time of one call [ms], the median core time (``Result.stats["wall_time"]``)
[ms] and their difference: the fixed cost of a call (scene, options, thread, arrays). To compare
two builds, run this script alternately under each (A B A B ...) and compare the medians, e.g.

    for i in 1 2 3; do PYTHONPATH=build_a python benches/call_overhead.py; \
                       PYTHONPATH=build_b python benches/call_overhead.py; done

BENCHMARKS.md section 9 has the numbers before and after the compiled scene.
"""

from __future__ import annotations

import statistics
import time

import rvdyn


def main(calls: int = 300) -> None:
    scene = rvdyn.Scene.paper("rated")
    for _ in range(20):  # warm up: imports, allocator, caches
        rvdyn.simulate(scene, 1e-3)
    call, core = [], []
    for _ in range(calls):
        t0 = time.perf_counter()
        r = rvdyn.simulate(scene, 1e-3)
        call.append(time.perf_counter() - t0)
        core.append(float(r.stats["wall_time"]))
    c, k = statistics.median(call) * 1e3, statistics.median(core) * 1e3
    print(f"call {c:.3f} ms  core {k:.3f} ms  fixed cost {c - k:.3f} ms")


if __name__ == "__main__":
    import argparse

    argparse.ArgumentParser(description=__doc__).parse_args()
    main()
