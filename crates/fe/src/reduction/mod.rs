//! Model reduction to a few retained physical DOFs plus modal coordinates (paper Section 3.3):
//! Craig-Bampton (constraint modes Eqs. 3-4 + fixed-interface modes), the paper's variant
//! (exact free modes cleaned on the retained DOFs with the constraint modes, Eq. 5, then
//! orthogonalised) and its enrichment with the modes of the structure with joints released
//! (Zucca & Epureanu), which keeps the slipped-joint dynamics in the basis.
//!
//! Every method returns a [`Reduction`]: the reduced `LinearModel`, the basis `T` with
//! `U = T q` (Eq. 6 in the reduced coordinates) and the retained-DOF map.
mod basis;

use faer::Mat;
use stickslip_core::model::{Damping, DofLabel, LinearModel, Matrix, ModelError, NamedVector};

use crate::eigen::{EigenError, EigenOptions};

pub use basis::{craig_bampton, enriched, free_modes, modes_up_to};

/// Why a reduction cannot be built.
#[derive(Debug, thiserror::Error)]
pub enum ReductionError {
    #[error("no DOF retained: the reduction needs at least one retained DOF")]
    NothingRetained,
    #[error("retained DOF index {index} is out of range (the model has {n} DOFs)")]
    RetainedOutOfRange { index: usize, n: usize },
    #[error("DOF {0:?} is retained twice")]
    RetainedTwice(String),
    #[error("the stiffness with the retained DOFs fixed (K_ee) is singular: the retained DOFs do not stop every rigid-body motion of the structure, so the constraint modes (Eq. 4) do not exist; retain DOFs that ground every part, or add a soft spring")]
    InteriorMechanism(#[source] EigenError),
    #[error("eigensolver: {0}")]
    Eigen(#[from] EigenError),
    #[error("release {name:?}: {message}")]
    Release { name: String, message: String },
    #[error("reduced model: {0}")]
    Model(#[from] ModelError),
}

/// Which basis.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Method {
    /// Constraint modes + fixed-interface modes (Eqs. 3-4).
    CraigBampton,
    /// Constraint modes + free modes cleaned on the retained DOFs (Eq. 5), orthogonalised.
    FreeModes,
    /// [`Method::FreeModes`] enriched with modes of the structure with joints released.
    Enriched,
}

/// A joint whose stiffness is removed to compute the slipped-joint modes: the connector of
/// stiffness `stiffness` (N/m) along the application vector `direction` (e.g. the relative
/// vertical displacement of the two nodes of a blade contact) contributes
/// `stiffness · d dᵀ` to K, which the released structure lacks.
#[derive(Clone, Debug)]
pub struct Release {
    pub name: String,
    pub direction: Vec<f64>,
    pub stiffness: f64,
}

/// What to keep.
#[derive(Clone, Debug)]
pub struct ReductionOptions {
    /// Retained physical DOFs (indices into the full model).
    pub retained: Vec<usize>,
    /// Number of (fixed-interface or free) modes kept.
    pub modes: usize,
    /// Instead of the `modes` lowest, every mode with `lower ≤ ω² ≤ upper` (rad²/s²), however
    /// many: counted by the inertia of `K − σM` at the ends and found by
    /// [`crate::eigen::solve_band`] (`modes` is then not used).
    pub band: Option<(f64, f64)>,
    /// Eigensolver settings (`count` is overridden by `modes`).
    pub eigen: EigenOptions,
}

/// A reduced model and the map back to the full one.
#[derive(Clone, Debug)]
pub struct Reduction {
    /// `M_r = Tᵀ M T`, `K_r = Tᵀ K T`, damping carried over, loads projected. DOFs are the
    /// retained physical DOFs (same labels) then the modal coordinates `mode1`, `mode2`, ...
    pub model: LinearModel,
    /// `T` (full DOFs × reduced DOFs): constraint modes then dynamic vectors.
    pub basis: Mat<f64>,
    /// Retained DOFs, as indices into the full model, in reduced-DOF order.
    pub retained: Vec<usize>,
    pub method: Method,
    /// Frequencies (Hz) of the modes put in the basis (free, fixed-interface or released),
    /// for reporting.
    pub basis_frequencies_hz: Vec<f64>,
    /// Their residuals `‖Kφ − ω²Mφ‖ / ‖Kφ‖`.
    pub basis_residuals: Vec<f64>,
    /// Wall-clock seconds of each stage (factorisation, modes, projection), for reports.
    pub stages: Vec<(&'static str, f64)>,
}

impl Reduction {
    /// Number of reduced DOFs.
    pub fn n_reduced(&self) -> usize {
        self.basis.ncols()
    }

    /// Physical displacements `U = T q` from reduced coordinates `q`.
    pub fn recover(&self, q: &[f64]) -> Vec<f64> {
        assert_eq!(q.len(), self.basis.ncols(), "expected {} reduced coordinates", self.basis.ncols());
        let t = &self.basis;
        (0..t.nrows()).map(|i| q.iter().enumerate().map(|(j, qj)| t[(i, j)] * qj).sum()).collect()
    }

    /// `Tᵀ v`: the reduced form of a force vector or of a joint's application vector (the
    /// relative displacement `u = Vᵀ U = (Tᵀ V)ᵀ q`, Eqs. 7-8).
    pub fn project(&self, v: &[f64]) -> Vec<f64> {
        assert_eq!(v.len(), self.basis.nrows(), "expected a vector over the {} full DOFs", self.basis.nrows());
        let t = &self.basis;
        (0..t.ncols()).map(|j| (0..t.nrows()).map(|i| t[(i, j)] * v[i]).sum()).collect()
    }
}

/// Damping of the reduced model: Rayleigh stays Rayleigh with the same coefficients (Tᵀ(αM +
/// βK)T = αM_r + βK_r), modal ratios apply to the reduced model's modes, a matrix is
/// projected.
fn reduced_damping(damping: &Damping, t: &Mat<f64>) -> Damping {
    match damping {
        Damping::Matrix(d) => Damping::Matrix(Matrix::Dense(basis::project_matrix(d, t))),
        other => other.clone(),
    }
}

/// Assemble the reduced model from the basis.
fn reduced_model(full: &LinearModel, t: &Mat<f64>, retained: &[usize]) -> Result<LinearModel, ReductionError> {
    let m = basis::project_matrix(&full.mass, t);
    let k = basis::project_matrix(&full.stiffness, t);
    let n_modal = t.ncols() - retained.len();
    let mut dofs: Vec<DofLabel> = retained.iter().map(|&i| full.dofs[i].clone()).collect();
    dofs.extend((0..n_modal).map(DofLabel::modal));
    let loads = full
        .loads
        .iter()
        .map(|l| NamedVector {
            name: l.name.clone(),
            values: (0..t.ncols()).map(|j| (0..t.nrows()).map(|i| t[(i, j)] * l.values[i]).sum()).collect(),
        })
        .collect();
    let damping = reduced_damping(&full.damping, t);
    Ok(LinearModel::new(Matrix::Dense(m), Matrix::Dense(k), damping, dofs, loads)?)
}
