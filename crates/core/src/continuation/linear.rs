//! The linear systems of the corrector: the bordered `(n+1)×(n+1)` system of Eq. 32 and the
//! `n×n` system of a solve at fixed λ. Dense: factored by partial-pivot LU (`dense_lu`) on buffers
//! allocated once per branch (no allocation per Newton iteration). A dense Jacobian that the
//! problem declares block diagonal ([`Problem::decoupled_unknowns`]: the even and odd
//! harmonics of a half-wave symmetric balance) is factored by its two blocks, the bordered
//! system by eliminating the first block (a quarter of the flops of the whole LU for two
//! blocks of half the size). For a problem that factors its own Jacobian
//! ([`Problem::factored`]): by block elimination of the border, two solves with `∂R/∂x`.

use faer::{Mat, MatMut, MatRef};

use super::dense_lu::PivotedLu;
use super::singular::Determinant;
use super::{Problem, ProblemError};

/// Workspace for the corrector: Jacobian buffers, LU factors and right-hand side.
pub(super) struct Workspace {
    n: usize,
    /// Column-major `(n+1)×(n+1)`: `[∂R/∂x ∂R/∂λ; tᵀ]`, scaled, then factored into `pivots`.
    matrix: Mat<f64>,
    /// ∂R/∂λ as the problem writes it.
    pub dr_dlambda: Vec<f64>,
    pub residual: Vec<f64>,
    /// Right-hand side, overwritten by the solution.
    pub rhs: Vec<f64>,
    /// The row order of `matrix`'s factors.
    pivots: PivotedLu,
    /// Dense: `matrix` holds the Jacobian of the last evaluation, not yet factored.
    holds_jacobian: bool,
    /// Dense: `pivots` (or `split`) holds the LU factors of the last bordered system solved.
    holds_bordered_factors: bool,
    /// The problem factors `∂R/∂x` itself (`matrix` is then empty).
    factored: bool,
    /// Dense, and the problem completes a residual evaluation to its Jacobian
    /// ([`Problem::completes_jacobian`]).
    pub lazy: bool,
    /// Factored: the last factorisation was singular.
    singular: bool,
    /// Factored: `(∂R/∂x)⁻¹ ∂R/∂λ` for the border.
    border: Vec<f64>,
    /// Dense, the last Jacobian block diagonal: its blocks, and their factors once solved.
    split: Option<Split>,
    /// `split` holds the blocks of the last Jacobian evaluated.
    split_active: bool,
    /// The last factorisation was of `split`'s blocks.
    factors_split: bool,
    /// `∂R/∂λ` scaled for the border of a split system.
    border_scaled: Vec<f64>,
}

/// A block-diagonal Jacobian `diag(J_a, J_b)` (unknowns `a` and `b`, each ascending) and its
/// factors. The bordered system `[c_x J  c_λ r; tᵀ t_λ]` is solved by eliminating the first
/// block: with `w = (c_x J_a)⁻¹ c_λ r_a`, the second block bordered by the Schur complement,
/// `S = [c_x J_b  c_λ r_b; t_bᵀ  t_λ − t_aᵀ w]`, and `det B = det(c_x J_a) det S` (the blocks
/// are a symmetric permutation of `B`, which keeps its determinant). The first block is the
/// one away from the branch's folds (the even harmonics of a symmetric response, which it
/// does not move): `J_b`, singular at a fold, is never inverted alone there. Where `J_a` is the
/// identity (unknowns the problem pins, [`Problem::decoupled_block_is_identity`]), it is
/// neither gathered nor factored: its solves divide by `c_x`.
struct Split {
    a: Vec<usize>,
    b: Vec<usize>,
    /// `J_a` of the last Jacobian is the identity.
    identity: bool,
    /// `c_x` of the last factorisation.
    cx: f64,
    /// `c_x J_a`, factored (unless `identity`).
    first: PivotedLu,
    /// `S` of the bordered system (size `|b| + 1`), or `c_x J_b` at fixed λ, factored.
    second: PivotedLu,
    /// `w` and `t_a` of the last bordered system.
    w: Vec<f64>,
    t_a: Vec<f64>,
    /// Gathered right-hand sides.
    rhs_a: Vec<f64>,
    rhs_b: Vec<f64>,
}

