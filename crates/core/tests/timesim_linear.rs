//! Time integration of linear and smooth models against exact and discrete closed forms.
mod timesim_common;

use faer::c64;
use stickslip_core::elements::CubicSpring;
use stickslip_core::model::{Damping, Matrix, NonlinearModel};
use stickslip_core::timesim::{steady_state, Integrator, Scheme, SteadyState, SteadyStateOptions};
use timesim_common::*;

const TWO_PI: f64 = 2.0 * std::f64::consts::PI;

/// 3-DOF chain, no element: modes near 105, 295, 426 Hz; Rayleigh damping.
fn linear_chain() -> NonlinearModel {
    chain(3, 2.0, 5.0e6, 20.0, 1.0e-6, vec![])
}

/// First-harmonic complex amplitudes `c1 − i s1` of the recorded DOFs.
fn first_harmonics(s: &SteadyState) -> Vec<c64> {
    s.records
        .displacement
        .iter()
        .map(|x| {
            let c = SteadyState::harmonics(x, 1).unwrap();
            c64::new(c[1], -c[2])
        })
        .collect()
}

fn max_diff(a: &[c64], b: &[c64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| (x - y).norm()).fold(0.0, f64::max)
}

fn max_norm(a: &[c64]) -> f64 {
    a.iter().map(|x| x.norm()).fold(0.0, f64::max)
}

#[test]
fn linear_steady_state_has_newmark_period_error() {
    let model = linear_chain();
    let load = vec![0.0, 0.0, 100.0];
    let d = model.linear.damping_dense(None);
    for (f, p) in [(120.0, 32), (280.0, 64), (280.0, 128)] {
        let mut o = SteadyStateOptions::new(f, load.clone());
        o.steps_per_period = p;
        o.harmonics = 1;
        o.tolerance = 1e-10;
        o.record_dofs = vec![0, 1, 2];
        let s = steady_state(&model, &o).unwrap();
        let time = first_harmonics(&s);
        let omega = TWO_PI * f;
        let exact = harmonic_response(&model.linear, &d, omega, &load);
        // The trapezoidal rule integrates e^{iΩt} as if at Ω̃ = (2/h) tan(Ωh/2): its periodic
        // response to a sampled harmonic force is H(Ω̃) F (period error ≈ (Ωh)²/12).
        let h = 1.0 / (f * p as f64);
        let warped = 2.0 / h * (omega * h / 2.0).tan();
        let predicted = harmonic_response(&model.linear, &d, warped, &load);
        let expected_error = max_diff(&predicted, &exact);
        let error = max_diff(&time, &exact);
        // The measured error is the predicted one up to the periodicity tolerance (1e-10) and
        // the DFT of an exactly sampled period (exact): a factor 1 ± 1e-3.
        assert!(
            (error / expected_error - 1.0).abs() < 1e-3,
            "{f} Hz, P = {p}: error {error:.4e}, predicted {expected_error:.4e}"
        );
        // And the time solution is H(Ω̃) F itself, to the periodicity tolerance.
        assert!(max_diff(&time, &predicted) < 1e-8 * max_norm(&predicted));
        // The same from the scheme's own recurrences (independent derivation, HHT with α = 0).
        let recurrence = newmark_response(&model.linear, &d, omega, h, 0.0, &load);
        assert!(max_diff(&time, &recurrence) < 1e-8 * max_norm(&recurrence));
    }
}

#[test]
fn hht_steady_state_matches_its_recurrence_and_converges_at_second_order() {
    let model = linear_chain();
    let load = vec![0.0, 50.0, 100.0];
    let d = model.linear.damping_dense(None);
    let f = 280.0;
    let omega = TWO_PI * f;
    let exact = harmonic_response(&model.linear, &d, omega, &load);
    let mut errors = Vec::new();
    for p in [40, 80, 160] {
        let mut o = SteadyStateOptions::new(f, load.clone());
        o.scheme = Scheme::Hht { alpha: -0.1 };
        o.steps_per_period = p;
        o.harmonics = 1;
        o.tolerance = 1e-10;
        o.record_dofs = vec![0, 1, 2];
        let s = steady_state(&model, &o).unwrap();
        let time = first_harmonics(&s);
        let h = 1.0 / (f * p as f64);
        let recurrence = newmark_response(&model.linear, &d, omega, h, -0.1, &load);
        // Periodicity tolerance 1e-10 → agreement to ~1e-9 of the amplitude.
        assert!(max_diff(&time, &recurrence) < 1e-8 * max_norm(&recurrence), "P = {p}");
        errors.push(max_diff(&time, &exact));
    }
    // Second order: halving h divides the error by 4 (asymptotically; 3.5..4.5 allows the
    // O(h⁴) term at these step sizes).
    for w in errors.windows(2) {
        let ratio = w[0] / w[1];
        assert!((3.5..4.5).contains(&ratio), "error ratio {ratio} ({errors:?})");
    }
}

