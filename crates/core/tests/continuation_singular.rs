//! Folds and branch points from the continuation's own tangent and determinants
//! ([`Accepted::test_functions`], [`singular_points`]) on curves whose singular points are known
//! in closed form, and the test functions against their closed forms at every point.

use faer::MatMut;
use stickslip_core::continuation::{
    continue_branch, singular_points, Accepted, FactoredJacobian, Options, PointObserver, Predictor, Problem,
    ProblemError, Silent, SingularKind, TerminationReason, TestFunctions,
};

/// Keeps the test functions of every accepted point.
#[derive(Default)]
struct Tests(Vec<Option<TestFunctions>>);

impl<P: Problem + ?Sized> PointObserver<P> for Tests {
    fn on_accepted(&mut self, accepted: &mut Accepted<'_, P>) {
        self.0.push(accepted.test_functions().unwrap().cloned());
    }
}

/// The S-curve `x³ − 3x = λ`: folds at `(x, λ) = (−1, 2)` and `(1, −2)`.
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
        if let Some((mut dr_dx, dr_dlambda)) = jacobian {
            dr_dx[(0, 0)] = 3.0 * x[0] * x[0] - 3.0;
            dr_dlambda[0] = -1.0;
        }
        Ok(())
    }
}

/// `u = sin λ`, `v (λ − λ*) + v³ = 0`: the branch `v = 0` meets the pitchfork
/// `v² = λ* − λ` at `λ = λ*`, a branch point where the branch goes on forwards.
struct Pitchfork;

const PITCHFORK_AT: f64 = 0.3;

