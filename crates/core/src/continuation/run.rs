//! The continuation loop: PREDICT / CORRECT / ACCEPT-REJECT / ADAPT STEP / TERMINATE
//! (see the module documentation for the equations).

use super::linear::Workspace;
use super::{
    Accepted, Branch, Calls, ContinuationError, Determinant, Options, Point, PointObserver, Predictor, Problem,
    ProblemError, Rejection, TerminationReason, VariableScales,
};

/// Follow the solution curve of `problem` from `λ_start` (solved from `x_guess`) to `λ_end`.
///
/// Invalid input (options, guess, interval, scales) is an `Err`; everything that happens during
/// the continuation, failures included, is a [`TerminationReason`] in the returned [`Branch`],
/// which keeps every converged point.
pub fn continue_branch<P: Problem + ?Sized, O: PointObserver<P> + ?Sized>(
    problem: &mut P,
    x_guess: &[f64],
    lambda_start: f64,
    lambda_end: f64,
    options: &Options,
    observer: &mut O,
) -> Result<Branch, ContinuationError> {
    options.validate()?;
    let n = problem.dimension();
    if x_guess.len() != n {
        return Err(ContinuationError::WrongGuessLength { len: x_guess.len(), expected: n });
    }
    if let Some(index) = x_guess.iter().position(|v| !v.is_finite()) {
        return Err(ContinuationError::NonFiniteGuess { index });
    }
    if !(lambda_start.is_finite() && lambda_end.is_finite()) || lambda_start == lambda_end {
        return Err(ContinuationError::EmptyInterval { start: lambda_start, end: lambda_end });
    }
    let scales = problem.scales();
    for (name, value) in [("unknowns", scales.unknowns), ("residual", scales.residual)] {
        if let Some(v) = value {
            if !(v.is_finite() && v > 0.0) {
                return Err(ContinuationError::InvalidScale { name, value: v });
            }
        }
    }
    let mut runner = Runner::new(problem, options, lambda_start, lambda_end);
    runner.scale.x_fixed = scales.unknowns.is_some();
    runner.scale.x = scales.unknowns.unwrap_or_else(|| positive_or_one(norm(x_guess)));
    let mut points = Vec::new();
    let termination = runner.run(x_guess, scales.residual, observer, &mut points);
    Ok(Branch { points, termination, calls: runner.total, residual_scale: runner.scale.residual, resumed: Vec::new() })
}

fn norm(v: &[f64]) -> f64 {
    v.iter().map(|a| a * a).sum::<f64>().sqrt()
}

fn distance(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| (x - y) * (x - y)).sum::<f64>().sqrt()
}

fn positive_or_one(v: f64) -> f64 {
    if v.is_finite() && v > 0.0 {
        v
    } else {
        1.0
    }
}

/// `z = [x / s_x, λ / s_λ]`, residuals relative to `s_R` (Eq. 31's α = (s_x/s_λ)²).
struct Scaling {
    x: f64,
    lambda: f64,
    residual: f64,
    /// The problem fixed `s_x`; otherwise it follows the largest `‖x‖` met.
    x_fixed: bool,
}

impl Scaling {
    /// `out = [x / s_x, λ / s_λ]`.
    fn to_scaled(&self, x: &[f64], lambda: f64, out: &mut [f64]) {
        let n = x.len();
        for (o, xi) in out[..n].iter_mut().zip(x) {
            *o = xi / self.x;
        }
        out[n] = lambda / self.lambda;
    }

    fn variables(&self) -> VariableScales {
        VariableScales { unknowns: self.x, parameter: self.lambda, residual: self.residual }
    }

    /// A physical direction `[dx, dλ]` in scaled variables, in place.
    fn direction_to_scaled(&self, v: &mut [f64]) {
        let n = v.len() - 1;
        v[..n].iter_mut().for_each(|a| *a /= self.x);
        v[n] /= self.lambda;
    }

    /// A scaled direction in physical units `[dx, dλ]`, in place.
    fn direction_to_physical(&self, v: &mut [f64]) {
        let n = v.len() - 1;
        v[..n].iter_mut().for_each(|a| *a *= self.x);
        v[n] *= self.lambda;
    }
}

/// The equation closing the Newton system besides `R = 0`.
#[derive(Clone, Copy)]
enum Constraint {
    /// `tᵀ (z − z_pred) = 0`: the hyperplane orthogonal to the prediction (Eq. 32).
    Arclength,
    /// `λ` fixed (first point, interval ends).
    FixedLambda(f64),
}

