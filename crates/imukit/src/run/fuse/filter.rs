//! One fusion, step by step: the inputs read and checked, the rest at the start found, the
//! stances marked, the start (a state, or an alignment), the filter built, every IMU sample
//! propagated with the fixes and aid readings due by then, the rows written (forward, or
//! smoothed after a backward pass).
use imu_core::fusion::{
    Eskf, EskfError, EskfState, FixErrorModel, GnssFix, SensorErrorEstimate, has_fix_errors,
    has_sensor_errors,
};
use imu_core::{Body, Vec3};

use super::adapt::FixNoiseScale;
use super::detect::{
    Detection, REST_START_SPEED_M_S, StanceThreshold, detected_rest_s, first_stance_s,
    longest_without_stance, rest_rate, stances_with_threshold,
};
use super::inputs::{FixVelocity, Fixes, FusionInputs, UNKNOWN_VELOCITY_SIGMA_M_S};
use super::recovery::{Acceptance, filter_refusal};
use super::rows::{RESETS_COLUMN, fused_columns, push_fused_row};
use super::setup::{FIX_WHITE_SIGMA_M, covariance_interval_refusal};
use super::smooth::{SMOOTHING_GAP_S, smoothed_rows};
use super::start::{ALIGN_ATTITUDE_ALLOWANCE_RAD, ALIGN_MIN_SPEED_M_S, Begin, begin};
use super::{Fuse, FuseSetup, FuseSummary, Start};
use crate::error::Data;
use crate::error::{Error, Result, Subject};
use crate::io::columns::FUSE_COLUMNS;
use crate::io::table::Table;
use crate::run::epochs::PackedEpochs;
use crate::run::fuse::aids::AidStreams;
use crate::run::nav_earth::NavEarth;

/// The fusion `job` on `earth` with `S` error states: the fused table, the forward filter's
/// own table when `job` keeps it, and what was done.
pub(super) fn fuse_on<E: NavEarth, const S: usize>(
    earth: E,
    job: Fuse<'_>,
) -> Result<(Table, Option<Table>, FuseSummary)> {
    let Fuse {
        imu,
        gnss,
        aids,
        start,
        setup,
        keep_filtered,
    } = job;
    let [h, _, v] = setup.gnss_position_sigma_m;
    let inputs = FusionInputs::read(imu, gnss, E::GNSS_COLUMNS, E::GNSS_HINT, [h, v])?;
    // The detectors' noise, when a detector runs.
    let detection = (setup.detect_rest || setup.zupt)
        .then(|| Detection::of(&inputs.t, &inputs.f, &inputs.w, setup))
        .flatten();
    let setup = &with_rest_found(setup, start, &inputs, detection.as_ref());
    let t = &inputs.t;
    let mut aids = AidStreams::new(aids, setup, inputs.span(), t.len())?;
    let (stances, stance_threshold, stance_gap) =
        mark_stances(&mut aids, &inputs, setup, detection.as_ref());
    let fixes = Fixes::<E>::of(&inputs)?;
    let begin = begin(&earth, start, setup, &inputs, &fixes)?;
    aids.start_at(t[begin.first]);
    let fix_errors = fix_error_model::<S>(setup, &inputs.g_t);
    let mut filter = new_filter::<E, S>(earth, &begin, setup, fix_errors)?;
    let mut rows = Rows::<E, S>::new(setup, keep_filtered);
    let mut acceptance = Acceptance::default();
    let mut next_fix = begin.next_fix;
    let mut noise_scale = FixNoiseScale::new(setup.max_fix_noise_scale);
    let sign = setup.specific_force_factor();
    for (i, &ti) in t.iter().enumerate().skip(begin.first) {
        filter
            .propagate(ti, inputs.w[i], inputs.f[i].map(|x| sign * x))
            .map_err(|e| filter_error(Data::Imu, e))?;
        apply_fixes(
            &mut filter,
            (&inputs, &fixes),
            (setup, fix_errors.is_some()),
            i,
            &mut next_fix,
            (&mut acceptance, &mut noise_scale),
        )?;
        aids.apply(&mut filter, ti, i, inputs.w[i])?;
        rows.push(&mut filter, &begin.origin, acceptance.resets, setup.smooth);
    }
    let (updates, rejected) = filter.update_counts();
    let (table, filtered) = rows.finish(filter, &t[begin.first..], &begin.origin, setup.smooth)?;
    Ok((
        table,
        filtered,
        FuseSummary {
            updates,
            rejected,
            resets: acceptance.resets,
            rest_s: setup.rest_s,
            rest_detected: setup.detect_rest,
            sensor_errors: setup.estimate_sensor_errors,
            fix_errors,
            states: S,
            fix_noise_scale: noise_scale.scale(),
            stance_samples: stances,
            repeats: inputs.repeats,
            stance_gap,
            stance_threshold,
            detection,
        },
    ))
}

