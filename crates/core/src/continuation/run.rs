//! The continuation loop: PREDICT / CORRECT / ACCEPT-REJECT / ADAPT STEP / TERMINATE
//! (see the module documentation for the equations).

use super::linear::Workspace;
use super::{
    Branch, Calls, ContinuationError, Observer, Options, Point, Predictor, Problem, ProblemError, TerminationReason,
};

/// Follow the solution curve of `problem` from `λ_start` (solved from `x_guess`) to `λ_end`.
///
/// Invalid input (options, guess length, interval, scales) is an `Err`; everything that happens
/// during the continuation, including failures, is a [`TerminationReason`] in the returned
/// [`Branch`], which keeps every converged point.
pub fn continue_branch<P: Problem + ?Sized, O: Observer + ?Sized>(
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
    Ok(runner.run(x_guess, scales.residual, observer))
}

fn norm(v: &[f64]) -> f64 {
    v.iter().map(|a| a * a).sum::<f64>().sqrt()
}

fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

fn positive_or_one(v: f64) -> f64 {
    if v.is_finite() && v > 0.0 {
        v
    } else {
        1.0
    }
}

/// `out = [x / s_x, λ / s_λ]`.
fn to_scaled(x: &[f64], lambda: f64, scale: &Scaling, out: &mut [f64]) {
    let n = x.len();
    for (o, xi) in out[..n].iter_mut().zip(x) {
        *o = xi / scale.x;
    }
    out[n] = lambda / scale.lambda;
}

/// `z = [x / s_x, λ / s_λ]`, residuals relative to `s_R` (Eq. 31's α = (s_x/s_λ)²).
struct Scaling {
    x: f64,
    lambda: f64,
    residual: f64,
    /// The problem fixed `s_x`; otherwise it follows the largest `‖x‖` met.
    x_fixed: bool,
}

enum Outcome {
    Converged { iterations: usize, residual_norm: f64 },
    Failed { iterations: usize, residual_norm: f64 },
    Problem { lambda: f64, error: ProblemError },
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
    tolerance: f64,
    ws: Workspace,
    /// Calls for the point being computed, and for the whole branch.
    calls: Calls,
    total: Calls,
    /// Newton iterate (scaled), prediction, prediction direction, last point (scaled).
    z: Vec<f64>,
    z_pred: Vec<f64>,
    t: Vec<f64>,
    z_last: Vec<f64>,
    /// Physical `x` handed to the problem.
    x_phys: Vec<f64>,
    /// Previous step direction in physical units `[dx, dλ]`: the last secant, or the tangent at
    /// the first point; and the tangent at the last point (tangent predictor).
    previous_direction: Vec<f64>,
    tangent: Vec<f64>,
}

impl<'a, P: Problem + ?Sized> Runner<'a, P> {
    fn new(problem: &'a mut P, options: &'a Options, lambda_start: f64, lambda_end: f64) -> Self {
        let n = problem.dimension();
        Runner {
            problem,
            options,
            n,
            lambda_start,
            lambda_end,
            direction: (lambda_end - lambda_start).signum(),
            scale: Scaling { x: 1.0, lambda: (lambda_end - lambda_start).abs(), residual: 1.0, x_fixed: false },
            tolerance: 0.0,
            ws: Workspace::new(n),
            calls: Calls::default(),
            total: Calls::default(),
            z: vec![0.0; n + 1],
            z_pred: vec![0.0; n + 1],
            t: vec![0.0; n + 1],
            z_last: vec![0.0; n + 1],
            x_phys: vec![0.0; n],
            previous_direction: vec![0.0; n + 1],
            tangent: vec![0.0; n + 1],
        }
    }

    fn run<O: Observer + ?Sized>(&mut self, x_guess: &[f64], residual_scale: Option<f64>, observer: &mut O) -> Branch {
        let mut points: Vec<Point> = Vec::new();
        let termination = self.run_inner(x_guess, residual_scale, observer, &mut points);
        Branch { points, termination, calls: self.total }
    }

