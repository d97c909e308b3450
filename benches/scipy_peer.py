"""The same rigid-joint reducer written with NumPy + SciPy, against rvdyn at equal error.

What is measured
----------------
``PeerModel`` below is the rigid-joint model of rust/dynamics/rigid.rs written as a user
without rvdyn would write it: NumPy, vectorised over the 2 x 24 pin/disc pairs, integrated by
``scipy.integrate.solve_ivp`` (Radau and LSODA). Same coordinates (q = [th_c, alpha], the sun
prescribed: step start from rest at full input speed), same exact cycloid contact (Newton on
the curve parameter for all 48 pairs at once, seeded from the kinematic parameter pin angle
minus disc angle), same IMPACT law with the cubic STEP damping, same three sun/planet meshes
along the line of action (zero backlash), same masses (``Scene.paper('rated').model_info()``)
and load torque. Only the parameters are read from the rvdyn scene.

1. Same model: (a) the peer's pin forces evaluated at the states rvdyn recorded agree with the
   pin forces rvdyn recorded (state level); (b) both integrated over 0.02 s from rest with tight
   tolerances agree (trajectory level). Printed: max difference / peak pin force.
2. SciPy's cost against the simulated span (0.05, 0.1, 0.2 s) at one tolerance.
3. Equal error: a 0.2 s run from rest, pin-force error = max |F - F_ref| over [0.1, 0.2] s (all
   samples, discs, pins; samples every 1e-4 s) relative to the reference's peak pin force there;
   reference rvdyn dopri5 atol 1e-13 m, rtol 1e-11. rvdyn runs a ladder of steps/tolerances of
   its three integrators, SciPy a ladder of rtol (atol = 1e-3 rtol, in rad and rad/s) for
   Radau (vectorised right-hand side for its finite-difference Jacobian) and LSODA. For each
   target error, the cheapest setting of each side that reaches it; the ratio of their
   Python-side wall times (rvdyn's ``simulate`` call; SciPy's ``solve_ivp`` plus evaluating the
   pin forces at the samples). Every run is repeated, the best time kept (3 times for rvdyn,
   twice for SciPy).

Outputs: benches/results/scipy_peer.{json,md}.

Run: ``python benches/scipy_peer.py`` from the repository root (needs scipy). Takes about
80 s on a lightly loaded 2-core machine (the budget is 10 minutes).
"""

from __future__ import annotations

import json
import math
import os
import sys
import time
from pathlib import Path

import numpy as np
from scipy.integrate import solve_ivp

import rvdyn
from rvdyn import Scene, simulate

# Sample interval [s] of both sides and span of the equal-error runs [s]:
# `python benches/scipy_peer.py 1e-3` runs the comparison with 1 ms samples (results in
# scipy_peer_1ms.*), `python benches/scipy_peer.py 1e-3 1.0` over 1 s (scipy_peer_1ms_1s.*).
def _arguments() -> tuple[float, float]:
    import argparse

    p = argparse.ArgumentParser(description=__doc__)
    p.add_argument("record_interval", nargs="?", type=float, default=1e-4, help="sample interval [s]")
    p.add_argument("t_run", nargs="?", type=float, default=0.2, help="span of the equal-error runs [s]")
    a = p.parse_args()
    return a.record_interval, a.t_run


RECORD_INTERVAL, T_RUN = _arguments()
SUFFIX = ("" if RECORD_INTERVAL == 1e-4 else f"_{RECORD_INTERVAL * 1e3:g}ms") + (
    "" if T_RUN == 0.2 else f"_{T_RUN:g}s")
CHANNELS = ["motion", "pins"]
T_CHECK = 0.02  # span of the same-model check [s]
WINDOW_START = 0.5 * T_RUN  # error window [WINDOW_START, T_RUN] [s]
SCALING_SPANS = (0.05, 0.1, 0.2)
SCALING_RTOL = 1e-4
TARGETS = (1e-2, 1e-3, 1e-4, 1e-5)  # pin-force error / peak

