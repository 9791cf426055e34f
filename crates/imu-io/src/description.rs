//! What a table holds, carried in the table itself: its kind, the navigation frame and the body
//! frame that goes with it, the Earth, its origin and gravity, the accelerometer sign, the
//! sensor and the scenario that made it.
//!
//! Parquet keeps it in the file's key-value metadata, one key per entry (`imukit.kind`,
//! `imukit.nav_frame`, …; pyarrow, pandas and polars show them). CSV keeps it in the file's
//! first line, `# imukit: {"kind": "readings", "nav_frame": "NED", …}`: a comment to imukit's
//! readers, to pandas (`comment="#"`) and to NumPy (`np.loadtxt`, `np.genfromtxt`), and one JSON
//! object to anyone who wants to read it. The binary NumPy formats have no room for it.
//!
//! Readers take an entry as the default of the option it covers and refuse an option that
//! contradicts it, naming both ([`crate::described::Described::pick`]); a table without a description keeps the
//! options' own defaults. Entries that a later version adds are ignored by this one.
use std::io::{BufRead, BufReader, Read};
use std::path::Path;

use crate::choice::Choice;
use crate::conventions::{AccelSignName, EarthGravityName, EarthName, NavFrameName};
use crate::error::{Error, Result};
use crate::schema::TableKind;

/// The prefix of every entry's key in Parquet metadata.
pub const KEY_PREFIX: &str = "imukit.";

/// How a CSV file's description line starts.
pub const CSV_PREFIX: &str = "# imukit: ";

/// The longest description line a CSV reader looks at, bytes (a scenario is a few kilobytes).
const MAX_CSV_LINE: u64 = 1 << 20;

/// A geodetic origin: where a tangent-plane table's axes start.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Origin {
    /// Latitude, degrees.
    pub latitude_deg: f64,
    /// Longitude, degrees.
    pub longitude_deg: f64,
    /// Height above the WGS-84 ellipsoid, m.
    pub height_m: f64,
}

impl core::fmt::Display for Origin {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        write!(
            f,
            "an origin at {}°, {}°, {} m",
            self.latitude_deg, self.longitude_deg, self.height_m
        )
    }
}

/// How a WGS-84 table's gravity is described: the model's name, and its magnitude when it is a
/// constant.
#[must_use]
pub fn wgs84_gravity(model: imu_core::earth::GravityModel) -> (EarthGravityName, Option<f64>) {
    match model {
        imu_core::earth::GravityModel::Normal => (EarthGravityName::Normal, None),
        imu_core::earth::GravityModel::Constant(g) => (EarthGravityName::Constant, Some(g)),
    }
}

/// What a table holds; every entry optional (absent: not known, the reader's default applies).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Description {
    /// The kind of table.
    pub kind: Option<TableKind>,
    /// The navigation frame (the body frame follows it: FLU under ENU, FRD under NED).
    pub nav_frame: Option<NavFrameName>,
    /// The Earth.
    pub earth: Option<EarthName>,
    /// The tangent plane's origin on the WGS-84 Earth.
    pub origin: Option<Origin>,
    /// Gravity's magnitude on the flat Earth (or the constant of `earth_gravity = constant`),
    /// m/s².
    pub gravity_m_s2: Option<f64>,
    /// Gravity on the WGS-84 Earth.
    pub earth_gravity: Option<EarthGravityName>,
    /// The sign of the accelerometer columns.
    pub accel_sign: Option<AccelSignName>,
    /// The sensor: a preset's name, or what the scenario's `[imu]` says.
    pub sensor: Option<String>,
    /// The scenario file's text, when one made the table.
    pub scenario: Option<String>,
}

/// An entry's value as written: a name or text, or a number.
#[derive(Clone, Debug, PartialEq)]
pub enum Value {
    /// A name or a text.
    Text(String),
    /// A number.
    Number(f64),
}

impl Value {
    fn text(&self) -> String {
        match self {
            Self::Text(s) => s.clone(),
            Self::Number(x) => format!("{x}"),
        }
    }
}

