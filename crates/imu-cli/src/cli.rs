//! Command-line arguments.
use std::path::PathBuf;

use clap::builder::{PossibleValue, PossibleValuesParser, TypedValueParser};
use clap::{Args, Parser, Subcommand};
use imukit::choice::Choice;
use imukit::fuse::AlignName;
use imukit::io::conventions::{AccelSignName, EarthGravityName, EarthName, NavFrameName};
use imukit::navigate::VerticalName;
use imukit::orient::{Conventions, FilterKind};

/// A flag that takes one of a library choice's names (any case): the names for help and
/// completion, the library's value.
fn choice<T: Choice>() -> impl TypedValueParser<Value = T> {
    PossibleValuesParser::new(T::NAMES.iter().map(|(n, _)| PossibleValue::new(*n)))
        .map(|s| T::parse("", &s).unwrap_or_default())
}

/// A fast, exact and reproducible IMU simulator and inertial-navigation toolkit.
#[derive(Debug, Parser)]
#[command(
    name = "imukit",
    version,
    long_about = None,
    after_help = "Tables (readings, truth, estimates, errors) are CSV unless a file's extension \
                  says otherwise, when written and when read: .parquet (Apache Parquet), .npy (a \
                  NumPy structured array), .npz (a NumPy archive, one array per column)."
)]
pub struct Cli {
    /// No notes and no progress on standard error (warnings and errors still print).
    #[arg(long, short, global = true)]
    pub quiet: bool,
    /// What to do.
    #[command(subcommand)]
    pub command: Command,
}

/// A figure's size and resolution (`plot`, `allan --plot`, `study --plot`).
#[derive(Debug, Clone, clap::Args)]
pub struct FigureArgs {
    /// The figure's width and height, inches (default: a size for its panels).
    #[arg(long, num_args = 2, value_names = ["WIDTH_IN", "HEIGHT_IN"])]
    pub size: Option<Vec<f64>>,
    /// A PNG's resolution, pixels per inch (default 100; an SVG has none).
    #[arg(long)]
    pub dpi: Option<f64>,
}

pub use crate::cli_characterise::{CalibrateArgs, SpectrumArgs};

/// How a vendor's CSV maps to imukit's columns (`--map`), for the commands that read IMU data.
#[derive(Debug, Clone, clap::Args)]
pub struct MapArg {
    /// A column map (TOML) for a vendor's CSV: which of its columns hold the time, the
    /// accelerometer, the gyroscope and the magnetometer, in which units, and the sensor's
    /// axes in the body frame (docs/formats.md).
    #[arg(long, value_name = "FILE")]
    pub map: Option<PathBuf>,
    /// A part's calibration (`imukit calibrate --out`): each sensor's readings corrected as
    /// `matrix · (reading − bias)` as they are read.
    #[arg(long, value_name = "FILE")]
    pub calibration: Option<PathBuf>,
}

/// What the data's axes and accelerometer sign are (`--nav-frame`, `--accel-sign`,
/// `--conventions`), for the commands that navigate: each as given, else what the input files'
/// descriptions say, else the conventions'.
#[derive(Debug, Clone, clap::Args)]
pub struct FrameArgs {
    /// Navigation frame of the data [default: what the input files' descriptions say, else the
    /// conventions' (ENU)].
    #[arg(long, value_parser = choice::<NavFrameName>(), ignore_case = true)]
    pub nav_frame: Option<NavFrameName>,
    /// Sign of the accelerometer columns [default: what the input files' descriptions say, else
    /// the conventions' (specific-force)].
    #[arg(long, value_parser = choice::<AccelSignName>(), ignore_case = true)]
    pub accel_sign: Option<AccelSignName>,
    /// Conventions for what neither an option nor a description gives: `imukit` (ENU and
    /// specific force) or `matlab` (NED and MATLAB's accelerometer sign: a MATLAB export).
    #[arg(long, value_parser = choice::<Conventions>(), ignore_case = true)]
    pub conventions: Option<Conventions>,
}

/// Which topics of a ROS bag to read and on which clock (`--topic`, `--receive-time`), for every
/// command that reads tables.
#[derive(Debug, Clone, clap::Args)]
pub struct BagArgs {
    /// A topic to read from a ROS bag (`.mcap`, `.db3`, `.bag`, a bag folder) that holds
    /// several that fit; given once per topic the command reads (the IMU's, the fixes', the
    /// reference's).
    #[arg(long = "topic", value_name = "NAME")]
    pub topics: Vec<String>,
    /// Read a ROS bag's messages at the times the recorder received them, not at their
    /// header stamps.
    #[arg(long)]
    pub receive_time: bool,
}

/// The stretch of a run a command reads (`--start-s`, `--end-s`).
#[derive(Debug, Clone, Copy, clap::Args)]
pub struct WindowArgs {
    /// Read from this many seconds after the first sample of the (first) input; every input
    /// of the command is cut at the same instants.
    #[arg(long, value_name = "SECONDS", allow_hyphen_values = true)]
    pub start_s: Option<f64>,
    /// Read up to this many seconds after the first sample of the (first) input.
    #[arg(long, value_name = "SECONDS", allow_hyphen_values = true)]
    pub end_s: Option<f64>,
}

