//! `imukit spectrum LOG [--column NAME …] [--scenario S] --out PSD.csv [--plot FIG]`.
use imukit::io::output::{check_outputs, check_table_outputs};
use imukit::spectrum::{overlay, spectrum_of_log};

use super::CliError;

pub fn run(a: crate::cli::SpectrumArgs) -> Result<(), CliError> {
    let crate::cli::SpectrumArgs {
        input,
        map,
        bag,
        window,
        columns,
        segment_s,
        scenario,
        out,
        plot,
        figure,
    } = a;
    let mapped = map.input(&input)?;
    bag.check(&[Some(&input)])?;
    let source = bag.input(mapped);
    let mut outputs = vec![("--out", out.as_path())];
    if let Some(p) = &plot {
        imu_plot::check_figure_path(p)?;
        outputs.push(("--plot", p.as_path()));
    }
    check_outputs(&[("input", input.as_path())], &outputs)?;
    check_table_outputs(&[("--out", out.as_path())])?;
    let size = super::plot::figure_size(&figure)?;
    let psd = spectrum_of_log(&source, &columns, window.window()?, segment_s)?;
    // The overlay of the first column's sensor, from the scenario that made the log.
    let shown = psd
        .columns
        .iter()
        .find_map(|c| c.strip_prefix("psd_"))
        .unwrap_or_default()
        .to_string();
    let marks = match &scenario {
        Some(s) => overlay(&imukit::Scenario::from_file(s)?, &shown)?,
        None => None,
    };
    psd.write(&out)?;
    if let Some(p) = &plot {
        let name = super::allan::file_name(&input);
        imu_plot::spectrum_figure(p, &psd, &name, marks.as_ref(), size)?;
    }
    if let Some(o) = &marks {
        for (f, alias) in &o.aliases {
            crate::out_line!("{shown}: vibration at {f} Hz appears at {alias} Hz");
        }
    }
    crate::note!(
        "imukit: power spectral density of {} column(s), {} frequencies, written to {}",
        psd.columns.len() - 1,
        psd.rows(),
        out.display()
    );
    if let Some(p) = &plot {
        crate::note!("imukit: figure written to {}", p.display());
    }
    Ok(())
}