REFERENCE = ("dopri5", {"atol": 1e-13, "rtol": 1e-11})
RVDYN_SETTINGS = (
    [("generalized-alpha", {"dt": dt}) for dt in (1e-3, 6e-4, 4e-4, 3e-4, 2e-4, 1.5e-4, 1e-4, 7e-5, 5e-5, 3e-5, 2e-5)]
    + [("generalized-alpha-adaptive", {"atol": a, "rtol": 1e3 * a})
       for a in (3e-7, 1e-7, 3e-8, 1e-8, 3e-9, 1e-9, 3e-10, 1e-10)]
    + [("dopri5", {"atol": a}) for a in (1e-7, 1e-8, 1e-9, 1e-10)]
    + [("dopri5", {"atol": 1e-11, "rtol": 1e-9})]
    + [("rk4", {"dt": dt}) for dt in (4e-5, 2e-5, 1e-5)]
)
SCIPY_METHODS = ("LSODA", "Radau")
SCIPY_RTOLS = (1e-2, 3e-3, 1e-3, 3e-4, 1e-4, 3e-5, 1e-5, 3e-6, 1e-6)
SCIPY_ATOL_FACTOR = 1e-3
CHECK_TOLERANCES = {"rtol": 1e-10, "atol": 1e-13}

RESULTS = Path(__file__).resolve().parent / "results"


