//! Folds and branch points of a branch, from the continuation's own tangent and determinants:
//! the test functions of Seydel (Practical Bifurcation and Stability Analysis, 3rd ed. 2010,
//! ch. 5) and Allgower & Georg (Numerical Continuation Methods, 1990, ch. 8).
//!
//! In the scaled variables `z = [x / s_x, λ / s_λ]` of the continuation (Eq. 31) the branch
//! solves `R = 0`; its Jacobian `∂R/∂z = [∂R/∂x s_x, ∂R/∂λ s_λ] / s_R` (n × (n+1), as in
//! Eq. 32) has rank n at a regular point, and its unit null vector is the tangent `τ`.
//! Expanding the bordered matrix `B(v) = [∂R/∂z; vᵀ]` along its last row,
//!
//! ```text
//! det B(v) = vᵀ c,      ∂R/∂z c = 0,      c_λ = det(∂R/∂x s_x / s_R)
//! ```
//!
//! with `c` the cofactors of that row, a null vector of `∂R/∂z`: `c = (τᵀ c) τ`, hence
//!
//! ```text
//! det(∂R/∂x s_x / s_R) = det B(τ) τ_λ                                          (1)
//! ```
//!
//! - at a **fold** (limit point) `∂R/∂x` is singular but `∂R/∂z` is not: `det B(τ)` keeps
//!   its sign while the branch turns back in λ, so `τ_λ`, and with it `det ∂R/∂x`, changes sign;
//! - at a simple **branch point** `∂R/∂z` has rank n − 1 and `c` vanishes: along the branch
//!   (τ oriented continuously) `det B(τ)` changes sign, and `det ∂R/∂x` with it, while `τ_λ`
//!   does not (the branch goes on in the same direction).
//!
//! One LU gives all three ([`Accepted::test_functions`](super::Accepted::test_functions)):
//! solving `B(r) w = e_{n+1}`, `r` the step that reached the point, gives `w = c / (rᵀ c)`, so
//!
//! ```text
//! τ = w / |w|,      det B(τ) = det B(r) |w|,      det(∂R/∂x s_x / s_R) = det B(r) w_λ     (2)
//! ```
//!
//! (`τ` is oriented along `r`, since `rᵀ w = 1`), and `det B(r)` is the product of the LU's
//! pivots, negated for an odd number of row transpositions.
//!
//! Each singular point is located between its two points by [`zero_along`] (the corrector on
//! hyperplanes across their chord, so through the fold itself): a fold on `τ_λ`, bounded and
//! smooth through it and zero exactly where `det ∂R/∂x` is (1); a branch point on `det B(r)`,
//! smooth through it, relative to its value at the first point (a determinant of n + 1 pivots
//! may be far from 1), to no finer than [`BRANCH_POINT_RESOLUTION`] of the chord. The
//! reference `r` is fixed on the bracket: the sum of the two points' tangents, within 90° of
//! each (they are oriented along the branch), so of the tangent between. On a branch that is
//! only piecewise smooth (friction: a corner where a slip phase begins) a test function may
//! also change sign across a corner, where the Jacobian jumps: the location then ends on the
//! corner.

use super::linear::Workspace;
use super::{zero_along, Bracket, Extremum, Point, Problem, ProblemError};

/// A determinant as its sign (−1, 0 or +1) and the logarithm of its magnitude: the
/// determinant of a few hundred pivots overflows, its logarithm does not.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Determinant {
    pub sign: f64,
    pub ln_abs: f64,
}

/// The scales of the continuation's variables at a point (see "Scaled variables" in
/// [`super`]): `z = [x / s_x, λ / s_λ]`, residuals relative to `s_R`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct VariableScales {
    pub unknowns: f64,
    pub parameter: f64,
    pub residual: f64,
}

/// The test functions of folds and branch points at a point of a branch, in the scaled
/// variables `z = [x / s_x, λ / s_λ]` of the continuation there (residuals relative to `s_R`):
/// with `B(v) = [∂R/∂z; vᵀ]` the bordered Jacobian,
///
/// ```text
/// det(∂R/∂x s_x / s_R) = det B(τ) τ_λ                                          (1)
/// ```
///
/// `det B(τ)` keeps its sign through a fold, where `τ_λ` changes it; it changes sign at a
/// branch point, where `τ_λ` does not. From one LU of `B(r)`, any `r` not orthogonal to the
/// tangent, and the solution of `B(r) w = e_{n+1}`: `τ = w/|w|`, `det B(τ) = det B(r) |w|`
/// (Eq. 2). `s_x` follows the largest `‖x‖` met, so magnitudes compare between points only with
/// their `scales`; signs always do.
#[derive(Clone, Debug, PartialEq)]
pub struct TestFunctions {
    /// The unit tangent `τ = [dx/ds / s_x, dλ/ds / s_λ]` (s the scaled arclength), oriented
    /// along the branch: along the step that reached the point (at the first point, towards
    /// `λ_end`).
    pub tangent: Vec<f64>,
    /// `det B(τ) = det [∂R/∂z; τᵀ]`: changes sign at a branch point.
    pub bordered: Determinant,
    /// `det(∂R/∂x s_x / s_R)` (Eq. 1): changes sign at a fold and at a branch point.
    pub jacobian: Determinant,
    pub scales: VariableScales,
}

