//! Strapdown navigation on the rotating WGS-84 Earth: the local-NED mechanization with Earth
//! rate, transport rate, Coriolis and normal gravity (Groves, 2nd ed., §5.4; Titterton & Weston,
//! 2nd ed., §3.5 and §11.2), per sample and without heap.
//!
//! The navigation equations, state `(q_nb, v^n, φ, λ, h)`:
//! * `q̇_nb = ½ q_nb ⊗ (0, ω_ib^b) − ½ (0, ω_in^n) ⊗ q_nb`, `ω_in^n = ω_ie^n + ω_en^n`;
//! * `v̇^n = C_nb f^b + g^n − (2 ω_ie^n + ω_en^n) × v^n`, `g^n = [0, 0, γ(φ, h)]`;
//! * `φ̇ = v_N/(R_N + h)`, `λ̇ = v_E/((R_E + h) cos φ)`, `ḣ = −v_D` (the vertical channel, see
//!   [`VerticalChannel`]).
//!
//! Two schemes, as on the flat Earth: [`EarthRk4`] integrates rate samples by classical RK4 with
//! the quintic interpolation of [`rk4`](super::rk4) (fourth order), and [`EarthIncrements`] takes
//! Δθ/Δv increments with the two-sample coning and sculling corrections of [`step`](super::step)
//! plus the navigation-frame rotation over the interval, the Earth terms evaluated at the
//! interval's midpoint by one predictor–corrector pass (second order).
//!
//! The NED frame is refused beyond |φ| = 89.9° ([`MAX_LATITUDE_RAD`]), where `tan φ` in the
//! transport rate and `1/cos φ` in the longitude rate grow without bound.
use nalgebra::{Quaternion, UnitQuaternion, Vector3};

use crate::earth::gravity::GravityModel;
use crate::earth::rates::{MAX_LATITUDE_RAD, earth_rate_ned, geodetic_rates, transport_rate_ned};
use crate::earth::wgs84::Geodetic;
use crate::frame::{Body, Ned};
use crate::math;
use crate::rotation::Rotation;
use crate::strapdown::rk4::{NODES, RateWindow, lagrange};
use crate::strapdown::step::{StrapdownError, StrapdownOptions};
use crate::vector::Vec3;

/// The navigation state on the Earth.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EarthNavState {
    /// Time, s.
    pub t_s: f64,
    /// Attitude `C_nb` relative to the local NED frame.
    pub attitude: Rotation<Body, Ned>,
    /// Ground velocity `v^n`, local NED, m/s.
    pub velocity_m_s: Vec3<Ned>,
    /// Geodetic position.
    pub position: Geodetic,
}

impl Default for EarthNavState {
    fn default() -> Self {
        Self {
            t_s: 0.0,
            attitude: Rotation::identity(),
            velocity_m_s: Vec3::zeros(),
            position: Geodetic::default(),
        }
    }
}

/// How the height is found: the inertial vertical channel is unstable (a height error `δh`
/// makes gravity too small by `2γ/R·δh`, so errors grow as `cosh(t/τ)`, `τ = √(R/2g) ≈ 570 s`).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub enum VerticalChannel {
    /// Integrated freely, unstable as physics says (the default).
    #[default]
    Free,
    /// Held at the initial height with zero vertical velocity (ships, cars on flat ground,
    /// studies of the horizontal channels).
    Hold,
    /// Damped by a barometric altitude with Widnall and Sinha's third-order loop, its three
    /// poles at `−1/time_constant_s`: `ḣ = −v_D − k₁ δh`, `v̇_D += k₂ δh + b`, `ḃ = k₃ δh`
    /// (`δh = h − h_baro`, `b` the loop's acceleration correction), `k₁ = 3/τ`,
    /// `k₂ = 3/τ² + 2γ/R`, `k₃ = 1/τ³`: the height error then obeys
    /// `s³ + k₁ s² + (k₂ − 2γ/R) s + k₃ = (s + 1/τ)³`.
    Baro {
        /// Loop time constant, s (> 0; 100 s is usual).
        time_constant_s: f64,
    },
}

