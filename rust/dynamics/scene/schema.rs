//! The scene schema as a table: every field with its type, unit, default and rule. The table
//! is the source of `docs/scene.md` ([`markdown`]); tests check it against the serde types (every
//! field of every variant is listed, nothing else is, and each stated default is what an
//! omitted field becomes) and against the file.

/// One field of the scene schema.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Field {
    /// Dotted path; `[]` stands for any list index (`discs[].phase`).
    pub path: &'static str,
    /// The variant the field belongs to (`kind = constant`), empty when always present.
    pub when: &'static str,
    /// JSON type: number, integer, string, object, list, ...
    pub ty: &'static str,
    /// SI unit (`-` for none).
    pub unit: &'static str,
    /// The value an omitted field takes, as JSON text; `None` = required.
    pub default: Option<&'static str>,
    /// The rule the value must follow (checked when the scene is built).
    pub rule: &'static str,
    /// What it is.
    pub doc: &'static str,
}

const fn f(
    path: &'static str,
    when: &'static str,
    ty: &'static str,
    unit: &'static str,
    default: Option<&'static str>,
    rule: &'static str,
    doc: &'static str,
) -> Field {
    Field {
        path,
        when,
        ty,
        unit,
        default,
        rule,
        doc,
    }
}

const REQ: Option<&str> = None;
const ZERO: Option<&str> = Some("0.0");
const NULL: Option<&str> = Some("null");

