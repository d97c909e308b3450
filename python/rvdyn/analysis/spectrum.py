"""Order spectra of dynamic runs: which excitation of the reducer a ripple comes from.

:func:`order_spectrum` takes any recorded channel of a :class:`rvdyn.Result` over a steady
window and returns its amplitude spectrum with the peaks labelled by the nearest excitation order
of the scene (docs/model.md, "Excitation orders"; :func:`excitation_orders`).

Two ways to get the spectrum (docs/model.md, "Order spectra"):

- ``domain="time"``: FFT of the uniformly sampled channel with a periodic Hann window,
  amplitude-corrected by the window's coherent gain (``2 |X_k| / sum(w)``, Harris 1978); each
  peak's frequency and amplitude are interpolated between bins with the Hann-window formula of
  Grandke (1983). Orders are the frequencies over the mean input rotation frequency.
- ``domain="angle"`` (order tracking): the channel is resampled uniformly in the input angle
  (computed order tracking, Fyfe & Munck 1997) before the FFT, so an order stays sharp while
  the speed varies; bins are orders directly (``1/R`` apart for ``R`` input revolutions).
"""

from __future__ import annotations

import json
import math
import re
from dataclasses import dataclass, field
from typing import Any, Sequence

import numpy as np

from .. import _core
from ..errors import ParameterError
from .._args import pair as _pair
from .._args import real as _real
from .._args import whole as _whole

__all__ = ["ExcitationOrder", "SpectrumPeak", "OrderSpectrum", "excitation_orders", "order_spectrum",
           "plot_order_spectrum"]

#: The most harmonics of each excitation family (the core's limit).
MAX_HARMONICS: int = 10_000


@dataclass(frozen=True)
class ExcitationOrder:
    """One excitation of the reducer: ``order`` x the input rotation frequency.

    name: family (``"output"``, ``"crank"``, ``"crank_relative"``, ``"input"``, ``"pin_pass"``,
    ``"sun_mesh"``); harmonic: 1 for the fundamental; label: e.g. ``"pin pass x2"``."""

    name: str
    harmonic: int
    order: float
    label: str

    def frequency(self, input_speed: float) -> float:
        """Frequency [Hz] at the input speed ``input_speed`` [rad/s]."""
        return self.order * abs(float(input_speed)) / (2 * math.pi)


@dataclass(frozen=True)
class SpectrumPeak:
    """A peak of an order spectrum: ``frequency`` [Hz] and ``order`` (interpolated between
    bins), ``amplitude`` (of the sinusoid, in the channel's unit), and the nearest excitation
    order within the tolerance (``excitation``, ``label``; ``None`` if there is none)
    with the relative distance ``order_error = order / excitation.order - 1``."""

    frequency: float
    order: float
    amplitude: float
    excitation: ExcitationOrder | None
    order_error: float | None

    @property
    def label(self) -> str | None:
        """The nearest excitation order's label (e.g. ``"pin pass x2"``), ``None`` if none."""
        return None if self.excitation is None else self.excitation.label


@dataclass
class OrderSpectrum:
    """Amplitude spectrum of one channel over a window.

    frequency [Hz], order [-] and amplitude [channel unit] are arrays of the same length (one
    per FFT bin); ``input_frequency`` [Hz] is the mean input rotation frequency over the window;
    ``peaks`` the largest peaks, largest first, labelled with ``orders``."""

    channel: str
    unit: str
    domain: str
    window: tuple[float, float]
    input_frequency: float
    frequency: np.ndarray
    order: np.ndarray
    amplitude: np.ndarray
    peaks: list[SpectrumPeak]
    orders: list[ExcitationOrder] = field(default_factory=list)

    @property
    def resolution(self) -> float:
        """Bin spacing [Hz]."""
        return float(self.frequency[1] - self.frequency[0])

    def peak(self, label: str) -> SpectrumPeak:
        """The largest peak labelled ``label`` (e.g. ``"pin pass"``); ``ParameterError`` if
        none is."""
        for p in self.peaks:
            if p.label == label:
                return p
        found = sorted({p.label for p in self.peaks if p.label})
        raise ParameterError(f"no peak labelled {label!r}; labelled peaks: {found}")

    def table(self) -> list[dict[str, Any]]:
        """The peaks as rows (frequency [Hz], order, amplitude, label, order_error)."""
        return [{"frequency": p.frequency, "order": p.order, "amplitude": p.amplitude, "label": p.label,
                 "order_error": p.order_error} for p in self.peaks]

    def plot(self, ax: Any = None, x: str = "frequency", **kwargs: Any) -> Any:
        """Plot with :func:`plot_order_spectrum`."""
        return plot_order_spectrum(self, ax=ax, x=x, **kwargs)