/// How a written ROS 2 bag names its IMU and when it starts (`--out NAME.mcap`).
#[derive(Debug, Clone, clap::Args)]
pub struct BagOutArgs {
    /// The IMU's topic in a bag written (`--out NAME.mcap`; default /imu; the magnetometer's is
    /// TOPIC/mag).
    #[arg(long, value_name = "TOPIC")]
    pub bag_topic: Option<String>,
    /// The frame id of the IMU's messages in a bag written (default imu_link).
    #[arg(long, value_name = "FRAME")]
    pub bag_frame_id: Option<String>,
    /// The stamp of time 0 in a bag written, seconds since 1970-01-01 UTC (default 0: a
    /// simulated run's stamps start in 1970), such as 1700000000.
    #[arg(long, value_name = "SECONDS", allow_hyphen_values = true)]
    pub bag_start_s: Option<f64>,
}

/// Subcommands.
#[derive(Debug, Subcommand)]
#[allow(
    clippy::large_enum_variant,
    reason = "parsed once per process; boxing the options would only obscure them"
)]
pub enum Command {
    /// Truth kinematics and IMU readings of a scenario file (TOML or JSON): ideal, or through the
    /// scenario's sensor error model (`[imu]`: noise, biases, scale factors, presets).
    Simulate(SimulateArgs),
    /// Strapdown navigation (3D) or planar dead reckoning (`--planar`) of IMU data.
    Integrate(IntegrateArgs),
    /// Orientation from IMU readings by a filter: `robust` (imukit's own, the default:
    /// inclination from the accelerometer low-passed in an almost inertial frame, heading from
    /// the magnetometer unless a magnet is near, gyroscope bias learnt at rest and in motion),
    /// `imufilter` and `ahrsfilter` (MATLAB's Kalman filters), `ecompass`, `madgwick`, `mahony`
    /// or `complementary`.
    Orient(OrientArgs),
    /// Loosely coupled INS/GNSS fusion: an error-state Kalman filter (15 states; the sensor
    /// errors and the fixes' lasting errors add more) over IMU rates and GNSS fixes, the filter's
    /// model taken from the scenario that made them (`[imu]` errors, `[gnss]` accuracy, process
    /// and lever arm) or from the part and receiver named; writes the navigation columns, their one-sigma and the
    /// bias estimates with their one-sigma.
    Fuse(FuseArgs),
    /// Which IMU bridges a GNSS outage: a scenario with `[[gnss.outages]]` simulated with each
    /// IMU preset over seeded Monte Carlo runs (all cores; each run a part of the preset's type)
    /// and fused with its GNSS; writes, per preset and time into the first outage, the RMS
    /// horizontal position error and the filter's one-sigma, and prints them at the outage's
    /// end.
    Study {
        /// Study file (TOML): `scenario = "S.toml"`, `presets = ["mpu-6050", …]`, `runs = 100`;
        /// optional `rest_s`, `sensor_errors`, `odometer`, `baro`, `nhc_sigma_m_s`, `draw_parts`.
        study: PathBuf,
        /// Where to write the table (CSV: `t_s` since the outage began, then per preset
        /// `<preset>_rms_error_m` and `<preset>_sigma_m`).
        #[arg(long)]
        out: PathBuf,
        /// A figure of the table (`.png` or `.svg`).
        #[arg(long)]
        plot: Option<PathBuf>,
    },
    /// Errors of an estimate against truth over time: a navigation output (position, velocity,
    /// attitude) or an orientation output (attitude), with RMS, maximum and final values printed.
    Compare {
        /// Truth CSV (`t_s, pos_*, vel_*, q_*`), or a reference on the Earth (`lat_rad,
        /// lon_rad, height_m`, `lat_deg, lon_deg, height_m` or `ecef_*_m`, with velocity and
        /// attitude where it has them): errors then north, east, down (docs/earth.md).
        truth: PathBuf,
        /// Estimate CSV: navigation (`imukit integrate`) or orientation (`imukit orient`). An
        /// orientation estimate is scored as orientation benchmarks do: the error's heading and
        /// inclination parts beside its angle; rows where the reference has no value (empty or
        /// NaN quaternion cells, a gap in its times) or no time are skipped and counted.
        estimate: PathBuf,
        /// Which topics of a ROS bag, on which clock.
        #[command(flatten)]
        bag: BagArgs,
        /// The stretch of the run to read.
        #[command(flatten)]
        window: WindowArgs,
        /// Where to write the errors over time (CSV, or by extension `.parquet`, `.npy`, `.npz`).
        #[arg(long)]
        out: Option<PathBuf>,
        /// Orientation estimates: remove one constant heading offset (the circular mean of the
        /// heading error) before scoring — a 6D estimate's heading is arbitrary.
        #[arg(long)]
        align_heading: bool,
    },
    /// The planar cart exercise end to end: the built-in cart's clean and erroneous `.dat` files,
    /// dead-reckoned with both schemes, and a plot of the trajectories (start and end marked).
    Exercise {
        /// Output folder.
        #[arg(long, default_value = "imukit-exercise")]
        out_dir: PathBuf,
        /// Seed of the sensor errors.
        #[arg(long, default_value_t = 1)]
        seed: u64,
    },
    /// Lists the sensor presets, or prints one as a parameter file or as Kalibr's `imu.yaml`.
    Presets {
        /// Name of a preset.
        #[arg(conflicts_with = "params")]
        name: Option<String>,
        /// A parameter file to print instead of a preset: imukit TOML/JSON or MATLAB
        /// `loadparams` JSON (`--part` picks one of several parts).
        #[arg(long, value_name = "FILE")]
        params: Option<PathBuf>,
        /// The part of a MATLAB parameter file that holds several.
        #[arg(long, requires = "params")]
        part: Option<String>,
        /// What to print: imukit's parameter file, or Kalibr's IMU noise file (`imu.yaml`; its
        /// comments say how each figure was reached).
        #[arg(long, value_enum, default_value_t = PresetFormat::Toml)]
        format: PresetFormat,
        /// The IMU's rate written into Kalibr's file, Hz (the logger's rate).
        #[arg(long, default_value_t = imukit::io::kalibr::DEFAULT_RATE_HZ)]
        rate_hz: f64,
        /// The IMU's topic written into Kalibr's file.
        #[arg(long, default_value = imukit::io::kalibr::DEFAULT_TOPIC)]
        topic: String,
    },
    /// Converts a datasheet figure to imukit's SI parameter units (single-sided densities,
    /// g = 9.80665 m/s²), e.g. `imukit convert 0.15 "°/√h"`.
    Convert {
        /// The value.
        value: f64,
        /// Its unit (°/√h, °/h, °/s/√Hz, µg/√Hz, m/s/√h, mg, ppm, …).
        unit: String,
    },
    /// Allan deviation of IMU columns (octave τ) with white noise N, bias instability B and
    /// random walk K fitted (a term not resolved shows as its bound).
    Allan(AllanArgs),
    /// Noise identification of a static log: Allan curves with 95 % bands, the noise terms
    /// (quantisation, white noise, bias instability, rate random walk, rate ramp) each with its
    /// 95 % interval or, not resolved, its bound and the record that would resolve it; an imukit
    /// parameter file, a Kalibr imu.yaml, the fusion filter's noise.
    Identify(IdentifyArgs),
    /// Calibrates a part from the log of a procedure, without equipment: set down in 7 to 24
    /// orientations and turned between them (accelerometer bias, scale and misalignment from
    /// gravity's magnitude at the rests; gyroscope bias from the rests, scale and misalignment
    /// from the turns), and a magnetometer turned through all directions (hard and soft iron,
    /// the field's strength); each term with its standard deviation. Writes a calibration file
    /// that `--calibration FILE` applies wherever readings are read.
    Calibrate(CalibrateArgs),
    /// Power spectral density of readings (Welch: Hann-windowed segments, half overlapping,
    /// one-sided): `frequency_hz, psd_<column>…`; with the scenario that made a simulated log,
    /// the figure marks where each vibration sine lands (its alias) and draws the chain's gain.
    Spectrum(SpectrumArgs),
    /// Runs a built-in scenario (default: the figure-8 with its lever arm) and writes the
    /// scenario, truth, IMU readings, figures (truth.png, imu.png), an animation (animation.html)
    /// and a summary into a folder.
    Demo {
        /// Output folder.
        #[arg(long, default_value = "imukit-demo")]
        out_dir: PathBuf,
        /// Built-in scenario to run.
        #[arg(long, default_value = imukit::scenario::builtin::DEMO)]
        scenario: String,
    },
    /// Writes shipped examples (scenario files, data, Python scripts) where the guides' commands
    /// read them (`examples/track.toml`), or lists them. A file already there is left alone if
    /// it is the shipped one and never overwritten if it differs.
    Example {
        /// Examples to write (`all` for every file); none lists them.
        names: Vec<String>,
        /// Folder the examples go into, keeping their places in it (`study/tunnel.toml` reads
        /// `../car_tunnel.toml`).
        #[arg(long, default_value = imukit::examples::DEFAULT_FOLDER)]
        out_dir: PathBuf,
    },
    /// Lists the built-in scenarios, or prints one as an editable scenario file.
    Scenario {
        /// Name of a built-in scenario.
        name: Option<String>,
    },
    /// Default figures of imukit CSV files (truth, IMU readings, navigation output, Allan
    /// table, errors; the kind is recognised from the columns). Several files of one kind are
    /// overlaid, the second dashed, the third dotted (truth vs estimates).
    Plot {
        /// The CSV files.
        #[arg(required = true)]
        files: Vec<PathBuf>,
        /// The stretch of the run to read.
        #[command(flatten)]
        window: WindowArgs,
        /// The figure file (`.svg` or `.png`).
        #[arg(long)]
        out: PathBuf,
        /// Navigation frame of the positions (NED paths are drawn east, north, up; default:
        /// what the files' descriptions say, else ENU).
        #[arg(long, value_parser = choice::<NavFrameName>(), ignore_case = true)]
        nav_frame: Option<NavFrameName>,
        /// Size and resolution.
        #[command(flatten)]
        figure: FigureArgs,
    },
    /// Animates the body moving along its path from a truth CSV: a box turned by the attitude,
    /// the reference point and the IMU point at the lever arm marked, the trail drawn.
    Animate {
        /// Truth CSV (`t_s, pos_*_m, q_*`, as `imukit simulate --truth` writes).
        truth: PathBuf,
        /// The stretch of the run to animate.
        #[command(flatten)]
        window: WindowArgs,
        /// The animation file: `.gif`, or `.html` (a self-contained page, no network needed).
        #[arg(long)]
        out: PathBuf,
        /// Box length, width and height along body x, y, z, m (default: a tenth of the path's
        /// extent long).
        #[arg(long = "body-m", alias = "body", num_args = 3, value_names = ["L", "W", "H"])]
        body: Option<Vec<f64>>,
        /// Lever arm of the IMU point from the reference point, body frame, m.
        #[arg(long = "lever-arm-m", alias = "lever-arm", num_args = 3, value_names = ["X", "Y", "Z"], allow_hyphen_values = true)]
        lever_arm: Option<Vec<f64>>,
        /// Frames per second.
        #[arg(long, default_value_t = imu_plot::spec::DEFAULT_FPS)]
        fps: f64,
        /// Seconds of motion per second of animation (default: the animation lasts 4 to 12 s).
        #[arg(long)]
        speed: Option<f64>,
        /// Navigation frame of the truth (NED is drawn turned so that up is up; default: what
        /// the file's description says, else ENU).
        #[arg(long, value_parser = choice::<NavFrameName>(), ignore_case = true)]
        nav_frame: Option<NavFrameName>,
    },
    /// Prints a shell's completion script for imukit to standard output.
    Completions {
        /// The shell (bash: `source <(imukit completions bash)`; zsh: save it as `_imukit` in a
        /// folder of `$fpath`; fish: `~/.config/fish/completions/imukit.fish`).
        #[arg(value_enum)]
        shell: clap_complete::Shell,
    },
    /// Prints imukit's manual page (roff) to standard output, or with --out-dir writes one page
    /// per command (imukit.1, imukit-simulate.1, …) into a folder: `imukit man | man -l -`.
    Man {
        /// The folder for the pages.
        #[arg(long)]
        out_dir: Option<PathBuf>,
    },
}