impl TestFunctions {
    /// From the unit tangent `τ = w / |w|`, `|w|` and `det B(r)`, `w` the solution of
    /// `B(r) w = e_{n+1}` for any `r` (Eq. 2).
    pub(super) fn new(tangent: Vec<f64>, w_norm: f64, bordered_by_r: Determinant, scales: VariableScales) -> Self {
        let tangent_lambda = tangent[tangent.len() - 1];
        let lambda_sign = if tangent_lambda == 0.0 { 0.0 } else { tangent_lambda.signum() };
        TestFunctions {
            bordered: Determinant { sign: bordered_by_r.sign, ln_abs: bordered_by_r.ln_abs + w_norm.ln() },
            jacobian: Determinant {
                sign: bordered_by_r.sign * lambda_sign,
                ln_abs: bordered_by_r.ln_abs + w_norm.ln() + tangent_lambda.abs().ln(),
            },
            tangent,
            scales,
        }
    }

    /// `τ_λ`: the λ-component of the unit tangent (scaled), which changes sign at a fold.
    pub fn lambda_component(&self) -> f64 {
        self.tangent[self.tangent.len() - 1]
    }

    /// The tangent in physical units, `[dx/ds, dλ/ds]` per unit of scaled arclength.
    pub fn physical_tangent(&self) -> Vec<f64> {
        let n = self.tangent.len() - 1;
        let mut t = self.tangent.clone();
        t[..n].iter_mut().for_each(|v| *v *= self.scales.unknowns);
        t[n] *= self.scales.parameter;
        t
    }
}

/// `B(r)` factored for the Jacobian in `workspace` (its last evaluation, with the Jacobian),
/// `B(r) w = e_{n+1}` solved: `det B(r)`, and whether `w` (in `workspace.rhs`) is finite.
/// `None` for a problem that factors its own Jacobian.
pub(super) fn factor_bordered<P: Problem + ?Sized>(
    workspace: &mut Workspace,
    problem: &mut P,
    scales: VariableScales,
    reference: &[f64],
) -> Option<(Determinant, bool)> {
    if workspace.factors() {
        return None;
    }
    let n = reference.len() - 1;
    workspace.rhs.iter_mut().for_each(|v| *v = 0.0);
    workspace.rhs[n] = 1.0;
    let solved = workspace.solve_bordered(problem, scales.unknowns, scales.parameter, scales.residual, reference);
    workspace.bordered_determinant().map(|d| (d, solved))
}

/// [`factor_bordered`] made into the test functions (Eq. 2); `None` also where `B(r)` is
/// singular (no tangent).
pub(super) fn test_functions_at<P: Problem + ?Sized>(
    workspace: &mut Workspace,
    problem: &mut P,
    scales: VariableScales,
    reference: &[f64],
) -> Option<TestFunctions> {
    match factor_bordered(workspace, problem, scales, reference)? {
        (determinant, true) => {
            let w = &workspace.rhs;
            let length = w.iter().map(|v| v * v).sum::<f64>().sqrt();
            Some(TestFunctions::new(w.iter().map(|v| v / length).collect(), length, determinant, scales))
        }
        (_, false) => None,
    }
}

/// What happens between two points.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SingularKind {
    /// A limit point: the branch turns back in λ.
    Fold,
    /// Another branch crosses this one.
    BranchPoint,
}

/// A fold or branch point located on a branch.
#[derive(Clone, Debug, PartialEq)]
pub struct SingularPoint {
    pub kind: SingularKind,
    pub x: Vec<f64>,
    pub lambda: f64,
    /// Index of the accepted point just before it.
    pub after_point: usize,
    /// False when the location failed: then `x` and `lambda` are the point after it.
    pub located: bool,
}

/// The folds and branch points between consecutive `points` of a branch of `problem`, from
/// their test functions (`tests[i]` those of `points[i]`, as [`Accepted::test_functions`]
/// gives them; `None` where there are none, which skips the two segments around), each located
/// to `tolerance` on the chord between its two points. A fold: `τ_λ` changes sign (equivalently
/// `det ∂R/∂x` does and `det B(τ)` does not); a branch point: `det B(τ)` changes sign. For a
/// problem that factors its own Jacobian, which has no test functions, the folds alone, where
/// λ turns back along the branch (`turning_points`).
///
/// [`Accepted::test_functions`]: super::Accepted::test_functions
pub fn singular_points<P: Problem>(
    problem: &mut P,
    points: &[Point],
    tests: &[Option<TestFunctions>],
    tolerance: f64,
) -> Vec<SingularPoint> {
    if problem.factored().is_some() {
        return turning_points(problem, points, tolerance);
    }
    let mut found = Vec::new();
    for (i, pair) in points.windows(2).enumerate() {
        let (Some(Some(t0)), Some(Some(t1))) = (tests.get(i), tests.get(i + 1)) else { continue };
        let crossed = [
            (SingularKind::BranchPoint, t0.bordered.sign * t1.bordered.sign < 0.0),
            (SingularKind::Fold, t0.lambda_component() * t1.lambda_component() < 0.0),
        ];
        for kind in crossed.into_iter().filter_map(|(kind, crossed)| crossed.then_some(kind)) {
            let (p0, p1) = (&pair[0], &pair[1]);
            found.push(match locate(problem, kind, [p0, p1], [t0, t1], tolerance) {
                Ok(z) => SingularPoint { kind, x: z.x, lambda: z.lambda, after_point: i, located: true },
                Err(_) => SingularPoint { kind, x: p1.x.clone(), lambda: p1.lambda, after_point: i, located: false },
            });
        }
    }
    found
}

