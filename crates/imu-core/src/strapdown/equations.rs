//! The navigation equations both schemes integrate, on any [`EarthModel`]: the continuous
//! state, its derivative, the vertical channel, and the checks at the start and after each
//! interval.
use nalgebra::{Quaternion, UnitQuaternion, Vector3};

use crate::earth::EarthModel;
use crate::nav_frame::NavFrame;
use crate::rotation::Rotation;
use crate::vector::Vec3;

use super::{NavState, StrapdownError, StrapdownOptions, VerticalChannel};

/// The continuous state: attitude, velocity, position coordinates and the baro loop's
/// acceleration correction.
#[derive(Clone, Copy, Debug)]
pub(crate) struct State {
    pub(crate) q: Quaternion<f64>,
    pub(crate) v: Vector3<f64>,
    pub(crate) c: [f64; 3],
    /// Baro loop correction, m/s² (up).
    pub(crate) b: f64,
}

impl State {
    #[inline(always)]
    pub(crate) fn add(&self, d: &State, h: f64) -> State {
        State {
            q: self.q + d.q * h,
            v: self.v + d.v * h,
            c: core::array::from_fn(|i| self.c[i] + d.c[i] * h),
            b: self.b + d.b * h,
        }
    }

    /// The state halfway between `self` and `other`.
    pub(crate) fn midpoint(&self, other: &State) -> State {
        State {
            q: (self.q + other.q).normalize(),
            v: (self.v + other.v) * 0.5,
            c: core::array::from_fn(|i| 0.5 * (self.c[i] + other.c[i])),
            b: 0.5 * (self.b + other.b),
        }
    }
}

/// Whether every value is finite: `x − x` is 0 for a finite `x` and NaN for an infinite or NaN
/// one, so the sum is 0 exactly when all are finite (no branch per value).
#[inline(always)]
#[allow(clippy::eq_op)] // `x − x` is the test itself
pub(crate) fn all_finite(values: &[f64]) -> bool {
    values.iter().map(|x| x - x).sum::<f64>() == 0.0
}

/// Keeps `q` a unit quaternion: rescaled when its squared norm has drifted from 1 by more
/// than 1e-12. A product of unit quaternions drifts by rounding only (about 1e-16 a step), so
/// this rarely rescales; the increments scheme checks every few dozen steps.
#[inline(always)]
pub(crate) fn keep_unit(q: &mut Quaternion<f64>) {
    let n2 = q.norm_squared();
    if (n2 - 1.0).abs() > 1e-12 {
        *q /= crate::math::sqrt(n2);
    }
}

/// `−Z_UP`: +1 where the frame's z axis points down.
fn down<E: EarthModel>() -> f64 {
    -<E::Frame as NavFrame>::Z_UP
}

/// The Earth's terms of the velocity equation and the frame's rate at `s`:
/// `(g^n − (2ω_ie + ω_en) × v, ω_in^n)`, the rate `None` when the frame does not turn.
#[inline(always)]
pub(crate) fn earth_terms<E: EarthModel>(
    earth: &E,
    s: &State,
) -> (Vector3<f64>, Option<Vector3<f64>>) {
    let v = Vec3::<E::Frame>::from_nalgebra(s.v);
    let t = earth.terms(&s.c, &v);
    if !E::ROTATING {
        return (*t.gravity_m_s2.as_nalgebra(), None);
    }
    let coriolis = (t.earth_rate_rad_s * 2.0 + t.transport_rate_rad_s).cross(&v);
    (
        *(t.gravity_m_s2 - coriolis).as_nalgebra(),
        Some(*(t.earth_rate_rad_s + t.transport_rate_rad_s).as_nalgebra()),
    )
}

/// The vertical channel's gains `(k₁, k₂, k₃)` for the baro loop at `c`.
pub(crate) fn baro_gains<E: EarthModel>(earth: &E, tau_s: f64, c: &[f64; 3]) -> (f64, f64, f64) {
    let v = Vec3::<E::Frame>::zeros();
    let g = down::<E>() * earth.terms(c, &v).gravity_m_s2.z();
    (
        3.0 / tau_s,
        3.0 / (tau_s * tau_s) + 2.0 * g / earth.radius_m(c),
        1.0 / (tau_s * tau_s * tau_s),
    )
}

