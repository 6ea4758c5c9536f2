//! Rigid unilateral contact with Coulomb friction by the dynamic Lagrangian frequency-time
//! method (DLFT; Nacivet, Pierre, Thouverez & Jézéquel, J. Sound Vib. 265, 2003),
//! on the condensed balance of [`super::condensed`]: the alternative to a penalty contact, with
//! no contact stiffness to guess.
//!
//! **What is solved.** `x` holds the harmonics 0..N of the relative displacements on the q
//! contact directions (per contact: tangential, then the normal approach, as for [`Contact`]),
//! `H(kΩ)` is the condensed receptance and `Z = H⁻¹` the condensed dynamic stiffness, harmonic
//! by harmonic. The contact forces `λ` (variations about the preloaded state, as the `g` of
//! [`Contact`]) balance the linear part:
//!
//! ```text
//! R(x) = x − λ_F u_F + H λ(x) = 0,    i.e.  λ = g_lin(x) = Z (λ_F u_F − x)        (1)
//! ```
//!
//! with `λ` subject, at every time sample `t_j`, to the Signorini and Coulomb conditions of a
//! rigid contact of normal preload N0: `N = N0 + λ_n ≥ 0`, `x_n ≤ 0`, `N x_n = 0`;
//! `|λ_t| ≤ μN`, no tangential motion while `|λ_t| < μN`, slip against the motion otherwise.
//!
//! **DLFT** (Nacivet et al.). The force is predicted in the frequency domain as the
//! linear force plus a penalty `ε` on the relative displacement,
//!
//! ```text
//! λ_u = g_lin(x) + ε x                                                                 (2)
//! ```
//!
//! and corrected sample by sample in time: open where `N0 + λ_u,n ≤ 0` (`N = 0`, `λ_t = 0`);
//! closed otherwise with `λ_n = λ_u,n`; tangentially a stick prediction adds the *increment*
//! of `λ_u,t` to the previous sample's force, `λ_t(t_j) = λ_t(t_j−1) + λ_u,t(t_j) − λ_u,t(t_j−1)`,
//! and slip projects it on the disc of radius μN. The correction is then projected back on
//! the N harmonics and inserted in (1).
//!
//! **The correction is the penalty contact law.** Writing `λ_u = ε y`, the correction above is
//! the return mapping of [`Contact`] with `k_t = k_n = ε` applied to the "displacement"
//! `y = x + g_lin(x)/ε`: `N = max(0, N0 + ε y_n)`; stick keeps the slider `w` so that
//! `T = ε (y_t − w)` grows by the increments of `ε y_t`; slip and separation move it. The
//! starting value of the stick force (which DLFT implementations often settle by marching two
//! periods) is the periodic regime of that law, found as for any hysteretic element
//! ([`super::element_aft`]: from the last open sample, where the slider resets, or by
//! marching periods until the state repeats). The DLFT force is the AFT of that law at `y(x)`,
//! with its analytic Jacobian `∂λ/∂y`, and
//!
//! ```text
//! ∂R/∂x = I + H (∂λ/∂y)(I − Z/ε).                                                      (3)
//! ```
//!
//! **Exact constraints need one sample per unknown.** At a solution the projection of `λ`
//! equals `g_lin(x)`, so `ε x = P[λ_u − λ]` (P: the projection on N harmonics of the samples).
//! With `n_t = 2N+1` samples, sampling and P are inverse one-to-one maps between the 2N+1
//! coefficients and the 2N+1 samples, so `λ(t_j) = g_lin(t_j)` and `ε x(t_j) = λ_u(t_j) − λ(t_j)` at every sample: zero where the
//! contact is closed (no penetration) and, tangentially, zero increment where it sticks (no
//! slip between samples); where it is open, `x_n(t_j) < 0`. The constraints then hold exactly
//! at the samples and the solution does not depend on ε (to round-off): this is the
//! collocation form, `HbmSettings { harmonics: N, samples: 2N + 1 }`, and the rigid limit of
//! the penalty contact sampled the same way, which approaches it as 1/k (tests/hbm_dlft.rs:
//! 2.1e-2, 2.1e-3, 2.1e-4 at k = 1e8, 1e9, 1e10 N/m on a 1e6 N/m structure, N = 7).
//!
//! With `n_t > 2N+1` samples (oversampled, as for smooth laws), `n_t` constraints cannot all
//! hold for a displacement of 2N+1 coefficients: the stick plateaus and closed intervals of a
//! rigid contact are not trigonometric polynomials. DLFT then satisfies them in the projected
//! sense only, weighted by ε, and its solution moves with ε by the order of the truncation
//! error; the penalty contact, as k → ∞, tries to satisfy all `n_t` and locks (its solution
//! first approaches the rigid one, then leaves it: on the quasi-static test case at N = 7 and
//! 1024 samples, 3.9e-2 from the exact cycle at k = 1e8 N/m, 1.1e-1 at 1e10, 5.3e-1 at 1e11).
//! Measured on the quasi-static test, the change of the oversampled DLFT solution between ε/10
//! and 10ε is 2.7e-2, 1.05e-2 and 3.3e-3 of its norm at N = 7, 15, 31, falling like the
//! collocated solution's distance to the exact cycle (2.3e-2, 8.6e-3, 3.0e-3). Both forms
//! converge as N grows; only the collocated one is free of ε at a given N.
//!
//! **Robustness.** The residual is piecewise smooth, with a kink wherever a sample switches
//! between stick, slip and separation; Newton can cycle between such pieces. Measured on the
//! 2-DOF test model (0.1 kg and 0.01 kg on 1e6 N/m, 60 Hz), continuation in force level from
//! the stuck state ([`DlftLevelSweep`]) reaches level 1 with the collocated form at N = 7 but
//! stops (Newton cycling) at level 0.502 at N = 15 and 31, where the oversampled form (512
//! samples) passes at N = 7, 15 and 31. Level 0.5 is that model's shakedown limit: from the
//! onset of slip (0.3125) up to it, the contact slips during the first period only and then
//! sticks (a continuum of stuck periodic solutions, the one computed fixed by the law's
//! stuck-mean start); above it, it slips both ways every period, and the branch has a corner
//! there. The penalty contact at k ≥ 1e8 N/m stops at the onset of slip (level 0.31) with
//! either sampling. A cold Newton solve ([`DlftHbm::solve`]) is less robust than the level
//! continuation.
//!
//! **Choice of ε.** ε sets how the prediction weighs the constraint against the linear force,
//! hence the conditioning of (3) and Newton's path, not (collocated) the solution. Nacivet et
//! al. take it of the order of the structure's stiffness seen by the contact;
//! [`DlftHbm::default_epsilon`] is the mean of `|Z_ii(Ω)|` at harmonic 1. For a quasi-static
//! structure (`Z ≈ K` at every harmonic) with a diagonal `K = k I` and `ε = k`, `I − Z/ε`
//! vanishes, the prediction is the external force and Newton converges in one step.
//!
//! Scope: a Newton solve at fixed (Ω, λ_F) ([`DlftHbm::solve`]) and continuation in Ω or λ_F
//! ([`DlftFrequencySweep`], [`DlftLevelSweep`]); dense matrices of size (2N+1)q (contacts are
//! few here: a patch of many nodes would want the structured solvers of the penalty balance).

