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
//!   the crossing exponent's real part, along the branch. The unstable exponents are counted
//!   by kind, so that a crossing is found on a branch already unstable too
//!   ([`floquet_bifurcations`]).
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
use super::stability::{nearer, Hill, Stability, StabilityError};
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
/// complex eigenproblem of size 2m(2N+1) per step, tens of LUs' worth; here in the start's
/// parity block, by inverse subspace iteration) remains where Newton's root lies far from its
/// start ([`continues`]): there the nonlinear problem has several roots, and the fixed point's
/// "nearest eigenvalue" rule picks which; Newton might settle on another.
/// [`stability_by_eigenproblems`] is the fixed point on the whole spectrum everywhere, the
/// reference.
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
    let (mut stability, blocks) = hill.exponents_in_blocks(omega, jacobian.as_ref())?;
    if !hbm.has_memory_delay() {
        return Ok(stability);
    }
    let leading: Vec<usize> =
        (0..stability.exponents.len()).filter(|&i| stability.exponents[i].im >= 0.0).take(REFINED).collect();
    let periodic = stability.exponents.clone();
    for i in leading {
        let start = periodic[i];
        let newton = match reference {
            true => None,
            false => hill
                .refine(omega, start, None, blocks[i], true, MEMORY_ITERATIONS, |s| {
                    hbm.delayed_force_jacobian(omega, s)
                })?
                .map(|r| r.exponent)
                .filter(|&root| continues(start, root, &periodic, omega)),
        };
        let s = match newton {
            Some(s) => s,
            None => fixed_point(hbm, hill, omega, start, blocks[i], !reference)?,
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
/// `s ← the eigenvalue of Hill(J(s)) nearest s`, one complex eigenproblem a step. It
/// converges fast (|s| Δ is a fraction of a radian: a stick phase is shorter than a period).
/// In `start`'s parity block of Hill's matrix where it splits (`block`, from
/// [`Hill::exponents_in_blocks`]): half the size, and no jump to an exponent of the other
/// parity's perturbations. With `locally`, each step's nearest eigenvalue comes from inverse
/// subspace iteration ([`Hill::nearest_eigenvalue`]), the whole spectrum only where that has
/// not converged; the reference takes the whole spectrum at every step.
fn fixed_point(
    hbm: &CondensedHbm<'_>,
    hill: &Hill,
    omega: f64,
    start: c64,
    block: Option<usize>,
    locally: bool,
) -> Result<c64, BranchStabilityError> {
    let mut s = start;
    let mut previous_change = f64::INFINITY;
    for _ in 0..MEMORY_ITERATIONS {
        let jac = hbm.delayed_force_jacobian(omega, s);
        let local = if locally { hill.nearest_eigenvalue(omega, jac.as_ref(), block, s)? } else { None };
        let next = match local {
            Some(next) => next,
            None => {
                let all = hill.eigenvalues_of_block(omega, jac.as_ref(), block)?;
                all.iter().copied().min_by(|&a, &b| nearer(a, b, s)).unwrap_or(s)
            }
        };
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

/// Exponents within this of each other, relative to Ω, are one exponent repeated, not two: a
/// symmetry of the structure repeats them to round-off (Harmony's four blades: pairs 1e-11 Ω
/// apart), where exponents that coalesce along a branch come no closer than the continuation's
/// steps bring them (1e-3 Ω and more).
pub const REPEATED: f64 = 1e-9;

/// Is Newton's `root`, from the periodic exponent `start` (one of `periodic`), the exponent
/// that continues `start` with the sliders' memory? It must lie within [`CLOSE_ROOT`] of the
/// distance from `start` to the nearest other exponent (Ω at most), the copies of a repeated
/// `start` ([`REPEATED`]) not counted: their roots are its own. Counting them sent every
/// leading exponent of Harmony, a pair 1e-11 Ω apart, to the fixed point: a second per point,
/// for the roots Newton had found (the same within 1e-8 1/s).
pub fn continues(start: c64, root: c64, periodic: &[c64], omega: f64) -> bool {
    let distinct = periodic.iter().map(|p| (p - start).norm()).filter(|&d| d > REPEATED * omega);
    let nearest = distinct.fold(f64::INFINITY, f64::min);
    (root - start).norm() <= CLOSE_ROOT * nearest.min(omega)
}

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
/// frequency-sweep branch at `level`, given each point's stability, each located along the
/// branch to `tolerance` on the chord between its two points.
///
/// **Counted by kind, not by the stable flag.** At each point the exponents with a positive
/// real part are counted by kind ([`UnstableCounts`]): real ones, complex pairs (a pair once,
/// [`CrossingKind::ComplexPair`]) and multipliers on the negative real axis
/// ([`CrossingKind::HalfFrequency`]). Where between two points the count of a kind changes, one
/// of its exponents may have crossed the imaginary axis, whatever the others do: a complex pair
/// crossing while a real exponent is already positive (between the folds of a resonance, say)
/// is a Neimark-Sacker bifurcation of a branch that was unstable already, which the stable flag,
/// unstable on both sides, does not show. The count of a kind also changes where an unstable
/// exponent changes kind without crossing (a complex pair meeting on the real axis and splitting
/// into two real exponents there): then the count of another kind changes too. Where only one
/// kind's count changes, the crossing is reported, located or not; where several change in one
/// step (a fold and a crossing close together, or a change of kind), only a located zero of the
/// crossing exponent's real part (to `CROSSED` of Ω) is. Real exponents are left to
/// [`folds_and_branch_points`], which finds their crossings from the test functions (module
/// documentation).
///
/// **Located on the crossing exponent.** With `k` exponents of the kind unstable at the point
/// that has fewer, the one crossing is the `k`-th of that kind by real part (largest first): its
/// real part, continuous along the branch (an order statistic of continuous functions), changes
/// sign between the points, and [`zero_along`] finds its zero. On a stable branch (`k = 0`) it
/// is the kind's leading exponent, as the stable flag's change showed before.
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
        let (s0, s1) = (&stabilities[i], &stabilities[i + 1]);
        let (c0, c1) = (UnstableCounts::of(s0, p0.lambda), UnstableCounts::of(s1, p1.lambda));
        for kind in [CrossingKind::ComplexPair, CrossingKind::HalfFrequency] {
            let (e0, e1) = (kind.exponents(s0, p0.lambda), kind.exponents(s1, p1.lambda));
            let (n0, n1) = (c0.of_kind(kind), c1.of_kind(kind));
            // The k-th of the kind must exist at both points: one that appears or disappears
            // (changes kind) has not crossed the imaginary axis.
            let k = n0.min(n1);
            if n0 == n1 || k >= e0.len() || k >= e1.len() {
                continue;
            }
            let alone = c0.differ_only_in(&c1, kind);
            let unstable_end = if n1 > n0 { e1[k] } else { e0[k] };
            let located = zero_along(&mut FrequencySweep { hbm, level }, [p0, p1], tolerance, |problem, x, w| {
                let s = stability_at(problem.hbm, hill, x, w).map_err(|e| ProblemError::new(e.to_string()))?;
                kind.exponents(&s, w)
                    .get(k)
                    .map(|s| s.re)
                    .ok_or_else(|| ProblemError::new("the crossing exponent changed kind on the bracket"))
            });
            let bifurcation = match located {
                Ok(z) => {
                    let exponent = stability_at(hbm, hill, &z.x, z.lambda)
                        .ok()
                        .and_then(|s| kind.exponents(&s, z.lambda).get(k).copied())
                        .unwrap_or(unstable_end);
                    // With other kinds changing in the same step, only a zero of the exponent
                    // itself: where an exponent changed kind, the k-th of the kind jumps and
                    // the location ends on the jump, its real part far from zero.
                    if !alone && exponent.re.abs() > CROSSED * z.lambda {
                        continue;
                    }
                    Bifurcation {
                        kind: kind.bifurcation(),
                        omega: z.lambda,
                        x: z.x,
                        exponent: Some(exponent),
                        after_point: i,
                        located: true,
                    }
                }
                Err(_) if alone => Bifurcation {
                    kind: kind.bifurcation(),
                    omega: p1.lambda,
                    x: p1.x.clone(),
                    exponent: Some(unstable_end),
                    after_point: i,
                    located: false,
                },
                Err(_) => continue,
            };
            found.push(bifurcation);
        }
    }
    found
}

/// The kinds of Floquet exponent whose crossings [`floquet_bifurcations`] reports, by their
/// imaginary part at fundamental Ω (a multiplier `e^{sT}`, `T = 2π/Ω`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum CrossingKind {
    /// A complex pair `s, s̄` with `0 < |Im s| < Ω/2` (multipliers `e^{±iθ}`-like): a
    /// Neimark-Sacker bifurcation when it crosses.
    ComplexPair,
    /// `|Im s| = Ω/2`, a multiplier on the negative real axis: a period doubling when it
    /// crosses (through −1).
    HalfFrequency,
}

impl CrossingKind {
    /// The bifurcation a crossing of this kind is.
    pub fn bifurcation(&self) -> BifurcationKind {
        match self {
            CrossingKind::ComplexPair => BifurcationKind::NeimarkSacker,
            CrossingKind::HalfFrequency => BifurcationKind::PeriodDoubling,
        }
    }

    /// The exponents of this kind among `stability`'s at Ω, one per multiplier, largest real
    /// part first. A complex pair is represented by its member with `Im s > 0`. A multiplier on
    /// the negative real axis appears in Hill's spectrum as `s + iΩ/2` and `s − iΩ/2` (the same
    /// multiplier), which tie in the sorting of the physical exponents: exponents of this kind
    /// with the same real part (to [`EXPONENT_TOLERANCE`]) count once. (Where two such
    /// multipliers exist and the sorting keeps both representations of one, the other is not
    /// among the physical exponents at all, and not counted.)
    pub fn exponents(&self, stability: &Stability, omega: f64) -> Vec<c64> {
        let mut found: Vec<c64> = Vec::new();
        for &s in &stability.exponents {
            let im = s.im.abs();
            let half = (im - 0.5 * omega).abs() <= REAL * omega;
            match self {
                CrossingKind::ComplexPair if s.im > REAL * omega && !half => found.push(s),
                CrossingKind::HalfFrequency
                    if half && !found.iter().any(|f| (f.re - s.re).abs() <= EXPONENT_TOLERANCE * omega) =>
                {
                    found.push(c64::new(s.re, im))
                }
                _ => {}
            }
        }
        found.sort_by(|a, b| b.re.total_cmp(&a.re));
        found
    }
}

/// The number of exponents with a positive real part (to [`EXPONENT_TOLERANCE`] of Ω), by
/// kind: real ones, complex pairs (a pair once), multipliers on the negative real axis.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct UnstableCounts {
    pub real: usize,
    pub complex_pairs: usize,
    pub half_frequency: usize,
}

