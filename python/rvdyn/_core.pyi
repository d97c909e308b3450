"""Type stubs of the compiled core ``rvdyn._core`` (hand-written; keep in sync with rust/python/).

Units are SI: m, kg, s, N, rad, Pa; IMPACT stiffness in N/m^exponent. Array arguments accept a
float, a sequence or a numpy array; functions marked "broadcast" combine their array arguments
with numpy's broadcasting rules and return a float when every array argument is a scalar.
"""

from typing import Any, Sequence, Union, final

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ._types import GapResult, LineContact, OperatingPoint

_FloatOrArray = Union[float, NDArray[np.float64]]

__all__ = [
    "__version__",
    "CycloidGeometry",
    "InvoluteStage",
    "contact_stiffness",
    "stiffness_maximum",
    "hertz_line_contact",
    "impact_force",
    "roller_bearing_life",
    "crank_bearing_rows",
    "roller_system_life",
    "PAPER_IMPACT_STIFFNESS",
    "PAPER_IMPACT_EXPONENT",
    "PAPER_IMPACT_MAX_DAMPING",
    "PAPER_IMPACT_DEPTH",
    "PAPER_STIFFNESS_R1",
    "PAPER_STIFFNESS_R2",
    "transmission_ratio",
    "body_speeds",
    "operating_point",
    "PAPER_PRINTED_OUTPUT_TORQUE",
    "CompiledScene",
    "default_compliant_joints",
    "scene_fields",
    "Options",
    "options_from_dict",
    "integrators",
    "channels",
    "simulate",
    "sweep",
    "LtcaSolver",
    "excitation_orders",
    "campbell_crossings",
    "modes",
    "modes_state",
    "rigid_coordinates",
    "campbell_diagram",
]

__version__: str

PAPER_IMPACT_STIFFNESS: float
"""The paper's IMPACT stiffness 3.988e5 N/mm^1.5 in SI: 1.2611e10 N/m^1.5."""
PAPER_IMPACT_EXPONENT: float
"""The paper's IMPACT force exponent: 1.5."""
PAPER_IMPACT_MAX_DAMPING: float
"""The paper's IMPACT maximum damping 100 N s/mm in SI: 1e5 N s/m."""
PAPER_IMPACT_DEPTH: float
"""The paper's IMPACT penetration depth for full damping 0.01 mm in SI: 1e-5 m."""
PAPER_STIFFNESS_R1: float
"""Pin radius R1 [m] used to read the paper's Fig. 3 (assumed 10 mm)."""
PAPER_STIFFNESS_R2: float
"""Disc radius R2 [m] used to read the paper's Fig. 3 (disc pitch radius e zc = 103.5 mm)."""
PAPER_PRINTED_OUTPUT_TORQUE: float
"""The output torque printed in the paper, 4024.9 N m: inconsistent with its 112 kW (it is
10.3 kW at the output speed); the lossless value is 43.92 kN m."""

