"""Property-based tests of the public API (hypothesis): geometry, contact, kinematics, and
scenes, short simulations and their results.

Properties, for arguments drawn from physical, extreme (subnormal, 1e308, 2**64) and invalid
(NaN, inf, negative) values:

- every call either returns, with no NaN or infinity in any returned number or array, or
  raises an exception of the documented hierarchy (``rvdyn.RvdynError`` subclasses; a
  ``TypeError`` only where an argument of the wrong type is passed on purpose; a
  ``MemoryError`` only for results too large for memory);
- no call kills the interpreter: the cases that could (huge broadcasts, zero-stride views of
  2**40 elements and more, more than 32 dimensions) run in child processes with a memory cap.

Bounded in time: a fixed number of examples per test (``RVDYN_HYPOTHESIS_EXAMPLES``, default
150), no deadline, derandomized (the same examples on every run), no example database. The
counts of calls tried and calls that ended cleanly are printed in pytest's terminal summary
("hypothesis API suite: calls tried / clean") and checked by ``test_zz_counts``.
"""

from __future__ import annotations

import collections
import json
import math
import os
import subprocess
import sys
import textwrap
import warnings
from typing import Any, Callable

import numpy as np
import pytest

hypothesis = pytest.importorskip("hypothesis")
# The hostile options draw steps too long for the pin mesh, and steps or tolerances too loose for
# a light scene, on purpose: the step check's RuntimeWarnings are right there; these tests are
# about bad input.
pytestmark = [pytest.mark.filterwarnings("ignore:.*pin-mesh period:RuntimeWarning"),
              pytest.mark.filterwarnings("ignore:.*started from rest:RuntimeWarning")]
from hypothesis import HealthCheck, given, settings  # noqa: E402
from hypothesis import strategies as st  # noqa: E402
from hypothesis.extra import numpy as hnp  # noqa: E402

import rvdyn  # noqa: E402

EXAMPLES = int(os.environ.get("RVDYN_HYPOTHESIS_EXAMPLES", "150"))
SETTINGS = settings(
    max_examples=EXAMPLES,
    deadline=None,
    derandomize=True,
    database=None,
    suppress_health_check=[HealthCheck.too_slow, HealthCheck.filter_too_much,
                           HealthCheck.data_too_large],
)

#: calls tried and calls that ended cleanly, per category.
TRIED: collections.Counter[str] = collections.Counter()
CLEAN: collections.Counter[str] = collections.Counter()
#: of the clean calls, those that returned (the others raised a documented error).
RETURNED: collections.Counter[str] = collections.Counter()


class _CountsReport:
    """A pytest plugin that prints the counts in the terminal summary (after the run)."""

    def pytest_terminal_summary(self, terminalreporter):
        terminalreporter.section("hypothesis API suite: calls tried / clean")
        terminalreporter.write_line(
            f"total: {sum(TRIED.values())} tried, {sum(CLEAN.values())} clean "
            f"({sum(RETURNED.values())} returned finite values, the rest raised a documented "
            f"error)")
        for k in sorted(TRIED):
            terminalreporter.write_line(
                f"  {k}: {TRIED[k]} tried, {CLEAN[k]} clean ({RETURNED[k]} returned)")


@pytest.fixture(scope="module", autouse=True)
def _report_counts(request):
    plugin = _CountsReport()
    if not request.config.pluginmanager.is_registered(plugin):
        request.config.pluginmanager.register(plugin, "rvdyn-hypothesis-counts")
    yield