impl UnstableCounts {
    /// The counts of `stability`'s exponents at Ω.
    pub fn of(stability: &Stability, omega: f64) -> Self {
        let positive = |s: &c64| s.re > EXPONENT_TOLERANCE * omega;
        let unstable = |kind: CrossingKind| kind.exponents(stability, omega).iter().filter(|s| positive(s)).count();
        UnstableCounts {
            real: stability.exponents.iter().filter(|s| s.im.abs() <= REAL * omega && positive(s)).count(),
            complex_pairs: unstable(CrossingKind::ComplexPair),
            half_frequency: unstable(CrossingKind::HalfFrequency),
        }
    }

    /// The count of one kind.
    pub fn of_kind(&self, kind: CrossingKind) -> usize {
        match kind {
            CrossingKind::ComplexPair => self.complex_pairs,
            CrossingKind::HalfFrequency => self.half_frequency,
        }
    }

    /// Do `self` and `other` differ in `kind`'s count only?
    fn differ_only_in(&self, other: &Self, kind: CrossingKind) -> bool {
        let others_equal = match kind {
            CrossingKind::ComplexPair => self.real == other.real && self.half_frequency == other.half_frequency,
            CrossingKind::HalfFrequency => self.real == other.real && self.complex_pairs == other.complex_pairs,
        };
        others_equal && self.of_kind(kind) != other.of_kind(kind)
    }
}

