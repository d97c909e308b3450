"""Rolling bearings after a run: the split of each crank's lumped bearing into its two rows.

The planar models carry each crank on one lumped bearing. The two bearings of a real crank
share its load unequally, because the two discs' eccentric loads point in different directions
and act at different axial positions: a tilting moment the plane cannot see. Given the axial
layout, the statics of a rigid crank on two radial supports (statically determinate) give each
bearing's load (docs/model.md, "Crank bearing rows"); :meth:`rvdyn.Result.bearing_life` and
:meth:`rvdyn.analysis.ltca.LtcaResult.bearing_safety` rate each one with a ``crank_layout``,
given to them or carried by the scene (its field ``crank_layout``, docs/scene.md).
"""

from __future__ import annotations

import json
import math
import warnings
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from . import _core
from .errors import ParameterError

__all__ = ["CrankLayout"]


@dataclass(frozen=True)
class CrankLayout:
    """Where a crank's parts sit along its axis [m] (any origin, one direction for all).

    Attributes
    ----------
    bearings : tuple[float, float]
        Mid-planes of the two crank bearings, different ("a" and "b" in the results).
    discs : tuple[float, ...]
        Mid-planes of the discs (their eccentrics), one per disc in the order of the discs.
    planet : float
        Mid-plane of the planet, where the mesh force acts (a dynamic run's crank inertia force
        is put there too: exact in the quasi-static LTCA; docs/model.md gives the error).
    roller_length : float or None
        Roller length of each of the two bearings [m], in (0, 1], for their ISO 76/281 ratings; None: half
        the scene's lumped crank roller length (the lumped row stands for two equal bearings).

    Examples
    --------
    >>> layout = CrankLayout(bearings=(-0.06, 0.06), discs=(-0.02, 0.02), planet=-0.09)
    >>> layout.rows([0.0, 0.0], [[1000.0, 0.0], [-1000.0, 0.0]]).tolist()  # a pure couple
    [[333.33333333333337, 0.0], [-333.33333333333337, 0.0]]
    """

    bearings: tuple[float, float]
    discs: tuple[float, ...]
    planet: float
    roller_length: float | None = None

    def __post_init__(self) -> None:
        try:
            bearings = tuple(float(z) for z in self.bearings)
            discs = tuple(float(z) for z in self.discs)
            planet = float(self.planet)
        except (TypeError, ValueError, OverflowError) as exc:
            raise ParameterError(f"CrankLayout takes axial positions in metres (numbers): {exc}") from None
        if len(bearings) != 2:
            raise ParameterError(f"CrankLayout.bearings must hold the two crank bearings' positions [m], "
                                 f"got {len(bearings)}")
        length = self.roller_length
        if length is not None:
            try:
                value = float(length) if isinstance(length, (int, float)) and not isinstance(length, bool) else math.nan
            except OverflowError:  # an int beyond the floats
                value = math.nan
            if not (math.isfinite(value) and 0 < value <= 1.0):  # the scene's bound on roller lengths
                raise ParameterError(f"CrankLayout.roller_length must be a length in (0, 1] m or None, got {length!r} "
                                     "(a value in mm? 20 mm is 0.02 m)")
            object.__setattr__(self, "roller_length", value)
        object.__setattr__(self, "bearings", bearings)
        object.__setattr__(self, "discs", discs)
        object.__setattr__(self, "planet", planet)
        # The core checks the rest (finite, a disc at least, bearings apart) with its message.
        _core.crank_bearing_rows([0.0, 0.0], [[0.0, 0.0]] * len(discs), bearings=(bearings[0], bearings[1]),
                                 discs=discs, planet=planet)

    def rows(self, crank_bearing_force: ArrayLike, eccentric_bearing_force: ArrayLike) -> NDArray[np.float64]:
        """Forces [N] of bearing ``bearings[0]`` and ``bearings[1]`` on the crank, shape
        (..., 2, 2), from the lumped crank bearing force (..., 2) and the discs' eccentric
        bearing forces (..., discs, 2) of a run or an LTCA (:func:`rvdyn.crank_bearing_rows`)."""
        b = self.bearings
        return _core.crank_bearing_rows(crank_bearing_force, eccentric_bearing_force, bearings=(b[0], b[1]),
                                        discs=self.discs, planet=self.planet)

    @classmethod
    def of_scene(cls, scene: dict[str, Any]) -> CrankLayout | None:
        """The layout a scene carries (``crank_layout``, docs/scene.md; ``scene`` a dict as
        :meth:`rvdyn.Scene.to_dict` gives), or None if it carries none or its crank bearing is
        not built from rollers (nothing to rate row by row).

        >>> import rvdyn
        >>> scene = rvdyn.Scene.physical("rated").replace(
        ...     crank_layout={"bearings": [-0.06, 0.06], "discs": [-0.02, 0.02], "planet": -0.09})
        >>> CrankLayout.of_scene(scene.to_dict()).bearings
        (-0.06, 0.06)
        """
        spec = scene.get("crank_layout")
        crank = (scene.get("joints") or {}).get("crank_bearing")
        if not spec or not (isinstance(crank, dict) and crank.get("rollers")):
            return None
        return cls(bearings=tuple(spec["bearings"]), discs=tuple(spec["discs"]), planet=spec["planet"],
                   roller_length=spec.get("roller_length"))

    def row_scene(self, scene: dict[str, Any]) -> dict[str, Any]:
        """A copy of ``scene`` (a dict) whose crank bearing is one of the two rows: rollers of
        :attr:`roller_length`. ``ParameterError`` if the scene's crank bearing has no rollers."""
        crank = ((scene.get("joints") or {}).get("crank_bearing") or {})
        rollers = crank.get("rollers") if isinstance(crank, dict) else None
        if not rollers:
            raise ParameterError("crank_layout needs a crank bearing built from rollers "
                                 "(joints.crank_bearing.rollers, as Scene.physical has)")
        length = self.roller_length if self.roller_length is not None else 0.5 * float(rollers["length"])
        out = dict(scene)
        out["joints"] = {**scene["joints"], "crank_bearing": {**crank, "rollers": {**rollers, "length": length}}}
        return out


