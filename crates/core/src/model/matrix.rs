use faer::sparse::SparseColMat;
use faer::Mat;

/// A real square matrix of the linear model, dense (reduced models, small inline models) or
/// sparse (assembled FE models).
#[derive(Clone, Debug)]
pub enum Matrix {
    Dense(Mat<f64>),
    Sparse(SparseColMat<usize, f64>),
}

impl Matrix {
    pub fn nrows(&self) -> usize {
        match self {
            Matrix::Dense(m) => m.nrows(),
            Matrix::Sparse(m) => m.nrows(),
        }
    }

    pub fn ncols(&self) -> usize {
        match self {
            Matrix::Dense(m) => m.ncols(),
            Matrix::Sparse(m) => m.ncols(),
        }
    }

    /// Dense copy (sparse matrices are expanded).
    pub fn to_dense(&self) -> Mat<f64> {
        match self {
            Matrix::Dense(m) => m.clone(),
            Matrix::Sparse(m) => m.to_dense(),
        }
    }

    /// `y = A x`.
    pub fn mul_vec(&self, x: &[f64], y: &mut [f64]) {
        assert_eq!(x.len(), self.ncols(), "expected x of length {}, got {}", self.ncols(), x.len());
        assert_eq!(y.len(), self.nrows(), "expected y of length {}, got {}", self.nrows(), y.len());
        y.iter_mut().for_each(|v| *v = 0.0);
        match self {
            Matrix::Dense(m) => {
                for j in 0..m.ncols() {
                    let xj = x[j];
                    if xj != 0.0 {
                        for (i, yi) in y.iter_mut().enumerate() {
                            *yi += m[(i, j)] * xj;
                        }
                    }
                }
            }
            Matrix::Sparse(m) => {
                let m = m.as_ref();
                for j in 0..m.ncols() {
                    let xj = x[j];
                    let rows = m.symbolic().row_idx_of_col_raw(j);
                    let vals = m.val_of_col(j);
                    for (&i, &v) in rows.iter().zip(vals) {
                        y[i] += v * xj;
                    }
                }
            }
        }
    }

    /// `xᵀ A y`.
    pub fn bilinear(&self, x: &[f64], y: &[f64]) -> f64 {
        let mut ay = vec![0.0; self.nrows()];
        self.mul_vec(y, &mut ay);
        x.iter().zip(&ay).map(|(a, b)| a * b).sum()
    }

    /// Largest `|A_ij − A_ji|` relative to the largest `|A_ij|`: 0 for a symmetric matrix.
    pub fn asymmetry(&self) -> f64 {
        let d = self.to_dense();
        let mut max = 0.0f64;
        let mut diff = 0.0f64;
        for j in 0..d.ncols() {
            for i in 0..d.nrows() {
                max = max.max(d[(i, j)].abs());
                diff = diff.max((d[(i, j)] - d[(j, i)]).abs());
            }
        }
        if max == 0.0 {
            0.0
        } else {
            diff / max
        }
    }

    /// Every stored value is finite.
    pub fn is_finite(&self) -> bool {
        match self {
            Matrix::Dense(m) => (0..m.ncols()).all(|j| (0..m.nrows()).all(|i| m[(i, j)].is_finite())),
            Matrix::Sparse(m) => m.val().iter().all(|v| v.is_finite()),
        }
    }
}

impl From<Mat<f64>> for Matrix {
    fn from(m: Mat<f64>) -> Self {
        Matrix::Dense(m)
    }
}

impl From<SparseColMat<usize, f64>> for Matrix {
    fn from(m: SparseColMat<usize, f64>) -> Self {
        Matrix::Sparse(m)
    }
}
