//! Continuation on algebraic curves whose points are known exactly: a circle (one fold, back to
//! the start on the other side), a cubic S-curve (two folds, both sweep directions), and
//! problems that fail on purpose to check step halving and termination reasons.

use faer::MatMut;
use stickslip_core::continuation::{
    continue_branch, Branch, Options, Point, Predictor, Problem, ProblemError, ProgressOverWhole, Scales, Silent,
    TerminationReason,
};

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

/// x³ − 3x − λ = 0: folds at x = ∓1, λ = ±2.
struct SCurve;

impl Problem for SCurve {
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
        residual[0] = x[0].powi(3) - 3.0 * x[0] - lambda;
        if let Some((mut jx, dl)) = jacobian {
            jx[(0, 0)] = 3.0 * x[0] * x[0] - 3.0;
            dl[0] = -1.0;
        }
        Ok(())
    }
}

/// The straight line x = λ, whose residual is NaN on chosen calls or in a chosen region, and
/// which returns an error beyond `error_above`.
struct Line {
    calls: usize,
    nan_on_call: Option<usize>,
    nan_above: f64,
    error_above: f64,
    /// NaN residuals for λ strictly inside.
    hole: (f64, f64),
}

impl Line {
    fn new() -> Self {
        Line {
            calls: 0,
            nan_on_call: None,
            nan_above: f64::INFINITY,
            error_above: f64::INFINITY,
            hole: (f64::INFINITY, f64::INFINITY),
        }
    }
}

impl Problem for Line {
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
        self.calls += 1;
        if lambda > self.error_above {
            return Err(ProblemError::new(format!("no solution model beyond λ = {}", self.error_above)));
        }
        let in_hole = lambda > self.hole.0 && lambda < self.hole.1;
        residual[0] = if Some(self.calls) == self.nan_on_call || lambda > self.nan_above || in_hole {
            f64::NAN
        } else {
            x[0] - lambda
        };
        if let Some((mut jx, dl)) = jacobian {
            jx[(0, 0)] = 1.0;
            dl[0] = -1.0;
        }
        Ok(())
    }
}

fn run<P: Problem>(problem: &mut P, guess: f64, start: f64, end: f64, options: &Options) -> Branch {
    continue_branch(problem, &[guess], start, end, options, &mut Silent).expect("valid input")
}

/// Number of reversals of the direction of λ along the branch (one per fold passed).
fn reversals(points: &[Point]) -> usize {
    let steps: Vec<f64> = points.windows(2).map(|w| w[1].lambda - w[0].lambda).collect();
    steps.windows(2).filter(|w| w[0] * w[1] < 0.0).count()
}

const PREDICTORS: [Predictor; 3] = [Predictor::Secant, Predictor::Tangent, Predictor::Lagrange];

#[test]
fn circle_passes_its_fold_and_stops_exactly_at_the_start_on_the_other_side() {
    for predictor in PREDICTORS {
        let options = Options { predictor, ..Options::default() };
        let branch = run(&mut Circle, 0.9, 0.0, 1.5, &options);
        assert_eq!(branch.termination, TerminationReason::ReturnedToStart, "{predictor:?}");
        // Every point on the circle: the residual tolerance is 1e-10 of ‖R(0, 0)‖ = 1, and
        // |x² + λ² − 1| is the distance to the unit circle to first order (times 2).
        for p in &branch.points {
            assert!((p.x[0].hypot(p.lambda) - 1.0).abs() < 1e-10, "{predictor:?}: {p:?}");
        }
        assert_eq!(reversals(&branch.points), 1, "{predictor:?}: one fold, at λ = 1");
        let top = branch.points.iter().map(|p| p.lambda).fold(f64::MIN, f64::max);
        // The fold is passed by steps of at most max_step = 0.05 in scaled arclength (s_λ = 1.5,
        // s_x = 1): the largest λ seen is within the sagitta of one step, (0.05·1.5)²/2 < 3e-3.
        assert!(top > 1.0 - 3e-3, "{predictor:?}: fold at λ = 1 reached, got {top}");
        let last = branch.points.last().unwrap();
        assert_eq!(last.lambda, 0.0);
        assert!((last.x[0] + 1.0).abs() < 1e-10, "{predictor:?}: ends at (−1, 0), got {}", last.x[0]);
        assert!(branch.points.iter().all(|p| p.lambda >= 0.0));
    }
}

