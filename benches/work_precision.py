"""Work-precision of rvdyn's integrators: wall time against the error it buys.

What is measured
----------------
Scene: ``Scene.paper("rated")`` (43.9 kN m on the output, step start from rest at 8328 deg/s),
with rigid joints and with compliant joints (eccentric bearings 1e9 N/m, 1e4 N s/m; crank
bearings 2e9 N/m, 1e4 N s/m; no clearance). Each run simulates 0.5 s, records the channels
``motion`` and ``pins`` every 1e-4 s (the same sample times in every run) and is compared with
a converged reference run over the window [0.2, 0.5] s, which excludes the start-up impact
(0.5 s holds 4.7 crank revolutions relative to the carrier, 0.107 s each).

Integrators and settings: generalized-alpha dt in {2e-5, 5e-5, 1e-4, 2e-4, 4e-4, 1e-3} s;
generalized-alpha-adaptive atol in {1e-7, 3e-8, 1e-8, 3e-9, 1e-9, 1e-10} m with rtol = 1000 atol
(per metre of lever: the same relative weight of velocity errors at every tolerance); rk4 dt in
{2.5e-6, 5e-6, 1e-5, 2e-5, 4e-5, 8e-5} s (the last ones probe its stability limit; a
``SimulationError`` is recorded as "unstable"); dopri5 atol in {1e-7, 1e-8, 1e-9, 1e-10} m with
the default rtol 1e-6, plus (atol 1e-11, rtol 1e-9) and (atol 1e-12, rtol 1e-10). The fixed-step
check is off (``step_check="off"``): the large steps are measured on purpose.

Reference: dopri5 atol 1e-13 m, rtol 1e-11. Its convergence is shown by two other runs that
must agree with it far below the errors plotted: dopri5 one decade tighter (atol 1e-14,
rtol 1e-12) and an independent method, rk4 with dt = 1.25e-6 s (60 times below its stability
limit). (The looser dopri5 atol 1e-12, rtol 1e-10 is one of the dopri5 points: its pin-force
error, a few 1e-7 of the peak, is too close to the finest rk4 errors for it to be the reference.)

Error measures, all over the window [0.2, 0.5] s:
  (a) mean output speed over whole crank revolutions (``Result.mean_output_speed(0.2)``):
      relative error against the reference's; the deviation from theory (input / 57) is
      stored too;
  (b) pin forces: max |F - F_ref| over samples, discs and pins, and the RMS of F - F_ref over
      the same entries (unloaded pins included), both relative to the reference's peak pin
      force in the window;
  (c) disc centre path: max distance between the run's and the reference's disc centres [m].
Wall time: ``result.stats["wall_time"]`` (the Rust core) and the Python-side time of the
``simulate`` call; runs under 1 s are repeated and the best time kept.

Outputs: benches/results/work_precision.{png,json,md} (error against time) and
work_precision_tolerance.png (error against the tolerance or step); a recommendation (the
cheapest setting of each integrator with a max pin-force error <= 0.1 % of the peak) is printed
and stored.

``--preset physical`` measures ``Scene.physical("rated")`` instead (line-contact pin law, ISO
mesh stiffness, compliant roller bearings with clearance, damping ratio 0.05; drive ramped from
rest over 0.05 s), with the same span, window, samples and error measures, and writes
work_precision_physical.{png,json,md} and work_precision_physical_tolerance.png. Its modes reach
8 kHz and its roller contacts are stiff, so the settings are scaled to it: generalized-alpha dt
in {5e-6, 1e-5, 2e-5, 5e-5, 1e-4} s; generalized-alpha-adaptive atol in {1e-7, 3e-8, 1e-8,
3e-9} m with rtol = 1e4 atol (the ratio of benches/speed_goal.py's physical settings); rk4 dt in
{2.5e-6, 5e-6, 1e-5, 2e-5, 4e-5} s; dopri5 (atol, rtol) in {(1e-7, 1e-3), (1e-8, 3e-4),
(1e-8, 1e-4), (1e-9, 1e-5), (1e-10, 1e-6)}. Reference dopri5 atol 1e-12 m, rtol 1e-8, checked
against dopri5 atol 1e-13 m, rtol 1e-9 and rk4 at dt 1e-6 s (the tightest settings
benches/speed_goal.py showed to agree to 2.4e-6 of the peak over 5 s). About 3 minutes.

Run: ``python benches/work_precision.py`` from the repository root, with the extension built
(``maturin develop --release``). Takes about 70 s on a lightly loaded 2-core machine (the
budget is 10 minutes).
"""

