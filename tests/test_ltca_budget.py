"""The compliance budget (rvdyn.analysis.compliance_budget; docs/model.md, "Compliance budget")."""

from __future__ import annotations

import math

import numpy as np
import pytest

import rvdyn
from rvdyn.analysis import ARCMIN, ComplianceBudget, compliance_budget, torque_twist
from rvdyn.errors import ParameterError

RATED = 43921.3


@pytest.mark.parametrize("psi", [0.0, 0.1, 0.2])
def test_a_family_made_rigid_takes_its_part_with_it_rigid_joints(psi: float) -> None:
    """The torque path runs through the pins and the first-stage mesh in series: a scene with
    the other family 1e6 times stiffer (a new scene, a new equilibrium) has the compliance the
    budget gives that family. What differs: with the other family rigid the crank angle and
    with it the pins' load sharing move a little (measured: 9.7e-5 of the compliance with the
    mesh rigid, 1.5e-4 with the pins rigid). Asserted: 3e-4 of the compliance."""
    sc = rvdyn.Scene.paper("rated")
    b = compliance_budget(sc, RATED, psi)
    c = 1.0 / b.torsional_stiffness[0]
    pins = b.compliance[0, :2].sum()
    mesh = b.compliance[0, b.parts.index("sun/planet meshes")]
    k = sc["contact.mesh.stiffness"]
    rigid_mesh = compliance_budget(sc.replace(**{"contact.mesh.stiffness": 1e6 * k}), RATED, psi)
    rigid_pins = compliance_budget(sc.replace(**{"contact.pin.stiffness": 1e6 * sc["contact.pin.stiffness"]}),
                                   RATED, psi)
    assert 1.0 / rigid_mesh.torsional_stiffness[0] == pytest.approx(pins, abs=3e-4 * c)
    assert 1.0 / rigid_pins.torsional_stiffness[0] == pytest.approx(mesh, abs=3e-4 * c)
    assert mesh > 0.01 * c  # a part the check can see


@pytest.mark.parametrize("psi", [0.0, 0.1, 0.2])
def test_a_family_made_rigid_takes_its_part_with_it_compliant_joints(psi: float) -> None:
    """Compliant joints: carrier, crank bearings, cranks, eccentric bearings, discs and pins in
    series, and the cranks' mesh. Each bearing family and the mesh 1e4 times stiffer lowers the
    compliance by the budget's part of it (less 1e-4 of that part, what the stiffer family keeps).
    What differs: the bodies move by the removed deflection, which shifts the pins' load sharing
    (measured: up to 8.6e-4 of the compliance, the eccentric bearings at crank angle 0.1).
    Asserted: 2e-3 of the compliance."""
    sc = rvdyn.Scene.paper("rated").with_compliant_joints()
    b = compliance_budget(sc, RATED, psi)
    c = 1.0 / b.torsional_stiffness[0]
    keys = {"eccentric bearings": "joints.eccentric_bearing.stiffness",
            "crank bearings": "joints.crank_bearing.stiffness", "sun/planet meshes": "contact.mesh.stiffness"}
    for name, key in keys.items():
        part = b.compliance[0, b.parts.index(name)]
        stiff = compliance_budget(sc.replace(**{key: 1e4 * sc[key]}), RATED, psi)
        drop = c - 1.0 / stiff.torsional_stiffness[0]
        assert drop == pytest.approx(part, abs=2e-3 * c), name
        assert part > 0.01 * c, name


def test_budget_of_the_physical_preset_adds_up_and_matches_the_loop_tangent() -> None:
    sc = rvdyn.Scene.physical("rated")
    b = compliance_budget(sc, [0.25 * RATED, RATED])
    assert b.parts == ("pin contacts disc 0", "pin contacts disc 1", "sun/planet meshes", "eccentric bearings",
                       "crank bearings")
    assert b.compliance.shape == (2, 5) and b.torque.shape == (2,)
    np.testing.assert_allclose(b.share.sum(axis=1), 1.0, atol=1e-10)
    assert np.all(b.split_error < 1e-10)
    assert np.all(b.compliance > 0)
    # The same tangent as the torque-twist loop's at its +rated point (crank angle 0).
    loop = torque_twist(sc, RATED, 0.0, 21, friction=False)
    i = int(np.argmax(loop.torque))
    assert b.torsional_stiffness[1] == pytest.approx(loop.tangent_stiffness[i], rel=1e-9)
    g = b.grouped()
    assert g.parts == ("pin contacts", "sun/planet meshes", "eccentric bearings", "crank bearings")
    np.testing.assert_allclose(g.compliance[:, 0], b.compliance[:, :2].sum(axis=1), rtol=1e-15)
    rows = b.table()
    assert [r["share"] for r in rows] == sorted((r["share"] for r in rows), reverse=True)
    assert rows[0]["stiffness_Nm_per_arcmin"] == pytest.approx(1.0 / (b.compliance[1].max()) * ARCMIN)
    s = b.summary()
    assert s["torque_Nm"] == RATED and sum(s["share"].values()) == pytest.approx(1.0)
    assert s["tangent_stiffness_Nm_per_arcmin"] == pytest.approx(b.torsional_stiffness[1] * ARCMIN)
    assert b.where(0).startswith(b.grouped().table(0)[0]["part"])
    assert "ComplianceBudget(" in repr(b) and "%" in repr(b)
    # Read-only arrays, as every result's.
    with pytest.raises(ValueError):
        b.compliance[0, 0] = 1.0