enum Outcome {
    Converged { iterations: usize, residual_norm: f64 },
    Failed { iterations: usize, residual_norm: f64, cause: Rejection },
    Problem { lambda: f64, error: ProblemError },
}

/// Step length and the bookkeeping of the attempts since the last accepted point.
struct StepControl {
    step: f64,
    just_rejected: bool,
    attempts: usize,
    failed_iterations: usize,
    /// Leaps tried since the steps reached `min_step`.
    leaps: usize,
}

impl StepControl {
    /// ADAPT STEP after a rejection: halve down to `min_step`, then leap (each 4 times the
    /// last, at most `max_step`). Returns the termination when the leaps are spent.
    fn reject(
        &mut self,
        rejection: Rejection,
        iterations: usize,
        residual_norm: f64,
        last_lambda: f64,
        options: &Options,
    ) -> Option<TerminationReason> {
        self.failed_iterations += iterations;
        self.attempts += 1;
        self.just_rejected = true;
        if self.leaps == 0 && 0.5 * self.step >= options.min_step {
            self.step *= 0.5;
            return None;
        }
        if self.leaps < options.leaps && self.step < options.max_step {
            self.leaps += 1;
            self.step = (4.0 * self.step).min(options.max_step);
            return None;
        }
        Some(TerminationReason::StepTooSmall {
            rejection,
            lambda: last_lambda,
            residual_norm,
            attempts: self.attempts,
            leaps: self.leaps,
            iterations: self.failed_iterations,
            last_iterate: None,
        })
    }

    /// ADAPT STEP after an acceptance: grow after an easy correction, unless the step was just
    /// cut (it would oscillate between failing and succeeding lengths).
    fn accept(&mut self, iterations: usize, options: &Options) {
        if !self.just_rejected && iterations <= options.easy_iterations {
            self.step = (self.step * options.growth).min(options.max_step);
        }
        self.just_rejected = false;
        self.attempts = 0;
        self.failed_iterations = 0;
        self.leaps = 0;
    }
}

struct Runner<'a, P: ?Sized> {
    problem: &'a mut P,
    options: &'a Options,
    n: usize,
    lambda_start: f64,
    lambda_end: f64,
    /// +1 when λ_end > λ_start, −1 otherwise.
    direction: f64,
    scale: Scaling,
    /// `max(rtol s_R, atol)`.
    tolerance: f64,
    ws: Workspace,
    /// Calls for the point being computed, and for the whole branch.
    calls: Calls,
    total: Calls,
    // Scaled vectors of length n + 1: Newton iterate, prediction, unit prediction direction,
    // last two-but-one, one-but-last and last points, and a scratch reference direction.
    z: Vec<f64>,
    z_pred: Vec<f64>,
    t: Vec<f64>,
    z_older: Vec<f64>,
    z_old: Vec<f64>,
    z_last: Vec<f64>,
    reference: Vec<f64>,
    /// Physical `x` handed to the problem.
    x_phys: Vec<f64>,
    /// Physical `[dx, dλ]`: the previous step's direction (the last secant, or the tangent at
    /// the first point), for the angle check; and the tangent at the last point.
    previous_direction: Vec<f64>,
    tangent: Vec<f64>,
    /// The step that reached the point handed to the observer, scaled as it was taken: the
    /// orientation of the tangent there ([`Accepted::test_functions`]).
    step_direction: Vec<f64>,
    /// The last tangent computed ([`Self::tangent_at_last_point`]), scaled, and from its
    /// factorisation `|w|`, the determinant of the bordered matrix and the scales: the test
    /// functions at that point for nothing more.
    last_tangent: Vec<f64>,
    last_tangent_factors: Option<(f64, Determinant, VariableScales)>,
    /// The last error at a trial iterate, and where.
    trial_error: Option<(f64, ProblemError)>,
    /// The last evaluation was of the residual alone.
    last_residual_only: bool,
}

