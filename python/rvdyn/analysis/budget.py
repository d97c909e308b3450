"""The compliance budget: which parts of the loaded reducer its torsional compliance comes from
(docs/model.md, "Compliance budget")."""

from __future__ import annotations

import re
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, Sequence

import numpy as np

from .. import _core
from .._args import read_only, short
from ..errors import ParameterError
from .ltca import ARCMIN, MAX_POINTS, _float, _rated, _scene

if TYPE_CHECKING:  # pragma: no cover
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure

    from ..scene import Scene

__all__ = ["ComplianceBudget", "compliance_budget"]

_PINS = re.compile(r"pin contacts disc \d+")


@dataclass(frozen=True)
class ComplianceBudget:
    """Where the tangent torsional compliance of the loaded reducer comes from, at one crank
    angle over a set of output torques.

    ``torque`` (m,) [N m]; ``parts``: the coupling families (``"pin contacts disc 0"``, ...,
    ``"sun/planet meshes"``, ``"eccentric bearings"``, ``"crank bearings"``, those the scene
    has); ``compliance`` (m, parts) [rad/(N m)]: each family's part of the tangent compliance
    ``d twist / dT``, summing to it; ``torsional_stiffness`` (m,) [N m/rad]: the tangent
    ``dT / d twist``; ``split_error`` (m,): how far the parts' sum is from the whole
    (round-off); ``crank_angle`` [rad]. The first stage's parts are referred to the output
    (through the ratio squared), so they are small."""

    crank_angle: float
    torque: np.ndarray
    parts: tuple[str, ...]
    compliance: np.ndarray
    torsional_stiffness: np.ndarray
    split_error: np.ndarray

    def __post_init__(self) -> None:
        for name in ("torque", "compliance", "torsional_stiffness", "split_error"):
            object.__setattr__(self, name, read_only(np.asarray(getattr(self, name), dtype=float)))
        object.__setattr__(self, "parts", tuple(self.parts))

    @property
    def share(self) -> np.ndarray:
        """Each part's share of the compliance (m, parts) [-]; rows sum to 1."""
        return self.compliance * self.torsional_stiffness[:, None]  # type: ignore[no-any-return]

    @property
    def part_stiffness(self) -> np.ndarray:
        """Each part's equivalent torsional stiffness at the output ``1 / compliance`` (m,
        parts) [N m/rad]: the reducer's stiffness if every other part were rigid and the
        deflection shape stayed the same (the parts add up as springs in series)."""
        with np.errstate(divide="ignore"):
            return 1.0 / self.compliance

    def grouped(self) -> "ComplianceBudget":
        """The same budget with the discs' pin contacts summed into one part ``"pin
        contacts"`` (placed first)."""
        pins = [i for i, p in enumerate(self.parts) if _PINS.fullmatch(p)]
        if len(pins) <= 1:
            return self
        rest = [i for i in range(len(self.parts)) if i not in pins]
        comp = np.column_stack([self.compliance[:, pins].sum(axis=1)] + [self.compliance[:, i] for i in rest])
        return ComplianceBudget(crank_angle=self.crank_angle, torque=self.torque,
                                parts=("pin contacts",) + tuple(self.parts[i] for i in rest),
                                compliance=comp, torsional_stiffness=self.torsional_stiffness,
                                split_error=self.split_error)

    def predict(self, stiffer: dict[str, float]) -> np.ndarray:
        """The tangent torsional stiffness [N m/rad], shape (m,), predicted to first order when
        each part named in ``stiffer`` becomes that many times stiffer at the same loads
        (``{"crank bearings": 1.2}``; ``"pin contacts"`` stands for every disc's pins):
        ``1 / (c - sum_f c_f (1 - 1 / s_f))``, the parts in series with their loads held.
        The loads move a little in a changed scene: docs/model.md, "Compliance budget", gives
        measured differences (0.2-0.8 % of the change for 25 % longer bearing rollers); for large
        changes check the prediction with an analysis of the changed scene."""
        if not isinstance(stiffer, dict) or not stiffer:
            raise ParameterError(f"stiffer must be a non-empty dict of part name -> stiffness factor, got {short(stiffer)}")
        g = self.grouped()
        names = set(self.parts) | set(g.parts)
        if "pin contacts" in stiffer and any(_PINS.fullmatch(n) for n in stiffer):
            raise ParameterError('name either "pin contacts" or single discs\' pins, not both')
        drop = np.zeros(self.torque.size)
        for name, factor in stiffer.items():
            if name not in names:
                raise ParameterError(f"no part {name!r} in this budget: its parts are {', '.join(sorted(names))}")
            s = _float(f"stiffer[{name!r}]", factor, "-")
            if not 1e-12 <= s <= 1e12:
                raise ParameterError(f"stiffer[{name!r}] must be a stiffness factor in [1e-12, 1e12] (1e12 for "
                                     f"a part made rigid), got {s}")
            part = g.compliance[:, g.parts.index(name)] if name in g.parts else \
                self.compliance[:, self.parts.index(name)]
            drop += part * (1.0 - 1.0 / s)
        return 1.0 / (1.0 / self.torsional_stiffness - drop)

    def _index(self, index: int) -> int:
        m = self.torque.size
        if isinstance(index, bool) or not isinstance(index, (int, np.integer)) or not -m <= int(index) < m:
            raise ParameterError(f"index must be a whole number in [-{m}, {m}) (one per torque), got {short(index)}")
        return int(index) % m

    def table(self, index: int = -1) -> list[dict[str, Any]]:
        """One row per part at torque ``index`` (default the last), largest share first:
        ``part``, ``share`` [-], ``compliance_arcmin_per_kNm`` [arcmin/(kN m)] and
        ``stiffness_Nm_per_arcmin`` [N m/arcmin] (the part's equivalent stiffness)."""
        i = self._index(index)
        order = np.argsort(-self.compliance[i])
        return [{"part": self.parts[j], "share": float(self.share[i, j]),
                 "compliance_arcmin_per_kNm": float(self.compliance[i, j] * 1e3 / ARCMIN),
                 "stiffness_Nm_per_arcmin": float(self.part_stiffness[i, j] * ARCMIN)} for j in order]

    def where(self, index: int = -1) -> str:
        """The parts at torque ``index`` with their shares, largest first, the discs' pins
        together, e.g. ``"eccentric bearings 48 %, pin contacts 31 %, ..."``."""
        g = self.grouped()
        i = g._index(index)
        return ", ".join(f"{r['part']} {100 * r['share']:.1f} %" for r in g.table(i))

    def summary(self, index: int = -1) -> dict[str, Any]:
        """At torque ``index``: the torque [N m], tangent stiffness [N m/arcmin] and each part's
        share (discs' pins together)."""
        g = self.grouped()
        i = g._index(index)
        return {"torque_Nm": float(g.torque[i]),
                "tangent_stiffness_Nm_per_arcmin": float(g.torsional_stiffness[i] * ARCMIN),
                "share": {p: float(s) for p, s in zip(g.parts, g.share[i])}}

    def __repr__(self) -> str:
        return (f"ComplianceBudget(crank_angle={self.crank_angle:.6g} rad, torques={self.torque.size}, "
                f"at {self.torque[-1]:.6g} N m: {self.where()})")

    def plot(self, ax: Axes | None = None) -> Figure:
        """The shares [%] of the parts (discs' pins together): bars at one torque, stacked
        areas against the torque [kN m] for several."""
        from ..plotting import new_figure

        g = self.grouped()
        fig, ax = new_figure((8.0, 4.5)) if ax is None else (ax.figure, ax)
        share = 100.0 * g.share
        if g.torque.size == 1:
            ax.barh(list(g.parts), share[0])
            ax.set_xlabel("share of the torsional compliance [%]")
            ax.invert_yaxis()
        else:
            order = np.argsort(g.torque)
            ax.stackplot(g.torque[order] / 1e3, share[order].T, labels=list(g.parts))
            ax.set_xlabel("output torque [kN m]")
            ax.set_ylabel("share of the torsional compliance [%]")
            ax.set_ylim(min(0.0, float(share.min())), max(100.0, float(share.sum(axis=1).max())))
            ax.legend(loc="center left", bbox_to_anchor=(1.01, 0.5), fontsize="small")
        ax.set_title(f"compliance budget at crank angle {self.crank_angle:.3g} rad\ntangent stiffness "
                     f"{g.torsional_stiffness[-1] * ARCMIN:.0f} N m/arcmin at {g.torque[-1] / 1e3:.3g} kN m",
                     fontsize="medium")
        return fig  # type: ignore[return-value]


