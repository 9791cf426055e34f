//! A job's outputs checked before work starts: against its inputs and each other (no input is
//! overwritten), their names against the formats written, and folders inside an output folder
//! made through no link.
use std::path::{Path, PathBuf};

use super::folder_of;
use crate::TableFormat;
use crate::error::{Error, Result, invalid};

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
pub(super) fn is_special(path: &Path) -> bool {
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
