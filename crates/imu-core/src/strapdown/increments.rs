//! 3D strapdown on Δθ/Δv increments, per sample, on any [`EarthModel`].
//!
//! Per interval k, from the angle increment `Δθ_k = ∫ω_b dt` and the velocity increment
//! `Δv_k = ∫f_b dt` (body frame, specific force):
//! * attitude `q_k = exp(−ζ_k) ⊗ q_{k−1} ⊗ exp(φ_k)`, `φ_k = Δθ_k + (Δθ_{k−1} × Δθ_k)/12`
//!   (two-sample coning correction; the exponential of the rotation vector is exact), `ζ_k =
//!   ω_in Δt` the navigation frame's turn over the interval (none on the flat Earth);
//! * velocity `v_k = v_{k−1} + (I − ½[ζ_k×]) C_nb,k−1 (Δv_k + ½ Δθ_k × Δv_k +
//!   (Δθ_{k−1} × Δv_k + Δv_{k−1} × Δθ_k)/12) + (g − (2ω_ie + ω_en) × v) Δt` (rotation and
//!   two-sample sculling compensation, gravity and Coriolis);
//! * position coordinates `c_k = c_{k−1} + ċ(c_mid, v_mid) Δt` (the trapezoid of the velocity).
//!
//! On a rotating Earth the Earth's terms are evaluated at the interval's midpoint by one
//! predictor–corrector pass (second order); on the flat Earth they are constant and the
//! predictor is exact. References: P. Savage, *Strapdown Analytics* (2000), ch. 7; Titterton &
//! Weston, *Strapdown Inertial Navigation Technology* (2nd ed.), §11.2. The corrections can be
//! switched off to compare. Rate inputs are turned into increments by the trapezoidal rule
//! ([`RateIncrements`]).
use nalgebra::Vector3;

use crate::earth::EarthModel;
use crate::nav_frame::NavFrame;
use crate::rotation::{quaternion_product, rotate, rotation_vector_quaternion};

use super::equations::{State, all_finite, check_initial, earth_terms, finish, keep_unit, start};
use super::{
    NavState, StrapdownError, StrapdownOptions, VerticalChannel, check_baro, check_lengths,
};

/// Steps between checks of the quaternion's norm: a product of unit quaternions drifts from
/// unit length by rounding only, about 1e-16 a step, and a check on every step sits on the
/// recursion's critical path (it cost the flat scheme about a third of its throughput).
const UNIT_CHECK_INTERVAL: usize = 64;

#[inline(always)]
fn finite3(v: &[f64; 3]) -> bool {
    all_finite(v)
}

/// Strapdown on Δθ/Δv increments.
#[derive(Clone, Copy, Debug)]
pub struct Increments<E: EarthModel> {
    earth: E,
    state: State,
    t_s: f64,
    options: StrapdownOptions,
    prev_dtheta: Vector3<f64>,
    prev_dv: Vector3<f64>,
    index: usize,
}

impl<E: EarthModel> Increments<E> {
    /// Starts from `initial` on `earth`.
    ///
    /// # Errors
    /// A non-finite initial state, one outside the frame's domain (beyond ±89.9° on WGS-84),
    /// a baro time constant ≤ 0.
    pub fn new(
        earth: E,
        initial: &NavState<E>,
        options: StrapdownOptions,
    ) -> Result<Self, StrapdownError> {
        check_initial(&earth, initial, &options)?;
        Ok(Self {
            earth,
            state: start(initial, options.vertical),
            t_s: initial.t_s,
            options,
            prev_dtheta: Vector3::zeros(),
            prev_dv: Vector3::zeros(),
            index: 1,
        })
    }

    /// Replaces the state (a filter's correction), keeping the previous increments that the
    /// coning and sculling corrections use.
    ///
    /// # Errors
    /// As [`Self::new`].
    pub fn reset(&mut self, state: &NavState<E>) -> Result<(), StrapdownError> {
        check_initial(&self.earth, state, &self.options)?;
        self.state = start(state, self.options.vertical);
        self.t_s = state.t_s;
        Ok(())
    }

