"""rvdyn: dynamics of RV cycloid planetary reducers, with a Rust core.

Units are SI everywhere (m, kg, s, N, rad, Pa; IMPACT stiffness in N/m^exponent). Degrees per
second appear only in the command-line output and through :func:`deg_s` / :func:`rad_s`.

Main entry points
-----------------
CycloidGeometry
    Exact cycloid disc: profile, normals, curvature, exact pin gap, mass properties.
InvoluteStage
    The involute first stage (sun and planets).
contact_stiffness, stiffness_maximum, hertz_line_contact, impact_force
    Contact laws (vectorised, numpy in and out).
crank_bearing_rows, CrankLayout
    A crank's two bearing loads from the planar models' lumped crank bearing force.
transmission_ratio, body_speeds, operating_point
    Kinematics and the operating point.
Scene, Options, simulate, sweep, Result
    Reducer scenes, run options, dynamic runs (one or many in parallel) and their recorded
    results. The theory is in the repository's ``docs/model.md``, the user guide in
    ``docs/guide.md``.
study
    Tolerance studies (Monte Carlo / Latin hypercube, threads / processes / Dask / Ray).
order_spectrum, excitation_orders
    Order spectrum of a recorded channel, labelled with the reducer's excitation orders.
modes, modes_at, modes_over_mesh, campbell
    Modes about the loaded equilibrium or a dynamic run's state (energy shares per
    contact/bearing/shaft family), over a
    mesh period, and the Campbell diagram over input speed.
rvdyn.plotting
    Matplotlib figures (geometry, contact stiffness).
"""

from __future__ import annotations

import math

from . import _args, _core
from ._core import (
    PAPER_IMPACT_DEPTH,
    PAPER_IMPACT_EXPONENT,
    PAPER_IMPACT_MAX_DAMPING,
    PAPER_IMPACT_STIFFNESS,
    PAPER_PRINTED_OUTPUT_TORQUE,
    PAPER_STIFFNESS_R1,
    PAPER_STIFFNESS_R2,
    CycloidGeometry,
    InvoluteStage,
    body_speeds,
    contact_stiffness,
    crank_bearing_rows,
    hertz_line_contact,
    impact_force,
    operating_point,
    stiffness_maximum,
    transmission_ratio,
)
from ._types import GapResult, LineContact, OperatingPoint
from .analysis.campbell import campbell
from .bearing import CrankLayout
from .analysis.modes import modes, modes_at, modes_over_mesh
from .analysis.spectrum import excitation_orders, order_spectrum
from .result import Result
from .scene import Scene
from .simulation import INTEGRATORS, Options, simulate, sweep
from .analysis import ltca
from .errors import (
    ConvergenceError,
    GeometryError,
    ParameterError,
    RvdynError,
    SceneError,
    SimulationError,
)
from . import study  # noqa: E402  (rvdyn.study(...) runs a tolerance study; see rvdyn.study)

__version__: str = _core.__version__

__all__ = [
    "__version__",
    "Scene",
    "Result",
    "Options",
    "simulate",
    "sweep",
    "ltca",
    "study",
    "INTEGRATORS",
    "order_spectrum",
    "excitation_orders",
    "modes",
    "modes_at",
    "modes_over_mesh",
    "campbell",
    "CycloidGeometry",
    "InvoluteStage",
    "GapResult",
    "LineContact",
    "OperatingPoint",
    "contact_stiffness",
    "stiffness_maximum",
    "hertz_line_contact",
    "crank_bearing_rows",
    "CrankLayout",
    "impact_force",
    "transmission_ratio",
    "body_speeds",
    "operating_point",
    "deg_s",
    "rad_s",
    "PAPER_IMPACT_STIFFNESS",
    "PAPER_IMPACT_EXPONENT",
    "PAPER_IMPACT_MAX_DAMPING",
    "PAPER_IMPACT_DEPTH",
    "PAPER_PRINTED_OUTPUT_TORQUE",
    "PAPER_STIFFNESS_R1",
    "PAPER_STIFFNESS_R2",
    "RvdynError",
    "GeometryError",
    "ParameterError",
    "SceneError",
    "ConvergenceError",
    "SimulationError",
]


def deg_s(rad_per_s: float) -> float:
    """Convert an angular speed from rad/s to deg/s (e.g. for comparing with the paper). A
    value that is not a finite number is a :class:`ParameterError`."""
    return _args.real("rad_per_s", rad_per_s, "rad/s") * 180.0 / math.pi


def rad_s(deg_per_s: float) -> float:
    """Convert an angular speed from deg/s to rad/s (the paper's 8328 deg/s -> 145.35 rad/s). A
    value that is not a finite number is a :class:`ParameterError`."""
    return _args.real("deg_per_s", deg_per_s, "deg/s") * math.pi / 180.0
