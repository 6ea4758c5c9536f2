//! A symmetry-breaking branch point of a forced response, found by the continuation's
//! bordered determinant ([`folds_and_branch_points`]) and checked against Hill's exponents and
//! a closed form.
//!
//! Two identical Duffing oscillators (`m ẍᵢ + c ẋᵢ + k3 xᵢ³ + ...` to the ground), coupled so
//! that their out-of-phase mode (K = [[9000, 1000], [1000, 9000]] N/m: 14.2 Hz) lies below the
//! in-phase one (15.9 Hz), are driven in phase. The in-phase response hardens through the
//! out-of-phase mode's frequency, which hardens twice as fast (averaged over the period, the
//! cubic springs add `0.75 k3 A²` to the in-phase stiffness and `1.5 k3 A²` to that of an
//! out-of-phase perturbation): a 1:1 internal resonance, where the in-phase motion loses
//! stability to a localised one. The out-of-phase part of the Jacobian becomes singular there
//! while the in-phase part is not: a branch point (a pitchfork, by the symmetry), where the
//! in-phase branch goes on in the same direction.
//!
//! To first order (x = A cos θ in both, perturbation y = x₁ − x₂ = p cos θ + q sin θ, θ the
//! phase of the response) the in-phase branch is `((k − mΩ² + ¾ k3 A²)² + (cΩ)²) A² = F²`
//! and the perturbation's balance
//!
//! ```text
//! [ k + 2kc − mΩ² + 9/4 k3 A²      c Ω                 ] [p]
//! [ −c Ω                           k + 2kc − mΩ² + ¾ k3 A² ] [q] = 0
//! ```
//!
//! (`3 k3 x² y` projected on cos θ and sin θ), singular where its determinant vanishes.
use faer::linalg::solvers::Solve;
use faer::Mat;
use stickslip_core::continuation::{zero_along, Accepted, Options, PointObserver, Problem, TestFunctions};
use stickslip_core::elements::{CubicSpring, Element};
use stickslip_core::hbm::bifurcation::is_stable;
use stickslip_core::hbm::{
    floquet_bifurcations, folds_and_branch_points, stability_at, sweep_frequency, BifurcationKind, CondensedHbm,
    FrequencySweep, HbmSettings, Hill, HillSettings, Jacobians,
};
use stickslip_core::model::{Damping, DofLabel, ElementSite, LinearModel, Matrix, NonlinearModel};

const M: f64 = 1.0;
const K: f64 = 1.0e4;
/// Negative: the out-of-phase mode is the lower one.
const KC: f64 = -1.0e3;
const C: f64 = 2.0;
const K3: f64 = 1.0e7;
const F: f64 = 5.0;
const HARMONICS: usize = 7;

/// Keeps the test functions of every accepted point.
#[derive(Default)]
struct Tests(Vec<Option<TestFunctions>>);

impl<P: Problem + ?Sized> PointObserver<P> for Tests {
    fn on_accepted(&mut self, accepted: &mut Accepted<'_, P>) {
        self.0.push(accepted.test_functions().unwrap().cloned());
    }
}

fn coupled_pair() -> NonlinearModel {
    let linear = LinearModel::new(
        Matrix::Dense(Mat::from_fn(2, 2, |i, j| if i == j { M } else { 0.0 })),
        Matrix::Dense(Mat::from_fn(2, 2, |i, j| if i == j { K + KC } else { -KC })),
        Damping::Rayleigh { alpha: C / M, beta: 0.0 },
        vec![DofLabel::named("x1"), DofLabel::named("x2")],
        vec![],
    )
    .unwrap();
    let spring = |i: usize| {
        let law: Box<dyn Element> = Box::new(CubicSpring::new(K3).unwrap());
        ElementSite {
            name: format!("k3_{i}"),
            law,
            directions: vec![vec![f64::from(u8::from(i == 0)), f64::from(u8::from(i == 1))]],
        }
    };
    NonlinearModel::new(linear, vec![spring(0), spring(1)]).unwrap()
}

