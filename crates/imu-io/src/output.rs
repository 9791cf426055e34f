//! Output files: written to a temporary file no one else can reach (unnamed where the system
//! allows, else a fresh random name created exclusively) and renamed into place when complete, so
//! a failed or interrupted command leaves no partial file and two runs on one name leave one
//! whole file; a command's outputs put in place together ([`OutputGroup`]), all or none, and
//! removed on a signal ([`abandon_outputs`]); special files (`/dev/null`, `/dev/stdout`, FIFOs)
//! written directly, never replaced, while a link planted elsewhere is replaced, never followed;
//! and a job's outputs checked against its inputs and against each other before work starts
//! ([`check_outputs`]), so no input is overwritten.
use std::fs::File;
use std::io::{BufWriter, Seek, SeekFrom, Write};
use std::num::NonZeroU64;
use std::path::{Path, PathBuf};
use std::sync::{Mutex, MutexGuard, PoisonError};

use crate::TableFormat;
use crate::asl::AslWriter;
use crate::bag::{BagOptions, BagWriter};
use crate::description::Description;
use crate::error::{Error, Result, invalid};
use crate::npy::NpySink;
use crate::npz::NpzSink;
use crate::parquet::ParquetSink;
use crate::table::{Table, check_column_names, check_finite, write_rows};

/// The longest file name most file systems take, bytes.
const NAME_MAX: usize = 255;

/// The suffix of a file being written.
const PARTIAL: &str = ".imukit-partial";

/// What an output gathers before it hands it to the system in one write, bytes: the block CSV
/// rows are formatted into (at most; a chunk of rows is written when formatted) and the buffer
/// `.npy` records go through. `imukit simulate` of 10⁶ readings (the comparison's formula job,
/// one thread, best of five processes, three rounds): CSV 0.37 → 0.35 s with blocks of up to a
/// mebibyte instead of 60 KiB, `.npy` 0.22 → 0.19 s with this buffer instead of 8 KiB (fewer
/// calls, and the kernel copies larger pieces into its cache). Parquet's pages (about 50 KB)
/// gathered the same way showed no change, so they are written as they come.
pub const WRITE_BLOCK: usize = 1 << 20;

/// How much an output file is written before its new part is handed to the disk, bytes.
pub const WRITEBACK_STEP: u64 = 8 << 20;

/// An output file whose written part is handed to the disk as it grows, every
/// [`WRITEBACK_STEP`] bytes, while the command goes on working, instead of all at once when it
/// ends: the sync at the end (the file must be on the disk before it is renamed into place)
/// then waits for the last step only. On Linux the kernel is asked to start writing the new
/// part back (`posix_fadvise`'s `DONTNEED`, which starts the write-back of dirty pages without
/// waiting for it); elsewhere, and where the file system declines, the file is written as any
/// other. Seeks and the file's contents are those of the file itself.
#[derive(Debug)]
pub struct OutputFile {
    file: File,
    /// Where the next byte goes.
    position: u64,
    /// Up to where the disk has been asked to write.
    handed: u64,
}

impl OutputFile {
    /// `file`, written from its start.
    #[must_use]
    pub fn new(file: File) -> Self {
        Self {
            file,
            position: 0,
            handed: 0,
        }
    }

    /// The file.
    #[must_use]
    pub fn get_ref(&self) -> &File {
        &self.file
    }

    /// The file, with what was written.
    #[must_use]
    pub fn into_inner(self) -> File {
        self.file
    }

    /// Hands the bytes written since the last step to the disk, once there are enough.
    fn hand_over(&mut self) {
        if self.position < self.handed {
            // Written again further back (an archive's header): from there on.
            self.handed = self.position;
        }
        let Some(len) = NonZeroU64::new(self.position - self.handed) else {
            return;
        };
        if len.get() < WRITEBACK_STEP {
            return;
        }
        #[cfg(any(target_os = "linux", target_os = "android"))]
        {
            // Advice only: a refusal changes nothing, the sync at the end reports real errors.
            let _ = rustix::fs::fadvise(
                &self.file,
                self.handed,
                Some(len),
                rustix::fs::Advice::DontNeed,
            );
        }
        self.handed = self.position;
    }
}

impl Write for OutputFile {
    fn write(&mut self, buf: &[u8]) -> std::io::Result<usize> {
        let n = self.file.write(buf)?;
        self.position += n as u64;
        self.hand_over();
        Ok(n)
    }

