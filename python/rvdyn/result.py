"""Results of a dynamic run: numpy arrays (first axis = time), summaries, plots, ``.npz`` files.

Every recorded channel is declared once, in Rust (``rvdyn._core.channels()``: name, group,
shape, unit, dtype, doc); :class:`Result` exposes each as a typed attribute built from that
registry.
"""

from __future__ import annotations

import json
import math
import warnings
import zipfile
from pathlib import Path
from typing import TYPE_CHECKING, Any, Generic, Iterable, TypeVar, overload

import numpy as np
from numpy.typing import NDArray

from . import _core
from .errors import ParameterError, RvdynError
from ._args import read_only
from .bearing import Family, rate_lives
from ._args import real as _real
from ._args import whole as _whole
from .plotting import pin_indices

if TYPE_CHECKING:
    from .bearing import CrankLayout

__all__ = ["Result", "CHANNELS", "CHANNEL_SPECS"]

#: The channel registry of the core: name -> {name, group, shape, unit, dtype, doc}.
CHANNEL_SPECS: dict[str, dict[str, Any]] = {c["name"]: dict(c) for c in _core.channels()}


def _describe(spec: dict[str, Any]) -> str:
    shape = ", ".join(("n",) + tuple(spec["shape"]))
    return f"{spec['doc']} [{spec['unit']}], ({shape})"


#: Channel name -> meaning, unit and shape (n = samples).
CHANNELS: dict[str, str] = {name: _describe(spec) for name, spec in CHANNEL_SPECS.items()}

#: The share of the loss ``W_in - W_out`` over an efficiency window above which the energy
#: residual's change over the window makes :meth:`Result.efficiency` warn (sound runs: about
#: 1e-6 of it; generalized-alpha at ``rho_inf`` 0.8 with contact damping 1e8 N s/m: 1.0).
EFFICIENCY_BALANCE_SHARE = 0.01
#: ... and the share of the input work below which the residual's change is not reported.
EFFICIENCY_BALANCE_FLOOR = 1e-4

_T = TypeVar("_T", bound=np.generic)


class _Channel(Generic[_T]):
    """A recorded channel of :class:`Result` (a read-only numpy array, first axis = time)."""

    def __set_name__(self, owner: type, name: str) -> None:
        spec = CHANNEL_SPECS.get(name)
        if spec is None:
            raise RuntimeError(f"Result.{name} is not in the core's channel registry")
        self.name = name
        self.spec = spec
        self.__doc__ = CHANNELS[name]

    @overload
    def __get__(self, obj: None, owner: type | None = None) -> _Channel[_T]: ...
    @overload
    def __get__(self, obj: Result, owner: type | None = None) -> NDArray[_T]: ...
    def __get__(self, obj: Result | None, owner: type | None = None) -> _Channel[_T] | NDArray[_T]:
        if obj is None:
            return self
        arrays = obj._arrays
        if self.name in arrays:
            return arrays[self.name]
        if obj.error is not None:
            raise AttributeError(f"channel {self.name!r} is missing: the run failed ({obj.error})")
        raise AttributeError(
            f"channel {self.name!r} was not recorded: ask for it with channels=[{self.spec['group']!r}, ...]"
        )


