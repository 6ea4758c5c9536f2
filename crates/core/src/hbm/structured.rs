//! Newton systems of the condensed balance solved by their structure, for contact patches of
//! many directions where the dense `(2N+1)q` LU is the whole cost.
//!
//! The Jacobian of [`super::CondensedHbm`] is `J = I + H B`: `H` is block diagonal over the
//! harmonics (the linear part, shared by every element) and `B = ∂G/∂x` block diagonal over
//! the elements. An element whose tangent stiffness does not change over the period (a contact
//! stuck for the whole cycle, one open for the whole cycle, a linear spring) does not couple
//! harmonics: its block is block diagonal over the harmonics too, and it is part of the linear
//! dynamics at this iterate. With `L` those elements and `N` the others (slipping or separating
//! for part of the period):
//!
//! ```text
//! A = I + H B_L                  block diagonal over harmonics: one LU of size 2q per harmonic
//! C = A⁻¹ H E_N                  (E_N selects the directions of N)
//! M = I + (E_Nᵀ C) B_N           dense, (2N+1) q_N square
//! J⁻¹ b = w − C B_N M⁻¹ E_Nᵀ w,  w = A⁻¹ b
//! ```
//!
//! which is exact (Woodbury's identity on `J = A + H E_N B_N E_Nᵀ`). The cost falls from
//! O((N q)³) to O(N q³ + (N q_N)³): most of a patch sticks at moderate amplitude, and only the
//! nodes that slip or lift off enter the dense system.
//!
//! **Iterative reduced system.** When every direction of a large patch slips or opens in the
//! period, `M` is the whole `(2N+1) q` system and its dense LU the whole cost (1.7 s at q = 300,
//! N = 7). Above `DIRECT_UP_TO` unknowns `M` is not formed: `M u = y` is solved by BiCGSTAB
//! (faer's `matrix_free::bicgstab`), `M` applied as `u + G (B_N u)` (`G = E_Nᵀ C`, block
//! diagonal over harmonics; `B_N` block diagonal over elements), right-preconditioned by
//! `P = I + G B̄` with `B̄` the part of `B_N` that does not couple harmonics, in complex form (the
//! mean stiffness of each element over the period): one complex LU of size q_N per harmonic.
//! The time-varying part of the stiffness is what the iterations resolve. Converged to 1e-12
//! relative (an inexact Newton step far below the continuation's tolerance); if it is not,
//! `M` is formed and factored as below it.
//!
//! A block counts as invariant when its entries coupling different harmonics are below
//! `1e-10` of its largest entry (a stuck element's are round-off of the AFT); neglecting them
//! changes the Newton step by as much, far below the continuation's tolerance.

use faer::dyn_stack::{MemBuffer, MemStack, StackReq};
use faer::linalg::solvers::{PartialPivLu, Solve};
use faer::matrix_free::bicgstab::{bicgstab, bicgstab_scratch, BicgParams};
use faer::matrix_free::{InitialGuessStatus, LinOp, Precond};
use faer::{c64, Mat, MatMut, MatRef, Par};

use super::fourier::{cos_index, sin_index};
use super::receptance::HarmonicReceptance;

/// Relative size of the harmonic couplings below which an element's block is invariant.
const INVARIANT: f64 = 1e-10;

/// Largest reduced system `M` ((2N+1) q_N unknowns) factored densely; above, it is solved
/// iteratively (module docs). At 1200 unknowns the dense LU takes ~30 ms.
const DIRECT_UP_TO: usize = 1200;

/// Relative residual of the iterative solve of `M`, and its iteration limit.
const ITERATIVE_TOLERANCE: f64 = 1e-12;
const ITERATIVE_MAX: usize = 300;

/// Harmonic of coefficient `c` in the coefficient-major layout (0: constant, then cos k, sin k).
fn harmonic_of(c: usize) -> usize {
    c.div_ceil(2)
}

/// The coefficients of harmonic k: the constant, or its cosine and sine (no allocation: this
/// runs for every entry of the reduced matrix).
fn coefficients(k: usize) -> impl Iterator<Item = usize> {
    let (first, second) = if k == 0 { (0, None) } else { (cos_index(k), Some(sin_index(k))) };
    std::iter::once(first).chain(second)
}

