//! Output files: written to a temporary file no one else can reach (unnamed where the system
//! allows, else a fresh random name created exclusively) and renamed into place when complete, so
//! a failed or interrupted command leaves no partial file and two runs on one name leave one
//! whole file; a command's outputs put in place together ([`OutputGroup`]), all or none, and
//! removed on a signal ([`abandon_outputs`]); special files (`/dev/null`, `/dev/stdout`, FIFOs)
//! written directly, never replaced, while a link planted elsewhere is replaced, never followed;
//! and a job's outputs checked against its inputs and against each other before work starts
//! ([`check_outputs`]), so no input is overwritten.
use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};

use crate::TableFormat;
use crate::asl::AslWriter;
use crate::bag::{BagOptions, BagWriter};
use crate::description::Description;
use crate::error::{Error, Result};
use crate::npy::NpySink;
use crate::npz::NpzSink;
use crate::parquet::ParquetSink;
use crate::table::{Table, check_column_names, check_finite, write_rows};

/// The longest file name most file systems take, bytes.
const NAME_MAX: usize = 255;

/// The suffix of a file being written.
const PARTIAL: &str = ".imukit-partial";

pub use crate::writeback::{OutputFile, WRITE_BLOCK, WRITEBACK_STEP};

/// Writes a file through `fill` into a temporary file beside it, put in place only when
/// complete ([`AtomicFile`]); nothing is left on error.
///
/// # Errors
/// [`Error::Io`] naming the file.
pub fn write_atomically(
    path: &Path,
    fill: impl FnOnce(&mut BufWriter<OutputFile>) -> std::io::Result<()>,
) -> Result<()> {
    let mut file = AtomicFile::create(path)?;
    fill(file.writer()).map_err(|source| file.error(source))?;
    file.commit()
}

/// Where an output's bytes go until it is committed.
#[derive(Debug)]
enum Staged {
    /// A special file (`/dev/null`, a FIFO), written directly.
    Direct,
    /// A file with no name in the output's folder (Linux's `O_TMPFILE`): however the process
    /// ends, nothing is left; it is given a name only when committed.
    Unnamed { folder: PathBuf },
    /// A file under a fresh random name beside the output (created exclusively, so never through
    /// a link planted there), removed on error or on a signal ([`abandon_outputs`]).
    Named(PathBuf),
}

/// A file written under a temporary name beside its path and put in place by
/// [`AtomicFile::commit`]; dropped uncommitted (an error on the way), the temporary file is
/// removed, so no half-written file is ever left looking complete. The temporary file can
/// neither collide with another run's nor be redirected by a link planted beside the output:
/// on Linux it has no name at all until the commit (`O_TMPFILE`), elsewhere a fresh random one
/// created exclusively. Two runs writing one name each put a whole file in place; the last
/// rename wins.
#[derive(Debug)]
pub struct AtomicFile {
    path: PathBuf,
    /// The header's columns and the rows written, to name a refused value.
    columns: Vec<String>,
    rows: usize,
    staged: Staged,
    writer: Option<BufWriter<OutputFile>>,
    /// A Parquet table being written (it holds the writer until the commit).
    parquet: Option<ParquetSink>,
    /// A `.npy` table being written (on a handle of its own to the same file).
    npy: Option<NpySink>,
    /// A `.npz` table being gathered (the archive is written at the commit).
    npz: Option<NpzSink>,
    /// A CSV table in the ASL layout ([`AtomicFile::begin_asl`]).
    asl: Option<AslWriter>,
    /// A ROS 2 bag ([`AtomicFile::begin_bag`]; it holds the writer until the commit).
    bag: Option<BagWriter>,
}

