//! The lowest modes of large sparse `(K, M)` (paper Section 3.3: the 34 modes of the reduced
//! model): block shift-invert Lanczos in the M inner product with full reorthogonalisation and
//! thick restart (single-vector thick restart as a fallback), on a sparse LDLᵀ of `K − σM`
//! ([`ShiftedFactor`], ordered by METIS's nested dissection) or on a low-rank update of one
//! ([`LowRankUpdate`]: the structure with its joints released, without a second factorisation).
//!
//! The shift σ lies below the lowest eigenvalue by default (a small negative value), so
//! free-free structures, whose rigid-body modes sit at ω = 0, are solved as they are. Every
//! returned mode's residual `‖Kφ − ω²Mφ‖ / ‖Kφ‖` is computed and returned.
mod band;
mod factor;
mod lanczos;
pub mod ordering;
mod product;
mod update;

pub use band::{count_in_band, solve_band, solve_band_split, MODES_PER_SHIFT};
pub use factor::{ShiftInvert, ShiftedFactor};
use product::Stiffness;
pub use product::{symmetric_product, symmetric_times};
pub use update::LowRankUpdate;

use faer::sparse::{SparseColMat, Triplet};
use stickslip_core::model::{Matrix, Modes};

/// What stops the eigensolver.
#[derive(Debug, thiserror::Error)]
pub enum EigenError {
    #[error("K - sigma M is singular at sigma = {shift:.6e} rad^2/s^2{}: the structure has a mechanism (a rigid-body motion at sigma = 0) or the shift sits on an eigenvalue; use a negative or different shift, or ground the mechanism", dof_text(.dof))]
    Singular { shift: f64, dof: Option<usize> },
    #[error("sparse factorisation failed: {0}")]
    Factorisation(String),
    #[error("{requested} modes requested, the model has {available} DOFs")]
    TooManyModes { requested: usize, available: usize },
    #[error("K and M must be square and of the same size, got K {k_rows}x{k_cols} and M {m_rows}x{m_cols}")]
    Size { k_rows: usize, k_cols: usize, m_rows: usize, m_cols: usize },
    #[error("Lanczos did not converge in {restarts} restarts: {converged} of {requested} modes reached the tolerance (largest relative Ritz residual {worst:.2e}); ask for fewer modes or a shift nearer the wanted ones")]
    NotConverged { restarts: usize, converged: usize, requested: usize, worst: f64 },
    #[error("the mass matrix is indefinite: {what}; M must be positive (semi)definite (check the sign and the assembly of the mass matrix)")]
    MassIndefinite { what: String },
    #[error("mode {mode} has residual ||K phi - w^2 M phi|| / ||K phi|| = {residual:.2e} above {tolerance:.1e}: the factorisation is inaccurate (check the matrices for near-singular blocks)")]
    Inaccurate { mode: usize, residual: f64, tolerance: f64 },
    #[error("band: {0}")]
    Band(String),
    #[error("band [{lower_hz} Hz, {upper_hz} Hz]: the inertia of K - sigma M at its ends counts {expected} eigenvalues in it and the Lanczos iteration found {found} of them (repeated eigenvalues beyond the block size?); split the band")]
    BandIncomplete { lower_hz: f64, upper_hz: f64, expected: usize, found: usize },
    #[error("the sparse factor of K - sigma M would take {needed_gb:.1} GB ({entries} entries, estimated by the symbolic analysis before factorising) and this machine has {available_gb:.1} GB available: use a coarser mesh or a machine with more memory")]
    FactorTooLarge { entries: usize, needed_gb: f64, available_gb: f64 },
}

fn dof_text(dof: &Option<usize>) -> String {
    dof.map(|d| format!(" (zero pivot at DOF index {d})")).unwrap_or_default()
}

