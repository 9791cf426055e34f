//! Kalibr's IMU noise file (`imu.yaml`): the four figures Kalibr's camera–IMU calibration takes
//! (and with it most visual–inertial estimators' settings), written from a parameter file.
//!
//! Kalibr's figures are continuous-time, single-sided: a white-noise density `σ_c` whose discrete
//! standard deviation is `σ_c·√f_s`, and a bias random walk `σ_b` whose step is `σ_b/√f_s`
//! (Kalibr wiki, "IMU Noise Model"). imukit's single-sided densities are the same figures; a
//! double-sided file's (MATLAB's convention, bandwidth `f_s/2`) are turned into them: `N/√2` and
//! `K·√2`. Kalibr takes one figure per sensor: the largest axis is written.
//!
//! Kalibr has no bias-instability term. When a part gives none of its bias drift as a random walk
//! but has a bias instability, the random walk written is the one that drift implies:
//! - flicker with its floor `0.664·B` up to `τ₂`: the random walk whose Allan deviation
//!   `K·√(τ/3)` reaches that floor at `τ₂`, `K = 0.664·B·√(3/τ₂)` (below the floor before `τ₂`, the
//!   drift beyond it);
//! - Gauss–Markov of steady deviation `B` and correlation time `T`: its driving noise,
//!   `K = B·√(2/T)` (the random walk it follows over times short against `T`).
//!
//! MATLAB's default bias-instability filter is short-memory noise (white under Allan analysis):
//! it implies no random walk. Every such choice is stated in the file's comments.
//!
//! **Reading** ([`read`]): a Kalibr file — flat, as Kalibr's `imu.yaml`, or one IMU of an
//! `imu0: {…}` chain — becomes a parameter file of those four figures, single-sided, on every
//! axis (`--imu kalibr.yaml`): white noise and bias random walk, no bias instability or other
//! error. YAML is parsed by the `yaml-rust2` crate as a stream of events: the file is read up
//! to 64 KiB, and anchors' aliases (which would let a small file expand without bound) are
//! refused.
use std::path::Path;

use imu_core::allan::BIAS_INSTABILITY_FACTOR;
use imu_core::sensor::{BiasInstabilityModel, FilterBuffer, NoiseType, SensorParams};

use crate::error::{Error, Result};

/// The longest Kalibr file read, bytes (Kalibr's own are a few hundred).
const MAX_YAML_BYTES: u64 = 64 * 1024;

/// A YAML node as the reader keeps it: scalars, and mappings of scalar keys; sequences are
/// kept only as such (Kalibr's transforms), not their items.
#[derive(Debug)]
enum Node {
    Scalar(String),
    Map(Vec<(String, Node)>),
    Seq,
}

/// A mapping being built: its entries so far and the key waiting for its value.
type OpenMap = (Vec<(String, Node)>, Option<String>);

/// Builds [`Node`]s from the parser's events with an explicit stack (no recursion, however
/// deep the file nests), noting an alias or a non-scalar key.
#[derive(Default)]
struct Tree {
    /// Open mappings (their entries so far and the key waiting for its value) and sequences.
    open: Vec<Option<OpenMap>>,
    root: Option<Node>,
    refused: Option<String>,
    /// The line of the event being taken (1-based).
    line: usize,
    /// YAML documents begun.
    documents: usize,
}

impl Tree {
    fn put(&mut self, node: Node) {
        match self.open.last_mut() {
            None => {
                if self.root.is_none() {
                    self.root = Some(node);
                }
            }
            Some(None) => {} // an item of a sequence: not kept
            Some(Some((entries, key))) => match key.take() {
                Some(k) => entries.push((k, node)),
                None => match node {
                    Node::Scalar(k) => {
                        if entries.iter().any(|(e, _)| *e == k) {
                            let line = self.line;
                            self.refused
                                .get_or_insert_with(|| format!("line {line}: key {k} given twice"));
                        }
                        *key = Some(k);
                    }
                    _ => {
                        self.refused
                            .get_or_insert_with(|| "a key that is not a plain name".into());
                        *key = Some(String::new());
                    }
                },
            },
        }
    }
}

impl yaml_rust2::parser::MarkedEventReceiver for Tree {
    fn on_event(&mut self, ev: yaml_rust2::Event, mark: yaml_rust2::scanner::Marker) {
        use yaml_rust2::Event;
        self.line = mark.line();
        match ev {
            Event::DocumentStart => {
                self.documents += 1;
                if self.documents > 1 {
                    self.refused.get_or_insert_with(|| {
                        format!(
                            "line {}: a second YAML document (---): a Kalibr file is one",
                            mark.line()
                        )
                    });
                }
            }
            Event::Scalar(text, ..) => self.put(Node::Scalar(text)),
            Event::MappingStart(..) => self.open.push(Some((Vec::new(), None))),
            Event::SequenceStart(..) => self.open.push(None),
            Event::MappingEnd | Event::SequenceEnd => {
                if let Some(open) = self.open.pop() {
                    self.put(open.map_or(Node::Seq, |(entries, _)| Node::Map(entries)));
                }
            }
            Event::Alias(_) => {
                self.refused.get_or_insert_with(|| {
                    format!("line {}: an alias (*name): not read", mark.line())
                });
                self.put(Node::Seq);
            }
            _ => {}
        }
    }
}

