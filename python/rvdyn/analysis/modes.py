"""Modes of a loaded reducer: the rigid or compliant model linearised about its quasi-static
equilibrium (docs/model.md, "Modal analysis").

:func:`modes` gives the natural frequencies, damping ratios, mode shapes with named
coordinates and the share of strain energy in each contact family and bearing family at one
crank angle; :func:`modes_over_mesh` follows them over a range of crank angle, by default one
pin pitch (the stiffness varies with the crank angle). The command ``rvdyn modes`` writes both with the Campbell diagram.
"""

from __future__ import annotations

import math
import warnings
from dataclasses import dataclass, field
from typing import Any, Sequence

import numpy as np

from .. import _core
from .._args import short, whole
from ..errors import ParameterError

#: Most crank angles ``modes_over_mesh`` takes (one modal analysis each).
MAX_MESH_POINTS: int = 1_000_000

__all__ = ["Modes", "MeshSweep", "modes", "modes_at", "modes_over_mesh", "scene_torque"]


def _scene(scene: Any) -> Any:
    from ..scene import Scene

    if not isinstance(scene, Scene):
        raise ParameterError(f"scene must be an rvdyn.Scene (e.g. rvdyn.Scene.paper('rated')), got {type(scene).__name__}")
    return scene


def scene_torque(scene: Any) -> float:
    """The scene's constant output (load) torque [N m]; ``ParameterError`` if its load is not
    constant (then give ``torque=...``)."""
    load = _scene(scene).to_dict().get("load", {})
    if load.get("kind") == "constant":
        return float(load["torque"])
    if load.get("kind") == "idle":
        return 0.0
    raise ParameterError(f"the scene's load is {load.get('kind')!r}, not constant: give torque=... [N m]")


def _finite(name: str, value: Any, unit: str) -> float:
    try:
        v = float(value)
    except (OverflowError, TypeError, ValueError):
        raise ParameterError(f"{name} must be a number [{unit}], got {short(value)}") from None
    if not math.isfinite(v):
        raise ParameterError(f"{name} must be finite [{unit}], got {v}")
    return v


