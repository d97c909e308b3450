"""Quasi-static analyses at large crank angles and at zero torque (an outside review found the
torque-twist loop failing from about 500 rad, the unloaded TE at 1e4 rad with advice about the
torque, and round-off forces of 1e-8 N counted as loaded pins at zero torque)."""

from __future__ import annotations

import math

import numpy as np
import pytest

import rvdyn
from rvdyn import ParameterError, Scene
from rvdyn.analysis import torque_twist, transmission_error


def test_the_twist_loop_repeats_at_large_crank_angles() -> None:
    paper = Scene.paper("rated")
    period = 2 * math.pi / 24
    near = torque_twist(paper, None, 0.1, 21)
    far = torque_twist(paper, None, 0.1 + 1900 * period, 21)  # 497.5 rad: failed before
    assert far.crank_angle == 0.1 + 1900 * period  # the caller's angle is reported
    # The same state (reduced by whole periods, exact but for the last bits of the angle).
    assert np.max(np.abs(far.twist - near.twist)) < 1e-12
    assert far.rigidity == pytest.approx(near.rigidity, rel=1e-9)
    assert far.lost_motion == pytest.approx(near.lost_motion, rel=1e-9)


def test_the_physical_twist_loop_at_1000_rad() -> None:
    physical = Scene.physical("rated")
    loop = torque_twist(physical, None, 1000.0, 21)  # ParameterError about a 4e-3 N m torque before
    window = float(rvdyn._core.LtcaSolver(physical._compiled, 1e-12).te_window)
    ref = torque_twist(physical, None, 1000.0 % window, 21)
    assert np.max(np.abs(loop.twist - ref.twist)) < 1e-12
    assert loop.rigidity == pytest.approx(ref.rigidity, rel=1e-9)


def test_transmission_error_from_a_large_start() -> None:
    paper = Scene.paper("rated")
    period = 2 * math.pi / 24
    far = transmission_error(paper, None, 8, start=1e4, window=False)  # ConvergenceError before
    near = transmission_error(paper, None, 8, start=1e4 % period, window=False)
    assert far.crank_angle[0] == 1e4
    np.testing.assert_allclose(far.crank_angle - 1e4, near.crank_angle - 1e4 % period, atol=1e-11)
    for curve in ("forward", "reverse", "unloaded_forward", "unloaded_reverse"):
        assert np.max(np.abs(getattr(far, curve) - getattr(near, curve))) < 1e-14
        assert far.extremes[curve]["max"] == pytest.approx(near.extremes[curve]["max"], abs=1e-14)
        # Where a flat extreme lies is fixed only where the TE changes by more than its
        # round-off: the two runs put the forward maximum 1.3e-5 rad apart with the same TE to
        # 1e-14 rad (5e-5 of the 0.26 rad period).
        shift = far.extremes[curve]["max_angle"] - near.extremes[curve]["max_angle"]
        assert shift == pytest.approx(1e4 - 1e4 % period, abs=1e-4)


def test_ltca_at_a_huge_crank_angle_names_the_angle_not_the_torque() -> None:
    with pytest.raises(ParameterError, match="crank angle .* turned so far") as info:
        rvdyn.ltca(Scene.paper("rated"), None, [1e13])
    assert "mesh periods" in str(info.value)


def test_zero_torque_has_no_loaded_pins_and_no_fea_loads() -> None:
    r = rvdyn.ltca(Scene.physical("rated"), 0.0, [0.0])
    assert r.loaded_pins.max() == 0  # 7-8 per disc with 1e-8 N of round-off before
    assert r.pin_force.max() == 0.0
    assert r.fea_csv.strip().count("\n") == 0, r.fea_csv  # the header only
