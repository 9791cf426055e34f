//! Where the filter begins: at a given state, or aligned — from the first fix at speed
//! (position, velocity and a nose-first attitude) or at rest on the rotating Earth (levelling
//! and gyrocompassing) — with each start's one-sigma.
use imu_core::Vec3;
use imu_core::fusion::InitialSigma;
use imu_core::fusion::align::{self, PartFigures};
use imu_core::strapdown::NavState;

use super::inputs::{FixVelocity, Fixes, FusionInputs};
use super::{FuseSetup, Start};
use crate::error::Data;
use crate::error::{Error, RequestOption, Result, invalid, refused};
use crate::run::nav_earth::{self, NavEarth};

/// The horizontal speed from which a GNSS velocity gives the heading, m/s.
pub const ALIGN_MIN_SPEED_M_S: f64 = 3.0;

/// One-sigma the alignment from GNSS allows for a vehicle's nose pointing off its velocity
/// (sideslip, angle of attack) and for its roll, rad.
pub const ALIGN_ATTITUDE_ALLOWANCE_RAD: [f64; 2] = [0.02, 0.05];

/// The one-sigma of a start aligned from a GNSS fix of velocity `v` (attitude by
/// [`imu_core::fusion::align::moving`]): position the fix's plus the lever arm's length (the
/// antenna's offset is not yet known in the navigation frame), velocity the fix's, heading and
/// pitch `σ_v/|v_h|` and [`ALIGN_ATTITUDE_ALLOWANCE_RAD`]`[0]` in quadrature, roll
/// [`ALIGN_ATTITUDE_ALLOWANCE_RAD`]`[1]` (roll about the heading and pitch across it, turned onto
/// the frame's horizontal axes), biases as `setup` has them.
#[must_use]
pub fn gnss_alignment_sigma(v: [f64; 3], setup: &FuseSetup) -> InitialSigma {
    let horizontal = v[0].hypot(v[1]);
    let vel_sigma = setup.gnss_velocity_sigma_m_s.unwrap_or(1.0);
    let lever = setup.lever_arm_m.iter().map(|l| l * l).sum::<f64>().sqrt();
    let pos_sigma = setup
        .gnss_position_sigma_m
        .iter()
        .fold(0.0_f64, |a, b| a.max(*b));
    let angle = (vel_sigma / horizontal)
        .atan()
        .hypot(ALIGN_ATTITUDE_ALLOWANCE_RAD[0]);
    // Roll is about the heading, pitch across it: on the frame's horizontal axes, the diagonal
    // of σ_r² u uᵀ + σ_p² u⊥ u⊥ᵀ for the heading's unit vector u (the same in ENU and NED).
    let roll = ALIGN_ATTITUDE_ALLOWANCE_RAD[1];
    let (cos, sin) = (v[0] / horizontal, v[1] / horizontal);
    let tilt = |along: f64, across: f64| (roll * along).hypot(angle * across);
    InitialSigma {
        position_m: pos_sigma + lever,
        velocity_m_s: vel_sigma,
        attitude_rad: [tilt(cos, sin), tilt(sin, cos), angle],
        ..setup.initial_sigma
    }
}

/// The GNSS speed above which a vehicle is not at rest for the static alignment, m/s.
const STATIC_SPEED_M_S: f64 = 0.5;

/// Where the filter begins: the first IMU sample it takes, its state there, the plane's origin,
/// the state's one-sigma, and the first fix not yet used.
pub(super) struct Begin<E: NavEarth> {
    /// The first IMU sample the filter takes.
    pub first: usize,
    /// Its state there.
    pub state: NavState<E>,
    /// The plane's origin.
    pub origin: E::Origin,
    /// The state's one-sigma.
    pub sigma: InitialSigma,
    /// The first fix the filter has not used.
    pub next_fix: usize,
}

/// The start `start` asks for, on `earth`, from the fusion's `inputs` and `fixes`.
///
/// # Errors
/// A start's refusals: a static alignment on the flat Earth, or without the rest, the fixes or
/// the samples it needs; an alignment from GNSS without a fix at speed; an initial state that
/// is not one.
pub(super) fn begin<E: NavEarth>(
    earth: &E,
    start: Start<'_>,
    setup: &FuseSetup,
    inputs: &FusionInputs,
    fixes: &Fixes<E>,
) -> Result<Begin<E>> {
    let t = &inputs.t;
    let begin = match start {
        Start::State(initial) => {
            let (state, origin) = nav_earth::start::<E>(initial, t[0])?;
            Begin {
                first: 0,
                state,
                origin,
                sigma: setup.initial_sigma,
                next_fix: 0,
            }
        }
        Start::AlignStatic { .. } if !E::ROTATING => {
            return Err(refused(
                RequestOption::Align,
                "\"static\": on the flat Earth the gyroscopes cannot find north (the flat model \
                 has no Earth rate); a static alignment needs a scenario on the WGS-84 Earth — \
                 use \"gnss\" (heading from the first fix at speed) or give the initial state",
            ));
        }
        Start::AlignStatic { duration_s } => at_rest(earth, duration_s, setup, inputs, fixes)?,
        Start::Level => level(setup, inputs, fixes)?,
        Start::AlignGnss => from_gnss(earth, setup, inputs, fixes)?,
    };
    Ok(Begin {
        state: NavState {
            t_s: t[begin.first],
            ..begin.state
        },
        ..begin
    })
}