/// Every field of a scene, in document order.
pub static FIELDS: &[Field] = &[
    f(
        "name",
        "",
        "string",
        "-",
        Some("\"\""),
        "",
        "a label for reports",
    ),
    f(
        "stage1",
        "",
        "object or null",
        "-",
        NULL,
        "null = a single-stage cycloid drive driven at the cranks",
        "the involute first stage (sun and planets on the cranks)",
    ),
    f("stage1.z_sun", "", "integer", "-", REQ, ">= 5", "sun teeth"),
    f(
        "stage1.z_planet",
        "",
        "integer",
        "-",
        REQ,
        ">= 5",
        "teeth of each planet",
    ),
    f(
        "stage1.planets",
        "",
        "integer",
        "-",
        REQ,
        "= cranks; planets must not collide",
        "number of planets (equally spaced)",
    ),
    f("stage1.module", "", "number", "m", REQ, "> 0", "module"),
    f(
        "stage1.pressure_angle",
        "",
        "number",
        "rad",
        REQ,
        "in (0, 45) deg",
        "pressure angle",
    ),
    f(
        "stage1.face_width",
        "",
        "number",
        "m",
        REQ,
        "> 0",
        "face width of the mesh",
    ),
    f(
        "stage1.backlash",
        "",
        "number",
        "m",
        ZERO,
        ">= 0",
        "total backlash of one mesh along the line of action",
    ),
    f(
        "cycloid",
        "",
        "object",
        "-",
        REQ,
        "a valid disc: curtate ratio e zp / (rp + d_rp) < 1, no pin overlap, no undercut",
        "cycloid disc geometry and the default profile modifications",
    ),
    f(
        "cycloid.pins",
        "",
        "integer",
        "-",
        REQ,
        ">= 3",
        "number of pins zp (the disc has zp - 1 lobes)",
    ),
    f(
        "cycloid.eccentricity",
        "",
        "number",
        "m",
        REQ,
        "> 0",
        "eccentricity e",
    ),
    f(
        "cycloid.pin_circle_radius",
        "",
        "number",
        "m",
        REQ,
        "> 0",
        "pin circle radius rp",
    ),
    f(
        "cycloid.pin_radius",
        "",
        "number",
        "m",
        REQ,
        "> 0, pins must not overlap",
        "pin radius rrp",
    ),
    f(
        "cycloid.face_width",
        "",
        "number",
        "m",
        REQ,
        "> 0",
        "disc face width",
    ),
    f(
        "cycloid.d_rp",
        "",
        "number",
        "m",
        ZERO,
        "finite; |d_rp| <= rrp (after discs[] overrides)",
        "shift modification (grinding convention: rp -> rp + d_rp)",
    ),
    f(
        "cycloid.d_rrp",
        "",
        "number",
        "m",
        ZERO,
        "finite; |d_rrp| <= rrp (after discs[] overrides)",
        "equidistant modification (rrp -> rrp + d_rrp; positive removes material)",
    ),
    f(
        "cycloid.d_delta",
        "",
        "number",
        "rad",
        ZERO,
        "finite; |d_delta| rp <= rrp (after discs[] overrides)",
        "rotation modification (the profile turned by this angle)",
    ),
    f(
        "discs",
        "",
        "list of objects",
        "-",
        REQ,
        "1 or 2 discs",
        "the discs on the crank eccentrics",
    ),
    f(
        "discs[].phase",
        "",
        "number",
        "rad",
        REQ,
        "finite",
        "phase of this disc's eccentric on the crank (0 and pi for the two-disc RV)",
    ),
    f(
        "discs[].d_rp",
        "",
        "number or null",
        "m",
        NULL,
        "finite; null = cycloid.d_rp",
        "this disc's shift modification",
    ),
    f(
        "discs[].d_rrp",
        "",
        "number or null",
        "m",
        NULL,
        "finite; null = cycloid.d_rrp",
        "this disc's equidistant modification",
    ),
    f(
        "discs[].d_delta",
        "",
        "number or null",
        "rad",
        NULL,
        "finite; null = cycloid.d_delta",
        "this disc's rotation modification",
    ),
    f(
        "discs[].profile_error",
        "",
        "object or null",
        "-",
        NULL,
        "offset bound sum |a| + max |table| < a tenth of the pin radius",
        "profile error: normal offset delta(phi) of the ground profile (positive = material added: gap - delta)",
    ),
    f(
        "discs[].profile_error.harmonics",
        "",
        "list of [a, n, p]",
        "m, -, rad",
        Some("[]"),
        "finite; order n an integer >= 0",
        "harmonics a cos(n phi + p) of the curve parameter phi",
    ),
    f(
        "discs[].profile_error.table",
        "",
        "list of [phi, offset]",
        "rad, m",
        Some("[]"),
        "phi strictly increasing in [0, 2 pi); finite",
        "offset table, linear in between and periodic",
    ),
    f(
        "cranks",
        "",
        "integer",
        "-",
        REQ,
        ">= 1; = stage1.planets",
        "number of crankshafts",
    ),
    f(
        "pin_errors",
        "",
        "object",
        "-",
        Some("{\"position\": [], \"radius\": []}"),
        "",
        "pin manufacturing errors (index j = the paper's pin j+1)",
    ),
    f(
        "pin_errors.position",
        "",
        "list of [dx, dy]",
        "m",
        Some("[]"),
        "empty or one per pin; finite; each at most rrp long; neighbouring pins must not overlap",
        "position error of each pin centre, fixed frame",
    ),
    f(
        "pin_errors.radius",
        "",
        "list of numbers",
        "m",
        Some("[]"),
        "empty or one per pin; finite; neighbouring pins must not overlap",
        "radius error of each pin (positive = larger pin)",
    ),
    f(
        "density",
        "",
        "number",
        "kg/m^3",
        REQ,
        "> 0",
        "material density for the computed inertias",
    ),
    f(
        "inertias",
        "",
        "object",
        "-",
        Some(
            "{\"sun\": null, \"crank\": null, \"disc\": null, \"carrier\": null, \"load_inertia\": 0.0, \"motor_inertia\": 0.0}",
        ),
        "",
        "mass properties of the bodies (null = computed from the geometry)",
    ),
    f(
        "inertias.sun",
        "",
        "object or null",
        "-",
        NULL,
        "",
        "sun gear and input shaft (inertia about the reducer axis)",
    ),
    f("inertias.sun.mass", "", "number", "kg", REQ, "> 0", "mass"),
    f(
        "inertias.sun.inertia",
        "",
        "number",
        "kg m^2",
        REQ,
        "> 0",
        "moment of inertia",
    ),
    f(
        "inertias.crank",
        "",
        "object or null",
        "-",
        NULL,
        "",
        "one crankshaft with its planet and eccentrics (inertia about the crank axis)",
    ),
    f(
        "inertias.crank.mass",
        "",
        "number",
        "kg",
        REQ,
        "> 0",
        "mass",
    ),
    f(
        "inertias.crank.inertia",
        "",
        "number",
        "kg m^2",
        REQ,
        "> 0",
        "moment of inertia",
    ),
    f(
        "inertias.disc",
        "",
        "object or null",
        "-",
        NULL,
        "",
        "one cycloid disc (inertia about its centre)",
    ),
    f("inertias.disc.mass", "", "number", "kg", REQ, "> 0", "mass"),
    f(
        "inertias.disc.inertia",
        "",
        "number",
        "kg m^2",
        REQ,
        "> 0",
        "moment of inertia",
    ),
    f(
        "inertias.carrier",
        "",
        "object or null",
        "-",
        NULL,
        "",
        "carrier (output) with everything bolted to it (inertia about the reducer axis)",
    ),
    f(
        "inertias.carrier.mass",
        "",
        "number",
        "kg",
        REQ,
        "> 0",
        "mass",
    ),
    f(
        "inertias.carrier.inertia",
        "",
        "number",
        "kg m^2",
        REQ,
        "> 0",
        "moment of inertia",
    ),
    f(
        "inertias.load_inertia",
        "",
        "number",
        "kg m^2",
        ZERO,
        ">= 0; > 0 with shafts.output",
        "extra load inertia on the output (on the carrier, or at the end of the output shaft)",
    ),
    f(
        "inertias.motor_inertia",
        "",
        "number",
        "kg m^2",
        ZERO,
        ">= 0; > 0 needs stage1; > 0 with shafts.input and a torque drive",
        "motor inertia on the input (on the sun, or at the end of the drive shaft)",
    ),
    f(
        "joints",
        "",
        "object",
        "-",
        REQ,
        "",
        "the crank-eccentric/disc and crank/carrier bearings",
    ),
    f(
        "joints.kind",
        "",
        "string",
        "-",
        REQ,
        "\"rigid\" or \"compliant\"",
        "ideal joints (the paper) or spring-damper bearings",
    ),
    f(
        "joints.eccentric_bearing",
        "kind = compliant",
        "object",
        "-",
        REQ,
        "",
        "needle bearing between each eccentric and its disc hole",
    ),
    f(
        "joints.eccentric_bearing.stiffness",
        "",
        "number",
        "N/m",
        REQ,
        "> 0 (with rollers >= 0: in parallel)",
        "radial stiffness",
    ),
    f(
        "joints.eccentric_bearing.damping",
        "",
        "number",
        "N s/m",
        REQ,
        ">= 0",
        "radial damping",
    ),
    f(
        "joints.eccentric_bearing.clearance",
        "",
        "number",
        "m",
        ZERO,
        ">= 0; with rollers, at most 1 % of their pitch diameter",
        "radial clearance per side (half the ISO 5753 radial internal clearance)",
    ),
    f(
        "joints.eccentric_bearing.rollers",
        "",
        "object or null",
        "-",
        NULL,
        "null = linear bearing; with rollers, stiffness and damping act in parallel (0 for none)",
        "roller (needle) bearing built from its rollers: Palmgren line contact per roller at both raceways",
    ),
    f(
        "joints.eccentric_bearing.rollers.count",
        "",
        "integer",
        "-",
        REQ,
        ">= 3",
        "number of rollers",
    ),
    f(
        "joints.eccentric_bearing.rollers.length",
        "",
        "number",
        "m",
        REQ,
        "> 0, <= 1 m",
        "effective roller length",
    ),
    f(
        "joints.eccentric_bearing.rollers.diameter",
        "",
        "number",
        "m",
        REQ,
        "> 0, < pitch_diameter, <= 1 m; count x diameter < pi x pitch_diameter",
        "roller diameter (ISO 281 load rating)",
    ),
    f(
        "joints.eccentric_bearing.rollers.pitch_diameter",
        "",
        "number",
        "m",
        REQ,
        "> diameter",
        "pitch diameter of the roller set (load rating, friction)",
    ),
    f(
        "joints.eccentric_bearing.rollers.damping_ratio",
        "",
        "number",
        "-",
        REQ,
        "[0, 1)",
        "stiffness-proportional roller damping: ratio at `frequency`",
    ),
    f(
        "joints.eccentric_bearing.rollers.frequency",
        "",
        "number",
        "Hz",
        REQ,
        "> 0",
        "reference frequency of the damping ratio",
    ),
    f(
        "joints.crank_bearing",
        "kind = compliant",
        "object or null",
        "-",
        NULL,
        "null = rigid crank bearings",
        "bearing between each crankshaft and the carrier",
    ),
    f(
        "joints.crank_bearing.stiffness",
        "",
        "number",
        "N/m",
        REQ,
        "> 0 (with rollers >= 0: in parallel)",
        "radial stiffness",
    ),
    f(
        "joints.crank_bearing.damping",
        "",
        "number",
        "N s/m",
        REQ,
        ">= 0",
        "radial damping",
    ),
    f(
        "joints.crank_bearing.clearance",
        "",
        "number",
        "m",
        ZERO,
        ">= 0; with rollers, at most 1 % of their pitch diameter",
        "radial clearance per side (half the ISO 5753 radial internal clearance)",
    ),
    f(
        "joints.crank_bearing.rollers",
        "",
        "object or null",
        "-",
        NULL,
        "null = linear bearing; with rollers, stiffness and damping act in parallel (0 for none)",
        "roller (needle) bearing built from its rollers: Palmgren line contact per roller at both raceways",
    ),
    f(
        "joints.crank_bearing.rollers.count",
        "",
        "integer",
        "-",
        REQ,
        ">= 3",
        "number of rollers",
    ),
    f(
        "joints.crank_bearing.rollers.length",
        "",
        "number",
        "m",
        REQ,
        "> 0, <= 1 m",
        "effective roller length",
    ),
    f(
        "joints.crank_bearing.rollers.diameter",
        "",
        "number",
        "m",
        REQ,
        "> 0, < pitch_diameter, <= 1 m; count x diameter < pi x pitch_diameter",
        "roller diameter (ISO 281 load rating)",
    ),
    f(
        "joints.crank_bearing.rollers.pitch_diameter",
        "",
        "number",
        "m",
        REQ,
        "> diameter",
        "pitch diameter of the roller set (load rating, friction)",
    ),
    f(
        "joints.crank_bearing.rollers.damping_ratio",
        "",
        "number",
        "-",
        REQ,
        "[0, 1)",
        "stiffness-proportional roller damping: ratio at `frequency`",
    ),
    f(
        "joints.crank_bearing.rollers.frequency",
        "",
        "number",
        "Hz",
        REQ,
        "> 0",
        "reference frequency of the damping ratio",
    ),
    f(
        "contact",
        "",
        "object",
        "-",
        REQ,
        "",
        "contact laws per contact family",
    ),
    f(
        "contact.pin",
        "",
        "object",
        "-",
        REQ,
        "",
        "law of the pin / cycloid profile contacts",
    ),
    f(
        "contact.mesh",
        "",
        "object",
        "-",
        REQ,
        "",
        "law of the sun / planet meshes (along the line of action)",
    ),
    f(
        "contact.*.kind",
        "",
        "string",
        "-",
        REQ,
        "\"impact\", \"palmgren\", \"line\" (pins only) or \"iso6336\" (meshes only)",
        "ADAMS IMPACT law, steel line contact from the face width (Palmgren), line contact from the local profile curvature (Johnson), or ISO 6336-1 mesh stiffness along the line of action",
    ),
    f(
        "contact.*.stiffness",
        "kind = impact",
        "number",
        "N/m^exponent",
        REQ,
        "> 0",
        "IMPACT stiffness k",
    ),
    f(
        "contact.*.exponent",
        "kind = impact",
        "number",
        "-",
        REQ,
        ">= 1",
        "IMPACT force exponent e",
    ),
    f(
        "contact.*.max_damping",
        "",
        "number",
        "N s/m",
        REQ,
        ">= 0",
        "full damping cmax",
    ),
    f(
        "contact.*.damping_depth",
        "",
        "number",
        "m",
        REQ,
        "> 0",
        "penetration at which the full damping acts",
    ),
    f(
        "contact.*.youngs_modulus",
        "kind = line",
        "number",
        "Pa",
        Some("2.17e11"),
        "> 0",
        "Young's modulus of pins and discs",
    ),
    f(
        "contact.*.poisson_ratio",
        "kind = line",
        "number",
        "-",
        Some("0.3"),
        "in (-1, 0.5)",
        "Poisson's ratio of pins and discs",
    ),
    f(
        "contact.*.damping",
        "kind = line",
        "object",
        "-",
        REQ,
        "",
        "damping of the pin contacts",
    ),
    f(
        "contact.*.ramp",
        "kind = iso6336",
        "number",
        "-",
        Some("0.02"),
        ">= 0, at most half the shorter tooth zone",
        "smoothing ramp at the single/double tooth zone boundaries, fraction of a base pitch",
    ),
    f(
        "contact.*.damping",
        "kind = iso6336",
        "object",
        "-",
        REQ,
        "",
        "damping of the meshes",
    ),
    f(
        "contact.*.line_load",
        "kind = iso6336",
        "number or null",
        "N/m",
        NULL,
        "> 0",
        "nominal line load F_t K_A / b of one mesh for the ISO 6336-1 load factor (below 1e5 N/m = 100 N/mm, c' times (w / 1e5 N/m)^(1/4)); null = from the scene's load: the largest output torque magnitude over the ratio, shared by the planets at the sun's reference radius, K_A = 1 (idle: factor 1)",
    ),
    f(
        "contact.*.damping.kind",
        "",
        "string",
        "-",
        REQ,
        "\"restitution\" or \"damping_ratio\"",
        "restitution-based (Hunt-Crossley family) or stiffness-proportional damping",
    ),
    f(
        "contact.*.damping.model",
        "kind = restitution",
        "string",
        "-",
        REQ,
        "\"exact\", \"hunt-crossley\", \"lankarani-nikravesh\" or \"flores\"",
        "hysteresis factor from the coefficient of restitution",
    ),
    f(
        "contact.*.damping.restitution",
        "kind = restitution",
        "number",
        "-",
        REQ,
        "in (0, 1]",
        "coefficient of restitution at the reference speed",
    ),
    f(
        "contact.*.damping.reference_speed",
        "kind = restitution",
        "number",
        "m/s",
        REQ,
        "> 0",
        "impact speed at which the restitution holds",
    ),
    f(
        "contact.*.damping.ratio",
        "kind = damping_ratio",
        "number",
        "-",
        REQ,
        "in [0, 1)",
        "damping ratio of a linearised mode at `frequency`",
    ),
    f(
        "contact.*.damping.frequency",
        "kind = damping_ratio",
        "number",
        "Hz",
        REQ,
        "> 0",
        "reference frequency of the damping ratio",
    ),
    f(
        "friction",
        "",
        "object",
        "-",
        Some(
            "{\"pin\": 0.0, \"pin_rolling\": null, \"mesh\": 0.0, \"regularisation_speed\": 0.001, \"bearing\": null}",
        ),
        "",
        "friction (default: none, the paper)",
    ),
    f(
        "friction.pin",
        "",
        "number",
        "-",
        ZERO,
        "in [0, 1]",
        "Coulomb coefficient at the pin/disc contacts",
    ),
    f(
        "friction.pin_rolling",
        "",
        "number or null",
        "-",
        NULL,
        "in (0, 1]",
        "pins roll in the housing: sliding at this fraction of the pin radius (null = fixed pins)",
    ),
    f(
        "friction.mesh",
        "",
        "number",
        "-",
        ZERO,
        "in [0, 1]; > 0 needs stage1",
        "Coulomb coefficient at the sun/planet teeth",
    ),
    f(
        "friction.regularisation_speed",
        "",
        "number",
        "m/s",
        Some("0.001"),
        "> 0",
        "speed of the tanh regularisation of Coulomb friction",
    ),
    f(
        "friction.bearing",
        "",
        "object or null",
        "-",
        NULL,
        "compliant joints only (rigid joints: an error); rigid crank bearings have none",
        "Palmgren friction torque M0 + M1 of the compliant joint bearings",
    ),
    f(
        "friction.bearing.f0",
        "",
        "number",
        "-",
        REQ,
        ">= 0",
        "Palmgren load-independent factor",
    ),
    f(
        "friction.bearing.f1",
        "",
        "number",
        "-",
        REQ,
        ">= 0, <= 0.01",
        "Palmgren load factor",
    ),
    f(
        "friction.bearing.viscosity",
        "",
        "number",
        "m^2/s",
        REQ,
        ">= 0",
        "oil kinematic viscosity",
    ),
    f(
        "errors",
        "",
        "object",
        "-",
        Some(
            "{\"crank_eccentricity\": [], \"crank_phase\": [], \"disc_holes\": [], \"carrier_seats\": []}",
        ),
        "compliant joints only",
        "manufacturing and assembly errors of cranks, discs and carrier",
    ),
    f(
        "errors.crank_eccentricity",
        "",
        "list of numbers",
        "m",
        Some("[]"),
        "empty or one per crank, |de| < e",
        "eccentricity error of each crank",
    ),
    f(
        "errors.crank_phase",
        "",
        "list of numbers",
        "rad",
        Some("[]"),
        "empty or one per crank",
        "phase error of each crank's eccentrics",
    ),
    f(
        "errors.disc_holes",
        "",
        "list of [dx, dy]",
        "m",
        Some("[]"),
        "empty or one per crank and disc (crank * discs + disc)",
        "crank hole position errors in the discs (disc frame)",
    ),
    f(
        "errors.carrier_seats",
        "",
        "list of [dx, dy]",
        "m",
        Some("[]"),
        "empty or one per crank",
        "crank seat position errors in the carrier (carrier frame)",
    ),
    f(
        "gear_errors",
        "",
        "object",
        "-",
        Some(
            "{\"sun\": {\"runout\": 0.0, \"runout_phase\": 0.0, \"pitch_amplitude\": 0.0, \"pitch_phase\": 0.0, \"pitch_deviation\": []}, \"planets\": []}",
        ),
        "needs stage1 when any error is set",
        "runout and pitch errors of the first-stage gears (an extra approach of each mesh flank)",
    ),
    f(
        "gear_errors.sun",
        "",
        "object",
        "-",
        Some(
            "{\"runout\": 0.0, \"runout_phase\": 0.0, \"pitch_amplitude\": 0.0, \"pitch_phase\": 0.0, \"pitch_deviation\": []}",
        ),
        "",
        "errors of the sun",
    ),
    f(
        "gear_errors.sun.runout",
        "",
        "number",
        "m",
        ZERO,
        "[0, module / 10)",
        "eccentricity of the toothing on the gear axis",
    ),
    f(
        "gear_errors.sun.runout_phase",
        "",
        "number",
        "rad",
        ZERO,
        "finite",
        "direction of the runout in the gear's body frame",
    ),
    f(
        "gear_errors.sun.pitch_amplitude",
        "",
        "number",
        "m",
        ZERO,
        "|A| < module / 10",
        "sinusoidal cumulative pitch deviation A sin(psi + pitch_phase) on the reference circle (rotation order)",
    ),
    f(
        "gear_errors.sun.pitch_phase",
        "",
        "number",
        "rad",
        ZERO,
        "finite",
        "phase of the sinusoidal pitch deviation",
    ),
    f(
        "gear_errors.sun.pitch_deviation",
        "",
        "list of numbers",
        "m",
        Some("[]"),
        "empty or one per tooth; each |F| < module / 10",
        "cumulative pitch deviation of each tooth on the reference circle (tooth k at 2 pi k / z, linear in between, periodic; positive = ahead)",
    ),
    f(
        "gear_errors.planets",
        "",
        "list of objects",
        "-",
        Some("[]"),
        "empty or one per planet",
        "errors of each planet (the fields of gear_errors.sun)",
    ),
    f(
        "gear_errors.planets[].runout",
        "",
        "number",
        "m",
        ZERO,
        "[0, module / 10)",
        "eccentricity of the toothing on the gear axis",
    ),
    f(
        "gear_errors.planets[].runout_phase",
        "",
        "number",
        "rad",
        ZERO,
        "finite",
        "direction of the runout in the gear's body frame",
    ),
    f(
        "gear_errors.planets[].pitch_amplitude",
        "",
        "number",
        "m",
        ZERO,
        "|A| < module / 10",
        "sinusoidal cumulative pitch deviation A sin(psi + pitch_phase) on the reference circle (rotation order)",
    ),
    f(
        "gear_errors.planets[].pitch_phase",
        "",
        "number",
        "rad",
        ZERO,
        "finite",
        "phase of the sinusoidal pitch deviation",
    ),
    f(
        "gear_errors.planets[].pitch_deviation",
        "",
        "list of numbers",
        "m",
        Some("[]"),
        "empty or one per tooth; each |F| < module / 10",
        "cumulative pitch deviation of each tooth on the reference circle (tooth k at 2 pi k / z, linear in between, periodic; positive = ahead)",
    ),
    f(
        "crank_layout",
        "",
        "object or null",
        "-",
        NULL,
        "",
        "axial layout of each crankshaft (null = the lumped crank bearing row only); the analyses split the lumped row into the two bearings with it (docs/model.md, Crank bearing rows)",
    ),
    f(
        "crank_layout.bearings",
        "",
        "list of 2 numbers",
        "m",
        REQ,
        "finite, apart by more than 1e-9 of the layout's extent",
        "mid-planes of the two crank bearings (a and b), along the crank axis (any origin, one direction)",
    ),
    f(
        "crank_layout.discs",
        "",
        "list of numbers",
        "m",
        REQ,
        "finite; one per disc, in their order",
        "mid-planes of the discs (their eccentrics)",
    ),
    f(
        "crank_layout.planet",
        "",
        "number",
        "m",
        REQ,
        "finite",
        "mid-plane of the planet, where the mesh force acts",
    ),
    f(
        "crank_layout.roller_length",
        "",
        "number or null",
        "m",
        NULL,
        "(0, 1]",
        "roller length of each of the two bearings, for their ISO 76/281 ratings (null = half the lumped crank roller length)",
    ),
    f(
        "crank_shaft",
        "",
        "object or null",
        "-",
        NULL,
        "needs crank_layout and compliant joints",
        "the crankshafts' round section, for their bending between the bearings (null = rigid cranks): in the quasi-static analyses, the modes and the dynamic model; docs/model.md, Crankshaft bending",
    ),
    f(
        "crank_shaft.diameter",
        "",
        "number",
        "m",
        REQ,
        "(0, 1]; no disc at a bearing's plane",
        "diameter of the solid shaft between the bearings",
    ),
    f(
        "crank_shaft.modulus",
        "",
        "number",
        "Pa",
        Some("2.06e11"),
        "[1e9, 1e12]",
        "Young's modulus of the shaft (steel)",
    ),
    f(
        "crank_shaft.poisson",
        "",
        "number",
        "-",
        Some("0.3"),
        "[0, 0.5)",
        "Poisson's ratio of the shaft (steel), for its shear modulus",
    ),
    f(
        "crank_shaft.eccentric_mass",
        "",
        "number or null",
        "kg",
        NULL,
        "> 0, below the crank's mass per disc",
        "mass moving with each eccentric's centre in the dynamic model, taken from the crank's (null = the shaft's section over the disc width; the quasi-static analyses and the modes take the eccentrics as massless)",
    ),
    f(
        "shafts",
        "",
        "object",
        "-",
        Some("{\"output\": null, \"input\": null}"),
        "",
        "shafts between the reducer and its machine (null = rigid connection)",
    ),
    f(
        "shafts.output",
        "",
        "object or null",
        "-",
        NULL,
        "needs inertias.load_inertia > 0",
        "output shaft between the carrier and the load inertia; the load torque acts on the load",
    ),
    f(
        "shafts.output.stiffness",
        "",
        "number",
        "N m/rad",
        REQ,
        "> 0",
        "torsional stiffness",
    ),
    f(
        "shafts.output.damping",
        "",
        "number",
        "N m s/rad",
        ZERO,
        ">= 0",
        "torsional damping",
    ),
    f(
        "shafts.input",
        "",
        "object or null",
        "-",
        NULL,
        "needs stage1",
        "drive shaft (coupling) between the motor and the sun; the drive acts on the motor",
    ),
    f(
        "shafts.input.stiffness",
        "",
        "number",
        "N m/rad",
        REQ,
        "> 0",
        "torsional stiffness",
    ),
    f(
        "shafts.input.damping",
        "",
        "number",
        "N m s/rad",
        ZERO,
        ">= 0",
        "torsional damping",
    ),
    f(
        "drive",
        "",
        "object",
        "-",
        REQ,
        "",
        "the drive on the input (sun, or the cranks without a first stage)",
    ),
    f(
        "drive.kind",
        "",
        "string",
        "-",
        REQ,
        "\"speed\" or \"torque\"",
        "prescribed input speed, or prescribed input torque (the input is then free)",
    ),
    f(
        "drive.speed",
        "kind = speed",
        "number",
        "rad/s",
        REQ,
        "finite",
        "input speed",
    ),
    f(
        "drive.start",
        "kind = speed",
        "string",
        "-",
        REQ,
        "\"step\" or \"ramp\"",
        "full speed from t = 0, or a smooth cubic ramp",
    ),
    f(
        "drive.ramp_time",
        "kind = speed",
        "number",
        "s",
        ZERO,
        "> 0 for a ramp start",
        "ramp duration",
    ),
    f(
        "drive.torque",
        "kind = torque",
        "number",
        "N m",
        REQ,
        "finite",
        "input torque",
    ),
    f(
        "drive.ramp_time",
        "kind = torque",
        "number",
        "s",
        ZERO,
        ">= 0",
        "ramp duration of the torque",
    ),
    f(
        "load",
        "",
        "object",
        "-",
        REQ,
        "",
        "load torque on the carrier (against positive output rotation)",
    ),
    f(
        "load.kind",
        "",
        "string",
        "-",
        REQ,
        "\"idle\", \"constant\", \"step\" or \"table\"",
        "the load law",
    ),
    f(
        "load.torque",
        "kind = constant",
        "number",
        "N m",
        REQ,
        "finite",
        "constant torque from t = 0",
    ),
    f(
        "load.before",
        "kind = step",
        "number",
        "N m",
        REQ,
        "finite",
        "torque before the step",
    ),
    f(
        "load.after",
        "kind = step",
        "number",
        "N m",
        REQ,
        "finite",
        "torque after the step",
    ),
    f(
        "load.time",
        "kind = step",
        "number",
        "s",
        REQ,
        "finite",
        "time of the step",
    ),
    f(
        "load.points",
        "kind = table",
        "list of [t, torque]",
        "s, N m",
        REQ,
        "at least one; times strictly increasing; finite",
        "piecewise-linear table, held constant outside",
    ),
    f(
        "initial",
        "",
        "string",
        "-",
        REQ,
        "\"rest\" or \"steady\" (steady needs a speed drive with a step start)",
        "everything at rest in the kinematic pose, or every body at its kinematic speed",
    ),
];

