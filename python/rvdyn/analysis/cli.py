"""``rvdyn analyze``: the quasi-static analysis of a scene (load distribution, TE in both
directions, torque-twist loop, compliance budget, contact pressure, loads for FEA, summary)."""

from __future__ import annotations

import argparse
import dataclasses
import json
import math
import sys
from pathlib import Path
__all__ = ["add_arguments", "run"]


def add_arguments(p: argparse.ArgumentParser) -> None:
    """Arguments of ``rvdyn analyze``."""
    p.add_argument("scene", nargs="?", default=None,
                   help="scene file (.json or .toml); default: the preset chosen by --preset at rated load")
    p.add_argument("--preset", choices=("physical", "paper"), default="physical",
                   help="preset used without a scene file (default physical: line-contact pins, ISO "
                   "6336 meshes, roller bearings; paper: the paper's IMPACT laws, rigid joints)")
    p.add_argument("--torque", type=float, default=None, metavar="NM",
                   help="output torque [N m] (default: the scene's constant load)")
    p.add_argument("--angles", type=int, default=None, metavar="N",
                   help="crank angles per mesh period (default 90 for the load distribution; "
                        "for the TE, eight per tooth-mesh cycle of an ISO mesh, at least 90)")
    p.add_argument("--light", type=float, default=None, metavar="NM",
                   help="light load [N m] of the unloaded TE (default 1e-6 of the torque, at least "
                   "1e-3 N m); raise it if the unloaded TE finds no equilibrium")
    p.add_argument("--loop-points", type=int, default=201, metavar="N",
                   help="points of the torque-twist loop (default 201)")
    p.add_argument("--crank-layout", type=float, nargs="+", default=None, metavar="Z",
                   help="axial positions [m] of each crank's two bearings, its planet gear and the discs, "
                   "in this order (e.g. -0.06 0.06 -0.09 -0.02 0.02): the crank bearing's static safety "
                   "is then given for each of the two bearings (rvdyn.CrankLayout) instead of the "
                   "lumped one (default: the scene's crank_layout, if it has one)")
    from ..cli import _folder

    p.add_argument("--out", default="rvdyn-out", metavar="DIR", type=_folder,
                   help="output folder (default rvdyn-out)")


def _progress(done: int, total: int) -> None:
    from ..cli import _PROGRESS_OPEN

    print(f"\r  LTCA: {done}/{total} crank angles", end="" if done < total else "\n",
          file=sys.stderr, flush=True)
    _PROGRESS_OPEN[0] = done < total