use std::sync::Arc;

use faer::linalg::matmul::matmul;
use faer::linalg::solvers::{DenseSolveCore, Solve};
use faer::{c64, Accum, Mat, MatMut, Par};

use super::condensed::{HbmError, HbmSettings, Jacobians};
use super::element_aft::ElementAft;
use super::fourier::{cos_index, sin_index, AftPlan};
use super::receptance::{HarmonicReceptance, Receptance};
use super::sweep::{from_level_ramp, off_resonance_of, resumed_past_stops, within, SweepError};
use crate::continuation::{
    continue_branch, Branch, Options, PointObserver, Problem, ProblemError, ProgressOverWhole, Scales, Silent,
};
use crate::elements::{Contact, ElementError};
use crate::model::{LinearModel, ModelError, NonlinearModel};

/// A rigid point contact, defined with the models that hold it.
pub use crate::model::RigidContact;

/// The DLFT balance of a linear model with rigid contacts under `λ_F F cos Ωt`.
pub struct DlftHbm {
    plan: AftPlan,
    /// The linear part, shared by the balances of one model and excitation
    /// ([`Self::share_linear_part`]).
    receptance: Arc<Receptance>,
    contacts: Vec<RigidContact>,
    force: Vec<f64>,
    q: usize,
    offsets: Vec<usize>,
    /// The correction law of each contact: [`Contact`] with `k_t = k_n = ε`.
    laws: Vec<Contact>,
    afts: Vec<ElementAft>,
    epsilon: f64,
    /// Frequency at which the per-harmonic matrices below were computed.
    omega: f64,
    harmonic: HarmonicReceptance,
    /// `H` and `B = I − Z/ε` in the real coefficient-major layout, block diagonal per
    /// harmonic, and their derivatives with respect to Ω.
    h_real: Mat<f64>,
    b_real: Mat<f64>,
    dh_real: Mat<f64>,
    db_real: Mat<f64>,
    /// `u_F` of harmonic 1 in the real layout (cos, sin pair per direction), and `∂u_F/∂Ω`.
    u_force: Vec<f64>,
    du_force: Vec<f64>,
    // Work buffers.
    y: Vec<f64>,
    dy: Vec<f64>,
    dlambda_domega: Vec<f64>,
    lambda: Vec<f64>,
    dlambda: Mat<f64>,
    hj: Mat<f64>,
    elem_y: Vec<Vec<f64>>,
    elem_g: Vec<Vec<f64>>,
    elem_jac: Vec<Mat<f64>>,
    elem_dw: Vec<Vec<f64>>,
}

