//! Frame markers: the navigation frames [`Enu`] and [`Ned`], the [`Body`] frame in the
//! navigation frame's convention, and [`Frd`], body axes forward-right-down whatever the frame.
//!
//! Frames are types, so a body-frame vector cannot be added to a navigation-frame one and generic
//! code (`fn f<N: NavFrame>`) replaces an `is_enu` flag. The front ends pick `Enu` or `Ned` once.
use crate::rotation::Rotation;
use crate::vector::Vec3;

mod sealed {
    pub trait Sealed {}
    impl Sealed for super::Enu {}
    impl Sealed for super::Ned {}
    impl Sealed for super::Body {}
    impl Sealed for super::Frd {}
    impl Sealed for super::Ecef {}
}

/// The gravity magnitude imukit uses unless told otherwise, m/s²: 9.81, MATLAB imuSensor's
/// value (the standard gravity 9.80665 m/s² is what datasheet units such as mg convert with; see
/// `imukit::io::units`).
pub const DEFAULT_GRAVITY_M_S2: f64 = 9.81;

/// A coordinate frame marker.
pub trait Frame:
    sealed::Sealed + Copy + Default + core::fmt::Debug + PartialEq + Send + Sync + 'static
{
    /// Short name used in messages and file headers.
    const NAME: &'static str;
}

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

/// East-North-Up navigation frame (the default). Body frame is FLU.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Enu;

/// North-East-Down navigation frame (MATLAB's default). Body frame is FRD.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Ned;

/// The body frame of the moving rigid body (and of the IMU mounted on it), in the navigation
/// frame's convention: forward-left-up (FLU) under [`Enu`], forward-right-down (FRD) under
/// [`Ned`]. Code generic over the navigation frame reads and writes the body axes through it.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Body;

/// Body axes forward-right-down, whatever the navigation frame: the convention of the Earth's
/// kinematics (`earth::ideal`, local NED) and of alignment. [`NavFrame::frd_to_body`] is the
/// typed turn from it to [`Body`].
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Frd;

impl Frame for Enu {
    const NAME: &'static str = "ENU";
}
impl Frame for Ned {
    const NAME: &'static str = "NED";
}
impl Frame for Body {
    const NAME: &'static str = "body";
}
impl Frame for Frd {
    const NAME: &'static str = "FRD";
}

/// The Earth-centred, Earth-fixed frame of WGS-84: x through the equator at the prime meridian,
/// z through the north pole, y completing the right-handed set (see [`crate::earth`]).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Ecef;

impl Frame for Ecef {
    const NAME: &'static str = "ECEF";
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
