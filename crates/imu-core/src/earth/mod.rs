//! The real Earth: the WGS-84 ellipsoid, normal gravity, the Earth and transport rates, and the
//! ideal IMU of a vehicle moving over the rotating Earth.
//!
//! Frames: ECEF ([`Ecef`](crate::Ecef)); the local NED frame at the current position (north along
//! the meridian, down along the ellipsoid normal); the body frame FRD. `C_nb = Rz(yaw) Ry(pitch)
//! Rx(roll)` with yaw from true north. The flat model of the rest of the crate (constant gravity,
//! a non-rotating local-level frame) stays the default of every front end; this module is what
//! `earth = "wgs84"` selects. See `docs/design.md` (the Earth model) for the formulas and their
//! sources.
pub mod gravity;
pub mod ideal;
pub mod model;
pub mod rates;
pub mod wgs84;
pub mod wmm;

pub use gravity::{GravityModel, normal_gravity_m_s2};
pub use ideal::{EarthMount, EarthTruth, EcefKinematics};
pub use model::{EarthModel, EarthTerms, ErrorCouplings, FlatEarth, Wgs84};
pub use rates::{MAX_LATITUDE_RAD, earth_rate_ned, transport_rate_ned};
pub use wgs84::Geodetic;
pub use wmm::{MagneticModel, WmmError};