impl Split {
    fn new(a: &[usize], n: usize) -> Self {
        let b: Vec<usize> = (0..n).filter(|i| a.binary_search(i).is_err()).collect();
        let (na, nb) = (a.len(), b.len());
        Split {
            identity: false,
            cx: 1.0,
            first: PivotedLu::new(na),
            second: PivotedLu::new(nb + 1),
            w: vec![0.0; na],
            t_a: vec![0.0; na],
            rhs_a: vec![0.0; na],
            rhs_b: vec![0.0; nb + 1],
            a: a.to_vec(),
            b,
        }
    }

    /// Factor the blocks of `c_x J` (in `jacobian`, n × n) for the bordered system with
    /// column `c_λ r` and row `t`.
    fn factor_bordered(&mut self, jacobian: MatRef<'_, f64>, cx: f64, border: &[f64], t: &[f64]) {
        let nb = self.b.len();
        self.cx = cx;
        if !self.identity {
            let a = &self.a;
            self.first.factor_written(a.len(), |m| gather(m, jacobian, a, cx));
        }
        for (k, &i) in self.a.iter().enumerate() {
            self.w[k] = border[i];
            self.t_a[k] = t[i];
        }
        Self::solve_first(&mut self.first, self.identity, cx, &mut self.w);
        let t_w: f64 = self.t_a.iter().zip(&self.w).map(|(a, b)| a * b).sum();
        let b = &self.b;
        self.second.factor_written(nb + 1, |mut s| {
            gather(s.as_mut().submatrix_mut(0, 0, nb, nb), jacobian, b, cx);
            for (k, &i) in b.iter().enumerate() {
                s[(k, nb)] = border[i];
                s[(nb, k)] = t[i];
            }
            s[(nb, nb)] = t[t.len() - 1] - t_w;
        });
    }

    /// Solve the bordered system factored by [`Self::factor_bordered`] for `rhs` (n + 1), in
    /// place.
    fn solve_bordered(&mut self, rhs: &mut [f64]) {
        let nb = self.b.len();
        for (k, &i) in self.a.iter().enumerate() {
            self.rhs_a[k] = rhs[i];
        }
        Self::solve_first(&mut self.first, self.identity, self.cx, &mut self.rhs_a);
        for (k, &i) in self.b.iter().enumerate() {
            self.rhs_b[k] = rhs[i];
        }
        let t_y: f64 = self.t_a.iter().zip(&self.rhs_a).map(|(a, b)| a * b).sum();
        self.rhs_b[nb] = rhs[rhs.len() - 1] - t_y;
        self.second.solve(&mut self.rhs_b);
        let alpha = self.rhs_b[nb];
        for (k, &i) in self.a.iter().enumerate() {
            rhs[i] = self.rhs_a[k] - alpha * self.w[k];
        }
        for (k, &i) in self.b.iter().enumerate() {
            rhs[i] = self.rhs_b[k];
        }
        rhs[rhs.len() - 1] = alpha;
    }

    /// Factor and solve `c_x J Δu = rhs` (n), in place.
    fn solve_fixed(&mut self, jacobian: MatRef<'_, f64>, cx: f64, rhs: &mut [f64]) {
        self.cx = cx;
        if !self.identity {
            let a = &self.a;
            self.first.factor_written(a.len(), |m| gather(m, jacobian, a, cx));
        }
        let b = &self.b;
        self.second.factor_written(b.len(), |m| gather(m, jacobian, b, cx));
        for (k, &i) in self.a.iter().enumerate() {
            self.rhs_a[k] = rhs[i];
        }
        Self::solve_first(&mut self.first, self.identity, self.cx, &mut self.rhs_a);
        let nb = self.b.len();
        for (k, &i) in self.b.iter().enumerate() {
            self.rhs_b[k] = rhs[i];
        }
        self.second.solve(&mut self.rhs_b[..nb]);
        for (k, &i) in self.a.iter().enumerate() {
            rhs[i] = self.rhs_a[k];
        }
        for (k, &i) in self.b.iter().enumerate() {
            rhs[i] = self.rhs_b[k];
        }
    }

