//! Time integration with Jenkins friction elements: energy balance, exact loops, convergence
//! order, stick/slip transitions and slider drift, and the describing-function solution.
mod timesim_common;

use stickslip_core::timesim::{steady_state, Integrator, Scheme, SteadyState, SteadyStateOptions};
use timesim_common::*;

const TWO_PI: f64 = 2.0 * std::f64::consts::PI;

fn table6_steady(f: f64, p: usize, force: f64, scheme: Scheme) -> SteadyState {
    let model = table6();
    let mut o = SteadyStateOptions::new(f, vec![force]);
    o.record_dofs = vec![0];
    o.steps_per_period = p;
    o.harmonics = 7.min(p / 10);
    o.tolerance = 1e-10;
    o.scheme = scheme;
    steady_state(&model, &o).unwrap()
}

fn amplitude(c: &[f64], k: usize) -> f64 {
    c[2 * k - 1].hypot(c[2 * k])
}

fn half_peak_to_peak(x: &[f64]) -> f64 {
    let max = x.iter().copied().fold(f64::MIN, f64::max);
    let min = x.iter().copied().fold(f64::MAX, f64::min);
    0.5 * (max - min)
}

#[test]
fn energy_balance_per_cycle_and_exact_hysteresis_loop() {
    for f in [200.0, 230.0, 260.0] {
        let s = table6_steady(f, 512, F_EXCIT, Scheme::AverageAcceleration);
        let e = &s.energy;
        // Average acceleration conserves the discrete energy exactly with the tally's
        // quadratures, so over one period input − dissipation = ΔT + ΔV, the change of stored
        // energy between two samples one period apart: ≤ 2ε × (stored energy ≈ input here)
        // with the periodicity ε = 1e-10. 1e-8 leaves a factor 100 for round-off.
        let imbalance = (e.input - e.dissipated()).abs() / e.input;
        assert!(imbalance < 1e-8, "{f} Hz: imbalance {imbalance:e} ({e:?})");
        assert!(e.viscous > 0.0 && e.elements[0] > 0.0);
        // Masing: a Jenkins loop with one maximum and one minimum per cycle dissipates
        // 4 F_c (a − F_c/k), a the half peak-to-peak displacement, whatever the waveform. The
        // sampled extremes miss the true ones by at most a (π/P)²/2 ≈ 2e-5 a, amplified by
        // a/(a − F_c/k) < 3 here: 2e-4 is a safe bound.
        let a = half_peak_to_peak(&s.records.elements.displacement[0]);
        let masing = jenkins_dissipation(K_JENKINS, F_COULOMB, a);
        let rel = (e.elements[0] - masing).abs() / masing;
        assert!(rel < 2e-4, "{f} Hz: element dissipation {} vs Masing {masing} ({rel:e})", e.elements[0]);
    }
    // HHT balances forces at t_{n+1+α}, not with the trapezoidal quadratures of the tally,
    // and its algorithmic damping at low Ωh is of higher order: the imbalance is second order,
    // of the size |α| (Ωh)² ≈ 3e-5 at 256 steps per period (α = −0.05). Bound: 5 times that.
    let s = table6_steady(238.0, 256, F_EXCIT, Scheme::Hht { alpha: -0.05 });
    let imbalance = (s.energy.input - s.energy.dissipated()).abs() / s.energy.input;
    let omega_h = TWO_PI / 256.0;
    assert!(imbalance < 5.0 * 0.05 * omega_h * omega_h, "HHT energy imbalance {imbalance:e}");
}

#[test]
fn friction_steady_state_converges_at_second_order() {
    // Across Jenkins transitions the force is continuous and only its derivatives jump, so
    // the trapezoidal rule keeps its order (see the integrator's documentation). Reference:
    // P = 4096.
    let reference = table6_steady(238.0, 4096, F_EXCIT, Scheme::AverageAcceleration);
    let cr = SteadyState::harmonics(&reference.records.displacement[0], 1).unwrap();
    let errors: Vec<f64> = [64, 128, 256, 512]
        .iter()
        .map(|&p| {
            let s = table6_steady(238.0, p, F_EXCIT, Scheme::AverageAcceleration);
            let c = SteadyState::harmonics(&s.records.displacement[0], 1).unwrap();
            (c[1] - cr[1]).hypot(c[2] - cr[2]) / amplitude(&cr, 1)
        })
        .collect();
    // Where a transition falls inside a step varies with P, which scatters the ratio around 4
    // (measured 3.5..4.6): the mean order over the three halvings must be 2 ± 0.15, and
    // every single ratio above 3 (order > 1.58).
    let order = (errors[0] / errors[3]).log2() / 3.0;
    assert!((order - 2.0).abs() < 0.15, "order {order} ({errors:?})");
    for w in errors.windows(2) {
        assert!(w[0] / w[1] > 3.0, "{errors:?}");
    }
}

