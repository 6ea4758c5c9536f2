//! Every mode of `(K, M)` in a band of eigenvalues `[λ₁, λ₂]` (λ = ω²), with no count given:
//! the number of eigenvalues in the band is known exactly before iterating, from the inertia
//! of `K − σM` at both ends (Sylvester's law of inertia: the number of negative pivots of the
//! LDLᵀ factor of `K − σM` is the number of eigenvalues below σ), and the shift-invert Lanczos
//! iteration (Ericsson & Ruhe, Math. Comp. 35, 1980) is asked for exactly those, then checked
//! against that count: an eigenvalue missed by the iteration (a copy of a repeated one, say) is
//! found again with a larger block, or reported, never silently dropped.
//!
//! The shift sits at the band's middle, where the eigenvalues nearest it are exactly those of
//! the band (all others lie farther than its half-width); at its lower end when nothing lies
//! below (the lowest modes, free-free included: the end is then below the rigid-body modes).
//! Wide bands are split where the count exceeds [`MODES_PER_SHIFT`]: the inertia at the split
//! point counts each half, and each half is solved at its own shift.
use faer::sparse::SparseColMat;
use faer::Mat;
use stickslip_core::model::Modes;

use super::{default_shift, lanczos, EigenError, EigenOptions, EigenSolution, ShiftedFactor};

/// Most modes computed at one shift; wider bands are split. The Lanczos basis holds three times
/// the modes wanted (memory `3 count n`) and its orthogonalisation grows as their square, while
/// a new shift costs one numeric factorisation; 300 is the largest count measured at one shift
/// (BENCHMARKS.md, "Many modes").
pub const MODES_PER_SHIFT: usize = 300;

/// Relative widening of the band's ends before their inertia is taken, so that an eigenvalue
/// at an end (to round-off) is inside; the next widenings are tried when the end falls on an
/// eigenvalue to working precision (a singular `K − σM`).
const END_WIDENING: [f64; 3] = [1e-9, 1e-7, 1e-5];

/// Every mode with `lower ≤ ω² ≤ upper` (rad²/s², `0 ≤ lower ≤ upper`, finite), in increasing
/// order, each with its residual checked as by [`super::solve`]; `opts.count` and
/// `opts.shift` are not used. A band holding no eigenvalue gives an empty solution. A lower end
/// at 0 includes the rigid-body modes of a free-free structure.
pub fn solve_band(
    k: &SparseColMat<usize, f64>,
    m: &SparseColMat<usize, f64>,
    lower: f64,
    upper: f64,
    opts: &EigenOptions,
) -> Result<EigenSolution, EigenError> {
    solve_band_split(k, m, lower, upper, opts, MODES_PER_SHIFT)
}

/// [`solve_band`] with the number of modes per shift given (tests split small bands).
#[doc(hidden)]
pub fn solve_band_split(
    k: &SparseColMat<usize, f64>,
    m: &SparseColMat<usize, f64>,
    lower: f64,
    upper: f64,
    opts: &EigenOptions,
    per_shift: usize,
) -> Result<EigenSolution, EigenError> {
    let n = k.nrows();
    let (mut factor, lo, hi) = band_ends(k, m, lower, upper)?;
    let mut parts = Parts { omega: Vec::new(), shapes: Vec::new(), residuals: Vec::new(), solves: 0, restarts: 0 };
    let mut first_shift = None;
    solve_part(k, m, &mut factor, lo, hi, opts, per_shift.max(1), &mut parts, &mut first_shift)?;
    let p = parts.omega.len();
    let mut shapes = Mat::<f64>::zeros(n, p);
    for (c, col) in parts.shapes.iter().enumerate() {
        shapes.col_mut(c).iter_mut().zip(col).for_each(|(x, v)| *x = *v);
    }
    Ok(EigenSolution {
        modes: Modes { omega: parts.omega, shapes },
        residuals: parts.residuals,
        shift: first_shift.unwrap_or(lo.0),
        below_shift: lo.1,
        solves: parts.solves,
        restarts: parts.restarts,
    })
}

