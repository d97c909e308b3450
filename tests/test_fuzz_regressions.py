"""Regression tests for the bad inputs found by fuzzing the geometry, contact and kinematics API.

Calls that could kill the interpreter (an allocation abort) run in a child process, so a
regression fails the test instead of ending the test session.
"""

from __future__ import annotations

import math
import subprocess
import sys
import textwrap

import numpy as np
import pytest

import rvdyn

PAPER = dict(pins=24, eccentricity=4.5e-3, pin_circle_radius=0.15, pin_radius=0.01, face_width=0.04)


def run_child(code: str, timeout: float = 120.0) -> subprocess.CompletedProcess[str]:
    """Run `code` in a fresh interpreter; return the finished process."""
    return subprocess.run(
        [sys.executable, "-c", textwrap.dedent(code)],
        capture_output=True,
        text=True,
        timeout=timeout,
        env={"RUST_BACKTRACE": "0", "PATH": "/usr/bin:/bin"},
    )


# --- more than 32 dimensions ----------------------------------------------------------------


@pytest.mark.parametrize(
    "call",
    [
        lambda: rvdyn.CycloidGeometry.paper().profile(np.zeros((1,) * 32)),  # result: 33 dims
        lambda: rvdyn.CycloidGeometry.paper().normal(np.zeros((1,) * 32)),
        lambda: rvdyn.CycloidGeometry.paper().curvature_radius(np.zeros((1,) * 33)),
        lambda: rvdyn.contact_stiffness(np.full((1,) * 33, 5e-3), 0.01, 0.1),
        lambda: rvdyn.hertz_line_contact(np.ones((1,) * 33), 0.04, 0.01, 0.1),
        lambda: rvdyn.impact_force(np.zeros((1,) * 33), 0.0, 1e10),
    ],
    ids=["profile", "normal", "curvature_radius", "contact_stiffness", "hertz", "impact"],
)
def test_more_than_32_dimensions_is_a_parameter_error(call):
    # A PanicException (a BaseException) escaped here before.
    with pytest.raises(rvdyn.ParameterError, match="at most 32"):
        call()


def test_32_dimensions_still_work_where_the_result_fits():
    g = rvdyn.CycloidGeometry.paper()
    out = g.curvature_radius(np.zeros((1,) * 32))
    assert out.shape == (1,) * 32
    assert out.ravel()[0] == pytest.approx(g.curvature_radius(0.0))


# --- sizes checked before allocating --------------------------------------------------------


@pytest.mark.parametrize(
    "stmt",
    [
        "rvdyn.contact_stiffness(np.full((2**20, 1), 5e-3), np.full((1, 2**20), 0.01), 0.1)",
        "rvdyn.CycloidGeometry.paper().profile(np.broadcast_to(np.array(0.1), (2**40,)))",
        "rvdyn.hertz_line_contact(np.broadcast_to(1.0, (2**29, 2**30)), 0.04, 0.01, 0.1)",
        "rvdyn.impact_force(np.broadcast_to(1e-6, (2**59,)), 0.0, 1e10)",
    ],
    ids=["broadcast", "zero-stride-profile", "zero-stride-hertz", "zero-stride-impact"],
)
def test_huge_results_raise_memory_error_in_a_live_interpreter(stmt):
    # These aborted the interpreter (SIGABRT, exit 134) allocating terabytes.
    p = run_child(
        f"""
        import numpy as np, rvdyn
        try:
            {stmt}
        except MemoryError as e:
            print("MemoryError", e)
        """
    )
    assert p.returncode == 0, p.stderr[-500:]
    assert p.stdout.startswith("MemoryError cannot allocate"), p.stdout


def test_pin_counts_are_bounded_before_building_the_profile():
    # 10**8 pins passed every rule and the seed polyline aborted the process.
    p = run_child(
        """
        import rvdyn
        try:
            rvdyn.CycloidGeometry(10**8, 1e-9, 0.15, 1e-9, 0.04)
        except rvdyn.GeometryError as e:
            print("GeometryError", e)
        """
    )
    assert p.returncode == 0, p.stderr[-500:]
    assert "at most 1000 pins" in p.stdout


def test_crank_and_planet_counts_are_bounded():
    with pytest.raises(rvdyn.GeometryError, match="cranks must be from 1 to 64"):
        rvdyn.Scene.paper("rated").replace(stage1=None, cranks=2**32 - 1)
    with pytest.raises(rvdyn.GeometryError, match="at most 64 planets"):
        rvdyn.InvoluteStage(18, 42, 65, 3e-3, 0.35, 0.03)
    with pytest.raises(rvdyn.GeometryError, match="at most 10000"):
        rvdyn.InvoluteStage(2**32 - 1, 5, 3, 3e-3, 0.35, 0.03)


