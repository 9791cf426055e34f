//! Frame markers: the navigation frames [`Enu`] and [`Ned`], the [`Body`] frame in the
//! navigation frame's convention, and [`Frd`], body axes forward-right-down whatever the frame.
//!
//! Frames are types, so a body-frame vector cannot be added to a navigation-frame one and generic
//! code (`fn f<N: NavFrame>`, [`crate::nav_frame`]) replaces an `is_enu` flag. The front ends
//! pick `Enu` or `Ned` once.

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
/// kinematics (`earth::ideal`, local NED) and of alignment. [`crate::NavFrame::frd_to_body`] is the
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