    fn run_inner<O: Observer + ?Sized>(
        &mut self,
        x_guess: &[f64],
        residual_scale: Option<f64>,
        observer: &mut O,
        points: &mut Vec<Point>,
    ) -> TerminationReason {
        let n = self.n;
        let opts = self.options;

        // Residual scale: the problem's, or ‖R(0, λ)‖ (the forcing of a forced problem) at
        // λ_start, or at λ_end when it vanishes at the start (a force sweep from zero), or 1.
        self.scale.residual = match residual_scale {
            Some(s) => s,
            None => {
                self.x_phys.iter_mut().for_each(|v| *v = 0.0);
                let mut scale = 0.0;
                // A problem that cannot be evaluated at x = 0 falls back to 1; its errors are
                // reported by the first solve.
                for lambda in [self.lambda_start, self.lambda_end] {
                    if let Ok(r) = self.evaluate(lambda, false) {
                        if r.is_finite() && r > 0.0 {
                            scale = r;
                            break;
                        }
                    }
                }
                positive_or_one(scale)
            }
        };
        self.tolerance = (opts.rtol * self.scale.residual).max(opts.atol);

        // First point: Newton at fixed λ_start from the caller's guess.
        to_scaled(x_guess, self.lambda_start, &self.scale, &mut self.z);
        let (iterations, residual_norm) = match self.newton(None, self.lambda_start, opts.first_point_max_iterations) {
            Outcome::Converged { iterations, residual_norm } => (iterations, residual_norm),
            Outcome::Failed { iterations, residual_norm } => {
                return TerminationReason::FirstPointFailed { lambda: self.lambda_start, residual_norm, iterations }
            }
            Outcome::Problem { lambda, error } => {
                return TerminationReason::ProblemError { lambda, last_lambda: None, error }
            }
        };

        // Initial tangent, oriented towards λ_end; it also sizes s_x for a start at x = 0.
        self.t.iter_mut().for_each(|v| *v = 0.0);
        self.t[n] = self.direction;
        let reference = self.t.clone();
        if !self.tangent_at_last_point(&reference) {
            self.tangent.copy_from_slice(&reference);
        }
        let x0: Vec<f64> = self.z[..n].iter().map(|u| u * self.scale.x).collect();
        for i in 0..n {
            self.previous_direction[i] = self.tangent[i] * self.scale.x;
        }
        self.previous_direction[n] = self.tangent[n] * self.scale.lambda;
        if !self.scale.x_fixed {
            let dx_dlambda = norm(&self.previous_direction[..n]) / self.previous_direction[n].abs();
            let across_band = if dx_dlambda.is_finite() { dx_dlambda * self.scale.lambda } else { 0.0 };
            self.scale.x = positive_or_one(norm(&x0).max(across_band));
        }
        self.tangent.copy_from_slice(&self.previous_direction);
        let first = Point {
            x: x0,
            lambda: self.lambda_start,
            iterations,
            residual_norm,
            step: 0.0,
            rejected: 0,
            calls: self.calls,
        };
        self.calls = Calls::default();
        let mut furthest = 0.0;
        observer.on_point(&first, 0.0);
        points.push(first);

        let mut step = opts.initial_step;
        let mut just_rejected = false;
        let mut attempts = 0usize;
        let mut failed_iterations = 0usize;
        loop {
            if points.len() >= opts.max_points {
                return TerminationReason::MaxPoints;
            }
            let last = points.last().expect("the first point is stored");
            to_scaled(&last.x, last.lambda, &self.scale, &mut self.z_last);

            // PREDICT
            self.predict(points, step);

            // CORRECT (Eq. 32)
            self.z.copy_from_slice(&self.z_pred);
            let outcome = self.newton(Some(()), 0.0, opts.max_iterations);

            // ACCEPT-REJECT
            let (iterations, residual_norm) = match outcome {
                Outcome::Problem { lambda, error } => {
                    return TerminationReason::ProblemError { lambda, last_lambda: Some(last.lambda), error }
                }
                Outcome::Failed { iterations, residual_norm } => {
                    failed_iterations += iterations;
                    attempts += 1;
                    step *= 0.5;
                    just_rejected = true;
                    if step < opts.min_step {
                        return TerminationReason::StepTooSmall {
                            lambda: last.lambda,
                            residual_norm,
                            attempts,
                            iterations: failed_iterations,
                        };
                    }
                    continue;
                }
                Outcome::Converged { iterations, residual_norm } => (iterations, residual_norm),
            };
            let mut acceptable = self.correction_distance() <= step && self.turn_angle() <= opts.max_angle;
            let lambda_new = self.z[n] * self.scale.lambda;
            let beyond_end = (lambda_new - self.lambda_end) * self.direction >= 0.0;
            let before_start = (lambda_new - self.lambda_start) * self.direction < 0.0;
            if acceptable && before_start && points.len() == 1 {
                // The first step is oriented towards λ_end: going back is a bad correction.
                acceptable = false;
            }
            if acceptable && (beyond_end || before_start) {
                // TERMINATE: solve again at exactly the interval end, from the interpolated guess.
                let boundary = if beyond_end { self.lambda_end } else { self.lambda_start };
                let theta = (boundary - last.lambda) / (lambda_new - last.lambda);
                for i in 0..n {
                    let u_last = self.z_last[i];
                    self.z[i] = u_last + theta * (self.z[i] - u_last);
                }
                self.z[n] = boundary / self.scale.lambda;
                match self.newton(None, boundary, opts.max_iterations) {
                    Outcome::Converged { iterations, residual_norm } => {
                        let distance = self.distance_from_last();
                        let point = self.make_point(boundary, iterations, residual_norm, distance, attempts);
                        observer.on_point(&point, if beyond_end { 1.0 } else { furthest });
                        points.push(point);
                        return if beyond_end {
                            TerminationReason::ReachedEnd
                        } else {
                            TerminationReason::ReturnedToStart
                        };
                    }
                    Outcome::Problem { lambda, error } => {
                        return TerminationReason::ProblemError { lambda, last_lambda: Some(last.lambda), error }
                    }
                    Outcome::Failed { .. } => acceptable = false,
                }
            }
            if !acceptable {
                failed_iterations += iterations;
                attempts += 1;
                step *= 0.5;
                just_rejected = true;
                if step < opts.min_step {
                    return TerminationReason::StepTooSmall {
                        lambda: last.lambda,
                        residual_norm,
                        attempts,
                        iterations: failed_iterations,
                    };
                }
                continue;
            }

            // Accepted.
            let last_x_lambda = (last.lambda, points.len());
            let point = self.make_point(lambda_new, iterations, residual_norm, step, attempts);
            for i in 0..n {
                self.previous_direction[i] = (self.z[i] - self.z_last[i]) * self.scale.x;
            }
            self.previous_direction[n] = lambda_new - last_x_lambda.0;
            if opts.predictor == Predictor::Tangent {
                // The Jacobian buffer holds ∂R at the accepted point: orient its null vector
                // along the step just taken.
                for i in 0..=n {
                    self.t[i] = self.z[i] - self.z_last[i];
                }
                let reference = self.t.clone();
                if self.tangent_at_last_point(&reference) {
                    for i in 0..n {
                        self.tangent[i] *= self.scale.x;
                    }
                    self.tangent[n] *= self.scale.lambda;
                } else {
                    self.tangent.copy_from_slice(&self.previous_direction);
                }
            }
            if !self.scale.x_fixed {
                self.scale.x = self.scale.x.max(norm(&point.x));
            }
            let fraction = ((lambda_new - self.lambda_start) / (self.lambda_end - self.lambda_start)).clamp(0.0, 1.0);
            furthest = f64::max(furthest, fraction);
            observer.on_point(&point, furthest);
            points.push(point);

            // ADAPT STEP
            if !just_rejected && iterations <= opts.easy_iterations {
                step = (step * opts.growth).min(opts.max_step);
            }
            just_rejected = false;
            attempts = 0;
            failed_iterations = 0;
        }
    }

