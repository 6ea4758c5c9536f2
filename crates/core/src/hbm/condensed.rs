//! The harmonic balance condensed onto the nonlinear directions (paper Eqs. 16-30).
//!
//! Unknowns: the harmonics of `u = Vᵀ U` on the q application directions, coefficient-major
//! (`x[c·q + i]`, see [`super::fourier`]): (2N+1)q unknowns whatever the model size. With
//! `G(x)` the element forces' harmonics (AFT, Eq. 15) and, per harmonic k, `H_k = H(kΩ)` and
//! `u_F,k` from [`Receptance`], the residual is
//!
//! ```text
//! R_k = x_k − λ_F u_F,k δ_k1 + H_k G_k           (complex, x_k = c_k − i s_k)
//! ```
//!
//! i.e. Eq. 29 premultiplied by the condensed flexibility `H_k = (A_qq − A_qp A_pp⁻¹ A_pq)⁻¹`,
//! which the modal sum gives directly (no inversion) and which makes the residual a
//! displacement, compared with the linear response amplitude. The excitation is
//! `λ_F F cos Ωt` (Eq. 18: on the cosine of harmonic 1). In real form, for the pair (c, s):
//!
//! ```text
//! [R_c]   [x_c]       [ Re u_F]   [ Re H   Im H] [G_c]
//! [R_s] = [x_s] − λ_F [−Im u_F] + [−Im H   Re H] [G_s]
//! ```

use faer::{c64, Mat, MatMut};
use multiversion::multiversion;

use super::element_aft::{AftError, ElementAft};
use super::fourier::{coefficient_is_even, cos_index, sin_index, AftPlan, FourierError};
use super::joint_forces::JointForces;
use std::sync::Arc;

use super::receptance::{HarmonicReceptance, Receptance};
use super::structured::{ReducedFactor, StructuredJacobian};
use crate::model::{ModelError, NonlinearModel};

/// Numerical settings of the harmonic balance.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct HbmSettings {
    /// Number of harmonics N (paper: 7).
    pub harmonics: usize,
    /// Time samples per period n_t of the AFT (paper: 300).
    pub samples: usize,
}

impl Default for HbmSettings {
    fn default() -> Self {
        HbmSettings { harmonics: 7, samples: 300 }
    }
}