/// Kalibr's four figures' keys, with the sensor and quantity each sets.
const KALIBR_KEYS: [&str; 4] = [
    "accelerometer_noise_density",
    "accelerometer_random_walk",
    "gyroscope_noise_density",
    "gyroscope_random_walk",
];

/// Reads a Kalibr IMU file (see the module documentation).
///
/// # Errors
/// An unreadable or oversized file, YAML the parser refuses (with its line), an alias, a
/// missing figure or one that is not a finite non-negative number — each naming the file and
/// the key.
pub fn read(path: &Path) -> Result<KalibrImu> {
    let (file, length) = crate::open_with_length(path)?;
    let origin = path.display().to_string();
    let bad = |message: String| Error::Scenario {
        origin: origin.clone(),
        message,
    };
    if length > MAX_YAML_BYTES {
        return Err(bad(format!(
            "{length} bytes: a Kalibr IMU file is a few lines (read up to {MAX_YAML_BYTES} bytes)"
        )));
    }
    let mut text = String::new();
    std::io::Read::read_to_string(&mut std::io::Read::take(file, MAX_YAML_BYTES), &mut text)
        .map_err(|source| Error::Io {
            path: path.into(),
            source,
        })?;
    let mut tree = Tree::default();
    yaml_rust2::parser::Parser::new_from_str(&text)
        .load(&mut tree, true)
        .map_err(|e| bad(format!("not YAML: {e}")))?;
    if let Some(r) = tree.refused {
        return Err(bad(r));
    }
    let Some(Node::Map(top)) = tree.root else {
        return Err(bad(
            "expected a mapping of Kalibr's keys (accelerometer_noise_density: …)".into(),
        ));
    };
    // Flat, or the one IMU of a chain (`imu0: {…}`).
    let has_keys = |m: &[(String, Node)]| m.iter().any(|(k, _)| KALIBR_KEYS.contains(&k.as_str()));
    let entries: &[(String, Node)] = if has_keys(&top) {
        &top
    } else {
        let imus: Vec<(&String, &Vec<(String, Node)>)> = top
            .iter()
            .filter_map(|(k, v)| match v {
                Node::Map(m) if has_keys(m) => Some((k, m)),
                _ => None,
            })
            .collect();
        match imus.as_slice() {
            [(_, m)] => m,
            [] => {
                return Err(bad(format!(
                    "none of Kalibr's keys ({})",
                    KALIBR_KEYS.join(", ")
                )));
            }
            several => {
                let names: Vec<&str> = several.iter().map(|(k, _)| k.as_str()).collect();
                return Err(bad(format!(
                    "several IMUs ({}): give a file of one",
                    names.join(", ")
                )));
            }
        }
    };
    let scalar = |key: &str| {
        entries.iter().find_map(|(k, v)| match v {
            Node::Scalar(s) if k == key => Some(s.as_str()),
            _ => None,
        })
    };
    let figure = |key: &str| -> Result<f64> {
        let text = scalar(key).ok_or_else(|| bad(format!("key {key}: missing")))?;
        match text.trim().parse::<f64>() {
            Ok(x) if x.is_finite() && x >= 0.0 => Ok(x),
            _ => Err(bad(format!(
                "key {key}: \"{text}\" is not a finite non-negative number"
            ))),
        }
    };
    let sensor = |n: &str, k: &str| -> Result<KalibrSensor> {
        Ok(KalibrSensor {
            noise_density: figure(n)?,
            random_walk: figure(k)?,
            notes: Vec::new(),
        })
    };
    let update_rate_hz = match scalar("update_rate") {
        Some(_) => figure("update_rate")?,
        None => DEFAULT_RATE_HZ,
    };
    Ok(KalibrImu {
        accelerometer: sensor(KALIBR_KEYS[0], KALIBR_KEYS[1])?,
        gyroscope: sensor(KALIBR_KEYS[2], KALIBR_KEYS[3])?,
        update_rate_hz,
        rostopic: scalar("rostopic").unwrap_or(DEFAULT_TOPIC).to_string(),
        name: Some(format!("Kalibr IMU file {}", path.display())),
    })
}

/// The topic written when none is given: imukit's IMU topic in a ROS bag.
pub const DEFAULT_TOPIC: &str = "/imu";

