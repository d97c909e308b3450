"""The paper's runs (``rvdyn paper``): idle and full load at 8328 deg/s, figures and a summary.

Full load comes in two versions (docs/model.md#errata-of-the-paper, erratum 3): ``paper`` is the printed 4024.9 N m on
the output (10.3 kW, not the stated 112 kW); ``rated`` is 43.9 kN m = 57 x 770.6 N m, the
lossless output torque of 112 kW at 8328 deg/s.
"""

from __future__ import annotations

import argparse
import json
import math
import os
import sys
import threading
import time
import warnings
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path
from typing import Any, Callable, Iterable, NamedTuple

import numpy as np

from .errors import ParameterError
from .result import Result
from .scene import Scene
from .simulation import simulate

#: The paper's reported numbers, for comparison in the summary.
PAPER_REPORTED = {
    "output_speed_theory_deg_s": 146.1,
    "output_speed_simulated_deg_s": 144.9,
    "relative_error": 0.0083,
    "loaded_pins": 6,
    "largest_moment_pin_near_4_92_s": 24,
}
LOAD_CASES = ("idle", "paper", "rated")


#: The channel groups the summary and the figures read: the bearing forces are not computed.
#: Samples every 1e-4 s (the default; the zoomed figures show 0.2 s, about 2 samples per pixel
#: column) and the library's default integrator settings: the numbers are those of a run with
#: every channel.
PAPER_CHANNELS = ("motion", "pins", "mesh", "energy")


def run_case(load: str, t_end: float, integrator: str | None, progress: bool | None) -> tuple[Scene, Result, float]:
    """Simulate one load case of the default scene (channels :data:`PAPER_CHANNELS`) with
    ``integrator`` (None: the scene's default, dopri5 for the idle case and generalized-alpha
    for the loaded ones); returns scene, result and wall time [s]."""
    scene = Scene.paper(load)
    start = time.perf_counter()
    # Every 1e-4 s exactly (the default cap of 50 000 samples would stretch a 5 s run's
    # interval to 5/49 999 s): samples then fall on generalized-alpha's step ends, whose power
    # flows they provide (one force evaluation less per step).
    result = simulate(scene, t_end, integrator, progress=progress, channels=list(PAPER_CHANNELS),
                      record_interval=1e-4, max_samples=int(round(t_end / 1e-4)) + 1)
    return scene, result, time.perf_counter() - start


def summarize(load: str, scene: Scene, result: Result, wall: float) -> dict[str, Any]:
    """Summary numbers of one run (SI, plus deg/s where the paper uses it)."""
    speed_in = scene["drive.speed"]
    theory = speed_in / scene.ratio
    t_end = float(result.t[-1])
    t_start = min(1.0, 0.2 * t_end)
    window = result.steady_window(t_start)
    mean = result.mean_output_speed(t_start)
    e = scene["cycloid.eccentricity"]
    radius = result.disc_path_radius(t_start)
    pins = result.loaded_pin_stats(t_start)
    t_moment = min(4.92, t_end)
    load_torque = scene["load"].get("torque", 0.0)
    balance = result.energy_balance()
    i0 = int(np.searchsorted(result.t, t_start))
    return {
        "load_case": load,
        "load_torque_N_m": load_torque,
        "t_end_s": t_end,
        "integrator": result.options.get("integrator"),
        "steady_window_s": list(window),
        "output_speed_theory_deg_s": math.degrees(theory),
        "output_speed_mean_deg_s": math.degrees(mean),
        "output_speed_relative_error": mean / theory - 1.0,
        "output_speed_ripple_deg_s": float(np.degrees(np.ptp(result.carrier_speed[i0:]))),
        "disc_path_radius_mm": {"eccentricity": e * 1e3, "min": radius[:, 0].min() * 1e3,
                                "mean": radius[:, 1].mean() * 1e3, "max": radius[:, 2].max() * 1e3},
        "loaded_pins_per_disc": [{"min": int(p[0]), "mean": float(p[1]), "max": int(p[2])} for p in pins],
        "largest_moment_pin": {"time_s": t_moment, "disc0": result.largest_moment_pin(t_moment, 0),
                               "moment_about": "disc centre"},
        "peak_pin_force_N": float(result.pin_force[i0:].max()),
        "mean_input_torque_N_m": float(result.input_torque[i0:].mean()),
        "energy_balance": balance,
        "wall_time_s": wall,
        "steps": result.stats.get("steps"),
        "force_evaluations": result.stats.get("evaluations"),
    }


