//! `imukit completions SHELL` and `imukit man [--out-dir DIR]`: the shell completion scripts and
//! the manual pages, both written from the clap definition that also gives `--help`, so they
//! cannot disagree with it.
use std::io::Write;
use std::path::Path;

use clap::CommandFactory;
use imukit::io::output::write_atomically;

use super::CliError;
use crate::cli::Cli;

/// Writes the completion script of `shell` to standard output.
pub fn completions(shell: clap_complete::Shell) -> Result<(), CliError> {
    let mut out = Vec::new();
    clap_complete::generate(shell, &mut Cli::command(), "imukit", &mut out);
    to_stdout(&out)
}

/// Writes the manual page of imukit to standard output, or one page per command into `out_dir`.
pub fn man(out_dir: Option<&Path>) -> Result<(), CliError> {
    let mut command = Cli::command();
    // Built, the subcommands carry the global options (`--quiet`) on their pages too.
    command.build();
    let Some(dir) = out_dir else {
        return to_stdout(&page(&command)?);
    };
    std::fs::create_dir_all(dir).map_err(|source| CliError::Io {
        path: dir.display().to_string(),
        source,
    })?;
    let mut written = vec![write_page(dir, "imukit", &command)?];
    for sub in command.get_subcommands().filter(|s| s.get_name() != "help") {
        let name = format!("imukit-{}", sub.get_name());
        let sub = sub
            .clone()
            .name(name.clone())
            .version(env!("CARGO_PKG_VERSION"));
        written.push(write_page(dir, &name, &sub)?);
    }
    crate::note!(
        "imukit: {} manual pages in {} (read one with `man -l {}`)",
        written.len(),
        dir.display(),
        dir.join("imukit.1").display()
    );
    Ok(())
}

fn page(command: &clap::Command) -> Result<Vec<u8>, CliError> {
    let mut out = Vec::new();
    clap_mangen::Man::new(command.clone())
        .render(&mut out)
        .map_err(|source| CliError::Io {
            path: "the manual page".into(),
            source,
        })?;
    Ok(out)
}

fn write_page(dir: &Path, name: &str, command: &clap::Command) -> Result<String, CliError> {
    let path = dir.join(format!("{name}.1"));
    let text = page(command)?;
    write_atomically(&path, |w| w.write_all(&text))?;
    Ok(path.display().to_string())
}

fn to_stdout(bytes: &[u8]) -> Result<(), CliError> {
    let mut stdout = std::io::stdout().lock();
    stdout
        .write_all(bytes)
        .and_then(|()| stdout.flush())
        .map_err(|source| CliError::Io {
            path: "standard output".into(),
            source,
        })
}
