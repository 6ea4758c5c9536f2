//! The harmonic balance as a continuation problem: in the frequency Ω at a fixed force level
//! (the FRF of one level, paper Section 4.3), or in the force level at a fixed frequency. One
//! continuation code ([`crate::continuation`]) serves both.

use faer::MatMut;

use super::condensed::{CondensedHbm, HbmError, Jacobians};
use crate::continuation::{
    continue_branch, Branch, ContinuationError, FactoredJacobian, Options, PointObserver, Problem, ProblemError,
    ProgressOverWhole, Resumption, Silent, TerminationReason,
};

/// A sweep that could not start (a failure during the sweep is a termination reason of the
/// branch instead, with every point found before it).
#[derive(Debug, thiserror::Error)]
pub enum SweepError {
    #[error(transparent)]
    Hbm(#[from] HbmError),
    #[error(transparent)]
    Continuation(#[from] ContinuationError),
    #[error(transparent)]
    Stability(#[from] super::bifurcation::BranchStabilityError),
}

/// `R(x; Ω) = 0` at a fixed level, λ = Ω (rad/s).
pub struct FrequencySweep<'a, 'm> {
    pub hbm: &'a mut CondensedHbm<'m>,
    pub level: f64,
}

/// `R(x; λ_F) = 0` at a fixed Ω (rad/s), λ = the force level.
pub struct LevelSweep<'a, 'm> {
    pub hbm: &'a mut CondensedHbm<'m>,
    pub omega: f64,
}

impl Problem for FrequencySweep<'_, '_> {
    fn dimension(&self) -> usize {
        self.hbm.dimension()
    }

    fn evaluate(
        &mut self,
        x: &[f64],
        omega: f64,
        residual: &mut [f64],
        jacobian: Option<(MatMut<'_, f64>, &mut [f64])>,
    ) -> Result<(), ProblemError> {
        let jac = jacobian.map(|(dx, dl)| Jacobians { dx, domega: Some(dl), dlevel: None });
        self.hbm.evaluate(x, omega, self.level, residual, jac).map_err(problem_error)
    }

    fn completes_jacobian(&self) -> bool {
        self.hbm.completes_jacobian()
    }

    fn complete_jacobian(&mut self, (dx, dl): (MatMut<'_, f64>, &mut [f64])) -> Result<(), ProblemError> {
        completed(self.hbm.complete_jacobian(dx, Some(dl), None))
    }

    fn completion_writes_every_entry(&self) -> bool {
        true
    }

    fn decoupled_unknowns(&self) -> Option<&[usize]> {
        self.hbm.decoupled_unknowns()
    }

    fn decoupled_block_is_identity(&self) -> bool {
        self.hbm.decoupled_block_is_identity()
    }

    fn factored(&mut self) -> Option<&mut dyn FactoredJacobian> {
        if self.hbm.factors_by_structure() {
            Some(self)
        } else {
            None
        }
    }
}

impl FactoredJacobian for FrequencySweep<'_, '_> {
    fn evaluate_and_factor(
        &mut self,
        x: &[f64],
        omega: f64,
        residual: &mut [f64],
        dr_domega: &mut [f64],
    ) -> Result<bool, ProblemError> {
        self.hbm.evaluate_factored(x, omega, self.level, residual, Some(dr_domega), None).map_err(problem_error)
    }

    fn solve(&mut self, rhs: &mut [f64]) -> bool {
        self.hbm.solve_factored(rhs)
    }
}

impl Problem for LevelSweep<'_, '_> {
    fn dimension(&self) -> usize {
        self.hbm.dimension()
    }

    fn evaluate(
        &mut self,
        x: &[f64],
        level: f64,
        residual: &mut [f64],
        jacobian: Option<(MatMut<'_, f64>, &mut [f64])>,
    ) -> Result<(), ProblemError> {
        let jac = jacobian.map(|(dx, dl)| Jacobians { dx, domega: None, dlevel: Some(dl) });
        self.hbm.evaluate(x, self.omega, level, residual, jac).map_err(problem_error)
    }

    fn completes_jacobian(&self) -> bool {
        self.hbm.completes_jacobian()
    }

    fn complete_jacobian(&mut self, (dx, dl): (MatMut<'_, f64>, &mut [f64])) -> Result<(), ProblemError> {
        completed(self.hbm.complete_jacobian(dx, None, Some(dl)))
    }

    fn decoupled_unknowns(&self) -> Option<&[usize]> {
        self.hbm.decoupled_unknowns()
    }

    fn decoupled_block_is_identity(&self) -> bool {
        self.hbm.decoupled_block_is_identity()
    }

    fn factored(&mut self) -> Option<&mut dyn FactoredJacobian> {
        if self.hbm.factors_by_structure() {
            Some(self)
        } else {
            None
        }
    }
}

impl FactoredJacobian for LevelSweep<'_, '_> {
    fn evaluate_and_factor(
        &mut self,
        x: &[f64],
        level: f64,
        residual: &mut [f64],
        dr_dlevel: &mut [f64],
    ) -> Result<bool, ProblemError> {
        self.hbm.evaluate_factored(x, self.omega, level, residual, None, Some(dr_dlevel)).map_err(problem_error)
    }

    fn solve(&mut self, rhs: &mut [f64]) -> bool {
        self.hbm.solve_factored(rhs)
    }
}

/// An element that fails on a trial motion (no periodic regime, a non-finite force) rejects
/// the step, which is retried shorter; any other error ends the branch.
/// [`CondensedHbm::complete_jacobian`]'s outcome for the continuation.
fn completed(done: bool) -> Result<(), ProblemError> {
    if done {
        Ok(())
    } else {
        Err(ProblemError::new("no residual evaluation of sliders to complete to a Jacobian"))
    }
}

fn problem_error(e: HbmError) -> ProblemError {
    match e {
        HbmError::Aft(_) => ProblemError::at_trial_iterate(e.to_string()),
        _ => ProblemError::new(e.to_string()),
    }
}

/// Continue the periodic response at force level `level` from `omega_start` to `omega_end`
/// (rad/s, either direction), starting from the stuck solution.
///
/// When Newton cannot reach the first point from the stuck solution (a joint already slipping
/// hard at the start of the band), the start is found by continuation in the force level at
/// `omega_start`, from a level where the joints stick up to `level`.
pub fn sweep_frequency<'m, O: ?Sized + for<'a> PointObserver<FrequencySweep<'a, 'm>>>(
    hbm: &mut CondensedHbm<'m>,
    level: f64,
    omega_start: f64,
    omega_end: f64,
    options: &Options,
    observer: &mut O,
) -> Result<Branch, SweepError> {
    let omega_start = off_resonance(hbm, omega_start, omega_end, level)?;
    let guess = hbm.stuck_solution(omega_start, level)?;
    let ramp = |omega: f64| {
        move |hbm: &mut CondensedHbm<'m>, ramp: &Options| {
            sweep_level(hbm, omega, 1e-3 * level, level, ramp, &mut Silent)
        }
    };
    let branch = from_level_ramp(
        hbm,
        &guess,
        options,
        |hbm, guess| {
            continue_branch(&mut FrequencySweep { hbm, level }, guess, omega_start, omega_end, options, observer)
        },
        ramp(omega_start),
    )?;
    let band = (omega_end - omega_start).abs();
    Ok(resumed_past_stops(
        hbm,
        branch,
        omega_end,
        options,
        band,
        |hbm, guess, from, to| {
            let bridge = within(options, band, from, to);
            from_level_ramp(
                hbm,
                guess,
                &bridge,
                |hbm, guess| continue_branch(&mut FrequencySweep { hbm, level }, guess, from, to, &bridge, &mut Silent),
                ramp(from),
            )
        },
        |hbm, guess, from| {
            let rest = within(options, band, from, omega_end);
            let offset = 1.0 - (omega_end - from).abs() / band;
            let observer = &mut ProgressOverWhole { inner: &mut *observer, offset };
            continue_branch(&mut FrequencySweep { hbm, level }, guess, from, omega_end, &rest, observer)
        },
    ))
}

/// The options of a continuation over `from..to`, a part of a band `band` long, with the same
/// steps in λ as over the band (steps are fractions of the interval continued).
pub(crate) fn within(options: &Options, band: f64, from: f64, to: f64) -> Options {
    let scale = band / (to - from).abs().max(f64::MIN_POSITIVE);
    Options {
        initial_step: (options.initial_step * scale).min(1.0),
        min_step: (options.min_step * scale).min(1.0),
        max_step: (options.max_step * scale).min(1.0),
        ..options.clone()
    }
}

/// Stops resumed per branch, at most.
const MAX_RESUMPTIONS: usize = 4;
/// How far beyond a stop the branch is started afresh: these fractions of the largest step,
/// nearest first (the further, the likelier another branch across a jump).
const RESTART_DISTANCES: [f64; 3] = [0.0625, 0.25, 1.0];
/// A bridge arrives at the stop's solution when its last point is within this of it, relative
/// to its norm: two solutions of one branch at one λ agree to Newton's tolerance, those of two
/// branches differ at first order.
const SAME_SOLUTION: f64 = 1e-6;

/// Resume a frequency sweep that stopped before its end, where every step and leap failed (a
/// corner of a non-smooth branch: the slip instants of the joints jump, and Newton, started
/// from the tangent's prediction, cycles between slip patterns). The branch is started afresh a
/// little further on (`bridge(balance, guess, from, to)`: from the last point's solution, else
/// through the force ramp), followed back to the stop, and where it arrives at the solution the
/// branch stopped at, the sweep goes on (`forward(balance, guess, from)`) from the bridge's point
/// next to the stop: the bridge shows that the points on either side of the stop are one branch.
/// A bridge that arrives elsewhere (another branch, across a jump) or not at all leaves the stop
/// as it was, as does a rest of the sweep that fails to start. Returns the branch, its
/// resumptions in `resumed`.
pub(crate) fn resumed_past_stops<B: ?Sized>(
    balance: &mut B,
    mut branch: Branch,
    lambda_end: f64,
    options: &Options,
    band: f64,
    mut bridge: impl FnMut(&mut B, &[f64], f64, f64) -> Result<Branch, SweepError>,
    mut forward: impl FnMut(&mut B, &[f64], f64) -> Result<Branch, ContinuationError>,
) -> Branch {
    while branch.resumed.len() < MAX_RESUMPTIONS && matches!(branch.termination, TerminationReason::StepTooSmall { .. })
    {
        let Some(last) = branch.points.last() else { break };
        let (stopped_at, stop) = (last.lambda, last.x.clone());
        let left = lambda_end - stopped_at;
        let norm = stop.iter().map(|v| v * v).sum::<f64>().sqrt();
        let mut resumed = None;
        for fraction in RESTART_DISTANCES {
            let restart = stopped_at + left.signum() * (fraction * options.max_step * band).min(left.abs());
            let Ok(back) = bridge(balance, &stop, restart, stopped_at) else { continue };
            branch.calls += back.calls;
            let arrived = matches!(back.termination, TerminationReason::ReachedEnd)
                && back.points.last().is_some_and(|p| {
                    let gap = p.x.iter().zip(&stop).map(|(a, b)| (a - b) * (a - b)).sum::<f64>().sqrt();
                    gap <= SAME_SOLUTION * norm
                });
            if arrived && back.points.len() >= 2 {
                resumed = Some((restart, back.points[back.points.len() - 2].clone()));
                break;
            }
        }
        let Some((restarted_at, next)) = resumed else { break };
        // A rest that cannot even start leaves the stop as it was, with its points.
        let Ok(rest) = forward(balance, &next.x, next.lambda) else { break };
        branch.resumed.push(Resumption { stopped_at, restarted_at });
        branch.points.extend(rest.points);
        branch.termination = rest.termination;
        branch.calls += rest.calls;
        branch.residual_scale = branch.residual_scale.max(rest.residual_scale);
    }
    branch
}

/// A frequency sweep of `balance` from `guess` (`frequency`); when Newton cannot reach its
/// first point (a joint already slipping hard at the start of the band), the start is found by
/// `ramp`, a force-level continuation at the first frequency from 1/1000 of the level (stuck
/// for any joint that slips at less than 1000x the force where it slips at the level), given
/// its options (at least 1000 points), and the sweep starts again from its last point.
pub(crate) fn from_level_ramp<B: ?Sized>(
    balance: &mut B,
    guess: &[f64],
    options: &Options,
    mut frequency: impl FnMut(&mut B, &[f64]) -> Result<Branch, ContinuationError>,
    ramp: impl FnOnce(&mut B, &Options) -> Result<Branch, SweepError>,
) -> Result<Branch, SweepError> {
    let branch = frequency(balance, guess)?;
    if !matches!(branch.termination, TerminationReason::FirstPointFailed { .. }) {
        return Ok(branch);
    }
    let start = ramp(balance, &Options { max_points: options.max_points.max(1000), ..options.clone() })?;
    match (&start.termination, start.points.last()) {
        (TerminationReason::ReachedEnd, Some(p)) => Ok(frequency(balance, &p.x)?),
        _ => Ok(branch),
    }
}

/// `omega` itself if the balance can be evaluated there, else the nearest frequency towards
/// `omega_toward` where it can (1e-6 to 1e-4 of `omega` away). Without damping the flexibility
/// `H(kΩ)` is infinite where a harmonic kΩ meets a natural frequency: the condensed residual
/// (a displacement) is not defined at that exact Ω, although the response through it is.
pub fn off_resonance(hbm: &mut CondensedHbm<'_>, omega: f64, omega_toward: f64, level: f64) -> Result<f64, HbmError> {
    let n = hbm.dimension();
    let (zero, mut r) = (vec![0.0; n], vec![0.0; n]);
    // An evaluation error is the balance's, not the frequency's: reported as such.
    hbm.evaluate(&zero, omega, level, &mut r, None)?;
    Ok(off_resonance_of(&mut FrequencySweep { hbm, level }, omega, omega_toward))
}

/// [`off_resonance`] for any balance continued in frequency (λ = Ω): the first of `omega` and
/// the frequencies 1e-6, 1e-5, 1e-4 of it towards `omega_toward` where the residual at `x = 0`
/// can be evaluated and is finite; `omega` if none is.
pub fn off_resonance_of<P: Problem>(problem: &mut P, omega: f64, omega_toward: f64) -> f64 {
    let n = problem.dimension();
    let (zero, mut r) = (vec![0.0; n], vec![0.0; n]);
    let direction = if omega_toward >= omega { 1.0 } else { -1.0 };
    for shift in [0.0, 1e-6, 1e-5, 1e-4] {
        let w = omega * (1.0 + direction * shift);
        if problem.evaluate(&zero, w, &mut r, None).is_ok() && r.iter().all(|v| v.is_finite()) {
            return w;
        }
    }
    omega
}

/// Continue the periodic response at frequency `omega` (rad/s) in the force level from
/// `level_start` to `level_end`.
pub fn sweep_level<'m, O: ?Sized + for<'a> PointObserver<LevelSweep<'a, 'm>>>(
    hbm: &mut CondensedHbm<'m>,
    omega: f64,
    level_start: f64,
    level_end: f64,
    options: &Options,
    observer: &mut O,
) -> Result<Branch, SweepError> {
    let guess = hbm.stuck_solution(omega, level_start)?;
    Ok(continue_branch(&mut LevelSweep { hbm, omega }, &guess, level_start, level_end, options, observer)?)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::continuation::{Calls, Point};

    fn branch(termination: TerminationReason, x: &[f64]) -> Branch {
        let point = Point {
            x: x.to_vec(),
            lambda: 1.0,
            iterations: 1,
            residual_norm: 0.0,
            step: 0.0,
            rejected: 0,
            calls: Calls::default(),
        };
        Branch { points: vec![point], termination, calls: Calls::default(), residual_scale: 1.0, resumed: Vec::new() }
    }

    fn failed() -> TerminationReason {
        TerminationReason::FirstPointFailed { lambda: 1.0, residual_norm: 1.0, iterations: 50 }
    }

    /// The guesses the frequency sweep was started from, and the ramps' `max_points`.
    #[derive(Default)]
    struct Log {
        guesses: Vec<Vec<f64>>,
        ramps: Vec<usize>,
    }

    fn run(first_fails: bool, ramp_ends: TerminationReason) -> (Branch, Log) {
        let mut log = Log::default();
        let options = Options { max_points: 200, ..Options::default() };
        let result = from_level_ramp(
            &mut log,
            &[0.0],
            &options,
            |log, guess| {
                log.guesses.push(guess.to_vec());
                let fails = first_fails && log.guesses.len() == 1;
                Ok(branch(if fails { failed() } else { TerminationReason::ReachedEnd }, &[10.0 + guess[0]]))
            },
            |log, ramp| {
                log.ramps.push(ramp.max_points);
                Ok(branch(ramp_ends, &[7.0]))
            },
        )
        .unwrap();
        (result, log)
    }

    #[test]
    fn a_sweep_whose_first_point_converges_needs_no_ramp() {
        let (result, log) = run(false, TerminationReason::ReachedEnd);
        assert_eq!(result.termination, TerminationReason::ReachedEnd);
        assert_eq!(log.guesses, [vec![0.0]]);
        assert!(log.ramps.is_empty());
    }

    #[test]
    fn a_failed_first_point_is_reached_by_the_ramp_and_the_sweep_starts_again_from_its_end() {
        let (result, log) = run(true, TerminationReason::ReachedEnd);
        assert_eq!(result.termination, TerminationReason::ReachedEnd);
        // Started again from the ramp's last point, the ramp allowed at least 1000 points.
        assert_eq!(log.guesses, [vec![0.0], vec![7.0]]);
        assert_eq!(log.ramps, [1000]);
        assert_eq!(result.points[0].x, [17.0]);
    }

    #[test]
    fn a_ramp_that_does_not_reach_the_level_leaves_the_first_failure() {
        let (result, log) = run(true, TerminationReason::MaxPoints);
        assert!(matches!(result.termination, TerminationReason::FirstPointFailed { .. }));
        assert_eq!(log.guesses.len(), 1);
    }

    fn points(at: &[(f64, f64)]) -> Vec<Point> {
        at.iter()
            .map(|&(lambda, x)| Point {
                x: vec![x],
                lambda,
                iterations: 1,
                residual_norm: 0.0,
                step: 0.0,
                rejected: 0,
                calls: Calls::default(),
            })
            .collect()
    }

    fn stopped() -> TerminationReason {
        TerminationReason::StepTooSmall {
            rejection: crate::continuation::Rejection::NoConvergence,
            lambda: 2.0,
            residual_norm: 1e-5,
            attempts: 8,
            leaps: 7,
            iterations: 100,
            last_iterate: None,
        }
    }

    fn with(points_at: &[(f64, f64)], termination: TerminationReason) -> Branch {
        Branch {
            points: points(points_at),
            termination,
            calls: Calls::default(),
            residual_scale: 1.0,
            resumed: Vec::new(),
        }
    }

    /// Resume a branch stopped at λ = 2 (x = 2) on the way to 10, with bridges made by `bridge`
    /// (given the restart λ and the call's number) and a rest of the sweep made by `forward`;
    /// returns the result, the bridges' (guess, from, to) and the rests' (guess, from).
    #[allow(clippy::type_complexity)]
    fn resume(
        bridge: impl Fn(f64, usize) -> Result<Branch, SweepError>,
        forward: impl Fn(f64) -> Result<Branch, ContinuationError>,
    ) -> (Branch, Vec<(f64, f64, f64)>, Vec<(f64, f64)>) {
        let options = Options { max_step: 0.5, ..Options::default() };
        let (mut bridges, mut rests) = (Vec::new(), Vec::new());
        let branch = with(&[(1.0, 1.0), (2.0, 2.0)], stopped());
        let result = resumed_past_stops(
            &mut (),
            branch,
            10.0,
            &options,
            9.0,
            |_, guess, from, to| {
                bridges.push((guess[0], from, to));
                bridge(from, bridges.len())
            },
            |_, guess, from| {
                rests.push((guess[0], from));
                forward(from)
            },
        );
        (result, bridges, rests)
    }

    /// A bridge from `from` back to the stop, arriving at `x_end` there.
    fn bridge_to(from: f64, x_end: f64) -> Result<Branch, SweepError> {
        Ok(with(&[(from, from), (2.1, 2.1), (2.0, x_end)], TerminationReason::ReachedEnd))
    }

    #[test]
    fn a_stopped_sweep_goes_on_from_the_bridge_point_next_to_the_stop() {
        let (result, bridges, rests) = resume(
            |from, _| bridge_to(from, 2.0),
            |from| Ok(with(&[(from, from), (10.0, 10.0)], TerminationReason::ReachedEnd)),
        );
        // The nearest restart, 1/16 of the largest step (0.5 of the band, 9) beyond the stop,
        // from the stop's solution, followed back to the stop.
        assert_eq!(bridges, [(2.0, 2.0 + 0.0625 * 0.5 * 9.0, 2.0)]);
        assert_eq!(rests, [(2.1, 2.1)]);
        let lambdas: Vec<f64> = result.points.iter().map(|p| p.lambda).collect();
        assert_eq!(lambdas, [1.0, 2.0, 2.1, 10.0]);
        assert_eq!(result.termination, TerminationReason::ReachedEnd);
        assert_eq!(result.resumed, [Resumption { stopped_at: 2.0, restarted_at: 2.28125 }]);
    }

    #[test]
    fn a_bridge_that_arrives_at_another_solution_leaves_the_stop() {
        // Off by 1e-5 of the stop's solution: another branch (one branch agrees to Newton's
        // tolerance), at every restart distance.
        let (result, bridges, rests) = resume(|from, _| bridge_to(from, 2.0 * (1.0 + 1e-5)), |_| unreachable!());
        let restarts: Vec<f64> = bridges.iter().map(|b| b.1).collect();
        assert_eq!(restarts, [2.28125, 3.125, 6.5]);
        assert!(rests.is_empty());
        assert_eq!(result.points.len(), 2);
        assert_eq!(result.termination, stopped());
        assert!(result.resumed.is_empty());
    }

    #[test]
    fn a_bridge_that_fails_near_the_stop_is_tried_further_on() {
        let (result, bridges, _) = resume(
            |from, call| match call {
                1 => Err(SweepError::Hbm(HbmError::NotEvaluated)),
                2 => Ok(with(&[(from, from), (2.5, 2.5)], stopped())),
                _ => bridge_to(from, 2.0),
            },
            |from| Ok(with(&[(from, from), (10.0, 10.0)], TerminationReason::ReachedEnd)),
        );
        assert_eq!(bridges.len(), 3);
        assert_eq!(result.resumed, [Resumption { stopped_at: 2.0, restarted_at: 6.5 }]);
        assert_eq!(result.termination, TerminationReason::ReachedEnd);
    }

    #[test]
    fn a_branch_that_keeps_stopping_is_resumed_a_bounded_number_of_times() {
        // Every rest stops again just after its start.
        let (result, bridges, rests) =
            resume(|from, _| bridge_to(from, 2.0), |from| Ok(with(&[(from, from), (from + 0.01, 2.0)], stopped())));
        assert_eq!(rests.len(), MAX_RESUMPTIONS);
        assert_eq!(bridges.len(), MAX_RESUMPTIONS);
        assert_eq!(result.resumed.len(), MAX_RESUMPTIONS);
        assert_eq!(result.termination, stopped());
    }

    #[test]
    fn a_rest_that_fails_to_start_leaves_the_stop_with_its_points() {
        let (result, _, rests) = resume(
            |from, _| bridge_to(from, 2.0),
            |_| Err(ContinuationError::WrongGuessLength { len: 0, expected: 1 }),
        );
        assert_eq!(rests.len(), 1);
        assert_eq!(result.points.len(), 2);
        assert_eq!(result.termination, stopped());
        assert!(result.resumed.is_empty());
    }
}
