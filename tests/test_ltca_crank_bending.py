"""Crankshaft bending in the LTCA (scene field ``crank_shaft``; docs/model.md, "Crankshaft
bending"): the reported deflections against beam theory."""

from __future__ import annotations

import math

import numpy as np

import rvdyn

LAYOUT = {"bearings": [-0.06, 0.06], "discs": [-0.02, 0.02], "planet": -0.09}


def simple_span_flexibility(z: list[float], supports: tuple[float, float], ei: float) -> np.ndarray:
    """Deflection at ``z[k]`` per unit load at ``z[l]`` of a simply supported span (loads between
    the supports): ``b x (L^2 - b^2 - x^2) / (6 E I L)`` for ``x <= a`` (Young & Budynas 2002,
    table 8.1), mirrored for ``x > a``."""
    za, zb = supports
    span = zb - za
    c = np.empty((len(z), len(z)))
    for k, zk in enumerate(z):
        for j, zl in enumerate(z):
            x, a = zk - za, zl - za
            if x > a:
                x, a = span - x, span - a
            b = span - a
            c[k, j] = b * x * (span**2 - b**2 - x**2) / (6.0 * ei * span)
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
    c = simple_span_flexibility([-0.02, 0.02], (-0.06, 0.06), ei)
    defl = res.crank_deflection
    assert defl.shape == (5, 3, 2, 2)
    # (angles, cranks, discs, 2): deflection u = C (force on the eccentric) = -C (force on the disc).
    want = -np.einsum("kl,ncla->ncka", c, res.eccentric_bearing_force)
    scale = np.abs(defl).max()
    assert scale > 1e-5
    np.testing.assert_allclose(defl, want, rtol=0, atol=1e-9 * scale)
    # Without the shaft: no deflections.
    assert rvdyn.ltca(rvdyn.Scene.physical("rated"), crank_angles=[0.0]).crank_deflection.shape == (1, 0, 2, 2)

