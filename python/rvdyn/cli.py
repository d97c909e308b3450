"""The ``rvdyn`` command line.

Subcommands::

    rvdyn info [--json]                     kinematics, operating point, geometry, stiffness
    rvdyn plot-geometry [--out DIR] [--psi RAD]
    rvdyn plot-stiffness [--out DIR]
    rvdyn paper [--out DIR] [--t-end S] [--load {idle,paper,rated,all}] [--integrator NAME]
    rvdyn analyze [SCENE] [--torque NM] [--angles N] [--loop-points N] [--crank-layout Z ...] [--out DIR]
    rvdyn study SPEC.toml [--out DIR] [--samples N] [--no-plots]
    rvdyn modes [SCENE] [--torque NM] [--compliant] [--power W] [--speeds LO HI] [--out DIR]

Each subcommand is one entry of :data:`COMMANDS` (name, help, arguments, handler): to add a
subcommand, write ``_add_x(parser)`` and ``_run_x(args) -> int`` and append one
:class:`Command`. Speeds are printed in deg/s and rad/s (the paper uses deg/s); everything else
is SI.
"""

from __future__ import annotations

import argparse
import importlib
import json
import math
import os
import re
import sys
import warnings
from dataclasses import dataclass
from typing import Any, Callable, Sequence

__all__ = ["main", "build_parser", "info_data", "COMMANDS", "Command"]

#: The paper's input speed [deg/s] and power [W] (section 4.1).
PAPER_INPUT_SPEED_DEG_S = 8328.0
PAPER_POWER_W = 112e3
DEFAULT_OUT = "rvdyn-out"


@dataclass(frozen=True)
class Command:
    """One subcommand: its name, one-line help, argument adder and handler (returns exit code)."""

    name: str
    help: str
    add_arguments: Callable[[argparse.ArgumentParser], None]
    run: Callable[[argparse.Namespace], int]


# ---------------------------------------------------------------------------------------------
# info


