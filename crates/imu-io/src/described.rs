//! The descriptions of a job's inputs taken together ([`Described`]): each setting the user
//! left out is what the files say, a contradiction between them, or with the user, refused; and
//! a description that names another kind of table than its file's columns is refused.
use std::path::Path;

use crate::TableFormat;
use crate::description::{Description, KEY_PREFIX, Origin, Value};
use crate::error::{Error, RequestOption, Result, refused};
use crate::schema::TableKind;

impl Description {
    /// The description of the table file at `path` in the format its extension names: Parquet
    /// metadata, a CSV file's first line; `None` when it has none (or the format has no room).
    ///
    /// # Errors
    /// An unreadable file; a description that is not what imukit writes (bad JSON, an unknown
    /// name, a number that is not finite), naming the file and the key.
    pub fn read(path: &Path) -> Result<Option<Self>> {
        match TableFormat::of(path) {
            TableFormat::Parquet => {
                let metadata = crate::parquet::read_metadata(path)?;
                let entries: Vec<(&str, Value)> = metadata
                    .iter()
                    .filter_map(|(k, v)| {
                        k.strip_prefix(KEY_PREFIX)
                            .map(|k| (k, Value::Text(v.clone())))
                    })
                    .collect();
                if entries.is_empty() {
                    return Ok(None);
                }
                let place = format!("{}, metadata", path.display());
                Self::from_entries(entries, &place).map(Some)
            }
            TableFormat::Npy | TableFormat::Npz | TableFormat::Nmea => Ok(None),
            TableFormat::Mcap => crate::bag::description(path),
            TableFormat::Csv => Self::read_csv(path),
        }
    }
}

/// Refuses a file whose description names a kind of table its columns are not (a description
/// copied onto other data, or edited by hand): its settings would then be taken for data they
/// do not describe. A file whose header cannot be read is left to its reader.
fn check_kind(path: &Path, d: &Description) -> Result<()> {
    let Some(said) = d.kind else {
        return Ok(());
    };
    let Ok(header) = crate::read::read_header(path) else {
        return Ok(());
    };
    let Some(found) = TableKind::detect(&header) else {
        return Ok(());
    };
    let alike = |a: TableKind, b: TableKind| {
        use TableKind::{Fused, Navigation, PlanarReadings, Readings};
        a == b || matches!((a, b), (Navigation, Fused) | (Readings, PlanarReadings))
    };
    if alike(said, found) || alike(found, said) {
        return Ok(());
    }
    Err(Error::CsvFormat {
        file: path.into(),
        message: format!(
            "its description says it holds {said} but its columns are those of {found}: the \
             description belongs to other data (remove the `# imukit:` line, or write the table \
             again)"
        ),
    })
}

/// The descriptions of a job's input files, which together fix the settings they give: each
/// setting is what the user asked for, else what the files say, else the library's default.
#[derive(Clone, Debug, Default)]
pub struct Described {
    /// Each input's name as messages give it (a file's path, "the imu table") and its
    /// description.
    files: Vec<(String, Description)>,
}

impl Described {
    /// The descriptions of `paths` (a file without one adds nothing).
    ///
    /// # Errors
    /// As [`Description::read`].
    pub fn read(paths: &[&Path]) -> Result<Self> {
        let mut files = Vec::new();
        for p in paths {
            if let Some(d) = Description::read(p)? {
                check_kind(p, &d)?;
                files.push((p.display().to_string(), d));
            }
        }
        Ok(Self { files })
    }

    /// The descriptions of inputs held in memory (Python's tables), each with the name
    /// messages give it (`"the imu table"`); an empty description adds nothing.
    #[must_use]
    pub fn of(named: impl IntoIterator<Item = (String, Description)>) -> Self {
        Self {
            files: named.into_iter().filter(|(_, d)| !d.is_empty()).collect(),
        }
    }

    /// The inputs and their descriptions, with the names messages give them.
    pub fn inputs(&self) -> impl Iterator<Item = (&str, &Description)> {
        self.files.iter().map(|(n, d)| (n.as_str(), d))
    }

