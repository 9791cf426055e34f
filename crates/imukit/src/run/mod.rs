//! The jobs a user runs: simulate ([`simulate`], [`arrays`] for in-memory arrays), navigate
//! ([`navigate`] and with GNSS [`fuse`] on either Earth through `nav_earth`, [`planar`]), orient
//! ([`orient`]), compare ([`compare`]), analyse ([`allan`]) and compare IMUs through a GNSS
//! outage ([`study`]). A streamed run may use two threads ([`pipeline`]).
pub mod allan;
pub mod arrays;
pub mod calibrate;
pub mod compare;
pub mod epochs;
pub mod fuse;
pub mod identify;
pub mod imu_sensor;
pub(crate) mod nav_earth;
pub mod navigate;
pub mod orient;
pub mod pipeline;
pub mod planar;
pub mod reference;
pub mod simulate;
pub mod spectrum;
pub mod study;
