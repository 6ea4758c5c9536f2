//! Swept-sine excitation: `F(t) = F̂ cos φ(t)` with a piecewise linear sweep `f(t) = f_s + r (t − t_s)`
//! on each segment, `φ = 2π ∫ f dt`, up (`f_end > f_start`) or down, at one rate or slower
//! inside a band, as the shaker runs of the paper (10 Hz/s, 1 Hz/s in the friction range).

use faer::Mat;

use super::records::{CycleEnergy, Records};
use super::steady::{check_frequency, check_steps, run_until_periodic};
use super::{EnergyTally, Integrator, Scheme, State, TimesimError};
use crate::model::NonlinearModel;

/// Most time steps a sweep may take (about an hour of one core for a reduced model).
const MAX_STEPS: f64 = 1e9;

/// What to compute.
#[derive(Clone, Debug)]
pub struct SweepOptions {
    pub start_hz: f64,
    pub end_hz: f64,
    /// Sweep rate (Hz/s, > 0); the direction is that from `start_hz` to `end_hz`.
    pub rate_hz_per_s: f64,
    /// A slower rate inside a band (the paper: 1 Hz/s where friction acts, 10 Hz/s elsewhere).
    pub slow_band: Option<SlowBand>,
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
    /// The mode shapes Φ when the model is in modal coordinates
    /// ([`NonlinearModel::into_modal`]): `record_dofs` are then DOFs of the physical model,
    /// recorded as `Φ η`, and the load is in modal coordinates (`Φᵀ F`).
    pub mode_shapes: Option<Mat<f64>>,
    /// Low-pass every recorded series at this cutoff (Hz) before keeping every
    /// `record_every`-th step, as a data acquisition system does (see
    /// [`crate::signal::antialias`]); `None` records the integration's samples as they are.
    pub anti_alias_hz: Option<f64>,
}

/// A band swept at its own rate.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SlowBand {
    pub low_hz: f64,
    pub high_hz: f64,
    pub rate_hz_per_s: f64,
}

/// The instantaneous frequency and phase of a sweep against time.
#[derive(Clone, Debug)]
pub struct SweepSchedule {
    /// Segments `(t_start, f_start, signed rate, φ_start)`, in time order.
    segments: Vec<(f64, f64, f64, f64)>,
    duration: f64,
}

impl SweepSchedule {
    fn segment(&self, t: f64) -> (f64, f64, f64, f64) {
        *self.segments.iter().rev().find(|s| t >= s.0).unwrap_or(&self.segments[0])
    }

    /// Instantaneous frequency (Hz) at `t`.
    pub fn frequency_hz(&self, t: f64) -> f64 {
        let (t0, f0, r, _) = self.segment(t);
        f0 + r * (t - t0)
    }

    /// Excitation phase `φ(t) = 2π ∫₀ᵗ f dτ` (rad).
    pub fn phase(&self, t: f64) -> f64 {
        let (t0, f0, r, phi0) = self.segment(t);
        let dt = t - t0;
        phi0 + 2.0 * std::f64::consts::PI * (f0 * dt + 0.5 * r * dt * dt)
    }

