"""Kernels: the analysis run for each sample, reduced to a few scalar metrics.

A kernel is a picklable object with ``name``, ``metrics`` (the metric names it returns, or
``None`` if unknown in advance) and ``__call__(scene) -> dict[str, float]``. Built-in kernels
are looked up by name in :data:`KERNELS` (``register_kernel`` adds one):

``"dynamic"``  :class:`DynamicKernel`: :func:`rvdyn.simulate` then summary metrics.
``"ltca"``     :class:`LtcaKernel`: the quasi-static analysis (:mod:`rvdyn.analysis`) reduced to
               :data:`LTCA_METRICS` (transmission error, pin loads, rigidity, lost motion).

Any picklable top-level function ``f(scene) -> dict`` is a kernel too (``FunctionKernel``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any, Callable, Mapping

import numpy as np

from ..errors import ParameterError
from ..scene import Scene

__all__ = ["DynamicKernel", "LtcaKernel", "FunctionKernel", "KERNELS", "register_kernel", "get_kernel",
           "DYNAMIC_METRICS", "LTCA_METRICS", "LTCA_BEARING_METRICS", "LTCA_CRANK_METRICS"]

#: Metrics of :class:`DynamicKernel`, evaluated on the window [t_start, t_end] (SI units).
DYNAMIC_METRICS: dict[str, str] = {
    "peak_pin_force": "largest pin normal force on any disc [N]",
    "loaded_pins_min": "fewest pins in contact on any disc [-]",
    "loaded_pins_mean": "mean number of pins in contact, averaged over discs [-]",
    "output_speed_error": "mean output speed / (mean input speed / ratio) - 1 [-]",
    "output_speed_ripple": "output speed peak-to-peak [rad/s]",
    "transmission_error_pp": "peak-to-peak of output angle - input angle / ratio [rad]",
    "peak_input_torque": "largest |input torque| [N m]",
}


#: Sample spacing of the dynamic kernel's runs [s] (``simulate``'s default).
RECORD_INTERVAL: float = 1e-4


@dataclass(frozen=True)
class DynamicKernel:
    """A dynamic run of ``t_end`` [s] reduced to :data:`DYNAMIC_METRICS`.

    t_start: start of the evaluated window [s] (default 20 % of t_end, after the start-up
    transient). integrator, dt: as for :func:`rvdyn.simulate` (None: its defaults). Only the motion, pin and mesh
    channels are recorded."""

    t_end: float = 0.5
    t_start: float | None = None
    integrator: str | None = None
    dt: float | None = None
    name: str = field(default="dynamic", init=False)

    def __post_init__(self) -> None:
        if not (isinstance(self.t_end, (int, float)) and math.isfinite(self.t_end) and self.t_end > 0):
            raise ParameterError(f"dynamic kernel: t_end must be a finite time > 0 [s], got {self.t_end!r}")
        if self.t_start is not None and not (math.isfinite(self.t_start) and 0 <= self.t_start < self.t_end):
            raise ParameterError(f"dynamic kernel: t_start must lie in [0, t_end), got {self.t_start!r}")
        # The run's options are checked here, once, rather than failing every sample.
        from ..simulation import Options

        try:
            Options(self.integrator, dt=self.dt)
        except ParameterError as exc:
            raise ParameterError(f"dynamic kernel: {exc}") from None
        if self.t_end < 10 * RECORD_INTERVAL:
            raise ParameterError(f"dynamic kernel: t_end = {self.t_end!r} s records fewer than 10 samples "
                                 f"(every {RECORD_INTERVAL:g} s); the metrics need a run of at least "
                                 f"{10 * RECORD_INTERVAL:g} s")

    @property
    def metrics(self) -> tuple[str, ...]:
        return tuple(DYNAMIC_METRICS)

    def __call__(self, scene: Scene) -> dict[str, float]:
        from ..simulation import simulate

        res = simulate(scene, self.t_end, self.integrator, dt=self.dt, channels=["motion", "pins", "mesh"],
                       record_interval=RECORD_INTERVAL, progress=False)
        t = res.t
        t0 = 0.2 * self.t_end if self.t_start is None else self.t_start
        i0 = min(int(np.searchsorted(t, t0)), len(t) - 2)
        w = slice(i0, None)
        ratio = _ratio(scene)
        span = float(t[-1] - t[i0])
        mean_in = float(res.sun_angle[-1] - res.sun_angle[i0]) / span
        mean_out = float(res.carrier_angle[-1] - res.carrier_angle[i0]) / span
        te = res.carrier_angle[w] - res.sun_angle[w] / ratio
        loaded = res.loaded_pins[w]
        return {
            "peak_pin_force": float(np.max(res.pin_force[w])),
            "loaded_pins_min": float(np.min(loaded)),
            "loaded_pins_mean": float(np.mean(loaded)),
            "output_speed_error": mean_out / (mean_in / ratio) - 1.0 if mean_in != 0 else math.nan,
            "output_speed_ripple": float(np.ptp(res.carrier_speed[w])),
            "transmission_error_pp": float(np.ptp(te)),
            "peak_input_torque": float(np.max(np.abs(res.input_torque[w]))),
        }


def metric_units(kernel: Any) -> dict[str, str]:
    """The unit of each metric of ``kernel`` that it states: a ``units`` mapping of the kernel,
    else the ``[unit]`` that ends each description of the built-in kernels' metrics ("-" for
    none). Empty for a kernel that does not say."""
    units = getattr(kernel, "units", None)
    if isinstance(units, Mapping):
        return {str(k): str(v) for k, v in units.items()}
    docs = {DynamicKernel: DYNAMIC_METRICS,
            LtcaKernel: {**LTCA_METRICS, **LTCA_BEARING_METRICS, **LTCA_CRANK_METRICS}}.get(type(kernel), {})
    out: dict[str, str] = {}
    metrics = set(getattr(kernel, "metrics", None) or docs)
    for name, text in docs.items():
        if name in metrics and text.endswith("]") and "[" in text:
            out[name] = text[text.rindex("[") + 1:-1]
    return out


def _ratio(scene: Scene) -> float:
    """Transmission ratio input speed / output speed of the scene."""
    ratio = getattr(scene, "ratio", None)
    if ratio is not None:
        return float(ratio() if callable(ratio) else ratio)
    from .._core import transmission_ratio

    stage = scene["stage1"]
    pins = int(scene["cycloid.pins"])
    if stage is None:  # the input drives the cranks (as Scene.ratio): -(zp - 1) = -zc
        return -float(pins - 1)
    return float(transmission_ratio(int(stage["z_sun"]), int(stage["z_planet"]), pins))


@dataclass(frozen=True)
class FunctionKernel:
    """A kernel from a picklable top-level function ``fn(scene) -> {metric: float}``;
    ``metrics`` lists its metric names (lets criteria be checked before the study runs)."""

    fn: Callable[[Scene], Mapping[str, float]]
    metrics: tuple[str, ...] | None = None
    name: str = "function"

    def __call__(self, scene: Scene) -> dict[str, float]:
        return {k: float(v) for k, v in self.fn(scene).items()}


#: Metrics of :class:`LtcaKernel` (SI units; the conventions of docs/model.md, "Quasi-static analysis").
LTCA_METRICS: dict[str, str] = {
    "te_pp_forward": "transmission error peak-to-peak over the window after which it repeats (or one mesh period) at +torque, extremes located between the crank angles [rad]",
    "te_pp_reverse": "transmission error peak-to-peak over the window after which it repeats (or one mesh period) at -torque, extremes located between the crank angles [rad]",
    "peak_pin_force": "largest pin force over the crank angles and discs at the torque [N]",
    "loaded_pins_min": "fewest pins in contact on any disc over the crank angles [-]",
    "torsional_rigidity": "catalogue torsional rigidity of the torque-twist loop [N m/rad]",
    "lost_motion": "catalogue lost motion of the torque-twist loop [rad]",
}

#: Metrics :class:`LtcaKernel` adds with ``bearings=True`` (:meth:`rvdyn.analysis.LtcaResult.bearing_life`
#: over one mesh period at +torque, steady running at the scene's drive speed, the scene's crank layout).
LTCA_BEARING_METRICS: dict[str, str] = {
    "bearing_l10_hours_min": "shortest ISO 281 rating life of the bearing families (a crank's two rows as a system) [h]",
    "bearing_static_safety_min": "smallest ISO 76 static safety s0 of the bearing families [-]",
}


#: Metrics :class:`LtcaKernel` adds with ``crank_bending=True`` (a scene with ``crank_shaft``;
#: :meth:`rvdyn.analysis.LtcaResult.crank_bending_stress` and ``crank_deflection`` over one mesh
#: period at +torque; docs/model.md, "Crankshaft bending").
LTCA_CRANK_METRICS: dict[str, str] = {
    "crank_bending_stress_max": "largest nominal bending stress 32 M / (pi d^3) in any crankshaft [Pa]",
    "crank_deflection_max": "largest bending deflection of an eccentric from its crank's line [m]",
}


@dataclass(frozen=True)
class LtcaKernel:
    """Loaded tooth contact analysis reduced to :data:`LTCA_METRICS`.

    torque: output torque [N m] (None: the scene's constant load; its magnitude is used for
    the two drive directions and as the rated torque of the twist loop). points: crank angles
    per mesh period for the transmission error and the pin loads (small by default to keep
    a sample cheap; raised to two per tooth-mesh cycle of an ISO 6336 mesh,
    :func:`rvdyn.analysis.tooth_mesh_angles`, so that the TE's extremes are found).
    twist_points: points of the torque-twist loop 0 -> +T -> -T -> 0, taken at crank_angle
    [rad]. window: the TE over the window after which it repeats (with roller bearings, whose
    roller sets stay fixed in the frame, several mesh periods: twelve on the physical preset
    without pin errors, twelve times the cost) or, with ``window=False``, over one mesh period.
    bearings: also the bearings' life and static safety (:data:`LTCA_BEARING_METRICS`, from an
    LTCA at ``points`` crank angles over one mesh period; needs roller bearings and a constant
    drive speed). crank_bending: also the crankshafts' bending stress and deflection
    (:data:`LTCA_CRANK_METRICS`, from the same LTCA; needs a scene with ``crank_shaft``). A
    sample whose analysis fails (no equilibrium, invalid geometry) raises its error, which the
    study records in the sample's row."""

    torque: float | None = None
    points: int = 24
    twist_points: int = 41
    crank_angle: float = 0.0
    window: bool = True
    bearings: bool = False
    crank_bending: bool = False
    name: str = field(default="ltca", init=False)

    def __post_init__(self) -> None:
        if self.torque is not None and not (isinstance(self.torque, (int, float)) and math.isfinite(self.torque)
                                            and self.torque != 0):
            raise ParameterError(f"ltca kernel: torque must be a finite non-zero number [N m], got {self.torque!r}")
        if not (isinstance(self.points, int) and self.points >= 2):
            raise ParameterError(f"ltca kernel: points must be an int >= 2, got {self.points!r}")
        if not (isinstance(self.twist_points, int) and self.twist_points >= 5):
            raise ParameterError(f"ltca kernel: twist_points must be an int >= 5, got {self.twist_points!r}")
        if not (isinstance(self.crank_angle, (int, float)) and math.isfinite(self.crank_angle)):
            raise ParameterError(f"ltca kernel: crank_angle must be a finite angle [rad], got {self.crank_angle!r}")
        if not isinstance(self.window, bool):
            raise ParameterError(f"ltca kernel: window must be True or False, got {self.window!r}")
        if not isinstance(self.bearings, bool):
            raise ParameterError(f"ltca kernel: bearings must be True or False, got {self.bearings!r}")
        if not isinstance(self.crank_bending, bool):
            raise ParameterError(f"ltca kernel: crank_bending must be True or False, got {self.crank_bending!r}")

    @property
    def metrics(self) -> tuple[str, ...]:
        return (tuple(LTCA_METRICS) + (tuple(LTCA_BEARING_METRICS) if self.bearings else ())
                + (tuple(LTCA_CRANK_METRICS) if self.crank_bending else ()))

    def __call__(self, scene: Scene) -> dict[str, float]:
        # The computations of rvdyn.analysis.transmission_error (its loaded part, with the
        # extremes located between the crank angles), ltca and torque_twist, on one solver
        # (built once per sample; the same metrics to ~1e-12 relative): TE at +-torque over one
        # mesh period with the pin loads of its +torque equilibria, then the loop. The unloaded
        # TE is not a metric and is not computed.
        from .. import _core
        from ..analysis.ltca import _rated, _scene, _tooth_mesh_angles, _window_periods

        sc = _scene(scene)
        if self.crank_bending and not sc["crank_shaft"]:
            raise ParameterError("ltca kernel: crank_bending=True needs a scene with crank_shaft (and crank_layout)")
        torque = abs(_rated(sc, self.torque))
        solver = _core.LtcaSolver(sc._compiled, 1e-12)
        period = float(solver.mesh_period)
        points = max(self.points, _tooth_mesh_angles(sc, period))
        periods = _window_periods(float(solver.te_window), period) if self.window else 1
        te = solver.transmission_error(torque, None, points, 0.0, True, periods)
        pp = {k: float(e["max"] - e["min"]) for k, e in te["extremes"].items()}
        pins = te["pin_loads"]["forward"]
        loop = solver.twist_loop(torque, float(self.crank_angle), self.twist_points)
        out = {
            "te_pp_forward": pp["forward"],
            "te_pp_reverse": pp["reverse"],
            "peak_pin_force": float(np.max(pins["peak_force"])),
            "loaded_pins_min": float(np.min(pins["loaded_pins_min"])),
            "torsional_rigidity": float(loop["rigidity"]),
            "lost_motion": float(loop["lost_motion"]),
        }
        if self.bearings or self.crank_bending:
            import warnings

            from ..analysis.ltca import ltca

            angles = period * np.arange(points) / points
            with warnings.catch_warnings():  # s0 below 1 is a metric here, not a warning per sample
                warnings.simplefilter("ignore", RuntimeWarning)
                res = ltca(sc, torque, angles)
                if self.bearings:
                    life = res.bearing_life()
                    out["bearing_l10_hours_min"] = min(v["l10_hours"] for v in life.values())
                    out["bearing_static_safety_min"] = min(v["static_safety"] for v in life.values())
            if self.crank_bending:
                out["crank_bending_stress_max"] = float(res.crank_bending_stress().max())
                out["crank_deflection_max"] = float(np.linalg.norm(res.crank_deflection, axis=-1).max())
        return out