class Result:
    """Recorded channels of one run.

    Each channel (see :data:`CHANNELS`) that was recorded is an attribute holding a numpy array
    whose first axis is time; ``stats`` holds the integrator statistics (integer counts: steps,
    evaluations, ...; ``dt`` [s] or None for an adaptive run; ``wall_time`` [s]); ``scene`` the
    scene as a dict; ``options`` the options the run actually used (integrator, dt, atol, ...,
    ``t_end``; ``point`` for a sweep). A run of :func:`rvdyn.sweep` that failed has ``ok``
    False and its exception in ``error``.
    """

    t: _Channel[np.float64] = _Channel()
    sun_angle: _Channel[np.float64] = _Channel()
    sun_speed: _Channel[np.float64] = _Channel()
    carrier_angle: _Channel[np.float64] = _Channel()
    carrier_speed: _Channel[np.float64] = _Channel()
    crank_angle: _Channel[np.float64] = _Channel()
    crank_speed: _Channel[np.float64] = _Channel()
    disc_center: _Channel[np.float64] = _Channel()
    disc_angle: _Channel[np.float64] = _Channel()
    load_angle: _Channel[np.float64] = _Channel()
    load_speed: _Channel[np.float64] = _Channel()
    motor_angle: _Channel[np.float64] = _Channel()
    motor_speed: _Channel[np.float64] = _Channel()
    pin_force: _Channel[np.float64] = _Channel()
    pin_penetration: _Channel[np.float64] = _Channel()
    pin_moment: _Channel[np.float64] = _Channel()
    loaded_pins: _Channel[np.int64] = _Channel()
    pin_point: _Channel[np.float64] = _Channel()
    pin_normal: _Channel[np.float64] = _Channel()
    mesh_force: _Channel[np.float64] = _Channel()
    mesh_deflection: _Channel[np.float64] = _Channel()
    input_torque: _Channel[np.float64] = _Channel()
    output_shaft_torque: _Channel[np.float64] = _Channel()
    input_shaft_torque: _Channel[np.float64] = _Channel()
    kinetic_energy: _Channel[np.float64] = _Channel()
    potential_energy: _Channel[np.float64] = _Channel()
    input_work: _Channel[np.float64] = _Channel()
    output_work: _Channel[np.float64] = _Channel()
    dissipated_energy: _Channel[np.float64] = _Channel()
    energy_residual: _Channel[np.float64] = _Channel()
    pin_friction_power: _Channel[np.float64] = _Channel()
    mesh_friction_power: _Channel[np.float64] = _Channel()
    bearing_friction_power: _Channel[np.float64] = _Channel()
    crank_bearing_force: _Channel[np.float64] = _Channel()
    eccentric_bearing_force: _Channel[np.float64] = _Channel()
    crank_deflection: _Channel[np.float64] = _Channel()

    def __init__(self, arrays: dict[str, NDArray[Any]], stats: dict[str, Any], scene: dict[str, Any] | None = None,
                 options: dict[str, Any] | None = None, error: RvdynError | None = None):
        unknown = set(arrays) - set(CHANNEL_SPECS)
        if unknown:
            raise ParameterError(f"unknown channels {sorted(unknown)}: the channels are {sorted(CHANNEL_SPECS)}")
        self._arrays: dict[str, NDArray[Any]] = {k: read_only(np.asarray(v)) for k, v in arrays.items()}
        self.stats: dict[str, Any] = dict(stats)
        self.scene: dict[str, Any] = scene or {}
        self.options: dict[str, Any] = options or {}
        self.error: RvdynError | None = error

    @classmethod
    def failed(cls, error: RvdynError, scene: dict[str, Any] | None = None,
               options: dict[str, Any] | None = None) -> Result:
        """The entry of a run that raised ``error`` (``ok`` False, no channels)."""
        return cls({}, {}, scene, options, error)

    @property
    def ok(self) -> bool:
        """Whether the run finished (False: see ``error``)."""
        return self.error is None

    @property
    def success(self) -> bool:
        """The same as ``ok`` (the name ``scipy.integrate.solve_ivp``'s result uses)."""
        return self.error is None

    @property
    def message(self) -> str:
        """Why the run ended, in words: that it reached its end time, or the exception's class
        and text (``solve_ivp``'s ``message``)."""
        if self.error is not None:
            return f"{type(self.error).__name__}: {self.error}"
        t = self._arrays.get("t")
        end = f" t = {float(t[-1]):.6g} s" if t is not None and len(t) else ""
        return f"the run reached its end time{end}"

    @property
    def channels(self) -> list[str]:
        """Names of the recorded arrays."""
        return sorted(self._arrays)

    def __repr__(self) -> str:
        if self.error is not None:
            return f"Result(failed: {type(self.error).__name__}: {self.error})"
        n = len(self._arrays.get("t", []))
        return f"Result({n} samples, t_end={float(self._arrays['t'][-1]) if n else 0:.4g} s, channels={self.channels})"

    # ----------------------------------------------------------------- analysis
    def _steady_start(self, t_start: float | None) -> float:
        t = self.t
        t0 = float(t[-1] * 0.2) if t_start is None else _real("t_start [s]", t_start)
        if not (t[0] <= t0 < t[-1]):
            raise ParameterError(f"t_start = {t0:.6g} s must lie inside the run [{t[0]:.6g}, {t[-1]:.6g}) s")
        return t0

    def _disc(self, disc: Any) -> int:
        """A disc index checked against the recorded discs."""
        return _whole("disc", disc, 0, int(self.disc_center.shape[1]) - 1)

    def steady_window(self, t_start: float | None = None) -> tuple[float, float]:
        """The largest window ``[t0, t_end]`` with ``t0 >= t_start`` spanning whole crank
        revolutions relative to the carrier (whole mesh cycles: every pin is back in its
        place). ``t_start`` defaults to 20 % of the run. Times in s."""
        t = self.t
        rel = self.crank_angle[:, 0] - self.carrier_angle
        t0 = self._steady_start(t_start)
        i0 = int(np.searchsorted(t, t0))
        span = abs(rel[-1] - rel[i0])
        turns = math.floor(span / (2 * math.pi))
        if turns < 1:
            raise ParameterError(
                f"the window from {t0:.3g} s holds less than one crank revolution; run longer or start earlier"
            )
        # Remaining crank rotation until the end: decreases to 0 in a running reducer. Find the
        # sample interval holding the target, then refine on the cubic Hermite interpolant of
        # the angle (angles and speeds are both recorded), which is O(dt^4) accurate.
        rel_speed = self.crank_speed[:, 0] - self.carrier_speed
        remaining = np.abs(rel[i0:] - rel[-1])
        target = turns * 2 * math.pi
        k = i0 + int(np.nonzero(remaining >= target)[0][-1])
        sign = math.copysign(1.0, rel[-1] - rel[i0])
        lo, hi = float(t[k]), float(t[min(k + 1, len(t) - 1)])

        def f(x: float) -> float:
            return float(sign * (rel[-1] - _hermite(x, t, rel, rel_speed)) - target)

        for _ in range(60):
            mid = 0.5 * (lo + hi)
            if f(mid) >= 0:
                lo = mid
            else:
                hi = mid
        t_window = 0.5 * (lo + hi)
        return t_window, float(t[-1])

    def spectrum(self, channel: str, window: tuple[float, float] | None = None, **options: Any) -> Any:
        """Order spectrum of ``channel`` over ``window`` [s] with peaks labelled by the excitation
        orders: :func:`rvdyn.order_spectrum` (options as there)."""
        from .analysis.spectrum import order_spectrum

        return order_spectrum(self, channel, window, **options)

    def mean_output_speed(self, t_start: float | None = None) -> float:
        """Mean carrier speed [rad/s] over whole crank revolutions after ``t_start`` [s]:
        (angle change) / (time), exact for the recorded angles, no averaging of samples."""
        t0, t1 = self.steady_window(t_start)
        a0 = _hermite(t0, self.t, self.carrier_angle, self.carrier_speed)
        return (float(self.carrier_angle[-1]) - a0) / (t1 - t0)

    def disc_path_radius(self, t_start: float | None = None) -> np.ndarray:
        """(min, mean, max) distance of each disc centre from the reducer axis [m] after
        ``t_start``, shape (discs, 3)."""
        i0 = int(np.searchsorted(self.t, self._steady_start(t_start)))
        r = np.linalg.norm(self.disc_center[i0:], axis=-1)
        return np.stack([r.min(axis=0), r.mean(axis=0), r.max(axis=0)], axis=-1)

    def loaded_pin_stats(self, t_start: float | None = None) -> np.ndarray:
        """(min, mean, max) number of loaded pins per disc after ``t_start``, shape (discs, 3)."""
        i0 = int(np.searchsorted(self.t, self._steady_start(t_start)))
        n = self.loaded_pins[i0:]
        return np.stack([n.min(axis=0), n.mean(axis=0), n.max(axis=0)], axis=-1)

    def largest_moment_pin(self, time: float, disc: int = 0) -> int:
        """The paper's number (1-based) of the pin with the largest |moment| on ``disc`` at the
        sample nearest ``time`` [s] (inside the run)."""
        t = self.t
        time = _real("time [s]", time)
        if not (t[0] <= time <= t[-1]):
            raise ParameterError(f"time = {time:.6g} s must lie inside the run [{t[0]:.6g}, {t[-1]:.6g}] s")
        disc = self._disc(disc)
        i = int(np.argmin(np.abs(t - time)))
        return int(np.argmax(np.abs(self.pin_moment[i, disc]))) + 1

    def energy_balance(self) -> dict[str, float]:
        """Final input work, output work, dissipation, energy change and the residual [J],
        plus the residual relative to the largest of them and of the energy stored at any
        sample (kinetic plus elastic): a run at constant speed exchanges only round-off, which
        is small against what it stores (0 when nothing moved and nothing is stored)."""
        w_in = float(self.input_work[-1])
        w_out = float(self.output_work[-1])
        diss = float(self.dissipated_energy[-1])
        change = float(self.kinetic_energy[-1] + self.potential_energy[-1] - self.kinetic_energy[0] - self.potential_energy[0])
        res = float(self.energy_residual[-1])
        stored = float(np.max(np.abs(self.kinetic_energy + self.potential_energy)))
        scale = max(abs(w_in), abs(w_out), abs(diss), abs(change), stored)
        return {"input_work": w_in, "output_work": w_out, "dissipated": diss, "energy_change": change,
                "residual": res, "relative_residual": abs(res) / scale if scale > 0 else 0.0}

    def efficiency(self, t_start: float | None = None) -> float:
        """Efficiency over the window from ``t_start`` [s] (default: 20 % of the run) to the
        end: the work delivered over the work put in, output over input when the input drives
        (``input_work`` > 0), input over output when the load drives the input (back-driving,
        both works negative; before, that returned 1.08 for a reducer losing 8 %). Over whole
        crank revolutions (:meth:`steady_window`) the mesh cycles' ripple cancels. Needs the
        ``"energy"`` channels; ``ParameterError`` when no work flows or power flows out at both
        ends. A ``RuntimeWarning`` when the energy balance over the window is off by more than
        1 % of the loss (and 1e-4 of the work): the integrator's error then shows in the
        efficiency (``docs/model.md``, "Efficiency and the energy balance")."""
        i0 = int(np.searchsorted(self.t, self._steady_start(t_start)))
        w_in = float(self.input_work[-1] - self.input_work[i0])
        w_out = float(self.output_work[-1] - self.output_work[i0])
        if w_in == 0.0 or w_out == 0.0:
            raise ParameterError("no work flows through the reducer in the window: efficiency undefined")
        if (w_in > 0.0) == (w_out > 0.0):
            self._check_window_balance(i0, w_in, w_out)
        if w_in > 0.0 and w_out > 0.0:
            return w_out / w_in
        if w_in < 0.0 and w_out < 0.0:
            return w_in / w_out
        raise ParameterError(f"the reducer takes work at both ends (input {w_in:.4g} J, output {w_out:.4g} J "
                             "in the window, e.g. while it speeds up): efficiency undefined")

    def _check_window_balance(self, i0: int, w_in: float, w_out: float) -> None:
        # The residual E - E0 - W_in + W_out + D over the window bounds the integrator's error in
        # the loss W_in - W_out: 1e-6 of it in sound runs, the whole loss when a loose
        # integrator meets heavy damping (docs/model.md, "Efficiency and the energy balance").
        drift = abs(float(self.energy_residual[-1] - self.energy_residual[i0]))
        loss = abs(w_in - w_out)
        if drift > EFFICIENCY_BALANCE_SHARE * loss and drift > EFFICIENCY_BALANCE_FLOOR * abs(w_in):
            warnings.warn(
                f"efficiency: the energy balance over the window is off by {drift:.4g} J, "
                f"{100 * drift / max(loss, 1e-300):.3g} % of the loss ({loss:.4g} J), so the efficiency is "
                f"uncertain by about {drift / abs(w_in):.2g}: the integrator does not resolve the scene's "
                "velocity-dependent forces (heavy contact damping, a small friction.regularisation_speed); "
                "with generalized-alpha use rho_inf=0 or a smaller dt, or use integrator=\"dopri5\"",
                RuntimeWarning, stacklevel=3)

    def friction_power_means(self, t_start: float | None = None) -> dict[str, float]:
        """Mean friction power [W] per family (pins, teeth, bearings) from ``t_start`` [s]."""
        i0 = int(np.searchsorted(self.t, self._steady_start(t_start)))
        return {name: float(np.mean(getattr(self, f"{name}_friction_power")[i0:]))
                for name in ("pin", "mesh", "bearing")}

    def crank_bending_stress(self) -> np.ndarray:
        """The largest nominal bending stress in each crankshaft [Pa], shape (n, cranks), for a
        scene with ``crank_shaft``: the shaft on its two bearings under the recorded
        ``eccentric_bearing_force`` (the ``bearings`` channel), ``32 |M| / (pi d^3)`` at the
        worst plane, as :meth:`rvdyn.analysis.LtcaResult.crank_bending_stress`. The eccentrics'
        own inertia force (their mass times their acceleration, next to the bearing force) is
        left out. ``ParameterError`` without ``crank_shaft`` or the ``bearings`` channel."""
        from .bearing import crank_bending_stress

        if "eccentric_bearing_force" not in self._arrays:
            raise ParameterError("crank_bending_stress needs the bearings channel: "
                                 "simulate(..., channels=[..., \"bearings\"])")
        return crank_bending_stress(self.scene, self.eccentric_bearing_force, "crank_bending_stress")

    def bearing_life(self, t_start: float | None = None,
                     crank_layout: CrankLayout | None = None) -> dict[str, dict[str, float]]:
        """Peak and equivalent radial load [N], ISO 281 rating [N] and basic rating life
        ``L10`` [million revolutions and hours], ISO 76 static rating ``C0r`` [N] and static safety
        ``s0 = C0r / peak load`` (a ``RuntimeWarning`` below 1: the raceways yield, and the elastic
        roller law no longer holds) of the most loaded eccentric and crank bearing,
        from ``t_start`` [s] to the end (default: :meth:`steady_window`, whole crank revolutions
        relative to the carrier, over which every eccentric bearing sees its whole load cycle).
        The equivalent load weights ``|F|^(10/3)`` by the bearing's revolutions (relative
        rotation of its rings); the life holds if the window repeats. A window of less than one
        such revolution gives a ``RuntimeWarning`` (an eccentric bearing's load swings by a factor
        of about three over the revolution, so part of it over- or understates the life), and
        one of fewer than two samples a ``ParameterError``. Needs the ``"bearings"`` and ``"motion"`` channels and a
        scene whose bearings are built from rollers (``rollers``): ``ParameterError`` if none is;
        a bearing family without rollers is left out.

        ``crank_layout`` (:class:`rvdyn.bearing.CrankLayout`, axial positions [m]; default the
        scene's ``crank_layout`` where it has one and its crank bearing has rollers) splits each
        crank's lumped bearing into its two bearings by the statics of the rigid crank
        (:func:`rvdyn.crank_bearing_rows`): the entry ``"crank"`` is then replaced by
        ``"crank_a"`` and ``"crank_b"`` (the bearings at ``crank_layout.bearings[0]`` and
        ``[1]``), each rated with rollers of ``crank_layout.roller_length`` (default half the
        lumped length), and ``"crank_pair"`` gives the L10 of the worst crank's two bearings
        as a system (Lundberg-Palmgren, ``(L_a^-9/8 + L_b^-9/8)^(-8/9)``) and the smaller
        ``static_safety`` of the two. The lumped entry hides the discs' tilting moment and
        rates the two bearings as one row, so it overstates their life and static safety."""
        families = self._bearing_families(crank_layout)  # its refusals before any other work
        if t_start is None:
            try:
                t0 = self.steady_window()[0]
            except ParameterError:
                t0 = self._steady_start(None)
        else:
            t0 = self._steady_start(t_start)
        i0 = int(np.searchsorted(self.t, t0))
        t = self.t[i0:]
        if len(t) < 2:
            raise ParameterError(f"the window from t_start = {t0:.6g} s holds {len(t)} sample(s): "
                                 "start it earlier")
        turns = abs(float(self.crank_angle[-1, 0] - self.carrier_angle[-1]
                          - self.crank_angle[i0, 0] + self.carrier_angle[i0])) / (2 * math.pi)
        if turns < 0.99:  # (steady_window starts between two samples)
            warnings.warn(
                f"bearing_life: the window from {t0:.4g} s holds {turns:.2f} crank revolutions relative "
                "to the carrier; an eccentric bearing sees its whole load cycle only over whole ones "
                "(steady_window): run longer for a life that does not depend on the window",
                RuntimeWarning, stacklevel=2)
        duration = float(t[-1] - t[0])
        families = [(name, rating, static, forces[i0:], rel[i0:]) for name, rating, static, forces, rel in families]
        # Per interval between samples: the mean load and the rings' revolutions.
        rated: list[Family] = [
            (name, rating, static, float(np.linalg.norm(forces, axis=-1).max()),
             0.5 * (np.linalg.norm(forces[1:], axis=-1) + np.linalg.norm(forces[:-1], axis=-1)),
             np.abs(np.diff(rel, axis=0)) / (2 * np.pi))
            for name, rating, static, forces, rel in families]
        return rate_lives("bearing_life", rated, duration)

    def _bearing_families(
            self, crank_layout: CrankLayout | None,
    ) -> list[tuple[str, float | None, float | None, NDArray[np.float64], NDArray[np.float64]]]:
        """:func:`rvdyn.bearing.families` over the whole run, each with the relative angle of its
        rings (n, ...) [rad]: eccentric (crank against disc) or crank (crank against carrier)."""
        from .bearing import families

        crank = self.crank_angle
        crank_rel = crank - self.carrier_angle[:, None]
        ecc_rel = crank[:, :, None] - self.disc_angle[:, None, :]
        return [(name, rating, static, forces, ecc_rel if name == "eccentric" else crank_rel)
                for name, rating, static, forces in families(self.scene, self.crank_bearing_force,
                                                              self.eccentric_bearing_force, crank_layout)]

    def plot_bearing_loads(self, crank_layout: CrankLayout | None = None, ax: Any = None) -> Any:
        """The load [kN] of the most loaded bearing of each family (those of :meth:`bearing_life`,
        split by ``crank_layout``, default the scene's) over the run, with each family's ISO 76
        static rating ``C0r`` as a dashed line: where a curve crosses its line (a start impact,
        a load step), the static safety is below 1. Needs the ``"bearings"`` and ``"motion"``
        channels and roller bearings (``ParameterError`` otherwise)."""
        from .bearing import plot_family_loads

        families = [(name, static, forces) for name, _, static, forces, _ in self._bearing_families(crank_layout)
                    if static is not None]
        return plot_family_loads(ax, self.t, families, "time [s]", "bearing loads and ISO 76 static ratings")

    # -------------------------------------------------------------------- files
    def save(self, path: str | Path) -> Path:
        """Write all arrays, statistics, scene and options to a compressed ``.npz`` file
        (metadata as standard JSON, no pickles)."""
        if self.error is not None:
            raise ParameterError(f"a failed run has nothing to save ({self.error})")
        p = Path(path)
        try:
            meta = json.dumps({"stats": self.stats, "scene": self.scene, "options": self.options}, allow_nan=False)
        except ValueError as exc:
            raise ParameterError(f"result metadata is not finite JSON: {exc}") from None
        arrays: dict[str, Any] = {"__meta__": np.array(meta), **self._arrays}
        np.savez_compressed(p, **arrays)
        return p if p.suffix == ".npz" else p.with_name(p.name + ".npz")

    @classmethod
    def load(cls, path: str | Path) -> Result:
        """Read a file written by :meth:`save` (never unpickles: ``allow_pickle=False``).

        A file that is missing, damaged or not written by :meth:`save` raises
        :class:`ParameterError` naming the file, with the original error chained.
        """
        p = Path(path)
        try:
            # The file is opened here so that it is closed also when numpy fails to read it.
            with open(p, "rb") as fh, np.load(fh, allow_pickle=False) as f:
                if "__meta__" not in f.files:
                    raise ValueError("no __meta__ entry: not a file written by Result.save")
                meta = json.loads(str(f["__meta__"]))
                if not isinstance(meta, dict):
                    raise ValueError("__meta__ is not a JSON object")
                arrays = {k: f[k] for k in f.files if k != "__meta__"}
        except (OSError, ValueError, EOFError, KeyError, zipfile.BadZipFile) as exc:
            raise ParameterError(f"cannot read result file {str(p)!r}: {exc}") from exc
        return cls(arrays, meta.get("stats", {}), meta.get("scene"), meta.get("options"))

    # -------------------------------------------------------------------- plots
    def plot_output_speed(self, ax: Any = None, theory: float | None = None) -> Any:
        """Output (carrier) speed vs time in deg/s, as the paper's Figs. 5-6, with the
        theoretical speed (input/ratio) if ``theory`` [rad/s] is given."""
        ax = _axes(ax)
        ax.plot(self.t, np.degrees(self.carrier_speed), lw=0.6, label="simulated")
        if theory is not None:
            ax.axhline(math.degrees(theory), color="k", ls="--", lw=0.8, label=f"theory {math.degrees(theory):.3f} deg/s")
        ax.set(xlabel="time [s]", ylabel="output speed [deg/s]")
        ax.legend(loc="best")
        return ax

    def plot_disc_center(self, disc: int = 0, axes: Any = None) -> Any:
        """Disc centre x and y vs time [mm] and its path, as the paper's Fig. 7."""
        import matplotlib.pyplot as plt

        disc = self._disc(disc)
        if axes is None:
            _, axes = plt.subplots(1, 2, figsize=(11, 4))
        c = self.disc_center[:, disc] * 1e3
        axes[0].plot(self.t, c[:, 0], lw=0.6, label="x")
        axes[0].plot(self.t, c[:, 1], lw=0.6, label="y")
        axes[0].set(xlabel="time [s]", ylabel=f"disc {disc} centre [mm]")
        axes[0].legend()
        axes[1].plot(c[:, 0], c[:, 1], lw=0.6)
        axes[1].set(xlabel="x [mm]", ylabel="y [mm]", aspect="equal", title="centre path")
        return axes

    def plot_pin_moments(self, pins: Iterable[int] = (22, 23, 24, 1, 2, 3, 4), disc: int = 0,
                         window: tuple[float, float] | None = None, ax: Any = None) -> Any:
        """Moment of each pin's force about the disc centre [N m] vs time, for the paper's pin
        numbers ``pins`` (1-based), as the paper's Figs. 8-14, in ``window`` [s]."""
        pins = list(pins)
        index = pin_indices(pins, int(self.pin_moment.shape[2]))
        disc = self._disc(disc)
        if window is not None:
            window = (_real("window start [s]", window[0]), _real("window end [s]", window[1]))
        ax = _axes(ax)
        t = self.t
        sel = slice(None) if window is None else (t >= window[0]) & (t <= window[1])
        for p, j in zip(pins, index):
            ax.plot(t[sel], self.pin_moment[sel, disc, j], lw=0.8, label=f"pin {p}")
        ax.set(xlabel="time [s]", ylabel=f"moment about disc {disc} centre [N m]")
        ax.legend(ncol=4, fontsize="small")
        return ax

    def plot_loaded_pins(self, ax: Any = None) -> Any:
        """Number of loaded pins per disc vs time."""
        ax = _axes(ax)
        for k in range(self.loaded_pins.shape[1]):
            ax.plot(self.t, self.loaded_pins[:, k], lw=0.8, drawstyle="steps-post", label=f"disc {k}")
        ax.set(xlabel="time [s]", ylabel="loaded pins")
        ax.legend()
        return ax

    def plot_input_torque(self, ax: Any = None) -> Any:
        """Input torque [N m] vs time."""
        ax = _axes(ax)
        ax.plot(self.t, self.input_torque, lw=0.6)
        ax.set(xlabel="time [s]", ylabel="input torque [N m]")
        return ax

    def plot_energy(self, ax: Any = None) -> Any:
        """Energy flows [J] and the balance residual vs time."""
        ax = _axes(ax)
        for name in ("input_work", "output_work", "dissipated_energy", "kinetic_energy", "energy_residual"):
            ax.plot(self.t, getattr(self, name), lw=0.8, label=name)
        ax.set(xlabel="time [s]", ylabel="energy [J]")
        ax.legend(fontsize="small")
        return ax


def _hermite(x: float, t: np.ndarray, y: np.ndarray, dy: np.ndarray) -> float:
    """Cubic Hermite interpolation of samples ``y`` with derivatives ``dy`` at time ``x``."""
    i = int(np.clip(np.searchsorted(t, x) - 1, 0, len(t) - 2))
    h = float(t[i + 1] - t[i])
    s = (x - float(t[i])) / h
    h00, h10, h01, h11 = (1 + 2 * s) * (1 - s) ** 2, s * (1 - s) ** 2, s * s * (3 - 2 * s), s * s * (s - 1)
    return float(h00 * y[i] + h10 * h * dy[i] + h01 * y[i + 1] + h11 * h * dy[i + 1])


def _axes(ax: Any) -> Any:
    if ax is not None:
        return ax
    import matplotlib.pyplot as plt

    return plt.subplots(figsize=(8, 4))[1]