/// How many modes, where, and how accurately.
#[derive(Clone, Debug)]
pub struct EigenOptions {
    /// Number of modes wanted.
    pub count: usize,
    /// Shift σ in rad²/s²: the modes nearest σ are found. `None` picks a small negative shift
    /// below the lowest eigenvalue, so the `count` lowest modes are found.
    pub shift: Option<f64>,
    /// Convergence test on the Ritz residual of the shift-invert operator, relative to its
    /// Ritz value. The eigenvalue error is of the order of its square.
    pub tolerance: f64,
    /// Lanczos restarts before giving up.
    pub max_restarts: usize,
    /// Krylov subspace dimension (`None`: `max(2 count + 20, count + 30)` capped at the size).
    pub subspace: Option<usize>,
    /// Largest accepted final residual `‖Kφ − ω²Mφ‖ / ‖Kφ‖`.
    pub residual_limit: f64,
    /// Vectors per block of the block Lanczos (`None`: `count / 3` within 1..=16). A block
    /// needs as many vectors as the largest multiplicity of the wanted eigenvalues to find
    /// every copy of a repeated one (in exact arithmetic a Krylov space of `b` start vectors
    /// holds at most `b` directions of an eigenspace).
    pub block: Option<usize>,
}

impl Default for EigenOptions {
    fn default() -> Self {
        EigenOptions {
            count: 10,
            shift: None,
            tolerance: 1e-10,
            max_restarts: 200,
            subspace: None,
            residual_limit: 1e-6,
            block: None,
        }
    }
}

/// Modes found by the sparse solver, with the evidence of their accuracy.
#[derive(Clone, Debug)]
pub struct EigenSolution {
    /// Mass-normalised modes in increasing frequency order.
    pub modes: Modes,
    /// `‖Kφ − ω²Mφ‖ / ‖Kφ‖` of each mode (for rigid-body modes, whose `Kφ` vanishes, the
    /// denominator is `|σ| ‖Mφ‖` instead).
    pub residuals: Vec<f64>,
    /// The shift used, rad²/s² (for a band, that of its lowest part).
    pub shift: f64,
    /// Number of eigenvalues below the shift (inertia of `K − σM`); for a band
    /// ([`solve_band`]), below its lower end.
    pub below_shift: usize,
    /// Linear solves with the factor and Lanczos restarts used.
    pub solves: usize,
    pub restarts: usize,
}

/// The `opts.count` modes of `(K, M)` nearest the shift (the lowest ones by default); see
/// `check_mass` for what is refused on top of the solver's own checks.
pub fn solve(
    k: &SparseColMat<usize, f64>,
    m: &SparseColMat<usize, f64>,
    opts: &EigenOptions,
) -> Result<EigenSolution, EigenError> {
    lanczos::check_sizes(&Stiffness::Sparse(k), m)?;
    let shift = opts.shift.unwrap_or_else(|| default_shift(k, m));
    check_mass(m, None)?;
    let factor = ShiftedFactor::new(k.as_ref(), Some(m.as_ref()), shift)?;
    modes_with_factor(k, m, &factor, opts)
}

/// As [`solve`], with an existing factorisation of `K − σM` or an update of one (its shift is
/// used).
pub fn modes_with_factor(
    k: &SparseColMat<usize, f64>,
    m: &SparseColMat<usize, f64>,
    factor: &dyn ShiftInvert,
    opts: &EigenOptions,
) -> Result<EigenSolution, EigenError> {
    check_mass(m, None)?;
    let solution = lanczos::modes_with_factor(&Stiffness::Sparse(k), m, factor, opts)?;
    check_mass(m, Some(&solution))?;
    Ok(solution)
}

/// The modes of `(K − Σ_j k_j d_j d_jᵀ, M)` (the structure with joints released) nearest the
/// shift of `update`, the factor of `K − σM` updated for the released joints: neither the
/// released stiffness nor its factor is formed (the products with it are those of K less the
/// rank-one terms).
pub fn modes_of_update(
    k: &SparseColMat<usize, f64>,
    m: &SparseColMat<usize, f64>,
    update: &LowRankUpdate<'_>,
    opts: &EigenOptions,
) -> Result<EigenSolution, EigenError> {
    check_mass(m, None)?;
    let (u, c) = update.terms();
    let solution = lanczos::modes_with_factor(&Stiffness::LessRankOnes { k, u, c }, m, update, opts)?;
    check_mass(m, Some(&solution))?;
    Ok(solution)
}

