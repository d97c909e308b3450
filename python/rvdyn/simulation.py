"""Dynamic runs: :func:`simulate` one scene, :func:`sweep` many in parallel."""

from __future__ import annotations

import itertools
import json
import sys
from typing import Any, Iterable, Mapping, Sequence

from . import _core
from .errors import ParameterError
from .result import Result
from .scene import Scene

__all__ = ["simulate", "sweep", "INTEGRATORS"]

#: Integrator names accepted by :func:`simulate`.
INTEGRATORS = ("generalized-alpha", "dopri5", "rk4")


def _check_scene(scene: Any) -> Scene:
    if not isinstance(scene, Scene):
        raise ParameterError(f"scene must be an rvdyn.Scene (e.g. rvdyn.Scene.paper()), got {type(scene).__name__}")
    return scene


def _options(t_end: float, integrator: str, dt: float | None, rtol: float | None, atol: float | None,
             rho_inf: float | None, record_interval: float | None, max_samples: int | None,
             channels: Sequence[str] | None) -> dict[str, Any]:
    if isinstance(channels, str):
        channels = [channels]
    return {"t_end": float(t_end), "integrator": str(integrator), "dt": dt, "rtol": rtol, "atol": atol,
            "rho_inf": rho_inf, "record_interval": record_interval, "max_samples": max_samples,
            "channels": None if channels is None else list(channels)}


def simulate(scene: Scene, t_end: float, integrator: str = "generalized-alpha", *, dt: float | None = None,
             rtol: float | None = None, atol: float | None = None, rho_inf: float | None = None,
             record_interval: float | None = None, max_samples: int | None = None,
             channels: Sequence[str] | None = None, progress: bool | None = None,
             skip_separated: bool = True) -> Result:
    """Simulate ``scene`` from t = 0 to ``t_end`` [s] and return the recorded :class:`Result`.

    integrator: ``"generalized-alpha"`` (implicit, order 2, fixed step ``dt``, default 1e-4 s;
    ``rho_inf`` in [0, 1] sets its high-frequency damping, default 0.8; ``atol`` [m] is its
    Newton tolerance on displacements, default 1e-9 m), ``"dopri5"``
    (adaptive Dormand-Prince 5(4); ``atol`` [m] bounds displacement errors, default 1e-9 m;
    ``rtol`` relative velocity tolerance, default 1e-6) or ``"rk4"`` (fixed step ``dt``,
    default 1e-5 s).
    record_interval: sample spacing [s] (default 1e-4 s), coarsened so that at most
    ``max_samples`` (default 50 000) samples are kept, which bounds memory on long runs.
    channels: any of ``"motion"``, ``"pins"``, ``"contact_points"``, ``"mesh"``, ``"energy"``
    (default all but ``"contact_points"``); channels not asked for are not computed.
    progress: draw a progress bar on stderr (default: when stderr is a terminal).
    skip_separated: skip the exact gap query of pins that provably cannot touch (a Lipschitz
    bound on the gap from the last exact query and the disc's motion since); the answer is the
    same either way, ``False`` exists to measure the saving.

    The core runs with the GIL released; Ctrl-C stops it cleanly (``KeyboardInterrupt``). A run
    that goes unstable raises :class:`rvdyn.SimulationError` saying when and what would help.
    """
    scene = _check_scene(scene)
    opts = _options(t_end, integrator, dt, rtol, atol, rho_inf, record_interval, max_samples, channels)
    if progress is None:
        progress = bool(getattr(sys.stderr, "isatty", lambda: False)())
    arrays, stats = _core.simulate(scene.to_json(), opts["t_end"], opts["integrator"], dt=dt, rtol=rtol,
                                   atol=atol, rho_inf=rho_inf, record_interval=record_interval,
                                   max_samples=max_samples, channels=opts["channels"], progress=bool(progress),
                                   skip_separated=bool(skip_separated))
    return Result(arrays, stats, scene.to_dict(), opts)


def _grid(base: Scene, grid: Mapping[str, Iterable[Any]]) -> tuple[list[Scene], list[dict[str, Any]]]:
    keys = list(grid)
    values = [list(grid[k]) for k in keys]
    scenes, points = [], []
    for combo in itertools.product(*values):
        point = dict(zip(keys, combo))
        scenes.append(base.replace(**point))
        points.append(point)
    return scenes, points


def sweep(scenes: Scene | Sequence[Scene], t_end: float, integrator: str = "generalized-alpha", *,
          grid: Mapping[str, Iterable[Any]] | None = None, threads: int | None = None,
          dt: float | None = None, rtol: float | None = None, atol: float | None = None,
          rho_inf: float | None = None, record_interval: float | None = None, max_samples: int | None = None,
          channels: Sequence[str] | None = None, skip_separated: bool = True) -> list[Result | Exception]:
    """Run many scenes in parallel (Rust threads, GIL released) and return one entry per
    scene, in order: a :class:`Result`, or the exception that run raised (a failed run does not
    stop the others).

    ``scenes`` is a list of scenes, or one base scene with ``grid`` mapping dotted field paths
    to values (the full Cartesian product is run; each result's ``options["point"]`` holds its
    field values). ``threads``: worker threads (default: all cores). Other options as for
    :func:`simulate`.
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
    opts = _options(t_end, integrator, dt, rtol, atol, rho_inf, record_interval, max_samples, channels)
    raw = _core.sweep([s.to_json() for s in scene_list], opts["t_end"], opts["integrator"], dt=dt, rtol=rtol,
                      atol=atol, rho_inf=rho_inf, record_interval=record_interval, max_samples=max_samples,
                      channels=opts["channels"], threads=threads, skip_separated=bool(skip_separated))
    out: list[Result | Exception] = []
    for scene, point, item in zip(scene_list, points, raw):
        if isinstance(item, BaseException):
            out.append(item)  # type: ignore[arg-type]
        else:
            arrays, stats = item
            out.append(Result(arrays, stats, scene.to_dict(), {**opts, "point": json.loads(json.dumps(point))}))
    return out
