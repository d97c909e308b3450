"""Kinematics bindings: ratio, body speeds and operating point against the paper (section 4)."""

from __future__ import annotations

import math

import pytest

import rvdyn

W_IN = math.radians(8328.0)  # the paper's input speed, 145.351 rad/s


def test_ratio_is_57():
    # i = 1 + (z2/z1) zp = 1 + (42/18) 24 = 57: exact in floating point.
    assert rvdyn.transmission_ratio(18, 42, 24) == 57.0
    assert rvdyn.transmission_ratio(20, 30, 12) == 19.0


def test_body_speeds_of_the_paper():
    s = rvdyn.body_speeds(W_IN)
    assert set(s) == {"sun", "crank_absolute", "crank_relative", "disc_spin", "disc_orbit",
                      "carrier"}
    # Output 8328/57 = 146.10526 deg/s; the paper rounds to 146.1 (its "theoretical" value).
    assert rvdyn.deg_s(s["carrier"]) == pytest.approx(146.105, abs=1e-3)
    assert s["sun"] == W_IN
    # Crank relative to the carrier: -zp * carrier; absolute: carrier + relative (-23/57 input).
    assert s["crank_relative"] == pytest.approx(-24 * s["carrier"], rel=1e-15)
    assert s["crank_absolute"] == pytest.approx(-23 / 57 * W_IN, rel=1e-14)
    # The discs spin with the carrier and orbit with the cranks; disc spin = -orbit / zc.
    assert s["disc_spin"] == s["carrier"]
    assert s["disc_orbit"] == s["crank_absolute"]
    assert s["disc_spin"] == pytest.approx(-s["disc_orbit"] / 23, rel=1e-14)
    # Rolling of the sun/planet mesh (pitch radii proportional to 18 and 42).
    assert 18 * (s["sun"] - s["carrier"]) + 42 * s["crank_relative"] == pytest.approx(0, abs=1e-10)
    other = rvdyn.body_speeds(1.0, z_sun=20, z_planet=30, pins=12)
    assert other["carrier"] == pytest.approx(1 / 19, rel=1e-15)


def test_operating_point_of_the_paper():
    op = rvdyn.operating_point(112e3, W_IN, 57.0)
    assert isinstance(op, rvdyn.OperatingPoint)
    # 112e3 / 145.3510 = 770.548 N m; the paper prints 770.6 (rounded up): +-0.1 N m.
    assert op.input_torque == pytest.approx(770.6, abs=0.1)
    # Lossless output 57 x 770.548 = 43,921 N m = 43.92 kN m (+-0.01 kN m, 4 digits).
    assert op.output_torque == pytest.approx(43.92e3, abs=10.0)
    assert op.output_speed == pytest.approx(W_IN / 57, rel=1e-15)
    assert op.output_torque * op.output_speed == pytest.approx(112e3, rel=1e-13)
    assert op.ratio == 57.0 and op.power == 112e3 and op.input_speed == W_IN


def test_paper_printed_output_torque_is_inconsistent():
    # Erratum 3: 4024.9 N m at 2.550 rad/s is 10.26 kW, not 112 kW (an 11x shortfall).
    assert rvdyn.PAPER_PRINTED_OUTPUT_TORQUE == 4024.9
    op = rvdyn.operating_point(112e3, W_IN, 57.0)
    printed_power = rvdyn.PAPER_PRINTED_OUTPUT_TORQUE * op.output_speed
    assert printed_power == pytest.approx(10.26e3, abs=10.0)
    assert op.output_torque / rvdyn.PAPER_PRINTED_OUTPUT_TORQUE > 10


def test_idle_and_units_helpers():
    idle = rvdyn.operating_point(0.0, W_IN, 57.0)
    assert idle.input_torque == 0.0 and idle.output_torque == 0.0
    assert rvdyn.rad_s(8328.0) == pytest.approx(145.35102, rel=1e-7)
    assert rvdyn.deg_s(rvdyn.rad_s(146.1)) == pytest.approx(146.1, rel=1e-15)
