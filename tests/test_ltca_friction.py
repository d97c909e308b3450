"""Quasi-static friction in the torque-twist loop (docs/model.md, "Friction in the LTCA").

Each check compares against something computed independently: the frictionless loop, a
closed-form friction moment from the frictionless LTCA's contact loads, or the mirror image.
"""

from __future__ import annotations

import numpy as np
import pytest

import rvdyn
from rvdyn.analysis import torque_twist
from rvdyn.analysis import running_friction
from rvdyn.errors import ParameterError, SceneError

RATED = 43_921.3


def _single_stage(mu: float) -> rvdyn.Scene:
    """The paper's reducer without its first stage, rigid joints (cranks held)."""
    return rvdyn.Scene.paper("rated", stage1=None, friction={"pin": mu})


def test_friction_off_is_the_frictionless_loop() -> None:
    """``friction=False`` (and a scene without friction) give today's closed loop exactly."""
    plain = rvdyn.Scene.physical("rated")
    rough = plain.replace(friction={"pin": 0.05, "mesh": 0.05})
    a = torque_twist(plain, RATED, 0.0, 21)
    b = torque_twist(rough, RATED, 0.0, 21, friction=False)
    c = torque_twist(rough, RATED, 0.0, 21)
    assert not a.friction and not b.friction and c.friction
    np.testing.assert_array_equal(a.twist, b.twist)
    assert (a.rigidity, a.lost_motion, a.backlash) == (b.rigidity, b.lost_motion, b.backlash)
    # Closed without friction: both branches the same curve (to 1e-12 rad).
    assert abs(a.width(0.5 * RATED)) < 1e-12
    # Open with it, by a fraction of the twist.
    assert c.width(0.5 * RATED) > 1e-3 * c.twist.max()


def test_bearing_friction_reaches_the_static_analyses() -> None:
    """A compliant scene with bearing friction: the LTCA, the loop, the modes and the mass
    properties accept it (their rigid copy of the scene refused it as a rigid scene with
    bearing friction), and the bearings' Palmgren torque widens the loop a little."""
    bearing = {"f0": 3.0, "f1": 3e-4, "viscosity": 68e-6}
    teeth = rvdyn.Scene.physical("rated", friction={"pin": 0.05, "mesh": 0.05})
    both = rvdyn.Scene.physical("rated", friction={"pin": 0.05, "mesh": 0.05, "bearing": bearing})
    a = torque_twist(teeth, RATED, 0.0, 41)
    b = torque_twist(both, RATED, 0.0, 41)
    assert b.width(0.5 * RATED) > a.width(0.5 * RATED) * (1 + 1e-3)
    assert b.backlash > a.backlash
    assert rvdyn.ltca(both, None, [0.0]).arrays["pin_force"].max() > 0
    assert both.model_info()["generalized_mass"] == teeth.model_info()["generalized_mass"]
    assert rvdyn.modes(both).frequency[0] == pytest.approx(rvdyn.modes(teeth).frequency[0], rel=1e-12)


def test_running_bearing_friction_at_the_running_speed_agrees_with_the_dynamic_run() -> None:
    """The running sweep's bearings turn at the running reducer's speeds (speed-dependent
    Palmgren M0), as the dynamic model's do. Bearing friction alone, a tenth of the rated
    torque (where M0 matters most): the quasi-static efficiency against a steady dynamic run's
    with the frictionless run's damping losses divided out; measured 0.99058 against 0.99057
    (the zero-speed M0 gave 0.99205). Asserted 3 % of the loss."""
    bearing = {"bearing": {"f0": 3.0, "f1": 3e-4, "viscosity": 68e-6}}
    torque = 0.1 * RATED
    quasi = float(running_friction(rvdyn.Scene.physical("rated", friction=bearing), torque)["efficiency_forward"])
    base = rvdyn.Scene.physical("rated", initial="steady", **{"drive.start": "step", "load.torque": torque})
    rough, smooth = (rvdyn.simulate(s, 0.06).efficiency(0.02) for s in (base.replace(friction=bearing), base))
    dynamic = rough / smooth
    assert 1.0 - quasi == pytest.approx(1.0 - dynamic, rel=0.03)


