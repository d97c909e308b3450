"""Linearised modes about a loaded equilibrium and the Campbell diagram (docs/model.md,
"Modes about a loaded equilibrium", "Excitation orders")."""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np

from .. import _core
from ..errors import ParameterError
from ..scene import Scene
from .ltca import _float, _rated, _scene

if TYPE_CHECKING:  # pragma: no cover
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure

__all__ = ["Modes", "Campbell", "modes", "campbell"]


@dataclass(frozen=True)
class Modes:
    """Modes about the equilibrium at ``crank_angle`` [rad] under ``torque`` [N m]:
    ``frequency`` (m,) [Hz], ``damping_ratio`` (m,), ``shape`` (m, dofs) mass-normalised,
    ``energy`` (m, families) strain-energy shares, names in ``dofs`` and ``families``."""

    crank_angle: float
    torque: float
    dofs: list[str]
    families: list[str]
    mass: np.ndarray
    frequency: np.ndarray
    damping_ratio: np.ndarray
    shape: np.ndarray
    energy: np.ndarray

    def table(self) -> list[dict[str, Any]]:
        """One row per mode: frequency, damping ratio, the dominant degree of freedom (largest
        kinetic energy share) and the energy share of each family."""
        rows = []
        for i, f in enumerate(self.frequency):
            kin = self.shape[i] ** 2 * self.mass
            rows.append({"mode": i + 1, "frequency_Hz": float(f), "damping_ratio": float(self.damping_ratio[i]),
                         "dominant_dof": self.dofs[int(np.argmax(kin))],
                         **{fam: float(self.energy[i, j]) for j, fam in enumerate(self.families)}})
        return rows


@dataclass(frozen=True)
class Campbell:
    """Natural frequencies [Hz] against input speed [rad/s] with the excitation orders
    (multiples of the input rotation frequency) and their crossings."""

    speeds: np.ndarray
    frequencies: np.ndarray
    orders: list[tuple[str, float]]
    crossings: list[dict[str, Any]]

    def plot(self, ax: Axes | None = None) -> Figure:
        """Campbell diagram: horizontal natural frequencies, order lines, crossings marked."""
        from ..plotting import new_figure

        fig, ax = new_figure((8.0, 5.5)) if ax is None else (ax.figure, ax)
        rpm = self.speeds * 60.0 / (2.0 * math.pi)
        for f in self.frequencies:
            ax.axhline(f, color="0.6", lw=0.8)
        for name, order in self.orders:
            ax.plot(rpm, order * self.speeds / (2.0 * math.pi), label=f"{name} ({order:.3f})")
        for c in self.crossings:
            ax.plot(c["input_speed"] * 60.0 / (2.0 * math.pi), c["frequency"], "kx")
        ax.set_xlabel("input speed [rpm]")
        ax.set_ylabel("frequency [Hz]")
        ax.set_ylim(0.0, 1.1 * float(np.max(self.frequencies)) if self.frequencies.size else 1.0)
        ax.legend(fontsize="small")
        ax.set_title("Campbell diagram")
        return fig  # type: ignore[return-value]


def modes(scene: Scene, torque: float | None = None, crank_angle: float = 0.0) -> Modes:
    """Modes of ``scene`` linearised about its LTCA equilibrium at ``crank_angle`` [rad] under
    ``torque`` [N m] (default: the scene's constant load), input held."""
    sc = _scene(scene)
    d = _core.modes(sc._compiled, _rated(sc, torque), _float("crank_angle", crank_angle, "rad"))
    return Modes(crank_angle=float(crank_angle), torque=float(d["torque"]), dofs=list(d["dofs"]),
                 families=list(d["families"]), mass=d["mass"], frequency=d["frequency"],
                 damping_ratio=d["damping_ratio"], shape=d["shape"], energy=d["energy"])


def campbell(scene: Scene, speeds: Any, torque: float | None = None, crank_angle: float = 0.0) -> Campbell:
    """Campbell diagram of ``scene`` over the input ``speeds`` [rad/s] (the natural frequencies
    of the linearised model at ``crank_angle`` do not depend on the speed)."""
    sc = _scene(scene)
    w = np.asarray(speeds, dtype=float)
    if w.ndim != 1 or w.size < 2 or not np.all(np.isfinite(w)) or np.any(w < 0):
        raise ParameterError("speeds must be a 1-D array of at least 2 finite input speeds >= 0 [rad/s]")
    m = modes(sc, torque, crank_angle)
    orders = [(str(n), float(o)) for n, o in _core.excitation_orders(sc._compiled)]
    crossings = [dict(c) for c in _core.campbell_crossings(m.frequency.tolist(), orders, float(w.min()),
                                                            float(w.max()))]
    return Campbell(speeds=w, frequencies=m.frequency, orders=orders, crossings=crossings)
