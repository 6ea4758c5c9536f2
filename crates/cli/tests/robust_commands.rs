//! Damaged or hostile inputs to the commands: a clear error and a failing exit code, never a
//! hang, a panic or a NaN written with success (issue 9).

mod common;

use std::process::Output;
use std::time::{Duration, Instant};

use common::{scratch, stickslip};

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

/// A simulated FRF table as `stickslip run` writes it, one level.
const SIMULATED: &str = "level_N,frequency_Hz,tip_disp_frf_m_per_N\n\
                         1,10,1e-6\n1,20,5e-6\n1,30,2e-5\n1,40,4e-6\n1,50,1e-6\n";

#[test]
fn compare_with_an_amplitude_of_1e308_finishes() {
    let dir = scratch("compare-huge");
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(dir.join("sim.csv"), SIMULATED).unwrap();
    // Once the log axis ended at 1e308 * 1.5 = inf and drawing its ticks never finished.
    let measured = "frequency_Hz,tip_amp_m_per_N\n10,1e-6\n20,1e308\n30,2e-5\n40,4e-6\n50,1e-300\n";
    std::fs::write(dir.join("meas.csv"), measured).unwrap();
    let start = Instant::now();
    let out = stickslip()
        .args(["compare", "--measured"])
        .arg(dir.join("meas.csv"))
        .arg("--simulated")
        .arg(dir.join("sim.csv"))
        .arg("--out")
        .arg(dir.join("out"))
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", stderr(&out));
    assert!(start.elapsed() < Duration::from_secs(30), "compare took {:?}", start.elapsed());
    assert!(dir.join("out/compare_level0_tip_disp.svg").exists());
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn compare_refuses_nan_samples_and_unordered_frequencies() {
    let dir = scratch("compare-nan");
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(dir.join("sim.csv"), SIMULATED).unwrap();
    let cases = [
        (
            "nan.csv",
            "frequency_Hz,tip_amp_m_per_N\n10,1e-6\n20,NaN\n",
            "nan.csv:3: column 2 (`tip_amp_m_per_N`): `NaN` is not a finite number",
        ),
        (
            "inf.csv",
            "frequency_Hz,tip_amp_m_per_N\n10,1e-6\n20,inf\n",
            "inf.csv:3: column 2 (`tip_amp_m_per_N`): `inf` is not a finite number",
        ),
        (
            "order.csv",
            "frequency_Hz,tip_amp_m_per_N\n10,1e-6\n30,2e-6\n20,3e-6\n",
            "order.csv:4: column 1 (`frequency_Hz`): 20 does not increase on 30 (line 3)",
        ),
    ];
    for (name, text, expected) in cases {
        std::fs::write(dir.join(name), text).unwrap();
        let out = stickslip()
            .args(["compare", "--measured"])
            .arg(dir.join(name))
            .arg("--simulated")
            .arg(dir.join("sim.csv"))
            .arg("--out")
            .arg(dir.join("out"))
            .output()
            .unwrap();
        assert!(!out.status.success(), "{name}: accepted");
        assert!(stderr(&out).contains(expected), "{name}: {}", stderr(&out));
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn extract_refuses_a_nan_sample_and_a_time_going_back() {
    let dir = scratch("extract-nan");
    std::fs::create_dir_all(&dir).unwrap();
    let cases = [
        (
            "nan.csv",
            "time_s,force_N\n0,1\n0.001,nan\n0.002,1\n",
            "nan.csv:3: column 2 (`force_N`): `nan` is not a finite number",
        ),
        (
            "back.csv",
            "time_s,force_N\n0,1\n0.002,2\n0.001,1\n",
            "back.csv:4: column 1 (`time_s`): 0.001 does not increase on 0.002 (line 3)",
        ),
    ];
    for (name, text, expected) in cases {
        std::fs::write(dir.join(name), text).unwrap();
        let out = stickslip()
            .arg("extract")
            .arg(dir.join(name))
            .args(["--reference", "force"])
            .arg("--out")
            .arg(dir.join("out"))
            .output()
            .unwrap();
        assert!(!out.status.success(), "{name}: accepted");
        assert!(stderr(&out).contains(expected), "{name}: {}", stderr(&out));
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

fn modes(dir: &std::path::Path, k: &str, m: &str) -> Output {
    std::fs::write(dir.join("k.mtx"), k).unwrap();
    std::fs::write(dir.join("m.mtx"), m).unwrap();
    stickslip()
        .arg("modes")
        .arg(dir.join("k.mtx"))
        .arg("--mass")
        .arg(dir.join("m.mtx"))
        .args(["--count", "2", "--out"])
        .arg(dir.join("out"))
        .output()
        .unwrap()
}

#[test]
fn modes_refuses_an_indefinite_or_rectangular_mass() {
    let dir = scratch("modes-mass");
    std::fs::create_dir_all(&dir).unwrap();
    let k = "%%MatrixMarket matrix coordinate real symmetric\n3 3 5\n1 1 2\n2 1 -1\n2 2 2\n3 2 -1\n3 3 2\n";
    let good = "%%MatrixMarket matrix coordinate real symmetric\n3 3 3\n1 1 1\n2 2 1\n3 3 1\n";
    let out = modes(&dir, k, good);
    assert!(out.status.success(), "{}", stderr(&out));
    // Indefinite: once f = 0 and residual NaN with exit code 0.
    let indefinite = "%%MatrixMarket matrix coordinate real symmetric\n3 3 3\n1 1 1\n2 2 -1\n3 3 1\n";
    let out = modes(&dir, k, indefinite);
    assert!(!out.status.success(), "indefinite mass accepted: {}", String::from_utf8_lossy(&out.stdout));
    assert!(stderr(&out).contains("the mass matrix is indefinite: diagonal entry 2 is -1e0"), "{}", stderr(&out));
    // Positive diagonal, indefinite all the same (eigenvalues 1 ± 2).
    let hidden = "%%MatrixMarket matrix coordinate real symmetric\n3 3 4\n1 1 1\n2 1 2\n2 2 1\n3 3 1\n";
    let out = modes(&dir, k, hidden);
    assert!(!out.status.success(), "indefinite mass accepted: {}", String::from_utf8_lossy(&out.stdout));
    assert!(!String::from_utf8_lossy(&out.stdout).contains("NaN"), "{}", String::from_utf8_lossy(&out.stdout));
    let rectangular = "%%MatrixMarket matrix coordinate real general\n3 4 3\n1 1 1\n2 2 1\n3 4 1\n";
    let out = modes(&dir, k, rectangular);
    assert!(!out.status.success());
    assert!(
        stderr(&out).contains("m.mtx: the matrix is 3x4; a stiffness or mass matrix must be square"),
        "{}",
        stderr(&out)
    );
    let small = "%%MatrixMarket matrix coordinate real symmetric\n2 2 2\n1 1 1\n2 2 1\n";
    let out = modes(&dir, k, small);
    assert!(!out.status.success());
    assert!(stderr(&out).contains("is 3x3 but") && stderr(&out).contains("is 2x2"), "{}", stderr(&out));
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn compare_takes_the_curves_it_is_given_and_says_what_it_passes_over() {
    let dir = scratch("compare-curves");
    std::fs::create_dir_all(&dir).unwrap();
    // Velocity amplitudes v symmetric about 30 Hz: the simulated displacement is v / Ω, and
    // compare's velocity is Ω times it, whose peak (a parabola through the three highest
    // samples) is 2e-4 m/s/N at 30 Hz exactly.
    let f = [10.0, 20.0, 30.0, 40.0, 50.0];
    let v = [1e-5, 5e-5, 2e-4, 5e-5, 1e-5];
    let mut sim = String::from("level_N,frequency_Hz,tip_disp_frf_m_per_N,tip_accel_frf_m_s2_per_N\n");
    let mut meas = String::from(
        "frequency_Hz,tip_amp_m_s_per_N,tip_m_s_per_N_phase_rad,tip_amp_m_per_N,tip_m_per_N_phase_rad,\
         contact_restoring_force_amp_N_per_N,contact_restoring_force_phase_rad\n",
    );
    for (f, v) in f.iter().zip(v) {
        let omega = 2.0 * std::f64::consts::PI * f;
        sim.push_str(&format!("1,{f},{:e},{:e}\n", v / omega, v * omega));
        meas.push_str(&format!("{f},{v:e},0.1,{:e},-1.5,0.5,0.2\n", v / omega));
    }
    std::fs::write(dir.join("sim.csv"), sim).unwrap();
    std::fs::write(dir.join("frf.csv"), meas).unwrap();
    let compare = |out: &str, extra: &[&str]| {
        stickslip()
            .args(["compare", "--measured"])
            .arg(dir.join("frf.csv"))
            .arg("--simulated")
            .arg(dir.join("sim.csv"))
            .arg("--out")
            .arg(dir.join(out))
            .args(extra)
            .output()
            .unwrap()
    };
    // Every curve: the joint's force per newton is passed over, said so.
    let o = compare("all", &[]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(stderr(&o).contains("curve `contact_restoring_force_amp_N_per_N` skipped"), "{}", stderr(&o));
    for plot in ["compare_level0_tip_vel.svg", "compare_level0_tip_disp.svg"] {
        assert!(dir.join("all").join(plot).exists(), "no {plot}");
    }
    // Only the velocity, picked by its column.
    let o = compare("vel", &["--curves", "tip_amp_m_s_per_N"]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(!dir.join("vel/compare_level0_tip_disp.svg").exists());
    let peaks = std::fs::read_to_string(dir.join("vel/peaks.csv")).unwrap();
    let rows: Vec<Vec<&str>> = peaks.lines().skip(1).map(|l| l.split(',').collect()).collect();
    assert_eq!(rows.len(), 1, "{peaks}");
    assert_eq!(rows[0][2], "m_s_per_N");
    let number = |i: usize| rows[0][i].parse::<f64>().unwrap();
    // measured and simulated frequency, then amplitudes (columns 5, 9 and 10 of 11).
    assert!((number(5) - 30.0).abs() <= 1e-9 && (number(4) - 30.0).abs() <= 1e-9, "{peaks}");
    assert!((number(9) - 2e-4).abs() <= 1e-12 && (number(8) - 2e-4).abs() <= 1e-12, "{peaks}");
    // Curves that are not there, or that compare cannot compare, are refused by name.
    let o = compare("none", &["--curves", "nope"]);
    assert!(!o.status.success());
    assert!(stderr(&o).contains("--curves: no measured curve `nope`; the measured files have [\"tip_amp_m_s_per_N\""));
    let o = compare("force", &["--curves", "contact_restoring_force"]);
    assert!(!o.status.success());
    assert!(
        stderr(&o).contains("curve `contact_restoring_force_amp_N_per_N` cannot be compared: use m_s2_per_N"),
        "{}",
        stderr(&o)
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn extract_leaves_a_frequency_channel_out_of_the_responses() {
    // A swept record as `timesim --sweep-rate` writes it carries the excitation's frequency
    // (`frequency_Hz`): once extract took it for a response, an FRF in Hz per newton.
    let dir = scratch("extract-frequency");
    std::fs::create_dir_all(&dir).unwrap();
    let (rate, f, phase) = (1000.0, 50.0, -0.3);
    let mut csv = String::from("time_s,frequency_Hz,force_N,tip_m\n");
    for j in 0..2000 {
        let t = j as f64 / rate;
        let w = 2.0 * std::f64::consts::PI * f * t;
        csv.push_str(&format!("{t:e},{f},{:e},{:e}\n", 2.0 * w.cos(), 1e-3 * (w + phase).cos()));
    }
    std::fs::write(dir.join("sweep.csv"), csv).unwrap();
    let o = stickslip()
        .args(["extract", "--reference", "force", "--cycles-per-block", "10", "--no-plots", "--out"])
        .arg(dir.join("out"))
        .arg(dir.join("sweep.csv"))
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", stderr(&o));
    let table = common::columns(&dir.join("out/sweep_frf.csv"));
    let mut names: Vec<&String> = table.keys().collect();
    names.sort();
    assert_eq!(names, ["frequency_Hz", "level_N", "tip_amp_m_per_N", "tip_phase_rad"]);
    // 1 mm under 2 N: 5e-4 m/N, 0.3 rad behind, in every block: sampled sines fitted over
    // whole cycles are exact to round-off (1e-15 measured; 1e-12 leaves room for the sums over
    // 200 samples and the reference's phase, not for a wrong normalisation or a block off by a
    // sample).
    for (a, p) in table["tip_amp_m_per_N"].iter().zip(&table["tip_phase_rad"]) {
        assert!((a - 5e-4).abs() <= 1e-12 * 5e-4 && (p - phase).abs() <= 1e-12, "{a:e} m/N, {p} rad");
    }
    std::fs::remove_dir_all(&dir).unwrap();
}
