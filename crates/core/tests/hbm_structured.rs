//! The structured Newton solve of the condensed balance (`hbm::structured`) against the dense
//! LU of the assembled Jacobian, on a contact patch where some contacts stick for the whole
//! period (absorbed into the linear part) and others slip or lift off (the reduced system).
#[path = "../benches/common/mod.rs"]
mod common;

use faer::linalg::solvers::Solve;
use faer::Mat;
use stickslip_core::hbm::{CondensedHbm, HbmSettings, Jacobians};

const TWO_PI: f64 = 2.0 * std::f64::consts::PI;

/// Relative difference between the structured and the dense solution of `J y = b` for a
/// pseudo-random `b`, and the number of directions that couple harmonics.
fn structured_against_dense(side: usize, level: f64) -> (f64, usize, usize) {
    let (model, force) = common::contact_patch(side);
    let mut hbm = CondensedHbm::new(&model, &force, HbmSettings { harmonics: 5, samples: 256 }).unwrap();
    let n = hbm.dimension();
    let omega = TWO_PI * 340.0;
    let x = hbm.linear_solution(omega, level);
    let mut r = vec![0.0; n];
    let mut jac = Mat::zeros(n, n);
    hbm.evaluate(&x, omega, level, &mut r, Some(Jacobians { dx: jac.as_mut(), domega: None, dlevel: None })).unwrap();
    let b: Vec<f64> = (0..n).map(|i| ((i * 7919) % 101) as f64 / 50.0 - 1.0).collect();
    let dense = jac.partial_piv_lu().solve(Mat::from_fn(n, 1, |i, _| b[i]));
    let mut r2 = vec![0.0; n];
    assert!(hbm.evaluate_factored(&x, omega, level, &mut r2, None, None).unwrap());
    assert_eq!(r, r2, "the residual does not depend on how the Jacobian is factored");
    let mut y = b.clone();
    assert!(hbm.solve_factored(&mut y));
    let diff = (0..n).map(|i| (y[i] - dense[(i, 0)]).powi(2)).sum::<f64>().sqrt();
    let size = (0..n).map(|i| dense[(i, 0)].powi(2)).sum::<f64>().sqrt();
    let coupled = hbm.structured_jacobian().unwrap().coupled_directions();
    (diff / size, coupled, hbm.n_directions())
}

/// Exact up to the LU round-off: the condition numbers here are below 1e4, so 1e-10 leaves
/// room for a million-fold loss and still fails on any wrong block.
#[test]
fn structured_solve_equals_the_dense_lu_when_part_of_the_patch_sticks() {
    // At 10 N every contact sticks: the whole Jacobian is the linear part's.
    let (err, coupled, _) = structured_against_dense(4, 10.0);
    assert_eq!(coupled, 0);
    assert!(err < 1e-10, "all stuck: {err:e}");
    // At 1000 N (the linear response, 10 µm at the corner) the edges slip and lift off while
    // the centre sticks: both parts are used.
    let (err, coupled, total) = structured_against_dense(4, 1000.0);
    assert!(coupled > 0 && coupled < total, "{coupled} of {total} directions couple harmonics");
    assert!(err < 1e-10, "mixed: {err:e}");
}

/// Where most of a larger patch slips or opens, the reduced system (above 1200 unknowns) is
/// solved by BiCGSTAB to 1e-12 relative residual: the step equals the dense LU's to what that
/// residual and the condition number (below 1e4 here) leave, asserted 1e-8.
#[test]
fn the_iterative_reduced_solve_equals_the_dense_lu_where_the_patch_slips() {
    for level in [2e4, 1e5] {
        let (err, coupled, total) = structured_against_dense(7, level);
        assert!(coupled * 11 > 1200, "{coupled} of {total} directions couple harmonics: not iterative");
        assert!(err < 1e-8, "{level} N, {coupled} of {total} directions: {err:e}");
        println!("{level} N: {coupled} of {total} directions couple harmonics, relative difference {err:.1e}");
    }
}

