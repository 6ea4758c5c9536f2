//! Bifurcations of a forced-response branch, from two sources:
//!
//! - **folds** (limit points: a sweep jumps there) and **branch points** (another branch of
//!   periodic solutions crosses this one) from the continuation's own test functions, its
//!   tangent and determinants at every accepted point ([`crate::continuation::singular_points`]):
//!   one LU per point, so they are found at every sweep, with or without stability;
//! - with stability (Hill's method, [`super::stability`]), where a complex pair of Floquet
//!   exponents crosses the imaginary axis between two accepted points: a **period doubling**
//!   when its imaginary part is ±Ω/2 (a multiplier through −1), a **Neimark-Sacker**
//!   bifurcation otherwise (the response becomes quasi-periodic), located by [`zero_along`] on
//!   the leading exponent's real part, along the branch.
//!
//! A real exponent crosses zero exactly where the balance's Jacobian is singular. At s = 0
//! (where the sliders' memory weights `e^{−sΔ}` are 1) Hill's matrix is the Jacobian of the
//! balance in dynamic-stiffness form, `Z + E ∂G/∂x Eᵀ` (`Z` the linear part's dynamic
//! stiffness, harmonic by harmonic, `E` the joints' directions), and the flexibility form the
//! continuation solves is `∂R/∂x = I + H ∂G/∂x` with `H = Eᵀ Z⁻¹ E`; by Sylvester's
//! determinant identity `det(Z + E ∂G/∂x Eᵀ) = det Z det(∂R/∂x)`, and `det Z ≠ 0` for a
//! damped structure. The two vanish together up to Hill's truncation of the modes (those beyond
//! the band act through their residual flexibility): on the Duffing oscillator, where no mode is
//! left out, the folds from the tangent and from Hill's leading exponent are 4e-16 apart at most
//! (`tests/stability_duffing.rs`), and at the symmetry-breaking branch point of two coupled
//! oscillators 3e-12 (`tests/stability_branch_point.rs`). Real crossings are therefore taken
//! from the test functions alone, which also see a fold or a branch point on a branch already
//! unstable (where the stable flag does not change), and the exponents give the complex
//! crossings only.

use faer::{c64, Mat};

use super::condensed::{CondensedHbm, HbmError};
use super::stability::{Hill, Stability, StabilityError};
use super::sweep::FrequencySweep;
use crate::continuation::{singular_points, zero_along, Point, Problem, ProblemError, SingularKind, TestFunctions};

/// The kinds of bifurcation a forced response shows.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BifurcationKind {
    Fold,
    BranchPoint,
    PeriodDoubling,
    NeimarkSacker,
}

impl BifurcationKind {
    pub fn name(&self) -> &'static str {
        match self {
            BifurcationKind::Fold => "fold",
            BifurcationKind::BranchPoint => "branch point",
            BifurcationKind::PeriodDoubling => "period doubling",
            BifurcationKind::NeimarkSacker => "Neimark-Sacker",
        }
    }
}

/// A bifurcation located on a branch.
#[derive(Clone, Debug, PartialEq)]
pub struct Bifurcation {
    pub kind: BifurcationKind,
    /// Where it is: Ω (rad/s) and the balance's unknowns.
    pub omega: f64,
    pub x: Vec<f64>,
    /// For a bifurcation found from the Floquet exponents, the crossing exponent at the
    /// located point (real part ~0); for a Neimark-Sacker, its imaginary part is the frequency
    /// of the new, incommensurate motion (rad/s). `None` for a fold or a branch point, found
    /// from the test functions: a real exponent crosses zero there.
    pub exponent: Option<c64>,
    /// Index of the accepted point just before it.
    pub after_point: usize,
    /// False when the location failed: then `omega` and `x` are the point after the crossing.
    pub located: bool,
}