/// Why a harmonic balance problem could not be set up or evaluated.
#[derive(Debug, thiserror::Error)]
pub enum HbmError {
    #[error(transparent)]
    Fourier(#[from] FourierError),
    #[error(transparent)]
    Model(#[from] ModelError),
    #[error(transparent)]
    Aft(#[from] AftError),
    #[error("the model has no nonlinear element: nothing to condense on (a linear FRF needs no harmonic balance)")]
    NoElements,
    #[error("Newton did not converge at {frequency_hz:.4} Hz, level {level} after {iterations} iterations (relative residual {residual:.3e}); try more harmonics, a closer start or a smaller step")]
    NoConvergence { frequency_hz: f64, level: f64, iterations: usize, residual: f64 },
    #[error("the excitation pattern has length {got}, expected {expected}")]
    ForceLength { got: usize, expected: usize },
    #[error("the balance was not last evaluated at the solution to post-process")]
    NotEvaluated,
}

/// Size of the condensed problem ((2N+1)q unknowns) from which the Newton systems are solved
/// by their structure ([`StructuredJacobian`]): below it a dense LU costs a few milliseconds
/// and the structure saves nothing.
pub const FACTOR_BY_STRUCTURE_FROM: usize = 500;

/// The condensed harmonic balance of a [`NonlinearModel`] under `λ_F F cos Ωt`.
pub struct CondensedHbm<'m> {
    model: &'m NonlinearModel,
    /// The Fourier plan, shared with the balances sharing the linear part.
    plan: Arc<AftPlan>,
    /// The linear part, shared by the balances of one model and excitation
    /// ([`Self::share_linear_part`]).
    receptance: Arc<Receptance>,
    force: Vec<f64>,
    q: usize,
    /// The nonlinear part: the joints' forces by AFT.
    joints: JointForces,
    harmonic: Vec<HarmonicReceptance>,
    h0: Mat<f64>,
    /// Complex force amplitudes of one harmonic and a receptance product, reused.
    amplitudes: Vec<c64>,
    /// The columns of the `H_k` laid out for the assembly ([`Self::assemble_jacobian`]).
    h_columns: Vec<f64>,
    product: Vec<c64>,
    /// `∂R/∂x` of the last [`Self::evaluate_factored`].
    factored: Option<StructuredJacobian>,
    /// The last factored reduced system of the structured Jacobians, the next one's
    /// preconditioner ([`super::structured`]).
    reduced_factor: Option<Arc<ReducedFactor>>,
    /// Solve Newton systems by [`StructuredJacobian`] rather than a dense LU.
    by_structure: bool,
    /// Every element is a slider, whose Jacobian follows from a residual evaluation's slip
    /// flags ([`Self::complete_jacobian`]).
    sliders_only: bool,
    /// Ω and λ_F of the last evaluation, and its x (what post-processing reads is that
    /// evaluation's: [`Self::evaluated_at`]).
    last: Option<(f64, f64)>,
    last_x: Vec<f64>,
    /// The last evaluation made the matrices `H_k` ([`Receptance::prefers_matrix`]).
    matrices_made: bool,
    /// The unknowns of the even harmonics (0, 2, 4, ...), ascending.
    even_unknowns: Vec<usize>,
    /// Per element, the rows of its Jacobian of the other parity than an even column's
    /// (`[0]`) and an odd column's (`[1]`), as 1 (0 elsewhere).
    parity_masks: Vec<[Vec<f64>; 2]>,
    /// The last dense `∂R/∂x` assembled couples no even harmonic with an odd one
    /// ([`Self::decoupled_unknowns`]).
    parity_split: bool,
    /// Offer the split where it holds (default; [`Self::without_parity_split`]).
    splits_parity: bool,
    /// The balance's solutions are half-wave symmetric (every element an odd slider, an even
    /// number of samples, excitation at the fundamental): the even harmonics are pinned at
    /// zero, `R_even = x_even` (see [`Self::pins_even_harmonics`]). Cleared for good by the
    /// first evaluation at an `x` with an even harmonic.
    pins_even: bool,
    /// The last residual was evaluated with the even harmonics pinned.
    pinned: bool,
    /// Number of residual (and Jacobian) evaluations since creation.
    pub evaluations: usize,
}

impl<'m> CondensedHbm<'m> {
    /// Set up the condensed balance of `model` excited by the pattern `force` (N per unit level).
    pub fn new(model: &'m NonlinearModel, force: &[f64], settings: HbmSettings) -> Result<Self, HbmError> {
        let n = model.linear.n_dofs();
        if force.len() != n {
            return Err(HbmError::ForceLength { got: force.len(), expected: n });
        }
        model.check_no_rigid_contacts("the condensed harmonic balance")?;
        if model.elements.is_empty() {
            return Err(HbmError::NoElements);
        }
        let directions: Vec<&[f64]> = model.application_vectors().map(|v| v.as_slice()).collect();
        let receptance = Arc::new(Receptance::new(&model.linear, &directions, force)?);
        let plan = Arc::new(AftPlan::new(settings.harmonics, settings.samples)?);
        Ok(Self::with_receptance(model, force, plan, receptance))
    }

    /// A balance of the same model, excitation and settings that shares this one's linear part
    /// (the receptance: the model's modes, the costly part of [`Self::new`]) and its Fourier
    /// plan, and has state of its own: what the force levels of a study, swept one per
    /// thread, have in common. It evaluates exactly as a balance made by [`Self::new`].
    pub fn share_linear_part(&self) -> Self {
        Self::with_receptance(self.model, &self.force, Arc::clone(&self.plan), Arc::clone(&self.receptance))
    }

    fn with_receptance(
        model: &'m NonlinearModel,
        force: &[f64],
        plan: Arc<AftPlan>,
        receptance: Arc<Receptance>,
    ) -> Self {
        let q = receptance.n_directions();
        let joints = JointForces::new(model, &plan);
        // Static receptance H(0) = Vᵀ K⁻¹ V (real).
        let mut h = HarmonicReceptance::new(q);
        receptance.evaluate_matrix(0.0, &mut h);
        let h0 = Mat::from_fn(q, q, |i, j| h.h[(i, j)].re);
        CondensedHbm {
            model,
            receptance,
            force: force.to_vec(),
            q,
            joints,
            harmonic: (0..plan.n_harmonics()).map(|_| HarmonicReceptance::new(q)).collect(),
            h0,
            amplitudes: vec![c64::new(0.0, 0.0); q],
            h_columns: Vec::new(),
            product: vec![c64::new(0.0, 0.0); q],
            factored: None,
            reduced_factor: None,
            by_structure: q * plan.n_coeffs() >= FACTOR_BY_STRUCTURE_FROM,
            sliders_only: model.elements.iter().all(|e| {
                let law = e.law.as_ref();
                law.slider_stiffness().is_some()
                    && law.n_dirs() == 1
                    && law.n_state() == 1
                    && !law.depends_on_velocity()
            }),
            last: None,
            matrices_made: false,
            last_x: vec![0.0; q * plan.n_coeffs()],
            even_unknowns: (0..plan.n_coeffs())
                .filter(|&c| coefficient_is_even(c))
                .flat_map(|c| c * q..(c + 1) * q)
                .collect(),
            parity_split: false,
            splits_parity: true,
            pins_even: false,
            pinned: false,
            parity_masks: model
                .elements
                .iter()
                .map(|site| {
                    let d = site.law.n_dirs();
                    let odd: Vec<f64> =
                        (0..plan.n_coeffs() * d).map(|i| if coefficient_is_even(i / d) { 0.0 } else { 1.0 }).collect();
                    let even = odd.iter().map(|w| 1.0 - w).collect();
                    [odd, even]
                })
                .collect(),
            plan,
            evaluations: 0,
        }
        .with_even_harmonics_pinned_where_symmetric()
    }

    /// Pin the even harmonics where every solution is half-wave symmetric, `x(t + T/2) =
    /// −x(t)`: every element an odd-symmetric slider (`g` of `−u` is `−g`, and its periodic
    /// state is unique, so a symmetric motion has symmetric forces) and an even number of
    /// samples (so that `t + T/2` is a sample and the stick pattern is symmetric too). The
    /// excitation is at the fundamental, odd. The even harmonics of such a balance are
    /// round-off (~1e-21 of a 1e-5 m motion) and their equations decouple from the odd ones;
    /// pinned, a point costs the odd harmonics' receptance, Jacobian and LU alone, and the
    /// sliders' AFT over half a period. Unlike the split of a Jacobian that is only found
    /// block diagonal ([`SPLIT_FROM`]), this pays at any size: nothing of the even block is
    /// gathered or factored.
    ///
    /// Not where the model leaves the joints' mean positions free once they slip (a part held
    /// by joints alone, each replacing the only stiffness there is): there the balance's
    /// solutions are not isolated (any mean will do), which the whole balance's singular
    /// harmonic-0 equations make the continuation stop on and diagnose, where pinning would
    /// quietly choose the mean zero.
    fn with_even_harmonics_pinned_where_symmetric(mut self) -> Self {
        self.pins_even = self.sliders_only
            && self.model.elements.iter().all(|e| e.law.odd_symmetric())
            && self.plan.n_samples().is_multiple_of(2)
            && self.means_held_when_slipping();
        self
    }

    /// Does the model hold the directions' mean positions with every joint slipping: is the
    /// static stiffness condensed on them, `H(0)⁻¹`, less the stiffness the joints replace,
    /// positive definite (its smallest eigenvalue above 1e-9 of its largest, far above the
    /// round-off of the difference, ~1e-16 of the stiffness)?
    fn means_held_when_slipping(&self) -> bool {
        use faer::linalg::solvers::DenseSolveCore;
        let mut s = self.h0.partial_piv_lu().inverse();
        for (e, site) in self.model.elements.iter().enumerate() {
            let (d, off) = (site.law.n_dirs(), self.joints.offsets[e]);
            for a in 0..d {
                for b in 0..d {
                    s[(off + a, off + b)] -= site.law.replaced_stiffness(a, b);
                }
            }
        }
        let largest = (0..self.q).fold(0.0f64, |m, i| m.max(s[(i, i)].abs()));
        crate::model::symmetric_eigen(s.as_ref())
            .is_some_and(|(values, _)| values.iter().all(|&v| v.is_finite() && v > 1e-9 * largest))
    }

    /// Are the even harmonics pinned at zero (`R_even = x_even`, the identity in `∂R/∂x`) and
    /// the joints' forces evaluated over half a period ([`ElementAft::evaluate_with_symmetry`])?
    /// Where the balance's solutions are half-wave symmetric, until an evaluation at an `x`
    /// with an even harmonic (a guess from elsewhere; a continuation started from the linear
    /// or stuck response keeps them exactly zero), after which the balance is the whole one.
    /// Never with the structured factorisation.
    pub fn pins_even_harmonics(&self) -> bool {
        self.pins_even && !self.by_structure
    }

    /// Number of unknowns (2N+1)q.
    pub fn dimension(&self) -> usize {
        self.q * self.plan.n_coeffs()
    }

    /// Number of nonlinear directions q.
    pub fn n_directions(&self) -> usize {
        self.q
    }

    pub fn plan(&self) -> &AftPlan {
        &self.plan
    }

    pub fn model(&self) -> &NonlinearModel {
        self.model
    }

    pub fn receptance(&self) -> &Receptance {
        &self.receptance
    }

    pub fn force(&self) -> &[f64] {
        &self.force
    }

    /// The linear (all elements removed from the balance, `G = 0`) solution at Ω and level:
    /// for elements in the paper's form that never slip, this is the exact stuck response.
    pub fn linear_solution(&mut self, omega: f64, level: f64) -> Vec<f64> {
        let q = self.q;
        let mut x = vec![0.0; self.dimension()];
        self.receptance.evaluate(omega, &mut self.harmonic[0]);
        for i in 0..q {
            let u = self.harmonic[0].u_force[i] * level;
            x[cos_index(1) * q + i] = u.re;
            x[sin_index(1) * q + i] = -u.im;
        }
        x
    }

    /// The response with every element linearised about rest (its tangent at zero motion: stuck
    /// sliders, zero cubic stiffness...): one Newton step from `x = 0`. This is the exact
    /// solution while every Jenkins/Iwan slider sticks, for elements in the paper's form as well
    /// as for standalone ones, and the natural start of a sweep.
    pub fn stuck_solution(&mut self, omega: f64, level: f64) -> Result<Vec<f64>, HbmError> {
        use faer::linalg::solvers::Solve;
        let n = self.dimension();
        let zero = vec![0.0; n];
        let mut r = vec![0.0; n];
        if self.by_structure {
            // At rest every element is linear: the structured factorisation is the cheap one.
            self.evaluate_factored(&zero, omega, level, &mut r, None, None)?;
            if self.solve_factored(&mut r) {
                return Ok(r.iter().map(|v| -v).collect());
            }
        }
        let mut jac = Mat::zeros(n, n);
        self.evaluate(&zero, omega, level, &mut r, Some(Jacobians { dx: jac.as_mut(), domega: None, dlevel: None }))?;
        let dx = jac.partial_piv_lu().solve(Mat::from_fn(n, 1, |i, _| r[i]));
        Ok((0..n).map(|i| -dx[(i, 0)]).collect())
    }

    /// Residual `R(x; Ω, λ_F)` and, if asked, `∂R/∂x`, `∂R/∂Ω`, `∂R/∂λ_F`.
    pub fn evaluate(
        &mut self,
        x: &[f64],
        omega: f64,
        level: f64,
        residual: &mut [f64],
        jacobian: Option<Jacobians<'_>>,
    ) -> Result<(), HbmError> {
        let want = jacobian.is_some();
        self.residual(x, omega, level, residual, want)?;
        if let Some(Jacobians { dx, domega, dlevel }) = jacobian {
            self.assemble_jacobian(dx, self.plan.n_coeffs());
            self.parameter_derivatives(level, domega, dlevel);
        }
        Ok(())
    }

    /// The residual, with what the Jacobian needs (`∂G`, the matrices `H_k`) if `want`.
    fn residual(
        &mut self,
        x: &[f64],
        omega: f64,
        level: f64,
        residual: &mut [f64],
        want: bool,
    ) -> Result<(), HbmError> {
        self.evaluations += 1;
        self.last = None;
        let q = self.q;
        if self.pins_even && self.even_unknowns.iter().any(|&i| x[i] != 0.0) {
            self.pins_even = false;
        }
        let pinned = self.pins_even_harmonics();
        self.pinned = pinned;
        self.joints.evaluate(self.model, &self.plan, x, omega, want, pinned)?;
        // The matrix H_k for a Jacobian, or where it costs no more than the products H_k G_k
        // that a residual alone needs (and a Jacobian completed from this residual then finds
        // it). The excitation's response u_F only on harmonic 1, the one it drives.
        let matrices = want || self.receptance.prefers_matrix();
        self.matrices_made = matrices;
        for k in 1..=self.plan.n_harmonics() {
            if pinned && k % 2 == 0 {
                continue;
            }
            let hr = &mut self.harmonic[k - 1];
            match (k, matrices) {
                (1, true) => self.receptance.evaluate_matrix(omega, hr),
                (1, false) => self.receptance.evaluate(omega, hr),
                _ => self.receptance.evaluate_unforced(k as f64 * omega, hr, matrices),
            }
        }
        // Harmonic 0: R_0 = x_0 + H(0) G_0 (pinned: R_0 = x_0).
        for i in 0..q {
            let mut r = x[i];
            if !pinned {
                for j in 0..q {
                    r += self.h0[(i, j)] * self.joints.g[j];
                }
            }
            residual[i] = r;
        }
        // Harmonic k: R_k = x_k − λ_F u_F δ_k1 + H_k G_k in the complex form c − i s (pinned
        // and even: R_k = x_k).
        for k in 1..=self.plan.n_harmonics() {
            let (ic, is) = (cos_index(k) * q, sin_index(k) * q);
            if pinned && k % 2 == 0 {
                residual[ic..ic + q].copy_from_slice(&x[ic..ic + q]);
                residual[is..is + q].copy_from_slice(&x[is..is + q]);
                continue;
            }
            let g = &self.joints.g;
            for (j, a) in self.amplitudes.iter_mut().enumerate() {
                *a = c64::new(g[ic + j], -g[is + j]);
            }
            let hr = &mut self.harmonic[k - 1];
            if matrices {
                // H_k is there: q² products instead of the modal sum's 2qm.
                multiply(&hr.h, &self.amplitudes, &mut self.product);
            } else {
                self.receptance.apply(hr, &self.amplitudes, &mut self.product);
            }
            for i in 0..q {
                let mut rc = x[ic + i] + self.product[i].re;
                let mut rs = x[is + i] - self.product[i].im;
                if k == 1 {
                    rc -= level * hr.u_force[i].re;
                    rs += level * hr.u_force[i].im;
                }
                residual[ic + i] = rc;
                residual[is + i] = rs;
            }
        }
        self.last = Some((omega, level));
        self.last_x.copy_from_slice(x);
        Ok(())
    }

    /// Can [`Self::complete_jacobian`] follow a residual evaluation (dense Newton systems,
    /// every element a slider)?
    pub fn completes_jacobian(&self) -> bool {
        self.sliders_only && !self.by_structure
    }

    /// `∂R/∂x` and, as asked, `∂R/∂Ω`, `∂R/∂λ_F` at the point of the last [`Self::evaluate`],
    /// made for the residual alone, as an evaluation with them would have written them: the
    /// sliders' Jacobians from their slip flags, the matrices `H_k` at the same Ω. What
    /// Newton needs at the iterates it does not accept, without evaluating their residual
    /// twice. False, nothing written, when [`Self::completes_jacobian`] is false or there was
    /// no evaluation.
    pub fn complete_jacobian(
        &mut self,
        dx: MatMut<'_, f64>,
        domega: Option<&mut [f64]>,
        dlevel: Option<&mut [f64]>,
    ) -> bool {
        let Some((omega, level)) = self.last.filter(|_| self.completes_jacobian()) else { return false };
        if !self.joints.complete_jacobian(self.model, &self.plan, self.pinned) {
            return false;
        }
        if !self.matrices_made {
            let pinned = self.pinned;
            for (k, hr) in self.harmonic.iter_mut().enumerate().filter(|(k, _)| !(pinned && (k + 1) % 2 == 0)) {
                self.receptance.complete_matrix((k + 1) as f64 * omega, hr);
            }
            self.matrices_made = true;
        }
        self.assemble_jacobian(dx, self.plan.n_coeffs());
        self.parameter_derivatives(level, domega, dlevel);
        true
    }

    /// [`Self::evaluate`] with `∂R/∂x` factored by its structure ([`StructuredJacobian`])
    /// instead of written dense, for [`Self::solve_factored`]: the Newton systems of many
    /// contact directions, whose dense LU would be the whole cost. `Ok(false)` if the
    /// factorisation is singular.
    pub fn evaluate_factored(
        &mut self,
        x: &[f64],
        omega: f64,
        level: f64,
        residual: &mut [f64],
        domega: Option<&mut [f64]>,
        dlevel: Option<&mut [f64]>,
    ) -> Result<bool, HbmError> {
        if let Some(factor) = self.factored.take().and_then(|f| f.reduced_factor()) {
            self.reduced_factor = Some(factor);
        }
        self.residual(x, omega, level, residual, true)?;
        self.parameter_derivatives(level, domega, dlevel);
        self.factored = StructuredJacobian::factor(
            self.q,
            &self.h0,
            &self.harmonic,
            &self.joints.offsets,
            &self.joints.elem_jac,
            self.reduced_factor.clone(),
        );
        Ok(self.factored.is_some())
    }

    /// Overwrite `b` with `(∂R/∂x)⁻¹ b` at the point of the last [`Self::evaluate_factored`];
    /// false if there is none or the result is not finite.
    pub fn solve_factored(&mut self, b: &mut [f64]) -> bool {
        self.factored.as_mut().is_some_and(|f| f.solve(b))
    }

    /// Are the Newton systems solved by their structure ([`Self::evaluate_factored`]) in
    /// sweeps? By default from [`FACTOR_BY_STRUCTURE_FROM`] unknowns.
    pub fn factors_by_structure(&self) -> bool {
        self.by_structure
    }

    /// Choose how sweeps solve the Newton systems: by structure or by a dense LU.
    pub fn set_factor_by_structure(&mut self, by_structure: bool) {
        self.by_structure = by_structure;
    }

    /// The factored Jacobian of the last [`Self::evaluate_factored`].
    pub fn structured_jacobian(&self) -> Option<&StructuredJacobian> {
        self.factored.as_ref()
    }

    /// The unknowns of the even harmonics when the last dense `∂R/∂x` assembled is zero
    /// between them and the odd ones (a half-wave symmetric response, `x(t + T/2) = −x(t)`:
    /// sliders, cubic springs driven at the fundamental), for the corrector to factor the two
    /// blocks apart (`continuation::Problem::decoupled_unknowns`). The even block is the one
    /// that stays regular at the folds of a symmetric branch (which move the odd harmonics).
    pub fn decoupled_unknowns(&self) -> Option<&[usize]> {
        self.parity_split.then_some(self.even_unknowns.as_slice())
    }

    /// The balance with its dense `∂R/∂x` always written whole, the parities coupled by their
    /// round-off: the reference the split is tested against.
    pub fn without_parity_split(mut self) -> Self {
        self.splits_parity = false;
        self.pins_even = false;
        self
    }

    /// The balance with its even harmonics solved like the odd ones even where its solutions
    /// are half-wave symmetric: the reference [`Self::pins_even_harmonics`] is tested against.
    pub fn without_pinned_even_harmonics(mut self) -> Self {
        self.pins_even = false;
        self
    }

    /// Is the even block of the last `∂R/∂x` assembled the identity (the even harmonics
    /// pinned)? For the corrector, which then neither gathers nor factors it.
    pub fn decoupled_block_is_identity(&self) -> bool {
        self.parity_split && self.pinned
    }

    fn assemble_jacobian(&mut self, mut dx: MatMut<'_, f64>, nc: usize) {
        let q = self.q;
        // A response with half-wave symmetry has joints' Jacobians that couple harmonics of
        // one parity only (∂g/∂x(t) is T/2-periodic); the AFT leaves round-off between
        // parities. Where every element's coupling between parities is below
        // `PARITY_COUPLING` of its largest term, it is left out (a change of the Newton
        // matrix by less than that, which moves no converged point beyond round-off) and the
        // matrix is block diagonal in the even and odd harmonics.
        let pinned = self.pinned;
        self.parity_split = pinned
            || self.splits_parity
                && q * nc >= SPLIT_FROM
                && self.model.elements.iter().enumerate().all(|(e, site)| {
                    let stiffness = site.law.slider_stiffness().unwrap_or(0.0);
                    parity_coupling_negligible(
                        &self.joints.elem_jac[e],
                        site.law.n_dirs(),
                        &self.parity_masks[e],
                        stiffness,
                    )
                });
        let split = self.parity_split;
        // Each column of the H_k, harmonic after harmonic, with its real and imaginary parts
        // apart: laid out as a column of ∂R/∂x below its first q rows (cos then sin rows of
        // each harmonic), so that a column is assembled by one pass over both.
        let n_harmonics = self.plan.n_harmonics();
        let per_direction = 2 * q * n_harmonics;
        self.h_columns.resize(q * per_direction, 0.0);
        for (k, hr) in self.harmonic.iter().enumerate() {
            for j in 0..q {
                let block = &mut self.h_columns[j * per_direction + k * 2 * q..j * per_direction + (k + 1) * 2 * q];
                let (re, im) = block.split_at_mut(q);
                for ((re, im), h) in re.iter_mut().zip(im.iter_mut()).zip(hr.h.col_as_slice(j)) {
                    (*re, *im) = (h.re, h.im);
                }
            }
        }
        for (e, site) in self.model.elements.iter().enumerate() {
            let d = site.law.n_dirs();
            let off = self.joints.offsets[e];
            let element = ElementColumns {
                q,
                d,
                h0: self.h0.as_ref().subcols(off, d),
                h_columns: &self.h_columns[off * per_direction..(off + d) * per_direction],
            };
            let je = &self.joints.elem_jac[e];
            for c2 in 0..nc {
                let even = split.then_some(coefficient_is_even(c2));
                for b in 0..d {
                    let col = c2 * q + off + b;
                    let column = dx.as_mut().col_mut(col).try_as_col_major_mut().expect("column-major").as_slice_mut();
                    if pinned && even == Some(true) {
                        // R_even = x_even: a column of the identity.
                        column.fill(0.0);
                    } else {
                        assemble_column(column, &element, je.col_as_slice(c2 * d + b), even);
                    }
                    column[col] += 1.0;
                }
            }
        }
    }

    /// `∂R/∂Ω` and `∂R/∂λ_F`, as asked, after an evaluation that computed `∂G/∂Ω`.
    fn parameter_derivatives(&mut self, level: f64, domega: Option<&mut [f64]>, dlevel: Option<&mut [f64]>) {
        let q = self.q;
        // ∂R/∂Ω = −λ_F ∂u_F/∂Ω + ∂H/∂Ω G + H ∂G/∂Ω, with ∂H_k/∂Ω = k H'(kΩ).
        if let Some(dw) = domega {
            let pinned = self.pinned;
            for i in 0..q {
                dw[i] = if pinned { 0.0 } else { (0..q).map(|j| self.h0[(i, j)] * self.joints.dg_domega[j]).sum() };
            }
            // Laws that do not depend on the velocity (sliders) have ∂G/∂Ω = 0: no product.
            let dg_zero = self.joints.dg_domega.iter().all(|v| *v == 0.0);
            for k in 1..=self.plan.n_harmonics() {
                let hr = &mut self.harmonic[k - 1];
                let (ic, is) = (cos_index(k) * q, sin_index(k) * q);
                if pinned && k % 2 == 0 {
                    dw[ic..ic + q].fill(0.0);
                    dw[is..is + q].fill(0.0);
                    continue;
                }
                let (g, dg) = (&self.joints.g, &self.joints.dg_domega);
                // k dH/dω(kΩ) G_k ...
                for (j, a) in self.amplitudes.iter_mut().enumerate() {
                    *a = c64::new(g[ic + j], -g[is + j]);
                }
                self.receptance.apply_derivative(hr, &self.amplitudes, &mut self.product);
                for i in 0..q {
                    let v = self.product[i] * k as f64;
                    dw[ic + i] = v.re;
                    dw[is + i] = -v.im;
                }
                // ... + H_k ∂G_k/∂Ω − λ_F ∂u_F/∂Ω δ_k1, with the matrix H_k of the Jacobian.
                if !dg_zero {
                    for (j, a) in self.amplitudes.iter_mut().enumerate() {
                        *a = c64::new(dg[ic + j], -dg[is + j]);
                    }
                    multiply(&hr.h, &self.amplitudes, &mut self.product);
                    for i in 0..q {
                        dw[ic + i] += self.product[i].re;
                        dw[is + i] -= self.product[i].im;
                    }
                }
                if k == 1 {
                    for i in 0..q {
                        dw[ic + i] -= level * hr.du_force[i].re;
                        dw[is + i] += level * hr.du_force[i].im;
                    }
                }
            }
        }
        if let Some(dl) = dlevel {
            dl.iter_mut().for_each(|v| *v = 0.0);
            let hr = &self.harmonic[0];
            for i in 0..q {
                dl[cos_index(1) * q + i] = -hr.u_force[i].re;
                dl[sin_index(1) * q + i] = hr.u_force[i].im;
            }
        }
    }

    /// Newton's method at fixed (Ω, λ_F) from `x0`, to `‖R‖ ≤ tolerance · ‖x‖` (R is a
    /// displacement, so the test is relative to the motion itself). Returns the solution and the
    /// number of iterations.
    pub fn solve(
        &mut self,
        omega: f64,
        level: f64,
        x0: &[f64],
        tolerance: f64,
        max_iterations: usize,
    ) -> Result<(Vec<f64>, usize), HbmError> {
        use faer::linalg::solvers::Solve;
        let n = self.dimension();
        let mut x = x0.to_vec();
        let mut r = vec![0.0; n];
        let mut jac = Mat::zeros(n, n);
        let norm = |v: &[f64]| v.iter().map(|a| a * a).sum::<f64>().sqrt();
        let mut rel = f64::INFINITY;
        for it in 0..=max_iterations {
            self.evaluate(&x, omega, level, &mut r, Some(Jacobians { dx: jac.as_mut(), domega: None, dlevel: None }))?;
            rel = norm(&r) / norm(&x).max(f64::MIN_POSITIVE);
            if rel <= tolerance {
                return Ok((x, it));
            }
            if it == max_iterations {
                break;
            }
            let rhs = Mat::from_fn(n, 1, |i, _| r[i]);
            let dx = jac.partial_piv_lu().solve(&rhs);
            for i in 0..n {
                x[i] -= dx[(i, 0)];
            }
        }
        Err(HbmError::NoConvergence {
            frequency_hz: omega / (2.0 * std::f64::consts::PI),
            level,
            iterations: max_iterations,
            residual: rel,
        })
    }

    /// AFT of every element (Eq. 15): `G(x)` and, if `want`, `∂G/∂Ω` and each element's block
    /// of `∂G/∂x` ([`JointForces`]).
    fn element_forces(&mut self, x: &[f64], omega: f64, want: bool) -> Result<(), HbmError> {
        Ok(self.joints.evaluate(self.model, &self.plan, x, omega, want, false)?)
    }

    /// `∂G/∂x` at `x` and Ω (q(2N+1) square, coefficient-major as the unknowns): the joints'
    /// harmonic stiffness, block diagonal over elements, which Hill's method needs assembled
    /// ([`super::stability`]).
    pub fn element_force_jacobian(&mut self, x: &[f64], omega: f64) -> Result<Mat<f64>, HbmError> {
        self.element_forces(x, omega, true)?;
        let jac = self.joints.assembled_jacobian(self.model, self.plan.n_coeffs(), |_, _| {});
        Ok(Mat::from_fn(jac.nrows(), jac.ncols(), |i, j| jac[(i, j)].re))
    }

    /// Ω and λ_F of the last evaluation, if it succeeded.
    pub fn last_evaluation(&self) -> Option<(f64, f64)> {
        self.last
    }

    /// Was the last evaluation (which succeeded) at exactly `x`, Ω, λ_F? Then the element
    /// forces and time samples it left are those of this point.
    pub fn evaluated_at(&self, x: &[f64], omega: f64, level: f64) -> bool {
        self.last == Some((omega, level)) && self.last_x == x
    }

    /// Evaluate the residual at `x`, Ω, λ_F unless the last evaluation was there: the element
    /// forces of that point for post-processing.
    pub fn evaluate_unless_at(&mut self, x: &[f64], omega: f64, level: f64) -> Result<(), HbmError> {
        if !self.evaluated_at(x, omega, level) {
            let mut residual = vec![0.0; self.dimension()];
            self.evaluate(x, omega, level, &mut residual, None)?;
        }
        Ok(())
    }

    /// [`Self::element_force_jacobian`] at the solution `x`, Ω: when the last evaluation was
    /// there (a continuation's converged one, made for the residual alone) and every element
    /// is a slider, completed from its slip flags ([`JointForces::complete_jacobian`]), else
    /// evaluated at `x`.
    pub fn element_force_jacobian_at_last(&mut self, x: &[f64], omega: f64) -> Result<Mat<f64>, HbmError> {
        let here = self.last.is_some_and(|(w, _)| w == omega) && self.last_x == x;
        if !(here && self.sliders_only && self.joints.complete_jacobian(self.model, &self.plan, false)) {
            return self.element_force_jacobian(x, omega);
        }
        let jac = self.joints.assembled_jacobian(self.model, self.plan.n_coeffs(), |_, _| {});
        Ok(Mat::from_fn(jac.nrows(), jac.ncols(), |i, j| jac[(i, j)].re))
    }

    /// `∂G/∂x` for a perturbation `e^{st} p(t)` of the solution last given to
    /// [`Self::element_force_jacobian`] (complex, same layout): the sliders' memory of their
    /// anchor weighted by `e^{−sΔ}` ([`ElementAft::add_memory_delay`]). The AFT is not run
    /// again: only the weights change with `s`.
    pub fn delayed_force_jacobian(&self, omega: f64, s: c64) -> Mat<c64> {
        let (afts, plan) = (&self.joints.afts, &self.plan);
        self.joints.assembled_jacobian(self.model, plan.n_coeffs(), |e, block| {
            afts[e].add_memory_delay(plan, omega, s, block);
        })
    }

    /// Did the last Jacobian include a slider's memory of its anchor, which a perturbation
    /// `e^{st}` delays ([`Self::delayed_force_jacobian`])?
    pub fn has_memory_delay(&self) -> bool {
        self.joints.has_memory_delay()
    }

    /// The AFT state of element `e` after the last evaluation (time samples of u, v, g, slip).
    pub fn element_aft(&self, e: usize) -> &ElementAft {
        &self.joints.afts[e]
    }

    /// Harmonics of the element forces after the last evaluation (coefficient-major, q wide).
    pub fn element_force_harmonics(&self) -> &[f64] {
        &self.joints.g
    }
}

/// The derivatives asked of [`CondensedHbm::evaluate`].
pub struct Jacobians<'a> {
    /// `∂R/∂x` (n × n).
    pub dx: MatMut<'a, f64>,
    /// `∂R/∂Ω`.
    pub domega: Option<&'a mut [f64]>,
    /// `∂R/∂λ_F`.
    pub dlevel: Option<&'a mut [f64]>,
}

/// `h g` for a dense complex matrix (a receptance `H_k` already evaluated).
fn multiply(h: &Mat<c64>, g: &[c64], out: &mut [c64]) {
    for (i, o) in out.iter_mut().enumerate() {
        *o = (0..g.len()).map(|j| h[(i, j)] * g[j]).sum();
    }
}

/// Complex amplitude `c − i s` of harmonic `k ≥ 1` of direction/DOF `i` in a coefficient-major
/// vector of width `width`.
pub fn complex_amplitude(x: &[f64], width: usize, k: usize, i: usize) -> c64 {
    c64::new(x[cos_index(k) * width + i], -x[sin_index(k) * width + i])
}

/// What the columns of one element's block of `∂R/∂x` read: the columns off..off+d of
/// `H(0)` (`h0`) and of the `H_k` (`h_columns`, as [`CondensedHbm::assemble_jacobian`] lays
/// them out, `2qN` per direction).
struct ElementColumns<'a> {
    q: usize,
    d: usize,
    h0: faer::MatRef<'a, f64>,
    h_columns: &'a [f64],
}

