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
//! A block counts as invariant when its entries coupling different harmonics are below
//! `1e-10` of its largest entry (a stuck element's are round-off of the AFT); neglecting them
//! changes the Newton step by as much, far below the continuation's tolerance.

use faer::linalg::solvers::Solve;
use faer::Mat;

use super::fourier::{cos_index, sin_index};
use super::receptance::HarmonicReceptance;

/// Relative size of the harmonic couplings below which an element's block is invariant.
const INVARIANT: f64 = 1e-10;

/// Harmonic of coefficient `c` in the coefficient-major layout (0: constant, then cos k, sin k).
fn harmonic_of(c: usize) -> usize {
    c.div_ceil(2)
}

/// Position of coefficient `c`, direction `i`, inside its harmonic's block (size q for the
/// constant, 2q for k ≥ 1: cosines then sines).
fn local(c: usize, i: usize, width: usize) -> usize {
    if c > 0 && c % 2 == 0 {
        width + i
    } else {
        i
    }
}

/// The factored Jacobian `I + H B` of one iterate.
pub struct StructuredJacobian {
    q: usize,
    n_coeffs: usize,
    /// LU of `A_k` per harmonic (k = 0..=N).
    blocks: Vec<faer::linalg::solvers::PartialPivLu<f64>>,
    /// The directions of the elements that couple harmonics, and for each element of N its
    /// first direction in this list and its global offset.
    n_dirs: Vec<usize>,
    n_elements: Vec<(usize, usize, usize)>,
    /// `C_k = A_k⁻¹ H_k E_N` per harmonic.
    coupling: Vec<Mat<f64>>,
    /// LU of `M`, or `None` when every element is invariant.
    reduced: Option<faer::linalg::solvers::PartialPivLu<f64>>,
    /// Each element's block of `B` (for the elements of N).
    element_jacobians: Vec<Mat<f64>>,
    /// Scratch of size (2N+1) q_N.
    reduced_rhs: Mat<f64>,
}

/// `H_k` in real form: the constant block `H(0)` (q × q), or `[[Re H, Im H], [−Im H, Re H]]`.
fn real_block(k: usize, h0: &Mat<f64>, harmonic: &[HarmonicReceptance]) -> Mat<f64> {
    if k == 0 {
        return h0.clone();
    }
    let h = &harmonic[k - 1].h;
    let q = h.nrows();
    Mat::from_fn(2 * q, 2 * q, |i, j| {
        let v = h[(i % q, j % q)];
        match (i < q, j < q) {
            (true, true) | (false, false) => v.re,
            (true, false) => v.im,
            (false, true) => -v.im,
        }
    })
}

