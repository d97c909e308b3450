"""Loaded tooth contact analysis and what follows from it (see :mod:`rvdyn.analysis`)."""

from __future__ import annotations

import math
import warnings
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any, Callable, Sequence

import numpy as np

from .. import _core
from ..errors import ConvergenceError, ParameterError
from .._args import read_only, short
from .._args import whole as _whole
from ..scene import Scene

if TYPE_CHECKING:  # pragma: no cover
    from ..bearing import CrankLayout
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure

__all__ = ["ARCMIN", "ARCSEC", "LtcaResult", "TeHarmonic", "TransmissionError", "TwistLoop", "ltca", "running_friction",
           "torque_twist", "tooth_mesh_angles", "transmission_error"]

#: One arc minute and one arc second [rad].
ARCMIN: float = math.pi / (180.0 * 60.0)
ARCSEC: float = math.pi / (180.0 * 3600.0)
#: Hertz peak pressure [Pa] above which the LTCA warns: 4000 MPa, the contact stress of the
#: static load rating of roller bearings (ISO 76), where steel begins to deform permanently.
ELASTIC_PRESSURE_LIMIT: float = 4.0e9
#: The most crank angles per period or loop points one analysis takes (the core's limit).
MAX_POINTS: int = 10_000_000


def _scene(scene: object) -> Scene:
    if not isinstance(scene, Scene):
        raise ParameterError(
            f"scene must be an rvdyn.Scene (e.g. rvdyn.Scene.paper('rated')), got {type(scene).__name__}")
    return scene


def _float(name: str, value: object, unit: str) -> float:
    try:
        x = float(value)  # type: ignore[arg-type]
    except (OverflowError, TypeError, ValueError):
        raise ParameterError(f"{name} must be a number [{unit}], got {short(value)}") from None
    if not math.isfinite(x):
        raise ParameterError(f"{name} must be a finite number [{unit}], got {x}")
    return x


def _rated(scene: Scene, torque: float | None) -> float:
    if torque is not None:
        return _float("torque", torque, "N m")
    load = scene["load"]
    if isinstance(load, dict) and load.get("kind") == "constant":
        return float(load["torque"])
    raise ParameterError("give the torque [N m] (--torque in rvdyn analyze): the scene's load is not a constant torque")


