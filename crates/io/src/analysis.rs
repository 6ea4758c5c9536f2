//! A study's frequency sweep at one force level, from the study's settings to result records:
//! the harmonic balance with condensation (core `hbm`) continued across the band (core
//! `continuation`), each converged point post-processed (core `post`) into an
//! [`output::PointRecord`](crate::output::PointRecord); and the [`ReportData`] of a whole run
//! ([`report_data`]).

use std::collections::BTreeMap;
use std::path::PathBuf;
use std::time::Instant;

use faer::MatMut;
use stickslip_core::continuation::{
    Accepted, Bracket, Branch, FactoredJacobian, Observer, Options, PointObserver, Predictor, Problem, ProblemError,
    Rejection, Scales, Silent, TerminationReason, TestFunctions,
};
use stickslip_core::hbm::bifurcation::is_stable;
use stickslip_core::hbm::dlft::{self, DlftFrequencySweep, DlftHbm};
use stickslip_core::hbm::receptance::Outputs;
use stickslip_core::hbm::{
    floquet_bifurcations, folds_and_branch_points, nonlinear_mode, stability_at_last_evaluation, sweep_frequency,
    sweep_level, Backbone, BranchStabilityError, CondensedHbm, FrequencySweep, HbmError,
    HbmSettings as CoreHbmSettings, Hill, HillSettings, NegativeDamping, NonlinearModeError, NonlinearModeSettings,
    Receptance, Stability, SweepError,
};
use stickslip_core::model::NonlinearModel;
use stickslip_core::post::{
    evaluate_dlft_point, evaluate_point, output_amplitude, point_result_with, OutputSelector, PointResult, TimeSeries,
};

use crate::output::{
    harmonics_from_coefficients, BifurcationRecord, ElementRecord, JointSides, LevelResult, OutputRecord, Peak,
    PointRecord, PointStability, SnapshotResult,
};
use crate::report::{
    number, peaks, JointSummary, LevelSummary, ModelSummary, NaturalFrequencies, ReportData, SweepSummary,
};
use crate::study::{
    self, ContactMethod, ContactSpec, ContactStiffness, DampingSpec, Excitation, JointStiffness, LawSpec, ModelSpec,
    OutputSpec, Placement, ReductionMethod, Snapshot, Study,
};

const TWO_PI: f64 = 2.0 * std::f64::consts::PI;

/// The backbone of a study's `[nonlinear_mode]` (`None` without that section), with the
/// names of its outputs (the section's, or every output of the study) in the order of the
/// points' output harmonics.
pub fn run_nonlinear_mode<O: Observer + ?Sized>(
    study: &Study,
    model: &NonlinearModel,
    outputs: &[OutputSpec],
    observer: &mut O,
) -> Option<Result<(Backbone, Vec<String>), NonlinearModeError>> {
    let spec = study.nonlinear_mode.as_ref()?;
    let chosen: Vec<&OutputSpec> = if spec.outputs.is_empty() {
        outputs.iter().collect()
    } else {
        spec.outputs.iter().filter_map(|n| outputs.iter().find(|o| &o.name == n)).collect()
    };
    let vectors: Vec<&[f64]> = chosen.iter().map(|o| o.vector.as_slice()).collect();
    let settings = NonlinearModeSettings {
        mode: spec.mode - 1,
        hbm: CoreHbmSettings { harmonics: study.hbm.harmonics, samples: study.hbm.samples },
        negative_damping: if spec.target_mode_only {
            NegativeDamping::TargetMode
        } else {
            NegativeDamping::MassProportional
        },
    };
    // Steps are scaled arclengths in log10 of the amplitude (1 = the whole range): at most
    // 1/20 of a decade (or of the range), so that the plots resolve the rise of damping at
    // the first slip; the continuation refines at the corners of stick/slip transitions.
    // Residuals are of order one (the balance is scaled by the amplitude), so the study's
    // relative tolerance applies as it is.
    let decades = (spec.amplitude_end / spec.amplitude_start).log10();
    let max_step = (0.05 / decades).min(0.05);
    let options = Options {
        max_step,
        initial_step: max_step.min(1e-2),
        max_iterations: study.hbm.max_iterations,
        rtol: study.hbm.tolerance,
        max_points: spec.max_points,
        ..Options::default()
    };
    let result =
        nonlinear_mode(model, &settings, spec.amplitude_start, spec.amplitude_end, &vectors, &options, observer)
            .map(|b| (b, chosen.iter().map(|o| o.name.clone()).collect()));
    Some(result)
}

/// With a general damping matrix, Hill's method drops the damping of the modes it does not keep
/// and its coupling to the kept ones (docs/stability.md): said when it keeps fewer modes than
/// the model has, so that the exponents are read as approximate.
fn stability_note(hill: &Hill, receptance: &Receptance) -> Option<String> {
    let Receptance::Direct(direct) = receptance else { return None };
    let all = direct.natural_frequencies().len();
    (hill.n_modes() < all).then(|| {
        format!(
            "stability: Hill's method keeps {} of the model's {all} modes (natural frequencies up to (N + 1) times the band's top, at most 24); with a damping matrix, the damping of the others and its coupling to the kept ones are left out, so the Floquet exponents are approximate",
            hill.n_modes()
        )
    })
}

/// The result of one level: the records of every converged point, and why the branch ended.
pub struct LevelRun {
    pub result: LevelResult,
    pub termination: TerminationReason,
    /// Total Newton iterations and residual evaluations over the sweep.
    pub newton_iterations: usize,
    pub evaluations: usize,
    /// What the sweep did that the user should know (e.g. a start moved off a resonance).
    pub note: Option<String>,
    /// For a branch that stopped short, what was found where it stopped (a singular balance).
    pub diagnosis: Option<String>,
    /// Where the level's time went.
    pub seconds: LevelSeconds,
}

/// The wall clock of a level's stages (s), so that a user sees what the located peaks and
/// bifurcations add to the sweep.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct LevelSeconds {
    /// The continuation across the band, with each point's record (and stability).
    pub sweep: f64,
    /// The resonance peaks located between the points (peaks.csv).
    pub peaks: f64,
    /// The bifurcations located between the points (bifurcations.csv).
    pub bifurcations: f64,
}

impl LevelRun {
    /// Did the branch cross the whole band?
    pub fn is_complete(&self) -> bool {
        matches!(self.termination, TerminationReason::ReachedEnd)
    }

