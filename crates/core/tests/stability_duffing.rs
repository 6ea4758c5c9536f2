//! Hill's method on a Duffing oscillator: the middle branch between the folds is unstable, the
//! Floquet multipliers equal those of the monodromy matrix integrated in time, and the folds
//! found from the continuation's tangent are where the leading exponent crosses zero.
mod duffing_common;

use duffing_common::{duffing, C, F, K, K3, M};
use faer::c64;
use stickslip_core::continuation::{
    zero_along, Accepted, Options, PointObserver, Problem, Silent, TerminationReason, TestFunctions,
};
use stickslip_core::hbm::fourier::{cos_index, sin_index};
use stickslip_core::hbm::{
    floquet_bifurcations, folds_and_branch_points, stability_at, sweep_frequency, BifurcationKind, CondensedHbm,
    FrequencySweep, HbmSettings, Hill, HillSettings,
};

const HARMONICS: usize = 7;

/// x(t) from the harmonics (1 DOF, coefficient-major).
fn displacement(x: &[f64], omega: f64, t: f64) -> f64 {
    let mut u = x[0];
    for k in 1..=HARMONICS {
        let (c, s) = (x[cos_index(k)], x[sin_index(k)]);
        u += c * (k as f64 * omega * t).cos() + s * (k as f64 * omega * t).sin();
    }
    u
}

/// Floquet multipliers from the monodromy matrix of the variational equation
/// `ÿ + c ẏ + (k + 3 k3 x(t)²) y = 0`, integrated over one period by classical Runge-Kutta.
fn monodromy_multipliers(x: &[f64], omega: f64) -> [c64; 2] {
    let period = 2.0 * std::f64::consts::PI / omega;
    let steps = 20_000;
    let h = period / steps as f64;
    let rhs = |t: f64, y: [f64; 2]| {
        let u = displacement(x, omega, t);
        [y[1], -(C * y[1] + (K + 3.0 * K3 * u * u) * y[0]) / M]
    };
    let mut columns = [[1.0, 0.0], [0.0, 1.0]];
    for y in columns.iter_mut() {
        for i in 0..steps {
            let t = i as f64 * h;
            let k1 = rhs(t, *y);
            let k2 = rhs(t + h / 2.0, [y[0] + h / 2.0 * k1[0], y[1] + h / 2.0 * k1[1]]);
            let k3 = rhs(t + h / 2.0, [y[0] + h / 2.0 * k2[0], y[1] + h / 2.0 * k2[1]]);
            let k4 = rhs(t + h, [y[0] + h * k3[0], y[1] + h * k3[1]]);
            for j in 0..2 {
                y[j] += h / 6.0 * (k1[j] + 2.0 * k2[j] + 2.0 * k3[j] + k4[j]);
            }
        }
    }
    // Eigenvalues of [[a, b], [c, d]] with columns the integrated unit states.
    let (a, b, c, d) = (columns[0][0], columns[1][0], columns[0][1], columns[1][1]);
    let (tr, det) = (a + d, a * d - b * c);
    let disc = c64::new(tr * tr / 4.0 - det, 0.0).sqrt();
    [c64::new(tr / 2.0, 0.0) + disc, c64::new(tr / 2.0, 0.0) - disc]
}

