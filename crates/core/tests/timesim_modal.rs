//! Time integration in modal coordinates (`NonlinearModel::into_modal`) against the same
//! integration in physical coordinates. The Newmark family is invariant under a linear change
//! of coordinates: with `U = Φ η`, `Φᵀ M Φ = I`, `Φᵀ K Φ = Ω²`, the discrete equations are the
//! physical ones multiplied by Φᵀ, and the element coordinates `Vᵀ U = (Φᵀ V)ᵀ η` are the same.
//! The two runs therefore agree to the round-off of the eigensolution, whatever the
//! nonlinearity: a difference above that would be a defect of the transformation (a missing
//! projection of the load or of an application vector, damping not carried over).

mod timesim_common;

use stickslip_core::elements::{Element, Jenkins};
use stickslip_core::timesim::{steady_state, swept_sine, SlowBand, SteadyStateOptions, SweepOptions};
use timesim_common::*;

/// A 4-mass chain (k = 1e6 N/m, m = 1 kg: modes 55-300 Hz), Rayleigh damping, one Jenkins
/// joint from the tip to the ground and one between masses 1 and 2: stick and slip both occur
/// at the levels below.
fn model() -> stickslip_core::model::NonlinearModel {
    let tip: Box<dyn Element> = Box::new(Jenkins::new(4e5, 20.0).unwrap());
    let link: Box<dyn Element> = Box::new(Jenkins::new(2e5, 15.0).unwrap());
    chain(4, 1.0, 1e6, 5.0, 1e-6, vec![(tip, 3, None), (link, 1, Some(2))])
}

fn project(shapes: &faer::Mat<f64>, v: &[f64]) -> Vec<f64> {
    (0..shapes.ncols()).map(|r| (0..v.len()).map(|i| shapes[(i, r)] * v[i]).sum()).collect()
}

/// Largest difference between two series relative to the largest value of the second.
fn relative_difference(a: &[f64], b: &[f64]) -> f64 {
    let scale = b.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    a.iter().zip(b).fold(0.0f64, |m, (x, y)| m.max((x - y).abs())) / scale
}

#[test]
fn modal_steady_state_equals_physical() {
    let physical = model();
    let modes = physical.linear.dense_modes().unwrap();
    let load = vec![0.0, 0.0, 0.0, 40.0];
    let mut o = SteadyStateOptions::new(70.0, load.clone());
    o.record_dofs = vec![0, 3];
    let reference = steady_state(&physical, &o).unwrap();

    let modal = model().into_modal(&modes).unwrap();
    let mut om = SteadyStateOptions::new(70.0, project(&modes.shapes, &load));
    om.record_dofs = vec![0, 3];
    om.mode_shapes = Some(modes.shapes.clone());
    let result = steady_state(&modal, &om).unwrap();

    // The periodicity criterion is judged on other coordinates (modal amplitudes), so the runs
    // stop after different numbers of periods (measured: 128 and 135); both are then within
    // the tolerance of the same steady state (measured difference 1.3e-6).
    // The steady state is an attractor: once both runs are within 1e-6 of it, the records
    // differ by the periodicity tolerance at most, not by round-off; 1e-5 leaves a margin of 10.
    for k in 0..2 {
        let d = relative_difference(&result.records.displacement[k], &reference.records.displacement[k]);
        assert!(d < 1e-5, "DOF {k}: relative difference {d:.2e}");
    }
    let joint = relative_difference(&result.records.elements.force[0], &reference.records.elements.force[0]);
    assert!(joint < 1e-5, "joint force differs by {joint:.2e}");
    // Energy per cycle is coordinate-free.
    let e = (result.energy.dissipated() / reference.energy.dissipated() - 1.0).abs();
    assert!(e < 1e-5, "dissipated energy differs by {e:.2e}");
}