def _finite(value: Any) -> bool:
    """True if every number in a returned value (float, array, tuple, dict, GapResult) is
    finite."""
    if value is None or isinstance(value, (str, bool, int, np.integer, rvdyn.CycloidGeometry,
                                           rvdyn.InvoluteStage, rvdyn.Scene, rvdyn.Result)):
        return True  # the numbers of built objects are checked through their properties
    if isinstance(value, (float, np.floating)):
        return math.isfinite(value)
    if isinstance(value, np.ndarray):
        return bool(np.isfinite(value).all()) if value.dtype.kind in "fc" else True
    if isinstance(value, dict):
        return all(_finite(v) for v in value.values())
    if isinstance(value, (tuple, list)):
        return all(_finite(v) for v in value)
    if hasattr(value, "_asdict"):
        return _finite(tuple(value))
    raise AssertionError(f"unexpected return type {type(value).__name__}")


def check(category: str, call: Callable[[], Any], *, type_error: bool = False) -> Any:
    """Run ``call``; count it; fail on a non-finite result or an undocumented exception."""
    TRIED[category] += 1
    try:
        out = call()
    except rvdyn.RvdynError as e:
        assert len(str(e)) < 1000, f"{category}: message of {len(str(e))} characters: {e}"
        CLEAN[category] += 1
        return None
    except TypeError:
        if not type_error:
            raise
        CLEAN[category] += 1
        return None
    assert _finite(out), f"{category}: non-finite result {out!r}"
    CLEAN[category] += 1
    RETURNED[category] += 1
    return out


# --- strategies -----------------------------------------------------------------------------

EXTREME_FLOATS = [0.0, -0.0, 5e-324, -5e-324, 2.2250738585072014e-308, 1e-300, 1e-12, 1e-9,
                  1e-6, 1.0, 1e3, 1e9, 1e300, 1.7976931348623157e308, -1e308, math.nan,
                  math.inf, -math.inf]
HUGE_INTS = [2**31, 2**32 - 1, 2**32, 2**63 - 1, 2**63, 2**64, 10**30, -1, -(2**63) - 1]


def log_uniform(lo: float, hi: float) -> st.SearchStrategy[float]:
    return st.floats(math.log10(lo), math.log10(hi)).map(lambda x: 10.0**x)


#: Any real: physical magnitudes of both signs, extremes, NaN and inf, huge Python ints, numpy
#: scalars.
any_real = st.one_of(
    log_uniform(1e-12, 1e4),
    log_uniform(1e-12, 1e4).map(lambda x: -x),
    st.sampled_from(EXTREME_FLOATS),
    st.floats(allow_nan=True, allow_infinity=True),
    st.sampled_from([10**400, -(10**400), 2**1024]),
    log_uniform(1e-6, 1.0).map(np.float32),
)

any_count = st.one_of(
    st.integers(-3, 2000),
    st.sampled_from(HUGE_INTS),
    st.integers(3, 200).map(np.int64),
    st.integers(3, 200).map(np.uint32),
)


@st.composite
def disc_params(draw) -> dict[str, Any]:
    """Mostly valid discs across the size range (so that the methods get exercised), else any
    values."""
    if draw(st.booleans()):
        pins = draw(st.one_of(st.integers(3, 120), st.sampled_from([3, 1000, 1001])))
        rp = draw(log_uniform(1e-9, 2e3))
        k1 = draw(st.floats(0.01, 0.99))
        zp = float(pins)
        spacing = rp * math.sin(math.pi / zp)
        return dict(
            pins=pins,
            eccentricity=k1 * rp / zp,
            pin_circle_radius=rp,
            pin_radius=draw(st.floats(0.05, 0.95)) * spacing,
            face_width=draw(log_uniform(1e-10, 2e3)),
            d_rp=draw(st.one_of(st.just(0.0), st.floats(-0.2, 0.2).map(lambda f: f * rp), any_real)),
            d_rrp=draw(st.one_of(st.just(0.0), st.floats(-0.2, 0.2).map(lambda f: f * spacing))),
            d_delta=draw(st.one_of(st.just(0.0), st.floats(-1.0, 1.0), any_real)),
        )
    return dict(pins=draw(any_count), eccentricity=draw(any_real),
                pin_circle_radius=draw(any_real), pin_radius=draw(any_real),
                face_width=draw(any_real), d_rp=draw(any_real), d_rrp=draw(any_real),
                d_delta=draw(any_real))