@dataclass
class Modes:
    """Modes about one equilibrium, lowest first (n coordinates = n modes).

    frequency [Hz]: undamped natural frequencies; damping_ratio: of the matched damped
    eigenvalue (``matched``; NaN otherwise, and ``modal_damping_ratio`` holds the modal
    estimate ``phi^T C phi / 2 w``, which :func:`rvdyn.campbell` uses for unmatched modes);
    damped_natural_frequency [Hz] (``|lambda| / 2 pi``), damped_frequency [Hz]
    (``Im lambda / 2 pi``, 0 when overdamped); shape (modes, coordinates): scaled so that the
    largest displacement at the coordinate's lever is +1; energy_share (modes, parts): share
    of the strain energy in each stiffness family (rows sum to 1); mass, stiffness, damping:
    the linearised matrices (SI: kg, kg m^2, N/m, N m/rad, N s/m ...). time [s]: the time of
    the dynamic state linearised about (0 for an equilibrium); with machine shafts the
    coordinates end with ``"sun angle"``, ``"load angle"``, ``"motor angle"`` and the parts
    with ``"shafts"``; about a moving state the last part is ``"rate-dependent"``. residual:
    the equilibrium's largest force residual relative to the load scale (NaN about a dynamic
    state, which is no equilibrium)."""

    torque: float
    crank_angle: float
    dof_names: list[str]
    part_names: list[str]
    frequency: np.ndarray
    damping_ratio: np.ndarray
    damped_natural_frequency: np.ndarray
    damped_frequency: np.ndarray
    modal_damping_ratio: np.ndarray
    mac: np.ndarray
    matched: np.ndarray
    shape: np.ndarray
    energy_share: np.ndarray
    dominant_dof: list[str]
    mass: np.ndarray
    stiffness: np.ndarray
    damping: np.ndarray
    eigenvalues: np.ndarray
    residual: float
    split_error: float
    stiffness_asymmetry: float
    extra: dict[str, Any] = field(default_factory=dict)
    time: float = 0.0

    @classmethod
    def _from_core(cls, d: dict[str, Any]) -> "Modes":
        names = list(d["dof_names"])
        return cls(
            torque=float(d["torque"]), crank_angle=float(d["crank_angle"]), dof_names=names,
            part_names=list(d["part_names"]), frequency=np.asarray(d["frequency"]),
            damping_ratio=np.asarray(d["damping_ratio"]),
            damped_natural_frequency=np.asarray(d["damped_natural_frequency"]),
            damped_frequency=np.asarray(d["damped_frequency"]),
            modal_damping_ratio=np.asarray(d["modal_damping_ratio"]), mac=np.asarray(d["mac"]),
            matched=np.asarray(d["matched"], dtype=bool), shape=np.asarray(d["shape"]),
            energy_share=np.asarray(d["energy_share"]), dominant_dof=[names[i] for i in d["dominant_dof"]],
            mass=np.asarray(d["mass"]), stiffness=np.asarray(d["stiffness"]), damping=np.asarray(d["damping"]),
            eigenvalues=np.array([complex(re, im) for re, im in d["eigenvalues"]]),
            residual=float(d["residual"]), split_error=float(d["split_error"]),
            stiffness_asymmetry=float(d["stiffness_asymmetry"]),
            extra={"equilibrium": list(d["equilibrium"]), "rigid_body": list(d["rigid_body"]),
                   "unstable": list(d["unstable"]), "shaft_angles": list(d["shaft_angles"])},
            time=float(d["time"]),
        )

    def __len__(self) -> int:
        return len(self.frequency)

    def where(self, mode: int) -> str:
        """Where mode ``mode`` (0-based) stores its strain energy: the parts above 10 %,
        largest first, e.g. ``"pin contacts 62 %, sun/planet meshes 38 %"``."""
        share = self.energy_share[mode]
        order = np.argsort(-share)
        parts = [f"{self.part_names[i]} {100 * share[i]:.0f} %" for i in order if share[i] >= 0.1]
        return ", ".join(parts) or "spread (no part above 10 %)"

    def table(self) -> list[dict[str, Any]]:
        """One row per mode: frequency [Hz], damping ratio, damped frequency [Hz], dominant
        coordinate, where the energy is, and the energy shares by part."""
        return [{"mode": i + 1, "frequency_hz": float(self.frequency[i]),
                 "damping_ratio": float(self.damping_ratio[i]),
                 "damped_frequency_hz": float(self.damped_frequency[i]),
                 "dominant_coordinate": self.dominant_dof[i], "energy": self.where(i),
                 "energy_share": {p: float(s) for p, s in zip(self.part_names, self.energy_share[i])}}
                for i in range(len(self))]

    def to_markdown(self) -> str:
        """The mode table as Markdown."""
        head = "| mode | f [Hz] | damping ratio | f_d [Hz] | dominant coordinate | strain energy |\n|---|---|---|---|---|---|"
        rows = [f"| {r['mode']} | {r['frequency_hz']:.1f} | {r['damping_ratio']:.3f} | "
                f"{r['damped_frequency_hz']:.1f} | {r['dominant_coordinate']} | {r['energy']} |" for r in self.table()]
        return "\n".join([head, *rows])

    def plot_energy(self, ax: Any = None) -> Any:
        """Stacked bars of the strain-energy shares per mode."""
        if ax is None:
            import matplotlib.pyplot as plt

            ax = plt.subplots(figsize=(max(6, 0.5 * len(self) + 3), 4))[1]
        x = np.arange(len(self))
        bottom = np.zeros(len(self))
        for j, name in enumerate(self.part_names):
            share = np.clip(self.energy_share[:, j], 0, None)
            ax.bar(x, share, bottom=bottom, label=name)
            bottom += share
        ax.set_xticks(x, [f"{f:.0f}" for f in self.frequency], rotation=60, fontsize=7)
        ax.set(xlabel="mode (natural frequency [Hz])", ylabel="share of strain energy", ylim=(0, 1.05),
               title=f"modes at {self.torque:.4g} N m, crank angle {self.crank_angle:.3g} rad")
        ax.legend(fontsize="small", loc="upper right")
        return ax

    def plot_shape(self, mode: int = 0, ax: Any = None) -> Any:
        """Bar chart of mode ``mode``'s shape over the named coordinates."""
        if ax is None:
            import matplotlib.pyplot as plt

            ax = plt.subplots(figsize=(max(6, 0.4 * len(self.dof_names) + 2), 3.5))[1]
        ax.bar(np.arange(len(self.dof_names)), self.shape[mode])
        ax.set_xticks(np.arange(len(self.dof_names)), self.dof_names, rotation=60, fontsize=7)
        ax.set(ylabel="shape (largest = 1 at its lever)",
               title=f"mode {mode + 1}: {self.frequency[mode]:.1f} Hz, damping ratio {self.damping_ratio[mode]:.3f}")
        return ax


