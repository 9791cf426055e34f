//! imu-core's integration tests, one binary: each module is one concept's tests.
//! `cargo test -p imu-core --test integration MODULE::` runs one module's.
mod aids;
mod align;
mod allan;
mod coning;
mod earth;
mod earth_frames;
mod earth_strapdown;
mod eskf;
mod finite_diff;
mod fix_errors;
mod gnss;
mod orientation;
mod planar;
mod process_noise;
mod rectification;
mod robust;
mod robust_motion;
mod rotation;
mod sensor;
mod sensor_noise;
mod signal;
mod smoother;
mod spherical_earth;
mod stillness;
mod trig;
mod wmm;
