//! `stickslip run` end to end on the shipped examples and on bad input.
use std::path::PathBuf;

mod common;
use common::{repo, scratch, stickslip};

/// Run a shipped example into a scratch folder; its FRF table as (header, rows), and the folder.
fn run_example(name: &str) -> (Vec<String>, Vec<Vec<f64>>, PathBuf) {
    let out = scratch(name);
    let status = stickslip()
        .args(["run", "--quiet", "--out"])
        .arg(&out)
        .arg(repo().join(format!("examples/{name}/study.toml")))
        .status()
        .unwrap();
    assert!(status.success(), "{name}");
    let table = std::fs::read_to_string(out.join("frf.csv")).unwrap();
    let mut lines = table.lines();
    let header = lines.next().unwrap().split(',').map(String::from).collect();
    let rows = lines.map(|l| l.split(',').map(|v| v.parse().unwrap()).collect()).collect();
    (header, rows, out)
}

#[test]
fn the_1dof_example_writes_an_frf_table_covering_the_band_at_every_level() {
    let (header, rows, out) = run_example("jenkins-1dof");
    assert_eq!(&header[..2], &["level_N", "frequency_Hz"]);
    let accel = header.iter().position(|h| h == "mass_accel_frf_m_s2_per_N").expect("acceleration FRF column");
    for level in [100.0, 1000.0, 3000.0, 10000.0] {
        let f: Vec<f64> = rows.iter().filter(|r| r[0] == level).map(|r| r[1]).collect();
        assert!(f.len() > 20, "level {level}: {} points", f.len());
        // The branch starts and ends exactly on the band's limits.
        assert_eq!(f[0], 150.0);
        assert!((f[f.len() - 1] - 350.0).abs() < 1e-9);
    }
    // Far below resonance the response is linear and stuck: |H| = Ω²/|k − MΩ² + iΩd|.
    let first = &rows[0];
    let w = 2.0 * std::f64::consts::PI * 150.0;
    let expected = w * w / ((2.24e7 - 10.0 * w * w).powi(2) + (350.0 * w).powi(2)).sqrt();
    assert!((first[accel] - expected).abs() < 1e-6 * expected, "{} vs {expected}", first[accel]);
    assert!(out.join("frf.npz").exists());
    assert!(out.join("frf_mass.png").exists());
}

#[test]
fn a_bad_study_is_refused_with_the_file_line_and_key() {
    let out = scratch("bad");
    std::fs::create_dir_all(&out).unwrap();
    let study = out.join("bad.toml");
    let text = std::fs::read_to_string(repo().join("examples/jenkins-1dof/study.toml")).unwrap();
    std::fs::write(&study, text.replace("threshold = 1000.0", "threshold = -5.0")).unwrap();
    let output = stickslip().args(["run", "--quiet", "--out"]).arg(&out).arg(&study).output().unwrap();
    assert!(!output.status.success());
    let message = String::from_utf8_lossy(&output.stderr);
    assert!(message.contains("bad.toml:"), "{message}");
    assert!(message.contains("threshold"), "{message}");
}

#[test]
fn the_blade_example_runs_from_the_mesh_and_softens_as_the_contact_slips() {
    let (header, rows, _) = run_example("blade-joint");
    let tip = header.iter().position(|h| h == "tip_disp_frf_m_per_N").expect("tip FRF column");
    let peak = |level: f64| {
        rows.iter()
            .filter(|r| r[0] == level)
            .fold((0.0, 0.0), |best, r| if r[tip] > best.1 { (r[1], r[tip]) } else { best })
    };
    // 0.5 N: the contact sticks, the peak is the stuck mode, 402.10 Hz by `stickslip modes` on
    // the full mesh (the reduction keeps it exactly; the peak of a 1 %-damped mode is within
    // 0.01 % of it, the points within a continuation step: 1 %).
    let (f_stuck, _) = peak(0.5);
    assert!((f_stuck - 402.1).abs() < 4.0, "stuck peak at {f_stuck} Hz");
    // 20 N: the contact slips most of the period, the resonance falls towards the free tip's.
    let (f_slip, _) = peak(20.0);
    assert!(f_slip < 330.0, "slipping peak at {f_slip} Hz");
}