def info_data() -> dict[str, Any]:
    """Everything ``rvdyn info`` prints, as a JSON-ready dict (SI units; speeds also in deg/s)."""
    import rvdyn

    z_sun, z_planet, pins = 18, 42, 24
    ratio = rvdyn.transmission_ratio(z_sun, z_planet, pins)
    w_in = rvdyn.rad_s(PAPER_INPUT_SPEED_DEG_S)
    speeds = rvdyn.body_speeds(w_in, z_sun, z_planet, pins)
    op = rvdyn.operating_point(PAPER_POWER_W, w_in, ratio)
    printed = rvdyn.PAPER_PRINTED_OUTPUT_TORQUE
    printed_power = printed * op.output_speed

    g = rvdyn.CycloidGeometry.paper()
    stage = rvdyn.InvoluteStage.paper()
    mass, inertia = g.mass_properties()

    r1, r2 = rvdyn.PAPER_STIFFNESS_R1, rvdyn.PAPER_STIFFNESS_R2
    paper_max = {"convex-convex": 3.988e5, "convex-concave": 5.093e5}
    stiffness: dict[str, Any] = {
        "r1_m": r1,
        "r2_m": r2,
        "radii_note": (
            "R1 = pin radius (assumed 10 mm), R2 = disc pitch radius e*zc = 103.5 mm "
            "(the paper gives no radii for its Fig. 3)"
        ),
        "exponent": 1.5,
        "conditions": {},
    }
    lo, hi = 1e-4, 0.1
    for cond, paper_value in paper_max.items():
        k5 = float(rvdyn.contact_stiffness(5e-3, r1, r2, cond))
        entry: dict[str, Any] = {
            "k_at_5mm_N_per_m1_5": k5,
            "k_at_5mm_N_per_mm1_5": k5 / 1000.0**1.5,
            "paper_maximum_N_per_mm1_5": paper_value,
            "paper_maximum_width_m": 5e-3,
            "search_bracket_m": [lo, hi],
        }
        try:
            w_max, k_max = rvdyn.stiffness_maximum(r1, r2, cond, lo=lo, hi=hi)
            entry["maximum"] = {"width_m": w_max, "k_N_per_m1_5": k_max}
        except rvdyn.ParameterError as exc:
            entry["maximum"] = None
            entry["maximum_note"] = str(exc)
        try:
            w_f, k_f = rvdyn.stiffness_maximum(r1, r2, cond, lo=1e-8, hi=1e-6)
            entry["formal_maximum"] = {
                "width_m": w_f,
                "k_N_per_m1_5": k_f,
                "note": "outside Hertz theory: the contact width b is far larger than the radii",
            }
        except rvdyn.ParameterError:
            entry["formal_maximum"] = None
        stiffness["conditions"][cond] = entry

    presets: dict[str, Any] = {}
    for name, compiled in (("paper", _core_scene("paper")), ("physical", _core_scene("physical"))):
        presets[name] = json.loads(compiled.physics_summary())
    presets["paper"]["main_torsional_mode"] = "overdamped (no underdamped mode at rated load)"
    # Computed, not quoted: the linearised modes about the rated equilibrium (a few ms).
    main = rvdyn.modes(rvdyn.Scene.physical("rated"), crank_angle=0.0)
    presets["physical"]["main_torsional_mode"] = (
        f"{main.frequency[0]:.0f} Hz, damping ratio {main.damping_ratio[0]:.3f} "
        "(linearised, rated load, crank angle 0)"
    )
    # Computed too: ISO 281 lives of the roller bearings at rated torque and speed, from the
    # LTCA over one mesh period (about 10 ms; LtcaResult.bearing_life).
    presets["paper"]["bearing_life"] = "none (rigid joints)"
    life = rvdyn.ltca(rvdyn.Scene.physical("rated")).bearing_life()
    presets["physical"]["bearing_life"] = ", ".join(
        f"{name} {v['l10_hours']:.1f} h (s0 {v['static_safety']:.2f})" for name, v in life.items()) + " (L10, ISO 281)"
    # Where each preset's torsional compliance comes from (compliance budget, about 1 ms each).
    from .analysis.budget import compliance_budget
    from .analysis.ltca import ARCMIN

    for name, scene in (("paper", rvdyn.Scene.paper("rated")), ("physical", rvdyn.Scene.physical("rated"))):
        budget = compliance_budget(scene).grouped()
        presets[name]["torsional_stiffness_Nm_per_arcmin"] = float(budget.torsional_stiffness[0] * ARCMIN)
        presets[name]["compliance_share"] = dict(zip(budget.parts, budget.share[0].tolist()))
    presets["note"] = (
        "the paper preset keeps the paper's IMPACT law only to reproduce the paper: its stiffness "
        "k' sqrt(w) from eqs. 5-11 has units N/mm but is read as N/mm^1.5, and it makes the pins "
        "about 8x too compliant; the physical preset derives its laws from geometry and materials"
    )

    return {
        "presets": presets,
        "scene": "paper (default): z1 18, z2 42, 3 planets, zp 24, e 4.5 mm given; "
        "rp 150 mm, rrp 10 mm, disc 40 mm, module 3 mm, 20 deg, gear face 30 mm assumed",
        "kinematics": {
            "z_sun": z_sun,
            "z_planet": z_planet,
            "pins": pins,
            "lobes": pins - 1,
            "ratio": ratio,
            "input_speed_deg_s": PAPER_INPUT_SPEED_DEG_S,
            "speeds": {
                name: {"rad_s": value, "deg_s": rvdyn.deg_s(value)}
                for name, value in speeds.items()
            },
        },
        "operating_point": {
            "power_W": op.power,
            "input_speed_rad_s": op.input_speed,
            "output_speed_rad_s": op.output_speed,
            "input_torque_Nm": op.input_torque,
            "output_torque_Nm": op.output_torque,
            "paper_printed_output_torque_Nm": printed,
            "paper_printed_output_power_W": printed_power,
            "paper_printed_output_torque_consistent": bool(
                math.isclose(printed, op.output_torque, rel_tol=0.01)
            ),
            "note": (
                f"the paper's printed output torque {printed} N m is only "
                f"{printed_power / 1e3:.1f} kW at the output speed; 112 kW gives "
                f"{op.output_torque / 1e3:.2f} kN m (lossless, = ratio x input torque)"
            ),
        },
        "geometry": {
            "cycloid": {
                "pins": g.pins,
                "lobes": g.lobes,
                "eccentricity_m": g.eccentricity,
                "pin_circle_radius_m": g.pin_circle_radius,
                "pin_radius_m": g.pin_radius,
                "face_width_m": g.face_width,
                "k1": g.k1,
                "min_convex_radius_m": g.min_convex_radius,
                "profile_min_convex_radius_m": _profile_min_convex_radius(g),
                "pitch_radius_m": g.pitch_radius,
                "root_curvature_radius_m": float(g.curvature_radius(0.0)),
                "disc_mass_kg": mass,
                "disc_inertia_kg_m2": inertia,
            },
            "involute": {
                "z_sun": stage.z_sun,
                "z_planet": stage.z_planet,
                "planets": stage.planets,
                "module_m": stage.module,
                "pressure_angle_rad": stage.pressure_angle,
                "face_width_m": stage.face_width,
                "centre_distance_m": stage.centre_distance,
                "contact_ratio": stage.contact_ratio,
            },
        },
        "stiffness": stiffness,
    }


