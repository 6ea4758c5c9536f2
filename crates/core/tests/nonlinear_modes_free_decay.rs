//! The standard validation of a damped nonlinear mode (Krack 2015, EPMC): a free decay
//! integrated in time from a periodic motion of the backbone, analysed cycle by cycle, must
//! give the backbone's frequency and damping ratio at each cycle's amplitude, compared
//! directly (no slow flow, no correction for the energy stored in the joint).
//!
//! On a 3-DOF chain whose joint carries 5 % of the modal stiffness of mode 1, so that the motion
//! stays in one mode. Even so the direct comparison holds only where the joint's share of the
//! stiffness is small at the amplitude considered: at large amplitude and in the stuck regime,
//! not just above the first slip (see [`DIRECT_FROM`]).
mod hbm_support;

const PI: f64 = std::f64::consts::PI;

use hbm_support::*;
use stickslip_core::continuation::{Options, Silent, TerminationReason};
use stickslip_core::elements::{Element, Jenkins};
use stickslip_core::hbm::fourier::{cos_index, sin_index};
use stickslip_core::hbm::{nonlinear_mode, HbmSettings, NegativeDamping, NonlinearModeSettings};
use stickslip_core::model::{Damping, DofLabel, LinearModel, NonlinearModel};
use stickslip_core::timesim::{Integrator, Scheme};

/// The joint: a Jenkins element from mass 1 to the ground in the paper's form, replacing
/// 1.3e5 N/m of the chain's 1e6 N/m ground spring there: k_J φ₁₁² / ω₁² = 5.0 % of the modal
/// stiffness of mode 1 (φ₁ mass-normalised). It slips at 1e-4 m (modal amplitude 2.1e-4 m·√kg).
const K_J: f64 = 1.3e5;
const F_C: f64 = 13.0;
/// Modal damping ratio of the linear mode 1 (Rayleigh, half from M and half from K).
const ZETA_LINEAR: f64 = 5e-3;
/// Harmonics and time samples of the backbone.
const HARMONICS: usize = 7;
const SAMPLES: usize = 256;
/// Time step: Newmark's average acceleration stretches the period by (ωh)²/12 = 2.1e-5.
const STEPS_PER_PERIOD: f64 = 400.0;

/// First joint amplitude (in slip amplitudes F_c/k_J) of the direct comparison.
///
/// Below it the direct comparison does not hold, whatever the backbone's accuracy: at an
/// extreme of the decay the velocities vanish and the slipping joint's spring holds its limit
/// force, so the stored energy `E = ½ xᵀ(K − k_J e eᵀ)x + F_c²/2k_J` grows with the amplitude
/// as the *fully slipped* structure's, `dE/da = ω_∞² a`, while the EPMC rates the dissipation
/// per cycle W against `½ Ω(a)² a²` (ζ = W / 2πΩ²a², Krack 2015, Eq. 5). The log decrement
/// `δ = W / ω_∞² a²` of the peaks thus gives `ζ Ω(a)² / ω_∞²`: a departure `Ω²/ω_∞² − 1`, the
/// share of the modal stiffness the joint still carries at amplitude a. It vanishes at large
/// amplitude and in the stuck regime (no slip: `dE/da = Ω² a`), but just above the first slip
/// it is `ω₁²/ω_∞² − 1 ≈ k_J φ₁₁² / ω_∞²`, 5.7 % here: the full share of the joint, so that
/// 2 % cannot be met there unless the joint carries less than 2 % of the modal stiffness. From
/// 3 slip amplitudes on the departure is at most 1.5 %; the cycles below are checked against
/// it instead (the "stored energy" correction of nonlinear_modes.rs's 1-DOF free decay).
const DIRECT_FROM: f64 = 3.0;

/// The 3-DOF chain of hbm_support (masses 1-1.2 kg, springs 1e6 N/m) with the joint on mass 1.
fn model() -> NonlinearModel {
    let undamped = chain(3, Damping::Rayleigh { alpha: 0.0, beta: 0.0 }, vec![]);
    let w1 = undamped.linear.dense_modes().unwrap().omega[0];
    let damping = Damping::Rayleigh { alpha: ZETA_LINEAR * w1, beta: ZETA_LINEAR / w1 };
    let joint: Box<dyn Element> = Box::new(Jenkins::replacing_stiffness(K_J, F_C).unwrap());
    chain(3, damping, vec![("ground", joint, vec![1.0, 0.0, 0.0])])
}

