//! Stability of a periodic solution by Hill's method: its Floquet exponents from the harmonic
//! balance itself, with no time integration.
//!
//! A perturbation `y(t) = e^{st} p(t)` of the periodic motion, `p` T-periodic, obeys the linear
//! equation with periodic coefficients obtained by linearising the equation of motion about the
//! solution. Written in the harmonics `P` of `p` (the balance's real cos/sin basis), with `∇` the
//! time derivative on harmonics (`(c, s)_k ↦ kΩ (s, −c)_k`), it is the quadratic eigenproblem
//!
//! ```text
//! [ s² I + s (2∇ + C) + (∇² + C∇ + Λ + K_nl) ] P = 0
//! ```
//!
//! (Hill 1886; in harmonic-balance form, Lazarus & Thomas, C. R. Mécanique 338, 2010, and
//! Krack & Gross, *Harmonic Balance for Nonlinear Vibration Problems*, Springer 2019, ch. 5).
//!
//! **Why modal form.** The balance is solved in flexibility form (the residual is a
//! displacement, [`super::condensed`]), where `s` would enter through the receptance at the
//! complex frequencies `kΩ − is`: a rational, not a polynomial, eigenproblem. In the
//! coordinates of the mass-normalised modes of the linear model (the same modes the modal
//! receptance sums), `I` and `Λ = diag(ω_r²)` are diagonal, `C = Φᵀ D Φ` is diagonal
//! (`diag(c_r)`) for proportional or modal damping and full for a general damping matrix `D`
//! (the modal equations then stay coupled through it, the eigenproblem is the same), and the
//! joints enter through the low-rank term `K_nl = Aᵀ J A`, `A = Vᵀ Φ` (q × m) and `J = ∂G/∂x`
//! the elements' harmonic Jacobian that Newton already uses: the quadratic problem is
//! polynomial, of size `m(2N+1)`, and its companion form is an ordinary real eigenproblem.
//!
//! **Modes kept.** The first `m` modes carry the dynamics; the modes above act quasi-statically
//! through their residual flexibility `R = Σ_{r>m} a_r a_rᵀ / ω_r²` (a static correction), so the
//! joints' stiffness seen by the kept modes is `Aᵀ J (I + R J)⁻¹ A`. With every mode kept this is
//! Hill's method on the whole model; the default keeps the modes that a harmonic of the band can
//! reach (see [`HillSettings`]). With a general damping matrix, the modes left out of the kept
//! set are condensed the same way (statically: their damping, and its coupling to the kept
//! modes, are dropped), so the exponents are exact only when every mode is kept: a model
//! whose modes all lie below the `HillSettings` bound, as small models' do.
//!
//! **Sorting.** The truncated Hill matrix has `2m(2N+1)` eigenvalues, each physical exponent
//! repeated (approximately) at `s + ijΩ`. The `2m` with the smallest `|Im s|` are the
//! physical ones (Lazarus & Thomas' criterion); the solution is stable when all have a
//! negative real part.

use faer::{c64, Mat, MatRef};

use super::fourier::{cos_index, sin_index};
use super::receptance::Receptance;

/// Newton's steps on a refined exponent stop below this, relative to Ω (Hill's matrix is known
/// to ~1e-13 of its scale, the exponent to ~1e-12 Ω).
const CONVERGED: f64 = 1e-11;

/// An exponent refined by [`Hill::refine`], with its eigenvector (Hill's `P`, normalised so that
/// the start's `vᴴP = 1`) to start the same exponent at a neighbouring point.
#[derive(Clone, Debug, PartialEq)]
pub struct Refined {
    pub exponent: c64,
    pub vector: Vec<c64>,
    /// Newton steps taken.
    pub iterations: usize,
}

/// How many modes Hill's method keeps dynamic.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct HillSettings {
    /// Keep the modes whose natural frequency is below this (rad/s); the others act through
    /// their residual flexibility.
    pub max_omega: f64,
    /// At most this many modes (the eigenproblem costs O((2m(2N+1))³)).
    pub max_modes: usize,
}

impl HillSettings {
    /// The modes a harmonic of the balance can excite in the band up to `omega_max` (rad/s):
    /// natural frequencies up to `(N + 1) Ω_max`, at most 24.
    pub fn for_band(harmonics: usize, omega_max: f64) -> Self {
        HillSettings { max_omega: (harmonics as f64 + 1.0) * omega_max, max_modes: 24 }
    }
}

/// Real parts of Floquet exponents within this fraction of the exponents' largest |Im s|
/// (~Ω/2) count as equal when choosing the leading one ([`Stability::leading`]). Hill's
/// exponents agree with the reference's to ~3e-11 Ω (`stability_newton.rs`): a tie a few
/// hundred times wider than their round-off, and far below any difference of damping a user
/// tells apart.
pub const LEADING_TIE: f64 = 1e-8;

/// Why stability cannot be computed.
#[derive(Clone, Debug, thiserror::Error, PartialEq)]
pub enum StabilityError {
    #[error("the Hill eigenproblem ({size} × {size}) did not converge")]
    Eigen { size: usize },
    #[error("the joints' Jacobian has size {got}, expected {expected}")]
    JacobianSize { got: usize, expected: usize },
}

/// The Floquet exponents of one periodic solution.
#[derive(Clone, Debug, PartialEq)]
pub struct Stability {
    /// The physical exponents (1/s), largest real part first.
    pub exponents: Vec<c64>,
}