/// The factored Jacobian `I + H B` of one iterate.
///
/// Per harmonic k the unknowns of the linear part are complex, `x_k = c − i s` (the layout of
/// [`super::condensed`]): an invariant element's block is then the complex `K_cc + i K_cs`
/// (its real form `[[K_cc, K_cs], [−K_cs, K_cc]]`), and `A_k` one complex q × q matrix.
pub struct StructuredJacobian {
    q: usize,
    n_coeffs: usize,
    /// LU of the complex `A_k` per harmonic (k = 0..=N).
    blocks: Vec<PartialPivLu<c64>>,
    /// The directions of the elements that couple harmonics.
    n_dirs: Vec<usize>,
    /// For each element that couples harmonics: its first position in `n_dirs` and its block of
    /// `B` ((2N+1) d square).
    n_elements: Vec<(usize, Mat<f64>)>,
    /// `C_k = A_k⁻¹ H_k E_N` per harmonic (complex q × q_N).
    coupling: Vec<Mat<c64>>,
    /// `M`'s solver, or `None` when every element is invariant.
    reduced: Option<Reduced>,
}

/// How `M u = y` is solved.
enum Reduced {
    /// LU of `M`.
    Dense(PartialPivLu<f64>),
    /// BiCGSTAB on `M` with the harmonic-block preconditioner (module docs).
    Iterative(Box<ReducedOperator>),
}

impl StructuredJacobian {
    /// Factor `I + H B` from the harmonic receptances (`h0` = H(0), `harmonic[k−1]` = H(kΩ)
    /// with its matrix evaluated) and the elements' blocks `element_jacobians` (element `e`
    /// on directions `offsets[e]..`, `(2N+1) d` square). `None` if a factor is singular.
    pub fn factor(
        q: usize,
        h0: &Mat<f64>,
        harmonic: &[HarmonicReceptance],
        offsets: &[usize],
        element_jacobians: &[Mat<f64>],
    ) -> Option<Self> {
        let n_harmonics = harmonic.len();
        let nc = 2 * n_harmonics + 1;
        let dims: Vec<usize> = element_jacobians.iter().map(|j| j.nrows() / nc).collect();
        let invariant: Vec<bool> = element_jacobians.iter().zip(&dims).map(|(j, &d)| is_invariant(j, d)).collect();
        let mut n_dirs = Vec::new();
        let mut n_elements = Vec::new();
        for (e, &inv) in invariant.iter().enumerate() {
            if !inv {
                n_elements.push((n_dirs.len(), element_jacobians[e].clone()));
                n_dirs.extend(offsets[e]..offsets[e] + dims[e]);
            }
        }
        let qn = n_dirs.len();
        let mut blocks = Vec::with_capacity(n_harmonics + 1);
        let mut coupling = Vec::with_capacity(n_harmonics + 1);
        for k in 0..=n_harmonics {
            let h = |i: usize, j: usize| if k == 0 { c64::new(h0[(i, j)], 0.0) } else { harmonic[k - 1].h[(i, j)] };
            let (c, s) = if k == 0 { (0, 0) } else { (cos_index(k), sin_index(k)) };
            // A_k = I + H_k B_L,k: each invariant element adds H_k's columns on its directions
            // times its complex block.
            let mut a = Mat::<c64>::identity(q, q);
            for (e, je) in element_jacobians.iter().enumerate() {
                if !invariant[e] {
                    continue;
                }
                let (d, off) = (dims[e], offsets[e]);
                for col in 0..d {
                    for row in 0..d {
                        let re = je[(c * d + row, c * d + col)];
                        let im = if k == 0 { 0.0 } else { je[(c * d + row, s * d + col)] };
                        if re == 0.0 && im == 0.0 {
                            continue;
                        }
                        let b = c64::new(re, im);
                        for i in 0..q {
                            a[(i, off + col)] += h(i, off + row) * b;
                        }
                    }
                }
            }
            let lu = a.partial_piv_lu();
            let hn = Mat::from_fn(q, qn, |i, j| h(i, n_dirs[j]));
            let ck = lu.solve(&hn);
            if !ck.col_iter().all(|c| c.iter().all(|v| v.re.is_finite() && v.im.is_finite())) {
                return None;
            }
            blocks.push(lu);
            coupling.push(ck);
        }
        let reduced = (qn > 0).then(|| {
            if nc * qn <= DIRECT_UP_TO {
                Reduced::Dense(reduced_matrix(nc, &n_dirs, &n_elements, &coupling).partial_piv_lu())
            } else {
                Reduced::Iterative(Box::new(ReducedOperator::new(nc, &n_dirs, &n_elements, &coupling)))
            }
        });
        Some(StructuredJacobian { q, n_coeffs: nc, blocks, n_dirs, n_elements, coupling, reduced })
    }