def _profile_min_convex_radius(g: Any) -> float:
    """Smallest convex radius of curvature of the disc profile [m], sampled over one lobe (the
    pin-centre curve's less the generating pin radius, where the profile is convex)."""
    import numpy as np

    rho = np.asarray(g.curvature_radius(np.linspace(0.0, 2.0 * math.pi / g.lobes, 20001)))
    return float(rho[rho > 0.0].min())


def _core_scene(preset: str) -> Any:
    from rvdyn import _core

    return _core.CompiledScene.paper("rated") if preset == "paper" else _core.CompiledScene.physical("rated")


def _format_presets(p: dict[str, Any]) -> list[str]:
    a, b = p["paper"], p["physical"]
    rows = [
        ("pin contact law", a["pin_law"], b["pin_law"]),
        ("pin approach at the reference pin force (*)",
         f"{a['pin_approach_m'] * 1e6:.1f} um at {a['peak_pin_force_N'] / 1e3:.1f} kN",
         f"{b['pin_approach_m'] * 1e6:.1f} um at {b['peak_pin_force_N'] / 1e3:.1f} kN"),
        ("mesh law", a["mesh_law"], b["mesh_law"]),
        ("mesh stiffness at the rated mesh force",
         f"{a['mesh_stiffness_N_per_m']:.3e} N/m", f"{b['mesh_stiffness_N_per_m']:.3e} N/m"),
        ("pin damping", a["damping"], b["damping"]),
        ("main torsional mode", a["main_torsional_mode"], b["main_torsional_mode"]),
        ("bearing life at rated torque and speed", a["bearing_life"], b["bearing_life"]),
        ("torsional stiffness at rated torque (**)", _stiffness_text(a), _stiffness_text(b)),
    ]
    # Columns as wide as their longest entry, so that no entry runs into the next.
    w0, w1 = (max(len(r[k]) for r in rows) for k in (0, 1))
    lines = ["Presets side by side (rated load)", f"  {'':{w0}s}  {'paper':{w1}s}  physical"]
    lines += [f"  {name:{w0}s}  {x:{w1}s}  {y}" for name, x, y in rows]
    lines.append("  (*) 4 T_c / (zp rc') with T_c = T_out / 2: the largest pin force of the classical load sharing "
                 "(rigid pins, linear law; Malhotra & Parameswaran 1983)")
    lines.append("  (**) tangent dT/d twist at crank angle 0, input held, and where the compliance comes from "
                 "(rvdyn.analysis.compliance_budget)")
    lines.append(f"  ({p['note']})")
    return lines


