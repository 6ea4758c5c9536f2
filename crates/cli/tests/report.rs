//! `stickslip run` writes `report.html`, a page that opens offline with every figure shown: checked
//! in a real headless browser (Debian's chromium) from its DOM dump.
//!
//! Without a browser the browser part prints a note and passes, unless STICKSLIP_REQUIRE_BROWSER=1
//! (as in CI), where it fails.
use std::io::Read;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

mod common;
use common::{repo, scratch, stickslip};

/// The browser to use: `chromium` (or `chromium-browser`) on the PATH.
fn browser() -> Option<PathBuf> {
    let path = std::env::var_os("PATH")?;
    ["chromium", "chromium-browser"]
        .iter()
        .flat_map(|name| std::env::split_paths(&path).map(move |dir| dir.join(name)))
        .find(|candidate| candidate.is_file())
}

/// The DOM of `page` after its scripts ran, as the headless browser dumps it.
fn dump_dom(browser: &Path, page: &Path, profile: &Path) -> String {
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
fn body_attribute(dom: &str, name: &str) -> Option<String> {
    let start = dom.find("<body")?;
    let tag = &dom[start..start + dom[start..].find('>')?];
    let key = format!("{name}=\"");
    let from = tag.find(&key)? + key.len();
    Some(tag[from..from + tag[from..].find('"')?].to_string())
}

#[test]
fn the_report_of_the_1dof_example_shows_every_figure_in_a_headless_browser() {
    let out = scratch("report");
    let output = stickslip()
        .args(["run", "--quiet", "--out"])
        .arg(&out)
        .arg(repo().join("examples/jenkins-1dof/study.toml"))
        .output()
        .unwrap();
    let message = String::from_utf8_lossy(&output.stderr);
    assert!(output.status.success(), "{message}");
    let report = out.join("report.html");
    assert!(message.contains(&format!("report: {}", report.display())), "{message}");

    // Every plot of the run is embedded, nothing refers to the network.
    let html = std::fs::read_to_string(&report).unwrap();
    let mut figures: Vec<String> = std::fs::read_dir(&out)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|n| n.ends_with(".png") || n.ends_with(".svg"))
        .collect();
    figures.sort();
    // FRF and its phase, per level (4) harmonics, hysteresis loop and slider velocity, the
    // nonlinear mode's backbone (frequency and damping ratio) and the FRF it predicts.
    assert_eq!(figures.len(), 17, "{figures:?}");
    assert_eq!(html.matches("<img src=\"data:image/png;base64,").count(), figures.len());
    for f in &figures {
        assert!(html.contains(&format!("<code>{f}</code>")), "{f} not in the report");
    }
    for external in ["src=\"http", "href=\"http", "src=\"//", "url("] {
        assert!(!html.contains(external), "the report refers to {external}...");
    }
    // The model and the peak table.
    assert!(html.contains("<td>Jenkins</td>"));
    assert!(html.contains("238.201"), "the stuck natural frequency, √(k/m)/2π");
    assert!(html.contains("<td class=\"num\">10000</td><td>mass</td>"));

    let Some(browser) = browser() else {
        let required = std::env::var("STICKSLIP_REQUIRE_BROWSER").is_ok_and(|v| v == "1");
        assert!(
            !required,
            "STICKSLIP_REQUIRE_BROWSER=1 but no chromium on the PATH (Debian: apt-get install chromium)"
        );
        eprintln!("note: no chromium on the PATH; report.html was not opened in a browser");
        let _ = std::fs::remove_dir_all(&out);
        return;
    };
    let profile = out.join("browser-profile");
    let dom = dump_dom(&browser, &report, &profile);
    let all = format!("{}/{}", figures.len(), figures.len());
    assert_eq!(body_attribute(&dom, "data-figures").as_deref(), Some(all.as_str()), "figures loaded");
    assert_eq!(body_attribute(&dom, "data-errors").as_deref(), Some("0"), "script errors");

    // The check sees a broken figure and a script error: one image's data corrupted, one
    // failing script added.
    let broken = out.join("broken.html");
    let corrupted = html.replacen("data:image/png;base64,", "data:image/png;base64,AAAA", 1).replacen(
        "</body>",
        "<script>no_such_function();</script></body>",
        1,
    );
    std::fs::write(&broken, corrupted).unwrap();
    let dom = dump_dom(&browser, &broken, &profile);
    let one_missing = format!("{}/{}", figures.len() - 1, figures.len());
    assert_eq!(body_attribute(&dom, "data-figures").as_deref(), Some(one_missing.as_str()));
    assert_eq!(body_attribute(&dom, "data-errors").as_deref(), Some("1"));
    let _ = std::fs::remove_dir_all(&out);
}

#[test]
fn no_report_is_written_with_no_report() {
    let out = scratch("no-report");
    let output = stickslip()
        .args(["run", "--quiet", "--no-report", "--out"])
        .arg(&out)
        .arg(repo().join("examples/jenkins-1dof/study.toml"))
        .output()
        .unwrap();
    assert!(output.status.success(), "{}", String::from_utf8_lossy(&output.stderr));
    assert!(out.join("frf.csv").exists());
    assert!(!out.join("report.html").exists());
    assert!(!String::from_utf8_lossy(&output.stderr).contains("report:"));
    let _ = std::fs::remove_dir_all(&out);
}
