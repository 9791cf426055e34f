//! The navigation frames' trait, [`NavFrame`]: what code generic over [`Enu`] and [`Ned`] needs
//! to know of its frame (which way is up, gravity and the default magnetic field in its axes,
//! the turns to and from NED and from forward-right-down body axes).
use crate::frame::{Body, Enu, Frame, Frd, Ned};
use crate::rotation::Rotation;
use crate::vector::Vec3;

/// A local-level navigation frame (flat Earth).
pub trait NavFrame: Frame {
    /// +1 when the frame's z axis points up (ENU), −1 when it points down (NED).
    const Z_UP: f64;

    /// Gravity vector `g_n` for a gravity magnitude `g_m_s2` (m/s²): ENU `[0, 0, −g]`, NED `[0, 0, +g]`.
    #[must_use]
    fn gravity(g_m_s2: f64) -> Vec3<Self> {
        Vec3::new(0.0, 0.0, -Self::Z_UP * g_m_s2)
    }

    /// MATLAB imuSensor's default magnetic field, µT, resolved in this frame
    /// (NED `[27.5550, −2.4169, −16.0849]`).
    #[must_use]
    fn default_magnetic_field_ut() -> Vec3<Self>;

    /// The change of axes from NED to this frame (the identity for NED).
    #[must_use]
    fn from_ned() -> Rotation<Ned, Self>;

    /// A NED vector re-resolved in this frame, by exchanging axes (exact; ENU `(y, x, −z)`).
    #[must_use]
    fn from_ned_axes(v: Vec3<Ned>) -> Vec3<Self>;

    /// A vector of this frame re-resolved in NED (the inverse of [`Self::from_ned_axes`]).
    #[must_use]
    fn to_ned_axes(v: Vec3<Self>) -> Vec3<Ned>;

    /// Body axes of this frame's convention from FRD: the identity under NED (FRD), a half turn
    /// about x under ENU (FLU: `(x, −y, −z)`).
    #[must_use]
    fn frd_to_body() -> Rotation<Frd, Body> {
        if Self::Z_UP > 0.0 {
            Rotation::from_wxyz([0.0, 1.0, 0.0, 0.0]).unwrap_or_default()
        } else {
            Rotation::identity()
        }
    }
}

impl NavFrame for Enu {
    const Z_UP: f64 = 1.0;
    fn default_magnetic_field_ut() -> Vec3<Self> {
        Vec3::new(-2.4169, 27.5550, 16.0849)
    }
    fn from_ned() -> Rotation<Ned, Self> {
        Rotation::ned_to_enu()
    }
    fn from_ned_axes(v: Vec3<Ned>) -> Vec3<Self> {
        Vec3::new(v.y(), v.x(), -v.z())
    }
    fn to_ned_axes(v: Vec3<Self>) -> Vec3<Ned> {
        Vec3::new(v.y(), v.x(), -v.z())
    }
}

impl NavFrame for Ned {
    const Z_UP: f64 = -1.0;
    fn default_magnetic_field_ut() -> Vec3<Self> {
        Vec3::new(27.5550, -2.4169, -16.0849)
    }
    fn from_ned() -> Rotation<Ned, Self> {
        Rotation::identity()
    }
    fn from_ned_axes(v: Vec3<Ned>) -> Vec3<Self> {
        v
    }
    fn to_ned_axes(v: Vec3<Self>) -> Vec3<Ned> {
        v
    }
}