impl Stability {
    /// The exponent with the largest real part: it decides stability and, with its imaginary
    /// part, the kind of a bifurcation when it crosses zero (real: fold or branch point;
    /// complex pair: Neimark-Sacker). Real parts within [`LEADING_TIE`] times the exponents'
    /// largest |Im s| (at most Ω/2: the physical exponents lie in that strip) of the largest
    /// count as equal, and of those the one with the smallest |Im s| leads (of a conjugate
    /// pair, Im s ≥ 0): with mass-proportional damping every stuck mode decays at the same
    /// −α/2, and round-off alone would otherwise choose among them, so that the imaginary part
    /// written for a point could change from one run or build to the next.
    pub fn leading(&self) -> c64 {
        let largest_re = self.exponents.iter().fold(f64::NEG_INFINITY, |m, s| m.max(s.re));
        let tie = LEADING_TIE * self.exponents.iter().fold(0.0f64, |m, s| m.max(s.im.abs()));
        self.exponents
            .iter()
            .copied()
            .filter(|s| s.re >= largest_re - tie)
            .min_by(|a, b| a.im.abs().total_cmp(&b.im.abs()).then(b.im.total_cmp(&a.im)))
            .unwrap_or(c64::new(f64::NEG_INFINITY, 0.0))
    }

    /// Stable when every exponent has a negative real part, up to `tolerance` (1/s).
    pub fn is_stable(&self, tolerance: f64) -> bool {
        self.exponents.iter().all(|s| s.re <= tolerance)
    }

    /// Floquet multipliers `e^{sT}` at fundamental `omega` (rad/s).
    pub fn multipliers(&self, omega: f64) -> Vec<c64> {
        let period = 2.0 * std::f64::consts::PI / omega;
        self.exponents.iter().map(|s| (*s * period).exp()).collect()
    }
}

/// Hill's method for the solutions of one condensed balance: the modal data, prepared once.
#[derive(Clone, Debug)]
pub struct Hill {
    omega_r: Vec<f64>,
    /// The damping of the kept modes, `C = Φᵀ D Φ` (m × m: diagonal unless the model has a
    /// general damping matrix).
    damping: Mat<f64>,
    /// `Vᵀ φ_r` of the kept modes (q × m).
    a: Mat<f64>,
    /// Residual flexibility of the other modes on the directions (q × q).
    residual: Mat<f64>,
    /// Split a half-wave symmetric problem into its even and odd harmonics.
    split_parity: bool,
}

impl Hill {
    /// Prepare Hill's method on the modes of `receptance`'s linear model.
    pub fn new(receptance: &Receptance, settings: HillSettings) -> Result<Self, StabilityError> {
        let (omega_r, damping, a) = match receptance {
            Receptance::Modal(modal) => {
                let c_r = modal.damping_coefficients();
                let damping = Mat::from_fn(c_r.len(), c_r.len(), |r, l| if r == l { c_r[r] } else { 0.0 });
                (modal.natural_frequencies(), damping, modal.participation())
            }
            Receptance::Direct(direct) => {
                (direct.natural_frequencies(), direct.modal_damping(), direct.participation())
            }
        };
        let q = a.nrows();
        let kept = omega_r.iter().take_while(|&&w| w <= settings.max_omega).count().clamp(1, settings.max_modes);
        let kept = kept.min(omega_r.len());
        let residual = Mat::from_fn(q, q, |i, j| {
            (kept..omega_r.len()).map(|r| a[(i, r)] * a[(j, r)] / (omega_r[r] * omega_r[r])).sum()
        });
        Ok(Hill {
            omega_r: omega_r[..kept].to_vec(),
            damping: damping.submatrix(0, 0, kept, kept).to_owned(),
            a: a.subcols(0, kept).to_owned(),
            residual,
            split_parity: true,
        })
    }

    /// Number of modes kept dynamic.
    pub fn n_modes(&self) -> usize {
        self.omega_r.len()
    }

    /// Floquet exponents of the solution at fundamental `omega` (rad/s) whose joints' harmonic
    /// Jacobian is `jacobian` (`∂G/∂x`, q(2N+1) square, coefficient-major as the balance's
    /// unknowns: [`super::CondensedHbm::element_force_jacobian`]).
    pub fn exponents(&self, omega: f64, jacobian: MatRef<'_, f64>) -> Result<Stability, StabilityError> {
        Ok(self.exponents_in_blocks(omega, jacobian)?.0)
    }

    /// [`Self::exponents`], with the parity of the harmonics of each exponent's eigenvector
    /// (0 even, 1 odd) where Hill's matrix split into even and odd harmonics (`None` where it
    /// did not): the block [`Self::refine`] may then work in.
    pub fn exponents_in_blocks(
        &self,
        omega: f64,
        jacobian: MatRef<'_, f64>,
    ) -> Result<(Stability, Vec<Option<usize>>), StabilityError> {
        let complex = Mat::from_fn(jacobian.nrows(), jacobian.ncols(), |i, j| c64::new(jacobian[(i, j)], 0.0));
        let all = self.eigenvalues_in_blocks(omega, complex.as_ref(), None)?;
        let (exponents, blocks) = self.physical(all).into_iter().unzip();
        Ok((Stability { exponents }, blocks))
    }

    /// Every eigenvalue of Hill's problem with the joints' Jacobian `jacobian` (complex when
    /// it depends on the exponent: [`super::CondensedHbm::delayed_force_jacobian`]).
    pub fn eigenvalues(&self, omega: f64, jacobian: MatRef<'_, c64>) -> Result<Vec<c64>, StabilityError> {
        self.eigenvalues_of_block(omega, jacobian, None)
    }

    /// [`Self::eigenvalues`] of the parity block `block` (0 even, 1 odd harmonics) where
    /// Hill's matrix splits into two ([`Self::exponents_in_blocks`]), every one where it does
    /// not or `block` is `None`: an exponent's eigenvector stays in its block, so the
    /// exponents that continue it are there, for one eigenproblem of half the size.
    pub fn eigenvalues_of_block(
        &self,
        omega: f64,
        jacobian: MatRef<'_, c64>,
        block: Option<usize>,
    ) -> Result<Vec<c64>, StabilityError> {
        Ok(self.eigenvalues_in_blocks(omega, jacobian, block)?.into_iter().map(|(s, _)| s).collect())
    }

