//! Helpers the command's tests share: the binary, a temporary folder, a table's text.
use std::process::Command;

pub(crate) fn imukit() -> Command {
    Command::new(env!("CARGO_BIN_EXE_imukit"))
}

/// A fresh folder under the system's temporary folder, removed with its files when dropped.
pub(crate) fn temp_dir(name: &str) -> tempfile::TempDir {
    tempfile::Builder::new()
        .prefix(&format!("imukit-cli-{name}-"))
        .tempdir()
        .unwrap()
}

/// A CSV table's text after its description line (`# imukit: {…}`, which must be there).
pub(crate) fn table_text(path: impl AsRef<std::path::Path>) -> String {
    let text = std::fs::read_to_string(path.as_ref()).unwrap();
    let (first, rest) = text.split_once('\n').unwrap();
    assert!(first.starts_with("# imukit: {\"kind\": "), "{first}");
    rest.to_string()
}

/// Runs `imukit` in `dir` with `args` and returns (exit code, stderr).
pub(crate) fn run_in(dir: &std::path::Path, args: &[&str]) -> (Option<i32>, String) {
    let out = imukit().current_dir(dir).args(args).output().unwrap();
    (out.status.code(), String::from_utf8(out.stderr).unwrap())
}
