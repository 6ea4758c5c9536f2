//! What a command wrote into its output folder, so that the folder holds one run's files.
//!
//! Each command lists the files it wrote in `<dir>/<command>_files.txt`, one path relative to
//! the folder per line. The next run of the same command into the same folder reads that list
//! and removes the files of it that it did not write again: a run at three force levels after
//! one at four leaves no plot of the fourth, a steady state at other frequencies no record of
//! the old ones. Only listed files are removed, so a file the user put there, or one another
//! command wrote (each has its own list), is never touched; a folder written before the lists
//! existed keeps its old files until they are listed once.

use std::path::{Component, Path, PathBuf};

use super::OutputError;

/// The list of the files `command` wrote into `dir`.
pub fn manifest_path(dir: &Path, command: &str) -> PathBuf {
    dir.join(format!("{command}_files.txt"))
}

/// Remove the files of the previous run of `command` in `dir` that this run did not write
/// (`written`), then list `written` as this run's files. Returns the files removed.
pub fn replace_previous_run(dir: &Path, command: &str, written: &[PathBuf]) -> Result<Vec<PathBuf>, OutputError> {
    let path = manifest_path(dir, command);
    let relative: Vec<PathBuf> =
        written.iter().map(|p| p.strip_prefix(dir).map_or_else(|_| p.clone(), Path::to_path_buf)).collect();
    let previous = match std::fs::read_to_string(&path) {
        Ok(text) => text,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => String::new(),
        Err(source) => return Err(OutputError::Io { path, source }),
    };
    let mut removed = Vec::new();
    for line in previous.lines().map(str::trim).filter(|l| !l.is_empty()) {
        let old = PathBuf::from(line);
        // Only plain paths inside the folder: an edited list cannot reach elsewhere.
        if !old.components().all(|c| matches!(c, Component::Normal(_))) || relative.contains(&old) {
            continue;
        }
        let file = dir.join(&old);
        match std::fs::remove_file(&file) {
            Ok(()) => {
                // A sub-folder of ours (points/) left empty goes too; one holding anything stays.
                if let Some(parent) = file.parent().filter(|p| *p != dir) {
                    let _ = std::fs::remove_dir(parent);
                }
                removed.push(file);
            }
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => {}
            Err(source) => return Err(OutputError::Io { path: file, source }),
        }
    }
    let mut text = String::new();
    for r in &relative {
        text.push_str(&r.to_string_lossy());
        text.push('\n');
    }
    std::fs::write(&path, text).map_err(|source| OutputError::Io { path, source })?;
    Ok(removed)
}