/// The folds of a branch of a problem that factors its own Jacobian ([`Problem::factored`]),
/// whose points have no test functions (neither the determinant nor the tangent at a point is
/// formed): where λ turns back, at a point where it is larger, or smaller, than at both its
/// neighbours. Each is located as the extremum of λ between those neighbours
/// ([`Bracket::across_fold`], [`Bracket::maximise`] of ±λ, to `tolerance` on their chord),
/// which is where `det ∂R/∂x` vanishes and τ_λ changes sign. Branch points are not found.
fn turning_points<P: Problem>(problem: &mut P, points: &[Point], tolerance: f64) -> Vec<SingularPoint> {
    let mut found = Vec::new();
    for i in 1..points.len().saturating_sub(1) {
        let (before, here, after) = (points[i - 1].lambda, points[i].lambda, points[i + 1].lambda);
        let sign = match (here > before && here > after, here < before && here < after) {
            (true, _) => 1.0,
            (_, true) => -1.0,
            _ => continue,
        };
        let kind = SingularKind::Fold;
        let located =
            Bracket::across_fold(problem, [&points[i - 1], &points[i], &points[i + 1]]).and_then(|mut bracket| {
                let extremum = bracket.maximise(problem, tolerance, |_, _, lambda| Ok(sign * lambda))?;
                Ok((extremum, bracket.middle()))
            });
        found.push(match located {
            Ok((e, middle)) => SingularPoint {
                kind,
                x: e.x,
                lambda: e.lambda,
                after_point: if e.s < middle { i - 1 } else { i },
                located: true,
            },
            Err(_) => {
                SingularPoint { kind, x: points[i].x.clone(), lambda: points[i].lambda, after_point: i, located: false }
            }
        });
    }
    found
}

/// The finest bracket, of the chord between its two points, a branch point is located to.
/// Within a distance `d` of it, the other branch crossing there is as near, and Newton on the
/// branch resolves the point only to ~`ε/d` in that direction (ε the round-off of the residual,
/// relative): the branch cannot be solved closer than ~√ε ≈ 1e-8 of the chord, and
/// [`zero_along`] keeps its trials an eighth of its bracket away from a point it could not
/// solve. At 1e-6 the branch point's λ is known to 1e-6 of a continuation step.
const BRANCH_POINT_RESOLUTION: f64 = 1e-6;

/// Locate the `kind` of singular point between `points` by [`zero_along`] on its test
/// function (module documentation), in the scaled variables of the first point.
fn locate<P: Problem>(
    problem: &mut P,
    kind: SingularKind,
    points: [&Point; 2],
    [t0, t1]: [&TestFunctions; 2],
    tolerance: f64,
) -> Result<Extremum, ProblemError> {
    let scales = t0.scales;
    let n = problem.dimension();
    // τ₀ + τ₁ in the first point's scaling (s_x may have grown at the second).
    let mut second = t1.physical_tangent();
    second[..n].iter_mut().for_each(|v| *v /= scales.unknowns);
    second[n] /= scales.parameter;
    let length = second.iter().map(|v| v * v).sum::<f64>().sqrt();
    let reference: Vec<f64> = t0.tangent.iter().zip(&second).map(|(a, b)| a + b / length).collect();
    let mut workspace = Workspace::new(problem);
    let mut first_ln_abs = None;
    let tolerance = match kind {
        SingularKind::Fold => tolerance,
        SingularKind::BranchPoint => tolerance.max(BRANCH_POINT_RESOLUTION),
    };
    zero_along(problem, points, tolerance, |problem, x, lambda| {
        workspace.evaluate(problem, x, lambda, true)?;
        let (determinant, solved) = factor_bordered(&mut workspace, problem, scales, &reference)
            .ok_or_else(|| ProblemError::new("the problem factors its own Jacobian: no determinant"))?;
        match kind {
            SingularKind::Fold if solved => {
                let w = &workspace.rhs;
                Ok(w[n] / w.iter().map(|v| v * v).sum::<f64>().sqrt())
            }
            SingularKind::Fold => Err(ProblemError::new("the bordered matrix is singular on the bracket")),
            SingularKind::BranchPoint => {
                let first = *first_ln_abs.get_or_insert(determinant.ln_abs);
                Ok(determinant.sign * (determinant.ln_abs - first).exp())
            }
        }
    })
}
