//! # imu-scenario — imukit's std layer, shared by the CLI and the Python package
//!
//! Scenario files ([`scenario`]), formula strings with exact derivatives ([`expr`]), tracks
//! ([`track`]), built-in scenarios ([`builtin`]) and the CSV schema ([`table`]). Units are
//! converted here and only here; the numerics live in `imu-core`.
pub mod analysis;
pub mod analytic;
pub mod arrays;
pub mod builtin;
pub mod compare;
pub mod error;
pub mod expr;
pub mod figures;
pub mod navigation;
pub mod orient;
pub mod params;
pub mod perturb;
pub mod planar;
pub mod presets;
pub mod scenario;
pub mod sensors;
pub mod stream;
pub mod table;
pub mod track;
pub mod units;
pub mod waypoints;

pub use error::{Error, Result};
pub use scenario::{Scenario, ScenarioSpec, Simulation};
pub use table::Table;
