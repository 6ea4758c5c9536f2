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
//! relative (an inexact Newton step far below the continuation's tolerance).
//!
//! **A factored `M`, reused.** Where the mean stiffness is a poor preconditioner (every
//! direction of Harmony's blade patches slips within the period: 66 iterations on average, one
//! solve in seven not converged within 300), `M` is formed and factored, in single precision
//! ([`ReducedFactor`]), and preconditions every later solve of that Jacobian (the continuation
//! solves two right-hand sides per Newton iterate, Eq. 32: about 2 iterations each) and of
//! the next Jacobians on the same coupled directions: from one Newton iterate or one point to
//! the next `M` changes little (the slip and separation intervals move by a few samples), and
//! about 7 iterations correct it. Where `FACTORED_MAX` iterations do not, `M` is factored
//! afresh. On Harmony's blade patches (q = 156, N = 7, 2340 unknowns: a single-precision LU
//! of 0.14 s, an iteration 4 ms) a Newton iterate costs 0.12 s instead of 0.6 s.
//!
//! A block counts as invariant when its entries coupling different harmonics are below
//! `1e-10` of its largest entry (a stuck element's are round-off of the AFT); neglecting them
//! changes the Newton step by as much, far below the continuation's tolerance.

use faer::dyn_stack::{MemBuffer, MemStack, StackReq};
use faer::linalg::solvers::{PartialPivLu, Solve};
use faer::matrix_free::bicgstab::{bicgstab, bicgstab_scratch, BicgParams};
use faer::matrix_free::{InitialGuessStatus, LinOp, Precond};
use faer::{c64, Mat, MatMut, MatRef, Par};
use std::sync::{Arc, OnceLock};

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

/// Iterations allowed to a solve preconditioned by a factored `M` (this Jacobian's, or an
/// earlier one's) before `M` is factored afresh, or, for this Jacobian's own factor, solved in
/// double precision: each iteration costs two triangular solves of the factor.
const FACTORED_MAX: usize = 12;

/// A single-precision LU of the reduced system `M` on the coupled directions `n_dirs`, the
/// preconditioner of the iterative solves (module docs). Single precision halves the
/// factorisation and the memory each iteration reads (M is ~2300 square at q = 156, N = 7,
/// larger than the caches); as a preconditioner its ~1e-7 accuracy costs one or two more
/// iterations, and the iterations still converge to 1e-12 in double precision.
pub struct ReducedFactor {
    n_dirs: Vec<usize>,
    lu: PartialPivLu<f32>,
}

impl ReducedFactor {
    fn new(m: &Mat<f64>, n_dirs: &[usize]) -> Self {
        let single = Mat::<f32>::from_fn(m.nrows(), m.ncols(), |i, j| m[(i, j)] as f32);
        ReducedFactor { n_dirs: n_dirs.to_vec(), lu: single.partial_piv_lu() }
    }
}

impl std::fmt::Debug for ReducedFactor {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("ReducedFactor").field("coupled_directions", &self.n_dirs.len()).finish()
    }
}

