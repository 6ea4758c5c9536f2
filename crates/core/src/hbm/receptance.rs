//! The linear part of the condensation (paper Eqs. 20-29): the dynamic flexibility of the
//! linear model seen from the nonlinear directions, harmonic by harmonic.
//!
//! For harmonic k at fundamental Ω, with `ω = kΩ` and `Z(ω) = K − ω²M + iωD`:
//!
//! ```text
//! H(ω) = Vᵀ Z(ω)⁻¹ V        (q × q, complex)      receptance on the q application directions
//! u_F(ω) = Vᵀ Z(ω)⁻¹ F      (q)                    linear response to the excitation pattern
//! ```
//!
//! `H⁻¹` is the Schur complement `A_qq − A_qp A_pp⁻¹ A_pq` of Eq. 28 written in the complex
//! form of one harmonic block of Eq. 17, with the application vectors in place of the
//! Gram-Schmidt basis of Eqs. 20-22 (same span, so the same condensed problem without
//! building the n × n orthonormal basis).
//!
//! Two ways to evaluate it:
//! - **Modal** (proportional or modal damping): with mass-normalised modes,
//!   `Z⁻¹ = Σ_r φ_r φ_rᵀ / (ω_r² − ω² + iω c_r)`, exact when every mode is kept, and cheap:
//!   O(q m) per harmonic for a residual and O(q² m) for the matrix, whatever the model size.
//! - **Direct** (a general damping matrix): one complex LU of `Z(ω)` per harmonic and frequency.
//!
//! Physical DOFs are recovered afterwards (Eq. 27) from the same representation.

use faer::linalg::matmul::triangular::{self, BlockStructure};
use faer::linalg::solvers::Solve;
use faer::{c64, Accum, Mat, MatMut, MatRef, Par};
use multiversion::multiversion;

use crate::model::{Damping, LinearModel, ModelError, Modes};

/// The linear dynamics of a model as seen from a few directions.
#[derive(Debug)]
pub enum Receptance {
    Modal(ModalReceptance),
    Direct(DirectReceptance),
}

#[derive(Debug)]
pub struct ModalReceptance {
    omega_r: Vec<f64>,
    /// Modal damping coefficients `c_r` (modal equation `q̈ + c_r q̇ + ω_r² q`).
    c_r: Vec<f64>,
    /// `A = Vᵀ Φ` (q × m).
    a: Mat<f64>,
    /// `b = Φᵀ F` (m).
    b: Vec<f64>,
    modes: Modes,
    /// The same data laid out for loops over the modes, which are the long dimension (q is a
    /// few directions, m every mode of the model): `ω_r²`, the rows of `A` (`rows[i·m + r]`),
    /// the rows of `A diag(b)` (`u_F`'s weights), and for few directions
    /// ([`PAIRWISE_UP_TO`]) the products `a_ir a_jr` of each pair j ≤ i, so that an entry of
    /// `H` is one dot product with the modal weights: four pairs side by side
    /// (`pairs[(b·m + r)·4 + p]` for pair 4b + p, zero beyond the last), the lanes of one
    /// vector ([`pair_dots`]).
    omega_r2: Vec<f64>,
    rows: Vec<f64>,
    force_rows: Vec<f64>,
    pairs: Vec<f64>,
}

/// Number of directions up to which `H` is summed pair by pair from precomputed products
/// (q(q+1)/2 dot products of length m: no temporaries, no call overhead); above it, two
/// triangular matrix products, which block for the cache.
const PAIRWISE_UP_TO: usize = 16;
/// Up to this many directions a residual forms `H` ([`Receptance::prefers_matrix`]).
const MATRIX_IN_RESIDUAL_UP_TO: usize = 8;

#[derive(Debug)]
pub struct DirectReceptance {
    mass: Mat<f64>,
    stiffness: Mat<f64>,
    damping: Mat<f64>,
    /// `[V F]` (n × (q+1)).
    rhs: Mat<c64>,
    /// `A = Vᵀ Φ` (q × m) and the mass-normalised undamped modes, for what is written in modal
    /// coordinates (Hill's method).
    a: Mat<f64>,
    modes: Modes,
}

/// A parameter of the linear part with respect to which [`ModalReceptance::matrix_with`]
/// differentiates `H`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LinearParameter {
    /// The harmonic's circular frequency ω (rad/s): `∂(1/den_r)/∂ω = (2ω − i c_r)/den_r²`.
    Frequency,
    /// α of a damping `α M` added to the model's: every modal coefficient `c_r → c_r + α`,
    /// `∂(1/den_r)/∂α = −iω/den_r²`. The negative damping `−ξ M` of a nonlinear mode (EPMC,
    /// Krack 2015, Eq. 2) is `α = −ξ`.
    MassDamping,
    /// β of a damping `β K` added: `c_r → c_r + β ω_r²`, `∂(1/den_r)/∂β = −iω ω_r²/den_r²`.
    StiffnessDamping,
}

