//! A command's outputs put in place together, all or none, and removed on a signal: the one
//! record of this process's outputs not yet in place.
use std::path::{Path, PathBuf};
use std::sync::{Mutex, MutexGuard, PoisonError};

use super::{folder_of, sync_folder, with_temporary_name};
use crate::error::{Error, Result};

/// The outputs of this process not yet in place: the temporary names that exist, and the
/// outputs of an open [`OutputGroup`] waiting for its commit. One lock guards both, so a
/// signal's clean-up ([`abandon_outputs`]) never runs in the middle of a commit.
pub(super) struct Staging {
    pub(super) named: Vec<PathBuf>,
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

pub(super) fn staging() -> MutexGuard<'static, Staging> {
    STAGING.lock().unwrap_or_else(PoisonError::into_inner)
}

impl Staging {
    pub(super) fn forget(&mut self, temp: &Path) {
        self.named.retain(|n| n != temp);
    }

    /// Removes a temporary name and forgets it.
    pub(super) fn discard(&mut self, temp: &Path) {
        let _ = std::fs::remove_file(temp);
        self.forget(temp);
    }

    /// Puts the complete file `temp` in place at `path`, or parks it while a group is open.
    pub(super) fn publish(&mut self, temp: PathBuf, path: &Path) -> std::io::Result<()> {
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
/// committed ([`super::AtomicFile::commit`]) waits, complete and synced, under its temporary name;
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
