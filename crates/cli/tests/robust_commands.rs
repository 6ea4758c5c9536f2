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
    assert!(dir.join("out/compare_level0_tip.svg").exists());
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