/// The factor on the densities written when none is given: the identified figures as they are.
pub const DEFAULT_INFLATION: f64 = 1.0;

/// The rate written when none is given, Hz (Kalibr's own example file's); the rate is the
/// logger's, so a user sets it.
pub const DEFAULT_RATE_HZ: f64 = 200.0;

/// Kalibr's figures for one sensor (SI units) and what was done to reach them.
#[derive(Clone, Debug, PartialEq)]
pub struct KalibrSensor {
    /// White-noise density, unit/√Hz (`unit` = rad/s or m/s²).
    pub noise_density: f64,
    /// Bias random walk, unit·√Hz.
    pub random_walk: f64,
    /// How the figures were reached, for the file's comments.
    pub notes: Vec<String>,
}

/// The contents of a Kalibr `imu.yaml`.
#[derive(Clone, Debug, PartialEq)]
pub struct KalibrImu {
    /// The accelerometer's figures (m/s²/√Hz, m/s³/√Hz).
    pub accelerometer: KalibrSensor,
    /// The gyroscope's figures (rad/s/√Hz, rad/s²/√Hz).
    pub gyroscope: KalibrSensor,
    /// The IMU's rate, Hz.
    pub update_rate_hz: f64,
    /// The IMU's topic.
    pub rostopic: String,
    /// The part's name, where the file has one.
    pub name: Option<String>,
}

/// `x` as a YAML 1.1 float (what PyYAML, which Kalibr reads with, takes for one: a point in the
/// mantissa, a sign in the exponent), seven significant digits.
fn yaml_float(x: f64) -> String {
    if x == 0.0 {
        return "0.0".to_owned();
    }
    let text = format!("{x:.6e}");
    match text.split_once('e') {
        Some((mantissa, exponent)) if !exponent.starts_with('-') => {
            format!("{mantissa}e+{exponent}")
        }
        _ => text,
    }
}

fn largest(v: [f64; 3]) -> f64 {
    v.into_iter().fold(0.0, f64::max)
}

pub(crate) fn sensor<B: FilterBuffer>(p: &SensorParams<B>, unit: &str) -> KalibrSensor {
    let mut notes = Vec::new();
    let (n, k) = (largest(p.noise_density), largest(p.random_walk));
    if p.noise_density.iter().any(|&x| x != n) || p.random_walk.iter().any(|&x| x != k) {
        notes.push("the axes differ: the largest axis is written".to_owned());
    }
    // The same discrete noise over the whole rate: N·√(share·fs) = σ_c·√fs, K/√(share·fs) = σ_b/√fs.
    let root_share = p.noise_type.bandwidth_share().sqrt();
    let (noise_density, mut random_walk) = (n * root_share, k / root_share);
    if p.noise_type == NoiseType::DoubleSided {
        notes.push("double-sided densities turned single-sided (N/√2, K·√2)".to_owned());
    }
    let b = largest(p.bias_instability);
    if random_walk == 0.0 && b > 0.0 {
        match &p.bias_instability_model {
            BiasInstabilityModel::Flicker { tau_max_s, .. } => {
                random_walk = BIAS_INSTABILITY_FACTOR * b * (3.0 / tau_max_s).sqrt();
                notes.push(format!(
                    "random walk from the bias instability B = {b:.6e} {unit} (flicker floor \
                     0.664·B up to τ₂ = {tau_max_s} s): K = 0.664·B·√(3/τ₂)"
                ));
            }
            BiasInstabilityModel::GaussMarkov { correlation_time_s } => {
                random_walk = b * (2.0 / correlation_time_s).sqrt();
                notes.push(format!(
                    "random walk from the Gauss–Markov bias instability B = {b:.6e} {unit}, \
                     T = {correlation_time_s} s: K = B·√(2/T)"
                ));
            }
            BiasInstabilityModel::Filter(_) => notes.push(
                "the bias instability's MATLAB filter is short-memory noise: no random walk \
                 follows from it"
                    .to_owned(),
            ),
        }
    }
    if random_walk == 0.0 {
        notes.push(
            "random walk 0: the part gives no bias drift, and Kalibr and most estimators need a \
             positive value: set one"
                .to_owned(),
        );
    }
    KalibrSensor {
        noise_density,
        random_walk,
        notes,
    }
}

impl KalibrImu {
    /// The figures as an imukit parameter file (TOML): single-sided noise density and bias
    /// random walk on every axis of both sensors, nothing else.
    #[must_use]
    pub fn to_params_toml(&self) -> String {
        let name = self.name.as_deref().unwrap_or("Kalibr IMU file");
        let quoted = |s: &str| serde_json::Value::String(s.to_string()).to_string();
        format!(
            "name = {}
source = {}

[accelerometer]
noise_density_m_s2_per_rt_hz = {:e}
             random_walk_m_s2_rt_hz = {:e}
noise_type = \"single-sided\"

[gyroscope]
             noise_density_rad_s_per_rt_hz = {:e}
random_walk_rad_s_rt_hz = {:e}
             noise_type = \"single-sided\"
",
            quoted(name),
            quoted("Kalibr's continuous-time white noise and bias random walk"),
            self.accelerometer.noise_density,
            self.accelerometer.random_walk,
            self.gyroscope.noise_density,
            self.gyroscope.random_walk,
        )
    }

