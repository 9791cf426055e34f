//! The streamed integration of an IMU file (memory does not grow with the file), and the
//! whole-table readers it falls back on.
use std::collections::VecDeque;
use std::path::Path;

use imu_core::AccelSign;
use imu_core::earth::EarthModel;
use imu_core::strapdown::rk4::{NODES, RateWindow, window_start};
use imu_core::strapdown::{
    Increments, NavState, RateIncrements, Rk4, StrapdownError, VerticalChannel,
};

use super::{
    BARO_COLUMN, EarthNav, Emit, InitialState, NavScheme, NavSetup, integrate, strapdown_options,
    with_earth,
};
use crate::error::Data;
use crate::error::{Result, invalid};
use crate::io::Input;
use crate::io::columns::{ACCEL_COLUMNS, DTHETA_COLUMNS, DV_COLUMNS, GYRO_COLUMNS};
use crate::io::output::AtomicFile;
use crate::io::rows::{Gaps, Repeats, TimeWindow, TimedRows};
use crate::io::table::Table;
use crate::run::nav_earth::{self, EarthJob, NavEarth};

/// What a streamed integration wrote.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct NavSummary {
    /// Rows written.
    pub rows: usize,
    /// The scheme used (what [`NavScheme::Auto`] chose).
    pub scheme: NavScheme,
    /// The last position in the plane, m.
    pub end_position_m: [f64; 3],
    /// The gaps in the sample times, integrated across.
    pub gaps: Gaps,
    /// The rows dropped as exact copies of the row before (a logger's repeats).
    pub repeats: Repeats,
}

/// Integrates the IMU CSV file `input` into the navigation CSV `out` (the columns of
/// [`integrate`]), the same numbers as [`integrate`], streamed: memory does not grow with the
/// file (the RK4 scheme holds the six samples around its current interval); gaps are judged
/// against the median interval of the first [`GAP_WINDOW`](crate::io::rows::GAP_WINDOW) rows
/// and reported in the summary.
/// The baro-damped vertical channel reads the file whole (within the memory budget of
/// [`read_whole`]). `out` appears only when complete. Only the rows of `window` are integrated,
/// from `initial` at the first of them.
///
/// # Errors
/// As [`integrate`], CSV errors naming file, row and column, a window that holds no row, and
/// I/O errors.
pub fn integrate_csv(
    input: impl Into<Input>,
    initial: &InitialState,
    setup: &NavSetup,
    window: TimeWindow,
    out: &Path,
) -> Result<NavSummary> {
    let input = &input.into();
    if let Some(EarthNav {
        vertical: VerticalChannel::Baro { .. },
        ..
    }) = setup.earth
    {
        let imu = read_whole(input)?;
        let t0 = TimeWindow::first_time(&imu, &input.path().display().to_string())?;
        let imu = window.apply(imu, t0, &input.path().display().to_string(), 1)?;
        let nav = integrate(&imu, initial, setup)?;
        let rates = ACCEL_COLUMNS
            .iter()
            .chain(&GYRO_COLUMNS)
            .all(|c| imu.columns.iter().any(|h| h == c));
        nav.write_described(out, &setup.description())?;
        let last = |c: &str| nav.column(c).and_then(|v| v.last().copied()).unwrap_or(0.0);
        return Ok(NavSummary {
            rows: nav.rows(),
            scheme: setup
                .scheme
                .for_input(rates, setup.options.coning || setup.options.sculling),
            end_position_m: [last("pos_x_m"), last("pos_y_m"), last("pos_z_m")],
            gaps: Gaps::of_times(&imu.column("t_s").unwrap_or_default(), 2),
            // Read whole, the readings' times are checked as they are: a repeat is refused.
            repeats: Repeats::default(),
        });
    }
    with_earth(
        setup,
        IntegrateCsv {
            input,
            initial,
            setup,
            window,
            out,
        },
    )
}

/// Reads an IMU CSV file whole, refused before reading when it could exceed the memory budget
/// of [`check_in_memory`](crate::io::memory::check_in_memory) with what the navigation keeps per
/// sample.
///
/// # Errors
/// The budget, and the reader's errors naming file, row and column.
pub fn read_whole(input: impl Into<Input>) -> Result<Table> {
    let input = input.into();
    let bytes = std::fs::metadata(input.path())
        .map_err(|source| crate::Error::Io {
            path: input.path().into(),
            source,
        })?
        .len();
    // A CSV value takes at least 2 bytes; each becomes a number in the table, and about 30
    // numbers per row come out (the states and the table).
    let rows_at_most = usize::try_from(bytes / 14).unwrap_or(usize::MAX);
    crate::io::memory::check_in_memory(rows_at_most, 8 * 7 * 2 + 8 * 17 * 2, Data::Imu)?;
    crate::io::read::read_table(input)
}