# ------------------------------------------------------------------------------------ the peer
class PeerModel:
    """Rigid-joint RV reducer in NumPy, from the equations of rust/dynamics/rigid.rs.

    State y = [th_c, alpha, th_c', alpha']: carrier angle, absolute crank angle (all cranks
    equal), their speeds. Disc k (eccentric phase a_k) has its centre at
    O_k = e (cos(alpha + a_k), sin(alpha + a_k)) and angle th_c - a_k / zc. A pin force -F n at
    the profile point X of disc k gives Q_c -= F (X - O_k) x n, Q_a -= F O_k x n; a mesh force F
    with deflection delta = r_bs (th_s - th_c) + r_bp (alpha - th_c) gives
    Q = -F grad(delta) per planet. The mass matrix is diagonal and constant.
    """

    def __init__(self, scene: Scene):
        d, info = scene.to_dict(), scene.model_info()
        cyc, stage = d["cycloid"], d["stage1"]
        assert d["joints"]["kind"] == "rigid" and d["drive"]["kind"] == "speed" and d["drive"]["start"] == "step"
        assert d["load"]["kind"] == "constant" and stage["backlash"] == 0.0 and d["initial"] == "rest"
        assert cyc["d_rp"] == cyc["d_rrp"] == cyc["d_delta"] == 0.0
        self.zp = cyc["pins"]
        self.zc = self.zp - 1
        self.e = cyc["eccentricity"]
        self.rp = cyc["pin_circle_radius"]
        self.rrp = cyc["pin_radius"]
        phases = np.array([disc["phase"] for disc in d["discs"]])
        self.phase = phases[:, None]  # (discs, 1)
        self.angle_offset = -phases[:, None] / self.zc
        th = 2 * np.pi * np.arange(self.zp) / self.zp
        self.pin_angle = th[None, :]  # (1, pins)
        self.pin_x, self.pin_y = self.rp * np.cos(self.pin_angle), self.rp * np.sin(self.pin_angle)
        pin, mesh = d["contact"]["pin"], d["contact"]["mesh"]
        self.pin_law = (pin["stiffness"], pin["exponent"], pin["max_damping"], pin["damping_depth"])
        self.mesh_law = (mesh["stiffness"], mesh["exponent"], mesh["max_damping"], mesh["damping_depth"])
        cos_pa = math.cos(stage["pressure_angle"])
        self.r_bs = 0.5 * stage["module"] * stage["z_sun"] * cos_pa
        self.r_bp = 0.5 * stage["module"] * stage["z_planet"] * cos_pa
        self.planets = stage["planets"]
        self.w_in = d["drive"]["speed"]
        self.load = d["load"]["torque"]
        self.mass = np.array(info["generalized_mass"][:2])  # carrier, crank

    @staticmethod
    def impact(x, xdot, k, expo, cmax, depth):
        """ADAMS IMPACT: k x^e + STEP(x, 0, 0, depth, cmax) xdot for x > 0, never negative."""
        xp = np.maximum(x, 0.0)
        s = np.minimum(xp / depth, 1.0)
        f = k * xp**expo + cmax * s * s * (3.0 - 2.0 * s) * xdot
        return np.where(x > 0.0, np.maximum(f, 0.0), 0.0)

    def foot(self, px, py, phi):
        """Foot of the pin centres (px, py) (disc frame) on the pin-centre curve
        C(phi) = rp (cos phi, sin phi) - e (cos zp phi, sin zp phi): Newton on
        f(phi) = (C - p) . C' for all pairs at once, from the seed ``phi``. Returns the foot
        point and the outward unit normal."""
        R, e, zp = self.rp, self.e, self.zp
        max_step = np.pi / (2 * zp)
        for _ in range(40):
            c1, s1 = np.cos(phi), np.sin(phi)
            cz, sz = np.cos(zp * phi), np.sin(zp * phi)
            cx, cy = R * c1 - e * cz, R * s1 - e * sz
            d1x, d1y = -R * s1 + e * zp * sz, R * c1 - e * zp * cz
            d2x, d2y = -R * c1 + e * zp * zp * cz, -R * s1 + e * zp * zp * sz
            rx, ry = cx - px, cy - py
            d1sq = d1x * d1x + d1y * d1y
            fp = d1sq + rx * d2x + ry * d2y
            if not np.all(fp > 0.0):
                raise FloatingPointError("a pin centre is beyond a centre of curvature of the profile")
            step = np.clip(-(rx * d1x + ry * d1y) / fp, -max_step, max_step)
            phi = phi + step
            if np.all(np.abs(step) * np.sqrt(d1sq) < 1e-8):
                # The last step moved the foot by < 1e-8 m: update point and tangent to first
                # order (the distance is stationary at the foot).
                cx, cy = cx + step * d1x, cy + step * d1y
                d1x, d1y = d1x + step * d2x, d1y + step * d2y
                norm = np.sqrt(d1x * d1x + d1y * d1y)
                return cx, cy, d1y / norm, -d1x / norm
        raise FloatingPointError("Newton on the curve parameter did not converge")

    def pin_forces(self, th_c, alpha, vc, va):
        """Pin forces (m, discs, pins) [N] and the generalised forces Q_c, Q_a (m,) for m states."""
        th_c, alpha, vc, va = (np.asarray(a, dtype=float).reshape(-1, 1, 1) for a in (th_c, alpha, vc, va))
        ox, oy = self.e * np.cos(alpha + self.phase), self.e * np.sin(alpha + self.phase)
        th = th_c + self.angle_offset
        c, s = np.cos(th), np.sin(th)
        dx, dy = self.pin_x - ox, self.pin_y - oy
        lx, ly = c * dx + s * dy, -s * dx + c * dy  # pin centre in the disc frame
        fx, fy, nlx, nly = self.foot(lx, ly, np.broadcast_to(self.pin_angle - th, lx.shape))
        pen = -((lx - fx) * nlx + (ly - fy) * nly)  # profile = pin-centre curve offset by rrp
        nx, ny = c * nlx - s * nly, s * nlx + c * nly
        px, py = fx - self.rrp * nlx, fy - self.rrp * nly  # contact point on the profile
        ax, ay = c * px - s * py, s * px + c * py
        lever_c = ax * ny - ay * nx
        lever_a = ox * ny - oy * nx
        f = self.impact(pen, lever_c * vc + lever_a * va, *self.pin_law)
        return f, -(f * lever_c).sum(axis=(1, 2)), -(f * lever_a).sum(axis=(1, 2))

    def rhs(self, t, y):
        """dy/dt for y of shape (4,) or (4, m) (vectorised for Radau's Jacobian)."""
        y = np.asarray(y, dtype=float)
        th_c, alpha, vc, va = y.reshape(4, -1)
        _, qc, qa = self.pin_forces(th_c, alpha, vc, va)
        th_s = self.w_in * t  # prescribed sun, full speed from t = 0
        delta = self.r_bs * (th_s - th_c) + self.r_bp * (alpha - th_c)
        rate = self.r_bs * (self.w_in - vc) + self.r_bp * (va - vc)
        fm = np.where(delta > 0.0, self.impact(delta, rate, *self.mesh_law),
                      -self.impact(-delta, -rate, *self.mesh_law))
        qc = qc + self.planets * fm * (self.r_bs + self.r_bp) - self.load
        qa = qa - self.planets * fm * self.r_bp
        out = np.stack([vc, va, qc / self.mass[0], qa / self.mass[1]])
        return out.reshape(y.shape)


# ------------------------------------------------------------------------------------ runs
def log(msg: str) -> None:
    print(msg, flush=True)


