//! `run` with a `[nonlinear_mode]` synthesises each level's forced response from the mode alone
//! (single nonlinear mode theory) beside the harmonic balance.
mod common;
use common::{columns, run_table6};

#[test]
fn the_single_mode_response_of_a_stuck_oscillator_is_its_linear_frf() {
    // 10 N: Table 6's joint sticks at every frequency (the resonance amplitude 10 N / (c Ω) =
    // 1.9e-5 m is below its slip, 1000 N / k_J = 1.2e-4 m), so the synthesised response must be
    // the linear FRF 1 / |k − mΩ² + icΩ| wherever the backbone's amplitudes reach.
    let (dir, output) =
        run_table6("single-mode", &[("levels = [100.0, 1000.0, 3000.0, 10000.0]", "levels = [10.0]")], "");
    assert!(output.status.success(), "{}", String::from_utf8_lossy(&output.stderr));
    let cols = columns(&dir.join("single_mode_frf.csv"));
    let (f, frf) = (&cols["frequency_Hz"], &cols["mass_disp_frf_m_per_N"]);
    assert!(f.len() >= 10, "{} points", f.len());
    let (m, k, c) = (10.0, 2.24e7, 350.0);
    let mut worst = 0.0f64;
    for (f, x) in f.iter().zip(frf) {
        let w = 2.0 * std::f64::consts::PI * f;
        let exact = 1.0 / (k - m * w * w).hypot(c * w);
        worst = worst.max((x / exact - 1.0).abs());
    }
    // Measured 8e-10 (the backbone's Newton tolerance, 1e-8 on its scaled residual, and the
    // bisection to round-off); asserted 1e-6.
    assert!(worst < 1e-6, "worst relative difference {worst:e}");
    assert!(dir.join("frf_single_mode_mass.png").exists());
}
