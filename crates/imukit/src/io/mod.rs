//! Files in and out: tables and CSV ([`table`]), tables as Parquet ([`parquet`]), parameter
//! files ([`params`]), the built-in
//! presets of real parts ([`presets`]), datasheet units ([`units`]) and the time-checked row
//! reader of IMU files ([`rows`]).
pub mod output;
pub mod params;
pub mod parquet;
pub mod presets;
pub mod rows;
pub mod table;
pub mod units;