impl DlftHbm {
    /// Set up the balance; `epsilon` (N/m) is the DLFT penalty of the prediction, of the order
    /// of the condensed dynamic stiffness ([`DlftHbm::default_epsilon`]). With
    /// `settings.samples = 2 * settings.harmonics + 1` the constraints hold exactly at the
    /// samples and the solution does not depend on ε; with more samples it does, by the order of
    /// the truncation error (module docs).
    pub fn new(
        linear: &LinearModel,
        contacts: &[RigidContact],
        force: &[f64],
        settings: HbmSettings,
        epsilon: f64,
    ) -> Result<Self, HbmError> {
        let receptance = Arc::new(Self::receptance_of(linear, contacts, force)?);
        Self::with_receptance(contacts, force, settings, epsilon, receptance)
    }

    /// The balance of a model of rigid contacts ([`NonlinearModel::with_rigid_contacts`]), which
    /// must have no other element (DLFT imposes the contacts' constraints only), with the
    /// default ε at `omega` (rad/s, [`DlftHbm::default_epsilon`]; collocated, the solution does
    /// not depend on it).
    pub fn for_model(
        model: &NonlinearModel,
        force: &[f64],
        settings: HbmSettings,
        omega: f64,
    ) -> Result<Self, HbmError> {
        if let Some(e) = model.elements.first() {
            return Err(HbmError::Model(ModelError::Invalid(format!(
                "the DLFT balance solves rigid contacts only, and the model has the element {:?} ({})",
                e.name,
                e.law.kind()
            ))));
        }
        let contacts = &model.rigid_contacts;
        let receptance = Arc::new(Self::receptance_of(&model.linear, contacts, force)?);
        let epsilon = mean_dynamic_stiffness(&receptance, omega);
        Self::with_receptance(contacts, force, settings, epsilon, receptance)
    }

    /// The receptance on the contacts' directions, after checking their number and lengths.
    fn receptance_of(linear: &LinearModel, contacts: &[RigidContact], force: &[f64]) -> Result<Receptance, HbmError> {
        let n = linear.n_dofs();
        if force.len() != n {
            return Err(HbmError::ForceLength { got: force.len(), expected: n });
        }
        if contacts.is_empty() {
            return Err(HbmError::NoElements);
        }
        for c in contacts {
            if !matches!(c.directions.len(), 2 | 3) {
                return Err(HbmError::Model(ModelError::Invalid(format!(
                    "contact {:?}: needs 2 or 3 application vectors, got {}",
                    c.name,
                    c.directions.len()
                ))));
            }
            for v in &c.directions {
                if v.len() != n {
                    return Err(HbmError::Model(ModelError::WrongLength {
                        what: format!("application vector of contact {:?}", c.name),
                        len: v.len(),
                        expected: n,
                    }));
                }
            }
        }
        let directions: Vec<&[f64]> = contacts.iter().flat_map(|c| c.directions.iter().map(|v| v.as_slice())).collect();
        Ok(Receptance::new(linear, &directions, force)?)
    }

    /// A balance of the same contacts, excitation, settings and ε that shares this one's linear
    /// part (the receptance: the model's modes, the costly part of [`Self::new`]) and has state
    /// of its own, as [`super::CondensedHbm::share_linear_part`]: it evaluates exactly as a
    /// balance made by [`Self::new`].
    pub fn share_linear_part(&self) -> Self {
        let settings = HbmSettings { harmonics: self.plan.n_harmonics(), samples: self.plan.n_samples() };
        Self::with_receptance(&self.contacts, &self.force, settings, self.epsilon, Arc::clone(&self.receptance))
            .expect("the settings of a balance that was set up")
    }