def _stiffness_text(preset: dict[str, Any]) -> str:
    """``"12783 N m/arcmin: crank bearings 47 %, ..."``, largest share first."""
    shares = sorted(preset["compliance_share"].items(), key=lambda kv: -kv[1])
    return (f"{preset['torsional_stiffness_Nm_per_arcmin']:.0f} N m/arcmin: "
            + ", ".join(f"{part} {100 * share:.0f} %" for part, share in shares))


def _format_info(d: dict[str, Any]) -> str:
    kin, op, geo, st = d["kinematics"], d["operating_point"], d["geometry"], d["stiffness"]
    cyc, inv = geo["cycloid"], geo["involute"]
    lines = [
        "rvdyn: default scene ('paper')",
        f"  {d['scene']}",
        "",
        "Kinematics",
        f"  ratio i = 1 + (z2/z1) zp = 1 + ({kin['z_planet']}/{kin['z_sun']}) {kin['pins']}"
        f" = {kin['ratio']:g}",
        f"  speeds for input {kin['input_speed_deg_s']:g} deg/s (counter-clockwise positive):",
    ]
    for name, v in kin["speeds"].items():
        lines.append(f"    {name:15s} {v['deg_s']:12.3f} deg/s  {v['rad_s']:12.5f} rad/s")
    lines += [
        "",
        "Operating point (lossless)",
        f"  power          {op['power_W'] / 1e3:10.1f} kW",
        f"  input torque   {op['input_torque_Nm']:10.2f} N m",
        f"  output torque  {op['output_torque_Nm'] / 1e3:10.2f} kN m",
        f"  paper's printed output torque {op['paper_printed_output_torque_Nm']} N m: "
        + ("consistent" if op["paper_printed_output_torque_consistent"] else "INCONSISTENT"),
        f"    ({op['note']})",
        "",
        "Geometry",
        f"  cycloid: zp {cyc['pins']}, zc {cyc['lobes']}, e {cyc['eccentricity_m'] * 1e3:g} mm, "
        f"rp {cyc['pin_circle_radius_m'] * 1e3:g} mm, rrp {cyc['pin_radius_m'] * 1e3:g} mm, "
        f"face {cyc['face_width_m'] * 1e3:g} mm",
        f"    K1 = {cyc['k1']:.4f}, pitch radius rc' = {cyc['pitch_radius_m'] * 1e3:.2f} mm, "
        f"profile: smallest convex radius {cyc['profile_min_convex_radius_m'] * 1e3:.3f} mm, "
        f"root radius of curvature {cyc['root_curvature_radius_m'] * 1e3:.3f} mm",
        f"    pin-centre curve: smallest convex radius {cyc['min_convex_radius_m'] * 1e3:.3f} mm "
        "(the undercut limit for the pin radius)",
        f"    disc mass {cyc['disc_mass_kg']:.3f} kg, inertia {cyc['disc_inertia_kg_m2']:.4f} "
        "kg m^2 (steel, with bore and holes)",
        f"  involute stage: {inv['z_sun']}/{inv['z_planet']}, {inv['planets']} planets, "
        f"module {inv['module_m'] * 1e3:g} mm, {math.degrees(inv['pressure_angle_rad']):g} deg, "
        f"centre distance {inv['centre_distance_m'] * 1e3:g} mm, "
        f"contact ratio {inv['contact_ratio']:.3f}",
        "",
        f"Contact stiffness (eqs. 5-11, errata corrected), R1 = {st['r1_m'] * 1e3:g} mm, "
        f"R2 = {st['r2_m'] * 1e3:g} mm",
        f"  ({st['radii_note']})",
    ]
    for cond, e in st["conditions"].items():
        lines.append(
            f"  {cond}: k(5 mm) = {e['k_at_5mm_N_per_m1_5']:.4e} N/m^1.5 "
            f"= {e['k_at_5mm_N_per_mm1_5']:.4e} N/mm^1.5 "
            f"(paper's maximum {e['paper_maximum_N_per_mm1_5']:.4g} N/mm^1.5 near 5 mm)"
        )
        lo, hi = e["search_bracket_m"]
        if e["maximum"] is not None:
            m = e["maximum"]
            lines.append(
                f"    maximum {m['k_N_per_m1_5']:.4e} N/m^1.5 at width {m['width_m'] * 1e3:.3f} mm"
            )
        else:
            lines.append(
                f"    no maximum for widths {lo * 1e3:g}-{hi * 1e3:g} mm: k decreases with width"
            )
        if e["formal_maximum"] is not None:
            f = e["formal_maximum"]
            lines.append(
                f"    formal maximum {f['k_N_per_m1_5']:.4e} N/m^1.5 at width "
                f"{f['width_m'] * 1e3:.3g} mm ({f['note']})"
            )
    lines += [""] + _format_presets(d["presets"])
    return "\n".join(lines)