impl StructuredJacobian {
    /// Factor `I + H B` from the harmonic receptances (`h0` = H(0), `harmonic[k−1]` = H(kΩ)
    /// with its matrix evaluated) and the elements' blocks `element_jacobians` (element `e`
    /// on directions `offsets[e]..offsets[e] + dims[e]`). `None` if a block is singular.
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
        let invariant: Vec<bool> =
            element_jacobians.iter().zip(&dims).map(|(j, &d)| couples_no_harmonics(j, d)).collect();
        let mut n_dirs = Vec::new();
        let mut n_elements = Vec::new();
        for (e, &inv) in invariant.iter().enumerate() {
            if !inv {
                n_elements.push((e, n_dirs.len(), offsets[e]));
                n_dirs.extend(offsets[e]..offsets[e] + dims[e]);
            }
        }
        let qn = n_dirs.len();
        let mut blocks = Vec::with_capacity(n_harmonics + 1);
        let mut coupling = Vec::with_capacity(n_harmonics + 1);
        for k in 0..=n_harmonics {
            let hk = real_block(k, h0, harmonic);
            let coeffs: Vec<usize> = if k == 0 { vec![0] } else { vec![cos_index(k), sin_index(k)] };
            let size = hk.nrows();
            // A_k = I + H_k B_L,k: each invariant element adds H_k's columns on its
            // directions times its block within harmonic k.
            let mut a = Mat::<f64>::identity(size, size);
            for (e, je) in element_jacobians.iter().enumerate() {
                if !invariant[e] {
                    continue;
                }
                let d = dims[e];
                for &c2 in &coeffs {
                    for b in 0..d {
                        let col = local(c2, offsets[e] + b, q);
                        for &c1 in &coeffs {
                            for a_dir in 0..d {
                                let v = je[(c1 * d + a_dir, c2 * d + b)];
                                if v != 0.0 {
                                    let src = local(c1, offsets[e] + a_dir, q);
                                    for i in 0..size {
                                        a[(i, col)] += hk[(i, src)] * v;
                                    }
                                }
                            }
                        }
                    }
                }
            }
            let lu = a.partial_piv_lu();
            // C_k = A_k⁻¹ H_k E_N (columns of N's directions within harmonic k).
            let cols: Vec<usize> = coeffs.iter().flat_map(|&c| n_dirs.iter().map(move |&i| local(c, i, q))).collect();
            let hn = Mat::from_fn(size, cols.len(), |i, j| hk[(i, cols[j])]);
            let ck = lu.solve(&hn);
            if !ck.col_iter().all(|c| c.iter().all(|v| v.is_finite())) {
                return None;
            }
            blocks.push(lu);
            coupling.push(ck);
        }
        // M = I + (E_Nᵀ C) B_N on the coefficient-major N unknowns c·q_N + j.
        let reduced = (qn > 0).then(|| {
            let mut m = Mat::<f64>::identity(nc * qn, nc * qn);
            for &(e, first, _) in &n_elements {
                let (je, d) = (&element_jacobians[e], dims[e]);
                for c_col in 0..nc {
                    for b in 0..d {
                        let col = c_col * qn + first + b;
                        for c2 in 0..nc {
                            let k = harmonic_of(c2);
                            let ck = &coupling[k];
                            let rows: &[usize] = if k == 0 { &[0] } else { &[cos_index(k), sin_index(k)] };
                            for a_dir in 0..d {
                                let v = je[(c2 * d + a_dir, c_col * d + b)];
                                if v == 0.0 {
                                    continue;
                                }
                                let src = local(c2, first + a_dir, qn);
                                for &c1 in rows {
                                    for i in 0..qn {
                                        let row = local(c1, n_dirs[i], q);
                                        m[(c1 * qn + i, col)] += ck[(row, src)] * v;
                                    }
                                }
                            }
                        }
                    }
                }
            }
            m.partial_piv_lu()
        });
        Some(StructuredJacobian {
            q,
            n_coeffs: nc,
            blocks,
            element_jacobians: n_elements.iter().map(|&(e, _, _)| element_jacobians[e].clone()).collect(),
            n_dirs,
            n_elements,
            coupling,
            reduced,
            reduced_rhs: Mat::zeros(nc * qn, 1),
        })
    }

    /// Number of directions that couple harmonics at this iterate (q_N).
    pub fn coupled_directions(&self) -> usize {
        self.n_dirs.len()
    }

    /// Overwrite `b` ((2N+1) q, coefficient-major) with `J⁻¹ b`; false if the result is not
    /// finite.
    pub fn solve(&mut self, b: &mut [f64]) -> bool {
        let (q, nc, qn) = (self.q, self.n_coeffs, self.n_dirs.len());
        // w = A⁻¹ b, harmonic by harmonic.
        for (k, lu) in self.blocks.iter().enumerate() {
            let coeffs: &[usize] = if k == 0 { &[0] } else { &[cos_index(k), sin_index(k)] };
            let size = coeffs.len() * q;
            let rhs = Mat::from_fn(size, 1, |i, _| b[coeffs[i / q] * q + i % q]);
            let w = lu.solve(&rhs);
            for i in 0..size {
                b[coeffs[i / q] * q + i % q] = w[(i, 0)];
            }
        }
        if let Some(reduced) = &self.reduced {
            // u = M⁻¹ E_Nᵀ w, then v = B_N u and b = w − C v.
            for c in 0..nc {
                for (j, &dir) in self.n_dirs.iter().enumerate() {
                    self.reduced_rhs[(c * qn + j, 0)] = b[c * q + dir];
                }
            }
            let u = reduced.solve(&self.reduced_rhs);
            let mut v = vec![0.0; nc * qn];
            for (&(_, first, _), je) in self.n_elements.iter().zip(&self.element_jacobians) {
                let d = je.nrows() / nc;
                for c1 in 0..nc {
                    for a in 0..d {
                        let mut s = 0.0;
                        for c2 in 0..nc {
                            for bb in 0..d {
                                s += je[(c1 * d + a, c2 * d + bb)] * u[(c2 * qn + first + bb, 0)];
                            }
                        }
                        v[c1 * qn + first + a] = s;
                    }
                }
            }
            for (k, ck) in self.coupling.iter().enumerate() {
                let coeffs: &[usize] = if k == 0 { &[0] } else { &[cos_index(k), sin_index(k)] };
                let vk = Mat::from_fn(coeffs.len() * qn, 1, |j, _| v[coeffs[j / qn] * qn + j % qn]);
                let cv = ck * &vk;
                for i in 0..coeffs.len() * q {
                    b[coeffs[i / q] * q + i % q] -= cv[(i, 0)];
                }
            }
        }
        b.iter().all(|v| v.is_finite())
    }
}

/// Does the block couple no two harmonics (entries between different harmonics negligible)?
fn couples_no_harmonics(je: &Mat<f64>, d: usize) -> bool {
    let n = je.nrows();
    let mut largest = 0.0_f64;
    for j in 0..n {
        for i in 0..n {
            largest = largest.max(je[(i, j)].abs());
        }
    }
    (0..n).all(|j| (0..n).all(|i| harmonic_of(i / d) == harmonic_of(j / d) || je[(i, j)].abs() <= INVARIANT * largest))
}
