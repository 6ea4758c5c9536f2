//! The nonlinear part of a harmonic balance: the joints' forces by AFT (paper Eq. 15), element
//! by element, on the q application directions. Every formulation (the forced response
//! [`super::CondensedHbm`], the nonlinear mode [`super::NonlinearMode`]) combines it with its
//! own linear part.

use faer::{c64, Mat};

use super::element_aft::{AftError, ElementAft};
use super::fourier::AftPlan;
use crate::model::NonlinearModel;

/// The elements' AFT state and results, on buffers allocated once.
pub struct JointForces {
    /// Number of directions q.
    pub q: usize,
    /// First global direction of each element.
    pub offsets: Vec<usize>,
    pub afts: Vec<ElementAft>,
    /// Force harmonics `G` and `∂G/∂Ω` (coefficient-major, q wide) after the last evaluation.
    pub g: Vec<f64>,
    pub dg_domega: Vec<f64>,
    elem_u: Vec<Vec<f64>>,
    elem_g: Vec<Vec<f64>>,
    /// Each element's block of `∂G/∂x` (`d(2N+1)` square, coefficient-major, d wide): the
    /// matrix is block diagonal over elements and never assembled.
    pub elem_jac: Vec<Mat<f64>>,
    elem_dgdw: Vec<Vec<f64>>,
}

impl JointForces {
    pub fn new(model: &NonlinearModel, plan: &AftPlan) -> Self {
        let nc = plan.n_coeffs();
        let mut offsets = Vec::with_capacity(model.elements.len());
        let mut q = 0;
        for e in &model.elements {
            offsets.push(q);
            q += e.law.n_dirs();
        }
        let dims: Vec<usize> = model.elements.iter().map(|e| e.law.n_dirs() * nc).collect();
        JointForces {
            q,
            offsets,
            afts: model.elements.iter().map(|e| ElementAft::new(e.law.as_ref(), plan)).collect(),
            g: vec![0.0; q * nc],
            dg_domega: vec![0.0; q * nc],
            elem_u: dims.iter().map(|&m| vec![0.0; m]).collect(),
            elem_g: dims.iter().map(|&m| vec![0.0; m]).collect(),
            elem_jac: dims.iter().map(|&m| Mat::zeros(m, m)).collect(),
            elem_dgdw: dims.iter().map(|&m| vec![0.0; m]).collect(),
        }
    }

    /// AFT of every element for the motion `x` (harmonics on the directions, coefficient-major)
    /// at Ω: `G` and, if `want`, `∂G/∂Ω` and each element's block of `∂G/∂x` (else `∂G/∂Ω`
    /// is zeroed). With `half_wave`, `x` is half-wave symmetric (its even harmonics are not
    /// read) and each element's AFT may use it ([`ElementAft::evaluate_with_symmetry`]).
    pub fn evaluate(
        &mut self,
        model: &NonlinearModel,
        plan: &AftPlan,
        x: &[f64],
        omega: f64,
        want: bool,
        half_wave: bool,
    ) -> Result<(), AftError> {
        let (q, nc) = (self.q, plan.n_coeffs());
        for (e, site) in model.elements.iter().enumerate() {
            let d = site.law.n_dirs();
            let off = self.offsets[e];
            for c in 0..nc {
                for a in 0..d {
                    self.elem_u[e][c * d + a] = x[c * q + off + a];
                }
            }
            let jac = if want { Some((self.elem_jac[e].as_mut(), &mut self.elem_dgdw[e][..])) } else { None };
            let (u, g) = (&self.elem_u[e], &mut self.elem_g[e]);
            self.afts[e].evaluate_with_symmetry(site.law.as_ref(), plan, omega, u, g, jac, half_wave)?;
            for c in 0..nc {
                for a in 0..d {
                    let row = c * q + off + a;
                    self.g[row] = self.elem_g[e][c * d + a];
                    self.dg_domega[row] = if want { self.elem_dgdw[e][c * d + a] } else { 0.0 };
                }
            }
        }
        Ok(())
    }

    /// Each element's block of `∂G/∂x` and `∂G/∂Ω` at the last evaluation, made without them,
    /// when every element is a slider ([`ElementAft::complete_slider_jacobian`]); false if one
    /// is not. With `odd_only`, the blocks' entries between odd harmonics alone.
    pub fn complete_jacobian(&mut self, model: &NonlinearModel, plan: &AftPlan, odd_only: bool) -> bool {
        let (q, nc) = (self.q, plan.n_coeffs());
        for (e, site) in model.elements.iter().enumerate() {
            let (jac, dgdw) = (self.elem_jac[e].as_mut(), &mut self.elem_dgdw[e]);
            if !self.afts[e].complete_slider_jacobian(plan, jac, dgdw, odd_only) {
                return false;
            }
            let (d, off) = (site.law.n_dirs(), self.offsets[e]);
            for c in 0..nc {
                for a in 0..d {
                    self.dg_domega[c * q + off + a] = self.elem_dgdw[e][c * d + a];
                }
            }
        }
        true
    }

    /// `∂G/∂x` assembled (q(2N+1) square) from the last evaluation with `want`, each element's
    /// block made complex and passed to `block` first (which may change it, e.g. to weight a
    /// slider's memory for a perturbation `e^{st}`).
    pub fn assembled_jacobian(
        &self,
        model: &NonlinearModel,
        nc: usize,
        mut block: impl FnMut(usize, &mut Mat<c64>),
    ) -> Mat<c64> {
        let q = self.q;
        let mut jac = Mat::zeros(q * nc, q * nc);
        for (e, site) in model.elements.iter().enumerate() {
            let (d, off) = (site.law.n_dirs(), self.offsets[e]);
            let mut b = Mat::from_fn(d * nc, d * nc, |i, j| c64::new(self.elem_jac[e][(i, j)], 0.0));
            block(e, &mut b);
            for c1 in 0..nc {
                for a in 0..d {
                    for c2 in 0..nc {
                        for bb in 0..d {
                            jac[(c1 * q + off + a, c2 * q + off + bb)] = b[(c1 * d + a, c2 * d + bb)];
                        }
                    }
                }
            }
        }
        jac
    }

    /// Did the last Jacobian include a slider's memory of its anchor
    /// ([`ElementAft::add_memory_delay`])?
    pub fn has_memory_delay(&self) -> bool {
        self.afts.iter().any(|a| a.has_memory_delay())
    }
}