/// The body frame that goes with a navigation frame.
fn body_frame(nav: NavFrameName) -> &'static str {
    match nav {
        NavFrameName::ENU => "FLU",
        NavFrameName::NED => "FRD",
    }
}

impl Description {
    /// The first setting (frame, Earth, origin, gravity, accelerometer sign) that `self` and
    /// `other` both state and state differently, as `nav_frame NED, not ENU`; `None` when they
    /// agree on every setting both state. The kind, sensor and scenario text are not settings.
    #[must_use]
    pub fn contradiction(&self, other: &Self) -> Option<String> {
        fn differ<T: PartialEq + core::fmt::Debug>(
            name: &str,
            a: Option<&T>,
            b: Option<&T>,
            show: impl Fn(&T) -> String,
        ) -> Option<String> {
            match (a, b) {
                (Some(a), Some(b)) if a != b => {
                    Some(format!("{name} {}, not {}", show(b), show(a)))
                }
                _ => None,
            }
        }
        differ(
            "nav_frame",
            self.nav_frame.as_ref(),
            other.nav_frame.as_ref(),
            ToString::to_string,
        )
        .or_else(|| {
            differ(
                "earth",
                self.earth.as_ref(),
                other.earth.as_ref(),
                ToString::to_string,
            )
        })
        .or_else(|| {
            differ(
                "accel_sign",
                self.accel_sign.as_ref(),
                other.accel_sign.as_ref(),
                ToString::to_string,
            )
        })
        .or_else(|| {
            differ(
                "gravity_m_s2",
                self.gravity_m_s2.as_ref(),
                other.gravity_m_s2.as_ref(),
                ToString::to_string,
            )
        })
        .or_else(|| {
            differ(
                "earth_gravity",
                self.earth_gravity.as_ref(),
                other.earth_gravity.as_ref(),
                ToString::to_string,
            )
        })
        .or_else(|| {
            differ("origin", self.origin.as_ref(), other.origin.as_ref(), |o| {
                format!("{}° {}° {} m", o.latitude_deg, o.longitude_deg, o.height_m)
            })
        })
    }

    /// A description of a table of `kind` and nothing else.
    #[must_use]
    pub fn of_kind(kind: TableKind) -> Self {
        Self {
            kind: Some(kind),
            ..Self::default()
        }
    }

    /// A description of a table with `columns` by its kind alone, as
    /// [`TableKind::detect`] finds it (empty for a table of no kind imukit knows).
    #[must_use]
    pub fn of_columns<S: AsRef<str>>(columns: &[S]) -> Self {
        Self {
            kind: TableKind::detect(columns),
            ..Self::default()
        }
    }

    /// What a navigation estimate of `kind` holds: its frame, its Earth (`earth_gravity`:
    /// `None` for the flat one, else the WGS-84 gravity model) and the flat Earth's gravity
    /// `gravity_m_s2`.
    #[must_use]
    pub fn of_navigation(
        kind: TableKind,
        nav_frame: NavFrameName,
        earth_gravity: Option<imu_core::earth::GravityModel>,
        gravity_m_s2: f64,
    ) -> Self {
        let (earth, earth_gravity, gravity_m_s2) = match earth_gravity {
            None => (EarthName::Flat, None, Some(gravity_m_s2)),
            Some(model) => {
                let (gravity, g) = wgs84_gravity(model);
                (EarthName::Wgs84, Some(gravity), g)
            }
        };
        Self {
            nav_frame: Some(nav_frame),
            earth: Some(earth),
            earth_gravity,
            gravity_m_s2,
            ..Self::of_kind(kind)
        }
    }

    /// The same description for a table of another kind.
    #[must_use]
    pub fn with_kind(&self, kind: TableKind) -> Self {
        Self {
            kind: Some(kind),
            ..self.clone()
        }
    }

    /// Whether it says nothing.
    #[must_use]
    pub fn is_empty(&self) -> bool {
        *self == Self::default()
    }

