//! A half-wave symmetric balance (sliders driven at the fundamental) has a Jacobian block
//! diagonal in its even and odd harmonics, which the corrector factors apart: the same branch
//! as with the whole matrix.
mod hbm_support;

use hbm_support::*;
use stickslip_core::continuation::{Options, Silent, TerminationReason};
use stickslip_core::elements::{Element, Jenkins};
use stickslip_core::hbm::{sweep_frequency, CondensedHbm, HbmSettings};
use stickslip_core::model::{relative_direction, Damping};
use stickslip_core::post::{evaluate_point, OutputSelector};

const TWO_PI: f64 = 2.0 * std::f64::consts::PI;

/// A 12-DOF chain with four sliders, N = 7 (60 unknowns, as the paper-size model), swept
/// across its first resonance at a level where the sliders stick and slip. Split and whole,
/// the same points, Newton iterations and rejected steps; the states within 1e-12 of their
/// largest (the split leaves out Jacobian terms below 1e-12 of the joints' and changes the
/// order of the LU's operations: round-off of the Newton steps, whose last is at the
/// tolerance); and the split is taken at every Jacobian, or the test would compare the whole
/// matrix with itself.
#[test]
fn the_split_jacobian_follows_the_same_branch_as_the_whole_matrix() {
    let n = 12;
    let law = || Box::new(Jenkins::replacing_stiffness(4e5, 15.0).unwrap()) as Box<dyn Element>;
    let laws: Vec<(&str, Box<dyn Element>, Vec<f64>)> = vec![
        ("a", law(), relative_direction(n, 2, Some(3))),
        ("b", law(), relative_direction(n, 5, Some(6))),
        ("c", Box::new(Jenkins::new(2e5, 10.0).unwrap()), relative_direction(n, 8, None)),
        ("d", law(), relative_direction(n, 10, Some(11))),
    ];
    let model = chain(n, Damping::Rayleigh { alpha: 15.0, beta: 1e-6 }, laws);
    let mut force = vec![0.0; n];
    force[0] = 1.0;
    let settings = HbmSettings { harmonics: 7, samples: 300 };
    let f1 = model.linear.dense_modes().unwrap().omega[0] / TWO_PI;
    let (w0, w1) = (TWO_PI * 0.8 * f1, TWO_PI * 1.2 * f1);
    let level = 150.0;
    let mut split = CondensedHbm::new(&model, &force, settings).unwrap();
    assert_eq!(split.dimension(), 60);
    let with = sweep_frequency(&mut split, level, w0, w1, &Options::default(), &mut Silent).unwrap();
    assert!(split.decoupled_unknowns().is_some_and(|even| even.len() == 4 * 7), "the split was not taken");
    let mut whole = CondensedHbm::new(&model, &force, settings).unwrap().without_parity_split();
    let without = sweep_frequency(&mut whole, level, w0, w1, &Options::default(), &mut Silent).unwrap();
    assert!(whole.decoupled_unknowns().is_none());
    assert_eq!(with.termination, TerminationReason::ReachedEnd);
    assert_eq!(with.points.len(), without.points.len());
    assert!(with.points.len() > 30, "{} points", with.points.len());
    let largest = without.points.iter().flat_map(|p| p.x.iter()).fold(0.0_f64, |m, v| m.max(v.abs()));
    for (a, b) in with.points.iter().zip(&without.points) {
        assert_eq!((a.iterations, a.rejected), (b.iterations, b.rejected), "at {} rad/s", b.lambda);
        assert!((a.lambda - b.lambda).abs() <= 1e-12 * b.lambda, "{} against {}", a.lambda, b.lambda);
        let apart = a.x.iter().zip(&b.x).map(|(u, v)| (u - v).abs()).fold(0.0, f64::max);
        assert!(apart <= 1e-12 * largest, "at {} rad/s: {apart:e} of {largest:e}", b.lambda);
    }
    // The sliders slip at the peak (otherwise the split would only be tested on linear
    // algebra: stuck sliders are affine in x).
    let peak = with
        .points
        .iter()
        .max_by(|a, b| a.x[4..].iter().map(|v| v.abs()).sum::<f64>().total_cmp(&b.x[4..].iter().map(|v| v.abs()).sum()))
        .unwrap();
    let tip = vec![OutputSelector { name: "tip".into(), vector: relative_direction(n, n - 1, None) }];
    let at_peak = evaluate_point(&mut split, &peak.x, peak.lambda, level, &tip).unwrap();
    let stick: Vec<f64> = at_peak.elements.iter().map(|e| e.stick_fraction).collect();
    assert!(stick.iter().filter(|&&s| s < 0.9).count() >= 2, "stick fractions at the peak {stick:?}");
}
