//! Loosely coupled INS/GNSS fusion for the CLI and Python: the core's error-state filter
//! ([`imu_core::fusion::eskf`]) over an IMU table (rates) and a GNSS table, flat Earth.
//!
//! Output: [`FUSE_COLUMNS`] — the navigation columns of `integrate`, the one-sigma of position,
//! velocity and attitude (navigation-frame axes), and the bias estimates — one row per IMU
//! sample. A fix is applied at the first IMU sample at or after its stamp (fixes are taken at IMU
//! samples in imukit's simulations, so exactly there).
use imu_core::fusion::{Eskf, EskfNoise, EskfState, InitialSigma};
use imu_core::{AccelSign, Body, Enu, NavFrame, Ned, Rotation, Vec3};

use crate::error::{Result, invalid};
use crate::io::table::{ACCEL_COLUMNS, GYRO_COLUMNS, Table};
use crate::run::navigate::{InitialState, NAV_COLUMNS, euler_unwrapped};
use crate::scenario::NavFrameName;
use crate::scenario::gnss::GNSS_COLUMNS;

/// Columns of a fused estimate: [`NAV_COLUMNS`], one-sigma columns, bias estimates.
pub const FUSE_COLUMNS: [&str; 29] = [
    "t_s",
    "pos_x_m",
    "pos_y_m",
    "pos_z_m",
    "vel_x_m_s",
    "vel_y_m_s",
    "vel_z_m_s",
    "q_w",
    "q_x",
    "q_y",
    "q_z",
    "yaw_rad",
    "pitch_rad",
    "roll_rad",
    "pos_x_sigma_m",
    "pos_y_sigma_m",
    "pos_z_sigma_m",
    "vel_x_sigma_m_s",
    "vel_y_sigma_m_s",
    "vel_z_sigma_m_s",
    "att_x_sigma_rad",
    "att_y_sigma_rad",
    "att_z_sigma_rad",
    "accel_bias_x_m_s2",
    "accel_bias_y_m_s2",
    "accel_bias_z_m_s2",
    "gyro_bias_x_rad_s",
    "gyro_bias_y_rad_s",
    "gyro_bias_z_rad_s",
];

const _: () = assert!(FUSE_COLUMNS.len() == NAV_COLUMNS.len() + 15);

/// How to fuse.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FuseSetup {
    /// Navigation frame of the tables.
    pub nav_frame: NavFrameName,
    /// Sign of the accelerometer columns.
    pub accel_sign: AccelSign,
    /// Gravity magnitude, m/s².
    pub gravity_m_s2: f64,
    /// The IMU's noise as the filter models it.
    pub noise: EskfNoise,
    /// Initial uncertainty.
    pub initial_sigma: InitialSigma,
    /// GNSS position one-sigma (x, y, z of the frame), m.
    pub gnss_position_sigma_m: [f64; 3],
    /// GNSS velocity one-sigma per axis, m/s (`None`: position only).
    pub gnss_velocity_sigma_m_s: Option<f64>,
    /// Antenna lever arm, body frame, m.
    pub lever_arm_m: [f64; 3],
    /// Innovation gate: NIS above this chi-square value is rejected (`f64::INFINITY`: off).
    pub gate: f64,
}

/// What a fusion did besides its table.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FuseSummary {
    /// Fixes applied.
    pub updates: usize,
    /// Fixes rejected by the gate.
    pub rejected: usize,
}

fn triples(t: &Table, names: &[&str; 3]) -> Option<Vec<[f64; 3]>> {
    let c: Vec<Vec<f64>> = names.iter().map(|n| t.column(n)).collect::<Option<_>>()?;
    Some((0..t.rows()).map(|i| [c[0][i], c[1][i], c[2][i]]).collect())
}

/// Fuses `imu` (rates) with `gnss` ([`GNSS_COLUMNS`]) from `initial`.
///
/// # Errors
/// Missing columns, GNSS times that do not increase or fall outside the IMU's span, the
/// filter's refusals (the sample or update named), a divergence.
pub fn fuse(
    imu: &Table,
    gnss: &Table,
    initial: &InitialState,
    setup: &FuseSetup,
) -> Result<(Table, FuseSummary)> {
    match setup.nav_frame {
        NavFrameName::ENU => fuse_in::<Enu>(imu, gnss, initial, setup),
        NavFrameName::NED => fuse_in::<Ned>(imu, gnss, initial, setup),
    }
}