    /// The eigenvalues of the parity block `only`, or of both (`None`), each with the block it
    /// came from (`None`: not split).
    fn eigenvalues_in_blocks(
        &self,
        omega: f64,
        jacobian: MatRef<'_, c64>,
        only: Option<usize>,
    ) -> Result<Vec<(c64, Option<usize>)>, StabilityError> {
        let mut all = Vec::new();
        for (mut matrix, block) in self.companion_blocks(omega, jacobian, only)? {
            let n = matrix.nrows();
            let failed = StabilityError::Eigen { size: n };
            // A real Hill matrix (a periodic Jacobian) is solved as such: half the work.
            let eigenvalues = if is_real(&matrix) {
                let mut real = Mat::from_fn(n, n, |i, j| matrix[(i, j)].re);
                balance(&mut real, |v| v * v);
                real_eigenvalues(real).ok_or_else(|| failed.clone())?
            } else {
                balance(&mut matrix, |v| v.norm_sqr());
                matrix.eigenvalues().map_err(|_| failed.clone())?
            };
            if eigenvalues.iter().any(|s| !s.re.is_finite() || !s.im.is_finite()) {
                return Err(failed);
            }
            all.extend(eigenvalues.into_iter().map(|s| (s, block)));
        }
        Ok(all)
    }

    /// The eigenvalue of Hill's problem nearest `s`, in the parity block `block` where the
    /// matrix splits (both blocks where it does not or `block` is `None`), by inverse subspace
    /// iteration on the balanced companion matrix shifted by `s`: one complex LU and a few
    /// solves, where the whole spectrum is a complex Schur form, about ten LUs' work
    /// (Saad, *Numerical Methods for Large Eigenvalue Problems*, 2011, §5.1). `None` where the
    /// nearest Ritz pair has not converged (backward error 1e-12 of the matrix's norm) within
    /// `SUBSPACE_STEPS` (12) steps: the caller then takes the whole spectrum.
    pub fn nearest_eigenvalue(
        &self,
        omega: f64,
        jacobian: MatRef<'_, c64>,
        block: Option<usize>,
        s: c64,
    ) -> Result<Option<c64>, StabilityError> {
        use faer::linalg::solvers::Solve;
        let mut nearest: Option<c64> = None;
        for (mut matrix, _) in self.companion_blocks(omega, jacobian, block)? {
            balance(&mut matrix, |v| v.norm_sqr());
            let n = matrix.nrows();
            let norm = matrix.norm_l2();
            let p = SUBSPACE_SIZE.min(n);
            let mut shifted = matrix.clone();
            for i in 0..n {
                shifted[(i, i)] -= s;
            }
            let lu = shifted.partial_piv_lu();
            // A generic start: no symmetry of the harmonics can make it orthogonal to an
            // eigenvector.
            let mut basis = Mat::from_fn(n, p, |i, j| {
                let t = (i * (j + 1)) as f64;
                c64::new(1.0 + 0.37 * t.sin(), 0.23 * (0.7 * t + j as f64).cos())
            });
            let mut found = None;
            for _ in 0..SUBSPACE_STEPS {
                let next = lu.solve(&basis);
                if !next.col_iter().all(|c| c.iter().all(|v| v.re.is_finite() && v.im.is_finite())) {
                    break;
                }
                basis = next.qr().compute_thin_Q();
                let image = &matrix * &basis;
                let projected = basis.adjoint() * &image;
                let Ok(eigen) = projected.eigen() else { break };
                let (values, vectors) = (eigen.S(), eigen.U());
                let k = (0..p).min_by(|&a, &b| nearer(values[a], values[b], s));
                let Some(k) = k else { break };
                let (theta, y) = (values[k], vectors.col(k));
                let x = &basis * y;
                let residual = &image * y - &x * faer::Scale(theta);
                if residual.norm_l2() <= SUBSPACE_TOLERANCE * norm * x.norm_l2() {
                    found = Some(theta);
                    break;
                }
            }
            let Some(mut theta) = found else { return Ok(None) };
            // A real matrix about a real shift has its conjugate as near: the one above the
            // axis, as [`nearer`] orders them (the Ritz values are conjugate only to their
            // convergence, not to the tie's round-off).
            if s.im == 0.0 && theta.im < 0.0 && is_real(&matrix) {
                theta = theta.conj();
            }
            if nearest.is_none_or(|best| nearer(theta, best, s).is_lt()) {
                nearest = Some(theta);
            }
        }
        Ok(nearest)
    }