/// Why stability along a branch could not be computed.
#[derive(Debug, thiserror::Error)]
pub enum BranchStabilityError {
    #[error(transparent)]
    Hbm(#[from] HbmError),
    #[error(transparent)]
    Stability(#[from] StabilityError),
}

/// Relative tolerance on a Floquet exponent's real part, of Ω: exponents within it of the
/// imaginary axis count as on it (round-off of the Hill eigenproblem is ~1e-12 Ω).
pub const EXPONENT_TOLERANCE: f64 = 1e-9;

/// Floquet exponents of the solution at `x`, Ω.
///
/// With sliders (Jenkins joints), Hill's matrix depends on the exponent itself: a stuck
/// slider remembers the displacement at its last slip, a delay Δ back, which a perturbation
/// `e^{st}` weights by `e^{−sΔ}` ([`super::ElementAft::add_memory_delay`]). The exponents of the
/// periodic Jacobian (s = 0 in the weights; one real eigenproblem on the companion form, which
/// also sorts out the physical exponents) start Newton's method on the nonlinear Hill problem
/// `T(s) P = 0` for the leading ones ([`Hill::refine`]: one complex LU of size m(2N+1) per
/// step). The fixed point `s ← the eigenvalue of Hill(J(s)) nearest s` that it replaces (a
/// complex eigenproblem of size 2m(2N+1) per step, tens of LUs' worth) remains where Newton's
/// root lies far from its start ([`CLOSE_ROOT`]): there the nonlinear problem has several
/// roots, and the fixed point's "nearest eigenvalue" rule picks which; Newton might settle on
/// another. [`stability_by_eigenproblems`] is the fixed point everywhere, the reference.
pub fn stability_at(
    hbm: &mut CondensedHbm<'_>,
    hill: &Hill,
    x: &[f64],
    omega: f64,
) -> Result<Stability, BranchStabilityError> {
    let jacobian = hbm.element_force_jacobian(x, omega)?;
    refined_stability(hbm, hill, jacobian, omega, false)
}

/// [`stability_at`] of the solution `x`, Ω at which `hbm` was last evaluated (a continuation's
/// converged evaluation, handed to its observer): the joints' Jacobian is completed from that
/// evaluation ([`CondensedHbm::element_force_jacobian_at_last`]) instead of evaluated again.
/// The same exponents.
pub fn stability_at_last_evaluation(
    hbm: &mut CondensedHbm<'_>,
    hill: &Hill,
    x: &[f64],
    omega: f64,
) -> Result<Stability, BranchStabilityError> {
    let jacobian = hbm.element_force_jacobian_at_last(x, omega)?;
    refined_stability(hbm, hill, jacobian, omega, false)
}

/// [`stability_at`] with the sliders' memory refined by the fixed point of dense eigenproblems
/// everywhere: the reference the faster [`stability_at`] is tested against.
pub fn stability_by_eigenproblems(
    hbm: &mut CondensedHbm<'_>,
    hill: &Hill,
    x: &[f64],
    omega: f64,
) -> Result<Stability, BranchStabilityError> {
    let jacobian = hbm.element_force_jacobian(x, omega)?;
    refined_stability(hbm, hill, jacobian, omega, true)
}

/// The exponents from the joints' Jacobian `∂G/∂x` of the solution `hbm` was last evaluated at.
fn refined_stability(
    hbm: &mut CondensedHbm<'_>,
    hill: &Hill,
    jacobian: Mat<f64>,
    omega: f64,
    reference: bool,
) -> Result<Stability, BranchStabilityError> {
    let mut stability = hill.exponents(omega, jacobian.as_ref())?;
    if !hbm.has_memory_delay() {
        return Ok(stability);
    }
    let leading: Vec<usize> =
        (0..stability.exponents.len()).filter(|&i| stability.exponents[i].im >= 0.0).take(REFINED).collect();
    let periodic = stability.exponents.clone();
    for i in leading {
        let start = periodic[i];
        let nearest = (0..periodic.len()).filter(|&j| j != i).map(|j| (periodic[j] - start).norm());
        let nearest = nearest.fold(f64::INFINITY, f64::min);
        let newton = match reference {
            true => None,
            false => hill
                .refine(omega, start, None, true, MEMORY_ITERATIONS, |s| hbm.delayed_force_jacobian(omega, s))?
                .map(|r| r.exponent)
                .filter(|s| (s - start).norm() <= CLOSE_ROOT * nearest.min(omega)),
        };
        let s = match newton {
            Some(s) => s,
            None => fixed_point(hbm, hill, omega, start)?,
        };
        // Its conjugate (the same perturbation, real) follows.
        if let Some(j) = (0..periodic.len())
            .filter(|&j| j != i)
            .min_by(|&a, &b| (periodic[a] - start.conj()).norm().total_cmp(&(periodic[b] - start.conj()).norm()))
            .filter(|&j| start.im > 0.0 && (periodic[j] - start.conj()).norm() <= 1e-9 * omega)
        {
            stability.exponents[j] = s.conj();
        }
        stability.exponents[i] = s;
    }
    stability.exponents.sort_by(|a, b| b.re.total_cmp(&a.re).then(b.im.total_cmp(&a.im)));
    Ok(stability)
}

/// The exponent near `start` with the sliders' memory, by the fixed point
/// `s ← the eigenvalue of Hill(J(s)) nearest s`, one dense complex eigenproblem a step. It
/// converges fast (|s| Δ is a fraction of a radian: a stick phase is shorter than a period).
fn fixed_point(hbm: &CondensedHbm<'_>, hill: &Hill, omega: f64, start: c64) -> Result<c64, BranchStabilityError> {
    let mut s = start;
    let mut previous_change = f64::INFINITY;
    for _ in 0..MEMORY_ITERATIONS {
        let jac = hbm.delayed_force_jacobian(omega, s);
        let all = hill.eigenvalues(omega, jac.as_ref())?;
        let next = all.iter().copied().min_by(|a, b| (a - s).norm().total_cmp(&(b - s).norm())).unwrap_or(s);
        let change = (next - s).norm();
        s = next;
        // Converged, or down to the eigensolver's round-off (~1e-10 of the matrix's
        // scale): the change stops decreasing.
        if change <= 1e-10 * omega || change >= previous_change {
            break;
        }
        previous_change = change;
    }
    Ok(s)
}

/// Exponents refined for the sliders' memory (the leading ones, one per conjugate pair) and the
/// iterations allowed each.
const REFINED: usize = 2;
const MEMORY_ITERATIONS: usize = 50;

/// Newton's root is taken for the exponent only within this fraction of the distance from its
/// start to the nearest other exponent; beyond, the fixed point decides (see [`stability_at`]).
/// The memory moves a leading exponent by a few per cent of its real part (4 % and 7 % on
/// Table 6), so a root further away is likely another root of the nonlinear problem (e^{−sΔ}
/// gives it infinitely many) or the other of two that a coalescing pair offers: on Table 6 at
/// 3000 N near 189 Hz, a complex pair 3.8 1/s from its conjugate, Newton settled 1.4 1/s away on
/// a complex root where the fixed point finds a real one. The strongly damped real exponent of a
/// stuck slider moves much further (Table 6 at 100 N: −358 to −644 1/s by the fixed point), where
/// Newton from the periodic start fails or lands on another root (the leading exponent's, or
/// −2.8e4 1/s): the fixed point's result is kept there too. The test `stability_newton` checks
/// the outcome against the fixed point everywhere.
pub const CLOSE_ROOT: f64 = 0.25;

/// Is the solution with these exponents stable at Ω?
pub fn is_stable(stability: &Stability, omega: f64) -> bool {
    stability.is_stable(EXPONENT_TOLERANCE * omega)
}

/// The folds and branch points of a frequency-sweep branch of `problem` (the condensed balance
/// or another in Ω, [`FrequencySweep`] or DLFT's), from the test functions of its points
/// (`tests[i]` those of `points[i]`, [`crate::continuation::Accepted::test_functions`]), each
/// located along the branch to `tolerance` on the chord between its two points.
pub fn folds_and_branch_points<P: Problem>(
    problem: &mut P,
    points: &[Point],
    tests: &[Option<TestFunctions>],
    tolerance: f64,
) -> Vec<Bifurcation> {
    singular_points(problem, points, tests, tolerance)
        .into_iter()
        .map(|p| Bifurcation {
            kind: match p.kind {
                SingularKind::Fold => BifurcationKind::Fold,
                SingularKind::BranchPoint => BifurcationKind::BranchPoint,
            },
            omega: p.lambda,
            x: p.x,
            exponent: None,
            after_point: p.after_point,
            located: p.located,
        })
        .collect()
}

/// The period doublings and Neimark-Sacker bifurcations between consecutive points of a
/// frequency-sweep branch at `level`: where the stable flag changes and the leading exponent
/// of the unstable point is complex (a real one is a fold or a branch point, found by
/// [`folds_and_branch_points`]), given each point's stability, each located along the branch to
/// `tolerance` on the chord between its two points.
pub fn floquet_bifurcations(
    hbm: &mut CondensedHbm<'_>,
    hill: &Hill,
    level: f64,
    points: &[Point],
    stabilities: &[Stability],
    tolerance: f64,
) -> Vec<Bifurcation> {
    let mut found = Vec::new();
    for i in 0..points.len().saturating_sub(1) {
        let (p0, p1) = (&points[i], &points[i + 1]);
        let (s0, s1) = (is_stable(&stabilities[i], p0.lambda), is_stable(&stabilities[i + 1], p1.lambda));
        if s0 == s1 {
            continue;
        }
        let unstable = if s0 { &stabilities[i + 1] } else { &stabilities[i] };
        let omega = p0.lambda.max(p1.lambda);
        let im = unstable.leading().im.abs();
        if im <= REAL * omega {
            // A real exponent: a fold or a branch point, from the test functions.
            continue;
        }
        let kind = if (im - 0.5 * omega).abs() <= REAL * omega {
            BifurcationKind::PeriodDoubling
        } else {
            BifurcationKind::NeimarkSacker
        };
        let located = zero_along(&mut FrequencySweep { hbm, level }, [p0, p1], tolerance, |problem, x, w| {
            let s = stability_at(problem.hbm, hill, x, w).map_err(|e| ProblemError::new(e.to_string()))?;
            Ok(s.leading().re)
        });
        found.push(match located {
            Ok(z) => {
                let exponent =
                    stability_at(hbm, hill, &z.x, z.lambda).map(|s| s.leading()).unwrap_or(unstable.leading());
                Bifurcation { kind, omega: z.lambda, x: z.x, exponent: Some(exponent), after_point: i, located: true }
            }
            Err(_) => Bifurcation {
                kind,
                omega: p1.lambda,
                x: p1.x.clone(),
                exponent: Some(unstable.leading()),
                after_point: i,
                located: false,
            },
        });
    }
    found
}

/// Imaginary parts within this fraction of Ω of 0 (a real exponent) or of Ω/2 (a multiplier
/// through −1) count as those: the exponents are accurate to ~1e-12 Ω (Hill's eigenproblem),
/// ~1e-9 Ω with the sliders' memory refined.
const REAL: f64 = 1e-6;