#: Kernel factories by name: ``factory(**options) -> kernel``.
KERNELS: dict[str, Callable[..., Any]] = {"dynamic": DynamicKernel, "ltca": LtcaKernel}


def register_kernel(name: str, factory: Callable[..., Any]) -> None:
    """Make ``factory(**options)`` available as ``kernel=name`` (replaces an entry)."""
    if not isinstance(name, str) or not name:
        raise ParameterError(f"kernel name must be a non-empty string, got {name!r}")
    KERNELS[name] = factory


def get_kernel(kernel: Any, **options: Any) -> Any:
    """A kernel object from a name (``"dynamic"``, options passed to its factory), a kernel
    object, or a plain function."""
    if isinstance(kernel, str):
        if kernel not in KERNELS:
            raise ParameterError(f"unknown kernel {kernel!r}; known: {sorted(KERNELS)}")
        import inspect

        factory = KERNELS[kernel]
        params = inspect.signature(factory).parameters
        known = [n for n in params if n != "self"]
        unknown = sorted(set(options) - set(known))
        if unknown and not any(p.kind is inspect.Parameter.VAR_KEYWORD for p in params.values()):
            raise ParameterError(f"kernel {kernel!r}: unknown options {unknown}; known: {known}")
        try:
            return factory(**options)
        except TypeError as exc:
            raise ParameterError(f"kernel {kernel!r}: {exc}") from None
    if options:
        raise ParameterError("kernel options are for a kernel given by name")
    if hasattr(kernel, "metrics") and callable(kernel):
        return kernel
    if callable(kernel):
        return FunctionKernel(kernel, None, getattr(kernel, "__name__", "function"))
    raise ParameterError(f"kernel must be a name {sorted(KERNELS)}, a kernel object or a function, got {kernel!r}")
