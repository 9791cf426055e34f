//! Dead reckoning and strapdown navigation from IMU data.
//!
//! [`planar`]: a cart in a plane with two accelerometers and a yaw gyro (the planar cart exercise), with the
//! exercise's own update rules kept verbatim and a consistent second-order default.
//! [`step`]: 3D strapdown with coning and sculling in a flat-Earth local-level frame (second order);
//! [`rk4`]: a fourth-order alternative for rate samples.
//! [`earth`]: both schemes on the rotating WGS-84 Earth (Earth rate, transport rate, Coriolis,
//! normal gravity, a free, held or baro-damped vertical channel).
pub mod earth;
pub mod planar;
pub mod rk4;
pub mod step;
