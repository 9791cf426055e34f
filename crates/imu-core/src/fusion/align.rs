//! Where a filter starts without a reference attitude, on any [`EarthModel`]:
//! - [`at_rest`]: levelling from the mean specific force and gyrocompassing from the mean body
//!   rate of a vehicle standing still (the horizontal part of the Earth's rate points north),
//!   with the one-sigma the part's figures allow (Groves, *Principles of GNSS, Inertial, and
//!   Multisensor Integrated Navigation Systems*, 2nd ed., §5.6);
//! - [`moving`]: the attitude of a vehicle moving nose first, from its velocity.
//!
//! Body axes follow the frame's convention (FLU under ENU, FRD under NED); the formulas are
//! written in NED/FRD and the frames exchanged exactly.
use crate::earth::EarthModel;
use crate::frame::{Body, Frd, Ned};
use crate::math;
use crate::nav_frame::NavFrame;
use crate::rotation::{EulerZyx, Rotation};
use crate::vector::Vec3;

/// The largest heading one-sigma [`at_rest`] accepts, rad: beyond it the gyroscopes do not find
/// north (their bias hides the Earth's rate).
pub const MAX_HEADING_SIGMA_RAD: f64 = 0.2;

/// How far the mean specific force may be from gravity for a vehicle at rest (a fraction of
/// gravity).
pub const REST_TOLERANCE: f64 = 0.05;

/// What a part's figures say of the averages of [`at_rest`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PartFigures {
    /// The accelerometer's bias (its constant bias and bias-instability floor in quadrature,
    /// worst axis), m/s².
    pub accel_bias_m_s2: f64,
    /// The gyroscope's bias, likewise, rad/s.
    pub gyro_bias_rad_s: f64,
    /// White accelerometer noise, (m/s²)/√Hz.
    pub accel_psd: f64,
    /// White gyroscope noise, (rad/s)/√Hz.
    pub gyro_psd: f64,
}

/// An attitude found at rest and the one-sigma it claims.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RestAlignment<N> {
    /// The attitude, body to navigation frame.
    pub attitude: Rotation<Body, N>,
    /// One-sigma of roll and pitch: the accelerometer bias over gravity, with the averaged
    /// white noise, rad.
    pub tilt_sigma_rad: f64,
    /// One-sigma of heading: the gyroscope bias over the Earth rate's horizontal part, with the
    /// averaged white noise, rad.
    pub heading_sigma_rad: f64,
}

/// Why an alignment at rest is refused.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum AlignError {
    /// The mean specific force is not gravity: the vehicle moved.
    NotAtRest {
        /// The mean specific force's magnitude, m/s².
        specific_force_m_s2: f64,
        /// Gravity there, m/s².
        gravity_m_s2: f64,
    },
    /// The heading would be worse than [`MAX_HEADING_SIGMA_RAD`] (or the Earth model has no
    /// rate to find north by).
    NoNorth {
        /// The gyroscope's bias, rad/s.
        gyro_bias_rad_s: f64,
        /// The Earth rate's horizontal part there, rad/s (0 on a non-rotating Earth).
        horizontal_rate_rad_s: f64,
    },
}

impl core::fmt::Display for AlignError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            Self::NotAtRest {
                specific_force_m_s2,
                gravity_m_s2,
            } => write!(
                f,
                "the mean specific force is {specific_force_m_s2:.3} m/s², not gravity \
                 ({gravity_m_s2:.3}): the vehicle is not at rest"
            ),
            Self::NoNorth {
                gyro_bias_rad_s,
                horizontal_rate_rad_s,
            } => write!(
                f,
                "this gyroscope (bias {gyro_bias_rad_s:.2e} rad/s) cannot find north against the \
                 Earth rate's {horizontal_rate_rad_s:.2e} rad/s here"
            ),
        }
    }
}

impl core::error::Error for AlignError {}