from __future__ import annotations

import argparse
import json
import math
import os
import platform
import sys
import time
from pathlib import Path

import numpy as np

import rvdyn
from rvdyn import Scene, SimulationError, simulate

T_END = 0.5  # simulated span [s]
WINDOW_START = 0.2  # start of the error window [s]
RECORD_INTERVAL = 1e-4  # sample spacing [s], identical in every run
CHANNELS = ["motion", "pins"]
PIN_TOLERANCE = 1e-3  # recommendation: max pin-force error <= 0.1 % of the peak
REPEAT_BELOW = 1.0  # runs faster than this [s] are repeated, best time kept

COMPLIANT_JOINTS = {
    "kind": "compliant",
    "eccentric_bearing": {"stiffness": 1e9, "damping": 1e4, "clearance": 0.0},
    "crank_bearing": {"stiffness": 2e9, "damping": 1e4, "clearance": 0.0},
}

REFERENCE = ("dopri5", {"atol": 1e-13, "rtol": 1e-11})
CONVERGENCE_CHECKS = [("dopri5", {"atol": 1e-14, "rtol": 1e-12}), ("rk4", {"dt": 1.25e-6})]

SETTINGS = (
    [("generalized-alpha", {"dt": dt}) for dt in (2e-5, 5e-5, 1e-4, 2e-4, 4e-4, 1e-3)]
    + [("generalized-alpha-adaptive", {"atol": atol, "rtol": 1e3 * atol})
       for atol in (1e-7, 3e-8, 1e-8, 3e-9, 1e-9, 1e-10)]
    + [("rk4", {"dt": dt}) for dt in (2.5e-6, 5e-6, 1e-5, 2e-5, 4e-5, 8e-5)]
    + [("dopri5", {"atol": atol}) for atol in (1e-7, 1e-8, 1e-9, 1e-10)]
    + [("dopri5", {"atol": 1e-11, "rtol": 1e-9}), ("dopri5", {"atol": 1e-12, "rtol": 1e-10})]
)

# The physical preset (see the module docstring).
PHYSICAL_REFERENCE = ("dopri5", {"atol": 1e-12, "rtol": 1e-8})
PHYSICAL_CHECKS = [("dopri5", {"atol": 1e-13, "rtol": 1e-9}), ("rk4", {"dt": 1e-6})]
PHYSICAL_SETTINGS = (
    [("generalized-alpha", {"dt": dt}) for dt in (5e-6, 1e-5, 2e-5, 5e-5, 1e-4)]
    + [("generalized-alpha-adaptive", {"atol": atol, "rtol": 1e4 * atol}) for atol in (1e-7, 3e-8, 1e-8, 3e-9)]
    + [("rk4", {"dt": dt}) for dt in (2.5e-6, 5e-6, 1e-5, 2e-5, 4e-5)]
    + [("dopri5", {"atol": a, "rtol": r}) for a, r in ((1e-7, 1e-3), (1e-8, 3e-4), (1e-8, 1e-4), (1e-9, 1e-5),
                                                       (1e-10, 1e-6))]
)
# Line style and marker fill of each block in the plots.
STYLES = {"rigid": ("-", True), "compliant": ("--", False), "physical": ("-", True)}

RESULTS = Path(__file__).resolve().parent / "results"


def scenes() -> dict[str, Scene]:
    rigid = Scene.paper("rated")
    return {"rigid": rigid, "compliant": rigid.replace(joints=COMPLIANT_JOINTS)}


def label(integrator: str, options: dict[str, float]) -> str:
    return ", ".join(f"{k}={v:g}" for k, v in options.items())


