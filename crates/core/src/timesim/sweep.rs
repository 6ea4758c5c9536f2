//! Swept-sine excitation: `F(t) = F̂ cos φ(t)` with a linear sweep `f(t) = f_0 + r t`,
//! `φ = 2π ∫ f dt = 2π (f_0 t + r t²/2)`, up (`f_end > f_start`) or down, as the shaker runs of
//! the paper (10 Hz/s, 1 Hz/s in the friction range).

use super::records::{CycleEnergy, Records};
use super::steady::{check_frequency, check_steps, run_until_periodic};
use super::{EnergyTally, Integrator, Scheme, State, TimesimError};
use crate::model::NonlinearModel;

/// What to compute.
#[derive(Clone, Debug)]
pub struct SweepOptions {
    pub start_hz: f64,
    pub end_hz: f64,
    /// Sweep rate (Hz/s, > 0); the direction is that from `start_hz` to `end_hz`.
    pub rate_hz_per_s: f64,
    /// Force amplitude on every DOF (N).
    pub load: Vec<f64>,
    pub scheme: Scheme,
    /// Steps per period at the highest frequency of the sweep (the step is constant).
    pub steps_per_period: usize,
    /// Highest harmonic of interest (checks `steps_per_period`, see [`super::SteadyStateOptions`]).
    pub harmonics: usize,
    pub record_dofs: Vec<usize>,
    /// Keep every `record_every`-th step in the records (per-cycle harmonics use every step).
    pub record_every: usize,
    /// Start from the periodic steady state at `start_hz` (tolerance, maximum periods) rather
    /// than from rest, so that the record holds no start transient.
    pub settle: Option<(f64, usize)>,
}

impl SweepOptions {
    /// Average acceleration, 128 steps per period at the highest frequency, harmonic 1,
    /// every step recorded, settled at the start frequency to 1e-6 within 5000 periods.
    pub fn new(start_hz: f64, end_hz: f64, rate_hz_per_s: f64, load: Vec<f64>) -> Self {
        SweepOptions {
            start_hz,
            end_hz,
            rate_hz_per_s,
            load,
            scheme: Scheme::AverageAcceleration,
            steps_per_period: 128,
            harmonics: 1,
            record_dofs: Vec::new(),
            record_every: 1,
            settle: Some((1e-6, 5000)),
        }
    }
}

/// One excitation cycle (`φ` from `2π m` to `2π (m+1)`) of a sweep.
#[derive(Clone, Debug)]
pub struct SweepCycle {
    /// Instantaneous frequency at the middle of the cycle (Hz).
    pub frequency_hz: f64,
    pub start_time: f64,
    /// First-harmonic coefficients `(c1, s1)` of each recorded DOF's displacement against the
    /// excitation phase, `x ≈ c1 cos φ + s1 sin φ`: `(1/π) ∮ x (cos φ, sin φ) dφ`.
    pub harmonic1: Vec<(f64, f64)>,
    /// Energy over the cycle (the tallies interpolated linearly inside the steps where the
    /// cycle starts and ends).
    pub energy: CycleEnergy,
}

impl SweepCycle {
    /// First-harmonic amplitude `√(c1² + s1²)` of recorded DOF `k` (m).
    pub fn amplitude(&self, k: usize) -> f64 {
        self.harmonic1[k].0.hypot(self.harmonic1[k].1)
    }
}

/// The sweep's records.
#[derive(Clone, Debug)]
pub struct SweepRecord {
    /// Time step (s).
    pub step: f64,
    pub records: Records,
    /// Instantaneous excitation frequency at each record sample (Hz).
    pub frequency_hz: Vec<f64>,
    pub cycles: Vec<SweepCycle>,
    pub final_state: State,
}