    fn with_receptance(
        contacts: &[RigidContact],
        force: &[f64],
        settings: HbmSettings,
        epsilon: f64,
        receptance: Arc<Receptance>,
    ) -> Result<Self, HbmError> {
        let invalid = |m: String| HbmError::Model(ModelError::Invalid(m));
        if !(epsilon.is_finite() && epsilon > 0.0) {
            return Err(invalid(format!("DLFT: epsilon must be a finite number > 0 (N/m), got {epsilon}")));
        }
        let mut laws = Vec::with_capacity(contacts.len());
        let mut offsets = Vec::with_capacity(contacts.len());
        let mut q = 0;
        for c in contacts {
            let element_error = |e: ElementError| invalid(format!("contact {:?}: {e}", c.name));
            let law = if c.directions.len() == 2 {
                Contact::new_2d(epsilon, epsilon, c.friction, c.preload)
            } else {
                Contact::new_3d(epsilon, epsilon, c.friction, c.preload)
            }
            .map_err(element_error)?;
            offsets.push(q);
            q += c.directions.len();
            laws.push(law);
        }
        let plan = AftPlan::new(settings.harmonics, settings.samples)?;
        let nc = plan.n_coeffs();
        let dim = nc * q;
        let afts = laws.iter().map(|l| ElementAft::new(l, &plan)).collect();
        let dims: Vec<usize> = contacts.iter().map(|c| c.directions.len() * nc).collect();
        Ok(DlftHbm {
            receptance,
            contacts: contacts.to_vec(),
            force: force.to_vec(),
            q,
            offsets,
            laws,
            afts,
            epsilon,
            omega: f64::NAN,
            harmonic: HarmonicReceptance::new(q),
            h_real: Mat::zeros(dim, dim),
            b_real: Mat::zeros(dim, dim),
            dh_real: Mat::zeros(dim, dim),
            db_real: Mat::zeros(dim, dim),
            u_force: vec![0.0; dim],
            du_force: vec![0.0; dim],
            y: vec![0.0; dim],
            dy: vec![0.0; dim],
            dlambda_domega: vec![0.0; dim],
            lambda: vec![0.0; dim],
            dlambda: Mat::zeros(dim, dim),
            hj: Mat::zeros(dim, dim),
            elem_y: dims.iter().map(|&m| vec![0.0; m]).collect(),
            elem_g: dims.iter().map(|&m| vec![0.0; m]).collect(),
            elem_jac: dims.iter().map(|&m| Mat::zeros(m, m)).collect(),
            elem_dw: dims.iter().map(|&m| vec![0.0; m]).collect(),
            plan,
        })
    }

    /// A DLFT penalty of the order of the condensed dynamic stiffness at `omega`: the mean of
    /// `|Z_ii|` at harmonic 1 (Nacivet et al. take ε of the order of the structure's stiffness).
    pub fn default_epsilon(
        linear: &LinearModel,
        contacts: &[RigidContact],
        force: &[f64],
        omega: f64,
    ) -> Result<f64, HbmError> {
        Ok(mean_dynamic_stiffness(&Self::receptance_of(linear, contacts, force)?, omega))
    }

    /// `‖u_F(Ω)‖`: the contact directions' response to the force at unit level with the
    /// contacts removed.
    pub fn free_response_norm(&self, omega: f64) -> f64 {
        let mut harmonic = HarmonicReceptance::new(self.q);
        self.receptance.evaluate(omega, &mut harmonic);
        harmonic.u_force.iter().map(|u| u.norm_sqr()).sum::<f64>().sqrt()
    }

    /// Number of unknowns (2N+1)q.
    pub fn dimension(&self) -> usize {
        self.q * self.plan.n_coeffs()
    }

    /// Number of contact directions q.
    pub fn n_directions(&self) -> usize {
        self.q
    }

    pub fn plan(&self) -> &AftPlan {
        &self.plan
    }

    /// The linear part: the receptance on the contact directions, which also recovers any
    /// output from the contact forces (Eq. 27, as for the condensed balance).
    pub fn receptance(&self) -> &Receptance {
        &self.receptance
    }

    /// The excitation pattern (N per unit level).
    pub fn force(&self) -> &[f64] {
        &self.force
    }

