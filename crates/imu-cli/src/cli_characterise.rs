//! The arguments of the commands that characterise a part from its readings: `imukit
//! calibrate` and `imukit spectrum` (the rest of the command line: `cli`).
use std::path::PathBuf;

use clap::Args;

use crate::cli::{BagArgs, FigureArgs, MapArg, WindowArgs};

/// The arguments of `imukit calibrate`.
#[derive(Args, Debug)]
pub struct CalibrateArgs {
    /// IMU readings of the procedure (with `t_s`).
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
    /// Local gravity, m/s² (the accelerometer is scaled to read it at rest).
    #[arg(long, default_value_t = imukit::core::DEFAULT_GRAVITY_M_S2)]
    pub gravity_m_s2: f64,
    /// Where to write the calibration (TOML).
    #[arg(long)]
    pub out: PathBuf,
    /// Also draw the residuals, raw and calibrated, into this figure (`.svg` or `.png`).
    #[arg(long)]
    pub plot: Option<PathBuf>,
    /// The figure's size and resolution.
    #[command(flatten)]
    pub figure: FigureArgs,
}

/// The arguments of `imukit spectrum`.
#[derive(Args, Debug)]
pub struct SpectrumArgs {
    /// IMU readings (with `t_s`).
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
    /// Length of the segments averaged, s (the resolution is its inverse).
    #[arg(long, default_value_t = imukit::spectrum::DEFAULT_SEGMENT_S)]
    pub segment_s: f64,
    /// The scenario that made the readings: the figure marks its vibration's aliases and draws
    /// the first column's chain.
    #[arg(long)]
    pub scenario: Option<PathBuf>,
    /// Where to write `frequency_hz, psd_<column>…` (CSV, or by extension `.parquet`, `.npy`,
    /// `.npz`).
    #[arg(long)]
    pub out: PathBuf,
    /// Also draw the densities into this figure (`.svg` or `.png`).
    #[arg(long)]
    pub plot: Option<PathBuf>,
    /// The figure's size and resolution.
    #[command(flatten)]
    pub figure: FigureArgs,
}
