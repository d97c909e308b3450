"""Dynamic runs: :func:`simulate` one scene, :func:`sweep` many in parallel.

Run options live in one object, :class:`rvdyn.Options` (built and validated in Rust); the
keyword arguments of :func:`simulate` and :func:`sweep` are a convenience mapped onto it in one
place (:func:`_resolve_options`).
"""

from __future__ import annotations

import itertools
import json
import operator
import sys
import warnings
from collections import abc
from typing import Any, Iterable, Mapping, Sequence

import numpy as np

from . import _core
from ._args import short as _short
from ._core import Options
from .errors import ParameterError, RvdynError
from .result import Result
from .scene import Scene

__all__ = ["simulate", "sweep", "Options", "INTEGRATORS"]

#: Integrator names accepted by :func:`simulate` (the Rust registry, default first).
INTEGRATORS: tuple[str, ...] = tuple(name for name, *_ in _core.integrators())


def _check_scene(scene: object) -> Scene:
    if not isinstance(scene, Scene):
        raise ParameterError(f"scene must be an rvdyn.Scene (e.g. rvdyn.Scene.paper()), got {type(scene).__name__}")
    return scene


def _resolve_options(options: Options | None, integrator: str | None, changes: dict[str, Any]) -> Options:
    """The options of a call: ``options`` (or the defaults) with the keyword arguments given
    (those not None) applied; validated in Rust."""
    given = {k: v for k, v in changes.items() if v is not None}
    if integrator is not None:
        given["integrator"] = integrator
    if options is None:
        return Options(**given)
    if not isinstance(options, Options):
        raise ParameterError(f"options must be an rvdyn.Options, got {type(options).__name__}")
    return options.replace(**given) if given else options


#: The default integrator of a scene with roller bearings (the physical preset), where the
#: paper scene's default (generalized-alpha, dt 1e-4 s) is off by 3 % of the peak pin force:
#: dopri5 at atol 1e-8 m, rtol 1e-4, 3.9e-4 of the peak, the cheapest setting below 1e-3 with a
#: margin in the work-precision benchmark of that preset (BENCHMARKS.md section 1.1).
ROLLER_DEFAULT: dict[str, Any] = {"integrator": "dopri5", "atol": 1e-8, "rtol": 1e-4}


#: The default integrator of a light scene (``Scene.light_load``: idle, or a nominal mesh force
#: below 10 N), with or without roller bearings. Its forces are a few newtons (the idle paper
#: scene's a decaying rattle with about 7e-8 m of mesh deflection over the second half of a 1 s
#: run, against 9e-5 m at rated load), which the loaded scenes' defaults do not resolve:
#: generalized-alpha at dt 1e-4 s has the idle mesh-force and input-torque RMS 12 times the
#: converged values over [0.5, 1] s and the peak mesh force 78 % too high at a nominal mesh force
#: of 0.95 N; ``ROLLER_DEFAULT`` put the physical preset's peak pin force 62 % too high idle over
#: [0.25, 0.5] s and 120 % at 0.95 N. dopri5 at atol 1e-11 m, rtol 1e-9 is within 0.5 % of a run
#: at 1e-13 m, 1e-11 in every force statistic of the idle paper scene and within 3 % in the pin
#: statistics of the others (docs/validation.md, "Idle rattle and light loads").
IDLE_DEFAULT: dict[str, Any] = {"integrator": "dopri5", "atol": 1e-11, "rtol": 1e-9}


def _has_rollers(scene: Scene) -> bool:
    joints = scene.to_dict()["joints"]
    return joints.get("kind") == "compliant" and any(
        (joints.get(b) or {}).get("rollers") is not None for b in ("eccentric_bearing", "crank_bearing"))


def _scene_defaults(scenes: Sequence[Scene], options: Options | None, integrator: str | None,
                    changes: dict[str, Any]) -> tuple[str | None, dict[str, Any]]:
    """The integrator and tolerances a call uses when it names none (unless ``options``,
    ``integrator`` or a step ``dt`` is given): ``IDLE_DEFAULT`` when every scene is light,
    ``ROLLER_DEFAULT`` for scenes with roller bearings, the library's defaults otherwise."""
    if options is not None or integrator is not None or changes.get("dt") is not None:
        return integrator, changes
    if scenes and all(s.light_load for s in scenes):
        default = IDLE_DEFAULT
    elif any(_has_rollers(s) for s in scenes):
        default = ROLLER_DEFAULT
    else:
        return integrator, changes
    out = dict(changes)
    for key in ("atol", "rtol"):
        if out.get(key) is None:
            out[key] = default[key]
    return str(default["integrator"]), out