@dataclass(frozen=True)
class LtcaResult:
    """Static equilibria at a set of crank angles under one output torque.

    Arrays (SI): ``crank_angle`` (n,) [rad]; ``output_angle``, ``input_angle``,
    ``transmission_error`` (output minus input/ratio), ``input_torque`` (n,) [rad, rad, rad,
    N m]; per disc and pin ``pin_force``, ``pin_gap``, ``half_width``, ``peak_pressure``
    (n, discs, pins) [N, m, m, Pa]; ``contact_point``, ``contact_normal`` (n, discs, pins, 2)
    in the disc frame [m, -]; ``loaded_pins`` (n, discs); ``disc_rotation`` (n, discs) [rad]
    from the kinematic angle; ``disc_angle`` (n, discs) [rad], each disc's angle in the fixed
    frame (the rotation from the disc frame to the fixed frame);
    ``disc_displacement`` (n, discs, 2) [m], fixed frame; ``mesh_force`` (n, cranks) [N];
    ``crank_bearing_force`` (n, cranks, 2) and ``eccentric_bearing_force`` (n, cranks, discs, 2)
    [N], fixed frame as in a dynamic run (rotate by ``-disc_angle`` to apply them to a disc mesh
    with the pin loads; empty for rigid joints); ``crank_deflection`` (n, cranks, discs, 2) [m],
    fixed frame: each eccentric's bending deflection from its crank's line (a scene with
    ``crank_shaft``; empty otherwise); ``torque_balance``, ``residual`` (n,) relative
    (to the torque and the load scale; near the smallest torque an equilibrium resolves they are
    set by the round-off of the contact forces, about 1e-5 at 1e-3 N m on the paper scene);
    ``iterations`` (n,); ``torsional_stiffness`` (n,) [N m/rad]. ``scene``: the analysed scene
    as a dict (:meth:`rvdyn.Scene.to_dict`; None for a result built by hand), whose bearing
    ratings :meth:`bearing_safety` reads.
    """

    torque: float
    mesh_period: float
    ratio: float
    face_width: float
    arrays: dict[str, np.ndarray] = field(repr=False)
    fea_csv: str = field(repr=False)
    fea_json: str = field(repr=False)
    scene: dict[str, Any] | None = field(default=None, repr=False)

    def __post_init__(self) -> None:
        object.__setattr__(self, "arrays", {k: read_only(np.asarray(v)) for k, v in self.arrays.items()})

    def __getattr__(self, name: str) -> np.ndarray:
        arrays = object.__getattribute__(self, "arrays")
        if name in arrays:
            value: np.ndarray = arrays[name]
            return value
        raise AttributeError(name)

    @property
    def peak_pin_force(self) -> float:
        """Largest pin force over all crank angles and discs [N]."""
        return float(np.max(self.arrays["pin_force"])) if self.arrays["pin_force"].size else 0.0

    def summary(self) -> dict[str, Any]:
        """Peak pin force [N], loaded pins per disc (min, max), the peak-to-peak of the TE at
        these crank angles [rad] (of the samples: ``transmission_error`` locates the extremes
        between them), worst torque balance and residual."""
        a = self.arrays
        return {
            "torque_Nm": self.torque,
            "crank_angles": int(a["crank_angle"].size),
            "peak_pin_force_N": self.peak_pin_force,
            "loaded_pins_min": int(a["loaded_pins"].min()),
            "loaded_pins_max": int(a["loaded_pins"].max()),
            "te_peak_to_peak_samples_rad": float(np.ptp(a["transmission_error"])),
            "torque_balance_max": float(a["torque_balance"].max()),
            "residual_max": float(a["residual"].max()),
            "peak_pressure_max_Pa": float(a["peak_pressure"].max()),
        }

    def crank_bending_stress(self) -> np.ndarray:
        """The largest nominal bending stress in each crankshaft [Pa], shape (n, cranks): the
        shaft of the scene's ``crank_shaft`` on its two bearings (``crank_layout``, simple
        supports) under the forces on its eccentrics (minus ``eccentric_bearing_force``),
        ``sigma = 32 |M| / (pi d^3)`` at the worst plane (the bending moment is largest at a
        load or a support; docs/model.md, "Crankshaft bending"). Nominal: no notch factor, no
        shear, no planet force. ``ParameterError`` without ``crank_shaft``."""
        from ..bearing import crank_bending_stress

        return crank_bending_stress(self.scene or {}, self.arrays["eccentric_bearing_force"],
                                    "crank_bending_stress")

    def bearing_safety(self, crank_layout: CrankLayout | None = None) -> dict[str, dict[str, float]]:
        """ISO 76 static safety of the most loaded bearing of each family over these crank
        angles: ``peak_load`` [N], the ``crank_angle`` [rad] where it occurs, the static rating
        ``static_rating`` ``C0r`` [N] and ``static_safety`` ``s0 = C0r / peak_load`` (a
        ``RuntimeWarning`` below 1: the raceways yield there, and the elastic roller law and
        the forces no longer hold). Families ``"eccentric"`` and ``"crank"``; with
        ``crank_layout`` (:class:`rvdyn.CrankLayout`, axial positions [m]; default the scene's
        ``crank_layout`` where it has one and its crank bearing has rollers) ``"crank"`` is
        replaced by the crank's two bearings ``"crank_a"`` and ``"crank_b"``
        (:func:`rvdyn.crank_bearing_rows`, exact here: no inertia force), each rated with
        rollers of ``crank_layout.roller_length`` (default half the lumped length). The rating
        life needs the duty cycle: :meth:`rvdyn.Result.bearing_life` gives it for a run.

        ``ParameterError`` if the result carries no scene, its joints are rigid (no bearing
        forces) or none of its bearings is built from rollers (no ``C0r``); a family without
        rollers is left out.

        >>> import rvdyn
        >>> lt = rvdyn.ltca(rvdyn.Scene.physical("rated"), crank_angles=[0.0])
        >>> s = lt.bearing_safety()
        >>> sorted(s), round(s["crank"]["static_safety"], 2) > 1
        (['crank', 'eccentric'], True)
        """
        from ..bearing import static_safety

        families = self._bearing_families(crank_layout)
        out: dict[str, dict[str, float]] = {}
        for name, _, static, forces in families:
            if static is None:
                continue
            mag = np.linalg.norm(forces, axis=-1)
            at = np.unravel_index(int(np.argmax(mag)), mag.shape)
            peak = float(mag[at])
            s0 = static_safety("bearing_safety", name, peak, static,
                               "use larger bearings (joints.*.rollers) or a lower torque")
            out[name] = {"peak_load": peak, "crank_angle": float(self.arrays["crank_angle"][at[0]]),
                         "static_rating": float(static), "static_safety": s0}
        return out

    def bearing_life(self, speed: float | None = None,
                     crank_layout: CrankLayout | None = None) -> dict[str, dict[str, float]]:
        """ISO 281 rating life of the bearings at this torque, from the quasi-static loads over
        the crank angles: the same entries as :meth:`rvdyn.Result.bearing_life` (peak and
        equivalent load, ratings, static safety, ``L10`` in million revolutions and hours, and
        with a crank layout ``crank_a``, ``crank_b`` and ``crank_pair``), for steady running at
        the input ``speed`` [rad/s, magnitude 1e-9 to 1e9] (default: the scene's constant drive
        speed).

        Each crank angle stands for an equal share of the rings' revolutions (the rings turn
        relative to each other by ``zp/zc`` of the crank angle, docs/model.md "Crank bearing
        rows"), so the crank angles must be equally spaced over whole mesh periods (the
        default grid of :func:`rvdyn.ltca`): ``ParameterError`` otherwise. With roller
        bearings the periods differ a little (the roller sets stay in the frame); more periods
        give the exact cycle. Inertia is left out (a run includes it); the refusals of
        :meth:`bearing_safety` apply.

        >>> import rvdyn
        >>> life = rvdyn.ltca(rvdyn.Scene.physical("rated")).bearing_life()  # 90 angles over the period
        >>> sorted(life), round(life["eccentric"]["l10_hours"], 1)  # at 8328 deg/s and 43.9 kN m
        (['crank', 'eccentric'], 18.6)
        """
        from ..bearing import Family, rate_lives

        families = self._bearing_families(crank_layout)  # its refusals first (no scene, rigid joints)
        psi = np.asarray(self.arrays["crank_angle"], dtype=float)
        n = psi.size
        step = (psi[-1] - psi[0]) / (n - 1) if n > 1 else 0.0
        periods = n * step / self.mesh_period if step > 0 else 0.0
        if (n < 2 or not np.allclose(np.diff(psi), step, rtol=1e-9, atol=0.0)
                or abs(periods - round(periods)) > 1e-6 or round(periods) < 1):
            raise ParameterError(
                f"bearing_life needs crank angles equally spaced over whole mesh periods ({self.mesh_period:.6g} "
                f"rad each), as rvdyn.ltca(scene, torque) gives (90 over one); got {n} angle(s) covering "
                f"{periods:.4g} period(s)")
        if speed is None:
            drive = (self.scene or {}).get("drive", {})
            if drive.get("kind") != "speed":
                raise ParameterError("the scene is not driven at a constant speed: give speed [rad/s]")
            speed = float(drive["speed"])
        try:
            omega = abs(float(speed))
        except (TypeError, ValueError, OverflowError) as exc:
            raise ParameterError(f"speed must be the input speed in rad/s, got {speed!r}") from exc
        # Beyond these the hours leave the floats (1e-9 rad/s: a revolution in 200 years).
        if not (1e-9 <= omega <= 1e9):
            raise ParameterError(f"speed must be an input speed from 1e-9 to 1e9 rad/s in magnitude, got {speed!r}")
        zp = int(self.scene["cycloid"]["pins"])  # type: ignore[index]
        ring_turn = float(step) * zp / (zp - 1) / (2 * math.pi)  # ring revolutions per crank angle step
        # The input turns with the crank angle as the held input's kinematics say.
        inputs = np.asarray(self.arrays["input_angle"], dtype=float)
        input_per_psi = abs(float(inputs[-1] - inputs[0])) / float(psi[-1] - psi[0])
        duration = float(n * step * input_per_psi / omega)  # [s] for the cycle at this speed
        rated: list[Family] = []
        for name, rating, static, forces in families:
            mag = np.linalg.norm(forces, axis=-1)
            rated.append((name, rating, static, float(mag.max()), mag, np.full(mag.shape, ring_turn)))
        return rate_lives("bearing_life", rated, duration)

    def _bearing_families(
            self, crank_layout: CrankLayout | None) -> list[tuple[str, float | None, float | None, np.ndarray]]:
        """Each bearing family's name, ISO 281 rating ``C`` and ISO 76 static rating ``C0r`` [N]
        (None without rollers) and forces (n, ..., 2) [N], as :meth:`bearing_safety` describes
        them; its refusals."""
        if self.scene is None:
            raise ParameterError("this LtcaResult carries no scene, so no bearing rating: take it from rvdyn.ltca")
        crank_force = self.arrays["crank_bearing_force"]
        ecc_force = self.arrays["eccentric_bearing_force"]
        if crank_force.size == 0:
            raise ParameterError("the scene's joints are rigid, so the LTCA has no bearing forces: give "
                                 "compliant joints with rollers (joints.*.rollers), as Scene.physical has")
        from ..bearing import families

        return families(self.scene, crank_force, ecc_force, crank_layout)

    def plot_bearing_loads(self, crank_layout: CrankLayout | None = None, ax: Axes | None = None) -> Figure:
        """The load [kN] of the most loaded bearing of each family (:meth:`bearing_safety`'s
        families and ``crank_layout``) at each crank angle, with the family's ISO 76 static
        rating ``C0r`` as a dashed line of the same colour (black for a rating shared by several
        families, as the crank's two rows): where a curve crosses its line, the static safety
        ``s0`` is below 1. Same refusals as :meth:`bearing_safety`.

        >>> import rvdyn
        >>> lt = rvdyn.ltca(rvdyn.Scene.physical("rated"), crank_angles=[0.0, 0.05, 0.1])
        >>> fig = lt.plot_bearing_loads()
        >>> [line.get_label() for line in fig.axes[0].get_lines()]
        ['eccentric', 'crank', 'eccentric C0r', 'crank C0r']
        """
        from ..bearing import plot_family_loads

        families = [(name, static, forces) for name, _, static, forces in self._bearing_families(crank_layout)
                    if static is not None]
        fig: Figure = plot_family_loads(ax, np.degrees(self.arrays["crank_angle"]), families, "crank angle [deg]",
                                        f"bearing loads and ISO 76 static ratings, T = {self.torque / 1e3:.2f} kN m")
        return fig

    def worst_index(self, disc: int = 0) -> int:
        """Index of the crank angle with the largest pin force on ``disc``."""
        return int(np.argmax(self.arrays["pin_force"][:, disc, :].max(axis=1)))

    def save_fea_loads(self, folder: str | Path) -> tuple[Path, Path]:
        """Write ``fea_loads.csv`` and ``fea_loads.json`` (format: docs/model.md, "Loads for
        FEA") into ``folder``; returns their paths."""
        out = Path(folder)
        out.mkdir(parents=True, exist_ok=True)
        csv_path, json_path = out / "fea_loads.csv", out / "fea_loads.json"
        csv_path.write_text(self.fea_csv)
        json_path.write_text(self.fea_json)
        return csv_path, json_path

    def plot_load_distribution(self, index: int | None = None, polar: bool = True,
                               ax: Axes | None = None) -> Figure:
        """Pin forces of both discs at crank angle ``index`` (default: the worst one), polar
        (pin positions around the ring) or as bars."""
        from ..plotting import new_figure

        i = self.worst_index() if index is None else int(index)
        f = self.arrays["pin_force"][i]
        nd, zp = f.shape
        if ax is None:
            if polar:
                from matplotlib.figure import Figure

                fig = Figure(figsize=(6.5, 6.5), layout="constrained")
                ax = fig.add_subplot(projection="polar")
            else:
                fig, ax = new_figure((8.0, 4.5))
        else:
            fig = ax.figure  # type: ignore[assignment]
        theta = 2.0 * np.pi * np.arange(zp) / zp
        for k in range(nd):
            if polar:
                ax.plot(np.append(theta, theta[0]), np.append(f[k], f[k][0]) / 1e3, marker="o",
                        label=f"disc {k}")
            else:
                w = 0.8 / nd
                ax.bar(np.arange(1, zp + 1) + (k - (nd - 1) / 2) * w, f[k] / 1e3, width=w,
                       label=f"disc {k}")
        if not polar:
            ax.set_xlabel("pin (the paper's numbering)")
            ax.set_ylabel("pin force [kN]")
        ax.set_title(f"pin forces [kN], crank angle {math.degrees(self.arrays['crank_angle'][i]):.2f} deg, "
                     f"T = {self.torque / 1e3:.2f} kN m")
        ax.legend()
        return fig

    def plot_contact_pressure(self, ax: Axes | None = None) -> Figure:
        """Largest Hertz peak pressure of each pin over the crank angles [MPa], per disc."""
        from ..plotting import new_figure

        fig, ax = new_figure((8.0, 4.5)) if ax is None else (ax.figure, ax)
        p = self.arrays["peak_pressure"].max(axis=0) / 1e6
        for k in range(p.shape[0]):
            ax.plot(np.arange(1, p.shape[1] + 1), p[k], marker="o", label=f"disc {k}")
        ax.set_xlabel("pin (the paper's numbering)")
        ax.set_ylabel("Hertz peak pressure, max over crank angles [MPa]")
        ax.set_title(f"contact pressure, T = {self.torque / 1e3:.2f} kN m")
        ax.legend()
        return fig  # type: ignore[return-value]


