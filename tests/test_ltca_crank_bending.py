"""Crankshaft bending in the LTCA (scene field ``crank_shaft``; docs/model.md, "Crankshaft
bending"): the reported deflections against beam theory."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

import rvdyn

LAYOUT = {"bearings": [-0.06, 0.06], "discs": [-0.02, 0.02], "planet": -0.09}


def simple_span_flexibility(z: list[float], supports: tuple[float, float], ei: float, gas: float) -> np.ndarray:
    """Deflection at ``z[k]`` per unit load at ``z[l]`` of a simply supported Timoshenko span
    (loads between the supports): bending ``b x (L^2 - b^2 - x^2) / (6 E I L)`` (Young & Budynas
    2002, table 8.1) plus shear ``b x / (kappa G A L)`` for ``x <= a``, mirrored for ``x > a``."""
    za, zb = supports
    span = zb - za
    c = np.empty((len(z), len(z)))
    for k, zk in enumerate(z):
        for j, zl in enumerate(z):
            x, a = zk - za, zl - za
            if x > a:
                x, a = span - x, span - a
            b = span - a
            c[k, j] = b * x * (span**2 - b**2 - x**2) / (6.0 * ei * span) + b * x / (gas * span)
    return c


def test_reported_deflections_are_the_beam_under_the_eccentric_loads() -> None:
    """Each crank's eccentric deflections equal the closed-form flexibility times the forces on
    its eccentrics (minus the reported forces on the discs), at every crank angle: the beam
    and the eccentric bearings in balance at each eccentric. Equal to the equilibrium's
    residual (1e-12 of the load): asserted 1e-9 of the largest deflection, which is tens of
    micrometres (a visible effect)."""
    d = 0.045
    sc = rvdyn.Scene.physical("rated").replace(crank_layout=LAYOUT, crank_shaft={"diameter": d})
    res = rvdyn.ltca(sc, crank_angles=np.linspace(0.0, 1.0, 5))
    ei = 2.06e11 * math.pi * d**4 / 64.0
    nu = 0.3  # steel, the default; Cowper's shear coefficient of a solid circle
    gas = 6 * (1 + nu) / (7 + 6 * nu) * 2.06e11 / (2 * (1 + nu)) * math.pi * d**2 / 4
    c = simple_span_flexibility([-0.02, 0.02], (-0.06, 0.06), ei, gas)
    defl = res.crank_deflection
    assert defl.shape == (5, 3, 2, 2)
    # (angles, cranks, discs, 2): deflection u = C (force on the eccentric) = -C (force on the disc).
    want = -np.einsum("kl,ncla->ncka", c, res.eccentric_bearing_force)
    scale = np.abs(defl).max()
    assert scale > 1e-5
    np.testing.assert_allclose(defl, want, rtol=0, atol=1e-9 * scale)
    # Without the shaft: no deflections.
    assert rvdyn.ltca(rvdyn.Scene.physical("rated"), crank_angles=[0.0]).crank_deflection.shape == (1, 0, 2, 2)



def _with_forces(forces: np.ndarray, discs: list[float], diameter: float) -> rvdyn.analysis.LtcaResult:
    scene = {"crank_layout": {"bearings": [-0.06, 0.06], "discs": discs, "planet": -0.09},
             "crank_shaft": {"diameter": diameter, "modulus": 2.06e11}}
    return rvdyn.analysis.LtcaResult(torque=1.0, mesh_period=1.0, ratio=1.0, face_width=0.01,
                                     arrays={"eccentric_bearing_force": forces}, fea_csv="", fea_json="",
                                     scene=scene)


def test_crank_bending_stress_is_the_beam_statics() -> None:
    """Closed forms of a simply supported beam: two equal forces P, same direction, at +-20 mm
    between bearings at +-60 mm: reactions P, the moment P * 40 mm between the loads; one force
    P at 20 mm beyond a bearing (an overhang): the moment P * 20 mm at that bearing. The stress
    is 32 M / (pi d^3), whatever the direction of P in the plane. Exact to round-off."""
    d, p = 0.05, 1e5
    u = np.array([0.6, -0.8])
    both = _with_forces(-(p * u)[None, None, None, :] * np.ones((1, 1, 2, 2)), [-0.02, 0.02], d)
    assert both.crank_bending_stress() == pytest.approx(32 * p * 0.04 / (math.pi * d**3), rel=1e-12)
    over = _with_forces(-(p * u)[None, None, None, :] * np.ones((1, 1, 1, 2)), [0.08], d)
    assert over.crank_bending_stress() == pytest.approx(32 * p * 0.02 / (math.pi * d**3), rel=1e-12)
    # Opposite forces (a couple): reactions (P 40 mm / 120 mm), the moment largest at the loads.
    couple = np.stack([-p * u, p * u])[None, None]
    want = p * 0.04 / 0.12 * 0.04
    assert _with_forces(couple, [-0.02, 0.02], d).crank_bending_stress() == pytest.approx(
        32 * want / (math.pi * d**3), rel=1e-12)
    with pytest.raises(rvdyn.ParameterError, match="crank_shaft"):
        rvdyn.ltca(rvdyn.Scene.physical("rated"), crank_angles=[0.0]).crank_bending_stress()


def test_analyze_reports_the_bending_cranks(tmp_path: Path) -> None:
    import json
    import subprocess
    import sys

    scene = rvdyn.Scene.physical("rated").replace(crank_layout=LAYOUT, crank_shaft={"diameter": 0.045})
    path = scene.save(tmp_path / "bent.toml")
    out = tmp_path / "out"
    r = subprocess.run([sys.executable, "-m", "rvdyn", "analyze", str(path), "--out", str(out), "--angles", "12",
                        "--loop-points", "21"], capture_output=True, text=True, timeout=300)
    assert r.returncode == 0, r.stderr
    summary = json.loads((out / "summary.json").read_text())
    want = rvdyn.ltca(scene, crank_angles=np.arange(12) * summary["mesh_period_rad"] / 12).crank_bending_stress()
    assert summary["crank_bending_stress_max_Pa"] == pytest.approx(float(want.max()), rel=1e-9)
    assert "crank bending" in summary["compliance_budget"]["share"]
    assert "largest nominal bending stress" in (out / "summary.md").read_text()


def test_the_ltca_kernel_gives_the_bending_metrics() -> None:
    """``LtcaKernel(crank_bending=True)``: the largest stress and deflection of the LTCA over
    the kernel's crank angles (two per tooth-mesh cycle of the physical preset's ISO mesh), with
    their units; a scene without ``crank_shaft`` is a ParameterError."""
    scene = rvdyn.Scene.physical("rated").replace(crank_layout=LAYOUT, crank_shaft={"diameter": 0.045})
    kernel = rvdyn.study.LtcaKernel(crank_bending=True, window=False)
    assert kernel.metrics[-2:] == tuple(rvdyn.study.LTCA_CRANK_METRICS)
    got = kernel(scene)
    n = rvdyn.analysis.tooth_mesh_angles(scene)
    period = rvdyn.ltca(scene, crank_angles=[0.0]).mesh_period
    res = rvdyn.ltca(scene, crank_angles=period * np.arange(n) / n)
    assert got["crank_bending_stress_max"] == float(res.crank_bending_stress().max())
    assert got["crank_deflection_max"] == float(np.linalg.norm(res.crank_deflection, axis=-1).max())
    assert rvdyn.study.kernels.metric_units(kernel)["crank_bending_stress_max"] == "Pa"
    with pytest.raises(rvdyn.ParameterError, match="crank_bending=True needs a scene with crank_shaft"):
        kernel(rvdyn.Scene.physical("rated"))
    with pytest.raises(rvdyn.ParameterError, match="crank_bending must be True or False"):
        rvdyn.study.LtcaKernel(crank_bending="yes")  # type: ignore[arg-type]