/// The arguments of `imukit simulate`.
#[derive(Args, Debug)]
pub struct SimulateArgs {
    /// The scenario file.
    pub scenario: PathBuf,
    /// Where to write the IMU readings (CSV, or by extension `.parquet`, `.npy`, `.npz`; a
    /// ROS 2 bag `.mcap` holds the truth and the fixes too).
    #[arg(long)]
    pub out: PathBuf,
    /// Where to write the truth (CSV, or by extension `.parquet`, `.npy`, `.npz`; with --runs
    /// once, or one per run when the mount's vibration is random and so differs by run).
    #[arg(long)]
    pub truth: Option<PathBuf>,
    /// Where to write the GNSS fixes of the scenario's `[gnss]` receiver (CSV; with --runs,
    /// one per run like the IMU readings).
    #[arg(long)]
    pub gnss: Option<PathBuf>,
    /// Where to write the readings of the scenario's `[baro]` barometer (CSV, or by extension `.parquet`, `.npy`, `.npz`).
    #[arg(long)]
    pub baro: Option<PathBuf>,
    /// Where to write the readings of the scenario's `[odometer]` (CSV, or by extension `.parquet`, `.npy`, `.npz`).
    #[arg(long)]
    pub odometer: Option<PathBuf>,
    /// Monte Carlo: this many runs, in parallel on all cores, one output per run
    /// (`IMU_run0000.csv`, …); run r draws its noise from (seed, r).
    #[arg(long)]
    pub runs: Option<u64>,
    /// Use at most this many threads (default: every core this process may use). A single
    /// run uses up to three (by default from 1 537 samples, four chunks): the truth, the
    /// sensors and the files, each a chunk ahead of the next; on two, CSV is written on its
    /// own thread, binary files beside the sensors. With --runs, this many runs go at a
    /// time. The numbers are the same however many.
    #[arg(long, allow_hyphen_values = true)]
    pub threads: Option<i64>,
    /// `euroc`: write the run as a EuRoC sequence, `--out` its folder: the readings in
    /// `mav0/imu0/data.csv` and the truth in `mav0/state_groundtruth_estimate0/data.csv`, in
    /// the ASL layout (nanosecond stamps; docs/formats.md).
    #[arg(long, value_parser = ["euroc"])]
    pub layout: Option<String>,
    /// A bag's IMU topic, frame id and start stamp.
    #[command(flatten)]
    pub bag_out: BagOutArgs,
}

