//! Time integration with the other element laws: Iwan (several history variables) and the
//! regularised Coulomb damper (velocity-dependent, exercising the ∂g/∂v part of the tangent).
mod timesim_common;

use faer::Mat;
use stickslip_core::elements::{Element, Iwan, RegularizedCoulomb};
use stickslip_core::model::{Damping, DofLabel, ElementSite, LinearModel, Matrix, NonlinearModel};
use stickslip_core::timesim::{steady_state, SteadyState, SteadyStateOptions};
use timesim_common::*;

/// The Table 6 oscillator with another law on its DOF.
fn table6_with(law: Box<dyn Element>) -> NonlinearModel {
    let one = |x: f64| Matrix::Dense(Mat::from_fn(1, 1, |_, _| x));
    let linear =
        LinearModel::new(one(MASS), one(K_TOTAL), Damping::Matrix(one(DAMPING)), vec![DofLabel::named("x")], vec![])
            .unwrap();
    NonlinearModel::new(linear, vec![ElementSite { name: "joint".into(), law, directions: vec![vec![1.0]] }]).unwrap()
}

fn run(model: &NonlinearModel, f: f64, p: usize) -> SteadyState {
    let mut o = SteadyStateOptions::new(f, vec![F_EXCIT]);
    o.steps_per_period = p;
    o.harmonics = 3;
    o.tolerance = 1e-10;
    o.record_dofs = vec![0];
    steady_state(model, &o).unwrap()
}

#[test]
fn iwan_loop_dissipation_is_the_sum_of_its_masing_sliders() {
    // Five sliders sharing k_J, thresholds spread up to a gross-slip force of 1000 N. Each
    // slider is a Jenkins element seeing the same displacement, so with one maximum and one
    // minimum per cycle the element dissipates Σ_i 4 F_i (a − F_i/k_i) over the sliders that
    // slip (k_i a > F_i). Tolerance as for the Jenkins loop: the sampled extremes at 512 steps
    // per period are within 2e-5 a of the true ones, amplified at most ~5 times by the
    // slider closest to its threshold: 5e-4.
    let iwan = Iwan::uniform(K_JENKINS, F_COULOMB, 5).unwrap().replacing_stiffness();
    let model = table6_with(Box::new(iwan));
    for f in [215.0, 238.0] {
        let s = run(&model, f, 512);
        let u = &s.records.elements.displacement[0];
        let a = 0.5 * (u.iter().copied().fold(f64::MIN, f64::max) - u.iter().copied().fold(f64::MAX, f64::min));
        let expected: f64 =
            (1..=5).map(|i| jenkins_dissipation(K_JENKINS / 5.0, F_COULOMB * 2.0 * i as f64 / 30.0, a)).sum();
        let w = s.energy.elements[0];
        assert!(expected > 0.0 && (w - expected).abs() < 5e-4 * expected, "{f} Hz: {w} vs {expected}");
        // The energy identity holds whatever the law (see the friction tests): 1e-8.
        assert!((s.energy.input - s.energy.dissipated()).abs() < 1e-8 * s.energy.input);
    }
}

#[test]
fn velocity_dependent_law_conserves_energy_and_converges_at_second_order() {
    // g = 300 N · tanh(u̇ / 0.05 m/s): smooth, velocity dependent, so the Newton tangent is
    // the c1 ∂g/∂v term alone. A smooth problem: second order, ratios 4 ± 0.5 against a
    // P = 2048 reference (which carries 1/16 of the P = 512 error).
    let model = table6_with(Box::new(RegularizedCoulomb::new(300.0, 0.05).unwrap()));
    let f = 238.0;
    let reference = run(&model, f, 2048);
    let cr = SteadyState::harmonics(&reference.records.displacement[0], 3).unwrap();
    let a_ref = cr[1].hypot(cr[2]);
    let mut errors = Vec::new();
    for p in [128, 256, 512] {
        let s = run(&model, f, p);
        // Energy identity of average acceleration: 1e-8 (periodicity 1e-10).
        assert!((s.energy.input - s.energy.dissipated()).abs() < 1e-8 * s.energy.input);
        // The damper dissipates: its work over the cycle is positive and a visible share.
        assert!(s.energy.elements[0] > 0.1 * s.energy.input);
        let c = SteadyState::harmonics(&s.records.displacement[0], 3).unwrap();
        errors.push((c[1] - cr[1]).hypot(c[2] - cr[2]) / a_ref);
    }
    for w in errors.windows(2) {
        let ratio = w[0] / w[1];
        assert!((3.5..4.6).contains(&ratio), "ratio {ratio} ({errors:?})");
    }
}