/// Harmonic of coefficient `c` in the coefficient-major layout (0: constant, then cos k, sin k).
fn harmonic_of(c: usize) -> usize {
    c.div_ceil(2)
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
    /// An earlier Jacobian's factored `M` on the same directions: the iterative solves'
    /// preconditioner.
    earlier: Option<Arc<ReducedFactor>>,
    /// This Jacobian's factored `M`, once an iterative solve needed it.
    own: OnceLock<Arc<ReducedFactor>>,
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
    /// on directions `offsets[e]..`, `(2N+1) d` square). `earlier`: a factored `M` of an
    /// earlier Jacobian ([`Self::reduced_factor`]), used as the preconditioner if its coupled
    /// directions are these. `None` if a factor is singular.
    pub fn factor(
        q: usize,
        h0: &Mat<f64>,
        harmonic: &[HarmonicReceptance],
        offsets: &[usize],
        element_jacobians: &[Mat<f64>],
        earlier: Option<Arc<ReducedFactor>>,
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
        let earlier = earlier.filter(|f| matches!(reduced, Some(Reduced::Iterative(_))) && f.n_dirs == n_dirs);
        Some(StructuredJacobian {
            q,
            n_coeffs: nc,
            blocks,
            n_dirs,
            n_elements,
            coupling,
            reduced,
            earlier,
            own: OnceLock::new(),
        })
    }

    /// The factored `M` this Jacobian formed, or else the earlier one it used: to hand to the
    /// next Jacobian.
    pub fn reduced_factor(&self) -> Option<Arc<ReducedFactor>> {
        self.own.get().or(self.earlier.as_ref()).cloned()
    }

    /// Form and keep the factored `M` now, for the next solves of this Jacobian and the next
    /// Jacobians on the same directions, rather than when an iterative solve first fails
    /// (`M` solved iteratively only; a no-op otherwise).
    pub fn factor_reduced(&self) {
        if matches!(self.reduced, Some(Reduced::Iterative(_))) {
            self.own.get_or_init(|| {
                let m = reduced_matrix(self.n_coeffs, &self.n_dirs, &self.n_elements, &self.coupling);
                Arc::new(ReducedFactor::new(&m, &self.n_dirs))
            });
        }
    }

    /// `M⁻¹ y` when `M` is solved iteratively (module docs): preconditioned by this Jacobian's
    /// factor if formed, else by the earlier factor or the mean stiffness; where that does not
    /// converge, with this Jacobian's factor formed; where even that does not, by a
    /// double-precision LU of `M`.
    fn solve_iteratively(&self, op: &ReducedOperator, y: MatRef<'_, f64>) -> Mat<f64> {
        let iterated = match (self.own.get(), &self.earlier) {
            (Some(own), _) => {
                return op
                    .solve(&self.n_elements, y, &SingleFactor(&own.lu), FACTORED_MAX)
                    .unwrap_or_else(|| self.solve_directly(y))
            }
            (None, Some(earlier)) => op.solve(&self.n_elements, y, &SingleFactor(&earlier.lu), FACTORED_MAX),
            (None, None) => op.solve(&self.n_elements, y, &ReducedPreconditioner(op), ITERATIVE_MAX),
        };
        iterated.unwrap_or_else(|| {
            self.factor_reduced();
            self.solve_iteratively(op, y)
        })
    }

    /// `M⁻¹ y` by a double-precision LU of `M`, formed for this solve alone (the last resort).
    fn solve_directly(&self, y: MatRef<'_, f64>) -> Mat<f64> {
        reduced_matrix(self.n_coeffs, &self.n_dirs, &self.n_elements, &self.coupling).partial_piv_lu().solve(y)
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
            Reduced::Iterative(op) => self.solve_iteratively(op, y.as_ref()),
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

    /// `M⁻¹ y` by BiCGSTAB right-preconditioned by `preconditioner`, `None` if it does not
    /// converge within `max_iters`; `elements` as the Jacobian's.
    fn solve(
        &self,
        elements: &[(usize, Mat<f64>)],
        y: MatRef<'_, f64>,
        preconditioner: &impl Precond<f64>,
        max_iters: usize,
    ) -> Option<Mat<f64>> {
        let n = self.nc * self.qn;
        let mut u = Mat::<f64>::zeros(n, 1);
        let identity = faer::matrix_free::IdentityPrecond { dim: n };
        let params = BicgParams {
            // From u = 0, passed as a guess: faer 0.24's `Zero` leaves the first residual unset.
            initial_guess: InitialGuessStatus::MaybeNonZero,
            rel_tolerance: ITERATIVE_TOLERANCE,
            max_iters,
            ..Default::default()
        };
        let matrix = ReducedMatrix(self, elements);
        let scratch = bicgstab_scratch(identity, preconditioner, &matrix, 1, Par::Seq);
        let mut buffer = MemBuffer::new(scratch);
        let result = bicgstab(
            u.as_mut(),
            identity,
            preconditioner,
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
    let mut product = Vec::new();
    for (first, je) in elements {
        let d = je.nrows() / nc;
        // Column by column (the block is column-major), so that the inner loop runs over
        // contiguous entries: this product is most of an iteration of the reduced solve.
        product.clear();
        product.resize(nc * d, 0.0);
        for (column, block_column) in je.col_iter().enumerate() {
            let x = u[(column / d) * qn + first + column % d];
            if x == 0.0 {
                continue;
            }
            let entries = block_column.try_as_col_major().expect("a contiguous column").as_slice();
            for (p, m) in product.iter_mut().zip(entries) {
                *p += m * x;
            }
        }
        for (row, p) in product.iter().enumerate() {
            v[(row / d) * qn + first + row % d] = *p;
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

/// A factored `M` in single precision as the preconditioner (module docs).
#[derive(Debug)]
struct SingleFactor<'a>(&'a PartialPivLu<f32>);

impl LinOp<f64> for SingleFactor<'_> {
    fn apply_scratch(&self, _rhs_ncols: usize, _par: Par) -> StackReq {
        StackReq::EMPTY
    }
    fn nrows(&self) -> usize {
        self.0.L().nrows()
    }
    fn ncols(&self) -> usize {
        self.0.L().nrows()
    }
    fn apply(&self, mut out: MatMut<'_, f64>, rhs: MatRef<'_, f64>, _par: Par, _stack: &mut MemStack) {
        let mut single = Mat::<f32>::from_fn(rhs.nrows(), rhs.ncols(), |i, j| rhs[(i, j)] as f32);
        self.0.solve_in_place(single.as_mut());
        for j in 0..rhs.ncols() {
            for i in 0..rhs.nrows() {
                out[(i, j)] = f64::from(single[(i, j)]);
            }
        }
    }
    fn conj_apply(&self, out: MatMut<'_, f64>, rhs: MatRef<'_, f64>, par: Par, stack: &mut MemStack) {
        self.apply(out, rhs, par, stack)
    }
}

impl Precond<f64> for SingleFactor<'_> {}

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
/// in real form (`[[Re, Im], [−Im, Re]]` per harmonic). Each entry of `B_N` adds a column of
/// that real form, which spans its harmonic's rows, contiguous in `M`'s column: one update of
/// 2 q_N entries per entry, so that forming `M` stays small against its LU.
fn reduced_matrix(nc: usize, n_dirs: &[usize], n_elements: &[(usize, Mat<f64>)], coupling: &[Mat<c64>]) -> Mat<f64> {
    let qn = n_dirs.len();
    // G_k in real form: rows and columns (cos, sin) × q_N (the constant alone at k = 0).
    let real: Vec<Mat<f64>> = coupling
        .iter()
        .enumerate()
        .map(|(k, ck)| {
            let width = if k == 0 { qn } else { 2 * qn };
            Mat::from_fn(width, width, |r, c| {
                let v = ck[(n_dirs[r % qn], c % qn)];
                match (r / qn, c / qn) {
                    (0, 0) | (1, 1) => v.re,
                    (0, 1) => v.im,
                    _ => -v.im,
                }
            })
        })
        .collect();
    let mut m = Mat::<f64>::identity(nc * qn, nc * qn);
    for (first, je) in n_elements {
        let d = je.nrows() / nc;
        for (block_col, entries) in je.col_iter().enumerate() {
            let column = m.col_mut((block_col / d) * qn + first + block_col % d);
            let column = column.try_as_col_major_mut().expect("a contiguous column").as_slice_mut();
            for (row, &v) in entries.iter().enumerate() {
                if v == 0.0 {
                    continue;
                }
                let (c2, a) = (row / d, row % d);
                let k = harmonic_of(c2);
                let (start, local) = if k == 0 { (0, 0) } else { (cos_index(k) * qn, c2 - cos_index(k)) };
                let g = real[k].col(local * qn + first + a);
                let g = g.try_as_col_major().expect("a contiguous column").as_slice();
                for (target, gv) in column[start..start + g.len()].iter_mut().zip(g) {
                    *target += gv * v;
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