def run(args: argparse.Namespace) -> int:
    """Run the analysis and write figures, loads and the summary into ``args.out``."""
    import numpy as np

    from ..plotting import save_figure
    from ..scene import Scene
    from .budget import compliance_budget
    from .ltca import ARCMIN, ARCSEC, ltca, torque_twist, transmission_error

    if args.scene is not None:
        scene = Scene.load(args.scene)
    else:
        scene = Scene.physical("rated") if args.preset == "physical" else Scene.paper("rated")
    # The options' own limits are checked before any work, not after the LTCA.
    from ..errors import ParameterError

    if args.angles is not None and args.angles < 2:
        raise ParameterError(f"--angles must be at least 2 crank angles per mesh period, got {args.angles}")
    if args.torque is not None and not (math.isfinite(args.torque) and args.torque != 0.0):
        raise ParameterError(f"--torque must be a finite, non-zero output torque [N m], got {args.torque}")
    if args.loop_points < 8:
        raise ParameterError(f"--loop-points must be at least 8, got {args.loop_points}")
    from ..bearing import CrankLayout

    layout = CrankLayout.of_scene(scene.to_dict())  # the scene's, unless --crank-layout is given
    if args.crank_layout is not None:
        z = args.crank_layout
        if len(z) < 4:
            raise ParameterError(f"--crank-layout needs the two bearings, the planet and at least one disc "
                                 f"(at least 4 positions [m]), got {len(z)}")
        layout = CrankLayout(bearings=(z[0], z[1]), planet=z[2], discs=tuple(z[3:]))
        layout.row_scene(scene.to_dict())  # a crank bearing built from rollers, checked before the work
    if args.torque is None and scene["load.kind"] != "constant":
        raise ParameterError(f"the scene's load is {scene['load.kind']!r}, not a constant torque: give --torque N_M")
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    print(f"rvdyn analyze: scene {scene['name'] or '(unnamed)'}, writing to {out}/", file=sys.stderr)
    probe = ltca(scene, args.torque, [0.0])
    period = probe.mesh_period
    n = 90 if args.angles is None else args.angles
    angles = period * np.arange(n) / n
    res = ltca(scene, args.torque, angles, progress=_progress, chunk=max(n // 10, 1))
    print("  TE both directions ...", file=sys.stderr)
    te = transmission_error(scene, args.torque, args.angles, light=args.light)
    print("  torque-twist loop ...", file=sys.stderr)
    loop = torque_twist(scene, args.torque, 0.0, args.loop_points)
    # Where the compliance comes from, from 5 % of the torque up (the loop's crank angle).
    budget = compliance_budget(scene, res.torque * np.linspace(0.05, 1.0, 20), 0.0)
    files = [
        save_figure(res.plot_load_distribution(), str(out / "load_distribution.png")),
        save_figure(res.plot_contact_pressure(), str(out / "contact_pressure.png")),
        save_figure(te.plot(), str(out / "transmission_error.png")),
        save_figure(loop.plot(), str(out / "torque_twist.png")),
        save_figure(budget.plot(), str(out / "compliance_budget.png")),
    ]
    csv_path, json_path = res.save_fea_loads(out)
    # Static safety at this torque where the bearings are built from rollers (ISO 76).
    rated = res.crank_bearing_force.size and any(c is not None for c in scene._compiled.bearing_ratings("static"))
    bearings = res.bearing_safety(layout) if rated else {}
    if bearings:
        files.append(save_figure(res.plot_bearing_loads(layout), str(out / "bearing_loads.png")))
    # ISO 281 life for steady running at the scene's drive speed (the LTCA's angles span the period).
    # (Its s0 warning would repeat bearing_safety's; the summary marks those lives instead.)
    lives = {}
    if bearings and scene["drive.kind"] == "speed":
        import warnings

        with warnings.catch_warnings():
            warnings.simplefilter("ignore", RuntimeWarning)
            lives = res.bearing_life(crank_layout=layout)
    pp = te.peak_to_peak()
    harmonics = te.harmonics("forward", 3)
    summary = {
        "scene": scene["name"],
        "torque_Nm": res.torque,
        "mesh_period_rad": period,
        # The TE figures are transmission_error's (extremes located between the angles), not
        # the load-distribution sweep's samples.
        **{k: v for k, v in res.summary().items() if not k.startswith("te_")},
        "te_peak_to_peak_arcsec": {k: v / ARCSEC for k, v in pp.items()},
        "te_window_rad": te.window,
        "te_periods": te.periods,
        # The largest harmonics of the forward TE, with the amplitude's aliasing estimate.
        "te_harmonics_forward": [
            {"harmonic": h.harmonic, "order": h.order, "label": h.label,
             "amplitude_arcsec": h.amplitude / ARCSEC,
             # None where no estimate is made (harmonics from a quarter of the grid up).
             "uncertainty_arcsec": h.uncertainty / ARCSEC if np.isfinite(h.uncertainty) else None}
            for h in harmonics],
        "te_mean_arcmin": {"forward": float(te.forward.mean()) / ARCMIN,
                           "reverse": float(te.reverse.mean()) / ARCMIN},
        **loop.summary(),
        "compliance_budget": budget.summary(),
        # Bending cranks (crank_shaft): the largest nominal bending stress over the period [Pa].
        "crank_bending_stress_max_Pa": (float(res.crank_bending_stress().max())
                                        if scene["crank_shaft"] else None),
        "bearing_static_safety": bearings,
        "bearing_life": lives,
        # The layout that split the crank bearing into crank_a and crank_b [m], if any.
        "crank_layout": dataclasses.asdict(layout) if layout is not None and bearings else None,
        "files": [*files, str(csv_path), str(json_path)],
    }
    (out / "summary.json").write_text(json.dumps(summary, indent=2))
    md = [
        "# rvdyn analyze",
        "",
        f"- output torque: {res.torque:.1f} N m; mesh period {period:.6f} rad of crank angle",
        f"- loaded pins per disc: {summary['loaded_pins_min']}-{summary['loaded_pins_max']}; "
        f"peak pin force {res.peak_pin_force / 1e3:.2f} kN; peak Hertz pressure "
        f"{summary['peak_pressure_max_Pa'] / 1e6:.0f} MPa",
        f"- TE peak-to-peak (forward at +{abs(res.torque):.1f} N m, reverse at -{abs(res.torque):.1f} N m, "
        f"whatever the sign of --torque): forward {pp['forward'] / ARCSEC:.3f} arcsec, reverse "
        f"{pp['reverse'] / ARCSEC:.3f} arcsec (unloaded {pp['unloaded_forward'] / ARCSEC:.3f} / "
        f"{pp['unloaded_reverse'] / ARCSEC:.3f} arcsec)" + (
            "" if te.periods == 1 else
            f" over the {te.periods} mesh periods ({te.window:.2f} rad of crank angle) after which the "
            f"TE repeats: the roller sets, fixed in the frame, make the periods differ"),
        "- largest TE harmonics (forward): " + "; ".join(
            f"{(h.label + ' ') if h.label else ''}(order {h.order:.3f}) {h.amplitude / ARCSEC:.3f}"
            + (f" +- {h.uncertainty / ARCSEC:.3f} arcsec" if np.isfinite(h.uncertainty) else " arcsec (not estimated)")
            for h in harmonics) + " (+-: the change on halving the grid; --angles refines it)",
        f"- torsional rigidity {summary['rigidity_Nm_per_arcmin']:.1f} N m/arcmin, lost motion "
        f"{summary['lost_motion_arcmin']:.3f} arcmin, backlash {summary['backlash_arcmin']:.3f} arcmin "
        f"(the loop runs to +-{abs(res.torque):.1f} N m, taken as the rated torque: rigidity between "
        f"the +-rated points, lost motion within +-3 % of it)",
        f"- compliance budget at {res.torque:.1f} N m (tangent stiffness "
        f"{summary['compliance_budget']['tangent_stiffness_Nm_per_arcmin']:.1f} N m/arcmin at crank angle 0): "
        f"{budget.where()} (compliance_budget.png: the shares from 5 % of the torque up)",
        *([f"- crankshafts ({scene['crank_shaft.diameter'] * 1e3:g} mm, bending between their bearings): "
           f"largest nominal bending stress {summary['crank_bending_stress_max_Pa'] / 1e6:.0f} MPa "
           "(32 M / (pi d^3), no notch factor)"] if scene["crank_shaft"] else []),
        *([("- bearings at this torque (ISO 76 static safety s0 = C0r / peak load): " + "; ".join(
            f"{name.replace('_', ' ')} peak {b['peak_load'] / 1e3:.1f} kN, C0r {b['static_rating'] / 1e3:.1f} kN, "
            f"s0 {b['static_safety']:.2f}" for name, b in bearings.items())
            + (" (crank a and b: the two bearings of the crank layout, from "
               + ("--crank-layout" if args.crank_layout is not None else "the scene's crank_layout")
               + ", each with rollers of "
               + ("half the lumped length" if layout.roller_length is None else f"{layout.roller_length * 1e3:g} mm")
               + ")" if layout is not None else ""))] if bearings else []),
        *([f"- rating life (ISO 281 L10, steady running at {scene['drive.speed']:.4g} rad/s input and this torque): "
           + "; ".join(f"{name.replace('_', ' ')} {b['l10_hours']:.4g} h"
                       + (" (s0 < 1: not valid)" if b["static_safety"] < 1 else "") for name, b in lives.items())]
          if lives else []),
        f"- equilibrium: torque balance <= {summary['torque_balance_max']:.1e}, residual <= "
        f"{summary['residual_max']:.1e} (relative)",
        *([f"- friction (pins {fr['pin']:g}, teeth {fr['mesh']:g}"
           + (f", bearings Palmgren f0 {fr['bearing']['f0']:g}, f1 {fr['bearing']['f1']:g}" if fr.get("bearing") else "")
           + "): in the torque-twist loop only; the load distribution, TE and input torque above are "
           "frictionless"] if (fr := scene.to_dict()["friction"])
          and (fr["pin"] > 0 or fr["mesh"] > 0 or fr.get("bearing")) else []),
        "",
        "Conventions and formulas: docs/model.md, \"Quasi-static analysis\".",
        "",
    ]
    (out / "summary.md").write_text("\n".join(md))
    print("\n".join(line for line in md if line.startswith("- ")))
    return 0