#: Angle arrays of small shapes (0-d to 3-d), extremes included.
angle_arrays = st.one_of(
    any_real,
    hnp.arrays(np.float64, hnp.array_shapes(min_dims=0, max_dims=3, max_side=4),
               elements=st.floats(allow_nan=True, allow_infinity=True)),
    hnp.arrays(np.float64, hnp.array_shapes(min_dims=1, max_dims=2, max_side=5),
               elements=st.floats(-100.0, 100.0)),
    st.lists(st.floats(-10.0, 10.0), max_size=5),
)


# --- geometry -------------------------------------------------------------------------------


@SETTINGS
@given(disc_params(), angle_arrays, any_real, any_real, any_real)
def test_cycloid_geometry(params, phi, psi, torque, density):
    g = check("CycloidGeometry()", lambda: rvdyn.CycloidGeometry(**params))
    if g is None:
        return
    for name in ("k1", "pitch_radius", "min_convex_radius", "eccentricity", "pin_radius"):
        check("CycloidGeometry properties", lambda: getattr(g, name))
    check("profile", lambda: g.profile(phi))
    check("normal", lambda: g.normal(phi))
    check("curvature_radius", lambda: g.curvature_radius(phi))
    check("pin_positions", g.pin_positions)
    pose = check("kinematic_pose", lambda: g.kinematic_pose(psi))
    check("mass_properties", lambda: g.mass_properties(density))
    check("mass_properties", g.mass_properties)
    check("classical_levers", lambda: g.classical_levers(psi))
    check("classical_pin_forces", lambda: g.classical_pin_forces(torque, psi))
    if pose is not None:
        centre, angle = pose
        pins = g.pin_positions()
        for j in (0, len(pins) // 3):
            check("gap", lambda: g.gap(pins[j], centre, angle))
        check("gap", lambda: g.gap(pins[0] * 1.5, centre, angle, pin_radius=density))
        check("gap", lambda: g.gap([torque, psi], centre, angle))


@st.composite
def stage_args(draw) -> tuple[Any, ...]:
    """Mostly plausible stages (teeth 5-200, 1-8 planets, physical module), else any values."""
    if draw(st.booleans()):
        return (draw(st.integers(5, 200)), draw(st.integers(5, 200)), draw(st.integers(1, 8)),
                draw(log_uniform(1e-9, 2e3)), draw(st.floats(0.05, 0.78)),
                draw(log_uniform(1e-9, 2e3)), draw(st.one_of(st.just(0.0), any_real)))
    return (draw(any_count), draw(any_count), draw(any_count), draw(any_real),
            draw(st.one_of(st.floats(0.0, 0.8), any_real)), draw(any_real), draw(any_real))


@SETTINGS
@given(stage_args())
def test_involute_stage(args):
    z_sun, z_planet, planets, module, alpha, face, backlash = args
    s = check("InvoluteStage()", lambda: rvdyn.InvoluteStage(z_sun, z_planet, planets, module,
                                                              alpha, face, backlash))
    if s is None:
        return
    for name in ("sun_pitch_radius", "planet_tip_radius", "centre_distance", "contact_ratio",
                 "line_of_action_length", "stage_ratio", "planet_angles", "sun_base_radius"):
        check("InvoluteStage properties", lambda: getattr(s, name))


@SETTINGS
@given(st.integers(3, 60), log_uniform(1e-3, 1.0), st.floats(0.1, 0.9), st.floats(0.1, 0.9),
       st.integers(1, 5))
def test_valid_involute_stages_and_discs_agree_with_their_rules(zp, rp, k1, f, planets):
    # Physical inputs: a valid disc is built and every derived value is finite and positive.
    e = k1 * rp / zp
    rrp = f * rp * math.sin(math.pi / zp)
    g = check("CycloidGeometry() physical", lambda: rvdyn.CycloidGeometry(zp, e, rp, rrp, 0.01))
    if g is not None:
        assert g.k1 == pytest.approx(k1, rel=1e-12)
        assert 0 < g.min_convex_radius and g.pitch_radius == pytest.approx(e * (zp - 1))
        phi = np.linspace(0, 2 * np.pi, 50)
        r = check("curvature_radius", lambda: g.curvature_radius(phi))
        if r is None:  # only where the profile is exactly straight (K1 = 1/zp at a root)
            with pytest.raises(rvdyn.GeometryError, match="straight"):
                g.curvature_radius(phi)
        xy = check("profile", lambda: g.profile(phi))
        assert xy is not None and xy.shape == (50, 2)
    s = check("InvoluteStage() physical", lambda: rvdyn.InvoluteStage(
        zp, zp + 7, planets, rp / (2 * zp + 7), 0.35, 0.01))
    if s is not None:
        assert s.planet_angles.shape == (planets,)
        assert s.contact_ratio >= 1.0


# --- contact --------------------------------------------------------------------------------


@st.composite
def broadcast_arrays(draw, n: int) -> list[Any]:
    """``n`` arrays of mutually broadcastable small shapes (or scalars), any float values."""
    shapes = draw(hnp.mutually_broadcastable_shapes(num_shapes=n, max_dims=3, max_side=4))
    out: list[Any] = []
    for shape in shapes.input_shapes:
        if draw(st.booleans()):
            out.append(draw(any_real))
        else:
            elements = st.one_of(log_uniform(1e-12, 1e4), st.sampled_from(EXTREME_FLOATS),
                                 st.floats(allow_nan=True, allow_infinity=True))
            a = draw(hnp.arrays(np.float64, shape, elements=elements))
            if draw(st.booleans()) and a.ndim:
                a = np.broadcast_to(a[(slice(0, 1),) * a.ndim], shape)  # zero strides
            out.append(a)
    return out


conditions = st.sampled_from(["convex-convex", "convex-concave", "convex_concave", "bogus"])


@SETTINGS
@given(broadcast_arrays(3), conditions, any_real, any_real, any_real, any_real)
def test_contact_stiffness(arrays, condition, e_mod, nu, exponent, penetration):
    w, r1, r2 = arrays
    check("contact_stiffness", lambda: rvdyn.contact_stiffness(w, r1, r2, condition))
    check("contact_stiffness", lambda: rvdyn.contact_stiffness(
        w, r1, r2, condition, e_mod, nu, exponent, penetration))


@SETTINGS
@given(any_real, any_real, conditions, any_real, any_real, any_real)
def test_stiffness_maximum(r1, r2, condition, lo, hi, exponent):
    check("stiffness_maximum", lambda: rvdyn.stiffness_maximum(r1, r2, condition, lo=lo, hi=hi))
    check("stiffness_maximum", lambda: rvdyn.stiffness_maximum(
        r1, r2, condition, exponent=exponent))


@SETTINGS
@given(broadcast_arrays(4), any_real, any_real)
def test_hertz_line_contact(arrays, e_mod, nu):
    f, w, r1, r2 = arrays
    check("hertz_line_contact", lambda: rvdyn.hertz_line_contact(f, w, r1, r2))
    check("hertz_line_contact", lambda: rvdyn.hertz_line_contact(f, w, r1, r2, e_mod, nu))


@SETTINGS
@given(broadcast_arrays(2), any_real, any_real, any_real, any_real)
def test_impact_force(arrays, k, exponent, cmax, depth):
    x, v = arrays
    check("impact_force", lambda: rvdyn.impact_force(x, v, k))
    check("impact_force", lambda: rvdyn.impact_force(x, v, k, exponent, cmax, depth))


# --- bearings -------------------------------------------------------------------------------

force_arrays = st.one_of(
    hnp.arrays(np.float64, hnp.array_shapes(min_dims=1, max_dims=4, max_side=3),
               elements=st.floats(allow_nan=True, allow_infinity=True)),
    hnp.arrays(np.float64, st.sampled_from([(2,), (5, 2), (4, 3, 2)]), elements=st.floats(-1e6, 1e6)),
)
disc_force_arrays = st.one_of(
    hnp.arrays(np.float64, hnp.array_shapes(min_dims=1, max_dims=5, max_side=3),
               elements=st.floats(allow_nan=True, allow_infinity=True)),
    hnp.arrays(np.float64, st.sampled_from([(2, 2), (5, 2, 2), (4, 3, 2, 2)]), elements=st.floats(-1e6, 1e6)),
)


@SETTINGS
@given(force_arrays, disc_force_arrays, any_real, any_real, st.lists(any_real, max_size=3), any_real,
       st.lists(any_real, max_size=3))
def test_crank_bearing_rows_and_system_life(crank, discs_f, za, zb, zd, zp, lives):
    check("crank_bearing_rows", lambda: rvdyn.crank_bearing_rows(
        crank, discs_f, bearings=(za, zb), discs=zd, planet=zp))
    check("crank_bearing_rows", lambda: rvdyn.crank_bearing_rows(
        crank, discs_f, bearings=(-0.06, 0.06), discs=(-0.02, 0.02), planet=-0.09))
    check("crank_bearing_rows", lambda: rvdyn.CrankLayout(
        bearings=(za, zb), discs=tuple(zd), planet=zp).rows(crank, discs_f))
    if lives and all(isinstance(x, float) and x == math.inf for x in lives):
        assert rvdyn._core.roller_system_life(lives) == math.inf  # bearings that never fail
    else:
        check("roller_system_life", lambda: rvdyn._core.roller_system_life(lives))


_LTCA: list[Any] = []


position = st.one_of(any_real, st.floats(-0.2, 0.2))


@SETTINGS
@given(position, position, st.lists(position, max_size=3), position,
       st.one_of(st.none(), any_real, st.floats(1e-3, 0.1)))
def test_ltca_bearing_safety(za, zb, zd, zp, length):
    if not _LTCA:
        _LTCA.append(rvdyn.ltca(rvdyn.Scene.physical("rated"), crank_angles=[0.0, 0.1]))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)  # s0 below 1 for some layouts: reported, not wrong
        out = check("bearing_safety", lambda: _unloaded_is_safe(_LTCA[0].bearing_safety(
            rvdyn.CrankLayout(bearings=(za, zb), discs=tuple(zd), planet=zp, roller_length=length))))
    if out is not None:
        assert all(v["static_safety"] >= 0 and v["peak_load"] >= 0 for v in out.values())