/// The first-order branch points (module documentation): Ω (rad/s) on the in-phase branch
/// below the backbone (`lower`, the resonant branch) or above it (the middle branch).
fn first_order_branch_point(lower: bool) -> f64 {
    // mΩ² at amplitude A on the branch, from the quadratic in mΩ².
    let omega2 = |a: f64| {
        let (b, r) = (K + 0.75 * K3 * a * a, (F / a).powi(2));
        let (p, q) = (2.0 * b - C * C / M, b * b - r);
        let root = (p * p - 4.0 * q).sqrt();
        (if lower { 0.5 * (p - root) } else { 0.5 * (p + root) }) / M
    };
    let det = |a: f64| {
        let w2 = omega2(a);
        let base = K + 2.0 * KC - M * w2;
        (base + 2.25 * K3 * a * a) * (base + 0.75 * K3 * a * a) + C * C * w2
    };
    // Where the two first-order branches exist (the quadratic has real roots) the determinant
    // changes sign once on each, between 5 and 20 mm.
    let (mut lo, mut hi) = (5e-3, 2e-2);
    assert!(det(lo) * det(hi) < 0.0);
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if det(mid) * det(lo) > 0.0 {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    omega2(lo).sqrt()
}

#[test]
fn the_in_phase_response_of_two_coupled_oscillators_breaks_its_symmetry_at_a_branch_point() {
    let model = coupled_pair();
    let settings = HbmSettings { harmonics: HARMONICS, samples: 64 };
    let mut hbm = CondensedHbm::new(&model, &[1.0, 1.0], settings).unwrap();
    let mut tests = Tests::default();
    let branch = sweep_frequency(&mut hbm, F, 50.0, 250.0, &Options::default(), &mut tests).unwrap();
    let points = &branch.points;
    let found = folds_and_branch_points(&mut FrequencySweep { hbm: &mut hbm, level: F }, points, &tests.0, 1e-10);
    let kinds: Vec<_> = found.iter().map(|b| b.kind).collect();
    // Up the resonant branch: symmetry lost, then the peak's fold; back along the middle
    // branch: symmetry regained, then the lower fold.
    use BifurcationKind::{BranchPoint, Fold};
    assert_eq!(kinds, [BranchPoint, Fold, BranchPoint, Fold], "{found:?}");
    assert!(found.iter().all(|b| b.located && b.exponent.is_none()));

    let hill = Hill::new(hbm.receptance(), HillSettings::for_band(HARMONICS, 250.0)).unwrap();
    for (b, lower) in [(&found[0], true), (&found[2], false)] {
        let (i, j) = (b.after_point, b.after_point + 1);
        let (t0, t1) = (tests.0[i].as_ref().unwrap(), tests.0[j].as_ref().unwrap());
        // The branch goes on in the same direction through it, and det ∂R/∂x changes sign
        // with the bordered determinant.
        assert!(t0.lambda_component() * t1.lambda_component() > 0.0);
        assert!(t0.jacobian.sign * t1.jacobian.sign < 0.0 && t0.bordered.sign * t1.bordered.sign < 0.0);

        // Hill: a real exponent is zero there. Located to 1e-6 of a step of ~0.5 rad/s, where
        // the exponent moves by ~2 1/s per rad/s: measured 1e-9 and 7e-9 1/s.
        let stability = stability_at(&mut hbm, &hill, &b.x, b.omega).unwrap();
        let crossing = stability.exponents.iter().min_by(|a, c| a.norm().total_cmp(&c.norm())).unwrap();
        assert!(crossing.norm() <= 1e-7 * b.omega && crossing.im == 0.0, "{crossing} at {} rad/s", b.omega);

        // The null vector of ∂R/∂x there is out of phase: x₁ = −x₂ in every coefficient (the
        // coefficients of the two springs alternate). Two steps of inverse iteration from a
        // vector with both parts, each dividing the other directions by the ratio of the two
        // smallest singular values. The in-phase part left (measured 1e-6 and 2e-5) is the
        // point's own asymmetry: Newton resolves the branch only to ~1e-8 of its scale across
        // the other branch there (x₁ and x₂ differ by 7e-7 of themselves at the first).
        let n = b.x.len();
        let (mut r, mut jacobian) = (vec![0.0; n], Mat::zeros(n, n));
        let jacobians = Jacobians { dx: jacobian.as_mut(), domega: None, dlevel: None };
        hbm.evaluate(&b.x, b.omega, F, &mut r, Some(jacobians)).unwrap();
        let lu = jacobian.partial_piv_lu();
        let start = Mat::from_fn(n, 1, |i, _| 1.0 + 0.1 * i as f64);
        let once = lu.solve(&start);
        let null = lu.solve(&(&once * faer::Scale(1.0 / once.norm_l2())));
        let in_phase: f64 = (0..n / 2).map(|c| (null[(2 * c, 0)] + null[(2 * c + 1, 0)]).powi(2)).sum::<f64>().sqrt();
        let norm: f64 = (0..n).map(|i| null[(i, 0)].powi(2)).sum::<f64>().sqrt();
        assert!(in_phase <= 1e-3 * norm, "in-phase part {:.1e} of the null vector", in_phase / norm);

        // The first-order closed form, to the harmonics it leaves out (measured 3e-4, 1e-4).
        let closed = first_order_branch_point(lower);
        assert!((b.omega - closed).abs() <= 1e-3 * closed, "{} rad/s, first order {closed}", b.omega);
    }

    // Where the in-phase motion loses stability (the resonant branch, stable before it): the
    // branch point is where Hill's leading exponent crosses zero, located independently.
    let b = &found[0];
    let (p0, p1) = (&points[b.after_point], &points[b.after_point + 1]);
    let stable = |p: &stickslip_core::continuation::Point, hbm: &mut CondensedHbm<'_>| {
        is_stable(&stability_at(hbm, &hill, &p.x, p.lambda).unwrap(), p.lambda)
    };
    assert!(stable(p0, &mut hbm) && !stable(p1, &mut hbm));
    let by_hill = zero_along(&mut FrequencySweep { hbm: &mut hbm, level: F }, [p0, p1], 1e-10, |p, x, w| {
        Ok(stability_at(p.hbm, &hill, x, w).unwrap().leading().re)
    })
    .unwrap();
    // Both located to 1e-6 of a step of ~0.5 rad/s at least, 5e-9 of Ω (measured 3e-12).
    let relative = (b.omega - by_hill.lambda).abs() / by_hill.lambda;
    assert!(
        relative <= 1e-8,
        "branch point at {} rad/s, Hill's exponent zero at {} ({relative:.1e})",
        b.omega,
        by_hill.lambda
    );

    // With the stability known, the exponents add no bifurcation: every crossing is real.
    let stabilities: Vec<_> = points.iter().map(|p| stability_at(&mut hbm, &hill, &p.x, p.lambda).unwrap()).collect();
    assert!(floquet_bifurcations(&mut hbm, &hill, F, points, &stabilities, 1e-10).is_empty());
}