def _m4(x: np.ndarray, y: np.ndarray, edges: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The first, smallest, largest and last sample of each run ``edges[k]:edges[k+1]`` (runs not
    empty, ``edges`` from 0 to ``len(y)``), in their order, each sample once; the first
    occurrence of a tied extreme, as numpy's argmin/argmax. ``y`` finite."""
    starts, ends = edges[:-1], edges[1:]
    lengths = ends - starts
    run = np.repeat(np.arange(len(starts)), lengths)

    def first(mask: np.ndarray) -> np.ndarray:
        hits = np.flatnonzero(mask)
        owner = run[hits]
        return hits[np.concatenate(([True], owner[1:] != owner[:-1]))]

    lo = first(y == np.repeat(np.minimum.reduceat(y, starts), lengths))
    hi = first(y == np.repeat(np.maximum.reduceat(y, starts), lengths))
    picks = np.stack([starts, lo, hi, ends - 1], axis=1)
    picks.sort(axis=1)
    idx = picks.ravel()
    idx = idx[np.concatenate(([True], idx[1:] != idx[:-1]))]  # a sample picked twice is kept once
    return x[idx], y[idx]


def envelope(x: np.ndarray, y: np.ndarray, buckets: int) -> tuple[np.ndarray, np.ndarray]:
    """The trace ``(x, y)`` reduced to the first, last, smallest and largest sample of each of
    ``buckets`` equal runs of samples, in their order of occurrence (the M4 aggregation of
    Jugel et al. 2014), at most ``4 buckets`` points. Traces already that short, or holding a
    value that is not finite, are returned unchanged. The figures use :func:`pixel_envelope`,
    the same with one run per pixel column."""
    n = len(x)
    if n <= 4 * buckets or not np.all(np.isfinite(y)):
        return x, y
    return _m4(x, y, np.linspace(0, n, buckets + 1).astype(int))


def pixel_envelope(x: np.ndarray, y: np.ndarray, px: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The trace ``(x, y)`` reduced to the first, last, smallest and largest sample in each pixel
    column, ``px`` being the samples' horizontal pixel coordinates (increasing): drawn, it
    covers the same pixels as the full trace, since within a column the full trace spans
    exactly its smallest to its largest value and the segments joining neighbouring columns
    are the trace's own (M4 aggregation, Jugel et al. 2014). At most 4 points per column;
    returned unchanged where that saves nothing or a value is not finite."""
    col = np.floor(px)
    edges = np.concatenate(([0], np.flatnonzero(col[1:] != col[:-1]) + 1, [len(x)]))
    if len(x) <= 4 * (len(edges) - 1) or not (np.all(np.isfinite(y)) and np.all(np.isfinite(col))):
        return x, y
    return _m4(x, y, edges)


def _long_traces(fig: Any) -> list[tuple[Any, np.ndarray, np.ndarray]]:
    """The lines of ``fig`` worth thinning, with their data: traces against time (x never
    decreasing) with more than 4 samples per pixel column of their axes. Lines whose x goes
    back and forth (the disc centre's path) are left out: an envelope of sample runs would cut
    chords across them."""
    found = []
    for ax in fig.axes:
        width = max(1, int(ax.bbox.width))
        for line in ax.get_lines():
            x, y = (np.asarray(v, dtype=float) for v in line.get_data())
            if (len(x) > 4 * width and line.get_linestyle() not in ("None", "", " ")
                    and bool(np.all(np.diff(x) >= 0))):
                found.append((line, x, y))
    return found


def _thin_lines(fig: Any) -> None:
    """Replace every long trace of ``fig`` (:func:`_long_traces`) by its per-pixel-column
    envelope (:func:`pixel_envelope`) at the axes' final place and limits: call it after the
    layout, just before drawing."""
    for ax in fig.axes:
        ax.get_xlim()  # the autoscaled limits (matplotlib applies a pending autoscale on reading them)
    for line, x, y in _long_traces(fig):
        px = line.get_transform().transform(np.column_stack([x, np.zeros_like(x)]))[:, 0]
        line.set_data(*pixel_envelope(x, y, px))


#: Resolution [dots per inch] of the figures.
DPI = 110
#: zlib level of the PNG files: 1 stores the same pixels as matplotlib's default 6 in about 60 %
#: of the encoding time (20 instead of 33 ms for a 1320 x 440 figure; files about 30 % larger).
PNG_COMPRESS_LEVEL = 1


def _import_matplotlib() -> None:
    """Import the parts of matplotlib the figures use (about 0.3 s)."""
    import matplotlib.backends.backend_agg  # noqa: F401
    import matplotlib.figure  # noqa: F401
    import matplotlib.pyplot  # noqa: F401  (Result.plot_disc_center imports it)


def _new_figure(figsize: tuple[float, float], ncols: int = 1) -> tuple[Any, Any]:
    """A Figure with ``ncols`` axes in a row, drawn by Agg (no pyplot, no global backend)."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    fig = Figure(figsize=figsize, dpi=DPI)
    FigureCanvasAgg(fig)
    return fig, fig.subplots(1, ncols)


#: Margins [in] around the axes of the paper figures: left (tick labels and y label), right,
#: bottom (tick labels and x label), top (title), and the gap between axes side by side. Fixed
#: instead of matplotlib's tight layout, which measures every tick label once more and took
#: 35-45 % of the drawing time; wide enough for every figure and load case (tested).
MARGINS_IN = {"left": 0.85, "right": 0.2, "bottom": 0.55, "top": 0.35, "gap": 1.0}


def _fixed_layout(fig: Any) -> None:
    """Place the axes of ``fig`` (in a row) with the margins :data:`MARGINS_IN`."""
    w, h = fig.get_size_inches()
    m = MARGINS_IN
    n = len(fig.axes)
    axes_w = (w - m["left"] - m["right"] - (n - 1) * m["gap"]) / n
    fig.subplots_adjust(left=m["left"] / w, right=1 - m["right"] / w, bottom=m["bottom"] / h,
                        top=1 - m["top"] / h, wspace=m["gap"] / axes_w)


def _save(fig: Any, path: Path) -> None:
    """Lay ``fig`` out (:func:`_fixed_layout`), thin its long traces to its pixels and write it
    as PNG."""
    _fixed_layout(fig)
    _thin_lines(fig)  # the traces hold 50 000 samples; a figure is ~1000 pixels wide
    fig.savefig(path, dpi=DPI, pil_kwargs={"compress_level": PNG_COMPRESS_LEVEL})


def _theory(scene: Scene) -> float:
    """Theoretical output speed input/ratio [rad/s]."""
    return float(scene["drive.speed"] / scene.ratio)


def _draw_output_speed(axes: Any, load: str, theory: float, result: Result) -> None:
    result.plot_output_speed(axes[0], theory=theory)
    axes[0].set_title(f"output speed, load {load} (paper Figs. 5-6)")
    # The steady ripple is invisible on the scale of the start impact: zoom on 0.2 s of it.
    t_end = float(result.t[-1])
    zoom = (result.t >= 0.6 * t_end) & (result.t <= 0.6 * t_end + min(0.2, 0.4 * t_end))
    axes[1].plot(result.t[zoom], np.degrees(result.carrier_speed[zoom]), lw=0.8)
    axes[1].axhline(math.degrees(theory), color="k", ls="--", lw=0.8)
    axes[1].set(xlabel="time [s]", ylabel="output speed [deg/s]", title="steady ripple (zoom)")


def _draw_disc_center(axes: Any, load: str, theory: float, result: Result) -> None:
    result.plot_disc_center(0, axes)
    axes[0].set_title("front disc centre (paper Fig. 7)")


def _draw_pin_moments(axes: Any, load: str, theory: float, result: Result) -> None:
    t_end = float(result.t[-1])
    centre = min(4.92, t_end)
    window = (max(0.0, centre - 0.12), min(t_end, centre + 0.08))
    result.plot_pin_moments(window=window, ax=axes[0])
    axes[0].axvline(centre, color="k", lw=0.5, ls=":")
    axes[0].set_title("moment of each pin's force about the front disc centre (paper Figs. 8-14)")


def _draw_loaded_pins(axes: Any, load: str, theory: float, result: Result) -> None:
    result.plot_loaded_pins(axes[0])


def _draw_input_torque(axes: Any, load: str, theory: float, result: Result) -> None:
    result.plot_input_torque(axes[0])


class FigureKind(NamedTuple):
    """One figure of a run: what draws it into its axes, its size [in], its number of axes (in
    a row) and the result channels it reads."""

    draw: Callable[[Any, str, float, Result], None]
    size: tuple[float, float]
    ncols: int
    channels: tuple[str, ...]


#: The figures of one run, by file name part.
FIGURES: dict[str, FigureKind] = {
    "output_speed": FigureKind(_draw_output_speed, (12, 4), 2, ("t", "carrier_speed")),
    "disc_center": FigureKind(_draw_disc_center, (11, 4), 2, ("t", "disc_center")),
    "pin_moments": FigureKind(_draw_pin_moments, (9, 4.5), 1, ("t", "pin_moment")),
    "loaded_pins": FigureKind(_draw_loaded_pins, (8, 3.5), 1, ("t", "loaded_pins")),
    "input_torque": FigureKind(_draw_input_torque, (8, 3.5), 1, ("t", "input_torque")),
}


def _clear(fig: Any) -> None:
    """Take from the axes of ``fig`` what a figure kind draws (data, legends, texts, titles,
    labels, limits, aspect, colour cycle), keeping the axes and their ticks."""
    for ax in fig.axes:
        for artist in [*ax.lines, *ax.collections, *ax.patches, *ax.texts, *ax.images, *ax.tables]:
            artist.remove()
        legend = ax.get_legend()
        if legend is not None:
            legend.remove()
        ax.set(title="", xlabel="", ylabel="", aspect="auto")
        ax.relim()
        ax.set_autoscale_on(True)
        ax.set_prop_cycle(None)


class Figures:
    """The figures of :data:`FIGURES`, each kind drawn into one matplotlib Figure that is made
    on its first use and cleared for the next run (:func:`_clear`): its axes, their ticks and
    texts are made once, about a quarter of the drawing time of ``rvdyn paper``'s 15 figures.
    The pixels are those of a new Figure (tested). Not for several threads at once."""

    def __init__(self) -> None:
        self._made: dict[str, Any] = {}

    def draw(self, name: str, load: str, theory: float, result: Result) -> Any:
        """The Figure of kind ``name`` for the run ``result`` of load case ``load``, whose
        theoretical output speed is ``theory`` [rad/s]; valid until the next call with ``name``."""
        if name not in FIGURES:
            raise ParameterError(f"unknown paper figure {name!r}: the figures are {sorted(FIGURES)}")
        kind = FIGURES[name]
        fig = self._made.get(name)
        if fig is None:
            fig = self._made[name] = _new_figure(kind.size, kind.ncols)[0]
        else:
            _clear(fig)
        kind.draw(fig.axes, load, theory, result)
        return fig

    def write(self, load: str, theory: float, result: Result, out: Path, names: Iterable[str]) -> list[Path]:
        """Write the figures ``names`` of one run into ``out`` as ``{load}_{name}.png``; returns the files."""
        files = []
        for name in names:
            path = out / f"{load}_{name}.png"
            _save(self.draw(name, load, theory, result), path)
            files.append(path)
        return files


def figures(load: str, scene: Scene, result: Result, out: Path) -> list[Path]:
    """Write the paper's figures for one run into ``out``; returns the files."""
    return Figures().write(load, _theory(scene), result, out, FIGURES)


def _split(jobs: list[tuple[str, str]]) -> tuple[list[tuple[str, str]], list[tuple[str, str]]]:
    """The figure jobs ``(load case, figure)`` left when the last run is done, shared between
    this process and the helper: every other one, in their order (the figures cost within a
    factor of about 2 of each other)."""
    return jobs[0::2], jobs[1::2]


def _helper_main(conn: Any, draw: Any, jobs: list[tuple[str, str]]) -> None:
    """Body of the helper process: draw ``jobs`` with ``draw`` (inherited by the fork, with the
    results it reads), send back the files written or the exception raised."""
    try:
        try:
            reply: Any = [draw(*job) for job in jobs]
        except Exception as exc:  # sent back and raised by the caller
            reply = exc
        try:
            conn.send(reply)
        except Exception:  # an exception that does not pickle: its text
            conn.send(RuntimeError(f"the figure process failed: {reply!r}"))
    except (KeyboardInterrupt, BrokenPipeError):  # Ctrl-C or the caller gone
        pass
    finally:
        conn.close()


class _Helper:
    """A process drawing part of the figures left once the last run is done, while the caller
    draws the others.

    Forked then, when the run's worker thread has ended: the child inherits matplotlib, already
    imported, and the results, so nothing is imported twice and nothing is sent but the reply.
    Before that moment the two cores are busy with the runs and with drawing the figures of
    the runs done. None of this where fork is not the platform's way, with one core, or while
    other Python threads run: then the caller draws all."""

    def __init__(self, proc: Any, conn: Any) -> None:
        self.proc, self.conn = proc, conn

    @classmethod
    def start(cls, draw: Any, jobs: list[tuple[str, str]]) -> _Helper | None:
        if sys.platform != "linux" or threading.active_count() > 1 or (os.cpu_count() or 1) < 2:
            return None
        import multiprocessing

        try:
            ctx = multiprocessing.get_context("fork")
            parent, child = ctx.Pipe(duplex=False)
            proc = ctx.Process(target=_helper_main, args=(child, draw, jobs), name="rvdyn-paper-figures", daemon=True)
            sys.stdout.flush()  # nothing buffered may be written twice
            sys.stderr.flush()
            with warnings.catch_warnings():
                # Python >= 3.12 warns about fork() in any process with several OS threads
                # (numpy's BLAS pool): no other Python thread runs and the child only draws.
                warnings.simplefilter("ignore", DeprecationWarning)
                proc.start()
        except (OSError, ValueError):  # no fork or no pipe here: draw in this process
            return None
        child.close()
        return cls(proc, parent)

    def finish(self) -> list[Path]:
        """Wait for the helper's figures; raise the error it met."""
        try:
            reply = self.conn.recv()
        except EOFError:
            reply = RuntimeError("the figure process ended without writing its figures")
        finally:
            self.close()
        if isinstance(reply, BaseException):
            raise reply
        return list(reply)

    def close(self) -> None:
        self.conn.close()
        self.proc.join(timeout=10)
        if self.proc.is_alive():  # pragma: no cover - a helper that hangs
            self.proc.kill()
            self.proc.join()


def markdown(summaries: list[dict[str, Any]]) -> str:
    """The summaries as a Markdown report."""
    lines = ["# rvdyn: the paper's runs", "",
             "Default scene (docs/model.md#default-scene), input 8328 deg/s, step start from rest, rigid joints, "
             "IMPACT contacts with the paper's parameters.", "",
             "| quantity | " + " | ".join(s["load_case"] for s in summaries) + " | published (source paper) |",
             "|---|" + "---|" * len(summaries) + "---|"]

    def row(name: str, values: list[str], paper: str = "") -> None:
        lines.append(f"| {name} | " + " | ".join(values) + f" | {paper} |")

    row("load torque on the output [N m]", [f"{s['load_torque_N_m']:.1f}" for s in summaries], "0 / 4024.9")
    row("mean output speed [deg/s] (whole crank revolutions)", [f"{s['output_speed_mean_deg_s']:.6f}" for s in summaries], "144.9")
    row("theory input/57 [deg/s]", [f"{s['output_speed_theory_deg_s']:.6f}" for s in summaries], "146.1")
    row("relative error", [f"{s['output_speed_relative_error']:.2e}" for s in summaries], "0.83 %")
    row("output speed ripple, peak to peak [deg/s]", [f"{s['output_speed_ripple_deg_s']:.3f}" for s in summaries])
    row("disc centre path radius min/mean/max [mm] (e = 4.5)",
        [f"{s['disc_path_radius_mm']['min']:.4f}/{s['disc_path_radius_mm']['mean']:.4f}/{s['disc_path_radius_mm']['max']:.4f}" for s in summaries], "4.5")
    row("loaded pins, front disc min/mean/max",
        [f"{d['min']}/{d['mean']:.2f}/{d['max']}" for d in (s["loaded_pins_per_disc"][0] for s in summaries)], "6")
    times = sorted({f"{s['largest_moment_pin']['time_s']:g}" for s in summaries})
    row(f"pin with the largest moment near {' / '.join(times)} s (front disc)",
        [str(s["largest_moment_pin"]["disc0"]) for s in summaries], "24 (at 4.92 s)")
    # The idle rattle's peak is below a newton: three digits, not a bare 0.
    row("peak pin force [N]", [f"{v:.0f}" if v >= 100 else f"{v:.3g}" for v in (s["peak_pin_force_N"] for s in summaries)])
    row("mean input torque [N m]", [f"{s['mean_input_torque_N_m']:.2f}" for s in summaries], "770.6 (full load)")
    row("energy balance residual (relative)", [f"{s['energy_balance']['relative_residual']:.2e}" for s in summaries])
    row("wall time [s]", [f"{s['wall_time_s']:.2f}" for s in summaries])
    row("integrator", [str(s.get("integrator", "")) for s in summaries])
    note = ("Moments are about the disc centre (about the ring centre they are 24/23 larger). "
            "The number of loaded pins is what this unmodified profile gives (docs/model.md#errata-of-the-paper, "
            "erratum 6).")
    if any(str(s.get("integrator", "")).startswith("generalized-alpha") for s in summaries):
        note += (" The energy residual of generalized-alpha holds the error of its work integrals at the start "
                 "impact (docs/model.md, \"Energy accounting\"); dopri5 (the idle case's default) closes the "
                 "balance to about 1e-6 and better.")
    lines += ["", note, ""]
    return "\n".join(lines)


def main(args: argparse.Namespace) -> int:
    """Entry point of ``rvdyn paper``: run the load cases, write figures and summaries.

    The runs go one after the other on a worker thread (the core releases the GIL) while this
    thread imports matplotlib and draws the figures of each run done; once the last run is
    done, a helper process (:class:`_Helper`) draws every other figure still to draw."""
    out = Path(getattr(args, "out", "rvdyn-out"))
    out.mkdir(parents=True, exist_ok=True)
    load = getattr(args, "load", "all")
    loads = LOAD_CASES if load == "all" else (load,)
    t_end = float(getattr(args, "t_end", 5.0))
    integrator = getattr(args, "integrator", None)
    several = len(loads) > 1
    how = integrator or ("the scene defaults (dopri5 at idle, generalized-alpha under load)" if "idle" in loads
                         else "generalized-alpha")
    print(f"running load case{'s' if several else ''} {', '.join(map(repr, loads))}: "
          f"{t_end} s simulated{' each' if several else ''} with {how} ...", flush=True)
    done: dict[str, tuple[float, Result]] = {}

    drawn = Figures()

    def draw(case: str, name: str) -> Path:
        return drawn.write(case, *done[case], out, [name])[0]

    summaries = []
    jobs: list[tuple[str, str]] = []
    helper: _Helper | None = None
    pool = ThreadPoolExecutor(max_workers=1, thread_name_prefix="rvdyn-paper")
    try:
        # No progress bar: one from the worker thread would mix with the lines printed here.
        runs = list(zip(loads, [pool.submit(run_case, case, t_end, integrator, False) for case in loads]))
        _import_matplotlib()  # while the first run goes
        while runs or jobs:
            # Take the runs done; wait for one only when no figure is left to draw.
            while runs and (runs[0][1].done() or not jobs):
                case, run = runs.pop(0)
                scene, result, wall = run.result()
                done[case] = (_theory(scene), result)
                summary = summarize(case, scene, result, wall)
                summaries.append(summary)
                jobs += [(case, name) for name in FIGURES]
                print(f"  {case}: mean output speed {summary['output_speed_mean_deg_s']:.6f} deg/s "
                      f"(theory {summary['output_speed_theory_deg_s']:.6f}, error {summary['output_speed_relative_error']:.2e}), "
                      f"simulated in {wall:.2f} s", flush=True)
                if not runs:
                    pool.shutdown(wait=True)  # the worker thread ends: nothing runs but this thread
                    jobs, theirs = _split(jobs)
                    helper = _Helper.start(draw, theirs)
                    if helper is None:
                        jobs += theirs
            if jobs:
                draw(*jobs.pop(0))
        if helper is not None:
            helper.finish()
            helper = None
    finally:
        # On an error or Ctrl-C the runs not started are dropped; a started one finishes.
        pool.shutdown(wait=True, cancel_futures=True)
        if helper is not None:
            helper.close()
    (out / "summary.json").write_text(json.dumps(summaries, indent=2), encoding="utf-8")
    (out / "summary.md").write_text(markdown(summaries), encoding="utf-8")
    print(f"wrote figures, summary.json and summary.md to {out}/")
    return 0