/// Integrate a linear swept sine (see the module documentation).
pub fn swept_sine(model: &NonlinearModel, options: &SweepOptions) -> Result<SweepRecord, TimesimError> {
    check_frequency("start_hz", options.start_hz)?;
    check_frequency("end_hz", options.end_hz)?;
    check_frequency("rate_hz_per_s", options.rate_hz_per_s)?;
    check_steps(options.steps_per_period, options.harmonics)?;
    if options.record_every == 0 {
        return Err(TimesimError::Invalid("record_every must be at least 1".into()));
    }
    let (f0, f1) = (options.start_hz, options.end_hz);
    let rate = options.rate_hz_per_s * (f1 - f0).signum();
    // Constant step, at least `steps_per_period` per period at the highest frequency and an
    // integer number per period at the start frequency (where the sweep may settle).
    let steps_at_start = (options.steps_per_period as f64 * f0.max(f1) / f0).ceil() as usize;
    let step = 1.0 / (f0 * steps_at_start as f64);
    let mut integrator = Integrator::new(model, options.scheme, step)?;
    let n = model.linear.n_dofs();
    let load = &options.load;
    let mut state = integrator.start(0.0, &vec![0.0; n], &vec![0.0; n], load, 1.0)?;
    if let Some((tolerance, max_periods)) = options.settle {
        let steady = run_until_periodic(&mut integrator, state, load, f0, steps_at_start, tolerance, max_periods, &[])?;
        state = integrator.resume(&steady.final_state, load, 1.0)?;
    }
    let (alpha, _, _) = integrator.parameters();
    let two_pi = 2.0 * std::f64::consts::PI;
    let phase = |t: f64| two_pi * (f0 * t + 0.5 * rate * t * t);
    let duration = (f1 - f0).abs() / options.rate_hz_per_s;
    let n_steps = (duration / step).ceil() as usize;

    let mut records = Records::new(model, &options.record_dofs)?;
    let mut frequency_hz = Vec::new();
    let mut slider = vec![0.0; integrator.n_directions()];
    let n_rec = options.record_dofs.len();
    let mut cycles = Vec::new();
    let mut acc = vec![(0.0, 0.0); n_rec];
    let mut cycle_start = 0.0;
    let mut cycle_tally = state.energy.clone();
    // Tally before the current step, and at the cycle boundary inside it (interpolated
    // linearly within the step, so that a cycle's energy is not off by a fraction of a step).
    let mut step_tally = state.energy.clone();
    let mut boundary_tally = state.energy.clone();
    let mut cycle_index = 0usize;
    let mut x_prev: Vec<f64> = options.record_dofs.iter().map(|&i| state.displacement[i]).collect();
    let mut phi_prev = 0.0;
    for k in 0..n_steps {
        if k % options.record_every == 0 {
            records.push(model, &state, &mut slider);
            frequency_hz.push(f0 + rate * state.time);
        }
        let t_end = (k + 1) as f64 * step;
        copy_tally(&state.energy, &mut step_tally);
        integrator.step(&mut state, load, phase(t_end + alpha * step).cos(), phase(t_end).cos())?;
        state.time = t_end;
        // Trapezoidal ∫ x (cos φ, sin φ) dφ over the step, split where φ crosses a cycle end
        // (x interpolated linearly), so that each cycle's integral is second-order accurate.
        let phi = phase(t_end);
        let boundary = two_pi * (cycle_index + 1) as f64;
        let (mut lo_phi, mut lo_frac) = (phi_prev, 0.0);
        let cross = phi >= boundary;
        let segments: &[(f64, f64)] = if cross {
            let lambda = (boundary - phi_prev) / (phi - phi_prev);
            &[(boundary, lambda), (phi, 1.0)]
        } else {
            &[(phi, 1.0)]
        };
        for (s, &(hi_phi, hi_frac)) in segments.iter().enumerate() {
            for (r, &i) in options.record_dofs.iter().enumerate() {
                let x_lo = x_prev[r] + lo_frac * (state.displacement[i] - x_prev[r]);
                let x_hi = x_prev[r] + hi_frac * (state.displacement[i] - x_prev[r]);
                let d = 0.5 * (hi_phi - lo_phi);
                acc[r].0 += d * (x_lo * lo_phi.cos() + x_hi * hi_phi.cos());
                acc[r].1 += d * (x_lo * lo_phi.sin() + x_hi * hi_phi.sin());
            }
            if cross && s == 0 {
                let t_boundary = t_end - step + hi_frac * step;
                let t_mid = 0.5 * (cycle_start + t_boundary);
                let pi = std::f64::consts::PI;
                cycles.push(SweepCycle {
                    frequency_hz: f0 + rate * t_mid,
                    start_time: cycle_start,
                    harmonic1: acc.iter().map(|&(c, s)| (c / pi, s / pi)).collect(),
                    energy: {
                        interpolate_tally(&step_tally, &state.energy, hi_frac, &mut boundary_tally);
                        CycleEnergy::between(&cycle_tally, &boundary_tally)
                    },
                });
                copy_tally(&boundary_tally, &mut cycle_tally);
                acc.iter_mut().for_each(|a| *a = (0.0, 0.0));
                cycle_start = t_boundary;
                cycle_index += 1;
            }
            lo_phi = hi_phi;
            lo_frac = hi_frac;
        }
        for (r, &i) in options.record_dofs.iter().enumerate() {
            x_prev[r] = state.displacement[i];
        }
        phi_prev = phi;
    }
    Ok(SweepRecord { step, records, frequency_hz, cycles, final_state: state })
}

fn copy_tally(from: &EnergyTally, to: &mut EnergyTally) {
    to.input = from.input;
    to.viscous = from.viscous;
    to.elements.copy_from_slice(&from.elements);
}

/// `out = a + λ (b − a)`.
fn interpolate_tally(a: &EnergyTally, b: &EnergyTally, lambda: f64, out: &mut EnergyTally) {
    out.input = a.input + lambda * (b.input - a.input);
    out.viscous = a.viscous + lambda * (b.viscous - a.viscous);
    for ((o, x), y) in out.elements.iter_mut().zip(&a.elements).zip(&b.elements) {
        *o = x + lambda * (y - x);
    }
}