/// Whether the JSON value `v` is of the table's type `ty` (a type the check does not know
/// passes: serde then has the last word).
fn has_type(v: &serde_json::Value, ty: &str) -> bool {
    use serde_json::Value;
    if let Some(base) = ty.strip_suffix(" or null") {
        return v.is_null() || has_type(v, base);
    }
    let numbers = |v: &Value, n: Option<usize>| {
        v.as_array()
            .is_some_and(|a| n.is_none_or(|n| a.len() == n) && a.iter().all(Value::is_number))
    };
    match ty {
        "number" => v.is_number(),
        "integer" => v.is_u64() || v.is_i64(),
        "string" => v.is_string(),
        "object" => v.is_object(),
        "list of objects" => v.as_array().is_some_and(|a| a.iter().all(Value::is_object)),
        "list of numbers" => numbers(v, None),
        "list of 2 numbers" => numbers(v, Some(2)),
        t if t.starts_with("list of [") => {
            let n = t.matches(',').count() + 1;
            v.as_array()
                .is_some_and(|a| a.iter().all(|p| numbers(p, Some(n))))
        }
        _ => true,
    }
}

/// `ty` after "a" or "an" ("an integer", "a list of numbers").
fn with_article(ty: &str) -> String {
    let an = ty.starts_with(['a', 'e', 'i', 'o', 'u']);
    format!("{} {ty}", if an { "an" } else { "a" })
}

