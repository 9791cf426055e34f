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
//!   [`allan_figure`], [`calibration_figure`], [`spectrum_figure`], [`trajectories_figure`], [`animate::animate`] (GIF or a self-contained HTML
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
mod calibration;
mod draw;
mod figures;
mod panels;
pub mod scene;
pub mod spec;
mod spectrum;
mod study;

pub use allan::allan_figure;
pub use calibration::calibration_figure;
pub use draw::{COLORS, FigureFormat, FigureSize, check_figure_path, rasterise, write_figure};
pub use figures::{plot_files, plot_tables};
pub use panels::{Trace, trajectories_figure};
pub use spec::{FramePlan, PanelSpec, TableKind};
pub use spectrum::spectrum_figure;
pub use study::study_figure;

/// What went wrong while drawing; `Display` says what and where.
#[derive(Debug, thiserror::Error)]
pub enum PlotError {
    /// A table could not be read, or holds what cannot be drawn (file, row and column named).
    #[error(transparent)]
    Data(#[from] imukit::Error),
    /// An option refused, named by its typed name ([`FigureOption`]): each front end spells
    /// it its own way (Python's keyword, the command line's flag).
    #[error("{}: {message}", option.key())]
    Option {
        /// The option.
        option: FigureOption,
        /// What is wrong.
        message: String,
    },
    /// A table value that cannot be drawn, or a table that is not a figure's.
    #[error("{field}: {message}")]
    Invalid {
        /// The file and row, or the figure.
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

/// An option of a figure or an animation, as a refusal names it ([`PlotError::Option`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FigureOption {
    /// The figure's width and height.
    Size,
    /// The figure's resolution.
    Dpi,
    /// An animation's frames per second.
    Fps,
    /// Seconds of motion per second of animation.
    Speed,
    /// The animated body box.
    Body,
    /// The lever arm of the animated IMU point.
    LeverArm,
}

impl FigureOption {
    /// Every option.
    pub const ALL: [Self; 6] = [
        Self::Size,
        Self::Dpi,
        Self::Fps,
        Self::Speed,
        Self::Body,
        Self::LeverArm,
    ];

    /// The option's name in [`animate::AnimateOptions`] and in Python's keywords.
    #[must_use]
    pub const fn key(self) -> &'static str {
        match self {
            Self::Size => "size",
            Self::Dpi => "dpi",
            Self::Fps => "fps",
            Self::Speed => "speed",
            Self::Body => "body_m",
            Self::LeverArm => "lever_arm_m",
        }
    }

    /// The command line's flag that sets the option.
    #[must_use]
    pub const fn flag(self) -> &'static str {
        match self {
            Self::Size => "--size",
            Self::Dpi => "--dpi",
            Self::Fps => "--fps",
            Self::Speed => "--speed",
            Self::Body => "--body-m",
            Self::LeverArm => "--lever-arm-m",
        }
    }
}

/// A refusal of the figure option `option`.
pub(crate) fn refused(option: FigureOption, message: impl Into<String>) -> PlotError {
    PlotError::Option {
        option,
        message: message.into(),
    }
}

pub(crate) fn invalid(field: impl Into<String>, message: impl Into<String>) -> PlotError {
    PlotError::Invalid {
        field: field.into(),
        message: message.into(),
    }
}