/// The Earth mechanization's options.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct EarthOptions {
    /// Gravity model (WGS-84 normal gravity by default).
    pub gravity: GravityModel,
    /// The vertical channel.
    pub vertical: VerticalChannel,
    /// Coning and sculling corrections (increments scheme).
    pub corrections: Corrections,
}

/// Which two-sample corrections the increments scheme applies (both by default).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Corrections {
    /// Two-sample coning correction.
    pub coning: bool,
    /// Rotation and two-sample sculling terms.
    pub sculling: bool,
}

impl Default for Corrections {
    fn default() -> Self {
        Self {
            coning: true,
            sculling: true,
        }
    }
}

impl From<&StrapdownOptions> for Corrections {
    fn from(o: &StrapdownOptions) -> Self {
        Self {
            coning: o.coning,
            sculling: o.sculling,
        }
    }
}

/// The continuous state integrated by the schemes: attitude, velocity, latitude, longitude,
/// height and the baro loop's acceleration correction.
#[derive(Clone, Copy, Debug)]
struct State {
    q: Quaternion<f64>,
    v: Vector3<f64>,
    /// `[φ, λ, h]`.
    p: [f64; 3],
    /// Baro loop correction, m/s² (down).
    b: f64,
}

impl State {
    fn geodetic(&self) -> Geodetic {
        Geodetic {
            latitude_rad: self.p[0],
            longitude_rad: self.p[1],
            height_m: self.p[2],
        }
    }

    fn add(&self, d: &State, h: f64) -> State {
        State {
            q: self.q + d.q * h,
            v: self.v + d.v * h,
            p: core::array::from_fn(|i| self.p[i] + d.p[i] * h),
            b: self.b + d.b * h,
        }
    }
}

/// Earth terms of the velocity equation and the navigation-frame rate at `s`: `(g^n − (2ω_ie
/// + ω_en) × v, ω_in^n)`.
fn earth_terms(s: &State, gravity: &GravityModel) -> (Vector3<f64>, Vector3<f64>) {
    let p = s.geodetic();
    let v = Vec3::<Ned>::from_nalgebra(s.v);
    let w_ie = earth_rate_ned(&p);
    let w_en = transport_rate_ned(&p, v);
    let g = Vector3::new(0.0, 0.0, gravity.magnitude_m_s2(&p));
    let coriolis = (w_ie * 2.0 + w_en).cross(&v);
    (g - coriolis.as_nalgebra(), *(w_ie + w_en).as_nalgebra())
}

/// The vertical channel's gains `(k₁, k₂, k₃)` for the baro loop at position `p`.
fn baro_gains(tau_s: f64, p: &Geodetic, gravity: &GravityModel) -> (f64, f64, f64) {
    let (r_n, r_e) = p.radii_m();
    let r = math::sqrt(r_n * r_e);
    let g = gravity.magnitude_m_s2(p);
    (
        3.0 / tau_s,
        3.0 / (tau_s * tau_s) + 2.0 * g / r,
        1.0 / (tau_s * tau_s * tau_s),
    )
}

struct Inputs<'a> {
    gravity: &'a GravityModel,
    vertical: VerticalChannel,
    /// Barometric height for the baro loop, m.
    baro_m: f64,
}

fn derivative(s: &State, w: [f64; 3], f: [f64; 3], inputs: &Inputs<'_>) -> State {
    let (earth, w_in) = earth_terms(s, inputs.gravity);
    let q_dot = (s.q * Quaternion::new(0.0, w[0], w[1], w[2])
        - Quaternion::new(0.0, w_in.x, w_in.y, w_in.z) * s.q)
        * 0.5;
    let c_nb = UnitQuaternion::new_unchecked(s.q);
    let mut v_dot = c_nb * Vector3::from(f) + earth;
    let rates = geodetic_rates(&s.geodetic(), Vec3::from_nalgebra(s.v));
    let mut p_dot = rates;
    let mut b_dot = 0.0;
    match inputs.vertical {
        VerticalChannel::Free => {}
        VerticalChannel::Hold => {
            v_dot.z = 0.0;
            p_dot[2] = 0.0;
        }
        VerticalChannel::Baro { time_constant_s } => {
            let (k1, k2, k3) = baro_gains(time_constant_s, &s.geodetic(), inputs.gravity);
            let dh = s.p[2] - inputs.baro_m;
            p_dot[2] -= k1 * dh;
            v_dot.z += k2 * dh + s.b;
            b_dot = k3 * dh;
        }
    }
    State {
        q: q_dot,
        v: v_dot,
        p: p_dot,
        b: b_dot,
    }
}