@final
class CycloidGeometry:
    """A validated cycloid disc and its pin ring (SI units: m, rad).

    Parameters: pins zp (>= 3), eccentricity e [m], pin_circle_radius rp [m], pin_radius
    rrp [m], face_width [m], d_rp and d_rrp shift and equidistant modifications [m] (grinding
    convention, the pins stay at rp with radius rrp), d_delta rotation modification [rad].

    Raises GeometryError naming the rule (fewer than 3 pins, curtate ratio K1 >= 1, overlapping
    pins, undercut, no material at the root) and ParameterError for non-finite or
    non-positive sizes.
    """

    def __new__(
        cls,
        pins: int,
        eccentricity: float,
        pin_circle_radius: float,
        pin_radius: float,
        face_width: float,
        d_rp: float = 0.0,
        d_rrp: float = 0.0,
        d_delta: float = 0.0,
    ) -> CycloidGeometry: ...
    @classmethod
    def paper(cls) -> CycloidGeometry:
        """The paper's default disc: zp 24, e 4.5 mm (given); rp 150 mm, rrp 10 mm, face 40 mm
        (assumed); no modification."""
    @property
    def pins(self) -> int:
        """Number of pins zp."""
    @property
    def lobes(self) -> int:
        """Number of lobes zc = zp - 1."""
    @property
    def eccentricity(self) -> float:
        """Eccentricity e [m]."""
    @property
    def pin_circle_radius(self) -> float:
        """Pin circle radius rp [m]."""
    @property
    def pin_radius(self) -> float:
        """Pin radius rrp [m]."""
    @property
    def face_width(self) -> float:
        """Disc face width [m]."""
    @property
    def d_rp(self) -> float:
        """Shift modification d_rp [m]."""
    @property
    def d_rrp(self) -> float:
        """Equidistant modification d_rrp [m]."""
    @property
    def d_delta(self) -> float:
        """Rotation modification d_delta [rad]."""
    @property
    def k1(self) -> float:
        """Curtate ratio K1 = e zp / (rp + d_rp) [-]."""
    @property
    def pitch_radius(self) -> float:
        """Disc pitch radius rc' = e zc [m]."""
    @property
    def min_convex_radius(self) -> float:
        """Minimum convex radius of curvature of the pin-centre curve [m] (undercut limit)."""
    def profile(self, phi: ArrayLike) -> NDArray[np.float64]:
        """Profile points (x, y) [m], disc frame, for curve parameters phi [rad] of any shape;
        returns shape phi.shape + (2,)."""
    def normal(self, phi: ArrayLike) -> NDArray[np.float64]:
        """Outward unit normals of the profile, disc frame; shape phi.shape + (2,)."""
    def curvature_radius(self, phi: ArrayLike) -> _FloatOrArray:
        """Signed radius of curvature of the profile [m] (positive convex); shape phi.shape,
        a float for a scalar phi."""
    def gap(
        self,
        pin_center: ArrayLike,
        disc_center: ArrayLike,
        disc_angle: float,
        pin_radius: float | None = None,
    ) -> GapResult:
        """Exact signed gap between a pin (centre (2,) [m]) and the disc placed at disc_center
        (2,) [m] turned by disc_angle [rad], fixed frame. pin_radius [m] overrides the disc's
        pin radius. Where several profile points are equally near (a pin at the disc centre, or
        on a symmetry line far from the profile) the gap is exact and phi, point and normal
        are one of them; at a straight profile point (K1 = 1/zp at the root) the curvature
        radius is round-off of either sign. Raises ParameterError (bad input) or
        ConvergenceError (the foot search fails)."""
    def pin_positions(self) -> NDArray[np.float64]:
        """Pin centres (zp, 2) [m]; row j is at angle 2 pi j / zp, the paper's pin j + 1."""
    def classical_pin_forces(self, disc_torque: float, crank_angle: float) -> NDArray[np.float64]:
        """Classical quasi-static pin forces (zp,) [N] of the unmodified disc carrying
        disc_torque [N m] about its centre at crank angle crank_angle [rad]: F_j = T l_j / sum l^2
        on the pins whose lever l_j has the torque's sign. A positive output torque of the
        reducer loads the pins with negative lever: compare ltca(scene, +T) with
        classical_pin_forces(-T_c, psi)."""
    def classical_levers(self, crank_angle: float) -> NDArray[np.float64]:
        """Levers (zp,) [m] of the contact normals about the disc centre at crank angle [rad]."""
    def kinematic_pose(self, psi: float) -> tuple[NDArray[np.float64], float]:
        """Disc centre (2,) [m] = e (cos psi, sin psi) and disc angle -psi/zc [rad] for the
        crank angle psi [rad]."""
    def mass_properties(self, density: float = 7850.0) -> tuple[float, float]:
        """(mass [kg], polar inertia about the disc centre [kg m^2]) of the disc with the
        default holes (a 40 mm bore and crank holes on a 90 mm circle: sized for the paper's
        disc; a disc too small for them raises GeometryError, and a scene then takes its
        inertias.disc), for a density [kg/m^3]."""
    def __reduce__(self) -> tuple[Any, ...]: ...

