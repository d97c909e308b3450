//! Where a force evaluation reports each contact: nowhere on the hot path, into a sample when
//! recording. Generic, so the hot path pays nothing for it.

/// Receives every contact of one force evaluation.
pub trait ContactSink {
    /// Whether the elastic energy of the contacts is wanted (costs a power per contact).
    fn wants_energy(&self) -> bool {
        false
    }
    /// Whether contact forces are wanted at all: a recorder of motion only says no, and the
    /// model then skips the force evaluation when it observes a state.
    fn wants_forces(&self) -> bool {
        true
    }
    /// Whether a penetration beyond the physical bound is an error. The integrator's
    /// evaluations say yes (it detects instability); a recorder observing an interpolated state
    /// between two accepted steps says no.
    fn checks_bounds(&self) -> bool {
        true
    }
    /// Whether the bearing forces are wanted: a model that computes them only for the
    /// report (the rigid model's reactions) skips them when not.
    fn wants_bearings(&self) -> bool {
        true
    }
    /// Pin `j` on disc `k`: normal force \[N\], penetration \[m\], moment of the pin force about
    /// the disc centre [N m], contact point and unit outward profile normal (fixed frame).
    #[allow(clippy::too_many_arguments)]
    fn pin(
        &mut self,
        _k: usize,
        _j: usize,
        _force: f64,
        _pen: f64,
        _moment: f64,
        _point: [f64; 2],
        _normal: [f64; 2],
    ) {
    }
    /// Mesh `i`: force along the line of action \[N\] (negative on the coast flank), deflection \[m\].
    fn mesh(&mut self, _i: usize, _force: f64, _deflection: f64) {}
    /// Bearing force \[N\] (fixed frame): `family` 0 = crank bearing `index` (force on the crank
    /// centre), 1 = eccentric bearing `index = crank * discs + disc` (force on the disc).
    fn bearing(&mut self, _family: usize, _index: usize, _force: [f64; 2]) {}
    /// Deflection \[m\] (fixed frame) of a bending crank's eccentric from the crank's line,
    /// `index = crank * discs + disc`.
    fn crank_deflection(&mut self, _index: usize, _deflection: [f64; 2]) {}
}

/// The sink of the hot path: ignores everything.
pub struct NoSink;
impl ContactSink for NoSink {}

/// A sink for the mechanical energy only (an integrator's check of the energy balance).
pub struct EnergySink;
impl ContactSink for EnergySink {
    fn wants_energy(&self) -> bool {
        true
    }
    fn wants_bearings(&self) -> bool {
        false
    }
}

/// Lets a generic force routine report into a dynamic sink (the recorder's) when observing.
pub(crate) struct DynSink<'a>(pub &'a mut dyn ContactSink);

impl ContactSink for DynSink<'_> {
    fn wants_energy(&self) -> bool {
        self.0.wants_energy()
    }
    fn wants_forces(&self) -> bool {
        self.0.wants_forces()
    }
    fn checks_bounds(&self) -> bool {
        self.0.checks_bounds()
    }
    fn wants_bearings(&self) -> bool {
        self.0.wants_bearings()
    }
    fn pin(
        &mut self,
        k: usize,
        j: usize,
        force: f64,
        pen: f64,
        moment: f64,
        point: [f64; 2],
        normal: [f64; 2],
    ) {
        self.0.pin(k, j, force, pen, moment, point, normal);
    }
    fn mesh(&mut self, i: usize, force: f64, deflection: f64) {
        self.0.mesh(i, force, deflection);
    }
    fn bearing(&mut self, family: usize, index: usize, force: [f64; 2]) {
        self.0.bearing(family, index, force);
    }
    fn crank_deflection(&mut self, index: usize, deflection: [f64; 2]) {
        self.0.crank_deflection(index, deflection);
    }
}