/// A variation of the linear part: damping `α M + β K` added to the model's, and a mode left
/// out of the modal sum (the target mode of a nonlinear mode, whose coordinate is kept as an
/// unknown).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct LinearVariation {
    pub mass_damping: f64,
    pub stiffness_damping: f64,
    pub without_mode: Option<usize>,
}

/// Output selectors prepared by [`Receptance::outputs`].
#[derive(Clone, Debug)]
pub struct Outputs(Vec<Vec<f64>>);

/// The receptance at one harmonic frequency ω: `u_F(ω)` and its ω-derivative always, the q × q
/// matrix `H(ω)` when asked ([`Receptance::evaluate_matrix`]), and products of `H` and `dH/dω`
/// with force amplitudes ([`Receptance::apply`], [`Receptance::apply_derivative`]). A residual
/// needs only the products (O(q m) with m modes); the matrix (O(q² m)) is for a Jacobian.
pub struct HarmonicReceptance {
    /// `H` (q × q), symmetric; up to date after [`Receptance::evaluate_matrix`] only.
    pub h: Mat<c64>,
    /// `u_F` (q).
    pub u_force: Vec<c64>,
    pub du_force: Vec<c64>,
    /// Modal: `1/den_r` and `d(1/den_r)/dω` of every mode, real and imaginary parts apart
    /// (the loops over modes vectorise).
    inverse: [Vec<f64>; 2],
    inverse_derivative: [Vec<f64>; 2],
    /// Modal: a product `Aᵀ g` (m, complex as two parts), reused.
    projected: [Vec<f64>; 2],
    /// Modal: the sums of the pairs' products, `H`'s lower triangle, reused.
    pair_sums: Vec<(f64, f64)>,
    /// Modal: `A diag(Re 1/den)` and `A diag(Im 1/den)` (q × m), and the real and imaginary
    /// parts of `H` (lower triangles), reused from call to call.
    scaled: [Mat<f64>; 2],
    parts: [Mat<f64>; 2],
    /// Direct: `dH/dω` (q × q).
    dh: Mat<c64>,
}

impl HarmonicReceptance {
    /// Buffers for `q` directions (sized for the model at the first evaluation).
    pub fn new(q: usize) -> Self {
        HarmonicReceptance {
            h: Mat::zeros(q, q),
            u_force: vec![c64::new(0.0, 0.0); q],
            du_force: vec![c64::new(0.0, 0.0); q],
            inverse: [Vec::new(), Vec::new()],
            inverse_derivative: [Vec::new(), Vec::new()],
            projected: [Vec::new(), Vec::new()],
            pair_sums: Vec::new(),
            scaled: [Mat::zeros(0, 0), Mat::zeros(0, 0)],
            parts: [Mat::zeros(0, 0), Mat::zeros(0, 0)],
            dh: Mat::zeros(0, 0),
        }
    }
}

impl Receptance {
    /// Prepare the receptance of `model` on the columns of `directions` (each of length n) for
    /// the excitation pattern `force`.
    pub fn new(model: &LinearModel, directions: &[&[f64]], force: &[f64]) -> Result<Self, ModelError> {
        let n = model.n_dofs();
        let q = directions.len();
        // The undamped modes, which also check M > 0 and K > 0 for both forms alike, and
        // `A = Vᵀ Φ`: the modal sum's, and Hill's method's with either form.
        let modes = model.dense_modes()?;
        let m = modes.omega.len();
        let phi = &modes.shapes;
        let a = Mat::from_fn(q, m, |i, r| (0..n).map(|l| directions[i][l] * phi[(l, r)]).sum());
        if model.damping.is_modal() {
            let b: Vec<f64> = (0..m).map(|r| (0..n).map(|l| force[l] * phi[(l, r)]).sum()).collect();
            let c_r =
                modes.omega.iter().enumerate().map(|(r, &w)| model.damping.modal_coefficient(r, w).unwrap()).collect();
            let omega_r2 = modes.omega.iter().map(|w| w * w).collect();
            let rows = (0..q).flat_map(|i| (0..m).map(move |r| (i, r))).map(|(i, r)| a[(i, r)]).collect();
            let force_rows = (0..q).flat_map(|i| (0..m).map(move |r| (i, r))).map(|(i, r)| a[(i, r)] * b[r]).collect();
            let pairs = if q <= PAIRWISE_UP_TO {
                let list: Vec<(usize, usize)> = lower_pairs(q).collect();
                let mut pairs = vec![0.0; list.len().div_ceil(PAIR_LANES) * m * PAIR_LANES];
                for (p, &(i, j)) in list.iter().enumerate() {
                    let (block, lane) = (p / PAIR_LANES, p % PAIR_LANES);
                    for r in 0..m {
                        pairs[(block * m + r) * PAIR_LANES + lane] = a[(i, r)] * a[(j, r)];
                    }
                }
                pairs
            } else {
                Vec::new()
            };
            Ok(Receptance::Modal(ModalReceptance {
                omega_r: modes.omega.clone(),
                c_r,
                a,
                b,
                modes,
                omega_r2,
                rows,
                force_rows,
                pairs,
            }))
        } else {
            let Damping::Matrix(d) = &model.damping else { unreachable!("non-modal damping is a matrix") };
            let rhs = Mat::from_fn(n, q + 1, |l, j| c64::new(if j < q { directions[j][l] } else { force[l] }, 0.0));
            Ok(Receptance::Direct(DirectReceptance {
                mass: model.mass.to_dense(),
                stiffness: model.stiffness.to_dense(),
                damping: d.to_dense(),
                rhs,
                a,
                modes,
            }))
        }
    }

