"""Campbell diagram of a loaded reducer: natural frequencies over input speed with the
excitation orders and their crossings (docs/model.md, "Campbell diagram").

The paper's travel speeds 3.3-5.5 km/h map to input speeds by proportion: 3.3 km/h is the
paper's 8328 deg/s ([P] section 4.1), so 5.5 km/h is 13880 deg/s (:func:`travel_to_input_speed`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, Sequence

import numpy as np

from .. import _core
from ..errors import ParameterError
from .modes import _finite, _loaded_torque, _scene
from .._args import pair as _pair
from .._args import whole as _whole
from .spectrum import MAX_HARMONICS, ExcitationOrder

__all__ = ["CampbellDiagram", "Crossing", "campbell", "travel_to_input_speed", "PAPER_TRAVEL_RANGE_KMH"]

#: The paper's travel speed range [km/h] ([P] section 4.1).
PAPER_TRAVEL_RANGE_KMH = (3.3, 5.5)
_PAPER_INPUT_AT_3_3 = math.radians(8328.0)  # rad/s at 3.3 km/h
#: The paper's reducer ratio [-].
PAPER_RATIO = 57.0


def travel_to_input_speed(kmh: float | np.ndarray) -> Any:
    """Input speed [rad/s] of the paper's travel drive at a travel speed [km/h]: proportional,
    8328 deg/s at 3.3 km/h ([P] section 4.1; implied wheel radius 0.3595 m)."""
    return np.asarray(kmh, dtype=float) * (_PAPER_INPUT_AT_3_3 / 3.3)


@dataclass(frozen=True)
class Crossing:
    """An order line meeting a mode: input ``speed`` [rad/s], ``frequency`` [Hz], the
    ``order`` and the mode (``mode``: 0-based index into the diagram's modes)."""

    speed: float
    frequency: float
    order: ExcitationOrder
    mode: int
    #: The reducer's ratio (input over output speed) [-].
    ratio: float = PAPER_RATIO

    @property
    def travel_speed_kmh(self) -> float:
        """Travel speed [km/h] of the paper's drive (its wheel) with this reducer at this input
        speed: the output speed ``speed / |ratio|`` times the paper's wheel radius."""
        return self.speed / abs(self.ratio) * PAPER_RATIO * 3.3 / _PAPER_INPUT_AT_3_3


@dataclass
class CampbellDiagram:
    """Natural frequencies [Hz] (speeds, modes) over input ``speeds`` [rad/s] with the output
    torque [N m] at each speed, the damping ratios, the excitation orders and the crossings.
    Each frequency is that of the mode's matched damped eigenvalue(s), ``|lambda| / 2 pi``,
    where the mode resonates (the undamped frequency when unmatched; equal to it for
    proportional damping, as on the physical preset)."""

    speeds: np.ndarray
    torques: np.ndarray
    frequency: np.ndarray
    damping_ratio: np.ndarray
    modes: list[int]
    orders: list[ExcitationOrder]
    crossings: list[Crossing]
    crank_angle: float

    def table(self) -> list[dict[str, Any]]:
        """One row per crossing (input speed in rad/s and deg/s, travel speed of the paper's
        drive in km/h, frequency [Hz], order label, mode number, damping ratio there)."""
        rows = []
        for c in self.crossings:
            zeta = float(np.interp(c.speed, self.speeds, self.damping_ratio[:, c.mode]))
            rows.append({"input_speed_rad_s": c.speed, "input_speed_deg_s": math.degrees(c.speed),
                         "travel_speed_kmh": c.travel_speed_kmh, "frequency_hz": c.frequency,
                         "order": c.order.label, "order_value": c.order.order, "mode": c.mode + 1,
                         "damping_ratio": zeta})
        return rows

    def plot(self, ax: Any = None, max_frequency: float | None = None) -> Any:
        """Natural frequencies and order lines against the input speed [deg/s], crossings
        marked."""
        if ax is None:
            import matplotlib.pyplot as plt

            ax = plt.subplots(figsize=(9, 6))[1]
        deg = np.degrees(self.speeds)
        for m in range(self.frequency.shape[1]):
            ax.plot(deg, self.frequency[:, m], color="k", lw=1)
        # Line style by family, colour by harmonic: the 20-odd lines stay tellable apart.
        styles = {"pin_pass": "--", "sun_mesh": ":"}
        for i, o in enumerate(self.orders):
            f = o.order * self.speeds / (2 * math.pi)
            colour = f"C{(o.harmonic - 1) % 10}" if o.name in styles else "0.5"
            ax.plot(deg, f, ls=styles.get(o.name, "-."), lw=1.0, color=colour, label=o.label)
        if self.crossings:
            ax.plot([math.degrees(c.speed) for c in self.crossings], [c.frequency for c in self.crossings],
                    "o", mfc="none", color="r", label="crossings")
        top = max_frequency or 1.1 * float(self.frequency.max())
        ax.set(xlabel="input speed [deg/s]", ylabel="frequency [Hz]", ylim=(0, top),
               title=f"Campbell diagram (crank angle {self.crank_angle:.3g} rad)")
        ax.legend(fontsize="x-small", ncol=2, loc="upper left")
        return ax


def campbell(scene: Any, speeds: Sequence[float] | np.ndarray | None = None, *, power: float | None = None,
             torque: float | None = None, crank_angle: float = 0.0, harmonics: int = 8,
             frequency_range: tuple[float, float] | None = None, points: int = 200) -> CampbellDiagram:
    """Campbell diagram of ``scene`` over the input ``speeds`` [rad/s] (increasing; default
    ``points`` speeds over the paper's travel range 3.3-5.5 km/h at this reducer's ratio,
    145.4-242.3 rad/s at the paper's 57).

    The modes at each speed are those about the equilibrium at ``crank_angle`` [rad] under the
    output torque of that speed: constant ``torque`` [N m], or ``power`` [W] transmitted
    (``T = power x ratio / speed``), or (neither given) the scene's load torque. The models have
    no speed-dependent terms, so the speed enters through the torque only. ``frequency_range``
    [Hz] keeps the modes inside it (``ParameterError`` if none is); pin-pass and sun-mesh
    harmonics up to ``harmonics``. The default 8 is set by the ISO 6336 mesh stiffness: a
    rectangular wave between one and two tooth pairs, whose harmonics fall only as ``1/h``
    (4 and 7 are strong at the paper's contact ratio 1.63, and the 4th sun-mesh harmonic meets
    the physical preset's main mode at 9116 deg/s, 9 % above the paper's input speed). A zero
    torque or power is a ``ParameterError``: unloaded contacts have no stiffness."""
    scene = _scene(scene)
    n_harmonics = _whole("harmonics", harmonics, 1, MAX_HARMONICS)
    n = _whole("points", points, 2, 1_000_000)
    if speeds is None:
        # The paper's travel range at this reducer's ratio (the same wheel speeds).
        scale = abs(float(scene.ratio)) / PAPER_RATIO
        lo, hi = (scale * float(v) for v in travel_to_input_speed(np.array(PAPER_TRAVEL_RANGE_KMH)))
        speeds = np.linspace(lo, hi, n)
    try:
        w = np.asarray(speeds, dtype=float).ravel()
    except (OverflowError, TypeError, ValueError) as e:
        raise ParameterError(f"speeds must be input speeds [rad/s], a 1-D list of numbers: {e}") from e
    if w.size == 0:
        raise ParameterError("speeds is empty: give at least one input speed [rad/s]")
    if power is not None and torque is not None:
        raise ParameterError("give power or torque, not both")
    if power is not None:
        p = _finite("power", power, "W")
        with np.errstate(divide="ignore"):
            t = p * float(scene.ratio) / w
    else:
        t = np.full(w.shape, _loaded_torque(scene, torque, "campbell"))
    if not np.all(np.isfinite(t)):
        raise ParameterError("input speeds must be finite and > 0 rad/s")
    if np.any(t == 0.0):
        raise ParameterError("campbell about equilibria needs a load: power 0 W leaves the contacts without "
                             "load and every frequency would be round-off; give a power or torque")
    if frequency_range is not None:
        frequency_range = _pair("frequency_range", frequency_range, "Hz")
    d = _core.campbell_diagram(scene.to_json(), [float(x) for x in w], [float(x) for x in t],
                               _finite("crank_angle", crank_angle, "rad"), n_harmonics, frequency_range)
    orders = [ExcitationOrder(n, int(h), float(o), lab) for n, h, o, lab in d["orders"]]
    crossings = [Crossing(float(s), float(f), orders[int(o)], int(m), float(scene.ratio))
                 for s, f, o, m in d["crossings"]]
    return CampbellDiagram(w, t, np.asarray(d["frequency"]), np.asarray(d["damping_ratio"]), list(d["modes"]),
                           orders, crossings, float(crank_angle))
