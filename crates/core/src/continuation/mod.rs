//! Pseudo-arclength continuation of `R(x, λ) = 0` (paper Section 4.3, Eqs. 31-32).
//!
//! Any problem with `n` unknowns `x` and one parameter `λ` (the excitation frequency Ω of a
//! harmonic-balance sweep, a force level at fixed frequency, the amplitude of a backbone...)
//! implements [`Problem`]; [`continue_branch`] follows its solution curve from `λ_start` to
//! `λ_end` through turning points and returns a [`Branch`] of converged [`Point`]s and the
//! [`TerminationReason`].
//!
//! # Scaled variables (Eq. 31)
//!
//! The arclength between consecutive points is (Eq. 31)
//!
//! ```text
//! Δs² = ‖x_{i+1} − x_i‖² + α |λ_{i+1} − λ_i|²
//! ```
//!
//! and α is chosen here, never by the user: the continuation works in the scaled variables
//! `z = [x / s_x, λ / s_λ]`, so α = (s_x / s_λ)², with `s_λ = |λ_end − λ_start|` (a step of 1 in
//! λ crosses the band) and `s_x` the largest of `‖x‖` at the first point, the change of `x` the
//! first tangent predicts across the band (`‖dx/dλ‖ s_λ`, which sizes a sweep that starts from
//! `x = 0`) and `‖x‖` of every point accepted since (a resonance peak rises far above its
//! off-resonance start). A problem may fix `s_x` instead ([`Scales`]). Residuals are measured
//! relative to a residual scale `s_R`: the problem's, or `‖R(0, λ_start)‖` (the forcing of a
//! forced problem), or `‖R(0, λ_end)‖` if that vanishes (a force-level sweep from zero), or 1.
//! Step sizes ([`Options`]) are scaled arclengths.
//!
//! # The loop
//!
//! The first point is a plain Newton solve at fixed `λ_start` from the caller's guess (e.g. the
//! linear solution). Then, from the last converged point `z_i`:
//!
//! - **PREDICT**: `z_p = z_i + h t`, `t` the unit secant `z_i − z_{i−1}` ([`Predictor::Secant`],
//!   default), the unit tangent, null vector of `[∂R/∂z]` ([`Predictor::Tangent`]), or the
//!   paper's second-degree Lagrange polynomial through `z_{i−2}, z_{i−1}, z_i` parametrised by
//!   their cumulative arclength (Eq. 31), evaluated at `s_i + h` ([`Predictor::Lagrange`]).
//!   A secant or Lagrange prediction rejected twice in a row is retried along the tangent at
//!   the last point (from the Jacobian there): at a sharp peak the curve turns within one
//!   step, and the secant keeps pointing off it however short the step.
//! - **CORRECT**: Newton on the bordered system (Eq. 32), the correction orthogonal to the
//!   prediction direction `t = (z_p − z_i)/‖z_p − z_i‖`:
//!
//!   ```text
//!   [ ∂R/∂z(z_k) ] Δz = − [ R(z_k)          ]      z_{k+1} = z_k + Δz
//!   [ tᵀ         ]        [ tᵀ (z_k − z_p)  ]
//!   ```
//!
//!   (Eq. 32 writes the last row as `2 (z_p − z_i)ᵀ`, the same hyperplane), until
//!   `‖R‖ ≤ max(rtol s_R, atol)`. The `(n+1)×(n+1)` system is factored by partial-pivot LU in
//!   place, on buffers allocated once per branch. Once Newton converges quadratically, the
//!   predicted last iterate is checked with a residual alone, saving the Jacobian at the
//!   solution that only the tangent predictor uses.
//! - **ACCEPT-REJECT**: a correction is rejected when Newton fails (no convergence within
//!   `max_iterations`, a non-finite residual, a singular bordered matrix, or a problem that
//!   cannot be evaluated at a trial iterate, [`ProblemError::at_trial_iterate`]), when the corrector
//!   travelled farther than the step itself (a jump to another part of the curve) or when the
//!   secant turned by more than `max_angle` from the previous one (a fold taken too coarsely).
//!   Friction makes branches only piecewise smooth (a stick/slip transition is a corner): a
//!   turn that persists after `corner_after` halvings (or with a step too close to
//!   `min_step` for that many) is a corner, not a coarse fold, and is accepted, with a
//!   corrector travel up to 10 steps (at a corner of angle α it travels `h tan α`,
//!   proportional to the step, whereas a jump stays far however small the step).
//! - **ADAPT STEP**: a rejection halves `h` and retries from `z_i`; an acceptance after at most
//!   `easy_iterations` Newton iterations multiplies `h` by `growth` (not right after a
//!   rejection); `h` stays within `[min_step, max_step]`. Where every step down to `min_step`
//!   fails, the point ahead is one Newton cannot converge at however close it starts (a
//!   non-smooth, singular residual: several identical joints switching between stick and slip
//!   at one time sample together); up to `leaps` steps, each 4 times the last from the
//!   smallest, try to land beyond it, where the branch is regular again. A leap is checked as
//!   any step.
//! - **TERMINATE**: the branch ends as a value ([`TerminationReason`]): when a point passes
//!   `λ_end` (or, after a fold, goes back past `λ_start`) the last point is replaced by a Newton
//!   solve at exactly that `λ` from the interpolated guess; when `max_points` are stored; when
//!   `h` falls below `min_step` and the leaps failed; when the problem returns an error. Every converged point before
//!   is kept.
//!
//! Progress goes to an [`Observer`]; the library never prints. Each point carries its call
//! counts ([`Calls`]).
//!
//! # Example
//!
//! The S-curve `x³ − 3x = λ` has folds at `λ = ±2`; continued from `λ = −5` to `5` it passes
//! both and ends exactly at `λ = 5`:
//!
//! ```
//! use faer::MatMut;
//! use stickslip_core::continuation::{continue_branch, Options, Problem, ProblemError, Silent, TerminationReason};
//!
//! struct SCurve;
//! impl Problem for SCurve {
//!     fn dimension(&self) -> usize {
//!         1
//!     }
//!     fn evaluate(
//!         &mut self,
//!         x: &[f64],
//!         lambda: f64,
//!         residual: &mut [f64],
//!         jacobian: Option<(MatMut<'_, f64>, &mut [f64])>,
//!     ) -> Result<(), ProblemError> {
//!         residual[0] = x[0].powi(3) - 3.0 * x[0] - lambda;
//!         if let Some((mut dr_dx, dr_dlambda)) = jacobian {
//!             dr_dx[(0, 0)] = 3.0 * x[0] * x[0] - 3.0;
//!             dr_dlambda[0] = -1.0;
//!         }
//!         Ok(())
//!     }
//! }
//!
//! let branch = continue_branch(&mut SCurve, &[-2.0], -5.0, 5.0, &Options::default(), &mut Silent)?;
//! assert_eq!(branch.termination, TerminationReason::ReachedEnd);
//! let last = branch.points.last().unwrap();
//! assert_eq!(last.lambda, 5.0);
//! // On the upper branch, to the residual tolerance 1e-10 ‖R(0, −5)‖ = 5e-10.
//! assert!((last.x[0].powi(3) - 3.0 * last.x[0] - 5.0).abs() <= 5e-10 && last.x[0] > 2.0);
//! # Ok::<(), stickslip_core::continuation::ContinuationError>(())
//! ```