    /// `(c_x J_a)⁻¹ values` in place: by the factors `first`, or, for an `identity` block, a
    /// division by `c_x`.
    fn solve_first(first: &mut PivotedLu, identity: bool, cx: f64, values: &mut [f64]) {
        if identity {
            values.iter_mut().for_each(|v| *v /= cx);
        } else {
            first.solve(values);
        }
    }

    fn bordered_determinant(&self) -> Determinant {
        let a = match self.identity {
            // det(c_x I) = c_x^|a|, c_x > 0.
            true => Determinant { sign: 1.0, ln_abs: self.a.len() as f64 * self.cx.ln() },
            false => self.first.determinant(),
        };
        let s = self.second.determinant();
        Determinant { sign: a.sign * s.sign, ln_abs: a.ln_abs + s.ln_abs }
    }
}

/// `block = c_x jacobian[rows, rows]`.
fn gather(mut block: MatMut<'_, f64>, jacobian: MatRef<'_, f64>, rows: &[usize], cx: f64) {
    for (l, &j) in rows.iter().enumerate() {
        let column = jacobian.col(j);
        for (k, &i) in rows.iter().enumerate() {
            block[(k, l)] = column[i] * cx;
        }
    }
}

impl Workspace {
    /// Buffers for `problem`, dense unless it factors its own Jacobian.
    pub fn new<P: Problem + ?Sized>(problem: &mut P) -> Self {
        let n = problem.dimension();
        let factored = problem.factored().is_some();
        let size = if factored { 0 } else { n + 1 };
        Workspace {
            n,
            matrix: Mat::zeros(size, size),
            factored,
            lazy: !factored && problem.completes_jacobian(),
            singular: false,
            border: if factored { vec![0.0; n] } else { Vec::new() },
            dr_dlambda: vec![0.0; n],
            residual: vec![0.0; n],
            rhs: vec![0.0; n + 1],
            pivots: PivotedLu::new(size),
            holds_jacobian: false,
            holds_bordered_factors: false,
            split: None,
            split_active: false,
            factors_split: false,
            border_scaled: vec![0.0; n],
        }
    }

    /// After the problem wrote a dense Jacobian: is it block diagonal, and in which blocks?
    fn note_blocks<P: Problem + ?Sized>(&mut self, problem: &P) {
        self.split_active = match problem.decoupled_unknowns() {
            Some(a) if !a.is_empty() && a.len() < self.n => {
                if self.split.as_ref().is_none_or(|split| split.a != a) {
                    self.split = Some(Split::new(a, self.n));
                }
                if let Some(split) = self.split.as_mut() {
                    split.identity = problem.decoupled_block_is_identity();
                }
                true
            }
            _ => false,
        };
    }

    /// Evaluate `problem` at `(x, λ)`: the residual into `self.residual` and, with
    /// `with_jacobian`, `∂R/∂λ` and `∂R/∂x` (dense into the matrix, or factored by the problem).
    pub fn evaluate<P: Problem + ?Sized>(
        &mut self,
        problem: &mut P,
        x: &[f64],
        lambda: f64,
        with_jacobian: bool,
    ) -> Result<(), ProblemError> {
        let n = self.n;
        self.dr_dlambda.iter_mut().for_each(|v| *v = 0.0);
        self.holds_jacobian = false;
        if !with_jacobian {
            return problem.evaluate(x, lambda, &mut self.residual, None);
        }
        if self.factored {
            let factored = problem.factored().expect("the problem said it factors its Jacobian");
            self.singular = !factored.evaluate_and_factor(x, lambda, &mut self.residual, &mut self.dr_dlambda)?;
            return Ok(());
        }
        let mut jx = self.matrix.as_mut().submatrix_mut(0, 0, n, n);
        jx.fill(0.0);
        self.holds_bordered_factors = false;
        problem.evaluate(x, lambda, &mut self.residual, Some((jx, &mut self.dr_dlambda)))?;
        self.note_blocks(problem);
        self.holds_jacobian = true;
        Ok(())
    }

