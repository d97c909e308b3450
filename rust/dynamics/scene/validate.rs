//! The rules a scene must follow as a whole (docs/scene.md lists them per field); each error
//! names the field and how to fix it.

use super::*;

impl Scene {
    /// Neighbouring pins, each at its place with its position and radius errors (pin `j` at
    /// `rp (cos, sin)(2 pi j / zp)`, as the models place them), must not overlap.
    fn check_pins_apart(&self) -> Result<()> {
        let zp = self.cycloid.pins as usize;
        let pe = &self.pin_errors;
        let pin = |j: usize| {
            let th = std::f64::consts::TAU * j as f64 / zp as f64;
            let dp = pe.position.get(j).copied().unwrap_or([0.0, 0.0]);
            let r = self.cycloid.pin_radius + pe.radius.get(j).copied().unwrap_or(0.0);
            let rp = self.cycloid.pin_circle_radius;
            ([rp * th.cos() + dp[0], rp * th.sin() + dp[1]], r)
        };
        for (j, dp) in pe.position.iter().enumerate() {
            let size = dp[0].hypot(dp[1]);
            if size > self.cycloid.pin_radius {
                return Err(RvdynError::Scene(format!(
                    "pin_errors.position[{j}] moves pin {} by {size:.6e} m, more than the pin \
                     radius {} m: pin errors are micrometres (m)",
                    j + 1,
                    self.cycloid.pin_radius
                )));
            }
        }
        for j in 0..zp {
            let (a, ra) = pin(j);
            let (b, rb) = pin((j + 1) % zp);
            let d = (a[0] - b[0]).hypot(a[1] - b[1]);
            if d <= ra + rb {
                return Err(RvdynError::Scene(format!(
                    "pin_errors: pins {} and {} overlap (centres {d:.6e} m apart, radii {ra:.6e} \
                     and {rb:.6e} m): pin errors are micrometres (position and radius, m)",
                    j + 1,
                    (j + 1) % zp + 1
                )));
            }
        }
        Ok(())
    }