    /// Why the branch ended, for users, with the diagnosis of a stop.
    pub fn ending(&self) -> String {
        describe_termination_with(&self.termination, self.diagnosis.as_deref())
    }
}

/// Continuation options of a study: steps in Hz become scaled arclengths (1 = the whole band,
/// Eq. 31's scaling is automatic), the Newton tolerance is relative to the linear response.
pub fn continuation_options(study: &Study) -> Options {
    let band = (study.sweep.end_hz - study.sweep.start_hz).abs();
    let c = &study.continuation;
    Options {
        predictor: match c.predictor {
            study::Predictor::Secant => Predictor::Secant,
            study::Predictor::Tangent => Predictor::Tangent,
            study::Predictor::Lagrange => Predictor::Lagrange,
        },
        initial_step: study.sweep.step_hz / band,
        min_step: c.min_step_hz / band,
        max_step: c.max_step_hz / band,
        max_iterations: study.hbm.max_iterations,
        rtol: study.hbm.tolerance,
        max_points: c.max_points,
        ..Options::default()
    }
}

/// Sweep the band of `study` at force `level` (N). Every converged point is kept, whatever
/// ends the branch; `observer` sees each point as it is accepted. For several levels of one
/// study, [`LevelSweeper`] sets the model's linear part up once.
pub fn run_level<O: Observer + ?Sized>(
    study: &Study,
    model: &NonlinearModel,
    excitation: &Excitation,
    outputs: &[OutputSpec],
    level: f64,
    observer: &mut O,
) -> Result<LevelRun, SweepError> {
    LevelSweeper::new(study, model, excitation, outputs)?.run(level, observer)
}

/// What the force levels of a study share, set up once: the balance's linear part (the
/// receptance, from the model's modes), Hill's setup when stability is asked, the outputs.
/// Each level sweeps with a balance of its own that shares the linear part
/// ([`CondensedHbm::share_linear_part`], [`DlftHbm::share_linear_part`]), so levels run in
/// parallel on one sweeper.
pub struct LevelSweeper<'a> {
    study: &'a Study,
    hbm: Balance<'a>,
    hill: Option<Hill>,
    selectors: Vec<OutputSelector>,
}

/// The balance a study solves: the condensed balance of its elements
/// (`contact_method = "penalty"`), or the DLFT balance of its rigid contacts (`"dlft"`). Both
/// recover the outputs from the forces on their directions (core `post`), so a point of either
/// is one [`PointRecord`].
// One per level, moved once: the size difference of the variants costs nothing.
#[allow(clippy::large_enum_variant)]
enum Balance<'m> {
    Penalty(CondensedHbm<'m>),
    Dlft(DlftHbm),
}

impl<'m> Balance<'m> {
    /// The balance of `study` on `model`; `omega` (rad/s) is where the DLFT penalty ε is taken
    /// (the structure's dynamic stiffness there, core `DlftHbm::for_model`; the collocated
    /// solution does not depend on it).
    fn new(study: &Study, model: &'m NonlinearModel, excitation: &Excitation, omega: f64) -> Result<Self, HbmError> {
        let settings = CoreHbmSettings { harmonics: study.hbm.harmonics, samples: study.hbm.samples };
        Ok(match study.hbm.contact_method {
            ContactMethod::Penalty => Balance::Penalty(CondensedHbm::new(model, &excitation.pattern, settings)?),
            ContactMethod::Dlft => Balance::Dlft(DlftHbm::for_model(model, &excitation.pattern, settings, omega)?),
        })
    }

    fn share_linear_part(&self) -> Self {
        match self {
            Balance::Penalty(h) => Balance::Penalty(h.share_linear_part()),
            Balance::Dlft(d) => Balance::Dlft(d.share_linear_part()),
        }
    }

    fn sweep_frequency<O>(
        &mut self,
        level: f64,
        omega_start: f64,
        omega_end: f64,
        options: &Options,
        observer: &mut O,
    ) -> Result<Branch, SweepError>
    where
        O: ?Sized + for<'a> PointObserver<FrequencySweep<'a, 'm>> + for<'a> PointObserver<DlftFrequencySweep<'a>>,
    {
        match self {
            Balance::Penalty(h) => sweep_frequency(h, level, omega_start, omega_end, options, observer),
            Balance::Dlft(d) => dlft::sweep_frequency(d, level, omega_start, omega_end, options, observer),
        }
    }

    fn sweep_level<O: Observer + ?Sized>(
        &mut self,
        omega: f64,
        level_start: f64,
        level_end: f64,
        options: &Options,
        observer: &mut O,
    ) -> Result<Branch, SweepError> {
        match self {
            Balance::Penalty(h) => sweep_level(h, omega, level_start, level_end, options, observer),
            Balance::Dlft(d) => dlft::sweep_level(d, omega, level_start, level_end, options, observer),
        }
    }

    fn evaluate_point(
        &mut self,
        x: &[f64],
        omega: f64,
        level: f64,
        selectors: &[OutputSelector],
    ) -> Result<PointResult, HbmError> {
        match self {
            Balance::Penalty(h) => evaluate_point(h, x, omega, level, selectors),
            Balance::Dlft(d) => evaluate_dlft_point(d, x, omega, level, selectors),
        }
    }

    /// The balance continued in frequency at `level`, for the location of peaks.
    fn frequency_problem(&mut self, level: f64) -> FrequencyProblem<'_, 'm> {
        match self {
            Balance::Penalty(hbm) => FrequencyProblem::Penalty(FrequencySweep { hbm, level }),
            // The bracket scales x by its own three points, not by the problem's scales.
            Balance::Dlft(dlft) => FrequencyProblem::Dlft(DlftFrequencySweep { dlft, level, unknowns_scale: None }),
        }
    }
}

/// A [`Balance`] continued in frequency: the core problem of its kind.
enum FrequencyProblem<'a, 'm> {
    Penalty(FrequencySweep<'a, 'm>),
    Dlft(DlftFrequencySweep<'a>),
}

impl FrequencyProblem<'_, '_> {
    fn level(&self) -> f64 {
        match self {
            FrequencyProblem::Penalty(p) => p.level,
            FrequencyProblem::Dlft(p) => p.level,
        }
    }