    /// The entries, in a fixed order, keys without [`KEY_PREFIX`] (what the CSV line holds).
    #[must_use]
    pub fn entries(&self) -> Vec<(&'static str, Value)> {
        let mut out = Vec::new();
        let name = |c: &dyn Fn() -> &'static str| Value::Text(c().to_string());
        if let Some(k) = self.kind {
            out.push(("kind", name(&|| k.name())));
        }
        if let Some(n) = self.nav_frame {
            out.push(("nav_frame", name(&|| n.name())));
            out.push(("body_frame", name(&|| body_frame(n))));
        }
        if let Some(e) = self.earth {
            out.push(("earth", name(&|| e.name())));
        }
        if let Some(o) = self.origin {
            out.push(("origin_latitude_deg", Value::Number(o.latitude_deg)));
            out.push(("origin_longitude_deg", Value::Number(o.longitude_deg)));
            out.push(("origin_height_m", Value::Number(o.height_m)));
        }
        if let Some(g) = self.gravity_m_s2 {
            out.push(("gravity_m_s2", Value::Number(g)));
        }
        if let Some(g) = self.earth_gravity {
            out.push(("earth_gravity", name(&|| g.name())));
        }
        if let Some(s) = self.accel_sign {
            out.push(("accel_sign", name(&|| s.name())));
        }
        if let Some(s) = &self.sensor {
            out.push(("sensor", Value::Text(s.clone())));
        }
        if let Some(s) = &self.scenario {
            out.push(("scenario", Value::Text(s.clone())));
        }
        out.push((
            "software",
            Value::Text(format!("imukit {}", env!("CARGO_PKG_VERSION"))),
        ));
        out
    }

    /// The entries as Parquet key-value metadata (keys with [`KEY_PREFIX`]; nothing when the
    /// description is empty).
    #[must_use]
    pub fn metadata(&self) -> Vec<(String, String)> {
        if self.is_empty() {
            return Vec::new();
        }
        self.entries()
            .into_iter()
            .map(|(k, v)| (format!("{KEY_PREFIX}{k}"), v.text()))
            .collect()
    }

    /// The CSV description line, `# imukit: {…}` without its line end (`None` when the
    /// description is empty).
    #[must_use]
    pub fn csv_line(&self) -> Option<String> {
        if self.is_empty() {
            return None;
        }
        // Written entry by entry, so that the line keeps the entries' order (kind first).
        let json = |s: &str| serde_json::Value::String(s.to_string()).to_string();
        let body: Vec<String> = self
            .entries()
            .into_iter()
            .map(|(k, v)| {
                let v = match v {
                    Value::Text(s) => json(&s),
                    Value::Number(x) => serde_json::Number::from_f64(x)
                        .map_or_else(|| "null".to_string(), |n| n.to_string()),
                };
                format!("{}: {v}", json(k))
            })
            .collect();
        Some(format!("{CSV_PREFIX}{{{}}}", body.join(", ")))
    }