fn fuse_in<N: NavFrame>(
    imu: &Table,
    gnss: &Table,
    initial: &InitialState,
    setup: &FuseSetup,
) -> Result<(Table, FuseSummary)> {
    let t = imu
        .column("t_s")
        .ok_or_else(|| invalid("IMU data", "missing column t_s"))?;
    let (Some(f), Some(w)) = (triples(imu, &ACCEL_COLUMNS), triples(imu, &GYRO_COLUMNS)) else {
        return Err(invalid(
            "IMU data",
            "fusion needs rates: accel_x/y/z_m_s2 and gyro_x/y/z_rad_s",
        ));
    };
    let missing: Vec<&str> = GNSS_COLUMNS
        .iter()
        .copied()
        .filter(|c| !gnss.columns.iter().any(|h| h == c))
        .collect();
    if !missing.is_empty() {
        return Err(invalid(
            "GNSS data",
            format!("missing column(s) {}", missing.join(", ")),
        ));
    }
    let g_t = gnss.column("t_s").unwrap_or_default();
    let g_p = triples(gnss, &["pos_x_m", "pos_y_m", "pos_z_m"]).unwrap_or_default();
    let g_v = triples(gnss, &["vel_x_m_s", "vel_y_m_s", "vel_z_m_s"]).unwrap_or_default();
    let (t0, t1) = (
        t.first().copied().unwrap_or(0.0),
        t.last().copied().unwrap_or(0.0),
    );
    for (k, &tk) in g_t.iter().enumerate() {
        if !tk.is_finite() || (k > 0 && tk <= g_t[k - 1]) {
            return Err(invalid(
                "GNSS data",
                format!("row {}: times must be finite and increase", k + 2),
            ));
        }
        if tk < t0 || tk > t1 {
            return Err(invalid(
                "GNSS data",
                format!(
                    "row {}: time {tk} s is outside the IMU's span [{t0}, {t1}] s",
                    k + 2
                ),
            ));
        }
    }
    let attitude = Rotation::<Body, N>::from_wxyz(initial.quaternion).ok_or_else(|| {
        invalid(
            "initial state",
            "the quaternion has zero norm or is not finite",
        )
    })?;
    let start = EskfState {
        t_s: t0,
        position_m: Vec3::from_array(initial.position_m),
        velocity_m_s: Vec3::from_array(initial.velocity_m_s),
        attitude,
        accel_bias_m_s2: [0.0; 3],
        gyro_bias_rad_s: [0.0; 3],
    };
    let filter_error =
        |context: &str, e: imu_core::fusion::EskfError| invalid(context, e.to_string());
    let mut filter = Eskf::<N>::new(
        &start,
        &setup.initial_sigma,
        setup.noise,
        setup.gravity_m_s2,
    )
    .map_err(|e| filter_error("filter", e))?;
    let sign = match setup.accel_sign {
        AccelSign::SpecificForce => 1.0,
        AccelSign::Matlab => -1.0,
    };
    let lever = Vec3::<Body>::from_array(setup.lever_arm_m);
    let vel_sigma = setup.gnss_velocity_sigma_m_s.unwrap_or(1.0);
    let mut table = Table::new(&FUSE_COLUMNS);
    let mut next_fix = 0;
    let mut last_yaw = None;
    for i in 0..t.len() {
        filter
            .propagate(t[i], w[i], f[i].map(|x| sign * x))
            .map_err(|e| filter_error("IMU data", e))?;
        while next_fix < g_t.len() && g_t[next_fix] <= t[i] {
            filter
                .update_gnss(
                    Vec3::from_array(g_p[next_fix]),
                    setup
                        .gnss_velocity_sigma_m_s
                        .map(|_| Vec3::from_array(g_v[next_fix])),
                    lever,
                    setup.gnss_position_sigma_m,
                    [vel_sigma; 3],
                    setup.gate,
                )
                .map_err(|e| invalid("GNSS data", format!("row {}: {e}", next_fix + 2)))?;
            next_fix += 1;
        }
        let s = filter.state();
        let sig = filter.sigmas();
        let e = euler_unwrapped(&s.attitude, &mut last_yaw);
        let (p, v, q) = (
            s.position_m.to_array(),
            s.velocity_m_s.to_array(),
            s.attitude.to_wxyz(),
        );
        let mut row = vec![
            t[i],
            p[0],
            p[1],
            p[2],
            v[0],
            v[1],
            v[2],
            q[0],
            q[1],
            q[2],
            q[3],
            e.yaw_rad,
            e.pitch_rad,
            e.roll_rad,
        ];
        row.extend_from_slice(&sig[..9]);
        row.extend_from_slice(&s.accel_bias_m_s2);
        row.extend_from_slice(&s.gyro_bias_rad_s);
        table.push_row(&row);
    }
    table.check_finite("fused navigation")?;
    let (updates, rejected) = filter.update_counts();
    Ok((table, FuseSummary { updates, rejected }))
}