#[test]
fn s_curve_passes_both_folds_in_both_directions_and_ends_exactly_at_the_end() {
    for predictor in PREDICTORS {
        let options = Options { predictor, ..Options::default() };
        // Up: from the lower branch at λ = −5 (x ≈ −2.28) to the upper one at λ = 5.
        let up = run(&mut SCurve, -2.0, -5.0, 5.0, &options);
        // Down: the mirror sweep.
        let down = run(&mut SCurve, 2.0, 5.0, -5.0, &options);
        for (branch, end, x_sign) in [(&up, 5.0, 1.0), (&down, -5.0, -1.0)] {
            assert_eq!(branch.termination, TerminationReason::ReachedEnd, "{predictor:?}");
            assert_eq!(reversals(&branch.points), 2, "{predictor:?}: folds at λ = ±2");
            // Residual tolerance 1e-10·‖R(0, λ_start)‖ = 5e-10; |∂R/∂x| ≥ 3(x² − 1) > 0 away
            // from the folds, so the residual itself is the check.
            for p in &branch.points {
                let r = p.x[0].powi(3) - 3.0 * p.x[0] - p.lambda;
                assert!(r.abs() <= 5e-10, "{predictor:?}: {p:?}");
            }
            let last = branch.points.last().unwrap();
            assert_eq!(last.lambda, end, "{predictor:?}: stops exactly at the end");
            assert!(last.x[0] * x_sign > 2.0, "{predictor:?}: on the far branch, x = {}", last.x[0]);
            // Both fold values of x = ±1 are visited: the points span x ∈ (−2.3, 2.3).
            let (lo, hi) = branch.points.iter().fold((f64::MAX, f64::MIN), |(a, b), p| (a.min(p.x[0]), b.max(p.x[0])));
            assert!(lo < -2.2 && hi > 2.2, "{predictor:?}: x spans [{lo}, {hi}]");
        }
    }
}

#[test]
fn a_failed_correction_halves_the_step_and_the_next_step_does_not_grow() {
    // On a straight line the secant prediction is exact: every point converges with zero
    // Newton iterations (one call) and the step grows by `growth` until `max_step`.
    let options = Options { initial_step: 1e-3, ..Options::default() };
    let mut line = Line::new();
    line.nan_on_call = Some(8);
    let branch = run(&mut line, 0.0, 0.0, 1.0, &options);
    assert_eq!(branch.termination, TerminationReason::ReachedEnd);
    let k = branch.points.iter().position(|p| p.rejected > 0).expect("a rejected attempt");
    assert_eq!(branch.points.iter().filter(|p| p.rejected > 0).count(), 1);
    let (before, hit, after) = (&branch.points[k - 1], &branch.points[k], &branch.points[k + 1]);
    assert_eq!(hit.rejected, 1);
    // Planned step: the previous one grown by 1.5 (the first step uses initial_step).
    let planned = if k == 1 { options.initial_step } else { before.step * options.growth };
    assert_eq!(hit.step, planned / 2.0, "one halving");
    assert_eq!(after.step, hit.step, "no growth right after a rejection");
    assert_eq!(branch.points[k + 2].step, hit.step * options.growth, "growth resumes");
    assert_eq!(hit.calls.residuals, 2, "the failed attempt and the accepted one");
    for p in &branch.points {
        // To the Newton tolerance, 1e-10 of ‖R(0, λ_end)‖ = 1 (R(0, 0) vanishes).
        assert!((p.x[0] - p.lambda).abs() <= 1e-10);
    }
}

