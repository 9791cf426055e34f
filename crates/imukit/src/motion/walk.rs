//! A walking foot (`type = "walk"`): what a foot-mounted IMU feels, with exact derivatives.
//!
//! After `start_s` standing still, each stride (one foot's cycle, `1/cadence_hz` long) is a
//! stance — the foot flat and still for `stance_fraction` of it — then a swing that carries the
//! foot `stride_m` along the path, lifting it by up to `lift_m` and pitching it by up to
//! `foot_pitch_rad`. With `p` the swing's progress from 0 to 1, the distance along the path is
//! `stride·(k + 10p³ − 15p⁴ + 6p⁵)` (zero velocity and acceleration at both ends: the foot leaves
//! and lands without a jerk in its path), the height `lift·64p³(1 − p)³` (it lands at zero
//! speed and acceleration), the pitch
//! `−foot_pitch·sin²(πp)` (toes down mid-swing). The path is a straight line along
//! `heading_rad`, or with `radius_m` a circle turning left, the foot's yaw along it — a walk
//! that comes back to where it started after every `2π·radius/stride` strides.
use crate::error::{Result, invalid};
use crate::motion::analytic::{Motion, Scalar};

/// The walk's parameters (see the module documentation).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct WalkMotion {
    /// Strides per second (one foot), Hz.
    pub cadence_hz: f64,
    /// Distance one stride carries the foot, m.
    pub stride_m: f64,
    /// Fraction of a stride the foot stands still, in (0, 1).
    pub stance_fraction: f64,
    /// Largest height of the foot in a swing, m.
    pub lift_m: f64,
    /// Largest pitch of the foot in a swing, rad.
    pub foot_pitch_rad: f64,
    /// Radius of the circle walked (turning left), m; `None`: a straight line.
    pub radius_m: Option<f64>,
    /// Time standing still before the first stride, s.
    pub start_s: f64,
    /// Initial heading from the x axis towards y, rad.
    pub heading_rad: f64,
    /// Where the foot starts, navigation frame, m.
    pub start_m: [f64; 3],
}

impl WalkMotion {
    /// The walk's figures, each named where it is out of range.
    ///
    /// # Errors
    /// A figure out of range, named by its key.
    pub fn check(&self) -> Result<()> {
        let w = self;
        let positive = |name: &str, v: f64| {
            if v.is_finite() && v > 0.0 {
                Ok(())
            } else {
                Err(invalid(
                    format!("trajectory.{name}"),
                    format!("must be a finite number > 0, got {v}"),
                ))
            }
        };
        positive("cadence_hz", w.cadence_hz)?;
        positive("stride_m", w.stride_m)?;
        if let Some(r) = w.radius_m {
            positive("radius_m", r)?;
        }
        if !(w.stance_fraction > 0.0 && w.stance_fraction < 1.0) {
            return Err(invalid(
                "trajectory.stance_fraction",
                format!("must be in (0, 1), got {}", w.stance_fraction),
            ));
        }
        for (name, v) in [
            ("lift_m", w.lift_m),
            ("foot_pitch_rad", w.foot_pitch_rad),
            ("start_s", w.start_s),
            ("heading_rad", w.heading_rad),
        ] {
            if !v.is_finite() || (name != "heading_rad" && v < 0.0) {
                return Err(invalid(
                    format!("trajectory.{name}"),
                    format!(
                        "must be a finite number{}, got {v}",
                        if name == "heading_rad" { "" } else { " ≥ 0" }
                    ),
                ));
            }
        }
        if w.start_m.iter().any(|v| !v.is_finite()) {
            return Err(invalid("trajectory.start_m", "must be finite"));
        }
        Ok(())
    }

    /// Distance along the path, height and swing progress at `t` (the progress is 0 at rest).
    fn along<D: Scalar>(&self, t: D) -> (D, D, D) {
        let zero = D::from(0.0);
        let u = (t - self.start_s) * self.cadence_hz;
        if u.re() <= 0.0 {
            return (zero, zero, zero);
        }
        let k = u.re().floor();
        let phase = u - k;
        let s = self.stance_fraction;
        if phase.re() < s {
            return (D::from(k * self.stride_m), zero, zero);
        }
        let p = (phase - s) / (1.0 - s);
        let p2 = p * p;
        let p3 = p2 * p;
        let q = p3 * 10.0 - p3 * p * 15.0 + p3 * p2 * 6.0;
        let one_minus = -p + 1.0;
        let om3 = one_minus * one_minus * one_minus;
        let height = p3 * om3 * (64.0 * self.lift_m);
        ((q + k) * self.stride_m, height, p)
    }
}

impl Motion for WalkMotion {
    fn position<D: Scalar>(&self, t: D) -> [D; 3] {
        let (s, z, _) = self.along(t);
        let (forward, left) = match self.radius_m {
            Some(r) => {
                let a = s / r;
                (a.sin() * r, (-a.cos() + 1.0) * r)
            }
            None => (s, D::from(0.0)),
        };
        let (sin_h, cos_h) = self.heading_rad.sin_cos();
        [
            forward * cos_h - left * sin_h + self.start_m[0],
            forward * sin_h + left * cos_h + self.start_m[1],
            z + self.start_m[2],
        ]
    }

    fn euler<D: Scalar>(&self, t: D) -> Option<[D; 3]> {
        let (s, _, p) = self.along(t);
        let yaw = match self.radius_m {
            Some(r) => s / r + self.heading_rad,
            None => D::from(self.heading_rad),
        };
        let swing = (p * std::f64::consts::PI).sin();
        let pitch = -(swing * swing) * self.foot_pitch_rad;
        Some([yaw, pitch, D::from(0.0)])
    }
}