def _warn(stats: dict[str, Any]) -> None:
    """Issue the run's accuracy warnings (a fixed step too long for the scene) as
    ``RuntimeWarning`` and keep them out of the numeric statistics."""
    for message in stats.pop("warnings", []):
        warnings.warn(message, RuntimeWarning, stacklevel=3)


def _warn_static_overload(scene: Scene, res: Result) -> None:
    """Warn when a roller bearing's recorded load exceeds its ISO 76 static rating ``C0r``
    (static safety ``s0 < 1``): the raceways would yield there (permanent deformation above 1e-4
    of the roller diameter), and the elastic roller law, the forces after it and the life do not
    hold (docs/model.md, "Load rating, life and friction torque")."""
    if "bearings" not in res.options.get("channels", ()) or len(res.t) == 0:
        return
    ratings = scene._compiled.bearing_ratings("static")
    for name, c0, key in (("eccentric", ratings[0], "eccentric_bearing_force"),
                          ("crank", ratings[1], "crank_bearing_force")):
        if c0 is None:
            continue
        load = np.linalg.norm(getattr(res, key), axis=-1).reshape(len(res.t), -1).max(axis=1)
        k = int(np.argmax(load))
        if load[k] > c0:
            warnings.warn(
                f"the {name} bearings' load reaches {load[k] / 1e3:.1f} kN at t = {res.t[k]:.4g} s, above "
                f"their ISO 76 static rating C0r = {c0 / 1e3:.1f} kN (static safety s0 = {c0 / load[k]:.2f} < 1): "
                "the raceways would yield, and the elastic roller law and the forces do not hold there. The "
                "presets apply their load as a step at t = 0 (also with initial=\"steady\"), which gives "
                "such a peak: ramp the load over a few periods of the main torsional mode, e.g. "
                "load={\"kind\": \"table\", \"points\": [[0, 0], [0.02, torque]]} (rated physical preset: "
                "155 kN peak, s0 1.18), or use larger bearings (joints.*.rollers)", RuntimeWarning, stacklevel=3)


def _t_end(t_end: object) -> float:
    if isinstance(t_end, bool):
        raise ParameterError(f"t_end must be a time in s, got {_short(t_end)}")
    try:
        return float(t_end)  # type: ignore[arg-type]
    except (OverflowError, TypeError, ValueError):
        raise ParameterError(f"t_end must be a time in s, got {_short(t_end)}") from None