def test_default_torque_is_the_scenes_load_and_a_negative_torque_works() -> None:
    sc = rvdyn.Scene.paper("rated")
    b = compliance_budget(sc)
    assert b.torque.tolist() == [sc["load.torque"]]
    r = compliance_budget(sc, -sc["load.torque"])
    # Rigid joints without errors: the reverse drive's tangent is the forward's mirror.
    assert r.torsional_stiffness[0] == pytest.approx(b.torsional_stiffness[0], rel=1e-6)


def test_plots_for_one_and_several_torques() -> None:
    from matplotlib.figure import Figure

    sc = rvdyn.Scene.paper("rated")
    one = compliance_budget(sc).plot()
    many = compliance_budget(sc, RATED * np.array([0.2, 0.6, 1.0])).plot()
    assert isinstance(one, Figure) and isinstance(many, Figure)
    assert len(one.axes[0].patches) == 2  # bars: the pins (both discs) and the meshes
    assert len(many.axes[0].collections) == 2  # stacked areas


@pytest.mark.parametrize("torque, message", [
    (0.0, "small torque"), (math.nan, "finite"), ([RATED, math.inf], "finite"), ([[RATED]], "1-D"),
    ([], "non-empty"), ("x", "number"), (["a"], "real numbers"),
])
def test_bad_torques_are_parameter_errors(torque: object, message: str) -> None:
    with pytest.raises(ParameterError, match=message):
        compliance_budget(rvdyn.Scene.paper("rated"), torque)  # type: ignore[arg-type]


def test_bad_crank_angle_scene_and_index_are_parameter_errors() -> None:
    sc = rvdyn.Scene.paper("rated")
    with pytest.raises(ParameterError, match="crank_angle"):
        compliance_budget(sc, RATED, math.inf)
    with pytest.raises(ParameterError, match="rvdyn.Scene"):
        compliance_budget("paper", RATED)  # type: ignore[arg-type]
    b = compliance_budget(sc, RATED)
    for bad in (1, -2, 0.5, True):
        with pytest.raises(ParameterError, match="index"):
            b.table(bad)  # type: ignore[arg-type]
    assert isinstance(b, ComplianceBudget)


def test_a_body_free_in_its_clearances_is_a_convergence_error() -> None:
    # 1e-3 N m on the physical preset: the roller bearings' clearances leave the tangent singular.
    with pytest.raises(rvdyn.ConvergenceError, match="free in its clearances.*larger torque"):
        compliance_budget(rvdyn.Scene.physical("rated"), 1e-3)


@pytest.mark.parametrize("bearing, tolerance", [("crank_bearing", 0.01), ("eccentric_bearing", 0.02)])
def test_the_budget_predicts_a_design_change(bearing: str, tolerance: float) -> None:
    """The physical preset with one bearing's rollers 25 % longer (a new scene, new equilibrium).
    At the same roller loads Palmgren's line contact (delta ~ Q^0.9 / l^0.8, docs/model.md,
    "Bearings") makes that family's compliance 1.25^0.8 times smaller, so the budget predicts
    the change of the tangent compliance as -c_f (1 - 1.25^-0.8), to first order. What it leaves
    out: the loads move among the rollers and the bodies (measured: 0.16 % of the change for the
    crank bearings, 0.8 % for the eccentric bearings). Asserted: 1 % and 2 % of the change, a
    change of 5-8 % of the compliance."""
    sc = rvdyn.Scene.physical("rated")
    b = compliance_budget(sc)
    c = 1.0 / b.torsional_stiffness[0]
    name = bearing.replace("_", " ") + "s"
    predicted = -b.compliance[0, b.parts.index(name)] * (1.0 - 1.25 ** -0.8)
    assert 1.0 / b.predict({name: 1.25 ** 0.8})[0] - c == pytest.approx(predicted, rel=1e-12)
    key = f"joints.{bearing}.rollers.length"
    longer = sc.replace(**{key: 1.25 * sc[key]})
    actual = 1.0 / compliance_budget(longer).torsional_stiffness[0] - c
    assert actual == pytest.approx(predicted, rel=tolerance)
    assert -0.1 * c < actual < -0.04 * c