    /// `selector` prepared for the recovery of the penalty balance's outputs (its modal
    /// projection, made once per peak rather than at every point of the bracket).
    fn prepare(&self, selector: &OutputSelector) -> Outputs {
        match self {
            FrequencyProblem::Penalty(p) => p.hbm.receptance().outputs(&[&selector.vector]),
            FrequencyProblem::Dlft(p) => p.dlft.receptance().outputs(&[&selector.vector]),
        }
    }

    /// |X₁| of `selector` (`prepared` by [`Self::prepare`]) at the solution `x`, Ω: for the
    /// penalty balance recovered alone from the evaluation that solved the point (core
    /// `output_amplitude`), for DLFT from the point's results.
    fn peak_quantity(
        &mut self,
        x: &[f64],
        omega: f64,
        selector: &OutputSelector,
        prepared: &Outputs,
    ) -> Result<f64, HbmError> {
        let level = self.level();
        match self {
            FrequencyProblem::Penalty(p) => output_amplitude(p.hbm, x, omega, level, prepared, 1),
            FrequencyProblem::Dlft(p) => {
                let r = evaluate_dlft_point(p.dlft, x, omega, level, std::slice::from_ref(selector))?;
                Ok(r.outputs[0].harmonic(1).0)
            }
        }
    }
}

impl Problem for FrequencyProblem<'_, '_> {
    fn dimension(&self) -> usize {
        match self {
            FrequencyProblem::Penalty(p) => p.dimension(),
            FrequencyProblem::Dlft(p) => p.dimension(),
        }
    }

