//! Files in and out: tables and CSV ([`table`]), parameter files ([`params`]), the built-in
//! presets of real parts ([`presets`]) and datasheet units ([`units`]).
pub mod params;
pub mod presets;
pub mod table;
pub mod units;