    fn flush(&mut self) -> std::io::Result<()> {
        self.file.flush()
    }
}

impl Seek for OutputFile {
    fn seek(&mut self, to: SeekFrom) -> std::io::Result<u64> {
        self.position = self.file.seek(to)?;
        Ok(self.position)
    }
}

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

/// The outputs of this process not yet in place: the temporary names that exist, and the
/// outputs of an open [`OutputGroup`] waiting for its commit. One lock guards both, so a
/// signal's clean-up ([`abandon_outputs`]) never runs in the middle of a commit.
struct Staging {
    named: Vec<PathBuf>,
    group: Option<Vec<Parked>>,
}

/// A complete output waiting under its temporary name for its group's commit.
struct Parked {
    temp: PathBuf,
    path: PathBuf,
}

static STAGING: Mutex<Staging> = Mutex::new(Staging {
    named: Vec::new(),
    group: None,
});

fn staging() -> MutexGuard<'static, Staging> {
    STAGING.lock().unwrap_or_else(PoisonError::into_inner)
}

impl Staging {
    fn forget(&mut self, temp: &Path) {
        self.named.retain(|n| n != temp);
    }

    /// Removes a temporary name and forgets it.
    fn discard(&mut self, temp: &Path) {
        let _ = std::fs::remove_file(temp);
        self.forget(temp);
    }

    /// Puts the complete file `temp` in place at `path`, or parks it while a group is open.
    fn publish(&mut self, temp: PathBuf, path: &Path) -> std::io::Result<()> {
        if let Some(group) = self.group.as_mut() {
            group.push(Parked {
                temp,
                path: path.to_path_buf(),
            });
            return Ok(());
        }
        let renamed = std::fs::rename(&temp, path);
        if renamed.is_err() {
            let _ = std::fs::remove_file(&temp);
        }
        self.forget(&temp);
        renamed?;
        sync_folder(&folder_of(path));
        Ok(())
    }
}

/// The outputs of one command, put in place together: while a group is open, every output
/// committed ([`AtomicFile::commit`]) waits, complete and synced, under its temporary name;
/// [`OutputGroup::commit`] renames them all into place, or none (a file it replaced is
/// restored if a later rename fails); dropped uncommitted (an error on the way), the group
/// removes them. One group is open at a time in a process (the command line opens it around a
/// command); a second [`OutputGroup::begin`] while one is open joins it.
#[derive(Debug)]
#[must_use = "an output group's files are put in place by its commit"]
pub struct OutputGroup {
    /// False for a group begun while another was open: the outer one commits.
    owner: bool,
}

impl OutputGroup {
    /// Opens the group (or joins the one open).
    pub fn begin() -> Self {
        let mut s = staging();
        let owner = s.group.is_none();
        if owner {
            s.group = Some(Vec::new());
        }
        Self { owner }
    }

    /// Puts every output of the group in place, all or none.
    ///
    /// # Errors
    /// [`Error::Io`] naming the output that could not be put in place (the others are then
    /// removed, and files they replaced restored).
    pub fn commit(mut self) -> Result<()> {
        if !self.owner {
            return Ok(());
        }
        self.owner = false;
        let mut s = staging();
        let parked = s.group.take().unwrap_or_default();
        let mut done: Vec<(PathBuf, Option<PathBuf>)> = Vec::new();
        let mut failed = None;
        for (k, p) in parked.iter().enumerate() {
            // A file already there is kept under a second name until every rename has worked.
            let backup = if std::fs::symlink_metadata(&p.path).is_ok() {
                let linked = with_temporary_name(&p.path, |t| {
                    t.make_in(folder_of(&p.path), |b| std::fs::hard_link(&p.path, b))
                });
                match linked.and_then(|t| t.into_temp_path().keep().map_err(|e| e.error)) {
                    Ok(b) => {
                        s.named.push(b.clone());
                        Some(b)
                    }
                    Err(e) => {
                        failed = Some((k, e));
                        break;
                    }
                }
            } else {
                None
            };
            if let Err(e) = std::fs::rename(&p.temp, &p.path) {
                if let Some(b) = backup {
                    s.discard(&b);
                }
                failed = Some((k, e));
                break;
            }
            s.forget(&p.temp);
            done.push((p.path.clone(), backup));
        }
        if let Some((k, source)) = failed {
            for (path, backup) in done.into_iter().rev() {
                match backup {
                    Some(b) => {
                        let _ = std::fs::rename(&b, &path);
                        s.forget(&b);
                    }
                    None => {
                        let _ = std::fs::remove_file(&path);
                    }
                }
            }
            for p in &parked[k..] {
                s.discard(&p.temp);
            }
            return Err(Error::Io {
                path: parked[k].path.clone(),
                source,
            });
        }
        let mut folders: Vec<PathBuf> = Vec::new();
        for (path, backup) in done {
            if let Some(b) = backup {
                s.discard(&b);
            }
            let folder = folder_of(&path);
            if !folders.contains(&folder) {
                folders.push(folder);
            }
        }
        for f in &folders {
            sync_folder(f);
        }
        Ok(())
    }
}

