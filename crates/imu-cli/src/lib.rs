//! # imu-cli — the `imukit` command line, and imukit's figures as a Rust API
//!
//! [`plot`] draws what `imukit plot` and `imukit animate` draw, for Rust callers:
//! [`plot::plot_files`] (the default figure of imukit CSV files, SVG or PNG),
//! [`plot::animate::animate`] (GIF or self-contained HTML of a truth table),
//! [`plot::allan_figure`] and [`plot::trajectories_figure`]. Which panels each kind of table gets
//! is decided in `imukit::figures`, shared with the Python package.
//!
//! ```no_run
//! use std::path::{Path, PathBuf};
//! imu_cli::plot::plot_files(&[PathBuf::from("truth.csv")], Path::new("truth.png"), false)?;
//! # Ok::<(), imu_cli::CliError>(())
//! ```
#[doc(hidden)]
pub mod cli;
#[doc(hidden)]
pub mod commands;
pub mod plot;

pub use commands::CliError;
