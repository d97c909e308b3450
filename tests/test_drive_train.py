"""Machine shafts: output shaft to the load inertia, drive shaft from the motor.

Closed forms: docs/model.md#machine-shafts. Every run is the paper preset at rated load (the
reducer's own compliance is about 3e7 N m/rad at the output, so the shafts below are the soft
elements of the chain).
"""

import math

import numpy as np
import pytest

import rvdyn
from rvdyn import Scene, SceneError

RATED = Scene.paper("rated")
T_OUT = RATED["load.torque"]
RATIO = 57.0


def _with(scene: Scene, joints: str) -> Scene:
    return scene.with_compliant_joints() if joints == "compliant" else scene


def _upward_crossing_frequencies(t: np.ndarray, y: np.ndarray) -> np.ndarray:
    i = np.nonzero((y[:-1] < 0) & (y[1:] >= 0))[0]
    tc = t[i] - y[i] * (t[i + 1] - t[i]) / (y[i + 1] - y[i])
    return 1.0 / np.diff(tc)


@pytest.mark.parametrize("joints", ["rigid", "compliant"])
@pytest.mark.parametrize("load_inertia", [13.0, 5.0])
def test_two_inertia_chain_frequency(joints: str, load_inertia: float) -> None:
    # The reducer (everything reflected to the output: J_r = M_cc + zc^2 M_aa + i^2 M_ss) and
    # the load J_L on an undamped output shaft k: f = sqrt(k (1/J_r + 1/J_L)) / (2 pi). A
    # torque drive T/i balances the load T: the chain's centre of mass stays at rest and the
    # shaft torque swings between 0 and 2T. Tolerance 0.5 %: the reducer's compliance in
    # series (k / k_r ~ 1e-3) lowers f by about 0.1-0.25 %; forgetting the sun's reflected
    # inertia (12 % of J_r) would move f by 6 %.
    k = 4e4
    shaft = {"inertias.load_inertia": load_inertia, "shafts.output": {"stiffness": k, "damping": 0.0}}
    m = RATED.replace(**shaft).model_info()["generalized_mass"]
    assert len(m) == 5 and m[3] == load_inertia
    j_r = m[0] + 23 ** 2 * m[1] + RATIO ** 2 * m[2]
    scene = _with(RATED.replace(**shaft, drive={"kind": "torque", "torque": T_OUT / RATIO, "ramp_time": 0.0}), joints)
    r = rvdyn.simulate(scene, t_end=0.4, integrator="dopri5", channels=["motion", "mesh"], record_interval=1e-4)
    tq = r.output_shaft_torque
    assert tq.max() == pytest.approx(2 * T_OUT, rel=0.02)
    f = _upward_crossing_frequencies(r.t, tq - tq.mean())
    assert len(f) >= 3
    want = math.sqrt(k * (1 / j_r + 1 / load_inertia)) / (2 * math.pi)
    assert abs(f.mean() / want - 1) < 5e-3, (f, want)
    # The shaft torque is the spring: k (carrier - load) with no damping.
    assert np.allclose(tq, k * (r.carrier_angle - r.load_angle), rtol=1e-12, atol=1e-9)


@pytest.mark.parametrize("joints", ["rigid", "compliant"])
def test_static_twist_of_the_shafts_at_rated_torque(joints: str) -> None:
    # Input held at rest (speed drive 0), rated load on the load inertia, both shafts damped
    # at 0.7 of critical: the chain settles (e^-90 after 0.3 s) at the static twists.
    # Output shaft: T / k_o, exactly (equilibrium of the load alone): 1e-9 relative (dopri5 at
    # atol 1e-11). Drive shaft: T / (i k_i) with the static torque ratio of the deflected
    # reducer, which differs from the kinematic 57 by its transmission-error slope (1.5e-4
    # rigid, 9e-4 compliant measured): 2e-3.
    ko, jl, ki, jm = 1e6, 5.0, 2e3, 0.01
    scene = _with(RATED.replace(**{
        "inertias.load_inertia": jl, "inertias.motor_inertia": jm,
        "shafts.output": {"stiffness": ko, "damping": 1.4 * math.sqrt(ko * jl)},
        "shafts.input": {"stiffness": ki, "damping": 1.4 * math.sqrt(ki * jm)},
        "drive": {"kind": "speed", "speed": 0.0, "start": "step", "ramp_time": 0.0},
    }), joints)
    r = rvdyn.simulate(scene, t_end=0.3, integrator="dopri5", channels=["motion", "mesh"],
                       record_interval=1e-3, atol=1e-11, rtol=1e-9)
    twist_out = r.carrier_angle[-1] - r.load_angle[-1]
    assert twist_out * ko / T_OUT == pytest.approx(1.0, abs=1e-9)
    assert r.output_shaft_torque[-1] == pytest.approx(T_OUT, rel=1e-9)
    twist_in = r.motor_angle[-1] - r.sun_angle[-1]
    assert twist_in * ki * RATIO / T_OUT == pytest.approx(1.0, abs=2e-3)
    # The motor is the prescribed body: it stays at rest, the sun turns by the twist.
    assert r.motor_angle[-1] == 0.0 and r.motor_speed[-1] == 0.0


