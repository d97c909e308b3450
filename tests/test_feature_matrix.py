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
