//! Partial-pivot LU of the corrector's dense systems: faer's factorisation, and the
//! triangular solves written here.
//!
//! The solves are written by hand because at the corrector's sizes (a harmonic balance
//! condensed onto a few joints: 15 to 60 unknowns, each block of a split Jacobian half that)
//! faer's solve spends most of its time in dispatch: counted on whole runs of the 10-DOF
//! chain, ~11,000 instructions a solve of size ~30 against ~3,800 for the loops below (n² =
//! 900 multiply-adds), 4 % of the whole run. A factorisation written the same way (LAPACK's
//! `dgetf2`, by columns) was tried and took as many instructions as faer's (~45,000 at size
//! ~30, its short column updates dominated by loop overhead), so faer factors.
use faer::dyn_stack::{MemBuffer, MemStack};
use faer::linalg::lu::partial_pivoting::factor;
use faer::{MatMut, MatRef, Par};
use multiversion::multiversion;

use super::singular::Determinant;

/// Partial-pivot LU factors `P A = L U` of a square matrix (L below the diagonal, its unit
/// diagonal implied; U on and above), in a buffer of their own.
pub(super) struct PivotedLu {
    /// Column-major `size × size`.
    factors: Vec<f64>,
    /// faer's row permutation (`(P A)_i = A_{perm_i}`) and its inverse.
    perm: Vec<usize>,
    perm_inv: Vec<usize>,
    /// Size of the last factorisation, and its number of row swaps.
    size: usize,
    swaps: usize,
    scratch: MemBuffer,
    /// The right-hand side permuted.
    permuted: Vec<f64>,
}

impl PivotedLu {
    /// For matrices of at most `capacity` rows.
    pub fn new(capacity: usize) -> Self {
        let req = factor::lu_in_place_scratch::<usize, f64>(capacity, capacity, Par::Seq, Default::default());
        PivotedLu {
            factors: vec![0.0; capacity * capacity],
            permuted: vec![0.0; capacity],
            perm: vec![0; capacity],
            perm_inv: vec![0; capacity],
            size: 0,
            swaps: 0,
            scratch: MemBuffer::new(req),
        }
    }

    /// Factor the square `a`. A zero pivot is kept: solves then give non-finite values, which
    /// callers check.
    pub fn factor(&mut self, a: MatRef<'_, f64>) {
        self.factor_written(a.nrows(), |mut m| m.copy_from(a));
    }