impl AtomicFile {
    /// Creates the temporary file.
    ///
    /// # Errors
    /// [`Error::Io`] naming the file.
    pub fn create(path: &Path) -> Result<Self> {
        let io = |source| Error::Io {
            path: path.to_path_buf(),
            source,
        };
        if path.is_dir() {
            return Err(io(std::io::Error::new(
                std::io::ErrorKind::IsADirectory,
                "is a folder, not a file",
            )));
        }
        if path.file_name().is_none() {
            return Err(io(std::io::Error::new(
                std::io::ErrorKind::InvalidInput,
                "names no file",
            )));
        }
        let (file, staged) = if is_special(path) {
            // A device or FIFO: written as it is, never renamed over.
            let file = std::fs::OpenOptions::new()
                .write(true)
                .open(path)
                .map_err(io)?;
            (file, Staged::Direct)
        } else {
            let folder = folder_of(path);
            if !folder.is_dir() {
                return Err(io(std::io::Error::new(
                    std::io::ErrorKind::NotFound,
                    format!("its folder {} does not exist", folder.display()),
                )));
            }
            match unnamed_in(&folder) {
                Some(file) => (file, Staged::Unnamed { folder }),
                None => {
                    let mut s = staging();
                    let (file, temp) = with_temporary_name(path, |t| t.tempfile_in(&folder))
                        .and_then(|t| t.keep().map_err(|e| e.error))
                        .map_err(io)?;
                    s.named.push(temp.clone());
                    (file, Staged::Named(temp))
                }
            }
        };
        Ok(Self {
            path: path.to_path_buf(),
            columns: Vec::new(),
            rows: 0,
            staged,
            writer: Some(BufWriter::new(OutputFile::new(file))),
            parquet: None,
            npy: None,
            npz: None,
            asl: None,
            bag: None,
        })
    }
    /// The file's path (its final name).
    #[must_use]
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// Starts a table of `columns` in the format the path's extension names
    /// ([`TableFormat`]): Parquet (with `description` in its metadata), `.npy` or `.npz` (which
    /// have no place for it), else CSV: the description's line (when it says anything), then
    /// the header line.
    ///
    /// # Errors
    /// [`Error::Io`] naming the file; the Parquet writer's refusal.
    pub fn begin_table(&mut self, columns: &[String], description: &Description) -> Result<()> {
        check_column_names(columns, &self.path)?;
        self.columns = columns.to_vec();
        match TableFormat::written(&self.path.display().to_string(), &self.path)? {
            TableFormat::Parquet => {
                let writer = self.writer.take().expect("a table is begun once");
                self.parquet = Some(ParquetSink::create(
                    writer,
                    &self.path,
                    columns,
                    &description.metadata(),
                )?);
                return Ok(());
            }
            TableFormat::Npy => {
                let file = self
                    .writer
                    .as_ref()
                    .expect("the writer lives until commit")
                    .get_ref()
                    .get_ref();
                self.npy = Some(NpySink::create(file, &self.path, columns)?);
                return Ok(());
            }
            TableFormat::Npz => {
                self.npz = Some(NpzSink::create(&self.path, columns)?);
                return Ok(());
            }
            TableFormat::Mcap => return self.begin_bag(description),
            TableFormat::Nmea => {
                return Err(Error::Invalid {
                    field: self.path.display().to_string().into(),
                    message: "NMEA logs are read, not written: write fixes as CSV, Parquet, \
                              .npy, .npz or a bag (.mcap)"
                        .into(),
                });
            }
            TableFormat::Csv => {}
        }
        let line = description.csv_line();
        let w = self.writer();
        let written = line
            .map_or(Ok(()), |l| writeln!(w, "{l}"))
            .and_then(|()| w.write_all(columns.join(",").as_bytes()))
            .and_then(|()| w.write_all(b"\n"));
        written.map_err(|e| self.error(e))
    }

    /// Starts a table of `columns` in the ASL layout of EuRoC sequences ([`AslWriter`]): its
    /// header line, then rows of integer-nanosecond stamps and the layout's columns.
    ///
    /// # Errors
    /// A table the layout has no place for; [`Error::Io`] naming the file.
    pub fn begin_asl(&mut self, columns: &[String]) -> Result<()> {
        let (asl, header) = AslWriter::for_columns(columns, &self.path.display().to_string())?;
        self.columns = columns.to_vec();
        self.asl = Some(asl);
        let w = self.writer();
        let written = w
            .write_all(header.as_bytes())
            .and_then(|()| w.write_all(b"\n"));
        written.map_err(|e| self.error(e))
    }

    /// Starts a ROS 2 bag ([`BagWriter`]), each channel carrying `description`; tables go in
    /// with [`Self::write_bag`].
    ///
    /// # Errors
    /// The bag writer's refusal, naming the file.
    pub fn begin_bag(&mut self, description: &Description) -> Result<()> {
        self.begin_bag_with(description, &BagOptions::default())
    }

    /// [`Self::begin_bag`] with the IMU's topic, frame id and start stamp as `options` say.
    ///
    /// # Errors
    /// The bag writer's refusal, naming the file.
    pub fn begin_bag_with(
        &mut self,
        description: &Description,
        options: &BagOptions,
    ) -> Result<()> {
        let writer = self.writer.take().expect("a bag is begun once");
        self.bag = Some(BagWriter::create(
            writer,
            &self.path.display().to_string(),
            description,
            options,
        )?);
        Ok(())
    }