    /// Number of directions that couple harmonics at this iterate (q_N).
    pub fn coupled_directions(&self) -> usize {
        self.n_dirs.len()
    }

    /// Overwrite `b` ((2N+1) q, coefficient-major) with `J⁻¹ b`; false if the result is not
    /// finite.
    pub fn solve(&self, b: &mut [f64]) -> bool {
        let (q, nc, qn) = (self.q, self.n_coeffs, self.n_dirs.len());
        // w = A⁻¹ b, harmonic by harmonic, in the complex form c − i s.
        for (k, lu) in self.blocks.iter().enumerate() {
            let w = lu.solve(Mat::from_fn(q, 1, |i, _| complex_at(b, q, k, i)));
            for i in 0..q {
                set_complex(b, q, k, i, w[(i, 0)]);
            }
        }
        let Some(reduced) = &self.reduced else { return b.iter().all(|v| v.is_finite()) };
        // u = M⁻¹ E_Nᵀ w (real, coefficient-major on the N directions), v = B_N u.
        let y = Mat::from_fn(nc * qn, 1, |row, _| b[(row / qn) * q + self.n_dirs[row % qn]]);
        let u = match reduced {
            Reduced::Dense(lu) => lu.solve(&y),
            Reduced::Iterative(op) => match op.solve(&self.n_elements, y.as_ref()) {
                Some(u) => u,
                // Not converged: M formed and factored after all.
                None => reduced_matrix(nc, &self.n_dirs, &self.n_elements, &self.coupling).partial_piv_lu().solve(&y),
            },
        };
        let mut v = vec![0.0; nc * qn];
        apply_elements(nc, qn, &self.n_elements, u.col(0).try_as_col_major().expect("one column").as_slice(), &mut v);
        // b = w − C v.
        for (k, ck) in self.coupling.iter().enumerate() {
            let cv = ck * Mat::from_fn(qn, 1, |j, _| complex_at(&v, qn, k, j));
            for i in 0..q {
                let w = complex_at(b, q, k, i);
                set_complex(b, q, k, i, w - cv[(i, 0)]);
            }
        }
        b.iter().all(|v| v.is_finite())
    }
}

/// `M = I + G B_N` applied without forming it, and its preconditioner `P = I + G B̄` factored
/// per harmonic (module docs).
struct ReducedOperator {
    nc: usize,
    qn: usize,
    /// `G_k = E_Nᵀ C_k` per harmonic (complex q_N square).
    g: Vec<Mat<c64>>,
    /// LU of `P_k` per harmonic.
    precond: Vec<PartialPivLu<c64>>,
}

impl std::fmt::Debug for ReducedOperator {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("ReducedOperator").field("nc", &self.nc).field("qn", &self.qn).finish()
    }
}

impl ReducedOperator {
    fn new(nc: usize, n_dirs: &[usize], n_elements: &[(usize, Mat<f64>)], coupling: &[Mat<c64>]) -> Self {
        let qn = n_dirs.len();
        let g: Vec<Mat<c64>> = coupling.iter().map(|ck| Mat::from_fn(qn, qn, |i, j| ck[(n_dirs[i], j)])).collect();
        let precond = g
            .iter()
            .enumerate()
            .map(|(k, gk)| {
                // P_k = I + G_k B̄_k: each element's mean complex block on its columns.
                let mut p = Mat::<c64>::identity(qn, qn);
                for (first, je) in n_elements {
                    let d = je.nrows() / nc;
                    for col in 0..d {
                        for row in 0..d {
                            let b = mean_complex(je, d, k, row, col);
                            if b == c64::new(0.0, 0.0) {
                                continue;
                            }
                            for i in 0..qn {
                                p[(i, first + col)] += gk[(i, first + row)] * b;
                            }
                        }
                    }
                }
                p.partial_piv_lu()
            })
            .collect();
        ReducedOperator { nc, qn, g, precond }
    }