    /// Number of directions q.
    pub fn n_directions(&self) -> usize {
        match self {
            Receptance::Modal(m) => m.a.nrows(),
            Receptance::Direct(d) => d.rhs.ncols() - 1,
        }
    }

    /// `u_F(ω)`, its ω-derivative and what [`Self::apply`] and [`Self::apply_derivative`] need,
    /// into `out` (the matrix `H` is left as it was).
    pub fn evaluate(&self, omega: f64, out: &mut HarmonicReceptance) {
        match self {
            Receptance::Modal(m) => m.evaluate(omega, out, true, false),
            Receptance::Direct(d) => d.evaluate(omega, out),
        }
    }

    /// [`Self::evaluate`] and the matrix `H(ω)` (q × q) into `out.h`.
    pub fn evaluate_matrix(&self, omega: f64, out: &mut HarmonicReceptance) {
        match self {
            Receptance::Modal(m) => m.evaluate(omega, out, true, true),
            Receptance::Direct(d) => d.evaluate(omega, out),
        }
    }

    /// [`Self::evaluate`] (with `matrix`, [`Self::evaluate_matrix`]) for a harmonic the
    /// excitation does not reach: `u_F` and its derivative may be left as they were.
    pub fn evaluate_unforced(&self, omega: f64, out: &mut HarmonicReceptance, matrix: bool) {
        match self {
            Receptance::Modal(m) => m.evaluate(omega, out, false, matrix),
            Receptance::Direct(d) => d.evaluate(omega, out),
        }
    }

    /// The matrix `H(ω)` into `out`, after an evaluation at ω without it: what
    /// [`Self::evaluate_matrix`] adds to [`Self::evaluate`], from the modal weights already
    /// there (the same values).
    pub fn complete_matrix(&self, omega: f64, out: &mut HarmonicReceptance) {
        match self {
            Receptance::Modal(m) => m.matrix(out),
            Receptance::Direct(d) => d.evaluate(omega, out),
        }
    }

    /// Is the matrix `H` about as cheap as the products [`Self::apply`] makes (few directions:
    /// `q(q+1)/2` modal sums against the products' `2q + 1`, with m modes each)? A residual
    /// then forms it and multiplies by it, and the Jacobian that Newton completes from that
    /// residual (two in three, typically) finds it made. At q = 4 the matrix and the products
    /// cost 20m and 22m multiplications; at q = 8, 72m against 38m, made up for by the
    /// Jacobians. True for the direct form, which makes the matrix at every evaluation.
    pub fn prefers_matrix(&self) -> bool {
        match self {
            Receptance::Modal(m) => m.a.nrows() <= MATRIX_IN_RESIDUAL_UP_TO,
            Receptance::Direct(_) => true,
        }
    }

    /// `H(ω) g` for complex force amplitudes `g` (q), with `hr` from an evaluation at ω.
    pub fn apply(&self, hr: &mut HarmonicReceptance, g: &[c64], out: &mut [c64]) {
        match self {
            Receptance::Modal(m) => {
                let HarmonicReceptance { inverse, projected, .. } = hr;
                m.apply(inverse, projected, g, out)
            }
            Receptance::Direct(_) => multiply(&hr.h, g, out),
        }
    }

    /// `dH/dω (ω) g`, with `hr` from an evaluation at ω.
    pub fn apply_derivative(&self, hr: &mut HarmonicReceptance, g: &[c64], out: &mut [c64]) {
        match self {
            Receptance::Modal(m) => {
                let HarmonicReceptance { inverse_derivative, projected, .. } = hr;
                m.apply(inverse_derivative, projected, g, out)
            }
            Receptance::Direct(_) => multiply(&hr.dh, g, out),
        }
    }