def excitation_orders(scene: Any, harmonics: int = 3) -> list[ExcitationOrder]:
    """Excitation orders of ``scene`` (an :class:`rvdyn.Scene`, its dict or JSON text), by
    increasing order, with the pin-pass and sun-mesh harmonics 1..``harmonics``
    (docs/model.md, "Excitation orders")."""
    text = _scene_json(scene)
    h_max = _whole("harmonics", harmonics, 1, MAX_HARMONICS)
    return [ExcitationOrder(n, int(h), float(o), lab) for n, h, o, lab in _core.excitation_orders(text, h_max)]


def _scene_json(scene: Any) -> str:
    if hasattr(scene, "to_json"):
        return str(scene.to_json())
    if isinstance(scene, dict):
        if not scene:
            raise ParameterError("the result carries no scene: give orders=... or a result from rvdyn.simulate")
        return json.dumps(scene)
    if isinstance(scene, str):
        return scene
    raise ParameterError(f"scene must be an rvdyn.Scene, a dict or JSON text, got {type(scene).__name__}")


def _unit(channel: str) -> str:
    from .. import result

    specs = getattr(result, "CHANNEL_SPECS", None)
    if isinstance(specs, dict) and channel in specs:
        return str(specs[channel].get("unit", ""))
    m = re.search(r"\[([^\]]*)\]", str(getattr(result, "CHANNELS", {}).get(channel, "")))
    return m.group(1) if m else ""


def _input_angle(result: Any) -> np.ndarray:
    """The input rotation angle [rad]: the sun's, or the crank's without a first stage."""
    if result.scene.get("stage1") is not None:
        return np.asarray(result.sun_angle, dtype=float)
    return np.asarray(result.crank_angle, dtype=float)[:, 0]


