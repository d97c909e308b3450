"""Arguments the Python layer checks itself (an outside review of the public API found each of
these escaping as a bare IndexError, TypeError, ValueError or OverflowError, being silently
ignored, or giving a wrong answer without an error)."""

from __future__ import annotations

import math

import numpy as np
import pytest

import rvdyn
from rvdyn import ParameterError, Scene


@pytest.fixture(scope="module")
def scene() -> Scene:
    return Scene.paper("rated")


@pytest.fixture(scope="module")
def run(scene: Scene) -> rvdyn.Result:
    return rvdyn.simulate(scene, 0.05)


@pytest.mark.parametrize("method", ["dopri5", "generalized-alpha-adaptive", "generalized-alpha"])
@pytest.mark.parametrize("atol", [1e300, 1e-4, 1.1e-6])
def test_a_tolerance_too_loose_for_the_contacts_is_refused(scene: Scene, method: str, atol: float) -> None:
    # dopri5 at atol 1e300 m ran and returned an output speed of 0.47 instead of 2.55 rad/s;
    # the adaptive generalized-alpha at 1e-4 m was 21 % off.
    with pytest.raises(ParameterError, match=r"atol must be .*<= 1e-6 m"):
        rvdyn.simulate(scene, 0.01, method, atol=atol)
    with pytest.raises(ParameterError, match="atol"):
        rvdyn.Options(method, atol=atol)


def test_the_loosest_tolerances_accepted_still_run(scene: Scene) -> None:
    r = rvdyn.simulate(scene, 0.01, "dopri5", atol=1e-6, rtol=1e-2)
    assert r.ok
    with pytest.raises(ParameterError, match=r"rtol must be .*<= 1e-2"):
        rvdyn.Options("dopri5", rtol=0.5)


@pytest.mark.parametrize("call", [
    lambda s, r: rvdyn.order_spectrum(r, "input_torque", (0.01,)),
    lambda s, r: rvdyn.order_spectrum(r, "input_torque", 0.01),
    lambda s, r: rvdyn.order_spectrum(r, "input_torque", (0.0, 0.02, 0.05)),
    lambda s, r: rvdyn.order_spectrum(r, "input_torque", (0.0, 0.05), orders=[1, 2]),
    lambda s, r: rvdyn.order_spectrum(r, "input_torque", index=3),
    lambda s, r: rvdyn.order_spectrum(r, "input_torque", tolerance=10**400),
    lambda s, r: rvdyn.campbell(s, [100.0, 150.0], frequency_range=(100.0,)),
    lambda s, r: rvdyn.campbell(s, [100.0, 150.0], frequency_range=5e3),
    lambda s, r: rvdyn.campbell(s, [100.0, 150.0], points="x"),
    lambda s, r: rvdyn.campbell(s, ["fast"]),
    lambda s, r: rvdyn.sweep(s, 0.005, grid={"load.torque": np.full((2, 2), 1e3)}),
    lambda s, r: rvdyn.sweep(s, 0.005, grid={"load.torque": 5e3}),
    lambda s, r: rvdyn.sweep(s, 0.005, grid={"load.torque": []}),
    lambda s, r: rvdyn.ltca(s, None, [0.0, 0.1], chunk=float("nan")),
    lambda s, r: rvdyn.ltca(s, None, [0.0, 0.1], chunk=0),
    lambda s, r: rvdyn.ltca(s, None, [0.0, 0.1], chunk=True),
    lambda s, r: rvdyn.modes_over_mesh(s, points=10**400),
    lambda s, r: rvdyn.simulate(s, 10**400),
    lambda s, r: rvdyn.modes(s, torque=10**400),
    lambda s, r: rvdyn.deg_s(float("nan")),
    lambda s, r: rvdyn.rad_s(float("inf")),
    lambda s, r: rvdyn.deg_s("fast"),
    lambda s, r: rvdyn.rad_s(10**400),
])
def test_bad_arguments_are_parameter_errors(scene: Scene, run: rvdyn.Result, call) -> None:  # type: ignore[no-untyped-def]
    with pytest.raises(ParameterError) as info:
        call(scene, run)
    assert len(str(info.value)) < 300, str(info.value)  # a 400-digit int is cut, not printed


def test_unit_helpers() -> None:
    assert rvdyn.rad_s(8328.0) == pytest.approx(145.35, abs=0.01)
    assert rvdyn.deg_s(math.pi) == pytest.approx(180.0)
    with pytest.raises(TypeError, match="rad_per_s"):
        rvdyn.deg_s(None)  # type: ignore[arg-type]


def test_result_arrays_are_read_only(scene: Scene, run: rvdyn.Result) -> None:
    # Writing into them changed later answers: output_work *= 2 made efficiency() 1.996.
    e0 = run.efficiency()
    for name in run.channels:
        assert not getattr(run, name).flags.writeable, name
    with pytest.raises(ValueError, match="read-only"):
        run.output_work[:] *= 2
    assert run.efficiency() == e0
    lt = rvdyn.ltca(scene, None, [0.0, 0.1])
    peak = lt.peak_pin_force
    with pytest.raises(ValueError, match="read-only"):
        lt.pin_force[:] = 0.0
    assert lt.peak_pin_force == peak
    loop = rvdyn.analysis.torque_twist(scene, points=16)
    for a in (loop.torque, loop.twist, loop.tangent_stiffness):
        assert not a.flags.writeable


def test_results_do_not_freeze_the_callers_arrays() -> None:
    t = np.linspace(0.0, 1.0, 5)
    r = rvdyn.Result({"t": t}, {})
    assert not r.t.flags.writeable
    assert t.flags.writeable  # a read-only view, not the caller's array


def test_classical_pin_forces_at_huge_crank_angles() -> None:
    # At 1e17 rad every pin got the same force (the pins' offsets fell below the angle's last
    # bit); at -1e17 it was a misleading GeometryError.
    g = rvdyn.CycloidGeometry.paper()
    for psi in (1e17, -1e17, 1e300):
        f = np.asarray(g.classical_pin_forces(1e3, psi))
        assert np.count_nonzero(f) == 12, f
