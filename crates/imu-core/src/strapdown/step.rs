//! 3D strapdown navigation in a flat-Earth local-level frame `N` (ENU or NED), per sample.
//!
//! Per interval k, from the angle increment `Δθ_k = ∫ω_b dt` and the velocity increment
//! `Δv_k = ∫f_b dt` (body frame, specific force):
//! * attitude `q_k = q_{k−1} ⊗ exp(φ_k)`, `φ_k = Δθ_k + (Δθ_{k−1} × Δθ_k)/12` (two-sample coning
//!   correction; the exponential of the rotation vector is exact);
//! * velocity `v_k = v_{k−1} + C_nb,k−1 (Δv_k + ½ Δθ_k × Δv_k + (Δθ_{k−1} × Δv_k + Δv_{k−1} × Δθ_k)/12)
//!   + g_n Δt` (rotation and two-sample sculling compensation, gravity);
//! * position `p_k = p_{k−1} + ½ (v_{k−1} + v_k) Δt` (trapezoid).
//!
//! References: P. Savage, *Strapdown Analytics* (2000), ch. 7; Titterton & Weston, *Strapdown
//! Inertial Navigation Technology* (2nd ed.), §11.2. The corrections can be switched off to
//! compare. Rate inputs are turned into increments by the trapezoidal rule ([`RateStrapdown`]).
use nalgebra::{UnitQuaternion, Vector3};

use crate::frame::{Body, NavFrame};
use crate::rotation::Rotation;
use crate::vector::Vec3;

/// The navigation state.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct NavState<N> {
    /// Time, s.
    pub t_s: f64,
    /// Attitude `C_nb`.
    pub attitude: Rotation<Body, N>,
    /// Velocity in the navigation frame, m/s.
    pub velocity_m_s: Vec3<N>,
    /// Position in the navigation frame, m.
    pub position_m: Vec3<N>,
}

impl<N: NavFrame> Default for NavState<N> {
    fn default() -> Self {
        Self {
            t_s: 0.0,
            attitude: Rotation::identity(),
            velocity_m_s: Vec3::zeros(),
            position_m: Vec3::zeros(),
        }
    }
}

/// Options of the strapdown algorithm.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StrapdownOptions {
    /// Gravity magnitude, m/s².
    pub gravity_m_s2: f64,
    /// Apply the two-sample coning correction.
    pub coning: bool,
    /// Apply the rotation and two-sample sculling terms to the velocity increment.
    pub sculling: bool,
}

impl Default for StrapdownOptions {
    fn default() -> Self {
        Self {
            gravity_m_s2: crate::frame::DEFAULT_GRAVITY_M_S2,
            coning: true,
            sculling: true,
        }
    }
}

/// Why a strapdown step was refused.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum StrapdownError {
    /// A NaN or infinite input at sample `index`.
    NotFinite {
        /// Sample index.
        index: usize,
    },
    /// Times must increase strictly.
    TimeNotIncreasing {
        /// Sample index.
        index: usize,
    },
    /// The latitude left ±89.9°, where the local NED frame is not used (Earth mechanization).
    NearPole {
        /// Sample index.
        index: usize,
    },
    /// An option out of its range.
    BadOption {
        /// Which option and its range.
        field: &'static str,
    },
    /// Input slices of different lengths, or an output slice too short.
    LengthMismatch {
        /// Which slice.
        field: &'static str,
        /// Needed length.
        expected: usize,
        /// Its length.
        got: usize,
    },
}

impl core::fmt::Display for StrapdownError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match *self {
            Self::NotFinite { index } => {
                write!(f, "sample {index} has a value that is not a finite number")
            }
            Self::TimeNotIncreasing { index } => {
                write!(
                    f,
                    "time at sample {index} does not increase after sample {}",
                    index.saturating_sub(1)
                )
            }
            Self::NearPole { index } => write!(
                f,
                "at sample {index} the latitude is beyond ±89.9°, where the local NED frame is \
                 not used (the transport rate grows without bound near the poles)"
            ),
            Self::BadOption { field } => write!(f, "{field}"),
            Self::LengthMismatch {
                field,
                expected,
                got,
            } => write!(f, "{field} has length {got}, expected {expected}"),
        }
    }
}