def run(scene: Scene, integrator: str, options: dict[str, float], repeat: bool = True):
    """Simulate; return (result, best core time [s], best Python-side time [s])."""
    best_core = best_py = math.inf
    result = None
    for attempt in range(2):
        t0 = time.perf_counter()
        result = simulate(scene, T_END, integrator, record_interval=RECORD_INTERVAL, channels=CHANNELS,
                          progress=False, step_check="off", **options)
        py = time.perf_counter() - t0
        best_core = min(best_core, result.stats["wall_time"])
        best_py = min(best_py, py)
        if not repeat or py >= REPEAT_BELOW:
            break
    return result, best_core, best_py


class Reference:
    """The reference run and the error measures of another run against it."""

    def __init__(self, result, theory: float):
        self.r = result
        self.window = result.t >= WINDOW_START - 1e-9
        self.peak = float(result.pin_force[self.window].max())
        self.speed = result.mean_output_speed(WINDOW_START)
        self.theory = theory

    def errors(self, r) -> dict[str, float]:
        if r.t.shape != self.r.t.shape or not np.allclose(r.t, self.r.t, rtol=0, atol=1e-12):
            raise RuntimeError("runs must be sampled at the same times")
        w = self.window
        df = r.pin_force[w] - self.r.pin_force[w]
        speed = r.mean_output_speed(WINDOW_START)
        return {
            "speed_rel": abs(speed / self.speed - 1.0),
            "speed_vs_theory": speed / self.theory - 1.0,
            "pin_max_rel": float(np.abs(df).max()) / self.peak,
            "pin_rms_rel": float(np.sqrt(np.mean(df**2))) / self.peak,
            "disc_max_m": float(np.linalg.norm(r.disc_center[w] - self.r.disc_center[w], axis=-1).max()),
        }


def log(msg: str) -> None:
    print(msg, flush=True)


def measure(name: str, scene: Scene, theory: float, reference=REFERENCE, checks=CONVERGENCE_CHECKS,
            settings=SETTINGS) -> dict:
    log(f"\n== {name} ==")
    t0 = time.perf_counter()
    ref_result, core, py = run(scene, *reference, repeat=False)
    ref = Reference(ref_result, theory)
    log(f"reference {reference[0]} {label(*reference)}: {py:.2f} s, {int(ref_result.stats['steps'])} steps; "
        f"peak pin force in the window {ref.peak:.1f} N (whole run {ref_result.pin_force.max():.1f} N); "
        f"mean output speed / theory - 1 = {ref.speed / theory - 1:.3e}")
    out = {
        "reference": {"integrator": reference[0], **reference[1], "wall_time": core, "python_time": py,
                      "steps": ref_result.stats["steps"], "peak_pin_force_window": ref.peak,
                      "peak_pin_force_run": float(ref_result.pin_force.max()),
                      "mean_output_speed": ref.speed, "speed_vs_theory": ref.speed / theory - 1.0},
        "convergence": [],
        "runs": [],
    }
    for integ, opts in checks:
        r, core, py = run(scene, integ, opts, repeat=False)
        e = ref.errors(r)
        out["convergence"].append({"integrator": integ, **opts, "wall_time": core, **e})
        log(f"convergence check {integ} {label(integ, opts)} vs reference: pin max {e['pin_max_rel']:.2e}, "
            f"rms {e['pin_rms_rel']:.2e} (of the peak), speed {e['speed_rel']:.1e}, disc {e['disc_max_m']:.1e} m "
            f"[{py:.1f} s]")
    for integ, opts in settings:
        row = {"integrator": integ, "setting": label(integ, opts), **opts}
        try:
            r, core, py = run(scene, integ, opts)
        except SimulationError as exc:
            row.update(status="unstable", message=str(exc))
            log(f"{integ:18s} {row['setting']:22s} unstable: {str(exc)[:100]}")
        else:
            e = ref.errors(r)
            # A run that returns without an error but is far off (more than 10 % of the peak
            # pin force) is flagged: it is not a usable result.
            status = "ok" if e["pin_max_rel"] < 0.1 else "wrong (no error raised)"
            row.update(status=status, wall_time=core, python_time=py, steps=r.stats["steps"],
                       evaluations=r.stats.get("evaluations"), **e)
            log(f"{integ:18s} {row['setting']:22s} {core:7.3f} s (python {py:7.3f} s)  speed {e['speed_rel']:.1e}  "
                f"pin max {e['pin_max_rel']:.2e} rms {e['pin_rms_rel']:.2e}  disc {e['disc_max_m']:.1e} m"
                + ("" if status == "ok" else f"  [{status}]"))
        out["runs"].append(row)
    out["recommendation"] = recommend(out["runs"])
    out["elapsed"] = time.perf_counter() - t0
    return out