#[test]
fn a_point_where_no_step_converges_is_leapt_over() {
    // NaN residuals on a hole 3e-5 wide around where the first step lands: the steps halve
    // towards it, down to min_step = 1e-6 in front of it, then leaps of 4, 16, 64... times the
    // smallest step try beyond it, and one lands past it.
    let options = Options { initial_step: 1e-2, min_step: 1e-6, ..Options::default() };
    let first_step = run(&mut Line::new(), 0.0, 0.0, 1.0, &options).points[1].lambda;
    let hole = (first_step - 1.5e-5, first_step + 1.5e-5);
    let branch = run(&mut Line { hole, ..Line::new() }, 0.0, 0.0, 1.0, &options);
    assert_eq!(branch.termination, TerminationReason::ReachedEnd);
    assert!(branch.points.iter().all(|p| !(p.lambda > hole.0 && p.lambda < hole.1)));
    let i = branch.points.iter().position(|p| p.lambda >= hole.1).unwrap();
    let (before, over) = (&branch.points[i - 1], &branch.points[i]);
    // In front of the hole the last accepted step was within a few min_steps of it (the next,
    // at most twice as long, failed); the leap is over 3e-5 long, at most 4⁶ times 2e-6.
    assert!(hole.0 - before.lambda < 4e-6, "approached to {} of the hole", hole.0 - before.lambda);
    assert!(over.rejected > 1 && over.step >= 3e-5 && over.step <= 4096.0 * 2e-6, "{over:?}");
    assert!(branch.points.iter().all(|p| (p.x[0] - p.lambda).abs() <= 1e-10));
    // Without leaps the branch stops in front of the hole.
    let strict = Options { leaps: 0, ..options };
    let branch = run(&mut Line { hole, ..Line::new() }, 0.0, 0.0, 1.0, &strict);
    assert!(matches!(branch.termination, TerminationReason::StepTooSmall { leaps: 0, .. }));
}

#[test]
fn steps_halve_down_to_min_step_before_a_wall() {
    // NaN residuals beyond λ = 0.5: every step that crosses it fails.
    let options = Options { initial_step: 1e-2, min_step: 1e-6, ..Options::default() };
    let mut line = Line::new();
    line.nan_above = 0.5;
    let branch = run(&mut line, 0.0, 0.0, 1.0, &options);
    let last = branch.points.last().unwrap();
    assert!(last.lambda <= 0.5);
    let planned = if last.rejected == 0 { (last.step * options.growth).min(options.max_step) } else { last.step };
    // Halvings while the step stays at or above min_step, then leaps of 4 times the last from
    // the smallest, up to max_step or `leaps` of them: all fail beyond the wall.
    let mut expected_attempts = 1;
    let mut h = planned;
    while 0.5 * h >= options.min_step {
        h *= 0.5;
        expected_attempts += 1;
    }
    let mut expected_leaps = 0;
    while expected_leaps < options.leaps && h < options.max_step {
        h = (4.0 * h).min(options.max_step);
        expected_leaps += 1;
    }
    match branch.termination {
        TerminationReason::StepTooSmall { lambda, attempts, leaps, residual_norm, .. } => {
            let message = branch.termination.to_string();
            assert!(message.contains(&format!("{attempts} steps tried")), "{message}");
            assert_eq!(lambda, last.lambda);
            assert_eq!(leaps, expected_leaps);
            assert_eq!(attempts, expected_attempts + expected_leaps);
            assert!(residual_norm.is_nan());
        }
        other => panic!("expected StepTooSmall, got {other:?}"),
    }
    // The wall is approached to within a step smaller than min_step·√2 ... plus the step
    // just before the halvings started; the points found are all kept and exact.
    assert!(branch.points.len() > 10);
    assert!(branch.points.iter().all(|p| (p.x[0] - p.lambda).abs() <= 1e-10)); // Newton tolerance
}

#[test]
fn a_problem_error_ends_the_branch_with_where_it_happened_and_keeps_the_points() {
    let mut line = Line::new();
    line.error_above = 0.6;
    let branch = run(&mut line, 0.0, 0.0, 1.0, &Options::default());
    let last = branch.points.last().unwrap().lambda;
    match &branch.termination {
        TerminationReason::ProblemError { lambda, last_lambda, error } => {
            assert!(*lambda > 0.6, "failed at λ = {lambda}");
            assert_eq!(*last_lambda, Some(last));
            assert!(error.message.contains("0.6"));
        }
        other => panic!("expected ProblemError, got {other:?}"),
    }
    let message = branch.termination.to_string();
    assert!(message.contains(&format!("last converged point at λ = {last}")), "{message}");
    assert!(last <= 0.6 && last > 0.5, "points up to the failure are kept, last at {last}");
    assert!(branch.points.iter().all(|p| (p.x[0] - p.lambda).abs() <= 1e-10)); // Newton tolerance
}