/// The arguments of `imukit integrate`.
#[derive(Args, Debug)]
pub struct IntegrateArgs {
    /// IMU data. 3D: CSV with rates (`accel_*_m_s2`, `gyro_*_rad_s`) or increments
    /// (`dv_*_m_s`, `dtheta_*_rad`). Planar: CSV (`t_s, accel_x_m_s2, accel_y_m_s2,
    /// gyro_z_rad_s`) or the exercise's whitespace `.dat` (t, a_x, a_y, ω_z).
    pub input: PathBuf,
    /// How a vendor's CSV maps to imukit's columns.
    #[command(flatten)]
    pub map: MapArg,
    /// Which topics of a ROS bag, on which clock.
    #[command(flatten)]
    pub bag: BagArgs,
    /// The stretch of the run to read.
    #[command(flatten)]
    pub window: WindowArgs,
    /// 3D: initial state from the first row of this truth file, or of a reference in
    /// latitude, longitude and height or ECEF (docs/earth.md; else at rest, level, at the
    /// origin unless --position0-m/--velocity0-m-s/--euler0-rad say otherwise).
    #[arg(long)]
    pub init: Option<PathBuf>,
    /// 3D: the data's frame and accelerometer sign.
    #[command(flatten)]
    pub frame: FrameArgs,
    /// 3D: gravity magnitude, m/s² (`--gravity` is the old spelling) [default: what the input
    /// files' descriptions say, else 9.81].
    #[arg(long, alias = "gravity")]
    pub gravity_m_s2: Option<f64>,
    /// 3D: switch off the coning and sculling corrections (for comparison).
    #[arg(long)]
    pub no_corrections: bool,
    /// 3D: initial attitude yaw, pitch, roll, rad.
    #[arg(long = "euler0-rad", alias = "euler0", num_args = 3, value_names = ["YAW", "PITCH", "ROLL"], allow_hyphen_values = true)]
    pub euler0: Option<Vec<f64>>,
    /// Planar dead reckoning (cart in a plane: two accelerometers and a yaw gyro).
    #[arg(long)]
    pub planar: bool,
    /// Planar: `trapezoid` (default) or `exercise` (the planar cart exercise's rules). 3D: `auto`
    /// (default: `rk4` for rates, `coning` for increments or with --no-corrections), `coning`
    /// (coning/sculling, second order, rates or increments) or `rk4` (fourth order, rates).
    #[arg(long)]
    pub scheme: Option<String>,
    /// 3D `rk4`: RK4 steps per sample interval.
    #[arg(long, default_value_t = imukit::navigate::DEFAULT_RK4_SUBSTEPS)]
    pub substeps: usize,
    /// Initial position, m: X Y (planar; the exercise's 100 100 by default) or X Y Z (3D).
    #[arg(long = "position0-m", alias = "position0", num_args = 2..=3, allow_hyphen_values = true)]
    pub position0: Option<Vec<f64>>,
    /// Planar: initial heading, rad from nav X, counter-clockwise.
    #[arg(
        long = "heading0-rad",
        alias = "heading0",
        default_value_t = 0.0,
        allow_hyphen_values = true
    )]
    pub heading0: f64,
    /// Initial velocity in the navigation frame, m/s: VX VY (planar) or VX VY VZ (3D).
    #[arg(long = "velocity0-m-s", alias = "velocity0", num_args = 2..=3, allow_hyphen_values = true)]
    pub velocity0: Option<Vec<f64>>,
    /// 3D: the Earth: `flat` (non-rotating, constant gravity) or `wgs84` (the
    /// rotating WGS-84 Earth: Earth rate, transport rate, Coriolis, normal gravity; the start
    /// needs a geodetic position, from an --init truth file of a `wgs84` scenario or
    /// --lat0-deg/--lon0-deg/--height0-m). Writes lat_rad, lon_rad, height_m beside the
    /// local columns [default: what the input files' descriptions say, else flat].
    #[arg(long, value_parser = choice::<EarthName>(), ignore_case = true)]
    pub earth: Option<EarthName>,
    /// 3D, `--earth wgs84`: the vertical channel: `free` (unstable, as physics says),
    /// `hold` (height and vertical velocity held) or `baro` (a third-order loop on the IMU
    /// file's `baro_height_m` column).
    #[arg(long, value_parser = choice::<VerticalName>(), ignore_case = true, default_value_t)]
    pub vertical: VerticalName,
    /// 3D, `--vertical baro`: the loop's time constant, s.
    #[arg(long, default_value_t = imukit::navigate::DEFAULT_BARO_TIME_CONSTANT_S)]
    pub baro_time_constant_s: f64,
    /// 3D, `--earth wgs84`: gravity, `normal` (WGS-84 normal gravity) or `constant`
    /// (--gravity-m-s2) [default: what the input files' descriptions say, else normal].
    #[arg(long, value_parser = choice::<EarthGravityName>(), ignore_case = true)]
    pub earth_gravity: Option<EarthGravityName>,
    /// 3D, `--vertical baro`: barometer readings (`t_s, baro_height_m`, as `imukit simulate
    /// --baro` writes) instead of a `baro_height_m` column in the IMU file.
    #[arg(long)]
    pub baro: Option<PathBuf>,
    /// 3D, `--earth wgs84`: the starting latitude, degrees (with --lon0-deg and
    /// --height0-m; instead of, or over, the --init file's).
    #[arg(long, allow_hyphen_values = true)]
    pub lat0_deg: Option<f64>,
    /// 3D, `--earth wgs84`: the starting longitude, degrees.
    #[arg(long, allow_hyphen_values = true)]
    pub lon0_deg: Option<f64>,
    /// 3D, `--earth wgs84`: the starting height above the WGS-84 ellipsoid, m.
    #[arg(long, allow_hyphen_values = true)]
    pub height0_m: Option<f64>,
    /// Where to write the trajectory (CSV, or by extension `.parquet`, `.npy`, `.npz`).
    #[arg(long)]
    pub out: PathBuf,
}

