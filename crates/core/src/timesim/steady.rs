//! Periodic steady state under a harmonic force `F(t) = F̂ cos(2π f t)`.
//!
//! # Periodicity criterion
//!
//! Every period (an integer number `P` of steps, so that samples fall at the same phases) the
//! displacements of **all** DOFs are compared with those one period earlier:
//!
//! ```text
//! ε_m = max_{i, j} |U_i(t_j + T) − U_i(t_j)| / max_{i, j} |U_i(t_j + T)|
//! ```
//!
//! and the state is steady when `ε < tolerance` for two consecutive periods (one small value
//! can be a coincidence of a beating transient; two in a row cannot for a transient decaying
//! exponentially). The amplitude in the denominator is the largest over all DOFs, so DOFs of
//! very different scales are judged by the largest motion.
//!
//! Joints far stiffer than the structure (1e10 N/m connectors) stick for less than a time step
//! at each motion reversal; whether a given step sticks or slips then varies from period to
//! period at round-off level, and the response repeats only to ~1e-3 (measured on the Harmony
//! model at its friction peak, on the outputs; more on local modes). A tight tolerance is then
//! never met, and a loose one stops on the transient, since ε measures the change over one
//! period, ~2πζ times the transient's amplitude. For such models, integrate a fixed number of
//! periods that lets the transient die (`min_periods`, e.g. 10/(2πζ)), judge the periodicity
//! on the recorded responses (`periodic_on_recorded`) with a tolerance above the jitter.

use super::records::{CycleEnergy, Records};
use super::{Integrator, Scheme, State, TimesimError};
use crate::hbm::fourier::AftPlan;
use crate::model::NonlinearModel;

/// Fewest steps per period of the highest harmonic of interest: Newmark's relative period
/// error `(ωh)²/12` is then at most `(2π/10)²/12 ≈ 3.3 %` at that harmonic.
pub(crate) const MIN_STEPS_PER_HARMONIC: usize = 10;

/// Most values of one period kept by the periodicity check (2 GB of f64).
const MAX_PERIOD_VALUES: f64 = 2.5e8;

/// What to compute.
#[derive(Clone, Debug)]
pub struct SteadyStateOptions {
    /// Excitation frequency (Hz).
    pub frequency_hz: f64,
    /// Force amplitude on every DOF (N): `F(t) = load · cos(2π f t)`.
    pub load: Vec<f64>,
    pub scheme: Scheme,
    /// Time steps per excitation period (the step is `1 / (f · steps_per_period)`).
    pub steps_per_period: usize,
    /// Highest harmonic that will be extracted from the records; `steps_per_period` must be at
    /// least 10 times it.
    pub harmonics: usize,
    /// Periodicity tolerance `ε` (see the module documentation).
    pub tolerance: f64,
    /// Give up after this many periods.
    pub max_periods: usize,
    /// DOFs whose displacement, velocity and acceleration are recorded.
    pub record_dofs: Vec<usize>,
    /// Start from this state (its displacement, velocity and element history, e.g. the final
    /// state at the previous frequency of a stepped sine) instead of rest.
    pub initial: Option<State>,
    /// The mode shapes Φ when the model is in modal coordinates
    /// ([`crate::model::NonlinearModel::into_modal`]): `record_dofs` are then DOFs of the
    /// physical model, recorded as `Φ η`, and the load is in modal coordinates (`Φᵀ F`).
    pub mode_shapes: Option<faer::Mat<f64>>,
    /// Judge the periodicity on the recorded DOFs only instead of every DOF (see the module
    /// documentation).
    pub periodic_on_recorded: bool,
    /// Integrate at least this many periods before judging the periodicity (see the module
    /// documentation: responses that repeat only to a loose tolerance).
    pub min_periods: usize,
}

impl SteadyStateOptions {
    /// Average acceleration, 256 steps per period, harmonics up to 7 extractable, tolerance
    /// 1e-6, at most 5000 periods, no DOF recorded, start at rest.
    pub fn new(frequency_hz: f64, load: Vec<f64>) -> Self {
        SteadyStateOptions {
            frequency_hz,
            load,
            scheme: Scheme::AverageAcceleration,
            steps_per_period: 256,
            harmonics: 7,
            tolerance: 1e-6,
            max_periods: 5000,
            record_dofs: Vec::new(),
            initial: None,
            mode_shapes: None,
            periodic_on_recorded: false,
            min_periods: 0,
        }
    }
}

/// One period of the steady state.
#[derive(Clone, Debug)]
pub struct SteadyState {
    pub frequency_hz: f64,
    /// Time step (s).
    pub step: f64,
    /// Periods integrated, the recorded one included.
    pub periods: usize,
    /// Periodicity `ε` of the recorded period.
    pub periodicity: f64,
    /// `steps_per_period` samples at phases `2π j / P`, `j = 0..P` (the period's end excluded),
    /// so that [`SteadyState::harmonics`] is an exact DFT.
    pub records: Records,
    /// Energy input and dissipated over the recorded period.
    pub energy: CycleEnergy,
    /// State at the end of the recorded period (phase 0 of the next one).
    pub final_state: State,
}

impl SteadyState {
    /// Fourier coefficients `[c0, c1, s1, ..., cN, sN]` (the [`crate::hbm::fourier`]
    /// convention, phase `θ = 2π f t`) of one recorded period of `signal`.
    pub fn harmonics(signal: &[f64], n_harmonics: usize) -> Result<Vec<f64>, TimesimError> {
        let plan = AftPlan::new(n_harmonics, signal.len()).map_err(|e| TimesimError::Invalid(e.to_string()))?;
        let mut coeffs = vec![0.0; plan.n_coeffs()];
        plan.analyze(signal, &mut coeffs, &mut plan.scratch());
        Ok(coeffs)
    }
}

