//! Streamed simulation: truth and readings in chunks of up to [`STREAM_CHUNK`] samples
//! ([`stream_chunk`]), the same numbers as [`Scenario::simulate`] bit for bit, written as they
//! are made.
//!
//! Analytic trajectories (expression, track, waypoints, and the built-ins made of them) are
//! evaluated sample by sample with the core's [`AnalyticStepper`] at times computed on demand, so
//! memory does not grow with the duration (only the leading standstill of a tangent attitude is
//! held until the body first moves). Sampled trajectories are read whole (their samples) and
//! differentiated chunk by chunk (whole for a tangent attitude); body-rate trajectories are
//! integrated whole; then everything is streamed. With [`RunThreads`] two, the truth is made a
//! chunk ahead on a second thread ([`crate::run::pipeline`]); the numbers do not change.
use std::path::Path;

use imu_core::kinematics::sampled::backfill_standstill;
use imu_core::sensor::ImuReading;
use imu_core::{Enu, NavFrame, Ned, Truth};

use crate::error::Result;
use crate::io::TableFormat;
use crate::io::bag::BagOptions;
use crate::io::conventions::NavFrameName;
use crate::io::description::Description;
use crate::io::output::AtomicFile;
use crate::io::schema::TableKind;
use crate::io::table::{ImuOutput, Table, check_finite_from};
use crate::motion::analytic::{AnalyticOptions, AnalyticStepper, DERIVATIVE_CHUNK, Motion};
use crate::motion::{Trajectory, with_time};
use crate::run::pipeline::{RunThreads, Stage, run_in_stages};
use crate::scenario::report::RunReport;
use crate::scenario::{SampleTimes, Scenario};

/// Samples per streamed chunk, at most.
pub const STREAM_CHUNK: usize = 4096;

/// Samples per streamed chunk, at least (unless the run is shorter).
pub const MIN_STREAM_CHUNK: usize = 512;

/// The chunk a run of `samples` samples is streamed in: [`STREAM_CHUNK`] for a long run, and an
/// eighth of the run for a shorter one (at least [`MIN_STREAM_CHUNK`]), so that a run of 10⁴
/// samples is still eight chunks for two threads to overlap. The numbers do not depend on it.
#[must_use]
pub fn stream_chunk(samples: usize) -> usize {
    samples.div_ceil(8).clamp(MIN_STREAM_CHUNK, STREAM_CHUNK)
}

/// One chunk of a streamed simulation: truth rows and IMU rows, the columns of
/// [`crate::Simulation`]'s tables.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Chunk {
    /// Truth rows.
    pub truth: Table,
    /// IMU rows (rates or increments).
    pub imu: Table,
    /// GNSS fixes in this chunk, when the scenario has a receiver.
    pub gnss: Option<Table>,
    /// Barometer readings in this chunk, when the scenario has one.
    pub baro: Option<Table>,
    /// Odometer readings in this chunk, when the scenario has one.
    pub odometer: Option<Table>,
    /// What this chunk's readings and motion say the user should know (clipped readings, the
    /// largest turn between two samples).
    pub report: RunReport,
}

/// The rows and columns of the truth and IMU tables a whole run gathers
/// ([`Scenario::gathered_shape`]).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct GatheredShape {
    /// Samples (rows of each table).
    pub rows: usize,
    /// Truth columns ([`Scenario::truth_columns`]).
    pub truth_columns: Vec<&'static str>,
    /// IMU columns ([`ImuOutput::columns`]).
    pub imu_columns: Vec<&'static str>,
}

/// The aids' readings of a whole run, when the scenario has them.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct AidTables {
    /// GNSS fixes.
    pub gnss: Option<Table>,
    /// Barometer readings.
    pub baro: Option<Table>,
    /// Odometer readings.
    pub odometer: Option<Table>,
    /// The run's report: readings clipped at the sensors' ranges, the largest turn between two
    /// samples ([`RunReport::warnings`]).
    pub report: RunReport,
}

