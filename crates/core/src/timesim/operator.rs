//! The linear operators of a step: `D x` and the solve with the effective matrix
//! `S = M/(βh²) + (1+α)(γ/(βh) D + K)`, dense, sparse or diagonal (a model in modal
//! coordinates, [`crate::model::NonlinearModel::modal_form`], whose step then costs O(n q)).

use std::collections::HashMap;

use faer::dyn_stack::{MemBuffer, MemStack};
use faer::linalg::cholesky::llt::factor::LltRegularization;
use faer::linalg::solvers::DenseSolveCore;
use faer::sparse::linalg::cholesky::{factorize_symbolic_cholesky, LltRef, SymbolicCholesky, SymmetricOrdering};
use faer::sparse::{SparseColMat, Triplet};
use faer::{Conj, Mat, MatMut, Par, Side};

use super::TimesimError;
use crate::model::{Damping, LinearModel, Matrix};

/// Models with more DOFs than this and sparse M, K (and D) are solved with a sparse Cholesky
/// factor; smaller ones with a dense explicit inverse, whose application is one contiguous
/// matrix-vector product (faster than two triangular solves at these sizes, and allocation-free).
const SPARSE_ABOVE: usize = 400;

/// A matrix of the linear part as the step applies it: dense column-major (contiguous
/// columns, so that `y = A x` is a sequence of axpys), or the model's sparse matrix.
#[derive(Debug)]
pub(crate) enum Operator {
    Dense { n: usize, values: Vec<f64> },
    Sparse(Matrix),
    Diagonal(Vec<f64>),
}

impl Operator {
    pub(crate) fn new(m: &Matrix) -> Self {
        if let Some(d) = m.diagonal_entries() {
            return Operator::Diagonal(d);
        }
        match m {
            Matrix::Dense(d) => Operator::from_dense(d),
            Matrix::Sparse(_) => Operator::Sparse(m.clone()),
        }
    }

    pub(crate) fn from_dense(d: &Mat<f64>) -> Self {
        if let Some(diagonal) = dense_diagonal(d) {
            return Operator::Diagonal(diagonal);
        }
        let n = d.nrows();
        let mut values = Vec::with_capacity(n * d.ncols());
        for j in 0..d.ncols() {
            values.extend_from_slice(d.col_as_slice(j));
        }
        Operator::Dense { n, values }
    }

    /// `y = A x`.
    pub(crate) fn apply(&self, x: &[f64], y: &mut [f64]) {
        match self {
            Operator::Dense { n, values } => {
                y.iter_mut().for_each(|v| *v = 0.0);
                for (col, &xj) in values.chunks_exact(*n).zip(x) {
                    if xj != 0.0 {
                        y.iter_mut().zip(col).for_each(|(yi, a)| *yi += a * xj);
                    }
                }
            }
            Operator::Sparse(m) => m.mul_vec(x, y),
            Operator::Diagonal(d) => y.iter_mut().zip(d).zip(x).for_each(|((y, d), x)| *y = d * x),
        }
    }
}

/// The diagonal of a square matrix with nothing off it.
fn dense_diagonal(a: &Mat<f64>) -> Option<Vec<f64>> {
    Matrix::Dense(a.clone()).diagonal_entries()
}

/// The linear part of the model as operators: `M x`, `K x`, `D x`.
#[derive(Debug)]
pub(crate) struct LinearOperators {
    pub(crate) mass: Operator,
    pub(crate) stiffness: Operator,
    pub(crate) damping: DampingOperator,
}

impl LinearOperators {
    pub(crate) fn new(model: &LinearModel) -> Result<Self, TimesimError> {
        Ok(LinearOperators {
            mass: Operator::new(&model.mass),
            stiffness: Operator::new(&model.stiffness),
            damping: DampingOperator::new(model)?,
        })
    }

    /// `y = D x`; `tmp` is a scratch vector of the model's length.
    pub(crate) fn damp(&self, x: &[f64], y: &mut [f64], tmp: &mut [f64]) {
        match &self.damping {
            DampingOperator::None => y.iter_mut().for_each(|v| *v = 0.0),
            DampingOperator::Matrix(d) => d.apply(x, y),
            DampingOperator::Rayleigh { alpha, beta } => {
                self.mass.apply(x, y);
                self.stiffness.apply(x, tmp);
                y.iter_mut().zip(tmp.iter()).for_each(|(a, b)| *a = alpha * *a + beta * b);
            }
        }
    }
}

/// `D x` without forming D when it is Rayleigh (sparse models stay sparse).
#[derive(Debug)]
pub(crate) enum DampingOperator {
    None,
    Matrix(Operator),
    Rayleigh { alpha: f64, beta: f64 },
}