/// An indefinite M is refused: before solving, a negative diagonal entry (`eᵢᵀ M eᵢ < 0`);
/// after, a mode whose mass `φᵀMφ` is not positive, or whose frequency, shape or residual is
/// not finite (mass-normalising a direction of negative mass divides by the square root of a
/// negative number: the solver's NaN residual passed its `>` test and the mode came out as
/// f = 0). The Lanczos iteration itself assumes the M inner product.
pub(crate) fn check_mass(m: &SparseColMat<usize, f64>, solution: Option<&EigenSolution>) -> Result<(), EigenError> {
    let Some(sol) = solution else {
        if m.nrows() == m.ncols() {
            if let Some((i, d)) = diagonal(m).into_iter().enumerate().find(|(_, d)| d.is_nan() || *d < 0.0) {
                return Err(EigenError::MassIndefinite { what: format!("diagonal entry {} is {d:e}", i + 1) });
            }
        }
        return Ok(());
    };
    let shapes = &sol.modes.shapes;
    let mx = symmetric_times(m.as_ref(), shapes.as_ref());
    for c in 0..shapes.ncols() {
        let mass: f64 = (0..shapes.nrows()).map(|i| shapes[(i, c)] * mx[(i, c)]).sum();
        let (omega, residual) = (sol.modes.omega[c], sol.residuals[c]);
        if !(mass > 0.0 && mass.is_finite() && omega.is_finite() && residual.is_finite()) {
            return Err(EigenError::MassIndefinite {
                what: format!(
                    "mode {} has modal mass phi^T M phi = {mass:e} (frequency {omega:e} rad/s, residual {residual:e})",
                    c + 1
                ),
            });
        }
    }
    Ok(())
}

/// A model matrix as sparse: a sparse one is borrowed (a copy of K and M of a 300k-DOF model
/// is 1.3 GB), a dense one keeps its non-zeros.
pub fn to_sparse(m: &Matrix) -> std::borrow::Cow<'_, SparseColMat<usize, f64>> {
    match m {
        Matrix::Sparse(s) => std::borrow::Cow::Borrowed(s),
        Matrix::Dense(d) => {
            let mut t = Vec::new();
            for j in 0..d.ncols() {
                for i in 0..d.nrows() {
                    if d[(i, j)] != 0.0 {
                        t.push(Triplet::new(i, j, d[(i, j)]));
                    }
                }
            }
            std::borrow::Cow::Owned(
                SparseColMat::try_new_from_triplets(d.nrows(), d.ncols(), &t).expect("indices are in range"),
            )
        }
    }
}

/// Default shift: far enough below zero that `K − σM` is positive definite for a free-free
/// structure, near enough that the lowest modes dominate the shift-invert spectrum. The
/// median of `K_ii / M_ii` is of the order of the highest eigenvalues of the mesh; 1e-8 of it
/// is well below the frequencies of interest of any sensible mesh (~1e-4 of the highest
/// frequency) and keeps the condition number of `K − σM` near 1e8.
pub fn default_shift(k: &SparseColMat<usize, f64>, m: &SparseColMat<usize, f64>) -> f64 {
    let (kd, md) = (diagonal(k), diagonal(m));
    let mut ratios: Vec<f64> = kd.iter().zip(&md).filter(|(k, m)| **k > 0.0 && **m > 0.0).map(|(k, m)| k / m).collect();
    if ratios.is_empty() {
        return -1.0;
    }
    ratios.sort_by(f64::total_cmp);
    -1e-8 * ratios[ratios.len() / 2]
}

/// Diagonal of a sparse matrix (zero where not stored).
pub fn diagonal(a: &SparseColMat<usize, f64>) -> Vec<f64> {
    let a = a.as_ref();
    (0..a.ncols())
        .map(|j| {
            let rows = a.symbolic().row_idx_of_col_raw(j);
            rows.iter().position(|&i| i == j).map(|p| a.val_of_col(j)[p]).unwrap_or(0.0)
        })
        .collect()
}
