"""Sobol sensitivity of the physical preset's transmission error (which tolerances matter):
`Scene.physical("rated")`, the same tolerances as `benches/study_physical.py` (the two profile
modifications, normal, band +-10 um = 6 sigma, and the 24 pin radii, uniform +-5 um),
first-order and total Sobol indices of the forward TE peak-to-peak from a Saltelli design
(`rvdyn.study.sobol`, SciPy's `sobol_indices`) with bootstrap confidence intervals.

    python benches/sobol_physical.py                   # n = 512 base samples: 14 336 analyses
    python benches/sobol_physical.py --n 64 --points 24  # a quick look

The TE needs a finer crank-angle grid than the study's 24 angles per mesh period to be a
smooth function of the tolerances (its peak falls between samples): --points (default 96).
"""

from __future__ import annotations

import argparse
import math
import time

import numpy as np

import rvdyn
from rvdyn.study import FunctionKernel, Tolerance, sobol

TOLERANCES = [
    Tolerance("cycloid.d_rrp", tol=1e-5),
    Tolerance("cycloid.d_rp", tol=1e-5),
    Tolerance("pin_errors.radius", tol=5e-6, dist="uniform"),
]
POINTS = 96


def te_forward(scene: rvdyn.Scene) -> dict[str, float]:
    """Forward TE peak-to-peak [rad] over one mesh period at rated torque, POINTS angles."""
    from rvdyn import _core
    from rvdyn.analysis.ltca import _rated, _scene

    sc = _scene(scene)
    solver = _core.LtcaSolver(sc._compiled, 1e-12)
    angles = (float(solver.mesh_period) * np.arange(POINTS) / POINTS).tolist()
    te = solver.sweep(abs(_rated(sc, None)), angles)["transmission_error"]
    return {"te_pp_forward": float(np.ptp(te))}


def main() -> None:
    global POINTS
    ap = argparse.ArgumentParser()
    ap.add_argument("--n", type=int, default=512)
    ap.add_argument("--points", type=int, default=POINTS)
    ap.add_argument("--runner", default="processes:2")
    ap.add_argument("--seed", type=int, default=11)
    args = ap.parse_args()
    POINTS = args.points
    kernel = FunctionKernel(te_forward, metrics=("te_pp_forward",))
    t0 = time.perf_counter()
    s = sobol(rvdyn.Scene.physical("rated"), kernel, TOLERANCES, args.n, "te_pp_forward", seed=args.seed,
              runner=args.runner, batch_size=16)
    wall = time.perf_counter() - t0
    d = len(s.names)
    print(f"n {args.n}, {args.n * (d + 2)} analyses, {args.points} angles per period, {wall:.1f} s")
    arcsec = math.radians(1 / 3600)
    print(f"(TE in arcsec: 1 arcsec = {arcsec:.3e} rad)")
    for k, (name, first) in enumerate(zip(s.names, s.values)):
        tot = s.total[k]
        ci = s.intervals[k] if s.intervals else None
        extra = f" first [{ci[0]:.3f}, {ci[1]:.3f}] total [{ci[2]:.3f}, {ci[3]:.3f}]" if ci else ""
        print(f"{name:28s} S1 {first:+.3f} ST {tot:+.3f}{extra}")


if __name__ == "__main__":
    main()