    fn evaluate(
        &mut self,
        x: &[f64],
        lambda: f64,
        residual: &mut [f64],
        jacobian: Option<(MatMut<'_, f64>, &mut [f64])>,
    ) -> Result<(), ProblemError> {
        match self {
            FrequencyProblem::Penalty(p) => p.evaluate(x, lambda, residual, jacobian),
            FrequencyProblem::Dlft(p) => p.evaluate(x, lambda, residual, jacobian),
        }
    }

    fn scales(&self) -> Scales {
        match self {
            FrequencyProblem::Penalty(p) => p.scales(),
            FrequencyProblem::Dlft(p) => p.scales(),
        }
    }

    fn factored(&mut self) -> Option<&mut dyn FactoredJacobian> {
        match self {
            FrequencyProblem::Penalty(p) => p.factored(),
            FrequencyProblem::Dlft(p) => p.factored(),
        }
    }

    fn completes_jacobian(&self) -> bool {
        match self {
            FrequencyProblem::Penalty(p) => p.completes_jacobian(),
            FrequencyProblem::Dlft(p) => p.completes_jacobian(),
        }
    }

    fn complete_jacobian(&mut self, jacobian: (MatMut<'_, f64>, &mut [f64])) -> Result<(), ProblemError> {
        match self {
            FrequencyProblem::Penalty(p) => p.complete_jacobian(jacobian),
            FrequencyProblem::Dlft(p) => p.complete_jacobian(jacobian),
        }
    }

    fn decoupled_unknowns(&self) -> Option<&[usize]> {
        match self {
            FrequencyProblem::Penalty(p) => p.decoupled_unknowns(),
            FrequencyProblem::Dlft(p) => p.decoupled_unknowns(),
        }
    }

    fn decoupled_block_is_identity(&self) -> bool {
        match self {
            FrequencyProblem::Penalty(p) => p.decoupled_block_is_identity(),
            FrequencyProblem::Dlft(p) => p.decoupled_block_is_identity(),
        }
    }
}

impl<'a> LevelSweeper<'a> {
    pub fn new(
        study: &'a Study,
        model: &'a NonlinearModel,
        excitation: &Excitation,
        outputs: &[OutputSpec],
    ) -> Result<Self, SweepError> {
        // ε of a DLFT balance at the band's centre.
        let centre = TWO_PI * 0.5 * (study.sweep.start_hz + study.sweep.end_hz);
        let hbm = Balance::new(study, model, excitation, centre)?;
        let hill = match (study.hbm.stability, &hbm) {
            (true, Balance::Penalty(hbm)) => {
                let omega_max = TWO_PI * study.sweep.start_hz.max(study.sweep.end_hz);
                let settings = HillSettings::for_band(study.hbm.harmonics, omega_max);
                Some(Hill::new(hbm.receptance(), settings).map_err(BranchStabilityError::from)?)
            }
            // Refused by the study's validation: Hill's method is written for the elements of
            // the penalty balance.
            (true, Balance::Dlft(_)) => {
                return Err(SweepError::Hbm(HbmError::Model(stickslip_core::model::ModelError::Invalid(
                    "stability is not available with rigid contacts (contact_method = \"dlft\")".into(),
                ))))
            }
            (false, _) => None,
        };
        Ok(LevelSweeper { study, hbm, hill, selectors: selectors(outputs) })
    }

    /// Sweep the band at force `level` (N), as [`run_level`].
    pub fn run<O: Observer + ?Sized>(&self, level: f64, observer: &mut O) -> Result<LevelRun, SweepError> {
        let (study, hill, selectors) = (self.study, self.hill.as_ref(), self.selectors.as_slice());
        let mut hbm = self.hbm.share_linear_part();
        let options = continuation_options(study);
        let mut recorder = PointRecorder {
            study,
            hill,
            selectors,
            level,
            progress: observer,
            points: Vec::new(),
            stabilities: Vec::new(),
            tests: Vec::new(),
            error: None,
        };
        let (start, end) = (TWO_PI * study.sweep.start_hz, TWO_PI * study.sweep.end_hz);
        let started = Instant::now();
        let branch: Branch = hbm.sweep_frequency(level, start, end, &options, &mut recorder)?;
        let sweep_seconds = started.elapsed().as_secs_f64();
        if let Some(error) = recorder.error {
            return Err(error);
        }
        let PointRecorder { points, stabilities, tests, .. } = recorder;
        let started = Instant::now();
        let peaks = locate_peaks(&mut hbm, &branch, level, selectors, &points);
        let peaks_seconds = started.elapsed().as_secs_f64();
        let started = Instant::now();
        // Folds and branch points at every sweep; period doublings and Neimark-Sacker
        // bifurcations where the stability is known.
        let mut found =
            folds_and_branch_points(&mut hbm.frequency_problem(level), &branch.points, &tests, BIFURCATION_TOLERANCE);
        if let (Some(hill), Balance::Penalty(hbm)) = (hill, &mut hbm) {
            found.extend(floquet_bifurcations(hbm, hill, level, &branch.points, &stabilities, BIFURCATION_TOLERANCE));
            found.sort_by_key(|b| b.after_point);
        }
        let bifurcations = found
            .into_iter()
            .map(|b| -> Result<BifurcationRecord, SweepError> {
                let result = hbm.evaluate_point(&b.x, b.omega, level, selectors)?;
                Ok(BifurcationRecord {
                    level_n: level,
                    kind: b.kind.name().to_string(),
                    frequency_hz: b.omega / TWO_PI,
                    harmonics: result
                        .outputs
                        .iter()
                        .map(|o| (o.name.clone(), harmonics_from_coefficients(&o.coeffs)))
                        .collect(),
                    exponent_im: b.exponent.map_or(0.0, |e| e.im),
                    located: b.located,
                })
            })
            .collect::<Result<Vec<_>, _>>()?;
        let seconds =
            LevelSeconds { sweep: sweep_seconds, peaks: peaks_seconds, bifurcations: started.elapsed().as_secs_f64() };
        let start_note = branch.points.first().filter(|p| p.lambda != TWO_PI * study.sweep.start_hz).map(|p| {
            format!(
                "the band starts where a harmonic of the excitation meets a natural frequency of the undamped linear model (its linear response is infinite there): the branch starts {:.3e} Hz off, at {} Hz",
                (p.lambda / TWO_PI - study.sweep.start_hz).abs(),
                p.lambda / TWO_PI
            )
        });
        let resumed_notes = branch.resumed.iter().map(|r| {
            format!(
                "the continuation stopped after {:.6} Hz (every step and leap failed) and was resumed: started again at {:.6} Hz and followed back to the stop, it arrived at the same solution, and the branch goes on from there",
                r.stopped_at / TWO_PI,
                r.restarted_at / TWO_PI
            )
        });
        let stability_note = match (hill, &hbm) {
            (Some(hill), Balance::Penalty(hbm)) => stability_note(hill, hbm.receptance()),
            _ => None,
        };
        let note = start_note.into_iter().chain(resumed_notes).chain(stability_note).collect::<Vec<_>>();
        let note = (!note.is_empty()).then(|| note.join("; "));
        // A branch that stopped: at its last point, or where Newton last stopped beyond it.
        let singular_note = match (&branch.termination, branch.points.last(), &mut hbm) {
            (TerminationReason::StepTooSmall { last_iterate, .. }, Some(last), Balance::Penalty(hbm)) => {
                singular_directions(hbm, &last.x, last.lambda, level, "the last point").or_else(|| {
                    let (x, omega) = last_iterate.as_ref()?;
                    singular_directions(hbm, x, *omega, level, "the last Newton iterate beyond it")
                })
            }
            _ => None,
        };
        Ok(LevelRun {
            note,
            diagnosis: singular_note,
            newton_iterations: branch.points.iter().map(|p| p.iterations).sum(),
            evaluations: branch.calls.residuals,
            result: LevelResult { level_n: level, points, peaks, bifurcations },
            termination: branch.termination,
            seconds,
        })
    }
}

/// The record of each point of a level (its stability, when asked, and the test functions of
/// folds and branch points) made as the continuation accepts it. For the penalty balance from
/// the evaluation that converged there (core [`point_result_with`], its time series where kept;
/// [`stability_at_last_evaluation`]): nothing is evaluated again after the branch. Progress
/// goes on to the caller's observer.
struct PointRecorder<'s, O: ?Sized> {
    study: &'s Study,
    hill: Option<&'s Hill>,
    selectors: &'s [OutputSelector],
    level: f64,
    progress: &'s mut O,
    points: Vec<PointRecord>,
    stabilities: Vec<Stability>,
    /// Per point, the continuation's test functions ([`Accepted::test_functions_estimate`]).
    tests: Vec<Option<TestFunctions>>,
    /// The first failure to post-process a point (the branch runs on; the level reports it).
    error: Option<SweepError>,
}

impl<O: Observer + ?Sized> PointRecorder<'_, O> {
    /// Record the accepted point from its results (made by `results`) and, with `stability`,
    /// its Floquet exponents.
    fn record<P: Problem + ?Sized>(
        &mut self,
        accepted: &mut Accepted<'_, P>,
        results: impl FnOnce(&mut P, &[f64], f64) -> Result<(PointResult, Option<Stability>), SweepError>,
    ) {
        self.progress.on_point(accepted.point(), accepted.fraction_done());
        if self.error.is_some() {
            return;
        }
        // The measure Newton's tolerance applies to: ‖R‖ relative to the residual scale.
        let residual = accepted.point().residual_norm / accepted.residual_scale();
        let (iterations, index) = (accepted.point().iterations, self.points.len());
        let (x, omega) = (accepted.point().x.clone(), accepted.point().lambda);
        // Before the problem is handed out: from the corrector's last factorisation, or the
        // Jacobian completed from the converged evaluation. A point where they cannot be made
        // has none (the folds and branch points on its two sides are not sought).
        self.tests.push(accepted.test_functions_estimate().ok().flatten().cloned());
        match results(accepted.problem(), &x, omega) {
            Ok((result, stability)) => {
                let mut point = record(&result, iterations, residual, self.study.output_options.time_data.keeps(index));
                if let Some(stability) = stability {
                    let leading = stability.leading();
                    point.stability = Some(PointStability {
                        stable: is_stable(&stability, omega),
                        exponent_re: leading.re,
                        exponent_im: leading.im,
                    });
                    self.stabilities.push(stability);
                }
                self.points.push(point);
            }
            Err(error) => self.error = Some(error),
        }
    }
}

impl<'a, 'm, O: Observer + ?Sized> PointObserver<FrequencySweep<'a, 'm>> for PointRecorder<'_, O> {
    fn on_accepted(&mut self, accepted: &mut Accepted<'_, FrequencySweep<'a, 'm>>) {
        let (hill, selectors) = (self.hill, self.selectors);
        // The time series only where the point's time data is kept.
        let series = match self.study.output_options.time_data.keeps(self.points.len()) {
            true => TimeSeries::Kept,
            false => TimeSeries::Skipped,
        };
        self.record(accepted, |problem, x, omega| {
            let result = point_result_with(problem.hbm, x, selectors, series)?;
            let stability = hill.map(|hill| stability_at_last_evaluation(problem.hbm, hill, x, omega)).transpose()?;
            Ok((result, stability))
        });
    }
}