def crank_bending_stress(scene: dict[str, Any], eccentric_bearing_force: ArrayLike, caller: str) -> NDArray[np.float64]:
    """The largest nominal bending stress in each crankshaft [Pa], shape (..., cranks): the
    shaft of ``scene``'s ``crank_shaft`` on its two bearings (``crank_layout``, simple
    supports) under the forces on its eccentrics (minus ``eccentric_bearing_force``, shape
    (..., cranks, discs, 2)), ``sigma = 32 |M| / (pi d^3)`` at the worst plane (the bending
    moment is largest at a load or a support; docs/model.md, "Crankshaft bending"). Nominal: no
    notch factor, no shear, no planet force. ``ParameterError`` (naming ``caller``) without
    ``crank_shaft``."""
    shaft, layout = scene.get("crank_shaft"), scene.get("crank_layout")
    if not shaft or not layout:
        raise ParameterError(f"{caller} needs a scene with crank_shaft and crank_layout "
                             "(the shaft's diameter and the planes of its bearings and discs)")
    za, zb = (float(z) for z in layout["bearings"])
    zd = np.asarray(layout["discs"], dtype=float)
    load = -np.asarray(eccentric_bearing_force, dtype=float)  # (..., cranks, discs, 2)
    # Reactions from the balance of forces and of moments about bearing a.
    rb = -np.einsum("...cka,k->...ca", load, zd - za) / (zb - za)
    ra = -load.sum(axis=-2) - rb
    planes = np.concatenate([[za, zb], zd])
    forces = np.concatenate([ra[..., None, :], rb[..., None, :], load], axis=-2)  # (..., c, planes, 2)
    # M(z) = sum over the forces left of z of F (z - z_j), at every plane.
    lever = np.clip(planes[None, :] - planes[:, None], 0.0, None)  # [at, from]
    moment = np.einsum("pj,...cja->...cpa", lever, forces)
    d = float(shaft["diameter"])
    return 32.0 * np.linalg.norm(moment, axis=-1).max(axis=-1) / (math.pi * d**3)  # type: ignore[no-any-return]