/// The first field of the scene tree `tree` whose value is not of the type the table gives
/// it, as a message naming its path, the type and unit expected and the value found; `None`
/// if every listed field has its type. serde's own message names no path inside an
/// internally tagged object (`joints`, `load`, the contact laws), this one does.
pub fn mistyped(tree: &serde_json::Value) -> Option<String> {
    use serde_json::Value;
    fn walk(v: &Value, at: &str, table: &str) -> Option<String> {
        let Value::Object(m) = v else { return None };
        for (k, child) in m {
            let (at, table) = if at.is_empty() {
                (k.clone(), k.clone())
            } else {
                (format!("{at}.{k}"), format!("{table}.{k}"))
            };
            let table = match table.strip_prefix("contact.") {
                Some(rest) if at.split('.').count() > 2 => {
                    format!("contact.*.{}", rest.split_once('.').map_or("", |p| p.1))
                }
                _ => table,
            };
            let rows: Vec<&Field> = FIELDS.iter().filter(|f| f.path == table).collect();
            if let Some(row) = rows.first()
                && !rows.iter().any(|f| has_type(child, f.ty))
            {
                let unit = if row.unit == "-" {
                    String::new()
                } else {
                    format!(" [{}]", row.unit)
                };
                let mut got = child.to_string();
                if got.chars().count() > 60 {
                    got = format!("{}...", got.chars().take(57).collect::<String>());
                }
                return Some(format!(
                    "{at} must be {}{unit}, got {got}",
                    with_article(row.ty)
                ));
            }
            let found = match child {
                Value::Object(_) => walk(child, &at, &table),
                Value::Array(items) => items
                    .iter()
                    .enumerate()
                    .find_map(|(i, item)| walk(item, &format!("{at}[{i}]"), &format!("{table}[]"))),
                _ => None,
            };
            if found.is_some() {
                return found;
            }
        }
        None
    }
    walk(tree, "", "")
}