mod dense_lu;
mod extremum;
mod linear;
mod run;
mod singular;

pub use dense_lu::PivotedLu;
pub use extremum::{maximise_along, zero_along, Bracket, Extremum};
pub use run::continue_branch;
pub use singular::{singular_points, Determinant, SingularKind, SingularPoint, TestFunctions, VariableScales};

use faer::{MatMut, MatRef};
use linear::Workspace;

/// `R(x, λ) = 0`, `x ∈ Rⁿ`, `λ` the continuation parameter (Ω, a force level, ...).
pub trait Problem {
    /// Number of unknowns `n` (and of residual equations).
    fn dimension(&self) -> usize;

    /// Write `R(x, λ)` into `residual` and, when `jacobian` is given, `∂R/∂x` (n×n, in a
    /// column-major view) and `∂R/∂λ`. The Jacobian buffers are zeroed before the call, so only
    /// non-zero entries need writing. An `Err` ends the continuation (it is reported with the
    /// `λ` where it happened); a non-finite residual only rejects the current step.
    fn evaluate(
        &mut self,
        x: &[f64],
        lambda: f64,
        residual: &mut [f64],
        jacobian: Option<(MatMut<'_, f64>, &mut [f64])>,
    ) -> Result<(), ProblemError>;

    /// Typical magnitudes for scaling; the default derives them from the start point.
    fn scales(&self) -> Scales {
        Scales::default()
    }

    /// A problem too large for a dense Jacobian (thousands of unknowns) may factor `∂R/∂x` by
    /// its own structure: when this returns `Some`, the corrector never asks [`Self::evaluate`]
    /// for `∂R/∂x` and solves its systems through [`FactoredJacobian`] instead (the bordered
    /// system of Eq. 32 by block elimination). `None`, the default: dense LU.
    fn factored(&mut self) -> Option<&mut dyn FactoredJacobian> {
        None
    }

    /// Can [`Self::complete_jacobian`] give the Jacobian at the point of the last residual
    /// evaluation for less than evaluating there again? Then the corrector evaluates residuals
    /// alone and completes only those it does not accept: the Jacobian at a converged point is
    /// never computed. Same iterates either way. Default: no.
    fn completes_jacobian(&self) -> bool {
        false
    }

    /// `∂R/∂x` and `∂R/∂λ` (buffers as for [`Self::evaluate`], zeroed unless
    /// [`Self::completion_writes_every_entry`]) at the point of the last
    /// [`Self::evaluate`], which was asked for the residual alone; called only when
    /// [`Self::completes_jacobian`].
    fn complete_jacobian(&mut self, _jacobian: (MatMut<'_, f64>, &mut [f64])) -> Result<(), ProblemError> {
        Err(ProblemError::new("this problem does not complete a residual evaluation to a Jacobian"))
    }

    /// Does [`Self::complete_jacobian`] write every entry of `∂R/∂x` and `∂R/∂λ`? Then the
    /// corrector does not zero them before the call (the fill of a 60 × 60 Jacobian is ~2 % of
    /// a paper-size sweep). Default: no.
    fn completion_writes_every_entry(&self) -> bool {
        false
    }

    /// `Some(a)` when the last dense `∂R/∂x` written ([`Self::evaluate`] or
    /// [`Self::complete_jacobian`]) is block diagonal: zero between the unknowns `a`
    /// (ascending) and the others. The corrector then factors the two blocks apart (the even
    /// and odd harmonics of a half-wave symmetric balance). `a` should be the block that stays
    /// regular at the branch's folds. Default: `None` (one dense block).
    fn decoupled_unknowns(&self) -> Option<&[usize]> {
        None
    }

    /// Is the block of [`Self::decoupled_unknowns`] in the last dense `∂R/∂x` the identity
    /// (unknowns the problem pins at zero by `R_a = x_a`: the even harmonics of a balance
    /// whose solutions are half-wave symmetric)? The corrector then neither factors nor
    /// gathers it. Default: no.
    fn decoupled_block_is_identity(&self) -> bool {
        false
    }
}

/// `∂R/∂x` factored by the problem itself ([`Problem::factored`]).
pub trait FactoredJacobian {
    /// `R(x, λ)` into `residual`, `∂R/∂λ` into `dr_dlambda`, and `∂R/∂x` factored for
    /// [`Self::solve`]. Errors as [`Problem::evaluate`]; `Ok(false)` if `∂R/∂x` is singular.
    fn evaluate_and_factor(
        &mut self,
        x: &[f64],
        lambda: f64,
        residual: &mut [f64],
        dr_dlambda: &mut [f64],
    ) -> Result<bool, ProblemError>;

    /// Overwrite `rhs` with `(∂R/∂x)⁻¹ rhs` at the last factored point; false if the result
    /// is not finite.
    fn solve(&mut self, rhs: &mut [f64]) -> bool;
}

/// Typical magnitudes a problem may impose (positive and finite when given).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Scales {
    /// Norm of a typical `x` (fixes `s_x`; default: automatic, see the module documentation).
    pub unknowns: Option<f64>,
    /// Norm of a typical residual term, e.g. the excitation force (default `‖R(0, λ_start)‖`, see the
    /// module documentation).
    pub residual: Option<f64>,
}

/// A failure of the problem itself (not a convergence failure), e.g. an invalid state.
#[derive(Clone, Debug, thiserror::Error, PartialEq)]
#[error("{message}")]
pub struct ProblemError {
    pub message: String,
    /// The problem cannot be evaluated at this iterate only (e.g. an element whose law has no
    /// periodic regime for a wild trial motion): the step is rejected and retried shorter,
    /// instead of ending the branch. At the first point it ends the branch all the same.
    pub at_trial_iterate: bool,
}

impl ProblemError {
    /// An error that ends the continuation.
    pub fn new(message: impl Into<String>) -> Self {
        ProblemError { message: message.into(), at_trial_iterate: false }
    }