    /// Fill `z_pred` and the unit prediction direction `t` from the last points.
    fn predict(&mut self, points: &[Point], step: f64) {
        let n = self.n;
        let (sx, sl) = (self.scale.x, self.scale.lambda);
        let scaling = &self.scale;
        let scaled = |p: &Point, out: &mut [f64]| to_scaled(&p.x, p.lambda, scaling, out);
        let use_tangent = points.len() == 1 || self.options.predictor == Predictor::Tangent;
        if use_tangent || points.len() == 2 || self.options.predictor == Predictor::Secant {
            if use_tangent {
                self.t.copy_from_slice(&self.tangent);
            } else {
                scaled(&points[points.len() - 2], &mut self.t);
                for i in 0..n {
                    self.t[i] = (self.z_last[i] - self.t[i]) * sx;
                }
                self.t[n] = (self.z_last[n] - self.t[n]) * sl;
            }
            // `t` holds a physical direction: scale it, normalise it, step along it.
            for i in 0..n {
                self.t[i] /= sx;
            }
            self.t[n] /= sl;
            let length = norm(&self.t);
            for i in 0..=n {
                self.t[i] /= length;
                self.z_pred[i] = self.z_last[i] + step * self.t[i];
            }
            return;
        }
        // Second-degree Lagrange polynomial through z_{i−2}, z_{i−1}, z_i at cumulative chord
        // lengths s = −(d₁ + d₂), −d₂, 0 (Eq. 31), evaluated at s = h.
        let mut z0 = vec![0.0; n + 1];
        let mut z1 = vec![0.0; n + 1];
        scaled(&points[points.len() - 3], &mut z0);
        scaled(&points[points.len() - 2], &mut z1);
        let d1 = z0.iter().zip(&z1).map(|(a, b)| (a - b) * (a - b)).sum::<f64>().sqrt();
        let d2 = z1.iter().zip(&self.z_last).map(|(a, b)| (a - b) * (a - b)).sum::<f64>().sqrt();
        let (s0, s1, s2, s) = (-(d1 + d2), -d2, 0.0, step);
        let l0 = (s - s1) * (s - s2) / ((s0 - s1) * (s0 - s2));
        let l1 = (s - s0) * (s - s2) / ((s1 - s0) * (s1 - s2));
        let l2 = (s - s0) * (s - s1) / ((s2 - s0) * (s2 - s1));
        for i in 0..=n {
            self.z_pred[i] = l0 * z0[i] + l1 * z1[i] + l2 * self.z_last[i];
            self.t[i] = self.z_pred[i] - self.z_last[i];
        }
        let length = norm(&self.t);
        self.t.iter_mut().for_each(|v| *v /= length);
    }

