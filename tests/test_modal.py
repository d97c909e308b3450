"""User contract of the modal analysis (rvdyn.analysis.modes, campbell)."""

from __future__ import annotations

import math

import numpy as np
import pytest

import rvdyn
from rvdyn import Scene
from rvdyn.analysis.modal import campbell, modes

RATED = 43_921.3


def test_compliant_modes_have_one_mode_per_dof_and_named_energy() -> None:
    m = modes(Scene.paper("rated").with_compliant_joints(), RATED, 0.1)
    assert m.frequency.shape == (16,) and m.shape.shape == (16, 16)
    assert np.all(np.diff(m.frequency) >= 0) and m.frequency[0] > 0
    assert np.allclose(m.energy.sum(axis=1), 1.0, atol=1e-6)
    rows = m.table()
    assert rows[0]["dominant_dof"] == "carrier rotation"
    assert set(m.families) >= {"pins of disc 0", "eccentric bearings"}
    # Mass-normalised shapes: phi^T M phi = 1.
    assert np.allclose((m.shape**2 * m.mass).sum(axis=1), 1.0, rtol=1e-9)


def test_rigid_and_very_stiff_compliant_share_their_low_modes() -> None:
    # Issue 10's check: a compliant scene with very stiff bearings has the rigid model's low
    # modes (within 1 %): here the two torsional modes (carrier, crank).
    rigid = modes(Scene.paper("rated"), RATED, 0.1)
    stiff = modes(Scene.paper("rated").with_compliant_joints(
        eccentric_bearing={"stiffness": 1e13, "damping": 0.0},
        crank_bearing={"stiffness": 1e13, "damping": 0.0}), RATED, 0.1)
    for k in range(2):
        assert stiff.frequency[k] == pytest.approx(rigid.frequency[k], rel=0.01)


def test_campbell_crossings_are_order_times_speed() -> None:
    scene = Scene.paper("rated")
    w = np.linspace(10.0, 400.0, 50)
    c = campbell(scene, w, RATED)
    assert c.crossings
    for x in c.crossings:
        assert x["frequency"] == pytest.approx(x["order_value"] * x["input_speed"] / (2 * math.pi), rel=1e-12)
    assert c.plot().axes
    with pytest.raises(rvdyn.ParameterError):
        campbell(scene, [1.0], RATED)
