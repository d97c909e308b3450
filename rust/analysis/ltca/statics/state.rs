//! What one evaluation found at every contact.

use crate::contact::pin_tangent::GapJet;

/// What one evaluation found at every contact (fixed frame, SI).
#[derive(Debug, Clone, Default)]
pub struct ContactState {
    /// Pin force \[N\] (>= 0) per disc and pin, at `k * pins + j`.
    pub pin_force: Vec<f64>,
    /// Signed gap \[m\] per disc and pin (negative = penetration).
    pub pin_gap: Vec<f64>,
    /// The gap jets (contact point, normal, curvature) per disc and pin.
    pub pin_jet: Vec<GapJet>,
    /// Moment about the reducer axis of the line law's location term on each disc, per disc
    /// and pin [N m] (0 for IMPACT): `O x Q_O + Q_theta` of `Q = -U_phi grad phi`, plus the
    /// same moment of a profile error's share `-F delta' grad phi`.
    pub pin_location_moment: Vec<f64>,
    /// Sum over the bearings of the couple `d x F` of each bearing's force pair [N m]: zero
    /// for an isotropic law (force along the deflection); the roller laws, with their roller
    /// sets fixed in the frame, push slightly off the deflection.
    pub bearing_couple: f64,
    /// Signed mesh force along the line of action per crank \[N\] (positive: drive flank).
    pub mesh_force: Vec<f64>,
    /// Mesh deflection along the line of action per crank \[m\].
    pub mesh_deflection: Vec<f64>,
    /// Crank bearing force on each crank centre \[N\] (compliant crank bearings).
    pub crank_bearing_force: Vec<[f64; 2]>,
    /// Eccentric bearing force on each disc at `i * discs + k` \[N\].
    pub eccentric_bearing_force: Vec<[f64; 2]>,
}