/// What the vertical channel adds to the rates at `s` (the baro loop) or holds (hold), given
/// the barometric height `baro_m`: changes `v_dot`, `c_dot` and returns `ḃ`.
#[inline(always)]
pub(crate) fn vertical_rates<E: EarthModel>(
    earth: &E,
    vertical: VerticalChannel,
    s: &State,
    baro_m: f64,
    v_dot: &mut Vector3<f64>,
    c_dot: &mut [f64; 3],
) -> f64 {
    match vertical {
        VerticalChannel::Free => 0.0,
        VerticalChannel::Hold => {
            v_dot.z = 0.0;
            c_dot[2] = 0.0;
            0.0
        }
        VerticalChannel::Baro { time_constant_s } => {
            let (k1, k2, k3) = baro_gains(earth, time_constant_s, &s.c);
            let (h, dc_dh) = earth.height_m(&s.c);
            let dh = h - baro_m;
            c_dot[2] -= dc_dh * k1 * dh;
            v_dot.z += down::<E>() * (k2 * dh + s.b);
            k3 * dh
        }
    }
}

/// The state's time derivative for body rate `w` and specific force `f`.
#[inline(always)]
pub(crate) fn derivative<E: EarthModel>(
    earth: &E,
    vertical: VerticalChannel,
    s: &State,
    w: [f64; 3],
    f: [f64; 3],
    baro_m: f64,
) -> State {
    let (acceleration, w_in) = earth_terms(earth, s);
    let turn = s.q * Quaternion::new(0.0, w[0], w[1], w[2]);
    let q_dot = match w_in {
        Some(w_in) => (turn - Quaternion::new(0.0, w_in.x, w_in.y, w_in.z) * s.q) * 0.5,
        None => turn * 0.5,
    };
    let c_nb = UnitQuaternion::from_quaternion(s.q);
    let mut v_dot = c_nb * Vector3::from(f) + acceleration;
    let mut c_dot = earth.position_rate(&s.c, &Vec3::from_nalgebra(s.v));
    let b_dot = vertical_rates(earth, vertical, s, baro_m, &mut v_dot, &mut c_dot);
    State {
        q: q_dot,
        v: v_dot,
        c: c_dot,
        b: b_dot,
    }
}

fn in_domain<E: EarthModel>(earth: &E, c: &[f64; 3], index: usize) -> Result<(), StrapdownError> {
    if earth.in_domain(c) {
        Ok(())
    } else {
        Err(StrapdownError::NearPole { index })
    }
}

/// The state after an interval (its quaternion normalised and finite by the scheme): in the
/// frame's domain, coordinates wrapped, finite; the navigation state at `t_s`.
pub(crate) fn finish<E: EarthModel>(
    earth: &E,
    s: &mut State,
    t_s: f64,
    index: usize,
) -> Result<NavState<E>, StrapdownError> {
    in_domain(earth, &s.c, index)?;
    s.c = earth.wrap(s.c);
    // The attitude is a product of unit quaternions of finite angles (increments), or checked by
    // the scheme (RK4): velocity and position are what finite inputs can overflow.
    if !all_finite(&[s.v.x, s.v.y, s.v.z, s.c[0], s.c[1], s.c[2]]) {
        return Err(StrapdownError::NotFinite { index });
    }
    Ok(NavState {
        t_s,
        attitude: Rotation::assume_from_quaternion(UnitQuaternion::new_unchecked(s.q)),
        velocity_m_s: Vec3::from_nalgebra(s.v),
        position: E::position(s.c),
    })
}

/// The continuous state of a navigation state (the vertical velocity zero when held).
pub(crate) fn start<E: EarthModel>(initial: &NavState<E>, vertical: VerticalChannel) -> State {
    let mut v = *initial.velocity_m_s.as_nalgebra();
    if vertical == VerticalChannel::Hold {
        v.z = 0.0;
    }
    State {
        q: *initial.attitude.quaternion().quaternion(),
        v,
        c: E::coordinates(&initial.position),
        b: 0.0,
    }
}

/// Checks an initial state: finite, in the frame's domain, a positive baro time constant.
pub(crate) fn check_initial<E: EarthModel>(
    earth: &E,
    initial: &NavState<E>,
    options: &StrapdownOptions,
) -> Result<(), StrapdownError> {
    let c = E::coordinates(&initial.position);
    let finite = [initial.t_s]
        .iter()
        .chain(&c)
        .chain(initial.velocity_m_s.as_nalgebra().iter())
        .all(|v| v.is_finite());
    if !finite {
        return Err(StrapdownError::NotFinite { index: 0 });
    }
    in_domain(earth, &c, 0)?;
    if let VerticalChannel::Baro { time_constant_s } = options.vertical
        && !(time_constant_s.is_finite() && time_constant_s > 0.0)
    {
        return Err(StrapdownError::BadOption {
            field: "vertical baro time constant (must be finite and > 0 s)",
        });
    }
    Ok(())
}