    /// Does the (dense) matrix hold the Jacobian of the last evaluation, not yet factored?
    pub fn holds_jacobian(&self) -> bool {
        self.holds_jacobian
    }

    /// Does the problem factor `∂R/∂x` itself (no dense matrix here)?
    pub fn factors(&self) -> bool {
        self.factored
    }

    /// `∂R/∂x` and `∂R/∂λ` of the last evaluation with the Jacobian (dense; before any solve,
    /// which factors the matrix in place).
    pub fn jacobian(&self) -> (MatRef<'_, f64>, &[f64]) {
        (self.matrix.as_ref().submatrix(0, 0, self.n, self.n), &self.dr_dlambda)
    }

    /// `∂R/∂x` (dense, into the matrix) and `∂R/∂λ` at the point of the last evaluation, which
    /// was of the residual alone (only when [`Self::lazy`]).
    pub fn complete<P: Problem + ?Sized>(&mut self, problem: &mut P) -> Result<(), ProblemError> {
        let n = self.n;
        let mut jx = self.matrix.as_mut().submatrix_mut(0, 0, n, n);
        if !problem.completion_writes_every_entry() {
            self.dr_dlambda.iter_mut().for_each(|v| *v = 0.0);
            jx.fill(0.0);
        }
        self.holds_jacobian = false;
        self.holds_bordered_factors = false;
        problem.complete_jacobian((jx, &mut self.dr_dlambda))?;
        self.note_blocks(problem);
        self.holds_jacobian = true;
        Ok(())
    }

    /// Solve the bordered system of Eq. 32 in scaled variables,
    /// `[∂R/∂x·s_x/s_R  ∂R/∂λ·s_λ/s_R; tᵀ] Δz = rhs`, with the Jacobian of the last
    /// evaluation. A dense solve scales the Jacobian in place (it is not held after). Returns
    /// false when the solution is not finite (singular bordered matrix).
    pub fn solve_bordered<P: Problem + ?Sized>(
        &mut self,
        problem: &mut P,
        x_scale: f64,
        lambda_scale: f64,
        residual_scale: f64,
        t: &[f64],
    ) -> bool {
        let n = self.n;
        let cx = x_scale / residual_scale;
        let cl = lambda_scale / residual_scale;
        if self.factored {
            // [cx J  cl r_λ; t_xᵀ t_λ] [a; α] = [b; β]: with y₁ = J⁻¹ b / cx and
            // y₂ = J⁻¹ r_λ · cl / cx, α = (β − t_xᵀ y₁) / (t_λ − t_xᵀ y₂) and a = y₁ − α y₂.
            let Some(factored) = problem.factored().filter(|_| !self.singular) else { return false };
            self.border.copy_from_slice(&self.dr_dlambda);
            if !factored.solve(&mut self.rhs[..n]) || !factored.solve(&mut self.border) {
                return false;
            }
            let (mut t_y1, mut t_y2) = (0.0, 0.0);
            for i in 0..n {
                self.rhs[i] /= cx;
                self.border[i] *= cl / cx;
                t_y1 += t[i] * self.rhs[i];
                t_y2 += t[i] * self.border[i];
            }
            let alpha = (self.rhs[n] - t_y1) / (t[n] - t_y2);
            for i in 0..n {
                self.rhs[i] -= alpha * self.border[i];
            }
            self.rhs[n] = alpha;
            return self.rhs.iter().all(|v| v.is_finite());
        }
        if let Some(split) = self.split.as_mut().filter(|_| self.split_active) {
            self.border_scaled.iter_mut().zip(&self.dr_dlambda).for_each(|(b, r)| *b = r * cl);
            let jacobian = self.matrix.as_ref().submatrix(0, 0, n, n);
            split.factor_bordered(jacobian, cx, &self.border_scaled, t);
            split.solve_bordered(&mut self.rhs);
            self.holds_jacobian = false;
            self.holds_bordered_factors = true;
            self.factors_split = true;
            return self.rhs.iter().all(|v| v.is_finite());
        }
        for j in 0..n {
            // A contiguous column at a time (this scales every Jacobian the corrector solves).
            let column = self.matrix.col_as_slice_mut(j);
            column[..n].iter_mut().for_each(|v| *v *= cx);
        }
        for i in 0..n {
            self.matrix[(i, n)] = self.dr_dlambda[i] * cl;
        }
        for (j, &tj) in t.iter().enumerate() {
            self.matrix[(n, j)] = tj;
        }
        let solved = self.factor_and_solve(n + 1);
        self.holds_bordered_factors = true;
        self.factors_split = false;
        solved
    }