    /// Hill's companion matrix at Ω with the joints' Jacobian `jacobian`: its parity block
    /// `only` where it splits into even and odd harmonics (both for `None`), else the whole
    /// matrix, each with its block's parity (`None`: not split).
    fn companion_blocks(
        &self,
        omega: f64,
        jacobian: MatRef<'_, c64>,
        only: Option<usize>,
    ) -> Result<Vec<ParityBlock>, StabilityError> {
        let q = self.a.nrows();
        let m = self.n_modes();
        let nq = jacobian.nrows();
        if nq % q != 0 || jacobian.ncols() != nq || nq == 0 {
            return Err(StabilityError::JacobianSize { got: nq, expected: q });
        }
        let nc = nq / q;
        let harmonics = (nc - 1) / 2;
        let size = m * nc;
        let k_nl = self.joint_stiffness(jacobian);
        // Companion form of s² P + s Δ₁ P + Δ₀ P = 0: s [P; sP] = [0 I; −Δ₀ −Δ₁] [P; sP].
        let mut companion = Mat::<c64>::zeros(2 * size, 2 * size);
        for i in 0..size {
            companion[(i, size + i)] = c64::new(1.0, 0.0);
        }
        for row in 0..size {
            for col in 0..size {
                companion[(size + row, col)] = -k_nl[(row, col)];
            }
        }
        let real = |v: f64| c64::new(v, 0.0);
        for r in 0..m {
            let w2 = self.omega_r[r] * self.omega_r[r];
            // Harmonic 0: Δ₀ = Λ, Δ₁ = C.
            companion[(size + r, r)] -= real(w2);
            for k in 1..=harmonics {
                let kw = k as f64 * omega;
                let (ic, is) = (cos_index(k) * m + r, sin_index(k) * m + r);
                // ∇ (c, s) = kΩ (s, −c); ∇² = −(kΩ)².
                // Δ₀ = (Λ − (kΩ)²) I + C ∇,   Δ₁ = C + 2∇.
                companion[(size + ic, ic)] -= real(w2 - kw * kw);
                companion[(size + is, is)] -= real(w2 - kw * kw);
                companion[(size + ic, size + is)] -= real(2.0 * kw);
                companion[(size + is, size + ic)] += real(2.0 * kw);
            }
            for l in 0..m {
                let c = self.damping[(r, l)];
                if c == 0.0 {
                    continue;
                }
                companion[(size + r, size + l)] -= real(c);
                for k in 1..=harmonics {
                    let kw = k as f64 * omega;
                    let (ic, is) = (cos_index(k) * m, sin_index(k) * m);
                    companion[(size + ic + r, is + l)] -= real(c * kw);
                    companion[(size + is + r, ic + l)] += real(c * kw);
                    companion[(size + ic + r, size + ic + l)] -= real(c);
                    companion[(size + is + r, size + is + l)] -= real(c);
                }
            }
        }
        // Parity of the harmonic of companion row/column i.
        let parity = |i: usize| coefficient_parity((i % size) / m);
        if !(self.split_parity && half_wave_symmetric(&k_nl, |i| parity(i) == 1)) {
            return Ok(vec![(companion, None)]);
        }
        // Half-wave symmetry (x(t + T/2) = −x(t): an odd law, such as a Jenkins slider or a
        // cubic spring, driven at the fundamental without a static load) leaves only odd
        // harmonics in the solution and even ones in the joints' Jacobian, which then couples
        // harmonics of the same parity only (∂g/∂x(t) is T/2-periodic). Hill's matrix, whose
        // modal part is diagonal in the harmonics, then splits exactly into an even-harmonic
        // and an odd-harmonic block, and its spectrum is the union of theirs, at a quarter of
        // the cost (two eigenproblems of about half the size: 2 (n/2)³ against n³). The
        // sliders' memory keeps the symmetry: a stick phase and its mirror half a period later
        // have the same delay.
        let blocks = (0..2).filter(|&p| only.is_none_or(|only| only == p)).map(|p| {
            let block: Vec<usize> = (0..2 * size).filter(|&i| parity(i) == p).collect();
            (Mat::from_fn(block.len(), block.len(), |a, b| companion[(block[a], block[b])]), Some(p))
        });
        Ok(blocks.collect())
    }

    /// `K_nl = Aᵀ J (I + R J)⁻¹ A` per coefficient pair (size m(2N+1), mode-wide and
    /// coefficient-major): the joints' stiffness seen by the kept modes, the modes above them
    /// condensed statically. `jacobian` has been checked to be q(2N+1) square.
    fn joint_stiffness(&self, jacobian: MatRef<'_, c64>) -> Mat<c64> {
        use faer::linalg::solvers::Solve;
        let q = self.a.nrows();
        let m = self.n_modes();
        let nq = jacobian.nrows();
        let nc = nq / q;
        // Joints' stiffness on the directions, the modes above the kept ones condensed
        // statically: J (I + R J)⁻¹ (per coefficient, R acts on each harmonic alike).
        let mut i_rj = Mat::<c64>::identity(nq, nq);
        for c in 0..nc {
            for i in 0..q {
                for col in 0..nq {
                    let mut v = c64::new(0.0, 0.0);
                    for l in 0..q {
                        v += jacobian[(c * q + l, col)] * self.residual[(i, l)];
                    }
                    i_rj[(c * q + i, col)] += v;
                }
            }
        }
        // J (I + R J)⁻¹ = ((I + R J)⁻ᵀ Jᵀ)ᵀ.
        let effective = {
            let jt = jacobian.transpose().to_owned();
            let x = i_rj.transpose().to_owned().partial_piv_lu().solve(&jt);
            x.transpose().to_owned()
        };
        let size = m * nc;
        let mut ja = Mat::<c64>::zeros(nq, size);
        for c2 in 0..nc {
            for r in 0..m {
                for row in 0..nq {
                    let mut v = c64::new(0.0, 0.0);
                    for l in 0..q {
                        v += effective[(row, c2 * q + l)] * self.a[(l, r)];
                    }
                    ja[(row, c2 * m + r)] = v;
                }
            }
        }
        let mut k_nl = Mat::<c64>::zeros(size, size);
        for c1 in 0..nc {
            for r in 0..m {
                for col in 0..size {
                    let mut v = c64::new(0.0, 0.0);
                    for l in 0..q {
                        v += ja[(c1 * q + l, col)] * self.a[(l, r)];
                    }
                    k_nl[(c1 * m + r, col)] = v;
                }
            }
        }
        k_nl
    }

