"""User contract of the quasi-static analysis (rvdyn.analysis): LTCA, TE, torque-twist loop,
loads for FEA, the analyze command; checked against a slow dynamic run of the same scene."""

from __future__ import annotations

import dataclasses
import json
import math
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import rvdyn
from rvdyn import Scene, simulate
from rvdyn.analysis import ARCMIN, ARCSEC, ltca, torque_twist, transmission_error

RATED = 43_921.3
INPUT_SPEED = math.radians(8328.0)
LINEAR = {"kind": "impact", "stiffness": 1.0e9, "exponent": 1.0, "max_damping": 2.0e5, "damping_depth": 1e-6}


@pytest.fixture(scope="module")
def slow_run() -> tuple[Scene, rvdyn.Result]:
    # Quasi-static: input at 1/50 of the paper's speed from a steady start, well damped linear
    # pin law (the setup of the classical load-sharing check in test_simulation.py).
    scene = Scene.paper("rated", **{"contact.pin": LINEAR, "drive.speed": INPUT_SPEED / 50, "initial": "steady"})
    return scene, simulate(scene, 0.4, "dopri5", atol=1e-10, record_interval=1e-3)


def test_ltca_agrees_with_a_slow_dynamic_run(slow_run: tuple[Scene, rvdyn.Result]) -> None:
    # Same scene and law, the input held where the run's input is: crank angle
    # psi = -zc th_s / i. Contract: peak pin force within 1 %, loaded-pin count exact, at the
    # last 5 samples of the steady window.
    scene, run = slow_run
    zc, ratio = 23.0, scene.ratio
    idx = np.arange(run.t.size - 5, run.t.size)
    psi = -zc * run.sun_angle[idx] / ratio
    res = ltca(scene, RATED, psi)
    for n, i in enumerate(idx):
        f_dyn = run.pin_force[i]
        f_st = res.pin_force[n]
        peak = f_st.max()
        assert abs(f_dyn.max() / peak - 1.0) < 0.01, (f_dyn.max(), peak)
        # Exact count: pins that carry more than a newton (the dynamic run's contact noise at
        # the edge of the loaded zone is far below that).
        assert np.array_equal((f_dyn > 1.0).sum(axis=1), (f_st > 1.0).sum(axis=1))


def test_te_agrees_with_the_slow_dynamic_run(slow_run: tuple[Scene, rvdyn.Result]) -> None:
    # TE = output - input / i over the steady window (0.2 s to 0.4 s, more than a mesh period
    # of 0.0134 s of crank angle at this speed): within 1 % of the LTCA's peak-to-peak, after
    # removing the mean (the run's mean carries the damper forces of the moving contacts).
    scene, run = slow_run
    i0 = np.searchsorted(run.t, 0.2)
    te_dyn = run.carrier_angle[i0:] - run.sun_angle[i0:] / scene.ratio
    psi = -23.0 * run.sun_angle[i0:] / scene.ratio
    res = ltca(scene, RATED, psi)
    te_st = res.transmission_error
    pp = np.ptp(te_st)
    assert pp > 0
    diff = (te_dyn - te_dyn.mean()) - (te_st - te_st.mean())
    assert np.max(np.abs(diff)) < 0.01 * pp, (np.max(np.abs(diff)), pp)


def test_result_arrays_balances_and_plots(tmp_path: Path) -> None:
    scene = Scene.paper("rated").with_compliant_joints()
    res = ltca(scene, RATED, np.linspace(0.0, 0.2, 7))
    n = 7
    assert res.pin_force.shape == (n, 2, 24)
    assert res.contact_point.shape == (n, 2, 24, 2)
    assert res.loaded_pins.shape == (n, 2)
    assert res.eccentric_bearing_force.shape == (n, 3, 2, 2)
    assert res.crank_bearing_force.shape == (n, 3, 2)
    assert np.all(res.torque_balance < 1e-9)
    assert np.all(res.residual < 1e-9)
    assert np.all(res.transmission_error < 0)
    # Unloaded pins carry nothing and have no Hertz strip.
    assert np.all((res.pin_force > 0) == (res.half_width > 0))
    s = res.summary()
    assert 10 <= s["loaded_pins_min"] <= s["loaded_pins_max"] <= 13
    for fig in (res.plot_load_distribution(), res.plot_load_distribution(polar=False),
                res.plot_contact_pressure()):
        assert fig.axes
    csv_path, json_path = res.save_fea_loads(tmp_path)
    doc = json.loads(json_path.read_text())
    assert doc["format"] == "rvdyn-ltca-loads/1"
    lines = csv_path.read_text().splitlines()
    assert lines[0].startswith("disc,pin,crank_angle_rad")
    assert len(lines) == len(doc["loads"]) + 1
    worst = max(ld["force"] for ld in doc["loads"])
    assert worst == pytest.approx(res.peak_pin_force, rel=1e-15)