    /// Does the (dense) matrix hold the LU factors of the last bordered system solved, no
    /// evaluation with the Jacobian since?
    pub fn holds_bordered_factors(&self) -> bool {
        self.holds_bordered_factors
    }

    /// Solve `rhs` again with the factors of the last bordered system (only when
    /// [`Self::holds_bordered_factors`]), in place. False if the solution is not finite.
    pub fn solve_with_bordered_factors(&mut self) -> bool {
        if let Some(split) = self.split.as_mut().filter(|_| self.factors_split) {
            split.solve_bordered(&mut self.rhs);
            return self.rhs.iter().all(|v| v.is_finite());
        }
        let size = self.n + 1;
        self.pivots.solve(&mut self.rhs[..size]);
        self.rhs.iter().all(|v| v.is_finite())
    }

    /// Solve `∂R/∂x·s_x/s_R Δu = rhs[..n]` (a Newton step at fixed λ).
    pub fn solve_fixed<P: Problem + ?Sized>(&mut self, problem: &mut P, x_scale: f64, residual_scale: f64) -> bool {
        let n = self.n;
        let cx = x_scale / residual_scale;
        if self.factored {
            let Some(factored) = problem.factored().filter(|_| !self.singular) else { return false };
            if !factored.solve(&mut self.rhs[..n]) {
                return false;
            }
            self.rhs[..n].iter_mut().for_each(|v| *v /= cx);
            return self.rhs[..n].iter().all(|v| v.is_finite());
        }
        if let Some(split) = self.split.as_mut().filter(|_| self.split_active) {
            let jacobian = self.matrix.as_ref().submatrix(0, 0, n, n);
            split.solve_fixed(jacobian, cx, &mut self.rhs[..n]);
            self.holds_jacobian = false;
            self.holds_bordered_factors = false;
            return self.rhs[..n].iter().all(|v| v.is_finite());
        }
        for j in 0..n {
            for i in 0..n {
                self.matrix[(i, j)] *= cx;
            }
        }
        self.factor_and_solve(n)
    }

    /// The determinant of the bordered matrix of the last [`Self::solve_bordered`], from its
    /// LU factors `P A = L U` (L unit lower triangular): the product of U's diagonal, negated
    /// for an odd number of row transpositions. `None` for a problem that factors its own
    /// Jacobian (the bordered matrix is never formed).
    pub fn bordered_determinant(&self) -> Option<Determinant> {
        if self.factored {
            return None;
        }
        if let Some(split) = self.split.as_ref().filter(|_| self.factors_split) {
            return Some(split.bordered_determinant());
        }
        Some(self.pivots.determinant())
    }

