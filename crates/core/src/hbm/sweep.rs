//! The harmonic balance as a continuation problem: in the frequency Ω at a fixed force level
//! (the FRF of one level, paper Section 4.3), or in the force level at a fixed frequency. One
//! continuation code ([`crate::continuation`]) serves both.

use faer::MatMut;

use super::condensed::{CondensedHbm, HbmError, Jacobians};
use crate::continuation::{
    continue_branch, Branch, ContinuationError, FactoredJacobian, Options, PointObserver, Problem, ProblemError,
    Silent, TerminationReason,
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
    from_level_ramp(
        hbm,
        &guess,
        options,
        |hbm, guess| {
            continue_branch(&mut FrequencySweep { hbm, level }, guess, omega_start, omega_end, options, observer)
        },
        |hbm, ramp| sweep_level(hbm, omega_start, 1e-3 * level, level, ramp, &mut Silent),
    )
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
        Branch { points: vec![point], termination, calls: Calls::default(), residual_scale: 1.0 }
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
}