impl Problem for Pitchfork {
    fn dimension(&self) -> usize {
        2
    }
    fn evaluate(
        &mut self,
        x: &[f64],
        lambda: f64,
        residual: &mut [f64],
        jacobian: Option<(MatMut<'_, f64>, &mut [f64])>,
    ) -> Result<(), ProblemError> {
        let (u, v) = (x[0], x[1]);
        residual[0] = u - lambda.sin();
        residual[1] = v * (lambda - PITCHFORK_AT) + v.powi(3);
        if let Some((mut dr_dx, dr_dlambda)) = jacobian {
            dr_dx[(0, 0)] = 1.0;
            dr_dx[(1, 1)] = lambda - PITCHFORK_AT + 3.0 * v * v;
            dr_dlambda[0] = -lambda.cos();
            dr_dlambda[1] = v;
        }
        Ok(())
    }
}

#[test]
fn the_test_functions_equal_their_closed_forms_on_the_s_curve() {
    // The tangent predictor's own factorisation at every point, and the secant's points made
    // from the Jacobian on demand: both must give the closed forms.
    for predictor in [Predictor::Secant, Predictor::Tangent] {
        let options = Options { predictor, ..Options::default() };
        let mut tests = Tests::default();
        let branch = continue_branch(&mut SCurve, &[-2.0], -5.0, 5.0, &options, &mut tests).unwrap();
        assert_eq!(branch.termination, TerminationReason::ReachedEnd);
        assert_eq!(tests.0.len(), branch.points.len());
        for (i, (p, t)) in branch.points.iter().zip(&tests.0).enumerate() {
            let t = t.as_ref().expect("a regular point has test functions");
            let (sx, sl, sr) = (t.scales.unknowns, t.scales.parameter, t.scales.residual);
            // Scaled ∂R/∂z = [a, b]: its null vector (−b, a) is the tangent up to its
            // orientation, along the branch (the next point lies ahead of it).
            let (a, b) = ((3.0 * p.x[0] * p.x[0] - 3.0) * sx / sr, -sl / sr);
            let length = a.hypot(b);
            let ahead = branch
                .points
                .get(i + 1)
                .map_or(1.0, |q| (-b * (q.x[0] - p.x[0]) / sx + a * (q.lambda - p.lambda) / sl).signum());
            let tangent = [-b * ahead / length, a * ahead / length];
            // Computed from a 2×2 LU and normalised: a few ulps.
            for (got, want) in t.tangent.iter().zip(tangent) {
                assert!(
                    (got - want).abs() <= 1e-14,
                    "{predictor:?}, point {i}: tangent {:?}, want {tangent:?}",
                    t.tangent
                );
            }
            // det ∂R/∂x (scaled) = a; det [∂R/∂z; τᵀ] = a τ_λ − b τ_x.
            let bordered = a * tangent[1] - b * tangent[0];
            for (determinant, want) in [(t.jacobian, a), (t.bordered, bordered)] {
                assert_eq!(determinant.sign, want.signum(), "{predictor:?}, point {i}");
                assert!((determinant.ln_abs - want.abs().ln()).abs() <= 1e-12, "{predictor:?}, point {i}");
            }
        }
        // Orientation along the branch: det B(τ) keeps its sign from end to end (no branch
        // point), det ∂R/∂x changes it at each fold.
        let signs: Vec<f64> = tests.0.iter().map(|t| t.as_ref().unwrap().bordered.sign).collect();
        assert!(signs.iter().all(|&s| s == signs[0]), "{predictor:?}");
    }
}

/// The S-curve solved as a problem that factors its own Jacobian (by division): the
/// continuation then has no determinant and no tangent at its points.
struct FactoredSCurve {
    derivative: f64,
}

impl Problem for FactoredSCurve {
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
    fn factored(&mut self) -> Option<&mut dyn FactoredJacobian> {
        Some(self)
    }
}

impl FactoredJacobian for FactoredSCurve {
    fn evaluate_and_factor(
        &mut self,
        x: &[f64],
        lambda: f64,
        residual: &mut [f64],
        dr_dlambda: &mut [f64],
    ) -> Result<bool, ProblemError> {
        SCurve.evaluate(x, lambda, residual, None)?;
        dr_dlambda[0] = -1.0;
        self.derivative = 3.0 * x[0] * x[0] - 3.0;
        Ok(self.derivative != 0.0)
    }
    fn solve(&mut self, rhs: &mut [f64]) -> bool {
        rhs[0] /= self.derivative;
        rhs[0].is_finite()
    }
}

#[test]
fn the_folds_of_a_problem_that_factors_its_own_jacobian_are_where_the_branch_turns_back() {
    // No test functions at its points: the folds are the extrema of λ along the branch,
    // located between the neighbours of the point where λ turns back.
    let mut problem = FactoredSCurve { derivative: 1.0 };
    let mut tests = Tests::default();
    let branch = continue_branch(&mut problem, &[-2.0], -5.0, 5.0, &Options::default(), &mut tests).unwrap();
    assert!(tests.0.iter().all(|t| t.is_none()));
    let found = singular_points(&mut problem, &branch.points, &tests.0, 1e-10);
    let kinds: Vec<_> = found.iter().map(|p| p.kind).collect();
    assert_eq!(kinds, [SingularKind::Fold, SingularKind::Fold], "{found:?}");
    for (p, (x, lambda)) in found.iter().zip([(-1.0, 2.0), (1.0, -2.0)]) {
        assert!(p.located, "{p:?}");
        let after = p.after_point;
        let (a, b) = (branch.points[after].x[0], branch.points[after + 1].x[0]);
        assert!((a - p.x[0]) * (b - p.x[0]) <= 0.0, "{p:?} not after point {after}: {a}, {b}");
        // λ = ±(2 − 3 (x ± 1)² + ...): its extremum along the chord is located from values of
        // λ, which fix x only to ~√(ε/3) ≈ 1e-8 of the fold in principle (parabolic steps do
        // better: 8e-11 and 5e-10 measured), λ to round-off.
        assert!((p.x[0] - x).abs() < 1e-8, "{p:?}");
        assert!((p.lambda - lambda).abs() < 1e-14, "{p:?}");
    }
}

#[test]
fn the_folds_of_the_s_curve_are_located_where_its_derivative_vanishes() {
    let mut tests = Tests::default();
    let branch = continue_branch(&mut SCurve, &[-2.0], -5.0, 5.0, &Options::default(), &mut tests).unwrap();
    let found = singular_points(&mut SCurve, &branch.points, &tests.0, 1e-10);
    let kinds: Vec<_> = found.iter().map(|p| p.kind).collect();
    assert_eq!(kinds, [SingularKind::Fold, SingularKind::Fold], "{found:?}");
    for (p, (x, lambda)) in found.iter().zip([(-1.0, 2.0), (1.0, -2.0)]) {
        assert!(p.located);
        // Located to 1e-10 of a chord of ~0.1 in x, so x to 1e-11 at worst (measured 1e-16:
        // τ_λ is nearly linear through the fold), and λ = ±(2 − 3 (x ± 1)² + ...) to the
        // square of that, round-off.
        assert!((p.x[0] - x).abs() < 1e-11, "{p:?}");
        assert!((p.lambda - lambda).abs() < 1e-14, "{p:?}");
    }
}

#[test]
fn the_branch_point_of_a_pitchfork_is_located_where_it_is_and_is_not_a_fold() {
    let mut tests = Tests::default();
    let branch = continue_branch(&mut Pitchfork, &[0.0, 0.0], 0.0, 1.0, &Options::default(), &mut tests).unwrap();
    assert_eq!(branch.termination, TerminationReason::ReachedEnd);
    let found = singular_points(&mut Pitchfork, &branch.points, &tests.0, 1e-10);
    let kinds: Vec<_> = found.iter().map(|p| p.kind).collect();
    assert_eq!(kinds, [SingularKind::BranchPoint], "{found:?}");
    let p = &found[0];
    // A branch point is located to 1e-6 of the chord between its two points (the branch
    // cannot be solved much closer to it), here ~0.04 in λ.
    let span = branch.points[p.after_point + 1].lambda - branch.points[p.after_point].lambda;
    assert!(p.located && (p.lambda - PITCHFORK_AT).abs() <= 1e-6 * span, "{p:?}, span {span}");
    assert_eq!(p.x[1], 0.0);
    // The branch goes on forwards through it: τ_λ keeps its sign on both sides.
    let (t0, t1) = (tests.0[p.after_point].as_ref().unwrap(), tests.0[p.after_point + 1].as_ref().unwrap());
    assert!(t0.lambda_component() > 0.0 && t1.lambda_component() > 0.0);
    assert!(t0.jacobian.sign * t1.jacobian.sign < 0.0);
}

#[test]
fn asking_for_the_test_functions_leaves_the_branch_as_it_was() {
    for predictor in [Predictor::Secant, Predictor::Tangent, Predictor::Lagrange] {
        let options = Options { predictor, ..Options::default() };
        let silent = continue_branch(&mut SCurve, &[-2.0], -5.0, 5.0, &options, &mut Silent).unwrap();
        let asked = continue_branch(&mut SCurve, &[-2.0], -5.0, 5.0, &options, &mut Tests::default()).unwrap();
        assert_eq!(silent.points, asked.points, "{predictor:?}");
        assert_eq!(silent.termination, asked.termination, "{predictor:?}");
    }
}
