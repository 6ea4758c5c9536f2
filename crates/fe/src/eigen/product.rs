//! `A X` for a symmetric sparse `A` (both triangles stored, as the assembled K and M) and a
//! dense block `X` of a few to a few hundred columns: the products of the block Lanczos, the
//! Rayleigh quotients and the reduction's projections.
//!
//! Written here because faer's `sparse_dense_matmul` walks the sparse matrix once per column of
//! `X`: with 12-column blocks on the 306k-DOF Harmony model (41 M entries) it took 31 % of the
//! eigensolution, memory-bound on 12 passes over the matrix. Here the block is stored by rows,
//! so the matrix is read once and each entry updates `b` contiguous values; since `A` is
//! symmetric, column `j` of `A` is its row `j`, so every output row is a gather that threads
//! compute independently.
use faer::reborrow::ReborrowMut;
use faer::sparse::{SparseColMat, SparseColMatRef};
use faer::{Mat, MatMut, MatRef};
use rayon::prelude::*;

/// Widest block multiplied in one pass over the matrix (see [`symmetric_product`]).
const SLAB: usize = 32;

/// Rows of the output per parallel task.
const ROWS_PER_TASK: usize = 2048;

/// `out = A X` for symmetric `A` (both triangles stored). Panics if the sizes differ.
pub fn symmetric_product(mut out: MatMut<'_, f64>, a: SparseColMatRef<'_, usize, f64>, x: MatRef<'_, f64>) {
    let (n, b) = (x.nrows(), x.ncols());
    assert!(
        a.nrows() == n && a.ncols() == n && out.nrows() == n && out.ncols() == b,
        "expected A {n}x{n} and out {n}x{b}, got A {}x{} and out {}x{}",
        a.nrows(),
        a.ncols(),
        out.nrows(),
        out.ncols()
    );
    if b == 0 || n == 0 {
        return;
    }
    if b > SLAB {
        // Wide blocks (the reduction basis, 149 columns at 306k DOFs) by slabs of columns: the
        // row-ordered copies below are two n × b temporaries (730 MB for the whole basis),
        // against one more pass over A per slab. Each entry is summed as in one pass.
        let slabs = b.div_ceil(SLAB);
        let width = b.div_ceil(slabs);
        for c0 in (0..b).step_by(width) {
            let w = width.min(b - c0);
            symmetric_product(out.rb_mut().subcols_mut(c0, w), a, x.subcols(c0, w));
        }
        return;
    }
    let mut xr = vec![0.0; n * b];
    for c in 0..b {
        for (i, v) in x.col(c).iter().enumerate() {
            xr[i * b + c] = *v;
        }
    }
    let mut yr = vec![0.0; n * b];
    yr.par_chunks_mut(b * ROWS_PER_TASK).enumerate().for_each(|(task, rows)| {
        for (local, row) in rows.chunks_mut(b).enumerate() {
            let j = task * ROWS_PER_TASK + local;
            for (&i, &v) in a.symbolic().row_idx_of_col_raw(j).iter().zip(a.val_of_col(j)) {
                for (y, x) in row.iter_mut().zip(&xr[i * b..i * b + b]) {
                    *y += v * x;
                }
            }
        }
    });
    for c in 0..b {
        for (i, v) in out.rb_mut().col_mut(c).iter_mut().enumerate() {
            *v = yr[i * b + c];
        }
    }
}

/// The stiffness of an eigenproblem, known through its products: a symmetric sparse matrix, or
/// one less a few rank-one terms (the structure with joints released, `K − U C Uᵀ`), which
/// needs no copy of K (0.66 GB at 306k DOFs).
pub enum Stiffness<'a> {
    Sparse(&'a SparseColMat<usize, f64>),
    /// `K − U diag(c) Uᵀ`.
    LessRankOnes {
        k: &'a SparseColMat<usize, f64>,
        u: MatRef<'a, f64>,
        c: &'a [f64],
    },
}

impl Stiffness<'_> {
    fn matrix(&self) -> &SparseColMat<usize, f64> {
        match self {
            Stiffness::Sparse(k) | Stiffness::LessRankOnes { k, .. } => k,
        }
    }

    pub fn nrows(&self) -> usize {
        self.matrix().nrows()
    }

    pub fn ncols(&self) -> usize {
        self.matrix().ncols()
    }

    /// `out = A X`.
    pub fn product(&self, mut out: MatMut<'_, f64>, x: MatRef<'_, f64>) {
        symmetric_product(out.rb_mut(), self.matrix().as_ref(), x);
        if let Stiffness::LessRankOnes { u, c, .. } = self {
            // out −= U (C (Uᵀ X)): r × b coefficients.
            let mut coef = u.transpose() * x;
            for (j, &cj) in c.iter().enumerate() {
                coef.row_mut(j).iter_mut().for_each(|v| *v *= cj);
            }
            faer::linalg::matmul::matmul(out, faer::Accum::Add, *u, coef.as_ref(), -1.0, faer::Par::Seq);
        }
    }
}

/// `A X` as a new matrix (see [`symmetric_product`]).
pub fn symmetric_times(a: SparseColMatRef<'_, usize, f64>, x: MatRef<'_, f64>) -> Mat<f64> {
    let mut out = Mat::zeros(x.nrows(), x.ncols());
    symmetric_product(out.as_mut(), a, x);
    out
}

#[cfg(test)]
mod tests {
    use faer::sparse::{SparseColMat, Triplet};
    use faer::Mat;

    #[test]
    fn equals_the_dense_product() {
        let n = 300;
        let mut t = Vec::new();
        for i in 0..n {
            t.push(Triplet::new(i, i, 4.0 + i as f64));
            for j in [i + 1, i + 7, i + 90] {
                if j < n {
                    let v = 1.0 / (1.0 + (i * j) as f64);
                    t.push(Triplet::new(i, j, v));
                    t.push(Triplet::new(j, i, v));
                }
            }
        }
        let a = SparseColMat::try_new_from_triplets(n, n, &t).unwrap();
        let x = Mat::<f64>::from_fn(n, 5, |i, c| ((i * 31 + c * 7) % 13) as f64 - 6.0);
        let got = super::symmetric_times(a.as_ref(), x.as_ref());
        let dense = a.to_dense() * &x;
        for i in 0..n {
            for c in 0..5 {
                // Same terms summed in another order: round-off of a few ulps.
                assert!((got[(i, c)] - dense[(i, c)]).abs() <= 1e-12 * dense[(i, c)].abs().max(1.0));
            }
        }
    }
}