def _loaded_torque(scene: Any, torque: float | None, what: str) -> float:
    """The torque [N m] of an equilibrium the modes are taken about: not zero."""
    t = scene_torque(scene) if torque is None else _finite("torque", torque, "N m")
    if t == 0.0:
        raise ParameterError(
            f"{what} about an equilibrium need a load: at 0 N m the contacts carry nothing and have no "
            "stiffness (a Hertz law's tangent is zero at zero load), so every frequency would be "
            "round-off; give a torque (e.g. the rated 43921.3 N m; --torque in rvdyn modes) or, for modes, "
            "state=(t, q, v) of a run")
    return t


def modes(scene: Any, torque: float | None = None, crank_angle: float = 0.0, *,
          state: tuple[float, Sequence[float], Sequence[float]] | None = None) -> Modes:
    """Modes of ``scene`` (rigid or compliant joints, with or without machine shafts) about
    its loaded quasi-static equilibrium at ``crank_angle`` [rad] under the output torque
    ``torque`` [N m] (default: the scene's constant load torque), input held (the motor with a
    drive shaft under a speed drive; free under a torque drive). With ``crank_shaft`` the
    eccentrics' bending deflections are condensed out (massless; the part ``"crank bending"``
    holds their strain energy; docs/model.md, "Modes with bending crankshafts"); such a scene
    needs eccentric bearings whose damping is proportional to their stiffness (rollers, or a
    linear bearing without clearance), else :class:`rvdyn.SceneError`.

    state: ``(t, q, v)`` of a dynamic run of this scene instead of an equilibrium: time [s],
    the model's free coordinates [rad, m] and velocities [rad/s, m/s] in the order of the run
    (``Result.stats["final_q"]``, see :func:`modes_at`); ``torque`` and ``crank_angle`` are
    then not used. The pose is taken as it is; the stiffness gains a ``"rate-dependent"`` part
    (the dynamic force's velocity terms), the damping matrix is taken at the state's speeds
    (docs/model.md, "Linearisation about a dynamic state").

    Raises :class:`rvdyn.ConvergenceError` when there is no equilibrium (a torque the contacts
    cannot carry), :class:`rvdyn.ParameterError` for non-finite input, a state of the wrong
    length or a zero-inertia body (naming its coordinate)."""
    scene = _scene(scene)
    if state is not None:
        try:
            t_s, q, v = state
        except (TypeError, ValueError):
            raise ParameterError("state must be a (t, q, v) triple") from None
        ms = Modes._from_core(_core.modes_state(scene.to_json(), _finite("state time", t_s, "s"),
                                                _as_list(q), _as_list(v)))
        unstable = int(sum(bool(u) for u in ms.extra["unstable"]))
        if unstable:
            # Off an equilibrium the tangent stiffness can be indefinite: such a mode grows.
            warnings.warn(
                f"modes: {unstable} of {len(ms)} modes are unstable about this state (the tangent "
                "stiffness is indefinite along them: the state is far from an equilibrium); their "
                "frequency is 0 and their damping ratio NaN, eigenvalues in .eigenvalues",
                RuntimeWarning, stacklevel=2)
        return ms
    t = _loaded_torque(scene, torque, "modes")
    psi = _finite("crank_angle", crank_angle, "rad")
    m = Modes._from_core(_core.modes(scene.to_json(), t, [psi])[0])
    floating = int(sum(bool(r) for r in m.extra["rigid_body"]))
    if floating and scene["drive.kind"] == "speed":
        # With the input held every body is tied down once the contacts are loaded.
        warnings.warn(
            f"modes: {floating} of {len(m)} modes have no stiffness at {t:.6g} N m (bodies floating in "
            "their clearances or contacts without load): their frequency is 0 and their damping "
            "ratio is NaN (not defined); a larger torque closes the clearances", RuntimeWarning, stacklevel=2)
    return m


