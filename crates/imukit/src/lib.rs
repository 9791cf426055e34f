//! # imukit — the library behind the `imukit` command and the Python package
//!
//! The std layer a Rust program embeds: scenario files, exact and sampled motions, sensor setups,
//! and the jobs (simulate, navigate, fuse, orient, compare, identify, Allan) the command line and
//! Python run. The numerics are in [`core`] (`imu-core`: `no_std`, no heap), files and formats in
//! [`io`] (`imu-io`, which knows no job); this crate parses, resolves, checks every input once and
//! runs the jobs.
//!
//! Conventions (the whole contract is in `docs/design.md` §2): SI units with the unit in every
//! boundary name; navigation frame ENU (default) or NED, flat Earth; body frame FLU under ENU,
//! FRD under NED; `C_nb = Rz(yaw)·Ry(pitch)·Rx(roll)`; quaternions Hamilton, scalar first,
//! `q_nb`; the accelerometer reports specific force (+g up at rest) unless told
//! `accel_sign = "matlab"`.
//!
//! Where things are, one folder per concept:
//!
//! | module | what |
//! |---|---|
//! | [`scenario`] | the scenario file as written ([`ScenarioSpec`]), its resolution into a runnable [`Scenario`], built-ins, sensor setups, Monte Carlo perturbations |
//! | [`motion`] | motions: formula strings with exact derivatives, Rust functions over dual numbers, tracks, waypoints, samples, body rates |
//! | [`io`] | the `imu-io` crate: [`Table`], every column set, the formats (CSV, Parquet, NumPy, bags, NMEA; readers that name file, row and column; writers that leave no partial file), parameter files, presets, datasheet units |
//! | [`run`] | the jobs: simulate (streamed), navigate (3D and planar), fuse, orient, compare, Allan, identify, study; each also at the crate's root ([`fuse`], [`orient`], …), where programs and the front ends name them |
//! | [`examples`] | the shipped examples (scenario files, data, Python scripts), written where the docs' commands read them |
//!
//! From `imu-io`, also at this crate's root: [`choice`] (options chosen by name), [`error`]
//! ([`Error`]: what went wrong and where) and [`sensor`] (the core's sensor types with
//! bias-instability filters on the heap).
//!
//! ## Simulate a scenario
//!
//! ```
//! use std::path::Path;
//! use imukit::ScenarioSpec;
//!
//! let spec = ScenarioSpec::from_toml(
//!     r#"
//!     rate_hz = 100.0
//!     duration_s = 2.0
//!     [trajectory]
//!     type = "expression"
//!     position_m = ["2*cos(0.5*t)", "2*sin(0.5*t)", "0"]
//!     attitude = "tangent"
//!     "#,
//!     "circle.toml",
//! )?;
//! let sim = spec.resolve(Path::new("."))?.simulate()?;
//! let omega_z = sim.truth.column("omega_z_rad_s").expect("a truth column");
//! assert!((omega_z[100] - 0.5).abs() < 1e-12); // the body turns at the circle's rate
//! let accel_z = sim.imu.column("accel_z_m_s2").expect("an IMU column");
//! assert_eq!(accel_z[0], 9.81); // specific force: +g up at rest in ENU
//! # Ok::<(), imukit::Error>(())
//! ```
//!
//! ## Integrate an IMU file
//!
//! ```
//! use imukit::navigate::{InitialState, NavSetup, integrate_csv};
//! use imukit::{Scenario, ScenarioSpec};
//!
//! let dir = std::env::temp_dir().join(format!("imukit-doc-{}", std::process::id()));
//! std::fs::create_dir_all(&dir).expect("a temporary folder");
//! let spec = ScenarioSpec::from_toml(
//!     "[trajectory]\ntype = \"builtin\"\nname = \"tilted-circle\"\n",
//!     "inline",
//! )?;
//! let sim = spec.resolve(&dir)?.simulate()?;
//! sim.imu.write_csv(&dir.join("imu.csv"))?;
//! sim.truth.write_csv(&dir.join("truth.csv"))?;
//!
//! let initial = InitialState::from_csv(&dir.join("truth.csv"))?;
//! let nav = integrate_csv(&dir.join("imu.csv"), &initial, &NavSetup::default(), Default::default(), &dir.join("nav.csv"))?;
//! assert_eq!(nav.rows, sim.truth.rows());
//! # std::fs::remove_dir_all(&dir).ok();
//! # Ok::<(), imukit::Error>(())
//! ```
//!
//! ## Read a CSV file
//!
//! ```
//! use imukit::io::read::read_table;
//! use imukit::Table;
//!
//! let path = std::env::temp_dir().join(format!("imukit-doc-read-{}.csv", std::process::id()));
//! let mut t = Table::new(&["t_s", "gyro_z_rad_s"]);
//! t.push_row(&[0.0, 0.1]);
//! t.push_row(&[0.01, 0.2]);
//! t.write_csv(&path)?;
//!
//! let back = read_table(&path)?; // errors name the file, the row and the column
//! assert_eq!(back.columns, ["t_s", "gyro_z_rad_s"]);
//! assert_eq!(back.column("gyro_z_rad_s"), Some(vec![0.1, 0.2]));
//! # std::fs::remove_file(&path).ok();
//! # Ok::<(), imukit::Error>(())
//! ```
#![forbid(unsafe_code)]
pub mod examples;
pub mod motion;
pub mod run;
pub mod scenario;

pub use imu_io as io;
pub use imu_io::{choice, error, sensor};

pub use error::{Error, Result};
pub use imu_core as core;
pub use io::table::Table;
pub use scenario::{Scenario, ScenarioSpec, Simulation};

// The jobs at the crate's root, where programs and the front ends name them
// (`imukit::fuse::fuse_with`, `imukit::orient::orient_csv`): `run` only groups them.
pub use run::{
    allan, arrays, calibrate, compare, epochs, fuse, identify, imu_sensor, navigate, orient,
    pipeline, planar, reference, simulate, spectrum, study,
};

/// The README's Rust examples, compiled and run as doctests.
#[cfg(doctest)]
#[doc = include_str!("../../../README.md")]
mod readme {}

/// The Rust guide's examples (`docs/rust.md`), compiled and run as doctests.
#[cfg(doctest)]
#[doc = include_str!("../../../docs/rust.md")]
mod rust_guide {}