impl<'a, O: Observer + ?Sized> PointObserver<DlftFrequencySweep<'a>> for PointRecorder<'_, O> {
    fn on_accepted(&mut self, accepted: &mut Accepted<'_, DlftFrequencySweep<'a>>) {
        let (selectors, level) = (self.selectors, self.level);
        self.record(accepted, |problem, x, omega| {
            Ok((evaluate_dlft_point(problem.dlft, x, omega, level, selectors)?, None))
        });
    }
}

/// Relative precision of a located peak on its bracket's chord (two continuation steps): far
/// below any point density. The top of a friction peak is often a corner between two arcs,
/// where the amplitude falls linearly away (by ~1e-3 of itself per unit of the chord on Table
/// 6): 1e-5 there leaves ~1e-8 of the amplitude (measured on every shipped example against
/// 1e-7: at most 3.2e-8 in amplitude and 1.4e-7 in frequency), far below the 1e-5 by which a
/// friction peak's arcs differ (the search steps onto a corner from the lines of its sides,
/// then once either side of it); a smooth top is found to far better (the amplitude is
/// quadratic there).
const PEAK_TOLERANCE: f64 = 1e-5;

/// Precision of a located bifurcation on the chord between its two points: the Floquet
/// exponent is linear in the arclength there, so this is reached in a few solves.
const BIFURCATION_TOLERANCE: f64 = 1e-10;

/// Per output, the resonance peak of |X₁|/F located along the branch between the neighbours of
/// its largest sampled point ([`Bracket::maximise`]), so that the peak table does not depend on
/// the point density. Outputs that peak at the same sampled point share the points solved
/// around it (a structure's outputs mostly resonate together). At an end of the band, or if
/// the location fails, the sampled point.
fn locate_peaks(
    hbm: &mut Balance<'_>,
    branch: &Branch,
    level: f64,
    selectors: &[OutputSelector],
    records: &[PointRecord],
) -> Vec<Peak> {
    let mut peaks = Vec::with_capacity(selectors.len());
    // The bracket around each sampled maximum, made once (`None`: it could not be).
    let mut brackets: BTreeMap<usize, Option<Bracket>> = BTreeMap::new();
    for (o, selector) in selectors.iter().enumerate() {
        let Some(i) = (0..records.len())
            .filter(|&i| records[i].outputs[o].disp_frf.is_finite())
            .max_by(|&a, &b| records[a].outputs[o].disp_frf.total_cmp(&records[b].outputs[o].disp_frf))
        else {
            continue;
        };
        let sampled = Peak {
            level_n: level,
            output: selector.name.clone(),
            frequency_hz: records[i].frequency_hz,
            disp_frf: records[i].outputs[o].disp_frf,
            accel_frf: records[i].outputs[o].accel_frf,
            located: false,
        };
        if i == 0 || i + 1 == branch.points.len() {
            peaks.push(sampled);
            continue;
        }
        let mut problem = hbm.frequency_problem(level);
        let prepared = problem.prepare(selector);
        let bracket = brackets.entry(i).or_insert_with(|| {
            Bracket::new(&mut problem, [&branch.points[i - 1], &branch.points[i], &branch.points[i + 1]]).ok()
        });
        let found = bracket.as_mut().map(|bracket| {
            bracket.maximise(&mut problem, PEAK_TOLERANCE, |p, x, omega| {
                p.peak_quantity(x, omega, selector, &prepared).map_err(|e| ProblemError::new(e.to_string()))
            })
        });
        peaks.push(match found {
            Some(Ok(e)) if e.value / level >= sampled.disp_frf => Peak {
                frequency_hz: e.lambda / TWO_PI,
                disp_frf: e.value / level,
                accel_frf: e.lambda * e.lambda * e.value / level,
                located: true,
                ..sampled
            },
            _ => sampled,
        });
    }
    peaks
}