@final
class InvoluteStage:
    """The involute first stage (sun and equally spaced planets; SI units).

    Parameters: z_sun, z_planet (>= 5 teeth), planets (>= 1), module [m], pressure_angle [rad]
    in (0, 45 deg), face_width [m], backlash [m] along the line of action (>= 0).

    Raises GeometryError (too few teeth, colliding planets, involute interference, contact
    ratio < 1) and ParameterError (non-finite or non-positive sizes, pressure angle out of range).
    """

    def __new__(
        cls,
        z_sun: int,
        z_planet: int,
        planets: int,
        module: float,
        pressure_angle: float,
        face_width: float,
        backlash: float = 0.0,
    ) -> InvoluteStage: ...
    @classmethod
    def paper(cls) -> InvoluteStage:
        """The paper's stage: 18/42 teeth, 3 planets (given); module 3 mm, 20 deg, face 30 mm
        (assumed)."""
    @property
    def z_sun(self) -> int:
        """Sun teeth."""
    @property
    def z_planet(self) -> int:
        """Teeth of each planet."""
    @property
    def planets(self) -> int:
        """Number of planets."""
    @property
    def module(self) -> float:
        """Module [m]."""
    @property
    def pressure_angle(self) -> float:
        """Pressure angle [rad]."""
    @property
    def face_width(self) -> float:
        """Face width [m]."""
    @property
    def backlash(self) -> float:
        """Total backlash of one mesh along the line of action [m]."""
    @property
    def sun_pitch_radius(self) -> float:
        """Sun pitch radius [m]."""
    @property
    def planet_pitch_radius(self) -> float:
        """Planet pitch radius [m]."""
    @property
    def sun_base_radius(self) -> float:
        """Sun base radius [m]."""
    @property
    def planet_base_radius(self) -> float:
        """Planet base radius [m]."""
    @property
    def centre_distance(self) -> float:
        """Centre distance = crank circle radius [m]."""
    @property
    def addendum(self) -> float:
        """Addendum (= module) [m]."""
    @property
    def sun_tip_radius(self) -> float:
        """Sun tip radius [m]."""
    @property
    def planet_tip_radius(self) -> float:
        """Planet tip radius [m]."""
    @property
    def line_of_action_length(self) -> float:
        """Length of the path of contact [m]."""
    @property
    def contact_ratio(self) -> float:
        """Transverse contact ratio [-]."""
    @property
    def stage_ratio(self) -> float:
        """Fixed-carrier stage ratio -z_planet / z_sun [-]."""
    @property
    def planet_angles(self) -> NDArray[np.float64]:
        """Planet centre angles (planets,) [rad], carrier frame, planet 0 on +x."""
    def __reduce__(self) -> tuple[Any, ...]: ...

def contact_stiffness(
    width: ArrayLike,
    r1: ArrayLike,
    r2: ArrayLike,
    condition: str = "convex-convex",
    youngs_modulus: float = 2.17e11,
    poisson_ratio: float = 0.3,
    exponent: float = 1.5,
    penetration: float = 1e-5,
) -> _FloatOrArray:
    """Paper's contact stiffness k [N/m^exponent] (eqs. 5-11, errata corrected) for contact
    width [m], pin radius r1 [m] and disc radius of curvature r2 [m] (broadcast); condition
    "convex-convex" or "convex-concave"; E [Pa], nu [-], IMPACT exponent [-] and penetration
    depth x [m]."""

def stiffness_maximum(
    r1: float,
    r2: float,
    condition: str = "convex-convex",
    lo: float = 1e-4,
    hi: float = 0.1,
    youngs_modulus: float = 2.17e11,
    poisson_ratio: float = 0.3,
    exponent: float = 1.5,
    penetration: float = 1e-5,
) -> tuple[float, float]:
    """(width [m], k_max [N/m^exponent]) of the largest stiffness for widths in [lo, hi] [m];
    ParameterError if there is no interior maximum (the case for physical widths with the
    corrected formulas)."""

def hertz_line_contact(
    force: ArrayLike,
    width: ArrayLike,
    r1: ArrayLike,
    r2: ArrayLike,
    youngs_modulus: float = 2.17e11,
    poisson_ratio: float = 0.3,
) -> LineContact:
    """Hertz line contact for force [N] over width [m] between radii r1, r2 [m] (positive
    convex, negative concave), broadcast: half_width [m], peak_pressure [Pa], mean_pressure
    [Pa], approach [m]."""

def roller_bearing_life(rating: float, loads: Sequence[float], revolutions: Sequence[float]) -> tuple[float, float]:
    """Equivalent load P [N] and ISO 281 L10 [million revolutions] of a roller bearing of rating C
    [N] over loads [N] weighted by revolutions; (0, inf) for a bearing that did not turn."""

def roller_system_life(lives: Sequence[float]) -> float:
    """L10 of roller bearings that fail when any one does: ``(sum L_i^-9/8)^(-8/9)``, in the
    unit of ``lives``."""