impl<'a, P: Problem + ?Sized> Runner<'a, P> {
    fn new(problem: &'a mut P, options: &'a Options, lambda_start: f64, lambda_end: f64) -> Self {
        let n = problem.dimension();
        let zeros = vec![0.0; n + 1];
        let ws = Workspace::new(problem);
        Runner {
            problem,
            options,
            n,
            lambda_start,
            lambda_end,
            direction: (lambda_end - lambda_start).signum(),
            scale: Scaling { x: 1.0, lambda: (lambda_end - lambda_start).abs(), residual: 1.0, x_fixed: false },
            tolerance: 0.0,
            ws,
            calls: Calls::default(),
            total: Calls::default(),
            z: zeros.clone(),
            z_pred: zeros.clone(),
            t: zeros.clone(),
            z_older: zeros.clone(),
            z_old: zeros.clone(),
            z_last: zeros.clone(),
            reference: zeros.clone(),
            x_phys: vec![0.0; n],
            previous_direction: zeros.clone(),
            tangent: zeros.clone(),
            step_direction: zeros.clone(),
            last_tangent: zeros,
            last_tangent_factors: None,
            trial_error: None,
            last_residual_only: false,
        }
    }

    fn run<O: PointObserver<P> + ?Sized>(
        &mut self,
        x_guess: &[f64],
        residual_scale: Option<f64>,
        observer: &mut O,
        points: &mut Vec<Point>,
    ) -> TerminationReason {
        let n = self.n;
        let options = self.options;
        self.scale.residual = residual_scale.unwrap_or_else(|| self.default_residual_scale());
        self.tolerance = (options.rtol * self.scale.residual).max(options.atol);

        // First point: Newton at fixed λ_start from the caller's guess.
        self.scale.to_scaled(x_guess, self.lambda_start, &mut self.z);
        let (iterations, residual_norm) =
            match self.newton(Constraint::FixedLambda(self.lambda_start), options.first_point_max_iterations, true) {
                Outcome::Converged { iterations, residual_norm } => (iterations, residual_norm),
                Outcome::Failed { cause: Rejection::TrialIterateFailed, .. } => {
                    let (lambda, error) = self.trial_error.take().expect("a trial iterate's error is kept");
                    return TerminationReason::ProblemError { lambda, last_lambda: None, error };
                }
                Outcome::Failed { iterations, residual_norm, .. } => {
                    return TerminationReason::FirstPointFailed { lambda: self.lambda_start, residual_norm, iterations }
                }
                Outcome::Problem { lambda, error } => {
                    return TerminationReason::ProblemError { lambda, last_lambda: None, error }
                }
            };
        let first = self.make_point(self.lambda_start, iterations, residual_norm, 0.0, 0);

        // Initial tangent, oriented towards λ_end (a pure λ step if the start is singular).
        self.reference.iter_mut().for_each(|v| *v = 0.0);
        self.reference[n] = self.direction;
        let first_tangent = self.tangent_at_last_point();
        if !first_tangent {
            self.tangent.copy_from_slice(&self.reference);
        }
        // The first point's test functions in the scaled variables of its tangent, before s_x
        // is set below.
        self.step_direction.copy_from_slice(&self.tangent);
        let first_scales = self.scale.variables();
        self.scale.direction_to_physical(&mut self.tangent);
        self.previous_direction.copy_from_slice(&self.tangent);
        if !self.scale.x_fixed {
            // s_x: ‖x₀‖, or the change of x the tangent predicts across the band, whichever
            // is larger (a sweep from x = 0 has only the latter).
            let dx_dlambda = norm(&self.tangent[..n]) / self.tangent[n].abs();
            let across_band = if dx_dlambda.is_finite() { dx_dlambda * self.scale.lambda } else { 0.0 };
            self.scale.x = positive_or_one(norm(&first.x).max(across_band));
        }
        self.hand_over(observer, &first, 0.0, first_scales, first_tangent);
        points.push(first);

        let mut control = StepControl {
            step: options.initial_step,
            just_rejected: false,
            attempts: 0,
            failed_iterations: 0,
            leaps: 0,
        };
        let mut furthest = 0.0;
        // The tangent at the last point for a secant (or Lagrange) prediction that failed
        // twice: computed once per point, on demand.
        let mut fallback_tangent = None;
        loop {
            if points.len() >= options.max_points {
                return TerminationReason::MaxPoints;
            }
            let last_lambda = points[points.len() - 1].lambda;

            // PREDICT. A secant rejected twice in a row at a sharp peak or a fold keeps
            // pointing off the curve however short the step (the curve turns within one step);
            // the tangent at the last point follows it.
            if options.predictor != Predictor::Tangent && control.attempts >= 2 && fallback_tangent.is_none() {
                fallback_tangent = Some(self.tangent_by_jacobian(&points[points.len() - 1]));
            }
            self.predict(points, control.step, fallback_tangent == Some(true));

            // CORRECT (Eq. 32)
            self.z.copy_from_slice(&self.z_pred);
            let outcome =
                self.newton(Constraint::Arclength, options.max_iterations, options.predictor == Predictor::Tangent);

            // ACCEPT-REJECT
            let (iterations, residual_norm) = match outcome {
                Outcome::Converged { iterations, residual_norm } => (iterations, residual_norm),
                Outcome::Failed { iterations, residual_norm, cause } => {
                    match control.reject(cause, iterations, residual_norm, last_lambda, options) {
                        Some(termination) => return self.with_last_iterate(termination),
                        None => continue,
                    }
                }
                Outcome::Problem { lambda, error } => {
                    return TerminationReason::ProblemError { lambda, last_lambda: Some(last_lambda), error }
                }
            };
            let lambda_new = self.z[n] * self.scale.lambda;
            let beyond_end = (lambda_new - self.lambda_end) * self.direction >= 0.0;
            let before_start = (lambda_new - self.lambda_start) * self.direction < 0.0;
            // A corrector that travelled farther than the step has likely jumped to another
            // part of the curve; a secant turning sharply has cut a fold too coarsely; the
            // first step is oriented towards λ_end, so going back is a bad correction. A turn
            // that persists after `corner_after` halvings is a corner of a non-smooth branch
            // (a stick/slip transition makes the curve only C0 there), not a fold cut too
            // coarsely: halving further would never reduce it. At a corner of angle α the
            // corrector lands h·tan α from the prediction, proportional to the step, whereas a
            // jump to another part of the curve stays far whatever the step: accept corners up
            // to tan α = 10. A step already so small that `corner_after` more halvings would
            // fall below `min_step` gets the rule at once (else the branch stops at the corner).
            let no_room =
                options.corner_after < 64 && control.step < options.min_step * 2f64.powi(options.corner_after as i32);
            let corner = control.attempts >= options.corner_after || no_room;
            let travelled = distance(&self.z, &self.z_pred);
            let mut rejection = if !(travelled <= control.step || (corner && travelled <= 10.0 * control.step)) {
                Some(Rejection::TravelledTooFar)
            } else if !(self.turn_angle() <= options.max_angle || corner) {
                Some(Rejection::TurnedTooSharply)
            } else if before_start && points.len() == 1 {
                Some(Rejection::WentBack)
            } else {
                None
            };

            // TERMINATE at an interval end: solve again at exactly that λ from the guess
            // interpolated between the last point and the one beyond.
            if rejection.is_none() && (beyond_end || before_start) {
                let boundary = if beyond_end { self.lambda_end } else { self.lambda_start };
                let theta = (boundary - last_lambda) / (lambda_new - last_lambda);
                for i in 0..n {
                    self.z[i] = self.z_last[i] + theta * (self.z[i] - self.z_last[i]);
                }
                self.z[n] = boundary / self.scale.lambda;
                match self.newton(Constraint::FixedLambda(boundary), options.max_iterations, false) {
                    Outcome::Converged { iterations, residual_norm } => {
                        let step = distance(&self.z, &self.z_last);
                        let point = self.make_point(boundary, iterations, residual_norm, step, control.attempts);
                        for i in 0..=n {
                            self.step_direction[i] = self.z[i] - self.z_last[i];
                        }
                        let (scales, fraction) = (self.scale.variables(), if beyond_end { 1.0 } else { furthest });
                        self.hand_over(observer, &point, fraction, scales, false);
                        points.push(point);
                        return if beyond_end {
                            TerminationReason::ReachedEnd
                        } else {
                            TerminationReason::ReturnedToStart
                        };
                    }
                    Outcome::Failed { .. } => rejection = Some(Rejection::EndSolveFailed),
                    Outcome::Problem { lambda, error } => {
                        return TerminationReason::ProblemError { lambda, last_lambda: Some(last_lambda), error }
                    }
                }
            }
            if let Some(rejection) = rejection {
                match control.reject(rejection, iterations, residual_norm, last_lambda, options) {
                    Some(termination) => return self.with_last_iterate(termination),
                    None => continue,
                }
            }

            // Accepted: record the step direction, the tangent for the next prediction, and
            // let s_x follow the largest ‖x‖.
            let point = self.make_point(lambda_new, iterations, residual_norm, control.step, control.attempts);
            for i in 0..=n {
                self.previous_direction[i] = self.z[i] - self.z_last[i];
            }
            self.step_direction.copy_from_slice(&self.previous_direction);
            let scales = self.scale.variables();
            // The workspace holds ∂R at the accepted point: the tangent there, oriented along
            // the step taken (the secant if the bordered matrix is singular).
            let tangent_found = options.predictor == Predictor::Tangent && {
                self.reference.copy_from_slice(&self.previous_direction);
                self.tangent_at_last_point()
            };
            self.scale.direction_to_physical(&mut self.previous_direction);
            if tangent_found {
                self.scale.direction_to_physical(&mut self.tangent);
            } else {
                self.tangent.copy_from_slice(&self.previous_direction);
            }
            if !self.scale.x_fixed {
                self.scale.x = self.scale.x.max(norm(&point.x));
            }
            let fraction = ((lambda_new - self.lambda_start) / (self.lambda_end - self.lambda_start)).clamp(0.0, 1.0);
            furthest = f64::max(furthest, fraction);
            self.hand_over(observer, &point, furthest, scales, tangent_found);
            points.push(point);
            fallback_tangent = None;

            // ADAPT STEP
            control.accept(iterations, options);
        }
    }