/// The attitude of a vehicle at rest at `position` on `earth` from the mean specific force
/// `specific_force_m_s2` and mean body rate `rate_rad_s` (body axes of the frame's convention)
/// over `duration_s`: roll `atan2(−f_y, −f_z)` and pitch `atan2(f_x, √(f_y² + f_z²))` (FRD);
/// the rate levelled by them, `ω_l = R_y(θ) R_x(φ) ω`, is the Earth rate
/// `(Ω_h cos ψ, −Ω_h sin ψ, ·)`, so yaw `ψ = atan2(−ω_l,y, ω_l,x)`. One-sigma: tilt
/// `√(b_a² + (q_a/√T)²)/g`, heading `√(b_g² + (q_g/√T)²)/Ω_h`.
///
/// # Errors
/// A specific force farther than [`REST_TOLERANCE`] from gravity; a heading one-sigma of
/// [`MAX_HEADING_SIGMA_RAD`] or more (always on an Earth that does not turn).
pub fn at_rest<E: EarthModel>(
    earth: &E,
    position: &E::Position,
    specific_force_m_s2: [f64; 3],
    rate_rad_s: [f64; 3],
    duration_s: f64,
    part: &PartFigures,
) -> Result<RestAlignment<E::Frame>, AlignError> {
    let terms = earth.terms(&E::coordinates(position), &Vec3::zeros());
    let gravity = E::Frame::to_ned_axes(terms.gravity_m_s2).z();
    let earth_rate = E::Frame::to_ned_axes(terms.earth_rate_rad_s);
    let horizontal = math::hypot(earth_rate.x(), earth_rate.y());
    let to_frd = E::Frame::frd_to_body().inverse();
    let f = to_frd
        .apply(Vec3::from_array(specific_force_m_s2))
        .to_array();
    let w = to_frd.apply(Vec3::from_array(rate_rad_s)).to_array();
    let magnitude = math::sqrt(f.iter().map(|x| x * x).sum::<f64>());
    if math::abs(magnitude - gravity) > REST_TOLERANCE * gravity || magnitude.is_nan() {
        return Err(AlignError::NotAtRest {
            specific_force_m_s2: magnitude,
            gravity_m_s2: gravity,
        });
    }
    let heading_sigma_rad =
        math::hypot(part.gyro_bias_rad_s, part.gyro_psd / math::sqrt(duration_s)) / horizontal;
    if heading_sigma_rad.is_nan() || heading_sigma_rad >= MAX_HEADING_SIGMA_RAD {
        return Err(AlignError::NoNorth {
            gyro_bias_rad_s: part.gyro_bias_rad_s,
            horizontal_rate_rad_s: horizontal,
        });
    }
    let (roll, pitch) = roll_pitch(f);
    let level = Rotation::<Frd, Frd>::from_euler(EulerZyx::new(0.0, pitch, roll));
    let wl = level.apply(Vec3::from_array(w)).to_array();
    let yaw = math::atan2(-wl[1], wl[0]);
    Ok(RestAlignment {
        attitude: attitude_of::<E::Frame>(yaw, pitch, roll),
        tilt_sigma_rad: tilt_sigma(part, duration_s, gravity),
        heading_sigma_rad,
    })
}

/// Levelling alone, for a start whose heading nothing measures (no Earth rate a gyroscope can
/// see, no fix): roll and pitch as [`at_rest`] finds them from the mean specific force
/// `specific_force_m_s2` (body axes of the frame's convention) over `duration_s`, the heading
/// the given `yaw_rad` (NED yaw: about down, from the frame's north), and the tilt's one-sigma
/// as [`at_rest`] states it; `heading_sigma_rad` is the caller's to state (0 here).
///
/// # Errors
/// A specific force farther than [`REST_TOLERANCE`] from `gravity_m_s2`.
pub fn level<N: NavFrame>(
    specific_force_m_s2: [f64; 3],
    gravity_m_s2: f64,
    yaw_rad: f64,
    duration_s: f64,
    part: &PartFigures,
) -> Result<RestAlignment<N>, AlignError> {
    let f = N::frd_to_body()
        .inverse()
        .apply(Vec3::from_array(specific_force_m_s2))
        .to_array();
    let magnitude = math::sqrt(f.iter().map(|x| x * x).sum::<f64>());
    if math::abs(magnitude - gravity_m_s2) > REST_TOLERANCE * gravity_m_s2 || magnitude.is_nan() {
        return Err(AlignError::NotAtRest {
            specific_force_m_s2: magnitude,
            gravity_m_s2,
        });
    }
    let (roll, pitch) = roll_pitch(f);
    Ok(RestAlignment {
        attitude: attitude_of::<N>(yaw_rad, pitch, roll),
        tilt_sigma_rad: tilt_sigma(part, duration_s, gravity_m_s2),
        heading_sigma_rad: 0.0,
    })
}

/// Roll and pitch from a specific force in FRD axes (the sensor level when it reads `(0, 0, −g)`).
fn roll_pitch(f: [f64; 3]) -> (f64, f64) {
    (
        math::atan2(-f[1], -f[2]),
        math::atan2(f[0], math::hypot(f[1], f[2])),
    )
}

/// The body-to-`N` attitude of NED Euler angles (FRD body).
fn attitude_of<N: NavFrame>(yaw: f64, pitch: f64, roll: f64) -> Rotation<Body, N> {
    let frd_ned = Rotation::<Frd, Ned>::from_euler(EulerZyx::new(yaw, pitch, roll));
    N::frd_to_body()
        .inverse()
        .then(&frd_ned)
        .then(&N::from_ned())
}

/// The tilt's one-sigma from averages over `duration_s`: the accelerometer's bias and its
/// averaged white noise over gravity.
fn tilt_sigma(part: &PartFigures, duration_s: f64, gravity_m_s2: f64) -> f64 {
    math::hypot(
        part.accel_bias_m_s2,
        part.accel_psd / math::sqrt(duration_s),
    ) / gravity_m_s2
}

/// The attitude of a vehicle moving nose first with velocity `v` (frame `N`): the body's x axis
/// along `v` — yaw `atan2(v_y, v_x)`, pitch `atan2(−v_z, |v_h|)` in either frame's own axes —
/// and roll 0.
#[must_use]
pub fn moving<N: NavFrame>(v: &Vec3<N>) -> Rotation<Body, N> {
    let horizontal = math::hypot(v.x(), v.y());
    Rotation::from_euler(EulerZyx::new(
        math::atan2(v.y(), v.x()),
        math::atan2(-v.z(), horizontal),
        0.0,
    ))
}
