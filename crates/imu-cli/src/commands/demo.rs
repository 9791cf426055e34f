//! `imukit demo`: the built-in default scenario, end to end, into a folder.
use std::fmt::Write as _;
use std::io::Write as _;
use std::path::Path;

use imu_plot::animate::{AnimateOptions, animate};
use imu_plot::{FigureSize, plot_tables};
use imukit::Simulation;
use imukit::io::conventions::NavFrameName;
use imukit::io::output::write_atomically;
use imukit::scenario::builtin;

use super::CliError;

pub fn run(out_dir: &Path, name: &str) -> Result<(), CliError> {
    let io = |source| CliError::Io {
        path: out_dir.display().to_string(),
        source,
    };
    // The scenario is checked before the folder is made.
    let spec = builtin::spec(name)?;
    std::fs::create_dir_all(out_dir).map_err(io)?;
    let sim = spec.resolve(out_dir)?.simulate()?;
    let files = [(
        "scenario.toml",
        "the scenario, editable: imukit simulate scenario.toml --out imu.csv",
    )];
    let toml_path = out_dir.join(files[0].0);
    let toml = builtin::toml(name)?;
    write_atomically(&toml_path, |w| w.write_all(toml.as_bytes()))?;
    sim.truth.write_csv(&out_dir.join("truth.csv"))?;
    sim.imu.write_csv(&out_dir.join("imu.csv"))?;
    let ned = spec.nav_frame == Some(NavFrameName::NED);
    // Drawn from the tables in memory: the files are put in place when the command ends.
    plot_tables(
        &[(out_dir.join("truth.csv"), sim.truth.clone())],
        &out_dir.join("truth.png"),
        ned,
        FigureSize::default(),
    )?;
    plot_tables(
        &[(out_dir.join("imu.csv"), sim.imu.clone())],
        &out_dir.join("imu.png"),
        ned,
        FigureSize::default(),
    )?;
    let lever_arm_m = spec.imu.lever_arm_m.unwrap_or([0.0; 3]);
    let opts = AnimateOptions {
        lever_arm_m,
        ned,
        ..AnimateOptions::default()
    };
    animate(
        &sim.truth,
        "truth.csv",
        &out_dir.join("animation.html"),
        &opts,
    )?;
    let summary = summary(name, &sim);
    let summary_path = out_dir.join("summary.txt");
    write_atomically(&summary_path, |w| w.write_all(summary.as_bytes()))?;
    crate::out!("{summary}");
    crate::out_line!(
        "\nWrote scenario.toml, truth.csv, imu.csv, summary.txt, the figures truth.png and imu.png \
         and the animation animation.html (open it in a browser) to {}",
        out_dir.display()
    );
    Ok(())
}

fn summary(name: &str, sim: &Simulation) -> String {
    let t = sim.truth.column("t_s").unwrap_or_default();
    let mut s = String::new();
    let _ = writeln!(s, "imukit demo: built-in scenario \"{name}\"");
    let _ = writeln!(
        s,
        "{} samples from {} s to {} s",
        t.len(),
        t.first().copied().unwrap_or(0.0),
        t.last().copied().unwrap_or(0.0)
    );
    let _ = writeln!(
        s,
        "{:<16} {:>14} {:>14} {:>14}",
        "IMU column", "min", "max", "rms"
    );
    for c in sim.imu.columns.iter().skip(1) {
        let v = sim.imu.column(c).unwrap_or_default();
        let min = v.iter().copied().fold(f64::INFINITY, f64::min);
        let max = v.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        let rms = (v.iter().map(|x| x * x).sum::<f64>() / v.len().max(1) as f64).sqrt();
        let _ = writeln!(s, "{c:<16} {min:>14.6} {max:>14.6} {rms:>14.6}");
    }
    s
}
