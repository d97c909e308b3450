"""Modes of the physical preset (line-contact pins, ISO 6336 meshes, roller bearings): the mode
table at rated load, and the main torsional mode against the free vibration of the nonlinear
dynamic model."""

from __future__ import annotations

import math

import numpy as np
import pytest

import rvdyn
from conftest import ringing

RATED = 43921.26037602  # 57 x 112 kW / 8328 deg/s [N m]


def test_physical_mode_table() -> None:
    m = rvdyn.modes(rvdyn.Scene.physical("rated"), crank_angle=0.0)
    assert len(m) == len(m.dof_names) == 16
    assert m.part_names == ["pin contacts disc 0", "pin contacts disc 1", "sun/planet meshes",
                            "eccentric bearings", "crank bearings"]
    assert m.residual < 1e-9 and m.split_error < 1e-12
    assert np.all(m.matched)
    np.testing.assert_allclose(m.energy_share.sum(axis=1), 1.0, atol=1e-9)
    # The preset's damping is stiffness-proportional with ratio 0.05 referred to 1790 Hz, its
    # main torsional mode: the linearisation finds that mode there, with that ratio, and the
    # other modes' ratios grow with frequency (zeta = beta w / 2).
    assert m.dominant_dof[0] == "carrier angle"
    assert m.frequency[0] == pytest.approx(1790.0, rel=0.01)
    assert m.damping_ratio[0] == pytest.approx(0.05, rel=0.02)
    assert np.all(np.diff(m.damping_ratio) > 0)


def test_physical_main_torsional_mode_matches_the_free_vibration() -> None:
    # The physical preset at 1 % of the paper's input speed from a steady start at rated load
    # (quasi-static: the crank turns 0.03 pin pitch during the decay), a 1 % torque pulse of
    # 0.2 ms at 0.03 s. The carrier speed after the pulse (mean removed) is dominated by the
    # main torsional mode (the others are damped faster: zeta grows with frequency): its
    # zero-padded FFT peak must match the damped frequency of the linearisation at the pulse's
    # crank angle within 1 %, the logarithmic decrement over 8 periods its damping ratio within
    # 5 % (the tolerances; measured 0.3 % and 2.1 %). dopri5 at rtol 1e-9, atol 1e-12
    # (its error is far below both).
    w_in = 0.01 * rvdyn.rad_s(8328)
    tp = 0.03
    load = {"kind": "table", "points": [[0, RATED], [tp, RATED], [tp + 1e-4, 1.01 * RATED], [tp + 2e-4, RATED]]}
    scene = rvdyn.Scene.physical("rated").replace(**{"drive.speed": w_in, "drive.start": "step",
                                                     "initial": "steady", "load": load})
    res = rvdyn.simulate(scene, 0.06, "dopri5", rtol=1e-9, atol=1e-12, record_interval=1e-5,
                         channels=["motion"])
    psi = float(res.crank_angle[np.searchsorted(res.t, tp), 0])
    m = rvdyn.modes(scene, torque=RATED, crank_angle=psi)
    assert m.dominant_dof[0] == "carrier angle"
    sel = res.t >= tp + 2e-4
    f_fft, zeta = ringing(res.carrier_speed[sel] - res.carrier_speed[sel].mean(), 1e-5)
    assert f_fft == pytest.approx(m.damped_frequency[0], rel=0.01)
    assert zeta == pytest.approx(m.damping_ratio[0], rel=0.05)


def test_damped_matching_follows_the_damping_continuously() -> None:
    # On the compliant paper preset the damped mode matched to undamped mode 1 (846 Hz) turns
    # at 1090 Hz: its heavy, non-proportional contact damping (modal damping ratio 0.55 of the
    # undamped shape) couples the coordinates and stiffens the mode. Independent check of the
    # matching of every mode: scale the damping by alpha from 0 to 1 (4000 steps, numpy's
    # eigensolver on the first-order form), follow both eigenvalues +-i w_j of each mode with
    # an optimal one-to-one assignment (scipy's linear_sum_assignment) to the extrapolated
    # points at each step, and compare the ends at alpha = 1 with rvdyn's damped frequency and
    # ratio (a conjugate pair) or natural frequency sqrt(l1 l2) and ratio (two real roots):
    # 1e-9 relative, measured 1e-14 (numpy's solver is independent of rvdyn's Schur form,
    # pencil polishing and adaptive continuation). The greedy MAC matching alone paired modes
    # 12 and 14 the other way round (MAC 0.51 and 0.33).
    from scipy.optimize import linear_sum_assignment

    m = rvdyn.modes(rvdyn.Scene.paper("rated").with_compliant_joints(), crank_angle=0.1)
    mass, k, c = m.mass, 0.5 * (m.stiffness + m.stiffness.T), m.damping
    n = mass.shape[0]
    mi = np.linalg.inv(mass)

    def eig(alpha: float) -> np.ndarray:
        a = np.block([[np.zeros((n, n)), np.eye(n)], [-mi @ k, -alpha * mi @ c]])
        return np.linalg.eigvals(a)

    w = 2 * np.pi * m.frequency
    pts = np.concatenate([[1j * x, -1j * x] for x in w])
    prev = pts.copy()
    for step, alpha in enumerate(np.linspace(0.0, 1.0, 4001)[1:]):
        e = eig(alpha)
        pred = pts + (pts - prev) if step else pts
        _, col = linear_sum_assignment(np.abs(pred[:, None] - e[None, :]))
        prev, pts = pts, e[col]
    for j in range(n):
        a, b = pts[2 * j], pts[2 * j + 1]
        if abs(a.imag) > 1e-6 * abs(a):
            up = a if a.imag > 0 else b
            assert up.imag / (2 * np.pi) == pytest.approx(m.damped_frequency[j], rel=1e-9), j
            assert -up.real / abs(up) == pytest.approx(m.damping_ratio[j], rel=1e-9), j
        else:
            wn = math.sqrt(a.real * b.real)
            assert wn / (2 * np.pi) == pytest.approx(m.damped_natural_frequency[j], rel=1e-9), j
            assert -(a.real + b.real) / (2 * wn) == pytest.approx(m.damping_ratio[j], rel=1e-9), j
    assert m.damped_frequency[0] > 1.2 * m.frequency[0]
    # Modes 12 and 14 (the greedy MAC matching had them swapped).
    assert m.damped_natural_frequency[11] == pytest.approx(3863.6, abs=0.1)
    assert m.damped_natural_frequency[13] == pytest.approx(4416.8, abs=0.1)


def test_friction_is_left_out_of_the_linearisation_about_an_equilibrium() -> None:
    # About an equilibrium (a slowly turning reducer) the regularised Coulomb law's slope at
    # rest, mu N / v_reg, is an artefact: it made the main mode's damping ratio 1.0 at
    # v_reg = 1e-3 m/s and 0.10 at 1e-2 (0.050 without friction).
    base = rvdyn.modes(rvdyn.Scene.physical("rated"), crank_angle=0.1)
    for v_reg in (1e-5, 1e-2):
        s = rvdyn.Scene.physical("rated").replace(**{"friction.pin": 0.05, "friction.mesh": 0.05,
                                                     "friction.regularisation_speed": v_reg})
        m = rvdyn.modes(s, crank_angle=0.1)
        np.testing.assert_allclose(m.damping_ratio, base.damping_ratio, rtol=1e-12)
        np.testing.assert_allclose(m.frequency, base.frequency, rtol=1e-12)
