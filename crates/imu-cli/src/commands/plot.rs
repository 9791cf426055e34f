//! `imukit plot` and `imukit animate`.
use std::path::{Path, PathBuf};

use imu_plot::animate::{self as anim, AnimateOptions};
use imu_plot::{FigureSize, plot_files};
use imukit::io::conventions::NavFrameName;
use imukit::io::described::Described;
use imukit::io::output::check_outputs;
use imukit::io::read::read_table;
use imukit::io::rows::TimeWindow;

use super::CliError;
use crate::cli::FigureArgs;

/// The frame positions are drawn in: `--nav-frame`, else what the files' descriptions say,
/// else ENU; a flag or a file that contradicts another is refused.
pub fn described_frame(
    files: &[&Path],
    asked: Option<NavFrameName>,
) -> Result<NavFrameName, CliError> {
    Ok(Described::read(files)?.pick(
        imukit::error::RequestOption::NavFrame,
        asked,
        |d| d.nav_frame,
        NavFrameName::default(),
    )?)
}

pub fn plot(
    files: &[PathBuf],
    out: &Path,
    nav_frame: Option<NavFrameName>,
    window: TimeWindow,
    size: FigureSize,
) -> Result<(), CliError> {
    imu_plot::check_figure_path(out)?;
    let inputs: Vec<(&str, &Path)> = files.iter().map(|f| ("input", f.as_path())).collect();
    check_outputs(&inputs, &[("--out", out)])?;
    let paths: Vec<&Path> = files.iter().map(PathBuf::as_path).collect();
    let nav_frame = described_frame(&paths, nav_frame)?;
    if window.is_whole() {
        plot_files(files, out, nav_frame == NavFrameName::NED, size)?;
    } else {
        // Every file cut at the same instants, counted from the first file's first sample.
        let mut tables = Vec::with_capacity(files.len());
        let mut t0 = None;
        for f in files {
            let table = read_table(f)?;
            let name = f.display().to_string();
            let origin = match t0 {
                Some(t) => t,
                None => *t0.insert(TimeWindow::first_time(&table, &name)?),
            };
            tables.push((f.clone(), window.apply(table, origin, &name, 1)?));
        }
        imu_plot::plot_tables(&tables, out, nav_frame == NavFrameName::NED, size)?;
    }
    crate::note!("imukit: wrote {}", out.display());
    Ok(())
}

/// The figure size and resolution of `--size` and `--dpi`, checked; refusals name the flag.
pub fn figure_size(args: &FigureArgs) -> Result<FigureSize, CliError> {
    let size_in = args
        .size
        .as_deref()
        .map(|s| (s[0], s.get(1).copied().unwrap_or(s[0])));
    FigureSize::new(size_in, args.dpi).map_err(CliError::from)
}

/// The animation options from the command line.
pub fn options(
    body: Option<&[f64]>,
    lever_arm: Option<&[f64]>,
    fps: f64,
    speed: Option<f64>,
    nav_frame: NavFrameName,
) -> AnimateOptions {
    let three = |v: &[f64]| [v[0], v[1], v[2]];
    AnimateOptions {
        body_m: body.map(three),
        lever_arm_m: lever_arm.map_or([0.0; 3], three),
        fps,
        speed,
        ned: nav_frame == NavFrameName::NED,
        ..AnimateOptions::default()
    }
}

pub fn animate(
    truth: &Path,
    out: &Path,
    window: TimeWindow,
    opts: &AnimateOptions,
) -> Result<(), CliError> {
    anim::check_animation_path(out)?;
    check_outputs(&[("truth file", truth)], &[("--out", out)])?;
    let table = read_table(truth)?;
    let name = truth.display().to_string();
    let t0 = TimeWindow::first_time(&table, &name)?;
    let table = window.apply(table, t0, &name, 2)?;
    let info = anim::animate(&table, &truth.display().to_string(), out, opts)?;
    crate::note!(
        "imukit: wrote {} ({} frames at {} frames/s, {}× real time)",
        out.display(),
        info.frames,
        opts.fps,
        info.speed
    );
    Ok(())
}
