"""Shared fixtures and reference helpers for the Python tests (SI units throughout)."""

from __future__ import annotations

import math

import numpy as np
import pytest

import rvdyn

#: The default disc (docs/model.md#default-scene).
ZP, E, RP, RRP, FACE = 24, 4.5e-3, 0.150, 0.010, 0.040
ZC = ZP - 1
K1 = E * ZP / RP


@pytest.fixture(scope="session")
def paper_disc() -> rvdyn.CycloidGeometry:
    return rvdyn.CycloidGeometry.paper()


def rotate(v: np.ndarray, angle: float) -> np.ndarray:
    """Rotate row vectors (..., 2) by ``angle`` [rad] counter-clockwise."""
    c, s = math.cos(angle), math.sin(angle)
    return v @ np.array([[c, -s], [s, c]]).T


def pin_centre(j: int) -> np.ndarray:
    """Centre [m] of pin j (0-based; the paper's pin j + 1)."""
    th = 2.0 * math.pi * j / ZP
    return np.array([RP * math.cos(th), RP * math.sin(th)])


def ringing(eta: np.ndarray, dt: float, periods: int = 8) -> tuple[float, float]:
    """Frequency [Hz] and damping ratio of the dominant mode in a decaying signal ``eta``
    (mean removed, samples ``dt`` [s] apart): the peak of its zero-padded FFT, and the
    logarithmic decrement over ``periods`` periods of its positive maxima (each refined by a
    parabola through three samples)."""
    spec = np.abs(np.fft.rfft(eta, 1 << 20))
    f_fft = float(np.fft.rfftfreq(1 << 20, dt)[5 + np.argmax(spec[5:])])
    peaks = []
    for j in range(1, len(eta) - 1):
        if eta[j] > 0 and eta[j] > eta[j - 1] and eta[j] >= eta[j + 1]:
            a, b, c = eta[j - 1], eta[j], eta[j + 1]
            d = 0.5 * (a - c) / (a - 2 * b + c)
            peaks.append(b - 0.25 * (a - c) * d)
    assert len(peaks) > periods + 1
    delta = math.log(peaks[0] / peaks[periods]) / periods
    return f_fft, delta / math.sqrt(4 * math.pi**2 + delta**2)
