"""Work a scene does not need, measured with and without (BENCHMARKS.md, "Skip").

Run: ``python benches/skip_work.py`` (about 1 minute). Each row is the best of 3 wall times
(core time, ``Result.stats["wall_time"]``) for 1 s simulated of the rated default scene with
the default integrator (generalized-alpha, dt 1e-4 s), unless the row says otherwise. Where a
skip must not change the answer, the largest difference is printed too.
"""

from __future__ import annotations

import json
import sys
from pathlib import Path

import numpy as np

from rvdyn import Scene, simulate

T = 1.0
OUT = Path(__file__).parent / "results"


def best(scene: Scene, repeats: int = 3, **kw):
    runs = [simulate(scene, T, **kw) for _ in range(repeats)]
    return min(r.stats["wall_time"] for r in runs), runs[0]


def main() -> int:
    rows = []

    def add(name: str, without: float, with_: float, diff: str = "") -> None:
        rows.append({"skip": name, "without_s": without, "with_s": with_, "speedup": without / with_, "answer": diff})
        print(f"{name:60s} without {without:.3f} s  with {with_:.3f} s  x{without / with_:.2f}  {diff}", flush=True)

    rated = Scene.paper("rated")
    pins = ["motion", "pins"]
    # 1. Rigid joints remove the compliant DOFs (16 coordinates -> 2).
    t_c, _ = best(rated.with_compliant_joints(), channels=pins)
    t_r, _ = best(rated, channels=pins)
    add("rigid joints instead of compliant (2 instead of 16 DOF)", t_c, t_r, "different model (bearings rigid)")
    # 2. Pins that provably cannot touch are not queried.
    for label, scene in (("unmodified profile", rated),
                         ("modified profile d_rrp +20 um, d_rp -20 um",
                          rated.replace(**{"cycloid.d_rrp": 2e-5, "cycloid.d_rp": -2e-5}))):
        t_off, r_off = best(scene, channels=pins, skip_separated=False)
        t_on, r_on = best(scene, channels=pins, skip_separated=True)
        diff = np.abs(r_on.pin_force - r_off.pin_force).max() / r_off.pin_force.max()
        add(f"separated pins not queried, {label}", t_off, t_on, f"max pin-force difference {diff:.1e} of peak")
    # 3. A single-disc scene builds one disc (24 contacts instead of 48).
    t_two, _ = best(rated, channels=pins)
    t_one, _ = best(rated.replace(discs=[{"phase": 0.0}]), channels=pins)
    add("one disc declared instead of two", t_two, t_one, "different reducer")
    # 4. A scene without the first stage builds no meshes (cranks driven directly).
    single = rated.replace(stage1=None, **{"drive.speed": -rated["drive.speed"] * 23 / 57})
    t_s1, _ = best(rated, channels=pins)
    t_s0, _ = best(single, channels=pins)
    add("no first stage declared (cranks driven)", t_s1, t_s0, "different reducer")
    # 5. Channels not asked for are neither computed nor stored.
    everything = ["motion", "pins", "mesh", "energy", "contact_points"]
    t_all, r_all = best(rated, channels=everything)
    t_min, r_min = best(rated, channels=["motion"])
    diff = np.abs(r_all.carrier_angle - r_min.carrier_angle).max()
    add("motion only instead of every channel", t_all, t_min, f"max carrier-angle difference {diff:.1e} rad")
    OUT.mkdir(exist_ok=True)
    (OUT / "skip_work.json").write_text(json.dumps(rows, indent=2))
    lines = ["| skipped work | without [s] | with [s] | speed-up | answer |", "|---|---|---|---|---|"]
    lines += [f"| {r['skip']} | {r['without_s']:.3f} | {r['with_s']:.3f} | {r['speedup']:.2f} | {r['answer']} |" for r in rows]
    (OUT / "skip_work.md").write_text("\n".join(lines) + "\n")
    print("\n".join(lines))
    return 0


if __name__ == "__main__":
    import argparse

    # No options: --help describes the run instead of starting it (it rewrites benches/results).
    argparse.ArgumentParser(description=__doc__).parse_args()
    sys.exit(main())
