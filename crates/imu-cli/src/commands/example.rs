//! `imukit example [NAME]... [--out-dir DIR]`: list the shipped examples or write them.
use std::path::Path;

use imukit::examples::{self, EXAMPLES, Written};

use super::CliError;

pub fn run(names: &[String], out_dir: &Path) -> Result<(), CliError> {
    if names.is_empty() {
        for e in EXAMPLES {
            crate::out_line!("{:<28} {}", e.name, e.what);
        }
        crate::out_line!(
            "{:<28} every file above, with the folder's README",
            examples::ALL
        );
        return Ok(());
    }
    let names: Vec<&str> = names.iter().map(String::as_str).collect();
    for w in examples::write(&names, out_dir)? {
        match w {
            Written::New(p) => crate::note!("imukit: wrote {}", p.display()),
            Written::Unchanged(p) => crate::note!("imukit: {} is already there", p.display()),
        }
    }
    Ok(())
}