    pub fn contacts(&self) -> &[RigidContact] {
        &self.contacts
    }

    /// The DLFT penalty ε (N/m).
    pub fn epsilon(&self) -> f64 {
        self.epsilon
    }

    /// The stuck solution: a rigid contact that sticks and stays closed has no relative
    /// motion, `x = 0` (exact while no sample slips or opens).
    pub fn stuck_solution(&self) -> Vec<f64> {
        vec![0.0; self.dimension()]
    }

    /// The contact forces `λ(x)` (harmonics, coefficient-major) of the last evaluation.
    pub fn contact_forces(&self) -> &[f64] {
        &self.lambda
    }

    /// The AFT state of contact `e` after the last evaluation; its samples of `g` are the
    /// contact force variations `(T, N − N0)` and its `u` samples are `y = λ_u/ε`.
    pub fn contact_aft(&self, e: usize) -> &ElementAft {
        &self.afts[e]
    }

    /// `H`, `B = I − Z/ε` and their Ω-derivatives per harmonic, in the real (cos, sin) layout
    /// of [`super::condensed`]: a complex q×q block `A` acts on the pair `(c, s)` of amplitudes
    /// `c − i s` as `[[Re A, Im A], [−Im A, Re A]]`. Harmonic k sees `H(kΩ)`, so
    /// `∂H_k/∂Ω = k H'(kΩ)`, and `∂Z/∂Ω = −Z (∂H/∂Ω) Z`.
    fn prepare(&mut self, omega: f64) {
        if omega == self.omega {
            return;
        }
        let (q, nh, eps) = (self.q, self.plan.n_harmonics(), self.epsilon);
        for m in [&mut self.h_real, &mut self.b_real, &mut self.dh_real, &mut self.db_real] {
            m.fill(0.0);
        }
        self.u_force.iter_mut().chain(self.du_force.iter_mut()).for_each(|v| *v = 0.0);
        let identity = |i: usize, j: usize| f64::from(u8::from(i == j));
        // Harmonic 0: real, independent of Ω.
        self.receptance.evaluate_matrix(0.0, &mut self.harmonic);
        let h0 = Mat::from_fn(q, q, |i, j| self.harmonic.h[(i, j)].re);
        let z0 = h0.partial_piv_lu().inverse();
        for i in 0..q {
            for j in 0..q {
                self.h_real[(i, j)] = h0[(i, j)];
                self.b_real[(i, j)] = identity(i, j) - z0[(i, j)] / eps;
            }
        }
        for k in 1..=nh {
            self.receptance.evaluate_matrix(k as f64 * omega, &mut self.harmonic);
            let h = &self.harmonic.h;
            let dh = self.receptance.derivative_matrix(&self.harmonic) * faer::Scale(c64::new(k as f64, 0.0));
            let z = h.partial_piv_lu().inverse();
            // ∂B/∂Ω = −(∂Z/∂Ω)/ε = Z (∂H/∂Ω) Z / ε.
            let db = &z * &dh * &z * faer::Scale(c64::new(1.0 / eps, 0.0));
            let (ic, is) = (cos_index(k) * q, sin_index(k) * q);
            for i in 0..q {
                for j in 0..q {
                    let b = c64::new(identity(i, j), 0.0) - z[(i, j)] / eps;
                    for (target, a) in [
                        (&mut self.h_real, h[(i, j)]),
                        (&mut self.b_real, b),
                        (&mut self.dh_real, dh[(i, j)]),
                        (&mut self.db_real, db[(i, j)]),
                    ] {
                        target[(ic + i, ic + j)] = a.re;
                        target[(ic + i, is + j)] = a.im;
                        target[(is + i, ic + j)] = -a.im;
                        target[(is + i, is + j)] = a.re;
                    }
                }
                if k == 1 {
                    let (u, du) = (self.harmonic.u_force[i], self.harmonic.du_force[i]);
                    self.u_force[ic + i] = u.re;
                    self.u_force[is + i] = -u.im;
                    self.du_force[ic + i] = du.re;
                    self.du_force[is + i] = -du.im;
                }
            }
        }
        self.omega = omega;
    }

