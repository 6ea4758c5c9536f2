//! Partial-pivot LU of the corrector's dense systems, and its triangular solves.
//!
//! Written by hand at the corrector's usual sizes (a harmonic balance condensed onto a few
//! joints: 15 to 60 unknowns, each block of a split Jacobian half that), where faer's general
//! routines spend much of their time in dispatch and short loops:
//! - the solves: counted on whole runs of the 10-DOF chain, faer's took ~11,000 instructions a
//!   solve of size ~30 against ~3,800 for the loops below (n² = 900 multiply-adds), 4 % of the
//!   whole run;
//! - the factorisation: two columns at a time (a rank-2 update of the trailing columns, each
//!   loaded and stored once for two pivots), vectorised with AVX2 where the processor has it;
//!   measured 2.5 µs against faer's 3.8 µs at size 28, 3.6 against 5.7 µs at 33, 14.8 against
//!   16.9 µs at 60 (one core, medians). A one-column version took about as many instructions as
//!   faer's. Above [`BY_HAND`] rows faer's blocked factorisation is used.
use faer::dyn_stack::{MemBuffer, MemStack};
use faer::linalg::lu::partial_pivoting::factor;
use faer::{MatMut, MatRef, Par};
use multiversion::multiversion;

use super::singular::Determinant;

/// Partial-pivot LU factors `P A = L U` of a square matrix (L below the diagonal, its unit
/// diagonal implied; U on and above), in a buffer of their own.
pub struct PivotedLu {
    /// Column-major `size × size`.
    factors: Vec<f64>,
    /// The row permutation (`(P A)_i = A_{perm_i}`), and its inverse, which faer's
    /// factorisation writes too (unused otherwise).
    perm: Vec<usize>,
    perm_inv: Vec<usize>,
    /// Size of the last factorisation, and its number of row swaps.
    size: usize,
    swaps: usize,
    /// faer's workspace, made at the first matrix above [`BY_HAND`] rows.
    scratch: Option<MemBuffer>,
    /// The right-hand side permuted.
    permuted: Vec<f64>,
}

impl PivotedLu {
    /// For matrices of at most `capacity` rows.
    pub fn new(capacity: usize) -> Self {
        PivotedLu {
            factors: vec![0.0; capacity * capacity],
            permuted: vec![0.0; capacity],
            perm: vec![0; capacity],
            perm_inv: vec![0; capacity],
            size: 0,
            swaps: 0,
            scratch: None,
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
        if n <= BY_HAND {
            self.swaps = factor_by_pairs(factors, n, &mut self.perm[..n]);
            return;
        }
        // Made at the first factorisation above BY_HAND rows, for the largest planned.
        let capacity = self.perm.len();
        let scratch = self.scratch.get_or_insert_with(|| {
            MemBuffer::new(factor::lu_in_place_scratch::<usize, f64>(capacity, capacity, Par::Seq, Default::default()))
        });
        let (info, _) = factor::lu_in_place(
            MatMut::from_column_major_slice_mut(factors, n, n),
            &mut self.perm[..n],
            &mut self.perm_inv[..n],
            Par::Seq,
            MemStack::new(scratch),
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

/// Matrices of at most this many rows are factored by [`factor_by_pairs`], larger ones by
/// faer's blocked LU (measured faster by hand up to 60 rows; the corrector's condensed systems
/// are below, those of a balance on a whole model far above).
const BY_HAND: usize = 64;

/// `P A = L U` in place (`a` column-major, n × n; L's unit diagonal implied), partial pivoting
/// as LAPACK's `dgetf2` (the first largest magnitude of the column), two pivots a pass: column
/// k is factored, updated into column k + 1, which is factored in turn, and every later column
/// then takes both updates at once. `perm` receives the rows (`(P A)_i = A_{perm_i}`); returns
/// the number of row swaps. A zero pivot is kept (its column left unscaled): solves then give
/// non-finite values. No fused multiply-add, so the factors are the same on every processor.
#[multiversion(targets("x86_64+avx2+fma", "x86_64+avx"))]
fn factor_by_pairs(a: &mut [f64], n: usize, perm: &mut [usize]) -> usize {
    let mut swaps = 0;
    perm.iter_mut().enumerate().for_each(|(i, p)| *p = i);
    // Pivot of column k (already updated by every earlier pivot), rows swapped across the
    // whole matrix, multipliers scaled.
    let pivot = |a: &mut [f64], perm: &mut [usize], k: usize, swaps: &mut usize| {
        let column = &a[k * n..(k + 1) * n];
        let (mut p, mut largest) = (k, column[k].abs());
        for (i, v) in column.iter().enumerate().skip(k + 1) {
            if v.abs() > largest {
                (p, largest) = (i, v.abs());
            }
        }
        if p != k {
            *swaps += 1;
            perm.swap(k, p);
            for j in 0..n {
                a.swap(j * n + k, j * n + p);
            }
        }
        let diagonal = a[k * n + k];
        if diagonal != 0.0 {
            let inverse = 1.0 / diagonal;
            a[k * n + k + 1..(k + 1) * n].iter_mut().for_each(|v| *v *= inverse);
        }
    };
    let mut k = 0;
    while k < n {
        pivot(a, perm, k, &mut swaps);
        if k + 1 == n {
            break;
        }
        {
            let (left, right) = a.split_at_mut((k + 1) * n);
            let (l, next) = (&left[k * n + k + 1..], &mut right[..n]);
            let u = next[k];
            if u != 0.0 {
                next[k + 1..].iter_mut().zip(l).for_each(|(x, l)| *x -= u * l);
            }
        }
        pivot(a, perm, k + 1, &mut swaps);
        let (left, right) = a.split_at_mut((k + 2) * n);
        let (l0, l1) = (&left[k * n..(k + 1) * n], &left[(k + 1) * n..(k + 2) * n]);
        for column in right.chunks_exact_mut(n) {
            let u0 = column[k];
            column[k + 1] -= u0 * l0[k + 1];
            let u1 = column[k + 1];
            if u0 != 0.0 || u1 != 0.0 {
                let rows = column[k + 2..].iter_mut().zip(&l0[k + 2..]).zip(&l1[k + 2..]);
                rows.for_each(|((x, a0), a1)| *x -= u0 * a0 + u1 * a1);
            }
        }
        k += 2;
    }
    swaps
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
