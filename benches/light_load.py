"""Force statistics of light loads against converged references (docs/validation.md, "Idle rattle
and light loads"; BENCHMARKS.md section 3, "Light loads").

Run: ``python benches/light_load.py FRACTION [PRESET] [RUNS]``. FRACTION is the constant load
as a fraction of the rated torque (0 = the idle scene), PRESET ``paper`` (default) or
``physical``, RUNS a comma-separated subset of the run names below (default all; the physical
references take 3-6 s of CPU each, the rest 0.1-3 s). Each run simulates 1 s from rest with
motion, pins and mesh recorded every 1e-4 s; the statistics are pin-force RMS and peak,
mesh-force RMS and peak and input-torque standard deviation over [0.5, 1] s (a rattle's values at
each instant depend on round-off, its statistics do not). Prints each run's statistics, its
relative errors against the tightest reference run (``ref1e-13``, else ``ref1e-12``), force
evaluations and CPU time, and writes ``benches/results/light_load_PRESET_FRACTION.json``.
"""

from __future__ import annotations

import argparse
import json
import time
import warnings
from pathlib import Path
from typing import Any

import numpy as np

from rvdyn import Scene, simulate

OUT = Path(__file__).parent / "results"
RUNS: dict[str, dict[str, Any]] = {
    "ga1e-4": {"integrator": "generalized-alpha", "dt": 1e-4},
    "ga2e-5": {"integrator": "generalized-alpha", "dt": 2e-5},
    "gaad1e-9": {"integrator": "generalized-alpha-adaptive", "atol": 1e-9},
    "dp1e-8": {"integrator": "dopri5", "atol": 1e-8, "rtol": 1e-4},
    "dp1e-9": {"integrator": "dopri5", "atol": 1e-9, "rtol": 1e-7},
    "dp1e-11": {"integrator": "dopri5", "atol": 1e-11, "rtol": 1e-9},
    "ref1e-12": {"integrator": "dopri5", "atol": 1e-12, "rtol": 1e-10},
    "ref1e-13": {"integrator": "dopri5", "atol": 1e-13, "rtol": 1e-11},
}
NAMES = ["pin RMS", "pin peak", "mesh RMS", "mesh peak", "input torque std"]


def statistics(r: Any) -> list[float]:
    w = r.t >= 0.5
    pins, mesh = r.pin_force[w], r.mesh_force[w]
    return [float(np.sqrt(np.mean(pins ** 2))), float(pins.max()), float(np.sqrt(np.mean(mesh ** 2))),
            float(np.abs(mesh).max()), float(r.input_torque[w].std())]


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("fraction", type=float, help="load as a fraction of the rated torque (0 = idle)")
    ap.add_argument("preset", nargs="?", default="paper", choices=("paper", "physical"))
    ap.add_argument("runs", nargs="?", default=",".join(RUNS), help="comma-separated run names")
    args = ap.parse_args()
    make = getattr(Scene, args.preset)
    rated = make("rated")
    torque = rated.to_dict()["load"]["torque"]
    scene = make("idle") if args.fraction == 0 else rated.replace(**{"load.torque": args.fraction * torque})
    print(f"{args.preset}, {args.fraction:g} of the rated torque: nominal mesh force "
          f"{scene.nominal_mesh_force:.4g} N, light load: {scene.light_load}")
    out: dict[str, Any] = {}
    for name in args.runs.split(","):
        t0 = time.process_time()
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")  # the step check's report is what is measured here
            r = simulate(scene, 1.0, channels=["motion", "pins", "mesh"], progress=False, **RUNS[name])
        out[name] = {"stats": statistics(r), "evaluations": r.stats["evaluations"],
                     "cpu": time.process_time() - t0}
    ref = out.get("ref1e-13") or out.get("ref1e-12")
    print(f"{'run':10s} " + " ".join(f"{n:>16s}" for n in NAMES) + "  evaluations   CPU")
    for name, o in out.items():
        cells = [f"{v:16.6g}" if ref is None else f"{(v - r0) / r0 * 100:+15.2f}%"
                 for v, r0 in zip(o["stats"], ref["stats"] if ref else o["stats"])]
        print(f"{name:10s} " + " ".join(cells) + f" {o['evaluations']:12d} {o['cpu']:5.2f}")
    OUT.mkdir(exist_ok=True)
    (OUT / f"light_load_{args.preset}_{args.fraction:g}.json").write_text(json.dumps(out, indent=1))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