#[test]
fn smooth_nonlinear_steady_state_converges_at_second_order() {
    // Duffing chain: a cubic spring between DOF 0 and the ground, strong enough to shift the
    // response by several percent; the Newton iterations run on every step.
    let model = chain(3, 2.0, 5.0e6, 20.0, 1.0e-6, vec![(Box::new(CubicSpring::new(4.0e14).unwrap()), 0, None)]);
    let load = vec![0.0, 0.0, 100.0];
    let run = |p: usize| {
        let mut o = SteadyStateOptions::new(115.0, load.clone());
        o.steps_per_period = p;
        o.harmonics = 3;
        o.tolerance = 1e-11;
        o.record_dofs = vec![2];
        let s = steady_state(&model, &o).unwrap();
        SteadyState::harmonics(&s.records.displacement[0], 3).unwrap()
    };
    let reference = run(1024);
    let errors: Vec<f64> = [64, 128, 256]
        .iter()
        .map(|&p| {
            let c = run(p);
            (c[1] - reference[1]).hypot(c[2] - reference[2])
        })
        .collect();
    let linear_amplitude = reference[1].hypot(reference[2]);
    assert!(errors[0] > 1e-4 * linear_amplitude, "the test needs a visible discretisation error");
    for w in errors.windows(2) {
        // The reference at P = 1024 carries 1/16 of the P = 256 error: ratios between 3.5 and
        // 4.6 are second order.
        let ratio = w[0] / w[1];
        assert!((3.5..4.6).contains(&ratio), "error ratio {ratio} ({errors:?})");
    }
}

#[test]
fn sparse_and_modal_paths_agree_with_dense() {
    // A 450-DOF chain (above the sparse threshold) with a Jenkins joint at its tip, stored
    // sparse, integrated 40 steps from rest, against the same model stored dense (dense
    // inverse): the two factorisations must agree to round-off (1e-9 relative allows the
    // conditioning of S, ~1e4), stick/slip decisions included.
    let n = 450;
    let joint = || -> Vec<(Box<dyn stickslip_core::elements::Element>, usize, Option<usize>)> {
        vec![(Box::new(stickslip_core::elements::Jenkins::new(1.0e6, 10.0).unwrap()), n - 1, None)]
    };
    let dense = chain(n, 1.0, 1.0e6, 5.0, 1.0e-7, joint());
    let to_sparse = |m: &Matrix| {
        let d = m.to_dense();
        let mut t = Vec::new();
        for j in 0..n {
            for i in 0..n {
                if d[(i, j)] != 0.0 {
                    t.push(faer::sparse::Triplet::new(i, j, d[(i, j)]));
                }
            }
        }
        Matrix::Sparse(faer::sparse::SparseColMat::try_new_from_triplets(n, n, &t).unwrap())
    };
    let mut lin = dense.linear.clone();
    lin.mass = to_sparse(&lin.mass);
    lin.stiffness = to_sparse(&lin.stiffness);
    let sparse_joint = joint()
        .into_iter()
        .map(|(law, i, j)| stickslip_core::model::ElementSite {
            name: "tip".into(),
            law,
            directions: vec![stickslip_core::model::relative_direction(n, i, j)],
        })
        .collect();
    let sparse = NonlinearModel::new(lin, sparse_joint).unwrap();
    let mut load = vec![0.0; n];
    load[n - 1] = 1000.0;
    let run = |model: &NonlinearModel| {
        let h = 1e-4;
        let mut it = Integrator::new(model, Scheme::Hht { alpha: -0.05 }, h).unwrap();
        let mut s = it.start(0.0, &vec![0.0; n], &vec![0.0; n], &load, 1.0).unwrap();
        for k in 1..=40 {
            let t = k as f64 * h;
            it.step(&mut s, &load, (500.0 * (t - 0.05 * h)).cos(), (500.0 * t).cos()).unwrap();
        }
        assert!(s.element_history[0] != 0.0, "the joint must have slipped");
        s.displacement
    };
    let (a, b) = (run(&dense), run(&sparse));
    let scale = a.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    let diff = a.iter().zip(&b).map(|(x, y)| (x - y).abs()).fold(0.0, f64::max);
    assert!(scale > 0.0 && diff < 1e-9 * scale, "diff {diff:e} scale {scale:e}");

    // Modal damping builds D = M Φ diag(2ζω) Φᵀ M; the same D given as a matrix must give the
    // same motion.
    let small = linear_chain();
    let mut modal = small.linear.clone();
    modal.damping = Damping::Modal { ratios: vec![0.02, 0.01] };
    let modes = modal.dense_modes().unwrap();
    let mut explicit = modal.clone();
    explicit.damping = Damping::Matrix(Matrix::Dense(modal.damping_dense(Some(&modes))));
    let load3 = vec![0.0, 0.0, 100.0];
    let amplitude = |lin: stickslip_core::model::LinearModel| {
        let m = NonlinearModel::new(lin, vec![]).unwrap();
        let mut o = SteadyStateOptions::new(280.0, load3.clone());
        o.record_dofs = vec![0];
        o.tolerance = 1e-9;
        let s = steady_state(&m, &o).unwrap();
        SteadyState::harmonics(&s.records.displacement[0], 1).unwrap()
    };
    let (x, y) = (amplitude(modal), amplitude(explicit));
    assert!((x[1] - y[1]).hypot(x[2] - y[2]) < 1e-8 * x[1].hypot(x[2]));
}