/// A frequency sweep of the patch through its resonance, its Newton systems solved by structure
/// and by dense LU: the same points. The corrector stops at the tolerance, so the two branches
/// can differ by the last Newton update, far below 1e-6 of the motion; a wrong solve changes
/// the steps and the points.
#[test]
fn a_sweep_solved_by_structure_follows_the_dense_sweep() {
    use stickslip_core::continuation::{Options, Silent};
    use stickslip_core::hbm::sweep_frequency;
    let (model, force) = common::contact_patch(3);
    let sweep = |by_structure: bool| {
        let mut hbm = CondensedHbm::new(&model, &force, HbmSettings { harmonics: 5, samples: 256 }).unwrap();
        hbm.set_factor_by_structure(by_structure);
        let options = Options::default();
        sweep_frequency(&mut hbm, 20.0, TWO_PI * 250.0, TWO_PI * 450.0, &options, &mut Silent).unwrap()
    };
    let (dense, structured) = (sweep(false), sweep(true));
    // The sweep passes through states where part of the patch slips: at the largest response
    // some directions, not all, couple harmonics.
    let size = |x: &[f64]| x.iter().map(|v| v * v).sum::<f64>();
    let peak = structured.points.iter().max_by(|a, b| size(&a.x).total_cmp(&size(&b.x))).unwrap();
    let mut hbm = CondensedHbm::new(&model, &force, HbmSettings { harmonics: 5, samples: 256 }).unwrap();
    let mut r = vec![0.0; hbm.dimension()];
    hbm.evaluate_factored(&peak.x, peak.lambda, 20.0, &mut r, None, None).unwrap();
    let coupled = hbm.structured_jacobian().unwrap().coupled_directions();
    assert!(coupled > 0 && coupled < hbm.n_directions(), "{coupled} directions couple harmonics at the peak");
    assert_eq!(dense.termination, structured.termination);
    assert_eq!(dense.points.len(), structured.points.len());
    let mut worst = 0.0_f64;
    for (a, b) in dense.points.iter().zip(&structured.points) {
        let size = a.x.iter().map(|v| v * v).sum::<f64>().sqrt();
        let diff = a.x.iter().zip(&b.x).map(|(u, v)| (u - v).powi(2)).sum::<f64>().sqrt();
        worst = worst.max(diff / size).max((a.lambda - b.lambda).abs() / a.lambda);
    }
    eprintln!("{} points, worst relative difference {worst:e}", dense.points.len());
    assert!(worst < 1e-6, "{worst:e}");
}

/// The factored reduced system (single precision, `StructuredJacobian::factor_reduced`) as the
/// preconditioner: of the Jacobian that formed it, and of the next Jacobian on the same coupled
/// directions. The iterations converge to 1e-12 in double precision whatever the preconditioner:
/// the steps equal the dense LU's as the plain iterative solve's do (1e-8, above), and the
/// earlier factor is kept (it converged, so no factor was formed afresh).
#[test]
fn a_factored_reduced_system_preconditions_this_and_the_next_jacobian() {
    let (model, force) = common::contact_patch(7);
    let mut hbm = CondensedHbm::new(&model, &force, HbmSettings { harmonics: 5, samples: 256 }).unwrap();
    let n = hbm.dimension();
    let (omega, level) = (TWO_PI * 340.0, 1e5);
    let b: Vec<f64> = (0..n).map(|i| ((i * 7919) % 101) as f64 / 50.0 - 1.0).collect();
    let step_error = |hbm: &mut CondensedHbm<'_>, x: &[f64]| {
        let mut r = vec![0.0; n];
        let mut jac = Mat::zeros(n, n);
        hbm.evaluate(x, omega, level, &mut r, Some(Jacobians { dx: jac.as_mut(), domega: None, dlevel: None }))
            .unwrap();
        let dense = jac.partial_piv_lu().solve(Mat::from_fn(n, 1, |i, _| b[i]));
        let mut y = b.clone();
        assert!(hbm.solve_factored(&mut y));
        let diff = (0..n).map(|i| (y[i] - dense[(i, 0)]).powi(2)).sum::<f64>().sqrt();
        diff / (0..n).map(|i| dense[(i, 0)].powi(2)).sum::<f64>().sqrt()
    };
    let x = hbm.linear_solution(omega, level);
    let mut r = vec![0.0; n];
    assert!(hbm.evaluate_factored(&x, omega, level, &mut r, None, None).unwrap());
    let jacobian = hbm.structured_jacobian().unwrap();
    let coupled = jacobian.coupled_directions();
    assert!(coupled * 11 > 1200, "{coupled} directions couple harmonics: not iterative");
    assert!(jacobian.reduced_factor().is_none(), "nothing factored yet");
    jacobian.factor_reduced();
    let factor = jacobian.reduced_factor().expect("factored");
    let own = step_error(&mut hbm, &x);
    // The next iterate: 1 % further along the motion, the same directions slipping.
    let next: Vec<f64> = x.iter().map(|v| 1.01 * v).collect();
    assert!(hbm.evaluate_factored(&next, omega, level, &mut r, None, None).unwrap());
    let jacobian = hbm.structured_jacobian().unwrap();
    assert_eq!(jacobian.coupled_directions(), coupled);
    assert!(jacobian.reduced_factor().is_some(), "the earlier factor is handed on");
    let earlier = step_error(&mut hbm, &next);
    // The earlier factor did precondition the solve (within its 12 iterations): a failure
    // would have factored this Jacobian's own, handed on in its place.
    let handed_on = hbm.structured_jacobian().unwrap().reduced_factor().unwrap();
    assert!(std::sync::Arc::ptr_eq(&factor, &handed_on), "the earlier factor did not converge: refactored");
    println!("{coupled} directions: own factor {own:.1e}, earlier factor {earlier:.1e}");
    assert!(own < 1e-8 && earlier < 1e-8, "own factor {own:e}, earlier factor {earlier:e}");
}