/// The number of eigenvalues `ω²` of `(K, M)` in `[lower, upper]` (rad²/s², as for
/// [`solve_band`]), from the inertia of `K − σM` at both ends alone: no mode is computed.
pub fn count_in_band(
    k: &SparseColMat<usize, f64>,
    m: &SparseColMat<usize, f64>,
    lower: f64,
    upper: f64,
) -> Result<usize, EigenError> {
    let (_, lo, hi) = band_ends(k, m, lower, upper)?;
    Ok(hi.1.saturating_sub(lo.1))
}

/// The band checked, and the inertia at its widened ends: the factor left is the lower end's.
#[allow(clippy::type_complexity)]
fn band_ends(
    k: &SparseColMat<usize, f64>,
    m: &SparseColMat<usize, f64>,
    lower: f64,
    upper: f64,
) -> Result<(ShiftedFactor, (f64, usize), (f64, usize)), EigenError> {
    lanczos::check_sizes(&super::product::Stiffness::Sparse(k), m)?;
    if !(lower.is_finite() && upper.is_finite()) {
        return Err(EigenError::Band(format!("the ends must be finite, got [{lower}, {upper}] rad^2/s^2")));
    }
    if lower < 0.0 {
        return Err(EigenError::Band(format!("the lower end must be >= 0, got {lower} rad^2/s^2")));
    }
    if upper < lower {
        return Err(EigenError::Band(format!(
            "the lower end must not exceed the upper one, got [{lower}, {upper}] rad^2/s^2"
        )));
    }
    super::check_mass(m, None)?;
    // Upper end first, then the lower one, so that the factor left is the lower end's: the shift
    // of a band with nothing below it. One factor is held at a time (symbolic analysis shared).
    let (mut factor, hi) = factor_at_end(k, m, upper, 1.0)?;
    let lo = if lower == 0.0 {
        // Below every eigenvalue of a positive semidefinite pair, rigid-body modes included.
        let s = default_shift(k, m).min(0.0);
        refactor_nudged(&mut factor, k, m, &[s, 2.0 * s, 4.0 * s])?
    } else {
        refactor_nudged(&mut factor, k, m, &END_WIDENING.map(|w| lower * (1.0 - w)))?
    };
    Ok((factor, lo, hi))
}

struct Parts {
    omega: Vec<f64>,
    shapes: Vec<Vec<f64>>,
    residuals: Vec<f64>,
    solves: usize,
    restarts: usize,
}

/// A factor at `end` widened outwards (`direction` +1: up, −1: down), and the shift used with
/// the number of eigenvalues below it.
fn factor_at_end(
    k: &SparseColMat<usize, f64>,
    m: &SparseColMat<usize, f64>,
    end: f64,
    direction: f64,
) -> Result<(ShiftedFactor, (f64, usize)), EigenError> {
    let mut last = None;
    for w in END_WIDENING {
        // An upper end at 0 (a band [0, 0]) is widened against the default shift's scale.
        let sigma = if end == 0.0 { -direction * default_shift(k, m) * w * 1e3 } else { end * (1.0 + direction * w) };
        match ShiftedFactor::new(k.as_ref(), Some(m.as_ref()), sigma) {
            Ok(f) => {
                let below = f.eigenvalues_below_shift();
                return Ok((f, (sigma, below)));
            }
            Err(e @ EigenError::Singular { .. }) => last = Some(e),
            Err(e) => return Err(e),
        }
    }
    Err(last.expect("at least one shift was tried"))
}

/// Refactor at the first of `shifts` where `K − σM` is not singular.
fn refactor_nudged(
    factor: &mut ShiftedFactor,
    k: &SparseColMat<usize, f64>,
    m: &SparseColMat<usize, f64>,
    shifts: &[f64],
) -> Result<(f64, usize), EigenError> {
    let mut last = None;
    for &sigma in shifts {
        match factor.refactor(k.as_ref(), Some(m.as_ref()), sigma) {
            Ok(()) => return Ok((sigma, factor.eigenvalues_below_shift())),
            Err(e @ EigenError::Singular { .. }) => last = Some(e),
            Err(e) => return Err(e),
        }
    }
    Err(last.expect("at least one shift was tried"))
}

