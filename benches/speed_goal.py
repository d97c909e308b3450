"""The speed goal (BENCHMARKS.md, "Speed goal"): 5 s simulated of the rated default scene with a
pin-force error of at most 0.1 % of the peak, in at most 0.5 s of wall time on one core.

Run: ``python benches/speed_goal.py`` (about 40 s: the converged references take most of it).
The error is measured over the whole 5 s run, after the start impact ([0.5, 5] s), against a
dopri5 reference (atol 1e-12 m, rtol 1e-10) whose own error is bounded by a tighter one
(atol 1e-13, rtol 1e-11). Samples every 1 ms in every run.
"""

from __future__ import annotations

import json
import sys
from pathlib import Path

import numpy as np

from rvdyn import Scene, simulate

OUT = Path(__file__).parent / "results"
T = 5.0
KW = {"record_interval": 1e-3, "channels": ["motion", "pins"], "progress": False}


def main() -> int:
    scene = Scene.paper("rated")
    ref = simulate(scene, T, "dopri5", atol=1e-12, rtol=1e-10, **KW)
    tight = simulate(scene, T, "dopri5", atol=1e-13, rtol=1e-11, **KW)
    win = ref.t >= 0.5
    peak = float(ref.pin_force[win].max())

    def err(r) -> tuple[float, float]:
        d = r.pin_force[win] - ref.pin_force[win]
        return float(np.abs(d).max() / peak), float(np.sqrt(np.mean(d**2)) / peak)

    rows = [{"run": "reference check: dopri5 atol 1e-13, rtol 1e-11", "wall_s": tight.stats["wall_time"],
             "pin_max": err(tight)[0], "pin_rms": err(tight)[1]}]
    print(f"reference: {ref.stats['wall_time']:.2f} s, peak pin force {peak:.0f} N; tighter run differs by "
          f"{err(tight)[0]:.1e} of the peak", flush=True)
    settings = [("generalized-alpha", {"dt": dt}, f"dt {dt:g} s") for dt in (1e-4, 2e-4, 5e-4)] + [
        ("generalized-alpha-adaptive", {"atol": a, "rtol": 1e3 * a}, f"atol {a:g} m, rtol {1e3 * a:g}")
        for a in (1e-7, 3e-8)]
    for integrator, opts, what in settings:
        runs = [simulate(scene, T, integrator, step_check="off", **opts, **KW) for _ in range(3)]
        wall = min(r.stats["wall_time"] for r in runs)
        e_max, e_rms = err(runs[0])
        rows.append({"run": f"{integrator} {what}", "wall_s": wall, "pin_max": e_max, "pin_rms": e_rms,
                     "steps": runs[0].stats["steps"]})
        print(f"{integrator} {what}: wall {wall:.3f} s, {runs[0].stats['steps']} steps, pin-force error max "
              f"{e_max:.2e}, RMS {e_rms:.2e} of the peak; goal (<= 0.5 s, <= 1e-3): "
              f"{'met' if wall <= 0.5 and e_max <= 1e-3 else 'not met'}", flush=True)
    OUT.mkdir(exist_ok=True)
    (OUT / "speed_goal.json").write_text(json.dumps({"peak_pin_force_N": peak, "rows": rows}, indent=2))
    return 0


if __name__ == "__main__":
    sys.exit(main())
