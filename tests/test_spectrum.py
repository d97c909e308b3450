"""Order spectra of dynamic runs (rvdyn.order_spectrum, docs/model.md "Order spectra")."""

from __future__ import annotations

import math

import matplotlib

matplotlib.use("Agg")

import numpy as np
import pytest

import rvdyn
from rvdyn.analysis.spectrum import ExcitationOrder, excitation_orders, order_spectrum

W_IN = math.radians(8328.0)  # the paper's input speed [rad/s]
F_IN = 8328.0 / 360.0  # its rotation frequency [Hz]
PIN_PASS = 552 / 57  # docs/model.md, Excitation orders


def _fake(t: np.ndarray, theta: np.ndarray, channel: np.ndarray) -> rvdyn.Result:
    """A Result with the input angle and one channel (carrier_speed), paper scene attached."""
    dtheta = np.gradient(theta, t)
    arrays = {"t": t, "sun_angle": theta, "sun_speed": dtheta, "carrier_speed": channel,
              "pin_force": np.zeros((len(t), 2, 24))}
    return rvdyn.Result(arrays, {}, rvdyn.Scene.paper("rated").to_dict())


def test_orders_of_the_paper_scene() -> None:
    o = {(e.name, e.harmonic): e for e in excitation_orders(rvdyn.Scene.paper(), harmonics=2)}
    assert o["pin_pass", 1].order == pytest.approx(PIN_PASS, rel=1e-14)
    assert o["pin_pass", 2].label == "pin pass x2"
    assert o["sun_mesh", 1].order == pytest.approx(1008 / 57, rel=1e-14)
    assert o["crank", 1].order == pytest.approx(23 / 57, rel=1e-14)
    assert o["pin_pass", 1].frequency(W_IN) == pytest.approx(224.03, abs=0.005)
    single = excitation_orders(rvdyn.Scene.paper().replace(stage1=None, drive={"kind": "speed", "speed": 10.0,
                                                                                "start": "step"}))
    assert {e.name for e in single} == {"output", "crank", "crank_relative", "pin_pass"}


def test_two_tones_give_their_frequency_amplitude_and_label() -> None:
    # Two sinusoids at the pin-pass order and twice the sun-mesh order, not on bins. The
    # Hann-window interpolation (Grandke 1983) recovers a lone tone's frequency and amplitude up
    # to the O(1/N^2) difference between the DFT kernel and its continuous approximation and the
    # sidelobe leakage of the other tone (Hann sidelobes fall as 1/k^3); measured
    # errors are 4e-9 bin and 1e-9 relative, the tolerances 1e-3 leave a wide margin.
    t = np.arange(0, 0.8, 1e-4)
    f1, f2 = PIN_PASS * F_IN, 2 * 1008 / 57 * F_IN
    x = 2.55 + 0.01 * np.sin(2 * np.pi * f1 * t + 0.3) + 0.003 * np.cos(2 * np.pi * f2 * t - 1.0)
    res = _fake(t, W_IN * t, x)
    spec = order_spectrum(res, "carrier_speed", window=(0.0, float(t[-1])))
    assert spec.input_frequency == pytest.approx(F_IN, rel=1e-12)
    assert spec.unit == "rad/s"
    p1, p2 = spec.peaks[:2]
    df = spec.resolution
    assert p1.label == "pin pass" and p2.label == "sun mesh x2"
    assert abs(p1.frequency - f1) < 1e-3 * df and abs(p2.frequency - f2) < 1e-3 * df
    assert p1.amplitude == pytest.approx(0.01, rel=1e-3)
    assert p2.amplitude == pytest.approx(0.003, rel=1e-3)
    assert abs(p1.order_error) < 1e-4
    assert spec.peak("sun mesh x2") is p2
    with pytest.raises(rvdyn.ParameterError, match="no peak labelled 'crank'"):
        spec.peak("crank")


def test_order_tracking_keeps_an_order_sharp_while_the_speed_varies() -> None:
    # The input speed swings +-20 % at 2 Hz; a response locked to the input angle at the
    # pin-pass order smears over ~+-45 Hz in time but is one line in the angle domain. The
    # channel is resampled linearly in angle (about 45 samples per period of the order): the
    # amplitude error of linear interpolation is below h^2/8 ~ 2.5e-3 (measured 1.7e-3); 1e-2
    # leaves a margin.
    t = np.arange(0, 1.0, 1e-4)
    theta = W_IN * t + 0.2 * W_IN / (2 * np.pi * 2.0) * (1 - np.cos(2 * np.pi * 2.0 * t))
    x = 0.5 * np.sin(PIN_PASS * theta)
    res = _fake(t, theta, x)
    spec = order_spectrum(res, "carrier_speed", window=(0.0, float(t[-1])), domain="angle")
    p = spec.peaks[0]
    assert p.label == "pin pass"
    assert p.order == pytest.approx(PIN_PASS, rel=1e-4)
    assert p.amplitude == pytest.approx(0.5, rel=1e-2)
    smeared = order_spectrum(res, "carrier_speed", window=(0.0, float(t[-1])))
    assert smeared.peaks[0].amplitude < 0.5 * p.amplitude