/// Where [`Scenario::stream_to_files`] writes: the IMU readings, and the truth and the aids'
/// readings when asked for.
#[derive(Clone, Copy, Debug)]
pub struct StreamOutputs<'a> {
    /// IMU readings.
    pub imu: Option<&'a Path>,
    /// Truth.
    pub truth: Option<&'a Path>,
    /// GNSS fixes (the scenario must have `[gnss]`).
    pub gnss: Option<&'a Path>,
    /// Barometer readings (`[baro]`).
    pub baro: Option<&'a Path>,
    /// Odometer readings (`[odometer]`).
    pub odometer: Option<&'a Path>,
    /// What the outputs hold ([`Scenario::description`]; each file's kind is added from its
    /// columns).
    pub description: &'a Description,
    /// The IMU readings and the truth in the ASL layout of a EuRoC sequence
    /// ([`crate::io::asl`]) instead of imukit's tables.
    pub asl: bool,
    /// A bag's IMU topic, frame id and start stamp (`None`: `/imu`, `imu_link`, 0 s).
    pub bag: Option<&'a BagOptions>,
}

/// An empty description, for outputs that say nothing beyond their kind.
static NO_DESCRIPTION: Description = Description {
    kind: None,
    nav_frame: None,
    earth: None,
    origin: None,
    gravity_m_s2: None,
    earth_gravity: None,
    accel_sign: None,
    sensor: None,
    scenario: None,
};

impl Default for StreamOutputs<'_> {
    fn default() -> Self {
        Self {
            imu: None,
            truth: None,
            gnss: None,
            baro: None,
            odometer: None,
            description: &NO_DESCRIPTION,
            asl: false,
            bag: None,
        }
    }
}

impl Scenario {
    /// Runs the scenario (Monte Carlo run `run`, or the plain seed) on `threads` and hands each
    /// chunk to `sink` in order, on the caller's thread; the chunks together equal
    /// [`Scenario::simulate`] / [`Scenario::simulate_run`] however many threads made them.
    ///
    /// # Errors
    /// The core's refusal (with the time), invalid parameters, or the sink's error.
    pub fn stream(
        &self,
        run: Option<u64>,
        threads: RunThreads,
        sink: impl FnMut(&Chunk) -> Result<()>,
    ) -> Result<()> {
        self.stream_with(run, threads, true, sink)
    }

    /// [`Self::stream`], the chunks' truth tables left empty unless `truth_table` (on the flat
    /// Earth: a run whose truth nobody writes does not tabulate it).
    fn stream_with(
        &self,
        run: Option<u64>,
        threads: RunThreads,
        truth_table: bool,
        mut sink: impl FnMut(&Chunk) -> Result<()>,
    ) -> Result<()> {
        match self.nav_frame {
            NavFrameName::ENU => self.stream_in::<Enu>(run, threads, truth_table, &mut sink),
            NavFrameName::NED => self.stream_in::<Ned>(run, threads, truth_table, &mut sink),
        }
    }