    /// What the files say of one setting, with the file that says it; refused when two of
    /// them say different things.
    fn agreed<T: PartialEq + Copy + core::fmt::Display>(
        &self,
        field: &str,
        get: impl Fn(&Description) -> Option<T>,
    ) -> Result<Option<(T, &str)>> {
        let mut found: Option<(T, &str)> = None;
        for (path, d) in &self.files {
            let Some(v) = get(d) else { continue };
            match found {
                Some((w, other)) if w != v => {
                    return Err(Error::Invalid {
                        field: field.to_string().into(),
                        message: format!("the inputs disagree: {other} says {w}, {path} says {v}"),
                    });
                }
                Some(_) => {}
                None => found = Some((v, path.as_str())),
            }
        }
        Ok(found)
    }

    /// The setting of the request option `option`: `asked` if given, else what the files say
    /// ([`Description`]'s entry `get`), else `default`.
    ///
    /// # Errors
    /// [`Error::Request`] naming `option` when `asked` contradicts a file (naming the file and
    /// both values), or when two files disagree.
    pub fn pick<T: PartialEq + Copy + core::fmt::Display>(
        &self,
        option: RequestOption,
        asked: Option<T>,
        get: impl Fn(&Description) -> Option<T>,
        default: T,
    ) -> Result<T> {
        Ok(self.known(option, asked, get)?.unwrap_or(default))
    }

    /// The setting of the request option `option` when the user or the files fix it: `asked`
    /// if given, else what the files say, else `None` (for a default that depends on other
    /// settings).
    ///
    /// # Errors
    /// As [`Self::pick`].
    pub fn known<T: PartialEq + Copy + core::fmt::Display>(
        &self,
        option: RequestOption,
        asked: Option<T>,
        get: impl Fn(&Description) -> Option<T>,
    ) -> Result<Option<T>> {
        match (
            asked,
            self.agreed(option.key(), get)
                .map_err(|e| e.of_option(option))?,
        ) {
            (Some(a), Some((d, path))) if a != d => Err(refused(
                option,
                format!(
                    "{a} contradicts {path}, whose description says {d} (leave the option out to \
                     use it)"
                ),
            )),
            (Some(a), _) => Ok(Some(a)),
            (None, found) => Ok(found.map(|(d, _)| d)),
        }
    }

    /// Refuses files whose description says another value of the setting of `option` than
    /// `value`, which `source` (a scenario file, say) fixes.
    ///
    /// # Errors
    /// [`Error::Request`] naming `option`, `source`, the file and both values; two files that
    /// disagree.
    pub fn check<T: PartialEq + Copy + core::fmt::Display>(
        &self,
        option: RequestOption,
        value: T,
        source: &str,
        get: impl Fn(&Description) -> Option<T>,
    ) -> Result<()> {
        match self
            .agreed(option.key(), get)
            .map_err(|e| e.of_option(option))?
        {
            Some((d, path)) if d != value => Err(refused(
                option,
                format!("{source} says {value}, the description of {path} says {d}"),
            )),
            _ => Ok(()),
        }
    }

    /// Refuses inputs, and options the user gave (`asked`, the options as a description), that
    /// say another navigation frame, Earth or accelerometer sign than `fixed`, the description of
    /// what `source` (a scenario file, say) makes.
    ///
    /// # Errors
    /// [`Error::Invalid`] naming the setting, `source` and both values.
    pub fn check_fixed(
        &self,
        fixed: &Description,
        asked: &Description,
        source: &str,
    ) -> Result<()> {
        fn option<T: PartialEq + core::fmt::Display>(
            option: RequestOption,
            asked: Option<T>,
            fixed: Option<T>,
            source: &str,
        ) -> Result<()> {
            match (asked, fixed) {
                (Some(a), Some(f)) if a != f => Err(refused(
                    option,
                    format!("{a} contradicts {source}, which says {f}"),
                )),
                _ => Ok(()),
            }
        }
        option(
            RequestOption::NavFrame,
            asked.nav_frame,
            fixed.nav_frame,
            source,
        )?;
        option(RequestOption::Earth, asked.earth, fixed.earth, source)?;
        option(
            RequestOption::AccelSign,
            asked.accel_sign,
            fixed.accel_sign,
            source,
        )?;
        if let Some(v) = fixed.nav_frame {
            self.check(RequestOption::NavFrame, v, source, |d| d.nav_frame)?;
        }
        if let Some(v) = fixed.earth {
            self.check(RequestOption::Earth, v, source, |d| d.earth)?;
        }
        if let Some(v) = fixed.accel_sign {
            self.check(RequestOption::AccelSign, v, source, |d| d.accel_sign)?;
        }
        Ok(())
    }

