//! The rules a scene must follow as a whole (docs/scene.md lists them per field); each error
//! names the field and how to fix it.

use super::*;

impl Scene {
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
            crate::geometry::CycloidGeometry::check(self.disc_params(k))?;
        }
        if self.cranks < 1 {
            return err("cranks must be at least 1".into());
        }
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
        if !(self.density.is_finite() && self.density > 0.0) {
            return err(format!("density must be > 0 kg/m^3, got {}", self.density));
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
                if !(b.stiffness.is_finite()
                    && b.stiffness > 0.0
                    && b.damping.is_finite()
                    && b.damping >= 0.0
                    && b.clearance.is_finite()
                    && b.clearance >= 0.0)
                {
                    return err(format!(
                        "joints.{n} needs stiffness > 0 N/m, damping >= 0 N s/m, clearance >= 0 m; got {b:?}"
                    ));
                }
            }
        }
        self.contact.pin.law(self.cycloid.face_width)?;
        if let Some(s) = &self.stage1 {
            self.contact.mesh.law(s.face_width)?;
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
}