pub(crate) fn check_steps(steps_per_period: usize, harmonics: usize) -> Result<(), TimesimError> {
    let min = MIN_STEPS_PER_HARMONIC * harmonics.max(1);
    if steps_per_period < min {
        return Err(TimesimError::TooFewSteps { steps_per_period, harmonics, min });
    }
    Ok(())
}

pub(crate) fn check_frequency(what: &str, f: f64) -> Result<(), TimesimError> {
    if !(f.is_finite() && f > 0.0) {
        return Err(TimesimError::Invalid(format!("{what} must be a finite frequency > 0 Hz, got {f}")));
    }
    Ok(())
}

/// Integrate until periodic (see the module documentation) and return the last period.
pub fn steady_state(model: &NonlinearModel, options: &SteadyStateOptions) -> Result<SteadyState, TimesimError> {
    check_frequency("frequency_hz", options.frequency_hz)?;
    check_steps(options.steps_per_period, options.harmonics)?;
    let step = 1.0 / (options.frequency_hz * options.steps_per_period as f64);
    let mut integrator = Integrator::new(model, options.scheme, step)?;
    let n = model.linear.n_dofs();
    let state = match &options.initial {
        Some(s) => integrator.resume(s, &options.load, 1.0)?,
        None => integrator.start(0.0, &vec![0.0; n], &vec![0.0; n], &options.load, 1.0)?,
    };
    run_until_periodic(
        &mut integrator,
        state,
        &options.load,
        options.frequency_hz,
        options.steps_per_period,
        options.tolerance,
        options.max_periods,
        &options.record_dofs,
        options.mode_shapes.as_ref(),
        (options.periodic_on_recorded, options.min_periods),
    )
}

/// The loop of [`steady_state`] on an existing integrator whose step is `1/(f P)`, from a
/// state at phase 0.
#[allow(clippy::too_many_arguments)]
pub(crate) fn run_until_periodic(
    integrator: &mut Integrator,
    mut state: State,
    load: &[f64],
    frequency_hz: f64,
    steps_per_period: usize,
    tolerance: f64,
    max_periods: usize,
    record_dofs: &[usize],
    mode_shapes: Option<&faer::Mat<f64>>,
    (periodic_on_recorded, min_periods): (bool, usize),
) -> Result<SteadyState, TimesimError> {
    if !(tolerance.is_finite() && tolerance > 0.0) {
        return Err(TimesimError::Invalid(format!("the periodicity tolerance must be > 0, got {tolerance}")));
    }
    // The check keeps one period of every DOF: bound it (a sweep starting far below its end
    // frequency has a very long start period).
    let kept = steps_per_period as f64 * integrator.model().linear.n_dofs() as f64;
    if kept > MAX_PERIOD_VALUES {
        return Err(TimesimError::Invalid(format!(
            "one period of {steps_per_period} steps × {} DOFs is {kept:.3e} values to compare, more than {MAX_PERIOD_VALUES:.1e} (2 GB): use fewer steps per period, or start a sweep nearer its end frequency",
            integrator.model().linear.n_dofs()
        )));
    }
    if periodic_on_recorded && record_dofs.is_empty() {
        return Err(TimesimError::Invalid("periodicity judged on the recorded DOFs, but none is recorded".into()));
    }
    let model = integrator.model();
    let n = model.linear.n_dofs();
    let p = steps_per_period;
    let omega = 2.0 * std::f64::consts::PI * frequency_hz;
    let step = integrator.step_size();
    let (alpha, _, _) = integrator.parameters();
    let mut records = Records::new(model, record_dofs, mode_shapes)?;
    let mut slider = vec![0.0; integrator.n_directions()];
    // Displacements one period back, overwritten as the period advances: a single n × P buffer.
    let mut previous = vec![0.0; n * p];
    let mut below = 0;
    let mut criterion = f64::INFINITY;
    for period in 1..=max_periods {
        records.clear();
        let tally = state.energy.clone();
        let t0 = state.time;
        let (mut diff, mut amp) = (0.0f64, 0.0f64);
        for j in 0..p {
            records.push(model, &state, &mut slider);
            if periodic_on_recorded {
                for (k, x) in records.displacement.iter().enumerate() {
                    let (u, pr) = (x[j], &mut previous[k * p + j]);
                    diff = diff.max((u - *pr).abs());
                    amp = amp.max(u.abs());
                    *pr = u;
                }
            } else {
                for (pr, &u) in previous[j * n..(j + 1) * n].iter_mut().zip(&state.displacement) {
                    diff = diff.max((u - *pr).abs());
                    amp = amp.max(u.abs());
                    *pr = u;
                }
            }
            // Phases from the step index, not the accumulated time, so that round-off does
            // not shift the excitation over thousands of periods.
            let t_end = (j + 1) as f64 * step;
            let eval = (omega * (t_end + alpha * step)).cos();
            integrator.step(&mut state, load, eval, (omega * t_end).cos())?;
        }
        state.time = t0 + p as f64 * step;
        if period > min_periods.max(1) {
            criterion = if amp > 0.0 { diff / amp } else { 0.0 };
            below = if criterion < tolerance { below + 1 } else { 0 };
            if below >= 2 {
                return Ok(SteadyState {
                    frequency_hz,
                    step,
                    periods: period,
                    periodicity: criterion,
                    records,
                    energy: CycleEnergy::between(&tally, &state.energy),
                    final_state: state,
                });
            }
        }
    }
    Err(TimesimError::NotPeriodic { frequency_hz, periods: max_periods, criterion, tolerance })
}
