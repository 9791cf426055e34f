//! The outage study: which IMU does a vehicle need to bridge a GNSS outage? A scenario (its
//! trajectory, `[gnss]` receiver and `[[gnss.outages]]`) is simulated with each IMU preset over
//! seeded Monte Carlo runs and fused by the loosely coupled filter ([`crate::run::fuse`]); the
//! study reports, per preset and time into the first outage, the RMS over runs of the
//! horizontal position error and the filter's own horizontal one-sigma (its RMS over runs), so
//! a user sees both how far each IMU drifts and whether the filter knows it.
//!
//! Runs are independent (run r of a preset draws `SeededNormals::for_run(seed, r)`), so
//! [`Study::run_one`] may be called on any thread in any order and [`Study::summarise`] gives
//! the same numbers.
use std::path::{Path, PathBuf};

use serde::Deserialize;

use crate::error::{Error, Result, invalid};
use crate::io::table::Table;
use crate::run::fuse::{
    AidTables, FuseRequest, FuseSetup, Start, fuse_filtered_and_smoothed, fuse_with,
};
use crate::run::navigate::InitialState;
use crate::scenario::{Scenario, ScenarioSpec};

/// Most Monte Carlo runs per preset a study takes.
pub const MAX_RUNS: u64 = 100_000;

/// A study file as written (TOML).
#[derive(Clone, Debug, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct StudySpec {
    /// The scenario file, relative to the study file: trajectory, `[imu]` (its `preset` is
    /// replaced by each of `presets`; other keys apply to all), `[gnss]` with at least one
    /// `[[gnss.outages]]`, and `[odometer]` or `[baro]` when the study uses them.
    pub scenario: PathBuf,
    /// IMU presets to compare (`imukit presets`), at least one.
    pub presets: Vec<String>,
    /// Monte Carlo runs per preset, 2 to [`MAX_RUNS`].
    pub runs: u64,
    /// Aid the filter with the scenario's `[odometer]` (which it must have).
    #[serde(default)]
    pub odometer: bool,
    /// Aid the filter with the scenario's `[baro]` (which it must have).
    #[serde(default)]
    pub baro: bool,
    /// The non-holonomic constraints of a ground vehicle, one-sigma m/s (off when absent).
    pub nhc_sigma_m_s: Option<f64>,
    /// The filter also estimates each IMU's scale-factor, misalignment and g-sensitivity errors
    /// (36 states; see [`FuseSetup::estimate_sensor_errors`]); absent: as `imukit fuse` does,
    /// when the part's figures warrant it.
    pub sensor_errors: Option<bool>,
    /// The vehicle stands still for the first this many seconds, and the filter is told so
    /// (see [`FuseSetup::rest_s`]); absent: as `imukit fuse` does, the rest found in the
    /// readings.
    pub rest_s: Option<f64>,
    /// Also smooth each run forward–backward ([`FuseSetup::smooth`]) and report the smoothed
    /// error beside the filter's.
    #[serde(default)]
    pub smooth: bool,
    /// Each run draws its own part of each preset's type (constant biases, scale factors,
    /// misalignment and g-sensitivity from normal distributions whose one-sigma are the
    /// preset's figures, see `scenario::perturb::drawn_part`): the study then speaks of the
    /// parts one may buy, not of one part. On by default; `false` simulates the preset's
    /// figures in every run (MATLAB's fixed parameters).
    #[serde(default = "drawn")]
    pub draw_parts: bool,
}

impl StudySpec {
    /// The fusion each run asks for, as `imukit fuse` would be asked (the start is each run's
    /// truth); smoothing is asked of each run apart ([`StudySpec::smooth`]).
    #[must_use]
    pub fn request(&self) -> FuseRequest<'static> {
        FuseRequest {
            nhc_sigma_m_s: self.nhc_sigma_m_s,
            sensor_errors: self.sensor_errors,
            rest_s: self.rest_s,
            ..FuseRequest::default()
        }
    }
}

fn drawn() -> bool {
    true
}

/// One preset, resolved.
#[derive(Clone, Debug)]
struct Case {
    preset: String,
    scenario: Scenario,
    setup: FuseSetup,
}

