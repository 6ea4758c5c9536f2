//! Hill's method on a friction response: a perturbation of the Table 6 system's periodic
//! response, integrated in time, decays at the rate of the leading Floquet exponent.
mod timesim_common;

use faer::Mat;
use stickslip_core::continuation::{Options, Silent, TerminationReason};
use stickslip_core::hbm::{stability_at, sweep_level, CondensedHbm, HbmSettings, Hill, HillSettings};
use stickslip_core::model::{Damping, NonlinearModel};
use stickslip_core::timesim::{Integrator, Scheme, State};
use timesim_common::{table6_with, DAMPING, MASS};

const TWO_PI: f64 = 2.0 * std::f64::consts::PI;

/// Table 6 with its damping written as α M (the same 350 N·s/m), the modal form Hill's method
/// needs.
fn table6_modal() -> NonlinearModel {
    table6_with(Damping::Rayleigh { alpha: DAMPING / MASS, beta: 0.0 })
}

/// Decay rate (1/s) of small perturbations of the steady state at `frequency_hz`, `level` (N),
/// from time integration alone: the steady state is reached from rest, then the monodromy
/// matrix over `PERIODS` periods is built by finite differences in the state (u, u̇, and the
/// slider's position w: a stuck slider remembers it), each column one perturbed integration
/// beside the reference; the rate is `ln |μ_max| / (PERIODS T)`.
fn decay_rate(model: &NonlinearModel, frequency_hz: f64, level: f64) -> f64 {
    const PERIODS: usize = 4;
    let omega = TWO_PI * frequency_hz;
    let steps_per_period = 2000;
    let h = 1.0 / (frequency_hz * steps_per_period as f64);
    let mut integrator = Integrator::new(model, Scheme::AverageAcceleration, h).unwrap();
    let load = [level];
    let advance = |integrator: &mut Integrator, state: &mut State, t0: f64, periods: usize| {
        for i in 0..periods * steps_per_period {
            let e = (omega * (t0 + (i + 1) as f64 * h)).cos();
            integrator.step(state, &load, e, e).unwrap();
        }
    };
    // 300 periods: the transient from rest decays as e^{−17.5 t} or faster, to below 1e-10.
    let mut state = integrator.start(0.0, &[0.0], &[0.0], &load, 1.0).unwrap();
    advance(&mut integrator, &mut state, 0.0, 300);
    let t = 300.0 / frequency_hz;
    // Scales of the three state variables: displacement, velocity, slider position.
    let u_scale = state.displacement[0].abs().max(1e-9);
    let scales = [u_scale, u_scale * omega, u_scale];
    let eps = 1e-7;
    let run = |integrator: &mut Integrator, perturbation: [f64; 3]| -> [f64; 3] {
        let mut start = state.clone();
        start.displacement[0] += perturbation[0];
        start.velocity[0] += perturbation[1];
        start.element_history[0] += perturbation[2];
        let mut s = integrator.resume(&start, &load, (omega * t).cos()).unwrap();
        advance(integrator, &mut s, t, PERIODS);
        [s.displacement[0], s.velocity[0], s.element_history[0]]
    };
    let reference = run(&mut integrator, [0.0; 3]);
    let mut monodromy = Mat::<f64>::zeros(3, 3);
    for col in 0..3 {
        let mut perturbation = [0.0; 3];
        perturbation[col] = eps * scales[col];
        let end = run(&mut integrator, perturbation);
        for row in 0..3 {
            monodromy[(row, col)] = (end[row] - reference[row]) / scales[row] / eps;
        }
    }
    let largest = monodromy.eigenvalues().unwrap().iter().map(|m| m.norm()).fold(0.0, f64::max);
    largest.ln() * frequency_hz / PERIODS as f64
}

#[test]
fn a_perturbed_friction_response_decays_at_the_leading_hill_exponent() {
    let model = table6_modal();
    let settings = HbmSettings { harmonics: 15, samples: 1024 };
    let mut hbm = CondensedHbm::new(&model, &[1.0], settings).unwrap();
    for frequency_hz in [200.0, 210.0, 225.0] {
        let omega = TWO_PI * frequency_hz;
        let ramp = sweep_level(&mut hbm, omega, 1.0, 3000.0, &Options::default(), &mut Silent).unwrap();
        assert_eq!(ramp.termination, TerminationReason::ReachedEnd);
        let x = &ramp.points.last().unwrap().x;
        let hill = Hill::new(hbm.receptance(), HillSettings::for_band(15, omega)).unwrap();
        let leading = stability_at(&mut hbm, &hill, x, omega).unwrap().leading();
        let measured = decay_rate(&model, frequency_hz, 3000.0);
        // Measured: Hill −31.74, −42.33, −57.49 1/s; time integration −31.93, −42.30, −57.64
        // (0.6 %, 0.07 %, 0.3 %; the finite-difference monodromy over 2000 steps a period is
        // the less precise of the two). Hill's matrix with the sliders' memory weighted by
        // e^{−sΔ} (the fixed point of stability_at); with the periodic Jacobian alone (weight 1)
        // the exponent was off by 4 % at 210 Hz and 7 % at 225 Hz. Asserted: 2 %.
        assert!(leading.re < 0.0);
        assert!(
            (measured - leading.re).abs() < 0.02 * leading.re.abs(),
            "{frequency_hz} Hz: Hill {leading}, measured {measured}"
        );
    }
}