    /// Scaled distance between the corrected and the predicted point.
    fn correction_distance(&self) -> f64 {
        self.z.iter().zip(&self.z_pred).map(|(a, b)| (a - b) * (a - b)).sum::<f64>().sqrt()
    }

    fn distance_from_last(&self) -> f64 {
        self.z.iter().zip(&self.z_last).map(|(a, b)| (a - b) * (a - b)).sum::<f64>().sqrt()
    }

    /// Angle between the new secant and the previous step direction, in scaled variables.
    fn turn_angle(&self) -> f64 {
        let n = self.n;
        let (mut d, mut a2, mut b2) = (0.0, 0.0, 0.0);
        for i in 0..=n {
            let s = if i < n { self.scale.x } else { self.scale.lambda };
            let a = self.z[i] - self.z_last[i];
            let b = self.previous_direction[i] / s;
            d += a * b;
            a2 += a * a;
            b2 += b * b;
        }
        (d / (a2 * b2).sqrt()).clamp(-1.0, 1.0).acos()
    }

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

    /// Evaluate at `x_phys`, `lambda`; returns `‖R‖`.
    fn evaluate(&mut self, lambda: f64, with_jacobian: bool) -> Result<f64, ProblemError> {
        let (residual, jx, dl) = self.ws.evaluation_buffers();
        let mut calls = Calls { residuals: 1, ..Calls::default() };
        let result = if with_jacobian {
            calls.jacobians = 1;
            self.problem.evaluate(&self.x_phys, lambda, residual, Some((jx, dl)))
        } else {
            self.problem.evaluate(&self.x_phys, lambda, residual, None)
        };
        self.calls += calls;
        self.total += calls;
        result.map(|()| norm(&self.ws.residual))
    }