    /// `M⁻¹ y` by BiCGSTAB, `None` if it does not converge; `elements` as the Jacobian's.
    fn solve(&self, elements: &[(usize, Mat<f64>)], y: MatRef<'_, f64>) -> Option<Mat<f64>> {
        let n = self.nc * self.qn;
        let mut u = Mat::<f64>::zeros(n, 1);
        let identity = faer::matrix_free::IdentityPrecond { dim: n };
        let params = BicgParams {
            // From u = 0, passed as a guess: faer 0.24's `Zero` leaves the first residual unset.
            initial_guess: InitialGuessStatus::MaybeNonZero,
            rel_tolerance: ITERATIVE_TOLERANCE,
            max_iters: ITERATIVE_MAX,
            ..Default::default()
        };
        let (matrix, preconditioner) = (ReducedMatrix(self, elements), ReducedPreconditioner(self));
        let scratch = bicgstab_scratch(identity, &preconditioner, &matrix, 1, Par::Seq);
        let mut buffer = MemBuffer::new(scratch);
        let result = bicgstab(
            u.as_mut(),
            identity,
            &preconditioner,
            &matrix,
            y,
            params,
            |_| {},
            Par::Seq,
            MemStack::new(&mut buffer),
        );
        (result.is_ok() && u.col(0).iter().all(|v| v.is_finite())).then_some(u)
    }
}

/// `v = B_N u` (real, coefficient-major on the `q_N` directions of the elements that couple
/// harmonics, each at its first position).
fn apply_elements(nc: usize, qn: usize, elements: &[(usize, Mat<f64>)], u: &[f64], v: &mut [f64]) {
    for (first, je) in elements {
        let d = je.nrows() / nc;
        for c1 in 0..nc {
            for a in 0..d {
                let mut sum = 0.0;
                for c2 in 0..nc {
                    for bb in 0..d {
                        sum += je[(c1 * d + a, c2 * d + bb)] * u[c2 * qn + first + bb];
                    }
                }
                v[c1 * qn + first + a] = sum;
            }
        }
    }
}

/// The complex form (`x_k = c − i s`) of the part of an element's block that does not couple
/// harmonics, at harmonic k, entry (row, col): `(K_cc + K_ss)/2 + i (K_cs − K_sc)/2`, exact for
/// an invariant block.
fn mean_complex(je: &Mat<f64>, d: usize, k: usize, row: usize, col: usize) -> c64 {
    if k == 0 {
        return c64::new(je[(row, col)], 0.0);
    }
    let (c, s) = (cos_index(k) * d, sin_index(k) * d);
    c64::new(
        0.5 * (je[(c + row, c + col)] + je[(s + row, s + col)]),
        0.5 * (je[(c + row, s + col)] - je[(s + row, c + col)]),
    )
}

/// `M` as an operator for the iterative solver, with the elements that couple harmonics.
#[derive(Debug)]
struct ReducedMatrix<'a>(&'a ReducedOperator, &'a [(usize, Mat<f64>)]);

/// `P⁻¹` as an operator for the iterative solver.
#[derive(Debug)]
struct ReducedPreconditioner<'a>(&'a ReducedOperator);

impl LinOp<f64> for ReducedMatrix<'_> {
    fn apply_scratch(&self, _rhs_ncols: usize, _par: Par) -> StackReq {
        StackReq::EMPTY
    }
    fn nrows(&self) -> usize {
        self.0.nc * self.0.qn
    }
    fn ncols(&self) -> usize {
        self.0.nc * self.0.qn
    }
    /// `M u = u + G (B_N u)`.
    fn apply(&self, mut out: MatMut<'_, f64>, rhs: MatRef<'_, f64>, _par: Par, _stack: &mut MemStack) {
        let op = self.0;
        let (n, qn) = (op.nc * op.qn, op.qn);
        for col in 0..rhs.ncols() {
            let u: Vec<f64> = (0..n).map(|i| rhs[(i, col)]).collect();
            let mut v = vec![0.0; n];
            apply_elements(op.nc, qn, self.1, &u, &mut v);
            let mut w = vec![0.0; n];
            for (k, gk) in op.g.iter().enumerate() {
                let gv = gk * Mat::from_fn(qn, 1, |j, _| complex_at(&v, qn, k, j));
                for i in 0..qn {
                    set_complex(&mut w, qn, k, i, gv[(i, 0)]);
                }
            }
            for i in 0..n {
                out[(i, col)] = u[i] + w[i];
            }
        }
    }
    fn conj_apply(&self, out: MatMut<'_, f64>, rhs: MatRef<'_, f64>, par: Par, stack: &mut MemStack) {
        self.apply(out, rhs, par, stack)
    }
}