    /// Adds the modal part of Hill's quadratic matrix at `s`, `s² I + s Δ₁ + Δ₀`, to `t`
    /// (harmonic 0: `Δ₀ = Λ`, `Δ₁ = C`; harmonic k: `Δ₀ = (Λ − (kΩ)²) I + C ∇`,
    /// `Δ₁ = C + 2∇`, `∇ (c, s) = kΩ (s, −c)`): 2 × 2 blocks per mode and harmonic, coupled
    /// between modes by the off-diagonal terms of `C`. `at[c]` is where the balance's
    /// coefficient `c` lies among `t`'s (`None`: not in `t`, a block of the other parity); the
    /// part never couples two coefficients of different harmonics.
    fn add_modal(&self, omega: f64, s: c64, at: &[Option<usize>], t: &mut Mat<c64>) {
        let m = self.n_modes();
        let harmonics = (at.len() - 1) / 2;
        for r in 0..m {
            let w2 = self.omega_r[r] * self.omega_r[r];
            if let Some(c0) = at[0] {
                t[(c0 * m + r, c0 * m + r)] += s * s + w2;
            }
            for k in 1..=harmonics {
                let (Some(c), Some(sn)) = (at[cos_index(k)], at[sin_index(k)]) else { continue };
                let kw = k as f64 * omega;
                let (ic, is) = (c * m + r, sn * m + r);
                let diagonal = s * s + (w2 - kw * kw);
                t[(ic, ic)] += diagonal;
                t[(is, is)] += diagonal;
                t[(ic, is)] += s * (2.0 * kw);
                t[(is, ic)] -= s * (2.0 * kw);
            }
            for l in 0..m {
                let c = self.damping[(r, l)];
                if c == 0.0 {
                    continue;
                }
                if let Some(c0) = at[0] {
                    t[(c0 * m + r, c0 * m + l)] += s * c;
                }
                for k in 1..=harmonics {
                    let (Some(ck), Some(sk)) = (at[cos_index(k)], at[sin_index(k)]) else { continue };
                    let kw = k as f64 * omega;
                    let (ic, is) = (ck * m, sk * m);
                    t[(ic + r, ic + l)] += s * c;
                    t[(is + r, is + l)] += s * c;
                    t[(ic + r, is + l)] += c * kw;
                    t[(is + r, ic + l)] -= c * kw;
                }
            }
        }
    }

    /// `(2s I + Δ₁) x`: the derivative of the modal part of Hill's matrix in `s`, applied, with
    /// `x` laid out as [`Self::add_modal`]'s `t` by `at`.
    fn modal_derivative(&self, omega: f64, s: c64, at: &[Option<usize>], x: &[c64]) -> Vec<c64> {
        let m = self.n_modes();
        let harmonics = (at.len() - 1) / 2;
        let mut y = vec![c64::new(0.0, 0.0); x.len()];
        for r in 0..m {
            if let Some(c0) = at[0] {
                y[c0 * m + r] = s * 2.0 * x[c0 * m + r];
            }
            for k in 1..=harmonics {
                let (Some(c), Some(sn)) = (at[cos_index(k)], at[sin_index(k)]) else { continue };
                let kw2 = 2.0 * k as f64 * omega;
                let (ic, is) = (c * m + r, sn * m + r);
                y[ic] = s * 2.0 * x[ic] + x[is] * kw2;
                y[is] = s * 2.0 * x[is] - x[ic] * kw2;
            }
            for l in 0..m {
                let c = self.damping[(r, l)];
                if c == 0.0 {
                    continue;
                }
                for coefficient in at.iter().flatten() {
                    let base = coefficient * m;
                    y[base + r] += x[base + l] * c;
                }
            }
        }
        y
    }

