"""Every bad input raises the right rvdyn exception with a message that says what is wrong.

Bad input is always a ValueError subclass (GeometryError or ParameterError); the message names
the argument or the rule, and says what would be valid.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

import rvdyn
from rvdyn import errors

NAN, INF = math.nan, math.inf
P = dict(pins=24, eccentricity=4.5e-3, pin_circle_radius=0.15, pin_radius=0.01, face_width=0.04)


def disc(**kw):
    return rvdyn.CycloidGeometry(**{**P, **kw})


G = rvdyn.CycloidGeometry.paper()
K = rvdyn.PAPER_IMPACT_STIFFNESS
PIN = np.array([0.15, 0.0])


def test_exception_hierarchy():
    assert issubclass(rvdyn.GeometryError, rvdyn.RvdynError)
    assert issubclass(rvdyn.GeometryError, ValueError)
    assert issubclass(rvdyn.ParameterError, ValueError)
    assert issubclass(rvdyn.SceneError, ValueError)
    assert issubclass(rvdyn.ConvergenceError, ArithmeticError)
    assert issubclass(rvdyn.SimulationError, RuntimeError)
    assert not issubclass(rvdyn.SimulationError, ValueError)
    assert rvdyn.RvdynError is errors.RvdynError
    for cls in (rvdyn.GeometryError, rvdyn.ParameterError, rvdyn.SceneError,
                rvdyn.ConvergenceError, rvdyn.SimulationError):
        assert cls.__module__ == "rvdyn.errors"


# (call, exception class, fragments the message must contain)
CASES = [
    # ---- CycloidGeometry: non-finite, negative, each geometry rule
    (lambda: disc(eccentricity=NAN), rvdyn.ParameterError, ["eccentricity", "finite"]),
    (lambda: disc(pin_circle_radius=INF), rvdyn.ParameterError, ["pin_circle_radius", "finite"]),
    (lambda: disc(pin_radius=-0.01), rvdyn.ParameterError, ["pin_radius", "> 0"]),
    (lambda: disc(face_width=0.0), rvdyn.ParameterError, ["face_width", "> 0"]),
    (lambda: disc(d_rp=NAN), rvdyn.ParameterError, ["d_rp", "finite"]),
    (lambda: disc(d_delta=-INF), rvdyn.ParameterError, ["d_delta", "finite"]),
    (lambda: disc(pins=-3), rvdyn.ParameterError, ["pins", "whole number", "-3"]),
    (lambda: disc(pins=2), rvdyn.GeometryError, ["at least 3 pins"]),
    (lambda: disc(eccentricity=7e-3), rvdyn.GeometryError, ["curtate", "< 1", "reduce"]),
    (lambda: disc(pin_radius=0.0196), rvdyn.GeometryError, ["overlap", "smaller pins"]),
    (lambda: disc(pin_radius=0.019, d_rrp=0.002), rvdyn.GeometryError, ["undercut"]),
    # ---- CycloidGeometry methods: NaN/inf arrays, wrong shapes
    (lambda: G.profile([0.1, NAN]), rvdyn.ParameterError, ["phi", "finite", "index 1"]),
    (lambda: G.normal(np.array([[INF]])), rvdyn.ParameterError, ["phi", "finite"]),
    (lambda: G.curvature_radius(NAN), rvdyn.ParameterError, ["phi", "finite"]),
    (lambda: G.gap([0.15, 0.0, 0.0], [0, 0], 0.0), rvdyn.ParameterError,
     ["pin_center", "shape (2,)", "(3,)"]),
    (lambda: G.gap(PIN, np.zeros((2, 2)), 0.0), rvdyn.ParameterError,
     ["disc_center", "(2, 2)"]),
    (lambda: G.gap([NAN, 0.0], [0, 0], 0.0), rvdyn.ParameterError, ["pin_center", "finite"]),
    (lambda: G.gap(PIN, [0, 0], INF), rvdyn.ParameterError, ["disc_angle", "finite"]),
    (lambda: G.gap(PIN, [0, 0], 0.0, pin_radius=-1.0), rvdyn.ParameterError, ["pin_radius"]),
    (lambda: G.kinematic_pose(NAN), rvdyn.ParameterError, ["psi", "finite"]),
    (lambda: G.mass_properties(density=-1.0), rvdyn.ParameterError, ["density", "kg/m^3"]),
    # ---- InvoluteStage
    (lambda: rvdyn.InvoluteStage(18, 42, 3, NAN, 0.35, 0.03), rvdyn.ParameterError, ["module"]),
    (lambda: rvdyn.InvoluteStage(18, 42, -1, 3e-3, 0.35, 0.03), rvdyn.ParameterError,
     ["planets", "-1"]),
    (lambda: rvdyn.InvoluteStage(18, 42, 0, 3e-3, 0.35, 0.03), rvdyn.GeometryError,
     ["at least 1 planet"]),
    # ---- contact stiffness
    (lambda: rvdyn.contact_stiffness(0.005, 0.01, 0.1, "concave"), rvdyn.ParameterError,
     ["unknown contact condition", "convex-convex", "convex-concave"]),
    (lambda: rvdyn.contact_stiffness([0.005, NAN], 0.01, 0.1), rvdyn.ParameterError,
     ["width", "finite", "index 1"]),
    (lambda: rvdyn.contact_stiffness(0.005, INF, 0.1), rvdyn.ParameterError, ["r1", "finite"]),
    (lambda: rvdyn.contact_stiffness([0.005, -0.001], 0.01, 0.1), rvdyn.ParameterError,
     ["contact width", "> 0", "index 1"]),
    (lambda: rvdyn.contact_stiffness([1e-3, 2e-3, 3e-3], [0.01, 0.02], 0.1),
     rvdyn.ParameterError, ["broadcast", "(3,)", "(2,)"]),
    (lambda: rvdyn.contact_stiffness(0.005, 0.01, 0.01, "convex-concave"), rvdyn.GeometryError,
     ["convex-concave", "r2"]),
    (lambda: rvdyn.contact_stiffness(0.005, 0.01, 0.1, poisson_ratio=0.5),
     rvdyn.ParameterError, ["Poisson", "(-1, 0.5)"]),
    (lambda: rvdyn.contact_stiffness(0.01, 0.01, 0.02, penetration=1e10), rvdyn.ParameterError,
     ["penetration 10000000000.0 m", "smaller penetration"]),
    (lambda: rvdyn.contact_stiffness(0.005, 0.01, 0.1, exponent=0.5), rvdyn.ParameterError,
     ["exponent", ">= 1"]),
    (lambda: rvdyn.stiffness_maximum(0.01, 0.1, lo=0.01, hi=0.001), rvdyn.ParameterError,
     ["lo < hi"]),
    (lambda: rvdyn.stiffness_maximum(0.01, 0.1, "x"), rvdyn.ParameterError, ["condition"]),
    # ---- Hertz
    (lambda: rvdyn.hertz_line_contact(-1.0, 0.04, 0.01, 0.1), rvdyn.ParameterError,
     ["force", ">= 0"]),
    (lambda: rvdyn.hertz_line_contact(1e3, [0.04, 0.0], 0.01, 0.1), rvdyn.ParameterError,
     ["length", "> 0", "index 1"]),
    (lambda: rvdyn.hertz_line_contact(1e3, 0.04, 0.012, -0.01), rvdyn.GeometryError,
     ["concave", "larger in magnitude"]),
    (lambda: rvdyn.hertz_line_contact(1e3, 0.04, 0.0, 0.1), rvdyn.GeometryError,
     ["r1", "non-zero"]),
    (lambda: rvdyn.hertz_line_contact(1e12, 0.04, 0.01, 0.1), rvdyn.ParameterError,
     ["half-width", "smaller radius 0.01 m", "line load"]),
    (lambda: rvdyn.hertz_line_contact(1e3, 0.01, 1e-300, 0.01), rvdyn.ParameterError,
     ["force, length and radii"]),
    (lambda: rvdyn.hertz_line_contact(1e3, 0.04, 0.01, 0.1, youngs_modulus=-2e11),
     rvdyn.ParameterError, ["Young's modulus"]),
    (lambda: rvdyn.hertz_line_contact(np.ones(3), np.ones(4), 0.01, 0.1), rvdyn.ParameterError,
     ["broadcast", "(3,)", "(4,)"]),
    # ---- IMPACT
    (lambda: rvdyn.impact_force(NAN, 0.0, K), rvdyn.ParameterError, ["penetration", "finite"]),
    (lambda: rvdyn.impact_force(1e-6, [0.0, INF], K), rvdyn.ParameterError,
     ["velocity", "finite", "m/s"]),
    (lambda: rvdyn.impact_force(1e-6, 0.0, -K), rvdyn.ParameterError, ["stiffness", "> 0"]),
    (lambda: rvdyn.impact_force(1e-6, 0.0, K, exponent=0.8), rvdyn.ParameterError,
     ["exponent", ">= 1"]),
    (lambda: rvdyn.impact_force(1e-6, 0.0, K, cmax=-1.0), rvdyn.ParameterError,
     ["max_damping", ">= 0"]),
    (lambda: rvdyn.impact_force(1e-6, 0.0, K, depth=0.0), rvdyn.ParameterError,
     ["damping_depth", "> 0"]),
    # ---- kinematics
    (lambda: rvdyn.transmission_ratio(0, 42, 24), rvdyn.GeometryError, ["at least 1"]),
    (lambda: rvdyn.transmission_ratio(18, 42, -24), rvdyn.ParameterError, ["pins", "-24"]),
    (lambda: rvdyn.body_speeds(NAN), rvdyn.ParameterError, ["input speed", "finite"]),
    (lambda: rvdyn.body_speeds(1.0, pins=2), rvdyn.GeometryError, ["3 pins"]),
    (lambda: rvdyn.operating_point(112e3, 0.0, 57.0), rvdyn.ParameterError,
     ["non-zero", "running speed"]),
    (lambda: rvdyn.operating_point(INF, 1.0, 57.0), rvdyn.ParameterError, ["power", "finite"]),
]


@pytest.mark.parametrize("call, cls, fragments", CASES,
                         ids=[f"case{i:02d}" for i in range(len(CASES))])
def test_bad_input_raises_a_clear_error(call, cls, fragments):
    with pytest.raises(cls) as info:
        call()
    exc = info.value
    assert type(exc) is cls  # exactly this class, not a sibling
    assert isinstance(exc, rvdyn.RvdynError)
    assert isinstance(exc, ValueError)  # bad input
    message = str(exc)
    for fragment in fragments:
        assert fragment.lower() in message.lower(), (fragment, message)


def test_wrong_python_types_are_type_errors():
    # Not a number at all: Python's own TypeError/ValueError from argument conversion.
    with pytest.raises((TypeError, ValueError)):
        G.profile("abc")
    with pytest.raises(TypeError):
        rvdyn.CycloidGeometry(24.5, 4.5e-3, 0.15, 0.01, 0.04)
    with pytest.raises(TypeError):
        rvdyn.contact_stiffness(0.005, 0.01, 0.1, condition=3)


def test_no_nan_comes_out_of_valid_input():
    phi = np.linspace(-100, 100, 10001)
    assert np.all(np.isfinite(G.profile(phi)))
    assert np.all(np.isfinite(G.curvature_radius(phi)))
    k = rvdyn.contact_stiffness(np.geomspace(1e-5, 1.0, 100), 0.01, 0.1035, "convex-concave")
    assert np.all(np.isfinite(k))


def test_plotting_rejects_bad_arguments():
    from rvdyn import plotting

    with pytest.raises(rvdyn.ParameterError, match="disc"):
        plotting.plot_geometry(disc="middle")
    with pytest.raises(rvdyn.ParameterError, match="psi"):
        plotting.plot_geometry(psi=NAN)
    with pytest.raises(rvdyn.ParameterError, match="widths"):
        plotting.plot_stiffness(widths=[[1e-3, 2e-3]])


# ---- the hand-written stubs (python/rvdyn/_core.pyi) mirror the compiled module --------------


def _stub_tree():
    import ast
    import pathlib

    import rvdyn._core

    path = pathlib.Path(rvdyn.__file__).with_name("_core.pyi")
    return ast.parse(path.read_text(encoding="utf-8")), rvdyn._core


def _params(fn) -> list[tuple[str, object]]:
    import ast

    args = fn.args
    names = [a.arg for a in args.posonlyargs + args.args]
    defaults = [None] * (len(names) - len(args.defaults)) + [
        ast.literal_eval(d) for d in args.defaults
    ]
    # Keyword-only arguments (e.g. Options(integrator, *, dt=...)); "..." means "no default
    # written in the stub" and is compared as None.
    names += [a.arg for a in args.kwonlyargs]
    defaults += [None if d is None or (isinstance(d, ast.Constant) and d.value is Ellipsis) else ast.literal_eval(d)
                 for d in args.kw_defaults]
    return [(n, d) for n, d in zip(names, defaults) if n not in ("self", "cls")]


def _runtime_params(obj) -> list[tuple[str, object]]:
    import inspect

    sig = inspect.signature(obj)
    return [(p.name, None if p.default is inspect.Parameter.empty else p.default)
            for p in sig.parameters.values() if p.name not in ("self", "cls")]


def test_stubs_name_every_public_object_of_the_core():
    import ast

    tree, core = _stub_tree()
    names = set()
    for node in tree.body:
        if isinstance(node, (ast.FunctionDef, ast.ClassDef)):
            names.add(node.name)
        elif isinstance(node, ast.AnnAssign):
            names.add(node.target.id)
    public = {n for n in dir(core) if not n.startswith("_")}
    assert public == names - {"__version__"}


def test_stub_signatures_match_the_core():
    import ast

    tree, core = _stub_tree()
    for node in tree.body:
        if isinstance(node, ast.FunctionDef):
            assert _params(node) == _runtime_params(getattr(core, node.name)), node.name
        elif isinstance(node, ast.ClassDef):
            cls = getattr(core, node.name)
            members = {n.name: n for n in node.body if isinstance(n, ast.FunctionDef)}
            constructor = members.get("__new__", members.get("__init__"))
            if constructor is not None:  # a class without one is built by factories only
                assert _params(constructor) == _runtime_params(cls), node.name
            for name, fn in members.items():
                decorators = {getattr(d, "id", None) for d in fn.decorator_list}
                if name.startswith("__") or "property" in decorators:
                    if "property" in decorators:
                        assert isinstance(getattr(cls, name), property) or hasattr(cls, name)
                    continue
                assert _params(fn) == _runtime_params(getattr(cls, name)), f"{node.name}.{name}"
            public = {n for n in dir(cls) if not n.startswith("_")}
            assert public == {n for n in members if not n.startswith("_")}, node.name