    /// Streams run `run` on `threads` into the files of `outputs` (CSV, Parquet, `.npy` or `.npz`
    /// by extension); each file appears only when complete.
    ///
    /// Returns the run's report ([`RunReport::warnings`] says what the user should know).
    ///
    /// # Errors
    /// As [`Scenario::stream`], an aid's file without that aid in the scenario, and I/O errors
    /// naming the file.
    pub fn stream_to_files(
        &self,
        run: Option<u64>,
        threads: RunThreads,
        outputs: &StreamOutputs<'_>,
    ) -> Result<RunReport> {
        for (path, present, field, what) in [
            (
                outputs.gnss,
                self.gnss.is_some(),
                "gnss",
                "a GNSS file was asked for, but the scenario has no [gnss] receiver",
            ),
            (
                outputs.baro,
                self.baro.is_some(),
                "baro",
                "a barometer file was asked for, but the scenario has no [baro]",
            ),
            (
                outputs.odometer,
                self.odometer.is_some(),
                "odometer",
                "an odometer file was asked for, but the scenario has no [odometer]",
            ),
        ] {
            if path.is_some() && !present {
                return Err(crate::error::invalid(field, what));
            }
        }
        let open = |p: Option<&Path>, asl: bool| {
            p.map(|p| TableSink::create(p, outputs.description, asl, outputs.bag))
                .transpose()
        };
        let (mut imu, mut truth) = (
            open(outputs.imu, outputs.asl)?,
            open(outputs.truth, outputs.asl)?,
        );
        let (mut gnss, mut baro, mut odometer) = (
            open(outputs.gnss, false)?,
            open(outputs.baro, false)?,
            open(outputs.odometer, false)?,
        );
        // A bag given for the readings holds the truth and the fixes too (unless they have files
        // of their own).
        let bag = imu.as_ref().is_some_and(|s| s.format == TableFormat::Mcap);
        let (bag_truth, bag_gnss) = (bag && truth.is_none(), bag && gnss.is_none());
        let tabulate = truth.is_some() || bag_truth;
        // Whether any file is CSV: it decides how two threads share the run (below).
        let text = [&imu, &truth, &gnss, &baro, &odometer]
            .into_iter()
            .flatten()
            .any(|s| s.format == TableFormat::Csv);
        let mut report = RunReport::default();
        let mut write = |chunks: &[Chunk]| -> Result<()> {
            for chunk in chunks {
                report.merge(&chunk.report);
                if let Some(sink) = imu.as_mut().filter(|_| bag) {
                    let tables = [
                        Some(&chunk.imu),
                        Some(&chunk.truth).filter(|_| bag_truth),
                        chunk.gnss.as_ref().filter(|_| bag_gnss),
                    ];
                    let tables: Vec<&Table> = tables.into_iter().flatten().collect();
                    sink.write_bag(&tables)?;
                }
                for (sink, table) in [
                    (&mut imu, Some(&chunk.imu).filter(|_| !bag)),
                    (&mut truth, Some(&chunk.truth)),
                    (&mut gnss, chunk.gnss.as_ref()),
                    (&mut baro, chunk.baro.as_ref()),
                    (&mut odometer, chunk.odometer.as_ref()),
                ] {
                    if let (Some(s), Some(t)) = (sink.as_mut(), table) {
                        s.write(t)?;
                    }
                }
            }
            Ok(())
        };
        let chunks = self.t_s.len().div_ceil(stream_chunk(self.t_s.len()));
        // Formatting CSV takes about as long as making the truth and readings: on two threads,
        // those files are written on the caller's thread while the chunks after are made on the
        // other. Binary files take little writing: there, as for tables, the truth is made a
        // chunk ahead on the second thread (1.1–1.2× faster than the other split, measured).
        // Three threads do all three at once.
        let (writer, maker) = match threads.stages(chunks) {
            1 => (RunThreads::One, RunThreads::One),
            2 if text => (RunThreads::Two, RunThreads::One),
            2 => (RunThreads::One, RunThreads::Two),
            _ => (RunThreads::Two, RunThreads::Two),
        };
        let make = |emit: Stage<'_, Chunk>| {
            self.stream_with(run, maker, tabulate, |c| emit(std::slice::from_ref(c)))
        };
        run_in_stages(writer, chunks, make, &mut write)?;
        for sink in [imu, truth, gnss, baro, odometer].into_iter().flatten() {
            sink.commit()?;
        }
        Ok(report)
    }

    /// The streamed simulation of run `run` (or the plain seed) on `threads`, gathered into whole
    /// tables: the numbers of [`Scenario::simulate`] / [`Scenario::simulate_run`] bit for bit,
    /// made a chunk at a time (each chunk's truth measured while it is in cache, no per-sample
    /// truth and readings held beside the tables). See [`Scenario::simulate_streamed_into`].
    ///
    /// # Errors
    /// As [`Scenario::simulate`].
    pub fn simulate_streamed(
        &self,
        run: Option<u64>,
        threads: RunThreads,
    ) -> Result<crate::Simulation> {
        let shape = self.gathered_shape()?;
        let mut truth = vec![0.0; shape.rows * shape.truth_columns.len()];
        let mut imu = vec![0.0; shape.rows * shape.imu_columns.len()];
        let aids = self.simulate_streamed_into(run, threads, Some(&mut truth), &mut imu)?;
        let table = |columns: Vec<&str>, data| Table {
            columns: columns.into_iter().map(str::to_string).collect(),
            data,
        };
        Ok(crate::Simulation {
            truth: table(shape.truth_columns, truth),
            imu: table(shape.imu_columns, imu),
            gnss: aids.gnss,
            baro: aids.baro,
            odometer: aids.odometer,
        })
    }

    /// The shape of the gathered truth and IMU tables, refused before anything is allocated when
    /// they would not fit in memory (`IMUKIT_MAX_MEMORY_GB`).
    ///
    /// # Errors
    /// [`crate::Error::Invalid`] on `duration_s` when the tables are too large.
    pub fn gathered_shape(&self) -> Result<GatheredShape> {
        let rows = self.t_s.len();
        let truth_columns = self.truth_columns();
        let imu_columns = self.imu.output.columns(self.imu.kind);
        let bytes_per_sample =
            core::mem::size_of::<f64>() * (truth_columns.len() + imu_columns.len());
        crate::io::memory::check_in_memory(rows, bytes_per_sample, "duration_s")?;
        Ok(GatheredShape {
            rows,
            truth_columns,
            imu_columns,
        })
    }

    /// [`Scenario::simulate_streamed`] written into the caller's memory (a NumPy array, say):
    /// `truth` and `imu` are row-major, [`GatheredShape::rows`] rows of the shape's columns; each
    /// chunk is checked finite (rows named from 2, as below a header) and copied in as it is
    /// made. Without a `truth` buffer only the readings are kept (the truth is made chunk by
    /// chunk for them, and on the flat Earth not tabulated). Returns the aids' tables.
    ///
    /// # Errors
    /// As [`Scenario::simulate`]; buffers of the wrong length.
    pub fn simulate_streamed_into(
        &self,
        run: Option<u64>,
        threads: RunThreads,
        mut truth: Option<&mut [f64]>,
        imu: &mut [f64],
    ) -> Result<AidTables> {
        let shape = self.gathered_shape()?;
        for (name, buffer, width) in [
            ("truth", truth.as_deref(), shape.truth_columns.len()),
            ("imu", Some(&*imu), shape.imu_columns.len()),
        ] {
            let Some(buffer) = buffer else { continue };
            if buffer.len() != shape.rows * width {
                return Err(crate::error::invalid(
                    name,
                    format!(
                        "has {} values, expected {} rows × {width}",
                        buffer.len(),
                        shape.rows
                    ),
                ));
            }
        }
        let mut aids = AidTables::default();
        let append = |into: &mut Option<Table>, from: Option<&Table>| match (into.as_mut(), from) {
            (Some(a), Some(b)) => a.data.extend_from_slice(&b.data),
            (None, b) => *into = b.cloned(),
            (Some(_), None) => {}
        };
        let mut rows = 0;
        self.stream_with(run, threads, truth.is_some(), |chunk| {
            let n = chunk.imu.rows();
            for (what, into, from) in [
                ("truth", truth.as_deref_mut(), &chunk.truth),
                ("IMU readings", Some(&mut *imu), &chunk.imu),
            ] {
                let Some(into) = into else { continue };
                check_finite_from(&from.columns, &from.data, what, rows + 2)?;
                let width = from.columns.len();
                into.get_mut(rows * width..(rows + n) * width)
                    .ok_or_else(|| {
                        crate::error::invalid(what, "the run made more rows than its sample times")
                    })?
                    .copy_from_slice(&from.data);
            }
            append(&mut aids.gnss, chunk.gnss.as_ref());
            append(&mut aids.baro, chunk.baro.as_ref());
            append(&mut aids.odometer, chunk.odometer.as_ref());
            aids.report.merge(&chunk.report);
            rows += n;
            Ok(())
        })?;
        if rows == 0 {
            return Err(crate::error::invalid("duration_s", "no samples"));
        }
        if rows != shape.rows {
            return Err(crate::error::invalid(
                "duration_s",
                format!(
                    "the run made {rows} rows of its {} sample times",
                    shape.rows
                ),
            ));
        }
        Ok(aids)
    }

    fn stream_in<N: NavFrame>(
        &self,
        run: Option<u64>,
        threads: RunThreads,
        truth_table: bool,
        sink: &mut dyn FnMut(&Chunk) -> Result<()>,
    ) -> Result<()> {
        let mut sensors =
            self.imu
                .reading_stream::<N>(self.gravity_m_s2, self.sample_rate_hz, run)?;
        if !truth_table {
            sensors = sensors.without_vibration_truth();
        }
        let kind = self.imu.kind;
        let output = self.imu.output;
        // The last reading of the previous chunk: increments integrate across the boundary.
        let mut previous: Option<(f64, ImuReading)> = None;
        let mut aids = self.aids(run)?;
        // One stretch, one chunk and one list of times, refilled chunk after chunk: nothing of
        // the size of a chunk is allocated per chunk on the flat Earth.
        let mut stretch = crate::scenario::Stretch::default();
        let mut chunk = Chunk::default();
        let mut t: Vec<f64> = Vec::new();
        let blank_report = sensors.report();
        let mut turn_rates: Vec<f64> = Vec::new();
        // With a signal chain, the samples it keeps of the motion at its internal rate.
        let mut kept: Vec<Truth<N>> = Vec::new();
        let mut clock = self
            .imu
            .clock
            .as_ref()
            .map(|c| c.source(self.imu.sensors.seed, run));
        let mut emit = |motion: &[Truth<N>]| -> Result<()> {
            let truth = self.on_earth(
                motion,
                &mut sensors,
                &mut aids,
                truth_table,
                &mut stretch,
                &mut kept,
            )?;
            if truth.is_empty() {
                // A chunk of the motion shorter than the chain's decimation may keep no sample.
                return Ok(());
            }
            let readings = &stretch.readings;
            t.clear();
            t.extend(truth.iter().map(|s| s.t_s));
            chunk.report.clone_from(&blank_report);
            chunk.report.add_readings(readings);
            turn_rates.clear();
            turn_rates.extend(truth.iter().map(|s| s.omega_b_rad_s.norm()));
            chunk.report.add_turns(&t, &turn_rates);
            match output {
                ImuOutput::Rates => chunk.imu.refill_readings(&t, readings, kind),
                ImuOutput::Increments => {
                    chunk.imu = match previous {
                        None => Table::from_increments(&t, readings, kind),
                        Some((t0, r0)) => {
                            let (mut t1, mut r1) = (vec![t0], vec![r0]);
                            t1.extend(&t);
                            r1.extend(readings);
                            let mut table = Table::from_increments(&t1, &r1, kind);
                            let width = table.columns.len();
                            table.data.drain(..width);
                            table
                        }
                    }
                }
            }
            previous = t.last().copied().zip(readings.last().copied());
            if let Some(clock) = &mut clock {
                clock.stamp_table(&mut chunk.imu);
            }
            // The stretch's truth table becomes the chunk's; the chunk's last one is refilled
            // next time.
            std::mem::swap(&mut chunk.truth, &mut stretch.truth);
            chunk.gnss = stretch.gnss.take();
            chunk.baro = stretch.baro.take();
            chunk.odometer = stretch.odometer.take();
            sink(&chunk)
        };
        let motion_times = self.motion_times();
        let t_s: &SampleTimes = &motion_times;
        let size = stream_chunk(t_s.len());
        let produce = |emit: Stage<'_, Truth<N>>| match &self.trajectory {
            Trajectory::Expression(m, o) => {
                motion_chunks(m, *o, t_s, size, "trajectory (expression)", emit)
            }
            Trajectory::Track(k) => motion_chunks(
                k,
                AnalyticOptions::default(),
                t_s,
                size,
                "trajectory (track)",
                emit,
            ),
            Trajectory::Waypoints(w) => motion_chunks(
                w,
                AnalyticOptions::default(),
                t_s,
                size,
                "trajectory (waypoints)",
                emit,
            ),
            Trajectory::Walk(w) => motion_chunks(
                w,
                AnalyticOptions::default(),
                t_s,
                size,
                "trajectory (walk)",
                emit,
            ),
            Trajectory::Positions(p) => motion_chunks(
                p,
                AnalyticOptions::default(),
                t_s,
                size,
                "trajectory (positions)",
                emit,
            ),
            Trajectory::Samples(path) => path.truth_chunks(size, emit),
            Trajectory::BodyRates(_) => {
                let truth = self.trajectory.truth::<N>(&t_s.to_vec())?;
                truth.chunks(size).try_for_each(emit)
            }
        };
        run_in_stages(threads, t_s.len().div_ceil(size), produce, &mut emit)
    }
}

