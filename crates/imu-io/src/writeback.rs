//! An output file whose written part is handed to the disk as it grows ([`OutputFile`]), and
//! the block sizes writers gather bytes in: the bottom of every writer, below the formats and
//! the atomic outputs ([`crate::output`]) that put them in place.
use std::fs::File;
use std::io::{Seek, SeekFrom, Write};
use std::num::NonZeroU64;

/// What an output gathers before it hands it to the system in one write, bytes: the block CSV
/// rows are formatted into (at most; a chunk of rows is written when formatted) and the buffer
/// `.npy` records go through — fewer, larger calls. Parquet's pages (about 50 KB) are written as
/// they come.
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

#[cfg(test)]
mod tests {
    use std::io::Read;

    use super::*;

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
