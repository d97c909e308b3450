"""Modes about the state of a dynamic run (``rvdyn.modes(scene, state=...)``,
``rvdyn.modes_at(result, t)``; docs/model.md, "Linearisation about a dynamic state")."""

from __future__ import annotations

import numpy as np
import pytest

import rvdyn

RATED = 43921.26037602  # 57 x 112 kW / 8328 deg/s [N m]


def _slow(compliant: bool) -> rvdyn.Scene:
    # Input at 1 % of the paper's speed, load ramped to rated over 0.05 s; the paper's damping
    # settles the ramp's transient well before 0.12 s.
    s = rvdyn.Scene.paper("rated").replace(**{
        "drive.speed": 0.01 * rvdyn.rad_s(8328),
        "load": {"kind": "table", "points": [[0, 0], [0.05, RATED]]}})
    return s.with_compliant_joints() if compliant else s


@pytest.mark.parametrize("compliant", [False, True])
def test_slow_steady_state_linearises_like_the_equilibrium(compliant: bool) -> None:
    # At the end of a slow loaded run the state is the loaded equilibrium at its crank angle up
    # to the slow motion's damping forces (their contact deflection) and a small inertia ripple:
    # the state linearisation (finite-difference rate terms, pose as it is) must give the
    # equilibrium linearisation's frequencies within 1e-3 and damping ratios within 1e-3
    # (measured 1.3e-4 rigid, 1.7e-5 compliant); as many modes as the run's free coordinates.
    s = _slow(compliant)
    r = rvdyn.simulate(s, 0.12, dt=1e-4, channels=["motion"])
    m = rvdyn.modes_at(r)
    assert len(m) == len(r.stats["final_q"]) == (16 if compliant else 2)
    assert m.time == pytest.approx(0.12) and m.torque == pytest.approx(RATED, rel=1e-9)
    assert m.part_names[-1] == "rate-dependent"
    e = rvdyn.modes(s, torque=RATED, crank_angle=m.crank_angle)
    np.testing.assert_allclose(m.frequency, e.frequency, rtol=1e-3)
    np.testing.assert_allclose(m.damping_ratio, e.damping_ratio, rtol=1e-3)
    np.testing.assert_allclose(m.energy_share.sum(axis=1), 1.0, atol=1e-9)


def test_recorded_time_of_a_rigid_run_and_errors() -> None:
    # A rigid run's motion channels hold its whole state: the last sample gives the end state's
    # modes to round-off (the interpolated sample at t_end is the final state).
    s = _slow(False)
    r = rvdyn.simulate(s, 0.12, dt=1e-4, channels=["motion"])
    end = rvdyn.modes_at(r)
    at = rvdyn.modes_at(r, 0.12)
    np.testing.assert_allclose(at.frequency, end.frequency, rtol=1e-8)
    mid = rvdyn.modes_at(r, 0.03)  # during the load ramp: a lower torque, softer contacts
    assert mid.time == pytest.approx(0.03) and mid.frequency[0] < end.frequency[0]
    with pytest.raises(rvdyn.ParameterError, match="outside the run"):
        rvdyn.modes_at(r, 1.0)
    with pytest.raises(rvdyn.ParameterError, match="2 free coordinates"):
        rvdyn.modes(s, state=(0.1, [0.0], [0.0]))
    with pytest.raises(rvdyn.ParameterError, match="finite"):
        rvdyn.modes(s, state=(0.1, [0.0, float("nan")], [0.0, 0.0]))
    rc = rvdyn.simulate(s.with_compliant_joints(), 2e-3, dt=1e-4, channels=["motion"])
    with pytest.raises(rvdyn.ParameterError, match="crank centres"):
        rvdyn.modes_at(rc, 1e-3)


def test_a_state_far_from_equilibrium_says_so() -> None:
    # The rated paper scene at rest in its kinematic pose: the tangent stiffness is
    # indefinite along one mode (eigenvalue +1074 1/s), which came back as f = 0 and a NaN
    # damping ratio without a word, and the residual of a state read 0.
    with pytest.warns(RuntimeWarning, match="1 of 2 modes are unstable"):
        m = rvdyn.modes(rvdyn.Scene.paper("rated"), state=(0.0, [0.0, 0.0], [0.0, 0.0]))
    assert sum(m.extra["unstable"]) == 1 and np.isnan(m.residual)
    assert np.max(m.eigenvalues.real) > 1000.0