def compliance_budget(scene: Scene, torque: float | Sequence[float] | np.ndarray | None = None,
                      crank_angle: float = 0.0) -> ComplianceBudget:
    """The compliance budget of ``scene`` at ``crank_angle`` [rad] with the input held, under
    the output ``torque`` [N m] (a number or a 1-D sequence; default the scene's constant load):
    each coupling family's part of the tangent torsional compliance ``d twist / dT``, from the
    frictionless LTCA equilibrium (docs/model.md, "Compliance budget"). Several torques are
    solved in turn, each warm-started from the previous.

    Raises ``ParameterError`` for a torque that is zero (the tangent inside the clearances is
    not defined: use a small torque) or not finite, ``ConvergenceError`` when there is no
    equilibrium or its tangent is singular (a body free in its clearances)."""
    sc = _scene(scene)
    if torque is None or np.ndim(torque) == 0:
        torques = np.array([_rated(sc, torque)])  # type: ignore[arg-type]
    else:
        try:
            torques = np.asarray(torque, dtype=float)
        except (OverflowError, TypeError, ValueError) as e:
            raise ParameterError(f"torque must be real numbers [N m]: {e}") from e
        if torques.ndim != 1 or torques.size == 0:
            raise ParameterError(f"torque must be a number or a non-empty 1-D sequence [N m], got shape {torques.shape}")
        if torques.size > MAX_POINTS:
            raise ParameterError(f"torque has {torques.size} values, more than the {MAX_POINTS} one analysis takes")
        if not np.all(np.isfinite(torques)):
            raise ParameterError("torque must be finite numbers [N m]")
    psi = _float("crank_angle", crank_angle, "rad")
    d = _core.LtcaSolver(sc._compiled, 1e-12).compliance_budget(torques.tolist(), psi)
    return ComplianceBudget(crank_angle=psi, torque=torques.copy(), parts=tuple(d["parts"]),
                            compliance=d["compliance"], torsional_stiffness=d["torsional_stiffness"],
                            split_error=d["split_error"])