/// The arguments of `imukit fuse`.
#[derive(Args, Debug)]
pub struct FuseArgs {
    /// IMU CSV (rates: `accel_*_m_s2`, `gyro_*_rad_s`).
    pub imu: PathBuf,
    /// How a vendor's CSV maps to imukit's columns.
    #[command(flatten)]
    pub map: MapArg,
    /// Which topics of a ROS bag, on which clock.
    #[command(flatten)]
    pub bag: BagArgs,
    /// The stretch of the run to read.
    #[command(flatten)]
    pub window: WindowArgs,
    /// GNSS CSV (`t_s, pos_x_m, pos_y_m, pos_z_m, vel_x_m_s, vel_y_m_s, vel_z_m_s`); left
    /// out, the filter runs on the IMU and the other aids alone (a foot with `--zupt`).
    pub gnss: Option<PathBuf>,
    /// A column map (TOML) for the GNSS CSV: its time column and, under `[columns]`, which of
    /// its columns are imukit's fix columns and accuracies (`pos_x_sigma_m = "pos_std_1"`;
    /// docs/formats.md).
    #[arg(long, value_name = "FILE", requires = "gnss")]
    pub gnss_map: Option<PathBuf>,
    /// The initial state: the first row of this truth file, or of a reference in latitude,
    /// longitude and height or ECEF (docs/earth.md; without an attitude, with --align).
    #[arg(long)]
    pub init: Option<PathBuf>,
    /// Start without truth: `gnss` takes position, velocity, heading and pitch from the first
    /// fix at 3 m/s or more (roll 0, each with its stated one-sigma); `static` (WGS-84
    /// scenarios, the vehicle at rest) levels and gyrocompasses over the first 60 s; `level`
    /// levels over the rest at the start, heading zero, at the origin (the default without a
    /// GNSS file and --init). The estimate begins there.
    #[arg(long, value_parser = choice::<AlignName>(), ignore_case = true)]
    pub align: Option<AlignName>,
    /// The scenario whose `[imu]` and `[gnss]` describe the data's errors (or: --imu and
    /// the --gnss-* accuracies; neither: the noise learnt from the log).
    #[arg(long, conflicts_with = "imu_model")]
    pub scenario: Option<PathBuf>,
    /// The IMU part, instead of a scenario: a preset's name (`imukit presets`) or a parameter
    /// file (imukit TOML, MATLAB JSON). Left out (and no --scenario), the white noise is
    /// learnt from the log's quiet stretches and the biases are an unknown consumer part's.
    /// The data's frame, Earth and accelerometer sign come from the input files' descriptions
    /// (else ENU, flat, specific force).
    #[arg(long = "imu", value_name = "PRESET|FILE")]
    pub imu_model: Option<String>,
    /// With --imu: the part in a MATLAB parameter file of several.
    #[arg(long, requires = "imu_model")]
    pub part: Option<String>,
    /// Without --scenario: the fixes' horizontal position accuracy, m (MATLAB gpsSensor's default
    /// when left out).
    #[arg(long, conflicts_with = "scenario", allow_hyphen_values = true)]
    pub gnss_horizontal_accuracy_m: Option<f64>,
    /// Without --scenario: the fixes' vertical position accuracy, m (MATLAB gpsSensor's default when
    /// left out).
    #[arg(long, conflicts_with = "scenario", allow_hyphen_values = true)]
    pub gnss_vertical_accuracy_m: Option<f64>,
    /// Without --scenario: the fixes' velocity accuracy per axis, m/s (MATLAB gpsSensor's default
    /// when left out).
    #[arg(long, conflicts_with = "scenario", allow_hyphen_values = true)]
    pub gnss_velocity_accuracy_m_s: Option<f64>,
    /// Without --scenario: the antenna's position from the IMU, body frame, m.
    #[arg(long, num_args = 3, value_names = ["X", "Y", "Z"], allow_hyphen_values = true,
          conflicts_with = "scenario")]
    pub gnss_lever_arm_m: Option<Vec<f64>>,
    /// Without --scenario: the fixes' MATLAB `DecayFactor` per fix, as a scenario's `[gnss]
    /// decay_factor` (0: white fixes of σ√2; between 0 and 1 the error drifts from the first
    /// fix and the filter estimates it). Left out, with no correlation time either, the fixes
    /// are taken as white with the accuracies given.
    #[arg(long, conflicts_with_all = ["scenario", "gnss_correlation_time_s"], allow_hyphen_values = true)]
    pub gnss_decay_factor: Option<f64>,
    /// Without --scenario: instead of the decay factor, a receiver's Gauss–Markov position error
    /// with this correlation time, s (`[gnss] correlation_time_s`), of the horizontal and
    /// vertical accuracies as its one-sigma: the filter estimates it.
    #[arg(long, conflicts_with = "scenario", allow_hyphen_values = true)]
    pub gnss_correlation_time_s: Option<f64>,
    /// Without --scenario: the fixes are stamped this late, s (`[gnss] latency_s`; 0).
    #[arg(long, conflicts_with = "scenario", allow_hyphen_values = true)]
    pub gnss_latency_s: Option<f64>,
    /// Scale the fixes' noise from their innovations: every 8 fixes whose normalised innovations
    /// lie outside a consistent filter's 99 % range scale it by their mean, between the stated
    /// accuracy and 5× it (a receiver worse than its figures). Off by default: the innovations
    /// cannot tell a receiver worse than stated from an IMU worse than modelled.
    #[arg(long)]
    pub gnss_adaptive: bool,
    /// Each fix's horizontal accuracy from its `hdop` column (an NMEA log's) times this
    /// user-equivalent range error, m (one-sigma).
    #[arg(long, allow_hyphen_values = true)]
    pub gnss_uere_m: Option<f64>,
    /// `flat` or `wgs84`: the scenario's Earth (default), checked when given. On `wgs84` the
    /// filter runs on the Earth's mechanization (Earth rate, transport rate, Coriolis,
    /// normal gravity) with geodetic fixes and adds `lat_rad, lon_rad, height_m`.
    #[arg(long, value_parser = choice::<EarthName>(), ignore_case = true)]
    pub earth: Option<EarthName>,
    /// The data's frame and accelerometer sign (with --scenario: checked against it).
    #[command(flatten)]
    pub frame: FrameArgs,
    /// Apply every fix (no chi-square innovation gate).
    #[arg(long)]
    pub no_gate: bool,
    /// Odometer readings (`t_s, speed_m_s`, from `imukit simulate --odometer`); the
    /// scenario's `[odometer]` gives their accuracy.
    #[arg(long)]
    pub odometer: Option<PathBuf>,
    /// Barometer readings (`t_s, baro_height_m`, from `imukit simulate --baro`); the
    /// scenario's `[baro]` gives their accuracy.
    #[arg(long)]
    pub baro: Option<PathBuf>,
    /// Non-holonomic constraints of a ground vehicle: no sideways or vertical body velocity,
    /// within this one-sigma (m/s; 0.1 when given without a value), with each odometer
    /// reading or at 10 Hz.
    #[arg(long, value_name = "SIGMA_M_S", num_args = 0..=1, default_missing_value = "0.1")]
    pub nhc: Option<f64>,
    /// Propagate the covariance once per this interval and at every update, s (0: every IMU
    /// sample; default 0.05).
    #[arg(long)]
    pub covariance_interval_s: Option<f64>,
    /// Estimate the IMU's scale-factor, misalignment and g-sensitivity errors (36 error states
    /// instead of 15; their one-sigma at the start from the part's `axes_misalignment_pct`
    /// and `acceleration_bias`); the estimate gains their columns. Default: when the part's
    /// figures reach 0.5 % (or 1e-5 (rad/s)/(m/s²) of g-sensitivity); `--sensor-errors`
    /// alone is `true`.
    #[arg(long, value_name = "true|false", num_args = 0..=1, default_missing_value = "true")]
    pub sensor_errors: Option<bool>,
    /// The vehicle stands still for the IMU's first this many seconds: zero-velocity and
    /// zero-rate updates at every sample there calibrate the gyroscope biases. Default: the
    /// rest found in the readings (blocks of 0.5 s whose spread and mean stay within the
    /// noise the log shows in its quiet stretches, else the part's); 0: none.
    #[arg(long, value_name = "SECONDS")]
    pub rest_s: Option<f64>,
    /// Smooth the estimate forward–backward (Rauch–Tung–Striebel over the filter): each
    /// sample's best estimate from all the data, before and after it, with its one-sigma.
    #[arg(long)]
    pub smooth: bool,
    /// Zero-velocity updates wherever the readings show a stance (a foot-mounted IMU: the
    /// SHOE detector with the noise the log shows in its quiet stretches and gravity as its
    /// accelerometer reads at rest), zero velocity and zero rate at each; a warning when
    /// under 5 % of the samples are stances.
    #[arg(long)]
    pub zupt: bool,
    /// Where to write the estimate (CSV, or by extension `.parquet`, `.npy`, `.npz`).
    #[arg(long)]
    pub out: PathBuf,
}