/// Value at θ of the coefficient vector `c` (`[c0, c1, s1, ...]`).
fn synthesise(c: &[f64], theta: f64) -> f64 {
    let nh = (c.len() - 1) / 2;
    c[0] + (1..=nh)
        .map(|k| c[cos_index(k)] * (k as f64 * theta).cos() + c[sin_index(k)] * (k as f64 * theta).sin())
        .sum::<f64>()
}

/// Linear interpolation of `(x, y)` samples (x increasing) at `x0`, `None` outside.
fn interpolate(xs: &[f64], ys: &[f64], x0: f64) -> Option<f64> {
    let i = xs.windows(2).position(|w| w[0] <= x0 && x0 <= w[1])?;
    let t = (x0 - xs[i]) / (xs[i + 1] - xs[i]);
    Some(ys[i] + t * (ys[i + 1] - ys[i]))
}

/// Circular frequency of mode 1 with the joint fully slipped (k_J taken out of K).
fn slipped_omega(model: &NonlinearModel) -> f64 {
    let n = model.linear.n_dofs();
    let (m, k) = (model.linear.mass.to_dense(), model.linear.stiffness.to_dense());
    let slipped = LinearModel::new(
        dense(n, |i, j| m[(i, j)]),
        dense(n, |i, j| k[(i, j)] - if i == 0 && j == 0 { K_J } else { 0.0 }),
        Damping::Rayleigh { alpha: 0.0, beta: 0.0 },
        (0..n).map(|i| DofLabel::named(format!("x{i}"))).collect(),
        vec![],
    )
    .unwrap();
    slipped.dense_modes().unwrap().omega[0]
}