    /// A termination for want of a step, with the last iterate of the failed correction.
    fn with_last_iterate(&self, mut termination: TerminationReason) -> TerminationReason {
        if let TerminationReason::StepTooSmall { last_iterate, .. } = &mut termination {
            let x = self.z[..self.n].iter().map(|u| u * self.scale.x).collect();
            *last_iterate = Some((x, self.z[self.n] * self.scale.lambda));
        }
        termination
    }

    /// Hand an accepted point to the observer, the problem as the converged evaluation left it;
    /// `step_direction` holds the step that reached it, scaled by `scales`. With
    /// `tangent_at_point`, the last tangent computed is the point's.
    fn hand_over<O: PointObserver<P> + ?Sized>(
        &mut self,
        observer: &mut O,
        point: &Point,
        fraction_done: f64,
        scales: VariableScales,
        tangent_at_point: bool,
    ) {
        let factors = self.last_tangent_factors.take().filter(|_| tangent_at_point);
        let mut accepted = Accepted {
            point,
            fraction_done,
            residual_scale: self.scale.residual,
            completable: self.ws.lazy && self.last_residual_only,
            // The converged evaluation included the Jacobian, and nothing factored it since.
            jacobian_held: self.ws.holds_jacobian(),
            direction: &self.step_direction,
            scales,
            tangent_factors: factors
                .map(|(w_norm, determinant, at)| (self.last_tangent.as_slice(), w_norm, determinant, at)),
            test_functions: None,
            problem: &mut *self.problem,
            workspace: &mut self.ws,
            calls: Calls::default(),
        };
        observer.on_accepted(&mut accepted);
        self.total += accepted.calls;
        // Whatever the observer evaluated, the next step starts from a fresh evaluation.
        self.last_residual_only = false;
    }