    /// One Floquet exponent near `start` as an eigenvalue of the nonlinear Hill problem
    /// `T(s) P = [s² I + s Δ₁ + Δ₀ + K_nl(s)] P = 0`, `K_nl(s)` from `jacobian(s)` (the joints'
    /// Jacobian with the sliders' memory weighted at `s`; constant if `depends_on_s` is false).
    ///
    /// **Why not an eigensolver.** Only a few exponents need refining, each close to a known
    /// start (the periodic Jacobian's exponent): Newton's method on `T(s) P = 0, vᴴP = 1` (the
    /// nonlinear inverse iteration of Ruhe, SIAM J. Numer. Anal. 10, 1973, §3; quadratic for a
    /// simple eigenvalue) costs one complex LU of size m(2N+1) per step, where a dense
    /// eigensolver on the companion form (size 2m(2N+1)) costs tens of times as much for the
    /// whole spectrum. `P` starts from `vector`, or one inverse-iteration step from a generic
    /// vector. The derivative of `K_nl(s)` in `s` (the memory's `−Δ e^{−sΔ}`) is left out of
    /// Newton's step: the root is the same (`T(s)` singular), only the convergence becomes
    /// linear, at about the rate of the `s ← eigenvalue of Hill(J(s))` fixed point it replaces.
    /// Adding it by central differences (two more stiffness evaluations a step) cost more time
    /// than the steps it saved at paper size (15.8 against 10.3 ms a point, measured at the same load).
    ///
    /// With `block` (the parity of the start's eigenvector, from [`Self::exponents_in_blocks`])
    /// and a joints' Jacobian that keeps even and odd harmonics apart, Newton works in that
    /// block of `T(s)` alone (LUs of half the size); the vector returned is Hill's whole `P`.
    ///
    /// `None` if the iteration does not settle within `max_iterations` (to `1e-11 Ω`, or to
    /// round-off, where the steps stop decreasing below `1e-8 Ω`).
    #[allow(clippy::too_many_arguments)]
    pub fn refine(
        &self,
        omega: f64,
        start: c64,
        vector: Option<&[c64]>,
        block: Option<usize>,
        depends_on_s: bool,
        max_iterations: usize,
        mut jacobian: impl FnMut(c64) -> Mat<c64>,
    ) -> Result<Option<Refined>, StabilityError> {
        use faer::linalg::solvers::Solve;
        let q = self.a.nrows();
        let m = self.n_modes();
        let mut s = start;
        let mut k_nl: Option<Mat<c64>> = None;
        let (mut x, mut v): (Vec<c64>, Vec<c64>) = (Vec::new(), Vec::new());
        let mut previous = f64::INFINITY;
        // The balance's coefficients worked in (those of its own parity block, or all), and
        // where each lies in the block (`None`: the other block); set at the first Jacobian.
        let mut coefficients: Vec<usize> = Vec::new();
        let mut at: Vec<Option<usize>> = Vec::new();
        // Hill's rows of those coefficients (all of each one's modes), for `P` as a whole.
        let mut rows: Vec<usize> = Vec::new();
        for iteration in 1..=max_iterations {
            if depends_on_s || k_nl.is_none() {
                let jac = jacobian(s);
                let nq = jac.nrows();
                if !nq.is_multiple_of(q) || jac.ncols() != nq || nq == 0 {
                    return Err(StabilityError::JacobianSize { got: nq, expected: q });
                }
                let nc = nq / q;
                if at.is_empty() {
                    // The block alone where the joints' Jacobian keeps the harmonics' parities
                    // apart (the modal part always does): the exponent's eigenvector lies in
                    // it, and each step's LU is of half the size, an eighth of the work.
                    let odd = |i: usize| coefficient_parity(i / q) == 1;
                    let block = block.filter(|_| half_wave_symmetric(&jac, odd));
                    coefficients = (0..nc).filter(|&c| block.is_none_or(|p| coefficient_parity(c) == p)).collect();
                    at = vec![None; nc];
                    coefficients.iter().enumerate().for_each(|(local, &c)| at[c] = Some(local));
                    rows = coefficients.iter().flat_map(|&c| c * m..(c + 1) * m).collect();
                } else if coefficients.len() < nc && !half_wave_symmetric(&jac, |i| coefficient_parity(i / q) == 1) {
                    // The parities coupled at another exponent (they do not, for the laws
                    // that split): the whole problem is the fixed point's to solve.
                    return Ok(None);
                }
                let jac = if coefficients.len() < nc {
                    let at = |i: usize| coefficients[i / q] * q + i % q;
                    let n = coefficients.len() * q;
                    Mat::from_fn(n, n, |i, j| jac[(at(i), at(j))])
                } else {
                    jac
                };
                k_nl = Some(self.joint_stiffness(jac.as_ref()));
            }
            let (size, full_size) = (rows.len(), at.len() * m);
            let mut t = k_nl.clone().expect("computed above");
            self.add_modal(omega, s, &at, &mut t);
            let lu = t.partial_piv_lu();
            let column = |v: &[c64]| Mat::from_fn(v.len(), 1, |i, _| v[i]);
            if x.is_empty() {
                x = match vector.filter(|v| v.len() == full_size) {
                    Some(v) => rows.iter().map(|&i| v[i]).collect(),
                    None => {
                        // A generic start (no symmetry of the harmonics can make it orthogonal
                        // to the eigenvector), improved by one inverse-iteration step. Real, so
                        // that a real exponent of a real T(s) stays exactly real.
                        let b = Mat::from_fn(size, 1, |a, _| c64::new(1.0 + 0.37 * (rows[a] as f64).sin(), 0.0));
                        let y = lu.solve(&b);
                        (0..size).map(|i| y[(i, 0)]).collect()
                    }
                };
                let norm = x.iter().map(|a| a.norm_sqr()).sum::<f64>().sqrt();
                if !(norm.is_finite() && norm > 0.0) {
                    return Ok(None);
                }
                x.iter_mut().for_each(|a| *a /= norm);
                v = x.clone();
            }
            // T'(s) x on the block: the modal derivative keeps the parities apart.
            let derivative = self.modal_derivative(omega, s, &at, &x);
            let u = lu.solve(column(&derivative));
            let vu: c64 = (0..size).map(|i| v[i].conj() * u[(i, 0)]).sum();
            // vᴴx = 1: Newton's step is 1 / vᴴT⁻¹T'x.
            let step = c64::new(1.0, 0.0) / vu;
            if !(step.re.is_finite() && step.im.is_finite()) {
                return Ok(None);
            }
            s -= step;
            x = (0..size).map(|i| u[(i, 0)] / vu).collect();
            let change = step.norm();
            // Hill's P, the other block's harmonics zero.
            let whole = |x: &[c64]| {
                let mut p = vec![c64::new(0.0, 0.0); full_size];
                rows.iter().zip(x).for_each(|(&i, &value)| p[i] = value);
                p
            };
            if change <= CONVERGED * omega {
                return Ok(Some(Refined { exponent: s, vector: whole(&x), iterations: iteration }));
            }
            if iteration > 2 && change >= previous {
                // Stalled: at round-off if the steps are already tiny, else not converging (a
                // linear rate near 1, or a jump between roots).
                let converged = change <= 1e3 * CONVERGED * omega;
                return Ok(converged.then_some(Refined { exponent: s, vector: whole(&x), iterations: iteration }));
            }
            previous = change;
        }
        Ok(None)
    }

    /// Hill's method without splitting half-wave symmetric problems into their even and odd
    /// harmonics: the whole matrix at once, the reference the split is tested against.
    pub fn without_symmetry(mut self) -> Self {
        self.split_parity = false;
        self
    }

    /// The 2m physical exponents among all the eigenvalues of Hill's problem, each with what
    /// came with it: the smallest |Im s| (Lazarus & Thomas 2010), largest real part first.
    fn physical<T>(&self, mut all: Vec<(c64, T)>) -> Vec<(c64, T)> {
        all.sort_by(|a, b| a.0.im.abs().total_cmp(&b.0.im.abs()));
        all.truncate(2 * self.n_modes());
        all.sort_by(|a, b| b.0.re.total_cmp(&a.0.re).then(b.0.im.total_cmp(&a.0.im)));
        all
    }
}

/// Coupling between harmonics of opposite parity below this, relative to the joints' largest
/// stiffness term, counts as none: the AFT of a half-wave symmetric solution leaves it at
/// round-off (~1e-16), and dropping 1e-12 of the stiffness moves an exponent by ~1e-12 of its
/// scale, far below the 1e-9 Ω within which exponents are compared to the imaginary axis.
const SYMMETRY: f64 = 1e-12;