/// One column of `∂R/∂x = I + H_block ∂G/∂x` without its identity term, from the element's
/// column `jcol` of `∂G/∂x` (its d directions' coefficients): ∂G/∂x is block diagonal over
/// elements, so the column only meets the element's d columns of H, O(nc d) per entry
/// instead of O(q). Every entry is written (each row meets one harmonic's H), so the matrix
/// needs no fill: the first direction's term is stored (`t + 0.0`: a −0 product as +0, as a
/// sum from zero stores it), the others added, in the order of the directions. `even` is
/// `Some(the column is of an even harmonic)` where the matrix is split by parity: the rows of
/// the other parity are then zero, written as H times zero: the same zeros while H_k is
/// finite (an infinite H_k, a resonance without damping, leaves the column's own parity
/// infinite as well, and the matrix fails to factor either way).
#[multiversion(targets("x86_64+avx2+fma", "x86_64+avx"))]
fn assemble_column(column: &mut [f64], element: &ElementColumns<'_>, jcol: &[f64], even: Option<bool>) {
    let ElementColumns { q, d, h0, h_columns } = *element;
    let (head, rest) = column.split_at_mut(q);
    if even == Some(false) {
        head.fill(0.0);
    } else {
        for a in 0..d {
            let g = jcol[a];
            for (out, h) in head.iter_mut().zip(h0.col(a).iter()) {
                if a == 0 {
                    *out = h * g + 0.0;
                } else {
                    *out += h * g;
                }
            }
        }
    }
    let per_direction = rest.len();
    for a in 0..d {
        let h = &h_columns[a * per_direction..(a + 1) * per_direction];
        for (k0, (out, h)) in rest.chunks_exact_mut(2 * q).zip(h.chunks_exact(2 * q)).enumerate() {
            let k = k0 + 1;
            let (gc, gs) = if even.is_some_and(|even| (k % 2 == 0) != even) {
                (0.0, 0.0)
            } else {
                (jcol[cos_index(k) * d + a], jcol[sin_index(k) * d + a])
            };
            let (cos_rows, sin_rows) = out.split_at_mut(q);
            let (re, im) = h.split_at(q);
            let rows = cos_rows.iter_mut().zip(sin_rows.iter_mut()).zip(re.iter().zip(im));
            for ((oc, os), (hr, hi)) in rows {
                let (c, s) = (hr * gc + hi * gs, -hi * gc + hr * gs);
                if a == 0 {
                    (*oc, *os) = (c + 0.0, s + 0.0);
                } else {
                    (*oc, *os) = (*oc + c, *os + s);
                }
            }
        }
    }
}