    /// An error at a trial iterate: the step is rejected ([`Rejection::TrialIterateFailed`]).
    pub fn at_trial_iterate(message: impl Into<String>) -> Self {
        ProblemError { message: message.into(), at_trial_iterate: true }
    }
}

/// How the next point is predicted.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Predictor {
    /// Along the chord through the last two points (tangent at the first step).
    #[default]
    Secant,
    /// Along the null vector of the bordered Jacobian at the last point.
    Tangent,
    /// Second-degree Lagrange polynomial through the last three points, parametrised by
    /// arclength (the paper's choice; secant while fewer than three points exist).
    Lagrange,
}

/// Settings of the continuation. Steps are scaled arclengths (see the module documentation):
/// a step of 1 crosses the whole λ interval when `x` does not change.
#[derive(Clone, Debug, PartialEq)]
pub struct Options {
    pub predictor: Predictor,
    pub initial_step: f64,
    pub min_step: f64,
    pub max_step: f64,
    /// Step multiplier after an easy correction.
    pub growth: f64,
    /// A correction with at most this many Newton iterations is easy.
    pub easy_iterations: usize,
    /// Newton iterations allowed per correction.
    pub max_iterations: usize,
    /// Newton iterations allowed for a solve at fixed λ from the caller's guess.
    pub first_point_max_iterations: usize,
    /// Largest turn (radians) of the secant between consecutive steps.
    pub max_angle: f64,
    /// After this many halvings for one point, a turn beyond `max_angle` is taken for a
    /// corner of a non-smooth branch and accepted (see ACCEPT-REJECT).
    pub corner_after: usize,
    /// Relative residual tolerance, of the residual scale.
    pub rtol: f64,
    /// Absolute residual floor (residual units): the tolerance never goes below it.
    pub atol: f64,
    /// Number of points after which the branch stops.
    pub max_points: usize,
    /// Leaps tried once the steps have halved down to `min_step`, each 4 times the last,
    /// before the branch stops (see ADAPT STEP).
    pub leaps: usize,
}

