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

    /// The diagonal, if every entry off it is zero (modal coordinates); `None` otherwise.
    pub fn diagonal_entries(&self) -> Option<Vec<f64>> {
        let n = self.nrows();
        if self.ncols() != n {
            return None;
        }
        let mut d = vec![0.0; n];
        match self {
            Matrix::Dense(m) => {
                for j in 0..n {
                    for i in 0..n {
                        if i == j {
                            d[i] = m[(i, j)];
                        } else if m[(i, j)] != 0.0 {
                            return None;
                        }
                    }
                }
            }
            Matrix::Sparse(m) => {
                let m = m.as_ref();
                for j in 0..n {
                    for (&i, &v) in m.symbolic().row_idx_of_col_raw(j).iter().zip(m.val_of_col(j)) {
                        if i == j {
                            d[i] += v;
                        } else if v != 0.0 {
                            return None;
                        }
                    }
                }
            }
        }
        Some(d)
    }

    /// A sparse diagonal matrix.
    pub fn from_diagonal(d: &[f64]) -> Self {
        let triplets: Vec<faer::sparse::Triplet<usize, usize, f64>> =
            d.iter().enumerate().map(|(i, &v)| faer::sparse::Triplet::new(i, i, v)).collect();
        Matrix::Sparse(
            SparseColMat::try_new_from_triplets(d.len(), d.len(), &triplets).expect("diagonal triplets are valid"),
        )
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
        let (mut max, mut diff) = (0.0f64, 0.0f64);
        match self {
            Matrix::Dense(d) => {
                for j in 0..d.ncols() {
                    for i in 0..d.nrows() {
                        max = max.max(d[(i, j)].abs());
                        diff = diff.max((d[(i, j)] - d[(j, i)]).abs());
                    }
                }
            }
            Matrix::Sparse(m) => {
                // Compare with the transpose entry by entry, without a dense copy (FE sizes):
                // both are sorted column by column, so A − Aᵀ's entries are found by merging.
                let a = m.as_ref();
                let t = a.transpose().to_col_major().expect("transpose of a valid CSC matrix");
                let t = t.as_ref();
                for j in 0..a.ncols() {
                    let (ra, va) = (a.symbolic().row_idx_of_col_raw(j), a.val_of_col(j));
                    let (rt, vt) = (t.symbolic().row_idx_of_col_raw(j), t.val_of_col(j));
                    let (mut p, mut q) = (0, 0);
                    while p < ra.len() || q < rt.len() {
                        let (x, y) = match (ra.get(p), rt.get(q)) {
                            (Some(&i), Some(&k)) if i == k => {
                                p += 1;
                                q += 1;
                                (va[p - 1], vt[q - 1])
                            }
                            (Some(&i), Some(&k)) if i < k => {
                                p += 1;
                                (va[p - 1], 0.0)
                            }
                            (Some(_), None) => {
                                p += 1;
                                (va[p - 1], 0.0)
                            }
                            _ => {
                                q += 1;
                                (0.0, vt[q - 1])
                            }
                        };
                        max = max.max(x.abs());
                        diff = diff.max((x - y).abs());
                    }
                }
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

#[cfg(test)]
mod tests {
    use super::*;
    use faer::sparse::Triplet;

    fn sparse(entries: &[(usize, usize, f64)]) -> Matrix {
        let t: Vec<_> = entries.iter().map(|&(i, j, v)| Triplet::new(i, j, v)).collect();
        Matrix::Sparse(SparseColMat::try_new_from_triplets(4, 4, &t).unwrap())
    }

    #[test]
    fn sparse_asymmetry_equals_the_dense_one() {
        let sym = sparse(&[(0, 0, 4.0), (1, 0, -1.0), (0, 1, -1.0), (3, 2, 2.0), (2, 3, 2.0), (3, 3, 1.0)]);
        assert_eq!(sym.asymmetry(), 0.0);
        // One entry without its mirror, one mirrored with a different value.
        let asym = sparse(&[(0, 0, 4.0), (1, 0, -1.0), (0, 1, -1.5), (3, 1, 0.5), (3, 3, 1.0)]);
        let dense = Matrix::Dense(asym.to_dense());
        assert_eq!(asym.asymmetry(), dense.asymmetry());
        assert_eq!(asym.asymmetry(), 0.5 / 4.0);
    }
}