    /// Check the scene as a whole; errors say which field is wrong and how to fix it.
    pub fn validate(&self) -> Result<()> {
        let err = |m: String| Err(RvdynError::Scene(m));
        if self.discs.is_empty() || self.discs.len() > 2 {
            return err(format!(
                "a scene needs 1 or 2 discs, got {}",
                self.discs.len()
            ));
        }
        for (k, d) in self.discs.iter().enumerate() {
            for (n, v) in [
                ("phase", Some(d.phase)),
                ("d_rp", d.d_rp),
                ("d_rrp", d.d_rrp),
                ("d_delta", d.d_delta),
            ] {
                if let Some(v) = v
                    && !v.is_finite()
                {
                    return err(format!("discs[{k}].{n} must be finite, got {v}"));
                }
            }
            // Modifications are tens of micrometres; one as large as the pin itself (a metre
            // typed for a millimetre) leaves no reducer to analyse. The rotation counts by the
            // arc it moves the profile at the pin circle.
            let p = self.disc_params(k);
            let rrp = self.cycloid.pin_radius;
            let rp = self.cycloid.pin_circle_radius;
            for (n, v, size) in [
                ("d_rp", p.d_rp, p.d_rp.abs()),
                ("d_rrp", p.d_rrp, p.d_rrp.abs()),
                ("d_delta", p.d_delta, (p.d_delta * rp).abs()),
            ] {
                // A pin radius that is itself invalid gets the geometry's own message below.
                if rrp > 0.0 && size > rrp {
                    return err(format!(
                        "disc {k}: the modification {n} = {v} moves the profile by {size:.4e} m, \
                         more than the pin radius {rrp} m; profile modifications are tens of \
                         micrometres (d_rp, d_rrp e.g. 2e-5 m; d_delta e.g. 1e-4 rad)"
                    ));
                }
            }
            crate::geometry::CycloidGeometry::check(self.disc_params(k))?;
            if let Some(pe) = &d.profile_error {
                pe.check(
                    &format!("discs[{k}].profile_error"),
                    crate::geometry::cycloid::ProfileError::LIMIT_FRACTION
                        * self.cycloid.pin_radius,
                )?;
            }
        }
        crate::geometry::involute::check_crank_count(self.cranks)?;
        if let Some(s) = &self.stage1 {
            s.validate()?;
            if s.planets != self.cranks {
                return err(format!(
                    "stage1.planets = {} must equal cranks = {} (each planet sits on a crank)",
                    s.planets, self.cranks
                ));
            }
        }
        let zp = self.cycloid.pins as usize;
        if !self.pin_errors.position.is_empty() && self.pin_errors.position.len() != zp {
            return err(format!(
                "pin_errors.position must have one (dx, dy) per pin ({zp}), got {}",
                self.pin_errors.position.len()
            ));
        }
        if !self.pin_errors.radius.is_empty() && self.pin_errors.radius.len() != zp {
            return err(format!(
                "pin_errors.radius must have one value per pin ({zp}), got {}",
                self.pin_errors.radius.len()
            ));
        }
        if self
            .pin_errors
            .position
            .iter()
            .flatten()
            .chain(&self.pin_errors.radius)
            .any(|v| !v.is_finite())
        {
            return err("pin_errors must be finite".into());
        }
        crate::geometry::cycloid::check_pin_radii(
            self.cycloid.pin_radius,
            &self.pin_errors.radius,
        )?;
        self.check_pins_apart()?;
        if let Err(e) = crate::geometry::mass::require_density(self.density) {
            return err(format!("scene density: {e}"));
        }
        let i = &self.inertias;
        for (n, mp) in [
            ("sun", i.sun),
            ("crank", i.crank),
            ("disc", i.disc),
            ("carrier", i.carrier),
        ] {
            if let Some(mp) = mp
                && !(mp.mass.is_finite()
                    && mp.mass > 0.0
                    && mp.inertia.is_finite()
                    && mp.inertia > 0.0)
            {
                return err(format!(
                    "inertias.{n} needs mass > 0 kg and inertia > 0 kg m^2, got {mp:?}"
                ));
            }
        }
        if !(i.load_inertia.is_finite() && i.load_inertia >= 0.0) {
            return err(format!(
                "inertias.load_inertia must be >= 0 kg m^2, got {}",
                i.load_inertia
            ));
        }
        self.validate_drive_train()?;
        if let Joints::Compliant {
            eccentric_bearing,
            crank_bearing,
        } = self.joints
        {
            for (n, b) in [
                ("eccentric_bearing", Some(eccentric_bearing)),
                ("crank_bearing", crank_bearing),
            ]
            .into_iter()
            .filter_map(|(n, b)| b.map(|b| (n, b)))
            {
                if !(b.clearance.is_finite() && b.clearance >= 0.0) {
                    return err(format!(
                        "joints.{n}.clearance must be >= 0 m (no preload), got {}",
                        b.clearance
                    ));
                }
                if let Some(r) = &b.rollers {
                    r.check(&format!("joints.{n}"))?;
                    let most = super::MAX_CLEARANCE_SHARE * r.pitch_diameter;
                    if b.clearance > most {
                        return err(format!(
                            "joints.{n}.clearance is the radial clearance per side in m (half the \
                             ISO 5753 radial internal clearance), at most {} of the rollers' \
                             pitch diameter, {most:.3e} m; got {} m",
                            super::MAX_CLEARANCE_SHARE,
                            b.clearance
                        ));
                    }
                    if !(b.stiffness.is_finite()
                        && b.stiffness >= 0.0
                        && b.damping.is_finite()
                        && b.damping >= 0.0)
                    {
                        return err(format!(
                            "joints.{n} has rollers: stiffness and damping (a linear \
                             spring-damper in parallel, 0 for none) must be >= 0, got {} N/m \
                             and {} N s/m",
                            b.stiffness, b.damping
                        ));
                    }
                } else if !(b.stiffness.is_finite()
                    && b.stiffness > 0.0
                    && b.damping.is_finite()
                    && b.damping >= 0.0)
                {
                    return err(format!(
                        "joints.{n} needs stiffness > 0 N/m, damping >= 0 N s/m, clearance >= 0 m; got {b:?}"
                    ));
                }
            }
        }
        self.friction.check()?;
        // Friction that no model of this scene applies is refused rather than dropped.
        if self.friction.bearing.is_some() && matches!(self.joints, Joints::Rigid) {
            return err(
                "friction.bearing acts in compliant bearings only (their roller or linear forces): \
                 with joints.kind = \"rigid\" it would be ignored; set compliant joints or remove it"
                    .into(),
            );
        }
        if self.friction.mesh > 0.0 && self.stage1.is_none() {
            return err(
                "friction.mesh acts at the sun/planet meshes, and this scene has no first stage \
                 (stage1 = null): remove it or give the stage"
                    .into(),
            );
        }
        if let Some(layout) = &self.crank_layout {
            layout
                .validate()
                .map_err(|e| RvdynError::Scene(format!("crank_layout: {e}")))?;
            if layout.discs.len() != self.discs.len() {
                return err(format!(
                    "crank_layout.discs needs the axial position [m] of each of the scene's {} \
                     discs, in their order; got {}",
                    self.discs.len(),
                    layout.discs.len()
                ));
            }
        }
        if let Some(shaft) = &self.crank_shaft {
            let Some(layout) = &self.crank_layout else {
                return err(
                    "crank_shaft needs crank_layout: the planes of the crank bearings and the \
                     discs along the crank, where the shaft is supported and loaded"
                        .into(),
                );
            };
            if matches!(self.joints, Joints::Rigid) {
                return err(
                    "crank_shaft bends the cranks between their bearings, which needs compliant \
                     joints (the eccentrics move against the discs): set joints.kind = \
                     \"compliant\" or remove crank_shaft"
                        .into(),
                );
            }
            shaft
                .stiffness(layout)
                .map_err(|e| RvdynError::Scene(format!("crank_shaft: {e}")))?;
        }
        self.errors.check(
            self.cranks as usize,
            self.discs.len(),
            self.cycloid.eccentricity,
        )?;
        if self.errors.any() && matches!(self.joints, Joints::Rigid) {
            return err(
                "errors (crank, hole and seat errors) need compliant joints: with ideal joints \
                 they over-constrain the discs; set joints.kind = \"compliant\""
                    .into(),
            );
        }
        self.contact.pin.pin_law(self.cycloid.face_width)?;
        if matches!(self.contact.pin, ContactLawSpec::Line { .. }) {
            // The line law needs 1/r_pin + kappa_profile > 0 along the whole profile (a concave
            // root flatter than the pin); check the most concave point, the root, on a fine
            // sample of one lobe of every disc, with the largest pin.
            let r_pin = self.cycloid.pin_radius
                + self.pin_errors.radius.iter().cloned().fold(0.0, f64::max);
            for k in 0..self.discs.len() {
                let g = crate::geometry::CycloidGeometry::new(self.disc_params(k))?;
                let lobe = std::f64::consts::TAU / f64::from(g.lobes());
                for i in 0..=256 {
                    let phi = lobe * (f64::from(i) / 256.0 - 0.5);
                    let kp = crate::contact::line_contact::pin_disc_profile_curvature(
                        g.centre_curve_curvature(phi),
                        g.generating_pin_radius(),
                    )?;
                    if 1.0 / r_pin + kp <= 0.0 {
                        return err(format!(
                            "contact.pin = \"line\": disc {k}'s profile is more concave ({:.4e} m \
                             radius at curve parameter {phi:.4} rad) than a pin of radius \
                             {r_pin} m is convex: the pin would sit in a conformal or nested \
                             seat, not a Hertz line contact",
                            1.0 / kp
                        ));
                    }
                }
            }
        }
        if let Some(s) = &self.stage1 {
            self.stage_mesh_law(s)?;
        }
        match self.drive {
            Drive::Speed {
                speed,
                start,
                ramp_time,
            } => {
                if !speed.is_finite() {
                    return err(format!("drive.speed must be finite rad/s, got {speed}"));
                }
                if start == StartKind::Ramp && !(ramp_time.is_finite() && ramp_time > 0.0) {
                    return err(format!(
                        "drive.ramp_time must be > 0 s for a ramp start, got {ramp_time}"
                    ));
                }
                // A steady start puts every body at full speed while a ramp holds the input at
                // rest at t = 0: the two together are not a kinematic state.
                if start == StartKind::Ramp && self.initial == Initial::Steady {
                    return err(
                        "initial = \"steady\" starts every body at full speed, but drive.start = \
                         \"ramp\" starts the input from rest: set drive.start = \"step\" for a \
                         steady start, or initial = \"rest\" for a ramp"
                            .into(),
                    );
                }
            }
            Drive::Torque { torque, ramp_time } => {
                if !(torque.is_finite() && ramp_time.is_finite() && ramp_time >= 0.0) {
                    return err(format!(
                        "drive.torque must be finite and ramp_time >= 0, got {torque}, {ramp_time}"
                    ));
                }
                if self.initial == Initial::Steady {
                    return err("initial = \"steady\" needs a speed drive (the steady speed is undefined for a torque drive)".into());
                }
            }
        }
        match &self.load {
            Load::Idle => {}
            Load::Constant { torque } => {
                if !torque.is_finite() {
                    return err(format!("load.torque must be finite N m, got {torque}"));
                }
            }
            Load::Step {
                before,
                after,
                time,
            } => {
                if !(before.is_finite() && after.is_finite() && time.is_finite()) {
                    return err("load step values must be finite".into());
                }
            }
            Load::Table { points } => {
                if points.is_empty() {
                    return err("load.points needs at least one (t, torque) pair".into());
                }
                if points.iter().flatten().any(|v| !v.is_finite()) {
                    return err("load.points must be finite".into());
                }
                if points.windows(2).any(|w| w[1][0] <= w[0][0]) {
                    return err("load.points times must increase strictly".into());
                }
            }
        }
        Ok(())
    }