def test_zero_stride_inputs_are_read_without_copying_and_give_the_dense_answer():
    w = np.broadcast_to(np.array(5e-3), (1000, 7))
    dense = rvdyn.contact_stiffness(np.full((1000, 7), 5e-3), 0.01, 0.1)
    np.testing.assert_array_equal(rvdyn.contact_stiffness(w, 0.01, 0.1), dense)
    # Views with negative, non-contiguous and zero strides mixed.
    x = np.arange(24.0).reshape(2, 3, 4)[:, ::-1, ::2] * 1e-3
    z = np.broadcast_to(x[:, :, :1], (2, 3, 5))
    g = rvdyn.CycloidGeometry.paper()
    np.testing.assert_array_equal(g.profile(x), g.profile(np.ascontiguousarray(x)))
    np.testing.assert_array_equal(g.profile(z), g.profile(np.ascontiguousarray(z)))
    f = rvdyn.hertz_line_contact(np.broadcast_to([[1e3], [2e3]], (2, 3)), 0.04, [0.01, 0.02, 0.03], 0.1)
    ref = rvdyn.hertz_line_contact(np.array([[1e3] * 3, [2e3] * 3]), 0.04, np.array([[0.01, 0.02, 0.03]] * 2), 0.1)
    for a, b in zip(f, ref):
        np.testing.assert_array_equal(a, b)


def test_error_index_names_the_element():
    with pytest.raises(rvdyn.ParameterError, match=r"at index \(1, 2\)"):
        rvdyn.contact_stiffness(np.array([[5e-3] * 3, [5e-3, 5e-3, -1.0]]), 0.01, 0.1)
    with pytest.raises(rvdyn.ParameterError, match=r"got NaN at index \(0, 1\)"):
        rvdyn.CycloidGeometry.paper().profile(np.array([[0.0, np.nan]]))


# --- pin radius errors ----------------------------------------------------------------------


@pytest.mark.parametrize("err", [-0.01, -0.02, -0.0100000001])
def test_pin_radius_errors_that_leave_no_pin_are_rejected(err):
    with pytest.raises(rvdyn.GeometryError, match=r"pin_errors.radius\[0\]"):
        rvdyn.Scene.paper("rated", **{"pin_errors.radius": [err] * 24})


def test_small_pin_radius_errors_still_run():
    s = rvdyn.Scene.paper("rated", **{"pin_errors.radius": [-0.005] + [0.0] * 23})
    assert s["pin_errors.radius"][0] == -0.005


# --- mass properties of discs too small for the default holes ------------------------------


@pytest.mark.parametrize("rp", [0.08, 0.09])
def test_holes_that_do_not_fit_are_a_geometry_error(rp):
    g = rvdyn.CycloidGeometry(24, 0.03 * rp, rp, rp / 15, 0.02)
    # Returned (0.456, -0.00558) for rp = 0.08 before.
    with pytest.raises(rvdyn.GeometryError, match="does not fit in this disc"):
        g.mass_properties()


def test_mass_properties_are_positive_or_an_error_for_every_size():
    for rp in np.linspace(0.06, 0.3, 49):
        g = rvdyn.CycloidGeometry(24, 0.03 * rp, rp, rp / 15, 0.04)
        try:
            m, j = g.mass_properties()
        except rvdyn.GeometryError:
            continue
        assert m > 0 and j > 0, (rp, m, j)


def test_a_scene_with_a_small_disc_needs_explicit_inertias():
    rp = 0.08
    cyc = {"pins": 24, "eccentricity": 0.03 * rp, "pin_circle_radius": rp, "pin_radius": rp / 15,
           "face_width": 0.02, "d_rp": 0.0, "d_rrp": 0.0, "d_delta": 0.0}
    s = rvdyn.Scene.paper("rated", cycloid=cyc)
    with pytest.raises(rvdyn.GeometryError, match="inertias.disc"):
        s.model_info()


# --- results that overflow are errors --------------------------------------------------------


@pytest.mark.parametrize(
    "call",
    [
        lambda: rvdyn.CycloidGeometry(24, 1e-303, 1e-300, 1e-302, 1e-300),
        lambda: rvdyn.CycloidGeometry(24, 4.5e157, 1.5e160, 1e159, 4e159),
        lambda: rvdyn.CycloidGeometry(**PAPER, d_rp=1e300),
        lambda: rvdyn.CycloidGeometry(**{**PAPER, "face_width": 1e308}),
        lambda: rvdyn.CycloidGeometry.paper().mass_properties(1e308),
        lambda: rvdyn.hertz_line_contact(1e308, 0.04, 0.01, 0.1),
        lambda: rvdyn.impact_force(1e300, 0.0, 1.26e10),
        lambda: rvdyn.impact_force(1e-5, 1e308, 1.26e10),
        lambda: rvdyn.operating_point(1.0, 5e-324, 1.0),
        lambda: rvdyn.body_speeds(1e308, 2**32 - 1, 1, 2**32 - 1),
        lambda: rvdyn.InvoluteStage(18, 42, 3, 1e300, 0.35, 0.03),
    ],
)
def test_no_nan_or_inf_for_extreme_inputs(call):
    with pytest.raises(rvdyn.RvdynError):
        call()