def modes_at(result: Any, t: float | None = None) -> Modes:
    """Modes about the state of a dynamic run (:class:`rvdyn.Result` of :func:`rvdyn.simulate`)
    at its end (``t=None``, any joints) or at the recorded sample nearest to ``t`` [s] (rigid
    joints: their whole state is in the ``"motion"`` channels). A compliant model's crank
    centres and disc speeds are not recorded: for a time inside a compliant run, simulate to
    that time and take the end. See :func:`modes` (``state=``) for the method.

    Raises :class:`rvdyn.ParameterError` for a result without the end state (saved before it
    was kept), a time outside the run, or a compliant run with ``t``."""
    from ..result import Result
    from ..scene import Scene

    if not isinstance(result, Result):
        raise ParameterError(f"result must be an rvdyn.Result, got {type(result).__name__}")
    if not result.scene:
        raise ParameterError("the result carries no scene: modes_at needs the scene it was run with")
    scene = Scene(result.scene)
    stats = result.stats
    if t is None:
        if "final_q" not in stats:
            raise ParameterError("this result has no end state (stats['final_q']); run it again with this version")
        return modes(scene, state=(float(stats["final_time"]), stats["final_q"], stats["final_v"]))
    tt = _finite("t", t, "s")
    coords = _core.rigid_coordinates(scene.to_json())
    if coords is None:
        raise ParameterError("a compliant run records neither the crank centres nor the disc speeds: "
                             "simulate to t and call modes_at(result) for the end state")
    times = np.asarray(result.t)
    if not times[0] - 1e-12 <= tt <= times[-1] + 1e-12:
        raise ParameterError(f"t = {tt} s is outside the run [{times[0]}, {times[-1]}] s")
    try:
        ang = [result.carrier_angle, result.crank_angle[:, 0], result.sun_angle, result.load_angle,
               result.motor_angle]
        spd = [result.carrier_speed, result.crank_speed[:, 0], result.sun_speed, result.load_speed,
               result.motor_speed]
    except AttributeError:
        raise ParameterError('modes_at(result, t) needs the "motion" channels recorded') from None
    i = int(np.argmin(np.abs(times - tt)))
    q = [float(ang[c][i]) for c in coords]
    v = [float(spd[c][i]) for c in coords]
    return modes(scene, state=(float(times[i]), q, v))


@dataclass
class MeshSweep:
    """Modes over crank angle: ``crank_angle`` [rad] (k,), ``frequency`` [Hz] and
    ``damping_ratio`` (k, modes), with the coordinate and part names and the energy shares
    (k, modes, parts)."""

    torque: float
    crank_angle: np.ndarray
    frequency: np.ndarray
    damping_ratio: np.ndarray
    energy_share: np.ndarray
    part_names: list[str]
    period: float
    #: True when ``period`` is the default, one pin pitch ``2 pi / zp``.
    pin_pitch: bool = False

    def variation(self) -> np.ndarray:
        """Peak-to-peak of each mode's frequency over the sweep relative to its mean."""
        out: np.ndarray = np.ptp(self.frequency, axis=0) / self.frequency.mean(axis=0)
        return out

    def plot(self, ax: Any = None) -> Any:
        """Natural frequencies against the crank angle over the period (degrees)."""
        if ax is None:
            import matplotlib.pyplot as plt

            ax = plt.subplots(figsize=(8, 5))[1]
        deg = np.degrees(self.crank_angle)
        for m in range(self.frequency.shape[1]):
            ax.plot(deg, self.frequency[:, m], lw=1)
        span = (f"one pin pitch, {math.degrees(self.period):.2f} deg of crank" if self.pin_pitch
                else f"{math.degrees(self.period):.2f} deg of crank")
        ax.set(xlabel="crank angle [deg]", ylabel="natural frequency [Hz]", yscale="log",
               title=f"modes over {span}, {self.torque:.4g} N m")
        return ax


