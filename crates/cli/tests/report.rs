//! `stickslip run` writes `report.html`, a page that opens offline with every figure shown: checked
//! in a real headless browser (Debian's chromium) from its DOM dump.
//!
//! Without a browser the browser part prints a note and passes, unless STICKSLIP_REQUIRE_BROWSER=1
//! (as in CI), where it fails.
mod common;
use common::browser::{body_attribute, browser, dump_dom};
use common::{repo, scratch, stickslip};

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

    // The check sees a broken figure, a script error and a console error: one image's data
    // corrupted, a failing script and one that logs an error added.
    let broken = out.join("broken.html");
    let corrupted = html.replacen("data:image/png;base64,", "data:image/png;base64,AAAA", 1).replacen(
        "</body>",
        "<script>no_such_function();</script><script>console.error('a console error');</script></body>",
        1,
    );
    std::fs::write(&broken, corrupted).unwrap();
    let dom = dump_dom(&browser, &broken, &profile);
    let one_missing = format!("{}/{}", figures.len() - 1, figures.len());
    assert_eq!(body_attribute(&dom, "data-figures").as_deref(), Some(one_missing.as_str()));
    assert_eq!(body_attribute(&dom, "data-errors").as_deref(), Some("2"), "the script error and the console error");
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