def static_safety(caller: str, family: str, peak: float, static: float, remedy: str) -> float:
    """ISO 76 static safety ``s0 = C0r / P0`` of the ``family`` bearings (peak radial load
    ``peak`` [N], static rating ``static`` [N]; inf at no load), with a ``RuntimeWarning`` naming
    ``caller`` and ``remedy`` below 1, where the raceways yield and the elastic roller law no
    longer holds. The warning points at the caller's caller."""
    s0 = static / peak if peak > 0 else math.inf
    if s0 < 1.0:
        warnings.warn(
            f"{caller}: the {family} bearings' peak load {peak / 1e3:.1f} kN exceeds their ISO 76 static "
            f"rating C0r = {static / 1e3:.1f} kN (static safety s0 = {s0:.2f} < 1): the raceways yield there "
            f"and the elastic roller law and the forces do not hold; {remedy}", RuntimeWarning, stacklevel=3)
    return s0


def families(scene: dict[str, Any], crank_force: NDArray[np.float64], eccentric_force: NDArray[np.float64],
             crank_layout: CrankLayout | None) -> list[tuple[str, float | None, float | None, NDArray[np.float64]]]:
    """The bearing families of a run or an LTCA of ``scene`` (a dict): name, ISO 281 rating
    ``C`` and ISO 76 static rating ``C0r`` [N] (None for a family without rollers) and forces
    (n, ..., 2) [N]: ``"eccentric"``, and ``"crank"`` or, split by ``crank_layout`` (default the
    scene's, :meth:`CrankLayout.of_scene`), ``"crank_a"`` and ``"crank_b"``, each rated as one
    row of ``crank_layout.roller_length``. ``ParameterError`` if no bearing has rollers."""
    compiled = _core.CompiledScene.from_json(json.dumps(scene))
    (c_ecc, c_crank), (s_ecc, s_crank) = compiled.bearing_ratings(), compiled.bearing_ratings("static")
    if c_ecc is None and c_crank is None:
        raise ParameterError(
            "no bearing of this scene is built from rollers, so there is no ISO 281 or ISO 76 rating: give "
            "joints.eccentric_bearing.rollers (and joints.crank_bearing.rollers), as Scene.physical does; "
            "the bearing forces are in eccentric_bearing_force and crank_bearing_force")
    out: list[tuple[str, float | None, float | None, NDArray[np.float64]]] = [
        ("eccentric", c_ecc, s_ecc, eccentric_force)]
    layout = crank_layout if crank_layout is not None else CrankLayout.of_scene(scene)
    if layout is None:
        out.append(("crank", c_crank, s_crank, crank_force))
    else:
        row = _core.CompiledScene.from_json(json.dumps(layout.row_scene(scene)))
        c_row, s_row = row.bearing_ratings()[1], row.bearing_ratings("static")[1]
        rows = layout.rows(crank_force, eccentric_force)
        out += [(f"crank_{side}", c_row, s_row, rows[..., j, :]) for j, side in enumerate("ab")]
    return out


#: One bearing family to rate (:func:`rate_lives`): name, ISO 281 rating ``C`` [N] and ISO 76
#: static rating ``C0r`` [N] (None without rollers), peak load [N], and per interval the load
#: [N] and the revolutions of the rings [-], shape (intervals, bearings...).
Family = tuple[str, float | None, float | None, float, NDArray[np.float64], NDArray[np.float64]]