    /// The matrix `dH/dω` (q × q) at the frequency of the evaluation into `hr`, for the
    /// formulations that need it whole (O(q² m)).
    pub fn derivative_matrix(&self, hr: &HarmonicReceptance) -> Mat<c64> {
        match self {
            Receptance::Modal(m) => {
                let (q, a) = (m.a.nrows(), &m.a);
                let [re, im] = &hr.inverse_derivative;
                Mat::from_fn(q, q, |i, j| {
                    (0..m.omega_r.len()).map(|r| c64::new(re[r], im[r]) * (a[(i, r)] * a[(j, r)])).sum()
                })
            }
            Receptance::Direct(_) => hr.dh.clone(),
        }
    }

    /// Prepare output selectors `o` (each of length n) for [`recover`](Self::recover): their
    /// modal projections `Φᵀ o` once, rather than at every harmonic of every point.
    pub fn outputs(&self, outputs: &[&[f64]]) -> Outputs {
        match self {
            Receptance::Modal(m) => {
                let phi = &m.modes.shapes;
                Outputs(
                    outputs
                        .iter()
                        .map(|o| {
                            (0..phi.ncols()).map(|r| o.iter().enumerate().map(|(l, v)| v * phi[(l, r)]).sum()).collect()
                        })
                        .collect(),
                )
            }
            Receptance::Direct(_) => Outputs(outputs.iter().map(|o| o.to_vec()).collect()),
        }
    }

    /// Recovery (Eq. 27): complex amplitude at harmonic frequency `omega` along each of
    /// `outputs` of `U = Z⁻¹ (level F − V G)`, with `G` the complex force amplitudes on the q
    /// directions (`g_c − i g_s`). Also the viscous power term: returns
    /// `(amplitudes, Uᴴ D U)` where `U` is the full response.
    pub fn recover(&self, omega: f64, level: f64, g: &[c64], outputs: &Outputs) -> (Vec<c64>, f64) {
        match self {
            Receptance::Modal(m) => m.recover(omega, level, g, outputs),
            Receptance::Direct(d) => d.recover(omega, level, g, outputs),
        }
    }
}

impl ModalReceptance {
    /// Natural circular frequencies ω_r of the modes (rad/s, increasing).
    pub fn natural_frequencies(&self) -> &[f64] {
        &self.omega_r
    }

    /// Modal damping coefficients c_r (modal equation `q̈ + c_r q̇ + ω_r² q`).
    pub fn damping_coefficients(&self) -> &[f64] {
        &self.c_r
    }

