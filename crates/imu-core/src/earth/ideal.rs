//! Truth and ideal IMU readings on the rotating WGS-84 Earth.
//!
//! A truth sample ([`EarthTruth`]) holds the geodetic position, the ground velocity `v^n` in the
//! local NED frame at that position and the derivative of its components `v̇^n`, the attitude
//! `C_nb` relative to that local NED, the attitude rate `ω_nb^b` and its derivative `α_nb^b`.
//! The ideal sensors (Groves 2nd ed. eq. 5.53 and 2.145; Titterton & Weston §3.5):
//!
//! * gyroscope `ω_ib^b = ω_nb^b + C_nbᵀ (ω_ie^n + ω_en^n)`;
//! * accelerometer (specific force at the reference point)
//!   `f^b = C_nbᵀ [v̇^n + (2 ω_ie^n + ω_en^n) × v^n − g^n]`, `g^n = [0, 0, γ(φ, h)]`; at rest and
//!   level it reads `−γ` on z (FRD);
//! * at a lever arm `r` the rigid-body terms use the inertial rate:
//!   `f_I = f_S + ω_ib^b × (ω_ib^b × r) + α_ib^b × r` (the gravitation gradient over `r` is
//!   neglected, about 3e-6 m/s² per metre).
//!
//! The same quantities in the Earth-fixed frame ([`EcefKinematics`]) give the independent form
//! `f^b = C_ebᵀ [a^e + 2 Ω^e × v^e − g^e]`, `ω_ib^b = ω_eb^b + C_ebᵀ Ω^e` with
//! `Ω^e = [0, 0, ω_ie]`; the conversions between the two are exact:
//! `v^n = C_ne v^e`, `v̇^n = C_ne a^e − ω_en^n × v^n`, `C_nb = C_ne C_eb`,
//! `ω_nb^b = ω_eb^b − C_bn ω_en^n`, `α_nb^b = α_eb^b + ω_nb^b × (C_bn ω_en^n) − C_bn ω̇_en^n`.
use crate::earth::gravity::GravityModel;
use crate::earth::rates::{
    earth_rate_ned, geodetic_rates, transport_rate_derivative_ned, transport_rate_ned,
};
use crate::earth::wgs84::{Geodetic, OMEGA_IE_RAD_S};
use crate::frame::{Ecef, Frd, Ned};
use crate::ideal::{AccelSign, IdealReading, at_lever_arm};
use crate::math;
use crate::rotation::{EulerZyx, Rotation};
use crate::vector::Vec3;

/// One truth sample on the WGS-84 Earth, local NED.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EarthTruth {
    /// Time, s.
    pub t_s: f64,
    /// Geodetic position of the reference point.
    pub position: Geodetic,
    /// Ground velocity `v^n` (Earth-relative), local NED, m/s.
    pub velocity_m_s: Vec3<Ned>,
    /// Time derivative of the components of `v^n`, m/s².
    pub acceleration_m_s2: Vec3<Ned>,
    /// Attitude `C_nb` relative to the local NED frame.
    pub attitude: Rotation<Frd, Ned>,
    /// The same attitude as z-y-x Euler angles (yaw from true north).
    pub euler: EulerZyx,
    /// Attitude rate `ω_nb^b`, rad/s.
    pub omega_nb_b_rad_s: Vec3<Frd>,
    /// Its derivative `α_nb^b`, rad/s².
    pub alpha_nb_b_rad_s2: Vec3<Frd>,
}

impl Default for EarthTruth {
    fn default() -> Self {
        Self {
            t_s: 0.0,
            position: Geodetic::default(),
            velocity_m_s: Vec3::zeros(),
            acceleration_m_s2: Vec3::zeros(),
            attitude: Rotation::identity(),
            euler: EulerZyx::default(),
            omega_nb_b_rad_s: Vec3::zeros(),
            alpha_nb_b_rad_s2: Vec3::zeros(),
        }
    }
}

