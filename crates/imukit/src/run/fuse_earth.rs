//! Loosely coupled INS/GNSS fusion on the WGS-84 Earth: the core's filter
//! ([`imu_core::fusion::eskf`] on [`Wgs84`]) over an IMU table (rates, frame `N`'s body convention) and a
//! GNSS table of geodetic fixes ([`GNSS_EARTH_COLUMNS`]), as [`super::fuse`] does on the flat
//! Earth. Output: [`FUSE_EARTH_COLUMNS`] — the flat fusion's columns (positions in the tangent
//! plane at the start's origin, velocity, attitude and one-sigmas on frame `N`'s axes, biases in
//! its body convention) and `lat_rad, lon_rad, height_m`. Odometer, barometer (the ellipsoidal
//! height) and the constraints aid it as on the flat Earth (the same code, `fuse_aids`).
use imu_core::earth::wgs84::OMEGA_IE_RAD_S;
use imu_core::earth::{Geodetic, GravityModel, Wgs84};
use imu_core::fusion::{Eskf, EskfError, EskfState, FULL_STATES, GnssFix, InitialSigma};

use imu_core::{Body, EulerZyx, NavFrame, Ned, Rotation, Vec3};

use crate::error::{Result, invalid};
use crate::io::table::{Table, concat_columns};
use crate::run::earth_nav::{self, EarthNavState};
use crate::run::fuse::{
    AidTables, FUSE_COLUMNS, FuseSetup, FuseSummary, FusionInputs, Start, align_from_gnss,
    count_fix, covariance_interval_refusal, fused_columns, push_sensor_errors,
};
use crate::run::fuse_aids::AidStreams;
use crate::run::navigate::GEODETIC_COLUMNS;
use crate::scenario::earth::frd_to_body;
use crate::scenario::gnss::GNSS_EARTH_COLUMNS;

/// Columns of a fused estimate on the Earth: [`FUSE_COLUMNS`] then the geodetic position.
pub const FUSE_EARTH_COLUMNS: [&str; 38] = concat_columns(FUSE_COLUMNS, GEODETIC_COLUMNS);

/// A geodetic position from radians and metres.
fn geodetic(latitude_rad: f64, longitude_rad: f64, height_m: f64) -> Geodetic {
    Geodetic {
        latitude_rad,
        longitude_rad,
        height_m,
    }
}

/// A vector of one-sigmas on NED (or FRD) axes, on frame `N`'s (its body convention's) axes:
/// the frames differ by a signed permutation, so the magnitudes move.
fn sigmas_to<N: NavFrame>(ned: [f64; 3]) -> [f64; 3] {
    N::from_ned()
        .apply(Vec3::<Ned>::from_array(ned))
        .to_array()
        .map(f64::abs)
}

/// The GNSS speed above which a vehicle is not at rest for the static alignment, m/s.
const STATIC_SPEED_M_S: f64 = 0.5;

/// Levelling and gyrocompassing from the mean specific force `f` and body rate `w` (FRD) of a
/// vehicle at rest for `duration_s` at `position`: roll `atan2(−f_y, −f_z)`, pitch
/// `atan2(f_x, √(f_y² + f_z²))`; the rate levelled by them, `ω_l = R_y(θ) R_x(φ) ω`, is the Earth
/// rate `(Ω cos φ cos ψ, −Ω cos φ sin ψ, −Ω sin φ)`, so yaw `ψ = atan2(−ω_l,y, ω_l,x)`. Stated
/// one-sigma: tilt the part's accelerometer bias over g with the white noise averaged, heading
/// the part's gyroscope bias and averaged white noise over `Ω cos φ` (Groves 2nd ed. §5.6);
/// the filter then starts with the part's biases as their uncertainty.
///
/// # Errors
/// A specific force far from gravity (not at rest), or a gyroscope whose stated heading
/// accuracy would be worse than 0.2 rad.
fn gyrocompass(
    f: [f64; 3],
    w: [f64; 3],
    position: &Geodetic,
    duration_s: f64,
    setup: &FuseSetup,
) -> Result<(EulerZyx, InitialSigma)> {
    let g = f.iter().map(|x| x * x).sum::<f64>().sqrt();
    let gamma = imu_core::earth::normal_gravity_m_s2(position);
    if (g - gamma).abs() > 0.05 * gamma {
        return Err(invalid(
            "align",
            format!(
                "\"static\": the mean specific force is {g:.3} m/s², not gravity ({gamma:.3}): \
                 the vehicle is not at rest"
            ),
        ));
    }
    let roll = (-f[1]).atan2(-f[2]);
    let pitch = f[0].atan2(f[1].hypot(f[2]));
    let level = Rotation::<Body, Body>::from_euler(EulerZyx::new(0.0, pitch, roll));
    let wl = level.apply(Vec3::from_array(w)).to_array();
    let yaw = (-wl[1]).atan2(wl[0]);
    let horizontal = OMEGA_IE_RAD_S * position.latitude_rad.cos();
    let noise = setup.noise;
    let [accel_bias, gyro_bias] = setup.part_bias;
    let heading = gyro_bias.hypot(noise.gyro_psd / duration_s.sqrt()) / horizontal;
    if heading.is_nan() || heading >= 0.2 {
        return Err(invalid(
            "align",
            format!(
                "\"static\": this gyroscope (bias {gyro_bias:.2e} rad/s) cannot find north against \
                 the Earth rate's {horizontal:.2e} rad/s here; use \"gnss\" or give the initial \
                 state"
            ),
        ));
    }
    let tilt = accel_bias.hypot(noise.accel_psd / duration_s.sqrt()) / gamma;
    Ok((
        EulerZyx::new(yaw, pitch, roll),
        InitialSigma {
            position_m: setup
                .gnss_position_sigma_m
                .iter()
                .fold(0.0_f64, |a, b| a.max(*b)),
            velocity_m_s: 0.05,
            attitude_rad: [tilt, tilt, heading],
            // What the averages took for the attitude stays a bias the filter must learn.
            accel_bias_m_s2: accel_bias.max(1e-6),
            gyro_bias_rad_s: gyro_bias.max(1e-9),
        },
    ))
}