/// The static alignment over the first `duration_s` (at rest, checked by the fixes' speeds),
/// at the last fix in it.
///
/// # Errors
/// Too few samples, no fix in the stretch, a fix that moves, the alignment's refusal.
fn at_rest<E: NavEarth>(
    earth: &E,
    duration_s: f64,
    setup: &FuseSetup,
    inputs: &FusionInputs,
    fixes: &Fixes<E>,
) -> Result<Begin<E>> {
    let (t, g_t, g_v) = (&inputs.t, &inputs.g_t, &inputs.g_v);
    let t0 = t[0];
    let i0 = t.partition_point(|&ti| ti < t0 + duration_s);
    if i0 < 2 || i0 >= t.len() {
        return Err(refused(
            RequestOption::Align,
            format!(
                "\"static\" averages the first {duration_s} s at rest: the IMU data must last \
                 longer"
            ),
        ));
    }
    let used = g_t.partition_point(|&x| x <= t[i0]);
    if used == 0 {
        return Err(invalid(
            Data::Gnss,
            format!(
                "no fix in the first {duration_s} s: the static alignment takes its position \
                 from the fixes"
            ),
        ));
    }
    if let Some(k) = (0..used).find(|&k| {
        let v = g_v[k];
        v[0].hypot(v[1]).hypot(v[2]) > STATIC_SPEED_M_S
    }) {
        return Err(invalid(
            Data::Gnss,
            format!(
                "row {}: the vehicle moves ({:.2} m/s) during the static alignment's first \
                 {duration_s} s",
                k + 2,
                g_v[k][0].hypot(g_v[k][1]).hypot(g_v[k][2])
            ),
        ));
    }
    #[allow(clippy::cast_precision_loss)]
    let mean = |v: &[[f64; 3]], s: f64| -> [f64; 3] {
        let sum = v[..i0]
            .iter()
            .fold([0.0; 3], |a, x| [0, 1, 2].map(|j| a[j] + x[j]));
        sum.map(|x| s * (x / i0 as f64))
    };
    let position = fixes.position[used - 1];
    let part = PartFigures {
        accel_bias_m_s2: setup.part_bias[0],
        gyro_bias_rad_s: setup.part_bias[1],
        accel_psd: setup.noise.accel_psd,
        gyro_psd: setup.noise.gyro_psd,
    };
    let aligned = align::at_rest(
        earth,
        &position,
        mean(&inputs.f, setup.specific_force_factor()),
        mean(&inputs.w, 1.0),
        t[i0] - t0,
        &part,
    )
    .map_err(|source| Error::Align {
        start: "static",
        source,
    })?;
    let sigma = InitialSigma {
        position_m: setup
            .gnss_position_sigma_m
            .iter()
            .fold(0.0_f64, |a, b| a.max(*b)),
        velocity_m_s: 0.05,
        attitude_rad: [
            aligned.tilt_sigma_rad,
            aligned.tilt_sigma_rad,
            aligned.heading_sigma_rad,
        ],
        // What the averages took for the attitude stays a bias the filter must learn.
        accel_bias_m_s2: part.accel_bias_m_s2.max(1e-6),
        gyro_bias_rad_s: part.gyro_bias_rad_s.max(1e-9),
    };
    Ok(Begin {
        first: i0,
        state: NavState {
            t_s: t[i0],
            attitude: aligned.attitude,
            velocity_m_s: Vec3::zeros(),
            position,
        },
        origin: E::origin_at(&position),
        sigma,
        next_fix: used,
    })
}

