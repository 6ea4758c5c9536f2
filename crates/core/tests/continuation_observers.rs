//! What the continuation hands its observers at each accepted point ([`Accepted`]): the
//! problem as the converged evaluation left it, the Jacobian there on demand and the test
//! functions of folds and branch points. Checked against evaluating each point again after the
//! branch, the way results were made before: the point's results, its stability and its
//! Jacobian must be the same numbers, the determinant that of that Jacobian, and the branch the
//! same as a silent observer's.
#[path = "../benches/common/mod.rs"]
mod common;

use faer::Mat;
use stickslip_core::continuation::{Accepted, Options, PointObserver, Silent, TerminationReason, TestFunctions};
use stickslip_core::hbm::{
    stability_at, stability_at_last_evaluation, sweep_frequency, CondensedHbm, FrequencySweep, HbmSettings, Hill,
    HillSettings, Jacobians, Stability,
};
use stickslip_core::model::NonlinearModel;
use stickslip_core::post::{evaluate_point, point_result, point_result_with, OutputSelector, PointResult, TimeSeries};

const TWO_PI: f64 = 2.0 * std::f64::consts::PI;

/// Everything an observer takes from each accepted point.
struct Taken<'h> {
    hill: &'h Hill,
    outputs: Vec<OutputSelector>,
    results: Vec<PointResult>,
    /// The same without the time series, as a run makes the points whose time data it does
    /// not keep.
    summaries: Vec<PointResult>,
    stabilities: Vec<Stability>,
    jacobians: Vec<(Mat<f64>, Vec<f64>)>,
    tests: Vec<TestFunctions>,
    fractions: Vec<f64>,
}

impl<'a, 'm> PointObserver<FrequencySweep<'a, 'm>> for Taken<'_> {
    fn on_accepted(&mut self, accepted: &mut Accepted<'_, FrequencySweep<'a, 'm>>) {
        self.fractions.push(accepted.fraction_done());
        // The Jacobian first: it is completed from the converged evaluation.
        let (dx, dl) = accepted.jacobian().unwrap().expect("a dense Jacobian");
        self.jacobians.push((dx.to_owned(), dl.to_vec()));
        self.tests.push(accepted.test_functions().unwrap().expect("a regular point").clone());
        let (x, omega) = (accepted.point().x.clone(), accepted.point().lambda);
        let hbm = &mut *accepted.problem().hbm;
        self.results.push(point_result(hbm, &x, &self.outputs).unwrap());
        self.summaries.push(point_result_with(hbm, &x, &self.outputs, TimeSeries::Skipped).unwrap());
        self.stabilities.push(stability_at_last_evaluation(hbm, self.hill, &x, omega).unwrap());
    }
}

/// The test functions as a run takes them: estimated from the corrector's last factorisation
/// where the point converged on a residual alone.
#[derive(Default)]
struct Estimates(Vec<TestFunctions>);

impl<'a, 'm> PointObserver<FrequencySweep<'a, 'm>> for Estimates {
    fn on_accepted(&mut self, accepted: &mut Accepted<'_, FrequencySweep<'a, 'm>>) {
        self.0.push(accepted.test_functions_estimate().unwrap().expect("a regular point").clone());
    }
}