    fn factor_and_solve(&mut self, size: usize) -> bool {
        self.holds_jacobian = false;
        self.holds_bordered_factors = false;
        self.pivots.factor(self.matrix.as_ref().submatrix(0, 0, size, size));
        self.pivots.solve(&mut self.rhs[..size]);
        self.rhs[..size].iter().all(|v| v.is_finite())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `R(x, λ) = J x − λ c` with a Jacobian block diagonal in the unknowns {0, 2, 3} and
    /// {1, 4}, declared as such or not; with `identity`, the first block is the identity
    /// (declared so with the blocks).
    struct Blocks {
        declare: bool,
        identity: bool,
    }

    const A: [usize; 3] = [0, 2, 3];

    fn jacobian(i: usize, j: usize, identity: bool) -> f64 {
        let same = A.contains(&i) == A.contains(&j);
        if !same {
            0.0
        } else if identity && A.contains(&i) {
            f64::from(i == j)
        } else if i == j {
            3.0 + i as f64
        } else {
            ((i * 7 + j * 3) % 5) as f64 * 0.4 - 0.8
        }
    }

    impl Problem for Blocks {
        fn dimension(&self) -> usize {
            5
        }

        fn evaluate(
            &mut self,
            x: &[f64],
            lambda: f64,
            residual: &mut [f64],
            jacobian_out: Option<(MatMut<'_, f64>, &mut [f64])>,
        ) -> Result<(), ProblemError> {
            let c = [1.0, -2.0, 0.5, 0.25, 3.0];
            for i in 0..5 {
                residual[i] = (0..5).map(|j| jacobian(i, j, self.identity) * x[j]).sum::<f64>() - lambda * c[i];
            }
            if let Some((mut dx, dl)) = jacobian_out {
                for i in 0..5 {
                    for j in 0..5 {
                        dx[(i, j)] = jacobian(i, j, self.identity);
                    }
                    dl[i] = -c[i];
                }
            }
            Ok(())
        }

        fn decoupled_unknowns(&self) -> Option<&[usize]> {
            self.declare.then_some(&A[..])
        }

        fn decoupled_block_is_identity(&self) -> bool {
            self.identity
        }
    }

    /// The bordered system and a solve at fixed λ give the same solution (to 1e-14 of it) and
    /// the same bordered determinant (to 1e-13 in its logarithm, and its sign) whether the
    /// Jacobian's two blocks are factored apart or the whole matrix is; so does a second
    /// right-hand side solved with the factors kept. A first block declared the identity is
    /// not factored, its solves divided by `c_x` (here 0.5) and its determinant `c_x³`: the
    /// same again.
    #[test]
    fn split_blocks_solve_as_the_whole_matrix() {
        for identity in [false, true] {
            split_blocks_solve_as_the_whole_matrix_with(identity);
        }
    }

    fn split_blocks_solve_as_the_whole_matrix_with(identity: bool) {
        let t = [0.3, -0.1, 0.7, 0.2, -0.5, 0.6];
        let rhs = [1.0, 2.0, -1.0, 0.5, 0.25, -0.75];
        let mut results = Vec::new();
        for declare in [false, true] {
            let mut problem = Blocks { declare, identity };
            let mut ws = Workspace::new(&mut problem);
            ws.evaluate(&mut problem, &[0.1, 0.2, 0.3, 0.4, 0.5], 1.5, true).unwrap();
            assert_eq!(ws.split_active, declare);
            assert_eq!(ws.split.as_ref().is_some_and(|split| split.identity), declare && identity);
            ws.rhs.copy_from_slice(&rhs);
            assert!(ws.solve_bordered(&mut problem, 2.0, 0.5, 4.0, &t));
            let bordered = ws.rhs.clone();
            let determinant = ws.bordered_determinant().unwrap();
            ws.rhs.copy_from_slice(&t);
            assert!(ws.solve_with_bordered_factors());
            let again = ws.rhs.clone();
            ws.evaluate(&mut problem, &[0.1, 0.2, 0.3, 0.4, 0.5], 1.5, true).unwrap();
            ws.rhs[..5].copy_from_slice(&rhs[..5]);
            assert!(ws.solve_fixed(&mut problem, 2.0, 4.0));
            let fixed = ws.rhs[..5].to_vec();
            results.push((bordered, determinant, again, fixed));
        }
        let (whole, split) = (&results[0], &results[1]);
        let close = |a: &[f64], b: &[f64]| {
            let scale = a.iter().map(|v| v.abs()).fold(0.0, f64::max);
            a.iter().zip(b).all(|(x, y)| (x - y).abs() <= 1e-14 * scale)
        };
        assert!(close(&whole.0, &split.0), "{:?} against {:?}", whole.0, split.0);
        assert!(close(&whole.2, &split.2), "{:?} against {:?}", whole.2, split.2);
        assert!(close(&whole.3, &split.3), "{:?} against {:?}", whole.3, split.3);
        assert_eq!(whole.1.sign, split.1.sign);
        assert!((whole.1.ln_abs - split.1.ln_abs).abs() <= 1e-13, "{:?} against {:?}", whole.1, split.1);
    }
}
