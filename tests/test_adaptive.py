"""The error-controlled generalized-alpha, interpolated output and the fixed-step check.
Tolerances are stated where used, with the reason."""

from __future__ import annotations

import math
import warnings

import numpy as np
import pytest

import rvdyn
from rvdyn import Scene, simulate

T = 0.05  # span of the short runs [s]: the start impact and 2 pin-mesh periods after it


@pytest.fixture(scope="module")
def reference() -> rvdyn.Result:
    return simulate(Scene.paper("rated"), T, "dopri5", atol=1e-13, rtol=1e-11, channels=["motion", "pins"])


def pin_error(r: rvdyn.Result, ref: rvdyn.Result) -> float:
    w = ref.t >= 0.5 * T
    return float(np.abs(r.pin_force[w] - ref.pin_force[w]).max() / ref.pin_force[w].max())


def test_adaptive_error_falls_with_the_tolerance(reference: rvdyn.Result) -> None:
    errors, steps = [], []
    for atol in (1e-7, 1e-8, 1e-9):
        r = simulate(Scene.paper("rated"), T, "generalized-alpha-adaptive", atol=atol, rtol=1e3 * atol,
                     channels=["motion", "pins"])
        assert r.ok and r.options["integrator"] == "generalized-alpha-adaptive"
        errors.append(pin_error(r, reference))
        steps.append(r.stats["steps"])
    # Each decade of tolerance buys at least a factor 3 in pin-force error (the method is
    # second order with error-per-unit-step control: about 10 asymptotically), for more steps.
    assert errors[0] > 3 * errors[1] > 9 * errors[2], errors
    assert steps[0] < steps[1] < steps[2], steps
    # At 1e-9 m the pin forces are within 1e-4 of their peak (measured 2e-6 on 0.5 s).
    assert errors[2] < 1e-4, errors


@pytest.mark.parametrize("integrator", ["generalized-alpha-adaptive", "dopri5"])
def test_samples_do_not_bound_the_adaptive_step(integrator: str) -> None:
    # Samples are interpolated between steps: the steps taken do not depend on the sample
    # interval (dopri5 took about 3 times more steps with samples every 0.1 ms before).
    runs = [simulate(Scene.paper("rated"), 0.02, integrator, record_interval=ri, channels=["motion"])
            for ri in (1e-5, 1e-3)]
    assert runs[0].stats["steps"] == runs[1].stats["steps"]
    assert runs[0].t.size == 2001 and runs[1].t.size == 21
    # The coarse samples are the fine ones at the same times (same steps, same interpolation).
    np.testing.assert_allclose(runs[0].carrier_speed[::100], runs[1].carrier_speed, rtol=0, atol=1e-12)


def test_a_fixed_step_too_long_for_the_pin_mesh_warns_or_raises() -> None:
    s = Scene.paper("rated")
    # 4.46 ms pin-mesh period at 8328 deg/s: 1 ms is 4.5 steps per period, below 8.
    with pytest.warns(RuntimeWarning, match=r"4\.46 steps per pin-mesh period \(4\.464e-3 s"):
        r = simulate(s, 2e-3, dt=1e-3)
    assert r.ok and "warnings" not in r.stats
    with pytest.raises(rvdyn.ParameterError, match="pin-mesh period"):
        simulate(s, 2e-3, dt=1e-3, step_check="raise")
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        simulate(s, 2e-3, dt=1e-3, step_check="off")
        simulate(s, 2e-3, dt=5e-4)  # 8.9 steps per period: no warning
        simulate(s, 2e-3, "generalized-alpha-adaptive")  # adaptive: not checked
    with pytest.raises(rvdyn.ParameterError, match="step_check"):
        simulate(s, 2e-3, step_check="loud")


@pytest.mark.parametrize("bad", [
    {"atol": 0.0}, {"atol": math.nan}, {"atol": -1e-9}, {"rtol": math.inf}, {"rtol": -1.0},
    {"h_min": 0.0}, {"h_min": math.nan}, {"max_steps": 0}, {"max_steps": -3},
])
def test_bad_adaptive_settings_are_parameter_errors(bad: dict[str, float]) -> None:
    with pytest.raises(rvdyn.ParameterError):
        simulate(Scene.paper("rated"), 1e-3, "generalized-alpha-adaptive", **bad)


def test_a_minimum_step_above_the_run_and_a_step_budget_are_refused_with_advice() -> None:
    with pytest.raises(rvdyn.ParameterError, match="h_min"):
        simulate(Scene.paper("rated"), 1e-3, "generalized-alpha-adaptive", h_min=1.0)
    for integrator in ("generalized-alpha-adaptive", "dopri5"):
        with pytest.raises(rvdyn.SimulationError, match=r"max_steps = 10 .*raise max_steps"):
            simulate(Scene.paper("rated"), 0.01, integrator, max_steps=10)


def test_options_carry_the_new_settings() -> None:
    o = rvdyn.Options("generalized-alpha-adaptive", h_min=1e-11, max_steps=1000, step_check="off")
    d = o.to_dict()
    assert (d["h_min"], d["max_steps"], d["step_check"]) == (1e-11, 1000, "off")
    assert rvdyn.Options(**d) == o
    assert "step_check='off'" in repr(o)
    assert "generalized-alpha-adaptive" in rvdyn.INTEGRATORS