/// The table as the Markdown of `docs/scene.md`.
pub fn markdown() -> String {
    let mut s = String::from(
        "# Scene fields\n\n\
         Generated from `rust/dynamics/scene/schema.rs` (the test \
         `scene_table_matches_docs` fails when this file and the code disagree; regenerate \
         with `cargo test scene_table -- --ignored`).\n\n\
         A scene is a JSON or TOML document (`rvdyn.Scene`); every value is SI. A field \
         marked *required* must be given; an omitted optional field takes its default. \
         Paths are dotted, `[]` stands for a list index, `contact.*` for `contact.pin` and \
         `contact.mesh`; \"when\" names the variant (`kind`) a field belongs to. A field that \
         is not in this table is an error. The default scene (`Scene.paper`) and where each \
         of its values comes from are in [model.md](model.md#default-scene).\n\n\
         | field | when | type | unit | default | rule | meaning |\n\
         |---|---|---|---|---|---|---|\n",
    );
    for x in FIELDS {
        let default = x
            .default
            .map_or("*required*".to_string(), |d| format!("`{d}`"));
        let when = if x.when.is_empty() { "" } else { x.when };
        s.push_str(&format!(
            "| `{}` | {} | {} | {} | {} | {} | {} |\n",
            x.path, when, x.ty, x.unit, default, x.rule, x.doc
        ));
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::dynamics::scene::Scene;
    use serde_json::{Value, json};
    use std::collections::BTreeSet;

    /// Scenes that together use every variant and every optional object.
    fn examples() -> Vec<Value> {
        let base = Scene::paper("rated").unwrap().to_value().unwrap();
        let mut out = vec![base.clone()];
        let mut v = base.clone();
        v["stage1"] = Value::Null;
        v["joints"] = json!({"kind": "compliant",
            "eccentric_bearing": {"stiffness": 1e9, "damping": 1e4, "clearance": 0.0},
            "crank_bearing": {"stiffness": 2e9, "damping": 1e4, "clearance": 0.0}});
        v["contact"]["pin"] =
            json!({"kind": "palmgren", "max_damping": 1e5, "damping_depth": 1e-5});
        v["drive"] = json!({"kind": "torque", "torque": 10.0, "ramp_time": 0.0});
        v["load"] = json!({"kind": "step", "before": 0.0, "after": 1.0, "time": 0.1});
        v["inertias"] = json!({"sun": {"mass": 1.0, "inertia": 1.0}, "crank": {"mass": 1.0, "inertia": 1.0},
            "disc": {"mass": 1.0, "inertia": 1.0}, "carrier": {"mass": 1.0, "inertia": 1.0},
            "load_inertia": 0.0});
        v["discs"][0]["d_rp"] = json!(0.0);
        out.push(v);
        let mut v = base.clone();
        v["load"] = json!({"kind": "table", "points": [[0.0, 0.0], [1.0, 1.0]]});
        out.push(v);
        let mut v = base.clone();
        v["load"] = json!({"kind": "idle"});
        out.push(v);
        // The physical preset: line pins, ISO meshes, damping ratios, roller bearings.
        let mut v = Scene::physical("rated").unwrap().to_value().unwrap();
        // The paper's step start (a ramp needs its ramp_time, which a test removes).
        v["drive"] = base["drive"].clone();
        v["friction"] = json!({"pin": 0.05, "pin_rolling": 0.5, "mesh": 0.05,
            "regularisation_speed": 0.001, "bearing": {"f0": 3.0, "f1": 3e-4, "viscosity": 6.8e-5}});
        v["errors"] = json!({"crank_eccentricity": [1e-6, 0.0, 0.0], "crank_phase": [0.0, 1e-5, 0.0],
            "disc_holes": [[1e-6, 0.0], [0.0, 0.0], [0.0, 0.0], [0.0, 0.0], [0.0, 0.0], [0.0, 0.0]],
            "carrier_seats": [[0.0, 1e-6], [0.0, 0.0], [0.0, 0.0]]});
        // Rollers with a parallel linear spring-damper (so that the scene stays valid when
        // a test removes `rollers`).
        v["joints"]["eccentric_bearing"]["stiffness"] = json!(1e8);
        v["joints"]["eccentric_bearing"]["damping"] = json!(1e3);
        v["joints"]["crank_bearing"]["stiffness"] = json!(1e8);
        v["joints"]["crank_bearing"]["damping"] = json!(1e3);
        v["crank_layout"] = json!({"bearings": [-0.06, 0.06], "discs": [-0.02, 0.02],
            "planet": -0.09, "roller_length": 0.02});
        v["crank_shaft"] =
            json!({"diameter": 0.045, "modulus": 2.06e11, "poisson": 0.3, "eccentric_mass": 0.3});
        out.push(v.clone());
        v["contact"]["pin"]["damping"] = json!({"kind": "restitution", "model": "exact",
            "restitution": 0.8, "reference_speed": 0.1});
        out.push(v);
        // Machine shafts, profile and gear errors.
        let mut v = base.clone();
        v["inertias"]["load_inertia"] = json!(2.0);
        v["inertias"]["motor_inertia"] = json!(0.01);
        v["shafts"] = json!({"output": {"stiffness": 1e6, "damping": 10.0},
            "input": {"stiffness": 1e4, "damping": 0.1}});
        v["discs"][0]["profile_error"] = json!({"harmonics": [[1e-6, 23.0, 0.5]],
            "table": [[0.0, 1e-6], [3.0, -1e-6]]});
        let g = json!({"runout": 1e-5, "runout_phase": 0.3, "pitch_amplitude": 5e-6,
            "pitch_phase": 0.1, "pitch_deviation": []});
        let mut sun = g.clone();
        sun["pitch_deviation"] = json!(vec![1e-6; 18]);
        v["gear_errors"] = json!({"sun": sun, "planets": [g.clone(), g.clone(), g]});
        out.push(v);
        out
    }

    /// (path, when) of every node of a scene tree, in the table's notation.
    fn nodes(v: &Value, prefix: &str, out: &mut BTreeSet<(String, String)>) {
        let Value::Object(m) = v else { return };
        let kind = m.get("kind").and_then(Value::as_str);
        for (k, child) in m {
            let path = if prefix.is_empty() {
                k.clone()
            } else {
                format!("{prefix}.{k}")
            };
            let path = path
                .replace("contact.pin.", "contact.*.")
                .replace("contact.mesh.", "contact.*.");
            // Direct children of a tagged object belong to its variant.
            let when = match kind {
                Some(kind) if k != "kind" => format!("kind = {kind}"),
                _ => String::new(),
            };
            out.insert((path.clone(), when));
            match child {
                Value::Array(items) if items.iter().all(Value::is_object) => {
                    for item in items {
                        nodes(item, &format!("{path}[]"), out);
                    }
                }
                _ => nodes(child, &path, out),
            }
        }
    }

    /// The table's (path, when) pairs.
    fn table_keys() -> BTreeSet<(String, String)> {
        FIELDS
            .iter()
            .map(|x| (x.path.to_string(), x.when.to_string()))
            .collect()
    }

    #[test]
    fn every_field_is_in_the_table_and_nothing_else() {
        let mut found = BTreeSet::new();
        for e in examples() {
            Scene::from_value(&e).expect("example scenes are valid");
            nodes(&e, "", &mut found);
        }
        // Damping fields are common to both contact laws: listed once, without a variant.
        let found: BTreeSet<(String, String)> = found
            .into_iter()
            .map(|(p, w)| {
                if p.ends_with("max_damping") || p.ends_with("damping_depth") {
                    (p, String::new())
                } else {
                    (p, w)
                }
            })
            .collect();
        let table = table_keys();
        let missing: Vec<_> = found.difference(&table).collect();
        let extra: Vec<_> = table.difference(&found).collect();
        assert!(missing.is_empty(), "fields not in the table: {missing:?}");
        assert!(extra.is_empty(), "table rows that are no field: {extra:?}");
    }

    /// Remove the field at `path` (table notation, `[]` = index 0) from a tree.
    fn remove(tree: &mut Value, path: &str) -> bool {
        let path = path.replace("[]", ".0");
        let keys: Vec<&str> = path.split('.').collect();
        let (last, parents) = keys.split_last().unwrap();
        let mut node = tree;
        for k in parents {
            node = match node {
                Value::Object(m) => match m.get_mut(*k) {
                    Some(n) => n,
                    None => return false,
                },
                Value::Array(a) => match a.get_mut(k.parse::<usize>().unwrap()) {
                    Some(n) => n,
                    None => return false,
                },
                _ => return false,
            };
        }
        node.as_object_mut()
            .is_some_and(|m| m.remove(*last).is_some())
    }

    #[test]
    fn stated_defaults_are_what_omitted_fields_become() {
        let mut checked = 0;
        for x in FIELDS {
            for example in examples() {
                for concrete in [x.path.replace("contact.*", "contact.pin")] {
                    let mut tree = example.clone();
                    if x.when.is_empty() || {
                        let parent = concrete.rsplit_once('.').map_or("", |p| p.0);
                        let kind =
                            crate::dynamics::scene::get_path(&tree, &format!("{parent}.kind"))
                                .ok()
                                .and_then(Value::as_str)
                                .map(|k| format!("kind = {k}"));
                        kind.as_deref() == Some(x.when)
                    } {
                        if !remove(&mut tree, &concrete) {
                            continue;
                        }
                        let built = Scene::from_value(&tree);
                        // An omission that another field's rule rejects (a shaft needs a load
                        // inertia) is reported naming the omitted field.
                        if x.default.is_some()
                            && let Err(e) = &built
                            && e.to_string().contains(x.path)
                        {
                            checked += 1;
                            continue;
                        }
                        match x.default {
                            None => assert!(built.is_err(), "{} is required", x.path),
                            Some(d) => {
                                let back = built
                                    .unwrap_or_else(|e| panic!("{} omitted: {e}", x.path))
                                    .to_value()
                                    .unwrap();
                                let got = crate::dynamics::scene::get_path(
                                    &back,
                                    &concrete.replace("[]", ".0"),
                                )
                                .unwrap();
                                let want: Value = serde_json::from_str(d).unwrap();
                                assert_eq!(got, &want, "default of {}", x.path);
                            }
                        }
                        checked += 1;
                    }
                }
            }
        }
        assert!(checked >= FIELDS.len(), "only {checked} checks");
    }

    /// Every field of the example scenes has its table type, and a value of another type at
    /// any field makes the scene an error naming that field's path (inside tagged objects too,
    /// where serde's own message stops at the object).
    #[test]
    fn a_mistyped_field_is_named_by_its_path() {
        let mut checked = 0;
        for example in examples() {
            assert_eq!(mistyped(&example), None);
            for x in FIELDS {
                let concrete = x
                    .path
                    .replace("contact.*", "contact.pin")
                    .replace("[]", ".0");
                let mut tree = example.clone();
                let Ok(node) = crate::dynamics::scene::get_path(&tree, &concrete) else {
                    continue;
                };
                if !x.when.is_empty() && node.is_null() {
                    continue;
                }
                let wrong = if x.ty.contains("string") {
                    json!(1.5)
                } else {
                    json!("x")
                };
                let named = concrete.replace(".0.", "[0].").replace(".0", "[0]");
                let (parent, key) = concrete.rsplit_once('.').unwrap_or(("", &concrete));
                let holder = if parent.is_empty() {
                    &mut tree
                } else {
                    let mut node = &mut tree;
                    for k in parent.split('.') {
                        node = match node {
                            Value::Array(a) => &mut a[k.parse::<usize>().unwrap()],
                            other => &mut other[k],
                        };
                    }
                    node
                };
                holder[key] = wrong;
                let err = Scene::from_value(&tree).unwrap_err().to_string();
                assert!(
                    err.contains(&format!("{named} must be {}", with_article(x.ty)))
                        || err.contains(&format!("invalid scene: {named}: ")),
                    "{}: {err}",
                    x.path
                );
                checked += 1;
            }
        }
        assert!(checked >= FIELDS.len(), "only {checked} checks");
    }

    #[test]
    fn scene_table_matches_docs() {
        let path = concat!(env!("CARGO_MANIFEST_DIR"), "/docs/scene.md");
        let text = std::fs::read_to_string(path).unwrap_or_default();
        assert!(
            text == markdown(),
            "docs/scene.md differs from the schema table: run `cargo test scene_table -- --ignored`"
        );
    }

    #[test]
    #[ignore = "writes docs/scene.md"]
    fn scene_table_write_docs() {
        let path = concat!(env!("CARGO_MANIFEST_DIR"), "/docs/scene.md");
        std::fs::create_dir_all(concat!(env!("CARGO_MANIFEST_DIR"), "/docs")).unwrap();
        std::fs::write(path, markdown()).unwrap();
    }
}