    /// Writes `tables` (IMU rates, a truth, GNSS fixes) into the bag begun, as their topics'
    /// messages in stamp order; the caller has checked the values finite.
    ///
    /// # Errors
    /// A table a bag has no topic for; the writer's refusal.
    ///
    /// # Panics
    /// When no bag was begun.
    pub fn write_bag(&mut self, tables: &[&Table]) -> Result<()> {
        self.bag.as_mut().expect("a bag was begun").write(tables)
    }

    /// Appends row-major `data` (rows of the table's width) to the table begun; the caller has
    /// checked the values finite.
    ///
    /// # Errors
    /// [`Error::Io`] naming the file; the Parquet writer's refusal.
    pub fn write_table_rows(&mut self, data: &[f64]) -> Result<()> {
        if let Some(p) = self.parquet.as_mut() {
            return p.write(data);
        }
        if let Some(n) = self.npy.as_mut() {
            return n.write(data);
        }
        if let Some(n) = self.npz.as_mut() {
            return n.write(data);
        }
        if let Some(b) = self.bag.as_mut() {
            return b.write(&[&Table {
                columns: self.columns.clone(),
                data: data.to_vec(),
            }]);
        }
        let width = self.columns.len().max(1);
        if let Some(asl) = self.asl.take() {
            let written = asl.write_rows(self.writer(), data, width);
            self.asl = Some(asl);
            return written.map_err(|e| self.error(e));
        }
        let written = write_rows(self.writer(), data, width, b",");
        written.map_err(|e| self.error(e))
    }

    /// The buffered writer.
    ///
    /// # Panics
    /// Never: the writer exists until `commit` consumes the file.
    pub fn writer(&mut self) -> &mut BufWriter<OutputFile> {
        self.writer.as_mut().expect("the writer lives until commit")
    }

    /// Starts a table of `columns` described by its kind alone ([`Self::begin_table`] with the
    /// kind [`crate::schema::TableKind::detect`] finds in the columns).
    ///
    /// # Errors
    /// As [`Self::begin_table`].
    pub fn write_header(&mut self, columns: &[&str]) -> Result<()> {
        let columns: Vec<String> = columns.iter().map(|c| (*c).to_string()).collect();
        self.begin_table(&columns, &Description::of_columns(&columns))
    }

    /// Writes one CSV row of `values` (shortest round-trip form).
    ///
    /// # Errors
    /// [`Error::NotFinite`] for a value that is not finite (the file is then not written);
    /// [`Error::Io`] naming the file.
    pub fn write_row(&mut self, values: &[f64]) -> Result<()> {
        self.rows += 1;
        if !values.iter().all(|v| v.is_finite())
            && let Err(e) = check_finite(&self.columns, values, &self.path.display().to_string())
        {
            // Rows are checked one at a time: say which row of the file it is.
            return Err(match e {
                Error::NotFinite {
                    what,
                    column,
                    value,
                    ..
                } => Error::NotFinite {
                    what,
                    row: self.rows + TableFormat::of(&self.path).first_row() - 1,
                    column,
                    value,
                },
                other => other,
            });
        }
        self.write_table_rows(values)
    }

    /// An I/O error of this file.
    #[must_use]
    pub fn error(&self, source: std::io::Error) -> Error {
        Error::Io {
            path: self.path.clone(),
            source,
        }
    }

    /// Flushes, syncs and renames the file into place.
    ///
    /// # Errors
    /// [`Error::Io`] naming the file (the temporary file is then removed).
    pub fn commit(mut self) -> Result<()> {
        if let Some(p) = self.parquet.take() {
            self.writer = Some(p.finish()?);
        }
        if let Some(n) = self.npy.take() {
            n.finish()?;
        }
        if let Some(n) = self.npz.take() {
            let writer = self.writer.take().expect("the writer lives until commit");
            self.writer = Some(n.finish(writer)?);
        }
        if let Some(b) = self.bag.take() {
            self.writer = Some(b.finish()?);
        }
        let file = match self.writer.take() {
            Some(w) => w
                .into_inner()
                .map_err(|e| self.error(e.into_error()))?
                .into_inner(),
            None => return Ok(()),
        };
        let staged = std::mem::replace(&mut self.staged, Staged::Direct);
        let put = |s: &mut Staging, temp: PathBuf| s.publish(temp, &self.path);
        let result = match staged {
            Staged::Direct => Ok(()),
            Staged::Named(temp) => {
                let synced = file.sync_all();
                drop(file);
                let mut s = staging();
                match synced {
                    Ok(()) => put(&mut s, temp),
                    Err(e) => {
                        s.discard(&temp);
                        Err(e)
                    }
                }
            }
            Staged::Unnamed { folder } => file.sync_all().and_then(|()| {
                let mut s = staging();
                let temp = name_unnamed(&file, &folder, &self.path)?;
                s.named.push(temp.clone());
                drop(file);
                put(&mut s, temp)
            }),
        };
        result.map_err(|source| self.error(source))
    }
}