def order_spectrum(result: Any, channel: str, window: tuple[float, float] | None = None, *,
                   index: int | Sequence[int] | None = None, domain: str = "time", harmonics: int = 10,
                   tolerance: float = 0.01, peaks: int = 10, threshold: float = 1e-3,
                   detrend: str = "mean", orders: Sequence[ExcitationOrder] | None = None) -> OrderSpectrum:
    """Amplitude spectrum of ``result``'s channel ``channel`` over ``window`` = (t0, t1) [s],
    with its peaks labelled by the scene's excitation orders.

    window: default the steady window of :meth:`Result.steady_window` (whole crank revolutions
    from 20 % of the run). index: for a channel with more than one value per sample, which one
    (e.g. ``index=(0, 5)`` for ``pin_force`` of disc 0, pin 6). domain: ``"time"`` (Hann-windowed
    FFT) or ``"angle"`` (order tracking: resampled uniformly in the input angle).
    detrend: ``"mean"`` or ``"linear"`` (for angles). peaks: how many peaks to return (largest
    first) among the local maxima above ``threshold`` x the largest. tolerance: a peak gets the
    label of the nearest excitation order (pin-pass and sun-mesh harmonics up to ``harmonics``)
    within ``max(tolerance x order, one bin)``. orders: give your own instead of the scene's.

    Returns an :class:`OrderSpectrum` (frequencies in Hz, amplitudes in the channel's unit).
    Raises :class:`rvdyn.ParameterError` for an unknown channel, a missing index, a window
    outside the run or too short, non-uniform sampling, or a run whose input does not turn.
    """
    if domain not in ("time", "angle"):
        raise ParameterError(f"domain must be 'time' or 'angle', got {domain!r}")
    if detrend not in ("mean", "linear"):
        raise ParameterError(f"detrend must be 'mean' or 'linear', got {detrend!r}")
    if not (isinstance(peaks, (int, np.integer)) and peaks >= 1):
        raise ParameterError(f"peaks must be a whole number >= 1, got {peaks!r}")
    tolerance = _real("tolerance", tolerance)
    if not tolerance >= 0:
        raise ParameterError(f"tolerance must be finite and >= 0, got {tolerance}")
    threshold = _real("threshold", threshold)
    if not 0 <= threshold < 1:
        raise ParameterError(f"threshold must be in [0, 1), got {threshold}")
    if orders is not None:
        if isinstance(orders, (str, bytes)) or not isinstance(orders, Sequence):
            raise ParameterError(f"orders must be a list of rvdyn.ExcitationOrder, got {type(orders).__name__}")
        wrong = [o for o in orders if not isinstance(o, ExcitationOrder)]
        if wrong:
            raise ParameterError(
                f"orders must be rvdyn.ExcitationOrder values (e.g. from excitation_orders(scene)), got {wrong[0]!r}")
    try:
        data = np.asarray(getattr(result, channel), dtype=float)
    except AttributeError as e:
        raise ParameterError(f"cannot take the spectrum of {channel!r}: {e}") from None
    if data.ndim > 1:
        if index is None:
            raise ParameterError(
                f"channel {channel!r} has shape {data.shape}: pick one series with index=(...) for the axes after time")
        idx = (index,) if isinstance(index, (int, np.integer)) else tuple(index)
        try:
            data = data[(slice(None),) + idx]
        except IndexError as e:
            raise ParameterError(f"index {index!r} does not fit channel {channel!r} of shape {data.shape}: {e}") from None
        if data.ndim != 1:
            raise ParameterError(f"index {index!r} leaves shape {data.shape[1:]} per sample; give one index per axis")
        channel_name = f"{channel}[{', '.join(str(int(i)) for i in idx)}]"
    else:
        if index is not None:
            raise ParameterError(f"channel {channel!r} has one value per sample: leave index=None")
        channel_name = channel
    t = np.asarray(result.t, dtype=float)
    t0, t1 = result.steady_window() if window is None else _pair("window", window, "s")
    if not (math.isfinite(t0) and math.isfinite(t1) and t[0] <= t0 < t1 <= t[-1] + 1e-12):
        raise ParameterError(f"window ({t0}, {t1}) s must lie inside the run [{t[0]}, {t[-1]}] s with t0 < t1")
    sel = (t >= t0 - 1e-12) & (t <= t1 + 1e-12)
    ts, xs = t[sel], data[sel]
    if len(ts) < 16:
        raise ParameterError(f"the window ({t0}, {t1}) s holds {len(ts)} samples; at least 16 are needed")
    if not np.all(np.isfinite(xs)):
        raise ParameterError(f"channel {channel!r} is not finite in the window")
    dt = np.diff(ts)
    if np.ptp(dt) > 1e-6 * dt.mean():
        raise ParameterError("the samples are not uniformly spaced in the window; record with a fixed record_interval")
    theta = _input_angle(result)[sel]
    turns = abs(theta[-1] - theta[0]) / (2 * math.pi)
    f_in = turns / (ts[-1] - ts[0])
    if not f_in > 0:
        raise ParameterError("the input does not turn in the window: orders are undefined")
    if orders is None:
        orders = excitation_orders(result.scene, harmonics)
    orders = list(orders)

    n = len(xs)
    if domain == "angle":
        if np.any(np.diff(theta) * np.sign(theta[-1] - theta[0]) <= 0):
            raise ParameterError("the input angle is not monotonic in the window: order tracking needs a turning input")
        a = np.abs(theta - theta[0])
        grid = np.linspace(0.0, a[-1], n, endpoint=False)
        xs = np.interp(grid, a, xs)
        abscissa = grid
    else:
        abscissa = ts - ts[0]
    if detrend == "linear":
        xs = xs - np.polyval(np.polyfit(abscissa, xs, 1), abscissa)
    else:
        xs = xs - xs.mean()
    w = 0.5 - 0.5 * np.cos(2 * math.pi * np.arange(n) / n)  # periodic Hann
    spec = np.abs(np.fft.rfft(xs * w)) * 2.0 / w.sum()
    spec[0] *= 0.5
    if domain == "angle":
        order = np.arange(len(spec)) / (n * (grid[1] - grid[0]) / (2 * math.pi))
        freq = order * f_in
    else:
        freq = np.fft.rfftfreq(n, float(dt.mean()))
        order = freq / f_in
    found = _peaks(spec, peaks, threshold)
    out = []
    d_order = float(order[1] - order[0])
    for k, delta, amp in found:
        o = float(order[k] + delta * d_order)
        exc, err = _label(o, orders, tolerance, d_order)
        out.append(SpectrumPeak(float(o * f_in), o, amp, exc, err))
    return OrderSpectrum(channel_name, _unit(channel),
                         domain, (float(ts[0]), float(ts[-1])), float(f_in), freq, order, spec, out, orders)