def crank_bearing_rows(
    crank_bearing_force: ArrayLike,
    eccentric_bearing_force: ArrayLike,
    *,
    bearings: tuple[float, float],
    discs: Sequence[float],
    planet: float,
) -> NDArray[np.float64]:
    """Forces [N] of a crank's two bearings (at axial positions ``bearings`` [m]) on the crank,
    shape (..., 2, 2), from the lumped crank bearing force (..., 2) and the discs' eccentric
    bearing forces (..., discs, 2), with the discs at ``discs`` and the planet at ``planet``
    [m] along the crank: statics of a rigid crank on two supports."""

def impact_force(
    penetration: ArrayLike,
    velocity: ArrayLike,
    k: float,
    exponent: float = 1.5,
    cmax: float = 1.0e5,
    depth: float = 1.0e-5,
) -> _FloatOrArray:
    """ADAMS IMPACT force [N] >= 0 for penetration [m] and penetration rate [m/s] (broadcast),
    stiffness k [N/m^exponent], exponent [-], cmax [N s/m], depth [m]."""

def transmission_ratio(z_sun: int, z_planet: int, pins: int) -> float:
    """Overall ratio 1 + (z_planet / z_sun) pins [-] (57 for the paper)."""

def body_speeds(
    input_speed: float, z_sun: int = 18, z_planet: int = 42, pins: int = 24
) -> dict[str, float]:
    """Speeds [rad/s] of sun, crank_absolute, crank_relative, disc_spin, disc_orbit, carrier
    for an input speed [rad/s]."""

def operating_point(power: float, input_speed: float, ratio: float) -> OperatingPoint:
    """Lossless operating point for power [W], input speed [rad/s] and ratio [-]."""

# ---- scenes and dynamic runs (rust/python/scene.rs, rust/python/simulate.rs; wrapped by
# rvdyn.Scene, rvdyn.simulate, rvdyn.sweep and rvdyn.Result: use those) -----------------------

@final
class CompiledScene:
    """A validated scene held by the core (immutable); ``rvdyn.Scene`` wraps it."""

    @staticmethod
    def from_json(text: str) -> CompiledScene:
        """Validate a scene given as JSON text (unknown fields are errors)."""
    @staticmethod
    def from_toml(text: str) -> CompiledScene:
        """Validate a scene given as TOML text."""
    @staticmethod
    def paper(load: str) -> CompiledScene:
        """The default scene; load is "idle", "paper" or "rated"."""
    @staticmethod
    def physical(load: str) -> CompiledScene:
        """The physical preset; load is "idle", "paper" or "rated"."""
    def physics_summary(self) -> str:
        """The contact physics at the rated operating point, as JSON text."""
    def bearing_ratings(self, kind: str = "dynamic") -> tuple[float | None, float | None]:
        """ISO 281 dynamic load ratings [N] (kind="static": ISO 76 static load ratings) of the
        eccentric and crank roller bearings (None if linear)."""
    def to_json(self, indent: bool = True) -> str:
        """The scene as JSON text."""
    def to_toml(self) -> str:
        """The scene as TOML text."""
    def get(self, path: str) -> str:
        """The value at a dotted field path, as JSON text."""
    def replace(self, changes: list[tuple[str, str]]) -> CompiledScene:
        """A new validated scene with (dotted path, JSON value) changes."""
    def nominal_mesh_force(self) -> float | None:
        """Nominal tangential force of one sun/planet mesh at the load's largest torque [N]
        (0 idle, None without a first stage)."""
    def is_light_load(self) -> bool:
        """Whether the load is light (idle, or a nominal mesh force below 10 N)."""
    def model_info(self) -> dict[str, Any]:
        """Mass properties [kg, kg m^2] and generalised masses the model uses (SI), crank radius
        [m], ratio, number of free coordinates (dof) and joint kind."""
    def __eq__(self, value: object, /) -> bool: ...
    def __hash__(self) -> int: ...

def default_compliant_joints() -> str:
    """The default compliant joints (assumed bearing stiffness [N/m] and damping [N s/m]) as JSON."""

def scene_fields() -> list[dict[str, str | None]]:
    """The scene schema (docs/scene.md): one dict per field with its dotted "path" ("[]" for
    any list index), "when" (the variant it belongs to), "type" (JSON type), "unit" (SI, "-"
    for none), "default" (JSON text; None = required), "rule" and "doc"."""