impl Default for Options {
    fn default() -> Self {
        Options {
            predictor: Predictor::Secant,
            initial_step: 1e-2,
            min_step: 1e-7,
            max_step: 5e-2,
            growth: 1.5,
            easy_iterations: 3,
            max_iterations: 10,
            first_point_max_iterations: 50,
            max_angle: 0.5,
            corner_after: 4,
            rtol: 1e-10,
            atol: 1e-14,
            max_points: 10_000,
            leaps: 10,
        }
    }
}

/// Calls made to the problem for one point (its rejected attempts included).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Calls {
    /// Residual evaluations.
    pub residuals: usize,
    /// Jacobian evaluations.
    pub jacobians: usize,
    /// LU factorisations: one per Newton iteration, plus the tangent at the previous point
    /// (the first point's, and every point's with the tangent predictor).
    pub factorizations: usize,
}

impl std::ops::AddAssign for Calls {
    fn add_assign(&mut self, other: Calls) {
        self.residuals += other.residuals;
        self.jacobians += other.jacobians;
        self.factorizations += other.factorizations;
    }
}

/// One converged solution.
#[derive(Clone, Debug, PartialEq)]
pub struct Point {
    pub x: Vec<f64>,
    pub lambda: f64,
    /// Newton iterations of the accepted correction.
    pub iterations: usize,
    /// `‖R(x, λ)‖` (Euclidean, residual units).
    pub residual_norm: f64,
    /// Scaled arclength step of the accepted prediction (0 for the first point; for a point
    /// placed on an end of the interval, the scaled distance from the previous point).
    pub step: f64,
    /// Rejected attempts before this point was accepted.
    pub rejected: usize,
    pub calls: Calls,
}