#[test]
fn a_start_without_solution_ends_the_branch_with_no_points_and_the_reason() {
    // x² + 4 = 1 has no real solution: Newton from x = 1 wanders until its iteration limit.
    let branch = run(&mut Circle, 1.0, 2.0, 3.0, &Options::default());
    assert!(branch.points.is_empty());
    match branch.termination {
        TerminationReason::FirstPointFailed { lambda, iterations, residual_norm } => {
            assert_eq!(lambda, 2.0);
            assert_eq!(iterations, Options::default().first_point_max_iterations);
            assert!(residual_norm >= 3.0, "x² + 3 ≥ 3, got {residual_norm}");
        }
        other => panic!("expected FirstPointFailed, got {other:?}"),
    }
}

#[test]
fn a_problem_failing_at_the_start_is_reported_with_no_points() {
    let mut line = Line::new();
    line.error_above = -1.0;
    let branch = run(&mut line, 0.0, 0.0, 1.0, &Options::default());
    assert!(branch.points.is_empty());
    match &branch.termination {
        TerminationReason::ProblemError { lambda, last_lambda, .. } => {
            assert_eq!((*lambda, *last_lambda), (0.0, None));
        }
        other => panic!("expected ProblemError, got {other:?}"),
    }
    assert!(branch.termination.to_string().contains("before any point converged"));
}

#[test]
fn invalid_input_is_an_error_naming_what_is_wrong() {
    let bad = Options { max_step: 1e-9, ..Options::default() };
    let err = continue_branch(&mut Circle, &[1.0], 0.0, 1.0, &bad, &mut Silent).unwrap_err();
    assert!(err.to_string().contains("max_step"), "{err}");
    let err = continue_branch(&mut Circle, &[1.0, 2.0], 0.0, 1.0, &Options::default(), &mut Silent).unwrap_err();
    assert!(err.to_string().contains("expected 1"), "{err}");
    let err = continue_branch(&mut Circle, &[1.0], 0.3, 0.3, &Options::default(), &mut Silent).unwrap_err();
    assert!(err.to_string().contains("empty"), "{err}");
    let err = continue_branch(&mut Circle, &[f64::NAN], 0.0, 1.0, &Options::default(), &mut Silent).unwrap_err();
    assert!(err.to_string().contains("not finite"), "{err}");
}

#[test]
fn observer_sees_every_point_with_monotone_progress() {
    let mut seen = Vec::new();
    let mut observer = |p: &Point, fraction: f64| seen.push((p.lambda, fraction));
    let branch = continue_branch(&mut SCurve, &[-2.0], -5.0, 5.0, &Options::default(), &mut observer).unwrap();
    assert_eq!(seen.len(), branch.points.len());
    assert!(seen.windows(2).all(|w| w[1].1 >= w[0].1));
    assert_eq!(seen.last().unwrap().1, 1.0);
    let total: usize = branch.points.iter().map(|p| p.calls.residuals).sum();
    // The residual-scale evaluation R(0, λ_start) belongs to the first point.
    assert_eq!(total, branch.calls.residuals);
}

/// The S-curve with the unknown's scale fixed to 1, so that the scaled variables are known
/// outside: z = (x, λ / 10) on the interval [−5, 5].
struct SCurveUnitScale;

impl Problem for SCurveUnitScale {
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
        SCurve.evaluate(x, lambda, residual, jacobian)
    }
    fn scales(&self) -> Scales {
        Scales { unknowns: Some(1.0), residual: None }
    }
}

