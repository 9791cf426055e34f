//! Output files: written under a temporary name and renamed into place when complete, so a
//! failed command leaves no partial file; special files (`/dev/null`, `/dev/stdout`, FIFOs) are
//! written directly, never replaced; and a job's outputs are checked against its inputs and
//! against each other before work starts ([`check_outputs`]), so no input is overwritten.
use std::fs::File;
use std::io::{BufWriter, Seek, SeekFrom, Write};
use std::num::NonZeroU64;
use std::path::{Path, PathBuf};

use crate::error::{Error, Result, invalid};
use crate::io::TableFormat;
use crate::io::npy::NpySink;
use crate::io::npz::NpzSink;
use crate::io::parquet::ParquetSink;
use crate::io::table::{check_finite, write_rows};

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

/// Writes a file through `fill` into a temporary name beside it, renamed into place only when
/// complete (no half-written file left looking complete); the temporary file is removed on error.
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

/// A file written under a temporary name beside its path and renamed into place by
/// [`AtomicFile::commit`]; dropped uncommitted (an error on the way), the temporary file is
/// removed, so no half-written file is ever left looking complete.
#[derive(Debug)]
pub struct AtomicFile {
    path: PathBuf,
    /// The header's columns and the rows written, to name a refused value.
    columns: Vec<String>,
    rows: usize,
    /// The temporary name; `None` for a special file written directly.
    tmp: Option<PathBuf>,
    writer: Option<BufWriter<OutputFile>>,
    /// A Parquet table being written (it holds the writer until the commit).
    parquet: Option<ParquetSink>,
    /// A `.npy` table being written (on a handle of its own to the same file).
    npy: Option<NpySink>,
    /// A `.npz` table being gathered (the archive is written at the commit).
    npz: Option<NpzSink>,
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
        if is_special(path) {
            // A device or FIFO: written as it is, never renamed over.
            let file = std::fs::OpenOptions::new()
                .write(true)
                .open(path)
                .map_err(io)?;
            return Ok(Self {
                path: path.to_path_buf(),
                columns: Vec::new(),
                rows: 0,
                tmp: None,
                writer: Some(BufWriter::new(OutputFile::new(file))),
                parquet: None,
                npy: None,
                npz: None,
            });
        }
        let tmp = temporary_path(path);
        let file = File::create(&tmp).map_err(io)?;
        Ok(Self {
            path: path.to_path_buf(),
            columns: Vec::new(),
            rows: 0,
            tmp: Some(tmp),
            writer: Some(BufWriter::new(OutputFile::new(file))),
            parquet: None,
            npy: None,
            npz: None,
        })
    }

    /// The file's path (its final name).
    #[must_use]
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// Starts a table of `columns` in the format the path's extension names
    /// ([`TableFormat`]): Parquet (with `metadata` in the file), `.npy` or `.npz` (which have no
    /// place for it), else a CSV header line.
    ///
    /// # Errors
    /// [`Error::Io`] naming the file; the Parquet writer's refusal.
    pub fn begin_table(&mut self, columns: &[String], metadata: &[(String, String)]) -> Result<()> {
        self.columns = columns.to_vec();
        match TableFormat::of(&self.path) {
            TableFormat::Parquet => {
                let writer = self.writer.take().expect("a table is begun once");
                self.parquet = Some(ParquetSink::create(writer, &self.path, columns, metadata)?);
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
            TableFormat::Csv => {}
        }
        let w = self.writer();
        let written = w
            .write_all(columns.join(",").as_bytes())
            .and_then(|()| w.write_all(b"\n"));
        written.map_err(|e| self.error(e))
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
        let width = self.columns.len().max(1);
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

    /// Starts a table of `columns` ([`Self::begin_table`] without metadata).
    ///
    /// # Errors
    /// As [`Self::begin_table`].
    pub fn write_header(&mut self, columns: &[&str]) -> Result<()> {
        let columns: Vec<String> = columns.iter().map(|c| (*c).to_string()).collect();
        self.begin_table(&columns, &[])
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
        let result = (|| -> std::io::Result<()> {
            let file = match self.writer.take() {
                Some(w) => Some(
                    w.into_inner()
                        .map_err(std::io::IntoInnerError::into_error)?,
                ),
                None => None,
            };
            match &self.tmp {
                Some(tmp) => {
                    if let Some(f) = file {
                        f.get_ref().sync_all()?;
                    }
                    std::fs::rename(tmp, &self.path)
                }
                None => Ok(()),
            }
        })();
        result.map_err(|source| self.error(source))
    }
}

impl Drop for AtomicFile {
    fn drop(&mut self) {
        // Committed files were renamed away; anything left is incomplete.
        if let Some(tmp) = &self.tmp {
            let _ = std::fs::remove_file(tmp);
        }
    }
}

/// The temporary name beside `path`: its file name with [`PARTIAL`] appended, the name cut (at a
/// character boundary) so that the whole stays within the file-name limit.
fn temporary_path(path: &Path) -> PathBuf {
    let name = path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    let mut keep = name.len().min(NAME_MAX - PARTIAL.len());
    while !name.is_char_boundary(keep) {
        keep -= 1;
    }
    path.with_file_name(format!("{}{PARTIAL}", &name[..keep]))
}

/// True for an existing path that is neither a regular file nor a folder: a device such as
/// `/dev/null`, a FIFO or a socket. Such outputs are written directly.
fn is_special(path: &Path) -> bool {
    std::fs::metadata(path).is_ok_and(|m| !m.is_file() && !m.is_dir())
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