/// A located crossing whose exponent's real part is within this fraction of Ω of zero is one.
/// The exponent is located to ~1e-10 of a step along the branch, where it moves by a fraction
/// of Ω per unit of Ω: its real part there is ~1e-13 Ω (measured below 2e-13 on the pair of
/// oscillators of `tests/stability_neimark_sacker.rs`), where an exponent that changed kind
/// jumps by a damping rate, ~1e-3 Ω and more.
const CROSSED: f64 = 1e-6;

/// Imaginary parts within this fraction of Ω of 0 (a real exponent) or of Ω/2 (a multiplier
/// through −1) count as those: the exponents are accurate to ~1e-12 Ω (Hill's eigenproblem),
/// ~1e-9 Ω with the sliders' memory refined.
const REAL: f64 = 1e-6;

#[cfg(test)]
mod tests {
    use super::*;

    /// Newton's root continues its start within a quarter of the distance to the nearest other
    /// exponent; a copy of the start 1e-11 Ω away (a repeated exponent) does not count, another
    /// exponent 4 1/s away does.
    #[test]
    fn a_repeated_exponent_does_not_shrink_the_trust_radius() {
        let omega = 1500.0;
        let start = c64::new(-7.5, 514.42);
        let copy = start + c64::new(0.0, 1e-11 * omega);
        let other = start + c64::new(0.0, 4.0);
        let periodic = [start, copy, other, start.conj(), copy.conj()];
        assert!(continues(start, start + c64::new(-0.9, 0.3), &periodic, omega));
        assert!(!continues(start, start + c64::new(-1.0, 0.3), &periodic, omega));
        // Without the other exponent, the radius is a quarter of the distance to the conjugates.
        let alone = [start, copy, start.conj(), copy.conj()];
        assert!(continues(start, start + c64::new(-3.0, 0.0), &alone, omega));
        // Copies further apart than `REPEATED` are two exponents.
        let apart = [start, start + c64::new(0.0, 1e-6 * omega)];
        assert!(!continues(start, start + c64::new(-1e-3, 0.0), &apart, omega));
    }
}
