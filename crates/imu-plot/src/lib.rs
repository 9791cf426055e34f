//! # imu-plot — imukit's figures
//!
//! What `imukit plot`, `imukit animate` and `imukit demo` draw, for Rust callers, and the figure
//! specs the Python package draws with matplotlib:
//!
//! * [`spec`]: which kind of table a CSV is ([`TableKind`], from its columns) and the panels each
//!   kind gets; the animation's frame plan and default body size. Python's `imukit.plot` asks
//!   these through the binding, so both front ends draw the same panels.
//! * [`scene`]: the animated body box (corners, edges, nose face) and the NED → ENU turn of poses,
//!   defined once and handed as data to the HTML page and to Python.
//! * [`plot_files`] (the default figure of imukit CSV files, SVG or PNG by extension),
//!   [`allan_figure`], [`trajectories_figure`], [`animate::animate`] (GIF or a self-contained HTML
//!   page).
//!
//! Every file is written to a temporary name and renamed when complete.
//!
//! ```no_run
//! use std::path::{Path, PathBuf};
//! use imu_plot::FigureSize;
//! let size = FigureSize::new(Some((8.0, 6.0)), Some(150.0))?; // inches, pixels per inch
//! imu_plot::plot_files(&[PathBuf::from("truth.csv")], Path::new("truth.png"), false, size)?;
//! # Ok::<(), imu_plot::PlotError>(())
//! ```
#![forbid(unsafe_code)]
mod allan;
pub mod animate;
mod draw;
mod figures;
mod panels;
pub mod scene;
pub mod spec;
mod study;

pub use allan::allan_figure;
pub use draw::{COLORS, FigureFormat, FigureSize, check_figure_path, rasterise, write_figure};
pub use figures::{plot_files, plot_tables};
pub use panels::{Trace, trajectories_figure};
pub use spec::{FramePlan, PanelSpec, TableKind};
pub use study::study_figure;

/// What went wrong while drawing; `Display` says what and where.
#[derive(Debug, thiserror::Error)]
pub enum PlotError {
    /// A table could not be read, or holds what cannot be drawn (file, row and column named).
    #[error(transparent)]
    Data(#[from] imukit::Error),
    /// An option or a table value that cannot be drawn.
    #[error("{field}: {message}")]
    Invalid {
        /// The option (`fps`, `body_m`, as named in [`animate::AnimateOptions`]) or the file and row.
        field: String,
        /// What is wrong.
        message: String,
    },
    /// A figure could not be drawn or encoded.
    #[error("{path}: {message}")]
    Draw {
        /// The figure file.
        path: String,
        /// What went wrong.
        message: String,
    },
}

impl PlotError {
    /// True for failures to read or write files (as opposed to bad input data).
    #[must_use]
    pub fn is_io(&self) -> bool {
        matches!(
            self,
            Self::Data(imukit::Error::Io { .. }) | Self::Draw { .. }
        )
    }
}

pub(crate) fn invalid(field: impl Into<String>, message: impl Into<String>) -> PlotError {
    PlotError::Invalid {
        field: field.into(),
        message: message.into(),
    }
}