def test_tiny_hertz_force_is_finite():
    # (0, inf, inf, nan) before: the half width underflowed to 0 and p0 divided by it.
    c = rvdyn.hertz_line_contact(5e-324, 0.04, 0.01, 0.1)
    assert all(math.isfinite(v) for v in c)
    assert c.half_width > 0 and c.peak_pressure > 0


# --- exception classes ----------------------------------------------------------------------


@pytest.mark.parametrize("value", [2**63, 2**64, 10**30, -(2**63) - 1])
def test_huge_counts_are_parameter_errors_with_the_cause_chained(value):
    for call in (
        lambda: rvdyn.CycloidGeometry(value, 4.5e-3, 0.15, 0.01, 0.04),
        lambda: rvdyn.transmission_ratio(value, 42, 24),
        lambda: rvdyn.body_speeds(1.0, z_planet=value),
        lambda: rvdyn.InvoluteStage(18, 42, value, 3e-3, 0.35, 0.03),
    ):
        with pytest.raises(rvdyn.ParameterError, match="whole number") as info:
            call()
        assert isinstance(info.value.__cause__, OverflowError)


def test_numpy_integers_and_floats_are_accepted_like_python_ones():
    for t in (np.int8, np.int32, np.int64, np.uint16, np.uint64):
        g = rvdyn.CycloidGeometry(t(24), 4.5e-3, 0.15, 0.01, 0.04)
        assert g.pins == 24
        assert rvdyn.transmission_ratio(t(18), t(42), t(24)) == 57.0
        assert rvdyn.InvoluteStage(t(18), t(42), t(3), 3e-3, 0.35, 0.03).planets == 3
    g = rvdyn.CycloidGeometry(24, np.float32(4.5e-3), np.float64(0.15), 0.01, np.float16(0.04))
    assert g.kinematic_pose(np.float32(0.5))[1] == pytest.approx(-0.5 / 23)


@pytest.mark.parametrize(
    "call",
    [
        lambda: rvdyn.CycloidGeometry(24, 10**400, 0.15, 0.01, 0.04),
        lambda: rvdyn.CycloidGeometry.paper().kinematic_pose(10**400),
        lambda: rvdyn.CycloidGeometry.paper().profile([10**400]),
        lambda: rvdyn.CycloidGeometry.paper().profile([[1.0], [1.0, 2.0]]),
        lambda: rvdyn.operating_point(10**400, 1.0, 1.0),
        lambda: rvdyn.impact_force(1e-6, 0.0, 10**400),
        lambda: rvdyn.contact_stiffness(["5e-3x"], 0.01, 0.1),
    ],
)
def test_unreadable_numbers_are_parameter_errors_with_the_cause_chained(call):
    # OverflowError and raw ValueError escaped before.
    with pytest.raises(rvdyn.ParameterError, match="cannot read") as info:
        call()
    assert isinstance(info.value.__cause__, (OverflowError, ValueError))
    assert not isinstance(info.value.__cause__, rvdyn.RvdynError)


def test_wrong_types_stay_type_errors():
    g = rvdyn.CycloidGeometry.paper()
    for bad in (None, {}, 1j, object(), "0.1", b"0.1", np.array([1j]),
                np.array(["0.1"]), np.array([1], dtype="datetime64[s]")):
        with pytest.raises(TypeError):
            g.profile(bad)
    with pytest.raises(TypeError):
        rvdyn.CycloidGeometry(24.0, 4.5e-3, 0.15, 0.01, 0.04)


# --- messages -------------------------------------------------------------------------------


@pytest.mark.parametrize(
    "call, must, must_not",
    [
        (lambda: rvdyn.contact_stiffness(5e-324, 0.01, 0.1), "5e-324", None),
        (lambda: rvdyn.hertz_line_contact(1.0, 0.04, 5e-324, 5e-324), "5e-324", None),
        (lambda: rvdyn.stiffness_maximum(0.01, 0.1, lo=1e-8, hi=1e308), "floating point", "too small"),
        (lambda: rvdyn.CycloidGeometry.paper().mass_properties(1e308), "1e308", None),
        (lambda: rvdyn.operating_point(1.0, 5e-324, 1.0), "5e-324", None),
    ],
)
def test_messages_are_short_and_consistent(call, must, must_not):
    with pytest.raises(rvdyn.RvdynError) as info:
        call()
    message = str(info.value)
    assert len(message) < 400, message  # up to 874 characters before
    assert "0000000000" not in message, message
    assert must in message
    if must_not:
        assert must_not not in message
