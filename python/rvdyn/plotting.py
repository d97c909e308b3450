"""Matplotlib figures for rvdyn (geometry, contact stiffness).

Matplotlib is imported lazily inside each function. Figures are built with
``matplotlib.figure.Figure`` (no pyplot, no global state, no GUI backend needed); saving them
renders with Agg. Pass ``ax=`` to draw into an existing axes instead.

All inputs are SI (m, rad); axes show millimetres where that reads better, labelled as such.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING, Any, Iterable, Sequence

import numpy as np

from . import _core
from ._args import real as _real
from ._args import short as _short
from ._args import whole as _whole
from .errors import ParameterError

if TYPE_CHECKING:  # pragma: no cover
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure

__all__ = ["plot_geometry", "plot_stiffness", "new_figure", "save_figure", "pin_indices"]

#: The paper's stiffness maxima (section 3.2), printed as N/mm^2, read as N/mm^1.5
#: (docs/model.md#erratum-4), "near 5 mm" contact width.
PAPER_STIFFNESS_MAXIMA = {"convex-convex": 3.988e5, "convex-concave": 5.093e5}
PAPER_STIFFNESS_WIDTH = 5e-3
_PER_MM15 = 1000.0**1.5


#: Most profile points per lobe a geometry plot draws (a finer outline is invisible).
MAX_SAMPLES_PER_LOBE = 10_000


def pin_indices(pins: Iterable[Any], zp: int) -> list[int]:
    """0-based indices of the paper's 1-based pin numbers ``pins`` on a ring of ``zp`` pins.

    Raises ParameterError for a number that is not a whole number from 1 to zp (0, -1 or NaN
    would otherwise pick a pin by Python's negative indexing under a wrong label).
    """
    try:
        numbers = list(pins)
    except TypeError as e:
        raise ParameterError(
            f"pins must be an iterable of pin numbers 1..{zp}, got {_short(pins)}"
        ) from e
    return [_whole("pin number", p, 1, zp) - 1 for p in numbers]


def new_figure(figsize: tuple[float, float] = (7.0, 7.0)) -> tuple[Figure, Axes]:
    """A new Figure with one Axes, independent of pyplot (safe in scripts and threads)."""
    from matplotlib.figure import Figure

    fig = Figure(figsize=figsize, layout="constrained")
    ax = fig.add_subplot()
    return fig, ax


def save_figure(fig: Figure, path: str, dpi: int = 150) -> str:
    """Write ``fig`` to ``path`` (format from the suffix, e.g. PNG) with the Agg renderer."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    FigureCanvasAgg(fig)
    fig.savefig(path, dpi=dpi)
    return path


def _disc_outline(
    geometry: _core.CycloidGeometry, centre: np.ndarray, angle: float, samples: int
) -> np.ndarray:
    """Profile points (samples, 2) [m] of a disc placed at ``centre`` turned by ``angle``."""
    phi = np.linspace(0.0, 2.0 * math.pi, samples)
    local = geometry.profile(phi)
    c, s = math.cos(angle), math.sin(angle)
    rot = np.array([[c, -s], [s, c]])
    points: np.ndarray = local @ rot.T + centre
    return points


def plot_geometry(
    geometry: _core.CycloidGeometry | None = None,
    psi: float = 0.0,
    ax: Axes | None = None,
    disc: str = "both",
    samples_per_lobe: int = 64,
    number_pins: bool = True,
) -> Figure:
    """Draw the cycloid disc(s) meshing with the pins at crank angle ``psi``.

    Parameters
    ----------
    geometry : CycloidGeometry, optional
        The disc; ``CycloidGeometry.paper()`` if None.
    psi : float
        Crank (eccentric) angle [rad] of the first disc: centre e (cos psi, sin psi), angle
        -psi/zc.
    ax : matplotlib Axes, optional
        Draw here; a new Figure is made if None.
    disc : {"both", "front", "rear"}
        Which disc(s) to draw. The rear disc sits on the eccentric opposite (phase pi), which
        also turns it by half a lobe (pi/zc): its lobe tips face the front disc's roots.
    samples_per_lobe : int
        Profile points per lobe.
    number_pins : bool
        Label the pins 1..zp as the paper does (pin j + 1 at angle 2 pi j / zp from +x).

    Returns
    -------
    matplotlib.figure.Figure
    """
    if not isinstance(disc, str) or disc not in ("both", "front", "rear"):
        raise ParameterError(f'disc must be "both", "front" or "rear", got {_short(disc)}')
    psi = _real("psi (crank angle [rad])", psi)
    samples_per_lobe = _whole("samples_per_lobe", samples_per_lobe, 4, MAX_SAMPLES_PER_LOBE)
    if geometry is not None and not isinstance(geometry, _core.CycloidGeometry):
        raise TypeError(f"geometry must be a CycloidGeometry or None, got {type(geometry).__name__}")
    from matplotlib.patches import Circle, Polygon

    g = geometry if geometry is not None else _core.CycloidGeometry.paper()
    if ax is None:
        fig, ax = new_figure()
    else:
        fig = ax.figure  # type: ignore[assignment]
    mm = 1e3
    samples = samples_per_lobe * g.lobes + 1
    discs = []
    if disc in ("both", "front"):
        discs.append(("front disc", psi, "tab:blue"))
    if disc in ("both", "rear"):
        discs.append(("rear disc (eccentric + pi)", psi + math.pi, "tab:orange"))
    for label, crank, colour in discs:
        centre, angle = g.kinematic_pose(crank)
        outline = _disc_outline(g, centre, angle, samples) * mm
        ax.add_patch(
            Polygon(outline, closed=True, facecolor=colour, alpha=0.15, edgecolor=colour,
                    linewidth=1.2, label=label)
        )
        ax.plot(centre[0] * mm, centre[1] * mm, "+", color=colour, markersize=10)
    pins = g.pin_positions() * mm
    r_pin = g.pin_radius * mm
    for j, (x, y) in enumerate(pins):
        ax.add_patch(Circle((x, y), r_pin, facecolor="0.6", edgecolor="k", linewidth=0.8))
        if number_pins:
            theta = math.atan2(y, x)
            r_lab = g.pin_circle_radius * mm + 1.8 * r_pin
            ax.text(r_lab * math.cos(theta), r_lab * math.sin(theta), str(j + 1),
                    ha="center", va="center", fontsize=8)
    t = np.linspace(0.0, 2.0 * math.pi, 361)
    rp = g.pin_circle_radius * mm
    ax.plot(rp * np.cos(t), rp * np.sin(t), ":", color="0.5", linewidth=0.8)
    ax.plot(0.0, 0.0, "k+", markersize=12)
    lim = (g.pin_circle_radius + 3.0 * g.pin_radius) * mm
    ax.set_xlim(-lim, lim)
    ax.set_ylim(-lim, lim)
    ax.set_aspect("equal")
    ax.set_xlabel("x [mm]")
    ax.set_ylabel("y [mm]")
    ax.set_title(
        f"Cycloid discs and pins at crank angle psi = {psi:.3f} rad\n"
        f"zp = {g.pins}, zc = {g.lobes}, e = {g.eccentricity * mm:g} mm, "
        f"rp = {g.pin_circle_radius * mm:g} mm, rrp = {r_pin:g} mm, K1 = {g.k1:.3f}",
        fontsize=10,
    )
    ax.legend(loc="lower left", fontsize=8)
    return fig


def plot_stiffness(
    r1: float | None = None,
    r2: float | None = None,
    widths: Sequence[float] | np.ndarray | None = None,
    ax: Axes | None = None,
    conditions: Sequence[str] = ("convex-convex", "convex-concave"),
    show_paper: bool = True,
    **stiffness_kwargs: Any,
) -> Figure:
    """Contact stiffness against contact width for both contact conditions (the paper's Fig. 3).

    Parameters
    ----------
    r1 : float, optional
        Pin radius [m]; ``rvdyn.PAPER_STIFFNESS_R1`` (10 mm) if None.
    r2 : float, optional
        Disc radius of curvature [m]; ``rvdyn.PAPER_STIFFNESS_R2`` (103.5 mm) if None.
    widths : array_like, optional
        Contact widths [m]; 0.5 mm to 40 mm if None.
    ax : matplotlib Axes, optional
        Draw here; a new Figure is made if None.
    conditions : sequence of str
        Conditions to draw ("convex-convex", "convex-concave").
    show_paper : bool
        Mark the paper's printed maxima (3.988e5 and 5.093e5 N/mm^1.5 near 5 mm).
    **stiffness_kwargs
        Passed to ``rvdyn.contact_stiffness`` (youngs_modulus [Pa], poisson_ratio,
        exponent, penetration [m]).

    Returns
    -------
    matplotlib.figure.Figure

    Each curve's maximum over the plotted widths is marked with a dot: with the corrected
    formulas the curves decrease with width, so that maximum is at the narrowest width (an
    interior maximum, if one exists, would be marked the same way).
    """
    r1 = _core.PAPER_STIFFNESS_R1 if r1 is None else _real("r1 [m]", r1)
    r2 = _core.PAPER_STIFFNESS_R2 if r2 is None else _real("r2 [m]", r2)
    if widths is None:
        w = np.linspace(0.5e-3, 40e-3, 400)
    else:
        try:
            w = np.asarray(widths, dtype=float)
        except (OverflowError, ValueError) as e:
            raise ParameterError(
                f"widths must be a 1-D array of contact widths [m], got {_short(widths)}"
            ) from e
    if w.ndim != 1 or w.size < 2:
        raise ParameterError(
            f"widths must be a 1-D array of at least 2 contact widths [m], got shape {w.shape}"
        )
    if isinstance(conditions, str):
        conditions = (conditions,)
    exponent = _real("exponent", stiffness_kwargs.get("exponent", 1.5))
    if ax is None:
        fig, ax = new_figure((7.5, 5.0))
    else:
        fig = ax.figure  # type: ignore[assignment]
    colours = {"convex-convex": "tab:blue", "convex-concave": "tab:red"}
    peaks = []
    for cond in conditions:
        k = np.asarray(_core.contact_stiffness(w, r1, r2, cond, **stiffness_kwargs))
        colour = colours.get(cond, None)
        (line,) = ax.plot(w * 1e3, k, color=colour, label=f"{cond} (rvdyn, errata corrected)")
        i = int(np.argmax(k))
        peaks.append((k[i], w[i], i in (0, k.size - 1), line.get_color()))
        ax.plot(w[i] * 1e3, k[i], "o", color=line.get_color())
        if show_paper and cond in PAPER_STIFFNESS_MAXIMA:
            kp = PAPER_STIFFNESS_MAXIMA[cond] * _PER_MM15
            ax.plot(PAPER_STIFFNESS_WIDTH * 1e3, kp, "*", markersize=12, color=line.get_color(),
                    label=f"{cond}: paper's printed maximum")
    # Labels of the marked maxima, highest first, stacked so that they do not overlap.
    for rank, (k_max, w_max, edge, colour) in enumerate(sorted(peaks, key=lambda p: -p[0])):  # type: ignore[assignment]
        what = "largest value (range edge, no interior maximum)" if edge else "maximum"
        ax.annotate(
            f"{what}: {k_max:.3e} at {w_max * 1e3:.2f} mm",
            (w_max * 1e3, k_max),
            textcoords="offset points",
            xytext=(10, 8 - 16 * rank),
            fontsize=8,
            color=colour,
        )
    ax.set_yscale("log")
    ax.set_xlabel("contact width L [mm]")
    ax.set_ylabel(f"contact stiffness k [N/m^{exponent:g}]")
    ax.set_title(f"Contact stiffness vs contact width (paper eqs. 5-11, errata corrected)\n"
                 f"R1 = {r1 * 1e3:g} mm, R2 = {r2 * 1e3:g} mm; stars: the paper's printed "
                 f"maxima (N/mm^1.5 converted)", fontsize=10)
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8)
    return fig