/// Sweep `model` at `level` with the observer, then evaluate every point again and compare.
fn check(model: &NonlinearModel, force: &[f64], level: f64, band_hz: (f64, f64)) -> usize {
    let settings = HbmSettings { harmonics: 7, samples: 300 };
    let n = model.linear.n_dofs();
    let mut hbm = CondensedHbm::new(model, force, settings).unwrap();
    let hill = Hill::new(hbm.receptance(), HillSettings::for_band(7, TWO_PI * band_hz.1)).unwrap();
    let outputs = vec![OutputSelector { name: "tip".into(), vector: (0..n).map(|i| f64::from(i == n - 1)).collect() }];
    let mut taken = Taken {
        hill: &hill,
        outputs: outputs.clone(),
        results: Vec::new(),
        summaries: Vec::new(),
        stabilities: Vec::new(),
        jacobians: Vec::new(),
        tests: Vec::new(),
        fractions: Vec::new(),
    };
    let (w0, w1) = (TWO_PI * band_hz.0, TWO_PI * band_hz.1);
    let branch = sweep_frequency(&mut hbm, level, w0, w1, &Options::default(), &mut taken).unwrap();
    assert_eq!(branch.termination, TerminationReason::ReachedEnd);
    // What the observer asked for does not change the path.
    let silent = sweep_frequency(&mut hbm, level, w0, w1, &Options::default(), &mut Silent).unwrap();
    assert_eq!(silent.points, branch.points);
    assert_eq!(taken.results.len(), branch.points.len());
    assert!(taken.fractions.windows(2).all(|f| f[0] <= f[1]) && taken.fractions.last() == Some(&1.0));

    // The same points evaluated again, one by one, as a run did before the observers had them.
    let dim = hbm.dimension();
    let mut slips = 0;
    for (i, p) in branch.points.iter().enumerate() {
        let again = evaluate_point(&mut hbm, &p.x, p.lambda, level, &outputs).unwrap();
        let got = &taken.results[i];
        // Bit for bit: the same AFT of the same x at the same Ω, the same recovery.
        assert_eq!(got.outputs[0].coeffs, again.outputs[0].coeffs, "point {i}");
        assert_eq!(got.outputs[0].displacement, again.outputs[0].displacement, "point {i}");
        assert_eq!(got.excitation_work, again.excitation_work, "point {i}");
        for (a, b) in got.elements.iter().zip(&again.elements) {
            assert_eq!(a.energy_per_cycle, b.energy_per_cycle, "point {i}");
            assert_eq!(a.stick_fraction, b.stick_fraction, "point {i}");
            assert_eq!(a.force, b.force, "point {i}");
        }
        slips += usize::from(got.elements.iter().any(|e| e.stick_fraction < 1.0));
        // Without the time series: every other value the same, bit for bit, the series empty
        // (one per element direction).
        let summary = &taken.summaries[i];
        assert_eq!(
            (summary.excitation_work, summary.viscous_dissipation),
            (got.excitation_work, got.viscous_dissipation)
        );
        for (a, b) in summary.outputs.iter().zip(&got.outputs) {
            assert_eq!((&a.coeffs, a.peak), (&b.coeffs, b.peak), "point {i}");
            assert!(a.displacement.is_empty() && a.velocity.is_empty() && !b.velocity.is_empty());
        }
        for (a, b) in summary.elements.iter().zip(&got.elements) {
            assert_eq!((a.energy_per_cycle, a.stick_fraction), (b.energy_per_cycle, b.stick_fraction), "point {i}");
            assert_eq!(a.direction_energy, b.direction_energy, "point {i}");
            assert_eq!(
                (a.displacement.len(), a.force.len(), a.slider_velocity.len()),
                (b.force.len(), b.force.len(), b.force.len())
            );
            assert!(a.displacement.iter().chain(&a.force).chain(&a.slider_velocity).all(Vec::is_empty));
        }

        // The Jacobian completed from the converged residual against a full evaluation: the
        // sliders' closed form from the same slip flags and the same matrices H_k, so the same
        // numbers bit for bit (measured; any reordering of the sums would show here).
        let mut r = vec![0.0; dim];
        let (mut dx, mut dl) = (Mat::<f64>::zeros(dim, dim), vec![0.0; dim]);
        let jacobians = Jacobians { dx: dx.as_mut(), domega: Some(&mut dl), dlevel: None };
        hbm.evaluate(&p.x, p.lambda, level, &mut r, Some(jacobians)).unwrap();
        let (cdx, cdl) = &taken.jacobians[i];
        assert!(dx == *cdx, "point {i}: ∂R/∂x differs");
        assert_eq!(&dl, cdl, "point {i}: ∂R/∂Ω differs");

        // The determinant of the test functions, from the bordered LU (Eq. 1 of
        // `continuation::singular`), against that of the Jacobian, scaled: two LUs of
        // different matrices, so to round-off of their logarithms (measured 7e-16).
        let t = &taken.tests[i];
        let direct = dx.determinant();
        let scaled_ln = direct.abs().ln() + dim as f64 * (t.scales.unknowns / t.scales.residual).ln();
        assert_eq!(t.jacobian.sign, direct.signum(), "point {i}");
        assert!((t.jacobian.ln_abs - scaled_ln).abs() <= 1e-12 * scaled_ln.abs().max(1.0), "point {i}");

        // Stability from the completed joints' Jacobian against one evaluated again: the same
        // matrix, so the same exponents bit for bit.
        let fresh = stability_at(&mut hbm, &hill, &p.x, p.lambda).unwrap();
        assert_eq!(taken.stabilities[i].exponents, fresh.exponents, "point {i}");
    }
    // The sweep crosses stick and slip, where the completion has work to do.
    assert!(slips > 10, "{slips} points slip");

    // The estimates a run takes, one Newton update before the point: the signs of the point's
    // test functions, the tangent to that update's order.
    let mut estimates = Estimates::default();
    let estimated = sweep_frequency(&mut hbm, level, w0, w1, &Options::default(), &mut estimates).unwrap();
    assert_eq!(estimated.points, branch.points);
    let (mut apart, mut estimated_points) = (0.0f64, 0);
    for (i, (e, t)) in estimates.0.iter().zip(&taken.tests).enumerate() {
        assert_eq!(e.bordered.sign, t.bordered.sign, "point {i}");
        assert_eq!(e.lambda_component().signum(), t.lambda_component().signum(), "point {i}");
        let gap = e.tangent.iter().zip(&t.tangent).map(|(a, b)| (a - b) * (a - b)).sum::<f64>().sqrt();
        apart = apart.max(gap);
        estimated_points += usize::from(gap != 0.0);
    }
    // Measured: the unit tangents at most 5.7e-6 (Table 6, 300 N), 5.9e-5 (3000 N) and 5.1e-4
    // (the chain) apart, the update before convergence being that small; asserted 1e-3. Every
    // point but the first ones (factored at the point) is estimated.
    assert!(apart <= 1e-3, "tangents {apart:e} apart");
    assert!(estimated_points + 2 >= branch.points.len(), "{estimated_points} estimated");
    branch.points.len()
}