    /// `‖R(0, λ)‖` (the forcing of a forced problem) at λ_start, or at λ_end when it vanishes
    /// at the start (a force-level sweep from zero), or 1. A problem that cannot be evaluated
    /// at x = 0 gets 1; its errors are reported by the first solve.
    fn default_residual_scale(&mut self) -> f64 {
        self.x_phys.iter_mut().for_each(|v| *v = 0.0);
        for lambda in [self.lambda_start, self.lambda_end] {
            if let Ok(r) = self.evaluate(lambda, false) {
                if r.is_finite() && r > 0.0 {
                    return r;
                }
            }
        }
        1.0
    }

    /// A problem error in Newton: a rejection if it is at a trial iterate (kept, to be reported
    /// if the first point fails on it), else the end of the branch.
    fn problem_outcome(&mut self, iterations: usize, lambda: f64, error: ProblemError) -> Outcome {
        if error.at_trial_iterate {
            self.trial_error = Some((lambda, error));
            Outcome::Failed { iterations, residual_norm: f64::INFINITY, cause: Rejection::TrialIterateFailed }
        } else {
            Outcome::Problem { lambda, error }
        }
    }

    /// The tangent at `last` from the Jacobian evaluated there, oriented along the previous
    /// step (physical units, in `tangent`); false if it cannot be computed.
    fn tangent_by_jacobian(&mut self, last: &Point) -> bool {
        self.x_phys.copy_from_slice(&last.x);
        if !matches!(self.evaluate(last.lambda, true), Ok(r) if r.is_finite()) {
            return false;
        }
        self.reference.copy_from_slice(&self.previous_direction);
        self.scale.direction_to_scaled(&mut self.reference);
        if !self.tangent_at_last_point() {
            return false;
        }
        self.scale.direction_to_physical(&mut self.tangent);
        true
    }