def best_of(fn, repeats: int):
    """Call fn() (returns (value, core_time or None)) ``repeats`` times; keep the best
    Python-side time and the best core time."""
    best_py = best_core = math.inf
    value = None
    for _ in range(repeats):
        t0 = time.perf_counter()
        value, core = fn()
        py = time.perf_counter() - t0
        best_py = min(best_py, py)
        best_core = min(best_core, core if core is not None else py)
    return value, best_core, best_py


def run_rvdyn(scene: Scene, t_end: float, integrator: str, opts: dict, repeats: int = 3):
    def go():
        r = simulate(scene, t_end, integrator, record_interval=RECORD_INTERVAL, channels=CHANNELS,
                     progress=False, step_check="off", **opts)
        return r, r.stats["wall_time"]
    return best_of(go, repeats)


def run_scipy(model: PeerModel, t_end: float, method: str, rtol: float, atol: float, repeats: int = 2):
    t_eval = np.arange(int(round(t_end / RECORD_INTERVAL)) + 1) * RECORD_INTERVAL

    def go():
        sol = solve_ivp(model.rhs, (0.0, t_end), np.zeros(4), method=method, t_eval=t_eval, rtol=rtol,
                        atol=atol, vectorized=(method == "Radau"))
        if sol.status != 0:
            raise RuntimeError(f"solve_ivp {method} failed: {sol.message}")
        forces = model.pin_forces(*sol.y)[0]
        return (sol, forces), None
    (sol, forces), _, py = best_of(go, repeats)
    return sol, forces, py


class PinError:
    """Max pin-force difference over a window, relative to the reference's peak there."""

    def __init__(self, ref_t, ref_force, t_start):
        self.window = ref_t >= t_start - 1e-9
        self.ref = ref_force[self.window]
        self.peak = float(self.ref.max())

    def __call__(self, force) -> float:
        return float(np.abs(force[self.window] - self.ref).max()) / self.peak


def same_model(scene: Scene, model: PeerModel) -> dict:
    log(f"1. same model? rvdyn and the peer from rest over {T_CHECK} s")
    ref, _, _ = run_rvdyn(scene, T_CHECK, *REFERENCE, repeats=1)
    err = PinError(ref.t, ref.pin_force, 0.0)
    f_state = model.pin_forces(ref.carrier_angle, ref.crank_angle[:, 0], ref.carrier_speed, ref.crank_speed[:, 0])[0]
    out = {"span": T_CHECK, "peak_pin_force": err.peak, "state_level": err(f_state), "trajectory_level": {}}
    log(f"   (a) peer forces at rvdyn's recorded states: max |dF| / peak = {out['state_level']:.1e} "
        f"(peak {err.peak:.0f} N, at the start-up impact)")
    for method in SCIPY_METHODS:
        sol, forces, py = run_scipy(model, T_CHECK, method, repeats=1, **CHECK_TOLERANCES)
        out["trajectory_level"][method] = {**CHECK_TOLERANCES, "max_rel": err(forces), "python_time": py,
                                           "nfev": int(sol.nfev)}
        log(f"   (b) SciPy {method} rtol {CHECK_TOLERANCES['rtol']:g}, atol {CHECK_TOLERANCES['atol']:g} vs rvdyn "
            f"{REFERENCE[0]} {REFERENCE[1]}: max |dF| / peak = {err(forces):.1e} [{py:.1f} s]")
    return out


def eval_cost(model: PeerModel) -> float:
    y = np.array([1e-3, -2e-2, 2.5, -58.0])
    n = 300
    t0 = time.perf_counter()
    for _ in range(n):
        model.rhs(1e-3, y)
    return (time.perf_counter() - t0) / n


def scaling(model: PeerModel) -> list[dict]:
    log(f"2. SciPy time against the simulated span (rtol {SCALING_RTOL:g}, atol {SCALING_RTOL * SCIPY_ATOL_FACTOR:g})")
    rows = []
    for method in SCIPY_METHODS:
        for span in SCALING_SPANS:
            sol, _, py = run_scipy(model, span, method, SCALING_RTOL, SCALING_RTOL * SCIPY_ATOL_FACTOR, repeats=1)
            rows.append({"method": method, "span": span, "python_time": py, "nfev": int(sol.nfev)})
            log(f"   {method:6s} {span:5.2f} s simulated: {py:6.2f} s, {sol.nfev} evaluations")
    return rows


def cheapest(rows: list[dict], target: float, time_key: str = "python_time") -> dict | None:
    ok = [r for r in rows if r.get("pin_max_rel", math.inf) <= target]
    return min(ok, key=lambda r: r[time_key], default=None)