def test_loop_width_is_the_friction_moment_over_the_stiffness() -> None:
    """Width at half the rated torque against ``2 mu S / k`` (first order in mu; the second-
    order terms of the two branches cancel in the width): S = sum N |arm . n| over the loaded
    pins from the frictionless LTCA at that torque (single stage, rigid joints: the disc turns
    about its fixed centre, so pin j slips by ``(arm . n) dtheta``), k its tangent stiffness.
    Measured 0.3 % at mu = 0.05; asserted 1 %."""
    mu = 0.05
    loop = torque_twist(_single_stage(mu), RATED, 0.0, 41)
    res = rvdyn.ltca(_single_stage(0.0), 0.5 * RATED, [0.0])
    arm_n = np.abs(np.sum(res.arrays["contact_point"] * res.arrays["contact_normal"], axis=-1))
    s = float(np.sum(res.arrays["pin_force"] * arm_n))
    est = 2.0 * mu * s / float(res.arrays["torsional_stiffness"][0])
    assert loop.width(0.5 * RATED) == pytest.approx(est, rel=0.01)


def test_reversing_the_torque_mirrors_the_loop_with_friction() -> None:
    """At crank angle 0 the physical preset is its own mirror image: the branch from -rated
    back to 0 is the point reflection of the branch from +rated to 0 (1e-9 of the tip twist;
    they are solved independently)."""
    loop = torque_twist(rvdyn.Scene.physical("rated", friction={"pin": 0.05, "mesh": 0.05}),
                        RATED, 0.0, 41)
    down = loop.twist[10:21]
    back = loop.twist[30:41]
    np.testing.assert_allclose(back, -down, rtol=0.0, atol=1e-9 * loop.twist[10])
    (ut, uw), (lt, lw) = loop.branches()
    assert np.all(np.diff(ut) > 0) and np.all(np.diff(lt) > 0)
    assert np.all(np.isfinite(loop.twist))
    # The stick segment at the tips: the unloading branch starts at the tip's twist.
    assert uw[-1] == pytest.approx(loop.twist[10], abs=0.0)


def test_bad_input_is_a_clear_error() -> None:
    with pytest.raises(SceneError, match="friction.pin"):
        torque_twist(rvdyn.Scene.physical("rated", friction={"pin": 1.5}), RATED, 0.0, 21)
    loop = torque_twist(_single_stage(0.05), RATED, 0.0, 9)
    with pytest.raises(ParameterError, match="within"):
        loop.width(2.0 * RATED)
    with pytest.raises(ParameterError):
        torque_twist(_single_stage(0.05), 0.0, 0.0, 21)


def test_running_efficiency_against_the_analytic_estimate() -> None:
    """Running sweeps with friction (contacts sliding as the running reducer, the input
    driving against the load): the quasi-static efficiency (frictionless over frictional
    input work at the same angles) over one mesh period against the analytic estimate of
    docs/model.md ("Analytic efficiency estimate",
    Malhotra & Parameswaran 1983 for the pins, Niemann & Winter 1983 tooth loss factor
    ``H_V = 0.1748`` of the paper's stage): ``eta = (1 - mu H_V (1 - 1/i)) / (1 + L_pin)``,
    ``L_pin = mu (4/pi)(1 - 1/i)(rp - rrp)/(e zp)``. The estimate uses the classical load
    sharing and the many-pins integrals (a few per cent of the loss apart from the discrete
    sums) and the mean tooth loss; the LTCA the actual pin loads: asserted 10 % of the loss
    (measured 1.1 % at 84 angles). Without friction the efficiency is 1 (exactly: the same
    sweep on both sides). Forward and reverse agree to 1e-9: they differed by 1.1 % of the loss
    while the mesh period ignored the tooth period, along which tooth friction changes."""
    mu = 0.05
    i = 57.0
    l_pin = mu * 4.0 / np.pi * (1.0 - 1.0 / i) * (0.150 - 0.010) / (0.0045 * 24)
    eta_est = (1.0 - mu * 0.1748 * (1.0 - 1.0 / i)) / (1.0 + l_pin)
    r = running_friction(rvdyn.Scene.paper("rated", friction={"pin": mu, "mesh": mu}), RATED)
    for key in ("efficiency_forward", "efficiency_reverse"):
        eta = float(r[key])
        assert (1.0 - eta) == pytest.approx(1.0 - eta_est, rel=0.10), (key, eta, eta_est)
    assert float(r["efficiency_forward"]) == pytest.approx(float(r["efficiency_reverse"]), rel=1e-9)
    free = running_friction(rvdyn.Scene.paper("rated"), RATED, 24)
    assert float(free["efficiency_forward"]) == pytest.approx(1.0, abs=1e-12)
    # Friction shifts the TE of both drive directions apart (more lost motion).
    assert np.mean(r["reverse"]) - np.mean(r["forward"]) > np.mean(free["reverse"]) - np.mean(free["forward"])