def recommend(runs: list[dict]) -> dict[str, dict | None]:
    """Cheapest (core time) setting of each integrator with pin max error <= PIN_TOLERANCE."""
    rec: dict[str, dict | None] = {}
    for integ in dict.fromkeys(r["integrator"] for r in runs):
        ok = [r for r in runs if r["integrator"] == integ and r["status"] == "ok" and r["pin_max_rel"] <= PIN_TOLERANCE]
        best = min(ok, key=lambda r: r["wall_time"], default=None)
        rec[integ] = None if best is None else {k: best[k] for k in ("setting", "wall_time", "pin_max_rel")}
    return rec


# ------------------------------------------------------------------------------------ output
COLORS = {"generalized-alpha": "tab:blue", "generalized-alpha-adaptive": "tab:purple", "dopri5": "tab:orange",
          "rk4": "tab:green"}
MEASURES = [
    ("speed_rel", "(a) mean output speed, relative error"),
    ("pin_max_rel", "(b) pin force, max |error| / peak"),
    ("pin_rms_rel", "(b') pin force, RMS error / peak"),
    ("disc_max_m", "(c) disc centre, max distance [m]"),
]
FLOOR = 1e-17  # errors below this (e.g. exactly 0) are drawn here


def plot(data: dict, path: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(2, 2, figsize=(12, 9.5))
    for ax, (key, title) in zip(axes.flat, MEASURES):
        for joints, block in data["joints"].items():
            style, fill = STYLES[joints]
            for integ, color in COLORS.items():
                # In the order of the settings (step or tolerance), so a curve that turns back
                # (no gain from a smaller step) shows as such.
                pts = [(max(r[key], FLOOR), r["wall_time"]) for r in block["runs"]
                       if r["integrator"] == integ and r["status"] == "ok"]
                if pts:
                    x, y = zip(*pts)
                    ax.plot(x, y, style, color=color, marker="o", mfc=color if fill else "white",
                            label=f"{integ}, {block_name(joints)}")
            bad = [(max(r[key], FLOOR), r["wall_time"]) for r in block["runs"] if r["status"].startswith("wrong")]
            if bad:
                ax.plot(*zip(*bad), "x", color="red", ms=9, ls="none",
                        label=f"wrong without an error, {block_name(joints)}")
            # Reference uncertainty: the largest disagreement of the convergence checks.
            floor = max(max(c[key] for c in block["convergence"]), FLOOR)
            ax.axvline(floor, color="grey", ls=style, lw=0.8, label=f"reference uncertainty, {block_name(joints)}")
        if key == "pin_max_rel":
            ax.axvline(PIN_TOLERANCE, color="red", lw=0.8, ls=":", label="0.1 % of the peak pin force")
        ax.set(xscale="log", yscale="log", xlabel="error", ylabel="core wall time [s]", title=title)
        ax.grid(True, which="major", alpha=0.3)
    handles, labels = {}, []
    for ax in axes.flat:
        for h, lab in zip(*ax.get_legend_handles_labels()):
            handles.setdefault(lab, h)
    fig.legend(list(handles.values()), list(handles), loc="lower center", ncol=3, fontsize="small")
    ref = data["reference"]
    blocks = "; ".join(f"{'solid/filled' if STYLES[j][1] else 'dashed/open'}: {block_name(j)}" for j in data["joints"])
    fig.suptitle(f"rvdyn work-precision: {data['scene']}, {T_END} s from rest, errors over "
                 f"[{WINDOW_START}, {T_END}] s against dopri5 atol {ref['atol']:g}, rtol {ref['rtol']:g}\n"
                 f"{blocks}; curves in the order of the step or tolerance; errors at the grey lines are upper "
                 "bounds", fontsize=9)
    fig.tight_layout(rect=(0, 0.1, 1, 1))
    fig.savefig(path, dpi=110)
    plt.close(fig)


def plot_tolerance(data: dict, path: Path) -> None:
    """Pin-force error against the tolerance (adaptive methods) and the step (fixed ones)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, (left, right) = plt.subplots(1, 2, figsize=(12, 5))
    for joints in data["joints"]:
        style, fill = STYLES[joints]
        for integ, color in COLORS.items():
            rows = [r for r in data["joints"][joints]["runs"] if r["integrator"] == integ and r["status"] == "ok"]
            ax, key = (right, "dt") if rows and "dt" in rows[0] else (left, "atol")
            pts = [(r[key], max(r["pin_max_rel"], FLOOR)) for r in rows if key in r]
            if pts:
                x, y = zip(*pts)
                ax.plot(x, y, style, color=color, marker="o", mfc=color if fill else "white",
                        label=f"{integ}, {block_name(joints)}")
    for ax, xlabel in ((left, "atol [m] (rtol as in the settings)"), (right, "dt [s]")):
        ax.axhline(PIN_TOLERANCE, color="red", lw=0.8, ls=":", label="0.1 % of the peak pin force")
        ax.set(xscale="log", yscale="log", xlabel=xlabel, ylabel="pin force, max |error| / peak")
        ax.grid(True, which="major", alpha=0.3)
        ax.legend(fontsize="small")
    left.set_title(f"{data['scene']}, adaptive methods: error against tolerance", fontsize=10)
    right.set_title(f"{data['scene']}, fixed-step methods: error against step", fontsize=10)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def block_name(joints: str) -> str:
    """The legend's name of a block of runs: the joints of the paper scene, or the preset."""
    return "physical preset" if joints == "physical" else f"{joints} joints"


def markdown(data: dict) -> str:
    ref = data["reference"]
    lines = [
        "# Work-precision (benches/work_precision.py)",
        "",
        f"Scene `{data['scene']}`, {T_END} s from rest, samples every {RECORD_INTERVAL:g} s, "
        f"errors over [{WINDOW_START}, {T_END}] s against dopri5 atol {ref['atol']:g} m, "
        f"rtol {ref['rtol']:g}. Pin-force errors relative to the reference's peak pin force in the "
        "window. Times: Rust core (`stats['wall_time']`) and the Python call, best of 2 for runs under 1 s.",
        f"Machine: {data['machine']['cpus']} cores, load average at start {data['machine']['load_average']}.",
        "",
    ]
    for joints, block in data["joints"].items():
        ref = block["reference"]
        lines += [
            f"## {block_name(joints)}",
            "",
            f"Reference: {ref['wall_time']:.2f} s, peak pin force {ref['peak_pin_force_window']:.1f} N in the "
            f"window ({ref['peak_pin_force_run']:.1f} N over the whole run); mean output speed / (input / ratio) - 1 = "
            f"{ref['speed_vs_theory']:.2e}.",
            "",
            "Convergence of the reference (the other run against it):",
            "",
            "| check | speed rel. | pin max | pin RMS | disc max [m] |",
            "|---|---|---|---|---|",
        ]
        for c in block["convergence"]:
            opts = ", ".join(f"{k}={c[k]:g}" for k in ("atol", "rtol", "dt") if k in c)
            lines.append(f"| {c['integrator']} {opts} | {c['speed_rel']:.1e} | {c['pin_max_rel']:.1e} | "
                         f"{c['pin_rms_rel']:.1e} | {c['disc_max_m']:.1e} |")
        lines += [
            "",
            "| integrator | setting | steps | core [s] | Python [s] | speed rel. err | speed vs theory | "
            "pin max / peak | pin RMS / peak | disc max [m] |",
            "|---|---|---|---|---|---|---|---|---|---|",
        ]
        for r in block["runs"]:
            if r["status"] == "unstable":
                lines.append(f"| {r['integrator']} | {r['setting']} | | | | unstable | | | | |")
                continue
            flag = "" if r["status"] == "ok" else f" ({r['status']})"
            lines.append(
                f"| {r['integrator']} | {r['setting']}{flag} | {int(r['steps'])} | {r['wall_time']:.3f} | "
                f"{r['python_time']:.3f} | {r['speed_rel']:.1e} | {r['speed_vs_theory']:+.2e} | "
                f"{r['pin_max_rel']:.2e} | {r['pin_rms_rel']:.2e} | {r['disc_max_m']:.1e} |")
        lines += ["", f"Cheapest setting with max pin-force error <= {PIN_TOLERANCE:.1%} of the peak:", ""]
        for integ, rec in block["recommendation"].items():
            lines.append(f"- {integ}: " + ("none" if rec is None else
                         f"{rec['setting']} ({rec['wall_time']:.3f} s, error {rec['pin_max_rel']:.1e})"))
        lines.append("")
    return "\n".join(lines)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--preset", choices=["paper", "physical"], default="paper")
    parser.add_argument("--joints", choices=["rigid", "compliant", "both"], default="both",
                        help="paper preset only")
    args = parser.parse_args()
    RESULTS.mkdir(exist_ok=True)
    start = time.perf_counter()
    if args.preset == "paper":
        all_scenes = scenes()
        names = ["rigid", "compliant"] if args.joints == "both" else [args.joints]
        reference, checks, settings, stem = REFERENCE, CONVERGENCE_CHECKS, SETTINGS, "work_precision"
        scene_name = 'Scene.paper("rated")'
    else:
        all_scenes = {"physical": Scene.physical("rated")}
        names = ["physical"]
        reference, checks, settings = PHYSICAL_REFERENCE, PHYSICAL_CHECKS, PHYSICAL_SETTINGS
        stem, scene_name = "work_precision_physical", 'Scene.physical("rated")'
    first = all_scenes[names[0]]
    theory = first["drive.speed"] / first.model_info()["ratio"]
    data = {
        "scene": scene_name,
        "t_end": T_END, "window": [WINDOW_START, T_END], "record_interval": RECORD_INTERVAL,
        "channels": CHANNELS, "reference": {"integrator": reference[0], **reference[1]},
        "theory_output_speed": theory,
        "machine": {"cpus": os.cpu_count(), "load_average": [round(x, 2) for x in os.getloadavg()],
                    "python": platform.python_version(), "rvdyn": rvdyn.__version__},
        "joints": {},
    }
    if args.preset == "paper":
        data["compliant_joints"] = COMPLIANT_JOINTS
    for name in names:
        try:
            data["joints"][name] = measure(name, all_scenes[name], theory, reference, checks, settings)
        except rvdyn.RvdynError as exc:  # e.g. the compliant model not available in this build
            log(f"{block_name(name)} could not be run: {type(exc).__name__}: {exc}")
            data["joints"][name] = {"error": f"{type(exc).__name__}: {exc}"}
    data["elapsed"] = time.perf_counter() - start
    ran = {k: v for k, v in data["joints"].items() if "runs" in v}
    (RESULTS / f"{stem}.json").write_text(json.dumps(data, indent=1))
    if ran:
        plot({**data, "joints": ran}, RESULTS / f"{stem}.png")
        plot_tolerance({**data, "joints": ran}, RESULTS / f"{stem}_tolerance.png")
        (RESULTS / f"{stem}.md").write_text(markdown({**data, "joints": ran}))
    log(f"\nRecommendation (cheapest setting with max pin-force error <= {PIN_TOLERANCE:.1%} of the peak):")
    for name, block in ran.items():
        for integ, rec in block["recommendation"].items():
            log(f"  {name:9s} {integ:18s} " + ("none of the settings" if rec is None else
                f"{rec['setting']:22s} {rec['wall_time']:.3f} s (error {rec['pin_max_rel']:.1e})"))
    log(f"\nwrote {RESULTS}/{stem}.{{json,md,png}}, {stem}_tolerance.png in {data['elapsed']:.0f} s")


if __name__ == "__main__":
    sys.exit(main())