    /// Residual `R(x) = x − λ_F u_F + H λ(y(x))` and, if asked, its derivatives:
    ///
    /// ```text
    /// y       = B x + (I − B) λ_F u_F                       (B = I − Z/ε)
    /// ∂R/∂x   = I + H (∂λ/∂y) B
    /// ∂R/∂λ_F = −u_F + H (∂λ/∂y)(I − B) u_F
    /// ∂R/∂Ω   = −λ_F ∂u_F/∂Ω + (∂H/∂Ω) λ + H [(∂λ/∂y) ∂y/∂Ω + ∂λ/∂Ω|_y],
    /// ∂y/∂Ω   = (∂B/∂Ω)(x − λ_F u_F) + (I − B) λ_F ∂u_F/∂Ω.
    /// ```
    pub fn evaluate(
        &mut self,
        x: &[f64],
        omega: f64,
        level: f64,
        residual: &mut [f64],
        jacobians: Option<Jacobians<'_>>,
    ) -> Result<(), HbmError> {
        self.prepare(omega);
        let (q, nc, n) = (self.q, self.plan.n_coeffs(), self.dimension());
        let want = jacobians.is_some();
        // y = B (x − λ_F u_F) + λ_F u_F.
        for i in 0..n {
            let mut v = 0.0;
            for j in 0..n {
                let b = self.b_real[(i, j)];
                if b != 0.0 {
                    v += b * (x[j] - level * self.u_force[j]);
                }
            }
            self.y[i] = v + level * self.u_force[i];
        }
        // The correction: AFT of the penalty law at y, contact by contact.
        if want {
            self.dlambda.fill(0.0);
        }
        for (e, law) in self.laws.iter().enumerate() {
            let d = law_dirs(law);
            let off = self.offsets[e];
            for c in 0..nc {
                for a in 0..d {
                    self.elem_y[e][c * d + a] = self.y[c * q + off + a];
                }
            }
            let jac = if want { Some((self.elem_jac[e].as_mut(), &mut self.elem_dw[e][..])) } else { None };
            self.afts[e].evaluate(law, &self.plan, omega, &self.elem_y[e], &mut self.elem_g[e], jac)?;
            for c in 0..nc {
                for a in 0..d {
                    self.lambda[c * q + off + a] = self.elem_g[e][c * d + a];
                    if want {
                        self.dlambda_domega[c * q + off + a] = self.elem_dw[e][c * d + a];
                        for c2 in 0..nc {
                            for b in 0..d {
                                self.dlambda[(c * q + off + a, c2 * q + off + b)] =
                                    self.elem_jac[e][(c * d + a, c2 * d + b)];
                            }
                        }
                    }
                }
            }
        }
        for i in 0..n {
            residual[i] = x[i] - level * self.u_force[i] + dot(self.h_real.row(i), &self.lambda);
        }
        let Some(jacobians) = jacobians else { return Ok(()) };
        // H ∂λ/∂y, shared by the three derivatives.
        matmul(self.hj.as_mut(), Accum::Replace, self.h_real.as_ref(), self.dlambda.as_ref(), 1.0, Par::Seq);
        let mut dx = jacobians.dx;
        matmul(dx.as_mut(), Accum::Replace, self.hj.as_ref(), self.b_real.as_ref(), 1.0, Par::Seq);
        for i in 0..n {
            dx[(i, i)] += 1.0;
        }
        if let Some(dlevel) = jacobians.dlevel {
            // (I − B) u_F into dy, then −u_F + H (∂λ/∂y) dy.
            for i in 0..n {
                self.dy[i] = self.u_force[i] - dot(self.b_real.row(i), &self.u_force);
            }
            for i in 0..n {
                dlevel[i] = -self.u_force[i] + dot(self.hj.row(i), &self.dy);
            }
        }
        if let Some(domega) = jacobians.domega {
            for i in 0..n {
                let mut v = level * (self.du_force[i] - dot(self.b_real.row(i), &self.du_force));
                for j in 0..n {
                    v += self.db_real[(i, j)] * (x[j] - level * self.u_force[j]);
                }
                self.dy[i] = v;
            }
            for i in 0..n {
                domega[i] = -level * self.du_force[i]
                    + dot(self.dh_real.row(i), &self.lambda)
                    + dot(self.hj.row(i), &self.dy)
                    + dot(self.h_real.row(i), &self.dlambda_domega);
            }
        }
        Ok(())
    }