    /// PREDICT: fill `z_last`, `z_pred` and the unit prediction direction `t`; along the
    /// tangent at the last point when `along_tangent` (else the options' predictor).
    fn predict(&mut self, points: &[Point], step: f64, along_tangent: bool) {
        let n = self.n;
        let count = points.len();
        let last = &points[count - 1];
        self.scale.to_scaled(&last.x, last.lambda, &mut self.z_last);
        let predictor = match (self.options.predictor, count) {
            _ if along_tangent => Predictor::Tangent,
            (_, 1) | (Predictor::Tangent, _) => Predictor::Tangent,
            (Predictor::Lagrange, 3..) => Predictor::Lagrange,
            _ => Predictor::Secant,
        };
        match predictor {
            Predictor::Tangent | Predictor::Secant => {
                if predictor == Predictor::Tangent {
                    self.t.copy_from_slice(&self.tangent);
                    self.scale.direction_to_scaled(&mut self.t);
                } else {
                    let previous = &points[count - 2];
                    self.scale.to_scaled(&previous.x, previous.lambda, &mut self.z_old);
                    for i in 0..=n {
                        self.t[i] = self.z_last[i] - self.z_old[i];
                    }
                }
                let length = norm(&self.t);
                for i in 0..=n {
                    self.t[i] /= length;
                    self.z_pred[i] = self.z_last[i] + step * self.t[i];
                }
            }
            Predictor::Lagrange => {
                // Second-degree Lagrange polynomial through z_{i−2}, z_{i−1}, z_i at their
                // cumulative chord lengths s = −(d₁ + d₂), −d₂, 0 (Eq. 31), evaluated at s = h;
                // the correction is orthogonal to z_pred − z_i (Eq. 32).
                let (older, old) = (&points[count - 3], &points[count - 2]);
                self.scale.to_scaled(&older.x, older.lambda, &mut self.z_older);
                self.scale.to_scaled(&old.x, old.lambda, &mut self.z_old);
                let d1 = distance(&self.z_older, &self.z_old);
                let d2 = distance(&self.z_old, &self.z_last);
                let (s0, s1, s) = (-(d1 + d2), -d2, step);
                let l0 = (s - s1) * s / ((s0 - s1) * s0);
                let l1 = (s - s0) * s / ((s1 - s0) * s1);
                let l2 = (s - s0) * (s - s1) / (s0 * s1);
                for i in 0..=n {
                    self.z_pred[i] = l0 * self.z_older[i] + l1 * self.z_old[i] + l2 * self.z_last[i];
                    self.t[i] = self.z_pred[i] - self.z_last[i];
                }
                let length = norm(&self.t);
                self.t.iter_mut().for_each(|v| *v /= length);
            }
        }
    }

    /// Angle between the new secant and the previous step direction, in scaled variables.
    fn turn_angle(&self) -> f64 {
        let n = self.n;
        let (mut dot, mut a2, mut b2) = (0.0, 0.0, 0.0);
        for i in 0..=n {
            let s = if i < n { self.scale.x } else { self.scale.lambda };
            let a = self.z[i] - self.z_last[i];
            let b = self.previous_direction[i] / s;
            dot += a * b;
            a2 += a * a;
            b2 += b * b;
        }
        (dot / (a2 * b2).sqrt()).clamp(-1.0, 1.0).acos()
    }

    /// The point at the current iterate; resets the per-point call counts.
    fn make_point(&mut self, lambda: f64, iterations: usize, residual_norm: f64, step: f64, rejected: usize) -> Point {
        let point = Point {
            x: self.z[..self.n].iter().map(|u| u * self.scale.x).collect(),
            lambda,
            iterations,
            residual_norm,
            step,
            rejected,
            calls: self.calls,
        };
        self.calls = Calls::default();
        point
    }

    /// Evaluate the problem at `x_phys`, `lambda`; returns `‖R‖`.
    fn evaluate(&mut self, lambda: f64, with_jacobian: bool) -> Result<f64, ProblemError> {
        let calls = Calls { residuals: 1, jacobians: usize::from(with_jacobian), factorizations: 0 };
        self.calls += calls;
        self.total += calls;
        self.last_residual_only = !with_jacobian;
        self.ws.evaluate(self.problem, &self.x_phys, lambda, with_jacobian)?;
        Ok(norm(&self.ws.residual))
    }

