//! Helpers shared by the unit tests.

/// `a` and `b` agree to the relative tolerance `rel` of the larger magnitude.
pub(crate) fn close(a: f64, b: f64, rel: f64) -> bool {
    (a - b).abs() <= rel * a.abs().max(b.abs())
}

/// Give `scene` bending crankshafts: bearings 120 mm apart, the discs 40 mm apart between them,
/// the planet overhung at -90 mm, a 45 mm steel shaft (as the LTCA's, modes' and dynamic
/// model's bending tests).
pub(crate) fn with_bending_cranks(scene: &mut crate::dynamics::scene::Scene) {
    scene.crank_layout = Some(crate::bearing::CrankLayout {
        bearings: [-0.06, 0.06],
        discs: vec![-0.02, 0.02],
        planet: -0.09,
        roller_length: None,
    });
    scene.crank_shaft = Some(crate::bearing::CrankShaft {
        diameter: 0.045,
        modulus: crate::bearing::crank_beam::STEEL_MODULUS,
        poisson: crate::bearing::crank_beam::STEEL_POISSON,
        eccentric_mass: None,
    });
}
