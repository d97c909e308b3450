"""Every analysis accepts every kind of valid scene.

Each analysis builds its own copies and models of the scene (a rigid counterpart for the
LTCA's laws, a torque-driven free copy for the modes), and a rule added to the scene's
validation can refuse such a copy although the user's scene is valid: a compliant scene with
bearing friction failed in the LTCA, the loop and the modes that way, and a speed-driven
scene with a drive shaft in the modes. Here each valid scene variant goes through each
analysis at a small size; a refusal is a failure unless listed with its reason.
"""

from __future__ import annotations

import math
import warnings
from typing import Any, Callable

import numpy as np
import pytest

import rvdyn
from rvdyn import Scene
from rvdyn.analysis import running_friction, torque_twist, transmission_error

# The rated load's step at t = 0 overloads the bearings for a moment (simulate warns; tested
# in test_physical.py::test_bearing_static_rating_and_safety); not what these tests look at.
START_IMPACT = "the (eccentric|crank) bearings' load reaches"

RATED = 43_921.3


def _variants() -> dict[str, Scene]:
    paper, physical = Scene.paper("rated"), Scene.physical("rated")
    friction = {"pin": 0.05, "mesh": 0.05, "bearing": {"f0": 3.0, "f1": 3e-4, "viscosity": 68e-6}}
    harmonic = {"harmonics": [[2e-6, 3, 0.5]]}
    return {
        "paper rigid": paper,
        "paper compliant": paper.with_compliant_joints(),
        "paper single stage": paper.replace(stage1=None),
        "physical": physical,
        "physical friction": physical.replace(friction=friction),
        "physical shafts": physical.replace(**{"inertias.load_inertia": 20.0, "shafts.output": {"stiffness": 2e6},
                                               "shafts.input": {"stiffness": 1e5}}),
        "physical assembly errors": physical.replace(**{"errors.crank_eccentricity": [2e-6, 0.0, 0.0]}),
        "physical pin and profile errors": physical.replace(**{
            "pin_errors.radius": [1e-6] + [0.0] * 23,
            "discs": [{"phase": 0.0, "profile_error": harmonic}, {"phase": math.pi}]}),
        "physical gear errors": physical.replace(**{"gear_errors.sun.runout": 5e-6}),
        "physical modified": physical.replace(**{"cycloid.d_rrp": 2e-5, "cycloid.d_rp": -2e-5}),
    }


VARIANTS = _variants()


def _analyses(s: Scene) -> dict[str, Callable[[], Any]]:
    out: dict[str, Callable[[], Any]] = {
        "model_info": s.model_info,
        "simulate": lambda: rvdyn.simulate(s, 2e-3, record_interval=5e-4),
        "ltca": lambda: rvdyn.ltca(s, None, [0.0, 0.05]),
        "torque_twist": lambda: torque_twist(s, RATED, 0.0, 11),
        "transmission_error": lambda: transmission_error(s, None, 24, window=False),
        "modes": lambda: rvdyn.modes(s),
        "campbell": lambda: rvdyn.campbell(s, [150.0, 160.0], harmonics=2),
    }
    if s["friction.pin"] or s["friction.mesh"]:
        out["running_friction"] = lambda: running_friction(s, None, 12)
    return out


CASES = [(v, a) for v, s in VARIANTS.items() for a in _analyses(s)]


@pytest.mark.parametrize("variant, analysis", CASES, ids=[f"{v}-{a}" for v, a in CASES])
def test_every_analysis_accepts_every_valid_scene(variant: str, analysis: str) -> None:
    run = _analyses(VARIANTS[variant])[analysis]
    with warnings.catch_warnings():
        # Coarse grids and short runs warn on purpose (too few angles per tooth-mesh cycle,
        # a fixed step check); what is checked here is that nothing is refused.
        warnings.simplefilter("ignore", RuntimeWarning)
        out = run()
    assert out is not None
    if analysis == "ltca":
        assert np.all(np.isfinite(out.arrays["pin_force"])) and out.arrays["torque_balance"].max() < 1e-9
    if analysis == "modes":
        assert np.all(np.isfinite(out.frequency)) and out.frequency.max() > 0


@pytest.fixture(scope="module")
def steady_runs() -> dict[str, rvdyn.Result]:
    # Whole crank revolutions after the default 20 % start need about 0.14 s at the paper's
    # speed; a steady start with a step drive (the physical preset ramps from rest).
    with warnings.catch_warnings():
        warnings.filterwarnings("ignore", message=START_IMPACT, category=RuntimeWarning)
        return {v: rvdyn.simulate(s.replace(**{"initial": "steady", "drive.start": "step"}), 0.15,
                                  record_interval=2e-4)
                for v, s in VARIANTS.items()}


def _result_methods(r: rvdyn.Result, tmp: Any) -> dict[str, Callable[[], Any]]:
    return {
        "steady_window": r.steady_window,
        "mean_output_speed": r.mean_output_speed,
        "disc_path_radius": r.disc_path_radius,
        "loaded_pin_stats": r.loaded_pin_stats,
        "largest_moment_pin": lambda: r.largest_moment_pin(0.1),
        "energy_balance": r.energy_balance,
        "efficiency": r.efficiency,
        "friction_power_means": r.friction_power_means,
        "spectrum": lambda: r.spectrum("carrier_speed"),
        "modes_at": lambda: rvdyn.modes_at(r),
        "save_load": lambda: rvdyn.Result.load(r.save(tmp / "run.npz")),
        "plots": lambda: [p() for p in (r.plot_output_speed, r.plot_disc_center, r.plot_pin_moments,
                                        r.plot_loaded_pins, r.plot_input_torque, r.plot_energy)],
    }


@pytest.mark.parametrize("variant", list(VARIANTS))
def test_every_result_method_works_on_every_valid_scene(variant: str, steady_runs: dict[str, rvdyn.Result],
                                                        tmp_path: Any) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    r = steady_runs[variant]
    ratio = VARIANTS[variant].ratio
    speed = VARIANTS[variant]["drive.speed"]
    for name, call in _result_methods(r, tmp_path).items():
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", RuntimeWarning)
            try:
                out = call()
            except Exception as err:  # noqa: BLE001 - the method's name goes into the failure
                pytest.fail(f"{name}: {type(err).__name__}: {err}")
        assert out is not None, name
    plt.close("all")
    # A gear train cannot slip: input / ratio over whole crank revolutions (the soft output
    # shaft's torsional transient moves the carrier by 2e-4 here).
    assert r.mean_output_speed() == pytest.approx(speed / ratio, rel=1e-3)
    if VARIANTS[variant]["joints.kind"] == "compliant" and VARIANTS[variant]["joints.eccentric_bearing.rollers"]:
        with warnings.catch_warnings():
            # The physical preset's assumed bearings are past their ISO 76 static rating at the
            # rated load (docs/model.md, "Roller bearings"): said, and tested in test_physical.py.
            warnings.filterwarnings("ignore", message=".*ISO 76 static rating", category=RuntimeWarning)
            life = r.bearing_life()
        assert all(np.isfinite(v["l10_hours"]) and v["static_safety"] > 0 for v in life.values())
    else:
        with pytest.raises(rvdyn.ParameterError, match="rollers"):
            r.bearing_life()
