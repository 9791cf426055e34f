//! `imukit plot` and `imukit animate`.
use std::path::{Path, PathBuf};

use crate::plot::animate::{self as anim, AnimateOptions};
use crate::plot::{plot_files, read_table};

use super::CliError;

pub fn plot(files: &[PathBuf], out: &Path) -> Result<(), CliError> {
    plot_files(files, out)?;
    println!("Wrote {}", out.display());
    Ok(())
}

pub fn animate(
    truth: &Path,
    out: &Path,
    body: Option<&[f64]>,
    lever_arm: Option<&[f64]>,
    fps: f64,
    speed: Option<f64>,
) -> Result<(), CliError> {
    let three = |v: &[f64]| [v[0], v[1], v[2]];
    let opts = AnimateOptions {
        body_m: body.map(three),
        lever_arm_m: lever_arm.map_or([0.0; 3], three),
        fps,
        speed,
        ..AnimateOptions::default()
    };
    let table = read_table(truth)?;
    let info = anim::animate(&table, &truth.display().to_string(), out, &opts)?;
    println!(
        "Wrote {} ({} frames at {} frames/s, {}× real time)",
        out.display(),
        info.frames,
        opts.fps,
        info.speed
    );
    Ok(())
}