    /// The file's text (YAML, comments stating the units and every choice made).
    #[must_use]
    pub fn to_yaml(&self) -> String {
        let mut s = String::from("# Kalibr IMU noise model (imu.yaml), written by imukit");
        if let Some(name) = &self.name {
            // A comment ends at the line's end: a name's own line breaks are not written.
            s += &format!(" from {}", name.replace(['\n', '\r'], " "));
        }
        s += "\n# continuous-time, single-sided figures: discrete σ = density·√rate, bias step = \
              random walk/√rate\n";
        for (sensor, what) in [
            (&self.accelerometer, "accelerometer"),
            (&self.gyroscope, "gyroscope"),
        ] {
            for note in &sensor.notes {
                s += &format!("# {what}: {note}\n");
            }
        }
        let num = yaml_float;
        // Quoted (a JSON string is a YAML double-quoted scalar): a topic with `: `, `#` or a
        // line break stays one value.
        s += &format!(
            "rostopic: {}\n",
            serde_json::Value::String(self.rostopic.clone())
        );
        s += &format!(
            "update_rate: {}  # Hz: the logger's rate (imukit presets … --rate-hz)\n",
            if self.update_rate_hz.fract() == 0.0 && self.update_rate_hz < 1e9 {
                format!("{:.1}", self.update_rate_hz)
            } else {
                yaml_float(self.update_rate_hz)
            }
        );
        s += &format!(
            "accelerometer_noise_density: {}  # m/s^2/sqrt(Hz)\n",
            num(self.accelerometer.noise_density)
        );
        s += &format!(
            "accelerometer_random_walk: {}  # m/s^3/sqrt(Hz)\n",
            num(self.accelerometer.random_walk)
        );
        s += &format!(
            "gyroscope_noise_density: {}  # rad/s/sqrt(Hz)\n",
            num(self.gyroscope.noise_density)
        );
        s += &format!(
            "gyroscope_random_walk: {}  # rad/s^2/sqrt(Hz)\n",
            num(self.gyroscope.random_walk)
        );
        s
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn write(dir: &tempfile::TempDir, name: &str, text: &str) -> std::path::PathBuf {
        let path = dir.path().join(name);
        std::fs::write(&path, text).expect("written");
        path
    }

    #[test]
    fn one_imu_of_a_chain_is_read_and_bad_files_are_refused_by_key() {
        let dir = tempfile::tempdir().expect("dir");
        let figures = "accelerometer_noise_density: 1.86e-03\naccelerometer_random_walk: 4.33e-04\n\
                       gyroscope_noise_density: 1.87e-04\ngyroscope_random_walk: 2.66e-05\n";
        let nested: String = figures.lines().map(|l| format!("  {l}\n")).collect();
        let chain =
            format!("imu0:\n  T_i_b:\n  - [1.0, 0.0]\n  - [0.0, 1.0]\n{nested}  rostopic: /imu0\n");
        let imu = read(&write(&dir, "chain.yaml", &chain)).expect("one IMU of a chain");
        assert_eq!(imu.gyroscope.random_walk, 2.66e-5);
        assert_eq!(imu.rostopic, "/imu0");
        let cases = [
            (
                "missing.yaml",
                figures.replace("gyroscope_random_walk: 2.66e-05\n", ""),
                "key gyroscope_random_walk: missing",
            ),
            (
                "negative.yaml",
                figures.replace("1.87e-04", "-1"),
                "key gyroscope_noise_density: \"-1\"",
            ),
            (
                "alias.yaml",
                format!("a: &x 1\n{}", figures.replace("4.33e-04", "*x")),
                "an alias",
            ),
            (
                "two.yaml",
                format!("imu0:\n{nested}imu1:\n{nested}"),
                "several IMUs (imu0, imu1)",
            ),
            ("list.yaml", "- 1\n- 2\n".to_string(), "expected a mapping"),
            ("broken.yaml", "a: [1, 2\n".to_string(), "not YAML"),
        ];
        for (name, text, want) in cases {
            let path = write(&dir, name, &text);
            let e = read(&path).unwrap_err().to_string();
            assert!(e.contains(name) && e.contains(want), "{name}: {e}");
        }
        let big = write(&dir, "big.yaml", &"#".repeat(70_000));
        assert!(read(&big).unwrap_err().to_string().contains("70000 bytes"));
    }
}