/// The arguments of `imukit orient`.
#[derive(Args, Debug)]
pub struct OrientArgs {
    /// IMU CSV: `t_s`, `accel_*_m_s2`, `gyro_*_rad_s`, and `mag_*_ut` for the filters that
    /// use a magnetometer (`ahrsfilter`, `ecompass`; the others use it when present).
    pub input: PathBuf,
    /// How a vendor's CSV maps to imukit's columns.
    #[command(flatten)]
    pub map: MapArg,
    /// Which topics of a ROS bag, on which clock.
    #[command(flatten)]
    pub bag: BagArgs,
    /// The stretch of the run to read.
    #[command(flatten)]
    pub window: WindowArgs,
    /// The filter.
    #[arg(long, value_parser = choice::<FilterKind>(), ignore_case = true, default_value_t)]
    pub filter: FilterKind,
    /// A filter setting, `KEY=VALUE`, repeatable: MATLAB's property names
    /// (`GyroscopeNoise=7.6154e-7`, `DecimationFactor=2`, `InitialProcessNoiseScale=10`,
    /// `SampleRate=100`; `Beta` for madgwick, `Kp`/`Ki` for mahony, `AccelerometerGain`/
    /// `MagnetometerGain` for complementary). Each sample is integrated over its own
    /// interval from `t_s`; `SampleRate=…` runs the filter at that fixed rate instead, as
    /// MATLAB's filters do.
    #[arg(long = "param", value_name = "KEY=VALUE")]
    pub params: Vec<String>,
    /// Run a 9-axis file as 6D: its magnetometer columns are ignored (the filters that may
    /// use a magnetometer use one when the file has it).
    #[arg(long)]
    pub no_mag: bool,
    /// Smooth the whole run after the fact (robust only): the filter forward, then backward
    /// from where it ended, and the mean of the two (the heading, with a magnetometer, the
    /// forward pass's). For logs processed offline; the file is read whole.
    #[arg(long)]
    pub smooth: bool,
    /// Conventions: `imukit` (ENU and specific force, as every command) or `matlab` (NED and
    /// MATLAB's accelerometer sign, as MATLAB's filters). --nav-frame and --accel-sign
    /// override either, and so does what the input's description says.
    #[arg(long, value_parser = choice::<Conventions>(), ignore_case = true, default_value_t)]
    pub conventions: Conventions,
    /// Navigation frame of the estimate (default: the input's description's, else the
    /// conventions').
    #[arg(long, value_parser = choice::<NavFrameName>(), ignore_case = true)]
    pub nav_frame: Option<NavFrameName>,
    /// Sign of the accelerometer columns (default: the input's description's, else the
    /// conventions').
    #[arg(long, value_parser = choice::<AccelSignName>(), ignore_case = true)]
    pub accel_sign: Option<AccelSignName>,
    /// Where to write the orientation (`t_s, q_w, q_x, q_y, q_z, yaw_rad, pitch_rad,
    /// roll_rad`).
    #[arg(long)]
    pub out: PathBuf,
}

