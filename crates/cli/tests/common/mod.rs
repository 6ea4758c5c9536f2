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

/// A headless browser (Debian's chromium) that opens a page and dumps its DOM after its scripts
/// ran: the check that a report shows its figures.
pub mod browser {
    use std::io::Read;
    use std::path::{Path, PathBuf};
    use std::process::{Command, Stdio};
    use std::time::{Duration, Instant};

    /// The browser to use: `chromium` (or `chromium-browser`) on the PATH.
    pub fn browser() -> Option<PathBuf> {
        let path = std::env::var_os("PATH")?;
        ["chromium", "chromium-browser"]
            .iter()
            .flat_map(|name| std::env::split_paths(&path).map(move |dir| dir.join(name)))
            .find(|candidate| candidate.is_file())
    }

    /// The DOM of `page` after its scripts ran, as the headless browser dumps it.
    pub fn dump_dom(browser: &Path, page: &Path, profile: &Path) -> String {
        let mut child = Command::new(browser)
            .args(["--headless", "--disable-gpu", "--no-sandbox", "--virtual-time-budget=5000", "--no-first-run"])
            .arg(format!("--user-data-dir={}", profile.display()))
            .arg("--dump-dom")
            .arg(format!("file://{}", page.display()))
            .stdin(Stdio::null())
            .stdout(Stdio::piped())
            .stderr(Stdio::null())
            .spawn()
            .expect("start the browser");
        let mut stdout = child.stdout.take().expect("browser stdout");
        let reader = std::thread::spawn(move || {
            let mut dom = String::new();
            stdout.read_to_string(&mut dom).map(|_| dom)
        });
        let deadline = Instant::now() + Duration::from_secs(120);
        let status = loop {
            if let Some(status) = child.try_wait().expect("wait for the browser") {
                break status;
            }
            if Instant::now() > deadline {
                let _ = child.kill();
                let _ = child.wait();
                panic!("the browser did not finish within 120 s on {}", page.display());
            }
            std::thread::sleep(Duration::from_millis(100));
        };
        let dom = reader.join().expect("reader thread").expect("browser output");
        assert!(status.success(), "the browser failed ({status}) on {}", page.display());
        dom
    }

    /// The value of attribute `name` on the `<body>` tag of `dom`.
    pub fn body_attribute(dom: &str, name: &str) -> Option<String> {
        let start = dom.find("<body")?;
        let tag = &dom[start..start + dom[start..].find('>')?];
        let key = format!("{name}=\"");
        let from = tag.find(&key)? + key.len();
        Some(tag[from..from + tag[from..].find('"')?].to_string())
    }

    /// The browser, or `None` with a note when there is none and none is required; with
    /// STICKSLIP_REQUIRE_BROWSER=1 (CI) a missing browser fails the test.
    pub fn required_browser() -> Option<PathBuf> {
        let found = browser();
        if found.is_none() {
            let required = std::env::var("STICKSLIP_REQUIRE_BROWSER").is_ok_and(|v| v == "1");
            assert!(
                !required,
                "STICKSLIP_REQUIRE_BROWSER=1 but no chromium on the PATH (Debian: apt-get install chromium)"
            );
            eprintln!("note: no chromium on the PATH; the report was not opened in a browser");
        }
        found
    }
}