/// Why a branch ended. None of these is an error: the points found are in the [`Branch`].
#[derive(Clone, Debug, PartialEq)]
pub enum TerminationReason {
    /// The last point is at `λ_end`.
    ReachedEnd,
    /// After a fold, the branch came back to `λ_start`; the last point is at `λ_start`.
    ReturnedToStart,
    /// `max_points` points are stored.
    MaxPoints,
    /// The solve at `λ_start` from the caller's guess did not converge.
    FirstPointFailed { lambda: f64, residual_norm: f64, iterations: usize },
    /// Every step down to `min_step` failed after the point at `lambda`.
    StepTooSmall {
        /// Why the last (smallest) step was rejected.
        rejection: Rejection,
        /// λ of the last converged point.
        lambda: f64,
        /// Residual norm at the end of the last failed correction.
        residual_norm: f64,
        /// Steps tried (each half the previous, then the leaps).
        attempts: usize,
        /// Of those, leaps beyond the smallest step (each 4 times the last).
        leaps: usize,
        /// Newton iterations spent on them.
        iterations: usize,
        /// The last iterate of the last failed correction, `(x, λ)`: where Newton stopped
        /// (e.g. at a singular Jacobian), to diagnose the stop.
        last_iterate: Option<(Vec<f64>, f64)>,
    },
    /// The problem returned an error when evaluated at `lambda`.
    ProblemError {
        lambda: f64,
        /// λ of the last converged point, if any.
        last_lambda: Option<f64>,
        error: ProblemError,
    },
}

impl std::fmt::Display for TerminationReason {
    /// One sentence saying where and why the branch ended (λ in the problem's units).
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            TerminationReason::ReachedEnd => write!(f, "reached the end of the interval"),
            TerminationReason::ReturnedToStart => write!(f, "came back to the start of the interval after a fold"),
            TerminationReason::MaxPoints => write!(f, "stopped at the maximum number of points"),
            TerminationReason::FirstPointFailed { lambda, residual_norm, iterations } => write!(
                f,
                "no solution found at the start λ = {lambda}: Newton from the initial guess ended at residual \
                 {residual_norm:.3e} after {iterations} iterations"
            ),
            TerminationReason::StepTooSmall {
                rejection, lambda, residual_norm, attempts, leaps, iterations, ..
            } => {
                write!(
                    f,
                    "no step accepted after the point at λ = {lambda}: {attempts} steps tried, each half the previous \
                 down to the minimum step, then {leaps} leaps each 4 times the last ({iterations} Newton \
                 iterations); the last was rejected because {rejection} (residual {residual_norm:.3e})"
                )
            }
            TerminationReason::ProblemError { lambda, last_lambda, error } => match last_lambda {
                Some(last) => {
                    write!(f, "the problem failed at λ = {lambda} (last converged point at λ = {last}): {error}")
                }
                None => write!(f, "the problem failed at λ = {lambda}, before any point converged: {error}"),
            },
        }
    }
}

/// Why a step was rejected (see ACCEPT-REJECT in the module documentation).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Rejection {
    /// Newton did not reach the tolerance within `max_iterations`.
    NoConvergence,
    /// Newton alternated between the same iterates until `max_iterations`: the residual is
    /// non-smooth there (e.g. a sample of a stiff friction joint switching between stick and
    /// slip) and the corrector's hyperplane does not meet the branch near the prediction.
    NewtonCycle,
    /// A residual that is not finite, or a singular bordered matrix.
    Singular,
    /// The corrector travelled farther than the step (a jump to another part of the curve).
    TravelledTooFar,
    /// The secant turned by more than `max_angle` from the previous one.
    TurnedTooSharply,
    /// The first step went back past `λ_start`.
    WentBack,
    /// The solve at exactly the end of the interval did not converge.
    EndSolveFailed,
    /// The problem could not be evaluated at a trial iterate ([`ProblemError::at_trial_iterate`]).
    TrialIterateFailed,
}

impl std::fmt::Display for Rejection {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            Rejection::NoConvergence => "Newton did not converge within the iteration limit",
            Rejection::NewtonCycle => {
                "Newton cycled between the same iterates (a non-smooth residual: the corrector's hyperplane \
                 misses the branch near the prediction)"
            }
            Rejection::Singular => "the residual was not finite or the bordered matrix singular",
            Rejection::TravelledTooFar => "the corrector travelled farther than the step",
            Rejection::TurnedTooSharply => "the branch turned by more than the largest angle",
            Rejection::WentBack => "the first step went back past the start of the interval",
            Rejection::EndSolveFailed => "the solve at the end of the interval did not converge",
            Rejection::TrialIterateFailed => {
                "the problem could not be evaluated at a trial iterate (e.g. an element with no periodic regime \
                 for the trial motion)"
            }
        })
    }
}