    /// The origin the files agree on, if any.
    ///
    /// # Errors
    /// Two files with different origins.
    pub fn origin(&self) -> Result<Option<Origin>> {
        Ok(self.agreed("origin", |d| d.origin)?.map(|(o, _)| o))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::conventions::{AccelSignName, EarthGravityName, EarthName, NavFrameName};
    use crate::description::*;

    /// A description copied onto data of another kind is refused by name; a matching one is read.
    #[test]
    fn a_description_of_another_kind_of_table_is_refused() {
        let dir = tempfile::tempdir().expect("dir");
        let wrong = dir.path().join("imu.csv");
        std::fs::write(
            &wrong,
            "# imukit: {\"kind\": \"truth\", \"nav_frame\": \"NED\"}\n\
             t_s,accel_x_m_s2,accel_y_m_s2,accel_z_m_s2,gyro_x_rad_s,gyro_y_rad_s,gyro_z_rad_s\n\
             0,0,0,-9.8,0,0,0\n",
        )
        .expect("written");
        let e = Described::read(&[wrong.as_path()])
            .expect_err("refused")
            .to_string();
        assert!(
            e.contains("imu.csv")
                && e.contains("says it holds truth but its columns are those of readings"),
            "{e}"
        );
        let right = dir.path().join("ok.csv");
        std::fs::write(
            &right,
            "# imukit: {\"kind\": \"readings\", \"nav_frame\": \"NED\"}\n\
             t_s,accel_x_m_s2,accel_y_m_s2,accel_z_m_s2,gyro_x_rad_s,gyro_y_rad_s,gyro_z_rad_s\n\
             0,0,0,-9.8,0,0,0\n",
        )
        .expect("written");
        assert!(Described::read(&[right.as_path()]).is_ok());
    }

    fn full() -> Description {
        Description {
            kind: Some(TableKind::Readings),
            nav_frame: Some(NavFrameName::NED),
            earth: Some(EarthName::Wgs84),
            origin: Some(Origin {
                latitude_deg: 45.5,
                longitude_deg: -7.25,
                height_m: 312.125,
            }),
            gravity_m_s2: Some(9.80665),
            earth_gravity: Some(EarthGravityName::Constant),
            accel_sign: Some(AccelSignName::Matlab),
            sensor: Some("[gyroscope]\nnoise_density_rad_s = 1e-5\n".into()),
            scenario: Some("rate_hz = 100.0\n# \"quoted\" and ünïcode\n".into()),
        }
    }

    #[test]
    fn a_description_comes_back_from_csv_and_parquet_metadata() {
        let d = full();
        let dir = tempfile::tempdir().unwrap();
        let csv = dir.path().join("t.csv");
        let line = d.csv_line().unwrap();
        assert!(
            line.starts_with("# imukit: {\"kind\": \"readings\""),
            "{line}"
        );
        assert!(!line.contains('\n'));
        std::fs::write(&csv, format!("{line}\nt_s,gyro_x_rad_s\n0.0,1.0\n")).unwrap();
        assert_eq!(Description::read(&csv).unwrap(), Some(d.clone()));
        let entries: Vec<(String, String)> = d.metadata();
        assert!(
            entries
                .iter()
                .any(|(k, v)| k == "imukit.body_frame" && v == "FRD")
        );
        let back = Description::from_entries(
            entries.iter().filter_map(|(k, v)| {
                k.strip_prefix(KEY_PREFIX)
                    .map(|k| (k, Value::Text(v.clone())))
            }),
            "m",
        )
        .unwrap();
        assert_eq!(back, d);
        // A file without one, and an empty description, say nothing.
        std::fs::write(&csv, "t_s,gyro_x_rad_s\n0.0,1.0\n").unwrap();
        assert_eq!(Description::read(&csv).unwrap(), None);
        assert!(Description::default().csv_line().is_none());
        assert!(Description::default().metadata().is_empty());
    }

    #[test]
    fn rows_are_counted_from_the_header_whatever_the_description_line() {
        let dir = tempfile::tempdir().unwrap();
        let csv = dir.path().join("t.csv");
        let line = Description::of_kind(TableKind::Readings)
            .csv_line()
            .unwrap();
        std::fs::write(&csv, format!("{line}\nt_s,gyro_x_rad_s\n0.0,1.0\n0.1,x\n")).unwrap();
        let mut rows = crate::read::CsvRows::open(&csv, &["t_s", "gyro_x_rad_s"], "").unwrap();
        let mut r = [0.0; 2];
        assert_eq!(rows.next_row(&mut r).unwrap(), Some(2));
        let e = rows.next_row(&mut r).unwrap_err().to_string();
        assert!(e.contains("row 3") && e.contains("gyro_x_rad_s"), "{e}");
        std::fs::write(&csv, format!("{line}\nt_s,gyro_x_rad_s\n0.0,1.0\n0.1\n")).unwrap();
        let mut rows = crate::read::CsvRows::open(&csv, &["t_s"], "").unwrap();
        rows.next_row(&mut r[..1]).unwrap();
        let e = rows.next_row(&mut r[..1]).unwrap_err().to_string();
        assert!(e.contains("row 3 has 1 fields"), "{e}");
    }

    #[test]
    fn a_bad_description_is_refused_by_file_and_key() {
        let dir = tempfile::tempdir().unwrap();
        let csv = dir.path().join("t.csv");
        let refused = |line: &str| {
            std::fs::write(&csv, format!("{line}\nt_s\n0.0\n")).unwrap();
            Description::read(&csv).unwrap_err().to_string()
        };
        let e = refused("# imukit: {\"nav_frame\": \"NWU\"}");
        assert!(
            e.contains("t.csv, line 1: key nav_frame") && e.contains("NWU"),
            "{e}"
        );
        let e = refused("# imukit: {\"gravity_m_s2\": \"heavy\"}");
        assert!(e.contains("key gravity_m_s2") && e.contains("heavy"), "{e}");
        let e = refused("# imukit: {\"nav_frame\": \"ENU\", \"body_frame\": \"FRD\"}");
        assert!(e.contains("key body_frame") && e.contains("FLU"), "{e}");
        let e = refused("# imukit: {\"origin_latitude_deg\": 45}");
        assert!(e.contains("latitude, longitude and height together"), "{e}");
        let e = refused("# imukit: {\"kind\": ");
        assert!(e.contains("line 1") && e.contains("not valid JSON"), "{e}");
        let e = refused("# imukit: [1, 2]");
        assert!(e.contains("not a JSON object"), "{e}");
        // Entries of a later version are ignored.
        std::fs::write(
            &csv,
            "# imukit: {\"kind\": \"truth\", \"unheard_of\": [1]}\nt_s\n",
        )
        .unwrap();
        assert_eq!(
            Description::read(&csv).unwrap(),
            Some(Description::of_kind(TableKind::Truth))
        );
    }

    #[test]
    fn a_setting_is_the_option_else_the_files_else_the_default() {
        let dir = tempfile::tempdir().unwrap();
        let (a, b, plain) = (
            dir.path().join("a.csv"),
            dir.path().join("b.csv"),
            dir.path().join("plain.csv"),
        );
        let write = |p: &Path, d: &Description| {
            std::fs::write(p, format!("{}\nt_s\n", d.csv_line().unwrap())).unwrap();
        };
        write(&a, &full());
        write(
            &b,
            &Description {
                nav_frame: Some(NavFrameName::ENU),
                ..full()
            },
        );
        std::fs::write(&plain, "t_s\n").unwrap();
        let nav = |d: &Description| d.nav_frame;
        let one = Described::read(&[&a, &plain]).unwrap();
        assert_eq!(
            one.pick(RequestOption::NavFrame, None, nav, NavFrameName::ENU)
                .unwrap(),
            NavFrameName::NED
        );
        assert_eq!(
            one.pick(
                RequestOption::NavFrame,
                Some(NavFrameName::NED),
                nav,
                NavFrameName::ENU
            )
            .unwrap(),
            NavFrameName::NED
        );
        let e = one
            .pick(
                RequestOption::NavFrame,
                Some(NavFrameName::ENU),
                nav,
                NavFrameName::ENU,
            )
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("nav_frame")
                && e.contains("ENU contradicts")
                && e.contains("a.csv")
                && e.contains("NED"),
            "{e}"
        );
        let none = Described::read(&[&plain]).unwrap();
        assert_eq!(
            none.pick(RequestOption::NavFrame, None, nav, NavFrameName::ENU)
                .unwrap(),
            NavFrameName::ENU
        );
        let e = Described::read(&[&a, &b])
            .unwrap()
            .pick(RequestOption::NavFrame, None, nav, NavFrameName::ENU)
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("disagree") && e.contains("a.csv") && e.contains("b.csv"),
            "{e}"
        );
        assert_eq!(one.origin().unwrap(), full().origin);
    }
}