/// Fuses on the Earth (see the module docs); `gravity` is the scenario's model.
///
/// # Errors
/// As [`super::fuse::fuse_with`]; a start without a geodetic position.
pub(crate) fn fuse_earth_in<N: NavFrame, const S: usize>(
    imu: &Table,
    gnss: &Table,
    aids: AidTables<'_>,
    start: Start<'_>,
    setup: &FuseSetup,
    gravity: GravityModel,
) -> Result<(Table, FuseSummary)> {
    let inputs = FusionInputs::read(
        imu,
        gnss,
        &GNSS_EARTH_COLUMNS,
        " (fixes on the WGS-84 Earth are geodetic)",
    )?;
    let FusionInputs {
        t,
        f,
        w,
        g_t,
        g_p,
        g_v,
    } = &inputs;
    let (t0, t1) = inputs.span();
    let mut aid_streams = AidStreams::new(aids, setup, (t0, t1), t.len())?;
    if let Some(k) = (0..g_p.len()).find(|&k| {
        let [lat, lon, h] = g_p[k];
        !(lat.abs() <= imu_core::earth::MAX_LATITUDE_RAD && lon.is_finite() && h.is_finite())
    }) {
        return Err(invalid(
            "GNSS data",
            format!(
                "row {}: the latitude must be within ±89.9° and the longitude and height finite",
                k + 2
            ),
        ));
    }
    let to_frd = frd_to_body::<N>().inverse();
    let sign = match setup.accel_sign {
        imu_core::AccelSign::SpecificForce => 1.0,
        imu_core::AccelSign::Matlab => -1.0,
    };
    let frd = |a: [f64; 3], s: f64| to_frd.apply(Vec3::from_array(a.map(|x| s * x))).to_array();
    // The first sample, state, tangent-plane origin and one-sigma; fixes before `next_fix` used.
    let (first, s0, origin, sigma, mut next_fix) = match start {
        Start::State(initial) => {
            let (s, origin) = earth_nav::start::<N>(initial, t0)?;
            (0, s, origin, setup.initial_sigma, 0)
        }
        Start::AlignStatic { duration_s } => {
            let i0 = t.partition_point(|&ti| ti < t0 + duration_s);
            if i0 < 2 || i0 >= t.len() {
                return Err(invalid(
                    "align",
                    format!(
                        "\"static\" averages the first {duration_s} s at rest: the IMU data must \
                         last longer"
                    ),
                ));
            }
            let fixes = g_t.partition_point(|&x| x <= t[i0]);
            if fixes == 0 {
                return Err(invalid(
                    "GNSS data",
                    format!(
                        "no fix in the first {duration_s} s: the static alignment takes its \
                         position from the fixes"
                    ),
                ));
            }
            if let Some(k) = (0..fixes).find(|&k| {
                let v = g_v[k];
                v[0].hypot(v[1]).hypot(v[2]) > STATIC_SPEED_M_S
            }) {
                return Err(invalid(
                    "GNSS data",
                    format!(
                        "row {}: the vehicle moves ({:.2} m/s) during the static alignment's first \
                         {duration_s} s",
                        k + 2,
                        g_v[k][0].hypot(g_v[k][1]).hypot(g_v[k][2])
                    ),
                ));
            }
            let mean = |v: &[[f64; 3]], s: f64| -> [f64; 3] {
                let sum = v[..i0]
                    .iter()
                    .fold([0.0; 3], |a, x| [0, 1, 2].map(|j| a[j] + x[j]));
                frd(sum.map(|x| x / i0 as f64), s)
            };
            let [lat, lon, h] = g_p[fixes - 1];
            let position = geodetic(lat, lon, h);
            let (euler, sigma) =
                gyrocompass(mean(f, sign), mean(w, 1.0), &position, t[i0] - t0, setup)?;
            let s = EarthNavState {
                t_s: t[i0],
                attitude: Rotation::<Body, Ned>::from_euler(euler),
                velocity_m_s: Vec3::zeros(),
                position,
            };
            (i0, s, position, sigma, fixes)
        }
        Start::AlignGnss => {
            let (k, i0, age) = inputs.first_fix_at_speed(setup.gnss_latency_s)?;
            let (_, sigma) = align_from_gnss([0.0; 3], g_v[k], age, setup);
            let [lat, lon, h] = g_p[k];
            let v = g_v[k];
            let (r_n, r_e) = geodetic(lat, lon, h).radii_m();
            let position = geodetic(
                lat + v[0] * age / (r_n + h),
                lon + v[1] * age / ((r_e + h) * lat.cos()),
                h - v[2] * age,
            );
            let euler = EulerZyx::new(v[1].atan2(v[0]), (-v[2]).atan2(v[0].hypot(v[1])), 0.0);
            let s = EarthNavState {
                t_s: t[i0],
                attitude: Rotation::<Body, Ned>::from_euler(euler),
                velocity_m_s: Vec3::from_array(v),
                position,
            };
            (i0, s, position, sigma, k + 1)
        }
    };
    let s0 = EarthNavState {
        t_s: t[first],
        ..s0
    };
    aid_streams.start_at(t[first]);
    let filter_error = |context: &str, e: EskfError| invalid(context, e.to_string());
    let start = EskfState {
        nav: s0,
        accel_bias_m_s2: [0.0; 3],
        gyro_bias_rad_s: [0.0; 3],
    };
    let filter = Eskf::<_, S>::new(Wgs84::<Ned>::new(gravity), &start, &sigma, setup.noise)
        .map_err(|e| filter_error("filter", e))?
        .with_covariance_interval(setup.covariance_interval_s)
        .map_err(|_| covariance_interval_refusal(setup))?;
    let mut filter = if S == FULL_STATES {
        filter
            .with_sensor_error_sigma(&setup.sensor_error_sigma)
            .map_err(|e| filter_error("sensor_error_sigma", e))?
    } else {
        filter
    };
    let lever = Vec3::<Body>::from_array(frd(setup.lever_arm_m, 1.0));
    let vel_sigma = setup.gnss_velocity_sigma_m_s.unwrap_or(1.0);
    let to_body = frd_to_body::<N>();
    let bias_to = |b: [f64; 3]| to_body.apply(Vec3::<Body>::from_array(b)).to_array();
    let bias_sigma_to = |b: [f64; 3]| bias_to(b).map(f64::abs);
    // FRD and the table's body axes differ by a diagonal signed permutation.
    let axis_sign = bias_to([1.0; 3]);
    let mut table = Table {
        columns: fused_columns(&FUSE_EARTH_COLUMNS, S == FULL_STATES),
        data: Vec::new(),
    };
    let mut rejected_in_a_row = 0;
    let mut last_yaw = None;
    for i in first..t.len() {
        filter
            .propagate(t[i], frd(w[i], 1.0), frd(f[i], sign))
            .map_err(|e| filter_error("IMU data", e))?;
        while next_fix < g_t.len() && g_t[next_fix] <= t[i] {
            let [lat, lon, h] = g_p[next_fix];
            let fix = GnssFix::<Wgs84<Ned>> {
                position: geodetic(lat, lon, h),
                velocity_m_s: setup
                    .gnss_velocity_sigma_m_s
                    .map(|_| Vec3::from_array(g_v[next_fix])),
                lever_arm_m: lever,
                position_sigma_m: setup.gnss_position_sigma_m,
                velocity_sigma_m_s: [vel_sigma; 3],
                age_s: t[i] - g_t[next_fix] + setup.gnss_latency_s,
            };
            count_fix(
                filter.update_gnss(&fix, setup.gate),
                next_fix,
                &mut rejected_in_a_row,
                setup.gate,
            )?;
            next_fix += 1;
        }
        aid_streams.apply(&mut filter, t[i], i)?;
        let s = filter.state();
        let sig = filter.sigmas();
        let nav = earth_nav::row::<N>(&s.nav, &origin, &mut last_yaw);
        let mut row = Vec::with_capacity(FUSE_EARTH_COLUMNS.len());
        row.extend_from_slice(&nav[..14]);
        for k in 0..3 {
            row.extend(sigmas_to::<N>([sig[3 * k], sig[3 * k + 1], sig[3 * k + 2]]));
        }
        row.extend(bias_to(s.accel_bias_m_s2));
        row.extend(bias_to(s.gyro_bias_rad_s));
        row.extend(bias_sigma_to([sig[9], sig[10], sig[11]]));
        row.extend(bias_sigma_to([sig[12], sig[13], sig[14]]));
        row.extend_from_slice(&nav[14..]);
        if S == FULL_STATES {
            push_sensor_errors(&mut row, &filter.sensor_errors(), &sig[15..], axis_sign);
        }
        table.push_row(&row);
    }
    table.check_finite("fused navigation")?;
    let (updates, rejected) = filter.update_counts();
    Ok((table, FuseSummary { updates, rejected }))
}
