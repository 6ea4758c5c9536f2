use super::{Damping, DofLabel, Matrix};

/// A named vector over the model's DOFs: an excitation pattern, an application vector, an
/// output selector.
#[derive(Clone, Debug)]
pub struct NamedVector {
    pub name: String,
    pub values: Vec<f64>,
}

/// What is wrong with a linear model, said so that the user knows what to fix.
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum ModelError {
    #[error("{what} is {rows}x{cols}, expected {expected}x{expected} (the model has {expected} DOFs)")]
    WrongSize { what: String, rows: usize, cols: usize, expected: usize },
    #[error("{what} has length {len}, expected {expected} (one value per DOF)")]
    WrongLength { what: String, len: usize, expected: usize },
    #[error("{what} is not symmetric (largest |A_ij - A_ji| is {asymmetry:.3e} of its largest entry); stickslip needs symmetric M, K and D")]
    NotSymmetric { what: String, asymmetry: f64 },
    #[error("{what} contains a value that is not finite (NaN or infinity)")]
    NotFinite { what: String },
    #[error("the mass matrix is not positive definite (Cholesky failed): every DOF needs mass; give massless DOFs a small mass or condense them out")]
    MassNotPositiveDefinite,
    #[error("the stiffness matrix is singular or indefinite (lowest eigenvalue {lowest:.3e}): the structure has a rigid-body motion; ground it, e.g. with a soft spring like the paper's shaker spring")]
    StiffnessNotPositiveDefinite { lowest: f64 },
    #[error("DOF {0:?} appears twice in the DOF list")]
    DuplicateDof(String),
    #[error("no DOF named {name:?} in the model (DOFs are: {known})")]
    UnknownDof { name: String, known: String },
    #[error("no vector named {name:?} in the model (known: {known})")]
    UnknownVector { name: String, known: String },
    #[error("{0}")]
    Invalid(String),
}

/// `M Ü + D U̇ + K U = F` with named DOFs and named force vectors (paper Eq. 6).
///
/// One type whether the model came from a mesh, an import or a reduction. Matrices are
/// symmetric; units are SI (kg, N/m, N·s/m, N).
#[derive(Clone, Debug)]
pub struct LinearModel {
    pub mass: Matrix,
    pub stiffness: Matrix,
    pub damping: Damping,
    pub dofs: Vec<DofLabel>,
    /// Force patterns (e.g. the shaker force direction), in N per unit load.
    pub loads: Vec<NamedVector>,
}

/// Relative asymmetry accepted in M, K, D: matrices written with 16 significant digits and
/// reductions in double precision are symmetric to ~1e-12; 1e-8 lets round-off through and
/// stops a transposed or mistyped entry.
const SYMMETRY_TOLERANCE: f64 = 1e-8;

impl LinearModel {
    /// Build and check a model: sizes, finiteness and symmetry of M, K, D, DOF names unique,
    /// load lengths.
    pub fn new(
        mass: Matrix,
        stiffness: Matrix,
        damping: Damping,
        dofs: Vec<DofLabel>,
        loads: Vec<NamedVector>,
    ) -> Result<Self, ModelError> {
        let model = LinearModel { mass, stiffness, damping, dofs, loads };
        model.check()?;
        Ok(model)
    }

    /// Number of DOFs.
    pub fn n_dofs(&self) -> usize {
        self.dofs.len()
    }