impl Drop for OutputGroup {
    fn drop(&mut self) {
        if !self.owner {
            return;
        }
        let mut s = staging();
        for p in s.group.take().unwrap_or_default() {
            s.discard(&p.temp);
        }
    }
}

/// Removes every output of this process not yet in place and keeps any other from being put in
/// place until the process ends: what a signal's handler does before exiting. The returned
/// guard holds the lock a commit takes, so the handler waits for a commit under way (its outputs
/// are then all in place) and no commit starts after; exit while holding it.
#[must_use = "hold the guard until the process exits"]
pub fn abandon_outputs() -> impl Sized {
    let mut s = staging();
    for p in s.group.take().unwrap_or_default() {
        let _ = std::fs::remove_file(&p.temp);
    }
    for n in std::mem::take(&mut s.named) {
        let _ = std::fs::remove_file(&n);
    }
    s
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
                    field: self.path.display().to_string(),
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

/// Makes the folder `root/inner` (each missing level created) for a job's outputs under the
/// output folder `root`, following no link below `root`: a link planted inside an output folder
/// (`seq/mav0 -> ../elsewhere`) would send the outputs somewhere the user never named. `root`
/// itself is the user's to name, link or not.
///
/// # Errors
/// [`Error::Invalid`] naming the link (or the file standing where a folder goes) and `field`;
/// I/O errors naming the folder.
pub fn create_folder_within(root: &Path, inner: &Path, field: &str) -> Result<PathBuf> {
    let io = |path: &Path, source| Error::Io {
        path: path.into(),
        source,
    };
    std::fs::create_dir_all(root).map_err(|e| io(root, e))?;
    let mut at = root.to_path_buf();
    for part in inner.components() {
        let std::path::Component::Normal(name) = part else {
            return Err(invalid(
                field,
                format!("{} is not a plain folder path", inner.display()),
            ));
        };
        at.push(name);
        match std::fs::symlink_metadata(&at) {
            Ok(m) if m.file_type().is_symlink() => {
                return Err(invalid(
                    field,
                    format!(
                        "{} is a link: imukit writes no output through a link inside an output \
                         folder (remove it, or name the folder it points to)",
                        at.display()
                    ),
                ));
            }
            Ok(m) if m.is_dir() => {}
            Ok(_) => {
                return Err(invalid(
                    field,
                    format!("{} is a file where a folder goes", at.display()),
                ));
            }
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => match std::fs::create_dir(&at) {
                Ok(()) => {}
                // Made by a run beside this one: checked again as a folder.
                Err(e) if e.kind() == std::io::ErrorKind::AlreadyExists => {
                    if !std::fs::symlink_metadata(&at).is_ok_and(|m| m.is_dir()) {
                        return Err(invalid(field, format!("{} is not a folder", at.display())));
                    }
                }
                Err(e) => return Err(io(&at, e)),
            },
            Err(e) => return Err(io(&at, e)),
        }
    }
    Ok(at)
}

/// True for an existing path that is neither a regular file nor a folder: a device such as
/// `/dev/null`, a FIFO or a socket. Such outputs are written directly. A symbolic link is
/// written through only where the system keeps its own (`/dev/stdout`, `/dev/fd/1`,
/// `/proc/self/fd/1`): a link planted anywhere else is replaced by the output, never followed,
/// whatever it points to.
fn is_special(path: &Path) -> bool {
    let Ok(itself) = std::fs::symlink_metadata(path) else {
        return false;
    };
    let special = |m: &std::fs::Metadata| !m.is_file() && !m.is_dir();
    if !itself.file_type().is_symlink() {
        return special(&itself);
    }
    let system = folder_of(path)
        .canonicalize()
        .is_ok_and(|f| f.starts_with("/dev") || f.starts_with("/proc"));
    system && std::fs::metadata(path).is_ok_and(|m| special(&m))
}

/// The identity of a path for comparison: the canonical path of the file, or of its folder
/// joined with its name when the file does not exist yet.
fn identity(path: &Path) -> Option<PathBuf> {
    if let Ok(p) = path.canonicalize() {
        return Some(p);
    }
    let parent = match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
        _ => PathBuf::from("."),
    };
    Some(parent.canonicalize().ok()?.join(path.file_name()?))
}