impl core::error::Error for StrapdownError {}

/// Checks that every `(field, length)` equals `n`.
pub(crate) fn check_lengths(
    n: usize,
    lengths: &[(&'static str, usize)],
) -> Result<(), StrapdownError> {
    match lengths.iter().find(|(_, got)| *got != n) {
        Some(&(field, got)) => Err(StrapdownError::LengthMismatch {
            field,
            expected: n,
            got,
        }),
        None => Ok(()),
    }
}

fn finite3(v: &[f64; 3]) -> bool {
    v.iter().all(|c| c.is_finite())
}

/// Strapdown on Δθ/Δv increments.
#[derive(Clone, Copy, Debug)]
pub struct Strapdown<N> {
    state: NavState<N>,
    options: StrapdownOptions,
    prev_dtheta: Vector3<f64>,
    prev_dv: Vector3<f64>,
    index: usize,
}

impl<N: NavFrame> Strapdown<N> {
    /// Starts from `initial`.
    #[must_use]
    pub fn new(initial: NavState<N>, options: StrapdownOptions) -> Self {
        Self {
            state: initial,
            options,
            prev_dtheta: Vector3::zeros(),
            prev_dv: Vector3::zeros(),
            index: 1,
        }
    }

    /// The current state.
    #[must_use]
    pub fn state(&self) -> &NavState<N> {
        &self.state
    }

    /// Advances over the interval ending at `t_s` with increments `dtheta_rad` (body, rad) and
    /// `dv_m_s` (body specific-force integral, m/s); returns the state at `t_s`.
    ///
    /// # Errors
    /// Non-finite inputs or a time that does not increase.
    pub fn step(
        &mut self,
        t_s: f64,
        dtheta_rad: [f64; 3],
        dv_m_s: [f64; 3],
    ) -> Result<NavState<N>, StrapdownError> {
        let index = self.index;
        if !(t_s.is_finite() && finite3(&dtheta_rad) && finite3(&dv_m_s)) {
            return Err(StrapdownError::NotFinite { index });
        }
        let dt = t_s - self.state.t_s;
        if dt <= 0.0 {
            return Err(StrapdownError::TimeNotIncreasing { index });
        }
        let dth = Vector3::from(dtheta_rad);
        let dv = Vector3::from(dv_m_s);
        let mut phi = dth;
        if self.options.coning {
            phi += self.prev_dtheta.cross(&dth) / 12.0;
        }
        let mut dv_corr = dv;
        if self.options.sculling {
            dv_corr += 0.5 * dth.cross(&dv)
                + (self.prev_dtheta.cross(&dv) + self.prev_dv.cross(&dth)) / 12.0;
        }
        let s = &mut self.state;
        let v_prev = s.velocity_m_s;
        let dv_nav = s.attitude.apply(Vec3::<Body>::from_nalgebra(dv_corr));
        let v = v_prev + dv_nav + N::gravity(self.options.gravity_m_s2) * dt;
        let q = s.attitude.quaternion() * UnitQuaternion::from_scaled_axis(phi);
        s.attitude = Rotation::assume_from_quaternion(q);
        s.position_m += (v_prev + v) * (0.5 * dt);
        s.velocity_m_s = v;
        s.t_s = t_s;
        self.prev_dtheta = dth;
        self.prev_dv = dv;
        self.index += 1;
        Ok(*s)
    }
}

/// Strapdown on rate samples (gyro rad/s, specific force m/s², body frame), turned into
/// increments by the trapezoidal rule between consecutive samples.
#[derive(Clone, Copy, Debug)]
pub struct RateStrapdown<N> {
    inner: Strapdown<N>,
    last: Option<(f64, [f64; 3], [f64; 3])>,
    index: usize,
}

impl<N: NavFrame> RateStrapdown<N> {
    /// Starts from `initial`; the first sample must be at `initial.t_s`.
    #[must_use]
    pub fn new(initial: NavState<N>, options: StrapdownOptions) -> Self {
        Self {
            inner: Strapdown::new(initial, options),
            last: None,
            index: 0,
        }
    }

    /// Takes one sample; the first returns the initial state.
    ///
    /// # Errors
    /// Non-finite values or non-increasing times, with the sample index.
    pub fn step(
        &mut self,
        t_s: f64,
        gyro_rad_s: [f64; 3],
        accel_m_s2: [f64; 3],
    ) -> Result<NavState<N>, StrapdownError> {
        let index = self.index;
        if !(t_s.is_finite() && finite3(&gyro_rad_s) && finite3(&accel_m_s2)) {
            return Err(StrapdownError::NotFinite { index });
        }
        let out = match self.last {
            None => {
                self.inner.state.t_s = t_s;
                Ok(self.inner.state)
            }
            Some((t0, w0, f0)) => {
                let h = 0.5 * (t_s - t0);
                if h <= 0.0 {
                    return Err(StrapdownError::TimeNotIncreasing { index });
                }
                let dth = core::array::from_fn(|i| h * (w0[i] + gyro_rad_s[i]));
                let dv = core::array::from_fn(|i| h * (f0[i] + accel_m_s2[i]));
                self.inner.index = index;
                self.inner.step(t_s, dth, dv)
            }
        };
        self.last = Some((t_s, gyro_rad_s, accel_m_s2));
        self.index += 1;
        out
    }
}

/// Strapdown over rate samples on slices, written into `out` (same length; `out[0]` is the
/// initial state at `t_s[0]`).
///
/// # Errors
/// As [`RateStrapdown::step`]; mismatched lengths.
pub fn strapdown_rates<N: NavFrame>(
    t_s: &[f64],
    gyro_rad_s: &[[f64; 3]],
    accel_m_s2: &[[f64; 3]],
    initial: NavState<N>,
    options: StrapdownOptions,
    out: &mut [NavState<N>],
) -> Result<(), StrapdownError> {
    let n = t_s.len();
    check_lengths(
        n,
        &[
            ("gyro_rad_s", gyro_rad_s.len()),
            ("accel_m_s2", accel_m_s2.len()),
            ("output", out.len()),
        ],
    )?;
    let mut nav = RateStrapdown::new(initial, options);
    for i in 0..n {
        out[i] = nav.step(t_s[i], gyro_rad_s[i], accel_m_s2[i])?;
    }
    Ok(())
}

/// Strapdown over Δθ/Δv increments on slices (`dtheta[i]`, `dv[i]` over the interval ending at
/// `t_s[i]`; entry 0 is ignored), written into `out` (`out[0]` is the initial state at `t_s[0]`).
///
/// # Errors
/// As [`Strapdown::step`]; mismatched lengths.
pub fn strapdown_increments<N: NavFrame>(
    t_s: &[f64],
    dtheta_rad: &[[f64; 3]],
    dv_m_s: &[[f64; 3]],
    initial: NavState<N>,
    options: StrapdownOptions,
    out: &mut [NavState<N>],
) -> Result<(), StrapdownError> {
    let n = t_s.len();
    check_lengths(
        n,
        &[
            ("dtheta_rad", dtheta_rad.len()),
            ("dv_m_s", dv_m_s.len()),
            ("output", out.len()),
        ],
    )?;
    if n == 0 {
        return Ok(());
    }
    let mut nav = Strapdown::new(
        NavState {
            t_s: t_s[0],
            ..initial
        },
        options,
    );
    out[0] = *nav.state();
    for i in 1..n {
        out[i] = nav.step(t_s[i], dtheta_rad[i], dv_m_s[i])?;
    }
    Ok(())
}
