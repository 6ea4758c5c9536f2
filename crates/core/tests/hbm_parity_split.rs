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
    let model = four_slider_chain();
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

/// The model of [`the_split_jacobian_follows_the_same_branch_as_the_whole_matrix`].
fn four_slider_chain() -> stickslip_core::model::NonlinearModel {
    let n = 12;
    let law = || Box::new(Jenkins::replacing_stiffness(4e5, 15.0).unwrap()) as Box<dyn Element>;
    let laws: Vec<(&str, Box<dyn Element>, Vec<f64>)> = vec![
        ("a", law(), relative_direction(n, 2, Some(3))),
        ("b", law(), relative_direction(n, 5, Some(6))),
        ("c", Box::new(Jenkins::new(2e5, 10.0).unwrap()), relative_direction(n, 8, None)),
        ("d", law(), relative_direction(n, 10, Some(11))),
    ];
    chain(n, Damping::Rayleigh { alpha: 15.0, beta: 1e-6 }, laws)
}

/// Jenkins sliders driven at the fundamental have half-wave symmetric solutions: the balance
/// pins its even harmonics at zero (`R_even = x_even`, the identity in the Jacobian, which
/// the corrector does not factor) and marches the sliders over half a period. Against the
/// same balance with the even harmonics solved (split by parity, as before pinning): the same
/// points, Newton iterations and rejected steps, frequencies within 1e-12 and states within
/// 1e-12 of their largest (the even harmonics solved are round-off, ~1e-16 of the motion, and
/// the two AFTs' transforms round differently: round-off of the Newton steps, whose last is
/// at the tolerance; measured 9.2e-16), the even harmonics of every pinned point exactly zero
/// and the reference's below 1e-12 of the largest.
#[test]
fn pinned_even_harmonics_follow_the_same_branch_as_solved_ones() {
    let model = four_slider_chain();
    let mut force = vec![0.0; 12];
    force[0] = 1.0;
    let settings = HbmSettings { harmonics: 7, samples: 300 };
    let f1 = model.linear.dense_modes().unwrap().omega[0] / TWO_PI;
    let (w0, w1) = (TWO_PI * 0.8 * f1, TWO_PI * 1.2 * f1);
    let level = 150.0;
    let mut pinned = CondensedHbm::new(&model, &force, settings).unwrap();
    assert!(pinned.pins_even_harmonics());
    let with = sweep_frequency(&mut pinned, level, w0, w1, &Options::default(), &mut Silent).unwrap();
    assert!(pinned.pins_even_harmonics() && pinned.decoupled_block_is_identity(), "pinning was given up");
    let mut solved = CondensedHbm::new(&model, &force, settings).unwrap().without_pinned_even_harmonics();
    let without = sweep_frequency(&mut solved, level, w0, w1, &Options::default(), &mut Silent).unwrap();
    assert!(solved.decoupled_unknowns().is_some() && !solved.decoupled_block_is_identity());
    assert_eq!(with.termination, TerminationReason::ReachedEnd);
    assert_eq!(with.points.len(), without.points.len());
    let even = pinned.decoupled_unknowns().unwrap().to_vec();
    let largest = without.points.iter().flat_map(|p| p.x.iter()).fold(0.0_f64, |m, v| m.max(v.abs()));
    let mut worst = 0.0_f64;
    for (a, b) in with.points.iter().zip(&without.points) {
        assert_eq!((a.iterations, a.rejected), (b.iterations, b.rejected), "at {} rad/s", b.lambda);
        assert!((a.lambda - b.lambda).abs() <= 1e-12 * b.lambda, "{} against {}", a.lambda, b.lambda);
        let apart = a.x.iter().zip(&b.x).map(|(u, v)| (u - v).abs()).fold(0.0, f64::max);
        worst = worst.max(apart / largest);
        assert!(apart <= 1e-12 * largest, "at {} rad/s: {apart:e} of {largest:e}", b.lambda);
        assert!(even.iter().all(|&i| a.x[i] == 0.0), "a pinned harmonic moved at {} rad/s", a.lambda);
        assert!(even.iter().all(|&i| b.x[i].abs() <= 1e-12 * largest));
    }
    println!("{} points, states apart by at most {worst:.1e} of the largest", with.points.len());
}

/// A motion with an even harmonic (a static offset that makes a slider slip one way more than
/// the other: a guess that is not half-wave symmetric) ends the pinning for good, and the
/// residual there is the whole balance's, bit for bit; a symmetric motion where the sliders
/// slip keeps it.
#[test]
fn an_unsymmetric_motion_ends_the_pinning() {
    let model = four_slider_chain();
    let mut force = vec![0.0; 12];
    force[0] = 1.0;
    let settings = HbmSettings { harmonics: 7, samples: 300 };
    let mut pinned = CondensedHbm::new(&model, &force, settings).unwrap();
    let mut solved = CondensedHbm::new(&model, &force, settings).unwrap().without_pinned_even_harmonics();
    let omega = TWO_PI * 0.9 * model.linear.dense_modes().unwrap().omega[0] / TWO_PI;
    let mut x = pinned.linear_solution(omega, 150.0);
    let n = x.len();
    let (mut r_pinned, mut r_solved) = (vec![0.0; n], vec![0.0; n]);
    pinned.evaluate(&x, omega, 150.0, &mut r_pinned, None).unwrap();
    assert!(pinned.pins_even_harmonics());
    // The first slider slipping both ways (k A = 4e5 × 1e-4 m, against 2 F_c = 30 N), its
    // mean half its amplitude.
    let scale = 1e-4 / x[4].hypot(x[8]);
    x.iter_mut().for_each(|v| *v *= scale);
    pinned.evaluate(&x, omega, 150.0, &mut r_pinned, None).unwrap();
    assert!(pinned.pins_even_harmonics(), "a symmetric slip ended the pinning");
    x[0] = 0.5e-4;
    pinned.evaluate(&x, omega, 150.0, &mut r_pinned, None).unwrap();
    solved.evaluate(&x, omega, 150.0, &mut r_solved, None).unwrap();
    assert!(!pinned.pins_even_harmonics(), "the pinning was kept");
    assert_eq!(r_pinned, r_solved);
    x[0] = 0.0;
    pinned.evaluate(&x, omega, 150.0, &mut r_pinned, None).unwrap();
    assert!(!pinned.pins_even_harmonics(), "the pinning came back");
}