def test_predict_is_the_series_rule_and_checks_its_input() -> None:
    b = compliance_budget(rvdyn.Scene.physical("rated"), [0.5 * RATED, RATED])
    c = 1.0 / b.torsional_stiffness
    g = b.grouped()
    pins, crank = g.compliance[:, 0], g.compliance[:, g.parts.index("crank bearings")]
    want = 1.0 / (c - pins * (1 - 1 / 2.0) - crank * (1 - 1 / 1.5))
    np.testing.assert_allclose(b.predict({"pin contacts": 2.0, "crank bearings": 1.5}), want, rtol=1e-14)
    # One disc's pins alone; a factor of 1 changes nothing; rigid parts leave the others.
    one = b.predict({"pin contacts disc 0": 1e12})
    np.testing.assert_allclose(one, 1.0 / (c - b.compliance[:, 0] * (1 - 1e-12)), rtol=1e-14)
    np.testing.assert_allclose(b.predict({"eccentric bearings": 1.0}), b.torsional_stiffness, rtol=1e-15)
    for bad, message in [({}, "non-empty"), ([1.0], "dict"), ({"gears": 2.0}, "no part 'gears'"),
                         ({"crank bearings": 0.0}, r"\[1e-12, 1e12\]"), ({"crank bearings": math.nan}, "finite"),
                         ({"crank bearings": "x"}, "number"),
                         ({"pin contacts": 2.0, "pin contacts disc 1": 2.0}, "not both")]:
        with pytest.raises(ParameterError, match=message):
            b.predict(bad)  # type: ignore[arg-type]


LAYOUT = {"bearings": [-0.06, 0.06], "discs": [-0.02, 0.02], "planet": -0.09}


def test_crank_bending_is_a_part_of_the_budget_and_behaves_as_one() -> None:
    """The physical preset with 45 mm crankshafts between bearings 120 mm apart (docs/model.md,
    "Crankshaft bending"): the bending is a part of the budget, and shafts of a material 1.5
    and 4.85 times stiffer (bending and shear alike, at the same loads) change the compliance
    as ``predict`` says, within 2 % of the change (the loads move a little)."""
    sc = rvdyn.Scene.physical("rated").replace(crank_layout=LAYOUT, crank_shaft={"diameter": 0.045})
    b = compliance_budget(sc)
    assert b.parts[-1] == "crank bending"
    c = 1.0 / b.torsional_stiffness[0]
    part = b.compliance[0, -1]
    assert part > 0.2 * c
    for factor in (1.5, 1e12 / 2.06e11):
        predicted = b.predict({"crank bending": factor})[0]
        stiffer = sc.replace(**{"crank_shaft.modulus": factor * 2.06e11})
        actual = compliance_budget(stiffer).torsional_stiffness[0]
        assert 1.0 / actual - c == pytest.approx(1.0 / predicted - c, rel=0.02)
        assert 1.0 / predicted - c == pytest.approx(-part * (1 - 1 / factor), rel=1e-12)
    # Without the shaft the cranks are rigid: the budget of the preset.
    rigid = compliance_budget(rvdyn.Scene.physical("rated"))
    assert "crank bending" not in rigid.parts and rigid.torsional_stiffness[0] > b.torsional_stiffness[0]


def test_bending_crank_scenes_name_what_is_wrong() -> None:
    """Bad crank_shaft values are named; the dynamic model gains each eccentric's centre (two
    coordinates per crank and disc: tests/test_dynamic_crank_bending.py)."""
    sc = rvdyn.Scene.physical("rated").replace(crank_layout=LAYOUT, crank_shaft={"diameter": 0.045})
    assert sc.model_info()["dof"] == rvdyn.Scene.physical("rated").model_info()["dof"] + 2 * 3 * 2
    with pytest.raises(rvdyn.SceneError, match="needs crank_layout"):
        rvdyn.Scene.physical("rated").replace(crank_shaft={"diameter": 0.045})
    with pytest.raises(rvdyn.SceneError, match="compliant joints"):
        rvdyn.Scene.paper("rated").replace(crank_layout=LAYOUT, crank_shaft={"diameter": 0.045})
    with pytest.raises(rvdyn.SceneError, match=r"crank_shaft: diameter must be in \(0, 1\] m"):
        rvdyn.Scene.physical("rated").replace(crank_layout=LAYOUT, crank_shaft={"diameter": 45.0})
    with pytest.raises(rvdyn.SceneError, match="bearing's plane"):
        rvdyn.Scene.physical("rated").replace(crank_layout={**LAYOUT, "discs": [-0.06, 0.02]},
                                              crank_shaft={"diameter": 0.045})