def main() -> None:
    start = time.perf_counter()
    RESULTS.mkdir(exist_ok=True)
    scene = Scene.paper("rated")
    model = PeerModel(scene)
    data = {"scene": 'Scene.paper("rated"), rigid joints', "record_interval": RECORD_INTERVAL,
            "reference": {"integrator": REFERENCE[0], **REFERENCE[1]},
            "machine": {"cpus": os.cpu_count(), "load_average": [round(x, 2) for x in os.getloadavg()],
                        "rvdyn": rvdyn.__version__, "scipy": __import__("scipy").__version__,
                        "numpy": np.__version__}}
    data["same_model"] = same_model(scene, model)
    data["peer_rhs_seconds"] = eval_cost(model)
    log(f"   peer right-hand side: {data['peer_rhs_seconds'] * 1e6:.0f} us per call (one state)")
    data["scipy_scaling"] = scaling(model)

    log(f"3. equal error: {T_RUN} s from rest, max pin-force error over [{WINDOW_START}, {T_RUN}] s / peak")
    ref, _, ref_py = run_rvdyn(scene, T_RUN, *REFERENCE, repeats=1)
    err = PinError(ref.t, ref.pin_force, WINDOW_START)
    data["equal_error"] = {"t_end": T_RUN, "window": [WINDOW_START, T_RUN], "peak_pin_force": err.peak,
                           "rvdyn": [], "scipy": []}
    log(f"   reference {REFERENCE[0]} {REFERENCE[1]}: {ref_py:.2f} s; peak pin force in the window {err.peak:.0f} N")
    for integ, opts in RVDYN_SETTINGS:
        r, core, py = run_rvdyn(scene, T_RUN, integ, opts)
        row = {"integrator": integ, "setting": ", ".join(f"{k}={v:g}" for k, v in opts.items()), "wall_time": core,
               "python_time": py, "evaluations": r.stats.get("evaluations"), "pin_max_rel": err(r.pin_force)}
        row["seconds_per_evaluation"] = core / row["evaluations"]
        data["equal_error"]["rvdyn"].append(row)
        log(f"   rvdyn {integ:18s} {row['setting']:20s} {py:7.3f} s (core {core:.3f} s)  error {row['pin_max_rel']:.2e}")
    for method in SCIPY_METHODS:
        for rtol in SCIPY_RTOLS:
            atol = rtol * SCIPY_ATOL_FACTOR
            row = {"integrator": f"scipy {method}", "setting": f"rtol={rtol:g}, atol={atol:g}"}
            try:
                sol, forces, py = run_scipy(model, T_RUN, method, rtol, atol)
            except (RuntimeError, FloatingPointError) as exc:
                row.update(status=f"failed: {exc}")
                log(f"   scipy {method:6s} {row['setting']:26s} failed: {exc}")
            else:
                row.update(python_time=py, nfev=int(sol.nfev), njev=int(sol.njev), pin_max_rel=err(forces))
                log(f"   scipy {method:6s} {row['setting']:26s} {py:7.3f} s  {sol.nfev:6d} evaluations  "
                    f"error {row['pin_max_rel']:.2e}")
            data["equal_error"]["scipy"].append(row)

    comparisons = []
    for target in TARGETS:
        a = cheapest(data["equal_error"]["rvdyn"], target)
        b = cheapest(data["equal_error"]["scipy"], target)
        c = {"target": target, "rvdyn": a, "scipy": b}
        if a and b:
            c["ratio_python_time"] = b["python_time"] / a["python_time"]
            c["ratio_vs_rvdyn_core"] = b["python_time"] / a["wall_time"]
        comparisons.append(c)
    data["comparison"] = comparisons
    data["elapsed"] = time.perf_counter() - start
    (RESULTS / f"scipy_peer{SUFFIX}.json").write_text(json.dumps(data, indent=1))
    (RESULTS / f"scipy_peer{SUFFIX}.md").write_text(markdown(data))
    log("\nSciPy / rvdyn wall time at equal pin-force error (cheapest setting of each side reaching the target):")
    for c in comparisons:
        a, b = c["rvdyn"], c["scipy"]
        if a and b:
            log(f"   <= {c['target']:.0e}: rvdyn {a['integrator']} {a['setting']} {a['python_time']:.3f} s "
                f"({a['pin_max_rel']:.1e}); SciPy {b['integrator']} {b['setting']} {b['python_time']:.2f} s "
                f"({b['pin_max_rel']:.1e}): ratio {c['ratio_python_time']:.0f}")
        else:
            log(f"   <= {c['target']:.0e}: not reached by " + ("rvdyn" if not a else "SciPy"))
    log(f"\nwrote {RESULTS}/scipy_peer{SUFFIX}.{{json,md}} in {data['elapsed']:.0f} s")