ERRORS = {
    "discs.0.profile_error": {"harmonics": [[3e-6, 23.0, 0.5], [2e-6, 2.0, 0.0]], "table": [[0.0, 1e-6], [3.0, -1e-6]]},
    "gear_errors": {
        "sun": {"runout": 1e-5, "runout_phase": 0.3, "pitch_amplitude": 5e-6, "pitch_phase": 0.1,
                "pitch_deviation": [1e-6 * math.sin(k) for k in range(18)]},
        "planets": [{"runout": 4e-6}, {"pitch_amplitude": 2e-6}, {}],
    },
}


@pytest.mark.parametrize("joints", ["rigid", "compliant"])
def test_energy_balance_closes_with_shafts_and_errors(joints: str) -> None:
    # Input work = output work + kinetic + elastic (contacts, bearings, shafts) + dissipated,
    # with both shafts, a profile error and gear errors (their foot and gradient terms in the
    # forces): 1e-6 of the input work at dopri5 atol 1e-12 (measured 1e-10).
    scene = _with(RATED.replace(**{
        "initial": "steady", "inertias.load_inertia": 5.0, "inertias.motor_inertia": 0.01,
        "shafts.output": {"stiffness": 1e6, "damping": 100.0}, "shafts.input": {"stiffness": 2e4, "damping": 0.5},
        **ERRORS}), joints)
    r = rvdyn.simulate(scene, t_end=0.02, integrator="dopri5", channels=["motion", "mesh", "energy"],
                       atol=1e-12, rtol=1e-9)
    assert r.input_work[-1] > 1e3
    assert abs(r.energy_residual[-1]) < 1e-6 * r.input_work[-1]


def test_without_shafts_the_new_channels_are_the_rigid_connection() -> None:
    r = rvdyn.simulate(RATED, t_end=2e-3, integrator="dopri5", channels=["motion", "mesh"])
    assert np.array_equal(r.load_angle, r.carrier_angle)
    assert np.array_equal(r.motor_speed, r.sun_speed)
    assert np.all(r.output_shaft_torque == T_OUT)
    assert np.array_equal(r.input_shaft_torque, r.input_torque)
    assert RATED.model_info()["generalized_mass"][3:] == [0.0, 0.0]


@pytest.mark.parametrize(("changes", "match"), [
    ({"shafts.output": {"stiffness": -1.0}}, r"shafts\.output\.stiffness must be > 0"),
    ({"inertias.load_inertia": 1.0, "shafts.output": {"stiffness": 1e6, "damping": -1.0}},
     r"shafts\.output\.damping must be >= 0"),
    ({"shafts.output": {"stiffness": 1e6}}, r"inertias\.load_inertia > 0"),
    ({"inertias.motor_inertia": -1.0}, r"inertias\.motor_inertia must be >= 0"),
    ({"shafts.input": {"stiffness": 1e4}, "drive": {"kind": "torque", "torque": 1.0}}, r"inertias\.motor_inertia > 0"),
    ({"shafts.input": {"stiffness": 0.0}}, r"shafts\.input\.stiffness must be > 0"),
])
def test_bad_shafts_are_scene_errors_naming_the_field(changes: dict[str, object], match: str) -> None:
    with pytest.raises(SceneError, match=match):
        RATED.replace(**changes)


@pytest.mark.parametrize("joints", ["rigid", "compliant"])
def test_modal_analysis_of_a_scene_with_shafts_models_them(joints: str) -> None:
    # The modal analysis adds the shafts' coordinates (tests/test_modal_shafts.py checks the
    # frequencies): the load angle with an output shaft, the sun angle with a drive shaft.
    from rvdyn.analysis import modes

    for shaft, name in (({"inertias.load_inertia": 5.0, "shafts.output": {"stiffness": 1e6}}, "load angle"),
                        ({"inertias.motor_inertia": 0.01, "shafts.input": {"stiffness": 1e4}}, "sun angle")):
        m = modes(_with(RATED.replace(**shaft), joints))
        assert m.dof_names[-1] == name and m.part_names[-1] == "shafts"


def test_a_scene_without_a_first_stage_reports_no_sun() -> None:
    # model_info listed the default sun (2.02 kg) and its inertia in the sun's generalised mass
    # for a scene whose stage1 is None.
    info = RATED.replace(stage1=None).model_info()
    assert info["sun_mass"] == 0.0 and info["sun_inertia"] == 0.0
    assert info["generalized_mass"][2] == 0.0 and info["generalized_mass"][0] > 0.0
    assert RATED.model_info()["sun_mass"] > 1.0
