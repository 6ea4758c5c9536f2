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

/// The columns of a numeric CSV table, by name.
pub fn columns(path: &std::path::Path) -> std::collections::HashMap<String, Vec<f64>> {
    let text = std::fs::read_to_string(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let mut lines = text.lines();
    let names: Vec<String> = lines.next().unwrap().split(',').map(String::from).collect();
    let mut cols: Vec<Vec<f64>> = vec![Vec::new(); names.len()];
    for l in lines {
        for (c, v) in cols.iter_mut().zip(l.split(',')) {
            c.push(v.parse().unwrap());
        }
    }
    names.into_iter().zip(cols).collect()
}

/// Run Table 6's study (`examples/jenkins-1dof`) with `edits` (text replacements, each of
/// which must apply) and `extra` appended, into scratch folder `name` (`run --quiet
/// --no-report`, no time data). Returns the folder and the command's output.
pub fn run_table6(name: &str, edits: &[(&str, &str)], extra: &str) -> (PathBuf, std::process::Output) {
    let dir = scratch(name);
    std::fs::create_dir_all(&dir).unwrap();
    let mut study = std::fs::read_to_string(repo().join("examples/jenkins-1dof/study.toml"))
        .unwrap()
        .replace("time_data = 10", "time_data = \"none\"");
    for (from, to) in edits {
        assert!(study.contains(from), "{from:?} is not in the study");
        study = study.replace(from, to);
    }
    study.push_str(extra);
    std::fs::write(dir.join("study.toml"), study).unwrap();
    let output = stickslip()
        .args(["run", "--quiet", "--no-report", "--out"])
        .arg(&dir)
        .arg(dir.join("study.toml"))
        .output()
        .unwrap();
    (dir, output)
}
