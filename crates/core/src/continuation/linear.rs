//! The linear systems of the corrector: the bordered `(n+1)×(n+1)` system of Eq. 32 and the
//! `n×n` system of a solve at fixed λ. Dense: factored by partial-pivot LU in place on buffers
//! allocated once per branch (no allocation per Newton iteration). For a problem that factors
//! its own Jacobian ([`Problem::factored`]): by block elimination of the border, two solves
//! with `∂R/∂x`.

use faer::dyn_stack::{MemBuffer, MemStack, StackReq};
use faer::linalg::lu::partial_pivoting::{factor, solve};
use faer::{Mat, MatMut, MatRef, Par};

use super::singular::Determinant;
use super::{Problem, ProblemError};

/// Workspace for the corrector: Jacobian buffers, LU factors and right-hand side.
pub(super) struct Workspace {
    n: usize,
    /// Column-major `(n+1)×(n+1)`: `[∂R/∂x ∂R/∂λ; tᵀ]`, factored in place.
    matrix: Mat<f64>,
    /// ∂R/∂λ as the problem writes it.
    pub dr_dlambda: Vec<f64>,
    pub residual: Vec<f64>,
    /// Right-hand side, overwritten by the solution.
    pub rhs: Vec<f64>,
    perm: Vec<usize>,
    perm_inv: Vec<usize>,
    /// Row transpositions of the last dense factorisation (the sign of its permutation).
    transpositions: usize,
    /// Dense: `matrix` holds the Jacobian of the last evaluation, not yet factored.
    holds_jacobian: bool,
    /// Dense: `matrix` holds the LU factors of the last bordered system solved.
    holds_bordered_factors: bool,
    scratch: MemBuffer,
    /// The problem factors `∂R/∂x` itself (`matrix` is then empty).
    factored: bool,
    /// Dense, and the problem completes a residual evaluation to its Jacobian
    /// ([`Problem::completes_jacobian`]).
    pub lazy: bool,
    /// Factored: the last factorisation was singular.
    singular: bool,
    /// Factored: `(∂R/∂x)⁻¹ ∂R/∂λ` for the border.
    border: Vec<f64>,
}

impl Workspace {
    /// Buffers for `problem`, dense unless it factors its own Jacobian.
    pub fn new<P: Problem + ?Sized>(problem: &mut P) -> Self {
        let n = problem.dimension();
        let factored = problem.factored().is_some();
        let size = if factored { 0 } else { n + 1 };
        let par = Par::Seq;
        let req = StackReq::any_of(&[
            factor::lu_in_place_scratch::<usize, f64>(size, size, par, Default::default()),
            solve::solve_in_place_scratch::<usize, f64>(size, 1, par),
        ]);
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
            perm: vec![0; n + 1],
            perm_inv: vec![0; n + 1],
            transpositions: 0,
            holds_jacobian: false,
            holds_bordered_factors: false,
            scratch: MemBuffer::new(req),
        }
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
        self.dr_dlambda.iter_mut().for_each(|v| *v = 0.0);
        let mut jx = self.matrix.as_mut().submatrix_mut(0, 0, n, n);
        jx.fill(0.0);
        self.holds_jacobian = false;
        self.holds_bordered_factors = false;
        problem.complete_jacobian((jx, &mut self.dr_dlambda))?;
        self.holds_jacobian = true;
        Ok(())
    }

    /// Solve the bordered system of Eq. 32 in scaled variables,
    /// `[∂R/∂x·s_x/s_R  ∂R/∂λ·s_λ/s_R; tᵀ] Δz = rhs`, with the Jacobian of the last
    /// evaluation. A dense factorisation destroys the Jacobian. Returns false when the
    /// solution is not finite (singular bordered matrix).
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
        let size = self.n + 1;
        let lu = self.matrix.as_ref();
        let perm = faer::perm::PermRef::new_checked(&self.perm[..size], &self.perm_inv[..size], size);
        let rhs = MatMut::from_column_major_slice_mut(&mut self.rhs[..size], size, 1);
        solve::solve_in_place(lu, lu, perm, rhs, Par::Seq, MemStack::new(&mut self.scratch));
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
        let mut determinant = Determinant { sign: if self.transpositions & 1 == 0 { 1.0 } else { -1.0 }, ln_abs: 0.0 };
        for i in 0..=self.n {
            let pivot = self.matrix[(i, i)];
            determinant.sign *= if pivot == 0.0 { 0.0 } else { pivot.signum() };
            determinant.ln_abs += pivot.abs().ln();
        }
        Some(determinant)
    }

    fn factor_and_solve(&mut self, size: usize) -> bool {
        self.holds_jacobian = false;
        self.holds_bordered_factors = false;
        let par = Par::Seq;
        let mut a = self.matrix.as_mut().submatrix_mut(0, 0, size, size);
        let stack = MemStack::new(&mut self.scratch);
        let (info, perm) = factor::lu_in_place(
            a.as_mut(),
            &mut self.perm[..size],
            &mut self.perm_inv[..size],
            par,
            stack,
            Default::default(),
        );
        self.transpositions = info.transposition_count;
        let lu = a.as_ref();
        let rhs = MatMut::from_column_major_slice_mut(&mut self.rhs[..size], size, 1);
        solve::solve_in_place(lu, lu, perm, rhs, par, MemStack::new(&mut self.scratch));
        self.rhs[..size].iter().all(|v| v.is_finite())
    }
}