/// The motion of the reference point and the body relative to the Earth-fixed frame: position,
/// velocity and acceleration as time derivatives taken in ECEF, attitude `C_eb`, body rate
/// `ω_eb^b` and its derivative.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EcefKinematics {
    /// Position, ECEF, m.
    pub position_m: Vec3<Ecef>,
    /// Velocity relative to the Earth, ECEF, m/s.
    pub velocity_m_s: Vec3<Ecef>,
    /// Its derivative in ECEF, m/s².
    pub acceleration_m_s2: Vec3<Ecef>,
    /// Attitude `C_eb`.
    pub attitude: Rotation<Frd, Ecef>,
    /// Frd rate relative to the Earth `ω_eb^b`, rad/s.
    pub omega_eb_b_rad_s: Vec3<Frd>,
    /// Its derivative, rad/s².
    pub alpha_eb_b_rad_s2: Vec3<Frd>,
}

/// The Earth rate in ECEF, `[0, 0, ω_ie]`, rad/s.
#[must_use]
pub fn earth_rate_ecef() -> Vec3<Ecef> {
    Vec3::new(0.0, 0.0, OMEGA_IE_RAD_S)
}

impl EarthTruth {
    /// The sample from Earth-fixed kinematics at time `t_s`; `None` where the geodetic position
    /// is undefined (within 43 km of the Earth's centre, or non-finite input).
    #[must_use]
    pub fn from_ecef(t_s: f64, k: &EcefKinematics) -> Option<Self> {
        let position = Geodetic::from_ecef(k.position_m)?;
        let c_ne = position.ned_to_ecef().inverse();
        let v = c_ne.apply(k.velocity_m_s);
        let w_en = transport_rate_ned(&position, v);
        let a = c_ne.apply(k.acceleration_m_s2) - w_en.cross(&v);
        let attitude = k.attitude.then(&c_ne);
        let c_bn = attitude.inverse();
        let w_en_b = c_bn.apply(w_en);
        let omega = k.omega_eb_b_rad_s - w_en_b;
        let alpha = k.alpha_eb_b_rad_s2 + omega.cross(&w_en_b)
            - c_bn.apply(transport_rate_derivative_ned(&position, v, a));
        Some(Self {
            t_s,
            position,
            velocity_m_s: v,
            acceleration_m_s2: a,
            attitude,
            euler: attitude.to_euler(),
            omega_nb_b_rad_s: omega,
            alpha_nb_b_rad_s2: alpha,
        })
    }

    /// The same motion in Earth-fixed terms (the inverse of [`Self::from_ecef`]).
    #[must_use]
    pub fn to_ecef(&self) -> EcefKinematics {
        let c_en = self.position.ned_to_ecef();
        let v = self.velocity_m_s;
        let w_en = transport_rate_ned(&self.position, v);
        let c_bn = self.attitude.inverse();
        let w_en_b = c_bn.apply(w_en);
        let omega = self.omega_nb_b_rad_s;
        EcefKinematics {
            position_m: self.position.to_ecef(),
            velocity_m_s: c_en.apply(v),
            acceleration_m_s2: c_en.apply(self.acceleration_m_s2 + w_en.cross(&v)),
            attitude: self.attitude.then(&c_en),
            omega_eb_b_rad_s: omega + w_en_b,
            alpha_eb_b_rad_s2: self.alpha_nb_b_rad_s2 - omega.cross(&w_en_b)
                + c_bn.apply(transport_rate_derivative_ned(
                    &self.position,
                    v,
                    self.acceleration_m_s2,
                )),
        }
    }