    /// CORRECT: Newton from `z` under `constraint`, to `‖R‖ ≤ tolerance`. With
    /// `jacobian_at_solution` the last evaluation includes the Jacobian, so the workspace holds
    /// ∂R at the returned point (for a tangent). Otherwise, once two residuals show quadratic
    /// convergence (`r_k ≈ r_{k−1}²/r_{k−2}`, predicted below a tenth of the tolerance), the
    /// residual is evaluated alone first: the Jacobian at the solution is never used, and a
    /// wrong guess costs one residual.
    fn newton(&mut self, constraint: Constraint, max_iterations: usize, jacobian_at_solution: bool) -> Outcome {
        let n = self.n;
        let mut iterations = 0;
        // Residual norms of the two previous iterates.
        let (mut older, mut old) = (f64::INFINITY, f64::INFINITY);
        // The last four residual norms, newest last, to tell a cycle from a slow convergence.
        let mut recent = [f64::NAN; 4];
        loop {
            let lambda = match constraint {
                Constraint::Arclength => self.z[n] * self.scale.lambda,
                Constraint::FixedLambda(lambda) => lambda,
            };
            for (x, u) in self.x_phys.iter_mut().zip(&self.z) {
                *x = u * self.scale.x;
            }
            // A problem that completes residuals to Jacobians: the residual alone, the Jacobian
            // only if the iterate is not accepted (below).
            let lazy = self.ws.lazy && !jacobian_at_solution;
            if !lazy && !jacobian_at_solution && iterations >= 2 && old * old / older <= 0.1 * self.tolerance {
                match self.evaluate(lambda, false) {
                    Ok(r) if r <= self.tolerance => return Outcome::Converged { iterations, residual_norm: r },
                    Ok(_) => {}
                    Err(error) => return self.problem_outcome(iterations, lambda, error),
                }
            }
            let residual_norm = match self.evaluate(lambda, !lazy) {
                Ok(r) => r,
                Err(error) => return self.problem_outcome(iterations, lambda, error),
            };
            if !residual_norm.is_finite() {
                return Outcome::Failed { iterations, residual_norm, cause: Rejection::Singular };
            }
            if residual_norm <= self.tolerance {
                return Outcome::Converged { iterations, residual_norm };
            }
            recent.rotate_left(1);
            recent[3] = residual_norm;
            if iterations == max_iterations {
                let same = |a: f64, b: f64| (a - b).abs() <= 1e-3 * a.max(b);
                let cause = if same(recent[3], recent[1]) && same(recent[2], recent[0]) {
                    Rejection::NewtonCycle
                } else {
                    Rejection::NoConvergence
                };
                return Outcome::Failed { iterations, residual_norm, cause };
            }
            if lazy {
                let calls = Calls { residuals: 0, jacobians: 1, factorizations: 0 };
                self.calls += calls;
                self.total += calls;
                self.last_residual_only = false;
                if let Err(error) = self.ws.complete(self.problem) {
                    return self.problem_outcome(iterations, lambda, error);
                }
            }
            let sr = self.scale.residual;
            for (b, r) in self.ws.rhs.iter_mut().zip(&self.ws.residual) {
                *b = -r / sr;
            }
            self.calls.factorizations += 1;
            self.total.factorizations += 1;
            let (solved, size) = match constraint {
                Constraint::Arclength => {
                    let offset: f64 = (0..=n).map(|i| self.t[i] * (self.z[i] - self.z_pred[i])).sum();
                    self.ws.rhs[n] = -offset;
                    (self.ws.solve_bordered(self.problem, self.scale.x, self.scale.lambda, sr, &self.t), n + 1)
                }
                Constraint::FixedLambda(_) => (self.ws.solve_fixed(self.problem, self.scale.x, sr), n),
            };
            if !solved {
                return Outcome::Failed { iterations, residual_norm, cause: Rejection::Singular };
            }
            for (z, dz) in self.z[..size].iter_mut().zip(&self.ws.rhs) {
                *z += dz;
            }
            (older, old) = (old, residual_norm);
            iterations += 1;
        }
    }

