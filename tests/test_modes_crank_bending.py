"""Modes with bending crankshafts (scene field ``crank_shaft``; docs/model.md, "Modes with
bending crankshafts"): the eccentric deflections condensed out of the linearisation."""

from __future__ import annotations

import numpy as np
import pytest

import rvdyn

LAYOUT = {"bearings": [-0.06, 0.06], "discs": [-0.02, 0.02], "planet": -0.09}


def _physical(**shaft: float) -> rvdyn.Scene:
    sc = rvdyn.Scene.physical("rated").replace(crank_layout=LAYOUT)
    return sc.replace(crank_shaft=shaft) if shaft else sc


def test_the_condensed_stiffness_keeps_the_quasi_static_torsional_compliance() -> None:
    """The linearisation's stiffness (sum of its parts, eccentric deflections condensed out)
    gives the output's compliance with the input held that the compliance budget computes on
    the LTCA's unknowns, deflections included (a second code path: the budget solves the whole
    tangent). The same equilibrium solved twice: equal to 1e-14 (measured); asserted 1e-9."""
    sc = _physical(diameter=0.045)
    m = rvdyn.modes(sc)
    assert m.dof_names[0] == "carrier angle"
    k = m.stiffness
    c_modes = np.linalg.inv(k)[0, 0]
    budget = rvdyn.analysis.compliance_budget(sc)
    assert c_modes == pytest.approx(float(budget.compliance.sum()), rel=1e-9)
    # The shaft is a third of the rigid cranks' stiffness here: a visible change.
    rigid = np.linalg.inv(rvdyn.modes(_physical()).stiffness)[0, 0]
    assert c_modes > 2.0 * rigid


def test_a_stiffening_shaft_converges_to_the_modes_of_rigid_cranks() -> None:
    """Shafts of 0.5 m and 1 m at the largest modulus the scene takes (1e12 Pa): the
    frequencies and damping ratios approach those of rigid cranks as the shaft's compliance,
    here its shear (`1/d^2`), vanishes: the differences fall four-fold from 0.5 m to 1 m
    (measured 4.08 for both). The damping comes from two routes that must meet: with rigid
    cranks the dynamic model's finite differences; with bending the dynamic model without the
    eccentric bearings' damping plus that damping from their tangent (``beta K``). Without
    that term the eccentric bearings would not damp at all. Measured at 1 m: frequencies
    2.1e-4, damping ratios 6.3e-4 relative; asserted 3e-4 and 1e-3."""
    rigid = rvdyn.modes(_physical())
    diff = []
    for d in (0.5, 1.0):
        m = rvdyn.modes(_physical(diameter=d, modulus=1e12))
        assert len(m) == len(rigid) == 16
        assert m.part_names[-1] == "crank bending"
        diff.append((np.abs(m.frequency / rigid.frequency - 1).max(),
                     np.abs(m.damping_ratio / rigid.damping_ratio - 1).max()))
    assert diff[1][0] < 3e-4 and diff[1][1] < 1e-3
    for k in range(2):
        assert 3.5 < diff[0][k] / diff[1][k] < 4.5


def test_a_bending_shaft_softens_and_carries_the_main_mode() -> None:
    """A 45 mm shaft carries most of the main torsional mode's strain energy (as it carries
    59 % of the static compliance) and lowers its frequency; the shaft's bending has no
    damping of its own, so the mode's damping ratio falls."""
    bent = rvdyn.modes(_physical(diameter=0.045))
    rigid = rvdyn.modes(_physical())
    main = int(np.argmax(bent.energy_share[:, bent.part_names.index("crank bending")]))
    assert main == 0
    assert bent.energy_share[0, -1] > 0.5
    assert bent.frequency[0] < 0.8 * rigid.frequency[0]
    assert bent.damping_ratio[0] < rigid.damping_ratio[0]
    assert np.all(np.isfinite(bent.damping_ratio))


def test_modes_with_bending_need_proportional_eccentric_damping() -> None:
    """A linear eccentric bearing with clearance damps only radially while its tangent has a
    tangential part: the damping on the deflected eccentric is not known from the tangent,
    and the analysis says so instead of guessing."""
    sc = rvdyn.Scene.paper("rated").replace(
        joints={"kind": "compliant",
                "eccentric_bearing": {"stiffness": 1e9, "damping": 1e4, "clearance": 5e-6},
                "crank_bearing": {"stiffness": 2e9, "damping": 1e4}},
        crank_layout=LAYOUT, crank_shaft={"diameter": 0.045})
    with pytest.raises(rvdyn.SceneError, match="proportional to their stiffness"):
        rvdyn.modes(sc)
    # Without clearance the same bearing is proportional (c / k) and the modes run.
    ok = sc.replace(joints={"kind": "compliant",
                            "eccentric_bearing": {"stiffness": 1e9, "damping": 1e4},
                            "crank_bearing": {"stiffness": 2e9, "damping": 1e4}})
    assert np.all(np.isfinite(rvdyn.modes(ok).frequency))