/// `imu` with a [`BARO_COLUMN`] taken from barometer readings `baro` (`t_s, baro_height_m`,
/// as `imukit simulate --baro` writes): each IMU sample gets the last reading at or before it
/// (the first reading before the first one).
///
/// # Errors
/// Missing columns, times that do not increase or fall outside the IMU's span, values that are
/// not finite, an empty file.
pub fn with_baro_column(imu: &Table, baro: &Table) -> Result<Table> {
    let t = imu
        .column("t_s")
        .ok_or_else(|| invalid(Data::Imu, "missing column t_s"))?;
    let (Some(&t0), Some(&t1)) = (t.first(), t.last()) else {
        return Err(invalid(Data::Imu, "has no rows"));
    };
    // The same rule as the fusion's aids: finite, increasing, within the IMU's span.
    let (tb, hb) =
        crate::run::fuse::aids::aid_series(baro, Data::Barometer, BARO_COLUMN, (t0, t1))?;
    if tb.is_empty() {
        return Err(invalid(Data::Barometer, "has no readings"));
    }
    let mut columns: Vec<&str> = imu.columns.iter().map(String::as_str).collect();
    if columns.contains(&BARO_COLUMN) {
        return Err(invalid(
            Data::Imu,
            format!("already has a {BARO_COLUMN} column; give the barometer once"),
        ));
    }
    columns.push(BARO_COLUMN);
    let mut out = Table::new(&columns);
    let width = imu.columns.len();
    let mut k = 0;
    for (i, ti) in t.iter().enumerate() {
        while k + 1 < tb.len() && tb[k + 1] <= *ti {
            k += 1;
        }
        let mut row = imu.data[i * width..(i + 1) * width].to_vec();
        row.push(hb[k]);
        out.push_row(&row);
    }
    Ok(out)
}

/// What the strapdown needs of its input, and the way to it from a vendor's columns.
pub(super) const NEEDS_READINGS: &str = "needs accel_x/y/z_m_s2 and gyro_x/y/z_rad_s (rates) or dv_x/y/z_m_s \
     and dtheta_x/y/z_rad (increments); a vendor's CSV is read through a column map (--map FILE, \
     docs/formats.md)";

/// The per-sample integrator of a streamed file.
enum Stepper<E: EarthModel> {
    Rates(RateIncrements<E>),
    Increments {
        nav: Increments<E>,
        initial: NavState<E>,
        started: bool,
    },
    /// RK4 holds the samples its next interval's quintic needs (six, from two before it) and
    /// emits each state once the three samples after the interval have been read (at the end
    /// of the file, the last intervals share the final six samples).
    Rk4 {
        nav: Rk4<E>,
        initial: NavState<E>,
        held: VecDeque<[f64; 7]>,
        first_held: usize,
        seen: usize,
        next_interval: usize,
    },
}

impl<E: EarthModel> Stepper<E> {
    /// Takes the next row `[t, force, turn]` (force: accelerometer or Δv, physical sign; turn:
    /// gyroscope or Δθ) and emits the states it completes, in order.
    fn push(&mut self, row: [f64; 7], emit: &mut Emit<'_, E>) -> Result<()> {
        let (t, force, turn) = (row[0], [row[1], row[2], row[3]], [row[4], row[5], row[6]]);
        let failed = |source: StrapdownError| crate::Error::Strapdown {
            context: Data::Imu.label().into(),
            source,
        };
        match self {
            Self::Rates(r) => emit(r.step(t, turn, force).map_err(failed)?),
            Self::Increments {
                initial, started, ..
            } if !*started => {
                *started = true;
                emit(*initial)
            }
            Self::Increments { nav, .. } => emit(nav.step(t, turn, force).map_err(failed)?),
            Self::Rk4 {
                nav,
                initial,
                held,
                first_held,
                seen,
                next_interval,
            } => {
                // Rows come from `TimedRows`: finite, times increasing.
                held.push_back(row);
                *seen += 1;
                if *seen == 1 {
                    return emit(NavState { t_s: t, ..*initial });
                }
                // Interval k's window starts at k − 2 (or 0) unless the file ends within three
                // samples after it, which is known once sample max(k + 3, 5) is read.
                while *seen >= (*next_interval + 4).max(NODES) {
                    let k = *next_interval;
                    let start = k.saturating_sub(NODES / 2 - 1);
                    emit(
                        nav.interval(&window(held, start - *first_held), k - start, 0.0, k + 1)
                            .map_err(failed)?,
                    )?;
                    *next_interval += 1;
                    while held.len() > NODES && *first_held + NODES / 2 - 1 < *next_interval {
                        held.pop_front();
                        *first_held += 1;
                    }
                }
                Ok(())
            }
        }
    }

    /// Emits the states still held once the file has ended.
    fn finish(&mut self, emit: &mut Emit<'_, E>) -> Result<()> {
        let Self::Rk4 {
            nav,
            held,
            first_held,
            seen,
            next_interval,
            ..
        } = self
        else {
            return Ok(());
        };
        let n = *seen;
        if n < NODES {
            return Err(invalid(
                Data::Imu,
                format!("the rk4 scheme needs at least {NODES} samples, got {n}"),
            ));
        }
        for k in *next_interval..n - 1 {
            let start = window_start(k, n);
            let state = nav
                .interval(&window(held, start - *first_held), k - start, 0.0, k + 1)
                .map_err(|source| crate::Error::Strapdown {
                    context: Data::Imu.label().into(),
                    source,
                })?;
            emit(state)?;
        }
        *next_interval = n - 1;
        Ok(())
    }
}