#[test]
fn free_decay_from_the_backbone_gives_its_frequency_and_damping() {
    let model = model();
    let n = model.linear.n_dofs();
    let modes = model.linear.dense_modes().unwrap();
    let (w1, phi) = (modes.omega[0], modes.shapes.col(0));
    let mass = model.linear.mass.to_dense();
    // The modal coordinate of mode 1, η = φ₁ᵀ M x.
    let modal: Vec<f64> = (0..n).map(|j| (0..n).map(|i| phi[i] * mass[(i, j)]).sum()).collect();
    let share = K_J * phi[0] * phi[0] / (w1 * w1);
    // Modal amplitude at which the joint (displacement φ₁₁ η) starts slipping.
    let eta_slip = F_C / (K_J * phi[0].abs());
    let w_slipped = slipped_omega(&model);
    eprintln!(
        "ω₁ {w1:.3} rad/s ({:.3} fully slipped), joint share of the modal stiffness {share:.4}, first slip at η {eta_slip:.3e}",
        w_slipped
    );
    assert!((0.05..0.2).contains(&share), "{share}");

    // The backbone from the stuck regime to 40 slip amplitudes, with every DOF as an output so
    // that each point has the physical harmonics of its motion. N = 7, 256 samples: the results
    // below move by 1e-5 at N = 11 with 512 samples and by 1.2e-4 at N = 3 with 128 (the higher
    // harmonics of a 5 % joint are small). Steps of at most 1 % of the λ range, 100 points: the
    // default 5 % (24 points) leaves 3e-2 of linear-interpolation error in ζ near the first slip,
    // where ζ turns sharply.
    let unit: Vec<Vec<f64>> = (0..n).map(|i| (0..n).map(|j| if i == j { 1.0 } else { 0.0 }).collect()).collect();
    let outputs: Vec<&[f64]> = unit.iter().map(|v| v.as_slice()).collect();
    let settings = NonlinearModeSettings {
        mode: 0,
        hbm: HbmSettings { harmonics: HARMONICS, samples: SAMPLES },
        negative_damping: NegativeDamping::default(),
    };
    let options = Options { max_step: 1e-2, ..Options::default() };
    let b =
        nonlinear_mode(&model, &settings, 0.3 * eta_slip, 40.0 * eta_slip, &outputs, &options, &mut Silent).unwrap();
    assert_eq!(b.termination, TerminationReason::ReachedEnd);
    // The backbone against the half range of η over its period, max − min over 2: the quantity
    // the decay shows. Every cycle has the amplitude a = √(X₁ᴴMX₁) of the mode's definition
    // and the target's share |η₁| of it; the motion's peak of η departs from both by higher
    // harmonics and the other modes, 7e-4 and 4e-4 at most here (one mode), which would move
    // the comparison by less than that times d ln ζ / d ln a ≤ 1; the half range is the
    // consistent choice, and unlike the peak it is blind to the static offset that a slider
    // stuck off centre leaves in the decay.
    let eta_coefficients =
        |o: &[Vec<f64>]| -> Vec<f64> { (0..o[0].len()).map(|c| (0..n).map(|i| modal[i] * o[i][c]).sum()).collect() };
    let half_range = |c: &[f64]| {
        let v: Vec<f64> = (0..2048).map(|j| synthesise(c, 2.0 * PI * j as f64 / 2048.0)).collect();
        0.5 * (v.iter().fold(f64::MIN, |m, &x| m.max(x)) - v.iter().fold(f64::MAX, |m, &x| m.min(x)))
    };
    let log_amplitude: Vec<f64> = b.points.iter().map(|p| half_range(&eta_coefficients(&p.outputs)).ln()).collect();
    let omega: Vec<f64> = b.points.iter().map(|p| p.omega).collect();
    let zeta: Vec<f64> = b.points.iter().map(|p| p.damping_ratio()).collect();
    let zeta_max = zeta.iter().fold(0.0f64, |m, &z| m.max(z));
    eprintln!(
        "{} backbone points: Ω {:.3} -> {:.3} rad/s, ζ {:.4e} up to {zeta_max:.4e}",
        b.points.len(),
        omega[0],
        omega[omega.len() - 1],
        zeta[0]
    );
    assert!(zeta_max > 2.0 * ZETA_LINEAR, "the joint should at least double the damping: {zeta_max}");

    // Release from the periodic motion at 30 slip amplitudes, at θ = 0 of its harmonics:
    // x(0) = c0 + Σ c_k, v(0) = Σ kΩ s_k.
    let start = b.points.iter().position(|p| p.amplitude > 30.0 * eta_slip).unwrap();
    let p = &b.points[start];
    let x0: Vec<f64> = p.outputs.iter().map(|c| synthesise(c, 0.0)).collect();
    let v0: Vec<f64> =
        p.outputs.iter().map(|c| (1..=HARMONICS).map(|k| k as f64 * p.omega * c[sin_index(k)]).sum()).collect();
    // The slider where the periodic motion has it at θ = 0: the element's own return map along
    // the joint displacement (DOF 1) over two periods from rest, the second one periodic. The
    // map is exact between samples but for the reversal missed between two of them, an
    // overshoot of (π/8192)² of the amplitude.
    let law = &model.elements[0].law;
    let (mut slider, mut force) = ([0.0], [0.0]);
    for j in 0..=2 * 8192 {
        let u = synthesise(&p.outputs[0], 2.0 * PI * j as f64 / 8192.0);
        law.update(&[u], &[0.0], &mut slider, &mut force, None);
    }
    let h = 2.0 * PI / p.omega / STEPS_PER_PERIOD;
    let mut integrator = Integrator::new(&model, Scheme::AverageAcceleration, h).unwrap();
    let zero = vec![0.0; n];
    let mut state = integrator.start(0.0, &x0, &v0, &zero, 0.0).unwrap();
    state.element_history[0] = slider[0];
    // Forces and acceleration again with that slider (the start took it from rest).
    let mut state = integrator.resume(&state, &zero, 0.0).unwrap();

    // Free decay (no load) down into the stuck regime: until a maximum of η below 0.8 η_slip.
    let eta = |x: &[f64]| -> f64 { (0..n).map(|i| modal[i] * x[i]).sum() };
    let (mut t, mut e) = (vec![0.0], vec![eta(&state.displacement)]);
    let mut steps = 0;
    loop {
        integrator.step(&mut state, &zero, 0.0, 0.0).unwrap();
        t.push(state.time);
        e.push(eta(&state.displacement));
        steps += 1;
        let k = e.len();
        if k >= 3 && e[k - 2] > e[k - 3] && e[k - 2] >= e[k - 1] && e[k - 2] > 0.0 && e[k - 2] < 0.8 * eta_slip {
            break;
        }
        assert!(steps < 200 * STEPS_PER_PERIOD as usize, "no decay into the stuck regime");
    }

    // Extrema (parabola through three samples) and zero crossings (linear) of η.
    let (mut maxima, mut minima, mut down) = (Vec::new(), Vec::new(), Vec::new());
    for i in 1..e.len() - 1 {
        let (a, b2, c) = (e[i - 1], e[i], e[i + 1]);
        if (b2 - a) * (c - b2) <= 0.0 && a != c {
            let d = 0.5 * (a - c) / (a - 2.0 * b2 + c);
            let extremum = (t[i] + d * h, b2 - 0.25 * (a - c) * d);
            if b2 > 0.0 && b2 > a {
                maxima.push(extremum);
            } else if b2 < 0.0 && b2 < a {
                minima.push(extremum);
            }
        }
        if b2 > 0.0 && c <= 0.0 {
            down.push(t[i] + h * b2 / (b2 - c));
        }
    }
    // Half cycles' amplitudes: each maximum with the minimum after it, (max − min)/2.
    let amplitudes: Vec<(f64, f64)> = maxima
        .iter()
        .filter_map(|&(tm, vm)| minima.iter().find(|m| m.0 > tm).map(|&(tn, vn)| (0.5 * (tm + tn), 0.5 * (vm - vn))))
        .collect();

    // The joint's amplitude over its slip amplitude F_c/k_J, per unit of modal amplitude.
    let per_eta = K_J * phi[0].abs() / F_C;
    let (mut direct, mut onset, mut stuck) = (Worst::default(), Worst::default(), Worst::default());
    let mut slipping_cycles = 0;
    for w in amplitudes.windows(2) {
        let ((t0, a0), (t1, a1)) = (w[0], w[1]);
        // One cycle: ζ from the log decrement δ of the amplitude over it, exactly as for a
        // linear oscillator (δ = 2πζ/√(1 − ζ²)); Ω from the period between the downward zero
        // crossings nearest the two half cycles (each halfway between its extrema). Both at the
        // cycle's mean log amplitude, where the backbone is interpolated.
        let delta = (a0 / a1).ln();
        let zeta_time = delta / (4.0 * PI * PI + delta * delta).sqrt();
        let nearest = |t0: f64| down.iter().copied().min_by(|x, y| (x - t0).abs().total_cmp(&(y - t0).abs())).unwrap();
        let omega_time = 2.0 * PI / (nearest(t1) - nearest(t0));
        let la = 0.5 * (a0.ln() + a1.ln());
        let (Some(w_mode), Some(z_mode)) =
            (interpolate(&log_amplitude, &omega, la), interpolate(&log_amplitude, &zeta, la))
        else {
            continue;
        };
        let r = la.exp() * per_eta;
        let (ew, ez) = (omega_time / w_mode - 1.0, zeta_time / z_mode - 1.0);
        let stored = if r > 1.0 { (w_mode / w_slipped).powi(2) - 1.0 } else { 0.0 };
        let kind = if r >= DIRECT_FROM {
            direct.add(ew, ez, z_mode);
            "direct"
        } else if (1.1..DIRECT_FROM).contains(&r) {
            // Slipping on both half cycles (the cycle's amplitude drops by 8 %): against the
            // stored-energy departure.
            onset.add(ew, ez - stored, z_mode);
            "onset"
        } else if r < 0.95 {
            stuck.add(ew, ez, z_mode);
            "stuck"
        } else {
            // Across the first slip, ζ turning over the cycle: not compared.
            "-"
        };
        slipping_cycles += usize::from(r > 1.0);
        eprintln!(
            "{kind:>6} joint {r:6.2} F/k: Ω {omega_time:.3} vs {w_mode:.3} ({ew:+.2e}), ζ {zeta_time:.4e} vs {z_mode:.4e} ({ez:+.2e}; Ω²/ω_∞² − 1 = {stored:+.2e})"
        );
    }
    eprintln!("{slipping_cycles} slipping cycles; from {DIRECT_FROM} slip amplitudes {direct:?}");
    eprintln!("between 1.1 and {DIRECT_FROM} (ζ against the stored energy) {onset:?}; stuck {stuck:?}");
    // The direct comparison from 3 slip amplitudes (where the joint gives 61 % of ζ) to 29
    // (21 %): 42 cycles, 25 of them at more than 1.5 times the linear damping ratio.
    assert!(direct.cycles >= 10 && direct.damped >= 5 && stuck.cycles >= 3, "{direct:?} {stuck:?}");
    // The frequency: measured 1.3e-4, mostly the decay's damped frequency (√(1 − ζ²): 8.4e-5 at
    // ζ = 1.3 %) and Newmark's period error (2.1e-5); unchanged at N = 11 with 512 samples,
    // 1.1e-4 at 1600 steps a period. 2 % would be the whole softening (768.96 to 748.2 rad/s)
    // and test nothing; 5e-4 is 2 % of it: a backbone softening by 2 % more or less (its joint
    // 5 % too stiff or too soft: 1.3e-3 at large amplitude) would fail.
    assert!(direct.frequency < 5e-4, "{direct:?}");
    // The damping ratio: measured 1.38e-2 at 3.2 F/k, growing from 3.2e-4 at 29 F/k as the
    // stored-energy departure does (1.50e-2 at 3.2 F/k, 6.0e-4 at 29 F/k); the same at 1600
    // steps a period and at N = 11 with 512 samples, 1.30e-2 with the negative damping on the
    // target mode only. A backbone whose joint dissipation were 2 % short would fail at 3.2 F/k
    // (+1.2 %, the joint giving 61 % of ζ there), one without it by a factor 2.6. Not resolved
    // here: the N = 1 backbone (1.64e-2; the check below tells it, 9.7e-3).
    assert!(direct.damping < 0.02, "{direct:?}");
    // Just above the first slip, the decay's ζ is the backbone's times Ω²/ω_∞² (up to 1.057,
    // see DIRECT_FROM): measured within 3.4e-3 of it (at 1.12 F/k, where the cycle's 8 %
    // amplitude drop straddles the sharpest turn of ζ), 1.4e-3 from 1.19 F/k on; 3.6e-3 at
    // N = 11 with 512 samples, 9.7e-3 at N = 1, 3.0e-2 with the default continuation steps (the
    // interpolation between backbone points). The frequency within 1.4e-4.
    assert!(onset.cycles >= 5 && onset.damping < 5e-3 && onset.frequency < 5e-4, "{onset:?}");
    // Stuck, the mode is linear (Ω = ω₁, ζ = ζ_lin) and so is the decay: measured 3.6e-5 in
    // frequency (the damped frequency 1.25e-5, Newmark's period error 2.1e-5) and 4.4e-5 in ζ
    // (Newmark's: 1.5e-5 and 2.7e-6 at 1600 steps a period).
    assert!(stuck.frequency < 1e-4 && stuck.damping < 2e-4, "{stuck:?}");
}

/// The worst relative departures over a set of cycles.
#[derive(Debug, Default)]
struct Worst {
    cycles: usize,
    /// Cycles at more than 1.5 times the linear damping ratio.
    damped: usize,
    frequency: f64,
    damping: f64,
}

impl Worst {
    fn add(&mut self, frequency: f64, damping: f64, zeta: f64) {
        self.cycles += 1;
        self.damped += usize::from(zeta >= 1.5 * ZETA_LINEAR);
        self.frequency = self.frequency.max(frequency.abs());
        self.damping = self.damping.max(damping.abs());
    }
}
