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