/// A continued solution branch.
#[derive(Clone, Debug, PartialEq)]
pub struct Branch {
    pub points: Vec<Point>,
    pub termination: TerminationReason,
    /// All calls, rejected attempts included.
    pub calls: Calls,
    /// The residual scale `s_R` (see "Scaled variables"): Newton converges when
    /// `‖R‖ ≤ max(rtol s_R, atol)`, so `Point::residual_norm / residual_scale` is the measure the
    /// tolerance applies to.
    pub residual_scale: f64,
    /// Stops before the end past which the branch was resumed (a frequency sweep started
    /// afresh beyond the stop and followed back to it, `hbm::sweep`): empty for a branch
    /// continued in one run.
    pub resumed: Vec<Resumption>,
}

/// Where a branch stopped before its end and was resumed.
#[derive(Clone, Debug, PartialEq)]
pub struct Resumption {
    /// λ of the last point before the stop.
    pub stopped_at: f64,
    /// λ where the branch was started afresh and followed back to the stop.
    pub restarted_at: f64,
}

/// Receives every converged point as it is accepted (progress, the points alone). An observer
/// that needs more of each point implements [`PointObserver`] instead.
pub trait Observer {
    /// `fraction_done` in [0, 1]: the furthest λ reached, as a fraction of the interval.
    fn on_point(&mut self, point: &Point, fraction_done: f64);
}

/// Receives every converged point as it is accepted, with the problem as it stands there
/// ([`Accepted`]): what a point's results need (the forces of its elements, the Jacobian that
/// its stability needs) is read from the evaluation that converged, not computed again after
/// the branch. Every [`Observer`] is one.
pub trait PointObserver<P: ?Sized> {
    fn on_accepted(&mut self, accepted: &mut Accepted<'_, P>);
}

impl<P: ?Sized, O: Observer + ?Sized> PointObserver<P> for O {
    fn on_accepted(&mut self, accepted: &mut Accepted<'_, P>) {
        self.on_point(accepted.point, accepted.fraction_done)
    }
}

/// Hands a continuation over the last part of an interval on to `inner` with its progress
/// over the whole interval: the part starts at `offset` of the whole, so its fraction `f` is
/// `offset + (1 − offset) f` of the whole (the rest of a sweep resumed past a stop, whose
/// progress would otherwise start again from zero).
pub struct ProgressOverWhole<'o, O: ?Sized> {
    pub inner: &'o mut O,
    pub offset: f64,
}

impl<P: ?Sized, O: PointObserver<P> + ?Sized> PointObserver<P> for ProgressOverWhole<'_, O> {
    fn on_accepted(&mut self, accepted: &mut Accepted<'_, P>) {
        let part = accepted.fraction_done;
        accepted.fraction_done = (self.offset + (1.0 - self.offset) * part).clamp(0.0, 1.0);
        self.inner.on_accepted(accepted);
        accepted.fraction_done = part;
    }
}

/// `∂R/∂x` (n × n) and `∂R/∂λ` at an accepted point ([`Accepted::jacobian`]).
pub type JacobianAt<'a> = (MatRef<'a, f64>, &'a [f64]);

/// An accepted point as the continuation hands it to a [`PointObserver`]: the point, and the
/// problem whose last evaluation was the residual at this very point (so per-point data, e.g.
/// the element forces of a harmonic balance, can be read from it as they stand), with the
/// Jacobian there on demand ([`Self::jacobian`]) and the test functions of folds and branch
/// points ([`Self::test_functions`]).
pub struct Accepted<'a, P: ?Sized> {
    point: &'a Point,
    fraction_done: f64,
    residual_scale: f64,
    problem: &'a mut P,
    workspace: &'a mut Workspace,
    /// The problem's last evaluation is still the residual alone at the point, which it can
    /// complete to a Jacobian ([`Problem::complete_jacobian`]).
    completable: bool,
    /// The workspace holds `∂R/∂x` and `∂R/∂λ` at the point, not yet factored.
    jacobian_held: bool,
    /// The step that reached the point, in the scaled variables of `scales` (at the first
    /// point, the tangent there or the direction towards `λ_end`): the tangent's orientation.
    direction: &'a [f64],
    scales: VariableScales,
    /// The continuation factored the bordered matrix `B(direction)` at the point itself (for
    /// its tangent): the unit tangent, `|w|`, `det B(direction)` (Eq. 2 of `singular`)
    /// and the scaled variables they are in.
    tangent_factors: Option<(&'a [f64], f64, Determinant, VariableScales)>,
    /// The test functions, once asked for (`Some(None)`: there are none).
    test_functions: Option<Option<TestFunctions>>,
    /// Calls made here (the Jacobian), added to the branch's.
    calls: Calls,
}