_PERIOD: list[rvdyn.analysis.LtcaResult] = []


@SETTINGS
@given(st.one_of(st.none(), any_real, st.floats(1.0, 1e3)), position, position)
def test_ltca_bearing_life(speed, za, zb):
    if not _PERIOD:
        period = rvdyn.ltca(rvdyn.Scene.physical("rated"), crank_angles=[0.0]).mesh_period
        _PERIOD.append(rvdyn.ltca(rvdyn.Scene.physical("rated"), crank_angles=np.arange(12) * period / 12))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)  # s0 below 1 for some layouts
        check("LtcaResult.bearing_life", lambda: _unloaded_is_safe(_PERIOD[0].bearing_life(speed=speed)))
        check("LtcaResult.bearing_life (layout)", lambda: _unloaded_is_safe(_PERIOD[0].bearing_life(
            speed=speed, crank_layout=rvdyn.CrankLayout(bearings=(za, zb), discs=(-0.02, 0.02), planet=-0.09))))


_BUDGET_SCENES = {"paper": rvdyn.Scene.paper("rated"), "physical": rvdyn.Scene.physical("rated")}


@SETTINGS
@given(st.sampled_from(["paper", "physical"]),
       st.one_of(st.none(), any_real, st.floats(-5e4, 5e4), st.lists(any_real, min_size=0, max_size=3)),
       any_real)
