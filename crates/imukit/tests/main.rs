//! imukit's integration tests, one binary (each binary would link every format again): each module is one job's or one concept's tests.
//! `cargo test -p imukit --test integration MODULE::` runs one module's.
mod asl;
mod chain;
mod clock;
mod common;
mod compiled_formulas;
mod core_body_rates;
mod core_closed_form;
mod core_sampled;
mod core_strapdown;
mod correlated_fixes;
mod earth;
mod fusion;
mod gnss;
mod hostile;
mod identify;
mod learnt;
mod navigation;
mod planar;
mod presets;
mod requests;
mod scenario;
mod sensors;
mod stream;
mod study;
mod vibration;
mod waypoints;