/// One streamed output, CSV, Parquet or `.npy` by its extension ([`AtomicFile::begin_table`]): the
/// columns once, then the chunks' rows, each checked finite and named by its file row.
struct TableSink {
    file: AtomicFile,
    format: TableFormat,
    name: String,
    /// The next row's number in the file (a CSV file's header is row 1).
    next_row: usize,
    description: Description,
    started: bool,
    /// In the ASL layout ([`AtomicFile::begin_asl`]).
    asl: bool,
    /// A bag's options.
    bag: BagOptions,
}

impl TableSink {
    fn create(
        path: &Path,
        description: &Description,
        asl: bool,
        bag: Option<&BagOptions>,
    ) -> Result<Self> {
        let format = TableFormat::of(path);
        Ok(Self {
            file: AtomicFile::create(path)?,
            format,
            name: path.display().to_string(),
            next_row: format.first_row(),
            description: description.clone(),
            started: false,
            asl,
            bag: bag.cloned().unwrap_or_default(),
        })
    }

    fn write(&mut self, table: &Table) -> Result<()> {
        if self.format == TableFormat::Mcap {
            return self.write_bag(&[table]);
        }
        // Nothing that is not a finite number reaches a file.
        check_finite_from(&table.columns, &table.data, &self.name, self.next_row)?;
        if !self.started && self.asl {
            self.file.begin_asl(&table.columns)?;
            self.started = true;
        }
        if !self.started {
            let kind = TableKind::detect(&table.columns);
            let description = Description {
                kind,
                ..self.description.clone()
            };
            self.file.begin_table(&table.columns, &description)?;
            self.started = true;
        }
        self.file.write_table_rows(&table.data)?;
        self.next_row += table.rows();
        Ok(())
    }