def test_compliance_budget(preset, torque, crank_angle):
    out = check("compliance_budget", lambda: (lambda b: (b.compliance, b.share, b.torsional_stiffness,
                                                         b.split_error, b.table()))(
        rvdyn.analysis.compliance_budget(_BUDGET_SCENES[preset], torque, crank_angle)))
    if out is not None:
        np.testing.assert_allclose(out[1].sum(axis=1), 1.0, atol=1e-8)
        assert np.all(out[2] > 0)


def _unloaded_is_safe(safety: dict[str, dict[str, float]]) -> dict[str, dict[str, float]]:
    """s0 is inf exactly where a bearing carries nothing (a layout that puts every load on the
    other bearing); 0 stands for it in the finiteness check."""
    for v in safety.values():
        if v["static_safety"] == math.inf:
            assert v["peak_load"] == 0.0, v
            v["static_safety"] = 0.0
        # An infinite life likewise for a bearing that carries next to nothing (a layout far
        # off puts every load on the other bearing: 1e-86 N gives L10 1e302, hours beyond
        # the floats).
        for key in ("l10_million_revolutions", "l10_hours"):
            if v.get(key) == math.inf and "equivalent_load" in v:
                assert v["equivalent_load"] < 1e-6 * v["rating"], v
                v[key] = 0.0
    return safety