/// A study ready to run.
#[derive(Clone, Debug)]
pub struct Study {
    cases: Vec<Case>,
    runs: u64,
    smooth: bool,
    odometer: bool,
    baro: bool,
    outage: (f64, f64),
    scenario_path: PathBuf,
    input_files: Vec<(&'static str, PathBuf)>,
}

/// The errors of one run along the outage: one entry per IMU sample from the outage's start up
/// to (not including) its end, where the first fix after it is applied.
#[derive(Clone, Debug, PartialEq)]
pub struct OutageRun {
    /// Time since the outage began, s.
    pub t_s: Vec<f64>,
    /// Horizontal position error `|p̂ − p|` (the frame's two horizontal axes), m.
    pub horizontal_error_m: Vec<f64>,
    /// The filter's horizontal one-sigma `√(σ_x² + σ_y²)`, m.
    pub horizontal_sigma_m: Vec<f64>,
    /// The smoothed estimate's horizontal error at the same samples, m (empty when the study
    /// does not smooth).
    pub smoothed_error_m: Vec<f64>,
    /// Times the filter lost the fixes and was reset to them over the whole run
    /// ([`crate::run::fuse::FuseSummary::resets`]): its one-sigma then understates its error.
    pub resets: usize,
}

/// How one run ended.
#[derive(Clone, Debug, PartialEq)]
pub enum RunOutcome {
    /// The filter came through: its errors along the outage.
    Outage(OutageRun),
    /// The filter diverged (fixes rejected one after another, or its covariance broke down):
    /// the IMU's errors are beyond what the 15-state filter models. The message says where.
    Diverged(String),
}

/// One preset's result at the end of the outage.
#[derive(Clone, Debug, PartialEq)]
pub struct PresetSummary {
    /// The preset.
    pub preset: String,
    /// Runs whose filter came through (the RMS is over these).
    pub completed: usize,
    /// Runs whose filter diverged, and the first one's message.
    pub diverged: (usize, Option<String>),
    /// Completed runs whose filter was reset to the fixes, and the resets in all.
    pub resets: (usize, usize),
    /// RMS over completed runs of the horizontal error at the last IMU sample of the outage
    /// (before the first fix after it), m (`None` with fewer than two completed runs).
    pub rms_error_m: Option<f64>,
    /// RMS over completed runs of the filter's horizontal one-sigma there, m.
    pub sigma_m: Option<f64>,
    /// With smoothing: RMS over completed runs of the smoothed horizontal error at the same
    /// sample, and the largest such RMS along the outage (the smoothed error is largest inside
    /// it, not at its end), m.
    pub smoothed_rms_error_m: Option<(f64, f64)>,
    /// Time from the outage's start to that last sample, s.
    pub outage_s: f64,
}

impl Study {
    /// Reads a study file and resolves its scenario once per preset.
    ///
    /// # Errors
    /// An unreadable or invalid file (key named), an unknown preset, a scenario without
    /// `[gnss]` or without an outage, an outage outside the scenario's span.
    pub fn from_file(path: &Path) -> Result<Self> {
        let text = std::fs::read_to_string(path).map_err(|source| Error::Io {
            path: path.into(),
            source,
        })?;
        let origin = path.display().to_string();
        let spec: StudySpec = toml::from_str(&text).map_err(|e| Error::Scenario {
            origin: origin.clone(),
            message: e.to_string(),
        })?;
        let base = path.parent().unwrap_or_else(|| Path::new("."));
        Self::new(&spec, base, &origin)
    }

