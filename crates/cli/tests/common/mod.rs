//! Helpers shared by the command-line tests: the binary, the repository, scratch folders.
// Each test file uses the part it needs.
#![allow(dead_code)]
use std::path::PathBuf;
use std::process::Command;

/// The `stickslip` binary built for the tests.
pub fn stickslip() -> Command {
    Command::new(env!("CARGO_BIN_EXE_stickslip"))
}

/// The repository's root.
pub fn repo() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../..")
}

/// An empty scratch folder name for test `name`, unique to this process (not created).
pub fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("stickslip-cli-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    dir
}