/// Largest turn between consecutive secants in the scaled variables (x, λ/10), the last
/// point (placed at λ_end by a fixed-λ solve, not by a checked step) left out.
fn largest_turn(points: &[Point]) -> f64 {
    let secants: Vec<(f64, f64)> = points[..points.len() - 1]
        .windows(2)
        .map(|w| (w[1].x[0] - w[0].x[0], (w[1].lambda - w[0].lambda) / 10.0))
        .collect();
    secants
        .windows(2)
        .map(|w| {
            ((w[0].0 * w[1].0 + w[0].1 * w[1].1) / (w[0].0.hypot(w[0].1) * w[1].0.hypot(w[1].1)))
                .clamp(-1.0, 1.0)
                .acos()
        })
        .fold(0.0, f64::max)
}

#[test]
fn the_angle_check_bounds_the_turn_between_consecutive_secants() {
    for predictor in PREDICTORS {
        // Coarse steps (0.3 of the scaled band) around folds whose radius of curvature in the
        // scaled variables is 1/0.6 (μ = λ/10 = (x³ − 3x)/10 has μ'' = 0.6 at x = ±1): turns
        // of ~0.2 rad per step.
        let coarse = Options { predictor, initial_step: 0.3, max_step: 0.3, ..Options::default() };
        let checked = run(&mut SCurveUnitScale, -2.0, -5.0, 5.0, &Options { max_angle: 0.1, ..coarse.clone() });
        let unchecked =
            run(&mut SCurveUnitScale, -2.0, -5.0, 5.0, &Options { max_angle: std::f64::consts::PI, ..coarse });
        for branch in [&checked, &unchecked] {
            assert_eq!(branch.termination, TerminationReason::ReachedEnd, "{predictor:?}");
            assert_eq!(reversals(&branch.points), 2, "{predictor:?}");
        }
        // Without the check the turns at the folds exceed 0.1 rad (so this test can fail);
        // with it, none does (1e-12: rounding of the recomputed secants).
        assert!(largest_turn(&unchecked.points) > 0.1, "{predictor:?}: {}", largest_turn(&unchecked.points));
        assert!(largest_turn(&checked.points) <= 0.1 + 1e-12, "{predictor:?}: {}", largest_turn(&checked.points));
    }
}

/// x = f(λ), f piecewise linear with a corner at λ = 0.5 (slope 1, then −0.25): a branch that
/// is only C0, like a frequency response at a stick/slip transition.
struct Corner;

fn corner_curve(lambda: f64) -> f64 {
    if lambda < 0.5 {
        lambda
    } else {
        0.5 - 0.25 * (lambda - 0.5)
    }
}

impl Problem for Corner {
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
        residual[0] = x[0] - corner_curve(lambda);
        if let Some((mut jx, dl)) = jacobian {
            jx[(0, 0)] = 1.0;
            dl[0] = if lambda < 0.5 { -1.0 } else { 0.25 };
        }
        Ok(())
    }
}

#[test]
fn a_corner_of_a_non_smooth_branch_is_passed_after_corner_after_halvings() {
    // With s_x = 1 (the first tangent predicts Δx = 1 across the band) and s_λ = 1, the secant
    // turns by atan(1) + atan(0.25) = 1.03 rad at the corner. A step straddling the corner
    // splits the turn in two, one of which still exceeds max_angle = 0.5 whatever the step:
    // only the corner rule lets the branch through.
    for predictor in PREDICTORS {
        let options = Options { predictor, ..Options::default() };
        let branch = run(&mut Corner, 0.0, 0.0, 1.0, &options);
        assert_eq!(branch.termination, TerminationReason::ReachedEnd, "{predictor:?}");
        // On the curve to the Newton tolerance, 1e-10 of the residual scale ‖R(0, 1)‖ = 0.375
        // (R(0, 0) vanishes), since ∂R/∂x = 1.
        for p in &branch.points {
            assert!((p.x[0] - corner_curve(p.lambda)).abs() <= 3.75e-11, "{predictor:?}: {p:?}");
        }
        let at_corner = branch.points.iter().find(|p| p.rejected >= options.corner_after);
        assert!(
            at_corner.is_some_and(|p| p.lambda > 0.5),
            "{predictor:?}: the corner is crossed by a rule-accepted step"
        );

        // Without the rule the steps shrink to nothing at the corner.
        let strict = Options { predictor, corner_after: usize::MAX, leaps: 0, ..Options::default() };
        let branch = run(&mut Corner, 0.0, 0.0, 1.0, &strict);
        match branch.termination {
            TerminationReason::StepTooSmall { lambda, .. } => {
                assert!((lambda - 0.5).abs() < 0.01, "{predictor:?}: stuck at the corner, at {lambda}")
            }
            other => panic!("{predictor:?}: expected StepTooSmall, got {other:?}"),
        }
    }
}