    /// Shafts, motor inertia and gear errors (docs/scene.md: `shafts`, `gear_errors`).
    fn validate_drive_train(&self) -> Result<()> {
        let err = |m: String| Err(RvdynError::Scene(m));
        let jm = self.inertias.motor_inertia;
        if !(jm.is_finite() && jm >= 0.0) {
            return err(format!(
                "inertias.motor_inertia must be >= 0 kg m^2, got {jm}"
            ));
        }
        if jm > 0.0 && self.stage1.is_none() {
            return err(
                "inertias.motor_inertia > 0 needs a first stage (stage1): the motor drives the \
                 sun"
                .into(),
            );
        }
        for (n, sh) in [("output", self.shafts.output), ("input", self.shafts.input)] {
            let Some(sh) = sh else { continue };
            if !(sh.stiffness.is_finite() && sh.stiffness > 0.0) {
                return err(format!(
                    "shafts.{n}.stiffness must be > 0 N m/rad (omit the shaft for a rigid \
                     connection), got {}",
                    sh.stiffness
                ));
            }
            if !(sh.damping.is_finite() && sh.damping >= 0.0) {
                return err(format!(
                    "shafts.{n}.damping must be >= 0 N m s/rad, got {}",
                    sh.damping
                ));
            }
        }
        if self.shafts.output.is_some() && self.inertias.load_inertia <= 0.0 {
            return err(
                "shafts.output needs inertias.load_inertia > 0 kg m^2 (the inertia at the \
                 shaft's far end)"
                    .into(),
            );
        }
        if self.shafts.input.is_some() {
            if self.stage1.is_none() {
                return err("shafts.input needs a first stage (stage1): it drives the sun".into());
            }
            if matches!(self.drive, Drive::Torque { .. }) && jm <= 0.0 {
                return err(
                    "shafts.input with a torque drive needs inertias.motor_inertia > 0 kg m^2 \
                     (the motor the torque acts on)"
                        .into(),
                );
            }
        }
        let g = &self.gear_errors;
        if g.any() || !g.planets.is_empty() {
            let Some(s) = &self.stage1 else {
                return err("gear_errors need a first stage (stage1)".into());
            };
            let limit = 0.1 * s.module;
            g.sun.check("gear_errors.sun", s.z_sun, limit)?;
            if !g.planets.is_empty() && g.planets.len() != s.planets as usize {
                return err(format!(
                    "gear_errors.planets must be empty or have one entry per planet ({}), got {}",
                    s.planets,
                    g.planets.len()
                ));
            }
            for (i, p) in g.planets.iter().enumerate() {
                p.check(&format!("gear_errors.planets[{i}]"), s.z_planet, limit)?;
            }
        }
        Ok(())
    }
}