def modes_over_mesh(scene: Any, torque: float | None = None, points: int = 25,
                    period: float | None = None, start: float = 0.0) -> MeshSweep:
    """Modes at ``points`` crank angles over ``period`` [rad] of crank angle from ``start``
    [rad]. The default period is one pin pitch ``2 pi / zp``: the pin-force pattern of an
    error-free reducer repeats after it (docs/model.md "Excitation orders"). With ISO 6336
    meshes the tooth-mesh cycle (``2 pi zc / (zp z_planet)``, 8.2 deg of crank on the paper's
    reducer) is shorter, so a pin pitch covers its single- and double-tooth zones, but the whole
    pattern repeats only after the mesh period (``rvdyn.ltca(...).mesh_period``, 23/24 of a
    turn on the physical preset); with pin errors only after ``2 pi``. Give ``period`` to
    sweep either. Torque [N m] as in :func:`modes` (not zero: ``ParameterError``)."""
    scene = _scene(scene)
    t = _loaded_torque(scene, torque, "modes_over_mesh")
    points = whole("points", points, 2, MAX_MESH_POINTS)
    per = 2 * math.pi / int(scene["cycloid.pins"]) if period is None else _finite("period", period, "rad")
    if per <= 0:
        raise ParameterError(f"period must be > 0 rad, got {per}")
    psi = _finite("start", start, "rad") + per * np.arange(points) / points
    res = [Modes._from_core(d) for d in _core.modes(scene.to_json(), t, [float(p) for p in psi])]
    return MeshSweep(t, psi, np.array([r.frequency for r in res]), np.array([r.damping_ratio for r in res]),
                     np.array([r.energy_share for r in res]), res[0].part_names, per, period is None)


def _as_list(values: Sequence[float] | np.ndarray) -> list[float]:
    return [float(v) for v in np.asarray(values, dtype=float).ravel()]


# ---- command line: rvdyn modes ----------------------------------------------------------------


def add_cli_arguments(p: Any) -> None:
    """Arguments of ``rvdyn modes``."""
    p.add_argument("scene", nargs="?", default=None,
                   help="scene file (.json or .toml); default: the preset chosen by --preset at rated load")
    p.add_argument("--preset", choices=("physical", "paper"), default="physical",
                   help="preset used without a scene file (default physical: line-contact pins, ISO "
                   "6336 meshes, roller bearings; paper: the paper's IMPACT laws, rigid joints)")
    p.add_argument("--compliant", action="store_true",
                   help="use the default compliant joints (bearings) instead of the scene's joints")
    p.add_argument("--torque", type=float, default=None, metavar="NM",
                   help="output torque [N m] (default: the scene's load torque)")
    p.add_argument("--crank-angle", type=float, default=0.0, metavar="RAD", help="crank angle [rad] (default 0)")
    p.add_argument("--power", type=float, default=None, metavar="W",
                   help="Campbell diagram at constant power [W] (default: constant torque)")
    p.add_argument("--speeds", type=float, nargs=2, default=None, metavar=("LO", "HI"),
                   help="input speed range [deg/s] of the Campbell diagram (default: the paper's "
                   "travel range 3.3-5.5 km/h at the scene's ratio, 8328-13880 deg/s at 57)")
    p.add_argument("--points", type=int, default=200, help="speeds in the Campbell diagram (default 200)")
    p.add_argument("--harmonics", type=int, default=8,
                   help="pin-pass and sun-mesh harmonics in the Campbell diagram (default 8: the ISO "
                   "mesh stiffness is a rectangular wave with strong higher harmonics)")
    from ..cli import _folder

    p.add_argument("--out", default="rvdyn-out", metavar="DIR", type=_folder,
                   help="output folder (default rvdyn-out)")