@final
class Options:
    """Options of a dynamic run (all but the end time), validated when built; None = default.

    integrator: "generalized-alpha" (default), "generalized-alpha-adaptive", "dopri5" or "rk4";
    dt [s] (None = the integrator's default: 1e-4, 1e-5 (initial), 1e-6 (initial), 1e-5 s);
    rtol (adaptive, velocities, default 1e-6, at most 1e-2); atol [m] (displacement tolerance
    of the error control and of Newton, default 1e-9 m, at most 1e-6 m); rho_inf in [0, 1]
    (default 0.8); record_interval [s], <= t_end (None = 1e-4 s or t_end if shorter);
    max_samples (default 50 000); channels (groups: "motion", "pins", "contact_points", "mesh",
    "energy", "bearings"; None = all but contact points); skip_separated (default True);
    step_check ("warn", "raise" or "off": a step or tolerance that cannot be accurate, default "warn");
    h_min [s] and max_steps (bounds of an adaptive method, default 1e-13 s and 1e8).
    """

    def __new__(
        cls,
        integrator: str | None = None,
        *,
        dt: float | None = None,
        rtol: float | None = None,
        atol: float | None = None,
        rho_inf: float | None = None,
        record_interval: float | None = None,
        max_samples: int | None = None,
        channels: Sequence[str] | str | None = None,
        skip_separated: bool | None = None,
        step_check: str | None = None,
        h_min: float | None = None,
        max_steps: int | None = None,
    ) -> Options: ...
    def replace(
        self,
        *,
        integrator: str | None = None,
        dt: float | None = None,
        rtol: float | None = None,
        atol: float | None = None,
        rho_inf: float | None = None,
        record_interval: float | None = None,
        max_samples: int | None = None,
        channels: Sequence[str] | str | None = None,
        skip_separated: bool | None = None,
        step_check: str | None = None,
        h_min: float | None = None,
        max_steps: int | None = None,
    ) -> Options:
        """A copy with the options given (not None) changed."""
    @property
    def integrator(self) -> str:
        """Integrator name."""
    @property
    def dt(self) -> float | None:
        """Step [s] (initial step of an adaptive method); None = the integrator's default."""
    @property
    def rtol(self) -> float:
        """Relative velocity tolerance of the adaptive method."""
    @property
    def atol(self) -> float:
        """Displacement tolerance [m]."""
    @property
    def rho_inf(self) -> float:
        """Spectral radius at infinite frequency of generalized-alpha."""
    @property
    def record_interval(self) -> float | None:
        """Sample interval [s]; None = 1e-4 s."""
    @property
    def max_samples(self) -> int:
        """Most samples kept."""
    @property
    def channels(self) -> list[str]:
        """Channel groups recorded."""
    @property
    def skip_separated(self) -> bool:
        """Whether pins that provably cannot touch skip the exact gap query."""
    @property
    def step_check(self) -> str:
        """What a fixed step that cannot be accurate does: "warn", "raise" or "off"."""
    @property
    def h_min(self) -> float:
        """Smallest step of an adaptive method [s]."""
    @property
    def max_steps(self) -> int:
        """Most steps of an adaptive method."""
    def to_dict(self) -> dict[str, Any]:
        """The options as a dict of constructor arguments."""
    def resolved(self, t_end: float) -> dict[str, Any]:
        """The options a run to t_end [s] actually uses (step and sample interval resolved)."""
    def __reduce__(self) -> tuple[Any, tuple[dict[str, Any]]]: ...
    def __eq__(self, value: object, /) -> bool: ...

def options_from_dict(d: dict[str, Any]) -> Options:
    """Rebuild options from Options.to_dict() (used by pickle)."""

def integrators() -> list[tuple[str, str, float, bool]]:
    """The registered integrators: (name, summary, default step [s], adaptive)."""

def channels() -> list[dict[str, Any]]:
    """The channel registry: name, group, shape (dimension names), unit, dtype, doc per channel."""

def simulate(
    scene: CompiledScene, t_end: float, options: Options, progress: bool = False
) -> tuple[dict[str, NDArray[Any]], dict[str, Any]]:
    """Run one scene for t_end [s]; returns (recorded numpy arrays, run statistics)."""

