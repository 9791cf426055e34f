//! `imukit exercise`: the planar cart exercise (inertial navigation in a plane), end to end.
use std::fmt::Write as _;
use std::path::Path;

use imu_core::strapdown::planar::{PlanarScheme, PlanarState};
use imukit::Table;
use imukit::planar::{integrate, samples_from_table, write_dat};
use imukit::scenario::builtin;

use super::CliError;
use imu_plot::{Trace, trajectories_figure};

/// Sensor errors of the exercise's second file: the ICM-42688-P preset's noise plus modest
/// turn-on biases, so the erroneous trajectory drifts visibly but stays on the page.
const ERRORS: &str = r#"
[imu]
preset = "icm-42688-p"
[imu.accelerometer]
constant_bias_m_s2 = [0.02, -0.015, 0.0]
[imu.gyroscope]
constant_bias_rad_s = [0.0, 0.0, 0.002]
"#;

pub fn run(out_dir: &Path, seed: u64) -> Result<(), CliError> {
    let io = |source| CliError::Io {
        path: out_dir.display().to_string(),
        source,
    };
    std::fs::create_dir_all(out_dir).map_err(io)?;
    let clean_spec = builtin::spec("cart")?;
    let clean = clean_spec.resolve(out_dir)?.simulate()?;
    let mut noisy_spec = clean_spec.clone();
    let errors = imukit::ScenarioSpec::from_toml(
        &format!("{ERRORS}\n[trajectory]\ntype = \"builtin\"\nname = \"cart\"\n"),
        "exercise errors",
    )?;
    noisy_spec.imu = errors.imu.or(&noisy_spec.imu);
    noisy_spec.imu.seed = Some(seed);
    let noisy = noisy_spec.resolve(out_dir)?.simulate()?;

    clean.truth.write_csv(&out_dir.join("truth.csv"))?;
    let files = [
        ("inertial_data.dat", &clean),
        ("inertial_data_errors.dat", &noisy),
    ];
    let mut traces = vec![Trace::from_table("truth (rail)", &clean.truth, false)?];
    let mut summary = String::new();
    let _ = writeln!(
        summary,
        "planar cart exercise: cart on a closed rail, start and end at (100, 100) m"
    );
    let _ = writeln!(
        summary,
        "{:<26} {:<10} {:>24} {:>14}",
        "data", "scheme", "end (X, Y) m", "end error m"
    );
    for (file, sim) in files {
        let samples = samples_from_table(&sim.imu)?;
        write_dat(&out_dir.join(file), &samples)?;
        for (scheme, name) in [
            (PlanarScheme::Exercise, "exercise"),
            (PlanarScheme::Trapezoid, "trapezoid"),
        ] {
            let nav = integrate(
                &samples,
                scheme,
                PlanarState::exercise_start(samples[0].t_s),
            )?;
            let stem = file.trim_end_matches(".dat");
            nav.write_csv(&out_dir.join(format!("{stem}_{name}.csv")))?;
            let (x, y) = end(&nav);
            let err = (x - 100.0).hypot(y - 100.0);
            let _ = writeln!(
                summary,
                "{file:<26} {name:<10} {:>24} {err:>14.3}",
                format!("({x:.3}, {y:.3})")
            );
            traces.push(Trace::from_table(&format!("{stem} ({name})"), &nav, false)?);
        }
    }
    let _ = writeln!(
        summary,
        "\nThe exercise's rotation R = [[cos α, sin α], [−sin α, cos α]] turns increments by −α: with the\n\
         left-turning rail it mirrors the trajectory about the start heading (see imukit's docs)."
    );
    trajectories_figure(
        &out_dir.join("trajectories.svg"),
        "Planar cart exercise: dead reckoning of the cart",
        &traces,
    )?;
    imukit::io::output::write_atomically(&out_dir.join("summary.txt"), |w| {
        std::io::Write::write_all(w, summary.as_bytes())
    })?;
    crate::out!("{summary}");
    crate::out_line!(
        "\nWrote inertial_data.dat, inertial_data_errors.dat, truth.csv, the four trajectories (CSV), \
         trajectories.svg and summary.txt to {}",
        out_dir.display()
    );
    Ok(())
}

fn end(nav: &Table) -> (f64, f64) {
    let x = nav.column("pos_x_m").unwrap_or_default();
    let y = nav.column("pos_y_m").unwrap_or_default();
    (
        x.last().copied().unwrap_or(f64::NAN),
        y.last().copied().unwrap_or(f64::NAN),
    )
}
