//! imu-io's integration tests, one binary: each module is one format's or one rule's tests.
//! `cargo test -p imu-io --test integration MODULE::` runs one module's.
mod binary_inputs;
mod calibration;
mod formats;
mod input;
mod kalibr;
mod output_group;