# --- kinematics -----------------------------------------------------------------------------


@SETTINGS
@given(any_count, any_count, any_count, any_real, any_real, any_real)
def test_kinematics(z_sun, z_planet, pins, speed, power, ratio):
    check("transmission_ratio", lambda: rvdyn.transmission_ratio(z_sun, z_planet, pins))
    check("body_speeds", lambda: rvdyn.body_speeds(speed, z_sun, z_planet, pins))
    check("body_speeds", lambda: rvdyn.body_speeds(speed))
    check("operating_point", lambda: rvdyn.operating_point(power, speed, ratio))


# --- wrong types: TypeError or ParameterError, nothing else ---------------------------------

wrong = st.sampled_from([None, "abc", "1.0", b"x", {}, [], [[1.0], [1.0, 2.0]], 1j, object(),
                         np.array(["a"]), np.array([1 + 1j]), np.array([1], dtype="datetime64[s]"),
                         [None], (1.0, "a")])


@SETTINGS
@given(wrong, st.integers(0, 5))
def test_wrong_types(value, which):
    g = rvdyn.CycloidGeometry.paper()
    calls = [
        lambda: g.profile(value),
        lambda: rvdyn.contact_stiffness(value, 0.01, 0.1),
        lambda: rvdyn.hertz_line_contact(1.0, value, 0.01, 0.1),
        lambda: rvdyn.impact_force(1e-6, value, 1e10),
        lambda: rvdyn.CycloidGeometry(24, value, 0.15, 0.01, 0.04),
        lambda: rvdyn.transmission_ratio(value, 42, 24),
    ]
    check("wrong types", calls[which], type_error=True)


# --- scenes, simulate and results -----------------------------------------------------------

def _fields(physical: bool) -> dict[str, st.SearchStrategy[Any]]:
    def pick(phys: st.SearchStrategy[Any], other: st.SearchStrategy[Any]) -> st.SearchStrategy[Any]:
        return phys if physical else st.one_of(phys, other)

    return {
        "cycloid.d_rp": pick(st.floats(-2e-4, 0.0), any_real),
        "cycloid.d_rrp": pick(st.floats(0.0, 5e-5), any_real),
        "cycloid.pin_radius": pick(st.floats(8e-3, 1.2e-2), any_real),
        "density": pick(st.floats(2e3, 2e4), any_real),
        "cranks": pick(st.just(3), any_count),
        "drive.speed": pick(st.floats(10.0, 200.0), any_real),
        "pin_errors.radius": pick(st.lists(st.floats(-2e-5, 2e-5), min_size=24, max_size=24),
                                  st.lists(any_real, min_size=24, max_size=24)),
    }