    /// `A = Vᵀ Φ` (q × m): each mode seen from the nonlinear directions.
    pub fn participation(&self) -> MatRef<'_, f64> {
        self.a.as_ref()
    }

    /// The mass-normalised modes of the linear model.
    pub fn modes(&self) -> &Modes {
        &self.modes
    }

    /// Modal damping coefficients under `variation`: `c_r + α + β ω_r²`.
    pub fn varied_damping(&self, r: usize, variation: &LinearVariation) -> f64 {
        self.c_r[r] + variation.mass_damping + variation.stiffness_damping * self.omega_r2[r]
    }

    /// `H(ω) = Σ_r a_r a_rᵀ / den_r(ω)` of the model under `variation` (`den_r = ω_r² − ω² +
    /// iω c_r'`, `c_r'` from [`Self::varied_damping`], the mode it leaves out skipped) into
    /// `h`, and its derivative with respect to each of `parameters` into `derivatives` (same
    /// order, q × q each): the linear part of a formulation whose unknowns or continuation
    /// parameter enter the linear dynamics (the frequency and the negative damping of a
    /// nonlinear mode). O(q² m).
    pub fn matrix_with(
        &self,
        omega: f64,
        variation: &LinearVariation,
        parameters: &[LinearParameter],
        mut h: MatMut<'_, c64>,
        derivatives: &mut [MatMut<'_, c64>],
    ) {
        let q = self.a.nrows();
        let mut weights = [c64::new(0.0, 0.0); 3];
        assert!(parameters.len() <= weights.len() && derivatives.len() == parameters.len(), "one matrix per parameter");
        h.fill(c64::new(0.0, 0.0));
        derivatives.iter_mut().for_each(|d| d.fill(c64::new(0.0, 0.0)));
        for r in (0..self.omega_r.len()).filter(|&r| Some(r) != variation.without_mode) {
            let c = self.varied_damping(r, variation);
            let inv = c64::new(self.omega_r2[r] - omega * omega, omega * c).inv();
            let inv2 = inv * inv;
            for (w, parameter) in weights.iter_mut().zip(parameters) {
                *w = match parameter {
                    LinearParameter::Frequency => c64::new(2.0 * omega, -c) * inv2,
                    LinearParameter::MassDamping => c64::new(0.0, -omega) * inv2,
                    LinearParameter::StiffnessDamping => c64::new(0.0, -omega * self.omega_r2[r]) * inv2,
                };
            }
            for i in 0..q {
                let ai = self.a[(i, r)];
                if ai == 0.0 {
                    continue;
                }
                for j in 0..q {
                    let aa = ai * self.a[(j, r)];
                    h[(i, j)] += inv * aa;
                    for (d, w) in derivatives.iter_mut().zip(&weights) {
                        d[(i, j)] += w * aa;
                    }
                }
            }
        }
    }

    /// The modal weights `1/den_r` and their ω-derivatives, with `force` `u_F` and its
    /// derivative (O(q m)) and, with `matrix`, `H = A diag(1/den) Aᵀ` (O(q² m)): loops over the
    /// modes on contiguous rows, or for many directions two real symmetric products (lower
    /// triangles) on a q × m participation matrix that stays in cache.
    fn evaluate(&self, omega: f64, out: &mut HarmonicReceptance, force: bool, matrix: bool) {
        let (q, m) = (self.a.nrows(), self.omega_r.len());
        for part in out.inverse.iter_mut().chain(&mut out.inverse_derivative).chain(&mut out.projected) {
            part.resize(m, 0.0);
        }
        modal_weights(omega, &self.omega_r2, &self.c_r, &mut out.inverse, &mut out.inverse_derivative);
        let [inv_re, inv_im] = &out.inverse;
        let [dinv_re, dinv_im] = &out.inverse_derivative;
        if force {
            for i in 0..q {
                let row = &self.force_rows[i * m..(i + 1) * m];
                let (re, im) = dot2(row, inv_re, inv_im);
                out.u_force[i] = c64::new(re, im);
                let (re, im) = dot2(row, dinv_re, dinv_im);
                out.du_force[i] = c64::new(re, im);
            }
        }
        if matrix {
            self.matrix(out);
        }
    }

    /// `H = A diag(1/den) Aᵀ` into `out.h` from the weights `out` holds.
    fn matrix(&self, out: &mut HarmonicReceptance) {
        let (q, m) = (self.a.nrows(), self.omega_r.len());
        let [inv_re, inv_im] = &out.inverse;
        if q <= PAIRWISE_UP_TO {
            let sums = &mut out.pair_sums;
            sums.resize(q * (q + 1) / 2, (0.0, 0.0));
            pair_dots(&self.pairs, m, inv_re, inv_im, sums);
            for (&(re, im), (i, j)) in sums.iter().zip(lower_pairs(q)) {
                let v = c64::new(re, im);
                out.h[(i, j)] = v;
                out.h[(j, i)] = v;
            }
            return;
        }
        if out.scaled[0].nrows() != q || out.scaled[0].ncols() != m {
            out.scaled = [Mat::zeros(q, m), Mat::zeros(q, m)];
            out.parts = [Mat::zeros(q, q), Mat::zeros(q, q)];
        }
        for part in 0..2 {
            let scaled = &mut out.scaled[part];
            let w = &out.inverse[part];
            for r in 0..m {
                for i in 0..q {
                    scaled[(i, r)] = self.a[(i, r)] * w[r];
                }
            }
            triangular::matmul(
                out.parts[part].as_mut(),
                BlockStructure::TriangularLower,
                Accum::Replace,
                out.scaled[part].as_ref(),
                BlockStructure::Rectangular,
                self.a.transpose(),
                BlockStructure::Rectangular,
                1.0,
                Par::Seq,
            );
        }
        let [re, im] = &out.parts;
        for j in 0..q {
            for i in j..q {
                let v = c64::new(re[(i, j)], im[(i, j)]);
                out.h[(i, j)] = v;
                out.h[(j, i)] = v;
            }
        }
    }

    /// `A diag(weights) Aᵀ g`, a receptance-like product in O(q m): `Aᵀ g` into `projected`,
    /// weighted, then one dot product per direction.
    fn apply(&self, weights: &[Vec<f64>; 2], projected: &mut [Vec<f64>; 2], g: &[c64], out: &mut [c64]) {
        weighted_product(&self.rows, self.omega_r.len(), weights, projected, g, out);
    }

    fn recover(&self, omega: f64, level: f64, g: &[c64], outputs: &Outputs) -> (Vec<c64>, f64) {
        let q = self.a.nrows();
        let m = self.omega_r.len();
        let mut amps = vec![c64::new(0.0, 0.0); outputs.0.len()];
        let mut dissipation = 0.0;
        for r in 0..m {
            let den = c64::new(self.omega_r[r] * self.omega_r[r] - omega * omega, omega * self.c_r[r]);
            let mut load = c64::new(level * self.b[r], 0.0);
            for i in 0..q {
                load -= g[i] * self.a[(i, r)];
            }
            let coord = load / den;
            // Modal viscous term: φ_rᵀ D φ_r = c_r (mass-normalised modes).
            dissipation += self.c_r[r] * coord.norm_sqr();
            for (amp, o) in amps.iter_mut().zip(&outputs.0) {
                *amp += coord * o[r];
            }
        }
        (amps, dissipation)
    }
}