    /// Newton's method at fixed (Ω, λ_F) from `x0` to `‖R‖ ≤ tolerance · max(‖x‖, λ_F ‖u_F‖)`
    /// (the scale of a free response, so that a stuck contact's `x = 0` is reached); the
    /// solution and the number of iterations. The rigid contact makes `R` piecewise smooth with
    /// many more kinks than a penalty law (every sample's stick/slip/open state switches on a
    /// hyperplane), so a full step that increases `‖R‖` is halved (up to 8 times) before it is
    /// taken.
    pub fn solve(
        &mut self,
        omega: f64,
        level: f64,
        x0: &[f64],
        tolerance: f64,
        max_iterations: usize,
    ) -> Result<(Vec<f64>, usize), HbmError> {
        let n = self.dimension();
        let mut x = x0.to_vec();
        let mut trial = x0.to_vec();
        let mut r = vec![0.0; n];
        let mut jac = Mat::zeros(n, n);
        let norm = |v: &[f64]| v.iter().map(|a| a * a).sum::<f64>().sqrt();
        let mut rel = f64::INFINITY;
        for it in 0..=max_iterations {
            self.evaluate(&x, omega, level, &mut r, Some(Jacobians { dx: jac.as_mut(), domega: None, dlevel: None }))?;
            let scale = norm(&x).max(level.abs() * norm(&self.u_force)).max(f64::MIN_POSITIVE);
            rel = norm(&r) / scale;
            if rel <= tolerance {
                return Ok((x, it));
            }
            if it == max_iterations {
                break;
            }
            let dx = jac.partial_piv_lu().solve(Mat::from_fn(n, 1, |i, _| r[i]));
            let r_norm = norm(&r);
            let mut step = 1.0;
            for _ in 0..8 {
                for i in 0..n {
                    trial[i] = x[i] - step * dx[(i, 0)];
                }
                self.evaluate(&trial, omega, level, &mut r, None)?;
                if norm(&r) < r_norm {
                    break;
                }
                step *= 0.5;
            }
            x.copy_from_slice(&trial);
        }
        Err(HbmError::NoConvergence {
            frequency_hz: omega / (2.0 * std::f64::consts::PI),
            level,
            iterations: max_iterations,
            residual: rel,
        })
    }
}

/// Continuation in frequency of the DLFT balance at a fixed force level, for
/// [`crate::continuation::continue_branch`] (`λ` is Ω, rad/s).
pub struct DlftFrequencySweep<'a> {
    pub dlft: &'a mut DlftHbm,
    pub level: f64,
    /// A typical `‖x‖` for the continuation's scaling ([`Scales::unknowns`]); `None`: from the
    /// start point and the first tangent, which size nothing for a start that sticks (`x = 0`
    /// and a zero tangent): [`sweep_frequency`] gives the free response there.
    pub unknowns_scale: Option<f64>,
}

/// Continuation in force level of the DLFT balance at a fixed frequency (`λ` is λ_F).
pub struct DlftLevelSweep<'a> {
    pub dlft: &'a mut DlftHbm,
    pub omega: f64,
}

impl Problem for DlftFrequencySweep<'_> {
    fn dimension(&self) -> usize {
        self.dlft.dimension()
    }

    fn evaluate(
        &mut self,
        x: &[f64],
        omega: f64,
        residual: &mut [f64],
        jacobian: Option<(MatMut<'_, f64>, &mut [f64])>,
    ) -> Result<(), ProblemError> {
        let jac = jacobian.map(|(dx, dl)| Jacobians { dx, domega: Some(dl), dlevel: None });
        self.dlft.evaluate(x, omega, self.level, residual, jac).map_err(problem_error)
    }

    fn scales(&self) -> Scales {
        Scales { unknowns: self.unknowns_scale, residual: None }
    }
}

impl Problem for DlftLevelSweep<'_> {
    fn dimension(&self) -> usize {
        self.dlft.dimension()
    }

    fn evaluate(
        &mut self,
        x: &[f64],
        level: f64,
        residual: &mut [f64],
        jacobian: Option<(MatMut<'_, f64>, &mut [f64])>,
    ) -> Result<(), ProblemError> {
        let jac = jacobian.map(|(dx, dl)| Jacobians { dx, domega: None, dlevel: Some(dl) });
        self.dlft.evaluate(x, self.omega, level, residual, jac).map_err(problem_error)
    }

    /// Displacements and residuals on the scale of the free response at unit level: a sweep
    /// that starts stuck has `x = 0` and a zero tangent there, which size nothing.
    fn scales(&self) -> Scales {
        let free = self.dlft.free_response_norm(self.omega);
        Scales { unknowns: Some(free), residual: Some(free) }
    }
}

