//! The dense linear systems of the corrector: the bordered `(n+1)×(n+1)` system of Eq. 32 and
//! the `n×n` system of a solve at fixed λ, factored by partial-pivot LU in place on buffers
//! allocated once per branch (no allocation per Newton iteration).

use faer::dyn_stack::{MemBuffer, MemStack, StackReq};
use faer::linalg::lu::partial_pivoting::{factor, solve};
use faer::{Mat, MatMut, Par};

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
    scratch: MemBuffer,
}

impl Workspace {
    pub fn new(n: usize) -> Self {
        let par = Par::Seq;
        let req = StackReq::any_of(&[
            factor::lu_in_place_scratch::<usize, f64>(n + 1, n + 1, par, Default::default()),
            solve::solve_in_place_scratch::<usize, f64>(n + 1, 1, par),
        ]);
        Workspace {
            n,
            matrix: Mat::zeros(n + 1, n + 1),
            dr_dlambda: vec![0.0; n],
            residual: vec![0.0; n],
            rhs: vec![0.0; n + 1],
            perm: vec![0; n + 1],
            perm_inv: vec![0; n + 1],
            scratch: MemBuffer::new(req),
        }
    }

    /// The residual buffer and zeroed ∂R/∂x, ∂R/∂λ buffers for the problem to fill.
    pub fn evaluation_buffers(&mut self) -> (&mut [f64], MatMut<'_, f64>, &mut [f64]) {
        let n = self.n;
        let mut jx = self.matrix.as_mut().submatrix_mut(0, 0, n, n);
        jx.fill(0.0);
        self.dr_dlambda.iter_mut().for_each(|v| *v = 0.0);
        (&mut self.residual, jx, &mut self.dr_dlambda)
    }

    /// Solve the bordered system of Eq. 32 in scaled variables,
    /// `[∂R/∂x·s_x/s_R  ∂R/∂λ·s_λ/s_R; tᵀ] Δz = rhs`, with the Jacobian the problem last wrote.
    /// The factorisation destroys the Jacobian. Returns false when the solution is not finite
    /// (singular bordered matrix).
    pub fn solve_bordered(&mut self, x_scale: f64, lambda_scale: f64, residual_scale: f64, t: &[f64]) -> bool {
        let n = self.n;
        let cx = x_scale / residual_scale;
        let cl = lambda_scale / residual_scale;
        for j in 0..n {
            for i in 0..n {
                self.matrix[(i, j)] *= cx;
            }
        }
        for i in 0..n {
            self.matrix[(i, n)] = self.dr_dlambda[i] * cl;
        }
        for (j, &tj) in t.iter().enumerate() {
            self.matrix[(n, j)] = tj;
        }
        self.factor_and_solve(n + 1)
    }

    /// Solve `∂R/∂x·s_x/s_R Δu = rhs[..n]` (a Newton step at fixed λ).
    pub fn solve_fixed(&mut self, x_scale: f64, residual_scale: f64) -> bool {
        let n = self.n;
        let cx = x_scale / residual_scale;
        for j in 0..n {
            for i in 0..n {
                self.matrix[(i, j)] *= cx;
            }
        }
        self.factor_and_solve(n)
    }

    fn factor_and_solve(&mut self, size: usize) -> bool {
        let par = Par::Seq;
        let mut a = self.matrix.as_mut().submatrix_mut(0, 0, size, size);
        let stack = MemStack::new(&mut self.scratch);
        let (_, perm) = factor::lu_in_place(
            a.as_mut(),
            &mut self.perm[..size],
            &mut self.perm_inv[..size],
            par,
            stack,
            Default::default(),
        );
        let lu = a.as_ref();
        let rhs = MatMut::from_column_major_slice_mut(&mut self.rhs[..size], size, 1);
        solve::solve_in_place(lu, lu, perm, rhs, par, MemStack::new(&mut self.scratch));
        self.rhs[..size].iter().all(|v| v.is_finite())
    }
}