scene_changes = st.booleans().flatmap(
    lambda physical: st.fixed_dictionaries({}, optional=_fields(physical)))

run_options = st.booleans().flatmap(lambda physical: st.fixed_dictionaries({}, optional={
    "dt": st.floats(1e-5, 1e-4) if physical else st.one_of(st.floats(1e-6, 1e-3), any_real),
    "max_samples": st.integers(2, 2000) if physical else any_count,
    "record_interval": (st.floats(1e-5, 1e-3) if physical
                        else st.one_of(st.floats(1e-5, 1e-3), any_real)),
}))


@settings(max_examples=max(10, EXAMPLES // 5), deadline=None, derandomize=True, database=None,
          suppress_health_check=[HealthCheck.too_slow, HealthCheck.filter_too_much])
@given(st.sampled_from(["idle", "paper", "rated"]), scene_changes, run_options,
       st.sampled_from(["rk4", "dopri5", "generalized-alpha"]),
       st.one_of(st.floats(0.0, 0.002), any_real))
def test_scenes_simulate_and_results(load, changes, options, integrator, when):
    scene = check("Scene.paper/replace", lambda: rvdyn.Scene.paper(load, **changes))
    if scene is None:
        return
    check("Scene.model_info", scene.model_info)
    # Short runs (2 ms): the property is about bad input, not about long dynamics.
    r = check("simulate", lambda: rvdyn.simulate(scene, 0.002, integrator, **options))
    if r is None:
        return
    for name in r.channels:
        check("Result channels", lambda: getattr(r, name))
    check("Result.largest_moment_pin", lambda: r.largest_moment_pin(when))
    check("Result.disc_path_radius", lambda: r.disc_path_radius(when))
    check("Result.loaded_pin_stats", lambda: r.loaded_pin_stats())
    check("Result.energy_balance", r.energy_balance)


# --- the dangerous cases, in child processes ------------------------------------------------

CHILD = textwrap.dedent(
    """
    import json, resource, sys
    import numpy as np, rvdyn
    # Cap the address space: an allocation beyond it must become a MemoryError.
    resource.setrlimit(resource.RLIMIT_AS, (3 << 30, 3 << 30))
    g = rvdyn.CycloidGeometry.paper()
    for case in json.loads(sys.stdin.read()):
        kind, shape = case["kind"], tuple(case["shape"])
        try:
            if kind == "ndim":
                a = np.zeros(shape)
                calls = [lambda: g.profile(a), lambda: g.curvature_radius(a),
                         lambda: rvdyn.contact_stiffness(a + 5e-3, 0.01, 0.1),
                         lambda: rvdyn.hertz_line_contact(a + 1.0, 0.04, 0.01, 0.1),
                         lambda: rvdyn.impact_force(a, 0.0, 1e10)]
            else:
                a = np.broadcast_to(np.array(case["value"]), shape)
                b = np.broadcast_to(np.array(0.01), shape[-1:]) if shape else 0.01
                calls = [lambda: g.profile(a), lambda: g.normal(a),
                         lambda: rvdyn.contact_stiffness(a, b, 0.1),
                         lambda: rvdyn.hertz_line_contact(a, 0.04, b, 0.1),
                         lambda: rvdyn.impact_force(a, b, 1e10)]
            for call in calls:
                try:
                    out = call()
                    ok = all(np.isfinite(np.asarray(x)).all() for x in
                             (out if isinstance(out, tuple) else (out,)))
                    print(json.dumps(["returned" if ok else "non-finite", kind]), flush=True)
                except (rvdyn.RvdynError, MemoryError) as e:
                    print(json.dumps(["clean", type(e).__name__]), flush=True)
                except BaseException as e:
                    print(json.dumps(["defect", type(e).__name__ + ": " + str(e)[:200]]),
                          flush=True)
        except MemoryError:
            print(json.dumps(["clean", "MemoryError (numpy)"]), flush=True)
    """
)


@st.composite
def dangerous_case(draw) -> dict[str, Any]:
    if draw(st.booleans()):
        return {"kind": "ndim", "shape": [1] * draw(st.integers(31, 64))}
    # A virtual size of at least 2**36 elements (512 GiB as float64): never allocatable.
    dims = draw(st.integers(1, 4))
    sizes = draw(st.lists(st.integers(1, 2**20), min_size=dims, max_size=dims))
    total = math.prod(sizes)
    if total < 2**36:
        sizes[-1] = max(sizes[-1], (2**36 + total // sizes[-1] - 1) // (total // sizes[-1]))
    if math.prod(sizes) * 8 > 2**62:  # numpy's own limit for an array's byte size
        sizes = [2**36]
    return {"kind": "view", "shape": sizes, "value": draw(st.floats(1e-6, 1.0))}


@settings(max_examples=max(3, EXAMPLES // 30), deadline=None, derandomize=True, database=None,
          suppress_health_check=[HealthCheck.too_slow])
@given(st.lists(dangerous_case(), min_size=4, max_size=8))
def test_dangerous_cases_in_a_child_process(cases):
    p = subprocess.run([sys.executable, "-c", CHILD], input=json.dumps(cases), text=True,
                       capture_output=True, timeout=300,
                       env={"RUST_BACKTRACE": "0", "PATH": "/usr/bin:/bin"})
    results = [json.loads(line) for line in p.stdout.splitlines() if line.startswith("[")]
    TRIED["dangerous (child process)"] += len(results)
    CLEAN["dangerous (child process)"] += sum(r[0] in ("clean", "returned") for r in results)
    RETURNED["dangerous (child process)"] += sum(r[0] == "returned" for r in results)
    assert p.returncode == 0, f"child died with {p.returncode}: {p.stderr[-800:]}"
    assert len(results) == 5 * len(cases), p.stdout
    bad = [r for r in results if r[0] not in ("clean", "returned")]
    assert not bad, bad


# --- any value at any scene field ------------------------------------------------------------

_SCENE_PATHS = sorted({f["path"].replace("[]", ".0").replace("contact.*", "contact.pin")  # type: ignore[union-attr]
                       for f in rvdyn._core.scene_fields()})
json_values = st.recursive(
    st.one_of(st.none(), st.booleans(), st.sampled_from(EXTREME_FLOATS[:-3]), st.sampled_from(HUGE_INTS),
              st.integers(-5, 30), st.text(max_size=8)),
    lambda inner: st.one_of(st.lists(inner, max_size=4), st.dictionaries(st.text(max_size=8), inner, max_size=3)),
    max_leaves=8)


@settings(max_examples=EXAMPLES, deadline=None, derandomize=True, database=None)
@given(st.sampled_from(["paper", "physical"]), st.sampled_from(_SCENE_PATHS), json_values)
def test_any_value_at_any_scene_field(preset, path, value):
    # A scene (which survives its JSON) or a SceneError / GeometryError / ParameterError; the
    # messages of mistyped values are checked field by field in the Rust schema tests.
    base = rvdyn.Scene.paper("rated") if preset == "paper" else rvdyn.Scene.physical("rated")
    TRIED["Scene.replace (any value)"] += 1
    try:
        scene = base.replace(**{path: value})
    except rvdyn.RvdynError as e:
        assert len(str(e)) < 1000, e
    else:
        assert rvdyn.Scene.from_json(scene.to_json()) == scene
        RETURNED["Scene.replace (any value)"] += 1
    CLEAN["Scene.replace (any value)"] += 1


def test_zz_counts():
    """Every call of this module was counted, and every one ended cleanly."""
    assert sum(TRIED.values()) > 0
    assert TRIED == CLEAN, {k: (TRIED[k], CLEAN[k]) for k in TRIED if TRIED[k] != CLEAN[k]}