impl<'a, P: Problem + ?Sized> Accepted<'a, P> {
    pub fn point(&self) -> &Point {
        self.point
    }

    /// The furthest λ reached, as a fraction of the interval (in [0, 1]).
    pub fn fraction_done(&self) -> f64 {
        self.fraction_done
    }

    /// The branch's residual scale ([`Branch::residual_scale`]): `point().residual_norm`
    /// divided by it is the measure Newton's tolerance applies to.
    pub fn residual_scale(&self) -> f64 {
        self.residual_scale
    }

    /// The problem, its last evaluation the residual at the point. An observer that evaluates
    /// it elsewhere changes that: [`Self::jacobian`] then evaluates the problem at the point
    /// again (ask for the Jacobian first to avoid it).
    pub fn problem(&mut self) -> &mut P {
        self.completable = false;
        self.problem
    }

    /// `∂R/∂x` (n × n) and `∂R/∂λ` at the point: completed from the converged residual
    /// evaluation where the problem can ([`Problem::completes_jacobian`]), else evaluated
    /// there. `None` for a problem that factors its own Jacobian ([`Problem::factored`]): the
    /// continuation never has it dense.
    pub fn jacobian(&mut self) -> Result<Option<JacobianAt<'_>>, ProblemError> {
        if self.workspace.factors() {
            return Ok(None);
        }
        if !self.jacobian_held {
            if self.completable {
                self.calls += Calls { residuals: 0, jacobians: 1, factorizations: 0 };
                self.workspace.complete(self.problem)?;
            } else {
                self.calls += Calls { residuals: 1, jacobians: 1, factorizations: 0 };
                self.workspace.evaluate(self.problem, &self.point.x, self.point.lambda, true)?;
            }
            // The problem's last evaluation is now the point's, with its Jacobian.
            self.completable = false;
            self.jacobian_held = true;
        }
        Ok(Some(self.workspace.jacobian()))
    }

    /// The test functions of folds and branch points at the point ([`TestFunctions`]: the unit
    /// tangent oriented along the branch, `det ∂R/∂x` and the bordered determinant): from the
    /// continuation's own factorisation where it made one at the point (the first point, and
    /// every point with [`Predictor::Tangent`]), else from the Jacobian there
    /// ([`Self::jacobian`]) and one LU of size n + 1, which the Jacobian does not survive (a
    /// later [`Self::jacobian`] evaluates it again: ask for it first). The path of the
    /// continuation does not depend on it. `None` for a problem that factors its own
    /// Jacobian, or where the bordered matrix is singular.
    /// [`Self::test_functions`], but where the converged evaluation was of the residual alone
    /// and the corrector's last factorisation is still held, from that factorisation: at the
    /// last Newton iterate before the point, within Newton's last update of it, for one solve
    /// instead of the Jacobian and an LU. Their signs are the point's unless a fold or branch
    /// point lies within that update; [`singular_points`] locates what they show by exact
    /// evaluations. Elsewhere the exact test functions.
    pub fn test_functions_estimate(&mut self) -> Result<Option<&TestFunctions>, ProblemError> {
        if self.test_functions.is_none()
            && self.tangent_factors.is_none()
            && self.completable
            && self.workspace.holds_bordered_factors()
        {
            let n = self.workspace.rhs.len() - 1;
            self.workspace.rhs.iter_mut().for_each(|v| *v = 0.0);
            self.workspace.rhs[n] = 1.0;
            if self.workspace.solve_with_bordered_factors() {
                if let Some(mut determinant) = self.workspace.bordered_determinant() {
                    // B(r) w = e_{n+1}, r the corrector's hyperplane (Eq. 2 of `singular`),
                    // w oriented along the step that reached the point; the bordered
                    // determinant, linear in its last row, turns with it.
                    let w = &self.workspace.rhs;
                    let length = w.iter().map(|v| v * v).sum::<f64>().sqrt();
                    let along: f64 = w.iter().zip(self.direction).map(|(a, b)| a * b).sum();
                    let sign = if along < 0.0 { -1.0 } else { 1.0 };
                    determinant.sign *= sign;
                    let tangent = w.iter().map(|v| sign * v / length).collect();
                    self.test_functions = Some(Some(TestFunctions::new(tangent, length, determinant, self.scales)));
                }
            }
        }
        self.test_functions()
    }

    pub fn test_functions(&mut self) -> Result<Option<&TestFunctions>, ProblemError> {
        if self.test_functions.is_none() {
            let found = match self.tangent_factors.take() {
                Some((tangent, w_norm, determinant, scales)) => {
                    Some(TestFunctions::new(tangent.to_vec(), w_norm, determinant, scales))
                }
                None if self.workspace.factors() => None,
                None => {
                    self.jacobian()?;
                    self.calls += Calls { residuals: 0, jacobians: 0, factorizations: 1 };
                    self.jacobian_held = false;
                    singular::test_functions_at(self.workspace, self.problem, self.scales, self.direction)
                }
            };
            self.test_functions = Some(found);
        }
        Ok(self.test_functions.as_ref().and_then(Option::as_ref))
    }
}