    /// Resolves `spec` (its scenario path relative to `base_dir`); `origin` names the study in
    /// errors.
    ///
    /// # Errors
    /// As [`Study::from_file`].
    pub fn new(spec: &StudySpec, base_dir: &Path, origin: &str) -> Result<Self> {
        let key = |k: &str| format!("{origin}: {k}");
        if let Some(c) = spec.nhc_sigma_m_s
            && !(c.is_finite() && c > 0.0)
        {
            return Err(invalid(
                key("nhc_sigma_m_s"),
                format!("must be a finite number > 0 (m/s), got {c}"),
            ));
        }
        if let Some(r) = spec.rest_s
            && !(r.is_finite() && r >= 0.0)
        {
            return Err(invalid(
                key("rest_s"),
                format!("must be a finite number ≥ 0 (s), got {r}"),
            ));
        }
        if spec.presets.is_empty() {
            return Err(invalid(key("presets"), "name at least one IMU preset"));
        }
        if !(2..=MAX_RUNS).contains(&spec.runs) {
            return Err(invalid(
                key("runs"),
                format!(
                    "must be 2 to {MAX_RUNS} (an RMS needs runs), got {}",
                    spec.runs
                ),
            ));
        }
        let scenario_path = base_dir.join(&spec.scenario);
        let scenario_spec = ScenarioSpec::from_file(&scenario_path)?;
        let scenario_dir = scenario_path.parent().unwrap_or(base_dir);
        let mut cases = Vec::with_capacity(spec.presets.len());
        for (i, preset) in spec.presets.iter().enumerate() {
            if spec.presets[..i].contains(preset) {
                return Err(invalid(
                    key(&format!("presets[{i}]")),
                    format!("{preset:?} is named twice"),
                ));
            }
            let mut s = scenario_spec.clone();
            s.imu.preset = Some(preset.clone());
            let mut scenario = s
                .resolve(scenario_dir)
                .map_err(|e| invalid(key(&format!("presets[{i}]")), e.to_string()))?;
            scenario.imu.sensors.draw_parts = spec.draw_parts;
            // The filter `imukit fuse` sets up for the same scenario and options.
            let setup = spec
                .request()
                .policy(FuseSetup::from_scenario(&scenario)?)?;
            cases.push(Case {
                preset: preset.clone(),
                scenario,
                setup,
            });
        }
        let first = &cases[0].scenario;
        let gnss = first.gnss.as_ref().ok_or_else(|| {
            invalid(
                key("scenario"),
                "its scenario has no [gnss] receiver: a study fuses the IMU with its fixes",
            )
        })?;
        let &(start, end) = gnss.outages.first().ok_or_else(|| {
            invalid(
                key("scenario"),
                "its [gnss] has no [[gnss.outages]]: the study measures the drift in the first one",
            )
        })?;
        let (t0, t1) = (
            first.t_s.at(0),
            first.t_s.at(first.t_s.len().saturating_sub(1)),
        );
        if !(start > t0 && end <= t1) {
            return Err(invalid(
                key("scenario"),
                format!(
                    "the first outage [{start}, {end}] s must start after the first fix and end \
                     within the scenario's span [{t0}, {t1}] s"
                ),
            ));
        }
        if spec.odometer && first.odometer.is_none() {
            return Err(invalid(
                key("odometer"),
                "its scenario has no [odometer] to aid the filter with",
            ));
        }
        if spec.baro && first.baro.is_none() {
            return Err(invalid(
                key("baro"),
                "its scenario has no [baro] to aid the filter with",
            ));
        }
        Ok(Self {
            cases,
            runs: spec.runs,
            smooth: spec.smooth,
            odometer: spec.odometer,
            baro: spec.baro,
            outage: (start, end),
            input_files: scenario_spec.input_files(scenario_dir),
            scenario_path,
        })
    }

    /// The scenario file the study runs.
    #[must_use]
    pub fn scenario_path(&self) -> &Path {
        &self.scenario_path
    }