/// The modes between the shifts `lo` and `hi` (each with its count of eigenvalues below),
/// appended to `parts` in increasing order.
#[allow(clippy::too_many_arguments)]
fn solve_part(
    k: &SparseColMat<usize, f64>,
    m: &SparseColMat<usize, f64>,
    factor: &mut ShiftedFactor,
    lo: (f64, usize),
    hi: (f64, usize),
    opts: &EigenOptions,
    per_shift: usize,
    parts: &mut Parts,
    first_shift: &mut Option<f64>,
) -> Result<(), EigenError> {
    let count = hi.1.saturating_sub(lo.1);
    if count == 0 {
        return Ok(());
    }
    let middle = 0.5 * (lo.0 + hi.0);
    // Shifts near the middle, should it fall on an eigenvalue.
    let width = hi.0 - lo.0;
    let near_middle = [middle, middle + 1e-6 * width, middle - 1e-4 * width];
    if count > per_shift && width > 0.0 {
        let mid = refactor_nudged(factor, k, m, &near_middle)?;
        solve_part(k, m, factor, lo, mid, opts, per_shift, parts, first_shift)?;
        return solve_part(k, m, factor, mid, hi, opts, per_shift, parts, first_shift);
    }
    // Nothing below the lower end: the `count` eigenvalues nearest it are the band's. Otherwise
    // the middle: the band's eigenvalues are the `count` nearest it.
    let shift = if lo.1 == 0 {
        if factor.shift() != lo.0 {
            factor.refactor(k.as_ref(), Some(m.as_ref()), lo.0)?;
        }
        lo.0
    } else {
        refactor_nudged(factor, k, m, &near_middle)?.0
    };
    first_shift.get_or_insert(shift);
    let n = k.nrows();
    // The iteration converges to the `count` eigenvalues nearest the shift; should it miss a
    // copy of a repeated eigenvalue it returns one outside the band instead. Then it runs again
    // with room for more modes and a larger block (more start vectors per eigenspace).
    let mut found = 0;
    for attempt in 0..3 {
        let extra = [0, count.div_ceil(2).max(6), count.max(12)][attempt];
        let wanted = (count + extra).min(n);
        let block = wanted.div_ceil(3).clamp(1, 16) << attempt;
        let sol = lanczos::modes_with_factor(
            &super::product::Stiffness::Sparse(k),
            m,
            &*factor,
            &EigenOptions { count: wanted, shift: Some(shift), block: Some(block.min(n)), ..opts.clone() },
        )?;
        super::check_mass(m, Some(&sol))?;
        parts.solves += sol.solves;
        parts.restarts += sol.restarts;
        // In the band: ω² between the two ends. The ends are shifts where K − σM is regular, so
        // no eigenvalue is within round-off of them; the Rayleigh quotient is accurate to the
        // square of the residual.
        let inside: Vec<usize> = (0..sol.modes.omega.len())
            .filter(|&c| {
                let l = sol.modes.omega[c].powi(2);
                l >= lo.0 && l <= hi.0
            })
            .collect();
        found = inside.len();
        if found == count {
            for c in inside {
                parts.omega.push(sol.modes.omega[c]);
                parts.residuals.push(sol.residuals[c]);
                parts.shapes.push(sol.modes.shapes.col(c).iter().copied().collect());
            }
            return Ok(());
        }
        if wanted == n {
            break;
        }
    }
    let hz = |l: f64| l.max(0.0).sqrt() / (2.0 * std::f64::consts::PI);
    Err(EigenError::BandIncomplete { lower_hz: hz(lo.0), upper_hz: hz(hi.0), expected: count, found })
}