def test_single_stage_input_torque_and_balance() -> None:
    # Without a first stage the cranks are the input. With rigid joints the disc forces never
    # reached the crank coordinates: input torque 0 and a torque balance of 4.3 %. Lossless
    # statics give T / i with i = -zc (-1909.6 N m); the compliant model, which always had it
    # right, agrees. Tolerances: the discrete pins move the input torque by 0.1 % over a pitch.
    t = 43921.3
    for scene in (Scene.paper("rated", stage1=None), Scene.paper("rated", stage1=None).with_compliant_joints()):
        res = ltca(scene, t, [0.0, 0.1])
        np.testing.assert_allclose(res.arrays["input_torque"], -t / 23, rtol=2e-3)
        assert np.all(res.arrays["torque_balance"] < 1e-9)


def test_zero_load_zero_te_and_reversed_torque_mirrors() -> None:
    scene = Scene.paper("rated")
    zero = ltca(scene, 0.0, [0.0, 0.3])
    assert np.max(np.abs(zero.transmission_error)) < 1e-12
    # Round-off forces (1e-15 N) are neither loaded pins nor FEA loads (7-8 pins were).
    assert np.all(zero.arrays["loaded_pins"] == 0) and zero.fea_csv.count("\n") == 1
    te = transmission_error(scene.replace(**{"cycloid.d_rrp": 2e-5, "cycloid.d_rp": -2e-5}), RATED, 24)
    # Mirror symmetry: reverse TE at psi = -(forward TE) at -psi; over a whole period the
    # peak-to-peak values agree.
    pp = te.peak_to_peak()
    assert pp["forward"] == pytest.approx(pp["reverse"], rel=1e-6)
    assert np.all(te.lost_motion() > 0)
    assert te.plot().axes
    # The repr gives the figures (arcsec), not the arrays.
    text = repr(te)
    assert "array" not in text and len(text) < 300
    assert f"forward {pp['forward'] / ARCSEC:.4g}" in text and "points=24" in text


def test_torque_twist_loop_units_and_conventions() -> None:
    scene = Scene.paper("rated").replace(**{"cycloid.d_rrp": 2e-5, "cycloid.d_rp": -2e-5})
    loop = torque_twist(scene, RATED, 0.0, 41)
    s = loop.summary()
    assert loop.torque.shape == loop.twist.shape == (41,)
    assert s["rigidity_Nm_per_arcmin"] == pytest.approx(loop.rigidity * ARCMIN)
    assert loop.backlash > 0 and loop.lost_motion > loop.backlash
    # Twist grows with torque on the loading branch.
    up = loop.torque[:11]
    assert np.all(np.diff(loop.twist[:11]) > 0) and up[-1] == pytest.approx(RATED)
    assert loop.plot().axes
    assert ARCSEC * 60 == pytest.approx(ARCMIN)
    text = repr(loop)
    assert "array" not in text and "points=41" in text
    assert f"rigidity={s['rigidity_Nm_per_arcmin']:.6g} N m/arcmin" in text


def test_bad_input_is_a_clear_error() -> None:
    scene = Scene.paper("rated")
    with pytest.raises(rvdyn.ParameterError):
        ltca(scene, float("nan"), [0.0])
    with pytest.raises(rvdyn.ParameterError):
        ltca(scene, RATED, [float("inf")])
    with pytest.raises(rvdyn.ConvergenceError, match="crank angle"):
        ltca(scene, 1e9, [0.1])
    with pytest.raises(rvdyn.ParameterError):
        ltca("paper", RATED, [0.0])  # type: ignore[arg-type]
    # A count where angles belong (transmission_error takes a count) is refused, not solved at
    # 360 rad; a float angle in a list is the way to one angle.
    for count in (360, np.int64(90)):
        with pytest.raises(rvdyn.ParameterError, match="not a count"):
            ltca(scene, RATED, count)  # type: ignore[arg-type]
    assert ltca(scene, RATED, [360.0]).crank_angle.tolist() == [360.0]