    /// Check sizes, finiteness and symmetry (see [`LinearModel::new`]).
    pub fn check(&self) -> Result<(), ModelError> {
        let n = self.dofs.len();
        let mut seen = std::collections::HashSet::new();
        for d in &self.dofs {
            if !seen.insert(&d.name) {
                return Err(ModelError::DuplicateDof(d.name.clone()));
            }
        }
        let mut mats: Vec<(&str, &Matrix)> = vec![("M (mass)", &self.mass), ("K (stiffness)", &self.stiffness)];
        if let Damping::Matrix(d) = &self.damping {
            mats.push(("D (damping)", d));
        }
        for (what, m) in mats {
            if m.nrows() != n || m.ncols() != n {
                return Err(ModelError::WrongSize { what: what.into(), rows: m.nrows(), cols: m.ncols(), expected: n });
            }
            if !m.is_finite() {
                return Err(ModelError::NotFinite { what: what.into() });
            }
            let asym = m.asymmetry();
            if asym > SYMMETRY_TOLERANCE {
                return Err(ModelError::NotSymmetric { what: what.into(), asymmetry: asym });
            }
        }
        match &self.damping {
            Damping::Rayleigh { alpha, beta }
                if !(alpha.is_finite() && beta.is_finite() && *alpha >= 0.0 && *beta >= 0.0) =>
            {
                return Err(ModelError::Invalid(format!(
                    "Rayleigh damping needs finite alpha >= 0 and beta >= 0, got alpha = {alpha}, beta = {beta}"
                )));
            }
            Damping::Modal { ratios } if ratios.is_empty() || ratios.iter().any(|z| !z.is_finite() || *z < 0.0) => {
                return Err(ModelError::Invalid(format!(
                    "modal damping needs at least one ratio, each finite and >= 0, got {ratios:?}"
                )));
            }
            _ => {}
        }
        for l in &self.loads {
            if l.values.len() != n {
                return Err(ModelError::WrongLength {
                    what: format!("load {:?}", l.name),
                    len: l.values.len(),
                    expected: n,
                });
            }
            if l.values.iter().any(|v| !v.is_finite()) {
                return Err(ModelError::NotFinite { what: format!("load {:?}", l.name) });
            }
        }
        Ok(())
    }

    /// Index of the DOF named `name`.
    pub fn dof_index(&self, name: &str) -> Result<usize, ModelError> {
        self.dofs.iter().position(|d| d.name == name).ok_or_else(|| ModelError::UnknownDof {
            name: name.into(),
            known: abbreviated_list(self.dofs.iter().map(|d| d.name.as_str())),
        })
    }

    /// The load named `name`.
    pub fn load(&self, name: &str) -> Result<&NamedVector, ModelError> {
        self.loads.iter().find(|l| l.name == name).ok_or_else(|| ModelError::UnknownVector {
            name: name.into(),
            known: abbreviated_list(self.loads.iter().map(|l| l.name.as_str())),
        })
    }

    /// Unit vector on the DOF named `name`.
    pub fn unit_vector(&self, name: &str) -> Result<Vec<f64>, ModelError> {
        let i = self.dof_index(name)?;
        let mut v = vec![0.0; self.n_dofs()];
        v[i] = 1.0;
        Ok(v)
    }

    /// Dense damping matrix (for time integration or general-damping harmonic solves); for
    /// modal damping it is `M Φ diag(2 ζ_r ω_r) Φᵀ M` and needs the modes.
    pub fn damping_dense(&self, modes: Option<&crate::model::Modes>) -> faer::Mat<f64> {
        let n = self.n_dofs();
        match &self.damping {
            Damping::None => faer::Mat::zeros(n, n),
            Damping::Matrix(d) => d.to_dense(),
            Damping::Rayleigh { alpha, beta } => {
                let m = self.mass.to_dense();
                let k = self.stiffness.to_dense();
                faer::Mat::from_fn(n, n, |i, j| alpha * m[(i, j)] + beta * k[(i, j)])
            }
            Damping::Modal { .. } => {
                let modes = modes.expect("modal damping needs the modes to build D");
                let m = self.mass.to_dense();
                let mphi = &m * &modes.shapes;
                let mut scaled = mphi.clone();
                for r in 0..modes.omega.len() {
                    let c = self.damping.modal_coefficient(r, modes.omega[r]).unwrap_or(0.0);
                    for i in 0..n {
                        scaled[(i, r)] *= c;
                    }
                }
                &scaled * mphi.transpose()
            }
        }
    }
}

fn abbreviated_list<'a>(names: impl Iterator<Item = &'a str>) -> String {
    let all: Vec<&str> = names.collect();
    if all.len() <= 12 {
        all.join(", ")
    } else {
        format!("{}, ... ({} in all)", all[..12].join(", "), all.len())
    }
}