impl Drop for AtomicFile {
    fn drop(&mut self) {
        // A committed file was put in place (or handed to its group); anything else is
        // incomplete. An unnamed file goes with its handle.
        if let Staged::Named(temp) = &self.staged {
            staging().discard(temp);
        }
    }
}

/// The folder of `path` (`.` for a bare file name).
fn folder_of(path: &Path) -> PathBuf {
    match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
        _ => PathBuf::from("."),
    }
}

/// Makes the names given in `folder` durable (best effort: a folder that cannot be opened or
/// synced changes nothing the user can see).
fn sync_folder(folder: &Path) {
    if let Ok(f) = File::open(folder) {
        let _ = f.sync_all();
    }
}

/// Runs `make` with a builder of temporary names beside `path`:
/// `.<name>.<random>.imukit-partial`, the name cut (at a character boundary) so that the whole
/// stays within the file-name limit, readable and writable as a new file would be (the
/// process's umask applies).
fn with_temporary_name<R>(path: &Path, make: impl FnOnce(&tempfile::Builder) -> R) -> R {
    const RANDOM: usize = 8;
    let name = path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    let mut keep = name.len().min(NAME_MAX - PARTIAL.len() - RANDOM - 2);
    while !name.is_char_boundary(keep) {
        keep -= 1;
    }
    let prefix = format!(".{}.", &name[..keep]);
    let mut b = tempfile::Builder::new();
    b.prefix(&prefix).suffix(PARTIAL).rand_bytes(RANDOM);
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt;
        b.permissions(std::fs::Permissions::from_mode(0o666));
    }
    make(&b)
}

/// A new file without a name in `folder` (`O_TMPFILE`), where the system has them and can name
/// them later (`/proc/self/fd`); `None` elsewhere.
#[cfg(any(target_os = "linux", target_os = "android"))]
fn unnamed_in(folder: &Path) -> Option<File> {
    use rustix::fs::{CWD, Mode, OFlags};
    static NAMEABLE: std::sync::OnceLock<bool> = std::sync::OnceLock::new();
    if !*NAMEABLE.get_or_init(|| Path::new("/proc/self/fd").is_dir()) {
        return None;
    }
    let fd = rustix::fs::openat(
        CWD,
        folder,
        OFlags::TMPFILE | OFlags::RDWR | OFlags::CLOEXEC,
        Mode::from_raw_mode(0o666),
    )
    .ok()?;
    Some(File::from(fd))
}

#[cfg(not(any(target_os = "linux", target_os = "android")))]
fn unnamed_in(_folder: &Path) -> Option<File> {
    None
}

/// Gives the unnamed `file` a fresh temporary name in `folder` (beside `path`).
#[cfg(any(target_os = "linux", target_os = "android"))]
fn name_unnamed(file: &File, folder: &Path, path: &Path) -> std::io::Result<PathBuf> {
    use rustix::fs::{AtFlags, CWD};
    use std::os::fd::AsRawFd;
    let fd = format!("/proc/self/fd/{}", file.as_raw_fd());
    with_temporary_name(path, |t| {
        t.make_in(folder, |temp| {
            rustix::fs::linkat(CWD, fd.as_str(), CWD, temp, AtFlags::SYMLINK_FOLLOW)
                .map_err(std::io::Error::from)
        })
    })
    .and_then(|t| t.into_temp_path().keep().map_err(|e| e.error))
}

#[cfg(not(any(target_os = "linux", target_os = "android")))]
fn name_unnamed(_file: &File, _folder: &Path, _path: &Path) -> std::io::Result<PathBuf> {
    Err(std::io::Error::other("no unnamed files here"))
}

mod check;
mod group;
mod table;
#[cfg(test)]
mod tests;

use check::is_special;
pub use check::{check_outputs, check_table_outputs, create_folder_within};
pub use group::{OutputGroup, abandon_outputs};
use group::{Staging, staging};