def test_analyze_command_writes_figures_loads_and_summary(tmp_path: Path) -> None:
    out = tmp_path / "out"
    r = subprocess.run([sys.executable, "-m", "rvdyn", "analyze", "--out", str(out), "--angles", "12",
                        "--loop-points", "21"], capture_output=True, text=True, timeout=300)
    assert r.returncode == 0, r.stderr
    for name in ("load_distribution.png", "contact_pressure.png", "transmission_error.png",
                 "torque_twist.png", "compliance_budget.png", "fea_loads.csv", "fea_loads.json", "summary.md",
                 "summary.json"):
        assert (out / name).exists(), name
    summary = json.loads((out / "summary.json").read_text())
    assert summary["rigidity_Nm_per_arcmin"] > 0 and summary["scene"] == "physical"
    # The compliance budget at the torque: every family of the physical preset, shares summing to 1.
    budget = summary["compliance_budget"]
    assert set(budget["share"]) == {"pin contacts", "sun/planet meshes", "eccentric bearings", "crank bearings"}
    assert sum(budget["share"].values()) == pytest.approx(1.0, abs=1e-9)
    assert budget["torque_Nm"] == pytest.approx(summary["torque_Nm"], rel=1e-12)
    assert "compliance budget at" in (out / "summary.md").read_text()
    assert "LTCA: 12/12" in r.stderr
    # The TE figures are transmission_error's located extremes only (not also the samples'
    # peak-to-peak of the load sweep), and 12 angles are too few for the ISO tooth-mesh cycle.
    assert not any(k.startswith("te_peak_to_peak") and k != "te_peak_to_peak_arcsec" for k in summary)
    assert set(summary["te_peak_to_peak_arcsec"]) == {"forward", "reverse", "unloaded_forward",
                                                      "unloaded_reverse"}
    assert "use --angles >= 84" in r.stderr
    # The forward TE's largest harmonics, each with its order, label and uncertainty (None where
    # the grid gives no estimate; JSON has no NaN).
    h = summary["te_harmonics_forward"]
    assert len(h) == 3 and all(x["amplitude_arcsec"] > 0 and x["order"] > 0 for x in h)
    assert all(x["uncertainty_arcsec"] is None or x["uncertainty_arcsec"] >= 0 for x in h)
    assert "NaN" not in (out / "summary.json").read_text()
    assert "largest TE harmonics (forward)" in (out / "summary.md").read_text()
    # The paper preset by flag.
    r = subprocess.run([sys.executable, "-m", "rvdyn", "analyze", "--preset", "paper", "--out", str(out),
                        "--angles", "6", "--loop-points", "21"], capture_output=True, text=True, timeout=300)
    assert r.returncode == 0, r.stderr
    assert json.loads((out / "summary.json").read_text())["scene"] == "paper"


def test_large_crank_angles_converge_or_say_why() -> None:
    """Crank angles of many turns (a long dynamic run's, say): the round-off floor of Newton's
    test grows with the largest unknown as a length (docs/model.md, "Newton iteration"), so the
    physical preset converges at 6e4 rad (a ConvergenceError before, from about 1e4 rad) to
    the equilibrium of the same crank position (TE within 3e-7 rad of it at 0.3 rad: the roller
    sets fixed in the frame do not repeat with the mesh period, docs/model.md, "Mesh period");
    where it still cannot (the paper preset at 6e4 rad), the error says to give the angle
    modulo the mesh period."""
    rated = 43_921.3
    scene = Scene.physical("rated")
    period = float(rvdyn._core.LtcaSolver(scene._compiled, 1e-12).mesh_period)
    far = ltca(scene, rated, [0.3 + 10_000 * period])
    near = ltca(scene, rated, [0.3])
    assert far.residual[0] < 1e-8 and far.torque_balance[0] < 1e-8
    assert abs(far.transmission_error[0] - near.transmission_error[0]) < 3e-7
    assert far.loaded_pins.tolist() == near.loaded_pins.tolist()
    with pytest.raises(rvdyn.ConvergenceError, match="modulo the mesh period"):
        ltca(Scene.paper("rated"), rated, [60_000.3])


