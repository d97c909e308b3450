"""Bad arguments to the plotting helpers end in the rvdyn hierarchy."""

from __future__ import annotations

import math

import numpy as np
import pytest

import rvdyn
from rvdyn import plotting


@pytest.mark.parametrize("pins", [[0], [25], [-1], [float("nan")], [1.5], [True], ["3"], [2**70]])
def test_pin_numbers_outside_1_to_zp_are_rejected(pins):
    # Pin 0 used to select pin 24 (index -1) under the label "pin 0".
    with pytest.raises(rvdyn.ParameterError, match="pin number"):
        plotting.pin_indices(pins, 24)


def test_pin_numbers_map_to_indices():
    assert plotting.pin_indices([1, 24, np.int64(3)], 24) == [0, 23, 2]
    assert plotting.pin_indices(range(1, 4), 3) == [0, 1, 2]
    with pytest.raises(rvdyn.ParameterError, match="iterable"):
        plotting.pin_indices(5, 24)


@pytest.mark.parametrize(
    "kwargs",
    [
        {"psi": float("nan")},
        {"psi": 10**400},
        {"psi": "x"},
        {"samples_per_lobe": 3},
        {"samples_per_lobe": 10**12},
        {"samples_per_lobe": float("nan")},
        {"samples_per_lobe": 64.0},
        {"disc": "middle"},
        {"disc": ["both"]},
    ],
)
def test_plot_geometry_rejects_bad_arguments_before_drawing(kwargs):
    pytest.importorskip("matplotlib")
    with pytest.raises(rvdyn.ParameterError):
        plotting.plot_geometry(**kwargs)


def test_plot_geometry_still_draws_with_numpy_arguments():
    pytest.importorskip("matplotlib")
    fig = plotting.plot_geometry(psi=np.float32(0.3), samples_per_lobe=np.int64(8), disc="front")
    assert fig.axes and math.isclose(len(fig.axes[0].patches), 24 + 1)


@pytest.mark.parametrize(
    "kwargs",
    [
        {"r1": "abc"},
        {"r2": 10**400},
        {"widths": ["a", "b"]},
        {"widths": [5e-3, float("nan")]},
        {"exponent": "1.5x"},
    ],
)
def test_plot_stiffness_rejects_bad_arguments(kwargs):
    pytest.importorskip("matplotlib")
    with pytest.raises(rvdyn.ParameterError):
        plotting.plot_stiffness(**kwargs)
