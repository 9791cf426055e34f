//! `imukit allan IMU.csv [--column NAME …] --out ADEV.csv`.
use std::path::Path;

use imukit::io::output::check_outputs;
use imukit::io::table::{ACCEL_COLUMNS, GYRO_COLUMNS, read_columns, read_header};
use imukit::run::allan::{allan, mean_rate};

use super::CliError;

pub fn run(
    input: &Path,
    columns: &[String],
    out: &Path,
    plot: Option<&Path>,
    size: imu_plot::FigureSize,
) -> Result<(), CliError> {
    if let Some(p) = plot {
        imu_plot::check_figure_path(p)?;
    }
    let mut outputs = vec![("--out", out)];
    outputs.extend(plot.map(|p| ("--plot", p)));
    check_outputs(&[("input", input)], &outputs)?;
    let header = read_header(input)?;
    let chosen: Vec<String> = if columns.is_empty() {
        GYRO_COLUMNS
            .iter()
            .chain(&ACCEL_COLUMNS)
            .filter(|c| header.iter().any(|h| h == *c))
            .map(|c| (*c).to_string())
            .collect()
    } else {
        columns.to_vec()
    };
    let mut required: Vec<&str> = vec!["t_s"];
    required.extend(chosen.iter().map(String::as_str));
    let hint = if chosen.is_empty() {
        "; no gyro_* or accel_* columns: name columns with --column"
    } else {
        ""
    };
    let data = read_columns(input, &required, hint)?;
    let rate = mean_rate(data.get("t_s"))?;
    let series: Vec<(String, Vec<f64>)> = chosen
        .iter()
        .map(|c| (c.clone(), data.get(c).to_vec()))
        .collect();
    // The library names the column; the file is named here.
    let in_file = |column: String| format!("{}, column {column}", input.display());
    let result = allan(&series, rate).map_err(|e| match e {
        imukit::Error::Invalid { field, message } => imukit::Error::Invalid {
            field: in_file(field),
            message,
        },
        imukit::Error::Allan { context, source } => imukit::Error::Allan {
            context: in_file(context),
            source,
        },
        other => other,
    })?;
    result.table.write(out)?;
    if let Some(p) = plot {
        let source = input.file_name().map_or_else(
            || input.display().to_string(),
            |n| n.to_string_lossy().into_owned(),
        );
        imu_plot::allan_figure(p, &result, &source, size)?;
    }
    println!(
        "{:<16} {:>14} {:>14} {:>14}",
        "column", "N (·/√Hz)", "B", "K (·√Hz)"
    );
    let show = |v: Option<f64>| v.map_or_else(|| "—".to_string(), |x| format!("{x:.4e}"));
    for (name, id) in &result.noise {
        println!(
            "{name:<16} {:>14} {:>14} {:>14}",
            show(id.noise_density),
            show(id.bias_instability),
            show(id.random_walk)
        );
    }
    if let Some(p) = plot {
        println!("\nFigure written to {}", p.display());
    }
    println!(
        "\nAllan deviation of {} columns at {} τ values ({rate} Hz) written to {}",
        series.len(),
        result.table.rows(),
        out.display()
    );
    Ok(())
}