def _add_info(p: argparse.ArgumentParser) -> None:
    p.add_argument("--json", action="store_true", help="print JSON (SI units) instead of text")


def _run_info(args: argparse.Namespace) -> int:
    data = info_data()
    if args.json:
        print(json.dumps(data, indent=2))
    else:
        print(_format_info(data))
    return 0


# ---------------------------------------------------------------------------------------------
# plots


def _out_dir(path: str) -> str:
    os.makedirs(path, exist_ok=True)
    return path


def _folder(text: str) -> str:
    """argparse type of ``--out``: a non-empty folder name (created when written to)."""
    if not text.strip():
        raise argparse.ArgumentTypeError("the output folder must not be empty")
    return text


#: Shortest ``rvdyn paper --t-end`` [s]: the summary averages whole crank revolutions
#: (relative to the carrier) from 20 % of the run on, and one takes 0.103 s at the paper's
#: input speed (8328 deg/s x 24/57 = 3506 deg/s); 0.2 s leaves 0.16 s, more than one.
PAPER_MIN_T_END = 0.2
#: Longest ``rvdyn paper --t-end`` [s]: it records every 1e-4 s (the paper's figures), so 20 s
#: is 200 000 samples of every channel, about 0.1 GB.
PAPER_MAX_T_END = 20.0


def _paper_t_end(text: str) -> float:
    """argparse type of ``rvdyn paper --t-end``: a finite time of at least PAPER_MIN_T_END s."""
    try:
        t = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"not a number of seconds: {text!r}") from None
    if not math.isfinite(t):
        raise argparse.ArgumentTypeError(f"must be a finite time in s, got {text}")
    if t < PAPER_MIN_T_END:
        raise argparse.ArgumentTypeError(
            f"must be at least {PAPER_MIN_T_END} s (the summary averages whole crank "
            f"revolutions after the first 20 % of the run), got {text}"
        )
    if t > PAPER_MAX_T_END:
        raise argparse.ArgumentTypeError(
            f"must be at most {PAPER_MAX_T_END:g} s (every 1e-4 s is recorded for the paper's "
            f"figures; use rvdyn.simulate with a longer record_interval for long runs), got {text}"
        )
    return t


def _add_plot_geometry(p: argparse.ArgumentParser) -> None:
    p.add_argument("--out", default=DEFAULT_OUT, metavar="DIR", type=_folder,
                   help=f"output folder (default {DEFAULT_OUT})")
    p.add_argument("--psi", type=float, default=0.0, metavar="RAD",
                   help="crank angle of the front disc [rad] (default 0)")
    p.add_argument("--disc", choices=("both", "front", "rear"), default="both",
                   help="which disc(s) to draw (default both)")


def _run_plot_geometry(args: argparse.Namespace) -> int:
    from .plotting import plot_geometry, save_figure

    fig = plot_geometry(psi=args.psi, disc=args.disc)
    path = save_figure(fig, os.path.join(_out_dir(args.out), "geometry.png"))
    print(f"wrote {path}")
    return 0


def _add_plot_stiffness(p: argparse.ArgumentParser) -> None:
    p.add_argument("--out", default=DEFAULT_OUT, metavar="DIR", type=_folder,
                   help=f"output folder (default {DEFAULT_OUT})")


def _run_plot_stiffness(args: argparse.Namespace) -> int:
    from .plotting import plot_stiffness, save_figure

    fig = plot_stiffness()
    path = save_figure(fig, os.path.join(_out_dir(args.out), "stiffness.png"))
    print(f"wrote {path}")
    return 0