def simulate(scene: Scene, t_end: float, integrator: str | None = None, *, options: Options | None = None,
             dt: float | None = None, rtol: float | None = None, atol: float | None = None,
             rho_inf: float | None = None, record_interval: float | None = None, max_samples: int | None = None,
             channels: Sequence[str] | str | None = None, progress: bool | None = None,
             skip_separated: bool | None = None, step_check: str | None = None,
             h_min: float | None = None, max_steps: int | None = None) -> Result:
    """Simulate ``scene`` from t = 0 to ``t_end`` [s] and return the recorded :class:`Result`.

    options: an :class:`rvdyn.Options`; the keyword arguments below, when given, change it.
    integrator: ``"generalized-alpha"`` (implicit, order 2, fixed step ``dt``, default 1e-4 s;
    ``rho_inf`` in [0, 1] sets its high-frequency damping, default 0.8; ``atol`` [m] is its
    Newton tolerance on displacements, default 1e-9 m), ``"generalized-alpha-adaptive"`` (the
    same method with its step chosen for ``atol`` [m] and ``rtol``: local error estimate, PI
    controller, initial step ``dt``, default 1e-5 s), ``"dopri5"``
    (adaptive Dormand-Prince 5(4); ``atol`` [m] bounds displacement errors, default 1e-9 m;
    ``rtol`` relative velocity tolerance, default 1e-6) or ``"rk4"`` (fixed step ``dt``,
    default 1e-5 s). Without ``integrator``, ``options`` or ``dt``, a scene with roller bearings
    (``Scene.physical``) runs dopri5 at atol 1e-8 m, rtol 1e-4 (``ROLLER_DEFAULT``: 3.0e-4 of the
    peak pin force over [0.05, 0.1] s from rest, where generalized-alpha at dt 1e-4 s is off by 3 %); a light
    scene (``Scene.light_load``: idle, or a nominal mesh force below 10 N; with or without them) runs dopri5 at
    atol 1e-11 m, rtol 1e-9 (``IDLE_DEFAULT``: its forces of a few newtons need that; generalized-alpha at dt
    1e-4 s has idle mesh forces 12 times too large); other scenes generalized-alpha. ``atol`` is at most 1e-6 m and ``rtol`` at most 1e-2 (looser ones are a
    ``ParameterError``: the contact approaches are tens of micrometres).
    record_interval: sample spacing [s], at most ``t_end`` (default 1e-4 s, or ``t_end`` for
    a shorter run), coarsened so that at most ``max_samples`` (default 50 000) samples are
    kept, which bounds memory on long runs.
    channels: any of ``"motion"``, ``"pins"``, ``"contact_points"``, ``"mesh"``, ``"energy"``,
    ``"bearings"``
    (default all but ``"contact_points"``); channels not asked for are not computed.
    progress: draw a progress bar on stderr (default: when stderr is a terminal).
    skip_separated: skip the exact gap query of pins that provably cannot touch (a Lipschitz
    bound on the gap from the last exact query and the disc's motion since); the answer is the
    same either way, ``False`` exists to measure the saving.
    step_check: what a step that cannot be accurate for the scene does (fewer than 8 steps
    per pin-mesh period; generalized-alpha above 2e-5 s, its adaptive form, or dopri5 above atol
    1e-10 m, on a light scene from rest): ``"warn"`` (default, a ``RuntimeWarning``), ``"raise"``
    (:class:`rvdyn.ParameterError`) or ``"off"``.
    h_min, max_steps: smallest step [s] of an adaptive integrator (default 1e-13 s) and most
    steps of any (default 1e8); beyond either an adaptive run stops with
    :class:`rvdyn.SimulationError`, and a fixed step that would take more than ``max_steps`` is a
    :class:`rvdyn.ParameterError` before the run.

    The core runs with the GIL released; Ctrl-C stops it cleanly (``KeyboardInterrupt``). A run
    that goes unstable raises :class:`rvdyn.SimulationError` saying when and what would help.

    >>> res = simulate(Scene.paper("rated"), 1e-3, dt=1e-4)
    >>> res.t.shape, res.options["integrator"], res.stats["steps"]
    ((11,), 'generalized-alpha', 10)
    """
    scene = _check_scene(scene)
    integrator, changes = _scene_defaults([scene], options, integrator, {
        "dt": dt, "rtol": rtol, "atol": atol, "rho_inf": rho_inf, "record_interval": record_interval,
        "max_samples": max_samples, "channels": channels, "skip_separated": skip_separated,
        "step_check": step_check, "h_min": h_min, "max_steps": max_steps})
    opts = _resolve_options(options, integrator, changes)
    t = _t_end(t_end)
    if progress is None:
        progress = bool(getattr(sys.stderr, "isatty", lambda: False)())
    used = opts.resolved(t)
    arrays, stats = _core.simulate(scene._compiled, t, opts, progress=bool(progress))
    _warn(stats)
    res = Result(arrays, stats, scene.to_dict(), used)
    _warn_static_overload(scene, res)
    return res


def _grid(base: Scene, grid: Mapping[str, Iterable[Any]]) -> tuple[list[Scene], list[dict[str, Any]]]:
    keys = list(grid)
    values = []
    for k in keys:
        column = grid[k]
        if isinstance(column, (str, bytes)) or not isinstance(column, abc.Iterable) or np.ndim(column) > 1:  # type: ignore[arg-type]
            raise ParameterError(
                f"grid[{k!r}] must be a 1-D list of values for that field, got {_short(column)}: "
                f"e.g. grid={{{k!r}: [1e4, 2e4]}}")
        # numpy scalars (a grid from np.array or np.linspace) as Python numbers: each run's
        # options["point"] must be JSON.
        col = [v.item() if hasattr(v, "item") and callable(v.item) else v for v in column]
        if not col:
            raise ParameterError(f"grid[{k!r}] is empty: give at least one value")
        values.append(col)
    scenes, points = [], []
    for combo in itertools.product(*values):
        point = dict(zip(keys, combo))
        scenes.append(base.replace(**point))
        points.append(point)
    return scenes, points


