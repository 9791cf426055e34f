//! Trajectories from body-frame acceleration and angular velocity, as MATLAB's
//! `kinematicTrajectory` builds them.
//!
//! Per sample k (state before the update, as MATLAB returns it): `a_n,k = C_nb,k a_b,k`; then
//! `q_{k+1} = q_k ⊗ exp(ω_b,k Δt)` (exact rotation-vector step), `v_{k+1} = v_k + a_n,k Δt`,
//! `p_{k+1} = p_k + v_k Δt + ½ a_n,k Δt²`. The scheme is first order in Δt for varying inputs
//! (exact for constant ones). `α_b` is the finite-difference derivative of the given `ω_b`
//! ([`finite_diff`](super::finite_diff)), or supplied by the caller.
use nalgebra::{UnitQuaternion, Vector3};

use crate::frame::Body;
use crate::kinematics::finite_diff::{Stencils, check_order};
use crate::kinematics::{KinematicsError, Truth, check_times};
use crate::math;
use crate::nav_frame::NavFrame;
use crate::rotation::Rotation;
use crate::vector::Vec3;

/// Where a body-rate trajectory starts.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BodyRateStart<N> {
    /// Position, navigation frame, m.
    pub position_m: Vec3<N>,
    /// Velocity, navigation frame, m/s.
    pub velocity_m_s: Vec3<N>,
    /// Attitude `C_nb`.
    pub attitude: Rotation<Body, N>,
}

impl<N: NavFrame> Default for BodyRateStart<N> {
    fn default() -> Self {
        Self {
            position_m: Vec3::zeros(),
            velocity_m_s: Vec3::zeros(),
            attitude: Rotation::identity(),
        }
    }
}

/// Truth from body-frame acceleration (`accel_body_m_s2`, kinematic, no gravity) and angular
/// velocity (`omega_body_rad_s`) at the times `t_s`, written into `out`. `alpha_body_rad_s2` gives
/// the angular acceleration; when `None` it is differentiated from `ω_b` at `order` (falling back
/// to order 2 for short series).
///
/// # Errors
/// Mismatched lengths, non-finite inputs, times that do not increase.
pub fn truth_from_body_rates<N: NavFrame>(
    t_s: &[f64],
    accel_body_m_s2: &[[f64; 3]],
    omega_body_rad_s: &[[f64; 3]],
    alpha_body_rad_s2: Option<&[[f64; 3]]>,
    start: BodyRateStart<N>,
    order: usize,
    out: &mut [Truth<N>],
) -> Result<(), KinematicsError> {
    let n = t_s.len();
    for (field, got) in [
        ("accel_body_m_s2", accel_body_m_s2.len()),
        ("omega_body_rad_s", omega_body_rad_s.len()),
        ("output", out.len()),
    ] {
        if got != n {
            return Err(KinematicsError::LengthMismatch {
                field,
                expected: n,
                got,
            });
        }
    }
    if let Some(a) = alpha_body_rad_s2
        && a.len() != n
    {
        return Err(KinematicsError::LengthMismatch {
            field: "alpha_body_rad_s2",
            expected: n,
            got: a.len(),
        });
    }
    check_times(t_s)?;
    for (field, series) in [
        ("accel_body_m_s2", accel_body_m_s2),
        ("omega_body_rad_s", omega_body_rad_s),
    ] {
        if let Some(index) = series.iter().position(|v| !v.iter().all(|c| c.is_finite())) {
            return Err(KinematicsError::NotFinite { field, index });
        }
    }
    let order = if check_order(order, n).is_ok() {
        order
    } else {
        2
    };
    let (mut p, mut v, mut q) = (
        *start.position_m.as_nalgebra(),
        *start.velocity_m_s.as_nalgebra(),
        *start.attitude.quaternion(),
    );
    let mut last_yaw: Option<f64> = None;
    let mut stencils = Stencils::new();
    for k in 0..n {
        let attitude = Rotation::<Body, N>::assume_from_quaternion(q);
        let a_n = q * Vector3::from(accel_body_m_s2[k]);
        let alpha = match alpha_body_rad_s2 {
            Some(a) => a[k],
            None if n >= 3 => {
                stencils
                    .derivatives_at(t_s, k, order, |j| omega_body_rad_s[j])
                    .0
            }
            None => [0.0; 3],
        };
        let mut euler = attitude.to_euler();
        if let Some(y) = last_yaw {
            euler.yaw_rad = math::unwrap_near(euler.yaw_rad, y);
        }
        last_yaw = Some(euler.yaw_rad);
        out[k] = Truth {
            t_s: t_s[k],
            position_m: Vec3::from_nalgebra(p),
            velocity_m_s: Vec3::from_nalgebra(v),
            acceleration_m_s2: Vec3::from_nalgebra(a_n),
            attitude,
            euler,
            omega_b_rad_s: Vec3::from_array(omega_body_rad_s[k]),
            alpha_b_rad_s2: Vec3::from_array(alpha),
        };
        if k + 1 < n {
            let dt = t_s[k + 1] - t_s[k];
            p += v * dt + a_n * (0.5 * dt * dt);
            v += a_n * dt;
            q *= UnitQuaternion::from_scaled_axis(Vector3::from(omega_body_rad_s[k]) * dt);
        }
    }
    Ok(())
}