    /// The Earth it runs on.
    #[must_use]
    pub fn earth(&self) -> &E {
        &self.earth
    }

    /// Advances over the interval ending at `t_s` with the increments `dtheta_rad` (∫ω_ib^b dt)
    /// and `dv_m_s` (∫f^b dt); returns the state at `t_s`.
    ///
    /// # Errors
    /// Non-finite input, a time that does not increase, a position outside the frame's domain,
    /// the baro vertical channel (which needs [`Self::step_with_baro`]).
    pub fn step(
        &mut self,
        t_s: f64,
        dtheta_rad: [f64; 3],
        dv_m_s: [f64; 3],
    ) -> Result<NavState<E>, StrapdownError> {
        if matches!(self.options.vertical, VerticalChannel::Baro { .. }) {
            return Err(StrapdownError::BadOption {
                field: "the baro vertical channel needs a barometric height per sample",
            });
        }
        self.step_with_baro(t_s, dtheta_rad, dv_m_s, 0.0)
    }

    /// [`Self::step`] with the barometric height `baro_height_m` the baro vertical channel
    /// damps the height towards (ignored by the other channels).
    ///
    /// # Errors
    /// As [`Self::step`].
    #[inline(always)] // keeps the increments in registers: a caller's stores reloaded as
    // vectors stall on store forwarding
    pub fn step_with_baro(
        &mut self,
        t_s: f64,
        dtheta_rad: [f64; 3],
        dv_m_s: [f64; 3],
        baro_height_m: f64,
    ) -> Result<NavState<E>, StrapdownError> {
        let index = self.index;
        if !(t_s.is_finite()
            && finite3(&dtheta_rad)
            && finite3(&dv_m_s)
            && baro_height_m.is_finite())
        {
            return Err(StrapdownError::NotFinite { index });
        }
        let dt = t_s - self.t_s;
        if dt.is_nan() || dt <= 0.0 {
            return Err(StrapdownError::TimeNotIncreasing { index });
        }
        let dth = Vector3::from(dtheta_rad);
        let dv = Vector3::from(dv_m_s);
        let mut phi = dth;
        if self.options.coning {
            phi += self.prev_dtheta.cross(&dth) / 12.0;
        }
        let mut dv_body = dv;
        if self.options.sculling {
            dv_body += 0.5 * dth.cross(&dv)
                + (self.prev_dtheta.cross(&dv) + self.prev_dv.cross(&dth)) / 12.0;
        }
        let s0 = self.state;
        let mut s1 = self.advance(&s0, &s0, phi, dv_body, dt, baro_height_m);
        if E::ROTATING {
            // Predictor: the Earth's terms at the start; corrector: at the predicted midpoint.
            s1 = self.advance(&s0, &s0.midpoint(&s1), phi, dv_body, dt, baro_height_m);
        }
        if index.is_multiple_of(UNIT_CHECK_INTERVAL) {
            keep_unit(&mut s1.q);
        }
        let out = finish(&self.earth, &mut s1, t_s, index)?;
        self.state = s1;
        self.t_s = t_s;
        self.prev_dtheta = dth;
        self.prev_dv = dv;
        self.index += 1;
        Ok(out)
    }