/// Continue the DLFT balance at force level `level` from `omega_start` to `omega_end` (rad/s,
/// either direction) from the stuck solution, as [`super::sweep_frequency`] does for the
/// penalty balance: a start moved off an undamped resonance ([`off_resonance_of`]), and when
/// Newton cannot reach the first point from `x = 0`, the start found by continuation in the
/// force level from a thousandth of `level`. The continuation's scale of `x` is the contacts'
/// free response `level ‖u_F(Ω_start)‖` (the relative motion with the contacts removed), since
/// a stuck start has `x = 0`.
pub fn sweep_frequency<O: ?Sized + for<'a> PointObserver<DlftFrequencySweep<'a>>>(
    dlft: &mut DlftHbm,
    level: f64,
    omega_start: f64,
    omega_end: f64,
    options: &Options,
    observer: &mut O,
) -> Result<Branch, SweepError> {
    let omega_start =
        off_resonance_of(&mut DlftFrequencySweep { dlft, level, unknowns_scale: None }, omega_start, omega_end);
    let free = level * dlft.free_response_norm(omega_start);
    let unknowns_scale = (free.is_finite() && free > 0.0).then_some(free);
    let guess = dlft.stuck_solution();
    let ramp = |omega: f64| {
        move |dlft: &mut DlftHbm, ramp: &Options| sweep_level(dlft, omega, 1e-3 * level, level, ramp, &mut Silent)
    };
    let branch = from_level_ramp(
        dlft,
        &guess,
        options,
        |dlft, guess| {
            let mut problem = DlftFrequencySweep { dlft, level, unknowns_scale };
            continue_branch(&mut problem, guess, omega_start, omega_end, options, observer)
        },
        ramp(omega_start),
    )?;
    let band = (omega_end - omega_start).abs();
    Ok(resumed_past_stops(
        dlft,
        branch,
        omega_end,
        options,
        band,
        |dlft, guess, from, to| {
            let bridge = within(options, band, from, to);
            from_level_ramp(
                dlft,
                guess,
                &bridge,
                |dlft, guess| {
                    let mut problem = DlftFrequencySweep { dlft, level, unknowns_scale };
                    continue_branch(&mut problem, guess, from, to, &bridge, &mut Silent)
                },
                ramp(from),
            )
        },
        |dlft, guess, from| {
            let rest = within(options, band, from, omega_end);
            let offset = 1.0 - (omega_end - from).abs() / band;
            let observer = &mut ProgressOverWhole { inner: &mut *observer, offset };
            continue_branch(
                &mut DlftFrequencySweep { dlft, level, unknowns_scale },
                guess,
                from,
                omega_end,
                &rest,
                observer,
            )
        },
    ))
}

/// Continue the DLFT balance at frequency `omega` (rad/s) in the force level from
/// `level_start` to `level_end`, from the stuck solution `x = 0`.
pub fn sweep_level<O: ?Sized + for<'a> PointObserver<DlftLevelSweep<'a>>>(
    dlft: &mut DlftHbm,
    omega: f64,
    level_start: f64,
    level_end: f64,
    options: &Options,
    observer: &mut O,
) -> Result<Branch, SweepError> {
    let guess = dlft.stuck_solution();
    Ok(continue_branch(&mut DlftLevelSweep { dlft, omega }, &guess, level_start, level_end, options, observer)?)
}

/// A correction law without a periodic regime for a wild trial motion rejects the step (it is
/// retried shorter), as in [`super::sweep`]; any other error ends the branch.
fn problem_error(e: HbmError) -> ProblemError {
    match e {
        HbmError::Aft(_) => ProblemError::at_trial_iterate(e.to_string()),
        _ => ProblemError::new(e.to_string()),
    }
}

/// The mean of `|Z_ii(Ω)|` at harmonic 1, `Z = H⁻¹` the condensed dynamic stiffness.
fn mean_dynamic_stiffness(receptance: &Receptance, omega: f64) -> f64 {
    let q = receptance.n_directions();
    let mut h = HarmonicReceptance::new(q);
    receptance.evaluate_matrix(omega, &mut h);
    let z = h.h.partial_piv_lu().inverse();
    (0..q).map(|i| z[(i, i)].norm()).sum::<f64>() / q as f64
}

fn dot(row: faer::RowRef<'_, f64>, v: &[f64]) -> f64 {
    row.iter().zip(v).map(|(a, b)| a * b).sum()
}

fn law_dirs(law: &Contact) -> usize {
    use crate::elements::Element;
    law.n_dirs()
}