/// The arguments of `imukit identify`.
#[derive(Args, Debug)]
pub struct IdentifyArgs {
    /// The static log (any format imukit reads, with `t_s`).
    pub input: PathBuf,
    /// How a vendor's CSV maps to imukit's columns.
    #[command(flatten)]
    pub map: MapArg,
    /// Which topics of a ROS bag, on which clock.
    #[command(flatten)]
    pub bag: BagArgs,
    /// The stretch of the run to read.
    #[command(flatten)]
    pub window: WindowArgs,
    /// Columns to analyse (default: every gyro and accel column present).
    #[arg(long = "column")]
    pub columns: Vec<String>,
    /// Where to write `tau_s` and per column `adev_`, `lower95_`, `upper95_`, `edf_`, `fit_`
    /// (CSV, or by extension `.parquet`, `.npy`, `.npz`). Each output is optional on its own;
    /// the terms are printed whatever is written.
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// Write the identified part as an imukit parameter file (TOML) for `--imu`.
    #[arg(long, value_name = "FILE")]
    pub params: Option<PathBuf>,
    /// Write the identified part as Kalibr's imu.yaml.
    #[arg(long, value_name = "FILE")]
    pub kalibr: Option<PathBuf>,
    /// Factor on the Kalibr file's densities (stated in the file).
    #[arg(long, default_value_t = imukit::io::kalibr::DEFAULT_INFLATION, value_name = "FACTOR")]
    pub kalibr_inflation: f64,
    /// The IMU topic written in the Kalibr file.
    #[arg(long, default_value = imukit::io::kalibr::DEFAULT_TOPIC, value_name = "TOPIC")]
    pub kalibr_topic: String,
    /// Draw the curves, their bands and the fitted terms (`.svg` or `.png`).
    #[arg(long)]
    pub plot: Option<PathBuf>,
    /// The figure's size and resolution.
    #[command(flatten)]
    pub figure: FigureArgs,
}