@dataclass(frozen=True)
class TeHarmonic:
    """One harmonic of a TE curve over its mesh period: ``harmonic`` k (cycles per period),
    ``order`` (cycles per input revolution), ``amplitude`` [rad] and ``phase`` [rad] of
    ``amplitude cos(2 pi k (psi - start) / period + phase)``, and the ``label`` of the scene's
    excitation order it falls on (``""`` if none; :func:`rvdyn.analysis.spectrum.excitation_orders`)."""

    harmonic: int
    order: float
    amplitude: float
    phase: float
    label: str
    #: ``2 |X_k - X'_k|`` [rad], ``X'`` from every second sample: how much the coefficient moves
    #: when the grid is halved, an estimate of its aliasing error (larger than the error for a
    #: coefficient that converges; NaN for ``k >= N/4`` or an odd ``N``, where none is made).
    uncertainty: float = float("nan")


@dataclass(frozen=True, repr=False)
class TransmissionError:
    """TE over ``periods`` whole mesh periods (by default the ``window`` after which the whole
    TE repeats), forward (+torque) and reverse (-torque), loaded and at a light load
    (unloaded) [rad]; ``crank_angle`` [rad], ``period`` (the mesh period) [rad]. The arrays
    ``crank_angle``, ``forward``, ``reverse``, ``unloaded_forward`` and ``unloaded_reverse`` all
    have shape ``(n,)``, one value per crank angle.
    ``extremes[curve]`` holds each curve's largest and smallest TE located between the crank
    angles: ``max``, ``min`` [rad] at ``max_angle``, ``min_angle`` [rad]; ``refined[curve]``
    is false where the equilibria depend on the path (a very light load), and the extremes are
    then the samples' (docs/model.md, "Transmission error"). ``window`` [rad] is the crank
    angle after which the whole TE repeats: ``period``, or with roller bearings (whose roller
    sets stay fixed in the frame) a multiple of it, over which the TE differs from period to
    period by the roller-pass ripple (docs/model.md, "Mesh period")."""

    crank_angle: np.ndarray
    period: float
    forward: np.ndarray
    reverse: np.ndarray
    unloaded_forward: np.ndarray
    unloaded_reverse: np.ndarray
    torque: float
    light: float
    extremes: dict[str, dict[str, float]]
    refined: dict[str, bool]
    window: float
    #: Mesh periods covered [-].
    periods: int = 1
    #: Input revolutions over the ``periods`` covered [-] (the order of harmonic k is k over this).
    input_turns: float = float("nan")
    #: The scene's excitation orders as (order, label), for the harmonics' labels.
    excitation: tuple[tuple[float, str], ...] = field(default=(), repr=False)

    def __post_init__(self) -> None:
        for name in ("crank_angle", "forward", "reverse", "unloaded_forward", "unloaded_reverse"):
            object.__setattr__(self, name, read_only(np.asarray(getattr(self, name), dtype=float)))

    def harmonics(self, curve: str = "forward", count: int = 8) -> list[TeHarmonic]:
        """The ``count`` largest harmonics of ``curve`` (``"forward"``, ``"reverse"``,
        ``"unloaded_forward"``, ``"unloaded_reverse"``) over the ``periods`` covered, largest
        first.

        The discrete Fourier transform of the samples, which cover whole mesh periods with the
        endpoint excluded (periodic when they cover the ``window``): ``X_k = (1/N) sum_j TE_j exp(-2 pi i j k / N)``, amplitude ``2 |X_k|``
        (``|X_k|`` at ``k = N/2``) and phase ``arg X_k``, for ``1 <= k <= N/2``; exact for a
        curve with no harmonics above ``N/2`` (docs/model.md, "Transmission error harmonics").
        ``harmonic`` counts cycles over the whole span (``periods`` mesh periods), not per
        period. A ``RuntimeWarning`` says when the pin-pass or sun-mesh fundamental lies at or
        beyond ``N/2``.
        Harmonics above ``N/2`` fold onto lower ones: refine ``points`` until the amplitudes
        you read stop changing. The order of harmonic k is ``k / input_turns`` per input
        revolution; a harmonic within 1e-9 of an excitation order of the scene (pin pass, sun
        mesh and their harmonics, the shafts' rotations) carries its label. ``uncertainty``
        estimates each amplitude's aliasing error from the same transform of every second
        sample."""
        names = ("forward", "reverse", "unloaded_forward", "unloaded_reverse")
        if curve not in names:
            raise ParameterError(f"curve must be one of {names}, got {curve!r}")
        if not (isinstance(count, (int, np.integer)) and not isinstance(count, bool) and count >= 1):
            raise ParameterError(f"count must be a whole number >= 1, got {count!r}")
        y = np.asarray(getattr(self, curve), dtype=float)
        n = y.size
        if n < 2:
            raise ParameterError(f"the {curve} curve has {n} samples: it was not computed (unloaded curves "
                                 "need a light load) or the grid is too short for a harmonic")
        x = np.fft.rfft(y) / n
        # The same coefficients from every second sample (valid below their Nyquist, N/4).
        half = np.fft.rfft(y[::2]) / (n // 2) if n % 2 == 0 and n >= 8 else np.zeros(0, complex)
        k = np.arange(1, x.size)
        amp = 2.0 * np.abs(x[1:])
        if n % 2 == 0:
            amp[-1] *= 0.5  # the Nyquist bin has no mirror
        # An excitation at or above the Nyquist bin cannot be read from these samples (at two
        # angles per tooth-mesh cycle the sun mesh falls on it and read 0.03 of its 0.96 arcsec).
        lost = {lab: oo * self.input_turns for oo, lab in self.excitation
                if lab in ("sun mesh", "pin pass") and oo * self.input_turns >= n / 2 - 1e-9}
        if lost:
            need = math.floor(2 * max(lost.values()) / self.periods) + 1
            warnings.warn(
                f"TransmissionError.harmonics: {n} samples resolve harmonics below {n // 2} over the "
                f"span; the {' and '.join(lost)} fundamental lies at or beyond it and is not read "
                f"correctly: use at least {need} points per period", RuntimeWarning, stacklevel=2)
        order = np.argsort(-amp, kind="stable")[: int(count)]
        out = []
        for i in order:
            h = int(k[i])
            o = h / self.input_turns
            label = next((lab for oo, lab in self.excitation if abs(oo - o) <= 1e-9 * max(abs(oo), 1.0)), "")
            unc = 2.0 * float(abs(x[h] - half[h])) if 4 * h < n and h < half.size else float("nan")
            out.append(TeHarmonic(harmonic=h, order=float(o), amplitude=float(amp[i]),
                                  phase=float(np.angle(x[h])), label=label, uncertainty=unc))
        return out

    def peak_to_peak(self) -> dict[str, float]:
        """Peak-to-peak of each curve [rad]: its refined largest minus smallest TE (at least
        the samples' own peak-to-peak)."""
        return {k: float(e["max"] - e["min"]) for k, e in self.extremes.items()}

    def __repr__(self) -> str:
        # The figures an engineer reads, not the arrays.
        pp = ", ".join(f"{k} {v / ARCSEC:.4g}" for k, v in self.peak_to_peak().items())
        return (f"TransmissionError(points={self.crank_angle.size}, periods={self.periods}, "
                f"period={self.period:.6g} rad, "
                f"torque={self.torque:.6g} N m, peak_to_peak_arcsec={{{pp}}}, window={self.window:.6g} rad)")

    def lost_motion(self) -> np.ndarray:
        """Difference of the reverse and forward TE at each crank angle [rad]: the twist width
        between the TE's two torques, ``+-torque`` (on the paper preset at rated load about 12.8
        arcmin). This is not the catalogue lost motion, the width at +-3 % of the rated torque
        (about 1.26 arcmin there): that is :attr:`TwistLoop.lost_motion` of
        :func:`torque_twist`."""
        diff: np.ndarray = self.reverse - self.forward
        return diff

    def plot(self, ax: Axes | None = None) -> Figure:
        """TE in arcsec about its mean, both directions, loaded and unloaded, with each curve's
        extremes (dots). Several mesh periods are drawn over one another against the crank
        angle within the period (the TE ripples tens of times per period: the whole window
        side by side would be a solid band), so that the spread between periods shows."""
        from ..plotting import new_figure

        fig, ax = new_figure((8.0, 4.5)) if ax is None else (ax.figure, ax)
        n = self.crank_angle.size // max(self.periods, 1)
        start = float(self.crank_angle[0]) if self.crank_angle.size else 0.0

        def phase(angle: np.ndarray) -> np.ndarray:
            return np.degrees(start + np.mod(np.asarray(angle) - start, self.period))

        for name, style in (("forward", "-"), ("reverse", "-"), ("unloaded_forward", "--"),
                            ("unloaded_reverse", "--")):
            y = getattr(self, name)
            if y.size == 0:
                continue
            rows = (y - y.mean()).reshape(-1, n) / ARCSEC
            x = np.degrees(self.crank_angle[:n])
            label = f"{name.replace('_', ' ')} (mean {y.mean() / ARCMIN:+.2f} arcmin)"
            (line,) = ax.plot(x, rows[0], style, lw=1.0 if self.periods == 1 else 0.6, label=label)
            for row in rows[1:]:
                ax.plot(x, row, style, lw=0.6, color=line.get_color(), alpha=0.5)
            # The extremes located between the crank angles (the peak-to-peak's ends).
            e = self.extremes[name]
            ax.plot(phase(np.array([e["max_angle"], e["min_angle"]])),
                    (np.array([e["max"], e["min"]]) - y.mean()) / ARCSEC, "o",
                    color=line.get_color(), markersize=4)
        ax.set_xlabel("crank angle [deg] (" + ("one mesh period" if self.periods == 1 else
                                               f"within the mesh period; {self.periods} periods overlaid") + ")")
        ax.set_ylabel("TE about its mean [arcsec]")
        ax.set_title(f"transmission error, T = +-{self.torque / 1e3:.2f} kN m")
        ax.legend(fontsize="small")
        return fig  # type: ignore[return-value]


@dataclass(frozen=True, repr=False)
class TwistLoop:
    """The torque-twist loop at one crank angle: ``torque`` [N m], ``twist`` [rad] (positive
    with positive torque), ``tangent_stiffness`` [N m/rad], each of shape ``(points,)`` in the
    loop's order; catalogue ``rigidity`` [N m/rad], ``lost_motion`` and ``backlash`` [rad]
    (docs/model.md, "Torque-twist loop"); ``crank_angle`` [rad], ``rated_torque`` [N m]."""

    crank_angle: float
    rated_torque: float
    torque: np.ndarray
    twist: np.ndarray
    tangent_stiffness: np.ndarray
    rigidity: float
    lost_motion: float
    backlash: float
    friction: bool = False

    def __post_init__(self) -> None:
        for name in ("torque", "twist", "tangent_stiffness"):
            object.__setattr__(self, name, read_only(np.asarray(getattr(self, name), dtype=float)))

    def branches(self) -> tuple[tuple[np.ndarray, np.ndarray], tuple[np.ndarray, np.ndarray]]:
        """The loop's upper (unloading, ``+rated -> -rated``) and lower (loading, ``-rated ->
        +rated``: the last quarter, then the first) branches as ``(torque, twist)`` pairs with
        increasing torque: torque [N m] and twist [rad], each of shape ``(m,)`` (about half the
        loop's points). Without friction both are the same curve."""
        n = self.torque.size
        i_max = int(np.argmax(self.torque))
        i_min = int(np.argmin(self.torque))
        up_t, up_w = self.torque[i_max:i_min + 1][::-1], self.twist[i_max:i_min + 1][::-1]
        lo_t = np.concatenate([self.torque[i_min:n], self.torque[1:i_max + 1]])
        lo_w = np.concatenate([self.twist[i_min:n], self.twist[1:i_max + 1]])
        return (up_t, up_w), (lo_t, lo_w)

    def width(self, torque: float) -> float:
        """Twist width of the loop [rad] at ``torque`` [N m] (upper minus lower branch,
        linear interpolation between the loop's points); the friction's hysteresis."""
        (ut, uw), (lt, lw) = self.branches()
        t = float(torque)
        if not (np.isfinite(t) and abs(t) <= self.rated_torque):
            raise ParameterError(f"torque must be within +-rated ({self.rated_torque} N m), got {torque}")
        return float(np.interp(t, ut, uw) - np.interp(t, lt, lw))

    def summary(self) -> dict[str, float]:
        """Rigidity [N m/arcmin], lost motion and backlash [arcmin]."""
        return {
            "rigidity_Nm_per_arcmin": self.rigidity * ARCMIN,
            "lost_motion_arcmin": self.lost_motion / ARCMIN,
            "backlash_arcmin": self.backlash / ARCMIN,
        }

    def __repr__(self) -> str:
        s = self.summary()
        return (f"TwistLoop(crank_angle={self.crank_angle:.6g} rad, rated_torque={self.rated_torque:.6g} N m, "
                f"points={self.torque.size}, rigidity={s['rigidity_Nm_per_arcmin']:.6g} N m/arcmin, "
                f"lost_motion={s['lost_motion_arcmin']:.4g} arcmin, backlash={s['backlash_arcmin']:.4g} arcmin, "
                f"friction={self.friction})")

    def plot(self, ax: Axes | None = None) -> Figure:
        """The hysteresis loop: twist [arcmin] against torque [kN m]."""
        from ..plotting import new_figure

        fig, ax = new_figure((6.5, 5.0)) if ax is None else (ax.figure, ax)
        ax.plot(self.twist / ARCMIN, self.torque / 1e3, marker=".")
        ax.axhline(0.0, color="0.7", lw=0.8)
        ax.axvline(0.0, color="0.7", lw=0.8)
        s = self.summary()
        ax.set_xlabel("output twist [arcmin]")
        ax.set_ylabel("output torque [kN m]")
        # Two lines: on one the backlash and its unit ran past a 6.5 in figure.
        ax.set_title(f"torque-twist: rigidity {s['rigidity_Nm_per_arcmin']:.0f} N m/arcmin\n"
                     f"lost motion {s['lost_motion_arcmin']:.3f} arcmin, backlash {s['backlash_arcmin']:.3f} arcmin",
                     fontsize="medium")
        return fig  # type: ignore[return-value]


def ltca(scene: Scene, torque: float | None = None, crank_angles: Sequence[float] | np.ndarray | None = None,
         *, tolerance: float = 1e-12, progress: Callable[[int, int], None] | None = None,
         chunk: int = 360) -> LtcaResult:
    """Loaded tooth contact analysis of ``scene`` under the output ``torque`` [N m] (default:
    the scene's constant load) at ``crank_angles`` [rad] (default: 90 angles over one mesh
    period), each equilibrium warm-started from the previous. Runs of at least 300 angles
    (per ``chunk``) are solved as parallel chains of at least 150 consecutive angles, each
    later chain started from the kinematic pose (docs/model.md, "Long sweeps in parallel
    chains"): the results do not depend on the number of threads.

    ``tolerance``: Newton's residual target, a fraction of the load scale (``|T| / rp``), in
    (0, 1e-6]; the balance of every body closes to 1e-9 at the default 1e-12.
    ``chunk``: crank angles solved per call into the core (a whole number >= 1, default 360);
    ``progress(done, total)`` is called after each chunk with the angles solved so far and
    their total (e.g. for a progress bar); the results do not depend on ``chunk``.

    The equilibria are frictionless whatever the scene's ``friction``: friction enters
    :func:`torque_twist` (by default) and :func:`running_friction`.

    Raises ``ConvergenceError`` (naming the crank angle and residual) when no equilibrium is
    found, ``ParameterError`` for non-finite input or a tolerance outside its range.
    """
    sc = _scene(scene)
    t = _rated(sc, torque)
    if crank_angles is None:
        period = float(_core.LtcaSolver(sc._compiled, 1e-12).mesh_period)
        angles = period * np.arange(90) / 90.0
    elif isinstance(crank_angles, (int, np.integer)):
        # `ltca(scene, T, 360)` reads as "360 angles" (transmission_error takes a count there)
        # but would be the single angle 360 rad.
        raise ParameterError(
            f"crank_angles = {crank_angles!r} is a whole number, not a list of angles: ltca takes crank "
            "angles [rad], not a count; for n angles over the mesh period pass "
            "np.arange(n) * period / n (period: LtcaResult.mesh_period of a default run), or omit "
            "crank_angles for 90 of them; for one angle pass a float in a list, e.g. [0.0]")
    else:
        try:
            angles = np.atleast_1d(np.asarray(crank_angles, dtype=float))
        except (OverflowError, TypeError, ValueError) as e:
            raise ParameterError(f"crank_angles must be real numbers [rad]: {e}") from e
    if angles.ndim != 1 or angles.size == 0:
        raise ParameterError(f"crank_angles must be a non-empty 1-D array [rad], got shape {angles.shape}")
    if not np.all(np.isfinite(angles)):
        raise ParameterError("crank_angles must be finite numbers [rad]")
    tol = _float("tolerance", tolerance, "-")
    solver = _core.LtcaSolver(sc._compiled, tol)
    parts: list[dict[str, np.ndarray]] = []
    step = _whole("chunk", chunk, 1, MAX_POINTS)
    for start in range(0, angles.size, step):
        # The solver keeps its warm start and its points across chunks.
        parts.append(solver.sweep(t, angles[start:start + step].tolist()))
        if progress is not None:
            progress(min(start + step, angles.size), angles.size)
    arrays = {k: np.concatenate([p[k] for p in parts]) for k in parts[0]}
    peak = float(arrays["peak_pressure"].max())
    if peak > ELASTIC_PRESSURE_LIMIT:
        warnings.warn(
            f"ltca: the peak Hertz pressure {peak / 1e9:.2f} GPa exceeds {ELASTIC_PRESSURE_LIMIT / 1e9:.1f} GPa, "
            "the contact stress at which ISO 76 sets the static load rating of roller bearings "
            "(permanent deformation of about 1e-4 of the roller diameter): the elastic contact laws "
            "no longer describe these contacts; lower the torque or enlarge the contacts",
            RuntimeWarning, stacklevel=2)
    fea_csv, fea_json = solver.fea_loads()
    return LtcaResult(torque=t, mesh_period=float(solver.mesh_period), ratio=float(solver.ratio),
                      face_width=float(solver.face_width), arrays=arrays, fea_csv=fea_csv,
                      fea_json=fea_json, scene=sc.to_dict())


def tooth_mesh_angles(scene: Scene) -> int:
    """The number of crank angles per mesh period (an int) that places two in every tooth-mesh
    cycle of an ISO 6336 mesh (whose stiffness steps between one and two tooth pairs once per
    base pitch, passed every ``2 pi zc / (z_planet zp)`` of crank angle with the input held;
    docs/model.md, "Transmission error"); 2 for mesh laws that do not vary along the path of
    contact."""
    sc = _scene(scene)
    return _tooth_mesh_angles(sc, float(_core.LtcaSolver(sc._compiled, 1e-12).mesh_period))


def _tooth_mesh_angles(sc: Scene, period: float) -> int:
    """:func:`tooth_mesh_angles` of a checked scene with its mesh period [rad] known."""
    d = sc.to_dict()
    stage = d.get("stage1")
    # The ISO law's stiffness and tooth friction (any law) vary along the path of contact.
    if stage is None or (d["contact"]["mesh"]["kind"] != "iso6336" and not d["friction"]["mesh"] > 0):
        return 2
    zp = int(d["cycloid"]["pins"])
    cycle = 2.0 * math.pi * (zp - 1) / (int(stage["z_planet"]) * zp)
    return max(2, math.ceil(2.0 * period / cycle - 1e-9))


def _input_turns(sc: Scene, period: float, ratio: float) -> float:
    """Input revolutions over ``period`` [rad] of crank angle: the held input turns by
    ``i / zc`` per crank angle with a first stage, else it is the crank (docs/model.md)."""
    d = sc.to_dict()
    zc = int(d["cycloid"]["pins"]) - 1
    per_crank = abs(ratio) / zc if d.get("stage1") is not None else 1.0
    return period * per_crank / (2.0 * math.pi)


def _window_periods(window: float, period: float) -> int:
    """Whole mesh periods in the TE ``window`` [rad] (a whole number by construction)."""
    return max(1, round(window / period))


def _excitation(sc: Scene) -> tuple[tuple[float, str], ...]:
    from .spectrum import excitation_orders

    return tuple((o.order, o.label) for o in excitation_orders(sc, 6))


def transmission_error(scene: Scene, torque: float | None = None, points: int | None = None, *,
                       light: float | None = None, start: float = 0.0, window: bool = True) -> TransmissionError:
    """TE at ``points`` crank angles per mesh period, at ``+-torque`` and at the light load
    ``+-light`` [N m] (default ``1e-6 torque``, at least 1e-3 N m) from crank angle ``start`` [rad], over the
    ``window`` after which the whole TE repeats (``window=False``: one mesh period). By
    default ``points`` is 90, or eight per tooth-mesh cycle of an ISO 6336 mesh if that is
    more (``4 tooth_mesh_angles(scene)``: 336 on the physical preset, whose TE ripples 42
    times per period). Each curve's extremes are located between the crank angles of each
    period (``extremes``).

    With roller bearings, whose roller sets stay fixed in the frame, the TE repeats only
    after several mesh periods (twelve on the physical preset: ``window``) and differs from
    period to period; one period alone can show a peak-to-peak far from the whole curve's (the
    physical preset's unloaded TE: 0.086 arcsec over the first period, 0.205 over the window).
    The cost grows with the periods covered (about 1.5 s on the physical preset, 0.14 s for one
    period)."""
    sc = _scene(scene)
    if not isinstance(window, bool):
        raise ParameterError(f"window must be True (the whole window) or False (one mesh period), got {window!r}")
    solver = _core.LtcaSolver(sc._compiled, 1e-12)
    period = float(solver.mesh_period)
    needed = _tooth_mesh_angles(sc, period)
    points = max(90, 4 * needed) if points is None else _whole("points", points, 2, MAX_POINTS)
    t = abs(_rated(sc, torque))
    # The light load: 1e-6 of the torque, but not below 1e-3 N m (the torque-twist loop's zero
    # points), where a floating body settles reliably above the forces' round-off.
    lt = max(1e-6 * t, min(1e-3, 0.01 * t)) if light is None else abs(_float("light", light, "N m"))
    if not 0.0 < lt < t:
        raise ParameterError(f"light must be a load between 0 and the torque {t:.6g} N m (the unloaded TE's "
                             f"light load; default 1e-6 of the torque, at least 1e-3 N m), got {lt:.6g} N m")
    periods = _window_periods(float(solver.te_window), period) if window else 1
    try:
        d = solver.transmission_error(t, lt, int(points), _float("start", start, "rad"), False, periods)
    except ConvergenceError as exc:
        import re

        m = re.search(r"output torque (-?[0-9.eE+-]+) N m", str(exc))
        if m is None or not math.isclose(abs(float(m.group(1))), lt, rel_tol=1e-5):
            raise
        # The unloaded curves' light load, not the torque given: say so, and what to change.
        raise ConvergenceError(
            f"the unloaded TE, at the light load {lt:.3g} N m (`light`), found no equilibrium: at "
            f"such a load bodies can float in their bearing clearances. Give a larger `light` "
            f"(`rvdyn analyze --light`), e.g. {max(10 * lt, 1.0):g} N m. ({exc})") from exc
    te = TransmissionError(crank_angle=d["crank_angle"], period=float(d["period"]),
                           forward=d["forward"], reverse=d["reverse"],
                           unloaded_forward=d["unloaded_forward"],
                           unloaded_reverse=d["unloaded_reverse"], torque=t, light=lt,
                           extremes={k: {q: float(e[q]) for q in ("max_angle", "max", "min_angle", "min")}
                                     for k, e in d["extremes"].items()},
                           refined={k: bool(e["refined"]) for k, e in d["extremes"].items()},
                           window=float(solver.te_window), periods=int(d["periods"]),
                           input_turns=_input_turns(sc, float(d["period"]) * int(d["periods"]),
                                                    float(solver.ratio)),
                           excitation=_excitation(sc))
    if int(points) < needed:
        warnings.warn(
            f"transmission_error: {int(points)} crank angles per mesh period are fewer than two "
            f"per tooth-mesh cycle of the ISO 6336 mesh, so a TE peak can lie where no angle's "
            f"neighbourhood is searched; use points >= {needed}", RuntimeWarning, stacklevel=2)
    path_dependent = [k for k, ok in te.refined.items() if not ok]
    if path_dependent:
        warnings.warn(
            f"transmission_error: the equilibria of {', '.join(path_dependent)} depend on the "
            f"path to them (bodies floating in their clearances; light load {lt:.3g} N m), so "
            "their peak-to-peak is the samples' (not located between them) and depends on the "
            "sweep; a larger load (`light` for the unloaded curves) makes them unique",
            RuntimeWarning, stacklevel=2)
    return te


def torque_twist(scene: Scene, rated_torque: float | None = None, crank_angle: float = 0.0,
                 points: int = 201, *, friction: bool = True) -> TwistLoop:
    """The torque-twist loop 0 -> +rated -> -rated -> 0 at ``crank_angle`` [rad] with the input
    held, with rigidity, lost motion and backlash (catalogue definitions). With the scene's
    friction (``scene.friction``; ``friction=False`` ignores it) the loop opens: quasi-static
    Coulomb sliding at pins, teeth and joint bearings, sticking at each reversal
    (docs/model.md, "Friction in the LTCA")."""
    sc = _scene(scene)
    t = abs(_rated(sc, rated_torque))
    n = _whole("points", points, 8, MAX_POINTS)
    d = _core.LtcaSolver(sc._compiled, 1e-12).twist_loop(t, _float("crank_angle", crank_angle, "rad"),
                                                         n, bool(friction))
    if not (math.isfinite(float(d["rigidity"])) and float(d["rigidity"]) > 0.0):
        raise ParameterError(
            f"the rated torque {t:.6g} N m twists the reducer by no more than round-off (rigidity "
            f"{float(d['rigidity'])!r}): give a torque the contacts deflect under, e.g. the scene's rated torque")
    return TwistLoop(crank_angle=float(crank_angle), rated_torque=t, torque=d["torque"],
                     twist=d["twist"], tangent_stiffness=d["tangent_stiffness"],
                     rigidity=float(d["rigidity"]), lost_motion=float(d["lost_motion"]),
                     backlash=float(d["backlash"]), friction=bool(d["friction"]))


def running_friction(scene: Scene, torque: float | None = None, points: int | None = None, *,
                     start: float = 0.0, window: bool = False) -> dict[str, np.ndarray | float]:
    """Quasi-static running sweeps with the scene's friction at ``points`` crank angles per
    mesh period (default: 24, or eight per tooth-mesh cycle of an ISO 6336 mesh or of tooth
    friction if that is more: the tooth sliding reverses at the pitch point, and two per cycle
    fold its harmonics onto the mean, 0.9169-0.9233 with the start angle on the physical preset
    at mu 0.05 against 0.9211-0.9213 at eight),
    over one mesh period from ``start`` [rad] or (``window=True``) over the whole window after
    which everything repeats (``TransmissionError.window``): every contact slides as in the
    running reducer, the input driving against ``+torque`` (forward) and ``-torque``
    (reverse) [N m]. Returns a dict of ``crank_angle`` [rad], TE ``forward`` / ``reverse``
    [rad], the held input's torque ``input_forward`` / ``input_reverse`` [N m] (arrays of
    shape ``(n,)``, one value per crank angle) and the quasi-static ``efficiency_forward`` /
    ``efficiency_reverse`` [-] (floats) of each direction: the input work of the frictionless reducer over the same
    sweep divided by that with friction, ``mean(T_in,0) / mean(T_in)`` (docs/model.md, "Friction
    in the LTCA"). The frictionless sweep's work is the output work up to the elastic energy's
    change and the quadrature of the input torque's steps at the ISO mesh's zone changes; both
    cancel in the quotient (1 without friction; the physical preset at mu 0.05 gives 0.9213 at
    the default 336 angles, where ``T / (i mean(T_in))`` gave 0.904-0.924 over 24-336).
    Fewer than two angles per tooth-mesh cycle warn; a zero torque is a ``ParameterError``."""
    sc = _scene(scene)
    t = abs(_rated(sc, torque))
    if t == 0.0:
        # Both input works are round-off then: their quotient was any number (1.013 seen).
        raise ParameterError("running_friction needs a torque: at 0 N m no work flows through the "
                             "reducer and the efficiency is undefined; give the torque [N m]")
    solver = _core.LtcaSolver(sc._compiled, 1e-12)
    period = float(solver.mesh_period)
    needed = _tooth_mesh_angles(sc, period)
    n = max(24, 4 * needed) if points is None else _whole("points", points, 1, MAX_POINTS)
    if not isinstance(window, bool):
        raise ParameterError(f"window must be True or False, got {window!r}")
    periods = _window_periods(float(solver.te_window), period) if window else 1
    angles = _float("start", start, "rad") + period * np.arange(n * periods) / n
    fwd = solver.friction_sweep(t, angles.tolist())
    rev = solver.friction_sweep(-t, angles.tolist())
    # The frictionless input torques at the same angles (each sweep on its own solver: a solver
    # keeps its points for the FEA export).
    free = [_core.LtcaSolver(sc._compiled, 1e-12).sweep(s, angles.tolist())["input_torque"] for s in (t, -t)]
    if n < needed:
        warnings.warn(
            f"running_friction: {n} crank angles per mesh period are fewer than two per tooth-mesh "
            f"cycle (along which the ISO mesh stiffness or the tooth friction changes), so the "
            f"input torque is sampled unevenly; use points >= {needed}", RuntimeWarning, stacklevel=2)
    return {"crank_angle": angles, "forward": fwd["transmission_error"],
            "reverse": rev["transmission_error"], "input_forward": fwd["input_torque"],
            "input_reverse": rev["input_torque"],
            "efficiency_forward": float(np.mean(free[0]) / np.mean(fwd["input_torque"])),
            "efficiency_reverse": float(np.mean(free[1]) / np.mean(rev["input_torque"]))}