def test_te_harmonics_of_a_known_curve_are_exact() -> None:
    """Harmonics of a TE made of two cosines on the physical preset's grid (336 samples over a
    mesh period of 2.375 input revolutions): amplitudes and phases exact to round-off, orders
    k / 2.375, and the pin-pass (k = 23, order 9.684) and sun-mesh (k = 42, order 17.684)
    labels of the scene's excitation orders; the half-grid uncertainty is round-off too."""
    real = transmission_error(Scene.physical("rated"), RATED, 336, window=False)
    n = real.crank_angle.size
    j = np.arange(n)
    curve = 3e-6 + 2e-6 * np.cos(2 * np.pi * 23 * j / n + 0.4) + 5e-7 * np.cos(2 * np.pi * 42 * j / n - 1.1)
    te = dataclasses.replace(real, forward=curve)
    h = te.harmonics("forward", 3)
    assert [x.harmonic for x in h[:2]] == [23, 42]
    assert h[0].amplitude == pytest.approx(2e-6, rel=1e-12) and h[0].phase == pytest.approx(0.4, abs=1e-10)
    assert h[1].amplitude == pytest.approx(5e-7, rel=1e-12) and h[1].phase == pytest.approx(-1.1, abs=1e-10)
    assert h[2].amplitude < 1e-20
    assert te.input_turns == pytest.approx(57 / 24, rel=1e-12)
    assert h[0].order == pytest.approx(23 * 24 / 57, rel=1e-12) and h[0].label == "pin pass"
    assert h[1].order == pytest.approx(42 * 24 / 57, rel=1e-12) and h[1].label == "sun mesh"
    assert h[0].uncertainty < 1e-20 and h[1].uncertainty < 1e-20
    # The paper preset's period is one pin pass: harmonic k is pin pass x k.
    paper = transmission_error(Scene.paper("rated"), RATED, 24).harmonics("forward", 2)
    assert paper[0].harmonic == 1 and paper[0].label == "pin pass"
    with pytest.raises(rvdyn.ParameterError, match="window must be True"):
        transmission_error(Scene.paper("rated"), RATED, 24, window="yes")  # type: ignore[arg-type]
    with pytest.raises(rvdyn.ParameterError, match="curve must be one of"):
        te.harmonics("sideways")
    with pytest.raises(rvdyn.ParameterError, match="count must be"):
        te.harmonics("forward", 0)
    with pytest.raises(rvdyn.ParameterError, match="was not computed"):
        dataclasses.replace(te, unloaded_forward=np.zeros(0)).harmonics("unloaded_forward")


def test_light_load_and_torque_limits() -> None:
    # A light load above the torque was accepted and then advised to be raised further; a zero
    # --torque failed only in the loop, after the LTCA and the TE.
    from rvdyn.analysis import transmission_error

    with pytest.raises(rvdyn.ParameterError, match="light must be a load between 0 and the torque"):
        transmission_error(rvdyn.Scene.paper("rated"), None, 6, light=1e9)
    r = subprocess.run([sys.executable, "-m", "rvdyn", "analyze", "--torque", "0"], capture_output=True,
                       text=True, timeout=300)
    assert r.returncode == 1 and "--torque must be a finite, non-zero" in r.stderr


def test_a_bearing_clearance_lengthens_the_te_window() -> None:
    # With clearance the load sharing among the cranks depends on where their seats stand
    # against the pins: the TE repeats only when the carrier has turned by a pin pitch (23 mesh
    # periods of crank angle). One period gave a forward peak-to-peak of 0.49 arcsec against 2.27
    # over the whole curve, and a reverse curve 3 times the forward.
    bearings = ({"stiffness": 1e9, "damping": 1e4, "clearance": 50e-6},
                {"stiffness": 2e9, "damping": 1e4, "clearance": 50e-6})
    scene = Scene.paper().with_compliant_joints(*bearings)
    with pytest.warns(RuntimeWarning, match="depend on the path"):  # the light-load curves float
        te = transmission_error(scene, 4024.9, 24)
    assert te.periods == 23 and te.window == pytest.approx(2 * math.pi * 23 / 24, rel=1e-12)
    pp = te.peak_to_peak()
    # Without friction the reverse curve is the forward one mirrored over the window.
    assert pp["reverse"] == pytest.approx(pp["forward"], rel=1e-6)
    assert pp["forward"] / ARCSEC > 2.2
    again = ltca(scene, 4024.9, [0.1, 0.1 + te.window]).transmission_error
    assert abs(again[1] - again[0]) < 1e-14
    # Linear bearings without clearance repeat after one mesh period.
    assert transmission_error(Scene.paper().with_compliant_joints(), 4024.9, 24).periods == 1