/// Scale `a` to `D⁻¹ a D`, `D` diagonal of powers of two, so that each row and column of the
/// same index have 2-norms within a small factor (about 2): the balancing of LAPACK's `dgebal` (Parlett &
/// Reinsch 1969), without its permutations. The eigenvalues are those of `a` (powers of two
/// scale exactly); the Schur form's error, ε times the norm, falls with the norm. Written here
/// because faer 0.24 does not balance before its Schur forms, and Hill's companion matrix needs
/// it: its lower blocks carry the kept modes' ω² and the joints' stiffness (1e8 on Harmony's
/// 24 modes), its upper the identity. Unbalanced, faer's multishift QR spent minutes on one
/// 336-row block of Harmony (its deflation windows reordering without end), 44 ms balanced.
/// `abs2` is the squared modulus of an entry; a row or column whose norm is not finite is left
/// as it is (the eigensolver then reports the failure).
fn balance<T: Copy + std::ops::MulAssign<f64>>(a: &mut Mat<T>, abs2: impl Fn(T) -> f64) {
    /// LAPACK's: scale a row and column only where it lowers their sum of norms by 5 %.
    const GAIN: f64 = 0.95;
    /// Sweeps over the rows: LAPACK's converges in a few; a bound keeps any input finite.
    const MAX_SWEEPS: usize = 64;
    // The norms are sums of squares: finite and non-zero, they lie within ~1e±154, so the
    // scale f ~ √(r/c) stays within ~2^±512, finite (LAPACK's bounds from the safe minimum are
    // for its overflow-free norms).
    let n = a.nrows();
    for _ in 0..MAX_SWEEPS {
        let mut scaled = false;
        for i in 0..n {
            let column: f64 = (0..n).map(|k| abs2(a[(k, i)])).sum::<f64>().sqrt();
            let row: f64 = (0..n).map(|k| abs2(a[(i, k)])).sum::<f64>().sqrt();
            if !(column > 0.0 && row > 0.0 && column.is_finite() && row.is_finite()) {
                continue;
            }
            let (mut c, mut r, mut f) = (column, row, 1.0);
            while c < r / 2.0 {
                (c, r, f) = (2.0 * c, r / 2.0, 2.0 * f);
            }
            while c / 2.0 >= r {
                (c, r, f) = (c / 2.0, 2.0 * r, f / 2.0);
            }
            if c + r >= GAIN * (column + row) {
                continue;
            }
            scaled = true;
            for k in 0..n {
                a[(i, k)] *= 1.0 / f;
                a[(k, i)] *= f;
            }
        }
        if !scaled {
            return;
        }
    }
}

/// Are all the entries of `m` real?
fn is_real(m: &Mat<c64>) -> bool {
    m.col_iter().all(|col| col.iter().all(|v| v.im == 0.0))
}

/// A block of Hill's companion matrix and the parity of its harmonics (`None`: the whole).
type ParityBlock = (Mat<c64>, Option<usize>);

/// Orders `a` before `b` if it lies nearer `s`; at the same distance to round-off (a
/// conjugate pair about a real `s`, which a real Hill matrix offers), the one above the real
/// axis first, so that either way of finding the nearest takes the same.
pub fn nearer(a: c64, b: c64, s: c64) -> std::cmp::Ordering {
    let (da, db) = ((a - s).norm(), (b - s).norm());
    if (da - db).abs() <= 1e-12 * da.max(db) {
        b.im.total_cmp(&a.im)
    } else {
        da.total_cmp(&db)
    }
}

/// Vectors of the inverse subspace iteration of [`Hill::nearest_eigenvalue`]: more than the
/// two copies of a repeated exponent (Harmony's blades), so that the nearest converges at the
/// rate of the fifth nearest.
const SUBSPACE_SIZE: usize = 4;
/// Its steps at most: from a fixed point's iterate, a step or two of the distance to the
/// nearest eigenvalue apart, it converges in a few.
const SUBSPACE_STEPS: usize = 12;
/// Its convergence: the nearest Ritz pair's residual against the matrix's norm (a backward
/// error near the Schur form's ~1e-15 ‖A‖ would cost more steps than the fixed point needs:
/// its iterates are compared to 1e-10 Ω).
const SUBSPACE_TOLERANCE: f64 = 1e-12;

/// Rows up to which faer's unblocked double-shift QR finds the eigenvalues instead of its
/// multishift QR with aggressive early deflation (faer's threshold is 75). Measured on random
/// matrices, one core: 1.64 against 2.15 ms at 80 rows (the odd block at paper size), 15.9
/// against 13.8 ms at 150; on a balanced 336-row block of Harmony, 44 against 63 ms.
const UNBLOCKED_UP_TO: usize = 100;

/// The eigenvalues of the real square `a` by faer's Hessenberg QR, unblocked up to
/// [`UNBLOCKED_UP_TO`] rows.
fn real_eigenvalues(a: Mat<f64>) -> Option<Vec<c64>> {
    use faer::dyn_stack::{MemBuffer, MemStack};
    use faer::linalg::evd::{evd_real, evd_scratch, ComputeEigenvectors, EvdParams};
    let n = a.nrows();
    let mut params: EvdParams = faer::Auto::<f64>::auto();
    params.schur.blocking_threshold = UNBLOCKED_UP_TO + 1;
    let par = faer::Par::Seq;
    let mut re = faer::diag::Diag::<f64>::zeros(n);
    let mut im = faer::diag::Diag::<f64>::zeros(n);
    let no = ComputeEigenvectors::No;
    let mut scratch = MemBuffer::new(evd_scratch::<f64>(n, no, no, par, params.into()));
    evd_real(a.as_ref(), re.as_mut(), im.as_mut(), None, None, par, MemStack::new(&mut scratch), params.into()).ok()?;
    Some((0..n).map(|i| c64::new(re[i], im[i])).collect())
}

/// The parity (0 even, 1 odd) of the harmonic of the balance's coefficient `c` (0: the mean,
/// then the cosine and sine of each harmonic).
fn coefficient_parity(c: usize) -> usize {
    c.div_ceil(2) % 2
}

