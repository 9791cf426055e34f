//! The jobs a user runs: simulate ([`simulate`], [`arrays`] for in-memory arrays), navigate
//! ([`navigate`], on the WGS-84 Earth [`earth_nav`], with GNSS [`fuse`], [`planar`]), orient
//! ([`orient`]), compare ([`compare`]), analyse ([`allan`]) and compare IMUs through a GNSS
//! outage ([`study`]). A streamed run may use two threads ([`pipeline`]).
pub mod allan;
pub mod arrays;
pub mod compare;
pub mod earth_nav;
pub mod fuse;
mod fuse_aids;
pub mod fuse_earth;
pub mod imu_sensor;
pub mod navigate;
pub mod orient;
pub mod pipeline;
pub mod planar;
pub mod simulate;
pub mod study;