def test_rated_paper_run_ripple_is_labelled_pin_pass() -> None:
    # docs/model.md, Excitation orders: the rated run's output-speed ripple is at the pin-pass
    # frequency 224.03 Hz with harmonics at 448 and 672 Hz. 1 s from rest, window [0.2, 1] s
    # (bins of 1.25 Hz): the three largest peaks carry those labels, at frequencies within 0.05
    # Hz of the orders (measured 224.028, 448.056, 672.084 Hz; the interpolation's accuracy
    # for a lone tone is far better, the margin covers the run's own slow drift).
    res = rvdyn.simulate(rvdyn.Scene.paper("rated"), 1.0, channels=["motion"])
    spec = rvdyn.order_spectrum(res, "carrier_speed", window=(0.2, 1.0))
    assert spec.input_frequency == pytest.approx(F_IN, rel=1e-6)
    labels = [p.label for p in spec.peaks[:3]]
    assert labels == ["pin pass", "pin pass x2", "pin pass x3"]
    for h, p in zip((1, 2, 3), spec.peaks[:3]):
        assert p.frequency == pytest.approx(h * PIN_PASS * F_IN, abs=0.05)
    # The ripple amplitude: half the 0.62 deg/s peak-to-peak of the docs, within 10 % (the
    # harmonics add to the peak-to-peak).
    assert math.degrees(spec.peaks[0].amplitude) == pytest.approx(0.29, rel=0.1)
    assert all(p.label != "sun mesh" for p in spec.peaks)
    assert res.spectrum("carrier_speed", (0.2, 1.0)).peaks[0].label == "pin pass"
    # Order tracking gives the same orders.
    tracked = rvdyn.order_spectrum(res, "carrier_speed", window=(0.2, 1.0), domain="angle")
    assert [p.label for p in tracked.peaks[:3]] == labels
    ax = spec.plot()
    assert ax.get_xlabel() == "frequency [Hz]"
    assert spec.plot(x="order").get_xlabel() == "order of the input"


def test_bad_requests_say_what_is_wrong() -> None:
    t = np.arange(0, 0.1, 1e-4)
    res = _fake(t, W_IN * t, np.sin(t))
    with pytest.raises(rvdyn.ParameterError, match=r"shape \(1000, 2, 24\): pick one series"):
        order_spectrum(res, "pin_force", window=(0, 0.09))
    spec = order_spectrum(res, "pin_force", window=(0, 0.09), index=(0, 5))
    assert spec.channel == "pin_force[0, 5]"
    with pytest.raises(rvdyn.ParameterError, match="does not fit"):
        order_spectrum(res, "pin_force", window=(0, 0.09), index=(3, 5))
    with pytest.raises(rvdyn.ParameterError, match="must lie inside the run"):
        order_spectrum(res, "carrier_speed", window=(0.05, 2.0))
    with pytest.raises(rvdyn.ParameterError, match="at least 16"):
        order_spectrum(res, "carrier_speed", window=(0.0, 0.001))
    with pytest.raises(rvdyn.ParameterError, match="cannot take the spectrum"):
        order_spectrum(res, "no_such_channel", window=(0, 0.09))
    with pytest.raises(rvdyn.ParameterError, match="domain"):
        order_spectrum(res, "carrier_speed", window=(0, 0.09), domain="fft")
    uneven = _fake(np.sort(np.r_[t, 0.05123]), W_IN * np.sort(np.r_[t, 0.05123]), np.zeros(len(t) + 1))
    with pytest.raises(rvdyn.ParameterError, match="uniformly spaced"):
        order_spectrum(uneven, "carrier_speed", window=(0, 0.09))
    still = _fake(t, np.zeros_like(t), np.sin(t))
    with pytest.raises(rvdyn.ParameterError, match="does not turn"):
        order_spectrum(still, "carrier_speed", window=(0, 0.09))
    with pytest.raises(rvdyn.ParameterError, match="harmonics"):
        excitation_orders(rvdyn.Scene.paper(), harmonics=0)
    own = [ExcitationOrder("probe", 1, 1.0, "probe")]
    spec = order_spectrum(_fake(t, W_IN * t, np.sin(W_IN * t)), "carrier_speed", window=(0, 0.0999), orders=own)
    assert spec.peaks[0].label == "probe"