def _peaks(spec: np.ndarray, count: int, threshold: float) -> list[tuple[int, float, float]]:
    """Local maxima (bin, offset in bins, corrected amplitude), largest first. Hann-window
    interpolation after Grandke (1983): with ``a`` the ratio of the larger neighbour to the
    peak bin, the offset is ``d = (2a - 1)/(a + 1)`` towards that neighbour and the amplitude
    ``A = |X_k| pi d (1 - d^2) / sin(pi d)``."""
    if len(spec) < 4:
        return []
    body = spec[2:-1]
    top = body.max() if len(body) else 0.0
    if top <= 0:
        return []
    ks = [k for k in range(2, len(spec) - 1)
          if spec[k] > spec[k - 1] and spec[k] >= spec[k + 1] and spec[k] >= threshold * top]
    res = []
    for k in ks:
        right = spec[k + 1] >= spec[k - 1]
        a = (spec[k + 1] if right else spec[k - 1]) / spec[k]
        d = (2 * a - 1) / (a + 1)
        d = min(max(d, 0.0), 1.0) * (1 if right else -1)
        corr = 1.0 if abs(d) < 1e-12 else math.pi * d * (1 - d * d) / math.sin(math.pi * d)
        res.append((k, d, float(spec[k] * corr)))
    res.sort(key=lambda r: -r[2])
    return res[:count]


def _label(order: float, orders: Sequence[ExcitationOrder], tolerance: float,
           bin_width: float) -> tuple[ExcitationOrder | None, float | None]:
    best, best_d = None, math.inf
    for e in orders:
        d = abs(order - e.order)
        if d <= max(tolerance * e.order, bin_width) and d < best_d:
            best, best_d = e, d
    if best is None:
        return None, None
    return best, order / best.order - 1.0


def plot_order_spectrum(spectrum: OrderSpectrum, ax: Any = None, x: str = "frequency", log: bool = True,
                        max_frequency: float | None = None, show_orders: bool = True) -> Any:
    """Amplitude against frequency [Hz] (``x="frequency"``) or order (``x="order"``), with the
    excitation orders as dashed lines and the labelled peaks annotated. ``max_frequency`` [Hz]
    limits the axis (default: a little beyond the highest labelled or largest peak)."""
    if x not in ("frequency", "order"):
        raise ParameterError(f"x must be 'frequency' or 'order', got {x!r}")
    if ax is None:
        import matplotlib.pyplot as plt

        ax = plt.subplots(figsize=(9, 4))[1]
    scale = 1.0 if x == "frequency" else 1.0 / spectrum.input_frequency
    xs = spectrum.frequency * scale
    hi = max_frequency
    if hi is None:
        hi = 1.25 * max([p.frequency for p in spectrum.peaks] or [float(spectrum.frequency[-1])])
    keep = spectrum.frequency <= hi
    (ax.semilogy if log else ax.plot)(xs[keep], spectrum.amplitude[keep], lw=0.8, color="C0")
    if show_orders:
        for i, e in enumerate(spectrum.orders):
            f = e.order * spectrum.input_frequency
            if f <= hi:
                ax.axvline(f * scale, color=f"C{1 + i % 8}", ls="--", lw=0.6, alpha=0.7)
    for p in spectrum.peaks:
        if p.label and p.frequency <= hi:
            ax.annotate(f"{p.label}\n{p.frequency:.1f} Hz", (p.frequency * scale, p.amplitude), fontsize=7,
                        xytext=(3, 3), textcoords="offset points")
    unit = f" [{spectrum.unit}]" if spectrum.unit else ""
    ax.set(xlabel="frequency [Hz]" if x == "frequency" else "order of the input",
           ylabel=f"amplitude{unit}",
           title=f"{spectrum.channel}, {spectrum.window[0]:.3g}-{spectrum.window[1]:.3g} s, "
                 f"input {spectrum.input_frequency:.2f} Hz")
    return ax