impl<F: FnMut(&Point, f64)> Observer for F {
    fn on_point(&mut self, point: &Point, fraction_done: f64) {
        self(point, fraction_done)
    }
}

/// An observer that ignores everything.
#[derive(Clone, Copy, Debug, Default)]
pub struct Silent;

impl Observer for Silent {
    fn on_point(&mut self, _: &Point, _: f64) {}
}

/// Invalid input to the continuation (as opposed to a branch that ends early).
#[derive(Clone, Debug, thiserror::Error, PartialEq)]
pub enum ContinuationError {
    #[error("continuation option `{name}` is {value}, expected {expected}")]
    InvalidOption { name: &'static str, value: f64, expected: &'static str },
    #[error("the initial guess has {len} unknowns, expected {expected} (the problem's dimension)")]
    WrongGuessLength { len: usize, expected: usize },
    #[error("the initial guess has a value that is not finite (NaN or infinity) at index {index}")]
    NonFiniteGuess { index: usize },
    #[error("the continuation interval [{start}, {end}] is empty or not finite: give two different finite values")]
    EmptyInterval { start: f64, end: f64 },
    #[error("the problem's {name} scale is {value}, expected a positive finite value")]
    InvalidScale { name: &'static str, value: f64 },
}

impl Options {
    /// Check every option; the error names the first invalid one.
    pub fn validate(&self) -> Result<(), ContinuationError> {
        fn check(ok: bool, name: &'static str, value: f64, expected: &'static str) -> Result<(), ContinuationError> {
            if ok {
                Ok(())
            } else {
                Err(ContinuationError::InvalidOption { name, value, expected })
            }
        }
        let positive = |v: f64| v.is_finite() && v > 0.0;
        check(positive(self.min_step), "min_step", self.min_step, "a positive number")?;
        check(
            positive(self.max_step) && self.max_step >= self.min_step,
            "max_step",
            self.max_step,
            "a positive number not below min_step",
        )?;
        check(
            positive(self.initial_step) && self.initial_step >= self.min_step && self.initial_step <= self.max_step,
            "initial_step",
            self.initial_step,
            "a number within [min_step, max_step]",
        )?;
        check(self.growth.is_finite() && self.growth >= 1.0, "growth", self.growth, "a number of at least 1")?;
        check(self.max_iterations >= 1, "max_iterations", self.max_iterations as f64, "at least 1")?;
        check(
            self.first_point_max_iterations >= 1,
            "first_point_max_iterations",
            self.first_point_max_iterations as f64,
            "at least 1",
        )?;
        check(
            positive(self.max_angle) && self.max_angle <= std::f64::consts::PI,
            "max_angle",
            self.max_angle,
            "an angle in (0, π] radians",
        )?;
        check(self.corner_after >= 1, "corner_after", self.corner_after as f64, "at least 1")?;
        check(positive(self.rtol), "rtol", self.rtol, "a positive number")?;
        check(self.atol.is_finite() && self.atol >= 0.0, "atol", self.atol, "a non-negative number")?;
        check(self.max_points >= 1, "max_points", self.max_points as f64, "at least 1")?;
        Ok(())
    }
}