def sweep(scenes: Scene | Sequence[Scene], t_end: float, integrator: str | None = None, *,
          options: Options | None = None, grid: Mapping[str, Iterable[Any]] | None = None,
          threads: int | None = None, dt: float | None = None, rtol: float | None = None,
          atol: float | None = None, rho_inf: float | None = None, record_interval: float | None = None,
          max_samples: int | None = None, channels: Sequence[str] | str | None = None,
          skip_separated: bool | None = None, step_check: str | None = None,
          h_min: float | None = None, max_steps: int | None = None) -> list[Result]:
    """Run many scenes in parallel (Rust threads, GIL released) and return one :class:`Result`
    per scene, in order. A run that failed has ``ok`` False and its exception in ``error``
    (a failed run does not stop the others); bad options raise before any run, as for
    :func:`simulate`. Ctrl-C stops every run and raises ``KeyboardInterrupt``.

    ``scenes`` is a list of scenes, or one base scene with ``grid`` mapping dotted field paths
    to values (the full Cartesian product is run; each result's ``options["point"]`` holds its
    field values). ``threads``: worker threads (default: all cores). Other options as for
    :func:`simulate`.

    >>> runs = sweep(Scene.paper("rated"), 1e-3, grid={"load.torque": [1e4, 2e4]}, dt=1e-4)
    >>> [r.ok for r in runs], runs[1].options["point"]
    ([True, True], {'load.torque': 20000.0})
    """
    if isinstance(scenes, Scene):
        if not grid:
            raise ParameterError("sweep over one scene needs grid={'field.path': [values, ...]}")
        scene_list, points = _grid(scenes, grid)
    else:
        if grid:
            raise ParameterError("give either a list of scenes or one scene with a grid, not both")
        scene_list = [_check_scene(s) for s in scenes]
        points = [{} for _ in scene_list]
    given = {"dt": dt, "rtol": rtol, "atol": atol, "rho_inf": rho_inf, "record_interval": record_interval,
             "max_samples": max_samples, "channels": channels, "skip_separated": skip_separated,
             "step_check": step_check, "h_min": h_min, "max_steps": max_steps}
    t = _t_end(t_end)
    # Each scene gets the defaults simulate would give it: light scenes, scenes with roller
    # bearings and the others run as groups, each with its own defaults.
    groups: dict[tuple[bool, bool], list[int]] = {}
    for i, s in enumerate(scene_list):
        light = s.light_load
        groups.setdefault((light, not light and _has_rollers(s)), []).append(i)
    plans = []
    for idx in groups.values():
        integ, changes = _scene_defaults([scene_list[i] for i in idx], options, integrator, given)
        opts = _resolve_options(options, integ, changes)
        plans.append((idx, opts, opts.resolved(t)))
    if threads is not None:
        try:
            if isinstance(threads, bool):
                raise TypeError
            threads = operator.index(threads)  # Python and numpy integers
        except TypeError:
            raise ParameterError(f"threads must be a whole number >= 1 (None = one per core), got {threads!r}") from None
        if threads < 1:
            raise ParameterError(f"threads must be a whole number >= 1 (None = one per core), got {threads!r}")
    results: list[Result | None] = [None] * len(scene_list)
    for idx, opts, used in plans:
        raw = _core.sweep([scene_list[i]._compiled for i in idx], t, opts, threads=threads)
        for i, item in zip(idx, raw):
            scene, point = scene_list[i], points[i]
            run_options = {**used, "point": json.loads(json.dumps(point))}
            if isinstance(item, BaseException):
                error = item if isinstance(item, RvdynError) else RvdynError(str(item))
                results[i] = Result.failed(error, scene.to_dict(), run_options)
            else:
                arrays, stats = item
                _warn(stats)
                done = Result(arrays, stats, scene.to_dict(), run_options)
                _warn_static_overload(scene, done)
                results[i] = done
    return [r for r in results if r is not None]