def sweep(
    scenes: list[CompiledScene], t_end: float, options: Options, threads: int | None = None
) -> list[tuple[dict[str, NDArray[Any]], dict[str, Any]] | BaseException]:
    """Run many scenes in parallel; per scene (arrays, statistics) or the exception it raised.
    Ctrl-C stops every run (KeyboardInterrupt)."""

# ---- quasi-static analysis (rust/python/ltca.rs; wrapped by rvdyn.analysis) -----------------

@final
class LtcaSolver:
    """The loaded tooth contact analysis of one scene; keeps its warm start and points."""

    def __new__(cls, scene: CompiledScene, tolerance: float) -> LtcaSolver: ...
    @property
    def mesh_period(self) -> float:
        """Crank-angle period of the contact pattern [rad]."""
    @property
    def te_window(self) -> float:
        """Crank-angle window after which the whole static state repeats [rad]: the mesh
        period, or a multiple of it with roller bearings (their roller sets stay fixed in the
        frame)."""
    @property
    def ratio(self) -> float:
        """Transmission ratio input/output."""
    @property
    def face_width(self) -> float:
        """Disc face width [m]."""
    def sweep(self, torque: float, crank_angles: Sequence[float]) -> dict[str, NDArray[Any]]:
        """Equilibria at crank_angles [rad] under torque [N m]: numpy arrays, crank angle first.
        At least 300 angles are solved as parallel chains of at least 150 (the same results on
        any number of threads)."""
    def fea_loads(self) -> tuple[str, str]:
        """Worst load case per disc over every point solved so far: (CSV, JSON)."""
    def transmission_error(self, torque: float, light: float | None, points: int, start: float,
                           pin_loads: bool = False, periods: int = 1) -> dict[str, Any]:
        """TE over ``periods`` mesh periods (``points`` crank angles each) at +-torque and
        (unless light is None) +-light [N m], with each curve's extremes located between the
        crank angles; with ``pin_loads``, key ``pin_loads`` holds per loaded curve
        ``peak_force`` [N] and ``loaded_pins_min`` per angle."""
    def twist_loop(self, rated: float, crank_angle: float, points: int, friction: bool = True) -> dict[str, Any]:
        """Torque-twist loop with rigidity, lost motion and backlash (with the scene's friction
        unless ``friction`` is false)."""
    def compliance_budget(self, torques: list[float], crank_angle: float) -> dict[str, Any]:
        """Compliance budget at ``crank_angle`` [rad] for each torque [N m]: ``parts``,
        ``compliance`` (torques, parts) [rad/(N m)], ``torsional_stiffness`` [N m/rad] and
        ``split_error`` (torques,)."""
    def friction_sweep(self, torque: float, crank_angles: list[float]) -> dict[str, Any]:
        """Running sweep with the scene's friction: TE [rad] and input torque [N m]."""

# ---- vibration analyses (rust/python/modes.rs) ------------------------------------------------

def excitation_orders(scene_json: str, harmonics: int = 3) -> list[tuple[str, int, float, str]]:
    """Excitation orders of a scene as (name, harmonic, order, label), by increasing order."""

def campbell_crossings(
    speeds: list[float],
    frequencies: list[list[float]],
    orders: list[tuple[str, int, float, str]],
) -> list[tuple[float, float, int, int]]:
    """Order-line crossings: (speed [rad/s], frequency [Hz], order index, mode index)."""

def modes(scene_json: str, torque: float, crank_angles: list[float]) -> list[dict[str, Any]]:
    """Modes about the equilibrium at each crank angle [rad] under the output torque [N m]."""

def modes_state(scene_json: str, t: float, q: list[float], v: list[float]) -> dict[str, Any]:
    """Modes about the state (q [rad, m], v [rad/s, m/s]) at time t [s] of a dynamic run."""

def rigid_coordinates(scene_json: str) -> list[int] | None:
    """The rigid model's free coordinates in [carrier, crank, sun, load, motor]; None if compliant."""

def campbell_diagram(
    scene_json: str,
    speeds: list[float],
    torques: list[float],
    crank_angle: float = 0.0,
    harmonics: int = 3,
    frequency_range: tuple[float, float] | None = None,
) -> dict[str, Any]:
    """Natural frequencies over input speeds [rad/s] (torque [N m] per speed) and crossings."""