    /// The inertial body rate `ω_ib^b = ω_nb^b + C_bn (ω_ie^n + ω_en^n)` and its derivative
    /// `α_ib^b = α_nb^b − ω_nb^b × C_bn ω_in^n + C_bn ω̇_in^n`, rad/s and rad/s².
    #[must_use]
    pub fn inertial_rate(&self) -> (Vec3<Frd>, Vec3<Frd>) {
        let p = &self.position;
        let v = self.velocity_m_s;
        let w_in = earth_rate_ned(p) + transport_rate_ned(p, v);
        let phi_dot = geodetic_rates(p, v)[0];
        let (s, c) = (math::sin(p.latitude_rad), math::cos(p.latitude_rad));
        let w_ie_dot = Vec3::<Ned>::new(
            -OMEGA_IE_RAD_S * s * phi_dot,
            0.0,
            -OMEGA_IE_RAD_S * c * phi_dot,
        );
        let w_in_dot = w_ie_dot + transport_rate_derivative_ned(p, v, self.acceleration_m_s2);
        let c_bn = self.attitude.inverse();
        let w_in_b = c_bn.apply(w_in);
        let omega = self.omega_nb_b_rad_s;
        (
            omega + w_in_b,
            self.alpha_nb_b_rad_s2 - omega.cross(&w_in_b) + c_bn.apply(w_in_dot),
        )
    }

    /// The specific force at the reference point, local NED, m/s²:
    /// `v̇^n + (2 ω_ie^n + ω_en^n) × v^n − g^n`.
    #[must_use]
    pub fn specific_force_ned(&self, gravity: &GravityModel) -> Vec3<Ned> {
        let p = &self.position;
        let v = self.velocity_m_s;
        let coriolis = (earth_rate_ned(p) * 2.0 + transport_rate_ned(p, v)).cross(&v);
        let g = Vec3::<Ned>::new(0.0, 0.0, gravity.magnitude_m_s2(p));
        self.acceleration_m_s2 + coriolis - g
    }
}

/// Where the IMU sits on the body and what the Earth model senses.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct EarthMount {
    /// Lever arm `r` from the reference point to the IMU, body frame, m.
    pub lever_arm_m: Vec3<Frd>,
    /// Accelerometer sign convention.
    pub accel_sign: AccelSign,
    /// Gravity model.
    pub gravity: GravityModel,
}

impl EarthMount {
    /// Specific force at the IMU point, body frame, m/s² (the physical sign).
    #[must_use]
    pub fn specific_force(&self, truth: &EarthTruth) -> Vec3<Frd> {
        let f_s = truth
            .attitude
            .inverse()
            .apply(truth.specific_force_ned(&self.gravity));
        let (w, alpha) = truth.inertial_rate();
        at_lever_arm(f_s, w, alpha, self.lever_arm_m)
    }

    /// The ideal reading of the three sensors, with the magnetic field at the position given in
    /// local NED (µT).
    #[must_use]
    pub fn read(&self, truth: &EarthTruth, magnetic_field_ned_ut: Vec3<Ned>) -> IdealReading<Frd> {
        let f = self.specific_force(truth);
        IdealReading {
            accel_m_s2: match self.accel_sign {
                AccelSign::SpecificForce => f,
                AccelSign::Matlab => -f,
            },
            gyro_rad_s: truth.inertial_rate().0,
            mag_ut: truth.attitude.inverse().apply(magnetic_field_ned_ut),
        }
    }
}

/// The ideal specific force and inertial rate from Earth-fixed kinematics, the independent
/// route: `f^b = C_ebᵀ [a^e + 2 Ω^e × v^e − g^e]`, `ω_ib^b = ω_eb^b + C_ebᵀ Ω^e`, with `g^e` the
/// gravity along the local down at the position (m/s², rad/s; reference point).
#[must_use]
pub fn ecef_specific_force_and_rate(
    k: &EcefKinematics,
    gravity: &GravityModel,
) -> Option<(Vec3<Frd>, Vec3<Frd>)> {
    let position = Geodetic::from_ecef(k.position_m)?;
    let down = position
        .ned_to_ecef()
        .apply(Vec3::<Ned>::new(0.0, 0.0, 1.0));
    let g = down * gravity.magnitude_m_s2(&position);
    let omega = earth_rate_ecef();
    let c_be = k.attitude.inverse();
    let f = c_be.apply(k.acceleration_m_s2 + omega.cross(&k.velocity_m_s) * 2.0 - g);
    Some((f, k.omega_eb_b_rad_s + c_be.apply(omega)))
}
