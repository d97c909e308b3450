"""Eccentric bearing reactions of the ideal (rigid) joints (docs/model.md#bearing-reactions-of-ideal-joints)."""

import math

import numpy as np

import rvdyn
from rvdyn import Scene

STEADY = Scene.paper("rated").replace(initial="steady")
KW = {"t_end": 0.01, "integrator": "dopri5", "channels": ["motion", "pins", "bearings"], "record_interval": 2e-5}


def _compliant(k: float) -> Scene:
    # Equal linear eccentric bearings (5 % damping for a disc of about 20 kg), rigid crank bearings.
    return STEADY.replace(joints={"kind": "compliant", "crank_bearing": None,
                                  "eccentric_bearing": {"stiffness": k, "damping": 0.1 * math.sqrt(20 * k)}})


def test_rigid_reactions_are_the_limit_of_stiff_equal_bearings() -> None:
    # The rigid model's reactions (disc balance, split as equal isotropic bearings share a
    # redundant support) against the compliant model with equal bearings of stiffness k: the
    # difference falls like 1/k (measured 4.6e-3 of the 145 kN peak at 1e10 N/m, 4.7e-4 at
    # 1e11). Tolerances: 2e-3 at 1e11, and at least a 5x drop per decade of stiffness.
    rigid = rvdyn.simulate(STEADY, **KW)
    w = rigid.t > 0.003
    a = rigid.eccentric_bearing_force[w]
    assert a.shape[1:] == (3, 2, 2)
    errors = []
    for k in (1e10, 1e11):
        b = rvdyn.simulate(_compliant(k), **KW).eccentric_bearing_force[w]
        peak = float(np.linalg.norm(b, axis=-1).max())
        errors.append(float(np.abs(a - b).max()) / peak)
    assert errors[1] < 2e-3, errors
    assert errors[0] > 5 * errors[1], errors
    # The reactions are far above the pin forces (about 4x the peak pin force).
    assert np.linalg.norm(a, axis=-1).max() > 3 * rigid.pin_force[w].max()


def test_rigid_reactions_balance_each_disc() -> None:
    # Sum over the cranks of the reactions on a disc = m_d O'' - (pin forces on it), checked
    # through the recorded pin forces and normals and the recorded crank motion.
    r = rvdyn.simulate(STEADY, t_end=0.003, integrator="dopri5", atol=1e-12, rtol=1e-10,
                       channels=["motion", "pins", "contact_points", "bearings"], record_interval=2e-6)
    info = STEADY.model_info()
    md = info["disc_mass"]
    t = r.t
    # O = e (cos b, sin b), b = crank angle + disc phase: O'' = e (z x u) a'' - e u a'^2, with
    # the crank acceleration a'' from one difference of the recorded crank speed.
    e = STEADY["cycloid.eccentricity"]
    beta = r.crank_angle[:, :1] + np.array([0.0, math.pi])[None, :]
    w = r.crank_speed[:, :1]
    dw = np.gradient(r.crank_speed[:, 0], t)[:, None]
    u = np.stack([np.cos(beta), np.sin(beta)], axis=-1)
    zu = np.stack([-np.sin(beta), np.cos(beta)], axis=-1)
    acc = e * (zu * dw[..., None] - u * (w ** 2)[..., None])
    assert np.allclose(r.disc_center, e * u, atol=1e-15)
    pins = -(r.pin_force[..., None] * r.pin_normal).sum(axis=2)  # force of the pins on each disc
    net = r.eccentric_bearing_force.sum(axis=1)  # (n, discs, 2)
    inner = slice(5, -5)
    resid = md * acc[inner] - pins[inner] - net[inner]
    peak = np.abs(net).max()
    # The central difference of the crank speed over 2e-6 s errs by about (w_r dt)^2 / 6 of
    # the acceleration's fast share (the start transient: 5e4 rad/s^2); measured 4e-5 of the
    # peak reaction (2e-3 with a 1e-5 s record); tolerance 1e-4.
    assert np.abs(resid).max() < 1e-4 * peak, np.abs(resid).max() / peak
