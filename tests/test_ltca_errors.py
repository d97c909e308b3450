"""The quasi-static analysis with manufacturing and assembly errors, through the Python API."""

from __future__ import annotations

import math

import numpy as np
import pytest

import rvdyn
from rvdyn import Scene
from rvdyn.analysis import ltca

ANGLES = np.linspace(0.0, 2.0 * math.pi / 24.0, 7)


def test_constant_profile_error_is_the_equidistant_modification() -> None:
    # A constant profile error a (harmonic of order 0) shrinks every gap by a: the LTCA equals
    # that of d_rrp = -a (paper preset, IMPACT pins, rigid joints). Tolerance 1e-9
    # relative: two Newton solutions at tolerance 1e-12.
    a = 5e-6
    base = Scene.paper("rated")
    err = base.replace(**{"discs": [{"phase": 0.0, "profile_error": {"harmonics": [[a, 0, 0.0]]}},
                                    {"phase": math.pi, "profile_error": {"harmonics": [[a, 0, 0.0]]}}]})
    equi = base.replace(**{"cycloid.d_rrp": -a})
    r1, r2 = ltca(err, None, ANGLES), ltca(equi, None, ANGLES)
    f1, f2 = r1.arrays["pin_force"], r2.arrays["pin_force"]
    assert np.max(np.abs(f1 - f2)) < 1e-9 * f1.max()
    te1, te2 = r1.arrays["transmission_error"], r2.arrays["transmission_error"]
    assert np.max(np.abs(te1 - te2)) < 1e-9 * np.max(np.abs(te1))
    assert r1.arrays["torque_balance"].max() < 1e-9


def test_assembly_errors_change_the_result_and_balance() -> None:
    # Crank eccentricity errors at compliant joints (physical preset): the analysis runs, the
    # torque balance closes, and the peak pin force differs from the error-free one.
    base = Scene.physical("rated")
    err = base.replace(**{"errors.crank_eccentricity": [5e-6, -5e-6, 0.0]})
    r0, r1 = ltca(base, None, ANGLES[:3]), ltca(err, None, ANGLES[:3])
    assert r1.arrays["torque_balance"].max() < 1e-9
    assert abs(r1.peak_pin_force / r0.peak_pin_force - 1.0) > 1e-4


def test_assembly_errors_at_rigid_joints_are_refused() -> None:
    scene = Scene.paper("rated")
    with pytest.raises(rvdyn.SceneError):
        ltca(scene.replace(**{"errors.crank_eccentricity": [1e-6, 0.0, 0.0]}), None, [0.0])


@pytest.mark.parametrize("modification", [{"cycloid.d_rrp": -0.0099}, {"cycloid.d_delta": 0.010 / 0.150},
                                          {"cycloid.d_rrp": -0.002}])
def test_a_profile_that_overlaps_the_pins_is_named_as_such(modification: dict[str, float]) -> None:
    # At the accepted limits of the modifications the disc overlaps the pins by millimetres at
    # the kinematic pose; the error used to advise reducing the torque or the clearances.
    with pytest.raises(rvdyn.ConvergenceError, match=r"overlap by .* at the\s+kinematic pose.*cannot be assembled"):
        ltca(Scene.paper(**modification), 4024.9, [0.0])
    # Overlaps within the bound are preloads the equilibrium resolves.
    assert ltca(Scene.paper(**{"cycloid.d_rrp": -2e-5}), 4024.9, [0.0]).torque_balance[0] < 1e-9


def test_a_rated_torque_too_small_for_a_loop_names_the_rated_torque() -> None:
    # The error used to name the loop's internal point next to zero (2e-7 N m) and advise a
    # minimum the argument already exceeded.
    from rvdyn.analysis import torque_twist

    with pytest.raises(rvdyn.ParameterError, match=r"rated torque 2\.000e-5 N m is too small for a torque-twist loop"):
        torque_twist(Scene.paper(), 2e-5, 0.0, 41)
    assert torque_twist(Scene.paper(), 1e-4, 0.0, 41).rigidity > 0