impl DampingOperator {
    /// Modal damping is a dense `M Φ diag(2ζω) Φᵀ M` built from all modes (meant for reduced
    /// models, where all modes are cheap); dense Rayleigh damping is formed once.
    fn new(model: &LinearModel) -> Result<Self, TimesimError> {
        let n = model.n_dofs();
        Ok(match &model.damping {
            Damping::None => DampingOperator::None,
            Damping::Matrix(d) => DampingOperator::Matrix(Operator::new(d)),
            Damping::Rayleigh { alpha, beta } => match (&model.mass, &model.stiffness) {
                (Matrix::Dense(m), Matrix::Dense(k)) => {
                    DampingOperator::Matrix(Operator::from_dense(&Mat::from_fn(n, n, |i, j| {
                        alpha * m[(i, j)] + beta * k[(i, j)]
                    })))
                }
                _ => DampingOperator::Rayleigh { alpha: *alpha, beta: *beta },
            },
            Damping::Modal { .. } => {
                let modes = model.dense_modes()?;
                DampingOperator::Matrix(Operator::from_dense(&model.damping_dense(Some(&modes))))
            }
        })
    }

    fn is_sparse(&self) -> bool {
        !matches!(self, DampingOperator::Matrix(Operator::Dense { .. } | Operator::Diagonal(_)))
    }

    /// Dense D.
    pub(crate) fn to_dense(&self, model: &LinearModel) -> Mat<f64> {
        let n = model.n_dofs();
        match self {
            DampingOperator::None => Mat::zeros(n, n),
            DampingOperator::Matrix(Operator::Dense { values, .. }) => Mat::from_fn(n, n, |i, j| values[j * n + i]),
            DampingOperator::Matrix(Operator::Sparse(d)) => d.to_dense(),
            DampingOperator::Matrix(Operator::Diagonal(d)) => {
                Mat::from_fn(n, n, |i, j| if i == j { d[i] } else { 0.0 })
            }
            DampingOperator::Rayleigh { alpha, beta } => {
                let (m, k) = (model.mass.to_dense(), model.stiffness.to_dense());
                Mat::from_fn(n, n, |i, j| alpha * m[(i, j)] + beta * k[(i, j)])
            }
        }
    }
}

/// A factorised symmetric positive definite matrix.
pub(crate) enum SpdSolver {
    /// Explicit inverse (small models).
    DenseInverse(Mat<f64>),
    /// Inverse of a diagonal matrix (models in modal coordinates).
    Diagonal(Vec<f64>),
    /// Sparse Cholesky factor (AMD ordering) with its solve workspace allocated once, so that
    /// a solve does not allocate.
    Sparse { symbolic: Box<SymbolicCholesky<usize>>, values: Vec<f64>, workspace: MemBuffer },
}

impl std::fmt::Debug for SpdSolver {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            SpdSolver::DenseInverse(m) => write!(f, "SpdSolver::DenseInverse({}x{})", m.nrows(), m.ncols()),
            SpdSolver::Diagonal(d) => write!(f, "SpdSolver::Diagonal({})", d.len()),
            SpdSolver::Sparse { values, .. } => write!(f, "SpdSolver::Sparse({} factor values)", values.len()),
        }
    }
}

impl SpdSolver {
    /// `out = A⁻¹ rhs`.
    pub(crate) fn solve(&mut self, rhs: &[f64], out: &mut [f64]) {
        match self {
            SpdSolver::DenseInverse(inv) => {
                out.iter_mut().for_each(|v| *v = 0.0);
                for (j, &r) in rhs.iter().enumerate() {
                    if r != 0.0 {
                        for (o, a) in out.iter_mut().zip(inv.col_as_slice(j)) {
                            *o += a * r;
                        }
                    }
                }
            }
            SpdSolver::Diagonal(inverse) => {
                out.iter_mut().zip(inverse.iter()).zip(rhs).for_each(|((o, d), r)| *o = d * r);
            }
            SpdSolver::Sparse { symbolic, values, workspace } => {
                out.copy_from_slice(rhs);
                let n = out.len();
                LltRef::new(symbolic, values).solve_in_place_with_conj(
                    Conj::No,
                    MatMut::from_column_major_slice_mut(out, n, 1),
                    Par::Seq,
                    MemStack::new(workspace),
                );
            }
        }
    }