/// The six held rows from `offset` as an RK4 window.
fn window(held: &VecDeque<[f64; 7]>, offset: usize) -> RateWindow {
    let row = |j: usize| &held[offset + j];
    RateWindow {
        t_s: std::array::from_fn(|j| row(j)[0]),
        gyro_rad_s: std::array::from_fn(|j| [row(j)[4], row(j)[5], row(j)[6]]),
        accel_m_s2: std::array::from_fn(|j| [row(j)[1], row(j)[2], row(j)[3]]),
    }
}

/// [`integrate_csv`] as an [`EarthJob`].
struct IntegrateCsv<'a> {
    input: &'a Input,
    initial: &'a InitialState,
    setup: &'a NavSetup,
    window: TimeWindow,
    out: &'a Path,
}

impl EarthJob for IntegrateCsv<'_> {
    type Output = Result<NavSummary>;

    fn run<E: NavEarth>(self, earth: E) -> Result<NavSummary> {
        let Self {
            input,
            initial,
            setup,
            window,
            out,
        } = self;
        let options = strapdown_options(setup);
        let header = crate::io::read::read_header(input)?;
        let has_all = |cols: &[&str]| cols.iter().all(|c| header.iter().any(|h| h == c));
        let rates = has_all(&ACCEL_COLUMNS) && has_all(&GYRO_COLUMNS);
        let (force, turn) = if rates {
            (ACCEL_COLUMNS, GYRO_COLUMNS)
        } else if has_all(&DV_COLUMNS) && has_all(&DTHETA_COLUMNS) {
            (DV_COLUMNS, DTHETA_COLUMNS)
        } else {
            return Err(invalid(Data::Imu, NEEDS_READINGS));
        };
        let mut columns = vec!["t_s"];
        columns.extend(force);
        columns.extend(turn);
        let mut rows = TimedRows::open(input, &columns, "")?.within(window);
        let start = rows.start_time()?;
        let (s0, origin) = nav_earth::start::<E>(initial, start)?;
        let failed = |source: StrapdownError| crate::Error::Strapdown {
            context: "initial state".into(),
            source,
        };
        let scheme = setup
            .scheme
            .for_input(rates, options.coning || options.sculling);
        let mut stepper = match (scheme, rates) {
            (NavScheme::ConingSculling, true) => {
                Stepper::Rates(RateIncrements::new(earth, s0, options).map_err(failed)?)
            }
            (NavScheme::ConingSculling, false) => Stepper::Increments {
                nav: Increments::new(earth, &s0, options).map_err(failed)?,
                initial: s0,
                started: false,
            },
            (NavScheme::Rk4 { substeps }, true) => Stepper::Rk4 {
                nav: Rk4::new(earth, &s0, options, substeps).map_err(failed)?,
                initial: s0,
                held: VecDeque::with_capacity(NODES + 1),
                first_held: 0,
                seen: 0,
                next_interval: 0,
            },
            (NavScheme::Rk4 { .. }, false) => {
                return Err(invalid(
                    Data::Imu,
                    "the rk4 scheme needs rates (accel_*, gyro_*), not increments",
                ));
            }
            (NavScheme::Auto { .. }, _) => unreachable!("for_input chooses a concrete scheme"),
        };
        let sign = match setup.accel_sign {
            AccelSign::SpecificForce => 1.0,
            AccelSign::Matlab => -1.0,
        };
        let mut file = AtomicFile::create(out)?;
        let columns: Vec<String> = nav_earth::nav_columns::<E>()
            .iter()
            .map(|c| (*c).to_string())
            .collect();
        file.begin_table(&columns, &setup.description())?;
        let width = nav_earth::nav_width::<E>();
        let (mut last_yaw, mut end, mut written) = (None, s0, 0usize);
        let mut write = |state: NavState<E>, file: &mut AtomicFile| -> Result<()> {
            file.write_row(&nav_earth::nav_row(&state, &origin, &mut last_yaw)[..width])?;
            end = state;
            written += 1;
            Ok(())
        };
        let mut r = [0.0; 7];
        while rows.next_row(&mut r)? {
            let row = [
                r[0],
                sign * r[1],
                sign * r[2],
                sign * r[3],
                r[4],
                r[5],
                r[6],
            ];
            stepper.push(row, &mut |state| write(state, &mut file))?;
        }
        stepper.finish(&mut |state| write(state, &mut file))?;
        file.commit()?;
        Ok(NavSummary {
            rows: written,
            scheme,
            end_position_m: E::plane_m(&end.position, &origin),
            gaps: rows.gaps(),
            repeats: rows.repeats(),
        })
    }
}