fn check_latitude(latitude_rad: f64, index: usize) -> Result<(), StrapdownError> {
    if math::abs(latitude_rad) > MAX_LATITUDE_RAD || !latitude_rad.is_finite() {
        return Err(StrapdownError::NearPole { index });
    }
    Ok(())
}

fn finish(s: &mut State, t_s: f64, index: usize) -> Result<EarthNavState, StrapdownError> {
    s.q = s.q.normalize();
    check_latitude(s.p[0], index)?;
    let two_pi = 2.0 * core::f64::consts::PI;
    // Longitude in (−π, π].
    if s.p[1] > core::f64::consts::PI || s.p[1] <= -core::f64::consts::PI {
        s.p[1] -= two_pi * math::round(s.p[1] / two_pi);
    }
    let out = EarthNavState {
        t_s,
        attitude: Rotation::assume_from_quaternion(UnitQuaternion::new_unchecked(s.q)),
        velocity_m_s: Vec3::from_nalgebra(s.v),
        position: s.geodetic(),
    };
    let finite =
        s.v.iter()
            .chain(&s.p)
            .chain(s.q.coords.iter())
            .all(|v| v.is_finite());
    if finite {
        Ok(out)
    } else {
        Err(StrapdownError::NotFinite { index })
    }
}

fn start(initial: &EarthNavState, vertical: VerticalChannel) -> State {
    let p = &initial.position;
    let mut v = *initial.velocity_m_s.as_nalgebra();
    if vertical == VerticalChannel::Hold {
        v.z = 0.0;
    }
    State {
        q: *initial.attitude.quaternion().quaternion(),
        v,
        p: [p.latitude_rad, p.longitude_rad, p.height_m],
        b: 0.0,
    }
}

/// Checks an initial state: finite, away from the poles, a positive baro time constant.
fn check_initial(initial: &EarthNavState, options: &EarthOptions) -> Result<(), StrapdownError> {
    let p = &initial.position;
    let finite = [initial.t_s, p.latitude_rad, p.longitude_rad, p.height_m]
        .iter()
        .chain(initial.velocity_m_s.as_nalgebra().iter())
        .all(|v| v.is_finite());
    if !finite {
        return Err(StrapdownError::NotFinite { index: 0 });
    }
    check_latitude(p.latitude_rad, 0)?;
    if let VerticalChannel::Baro { time_constant_s } = options.vertical
        && !(time_constant_s.is_finite() && time_constant_s > 0.0)
    {
        return Err(StrapdownError::BadOption {
            field: "vertical baro time constant (must be finite and > 0 s)",
        });
    }
    Ok(())
}

/// The fourth-order scheme on rate samples, one interval at a time (the caller hands each
/// interval's six-sample window, as for [`Rk4Strapdown`](super::rk4::Rk4Strapdown)).
#[derive(Clone, Copy, Debug)]
pub struct EarthRk4 {
    state: State,
    options: EarthOptions,
    substeps: usize,
}

impl EarthRk4 {
    /// Starts from `initial` with `substeps` (≥ 1; 0 counts as 1) RK4 steps per interval.
    ///
    /// # Errors
    /// A non-finite initial state, a latitude beyond ±89.9°, a baro time constant ≤ 0.
    pub fn new(
        initial: &EarthNavState,
        options: EarthOptions,
        substeps: usize,
    ) -> Result<Self, StrapdownError> {
        check_initial(initial, &options)?;
        Ok(Self {
            state: start(initial, options.vertical),
            options,
            substeps: substeps.max(1),
        })
    }