    /// Factorise `Σ_i c_i A_i` (terms with zero coefficient are skipped); `None` if it is not
    /// positive definite.
    fn combination(n: usize, terms: &[(f64, &Matrix)], dense_extra: Option<(f64, &Mat<f64>)>) -> Option<Self> {
        if let Some(d) = diagonal_combination(n, terms, dense_extra) {
            // Positive definite iff every entry is positive.
            return d
                .iter()
                .all(|&v| v > 0.0 && v.is_finite())
                .then(|| SpdSolver::Diagonal(d.iter().map(|v| 1.0 / v).collect()));
        }
        let all_sparse = n > SPARSE_ABOVE
            && dense_extra.is_none()
            && terms.iter().all(|(c, m)| *c == 0.0 || matches!(m, Matrix::Sparse(_)));
        if all_sparse {
            let mut sum: HashMap<(usize, usize), f64> = HashMap::new();
            for (c, m) in terms.iter().filter(|(c, _)| *c != 0.0) {
                if let Matrix::Sparse(s) = m {
                    let s = s.as_ref();
                    for j in 0..n {
                        for (&i, &v) in s.symbolic().row_idx_of_col_raw(j).iter().zip(s.val_of_col(j)) {
                            *sum.entry((i, j)).or_insert(0.0) += c * v;
                        }
                    }
                }
            }
            let triplets: Vec<Triplet<usize, usize, f64>> =
                sum.into_iter().map(|((i, j), v)| Triplet::new(i, j, v)).collect();
            let a = SparseColMat::try_new_from_triplets(n, n, &triplets).ok()?;
            let symbolic =
                factorize_symbolic_cholesky(a.symbolic(), Side::Lower, SymmetricOrdering::Amd, Default::default())
                    .ok()?;
            let mut values = vec![0.0; symbolic.len_val()];
            let mut scratch =
                MemBuffer::new(symbolic.factorize_numeric_llt_scratch::<f64>(Par::Seq, Default::default()));
            // No regularisation: a non-positive pivot means S (or M) is not positive definite.
            let exact = LltRegularization { dynamic_regularization_delta: 0.0, dynamic_regularization_epsilon: 0.0 };
            symbolic
                .factorize_numeric_llt(
                    &mut values,
                    a.as_ref(),
                    Side::Lower,
                    exact,
                    Par::Seq,
                    MemStack::new(&mut scratch),
                    Default::default(),
                )
                .ok()?;
            let workspace = MemBuffer::new(symbolic.solve_in_place_scratch::<f64>(1, Par::Seq));
            return Some(SpdSolver::Sparse { symbolic: Box::new(symbolic), values, workspace });
        }
        let mut a = Mat::<f64>::zeros(n, n);
        for (c, m) in terms.iter().filter(|(c, _)| *c != 0.0) {
            let d = m.to_dense();
            a += faer::Scale(*c) * &d;
        }
        if let Some((c, d)) = dense_extra {
            a += faer::Scale(c) * d;
        }
        let llt = a.llt(Side::Lower).ok()?;
        Some(SpdSolver::DenseInverse(llt.inverse()))
    }
}

/// `Σ_i c_i A_i` when every term is diagonal.
fn diagonal_combination(n: usize, terms: &[(f64, &Matrix)], dense_extra: Option<(f64, &Mat<f64>)>) -> Option<Vec<f64>> {
    let mut sum = vec![0.0; n];
    let extra = dense_extra.map(|(c, d)| (c, Matrix::Dense(d.clone())));
    for (c, m) in terms.iter().map(|&(c, m)| (c, m)).chain(extra.as_ref().map(|(c, m)| (*c, m))) {
        if c == 0.0 {
            continue;
        }
        let d = m.diagonal_entries()?;
        sum.iter_mut().zip(&d).for_each(|(s, d)| *s += c * d);
    }
    Some(sum)
}

/// `S = c_m M + c_d D + c_k K` factorised.
pub(crate) fn effective_solver(
    model: &LinearModel,
    operators: &LinearOperators,
    c_m: f64,
    c_d: f64,
    c_k: f64,
) -> Result<SpdSolver, TimesimError> {
    let n = model.n_dofs();
    let damping = &operators.damping;
    let solver = if damping.is_sparse() {
        // Rayleigh damping folds into the M and K coefficients.
        let (mut cm, mut ck) = (c_m, c_k);
        let mut terms: Vec<(f64, &Matrix)> = Vec::new();
        match damping {
            DampingOperator::Rayleigh { alpha, beta } => {
                cm += c_d * alpha;
                ck += c_d * beta;
            }
            DampingOperator::Matrix(Operator::Sparse(d)) => terms.push((c_d, d)),
            DampingOperator::Matrix(Operator::Dense { .. } | Operator::Diagonal(_)) => {
                unreachable!("dense and diagonal damping take the dense path")
            }
            DampingOperator::None => {}
        }
        terms.push((cm, &model.mass));
        terms.push((ck, &model.stiffness));
        SpdSolver::combination(n, &terms, None)
    } else {
        let d = damping.to_dense(model);
        SpdSolver::combination(n, &[(c_m, &model.mass), (c_k, &model.stiffness)], Some((c_d, &d)))
    };
    solver.ok_or(TimesimError::EffectiveNotPositiveDefinite)
}

/// M factorised, for the initial acceleration.
pub(crate) fn mass_solver(model: &LinearModel) -> Result<SpdSolver, TimesimError> {
    let n = model.n_dofs();
    // A positive definite M in double precision has a Cholesky factor; a singular one (a
    // massless DOF) fails or leaves a pivot at round-off level, which the check below catches.
    let solver = SpdSolver::combination(n, &[(1.0, &model.mass)], None).ok_or(TimesimError::SingularMass)?;
    if let SpdSolver::DenseInverse(inv) = &solver {
        let m = model.mass.to_dense();
        let norm = |a: &Mat<f64>| a.norm_max();
        if !(norm(inv) * norm(&m)).is_finite() || norm(inv) * norm(&m) > 1e12 {
            return Err(TimesimError::SingularMass);
        }
    }
    Ok(solver)
}