impl LinOp<f64> for ReducedPreconditioner<'_> {
    fn apply_scratch(&self, _rhs_ncols: usize, _par: Par) -> StackReq {
        StackReq::EMPTY
    }
    fn nrows(&self) -> usize {
        self.0.nc * self.0.qn
    }
    fn ncols(&self) -> usize {
        self.0.nc * self.0.qn
    }
    /// `P⁻¹ y`, harmonic by harmonic.
    fn apply(&self, mut out: MatMut<'_, f64>, rhs: MatRef<'_, f64>, _par: Par, _stack: &mut MemStack) {
        let op = self.0;
        let (n, qn) = (op.nc * op.qn, op.qn);
        for col in 0..rhs.ncols() {
            let mut x: Vec<f64> = (0..n).map(|i| rhs[(i, col)]).collect();
            for (k, lu) in op.precond.iter().enumerate() {
                let z = lu.solve(Mat::from_fn(qn, 1, |j, _| complex_at(&x, qn, k, j)));
                for i in 0..qn {
                    set_complex(&mut x, qn, k, i, z[(i, 0)]);
                }
            }
            for (i, v) in x.into_iter().enumerate() {
                out[(i, col)] = v;
            }
        }
    }
    fn conj_apply(&self, out: MatMut<'_, f64>, rhs: MatRef<'_, f64>, par: Par, stack: &mut MemStack) {
        self.apply(out, rhs, par, stack)
    }
}

impl Precond<f64> for ReducedPreconditioner<'_> {}

/// `c − i s` of harmonic k, direction i, in a coefficient-major vector of width `width`.
fn complex_at(x: &[f64], width: usize, k: usize, i: usize) -> c64 {
    if k == 0 {
        c64::new(x[i], 0.0)
    } else {
        c64::new(x[cos_index(k) * width + i], -x[sin_index(k) * width + i])
    }
}

fn set_complex(x: &mut [f64], width: usize, k: usize, i: usize, v: c64) {
    if k == 0 {
        x[i] = v.re;
    } else {
        x[cos_index(k) * width + i] = v.re;
        x[sin_index(k) * width + i] = -v.im;
    }
}

/// `M = I + (E_Nᵀ C) B_N` on the real coefficient-major N unknowns `c·q_N + j`, with `E_Nᵀ C`
/// in real form (`[[Re, Im], [−Im, Re]]` per harmonic).
fn reduced_matrix(nc: usize, n_dirs: &[usize], n_elements: &[(usize, Mat<f64>)], coupling: &[Mat<c64>]) -> Mat<f64> {
    let qn = n_dirs.len();
    // G (real form) at (row coefficient c1, N-row i; column coefficient c2, N-column j).
    let g = |c1: usize, i: usize, c2: usize, j: usize| -> f64 {
        let k = harmonic_of(c1);
        let v = coupling[k][(n_dirs[i], j)];
        if k == 0 {
            return v.re;
        }
        match (c1 % 2 == 1, c2 % 2 == 1) {
            (true, true) | (false, false) => v.re,
            (true, false) => v.im,
            (false, true) => -v.im,
        }
    };
    let mut m = Mat::<f64>::identity(nc * qn, nc * qn);
    for (first, je) in n_elements {
        let d = je.nrows() / nc;
        for c_col in 0..nc {
            for b in 0..d {
                let col = c_col * qn + first + b;
                for c2 in 0..nc {
                    for a in 0..d {
                        let v = je[(c2 * d + a, c_col * d + b)];
                        if v == 0.0 {
                            continue;
                        }
                        for c1 in coefficients(harmonic_of(c2)) {
                            for i in 0..qn {
                                m[(c1 * qn + i, col)] += g(c1, i, c2, first + a) * v;
                            }
                        }
                    }
                }
            }
        }
    }
    m
}

/// Is the block time-invariant over the period: no coupling between different harmonics, and
/// within harmonic k the real form of a complex number (`K_ss = K_cc`, `K_sc = −K_cs`), all to
/// [`INVARIANT`] of its largest entry?
fn is_invariant(je: &Mat<f64>, d: usize) -> bool {
    let n = je.nrows();
    let mut largest = 0.0_f64;
    for j in 0..n {
        for i in 0..n {
            largest = largest.max(je[(i, j)].abs());
        }
    }
    let tol = INVARIANT * largest;
    let n_harmonics = (n / d - 1) / 2;
    let coupled = (0..n).any(|j| (0..n).any(|i| harmonic_of(i / d) != harmonic_of(j / d) && je[(i, j)].abs() > tol));
    let not_complex = (1..=n_harmonics).any(|k| {
        let (c, s) = (cos_index(k) * d, sin_index(k) * d);
        (0..d).any(|a| {
            (0..d).any(|b| {
                (je[(s + a, s + b)] - je[(c + a, c + b)]).abs() > tol
                    || (je[(s + a, c + b)] + je[(c + a, s + b)]).abs() > tol
            })
        })
    });
    !(coupled || not_complex)
}