    /// A description from its entries (keys without the prefix), each value checked; `place`
    /// names where they were read (the file and where in it).
    pub fn from_entries<'a>(
        entries: impl IntoIterator<Item = (&'a str, Value)>,
        place: &str,
    ) -> Result<Self> {
        let mut d = Self::default();
        let mut body: Option<String> = None;
        let (mut lat, mut lon, mut height) = (None, None, None);
        for (key, value) in entries {
            let field = format!("{place}: key {key}");
            let text = || match &value {
                Value::Text(s) => Ok(s.clone()),
                Value::Number(_) => Err(Error::Invalid {
                    field: field.clone().into(),
                    message: "expected a name, got a number".into(),
                }),
            };
            let number = || {
                match &value {
                    Value::Number(x) => Ok(*x),
                    Value::Text(s) => s.trim().parse::<f64>().map_err(|_| Error::Invalid {
                        field: field.clone().into(),
                        message: format!("expected a number, got {s:?}"),
                    }),
                }
                .and_then(|x| {
                    if x.is_finite() {
                        Ok(x)
                    } else {
                        Err(Error::Invalid {
                            field: field.clone().into(),
                            message: format!("expected a finite number, got {x}"),
                        })
                    }
                })
            };
            match key {
                "kind" => d.kind = Some(TableKind::parse(&field, &text()?)?),
                "nav_frame" => d.nav_frame = Some(NavFrameName::parse(&field, &text()?)?),
                "body_frame" => body = Some(text()?),
                "earth" => d.earth = Some(EarthName::parse(&field, &text()?)?),
                "origin_latitude_deg" => lat = Some(number()?),
                "origin_longitude_deg" => lon = Some(number()?),
                "origin_height_m" => height = Some(number()?),
                "gravity_m_s2" => d.gravity_m_s2 = Some(number()?),
                "earth_gravity" => {
                    d.earth_gravity = Some(EarthGravityName::parse(&field, &text()?)?);
                }
                "accel_sign" => d.accel_sign = Some(AccelSignName::parse(&field, &text()?)?),
                "sensor" => d.sensor = Some(text()?),
                "scenario" => d.scenario = Some(text()?),
                _ => {}
            }
        }
        if let (Some(b), Some(n)) = (&body, d.nav_frame)
            && !b.eq_ignore_ascii_case(body_frame(n))
        {
            return Err(Error::Invalid {
                field: format!("{place}: key body_frame").into(),
                message: format!(
                    "{b} does not go with the navigation frame {} (its body frame is {})",
                    n.name(),
                    body_frame(n)
                ),
            });
        }
        d.origin = match (lat, lon, height) {
            (Some(latitude_deg), Some(longitude_deg), Some(height_m)) => Some(Origin {
                latitude_deg,
                longitude_deg,
                height_m,
            }),
            (None, None, None) => None,
            _ => {
                return Err(Error::Invalid {
                    field: format!("{place}: key origin_latitude_deg").into(),
                    message: "the origin needs its latitude, longitude and height together".into(),
                });
            }
        };
        Ok(d)
    }

    /// The description on a CSV file's first line (`None`: it has none).
    pub(crate) fn read_csv(path: &Path) -> Result<Option<Self>> {
        let io = |source| Error::Io {
            path: path.into(),
            source,
        };
        let file = std::fs::File::open(path).map_err(io)?;
        let mut line = Vec::new();
        BufReader::new(file.take(MAX_CSV_LINE))
            .read_until(b'\n', &mut line)
            .map_err(io)?;
        let place = format!("{}, line 1", path.display());
        let Some(rest) = line.strip_prefix(CSV_PREFIX.as_bytes()) else {
            return Ok(None);
        };
        if line.last() != Some(&b'\n') && line.len() as u64 >= MAX_CSV_LINE {
            return Err(Error::CsvFormat {
                file: path.into(),
                message: format!(
                    "line 1: the imukit description is longer than {MAX_CSV_LINE} bytes"
                ),
            });
        }
        let json: serde_json::Value =
            serde_json::from_slice(rest).map_err(|e| Error::CsvFormat {
                file: path.into(),
                message: format!("line 1: the imukit description is not valid JSON: {e}"),
            })?;
        let serde_json::Value::Object(map) = json else {
            return Err(Error::CsvFormat {
                file: path.into(),
                message: "line 1: the imukit description is not a JSON object".into(),
            });
        };
        // A value of another JSON type is kept as its JSON text: ignored under a key this
        // version does not know, refused by name under one it does.
        let entries = map.iter().map(|(k, v)| {
            let value = match v {
                serde_json::Value::String(s) => Value::Text(s.clone()),
                serde_json::Value::Number(n) => Value::Number(n.as_f64().unwrap_or(f64::NAN)),
                other => Value::Text(other.to_string()),
            };
            (k.as_str(), value)
        });
        Self::from_entries(entries, &place).map(Some)
    }
}