#[test]
fn modal_sweep_equals_physical_to_round_off() {
    let physical = model();
    let modes = physical.linear.dense_modes().unwrap();
    let load = vec![0.0, 0.0, 0.0, 40.0];
    let options = |load: Vec<f64>| {
        let mut o = SweepOptions::new(40.0, 90.0, 100.0, load);
        o.slow_band = Some(SlowBand { low_hz: 50.0, high_hz: 60.0, rate_hz_per_s: 20.0 });
        o.record_dofs = vec![0, 3];
        // From rest: a settled start would stop on a criterion judged in other coordinates.
        o.settle = None;
        o
    };
    let reference = swept_sine(&physical, &options(load.clone())).unwrap();
    let modal = model().into_modal(&modes).unwrap();
    let mut om = options(project(&modes.shapes, &load));
    om.mode_shapes = Some(modes.shapes.clone());
    let result = swept_sine(&modal, &om).unwrap();

    assert_eq!(result.records.len(), reference.records.len());
    // Same discrete equations in other coordinates: the runs differ by the eigensolution's
    // round-off (~1e-14) amplified over ~10⁴ steps, and by the stick/slip decisions that
    // round-off can flip at a transition (a flip changes the force by O(h) only). Measured:
    // 6e-12; 1e-9 fails on any error of the transformation, which is O(1).
    for k in 0..2 {
        let d = relative_difference(&result.records.displacement[k], &reference.records.displacement[k]);
        assert!(d < 1e-9, "DOF {k}: relative difference {d:.2e}");
        let a = relative_difference(&result.records.acceleration[k], &reference.records.acceleration[k]);
        assert!(a < 1e-9, "DOF {k}: acceleration relative difference {a:.2e}");
    }
    assert_eq!(result.cycles.len(), reference.cycles.len());
    for (c, r) in result.cycles.iter().zip(&reference.cycles) {
        assert!((c.amplitude(1) - r.amplitude(1)).abs() < 1e-9 * r.amplitude(1).max(1e-12));
        assert_eq!(c.frequency_hz, r.frequency_hz);
    }
    // The joints slipped: the comparison covers the nonlinear behaviour.
    assert!(reference.records.elements.slider_velocity[0].iter().any(|v| v.abs() > 0.0));
}

#[test]
fn slow_band_sets_the_duration_and_the_frequency() {
    let mut o = SweepOptions::new(300.0, 170.0, 10.0, vec![1.0]);
    o.slow_band = Some(SlowBand { low_hz: 180.0, high_hz: 245.0, rate_hz_per_s: 1.0 });
    let s = o.schedule().unwrap();
    // Down from 300: 55 Hz at 10 Hz/s, 65 Hz at 1 Hz/s, 10 Hz at 10 Hz/s.
    assert!((s.duration() - (5.5 + 65.0 + 1.0)).abs() < 1e-12);
    assert!((s.frequency_hz(5.5) - 245.0).abs() < 1e-12);
    assert!((s.frequency_hz(5.5 + 30.0) - 215.0).abs() < 1e-12);
    assert!((s.frequency_hz(s.duration()) - 170.0).abs() < 1e-12);
    // The phase is the integral of the frequency: its derivative, by central differences.
    for t in [1.0, 5.5, 20.0, 70.5, 71.2] {
        let dt = 1e-6;
        let f = (s.phase(t + dt) - s.phase(t - dt)) / (2.0 * dt) / (2.0 * std::f64::consts::PI);
        assert!((f - s.frequency_hz(t)).abs() < 1e-4, "at {t} s: {f} vs {}", s.frequency_hz(t));
    }
    // A band outside the sweep changes nothing; a reversed band is refused.
    o.slow_band = Some(SlowBand { low_hz: 400.0, high_hz: 500.0, rate_hz_per_s: 1.0 });
    assert!((o.schedule().unwrap().duration() - 13.0).abs() < 1e-12);
    o.slow_band = Some(SlowBand { low_hz: 245.0, high_hz: 180.0, rate_hz_per_s: 1.0 });
    assert!(o.schedule().unwrap_err().to_string().contains("low < high"));
}