def test_adaptive_steps_resolve_the_pin_mesh_at_any_tolerance() -> None:
    # The adaptive methods take at most an eighth of the pin-mesh period (4.46 ms at 8328
    # deg/s) per step, the fixed-step check's bound. At atol 1e-6 m generalized-alpha-adaptive
    # took 252 steps in 0.3 s (3.7 per period) with pin forces 1.1 % off; capped: 1.6e-3.
    s = Scene.paper("rated")
    period = 2 * math.pi * s.ratio / (24 * 23 * s["drive.speed"])
    r = simulate(s, 0.3, "generalized-alpha-adaptive", atol=1e-6, channels=["motion", "pins"])
    assert r.stats["steps"] >= 0.3 / (period / 8)
    ref = simulate(s, 0.3, "dopri5", atol=1e-11, rtol=1e-9, channels=["motion", "pins"])
    w = ref.t >= 0.06
    err = np.abs(r.pin_force[w] - ref.pin_force[w]).max() / ref.pin_force[w].max()
    assert err < 3e-3, err  # measured 1.6e-3: the 1e-3 class of 8 steps per period
    # A torque-driven scene has no prescribed pin-mesh period: no cap.
    td = Scene.paper("rated", **{"drive": {"kind": "torque", "torque": 780.0}})
    assert simulate(td, 0.02, "generalized-alpha-adaptive", atol=1e-6).ok


def test_a_run_shorter_than_the_minimum_step_names_t_end() -> None:
    with pytest.raises(rvdyn.ParameterError, match=r"t_end = 1e-15 s is shorter than .*h_min"):
        simulate(Scene.paper("rated"), 1e-15, "dopri5")


def test_generalized_alpha_warns_when_its_numerical_damping_replaces_the_contacts() -> None:
    # Without contact damping, generalized-alpha's rho_inf < 1 damps the contact vibration: the
    # peak pin force came out 8 % low at dt 1e-4 s on this scene with no warning.
    s = Scene.paper("rated", **{"contact.pin.max_damping": 0.0, "contact.mesh.max_damping": 0.0})
    ref = simulate(s, 0.05, "dopri5", atol=1e-11, rtol=1e-9, channels=["pins"])
    with pytest.warns(RuntimeWarning, match=r"pin and sun/planet mesh contacts have no damping.*rho_inf = 0\.8"):
        r = simulate(s, 0.05, channels=["pins"])
    w = ref.t >= 0.01
    assert abs(r.pin_force[w].max() / ref.pin_force[w].max() - 1) > 0.01  # what the warning is for
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        simulate(s, 0.01, rho_inf=1.0, channels=["pins"])  # no numerical damping
        simulate(s, 0.01, "dopri5", channels=["pins"])
        simulate(Scene.paper("rated", **{"contact.pin.max_damping": 0.0}), 0.01, "generalized-alpha-adaptive")
        simulate(Scene.paper("rated"), 0.01)  # damped contacts
    with pytest.warns(RuntimeWarning, match=r"scene's pin contacts have no damping"):
        simulate(Scene.paper("rated", **{"contact.pin.max_damping": 0.0}), 0.01)


def test_a_load_reversal_within_a_few_fixed_steps_warns() -> None:
    # The flank change of a reversal is an impact: generalized-alpha at dt 1e-4 s read the peak
    # pin force 12 % low (table reversal within 1e-4 s) and 3 % high (a step) against dopri5.
    rated = 43921.0
    step = {"kind": "step", "before": rated, "after": -rated, "time": 0.004}
    with pytest.warns(RuntimeWarning, match=r"0\.0 steps over the load reversal at t = 4\.0000e-3 s"):
        simulate(Scene.paper("rated", load=step), 0.005, channels=["motion"])
    table = {"kind": "table", "points": [[0.0, rated], [0.004, rated], [0.0045, -rated]]}
    with pytest.warns(RuntimeWarning, match=r"5\.0 steps over the load reversal"):
        simulate(Scene.paper("rated", load=table), 0.005, channels=["motion"])
    with pytest.raises(rvdyn.ParameterError, match="load reversal"):
        simulate(Scene.paper("rated", load=step), 0.005, step_check="raise")
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        slow = {"kind": "table", "points": [[0.0, rated], [0.004, rated], [0.02, -rated]]}
        simulate(Scene.paper("rated", load=slow), 0.005, channels=["motion"])  # 160 steps
        simulate(Scene.paper("rated", load=step), 0.003, channels=["motion"])  # after t_end
        simulate(Scene.paper("rated", load={"kind": "step", "before": 0.0, "after": rated, "time": 0.004}),
                 0.005, channels=["motion"])  # not a reversal
        simulate(Scene.paper("rated", load=step), 0.005, "dopri5", channels=["motion"])


def test_a_fixed_step_run_beyond_the_step_budget_is_refused_before_it_starts() -> None:
    # generalized-alpha at dt 1e-9 s over 0.3 s planned 3e8 steps (hours) although max_steps
    # (default 1e8) bounds an adaptive run.
    with pytest.raises(rvdyn.ParameterError, match=r"3\.000e8 steps, more than max_steps = 100000000"):
        simulate(Scene.paper("rated"), 0.3, dt=1e-9)
    with pytest.raises(rvdyn.ParameterError, match="max_steps = 10:"):
        simulate(Scene.paper("rated"), 1e-3, "rk4", dt=1e-5, max_steps=10)
    assert simulate(Scene.paper("rated"), 1e-3, "rk4", dt=1e-5, max_steps=100).ok  # exactly 100