#[test]
fn stick_slip_transitions_are_clean_and_the_slider_does_not_drift() {
    // Four transitions per period (stick → slip → stick, twice) and no slip interval shorter
    // than a few steps: no chattering. At 256 steps per period a slip phase lasts ~60 steps.
    for f in [200.0, 238.0, 260.0] {
        let s = table6_steady(f, 256, F_EXCIT, Scheme::AverageAcceleration);
        let v = &s.records.elements.slider_velocity[0];
        let slipping: Vec<bool> = v.iter().map(|x| *x != 0.0).collect();
        let changes: Vec<usize> =
            (0..slipping.len()).filter(|&j| slipping[j] != slipping[(j + 1) % slipping.len()]).collect();
        assert_eq!(changes.len(), 4, "{f} Hz: transitions at {changes:?}");
        let shortest = (0..4).map(|i| (changes[(i + 1) % 4] + 256 - changes[i]) % 256).min().unwrap();
        assert!(shortest > 10, "{f} Hz: a stick or slip phase of {shortest} steps");
    }

    // A long run: 3000 periods at 238 Hz, 64 steps per period. The slider position of the
    // paper-form element is w = −g/k_J. Once periodic, the discrete map is periodic to round-off:
    // the slider's mean and extremes over period 3000 equal those over period 200 to 1e-9 of
    // the slip displacement F_c/k_J, and its mean is 0 (the excitation has half-wave symmetry,
    // which the discrete scheme keeps for an even number of steps per period).
    let model = table6();
    let (f, p) = (238.0, 64usize);
    let h = 1.0 / (f * p as f64);
    let load = [F_EXCIT];
    let mut it = Integrator::new(&model, Scheme::AverageAcceleration, h).unwrap();
    let mut state = it.start(0.0, &[0.0], &[0.0], &load, 1.0).unwrap();
    let slip = F_COULOMB / K_JENKINS;
    let mut stats = Vec::new();
    for period in 1..=3000 {
        let (mut sum, mut lo, mut hi) = (0.0, f64::MAX, f64::MIN);
        for j in 0..p {
            let t = ((period - 1) * p + j + 1) as f64 * h;
            let e = (TWO_PI * f * t).cos();
            it.step(&mut state, &load, e, e).unwrap();
            let w = -state.element_force[0] / K_JENKINS;
            sum += w;
            lo = lo.min(w);
            hi = hi.max(w);
        }
        if period == 200 || period == 3000 {
            stats.push((sum / p as f64, lo, hi));
        }
    }
    let (a, b) = (stats[0], stats[1]);
    assert!(b.2 - b.1 > 0.1 * slip, "the slider must move: range {}", b.2 - b.1);
    for (x, y) in [(a.0, b.0), (a.1, b.1), (a.2, b.2)] {
        assert!((x - y).abs() < 1e-9 * slip, "slider statistics drift: {a:?} → {b:?}");
    }
    assert!(b.0.abs() < 1e-9 * slip, "slider mean {}", b.0);
    // And with a 4x finer step the slider range agrees to the scheme's accuracy (O(h²):
    // 4e-3 relative error in amplitude at P = 64, above) — no step-size-dependent offset.
    let fine = table6_steady(f, 256, F_EXCIT, Scheme::AverageAcceleration);
    let w_fine: Vec<f64> = fine.records.elements.force[0].iter().map(|g| -g / K_JENKINS).collect();
    let mean_fine = w_fine.iter().sum::<f64>() / w_fine.len() as f64;
    let range_fine = half_peak_to_peak(&w_fine);
    assert!(mean_fine.abs() < 1e-9 * slip);
    assert!(((b.2 - b.1) / 2.0 - range_fine).abs() < 2e-2 * range_fine);
}

