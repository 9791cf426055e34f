//! The command's integration tests, one binary: each module runs `imukit` as a user would for one concept.
//! `cargo test -p imu-cli --test integration MODULE::` runs one module's.
mod common;
mod conventions;
mod fuse;
mod fuse_model;
mod integrate;
mod orient;
mod outputs;
mod own_log;
mod plot;
mod refusals;
mod simulate;
