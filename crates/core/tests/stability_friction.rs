//! Hill's method on a friction response: a perturbation of the Table 6 system's periodic
//! response, integrated in time, decays at the rate of the leading Floquet exponent.
mod timesim_common;

use faer::Mat;
use stickslip_core::continuation::{Options, Silent, TerminationReason};
use stickslip_core::elements::Jenkins;
use stickslip_core::hbm::{stability_at, sweep_level, CondensedHbm, HbmSettings, Hill, HillSettings};
use stickslip_core::model::{Damping, DofLabel, ElementSite, LinearModel, Matrix, NonlinearModel};
use stickslip_core::timesim::{Integrator, Scheme, State};
use timesim_common::{DAMPING, F_COULOMB, K_JENKINS, K_TOTAL, MASS};

const TWO_PI: f64 = 2.0 * std::f64::consts::PI;

/// Table 6 with its damping written as α M (the same 350 N·s/m), the modal form Hill's method
/// needs.
fn table6_modal() -> NonlinearModel {
    let linear = LinearModel::new(
        Matrix::Dense(Mat::from_fn(1, 1, |_, _| MASS)),
        Matrix::Dense(Mat::from_fn(1, 1, |_, _| K_TOTAL)),
        Damping::Rayleigh { alpha: DAMPING / MASS, beta: 0.0 },
        vec![DofLabel::named("x")],
        vec![],
    )
    .unwrap();
    let law = Jenkins::replacing_stiffness(K_JENKINS, F_COULOMB).unwrap();
    NonlinearModel::new(
        linear,
        vec![ElementSite { name: "joint".into(), law: Box::new(law), directions: vec![vec![1.0]] }],
    )
    .unwrap()
}

/// Decay rate (1/s) of small perturbations of the steady state at `frequency_hz`, `level` (N),
/// from time integration alone: the steady state is reached from rest, then the monodromy
/// matrix over `PERIODS` periods is built by finite differences (the state perturbed in
/// displacement and in velocity, each integrated beside the reference: this includes the
/// shift of the stick-slip instants), and the rate is `ln |μ_max| / (PERIODS T)`.
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
    let (u_scale, v_scale) = (state.displacement[0].abs().max(1e-9), state.velocity[0].abs().max(1e-9 * omega));
    let eps = 1e-6;
    let run = |integrator: &mut Integrator, du: f64, dv: f64| -> (f64, f64) {
        let mut start = state.clone();
        start.displacement[0] += du;
        start.velocity[0] += dv;
        let mut s = integrator.resume(&start, &load, (omega * t).cos()).unwrap();
        advance(integrator, &mut s, t, PERIODS);
        (s.displacement[0], s.velocity[0])
    };
    let reference = run(&mut integrator, 0.0, 0.0);
    let by_u = run(&mut integrator, eps * u_scale, 0.0);
    let by_v = run(&mut integrator, 0.0, eps * v_scale);
    // Monodromy in the scaled state (u / u_scale, v / v_scale).
    let (a, c) =
        ((by_u.0 - reference.0) / (eps * u_scale), (by_u.1 - reference.1) / (eps * u_scale) * u_scale / v_scale);
    let (b, d) =
        ((by_v.0 - reference.0) / (eps * v_scale) * v_scale / u_scale, (by_v.1 - reference.1) / (eps * v_scale));
    let (tr, det) = (a + d, a * d - b * c);
    let disc = tr * tr / 4.0 - det;
    let largest = if disc >= 0.0 { (tr / 2.0).abs() + disc.sqrt() } else { det.sqrt() };
    largest.ln() * frequency_hz / PERIODS as f64
}

#[test]
fn a_perturbed_friction_response_decays_at_the_leading_hill_exponent() {
    let model = table6_modal();
    let settings = HbmSettings { harmonics: 15, samples: 1024 };
    let mut hbm = CondensedHbm::new(&model, &[1.0], settings).unwrap();
    for frequency_hz in [200.0, 205.0] {
        let omega = TWO_PI * frequency_hz;
        let ramp = sweep_level(&mut hbm, omega, 1.0, 3000.0, &Options::default(), &mut Silent).unwrap();
        assert_eq!(ramp.termination, TerminationReason::ReachedEnd);
        let x = &ramp.points.last().unwrap().x;
        let hill = Hill::new(hbm.receptance(), HillSettings::for_band(15, omega)).unwrap();
        let leading = stability_at(&mut hbm, &hill, x, omega).unwrap().leading();
        let measured = decay_rate(&model, frequency_hz, 3000.0);
        // Measured: Hill −32.2 and −38.2 1/s, time integration −31.8 and −37.1 1/s (1.3 % and
        // 2.9 %). Hill's matrix is built from the periodic Jacobian ∂G/∂x, which gives a stuck
        // slider's memory of its anchor (the last slip instant, a delay Δ back) the weight 1
        // instead of e^{−sΔ}: the error grows as |s| Δ, with the slip (7 % at 210 Hz, 10 % at
        // 215 Hz at this level; docs/stability.md). Asserted: 5 %, where the slip is moderate.
        assert!(leading.re < 0.0);
        assert!(
            (measured - leading.re).abs() < 0.05 * leading.re.abs(),
            "{frequency_hz} Hz: Hill {leading}, measured {measured}"
        );
    }
}