def markdown(data: dict) -> str:
    sm, ee = data["same_model"], data["equal_error"]
    lines = [
        "# rvdyn against a NumPy + SciPy peer (benches/scipy_peer.py)",
        "",
        "Rigid-joint model of `Scene.paper(\"rated\")`, step start from rest. Machine: "
        f"{data['machine']['cpus']} cores, load average at start {data['machine']['load_average']}; "
        f"SciPy {data['machine']['scipy']}, NumPy {data['machine']['numpy']}.",
        "",
        f"## Same model ({sm['span']} s from rest, peak pin force {sm['peak_pin_force']:.0f} N)",
        "",
        "| check | max abs pin-force difference / peak |",
        "|---|---|",
        f"| peer forces at rvdyn's recorded states | {sm['state_level']:.1e} |",
    ]
    for method, v in sm["trajectory_level"].items():
        lines.append(f"| SciPy {method} (rtol {v['rtol']:g}, atol {v['atol']:g}) vs rvdyn dopri5 "
                     f"(atol 1e-13, rtol 1e-11) | {v['max_rel']:.1e} |")
    per_eval = min(r["seconds_per_evaluation"] for r in ee["rvdyn"])
    lines += ["", f"Peer right-hand side: {data['peer_rhs_seconds'] * 1e6:.0f} us per call (one state); rvdyn: "
              f"{per_eval * 1e6:.1f} us of core time per force evaluation (the cheapest rvdyn run per evaluation, "
              "recording included).", "",
              f"## SciPy time against the span (rtol {SCALING_RTOL:g}, atol {SCALING_RTOL * SCIPY_ATOL_FACTOR:g})", "",
              "| method | span [s] | time [s] | evaluations |", "|---|---|---|---|"]
    for r in data["scipy_scaling"]:
        lines.append(f"| {r['method']} | {r['span']} | {r['python_time']:.2f} | {r['nfev']} |")
    lines += ["", f"## Equal error ({ee['t_end']} s from rest; max pin-force error over "
              f"[{ee['window'][0]}, {ee['window'][1]}] s / peak {ee['peak_pin_force']:.0f} N)", "",
              "| side | integrator | setting | time [s] (Python) | core [s] | pin max error / peak |",
              "|---|---|---|---|---|---|"]
    for r in ee["rvdyn"]:
        lines.append(f"| rvdyn | {r['integrator']} | {r['setting']} | {r['python_time']:.3f} | {r['wall_time']:.3f} | "
                     f"{r['pin_max_rel']:.2e} |")
    for r in ee["scipy"]:
        if "pin_max_rel" in r:
            lines.append(f"| SciPy | {r['integrator'][6:]} | {r['setting']} | {r['python_time']:.3f} | | "
                         f"{r['pin_max_rel']:.2e} |")
        else:
            lines.append(f"| SciPy | {r['integrator'][6:]} | {r['setting']} | {r['status']} | | |")
    lines += ["", "## SciPy / rvdyn at equal error (cheapest setting of each side reaching the target)", "",
              "| target | rvdyn setting | rvdyn time [s] (error) | SciPy setting | SciPy time [s] (error) | ratio |",
              "|---|---|---|---|---|---|"]
    for c in data["comparison"]:
        a, b = c["rvdyn"], c["scipy"]
        if a and b:
            lines.append(f"| {c['target']:.0e} | {a['integrator']} {a['setting']} | {a['python_time']:.3f} "
                         f"({a['pin_max_rel']:.1e}) | {b['integrator'][6:]} {b['setting']} | {b['python_time']:.2f} "
                         f"({b['pin_max_rel']:.1e}) | {c['ratio_python_time']:.0f} |")
        else:
            lines.append(f"| {c['target']:.0e} | {'-' if not a else a['setting']} | | {'-' if not b else b['setting']} | | "
                         "not reached |")
    lines.append("")
    return "\n".join(lines)


if __name__ == "__main__":
    sys.exit(main())
