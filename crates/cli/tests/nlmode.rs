//! `stickslip nlmode` on a study built from a mesh and reduced (the blade-joint example): the
//! backbone of a reduced model, checked against the full model's own modes, and its bad input.
mod common;
use common::{columns, repo, scratch, stickslip};
use std::path::{Path, PathBuf};

/// The blade-joint example (blade.inp, reduced by the paper's variant to its retained DOFs and
/// 8 modes, one Jenkins contact) copied into a scratch folder with `section` appended.
fn blade_study(name: &str, section: &str) -> PathBuf {
    let dir = scratch(name);
    std::fs::create_dir_all(&dir).unwrap();
    let example = repo().join("examples/blade-joint");
    std::fs::copy(example.join("blade.inp"), dir.join("blade.inp")).unwrap();
    let study = std::fs::read_to_string(example.join("study.toml")).unwrap();
    std::fs::write(dir.join("study.toml"), format!("{study}\n{section}")).unwrap();
    dir
}

fn nlmode(dir: &Path) -> std::process::Output {
    stickslip()
        .args(["--threads", "1", "nlmode", "study.toml", "--out", "out", "--quiet"])
        .current_dir(dir)
        .output()
        .unwrap()
}

/// The lowest natural frequency (Hz) of the full mesh, by `stickslip modes` (sparse
/// shift-invert Lanczos on the 3-D model, not the reduced one).
fn full_model_first_frequency(dir: &Path) -> f64 {
    let out =
        stickslip().args(["modes", "blade.inp", "--count", "1", "--out", "modes"]).current_dir(dir).output().unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let cols = columns(&dir.join("modes/modes.csv"));
    let key = cols.keys().find(|k| k.starts_with("frequency")).expect("a frequency column").clone();
    cols[&key][0]
}

#[test]
fn the_backbone_of_a_reduced_mesh_starts_at_the_full_models_mode() {
    // 1e-7 m·√kg: the contact sticks (it slips from 2 N / 5e4 N/m = 4e-5 m at the tip); 1e-3:
    // the tip 7 mm, slipping over 95 % of the cycle.
    let dir = blade_study("nlmode-blade", "[nonlinear_mode]\nmode = 1\namplitude_start = 1e-7\namplitude_end = 1e-3\n");
    let out = nlmode(&dir);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let b = columns(&dir.join("out/backbone.csv"));
    let (a, f, zeta) = (&b["modal_amplitude_m_sqrtkg"], &b["frequency_Hz"], &b["damping_ratio"]);
    let stick = &b["contact_stick_fraction"];
    assert!(a.len() >= 20, "{} points", a.len());
    assert!((a[0] / 1e-7 - 1.0).abs() < 1e-12 && (a[a.len() - 1] / 1e-3 - 1.0).abs() < 1e-12);
    // The paper's reduction keeps the full model's eigenmodes exactly (Eq. 5), so the stuck
    // backbone is the full mesh's first mode: measured 402.097142 Hz both ways, within the
    // eigensolver's residual (7e-10); asserted 1e-7.
    let f_full = full_model_first_frequency(&dir);
    assert!((f[0] / f_full - 1.0).abs() < 1e-7, "backbone {} Hz, full model {f_full} Hz", f[0]);
    // D = αM with α = 50 1/s: the linear mode's damping ratio is α / (2ω) in closed form.
    let zeta_0 = 50.0 / (2.0 * 2.0 * std::f64::consts::PI * f[0]);
    assert!((zeta[0] / zeta_0 - 1.0).abs() < 1e-8, "ζ {} against α/2ω {zeta_0}", zeta[0]);
    // Slipping frees the tip: the frequency falls all the way (402.1 → 307.3 Hz measured) and
    // the contact dissipates (ζ up to 1.5 %, against 0.99 % stuck).
    assert!(f.windows(2).all(|w| w[1] <= w[0] * (1.0 + 1e-9)), "frequency not falling");
    assert!(f[f.len() - 1] < 0.8 * f[0], "{} Hz at the end", f[f.len() - 1]);
    assert!(zeta.iter().cloned().fold(0.0, f64::max) > 1.3 * zeta_0);
    assert!(
        stick[0] == 1.0 && stick[stick.len() - 1] < 0.1,
        "stick fractions {} .. {}",
        stick[0],
        stick[stick.len() - 1]
    );
    // Each point's energy per cycle is the contact's and the viscous dissipation: the joint's
    // share grows from nothing.
    let joint = &b["contact_energy_J"];
    assert!(joint[0] == 0.0 && joint[joint.len() - 1] > 0.0);
    let singular = std::fs::read_to_string(dir.join("out/backbone_bifurcations.csv")).unwrap();
    assert!(singular.starts_with("kind,modal_amplitude_m_sqrtkg,frequency_Hz,damping_ratio,located"), "{singular}");
    assert!(dir.join("out/backbone_frequency.png").exists() && dir.join("out/backbone_damping.png").exists());
}

#[test]
fn bad_nonlinear_mode_sections_are_refused_naming_what_to_fix() {
    let cases = [
        // Beyond the reduced model's modes: the count is named.
        ("nlmode-blade-mode", "mode = 99\namplitude_start = 1e-7\namplitude_end = 1e-3\n", "modes"),
        // Starts where the contact already slips.
        ("nlmode-blade-start", "mode = 1\namplitude_start = 1e-3\namplitude_end = 1e-2\n", "amplitude"),
        // An inverted range, refused when the study is read.
        ("nlmode-blade-range", "mode = 1\namplitude_start = 1e-3\namplitude_end = 1e-7\n", "amplitude_end"),
    ];
    for (name, keys, expected) in cases {
        let dir = blade_study(name, &format!("[nonlinear_mode]\n{keys}"));
        let out = nlmode(&dir);
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert!(!out.status.success(), "{name}: accepted");
        assert!(stderr.contains(expected), "{name}: {stderr}");
        assert!(!stderr.contains("panicked"), "{name}: {stderr}");
    }
}
