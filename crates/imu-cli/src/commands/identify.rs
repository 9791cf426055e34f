//! `imukit identify STATIC.csv [--out CURVE.csv] [--params P.toml] [--kalibr imu.yaml] [--plot F]`.
use std::io::Write;
use std::path::Path;

use imukit::identify::{
    column_header, column_warnings, curve_table, filter_noise, kalibr, param_file, rest_line,
    scale_rows, term_rows,
};
use imukit::io::Input;
use imukit::io::output::{check_outputs, write_atomically};
use imukit::io::part_file::to_toml;
use imukit::io::rows::TimeWindow;

use super::CliError;
use super::allan::{analyse, file_name};

/// Where `identify` writes, besides the curve.
pub struct Outputs<'a> {
    pub out: Option<&'a Path>,
    pub params: Option<&'a Path>,
    pub kalibr: Option<&'a Path>,
    pub kalibr_inflation: f64,
    pub kalibr_topic: &'a str,
    pub plot: Option<&'a Path>,
}

pub fn run(
    source: &Input,
    columns: &[String],
    window: TimeWindow,
    to: &Outputs<'_>,
    size: imu_plot::FigureSize,
) -> Result<(), CliError> {
    let input = source.path();
    if let Some(p) = to.plot {
        imu_plot::check_figure_path(p)?;
    }
    let mut outputs: Vec<(&str, &Path)> = to.out.map(|p| ("--out", p)).into_iter().collect();
    outputs.extend(to.params.map(|p| ("--params", p)));
    outputs.extend(to.kalibr.map(|p| ("--kalibr", p)));
    outputs.extend(to.plot.map(|p| ("--plot", p)));
    check_outputs(&[("input", input)], &outputs)?;
    crate::report::warn_implausible(source);
    let result = analyse(source, columns, window)?;
    let source = file_name(input);
    // Everything is computed before anything is written.
    let file = param_file(&result, &source);
    let file = if to.params.is_some() || to.kalibr.is_some() {
        Some(file?)
    } else {
        file.ok()
    };
    let yaml = match (to.kalibr, &file) {
        (Some(_), Some(file)) => Some(kalibr(&result, file, to.kalibr_inflation, to.kalibr_topic)?),
        _ => None,
    };
    if let Some(out) = to.out {
        curve_table(&result).write(out)?;
    }
    if let (Some(path), Some(file)) = (to.params, &file) {
        let text = to_toml(file);
        write_atomically(path, |w| w.write_all(text.as_bytes()))?;
    }
    if let (Some(path), Some(text)) = (to.kalibr, &yaml) {
        write_atomically(path, |w| w.write_all(text.as_bytes()))?;
    }
    if let Some(p) = to.plot {
        imu_plot::allan_figure(p, &result, &source, size)?;
    }
    let rows = term_rows(&result);
    let scaled = scale_rows(&result);
    for c in &result.noise {
        crate::out_line!(
            "{}",
            column_header(&c.column, &c.fit, result.samples, result.sample_rate_hz)
        );
        for row in rows.iter().filter(|r| r.column == c.column) {
            crate::out_line!("{}", row.line());
        }
        for row in scaled.iter().filter(|r| r.column == c.column) {
            crate::out_line!("{}", row.line());
        }
        crate::out_line!("{}", rest_line(c));
    }
    for c in &result.noise {
        for w in column_warnings(&result, c) {
            crate::report::warn(&format!("{}: {w}", input.display()));
        }
    }
    if let Some(file) = &file {
        crate::out_line!(
            "\nThe fusion filter's noise for this part (fuse --imu with the parameter file):"
        );
        for (sensor, white, drift) in filter_noise(file, result.sample_rate_hz) {
            let u = if sensor == imukit::io::params::Sensor::Gyroscope {
                "rad/s"
            } else {
                "m/s²"
            };
            crate::out_line!(
                "  {:<13} white {white:.4e} {u}/√Hz, bias drift {drift:.4e} {u}·√Hz",
                sensor.key()
            );
        }
    }
    for (what, path) in [
        ("Allan curves with 95 % bands and fitted terms", to.out),
        ("Parameter file", to.params),
        ("Kalibr imu.yaml", to.kalibr),
        ("Figure", to.plot),
    ] {
        if let Some(p) = path {
            crate::note!("imukit: {what} written to {}", p.display());
        }
    }
    Ok(())
}