def run_cli(args: Any) -> int:
    """``rvdyn modes``: mode table, energy distribution, modes over a mesh period, Campbell
    diagram, summary (Markdown and JSON) in ``--out``."""
    import json
    import os

    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from ..scene import Scene
    from .campbell import campbell

    if args.scene is not None:
        scene = Scene.load(args.scene)
    else:
        scene = Scene.physical("rated") if args.preset == "physical" else Scene.paper("rated")
    if args.compliant:
        scene = scene.with_compliant_joints()
    os.makedirs(args.out, exist_ok=True)
    m = modes(scene, args.torque, args.crank_angle)
    sweep = modes_over_mesh(scene, m.torque, points=25, start=args.crank_angle)
    if args.speeds is not None and not (np.all(np.isfinite(args.speeds)) and 0 < args.speeds[0] < args.speeds[1]):
        raise ParameterError(f"--speeds LO HI must be finite input speeds in deg/s with 0 < LO < HI, "
                             f"got {args.speeds[0]} {args.speeds[1]}")
    speeds = None if args.speeds is None else np.radians(np.linspace(args.speeds[0], args.speeds[1], args.points))
    cd = campbell(scene, speeds, power=args.power, torque=None if args.power is not None else m.torque,
                  crank_angle=args.crank_angle, harmonics=args.harmonics, points=args.points)
    written = []

    def save(fig: Any, name: str) -> None:
        path = os.path.join(args.out, name)
        fig.tight_layout()
        fig.savefig(path, dpi=120)
        plt.close(fig)
        written.append(path)

    ax = m.plot_energy()
    save(ax.figure, "modes_energy.png")
    ax = sweep.plot()
    save(ax.figure, "modes_pin_pitch.png")
    ax = cd.plot()
    save(ax.figure, "campbell.png")
    crossings = cd.table()
    summary = {
        "scene": scene.to_dict().get("name", ""), "joints": scene.to_dict()["joints"]["kind"],
        "torque_N_m": m.torque, "crank_angle_rad": m.crank_angle, "coordinates": m.dof_names,
        "stiffness_parts": m.part_names, "modes": m.table(),
        "pin_pitch_variation": {f"mode {i + 1}": float(v) for i, v in enumerate(sweep.variation())},
        "campbell": {"input_speed_range_rad_s": [float(cd.speeds[0]), float(cd.speeds[-1])],
                     "power_W": args.power, "crossings": crossings},
        "equilibrium_residual": m.residual, "stiffness_split_error": m.split_error,
        "stiffness_asymmetry": m.stiffness_asymmetry,
    }
    path = os.path.join(args.out, "modes.json")
    with open(path, "w", encoding="utf-8") as f:
        json.dump(summary, f, indent=2)
    written.append(path)
    lines = [f"# Modes of {summary['scene'] or 'the scene'} ({summary['joints']} joints)", "",
             f"Output torque {m.torque:.6g} N m, crank angle {m.crank_angle:.4g} rad; {len(m)} coordinates "
             f"= {len(m)} modes. Equilibrium residual {m.residual:.2e}; stiffness asymmetry "
             f"{m.stiffness_asymmetry:.1e}.", "", "## Mode table", "", m.to_markdown(), "",
             f"## Over one pin pitch ({math.degrees(sweep.period):.2f} deg of crank)", "",
             "| mode | peak-to-peak / mean of f |", "|---|---|",
             *[f"| {i + 1} | {100 * v:.2f} % |" for i, v in enumerate(sweep.variation())], "",
             "## Campbell crossings", "",
             f"Input speeds {math.degrees(cd.speeds[0]):.0f}-{math.degrees(cd.speeds[-1]):.0f} deg/s "
             + (f"at constant power {args.power:g} W." if args.power is not None else f"at {m.torque:.6g} N m."), ""]
    if crossings:
        lines += ["| input speed [deg/s] | travel [km/h] | f [Hz] | order | mode | damping ratio |",
                  "|---|---|---|---|---|---|"]
        lines += [f"| {r['input_speed_deg_s']:.0f} | {r['travel_speed_kmh']:.2f} | {r['frequency_hz']:.1f} | "
                  f"{r['order']} | {r['mode']} | {r['damping_ratio']:.3f} |" for r in crossings]
    else:
        lines.append("No excitation order crosses a natural frequency in this speed range.")
    path = os.path.join(args.out, "modes.md")
    with open(path, "w", encoding="utf-8") as f:
        f.write("\n".join(lines) + "\n")
    written.append(path)
    print(m.to_markdown())
    print(f"{len(crossings)} Campbell crossing(s) in the speed range")
    for p in written:
        print(f"wrote {p}")
    return 0