    /// Integrates from `w.t_s[j]` to `w.t_s[j + 1]` (`j < 5`; values finite, times increasing,
    /// checked by the callers) with the barometric height `baro_height_m` (used by
    /// [`VerticalChannel::Baro`] only), and returns the state there; `index` names the sample
    /// in errors.
    ///
    /// # Errors
    /// The latitude leaves ±89.9° ([`StrapdownError::NearPole`]) or the state stops being
    /// finite.
    pub fn interval(
        &mut self,
        w: &RateWindow,
        j: usize,
        baro_height_m: f64,
        index: usize,
    ) -> Result<EarthNavState, StrapdownError> {
        let inputs = Inputs {
            gravity: &self.options.gravity,
            vertical: self.options.vertical,
            baro_m: baro_height_m,
        };
        let m = self.substeps;
        let h = (w.t_s[j + 1] - w.t_s[j]) / m as f64;
        let at = |x: f64| -> ([f64; 3], [f64; 3]) {
            let l = lagrange(&w.t_s, x);
            let sum = |s: &[[f64; 3]; NODES]| -> [f64; 3] {
                core::array::from_fn(|i| (0..NODES).map(|k| l[k] * s[k][i]).sum())
            };
            (sum(&w.gyro_rad_s), sum(&w.accel_m_s2))
        };
        let mut s = self.state;
        for step in 0..m {
            let t0 = w.t_s[j] + step as f64 * h;
            let (w0, f0) = if step == 0 {
                (w.gyro_rad_s[j], w.accel_m_s2[j])
            } else {
                at(t0)
            };
            let (wm, fm) = at(t0 + 0.5 * h);
            let (w1, f1) = if step + 1 == m {
                (w.gyro_rad_s[j + 1], w.accel_m_s2[j + 1])
            } else {
                at(t0 + h)
            };
            let k1 = derivative(&s, w0, f0, &inputs);
            let k2 = derivative(&s.add(&k1, 0.5 * h), wm, fm, &inputs);
            let k3 = derivative(&s.add(&k2, 0.5 * h), wm, fm, &inputs);
            let k4 = derivative(&s.add(&k3, h), w1, f1, &inputs);
            s = State {
                q: s.q + (k1.q + k2.q * 2.0 + k3.q * 2.0 + k4.q) * (h / 6.0),
                v: s.v + (k1.v + k2.v * 2.0 + k3.v * 2.0 + k4.v) * (h / 6.0),
                p: core::array::from_fn(|i| {
                    s.p[i] + (k1.p[i] + 2.0 * k2.p[i] + 2.0 * k3.p[i] + k4.p[i]) * (h / 6.0)
                }),
                b: s.b + (k1.b + 2.0 * k2.b + 2.0 * k3.b + k4.b) * (h / 6.0),
            };
            s.q = s.q.normalize();
            check_latitude(s.p[0], index)?;
        }
        let out = finish(&mut s, w.t_s[j + 1], index)?;
        self.state = s;
        Ok(out)
    }
}

/// The second-order scheme on Δθ/Δv increments (coning and sculling), per interval.
#[derive(Clone, Copy, Debug)]
pub struct EarthIncrements {
    state: State,
    t_s: f64,
    options: EarthOptions,
    prev_dtheta: Vector3<f64>,
    prev_dv: Vector3<f64>,
    index: usize,
}