# ---------------------------------------------------------------------------------------------
# paper (implemented in rvdyn.paper when present)


def _add_paper(p: argparse.ArgumentParser) -> None:
    p.add_argument("--out", default=DEFAULT_OUT, metavar="DIR", type=_folder,
                   help=f"output folder (default {DEFAULT_OUT})")
    p.add_argument("--t-end", type=_paper_t_end, default=5.0, metavar="SECONDS",
                   help=f"simulated time [s], at least {PAPER_MIN_T_END} (default 5.0)")
    p.add_argument("--load", choices=("idle", "paper", "rated", "all"), default="all",
                   help="load case: idle, paper (4024.9 N m as printed), rated (43.9 kN m), "
                   "or all (default)")
    try:
        from .simulation import INTEGRATORS
    except ImportError:  # pragma: no cover - a build without the simulation module
        INTEGRATORS = None  # type: ignore[assignment]
    p.add_argument("--integrator", default=None, metavar="NAME", choices=INTEGRATORS,
                   help="time integrator"
                   + (f": one of {', '.join(INTEGRATORS)}" if INTEGRATORS else "")
                   + " (default: the scene's own, dopri5 for the idle case and generalized-alpha for the loaded ones)")


def _run_paper(args: argparse.Namespace) -> int:
    try:
        paper = importlib.import_module("rvdyn.paper")
    except ModuleNotFoundError as exc:
        if exc.name != "rvdyn.paper":
            raise
        print("rvdyn paper: not available in this version (module rvdyn.paper is missing)",
              file=sys.stderr)
        return 2
    result = paper.main(args)
    return int(result) if result is not None else 0


def _add_analyze(p: argparse.ArgumentParser) -> None:
    from .analysis.cli import add_arguments

    add_arguments(p)


def _run_analyze(args: argparse.Namespace) -> int:
    from .analysis.cli import run

    return run(args)


# ---------------------------------------------------------------------------------------------
# study (rvdyn.study.config)


def _add_study(p: argparse.ArgumentParser) -> None:
    p.add_argument("spec", metavar="SPEC.toml", help="study spec (format: help(rvdyn.study.config))")
    p.add_argument("--out", default=None, metavar="DIR", type=_folder,
                   help="output folder (default: the spec's [output] dir)")
    p.add_argument("--samples", type=int, default=None, metavar="N", help="override the number of samples")
    p.add_argument("--no-plots", action="store_true", help="do not draw the figures")


def _run_study(args: argparse.Namespace) -> int:
    from .study.config import run_spec

    res = run_spec(args.spec, out=args.out, samples=args.samples, plots=not args.no_plots)
    y = res.get("yield")
    lost = f" ({res['lost']} lost by the runner, left out of the statistics)" if res.get("lost") else ""
    print(f"rvdyn study: {res['samples']} samples, {res['failed']} failed{lost}"
          + (f"; yield {y['rate']['value']:.4g} [{y['rate']['low']:.4g}, {y['rate']['high']:.4g}]" if y else ""))
    if res["samples"] and res["failed"] == res["samples"]:
        # Nothing to analyse: a wrong kernel option fails every sample, and a job script
        # should see it.
        print(f"rvdyn study: every sample failed; the first: {res.get('first_error')}", file=sys.stderr)
        return 1
    return 0


def _add_modes(p: argparse.ArgumentParser) -> None:
    from .analysis.modes import add_cli_arguments

    add_cli_arguments(p)


def _run_modes(args: argparse.Namespace) -> int:
    from .analysis.modes import run_cli

    return run_cli(args)