/// x = sin(4λ), whose law fails (as an element's AFT on a wild trial motion) at any iterate
/// farther than 0.02 from the branch.
struct Fragile {
    failures: usize,
}

impl Problem for Fragile {
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
        residual[0] = x[0] - (4.0 * lambda).sin();
        if residual[0].abs() > 0.02 {
            self.failures += 1;
            return Err(ProblemError::at_trial_iterate(format!("no periodic regime at x = {}", x[0])));
        }
        if let Some((mut jx, dl)) = jacobian {
            jx[(0, 0)] = 1.0;
            dl[0] = -4.0 * (4.0 * lambda).cos();
        }
        Ok(())
    }
}

#[test]
fn a_failure_at_a_trial_iterate_rejects_the_step_instead_of_ending_the_branch() {
    // Steps of 0.1 (scaled) predict iterates up to ~0.1 off the curve: those fail, are halved,
    // and the branch goes on to the end.
    let options = Options { initial_step: 0.1, max_step: 0.2, ..Options::default() };
    let mut problem = Fragile { failures: 0 };
    let branch = run(&mut problem, 0.0, 0.0, 2.0, &options);
    assert_eq!(branch.termination, TerminationReason::ReachedEnd);
    assert!(problem.failures > 0, "no trial iterate failed: the test does not test");
    assert!(branch.points.iter().map(|p| p.rejected).sum::<usize>() > 0);
    assert!(branch.points.iter().all(|p| (p.x[0] - (4.0 * p.lambda).sin()).abs() <= 1e-9));
    // At the first point the same error ends the branch, with its message.
    let mut problem = Fragile { failures: 0 };
    let branch = run(&mut problem, 1.0, 0.0, 2.0, &options);
    match &branch.termination {
        TerminationReason::ProblemError { lambda, last_lambda: None, error } => {
            assert_eq!(*lambda, 0.0);
            assert!(error.message.contains("no periodic regime"), "{}", error.message);
        }
        other => panic!("expected ProblemError, got {other:?}"),
    }
}

/// The rest of a sweep resumed past a stop reports its progress over the whole band: a
/// continuation over the last three quarters of an interval, handed on through
/// `ProgressOverWhole` with offset 0.25, gives fractions from 0.25 to exactly 1, never
/// decreasing (the furthest λ reached, through the S-curve's folds too), each equal to
/// 0.25 + 0.75 × its own fraction.
#[test]
fn progress_over_the_whole_interval_goes_on_from_the_offset() {
    let (mut own, mut whole) = (Vec::new(), Vec::new());
    let mut record_whole = |_: &Point, fraction: f64| whole.push(fraction);
    let mut both = |p: &Point, fraction: f64| {
        own.push(fraction);
        record_whole(p, 0.25 + 0.75 * fraction);
    };
    let branch = continue_branch(&mut SCurve, &[-2.0], -2.0, 2.0, &Options::default(), &mut both).unwrap();
    assert_eq!(branch.termination, TerminationReason::ReachedEnd);
    let mut handed = Vec::new();
    let mut record = |_: &Point, fraction: f64| handed.push(fraction);
    let mut observer = ProgressOverWhole { inner: &mut record, offset: 0.25 };
    continue_branch(&mut SCurve, &[-2.0], -2.0, 2.0, &Options::default(), &mut observer).unwrap();
    assert_eq!(handed, whole, "the same branch, each fraction rescaled");
    assert_eq!(handed.first().copied(), Some(0.25));
    assert_eq!(handed.last().copied(), Some(1.0));
    assert!(handed.windows(2).all(|w| w[0] <= w[1]), "{handed:?}");
    assert!(own.iter().all(|f| (0.0..=1.0).contains(f)));
}