impl EarthIncrements {
    /// Starts from `initial`.
    ///
    /// # Errors
    /// As [`EarthRk4::new`].
    pub fn new(initial: &EarthNavState, options: EarthOptions) -> Result<Self, StrapdownError> {
        check_initial(initial, &options)?;
        Ok(Self {
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
    /// As [`EarthIncrements::new`].
    pub fn reset(&mut self, state: &EarthNavState) -> Result<(), StrapdownError> {
        check_initial(state, &self.options)?;
        self.state = start(state, self.options.vertical);
        self.t_s = state.t_s;
        Ok(())
    }

    /// Advances over the interval ending at `t_s` with the increments `dtheta_rad` (∫ω_ib^b dt)
    /// and `dv_m_s` (∫f^b dt), and the barometric height (baro loop only).
    ///
    /// # Errors
    /// Non-finite input, a time that does not increase, a latitude beyond ±89.9°.
    pub fn step(
        &mut self,
        t_s: f64,
        dtheta_rad: [f64; 3],
        dv_m_s: [f64; 3],
        baro_height_m: f64,
    ) -> Result<EarthNavState, StrapdownError> {
        let index = self.index;
        let finite = [t_s]
            .iter()
            .chain(&dtheta_rad)
            .chain(&dv_m_s)
            .all(|v| v.is_finite());
        if !finite {
            return Err(StrapdownError::NotFinite { index });
        }
        let dt = t_s - self.t_s;
        if dt.is_nan() || dt <= 0.0 {
            return Err(StrapdownError::TimeNotIncreasing { index });
        }
        let dth = Vector3::from(dtheta_rad);
        let dv = Vector3::from(dv_m_s);
        let c = self.options.corrections;
        let mut phi = dth;
        if c.coning {
            phi += self.prev_dtheta.cross(&dth) / 12.0;
        }
        let mut dv_body = dv;
        if c.sculling {
            dv_body += 0.5 * dth.cross(&dv)
                + (self.prev_dtheta.cross(&dv) + self.prev_dv.cross(&dth)) / 12.0;
        }
        let inputs = Inputs {
            gravity: &self.options.gravity,
            vertical: self.options.vertical,
            baro_m: baro_height_m,
        };
        let s0 = self.state;
        // Predictor: the Earth terms at the start; corrector: at the midpoint of the prediction.
        let mut mid = s0;
        let mut s1 = s0;
        for _ in 0..2 {
            s1 = self.advance(&s0, &mid, phi, dv_body, dt, &inputs);
            mid = State {
                q: (s0.q + s1.q).normalize(),
                v: (s0.v + s1.v) * 0.5,
                p: core::array::from_fn(|i| 0.5 * (s0.p[i] + s1.p[i])),
                b: 0.5 * (s0.b + s1.b),
            };
        }
        let out = finish(&mut s1, t_s, index)?;
        self.state = s1;
        self.t_s = t_s;
        self.prev_dtheta = dth;
        self.prev_dv = dv;
        self.index += 1;
        Ok(out)
    }

    /// One interval from `s0` with the Earth terms evaluated at `mid`.
    fn advance(
        &self,
        s0: &State,
        mid: &State,
        phi: Vector3<f64>,
        dv_body: Vector3<f64>,
        dt: f64,
        inputs: &Inputs<'_>,
    ) -> State {
        let (earth, w_in) = earth_terms(mid, inputs.gravity);
        let zeta = w_in * dt;
        let c0 = UnitQuaternion::new_unchecked(s0.q);
        // Specific force into the navigation frame at the start, less half the frame's turn.
        let dv_sf = {
            let d = c0 * dv_body;
            d - 0.5 * zeta.cross(&d)
        };
        let q =
            UnitQuaternion::from_scaled_axis(-zeta) * c0 * UnitQuaternion::from_scaled_axis(phi);
        let mut v = s0.v + dv_sf + earth * dt;
        let v_mid = 0.5 * (s0.v + v);
        let rates = geodetic_rates(&mid.geodetic(), Vec3::from_nalgebra(v_mid));
        let mut p: [f64; 3] = core::array::from_fn(|i| s0.p[i] + rates[i] * dt);
        let mut b = s0.b;
        match inputs.vertical {
            VerticalChannel::Free => {}
            VerticalChannel::Hold => {
                v.z = 0.0;
                p[2] = s0.p[2];
            }
            VerticalChannel::Baro { time_constant_s } => {
                let (k1, k2, k3) = baro_gains(time_constant_s, &mid.geodetic(), inputs.gravity);
                let dh = mid.p[2] - inputs.baro_m;
                p[2] -= k1 * dh * dt;
                v.z += (k2 * dh + mid.b) * dt;
                b += k3 * dh * dt;
            }
        }
        State {
            q: *q.quaternion(),
            v,
            p,
            b,
        }
    }
}

/// The Earth mechanization over rate samples by RK4 (`substeps` per interval), written into
/// `out` (same length; `out[0]` is `initial` at `t_s[0]`); `baro_height_m` gives the barometric
/// height per sample for [`VerticalChannel::Baro`] (required then, ignored otherwise). Needs at
/// least 6 samples.
///
/// # Errors
/// Mismatched lengths, fewer than 6 samples, non-finite values, times that do not increase, a
/// latitude beyond ±89.9°, a baro channel without heights.
#[allow(clippy::too_many_arguments)]
pub fn strapdown_rates_earth(
    t_s: &[f64],
    gyro_rad_s: &[[f64; 3]],
    accel_m_s2: &[[f64; 3]],
    baro_height_m: Option<&[f64]>,
    initial: &EarthNavState,
    options: EarthOptions,
    substeps: usize,
    out: &mut [EarthNavState],
) -> Result<(), StrapdownError> {
    let n = t_s.len();
    crate::strapdown::step::check_lengths(
        n,
        &[
            ("gyro_rad_s", gyro_rad_s.len()),
            ("accel_m_s2", accel_m_s2.len()),
            ("output", out.len()),
        ],
    )?;
    let baro = check_baro(n, baro_height_m, &options)?;
    if n < NODES {
        return Err(StrapdownError::LengthMismatch {
            field: "samples (RK4 needs at least 6)",
            expected: NODES,
            got: n,
        });
    }
    for i in 0..n {
        let finite = t_s[i].is_finite()
            && gyro_rad_s[i]
                .iter()
                .chain(&accel_m_s2[i])
                .all(|c| c.is_finite())
            && baro.is_none_or(|b| b[i].is_finite());
        if !finite {
            return Err(StrapdownError::NotFinite { index: i });
        }
        if i > 0 && t_s[i] <= t_s[i - 1] {
            return Err(StrapdownError::TimeNotIncreasing { index: i });
        }
    }
    let first = EarthNavState {
        t_s: t_s[0],
        ..*initial
    };
    let mut nav = EarthRk4::new(&first, options, substeps)?;
    out[0] = first;
    for k in 0..n - 1 {
        let start = crate::strapdown::rk4::window_start(k, n);
        let window = RateWindow {
            t_s: core::array::from_fn(|j| t_s[start + j]),
            gyro_rad_s: core::array::from_fn(|j| gyro_rad_s[start + j]),
            accel_m_s2: core::array::from_fn(|j| accel_m_s2[start + j]),
        };
        let baro_k = baro.map_or(0.0, |b| b[k]);
        out[k + 1] = nav.interval(&window, k - start, baro_k, k + 1)?;
    }
    Ok(())
}

/// The Earth mechanization over Δθ/Δv increments (`dtheta[i]`, `dv[i]` over the interval ending
/// at `t_s[i]`; entry 0 ignored), written into `out` (`out[0]` is `initial` at `t_s[0]`).
///
/// # Errors
/// As [`EarthIncrements::step`]; mismatched lengths; a baro channel without heights.
#[allow(clippy::too_many_arguments)]
pub fn strapdown_increments_earth(
    t_s: &[f64],
    dtheta_rad: &[[f64; 3]],
    dv_m_s: &[[f64; 3]],
    baro_height_m: Option<&[f64]>,
    initial: &EarthNavState,
    options: EarthOptions,
    out: &mut [EarthNavState],
) -> Result<(), StrapdownError> {
    let n = t_s.len();
    crate::strapdown::step::check_lengths(
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
    let first = EarthNavState {
        t_s: t_s[0],
        ..*initial
    };
    let mut nav = EarthIncrements::new(&first, options)?;
    out[0] = first;
    for i in 1..n {
        let baro_i = baro.map_or(0.0, |b| b[i - 1]);
        if !baro_i.is_finite() {
            return Err(StrapdownError::NotFinite { index: i - 1 });
        }
        out[i] = nav.step(t_s[i], dtheta_rad[i], dv_m_s[i], baro_i)?;
    }
    Ok(())
}

/// The barometric heights the vertical channel needs: required (of length `n`) for the baro
/// loop, ignored otherwise.
fn check_baro<'a>(
    n: usize,
    baro: Option<&'a [f64]>,
    options: &EarthOptions,
) -> Result<Option<&'a [f64]>, StrapdownError> {
    match (options.vertical, baro) {
        (VerticalChannel::Baro { .. }, None) => Err(StrapdownError::BadOption {
            field: "the baro vertical channel needs a barometric height per sample",
        }),
        (VerticalChannel::Baro { .. }, Some(b)) => {
            crate::strapdown::step::check_lengths(n, &[("baro_height_m", b.len())])?;
            Ok(Some(b))
        }
        _ => Ok(None),
    }
}