    /// Newton from `z`: on the bordered system of Eq. 32 (`bordered = Some(())`, hyperplane
    /// `tᵀ(z − z_pred) = 0`) or at fixed `lambda` (`None`). The last evaluation leaves the
    /// Jacobian at the returned point in the workspace.
    fn newton(&mut self, bordered: Option<()>, lambda: f64, max_iterations: usize) -> Outcome {
        let n = self.n;
        let mut iterations = 0;
        loop {
            let lambda_k = if bordered.is_some() { self.z[n] * self.scale.lambda } else { lambda };
            for i in 0..n {
                self.x_phys[i] = self.z[i] * self.scale.x;
            }
            let residual_norm = match self.evaluate(lambda_k, true) {
                Ok(r) => r,
                Err(error) => return Outcome::Problem { lambda: lambda_k, error },
            };
            if !residual_norm.is_finite() {
                return Outcome::Failed { iterations, residual_norm };
            }
            if residual_norm <= self.tolerance {
                return Outcome::Converged { iterations, residual_norm };
            }
            if iterations == max_iterations {
                return Outcome::Failed { iterations, residual_norm };
            }
            let sr = self.scale.residual;
            for i in 0..n {
                self.ws.rhs[i] = -self.ws.residual[i] / sr;
            }
            self.calls.factorizations += 1;
            self.total.factorizations += 1;
            let solved = if bordered.is_some() {
                let mut offset = 0.0;
                for i in 0..=n {
                    offset += self.t[i] * (self.z[i] - self.z_pred[i]);
                }
                self.ws.rhs[n] = -offset;
                self.ws.solve_bordered(self.scale.x, self.scale.lambda, sr, &self.t)
            } else {
                self.ws.solve_fixed(self.scale.x, sr)
            };
            if !solved {
                return Outcome::Failed { iterations, residual_norm };
            }
            let size = if bordered.is_some() { n + 1 } else { n };
            for i in 0..size {
                self.z[i] += self.ws.rhs[i];
            }
            iterations += 1;
        }
    }

    /// Unit null vector of `∂R/∂z` at the last Newton point (Jacobian still in the workspace),
    /// oriented along `reference`, into `tangent` (scaled). False if the bordered matrix is
    /// singular.
    fn tangent_at_last_point(&mut self, reference: &[f64]) -> bool {
        let n = self.n;
        self.ws.rhs.iter_mut().for_each(|v| *v = 0.0);
        self.ws.rhs[n] = 1.0;
        self.calls.factorizations += 1;
        self.total.factorizations += 1;
        if !self.ws.solve_bordered(self.scale.x, self.scale.lambda, self.scale.residual, reference) {
            return false;
        }
        let length = norm(&self.ws.rhs);
        let sign = if dot(&self.ws.rhs, reference) < 0.0 { -1.0 } else { 1.0 };
        for i in 0..=n {
            self.tangent[i] = sign * self.ws.rhs[i] / length;
        }
        true
    }
}
