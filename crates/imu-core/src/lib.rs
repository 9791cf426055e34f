//! # imu-core — heap-free IMU kinematics and ideal sensors
//!
//! Conventions (the contract every module keeps; see `docs/design.md` §2):
//!
//! * **Units**: SI throughout (s, m, m/s, m/s², rad, rad/s, rad/s²); magnetic field in µT.
//! * **Navigation frame** `n`: [`Enu`] (x east, y north, z up) or [`Ned`] (x north, y east, z down),
//!   chosen by type parameter, never by a run-time flag. Gravity is `g_n = [0, 0, −g]` in ENU and
//!   `[0, 0, +g]` in NED.
//! * **Body frame** `b` ([`Body`]) coincides with `n` at zero attitude: FLU under ENU, FRD under NED.
//! * **Attitude** `C_nb` maps body vectors to the navigation frame, `v_n = C_nb v_b`
//!   ([`Rotation<Body, N>`]). Euler angles are intrinsic z-y-x, `C_nb = Rz(yaw)·Ry(pitch)·Rx(roll)`
//!   ([`EulerZyx`]). Quaternions are Hamilton, scalar first, `q = q_nb`.
//! * **Body rate** `ω_b` is defined by `[ω_b×] = C_nbᵀ dC_nb/dt`; `α_b = dω_b/dt`.
//! * **Specific force** at lever arm `r`: `f_b = C_nbᵀ (a_n − g_n) + ω_b × (ω_b × r) + α_b × r`
//!   (a level IMU at rest reads `+g` on its up axis); [`AccelSign::Matlab`] reports `−f_b`.
//!
//! The crate is `#![no_std]` and never allocates: batch functions write into slices the caller
//! owns, per-sample steppers keep their state in plain structs; nothing here links `alloc`. Float
//! math comes from `std` (default feature) or `libm`. Exact analytic trajectories over dual
//! numbers, which need the standard library, are in `imukit::motion::analytic`.
#![no_std]
#![deny(unsafe_code)]

#[cfg(not(any(feature = "std", feature = "libm")))]
compile_error!("imu-core needs float math: enable the `std` or the `libm` feature");

pub mod aiding;
pub mod allan;
pub mod calibration;
pub mod cpu;
pub mod earth;
pub mod frame;
pub mod fusion;
pub mod ideal;
pub mod kinematics;
mod math;
pub mod nav_frame;
pub mod orientation;
pub mod rotation;
pub mod sensor;
pub mod signal;
pub mod stillness;
pub mod strapdown;
pub mod trig;
pub mod vector;

pub use frame::{Body, DEFAULT_GRAVITY_M_S2, Ecef, Enu, Frame, Frd, Ned};
pub use ideal::{AccelSign, IdealReading, ImuMount};
pub use kinematics::{KinematicsError, Truth};
pub use nav_frame::NavFrame;
pub use rotation::{EulerZyx, Rotation};
pub use vector::Vec3;