COMMANDS: list[Command] = [
    Command("info", "print the default scene's kinematics, loads, geometry and stiffness",
            _add_info, _run_info),
    Command("plot-geometry", "draw the discs and pins (PNG)", _add_plot_geometry,
            _run_plot_geometry),
    Command("plot-stiffness", "draw contact stiffness vs contact width (PNG, paper Fig. 3)",
            _add_plot_stiffness, _run_plot_stiffness),
    Command("paper", "run the paper's simulations on the default scene and write figures",
            _add_paper, _run_paper),
    Command("analyze", "quasi-static analysis: load distribution, TE both directions, "
            "torque-twist loop, compliance budget, contact pressure, bearing loads, loads for FEA", _add_analyze, _run_analyze),
    Command("study", "run a tolerance study from a TOML spec (table, statistics, plots)", _add_study,
            _run_study),
    Command("modes", "modes about the loaded equilibrium, energy shares, Campbell diagram",
            _add_modes, _run_modes),
]


def build_parser(commands: Sequence[Command] = COMMANDS) -> argparse.ArgumentParser:
    """The argument parser with one subparser per :class:`Command`."""
    from . import __version__

    parser = argparse.ArgumentParser(
        prog="rvdyn",
        description="Dynamics of RV cycloid planetary reducers (SI units; speeds also in deg/s).",
    )
    parser.add_argument("--version", action="version", version=f"rvdyn {__version__}")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND")
    sub.required = True
    for cmd in commands:
        p = sub.add_parser(cmd.name, help=cmd.help, description=cmd.help)
        # argparse (before Python 3.13) reads "-4.39e4" as an option, not a negative number.
        p._negative_number_matcher = _NEGATIVE_NUMBER
        cmd.add_arguments(p)
        p.set_defaults(_run=cmd.run)
    return parser


_NEGATIVE_NUMBER = re.compile(r"^-(\d+\.?\d*|\.\d+)([eE][+-]?\d+)?$")

#: Library argument names in warnings, as the commands' options.
_OPTION_NAMES: dict[str, tuple[tuple[str, str], ...]] = {
    "analyze": (("use points >=", "use --angles >="), ("points per period", "--angles per period"),
                ("(`light` for the unloaded curves)", "(--light for the unloaded curves)")),
}

#: Whether a command's progress line (written with "\r", no newline yet) is open on stderr.
_PROGRESS_OPEN = [False]


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of the ``rvdyn`` console script; returns the exit code."""
    from .errors import RvdynError

    args = build_parser().parse_args(argv)
    seen: set[str] = set()

    def show(message: Warning | str, category: type[Warning], *_: object, **__: object) -> None:
        # One line each, once, on a line of its own (a progress line may be open), in the
        # command's own option names where the library names its arguments.
        words = str(message)
        for api, option in _OPTION_NAMES.get(args.command, ()):
            words = words.replace(api, option)
        text = f"rvdyn {args.command}: warning: {words}"
        if text not in seen:
            seen.add(text)
            print(f"\n{text}" if _PROGRESS_OPEN[0] else text, file=sys.stderr)

    try:
        with warnings.catch_warnings():
            warnings.simplefilter("always", RuntimeWarning)
            warnings.showwarning = show
            code = int(args._run(args))
        sys.stdout.flush()  # a full or closed stdout fails here, inside the handlers below
        return code
    except RvdynError as exc:
        print(f"rvdyn {args.command}: {type(exc).__name__}: {exc}", file=sys.stderr)
        return 1
    except KeyboardInterrupt:
        print(f"rvdyn {args.command}: interrupted", file=sys.stderr)
        return 130
    except BrokenPipeError:
        # Output piped into e.g. `head`: stop quietly, as Unix tools do.
        _silence_stdout()
        return 1
    except OSError as exc:
        # An output folder or file that cannot be made or written (a path through a file, a
        # read-only or full device, a folder where the PNG goes): say which and why.
        where = f" {exc.filename!r}" if exc.filename is not None else " standard output"
        reason = exc.strerror or str(exc)
        if isinstance(exc, FileExistsError):
            reason = "a file of that name exists where the output folder should be"
        print(f"rvdyn {args.command}: cannot write{where}: {reason}", file=sys.stderr)
        if exc.filename is None:
            _silence_stdout()
        return 1


def _silence_stdout() -> None:
    """Point stdout at /dev/null so that the interpreter's final flush cannot fail again."""
    try:
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())
    except (OSError, ValueError):  # pragma: no cover - no file descriptor behind stdout
        pass


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
