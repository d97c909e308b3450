"""Modes with machine shafts: output shaft to a load inertia, drive shaft from a motor
(docs/model.md, "Modes with machine shafts")."""

from __future__ import annotations

import math

import numpy as np
import pytest

import rvdyn

RATED = 43921.26037602  # 57 x 112 kW / 8328 deg/s [N m]


def _scene(ko: float | None, ki: float | None, **changes: object) -> rvdyn.Scene:
    d: dict[str, object] = {"inertias.load_inertia": 20.0, "inertias.motor_inertia": 0.05,
                            "shafts.output": None if ko is None else {"stiffness": ko, "damping": 10.0},
                            "shafts.input": None if ki is None else {"stiffness": ki, "damping": 0.1}}
    d.update(changes)
    return rvdyn.Scene.paper("rated").replace(**d)


def test_shaft_coordinates_names_and_energy_family() -> None:
    m = rvdyn.modes(_scene(2e6, 5e4))
    assert m.dof_names == ["carrier angle", "crank angle", "sun angle", "load angle"]
    assert m.part_names[-1] == "shafts" and len(m) == 4
    # Torque drive: the motor is free too (one more coordinate, a kinematic mode near 0 Hz).
    mt = rvdyn.modes(_scene(2e6, 5e4, drive={"kind": "torque", "torque": RATED / 57}), torque=RATED)
    assert mt.dof_names[-1] == "motor angle" and len(mt) == 5
    # The drive-shaft mode (sun on k_i against the held motor) stores its energy in the shafts.
    np.testing.assert_allclose(m.energy_share.sum(axis=1), 1.0, atol=1e-9)
    assert max(m.energy_share[:, -1]) > 0.9


def test_stiff_shafts_give_back_the_modes_without_shafts() -> None:
    # Shafts 1e5 times stiffer than the reducer: the load joins the carrier, the (held) motor
    # holds the sun, so the modes without shafts come back within 1 % (measured 2e-6).
    a = rvdyn.modes(_scene(None, None), crank_angle=0.2)
    b = rvdyn.modes(_scene(1e13, 1e12), crank_angle=0.2)
    assert len(b) == len(a) + 2
    np.testing.assert_allclose(b.frequency[: len(a)], a.frequency, rtol=0.01)


def test_soft_output_shaft_mode_matches_the_free_vibration_of_a_run() -> None:
    # Soft, lightly damped output shaft (k_o = 2e5 N m/rad, c_o = 5 N m s/rad, J_L = 20 kg m^2):
    # the load rings on the shaft after the load ramp. The FFT peak of the shaft twist rate
    # (carrier minus load speed) over 0.2-2.0 s must match the lowest mode's damped frequency
    # within 1 % (the free-vibration tolerance; frequency resolution 0.5 Hz zero-padded
    # to 0.004 Hz at ~16 Hz).
    ko, jl = 2e5, 20.0
    s = _scene(ko, None, **{"shafts.output": {"stiffness": ko, "damping": 5.0},
                            "drive.speed": 0.01 * rvdyn.rad_s(8328),
                            "load": {"kind": "table", "points": [[0, 0], [0.05, RATED]]}})
    m = rvdyn.modes(s, torque=RATED, crank_angle=0.0)
    assert m.dominant_dof[0] == "load angle" and m.energy_share[0, -1] > 0.99
    # The reducer is nearly rigid against the shaft: the load on the shaft with the carrier held
    # gives sqrt(k_o / J_L) (within 1 %).
    assert m.frequency[0] == pytest.approx(math.sqrt(ko / jl) / (2 * math.pi), rel=0.01)
    r = rvdyn.simulate(s, 2.0, dt=2e-4, record_interval=2e-4, channels=["motion"])
    sel = r.t >= 0.2
    x = (r.carrier_speed - r.load_speed)[sel]
    x = x - x.mean()
    n = 1 << 20
    f = np.fft.rfftfreq(n, 2e-4)
    peak = f[np.argmax(np.abs(np.fft.rfft(x * np.hanning(len(x)), n)))]
    assert peak == pytest.approx(m.damped_frequency[0], rel=0.01)


def test_a_speed_drive_holds_the_motor_so_its_inertia_is_not_needed() -> None:
    # The linearisation's torque-driven copy of the scene asked for a motor inertia that a
    # speed-driven scene (which holds the motor) need not give: a SceneError before.
    held = rvdyn.Scene.paper("rated").replace(**{"shafts.input": {"stiffness": 1e5}})
    m = rvdyn.modes(held)
    assert m.dof_names[-1] == "sun angle" and "motor angle" not in m.dof_names
    with_motor = rvdyn.modes(held.replace(**{"inertias.motor_inertia": 0.01}))
    np.testing.assert_array_equal(m.frequency, with_motor.frequency)