impl DirectReceptance {
    /// Natural circular frequencies ω_r of the undamped modes (rad/s, increasing).
    pub fn natural_frequencies(&self) -> &[f64] {
        &self.modes.omega
    }

    /// The damping matrix in the mass-normalised undamped modes, `Φᵀ D Φ` (m × m): full unless
    /// `D` happens to be proportional (the modal equations `q̈ + Φᵀ D Φ q̇ + Λ q` stay coupled).
    pub fn modal_damping(&self) -> Mat<f64> {
        let phi = &self.modes.shapes;
        phi.transpose() * &self.damping * phi
    }

    /// `A = Vᵀ Φ` (q × m): each mode seen from the nonlinear directions.
    pub fn participation(&self) -> MatRef<'_, f64> {
        self.a.as_ref()
    }

    /// The mass-normalised undamped modes.
    pub fn modes(&self) -> &Modes {
        &self.modes
    }

    fn dynamic_stiffness(&self, omega: f64) -> Mat<c64> {
        let n = self.mass.nrows();
        Mat::from_fn(n, n, |i, j| {
            c64::new(self.stiffness[(i, j)] - omega * omega * self.mass[(i, j)], omega * self.damping[(i, j)])
        })
    }

    fn evaluate(&self, omega: f64, out: &mut HarmonicReceptance) {
        let n = self.mass.nrows();
        let q = self.rhs.ncols() - 1;
        let z = self.dynamic_stiffness(omega);
        let y = z.partial_piv_lu().solve(&self.rhs);
        // Z' = −2ωM + iD; by symmetry of Z, Vᵀ Z⁻¹ Z' Z⁻¹ W = Y_Vᵀ Z' Y_W.
        let zp = Mat::from_fn(n, n, |i, j| c64::new(-2.0 * omega * self.mass[(i, j)], self.damping[(i, j)]));
        let zpy = &zp * &y;
        if out.dh.nrows() != q {
            out.dh = Mat::zeros(q, q);
        }
        for i in 0..q {
            for j in 0..=q {
                let mut v = c64::new(0.0, 0.0);
                let mut dv = c64::new(0.0, 0.0);
                for l in 0..n {
                    v += self.rhs[(l, i)] * y[(l, j)];
                    dv -= y[(l, i)] * zpy[(l, j)];
                }
                if j < q {
                    out.h[(i, j)] = v;
                    out.dh[(i, j)] = dv;
                } else {
                    out.u_force[i] = v;
                    out.du_force[i] = dv;
                }
            }
        }
    }

    fn recover(&self, omega: f64, level: f64, g: &[c64], outputs: &Outputs) -> (Vec<c64>, f64) {
        let n = self.mass.nrows();
        let q = self.rhs.ncols() - 1;
        let load = Mat::from_fn(n, 1, |l, _| {
            let mut v = self.rhs[(l, q)] * level;
            for i in 0..q {
                v -= self.rhs[(l, i)] * g[i];
            }
            v
        });
        let u = self.dynamic_stiffness(omega).partial_piv_lu().solve(&load);
        let amps = outputs.0.iter().map(|o| (0..n).map(|l| u[(l, 0)] * o[l]).sum()).collect();
        let mut dissipation = 0.0;
        for i in 0..n {
            for j in 0..n {
                dissipation += self.damping[(i, j)] * (u[(i, 0)].conj() * u[(j, 0)]).re;
            }
        }
        (amps, dissipation)
    }
}

/// The pairs (i, j), j ≤ i, of q directions: the lower triangle column by column.
fn lower_pairs(q: usize) -> impl Iterator<Item = (usize, usize)> {
    (0..q).flat_map(move |j| (j..q).map(move |i| (i, j)))
}