/// A snapshot that could not be computed.
#[derive(Debug, thiserror::Error)]
pub enum SnapshotError {
    #[error(transparent)]
    Sweep(#[from] SweepError),
    #[error("[[snapshot]] at {frequency_hz} Hz, {level} N: the continuation in the force level from {start} N {why}")]
    NotReached { frequency_hz: f64, level: f64, start: f64, why: String },
}

/// The periodic response of a `[[snapshot]]`: continued in the force level at its fixed
/// frequency from a thousandth of the level, where the joints stick, up to the level (the path
/// of a test's force ramp at a fixed frequency), then post-processed with its time signals.
///
/// For each joint placed `between` DOFs A and B where B is an output, the velocities of both
/// sides: B's is recovered as for any output, A's is B's plus the slider velocity of Eq. 33
/// (the joint's stiffness is a contact's, its elastic stroke negligible: the paper's Figs.
/// 22-23 compare a blade top P with its envelope contact B so).
pub fn run_snapshot(
    study: &Study,
    model: &NonlinearModel,
    excitation: &Excitation,
    outputs: &[OutputSpec],
    snapshot: &Snapshot,
) -> Result<SnapshotResult, SnapshotError> {
    let omega = TWO_PI * snapshot.frequency_hz;
    let mut hbm = Balance::new(study, model, excitation, omega).map_err(SweepError::from)?;
    let selectors = selectors(outputs);
    let point = solve_at(study, &mut hbm, &selectors, snapshot.frequency_hz, snapshot.level, true)?;
    let sides = study
        .joints
        .iter()
        .filter_map(|j| {
            let Placement::Between(a, b) = &j.placement else { return None };
            // A one-direction joint's record has the joint's name (contacts have one per direction).
            let e = point.elements.iter().find(|e| e.name == j.name)?;
            let o = study.outputs.iter().position(|o| matches!(&o.placement, Placement::Dof(d) if d == b))?;
            let velocity_b = point.outputs[o].vel.clone();
            let velocity_a = velocity_b.iter().zip(&e.slider_velocity).map(|(v, w)| v + w).collect();
            Some(JointSides { joint: j.name.clone(), dof_a: a.clone(), dof_b: b.clone(), velocity_a, velocity_b })
        })
        .collect();
    Ok(SnapshotResult { level_n: snapshot.level, point, sides })
}

/// The response at one frequency and level, reached by a force ramp at that frequency from a
/// thousandth of the level (see [`run_snapshot`]), post-processed into a record (with its time
/// signals if `time_data`).
fn solve_at(
    study: &Study,
    hbm: &mut Balance<'_>,
    selectors: &[OutputSelector],
    frequency_hz: f64,
    level: f64,
    time_data: bool,
) -> Result<PointRecord, SnapshotError> {
    let omega = TWO_PI * frequency_hz;
    let start = 1e-3 * level;
    // Steps relative to the ramp (1 = the whole of it), as the band's steps are to the band.
    let options = Options { max_points: study.continuation.max_points.max(1000), ..continuation_options(study) };
    let branch = hbm.sweep_level(omega, start, level, &options, &mut Silent)?;
    let p = match (&branch.termination, branch.points.last()) {
        (TerminationReason::ReachedEnd, Some(p)) => p,
        (t, last) => {
            let reached = last.map_or(start, |p| p.lambda);
            let why = format!("stopped at {reached} N: {}", describe_termination(t));
            return Err(SnapshotError::NotReached { frequency_hz, level, start, why });
        }
    };
    let result = hbm.evaluate_point(&p.x, omega, level, selectors).map_err(SweepError::from)?;
    Ok(record(&result, p.iterations, p.residual_norm / branch.residual_scale, time_data))
}

/// The responses at the study's `[grid]` frequencies at force `level` (N), each solved on its
/// own (no sweep between them) as [`run_snapshot`] does: the FRF on a grid, as the columns of
/// `frf.csv`. A frequency that cannot be solved is an error naming it.
pub fn run_grid(
    study: &Study,
    model: &NonlinearModel,
    excitation: &Excitation,
    outputs: &[OutputSpec],
    level: f64,
) -> Result<LevelResult, SnapshotError> {
    // ε of a DLFT balance at the grid's centre.
    let (low, high) = study.grid_hz.iter().fold((f64::INFINITY, 0.0f64), |(l, h), &f| (l.min(f), h.max(f)));
    let mut hbm = Balance::new(study, model, excitation, TWO_PI * 0.5 * (low + high)).map_err(SweepError::from)?;
    let selectors = selectors(outputs);
    let points = study
        .grid_hz
        .iter()
        .map(|&f| solve_at(study, &mut hbm, &selectors, f, level, false))
        .collect::<Result<Vec<_>, _>>()?;
    Ok(LevelResult { level_n: level, points, peaks: Vec::new(), bifurcations: Vec::new() })
}

fn selectors(outputs: &[OutputSpec]) -> Vec<OutputSelector> {
    outputs.iter().map(|o| OutputSelector { name: o.name.clone(), vector: o.vector.clone() }).collect()
}

/// A point's results as a record; the time signals only when `time_data`.
pub fn record(p: &PointResult, iterations: usize, residual: f64, time_data: bool) -> PointRecord {
    let keep = |v: &Vec<f64>| if time_data { v.clone() } else { Vec::new() };
    PointRecord {
        frequency_hz: p.frequency_hz(),
        iterations,
        residual,
        outputs: p
            .outputs
            .iter()
            .map(|o| {
                let (a1, _) = o.harmonic(1);
                OutputRecord {
                    name: o.name.clone(),
                    disp_frf: a1 / p.level,
                    accel_frf: p.omega * p.omega * a1 / p.level,
                    peak: o.peak,
                    harmonics: harmonics_from_coefficients(&o.coeffs),
                    disp: keep(&o.displacement),
                    vel: keep(&o.velocity),
                }
            })
            .collect(),
        // One record per direction: `joint` for a one-direction element, `joint.1`, `joint.2`,
        // ... otherwise (as the time integrator names its records), each with its own energy.
        elements: p
            .elements
            .iter()
            .flat_map(|e| {
                let d = e.displacement.len();
                (0..d).map(move |a| ElementRecord {
                    name: if d == 1 { e.name.clone() } else { format!("{}.{}", e.name, a + 1) },
                    energy_j: if d == 1 { e.energy_per_cycle } else { e.direction_energy[a] },
                    stick_fraction: e.stick_fraction,
                    loop_u: keep(&e.displacement[a]),
                    loop_force: keep(&e.force[a]),
                    slider_velocity: keep(&e.slider_velocity[a]),
                })
            })
            .collect(),
        input_energy_j: p.excitation_work,
        viscous_energy_j: p.viscous_dissipation,
        stability: None,
    }
}

/// Largest balance whose Jacobian a stopped branch has decomposed to explain the stop (a dense
/// SVD, O(n³): measured 0.08 s at 600 unknowns, 0.3 s at 1000, 4 s at 2000).
const DIAGNOSED_UP_TO: usize = 1200;

/// Why a branch may have stopped where it did: when the balance's Jacobian at its last point
/// is singular to round-off (smallest singular value below 1e-10 of the largest), the periodic
/// solutions there are not isolated and no step can be taken along a unique branch. Said with
/// where its null vector lies: in the mean (harmonic 0) of the joints' displacements, the sign
/// of a part held by friction alone, whose mean position nothing fixes once every joint
/// holding it slips during the cycle.
fn singular_directions(hbm: &mut CondensedHbm<'_>, x: &[f64], omega: f64, level: f64, where_: &str) -> Option<String> {
    let n = hbm.dimension();
    if n > DIAGNOSED_UP_TO || !x.iter().all(|v| v.is_finite()) || !omega.is_finite() {
        return None;
    }
    let mut residual = vec![0.0; n];
    let mut jacobian = faer::Mat::<f64>::zeros(n, n);
    let jacobians = stickslip_core::hbm::Jacobians { dx: jacobian.as_mut(), domega: None, dlevel: None };
    hbm.evaluate(x, omega, level, &mut residual, Some(jacobians)).ok()?;
    let svd = jacobian.svd().ok()?;
    let s = svd.S().column_vector();
    let (largest, smallest) = (s[0], s[n - 1]);
    if smallest.is_nan() || smallest > 1e-10 * largest {
        return None;
    }
    // The null vector: the last right singular vector; its share in harmonic 0 (the first q).
    let v = svd.V().col(n - 1);
    let q = hbm.n_directions();
    let mean_share: f64 = (0..q).map(|i| v[i] * v[i]).sum::<f64>() / (0..n).map(|i| v[i] * v[i]).sum::<f64>();
    let what = if mean_share >= 0.9 {
        format!(
            "its null vector lies in the mean (harmonic 0) of the joints' displacements ({:.1} %): a part held by the joints alone has no fixed mean position once each of them slips during the cycle; hold it elastically as well (a spring in K the joints do not replace) or lower the level",
            100.0 * mean_share
        )
    } else {
        format!("its null vector has {:.1} % of its norm in harmonic 0", 100.0 * mean_share)
    };
    Some(format!(
        "at {where_}, {:.6} Hz, the harmonic balance's Jacobian is singular (smallest singular value {:.1e} of the largest): the periodic solutions there are not isolated and the branch cannot be followed uniquely; {what}",
        omega / TWO_PI,
        smallest / largest
    ))
}

/// Say why a branch ended, for users.
pub fn describe_termination(t: &TerminationReason) -> String {
    describe_termination_with(t, None)
}

/// Why a backbone ended, for users (the command line and Python): where it turned back at a
/// branch point, that point; otherwise its branch's termination.
pub fn backbone_ending(backbone: &Backbone) -> String {
    match &backbone.turned_back_at {
        Some(bp) => format!(
            "turned back at a branch point at modal amplitude {:.4e} m·√kg, {:.4} Hz, damping ratio {:.4e} (another family of periodic motions crosses the backbone there; with alike joints, one where they stop moving alike) and the backbone is written up to it; the forced responses are the reference beyond",
            bp.amplitude,
            bp.omega / TWO_PI,
            bp.damping_ratio()
        ),
        None => describe_backbone_termination(&backbone.termination),
    }
}

/// Say why a backbone ended, for users: its branch is continued in `log10` of the modal
/// amplitude, not in frequency, so its stops are said in amplitude.
pub fn describe_backbone_termination(t: &TerminationReason) -> String {
    let amplitude = |lambda: &f64| 10f64.powf(*lambda);
    match t {
        TerminationReason::ReachedEnd => "reached the last amplitude".into(),
        TerminationReason::ReturnedToStart => {
            "came back to amplitude_start after a fold in amplitude".into()
        }
        TerminationReason::MaxPoints => "stopped at [nonlinear_mode] max_points (raise it)".into(),
        TerminationReason::FirstPointFailed { lambda, residual_norm, iterations } => format!(
            "no convergence at the first amplitude, {:.4e} m·√kg, after {iterations} Newton iterations (residual {residual_norm:.3e}): start at a smaller amplitude_start",
            amplitude(lambda)
        ),
        TerminationReason::StepTooSmall { rejection, lambda, residual_norm, attempts, leaps, iterations, .. } => format!(
            "stopped after modal amplitude {:.4e} m·√kg: {attempts} steps failed, ever smaller down to the minimum step, then {leaps} leaps ever longer ({iterations} Newton iterations, last residual {residual_norm:.3e}); the last was rejected because {rejection}; try more [harmonic_balance] samples, or negative_damping = \"target_mode\" where other modes lie near a harmonic of this one",
            amplitude(lambda)
        ),
        TerminationReason::ProblemError { lambda, error, .. } => {
            format!("the harmonic balance failed at modal amplitude {:.4e} m·√kg: {error}", amplitude(lambda))
        }
    }
}

/// [`describe_termination`], with what was found where a branch stopped short in place of the
/// general advice.
fn describe_termination_with(t: &TerminationReason, diagnosis: Option<&str>) -> String {
    match t {
        TerminationReason::ReachedEnd => "reached the end of the band".into(),
        TerminationReason::ReturnedToStart => "came back to the start of the band after a fold".into(),
        TerminationReason::MaxPoints => "stopped at max_points (raise [continuation] max_points)".into(),
        TerminationReason::FirstPointFailed { lambda, residual_norm, iterations } => format!(
            "no convergence at the first point, {:.3} Hz, after {iterations} Newton iterations (residual {residual_norm:.3e}): start the band where the response is closer to linear, or use more harmonics",
            lambda / TWO_PI
        ),
        TerminationReason::StepTooSmall { rejection, lambda, residual_norm, attempts, leaps, iterations, .. } => {
            let advice = match rejection {
                _ if diagnosis.is_some() => "",
                Rejection::NewtonCycle => {
                    "; with a stiff friction joint this is a time sample switching between stick and slip: try more [harmonic_balance] samples (e.g. 512)"
                }
                _ => "; try a smaller [continuation] min_step_hz, more [harmonic_balance] samples or another predictor",
            };
            let diagnosis = diagnosis.map(|d| format!("; {d}")).unwrap_or_default();
            format!(
                "stopped after {:.3} Hz: {attempts} steps failed, ever smaller down to [continuation] min_step_hz, then {leaps} leaps ever longer ({iterations} Newton iterations, last residual {residual_norm:.3e}); the last was rejected because {rejection}{advice}{diagnosis}",
                lambda / TWO_PI
            )
        }
        TerminationReason::ProblemError { lambda, error, .. } => {
            format!("the harmonic balance failed at {:.3} Hz: {error}", lambda / TWO_PI)
        }
    }
}

/// Largest model whose natural frequencies the report computes (dense eigensolution, O(n³)).
pub const REPORT_MAX_EIGEN_DOFS: usize = 2000;
/// Natural frequencies listed in the report.
const REPORT_FREQUENCIES: usize = 12;

/// What the report of a run shows: the study and its model described, the lowest natural
/// frequencies of the analysed linear model (dense eigensolution, up to
/// [`REPORT_MAX_EIGEN_DOFS`] DOFs), how each level ended, the FRF peaks, the files written
/// (`files`, as returned by [`crate::output::write_results`]) and `timings` (`(stage, seconds)`).
pub fn report_data(
    study: &Study,
    model: &NonlinearModel,
    excitation: &Excitation,
    runs: &[LevelRun],
    files: &[PathBuf],
    timings: Vec<(String, f64)>,
) -> ReportData {
    let levels: Vec<LevelResult> = runs.iter().map(|r| r.result.clone()).collect();
    ReportData {
        title: study.path.file_name().map_or_else(|| study.path.display().to_string(), |n| n.to_string_lossy().into()),
        study_path: study.path.display().to_string(),
        model: model_summary(study, model, &excitation.pattern),
        sweep: SweepSummary {
            load: excitation.load.clone(),
            levels_n: excitation.levels_n.clone(),
            start_hz: study.sweep.start_hz,
            end_hz: study.sweep.end_hz,
            harmonics: study.hbm.harmonics,
            samples: study.hbm.samples,
        },
        levels: runs
            .iter()
            .map(|r| LevelSummary {
                level_n: r.result.level_n,
                points: r.result.points.len(),
                complete: r.is_complete(),
                ending: match &r.note {
                    Some(note) => format!("{}; {note}", r.ending()),
                    None => r.ending(),
                },
            })
            .collect(),
        peaks: peaks(&levels),
        stability: study.hbm.stability,
        bifurcations: levels.iter().flat_map(|l| l.bifurcations.iter().cloned()).collect(),
        files: files.to_vec(),
        timings,
    }
}

/// The model of a study in words, with the natural frequencies of its linear part.
fn model_summary(study: &Study, model: &NonlinearModel, pattern: &[f64]) -> ModelSummary {
    let file =
        |p: &std::path::Path| p.file_name().map_or_else(|| p.display().to_string(), |n| n.to_string_lossy().into());
    let source = match &study.model {
        ModelSpec::Inline { .. } => "matrices in the study file".to_string(),
        ModelSpec::Files { mass, stiffness, .. } => format!("matrix files {} and {}", file(mass), file(stiffness)),
        ModelSpec::Mesh { path, .. } => format!("mesh {}", file(path)),
        ModelSpec::Harmony { design, .. } => format!(
            "generated Harmony-like assembly ({} elements, size {:.1} mm)",
            design.kind.abaqus_name(),
            design.element_size * 1e3
        ),
    };
    let reduction = study.reduction.as_ref().map(|r| {
        let method = match r.method {
            ReductionMethod::CraigBampton => "Craig-Bampton".to_string(),
            ReductionMethod::FreeModes => "free modes (paper Eq. 5)".to_string(),
            ReductionMethod::Enriched { release_modes } => {
                format!("free modes enriched with {release_modes} modes of the released structure")
            }
        };
        format!("{method}, {} modes, retained {}", r.modes, r.retain.join(", "))
    });
    let damping = match &study.damping {
        DampingSpec::None => "none".to_string(),
        DampingSpec::Rayleigh { alpha, beta } => {
            format!("Rayleigh D = α M + β K, α = {} 1/s, β = {} s", number(*alpha), number(*beta))
        }
        DampingSpec::Modal { ratios } => {
            let r: Vec<String> = ratios.iter().map(|z| number(*z)).collect();
            format!("modal ratios ζ = {}", r.join(", "))
        }
        DampingSpec::Matrix(_) => "a damping matrix in the study file".to_string(),
        DampingSpec::File(path) => format!("damping matrix file {}", file(path)),
    };
    let stiffness = |s: &JointStiffness| match s {
        JointStiffness::Own(k) => format!("own stiffness {} N/m", number(*k)),
        JointStiffness::Replaces(k) => format!("stiffness {} N/m, part of K, replaced (Eq. 11)", number(*k)),
        JointStiffness::ReplacesComputed => "stiffness VᵀKV of the model, replaced (Eq. 11)".to_string(),
    };
    let joints = study
        .joints
        .iter()
        .map(|j| {
            let (law, parameters) = match &j.law {
                LawSpec::Jenkins { threshold, stiffness: s } => {
                    ("Jenkins", format!("threshold {} N, {}", number(*threshold), stiffness(s)))
                }
                LawSpec::Iwan { stiffness: s, slip_force, sliders } => {
                    ("Iwan", format!("slip force {} N, {sliders} sliders, {}", number(*slip_force), stiffness(s)))
                }
                LawSpec::Coulomb { threshold, velocity_scale } => (
                    "regularised Coulomb",
                    format!("threshold {} N, velocity scale {} m/s", number(*threshold), number(*velocity_scale)),
                ),
                LawSpec::Cubic { k3 } => ("cubic spring", format!("k3 = {} N/m³", number(*k3))),
                LawSpec::Contact(ContactSpec { tangential, preload, stiffness, friction, .. }) => (
                    match (tangential.len(), stiffness) {
                        (1, Some(_)) => "2-D point contact",
                        (_, Some(_)) => "3-D point contact",
                        (1, None) => "2-D rigid point contact (DLFT)",
                        (_, None) => "3-D rigid point contact (DLFT)",
                    },
                    match stiffness {
                        Some(ContactStiffness { normal, tangential }) => format!(
                            "N0 = {} N, k_n = {} N/m, k_t = {} N/m, μ = {}",
                            number(*preload),
                            number(*normal),
                            number(*tangential),
                            number(*friction)
                        ),
                        None => format!("N0 = {} N, rigid, μ = {}", number(*preload), number(*friction)),
                    },
                ),
            };
            let describe = |p: &Placement| match p {
                Placement::Dof(d) => format!("DOF {d} and the ground"),
                Placement::Between(a, b) => format!("DOFs {a} and {b}"),
                Placement::Vector(_) => "a vector over the DOFs".to_string(),
            };
            let placement = match &j.law {
                LawSpec::Contact(ContactSpec { tangential, normal, .. }) => format!(
                    "tangential {}; normal {}",
                    tangential.iter().map(describe).collect::<Vec<_>>().join(", "),
                    describe(normal)
                ),
                _ => describe(&j.placement),
            };
            JointSummary { name: j.name.clone(), placement, law: law.to_string(), parameters }
        })
        .collect();
    let n = model.linear.n_dofs();
    let mut load_participation = Vec::new();
    let natural_frequencies = if n > REPORT_MAX_EIGEN_DOFS {
        NaturalFrequencies::NotAvailable(format!(
            "the model has {n} DOFs, more than the {REPORT_MAX_EIGEN_DOFS} of the dense eigensolution (see `stickslip modes`)"
        ))
    } else {
        match model.linear.dense_modes() {
            Ok(modes) => {
                // Which modes the load drives: (φ_rᵀF)² of the mass-normalised modes, over their
                // sum over every mode (FᵀM⁻¹F: the dense solution has them all).
                let shapes = &modes.shapes;
                let driven: Vec<f64> = (0..shapes.ncols())
                    .map(|r| pattern.iter().enumerate().map(|(i, p)| shapes[(i, r)] * p).sum::<f64>().powi(2))
                    .collect();
                let total: f64 = driven.iter().sum();
                if total > 0.0 {
                    load_participation = driven.iter().take(REPORT_FREQUENCIES).map(|d| d / total).collect();
                }
                NaturalFrequencies::Computed(modes.frequencies_hz().into_iter().take(REPORT_FREQUENCIES).collect())
            }
            Err(e) => NaturalFrequencies::NotAvailable(format!("the eigensolution failed: {e}")),
        }
    };
    ModelSummary { source, n_dofs: n, reduction, damping, joints, natural_frequencies, load_participation }
}