    /// Time from the start to the end frequency (s).
    pub fn duration(&self) -> f64 {
        self.duration
    }
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
            slow_band: None,
            mode_shapes: None,
            anti_alias_hz: None,
        }
    }

    /// The time step (s) and the steps per period at the start frequency: at least
    /// `steps_per_period` per period at the highest frequency and an integer number per period
    /// at the start frequency (where the sweep may settle).
    pub fn step(&self) -> (f64, usize) {
        let (f0, f1) = (self.start_hz, self.end_hz);
        let steps_at_start = (self.steps_per_period as f64 * f0.max(f1) / f0).ceil() as usize;
        (1.0 / (f0 * steps_at_start as f64), steps_at_start)
    }

    /// Frequency and phase against time, with the slow band if any.
    pub fn schedule(&self) -> Result<SweepSchedule, TimesimError> {
        check_frequency("start_hz", self.start_hz)?;
        check_frequency("end_hz", self.end_hz)?;
        check_frequency("rate_hz_per_s", self.rate_hz_per_s)?;
        let (f0, f1) = (self.start_hz, self.end_hz);
        let direction = (f1 - f0).signum();
        // Breakpoints in sweep order: the band's edges strictly between start and end.
        let mut breaks = vec![f0];
        if let Some(b) = self.slow_band {
            check_frequency("slow band rate_hz_per_s", b.rate_hz_per_s)?;
            if !(b.low_hz.is_finite() && b.high_hz.is_finite() && b.low_hz < b.high_hz) {
                return Err(TimesimError::Invalid(format!(
                    "the slow band must be two finite frequencies low < high, got {} and {} Hz",
                    b.low_hz, b.high_hz
                )));
            }
            let mut edges = vec![b.low_hz, b.high_hz];
            if direction < 0.0 {
                edges.reverse();
            }
            breaks.extend(edges.into_iter().filter(|&e| (e - f0) * direction > 0.0 && (f1 - e) * direction > 0.0));
        }
        breaks.push(f1);
        let two_pi = 2.0 * std::f64::consts::PI;
        let (mut t, mut phi) = (0.0, 0.0);
        let mut segments = Vec::new();
        for w in breaks.windows(2) {
            let mid = 0.5 * (w[0] + w[1]);
            let rate = match self.slow_band {
                Some(b) if (b.low_hz..=b.high_hz).contains(&mid) => b.rate_hz_per_s,
                _ => self.rate_hz_per_s,
            };
            let r = rate * direction;
            let dt = (w[1] - w[0]) / r;
            segments.push((t, w[0], r, phi));
            phi += two_pi * (w[0] * dt + 0.5 * r * dt * dt);
            t += dt;
        }
        Ok(SweepSchedule { segments, duration: t })
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
    let schedule = options.schedule()?;
    check_steps(options.steps_per_period, options.harmonics)?;
    if options.record_every == 0 {
        return Err(TimesimError::Invalid("record_every must be at least 1".into()));
    }
    let f0 = options.start_hz;
    // A start far below the end frequency makes the step tiny (a whole number of steps per
    // start period, `steps_per_period` at the end) and the sweep endless: say so up front.
    let per_start_period = options.steps_per_period as f64 * f0.max(options.end_hz) / f0;
    let step = 1.0 / (f0 * per_start_period.ceil());
    let total = schedule.duration() / step;
    if !(per_start_period <= MAX_STEPS && step.is_finite() && step > 0.0 && total <= MAX_STEPS) {
        return Err(TimesimError::Invalid(format!(
            "a sweep from {f0} Hz to {} Hz at these rates would take {total:.3e} time steps of {step:.3e} s (at most {MAX_STEPS:.0e}): start nearer the end frequency, sweep faster or use fewer steps per period",
            options.end_hz
        )));
    }
    let (step, steps_at_start) = options.step();
    let mut integrator = Integrator::new(model, options.scheme, step)?;
    let n = model.linear.n_dofs();
    let load = &options.load;
    let mut state = integrator.start(0.0, &vec![0.0; n], &vec![0.0; n], load, 1.0)?;
    if let Some((tolerance, max_periods)) = options.settle {
        let steady = run_until_periodic(
            &mut integrator,
            state,
            load,
            f0,
            steps_at_start,
            tolerance,
            max_periods,
            &[],
            None,
            (false, 0),
        )?;
        state = integrator.resume(&steady.final_state, load, 1.0)?;
    }
    let (alpha, _, _) = integrator.parameters();
    let two_pi = 2.0 * std::f64::consts::PI;
    let phase = |t: f64| schedule.phase(t);
    let n_steps = (schedule.duration() / step).ceil() as usize;

    let mut records = Records::new(model, &options.record_dofs, options.mode_shapes.as_ref())?;
    if let Some(cutoff) = options.anti_alias_hz {
        records.anti_alias(1.0 / step, cutoff)?;
    }
    let mut frequency_hz = Vec::new();
    let mut slider = vec![0.0; integrator.n_directions()];
    let n_rec = options.record_dofs.len();
    // The cycle integrals run over the coordinates the records read (all modal coordinates
    // of a modal model) and are combined into the recorded DOFs at each cycle's end.
    let sources = records.probes().sources(n);
    let n_src = sources.len();
    let mut cycles = Vec::new();
    let mut acc = vec![(0.0, 0.0); n_src];
    let (mut acc_c, mut acc_s) = (vec![0.0; n_src], vec![0.0; n_src]);
    let mut cycle_start = 0.0;
    let mut cycle_tally = state.energy.clone();
    // Tally before the current step, and at the cycle boundary inside it (interpolated
    // linearly within the step, so that a cycle's energy is not off by a fraction of a step).
    let mut step_tally = state.energy.clone();
    let mut boundary_tally = state.energy.clone();
    let mut cycle_index = 0usize;
    let mut x_prev: Vec<f64> = sources.iter().map(|&i| state.displacement[i]).collect();
    let mut phi_prev = 0.0;
    for k in 0..n_steps {
        let keep = k % options.record_every == 0;
        records.sample(model, &state, &mut slider, keep);
        if keep {
            frequency_hz.push(schedule.frequency_hz(state.time));
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
            let d = 0.5 * (hi_phi - lo_phi);
            let ((lo_sin, lo_cos), (hi_sin, hi_cos)) = (lo_phi.sin_cos(), hi_phi.sin_cos());
            for (r, &i) in sources.iter().enumerate() {
                let x_lo = x_prev[r] + lo_frac * (state.displacement[i] - x_prev[r]);
                let x_hi = x_prev[r] + hi_frac * (state.displacement[i] - x_prev[r]);
                acc[r].0 += d * (x_lo * lo_cos + x_hi * hi_cos);
                acc[r].1 += d * (x_lo * lo_sin + x_hi * hi_sin);
            }
            if cross && s == 0 {
                let t_boundary = t_end - step + hi_frac * step;
                let t_mid = 0.5 * (cycle_start + t_boundary);
                let pi = std::f64::consts::PI;
                for (r, &(c, s)) in acc.iter().enumerate() {
                    acc_c[r] = c / pi;
                    acc_s[r] = s / pi;
                }
                let probes = records.probes();
                cycles.push(SweepCycle {
                    frequency_hz: schedule.frequency_hz(t_mid),
                    start_time: cycle_start,
                    harmonic1: (0..n_rec).map(|k| (probes.combine(k, &acc_c), probes.combine(k, &acc_s))).collect(),
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
        for (r, &i) in sources.iter().enumerate() {
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