#[test]
fn observers_get_each_point_as_evaluating_it_again_would_on_table6() {
    for level in [300.0, 3000.0] {
        assert!(check(&common::table6(), &[1.0], level, (150.0, 350.0)) > 30);
    }
}

#[test]
fn observers_get_each_point_as_evaluating_it_again_would_on_a_chain_with_four_joints() {
    let model = common::chain_with_joints(20, 4, false);
    let mut force = vec![0.0; 20];
    force[19] = 1.0;
    // The chain's first mode is near 238 Hz like the paper's (benches/common).
    assert!(check(&model, &force, 2910.0, (170.0, 300.0)) > 30);
}

#[test]
fn a_plain_observer_still_sees_every_point() {
    let settings = HbmSettings { harmonics: 7, samples: 300 };
    let model = common::table6();
    let mut hbm = CondensedHbm::new(&model, &[1.0], settings).unwrap();
    let mut seen = 0;
    let branch =
        sweep_frequency(&mut hbm, 1000.0, TWO_PI * 150.0, TWO_PI * 350.0, &Options::default(), &mut |_: &_, _| {
            seen += 1
        })
        .unwrap();
    assert_eq!(seen, branch.points.len());
    let silent = sweep_frequency(&mut hbm, 1000.0, TWO_PI * 150.0, TWO_PI * 350.0, &Options::default(), &mut Silent);
    assert_eq!(silent.unwrap().points, branch.points);
}
