//! Bad input to the time integration gives typed errors that say what to change.
mod timesim_common;

use faer::Mat;
use stickslip_core::model::{Damping, DofLabel, LinearModel, Matrix, NonlinearModel};
use stickslip_core::timesim::{
    steady_state, swept_sine, Integrator, Scheme, SteadyStateOptions, SweepOptions, TimesimError,
};
use timesim_common::*;

#[test]
fn non_positive_or_non_finite_step_is_rejected() {
    let model = table6();
    for h in [0.0, -1e-5, f64::NAN, f64::INFINITY] {
        let err = Integrator::new(&model, Scheme::AverageAcceleration, h).unwrap_err();
        assert!(matches!(err, TimesimError::InvalidStep(_)), "{err}");
        assert!(err.to_string().contains("> 0 s"));
    }
}

#[test]
fn too_few_steps_for_the_requested_harmonics() {
    let model = table6();
    let mut o = SteadyStateOptions::new(238.0, vec![F_EXCIT]);
    o.harmonics = 7;
    o.steps_per_period = 64;
    let err = steady_state(&model, &o).unwrap_err();
    assert_eq!(err, TimesimError::TooFewSteps { steps_per_period: 64, harmonics: 7, min: 70 });
    assert!(err.to_string().contains("at least 70"));
    let mut s = SweepOptions::new(200.0, 260.0, 10.0, vec![F_EXCIT]);
    s.harmonics = 5;
    s.steps_per_period = 20;
    assert!(matches!(swept_sine(&model, &s).unwrap_err(), TimesimError::TooFewSteps { min: 50, .. }));
}

#[test]
fn singular_mass_matrix_is_rejected() {
    // Second DOF massless: M is singular, the initial acceleration does not exist.
    let m = Mat::from_fn(2, 2, |i, j| if i == 0 && j == 0 { 1.0 } else { 0.0 });
    let k = Mat::from_fn(2, 2, |i, j| if i == j { 2.0e6 } else { -1.0e6 });
    let linear = LinearModel::new(
        Matrix::Dense(m),
        Matrix::Dense(k),
        Damping::Rayleigh { alpha: 1.0, beta: 0.0 },
        vec![DofLabel::named("a"), DofLabel::named("b")],
        vec![],
    )
    .unwrap();
    let model = NonlinearModel::new(linear, vec![]).unwrap();
    let err = steady_state(&model, &SteadyStateOptions::new(100.0, vec![1.0, 0.0])).unwrap_err();
    assert_eq!(err, TimesimError::SingularMass);
    assert!(err.to_string().contains("give every DOF mass"));
}

#[test]
fn other_bad_input() {
    let model = table6();
    // HHT α outside [−1/3, 0].
    let err = Integrator::new(&model, Scheme::Hht { alpha: 0.2 }, 1e-5).unwrap_err();
    assert!(err.to_string().contains("[-1/3, 0]"), "{err}");
    // Load of the wrong length.
    let err = steady_state(&model, &SteadyStateOptions::new(238.0, vec![1.0, 2.0])).unwrap_err();
    assert!(matches!(err, TimesimError::WrongLength { len: 2, expected: 1, .. }), "{err}");
    // Recorded DOF out of range.
    let mut o = SteadyStateOptions::new(238.0, vec![F_EXCIT]);
    o.record_dofs = vec![3];
    assert_eq!(steady_state(&model, &o).unwrap_err(), TimesimError::DofOutOfRange { index: 3, n_dofs: 1 });
    // Not periodic within the allowed periods: says so with the criterion reached.
    let mut o = SteadyStateOptions::new(238.0, vec![F_EXCIT]);
    o.max_periods = 3;
    let err = steady_state(&model, &o).unwrap_err();
    assert!(matches!(err, TimesimError::NotPeriodic { periods: 3, .. }), "{err}");
    // Frequencies.
    let o = SteadyStateOptions::new(-5.0, vec![F_EXCIT]);
    assert!(steady_state(&model, &o).unwrap_err().to_string().contains("frequency_hz"));
    let s = SweepOptions::new(200.0, 260.0, 0.0, vec![F_EXCIT]);
    assert!(swept_sine(&model, &s).unwrap_err().to_string().contains("rate_hz_per_s"));
}

#[test]
fn a_sweep_starting_far_below_its_end_is_refused_before_it_runs() {
    let model = table6();
    // 1e-320 Hz: the step and the start period overflow (it used to write time_s = inf, or
    // to abort on a capacity overflow).
    let err = swept_sine(&model, &SweepOptions::new(1e-320, 300.0, 10.0, vec![F_EXCIT])).unwrap_err();
    assert!(err.to_string().contains("time steps"), "{err}");
    // 1e-4 Hz: a start period of 3.8e8 steps, whose periodicity check would keep them all.
    let err = swept_sine(&model, &SweepOptions::new(1e-4, 300.0, 10.0, vec![F_EXCIT])).unwrap_err();
    assert!(err.to_string().contains("values to compare"), "{err}");
}
