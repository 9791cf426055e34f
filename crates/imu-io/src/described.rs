//! The descriptions of a job's inputs taken together ([`Described`]): each setting the user
//! left out is what the files say, a contradiction between them, or with the user, refused; and
//! a description that names another kind of table than its file's columns is refused.
use std::path::Path;

use crate::description::{Description, Origin};
use crate::error::{Error, Result};
use crate::schema::TableKind;

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
                        field: field.to_string(),
                        message: format!("the inputs disagree: {other} says {w}, {path} says {v}"),
                    });
                }
                Some(_) => {}
                None => found = Some((v, path.as_str())),
            }
        }
        Ok(found)
    }

    /// The setting `field`: `asked` if given, else what the files say ([`Description`]'s entry
    /// `get`), else `default`.
    ///
    /// # Errors
    /// [`Error::Invalid`] naming `field` when `asked` contradicts a file (naming the file and
    /// both values), or when two files disagree.
    pub fn pick<T: PartialEq + Copy + core::fmt::Display>(
        &self,
        field: &str,
        asked: Option<T>,
        get: impl Fn(&Description) -> Option<T>,
        default: T,
    ) -> Result<T> {
        Ok(self.known(field, asked, get)?.unwrap_or(default))
    }

    /// The setting `field` when the user or the files fix it: `asked` if given, else what the
    /// files say, else `None` (for a default that depends on other settings).
    ///
    /// # Errors
    /// As [`Self::pick`].
    pub fn known<T: PartialEq + Copy + core::fmt::Display>(
        &self,
        field: &str,
        asked: Option<T>,
        get: impl Fn(&Description) -> Option<T>,
    ) -> Result<Option<T>> {
        match (asked, self.agreed(field, get)?) {
            (Some(a), Some((d, path))) if a != d => Err(Error::Invalid {
                field: field.to_string(),
                message: format!(
                    "{a} contradicts {path}, whose description says {d} (leave the option out to \
                     use it)"
                ),
            }),
            (Some(a), _) => Ok(Some(a)),
            (None, found) => Ok(found.map(|(d, _)| d)),
        }
    }

    /// Refuses files whose description says another `field` than `value`, which `source` (a
    /// scenario file, say) fixes.
    ///
    /// # Errors
    /// [`Error::Invalid`] naming `field`, `source`, the file and both values; two files that
    /// disagree.
    pub fn check<T: PartialEq + Copy + core::fmt::Display>(
        &self,
        field: &str,
        value: T,
        source: &str,
        get: impl Fn(&Description) -> Option<T>,
    ) -> Result<()> {
        match self.agreed(field, get)? {
            Some((d, path)) if d != value => Err(Error::Invalid {
                field: field.to_string(),
                message: format!("{source} says {value}, the description of {path} says {d}"),
            }),
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
            field: &str,
            asked: Option<T>,
            fixed: Option<T>,
            source: &str,
        ) -> Result<()> {
            match (asked, fixed) {
                (Some(a), Some(f)) if a != f => Err(Error::Invalid {
                    field: field.to_string(),
                    message: format!("{a} contradicts {source}, which says {f}"),
                }),
                _ => Ok(()),
            }
        }
        option("nav_frame", asked.nav_frame, fixed.nav_frame, source)?;
        option("earth", asked.earth, fixed.earth, source)?;
        option("accel_sign", asked.accel_sign, fixed.accel_sign, source)?;
        if let Some(v) = fixed.nav_frame {
            self.check("nav_frame", v, source, |d| d.nav_frame)?;
        }
        if let Some(v) = fixed.earth {
            self.check("earth", v, source, |d| d.earth)?;
        }
        if let Some(v) = fixed.accel_sign {
            self.check("accel_sign", v, source, |d| d.accel_sign)?;
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