/// The arguments of `imukit allan`.
#[derive(Args, Debug)]
pub struct AllanArgs {
    /// IMU readings CSV (with `t_s`).
    pub input: PathBuf,
    /// How a vendor's CSV maps to imukit's columns.
    #[command(flatten)]
    pub map: MapArg,
    /// Which topics of a ROS bag, on which clock.
    #[command(flatten)]
    pub bag: BagArgs,
    /// The stretch of the run to read.
    #[command(flatten)]
    pub window: WindowArgs,
    /// Columns to analyse (default: every gyro and accel column present).
    #[arg(long = "column")]
    pub columns: Vec<String>,
    /// Where to write `tau_s, adev_<column>…` (CSV, or by extension `.parquet`, `.npy`, `.npz`).
    #[arg(long)]
    pub out: PathBuf,
    /// Also draw the curves with the fitted lines into this figure (`.svg` or `.png`).
    #[arg(long)]
    pub plot: Option<PathBuf>,
    /// The figure's size and resolution.
    #[command(flatten)]
    pub figure: FigureArgs,
}

/// What `imukit presets NAME` prints.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum PresetFormat {
    /// imukit's parameter file (TOML, each figure with its datasheet source).
    Toml,
    /// Kalibr's IMU noise file (`imu.yaml`).
    Kalibr,
}