/// Does `k` (square) couple no index with `odd(i)` to one without, to [`SYMMETRY`]?
fn half_wave_symmetric(k: &Mat<c64>, odd: impl Fn(usize) -> bool) -> bool {
    let n = k.nrows();
    let (mut largest, mut cross) = (0.0_f64, 0.0_f64);
    for j in 0..n {
        for i in 0..n {
            let v = k[(i, j)].norm();
            largest = largest.max(v);
            if odd(i) != odd(j) {
                cross = cross.max(v);
            }
        }
    }
    cross <= SYMMETRY * largest
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Stuck modes with mass-proportional damping share the real part −α/2 up to round-off:
    /// the leading exponent is the one of smallest |Im s| among them, its upper conjugate,
    /// whatever the order and the round-off (here 1e-12 1/s, against a tie of 1e-8 × 700).
    /// An exponent less damped by more than the tie (7e-6 1/s: here 5e-5) leads alone. The stable flag
    /// reads every real part.
    #[test]
    fn the_leading_exponent_of_a_tie_is_the_smallest_imaginary_part() {
        let tied = [
            c64::new(-7.5 + 1e-12, 700.0),
            c64::new(-7.5 + 1e-12, -700.0),
            c64::new(-7.5, -310.0),
            c64::new(-7.5 - 1e-12, 310.0),
            c64::new(-7.5 + 5e-13, 512.0),
            c64::new(-3e4, 0.0),
        ];
        for shift in 0..tied.len() {
            let mut exponents = tied.to_vec();
            exponents.rotate_left(shift);
            let leading = Stability { exponents: exponents.clone() }.leading();
            assert_eq!(leading, c64::new(-7.5 - 1e-12, 310.0), "order {exponents:?}");
            exponents.push(c64::new(-7.5 + 5e-5, 650.0));
            assert_eq!(Stability { exponents }.leading(), c64::new(-7.5 + 5e-5, 650.0));
        }
        let stability = Stability { exponents: vec![c64::new(-1.0, 2.0), c64::new(1e-3, 0.0)] };
        assert!(!stability.is_stable(1e-6) && stability.is_stable(2e-3));
        assert_eq!(Stability { exponents: vec![] }.leading().re, f64::NEG_INFINITY);
    }

    /// Balancing keeps the eigenvalues and evens the norms. The companion form of three
    /// uncoupled modes (1e2, 1e4 and 3e4 rad/s, damping ratios 1 %, 5 %, 0.1 %) has entries from
    /// 1 to 9e8; its eigenvalues are −ζω ± iω√(1 − ζ²). Balanced, they come out within 1e-14 of
    /// |s| (measured ~1e-16: powers of two scale exactly), and each row's and column's norms
    /// within a factor 4 (LAPACK's criterion leaves them within about 2.3; the mode at 1e2 has
    /// the largest spread, ω² = 1e4 against 1 before).
    #[test]
    fn balancing_keeps_the_eigenvalues_and_evens_the_norms() {
        let modes = [(1e2, 0.01), (1e4, 0.05), (3e4, 0.001)];
        let m = modes.len();
        let mut a = Mat::<f64>::zeros(2 * m, 2 * m);
        for (r, &(w, zeta)) in modes.iter().enumerate() {
            a[(r, m + r)] = 1.0;
            a[(m + r, r)] = -w * w;
            a[(m + r, m + r)] = -2.0 * zeta * w;
        }
        let norms = |a: &Mat<f64>, i: usize| {
            let column = (0..2 * m).map(|k| a[(k, i)] * a[(k, i)]).sum::<f64>().sqrt();
            let row = (0..2 * m).map(|k| a[(i, k)] * a[(i, k)]).sum::<f64>().sqrt();
            column / row
        };
        let spread = |a: &Mat<f64>| (0..2 * m).map(|i| norms(a, i).ln().abs()).fold(0.0, f64::max).exp();
        assert!(spread(&a) > 1e8, "the test matrix is badly scaled");
        balance(&mut a, |v| v * v);
        assert!(spread(&a) <= 4.0, "norms apart by {} after balancing", spread(&a));
        let mut computed = real_eigenvalues(a).unwrap();
        computed.sort_by(|x, y| x.norm().total_cmp(&y.norm()).then(x.im.total_cmp(&y.im)));
        let mut exact: Vec<c64> = modes
            .iter()
            .flat_map(|&(w, zeta)| {
                let wd = w * (1.0 - zeta * zeta).sqrt();
                [c64::new(-zeta * w, -wd), c64::new(-zeta * w, wd)]
            })
            .collect();
        exact.sort_by(|x, y| x.norm().total_cmp(&y.norm()).then(x.im.total_cmp(&y.im)));
        for (s, e) in computed.iter().zip(&exact) {
            assert!((s - e).norm() <= 1e-14 * e.norm(), "{s} against {e}");
        }
    }

    /// A non-finite entry leaves its row and column as they are, and the sweeps end; entries
    /// 1e300 apart are balanced to within a factor 4, finite (eigenvalues ±1).
    #[test]
    fn balancing_stops_on_non_finite_entries_and_evens_extremes() {
        let mut b = Mat::from_fn(2, 2, |i, j| match (i, j) {
            (0, 1) => 1e150,
            (1, 0) => 1e-150,
            _ => 0.0,
        });
        balance(&mut b, |v| v * v);
        let ratio = b[(0, 1)] / b[(1, 0)];
        assert!((0.25..=4.0).contains(&ratio) && b[(0, 1)] * b[(1, 0)] == 1.0, "{b:?}");
        let mut a =
            Mat::from_fn(3, 3, |i, j| if (i, j) == (1, 2) { f64::NAN } else { 1e6_f64.powi(i as i32 - j as i32) });
        balance(&mut a, |v| v * v);
        assert!(a[(1, 2)].is_nan());
    }
}