    /// Unit null vector of `∂R/∂z` at the last Newton point (its Jacobian is still in the
    /// workspace), from the bordered system `[∂R/∂z; referenceᵀ] τ = [0; 1]`, oriented along
    /// `reference`, into `tangent` (scaled). False, `tangent` untouched, if it is singular.
    fn tangent_at_last_point(&mut self) -> bool {
        let n = self.n;
        self.ws.rhs.iter_mut().for_each(|v| *v = 0.0);
        self.ws.rhs[n] = 1.0;
        self.calls.factorizations += 1;
        self.total.factorizations += 1;
        if !self.ws.solve_bordered(self.problem, self.scale.x, self.scale.lambda, self.scale.residual, &self.reference)
        {
            return false;
        }
        let length = norm(&self.ws.rhs);
        let along: f64 = self.ws.rhs.iter().zip(&self.reference).map(|(a, b)| a * b).sum();
        let sign = if along < 0.0 { -1.0 } else { 1.0 };
        for (t, v) in self.tangent.iter_mut().zip(&self.ws.rhs) {
            *t = sign * v / length;
        }
        // B(reference) w = e_{n+1} solved: the test functions there (singular's Eq. 2), with w
        // oriented as the tangent.
        self.last_tangent.copy_from_slice(&self.tangent);
        self.last_tangent_factors = self.ws.bordered_determinant().map(|mut determinant| {
            determinant.sign *= sign;
            (length, determinant, self.scale.variables())
        });
        true
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use faer::MatMut;

    /// x² + λ² = 1.
    struct Circle;

    impl Problem for Circle {
        fn dimension(&self) -> usize {
            1
        }
        fn evaluate(
            &mut self,
            x: &[f64],
            lambda: f64,
            residual: &mut [f64],
            jacobian: Option<(MatMut<'_, f64>, &mut [f64])>,
        ) -> Result<(), ProblemError> {
            residual[0] = x[0] * x[0] + lambda * lambda - 1.0;
            if let Some((mut jx, dl)) = jacobian {
                jx[(0, 0)] = 2.0 * x[0];
                dl[0] = 2.0 * lambda;
            }
            Ok(())
        }
    }

    fn point(x: f64, lambda: f64) -> Point {
        Point { x: vec![x], lambda, iterations: 0, residual_norm: 0.0, step: 0.0, rejected: 0, calls: Calls::default() }
    }

    #[test]
    fn tangent_is_the_null_vector_of_the_jacobian_in_scaled_variables() {
        let options = Options::default();
        let mut circle = Circle;
        let mut runner = Runner::new(&mut circle, &options, 0.0, 2.0);
        runner.scale = Scaling { x: 3.0, lambda: 2.0, residual: 1.0, x_fixed: true };
        let (x, lambda) = (0.6, 0.8);
        runner.x_phys[0] = x;
        runner.evaluate(lambda, true).unwrap();
        runner.reference.copy_from_slice(&[0.0, 1.0]);
        assert!(runner.tangent_at_last_point());
        // Physical tangent of the circle at (x, λ): (dx, dλ) ∝ (−λ, x); scaled: (−λ/s_x, x/s_λ).
        let (u, m) = (-lambda / 3.0, x / 2.0);
        let length = u.hypot(m);
        // Unit length and orientation along the reference (dλ > 0); exact to rounding.
        assert!((runner.tangent[0] - u / length).abs() < 1e-15, "{:?}", runner.tangent);
        assert!((runner.tangent[1] - m / length).abs() < 1e-15, "{:?}", runner.tangent);
    }

    #[test]
    fn lagrange_prediction_continues_collinear_points_by_exactly_the_step() {
        // Three points on a line with uneven spacing: the quadratic in the chord length
        // reproduces the line, so the prediction lies on it at distance h from the last point.
        let options = Options { predictor: Predictor::Lagrange, ..Options::default() };
        let mut circle = Circle;
        let mut runner = Runner::new(&mut circle, &options, 0.0, 1.0);
        runner.scale = Scaling { x: 1.0, lambda: 1.0, residual: 1.0, x_fixed: true };
        let line = |s: f64| point(0.1 + 0.6 * s, 0.2 + 0.8 * s);
        let points = [line(0.0), line(0.05), line(0.2)];
        let h = 0.07;
        runner.predict(&points, h, false);
        let expected = line(0.2 + h);
        assert!((runner.z_pred[0] - expected.x[0]).abs() < 1e-15, "{:?}", runner.z_pred);
        assert!((runner.z_pred[1] - expected.lambda).abs() < 1e-15, "{:?}", runner.z_pred);
        assert!((runner.t[0] - 0.6).abs() < 1e-14 && (runner.t[1] - 0.8).abs() < 1e-14, "{:?}", runner.t);
    }
}