/// The levelled start ([`Start::Level`]) at the end of the rest at the start: roll and pitch
/// from the mean specific force over the rest, heading zero, velocity zero; on the flat Earth at
/// the origin unless a fix came by then, on WGS-84 at the last fix by then.
///
/// # Errors
/// No rest at the start, a mean specific force that is not gravity, no fix by then on WGS-84.
fn level<E: NavEarth>(
    setup: &FuseSetup,
    inputs: &FusionInputs,
    fixes: &Fixes<E>,
) -> Result<Begin<E>> {
    let t = &inputs.t;
    let i0 = t.partition_point(|&ti| ti < t[0] + setup.rest_s);
    if setup.rest_s <= 0.0 || i0 < 2 || i0 >= t.len() {
        return Err(refused(
            RequestOption::Align,
            format!(
                "\"level\" levels the sensor over its rest at the start, and {}: give the rest's \
                 length (rest_s) if the log does start still, or another start",
                if setup.detect_rest {
                    "none was found in the readings".to_owned()
                } else {
                    format!("a rest of {} s leaves no samples after it", setup.rest_s)
                }
            ),
        ));
    }
    let sign = setup.specific_force_factor();
    #[allow(clippy::cast_precision_loss)]
    let mean =
        [0, 1, 2].map(|k| sign * inputs.f[..i0].iter().map(|x| x[k]).sum::<f64>() / i0 as f64);
    let part = PartFigures {
        accel_bias_m_s2: setup.part_bias[0],
        gyro_bias_rad_s: setup.part_bias[1],
        accel_psd: setup.noise.accel_psd,
        gyro_psd: setup.noise.gyro_psd,
    };
    let levelled = align::level::<E::Frame>(mean, setup.gravity_m_s2, 0.0, t[i0] - t[0], &part)
        .map_err(|source| Error::Align {
            start: "level",
            source,
        })?;
    let used = inputs.g_t.partition_point(|&x| x <= t[i0]);
    let position = match used.checked_sub(1) {
        Some(k) => fixes.position[k],
        None if !E::ROTATING => {
            E::fix_position([0.0; 3]).ok_or_else(|| refused(RequestOption::Align, "no origin"))?
        }
        None => {
            return Err(invalid(
                Data::Gnss,
                "no fix by the end of the rest: on the WGS-84 Earth the levelled start takes \
                 its position from the fixes",
            ));
        }
    };
    let sigma = InitialSigma {
        // The frame is the start's: its origin and heading are exact by definition.
        position_m: if used == 0 {
            0.0
        } else {
            setup
                .gnss_position_sigma_m
                .iter()
                .fold(0.0_f64, |a, b| a.max(*b))
        },
        velocity_m_s: super::REST_VELOCITY_SIGMA_M_S,
        attitude_rad: [levelled.tilt_sigma_rad, levelled.tilt_sigma_rad, 0.0],
        ..setup.initial_sigma
    };
    Ok(Begin {
        first: i0,
        state: NavState {
            t_s: t[i0],
            attitude: levelled.attitude,
            velocity_m_s: Vec3::zeros(),
            position,
        },
        origin: E::origin_at(&position),
        sigma,
        next_fix: used,
    })
}

/// The alignment from the first fix at speed ([`ALIGN_MIN_SPEED_M_S`]): its position moved on
/// by its velocity to the IMU sample it is applied at, its velocity, a nose-first attitude.
///
/// # Errors
/// No fix with a velocity that fast.
fn from_gnss<E: NavEarth>(
    earth: &E,
    setup: &FuseSetup,
    inputs: &FusionInputs,
    fixes: &Fixes<E>,
) -> Result<Begin<E>> {
    let (k, i0, age) = first_fix_at_speed(inputs, setup.gnss_latency_s)?;
    let v = fixes.velocity[k];
    // The fix was valid `age` before sample i0: moved on by its velocity.
    let position = E::position(earth.offset(&E::coordinates(&fixes.position[k]), &(v * age)));
    Ok(Begin {
        first: i0,
        state: NavState {
            t_s: inputs.t[i0],
            attitude: align::moving(&v),
            velocity_m_s: v,
            position,
        },
        origin: E::origin_at(&position),
        sigma: gnss_alignment_sigma(v.to_array(), setup),
        next_fix: k + 1,
    })
}

/// For the alignment from GNSS: the first fix `k` of `inputs` at [`ALIGN_MIN_SPEED_M_S`] or
/// more, the IMU sample `i0` it is applied at, and its age there (latency included), s.
///
/// # Errors
/// No fix that fast.
fn first_fix_at_speed(inputs: &FusionInputs, latency_s: f64) -> Result<(usize, usize, f64)> {
    if inputs.velocities == FixVelocity::None {
        return Err(invalid(
            Data::Gnss,
            "the fixes have no velocity (vel_* columns): the heading cannot be taken from \
             GNSS velocity (give the initial state, or --align static on the WGS-84 Earth)",
        ));
    }
    let k = inputs
        .g_v
        .iter()
        .position(|v| v[0].hypot(v[1]) >= ALIGN_MIN_SPEED_M_S)
        .ok_or_else(|| {
            invalid(
                Data::Gnss,
                format!(
                    "no fix with a horizontal speed of {ALIGN_MIN_SPEED_M_S} m/s or more: the \
                     heading cannot be taken from GNSS velocity (give the initial state \
                     instead)"
                ),
            )
        })?;
    let t = &inputs.t;
    let i0 = t.partition_point(|&ti| ti < inputs.g_t[k]).min(t.len() - 1);
    Ok((k, i0, t[i0] - inputs.g_t[k] + latency_s))
}