    /// Factor the `n × n` matrix that `write` puts in the factors' buffer (every entry), with
    /// no copy of its own: blocks gathered from a larger matrix.
    pub fn factor_written(&mut self, n: usize, write: impl FnOnce(MatMut<'_, f64>)) {
        assert!(n <= self.perm.len(), "LU of a matrix larger than planned");
        self.size = n;
        let factors = &mut self.factors[..n * n];
        write(MatMut::from_column_major_slice_mut(factors, n, n));
        let (info, _) = factor::lu_in_place(
            MatMut::from_column_major_slice_mut(factors, n, n),
            &mut self.perm[..n],
            &mut self.perm_inv[..n],
            Par::Seq,
            MemStack::new(&mut self.scratch),
            Default::default(),
        );
        self.swaps = info.transposition_count;
    }

    /// Overwrite `rhs` with `A⁻¹ rhs`, `A` the matrix of the last [`Self::factor`].
    pub fn solve(&mut self, rhs: &mut [f64]) {
        let n = self.size;
        let permuted = &mut self.permuted[..n];
        for (p, &i) in permuted.iter_mut().zip(&self.perm[..n]) {
            *p = rhs[i];
        }
        solve_by_columns(&self.factors[..n * n], permuted);
        rhs[..n].copy_from_slice(permuted);
    }

    /// `det A` of the last [`Self::factor`]: U's diagonal, negated for an odd number of row
    /// swaps.
    pub fn determinant(&self) -> Determinant {
        let n = self.size;
        let mut determinant = Determinant { sign: if self.swaps & 1 == 0 { 1.0 } else { -1.0 }, ln_abs: 0.0 };
        for i in 0..n {
            let pivot = self.factors[i * n + i];
            determinant.sign *= if pivot == 0.0 { 0.0 } else { pivot.signum() };
            determinant.ln_abs += pivot.abs().ln();
        }
        determinant
    }
}

/// `L U x = b` (`lu` column-major, n × n, L's unit diagonal implied), in place: forward
/// then backward, a contiguous column at a time. No fused multiply-add, so the solution is
/// the same on every processor.
#[multiversion(targets("x86_64+avx2+fma", "x86_64+avx"))]
fn solve_by_columns(lu: &[f64], rhs: &mut [f64]) {
    let n = rhs.len();
    for k in 0..n {
        let b = rhs[k];
        if b != 0.0 {
            for (x, l) in rhs[k + 1..n].iter_mut().zip(&lu[k * n + k + 1..(k + 1) * n]) {
                *x -= b * l;
            }
        }
    }
    for k in (0..n).rev() {
        let column = &lu[k * n..k * n + k + 1];
        rhs[k] /= column[k];
        let b = rhs[k];
        for (x, u) in rhs[..k].iter_mut().zip(column) {
            *x -= b * u;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use faer::prelude::Solve;
    use faer::Mat;

    /// A reproducible matrix with entries in [−1, 1] (a linear congruential sequence).
    fn matrix(n: usize, seed: u64) -> Mat<f64> {
        let mut state = seed;
        Mat::from_fn(n, n, |_, _| {
            state = state.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            (state >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
        })
    }

    /// The solves agree with faer's own solve from the same factors to 1e-13 of the solution
    /// (the same operations in another order), solve `A x = b` to the accuracy of a
    /// backward-stable LU, `‖A x − b‖ ≤ 1e-12 ‖A‖ ‖x‖` (these random matrices are well
    /// conditioned and partial pivoting's growth stays small on them), and the determinant
    /// is faer's to 1e-10 in its logarithm, with its sign.
    #[test]
    fn solves_and_determinants_agree_with_faer() {
        for (n, seed) in [(1, 1), (2, 2), (7, 3), (16, 4), (33, 5), (61, 6), (150, 9)] {
            let a = matrix(n, seed);
            let b: Vec<f64> = (0..n).map(|i| (i as f64 * 0.7).sin()).collect();
            let mut lu = PivotedLu::new(n);
            lu.factor(a.as_ref());
            let mut x = b.clone();
            lu.solve(&mut x);
            let norm_a = a.norm_max() * n as f64;
            let norm_x = x.iter().map(|v| v.abs()).fold(0.0, f64::max);
            for i in 0..n {
                let ax: f64 = (0..n).map(|j| a[(i, j)] * x[j]).sum();
                assert!((ax - b[i]).abs() <= 1e-12 * norm_a * norm_x, "n = {n}, row {i}: {ax} against {}", b[i]);
            }
            let reference = a.partial_piv_lu();
            let expected = reference.solve(Mat::from_fn(n, 1, |i, _| b[i]));
            for i in 0..n {
                assert!(
                    (x[i] - expected[(i, 0)]).abs() <= 1e-13 * norm_x,
                    "n = {n}, {i}: {} against {}",
                    x[i],
                    expected[(i, 0)]
                );
            }
            let det = a.determinant();
            let ours = lu.determinant();
            assert_eq!(ours.sign, det.signum(), "n = {n}");
            assert!(
                (ours.ln_abs - det.abs().ln()).abs() <= 1e-10,
                "n = {n}: {} against {}",
                ours.ln_abs,
                det.abs().ln()
            );
        }
    }

    /// A singular matrix gives a zero determinant sign and a solve that is not finite, which
    /// the corrector reports as a singular system.
    #[test]
    fn a_singular_matrix_gives_a_non_finite_solve() {
        let mut a = matrix(5, 12);
        for i in 0..5 {
            a[(i, 3)] = 2.0 * a[(i, 1)];
        }
        let mut lu = PivotedLu::new(5);
        lu.factor(a.as_ref());
        let mut x = vec![1.0; 5];
        lu.solve(&mut x);
        let exact_zero = lu.determinant().sign == 0.0;
        assert!(exact_zero || x.iter().any(|v| !v.is_finite() || v.abs() > 1e12), "{x:?}");
    }
}
