"""The physical preset through the Python API (issue 8): preset, channels, efficiency, bearing life."""

import math

import numpy as np
import pytest

import rvdyn
from rvdyn import Scene, SceneError


@pytest.fixture(scope="module")
def physical_run():
    scene = Scene.physical("rated").replace(**{
        "initial": "steady",
        "drive": {"kind": "speed", "speed": math.radians(8328.0), "start": "step", "ramp_time": 0.0},
        "friction.pin": 0.05,
        "friction.mesh": 0.05,
    })
    return rvdyn.simulate(scene, t_end=0.03, integrator="dopri5", channels=["motion", "pins", "mesh", "energy", "bearings"])


def test_preset_is_the_physics_not_the_paper():
    s = Scene.physical("rated")
    assert s["contact.pin.kind"] == "line"
    assert s["contact.mesh.kind"] == "iso6336"
    assert s["joints.kind"] == "compliant"
    assert s["joints.eccentric_bearing.rollers.count"] == 26
    assert Scene.paper("rated")["contact.pin.kind"] == "impact"


def test_nonsense_is_a_scene_error_naming_the_field():
    with pytest.raises(SceneError, match="friction.pin"):
        Scene.physical("rated").replace(**{"friction.pin": 1.5})
    with pytest.raises(SceneError, match="count"):
        Scene.physical("rated").replace(**{"joints.eccentric_bearing.rollers.count": 0})
    with pytest.raises(SceneError, match="clearance"):
        Scene.physical("rated").replace(**{"joints.crank_bearing.clearance": -1e-6})


def test_channels_efficiency_and_bearing_life(physical_run):
    r = physical_run
    n = len(r.t)
    assert r.eccentric_bearing_force.shape == (n, 3, 2, 2)
    assert r.crank_bearing_force.shape == (n, 3, 2)
    assert np.all(np.isfinite(r.eccentric_bearing_force))
    # The eccentric bearings carry several times the peak pin force.
    peak_pin = r.pin_force[n // 2:].max()
    peak_ecc = np.linalg.norm(r.eccentric_bearing_force[n // 2:], axis=-1).max()
    assert peak_ecc > 2 * peak_pin
    # Efficiency with mu 0.05 on pins and teeth: the analytic estimate is 0.917 (2 points).
    eta = r.efficiency(t_start=0.01)
    assert abs(eta - 0.917) < 0.02
    fp = r.friction_power_means(t_start=0.01)
    assert fp["pin"] > fp["mesh"] > 0.0 and fp["bearing"] == 0.0
    life = r.bearing_life(t_start=0.01)
    for name in ("eccentric", "crank"):
        d = life[name]
        assert d["rating"] > 0 and d["equivalent_load"] > 0
        assert math.isfinite(d["l10_hours"]) and d["l10_hours"] > 0