    /// Writes a chunk of `tables` (readings, truth, fixes of one stretch of time) into the bag
    /// this sink writes, their messages in stamp order.
    fn write_bag(&mut self, tables: &[&Table]) -> Result<()> {
        for t in tables {
            check_finite_from(&t.columns, &t.data, &self.name, 1)?;
        }
        if !self.started {
            let mut description = self.description.clone();
            if let [only] = tables {
                description.kind = TableKind::detect(&only.columns);
            }
            self.file.begin_bag_with(&description, &self.bag)?;
            self.started = true;
        }
        self.file.write_bag(tables)
    }

    fn commit(self) -> Result<()> {
        self.file.commit()
    }
}

/// Exact truth of `motion` at `t_s` in chunks of `chunk` samples, as `truth_from_motion`
/// computes it whole: the leading tangent-attitude standstill is held until the body first
/// moves, then given that attitude.
pub(crate) fn motion_chunks<M: Motion, N: NavFrame>(
    motion: &M,
    options: AnalyticOptions,
    t_s: &SampleTimes,
    chunk: usize,
    what: &str,
    emit: &mut dyn FnMut(&[Truth<N>]) -> Result<()>,
) -> Result<()> {
    let mut stepper = AnalyticStepper::new(motion, options);
    // The truth of the samples not yet emitted is `buffer[..filled]`: each block is written over
    // what earlier chunks left instead of over defaults written first, and the buffer grows only
    // while a tangent attitude waits for the body to move.
    let mut buffer: Vec<Truth<N>> = vec![Truth::default(); chunk + DERIVATIVE_CHUNK];
    let mut filled = 0;
    let mut moving = false;
    let (mut times, mut points) = (
        Vec::with_capacity(DERIVATIVE_CHUNK),
        Vec::with_capacity(DERIVATIVE_CHUNK),
    );
    for start in (0..t_s.len()).step_by(DERIVATIVE_CHUNK) {
        times.clear();
        times.extend((start..t_s.len().min(start + DERIVATIVE_CHUNK)).map(|k| t_s.at(k)));
        motion.derivatives(&times, &mut points);
        let base = filled;
        filled += times.len();
        if buffer.len() < filled {
            buffer.resize(filled, Truth::default());
        }
        let first = stepper
            .step_block::<N>(&times, &points, &mut buffer[base..filled])
            .map_err(|e| with_time(&t_s.to_vec(), e, what))?;
        if let (false, Some(k)) = (moving, first) {
            moving = true;
            backfill_standstill(&mut buffer[..filled], Some(base + k));
        }
        while moving && filled >= chunk {
            emit(&buffer[..chunk])?;
            buffer.copy_within(chunk..filled, 0);
            filled -= chunk;
        }
    }
    if filled == 0 {
        Ok(())
    } else {
        emit(&buffer[..filled])
    }
}