    /// One interval from `s0` with the Earth's terms evaluated at `mid`.
    #[inline(always)]
    fn advance(
        &self,
        s0: &State,
        mid: &State,
        phi: Vector3<f64>,
        dv_body: Vector3<f64>,
        dt: f64,
        baro_m: f64,
    ) -> State {
        let (acceleration, w_in) = earth_terms(&self.earth, mid);
        let d = rotate(&s0.q, &dv_body);
        let body_turn = rotation_vector_quaternion(&phi);
        let (dv_sf, q) = match w_in {
            Some(w_in) => {
                // Specific force into the navigation frame at the start, less half the
                // frame's turn over the interval.
                let zeta = w_in * dt;
                let frame_turn = rotation_vector_quaternion(&-zeta);
                (
                    d - 0.5 * zeta.cross(&d),
                    quaternion_product(&quaternion_product(&frame_turn, &s0.q), &body_turn),
                )
            }
            None => (d, quaternion_product(&s0.q, &body_turn)),
        };
        let mut v = s0.v + dv_sf + acceleration * dt;
        let v_mid = crate::vector::Vec3::<E::Frame>::from_nalgebra(0.5 * (s0.v + v));
        let rates = self.earth.position_rate(&mid.c, &v_mid);
        let mut c: [f64; 3] = core::array::from_fn(|i| s0.c[i] + rates[i] * dt);
        let mut b = s0.b;
        match self.options.vertical {
            VerticalChannel::Free => {}
            VerticalChannel::Hold => {
                v.z = 0.0;
                c[2] = s0.c[2];
            }
            VerticalChannel::Baro { time_constant_s } => {
                let (k1, k2, k3) =
                    super::equations::baro_gains(&self.earth, time_constant_s, &mid.c);
                let (h, dc_dh) = self.earth.height_m(&mid.c);
                let dh = h - baro_m;
                c[2] -= dc_dh * k1 * dh * dt;
                v.z += -<E::Frame as NavFrame>::Z_UP * (k2 * dh + mid.b) * dt;
                b += k3 * dh * dt;
            }
        }
        State { q, v, c, b }
    }
}

/// Strapdown on rate samples (gyro rad/s, specific force m/s², body frame), turned into
/// increments by the trapezoidal rule between consecutive samples.
#[derive(Clone, Copy, Debug)]
pub struct RateIncrements<E: EarthModel> {
    inner: Increments<E>,
    initial: NavState<E>,
    last: Option<(f64, [f64; 3], [f64; 3])>,
    index: usize,
}

impl<E: EarthModel> RateIncrements<E> {
    /// Starts from `initial` on `earth`; the first sample sets the start time.
    ///
    /// # Errors
    /// As [`Increments::new`].
    pub fn new(
        earth: E,
        initial: NavState<E>,
        options: StrapdownOptions,
    ) -> Result<Self, StrapdownError> {
        Ok(Self {
            inner: Increments::new(earth, &initial, options)?,
            initial,
            last: None,
            index: 0,
        })
    }

    /// Takes one sample; the first returns the initial state at its time.
    ///
    /// # Errors
    /// Non-finite values or non-increasing times, with the sample index; as
    /// [`Increments::step`].
    pub fn step(
        &mut self,
        t_s: f64,
        gyro_rad_s: [f64; 3],
        accel_m_s2: [f64; 3],
    ) -> Result<NavState<E>, StrapdownError> {
        self.sample(t_s, gyro_rad_s, accel_m_s2, None)
    }

    /// [`Self::step`] with the barometric height `baro_height_m` the baro vertical channel damps
    /// the interval ending at `t_s` towards (ignored by the other channels and by the first
    /// sample).
    ///
    /// # Errors
    /// As [`Self::step`] and [`Increments::step_with_baro`].
    pub fn step_with_baro(
        &mut self,
        t_s: f64,
        gyro_rad_s: [f64; 3],
        accel_m_s2: [f64; 3],
        baro_height_m: f64,
    ) -> Result<NavState<E>, StrapdownError> {
        self.sample(t_s, gyro_rad_s, accel_m_s2, Some(baro_height_m))
    }