/// `setup` with the rest at the start found in the readings when it is to be found
/// ([`FuseSetup::detect_rest`]): none for a start in motion, and none beyond the first fix that
/// moves (steady motion in a straight line reads like rest: a fix moving faster than 5σ of its
/// velocity before the rest's end overrules the readings, and then there is no rest at all).
fn with_rest_found(
    setup: &FuseSetup,
    start: Start<'_>,
    inputs: &FusionInputs,
    detection: Option<&Detection>,
) -> FuseSetup {
    let Some(detection) = detection.filter(|_| setup.detect_rest) else {
        return *setup;
    };
    let moving_at_start = match start {
        Start::State(initial) => {
            let v = initial.velocity_m_s;
            (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt() > REST_START_SPEED_M_S
        }
        // Aligned from a fix at speed: the vehicle moves.
        Start::AlignGnss => true,
        Start::AlignStatic { .. } | Start::Level => false,
    };
    let readings_still = if moving_at_start {
        0.0
    } else {
        let rest = detected_rest_s(&inputs.t, &inputs.f, &inputs.w, detection);
        // On a foot, the first stance is the rest at the start (a standing person sways,
        // beyond the white noise the rest detector allows).
        if setup.zupt {
            rest.max(first_stance_s(
                &inputs.t, &inputs.f, &inputs.w, setup, detection,
            ))
        } else {
            rest
        }
    };
    let moves_at = (inputs.velocities != FixVelocity::None)
        .then(|| {
            let limit = 5.0 * setup.gnss_velocity_sigma_m_s.unwrap_or(1.0);
            inputs.g_t.iter().zip(&inputs.g_v).find(|(_, v)| {
                let vertical = if inputs.velocities == FixVelocity::Full {
                    v[2]
                } else {
                    0.0
                };
                (v[0] * v[0] + v[1] * v[1] + vertical * vertical).sqrt() > limit
            })
        })
        .flatten()
        .map_or(f64::INFINITY, |(tk, _)| tk - inputs.t[0]);
    FuseSetup {
        rest_s: if moves_at < readings_still {
            0.0
        } else {
            readings_still
        },
        ..*setup
    }
}

/// Marks the stances for zero-velocity updates when `setup` asks for them
/// ([`FuseSetup::zupt`]): how many samples are stances, the threshold used, and the longest
/// stretch without one after the rest.
fn mark_stances(
    aids: &mut AidStreams,
    inputs: &FusionInputs,
    setup: &FuseSetup,
    detection: Option<&Detection>,
) -> (usize, Option<StanceThreshold>, Option<(f64, f64)>) {
    let Some(detection) = detection.filter(|_| setup.zupt) else {
        return (0, None, None);
    };
    let (stance, threshold) =
        stances_with_threshold(&inputs.t, &inputs.f, &inputs.w, setup, detection);
    let count = stance.iter().filter(|s| **s).count();
    let gap = longest_without_stance(&inputs.t, &stance, setup.rest_s);
    aids.set_stance(stance, rest_rate(&inputs.t, &inputs.w, setup.rest_s));
    (count, Some(threshold), gap)
}

/// The filter's refusal of `context` (a setting or the IMU data), without a row.
fn filter_error(context: impl Into<Subject>, source: EskfError) -> Error {
    Error::Filter {
        context: context.into(),
        row: None,
        source,
    }
}

/// The fixes' correlated error for a filter of `S` states, the decay factor's interval the
/// fixes' median one (at times `g_t`): `None` without the fix-error states or with fewer than
/// two fixes.
fn fix_error_model<const S: usize>(setup: &FuseSetup, g_t: &[f64]) -> Option<FixErrorModel> {
    if !has_fix_errors(S) {
        return None;
    }
    let interval_s = crate::io::rows::Gaps::of_times(g_t, 0).median_s;
    setup.fix_error_model(interval_s)
}

/// The filter at `begin` on `earth`, with `setup`'s noise, covariance interval, sensor-error
/// states, the fixes' correlated errors (`fix_errors`) and smoothing.
fn new_filter<E: NavEarth, const S: usize>(
    earth: E,
    begin: &Begin<E>,
    setup: &FuseSetup,
    fix_errors: Option<FixErrorModel>,
) -> Result<Eskf<E, S>> {
    let start = EskfState {
        nav: begin.state,
        accel_bias_m_s2: [0.0; 3],
        gyro_bias_rad_s: [0.0; 3],
    };
    let filter = Eskf::<E, S>::new(earth, &start, &begin.sigma, setup.noise)
        .map_err(|e| filter_error("filter", e))?
        .with_covariance_interval(setup.covariance_interval_s)
        .map_err(|_| covariance_interval_refusal(setup))?;
    let filter = if has_sensor_errors(S) {
        filter
            .with_sensor_error_sigma(&setup.sensor_error_sigma)
            .map_err(|e| filter_error("sensor_error_sigma", e))?
    } else {
        filter
    };
    let filter = match fix_errors {
        Some(model) => filter
            .with_fix_errors(model)
            .map_err(|e| filter_error("gnss", e))?,
        None => filter,
    };
    if setup.smooth {
        filter
            .with_smoothing(SMOOTHING_GAP_S)
            .map_err(|e| filter_error("smooth", e))
    } else {
        Ok(filter)
    }
}

/// Applies every fix from `next_fix` stamped at or before IMU sample `i`, each valid its
/// latency before its stamp; after [`MAX_REJECTED_IN_A_ROW`](super::MAX_REJECTED_IN_A_ROW)
/// rejected in a row the filter is reset to the fix, the heading along its velocity when the
/// vehicle moves. With the fix-error states (`correlated`) a fix is told only its white part:
/// its own accuracy columns, else [`FIX_WHITE_SIGMA_M`].
fn apply_fixes<E: NavEarth, const S: usize>(
    filter: &mut Eskf<E, S>,
    (inputs, fixes): (&FusionInputs, &Fixes<E>),
    (setup, correlated): (&FuseSetup, bool),
    i: usize,
    next_fix: &mut usize,
    (acceptance, noise_scale): (&mut Acceptance, &mut FixNoiseScale),
) -> Result<()> {
    let (t, g_t) = (&inputs.t, &inputs.g_t);
    if !(*next_fix < g_t.len() && g_t[*next_fix] <= t[i]) {
        return Ok(()); // no fix due: most samples
    }
    let vel_sigma = setup.gnss_velocity_sigma_m_s.unwrap_or(1.0);
    // The third axis is the vertical in either frame (up in ENU, down in NED).
    let vertical_sigma = if inputs.velocities == FixVelocity::Horizontal {
        UNKNOWN_VELOCITY_SIGMA_M_S
    } else {
        vel_sigma
    };
    while *next_fix < g_t.len() && g_t[*next_fix] <= t[i] {
        let k = *next_fix;
        let root = noise_scale.scale().sqrt();
        let fix = GnssFix::<E> {
            position: fixes.position[k],
            velocity_m_s: setup
                .gnss_velocity_sigma_m_s
                .filter(|_| inputs.velocities != FixVelocity::None)
                .map(|_| fixes.velocity[k]),
            lever_arm_m: Vec3::<Body>::from_array(setup.lever_arm_m),
            position_sigma_m: inputs
                .accuracy
                .as_ref()
                .map_or(
                    if correlated {
                        [FIX_WHITE_SIGMA_M; 3]
                    } else {
                        setup.gnss_position_sigma_m
                    },
                    |a| a[k],
                )
                .map(|s| s * root),
            velocity_sigma_m_s: [vel_sigma, vel_sigma, vertical_sigma].map(|s| s * root),
            // Valid at its stamp minus the latency; applied at this IMU sample.
            age_s: t[i] - g_t[k] + setup.gnss_latency_s,
        };
        let outcome = filter.update(&fix, setup.gate);
        if let Ok(o) = &outcome {
            let rows = if fix.velocity_m_s.is_some() { 6 } else { 3 };
            if let Some(change) = noise_scale.observe(o.nis, rows) {
                filter
                    .scale_fix_errors(change)
                    .map_err(|e| filter_refusal(Data::Gnss, k, e))?;
            }
        }
        if acceptance.count(outcome, k, setup.gate)? {
            let heading = fix.velocity_m_s.and_then(|v| {
                let speed = v.x().hypot(v.y());
                (speed >= ALIGN_MIN_SPEED_M_S).then(|| {
                    (vel_sigma / speed)
                        .atan()
                        .hypot(ALIGN_ATTITUDE_ALLOWANCE_RAD[0])
                })
            });
            filter
                .reset_to_gnss(&fix, heading)
                .map_err(|e| filter_refusal(Data::Gnss, k, e))?;
        }
        *next_fix += 1;
    }
    Ok(())
}

/// The fused table as it grows: the forward filter's rows, or (smoothing) the epochs and
/// filtered states the backward pass needs, with the forward rows in a table of their own
/// when they are kept.
struct Rows<E: NavEarth, const S: usize> {
    table: Table,
    filtered_table: Option<Table>,
    row: Vec<f64>,
    last_yaw: Option<f64>,
    epochs: PackedEpochs<S>,
    filtered: Vec<(EskfState<E>, SensorErrorEstimate, usize)>,
}

impl<E: NavEarth, const S: usize> Rows<E, S> {
    /// An empty table of the fused columns on `E` (the sensor errors' with `S` full states,
    /// the resets last); the forward rows kept apart when smoothing with `keep_filtered`.
    fn new(setup: &FuseSetup, keep_filtered: bool) -> Self {
        let mut columns: Vec<&str> = FUSE_COLUMNS.to_vec();
        columns.extend(E::POSITION_COLUMNS);
        let mut columns = fused_columns(&columns, has_sensor_errors(S));
        columns.push(RESETS_COLUMN.to_string());
        let filtered_table = (setup.smooth && keep_filtered).then(|| Table {
            columns: columns.clone(),
            data: Vec::new(),
        });
        let width = columns.len();
        Self {
            table: Table {
                columns,
                data: Vec::new(),
            },
            filtered_table,
            row: Vec::with_capacity(width),
            last_yaw: None,
            epochs: PackedEpochs::new(),
            filtered: Vec::new(),
        }
    }

    /// The filter's state after a sample: a row, or (smoothing) what the backward pass needs.
    fn push(&mut self, filter: &mut Eskf<E, S>, origin: &E::Origin, resets: usize, smooth: bool) {
        let s = filter.state();
        if !smooth {
            let sig = filter.sigmas();
            push_fused_row(
                &mut self.table,
                &mut self.row,
                (&s, &filter.sensor_errors(), &sig),
                (origin, &mut self.last_yaw),
                resets,
            );
            return;
        }
        while let Some(e) = filter.take_epoch() {
            self.epochs.push(&e);
        }
        let errors = filter.sensor_errors();
        self.filtered.push((s, errors, resets));
        if let Some(kept) = self.filtered_table.as_mut() {
            push_fused_row(
                kept,
                &mut self.row,
                (&s, &errors, &filter.sigmas()),
                (origin, &mut self.last_yaw),
                resets,
            );
        }
    }

    /// The finished tables, checked finite: the smoothed one after the backward pass over the
    /// samples at times `t` when smoothing, and the forward one when kept.
    ///
    /// # Errors
    /// A value that is not finite.
    fn finish(
        mut self,
        mut filter: Eskf<E, S>,
        t: &[f64],
        origin: &E::Origin,
        smooth: bool,
    ) -> Result<(Table, Option<Table>)> {
        if smooth {
            filter.finish_smoothing();
            while let Some(e) = filter.take_epoch() {
                self.epochs.push(&e);
            }
            smoothed_rows::<E, S>(
                filter.earth(),
                &self.epochs,
                &self.filtered,
                t,
                (&mut self.table, &mut self.row),
                origin,
            );
        }
        self.table.check_finite("fused navigation")?;
        if let Some(kept) = &self.filtered_table {
            kept.check_finite("fused navigation")?;
        }
        Ok((self.table, self.filtered_table))
    }
}