/// Coupling between harmonics of opposite parity in an element's Jacobian below this,
/// relative to its largest term, counts as none (the AFT of a half-wave symmetric motion
/// leaves ~1e-16 there; an unsymmetric stick pattern, at least one sample in n_t).
const PARITY_COUPLING: f64 = 1e-12;

/// The Jacobian is offered split by parity from this many unknowns. Below, the check, the two
/// factorisations, their gathers and the elimination of the border cost more than the flops
/// they save: counted on whole runs (instructions), Table 6 (15 unknowns) took 2 % more split
/// and the 10-DOF chain with 4 sliders (60 unknowns) 8 % less.
const SPLIT_FROM: usize = 32;

/// Does an element's Jacobian (`(nc d) × (nc d)`, coefficient-major) couple harmonics of
/// opposite parity by no more than [`PARITY_COUPLING`] of its largest term or of its
/// `stiffness`, whichever is larger? (A stuck slider that replaces the stiffness of its joint
/// has a Jacobian of round-off alone: `k s_j − k_r = 0`.)
#[multiversion(targets("x86_64+avx2+fma", "x86_64+avx"))]
fn parity_coupling_negligible(jacobian: &Mat<f64>, d: usize, masks: &[Vec<f64>; 2], stiffness: f64) -> bool {
    // Per column, the largest term and the largest of the other parity's rows (through the
    // 0/1 mask: one pass without branches), in four lanes the compiler vectorises (a maximum
    // does not depend on the order it is taken in; a NaN term is passed over, as `f64::max`
    // passes it over).
    const L: usize = 4;
    let (mut largest, mut across) = ([0.0_f64; L], [0.0_f64; L]);
    let keep = |m: f64, x: f64| if x > m { x } else { m };
    for j in 0..jacobian.ncols() {
        let mask = &masks[usize::from(!coefficient_is_even(j / d))];
        let column = jacobian.col_as_slice(j);
        let (values, masks) = (column.chunks_exact(L), mask[..column.len()].chunks_exact(L));
        let (value_tail, mask_tail) = (values.remainder(), masks.remainder());
        for (v, m) in values.zip(masks) {
            for l in 0..L {
                largest[l] = keep(largest[l], v[l].abs());
                across[l] = keep(across[l], v[l].abs() * m[l]);
            }
        }
        for (l, (v, m)) in value_tail.iter().zip(mask_tail).enumerate() {
            largest[l] = keep(largest[l], v.abs());
            across[l] = keep(across[l], v.abs() * m);
        }
    }
    let (largest, across) = (largest.into_iter().fold(0.0, keep), across.into_iter().fold(0.0, keep));
    across <= PARITY_COUPLING * largest.max(stiffness)
}