    /// One sample: the trapezoid of the rates since the last one as increments.
    #[inline(always)]
    fn sample(
        &mut self,
        t_s: f64,
        gyro_rad_s: [f64; 3],
        accel_m_s2: [f64; 3],
        baro_height_m: Option<f64>,
    ) -> Result<NavState<E>, StrapdownError> {
        let index = self.index;
        if !(t_s.is_finite() && finite3(&gyro_rad_s) && finite3(&accel_m_s2)) {
            return Err(StrapdownError::NotFinite { index });
        }
        let out = match self.last {
            None => {
                self.inner.t_s = t_s;
                Ok(NavState {
                    t_s,
                    ..self.initial
                })
            }
            Some((t0, w0, f0)) => {
                let h = 0.5 * (t_s - t0);
                if h <= 0.0 {
                    return Err(StrapdownError::TimeNotIncreasing { index });
                }
                let dth = core::array::from_fn(|i| h * (w0[i] + gyro_rad_s[i]));
                let dv = core::array::from_fn(|i| h * (f0[i] + accel_m_s2[i]));
                self.inner.index = index;
                match baro_height_m {
                    None => self.inner.step(t_s, dth, dv),
                    Some(b) => self.inner.step_with_baro(t_s, dth, dv, b),
                }
            }
        };
        self.last = Some((t_s, gyro_rad_s, accel_m_s2));
        self.index += 1;
        out
    }
}

/// Strapdown over rate samples on slices, written into `out` (same length; `out[0]` is the
/// initial state at `t_s[0]`); `baro_height_m` gives the barometric height per sample for
/// [`VerticalChannel::Baro`] (required then, ignored otherwise; the interval ending at
/// `t_s[i]` uses entry `i − 1`, as [`strapdown_increments`]).
///
/// # Errors
/// As [`RateIncrements::step`]; mismatched lengths; a baro channel without heights.
#[allow(clippy::too_many_arguments)]
pub fn strapdown_rates<E: EarthModel>(
    earth: E,
    t_s: &[f64],
    gyro_rad_s: &[[f64; 3]],
    accel_m_s2: &[[f64; 3]],
    baro_height_m: Option<&[f64]>,
    initial: NavState<E>,
    options: StrapdownOptions,
    out: &mut [NavState<E>],
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
    let baro = check_baro(n, baro_height_m, &options)?;
    let mut nav = RateIncrements::new(earth, initial, options)?;
    for i in 0..n {
        out[i] = match baro {
            None => nav.step(t_s[i], gyro_rad_s[i], accel_m_s2[i])?,
            Some(b) => {
                let baro_i = if i == 0 { 0.0 } else { b[i - 1] };
                if !baro_i.is_finite() {
                    return Err(StrapdownError::NotFinite { index: i - 1 });
                }
                nav.step_with_baro(t_s[i], gyro_rad_s[i], accel_m_s2[i], baro_i)?
            }
        };
    }
    Ok(())
}

/// Strapdown over Δθ/Δv increments on slices (`dtheta[i]`, `dv[i]` over the interval ending at
/// `t_s[i]`; entry 0 is ignored), written into `out` (`out[0]` is the initial state at
/// `t_s[0]`); `baro_height_m` gives the barometric height per sample for
/// [`VerticalChannel::Baro`] (required then, ignored otherwise; the interval ending at
/// `t_s[i]` uses entry `i − 1`).
///
/// # Errors
/// As [`Increments::step`]; mismatched lengths; a baro channel without heights.
#[allow(clippy::too_many_arguments)]
pub fn strapdown_increments<E: EarthModel>(
    earth: E,
    t_s: &[f64],
    dtheta_rad: &[[f64; 3]],
    dv_m_s: &[[f64; 3]],
    baro_height_m: Option<&[f64]>,
    initial: NavState<E>,
    options: StrapdownOptions,
    out: &mut [NavState<E>],
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
    let baro = check_baro(n, baro_height_m, &options)?;
    if n == 0 {
        return Ok(());
    }
    let first = NavState {
        t_s: t_s[0],
        ..initial
    };
    let mut nav = Increments::new(earth, &first, options)?;
    out[0] = first;
    for i in 1..n {
        let baro_i = baro.map_or(0.0, |b| b[i - 1]);
        if !baro_i.is_finite() {
            return Err(StrapdownError::NotFinite { index: i - 1 });
        }
        out[i] = nav.step_with_baro(t_s[i], dtheta_rad[i], dv_m_s[i], baro_i)?;
    }
    Ok(())
}
