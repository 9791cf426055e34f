//! `imukit study STUDY.toml --out TABLE.csv [--plot FIGURE.png]`: the library's outage study,
//! every preset's runs on all cores, in a fixed order (same numbers on any number of threads).
use std::path::Path;

use imukit::io::output::check_outputs;
use imukit::study::Study;
use rayon::prelude::*;

use super::CliError;

pub fn run(study: &Path, out: &Path, plot: Option<&Path>) -> Result<(), CliError> {
    if let Some(p) = plot {
        imu_plot::check_figure_path(p)?;
    }
    let s = Study::from_file(study)?;
    let mut inputs = vec![("study file", study), ("scenario", s.scenario_path())];
    inputs.extend(s.input_files().iter().map(|(what, p)| (*what, p.as_path())));
    let mut outputs = vec![("--out", out)];
    outputs.extend(plot.map(|p| ("--plot", p)));
    check_outputs(&inputs, &outputs)?;
    imukit::io::output::check_table_outputs(&[("--out", out)])?;
    for line in s.undescribed() {
        crate::report::warn(&format!("the presets are not described alike: {line}"));
    }
    let presets = s.presets().count();
    let runs = s.runs();
    let total = presets as u64 * runs;
    let progress = crate::report::Progress::start(total, "runs");
    let flat = (0..total)
        .into_par_iter()
        .map(|k| {
            let r = s.run_one((k / runs) as usize, k % runs);
            progress.inc();
            r
        })
        .collect::<Result<Vec<_>, _>>()?;
    progress.finish();
    let mut per_preset = Vec::with_capacity(presets);
    let mut it = flat.into_iter();
    for _ in 0..presets {
        per_preset.push(it.by_ref().take(runs as usize).collect::<Vec<_>>());
    }
    let (table, summaries) = s.summarise(&per_preset)?;
    table.write(out)?;
    if let Some(p) = plot {
        imu_plot::study_figure(p, &table)?;
    }
    let (start, end) = s.outage_s();
    let into = summaries.first().map_or(0.0, |m| m.outage_s);
    crate::note!(
        "imukit: {runs} runs per preset through the GNSS outage at {start}–{end} s; horizontal \
         position error {into:.2} s into it (RMS over runs) and the filter's own one-sigma:"
    );
    for m in &summaries {
        let diverged = match &m.diverged {
            (0, _) => String::new(),
            (n, first) => format!(
                "; the filter diverged in {n} of {runs} runs ({})",
                first.as_deref().unwrap_or("")
            ),
        };
        let reset = match m.resets {
            (0, _) => String::new(),
            (k, total) => format!(
                "; the filter lost the fixes and was reset to them {total} times in {k} of {runs} \
                 runs: its one-sigma understates its error"
            ),
        };
        let smoothed = m
            .smoothed_rms_error_m
            .map(|(end, worst)| {
                format!("; smoothed: {end:.3} m there, at most {worst:.3} m along the outage")
            })
            .unwrap_or_default();
        match (m.rms_error_m, m.sigma_m) {
            (Some(e), Some(s)) => {
                crate::note!(
                    "  {:<14} {e:>10.3} m   (filter: {s:.3} m){smoothed}{reset}{diverged}",
                    m.preset
                );
            }
            _ => crate::note!("  {:<14} not reported{reset}{diverged}", m.preset),
        }
    }
    crate::note!(
        "imukit: table in {}{}",
        out.display(),
        plot.map(|p| format!(", figure in {}", p.display()))
            .unwrap_or_default()
    );
    Ok(())
}