def test_running_sweep_over_the_whole_window() -> None:
    # window=True covers the twelve mesh periods after which the physical preset's roller sets
    # repeat, at 84 angles each here; without friction the efficiency is 1.
    scene = rvdyn.Scene.physical("rated")
    d = running_friction(scene, RATED, 84, window=True)
    assert len(d["crank_angle"]) == 12 * 84
    assert float(d["efficiency_forward"]) == pytest.approx(1.0, abs=1e-12)
    with pytest.raises(rvdyn.ParameterError, match="window"):
        running_friction(scene, RATED, window=1)  # type: ignore[arg-type]


def test_running_friction_at_light_and_zero_torque() -> None:
    # At 100 N m the frictional Newton stalled at 1.9e-9 of the load (a few hundred ulps of
    # the forces) and hit its iteration cap with "friction coefficients may be too large"; at
    # 0 N m the efficiency was the quotient of two round-off works (1.013).
    rough = rvdyn.Scene.physical("rated", friction={"pin": 0.05, "mesh": 0.05})
    light = running_friction(rough, 100.0, 84)
    assert 0.85 < float(light["efficiency_forward"]) < 0.95
    with pytest.raises(rvdyn.ParameterError, match="needs a torque"):
        running_friction(rough, 0.0)


def test_default_grid_resolves_the_tooth_sliding_reversal() -> None:
    # Eight angles per tooth-mesh cycle by default (336 on the physical preset): at two (84)
    # the efficiency moved between 0.9169 and 0.9233 with the start angle, because the tooth
    # sliding reverses at the pitch point and its harmonics fold onto the mean; at 336 the
    # spread is 2.5e-4 and the 672-angle values lie within it (0.9212).
    rough = rvdyn.Scene.physical("rated", friction={"pin": 0.05, "mesh": 0.05})
    pitch = 2.0 * np.pi / 24.0
    eta = [float(running_friction(rough, RATED, start=s)["efficiency_forward"]) for s in (0.0, 0.25 * pitch)]
    assert len(running_friction(rough, RATED)["crank_angle"]) == 336
    assert abs(eta[0] - eta[1]) < 1e-3
    fine = float(running_friction(rough, RATED, 672)["efficiency_forward"])
    assert all(abs(e - fine) < 1e-3 for e in eta)
    coarse = [float(running_friction(rough, RATED, 84, start=s)["efficiency_forward"]) for s in (0.0, 0.125 * pitch)]
    assert abs(coarse[0] - coarse[1]) > 2e-3  # what the old default did (0.9169 and 0.9223)


def test_running_sweep_converges_at_the_round_off_floor_far_from_zero() -> None:
    # At crank angle 48 rad (eight periods on) the frictional Newton looped to its cap at a
    # residual of 4e-12 of the load and blamed the friction coefficients; it now stops at the
    # round-off floor of the largest unknown, as the frictionless solver does.
    period = 6.021385919380437
    d = running_friction(rvdyn.Scene.physical("rated"), RATED, start=8 * period)
    assert float(d["efficiency_forward"]) == pytest.approx(1.0, abs=1e-9)
    rough = rvdyn.Scene.physical("rated", friction={"pin": 0.05, "mesh": 0.05})
    for k in (3, 8):
        assert 0.9 < float(running_friction(rough, RATED, start=k * period)["efficiency_forward"]) < 0.93