    /// The files the scenario reads (for [`crate::io::output::check_outputs`]).
    #[must_use]
    pub fn input_files(&self) -> &[(&'static str, PathBuf)] {
        &self.input_files
    }

    /// Each preset's filter setup, in the study's order.
    pub fn setups(&self) -> impl Iterator<Item = (&str, &FuseSetup)> {
        self.cases.iter().map(|c| (c.preset.as_str(), &c.setup))
    }

    /// The presets, in the study's order.
    pub fn presets(&self) -> impl Iterator<Item = &str> {
        self.cases.iter().map(|c| c.preset.as_str())
    }

    /// The presets not described alike: for each error term (a turn-on bias, a bias drift —
    /// bias instability or random walk —, scale-factor and misalignment errors) of the
    /// accelerometer or gyroscope that some preset gives and others leave out, a line naming
    /// those that leave it out. A term left out counts as zero, so such parts are not compared
    /// on the same footing: the study says so before it runs.
    #[must_use]
    pub fn undescribed(&self) -> Vec<String> {
        type Given = fn(&crate::sensor::SensorParams) -> bool;
        let terms: [(&str, Given); 3] = [
            ("turn-on bias", |p| {
                p.constant_bias.iter().any(|&b| b != 0.0)
            }),
            ("bias drift (bias instability or random walk)", |p| {
                p.bias_instability
                    .iter()
                    .chain(&p.random_walk)
                    .any(|&b| b != 0.0)
            }),
            ("scale-factor and misalignment errors", |p| {
                p.axes_misalignment_pct.iter().enumerate().any(|(r, row)| {
                    row.iter()
                        .enumerate()
                        .any(|(c, &v)| v != if r == c { 100.0 } else { 0.0 })
                })
            }),
        ];
        let mut lines = Vec::new();
        for (sensor, pick) in [
            (
                "accelerometer",
                (|p| &p.accelerometer)
                    as fn(&crate::io::params::ImuParams) -> &crate::sensor::SensorParams,
            ),
            ("gyroscope", |p| &p.gyroscope),
        ] {
            for (term, given) in terms {
                let (with, without): (Vec<&Case>, Vec<&Case>) = self
                    .cases
                    .iter()
                    .partition(|c| given(pick(&c.scenario.imu.sensors.params)));
                if !with.is_empty() && !without.is_empty() {
                    let names = |cs: &[&Case]| {
                        cs.iter()
                            .map(|c| c.preset.as_str())
                            .collect::<Vec<_>>()
                            .join(", ")
                    };
                    lines.push(format!(
                        "{}: no {sensor} {term} (given by {}); taken as zero, it makes those \
                         parts look better than the others",
                        names(&without),
                        names(&with)
                    ));
                }
            }
        }
        lines
    }

    /// Runs per preset.
    #[must_use]
    pub fn runs(&self) -> u64 {
        self.runs
    }

    /// The first outage `(start, end)`, s.
    #[must_use]
    pub fn outage_s(&self) -> (f64, f64) {
        self.outage
    }

    /// Simulates run `run` of preset number `case` and fuses it; its errors along the outage,
    /// or the filter's divergence.
    ///
    /// # Errors
    /// The simulation's or the filter's refusal of its input, named with the preset and run.
    pub fn run_one(&self, case: usize, run: u64) -> Result<RunOutcome> {
        let c = self
            .cases
            .get(case)
            .ok_or_else(|| invalid("study", format!("no preset number {case}")))?;
        let named = |e: Error| invalid(format!("preset {}, run {run}", c.preset), e.to_string());
        let sim = c.scenario.simulate_run(run).map_err(named)?;
        let gnss = sim
            .gnss
            .as_ref()
            .ok_or_else(|| invalid("study", "the simulation wrote no GNSS fixes"))?;
        let initial = InitialState::from_table(&sim.truth)?;
        let aids = AidTables {
            odometer: sim.odometer.as_ref().filter(|_| self.odometer),
            baro: sim.baro.as_ref().filter(|_| self.baro),
        };
        // Smoothing, one pass gives the filter's table and the smoothed one.
        let fused = if self.smooth {
            fuse_filtered_and_smoothed(&sim.imu, gnss, aids, Start::State(&initial), &c.setup)
                .map(|(nav, smoothed, summary)| (nav, Some(smoothed), summary))
        } else {
            fuse_with(&sim.imu, gnss, aids, Start::State(&initial), &c.setup)
                .map(|(nav, summary)| (nav, None, summary))
        };
        let (nav, smoothed_nav, resets) = match fused {
            Ok((nav, smoothed, summary)) => (nav, smoothed, summary.resets),
            Err(Error::Diverged { context, message }) => {
                return Ok(RunOutcome::Diverged(format!(
                    "preset {}, run {run}: {context}: {message}",
                    c.preset
                )));
            }
            Err(e) => return Err(named(e)),
        };
        let col = |t: &Table, name: &str| {
            t.column(name)
                .ok_or_else(|| invalid("study", format!("no column {name}")))
        };
        let t = col(&nav, "t_s")?;
        let (px, py) = (col(&nav, "pos_x_m")?, col(&nav, "pos_y_m")?);
        let (tx, ty) = (col(&sim.truth, "pos_x_m")?, col(&sim.truth, "pos_y_m")?);
        let (sx, sy) = (col(&nav, "pos_x_sigma_m")?, col(&nav, "pos_y_sigma_m")?);
        let (start, end) = self.outage;
        let smoothed = match &smoothed_nav {
            Some(nav) => Some((col(nav, "pos_x_m")?, col(nav, "pos_y_m")?)),
            None => None,
        };
        let mut out = OutageRun {
            t_s: Vec::new(),
            horizontal_error_m: Vec::new(),
            horizontal_sigma_m: Vec::new(),
            smoothed_error_m: Vec::new(),
            resets,
        };
        // The row at the outage's end already holds the first fix after it: stop before it.
        for i in (0..t.len()).filter(|&i| t[i] >= start && t[i] < end) {
            out.t_s.push(t[i] - start);
            out.horizontal_error_m
                .push((px[i] - tx[i]).hypot(py[i] - ty[i]));
            out.horizontal_sigma_m.push(sx[i].hypot(sy[i]));
            if let Some((qx, qy)) = &smoothed {
                out.smoothed_error_m
                    .push((qx[i] - tx[i]).hypot(qy[i] - ty[i]));
            }
        }
        Ok(RunOutcome::Outage(out))
    }

    /// Every run of every preset, one after another (the CLI runs them on threads).
    ///
    /// # Errors
    /// As [`Study::run_one`].
    pub fn run_all(&self) -> Result<Vec<Vec<RunOutcome>>> {
        (0..self.cases.len())
            .map(|c| (0..self.runs).map(|r| self.run_one(c, r)).collect())
            .collect()
    }

    /// The study's table and per-preset summaries from `outcomes[case][run]`. Table columns:
    /// `t_s` (time since the outage began), then per preset with at least two completed runs
    /// `<preset>_rms_error_m` and `<preset>_sigma_m` (RMS over its completed runs), and with
    /// smoothing `<preset>_smoothed_rms_error_m`.
    ///
    /// # Errors
    /// Outcomes that do not match the study (presets, runs or samples), or no preset with two
    /// completed runs.
    pub fn summarise(&self, outcomes: &[Vec<RunOutcome>]) -> Result<(Table, Vec<PresetSummary>)> {
        let mismatch = || invalid("study", "the run results do not match the study");
        if outcomes.len() != self.cases.len()
            || outcomes.iter().any(|r| r.len() as u64 != self.runs)
        {
            return Err(mismatch());
        }
        let completed: Vec<Vec<&OutageRun>> = outcomes
            .iter()
            .map(|runs| {
                runs.iter()
                    .filter_map(|o| match o {
                        RunOutcome::Outage(r) => Some(r),
                        RunOutcome::Diverged(_) => None,
                    })
                    .collect()
            })
            .collect();
        let Some(t) = completed.iter().flatten().next().map(|r| r.t_s.clone()) else {
            return Err(invalid(
                "study",
                "the filter diverged in every run of every preset: nothing to report",
            ));
        };
        if t.is_empty() || completed.iter().flatten().any(|r| r.t_s != t) {
            return Err(mismatch());
        }
        let rms = |per_run: &[&OutageRun], k: usize, pick: fn(&OutageRun) -> &[f64]| {
            (per_run.iter().map(|r| pick(r)[k].powi(2)).sum::<f64>() / per_run.len() as f64).sqrt()
        };
        fn error(r: &OutageRun) -> &[f64] {
            &r.horizontal_error_m
        }
        fn sigma(r: &OutageRun) -> &[f64] {
            &r.horizontal_sigma_m
        }
        fn smoothed(r: &OutageRun) -> &[f64] {
            &r.smoothed_error_m
        }
        if self.smooth
            && completed
                .iter()
                .flatten()
                .any(|r| r.smoothed_error_m.len() != t.len())
        {
            return Err(mismatch());
        }
        let reported: Vec<usize> = (0..self.cases.len())
            .filter(|&c| completed[c].len() >= 2)
            .collect();
        if reported.is_empty() {
            return Err(invalid(
                "study",
                "no preset has two runs whose filter came through: nothing to report",
            ));
        }
        let mut names = vec!["t_s".to_string()];
        for &c in &reported {
            names.push(format!("{}_rms_error_m", self.cases[c].preset));
            names.push(format!("{}_sigma_m", self.cases[c].preset));
            if self.smooth {
                names.push(format!("{}_smoothed_rms_error_m", self.cases[c].preset));
            }
        }
        let name_refs: Vec<&str> = names.iter().map(String::as_str).collect();
        let mut table = Table::new(&name_refs);
        let mut row = Vec::with_capacity(names.len());
        for (k, &tk) in t.iter().enumerate() {
            row.clear();
            row.push(tk);
            for &c in &reported {
                row.push(rms(&completed[c], k, error));
                row.push(rms(&completed[c], k, sigma));
                if self.smooth {
                    row.push(rms(&completed[c], k, smoothed));
                }
            }
            table.push_row(&row);
        }
        table.check_finite("study")?;
        let last = t.len() - 1;
        let summaries = self
            .cases
            .iter()
            .enumerate()
            .map(|(c, case)| {
                let ok = completed[c].len() >= 2;
                let first_divergence = outcomes[c].iter().find_map(|o| match o {
                    RunOutcome::Diverged(m) => Some(m.clone()),
                    RunOutcome::Outage(_) => None,
                });
                PresetSummary {
                    preset: case.preset.clone(),
                    completed: completed[c].len(),
                    diverged: (outcomes[c].len() - completed[c].len(), first_divergence),
                    resets: (
                        completed[c].iter().filter(|r| r.resets > 0).count(),
                        completed[c].iter().map(|r| r.resets).sum(),
                    ),
                    rms_error_m: ok.then(|| rms(&completed[c], last, error)),
                    sigma_m: ok.then(|| rms(&completed[c], last, sigma)),
                    smoothed_rms_error_m: (ok && self.smooth).then(|| {
                        let worst = (0..=last)
                            .map(|k| rms(&completed[c], k, smoothed))
                            .fold(0.0, f64::max);
                        (rms(&completed[c], last, smoothed), worst)
                    }),
                    outage_s: t[last],
                }
            })
            .collect();
        Ok((table, summaries))
    }
}