/// Refuses table outputs (`(option, path)`) whose names promise a format imukit does not write
/// ([`TableFormat::written`]), before any work.
///
/// # Errors
/// As [`TableFormat::written`], naming the option.
pub fn check_table_outputs(outputs: &[(&str, &Path)]) -> Result<()> {
    for (name, path) in outputs {
        TableFormat::written(name, path)?;
    }
    Ok(())
}

/// Refuses a job whose outputs would overwrite one of its inputs or each other, before any work:
/// paths are compared after resolving `.`, `..` and links. Special files (`/dev/null`) may be
/// given as several outputs. `-` (standard output) is refused with a hint.
///
/// # Errors
/// [`Error::Invalid`] naming the output (by `name`) and the input it would overwrite.
pub fn check_outputs(inputs: &[(&str, &Path)], outputs: &[(&str, &Path)]) -> Result<()> {
    let mut seen: Vec<(&str, PathBuf)> = Vec::new();
    for (name, out) in outputs {
        if out.as_os_str() == "-" {
            return Err(invalid(
                *name,
                "\"-\" is not a file: give /dev/stdout to write to standard output",
            ));
        }
        if out.is_dir() {
            return Err(invalid(
                *name,
                format!("{} is a folder; give a file name", out.display()),
            ));
        }
        let Some(id) = identity(out) else { continue };
        for (input_name, input) in inputs {
            if identity(input).is_some_and(|i| i == id) && !is_special(out) {
                return Err(invalid(
                    *name,
                    format!(
                        "{} is also the {input_name}: writing it would destroy the input",
                        out.display()
                    ),
                ));
            }
        }
        if let Some((other, _)) = seen.iter().find(|(_, p)| *p == id)
            && !is_special(out)
        {
            return Err(invalid(
                *name,
                format!(
                    "{} is also the {other}: give two different files",
                    out.display()
                ),
            ));
        }
        seen.push((name, id));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::io::Read;

    #[test]
    fn a_table_is_written_only_under_a_name_whose_format_it_is() {
        let dir = tempfile::tempdir().unwrap();
        let table = Table {
            columns: vec!["t_s".into()],
            data: vec![0.0, 1.0],
        };
        for (name, needle) in [
            ("err.xlsx", ".xlsx is not a table format imukit writes"),
            ("x.mat", ".mat is not a table format"),
            ("x.h5", ".h5 is not a table format"),
            ("x.db3", "name it .mcap"),
            ("x.bag", "name it .mcap"),
            ("x.nmea", ".nmea is not a table format"),
        ] {
            let path = dir.path().join(name);
            let e = table.write(&path).unwrap_err().to_string();
            assert!(e.contains(name) && e.contains(needle), "{name}: {e}");
            assert!(!path.exists(), "{name} was written");
            assert!(check_table_outputs(&[("--out", &path)]).is_err());
        }
        for name in [
            "t.csv",
            "t.CSV",
            "t.txt",
            "t.parquet",
            "t.npy",
            "t.npz",
            "noext",
        ] {
            let path = dir.path().join(name);
            check_table_outputs(&[("--out", &path)]).unwrap();
            if cfg!(not(feature = "parquet")) && name.ends_with(".parquet") {
                // A build without Parquet refuses the file by name and leaves nothing.
                let e = table.write(&path).unwrap_err().to_string();
                assert!(e.contains("`parquet` feature is off"), "{e}");
                assert!(!path.exists());
                continue;
            }
            table.write(&path).unwrap();
            assert_eq!(
                crate::read::read_table(&path).unwrap().data,
                table.data,
                "{name}"
            );
        }
    }

    #[cfg(unix)]
    #[test]
    fn folders_inside_an_output_folder_are_made_through_no_link() {
        let dir = tempfile::tempdir().unwrap();
        let (out, elsewhere) = (dir.path().join("seq"), dir.path().join("elsewhere"));
        std::fs::create_dir_all(&out).unwrap();
        std::fs::create_dir_all(&elsewhere).unwrap();
        std::os::unix::fs::symlink(&elsewhere, out.join("mav0")).unwrap();
        let e = create_folder_within(&out, Path::new("mav0/imu0"), "--out")
            .unwrap_err()
            .to_string();
        assert!(e.contains("--out") && e.contains("mav0 is a link"), "{e}");
        assert!(!elsewhere.join("imu0").exists());
        // Without the link the folders are made, and made again without complaint.
        std::fs::remove_file(out.join("mav0")).unwrap();
        for _ in 0..2 {
            let made = create_folder_within(&out, Path::new("mav0/imu0"), "--out").unwrap();
            assert_eq!(made, out.join("mav0/imu0"));
            assert!(made.is_dir());
        }
        // The output folder itself may be a link the user named.
        let named = dir.path().join("named");
        std::os::unix::fs::symlink(&elsewhere, &named).unwrap();
        create_folder_within(&named, Path::new("mav0"), "--out").unwrap();
        assert!(elsewhere.join("mav0").is_dir());
        std::fs::write(out.join("file"), "x").unwrap();
        let e = create_folder_within(&out, Path::new("file/x"), "--out")
            .unwrap_err()
            .to_string();
        assert!(e.contains("is a file where a folder goes"), "{e}");
    }

    #[test]
    fn an_output_in_a_missing_folder_is_refused_naming_the_file_and_its_folder() {
        let dir = tempfile::tempdir().expect("a folder");
        let path = dir.path().join("nosuch").join("out.csv");
        let Err(e) = AtomicFile::create(&path) else {
            panic!("a missing folder was accepted")
        };
        let message = e.to_string();
        assert!(message.contains("out.csv"), "{message}");
        assert!(message.contains("nosuch does not exist"), "{message}");
        assert!(!message.contains(PARTIAL), "{message}");
        assert!(!dir.path().join("nosuch").exists());
    }

    #[test]
    fn an_output_file_holds_what_was_written_and_hands_each_step_to_the_disk() {
        // Past several steps, then back to the start (as an archive rewrites its header) and
        // on from the end: the file is exactly what was written, and the part handed to the
        // disk follows the writes (`handed` is where the last hand-over ended).
        let dir = tempfile::tempdir().expect("a folder");
        let path = dir.path().join("out.bin");
        let mut out = OutputFile::new(File::create(&path).expect("a file"));
        let step = usize::try_from(WRITEBACK_STEP).expect("a step fits");
        let block: Vec<u8> = (0..step / 3 + 7).map(|i| (i % 251) as u8).collect();
        let mut want = Vec::new();
        let mut handed = Vec::new();
        for _ in 0..10 {
            out.write_all(&block).expect("written");
            want.extend_from_slice(&block);
            handed.push((out.position, out.handed));
        }
        // Handed over a step at a time, at the end of a write, never further behind than a step.
        let step = WRITEBACK_STEP;
        assert!(
            handed
                .iter()
                .all(|&(at, h)| h % (block.len() as u64) == 0 && at - h < step),
            "{handed:?}"
        );
        let handed: Vec<u64> = handed.into_iter().map(|(_, h)| h).collect();
        assert!(
            handed.contains(&0) && handed.iter().any(|&h| h >= 2 * step),
            "{handed:?}"
        );
        out.seek(SeekFrom::Start(0)).expect("seek");
        out.write_all(b"head").expect("written");
        want[..4].copy_from_slice(b"head");
        assert_eq!(out.handed, 4, "handed from the rewritten place on");
        out.seek(SeekFrom::End(0)).expect("seek");
        out.write_all(b"tail").expect("written");
        want.extend_from_slice(b"tail");
        out.flush().expect("flushed");
        out.get_ref().sync_all().expect("synced");
        drop(out);
        let mut back = Vec::new();
        File::open(&path)
            .expect("opened")
            .read_to_end(&mut back)
            .expect("read");
        assert!(
            back == want,
            "{} bytes back, {} written",
            back.len(),
            want.len()
        );
    }
}