#[test]
fn below_the_slip_threshold_the_response_is_the_stuck_linear_one() {
    // 100 N at 260 Hz: stuck amplitude ≈ 2.3e-5 m, k_J a ≈ 190 N < F_c. The element never
    // slips, dissipates nothing, and the motion is the linear stuck response with Newmark's
    // period error (the linear test's closed form), to the periodicity tolerance.
    let (f, p) = (260.0, 128);
    let s = table6_steady(f, p, 100.0, Scheme::AverageAcceleration);
    assert!(s.records.elements.slider_velocity[0].iter().all(|v| *v == 0.0));
    assert!(s.energy.elements[0].abs() < 1e-12 * s.energy.input);
    let h = 1.0 / (f * p as f64);
    let omega = TWO_PI * f;
    let warped = 2.0 / h * (omega * h / 2.0).tan();
    let z = faer::c64::new(K_TOTAL - warped * warped * MASS, warped * DAMPING);
    let expected = 100.0 / z.norm();
    let c = SteadyState::harmonics(&s.records.displacement[0], 1).unwrap();
    assert!((amplitude(&c, 1) - expected).abs() < 1e-8 * expected);
}

#[test]
fn table6_first_harmonic_agrees_with_the_describing_function_to_what_n1_neglects() {
    // The N = 1 describing function (jenkins-closed-form.md) drops the harmonics 3, 5, ... of
    // the motion. The Jenkins force is Lipschitz in the motion with constant 2 k_J in the
    // sup norm (the play operator is 1-Lipschitz), so dropping them changes the force's
    // first harmonic by at most 2·2k_J Σ_{k≥3} a_k, and the first-harmonic amplitude by that
    // times the equivalent flexibility a_DF/F. Tolerance: that bound plus the time
    // discretisation at 512 steps per period (< 1e-3, measured 6e-4 at worst near 200 Hz).
    // The bound is not vacuous: it stays below 10 % at these frequencies.
    for f in [200.0, 215.0, 230.0, 245.0, 260.0] {
        let s = table6_steady(f, 512, F_EXCIT, Scheme::AverageAcceleration);
        let c = SteadyState::harmonics(&s.records.displacement[0], 7).unwrap();
        let a1 = amplitude(&c, 1);
        let higher: f64 = (3..=7).step_by(2).map(|k| amplitude(&c, k)).sum();
        let roots = table6_describing_function(TWO_PI * f);
        let a_df = roots.iter().copied().min_by(|x, y| (x - a1).abs().total_cmp(&(y - a1).abs())).unwrap();
        let bound = 4.0 * K_JENKINS * a_df / F_EXCIT * higher / a1 + 1e-3;
        let rel = (a1 - a_df).abs() / a_df;
        assert!(bound < 0.1, "{f} Hz: bound {bound}");
        assert!(rel < bound, "{f} Hz: time {a1:.6e}, describing function {a_df:.6e}: {rel:.3e} > {bound:.3e}");
        // Odd harmonics only: the even ones vanish by the half-wave symmetry (to the
        // periodicity tolerance).
        assert!(amplitude(&c, 2) < 1e-8 * a1 && c[0].abs() < 1e-8 * a1);
    }
}

#[test]
fn stepped_sine_continues_from_the_previous_state() {
    // Starting at 232 Hz from the periodic state at 230 Hz (displacement, velocity, slider
    // positions) reaches the same periodic state as from rest — it is unique here (the slider
    // slips both ways every cycle, which erases the history) — in fewer periods. Agreement
    // to 1e-8: two solutions each periodic to 1e-10.
    let model = table6();
    let steady = |f: f64, initial| {
        let mut o = SteadyStateOptions::new(f, vec![F_EXCIT]);
        o.record_dofs = vec![0];
        o.tolerance = 1e-10;
        o.initial = initial;
        steady_state(&model, &o).unwrap()
    };
    let previous = steady(230.0, None);
    let continued = steady(232.0, Some(previous.final_state.clone()));
    let fresh = steady(232.0, None);
    let a = SteadyState::harmonics(&continued.records.displacement[0], 1).unwrap();
    let b = SteadyState::harmonics(&fresh.records.displacement[0], 1).unwrap();
    assert!((a[1] - b[1]).hypot(a[2] - b[2]) < 1e-8 * amplitude(&b, 1));
    assert!(continued.periods < fresh.periods, "{} vs {} periods", continued.periods, fresh.periods);
}