/// The modal weights at ω: `1/den_r` and `d(1/den_r)/dω = (2ω − i c_r)/den_r²` with `den_r =
/// ω_r² − ω² + iω c_r`, real and imaginary parts apart, into `inverse` and `derivative`
/// (resized to the modes). The operations of `c64`'s `inv` and products, written on the parts
/// so that the loop over the modes vectorises (the same values bit for bit).
#[multiversion(targets("x86_64+avx2+fma", "x86_64+avx"))]
fn modal_weights(
    omega: f64,
    omega_r2: &[f64],
    c_r: &[f64],
    inverse: &mut [Vec<f64>; 2],
    derivative: &mut [Vec<f64>; 2],
) {
    let m = omega_r2.len();
    let [inv_re, inv_im] = inverse;
    let [dinv_re, dinv_im] = derivative;
    let (inv_re, inv_im, dinv_re, dinv_im) = (&mut inv_re[..m], &mut inv_im[..m], &mut dinv_re[..m], &mut dinv_im[..m]);
    let p = 2.0 * omega;
    for r in 0..m {
        let (a, b) = (omega_r2[r] - omega * omega, omega * c_r[r]);
        let norm = a * a + b * b;
        let (x, y) = (a / norm, -b / norm);
        // (p − i c) (x + i y), then times (x + i y) again.
        let c = -c_r[r];
        let (tr, ti) = (p * x - c * y, p * y + c * x);
        (inv_re[r], inv_im[r], dinv_re[r], dinv_im[r]) = (x, y, tr * x - ti * y, tr * y + ti * x);
    }
}

/// `A diag(weights) Aᵀ g` with `A`'s rows (m each) in `rows` (see [`ModalReceptance::apply`]),
/// `c64`'s products written on the parts so that the loops over the modes vectorise.
#[multiversion(targets("x86_64+avx2+fma", "x86_64+avx"))]
fn weighted_product(
    rows: &[f64],
    m: usize,
    weights: &[Vec<f64>; 2],
    projected: &mut [Vec<f64>; 2],
    g: &[c64],
    out: &mut [c64],
) {
    let [t_re, t_im] = projected;
    let (t_re, t_im) = (&mut t_re[..m], &mut t_im[..m]);
    t_re.iter_mut().chain(t_im.iter_mut()).for_each(|v| *v = 0.0);
    for (row, gj) in rows.chunks_exact(m).zip(g) {
        for ((a, re), im) in row.iter().zip(t_re.iter_mut()).zip(t_im.iter_mut()) {
            *re += a * gj.re;
            *im += a * gj.im;
        }
    }
    let [w_re, w_im] = weights;
    let (w_re, w_im) = (&w_re[..m], &w_im[..m]);
    for r in 0..m {
        let (a, b, c, d) = (t_re[r], t_im[r], w_re[r], w_im[r]);
        (t_re[r], t_im[r]) = (a * c - b * d, a * d + b * c);
    }
    for (row, o) in rows.chunks_exact(m).zip(out.iter_mut()) {
        let (re, im) = dot2(row, t_re, t_im);
        *o = c64::new(re, im);
    }
}

/// Pairs summed side by side by [`pair_dots`].
const PAIR_LANES: usize = 4;

/// [`dot2`] of every pair's products with `(x, y)`, into `sums` (the q(q+1)/2 pairs):
/// [`PAIR_LANES`] pairs at a time as the lanes of one vector (`pairs` laid out so), each
/// pair's sum split by the mode's index modulo 4 into four partial sums added as `dot2` adds
/// its own, so that every pair's sum is `dot2`'s, the same operations in the same order (the
/// same values), without `dot2`'s wait on its four sums.
#[multiversion(targets("x86_64+avx2+fma", "x86_64+avx"))]
fn pair_dots(pairs: &[f64], m: usize, x: &[f64], y: &[f64], sums: &mut [(f64, f64)]) {
    for (block, out) in sums.chunks_mut(PAIR_LANES).enumerate() {
        let products = &pairs[block * m * PAIR_LANES..(block + 1) * m * PAIR_LANES];
        // The x and y sums apart, so that the lanes are the pairs.
        let (tx, ty) = (lane_dot(products, &x[..m]), lane_dot(products, &y[..m]));
        for (p, o) in out.iter_mut().enumerate() {
            *o = (tx[p], ty[p]);
        }
    }
}

/// `Σ_r products[r][p] x[r]` for each lane p, split by r modulo 4 as [`dot2`] splits its sums.
#[inline(always)]
fn lane_dot(products: &[f64], x: &[f64]) -> [f64; PAIR_LANES] {
    const L: usize = PAIR_LANES;
    let m = x.len();
    let chunks = m / 4 * 4;
    let at = |r: usize| -> &[f64; L] { products[r * L..(r + 1) * L].try_into().expect("a block of pairs") };
    // [r mod 4][pair]
    let mut partial = [[0.0; L]; 4];
    for r in (0..chunks).step_by(4) {
        for (l, sum) in partial.iter_mut().enumerate() {
            let (a, xr) = (at(r + l), x[r + l]);
            for p in 0..L {
                sum[p] += a[p] * xr;
            }
        }
    }
    let mut total = [0.0; L];
    for p in 0..L {
        total[p] = (partial[0][p] + partial[1][p]) + (partial[2][p] + partial[3][p]);
    }
    for (r, &xr) in x.iter().enumerate().skip(chunks) {
        let a = at(r);
        for p in 0..L {
            total[p] += a[p] * xr;
        }
    }
    total
}