def _dynamic_loop(scene: rvdyn.Scene, quarter: float) -> np.ndarray:
    """Twist [rad] of a dynamic run with the input held and the output torque swept 0 ->
    +rated -> -rated -> 0 linearly, each quarter in ``quarter`` seconds, sampled where the
    41-point ``torque_twist`` loop has its torques."""
    swept = scene.replace(**{
        "drive.speed": 0.0, "drive.start": "step",
        "load": {"kind": "table", "points": [[0.0, 0.0], [quarter, RATED], [3.0 * quarter, -RATED],
                                             [4.0 * quarter, 0.0]]},
    })
    run = rvdyn.simulate(swept, 4.0 * quarter, "generalized-alpha", dt=1e-5,
                         record_interval=quarter / 10.0, channels="motion")
    assert run.t.size == 41
    # The load acts against positive output rotation: the loop's twist is minus the carrier's.
    return -run.carrier_angle


def test_friction_loop_agrees_with_slow_dynamic_runs() -> None:
    """The quasi-static friction loop (Coulomb, signs from the load path, stick at reversals)
    against the dynamic model's regularised friction (docs/model.md, "Friction in the dynamic
    models") on the physical preset, mu 0.05 on pins and teeth.

    The dynamic runs hold the input and sweep the output torque in quarters of 0.02 s and
    0.04 s: slow against the 1.8 kHz torsional mode, fast enough that the sliding speeds
    (about 1e-3 m/s) are tens of the regularisation speed (1e-4 m/s, so friction is Coulomb's
    except near a reversal). What remains is the damping's lag, proportional to the sweep
    rate: it halves when the quarter doubles (checked), so the quasi-static twist is the
    extrapolation ``2 phi(0.04) - phi(0.02)`` (Richardson in the rate). Compared where the
    motion is quasi-static and sliding: loading branches from half the rated torque up,
    unloading branches from 0.6 to 0.2 of it (near zero torque the bodies cross their
    clearances dynamically; just after a reversal the regularisation creeps where the LTCA
    sticks, over 20-30 % of the torque, less as the regularisation speed falls: at 0.7 of the
    torque, 0.3 after the reversal, the extrapolation is 2.3e-4 of the tip twist off and the
    lag ratio 0.69).
    Measured: branches within 4.5e-5 of the tip twist (asserted 2e-4, the next term of the
    rate expansion); widths at +-half rated 0.06 % and 0.01 % (asserted 1 %)."""
    scene = rvdyn.Scene.physical("rated", friction={"pin": 0.05, "mesh": 0.05,
                                                    "regularisation_speed": 1e-4})
    loop = torque_twist(scene, RATED, 0.0, 41)
    fast, slow = _dynamic_loop(scene, 0.02), _dynamic_loop(scene, 0.04)
    static = 2.0 * slow - fast
    tip = float(loop.twist[10])
    s = loop.torque / RATED
    loading = np.r_[5:11, 25:31]
    unloading = np.r_[14:19, 34:39]
    compared = np.r_[loading, unloading]
    np.testing.assert_allclose(s[loading], np.r_[0.5:1.01:0.1, -0.5:-1.01:-0.1], atol=1e-12)
    np.testing.assert_allclose(np.abs(s[unloading]), np.tile(np.r_[0.6:0.15:-0.1], 2), atol=1e-12)
    lag_fast = fast[compared] - loop.twist[compared]
    lag_slow = slow[compared] - loop.twist[compared]
    # The lag is the damping's: it trails the load, and halves with the rate.
    assert np.all(np.abs(lag_fast) > 1e-4 * tip)
    np.testing.assert_array_less(np.abs(lag_slow / lag_fast - 0.5), 0.15)
    np.testing.assert_array_less(np.abs(static[compared] - loop.twist[compared]), 2e-4 * tip)
    for t, (hi, lo) in ((0.5, (15, 5)), (-0.5, (25, 35))):
        assert loop.torque[hi] == pytest.approx(t * RATED) and loop.torque[lo] == pytest.approx(t * RATED)
        width = static[hi] - static[lo]
        assert width == pytest.approx(loop.width(t * RATED), rel=0.01), (t, width)