def rate_lives(caller: str, families: list[Family], duration: float) -> dict[str, dict[str, float]]:
    """ISO 281 equivalent load and ``L10`` of the most loaded bearing (largest equivalent load)
    of each family, with the ISO 76 static safety of its peak (:func:`static_safety`), over a
    duty cycle of ``duration`` [s] (the hours); and, where the families hold a crank's two
    rows ``crank_a`` and ``crank_b``, ``crank_pair``: the worst crank's system life
    (Lundberg-Palmgren) and the smaller ``s0``. Families without ratings are left out. The
    entries are those :meth:`rvdyn.Result.bearing_life` documents."""
    out: dict[str, dict[str, float]] = {}
    crank_lives: dict[str, tuple[dict[tuple[int, ...], tuple[float, float]], NDArray[np.float64]]] = {}
    for name, rating, static, peak, load, rev in families:
        if rating is None or static is None:
            continue
        total = rev.sum(axis=0)
        # ISO 281 per bearing in the core: (equivalent load, L10); the worst is the largest load.
        lives = {j: _core.roller_bearing_life(rating, load[(slice(None),) + j].tolist(),
                                              rev[(slice(None),) + j].tolist())
                 for j in np.ndindex(*load.shape[1:])}
        crank_lives[name] = (lives, total)
        worst = max(lives, key=lambda j: lives[j][0])
        p, l10 = lives[worst]
        rpm = float(total[worst]) / duration * 60.0 if duration > 0 else 0.0
        s0 = static_safety(caller, name, peak, static,
                           "nor does the rating life; use larger bearings (joints.*.rollers) or a lower load")
        out[name] = {"peak_load": peak, "equivalent_load": p, "rating": float(rating),
                     "static_rating": float(static), "static_safety": s0,
                     "l10_million_revolutions": l10,
                     "l10_hours": l10 * 1e6 / (60.0 * rpm) if rpm > 0 else math.inf}
    if "crank_a" in crank_lives and "crank_b" in crank_lives:
        # A crank's two bearings fail as a system (Lundberg-Palmgren); the worst crank counts.
        (lives_a, total), (lives_b, _) = crank_lives["crank_a"], crank_lives["crank_b"]
        pair = {j: _core.roller_system_life([lives_a[j][1], lives_b[j][1]]) for j in lives_a}
        worst = min(pair, key=lambda j: pair[j])
        rpm = float(total[worst]) / duration * 60.0 if duration > 0 else 0.0
        out["crank_pair"] = {
            "static_safety": min(out["crank_a"]["static_safety"], out["crank_b"]["static_safety"]),
            "l10_million_revolutions": pair[worst],
            "l10_hours": pair[worst] * 1e6 / (60.0 * rpm) if rpm > 0 else math.inf}
    return out


def plot_family_loads(ax: Any, x: NDArray[np.float64], families: list[tuple[str, float, NDArray[np.float64]]],
                      xlabel: str, title: str) -> Any:
    """Draw, against ``x`` (n,), the largest load [kN] over the bearings of each family
    ``(name, C0r [N], forces (n, ..., 2) [N])`` and each C0r as a dashed line (one line per
    rating, black where families share it, as the crank's two rows do) into ``ax`` (None: a new
    figure); returns the figure."""
    from .plotting import new_figure

    fig, ax = new_figure((8.0, 4.5)) if ax is None else (ax.figure, ax)
    ratings: dict[float, list[int]] = {}  # one line per rating
    for k, (name, static, forces) in enumerate(families):
        mag = np.linalg.norm(forces, axis=-1).reshape(len(x), -1).max(axis=1)
        ax.plot(x, mag / 1e3, marker="." if len(x) < 50 else None, color=f"C{k}", label=name)
        ratings.setdefault(float(static), []).append(k)
    for static, ks in ratings.items():
        ax.axhline(static / 1e3, color=f"C{ks[0]}" if len(ks) == 1 else "k", ls="--", lw=0.8,
                   label=", ".join(families[k][0] for k in ks) + " C0r")
    ax.set_ylim(bottom=0.0)  # loads against ratings from zero: the margin is seen in proportion
    ax.set_xlabel(xlabel)
    ax.set_ylabel("load of the most loaded bearing [kN]")
    ax.set_title(title)
    ax.legend(fontsize="small")
    return fig