#[test]
fn the_middle_branch_is_unstable_and_hill_matches_the_monodromy_matrix() {
    let model = duffing();
    let settings = HbmSettings { harmonics: HARMONICS, samples: 64 };
    let mut hbm = CondensedHbm::new(&model, &[1.0], settings).unwrap();
    let branch = sweep_frequency(&mut hbm, F, 50.0, 250.0, &Options::default(), &mut Silent).unwrap();
    assert_eq!(branch.termination, TerminationReason::ReachedEnd);
    let hill = Hill::new(hbm.receptance(), HillSettings::for_band(HARMONICS, 250.0)).unwrap();
    let points = &branch.points;
    let mut checked = [0, 0];
    for (i, p) in points.iter().enumerate() {
        let jac = hbm.element_force_jacobian(&p.x, p.lambda).unwrap();
        let stability = hill.exponents(p.lambda, jac.as_ref()).unwrap();
        assert_eq!(stability.exponents.len(), 2);
        // Between the folds the branch runs backwards in Ω: there, and only there, unstable.
        // Points within one step of a fold are left out (the exponent is near zero there).
        let backwards = |j: usize| points[j + 1].lambda < points[j].lambda;
        if i == 0 || i + 1 >= points.len() || backwards(i - 1) != backwards(i) {
            continue;
        }
        let tolerance = 1e-9 * p.lambda;
        assert_eq!(
            stability.is_stable(tolerance),
            !backwards(i),
            "Ω = {}: leading exponent {} on a branch going {}",
            p.lambda,
            stability.leading(),
            if backwards(i) { "backwards" } else { "forwards" }
        );
        // Multipliers against the monodromy matrix at every 4th point, stable and unstable.
        if i % 4 == 0 {
            let hill_mu = stability.multipliers(p.lambda);
            let mono = monodromy_multipliers(&p.x, p.lambda);
            for mu in &mono {
                let nearest = hill_mu.iter().map(|h| (h - mu).norm()).fold(f64::INFINITY, f64::min);
                // Runge-Kutta with 20,000 steps per period is accurate to ~1e-12; the harmonic
                // truncation (N = 7) of a Duffing solution whose harmonics fall by ~1e-2 each
                // is far below 1e-3, the asserted agreement.
                assert!(nearest < 1e-3 * mu.norm().max(1e-3), "Ω = {}: monodromy {mu}, Hill {hill_mu:?}", p.lambda);
            }
            checked[usize::from(backwards(i))] += 1;
        }
    }
    assert!(checked[0] >= 3 && checked[1] >= 1, "points compared (stable, unstable): {checked:?}");
}

/// Keeps the test functions of every accepted point.
#[derive(Default)]
struct Tests(Vec<Option<TestFunctions>>);

impl<P: Problem + ?Sized> PointObserver<P> for Tests {
    fn on_accepted(&mut self, accepted: &mut Accepted<'_, P>) {
        self.0.push(accepted.test_functions().unwrap().cloned());
    }
}

#[test]
fn the_folds_from_the_tangent_are_where_the_leading_exponent_crosses_zero() {
    let model = duffing();
    let settings = HbmSettings { harmonics: HARMONICS, samples: 64 };
    let mut hbm = CondensedHbm::new(&model, &[1.0], settings).unwrap();
    let mut tests = Tests::default();
    let branch = sweep_frequency(&mut hbm, F, 50.0, 250.0, &Options::default(), &mut tests).unwrap();
    let points = &branch.points;
    // Without any stability: the tangent's Ω-component changes sign at each fold.
    let found = folds_and_branch_points(&mut FrequencySweep { hbm: &mut hbm, level: F }, points, &tests.0, 1e-10);
    let kinds: Vec<_> = found.iter().map(|b| b.kind).collect();
    assert_eq!(kinds, [BifurcationKind::Fold, BifurcationKind::Fold], "{found:?}");
    // Hill's method, independently: the leading exponent crosses zero at each, located along
    // the same segment of the branch.
    let hill = Hill::new(hbm.receptance(), HillSettings::for_band(HARMONICS, 250.0)).unwrap();
    for b in &found {
        assert!(b.located);
        let pair = [&points[b.after_point], &points[b.after_point + 1]];
        let by_hill = zero_along(&mut FrequencySweep { hbm: &mut hbm, level: F }, pair, 1e-10, |p, x, w| {
            Ok(stability_at(p.hbm, &hill, x, w).unwrap().leading().re)
        })
        .unwrap();
        // Both are located to round-off on their own measure (1e-10 of the chord): measured
        // 4e-16 and 0 apart, asserted to 1e-9 (1e-6 of the fold frequency is the criterion). Hill's
        // matrix at s = 0 is the balance's Jacobian in dynamic-stiffness form, and this
        // oscillator has no mode left out of it: the two are singular together.
        let relative = (b.omega - by_hill.lambda).abs() / by_hill.lambda;
        assert!(
            relative < 1e-9,
            "fold at {} rad/s from the tangent, {} by Hill ({relative:.1e})",
            b.omega,
            by_hill.lambda
        );
        let exponent = stability_at(&mut hbm, &hill, &b.x, b.omega).unwrap().leading();
        assert!(exponent.norm() < 1e-6 * b.omega, "{exponent}");
    }
    // With the stability known, the exponents add no bifurcation (their crossings are real).
    let stabilities: Vec<_> = points.iter().map(|p| stability_at(&mut hbm, &hill, &p.x, p.lambda).unwrap()).collect();
    assert!(floquet_bifurcations(&mut hbm, &hill, F, points, &stabilities, 1e-10).is_empty());
}