/// `(Σ a x, Σ a y)`: two dot products sharing `a`, on four independent partial sums each so
/// that the loop vectorises (the order of a floating-point sum is otherwise fixed).
#[inline]
fn dot2(a: &[f64], x: &[f64], y: &[f64]) -> (f64, f64) {
    let (mut sx, mut sy) = ([0.0; 4], [0.0; 4]);
    let (ca, cx, cy) = (a.chunks_exact(4), x.chunks_exact(4), y.chunks_exact(4));
    let (ra, rx, ry) = (ca.remainder(), cx.remainder(), cy.remainder());
    for ((a, x), y) in ca.zip(cx).zip(cy) {
        for l in 0..4 {
            sx[l] += a[l] * x[l];
            sy[l] += a[l] * y[l];
        }
    }
    let (mut tx, mut ty) = ((sx[0] + sx[1]) + (sx[2] + sx[3]), (sy[0] + sy[1]) + (sy[2] + sy[3]));
    for ((a, x), y) in ra.iter().zip(rx).zip(ry) {
        tx += a * x;
        ty += a * y;
    }
    (tx, ty)
}

/// `h g` for a dense complex matrix.
fn multiply(h: &Mat<c64>, g: &[c64], out: &mut [c64]) {
    for (i, o) in out.iter_mut().enumerate() {
        *o = (0..g.len()).map(|j| h[(i, j)] * g[j]).sum();
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Reproducible values in [−1, 1] (a linear congruential sequence).
    fn values(n: usize, seed: u64) -> Vec<f64> {
        let mut state = seed;
        (0..n)
            .map(|_| {
                state = state.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
                (state >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
            })
            .collect()
    }

    /// The pairs summed side by side are `dot2`'s sums bit for bit (the modal receptance's
    /// values must not depend on how its loops are vectorised), for mode counts with and
    /// without a remainder modulo 4 and pair counts filling a block of lanes or not.
    #[test]
    fn pairs_summed_side_by_side_are_dot2_bit_for_bit() {
        for m in [1, 3, 4, 7, 137] {
            for count in [1usize, 3, 4, 6, 10] {
                let rows: Vec<Vec<f64>> = (0..count).map(|p| values(m, 7 + p as u64)).collect();
                let mut pairs = vec![0.0; count.div_ceil(PAIR_LANES) * m * PAIR_LANES];
                for (p, row) in rows.iter().enumerate() {
                    for (r, v) in row.iter().enumerate() {
                        pairs[((p / PAIR_LANES) * m + r) * PAIR_LANES + p % PAIR_LANES] = *v;
                    }
                }
                let (x, y) = (values(m, 1), values(m, 2));
                let mut sums = vec![(0.0, 0.0); count];
                pair_dots(&pairs, m, &x, &y, &mut sums);
                for (p, row) in rows.iter().enumerate() {
                    let (a, b) = dot2(row, &x, &y);
                    assert_eq!(
                        (sums[p].0.to_bits(), sums[p].1.to_bits()),
                        (a.to_bits(), b.to_bits()),
                        "m {m}, pair {p}"
                    );
                }
            }
        }
    }

    /// The modal weights written on the parts are `c64`'s `inv` and products bit for bit.
    #[test]
    fn modal_weights_are_the_complex_operations_bit_for_bit() {
        let m = 37;
        let omega_r2: Vec<f64> = values(m, 3).iter().map(|v| 1e6 * (1.0 + v)).collect();
        let c_r: Vec<f64> = values(m, 4).iter().map(|v| 10.0 * (1.0 + v)).collect();
        for omega in [0.0, 3.0, 700.0, 1e4] {
            let (mut inverse, mut derivative) = ([vec![0.0; m], vec![0.0; m]], [vec![0.0; m], vec![0.0; m]]);
            modal_weights(omega, &omega_r2, &c_r, &mut inverse, &mut derivative);
            for r in 0..m {
                let inv = c64::new(omega_r2[r] - omega * omega, omega * c_r[r]).inv();
                let dinv = c64::new(2.0 * omega, -c_r[r]) * inv * inv;
                let got = [inverse[0][r], inverse[1][r], derivative[0][r], derivative[1][r]];
                let expected = [inv.re, inv.im, dinv.re, dinv.im];
                assert_eq!(got.map(f64::to_bits), expected.map(f64::to_bits), "ω {omega}, mode {r}");
            }
        }
    }
}
