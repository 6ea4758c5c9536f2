//! The paper's reduction of Harmony (Section 3.3, Eq. 5) against the full model, at the coarse
//! refinement: "the retained eigenmodes of the reduced model are exactly those of the full
//! model" and "the linear dynamic behavior of the full and the reduced models are identical in
//! the range [0-2000] Hz". 103 retained DOFs (accelerometers, shaker, blade screws, contact
//! zones) + 34 free modes.

use faer::linalg::solvers::Solve;
use faer::Mat;
use stickslip_core::signal::shapes::dac;
use stickslip_fe::assembly::FeModel;
use stickslip_fe::eigen::{solve, to_sparse, EigenOptions, ShiftedFactor};
use stickslip_fe::harmony::{self, Configuration, Design};
use stickslip_fe::reduction::{free_modes, ReductionOptions};

const MODES: usize = 34;

#[test]
fn free_mode_reduction_keeps_the_modes_and_the_frf_of_the_full_model() {
    let mesh = Design::refined(0.5).build(Configuration::Assembly).unwrap();
    let fe = FeModel::assemble(mesh).unwrap();
    let retained: Vec<usize> = ["ACCELEROMETERS", "SHAKER", "BLADE_SCREWS", "CONTACT_ZONES"]
        .iter()
        .flat_map(|s| fe.set_dofs(s).unwrap())
        .collect();
    assert_eq!(retained.len(), 103);
    let opts =
        ReductionOptions { retained: retained.clone(), modes: MODES, band: None, eigen: EigenOptions::default() };
    let red = free_modes(&fe.model, &opts).unwrap();

    // Full model: enough modes to cover the FRF band and keep its frequencies off them.
    let (k, m) = (to_sparse(&fe.model.stiffness), to_sparse(&fe.model.mass));
    let (k, m) = (k.into_owned(), m.into_owned());
    let full = solve(&k, &m, &EigenOptions { count: 40, ..Default::default() }).unwrap();
    let f_full = full.modes.frequencies_hz();
    eprintln!("full model: mode {MODES} at {:.1} Hz, mode 40 at {:.1} Hz", f_full[MODES - 1], f_full[39]);
    assert!(f_full[39] > 1000.0, "40th mode at {} Hz", f_full[39]);

    // 1. Kept frequencies exact: the 34 full modes lie in the reduced space, so by interlacing
    // the reduced model's 34 lowest eigenvalues are theirs. Limit: the eigensolutions' own
    // accuracy (residuals ~1e-9 give eigenvalues to ~1e-14 relative; the reduced dense solve of
    // matrices with 1e10 N/m connectors loses a few digits more); 1e-7 on the frequency fails
    // on a wrong basis, which moves them by 1e-4 or more.
    let reduced = red.model.dense_modes().unwrap();
    let f_red = reduced.frequencies_hz();
    for r in 0..MODES {
        let e = (f_red[r] / f_full[r] - 1.0).abs();
        assert!(e < 1e-7, "mode {}: reduced {} Hz, full {} Hz ({e:.1e})", r + 1, f_red[r], f_full[r]);
    }

    // 2. DAC (Eq. 2) of the first two axial modes on the retained DOFs, full against reduced
    // (retained DOFs come first in the reduced coordinates). The shapes are the same vectors:
    // DAC = 1 to round-off.
    let top = fe.dof(harmony::accelerometer(0), 3).unwrap();
    let top_in_retained = retained.iter().position(|&i| i == top).unwrap();
    let largest = (0..MODES).map(|j| full.modes.shapes[(top, j)].abs()).fold(0.0, f64::max);
    let axial: Vec<usize> = (1..MODES).filter(|&j| full.modes.shapes[(top, j)].abs() > 0.1 * largest).take(2).collect();
    assert_eq!(axial.len(), 2);
    for &j in &axial {
        let a: Vec<f64> = retained.iter().map(|&i| full.modes.shapes[(i, j)]).collect();
        let b: Vec<f64> = (0..retained.len()).map(|i| reduced.shapes[(i, j)]).collect();
        let d = dac(&a, &b).unwrap();
        assert!(d > 1.0 - 1e-8, "mode {} ({} Hz): DAC {d}", j + 1, f_full[j]);
        assert!(b[top_in_retained].abs() > 0.0);
    }

    // 3. Linear FRF at the retained DOFs, force on the shaker, undamped (K − ω²M) x = f, away
    // from resonances (2 % or more from every natural frequency of the full model), 10 Hz to
    // 1 kHz. Measured (max over the retained DOFs relative to the largest): below 8.6e-9 up to
    // 90 Hz, 9.5e-8 at 183 Hz, 1.1e-7 at 234 Hz, 9.5e-7 at 298 Hz, then growing steeply:
    // 3.1e-5 at 483 Hz, 1.0e-4 at 616 Hz (785 Hz and 1 kHz lie within 2 % of modes and are
    // not checked), although the basis holds every mode up to 1459 Hz: the constraint modes
    // carry the static response of the modes above, not their dynamic part, whose share grows
    // as (f / f_mode)². So the paper's "identical in [0-2000] Hz" holds to ~1e-6 over the
    // friction band (170-300 Hz) only. Bounds: twice and three times the largest measured
    // below and above 300 Hz.
    let shaker = fe.dof(1, 3).unwrap();
    let n = fe.model.n_dofs();
    let mut f = vec![0.0; n];
    f[shaker] = 1.0;
    let fr = red.project(&f);
    let (kr, mr) = (red.model.stiffness.to_dense(), red.model.mass.to_dense());
    let mut checked = 0;
    for step in 0..20 {
        let hz = 10.0 * 100f64.powf(step as f64 / 19.0);
        if f_full.iter().any(|&fn_| (hz / fn_ - 1.0).abs() < 0.02) {
            continue;
        }
        checked += 1;
        let w2 = (2.0 * std::f64::consts::PI * hz).powi(2);
        let factor = ShiftedFactor::new(k.as_ref(), Some(m.as_ref()), w2).unwrap();
        let mut x = Mat::from_fn(n, 1, |i, _| f[i]);
        factor.solve_in_place(x.as_mut());
        let a = Mat::from_fn(kr.nrows(), kr.ncols(), |i, j| kr[(i, j)] - w2 * mr[(i, j)]);
        let q = a.partial_piv_lu().solve(Mat::from_fn(fr.len(), 1, |i, _| fr[i]));
        let scale = retained.iter().map(|&i| x[(i, 0)].abs()).fold(0.0, f64::max);
        let diff = retained.iter().enumerate().map(|(r, &i)| (x[(i, 0)] - q[(r, 0)]).abs()).fold(0.0, f64::max);
        let e = diff / scale;
        eprintln!("{hz:8.1} Hz: relative difference {e:.2e}");
        let bound = if hz <= 300.0 { 2e-6 } else { 3e-4 };
        assert!(e < bound, "{hz:.1} Hz: reduced and full FRFs differ by {e:.2e} (bound {bound:.0e})");
    }
    assert!(checked >= 15, "only {checked} frequencies away from resonances");
}
