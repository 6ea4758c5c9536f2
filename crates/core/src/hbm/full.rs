//! The uncondensed harmonic balance (paper Eqs. 14-19): all (2N+1)n unknowns, dense.
//!
//! Used to check the condensation (same solution on the nonlinear directions and everywhere
//! after recovery) and for small models. Residual in force units, for the pair (c, s) of
//! harmonic k ≥ 1 (x = c cos kΩt + s sin kΩt):
//!
//! ```text
//! R_c = (K − (kΩ)² M) c + kΩ D s + V G_c − λ_F F δ_k1
//! R_s = (K − (kΩ)² M) s − kΩ D c + V G_s
//! R_0 = K c_0 + V G_0
//! ```

use faer::{Mat, MatMut};

use super::condensed::{HbmError, HbmSettings};
use super::element_aft::ElementAft;
use super::fourier::{cos_index, sin_index, AftPlan};
use crate::model::NonlinearModel;

/// Dense full-size harmonic balance of a [`NonlinearModel`].
pub struct FullHbm<'m> {
    model: &'m NonlinearModel,
    plan: AftPlan,
    mass: Mat<f64>,
    stiffness: Mat<f64>,
    damping: Mat<f64>,
    force: Vec<f64>,
    afts: Vec<ElementAft>,
}

impl<'m> FullHbm<'m> {
    pub fn new(model: &'m NonlinearModel, force: &[f64], settings: HbmSettings) -> Result<Self, HbmError> {
        let n = model.linear.n_dofs();
        if force.len() != n {
            return Err(HbmError::ForceLength { got: force.len(), expected: n });
        }
        model.check_no_rigid_contacts("the full harmonic balance")?;
        let plan = AftPlan::new(settings.harmonics, settings.samples)?;
        let modes = if model.linear.damping.is_modal() { Some(model.linear.dense_modes()?) } else { None };
        let damping = model.linear.damping_dense(modes.as_ref());
        let afts = model.elements.iter().map(|e| ElementAft::new(e.law.as_ref(), &plan)).collect();
        Ok(FullHbm {
            model,
            mass: model.linear.mass.to_dense(),
            stiffness: model.linear.stiffness.to_dense(),
            damping,
            force: force.to_vec(),
            afts,
            plan,
        })
    }

    /// Number of unknowns (2N+1)n.
    pub fn dimension(&self) -> usize {
        self.plan.n_coeffs() * self.model.linear.n_dofs()
    }

    /// Residual and, if asked, `∂R/∂X`.
    pub fn evaluate(
        &mut self,
        x: &[f64],
        omega: f64,
        level: f64,
        residual: &mut [f64],
        mut jacobian: Option<MatMut<'_, f64>>,
    ) -> Result<(), HbmError> {
        let n = self.model.linear.n_dofs();
        let nc = self.plan.n_coeffs();
        let (k, m, d) = (&self.stiffness, &self.mass, &self.damping);
        residual.iter_mut().for_each(|r| *r = 0.0);
        if let Some(j) = jacobian.as_mut() {
            j.fill(0.0);
        }
        // Linear part, block by block (Eq. 17).
        for i in 0..n {
            for l in 0..n {
                residual[i] += k[(i, l)] * x[l];
                if let Some(j) = jacobian.as_mut() {
                    j[(i, l)] = k[(i, l)];
                }
            }
        }
        for h in 1..=self.plan.n_harmonics() {
            let w = h as f64 * omega;
            let (ic, is) = (cos_index(h) * n, sin_index(h) * n);
            for i in 0..n {
                for l in 0..n {
                    let dyn_ = k[(i, l)] - w * w * m[(i, l)];
                    let wd = w * d[(i, l)];
                    residual[ic + i] += dyn_ * x[ic + l] + wd * x[is + l];
                    residual[is + i] += dyn_ * x[is + l] - wd * x[ic + l];
                    if let Some(j) = jacobian.as_mut() {
                        j[(ic + i, ic + l)] = dyn_;
                        j[(ic + i, is + l)] = wd;
                        j[(is + i, is + l)] = dyn_;
                        j[(is + i, ic + l)] = -wd;
                    }
                }
            }
        }
        for i in 0..n {
            residual[cos_index(1) * n + i] -= level * self.force[i];
        }
        // Elements: R += V G(Vᵀ X), ∂R/∂X += V ∂G/∂u Vᵀ.
        for (e, site) in self.model.elements.iter().enumerate() {
            let dd = site.law.n_dirs();
            let mut u = vec![0.0; nc * dd];
            for c in 0..nc {
                for (a, v) in site.directions.iter().enumerate() {
                    u[c * dd + a] = (0..n).map(|l| v[l] * x[c * n + l]).sum();
                }
            }
            let mut g = vec![0.0; nc * dd];
            let mut je = Mat::zeros(nc * dd, nc * dd);
            let mut dw = vec![0.0; nc * dd];
            let jac = if jacobian.is_some() { Some((je.as_mut(), &mut dw[..])) } else { None };
            self.afts[e].evaluate(site.law.as_ref(), &self.plan, omega, &u, &mut g, jac)?;
            for c in 0..nc {
                for (a, va) in site.directions.iter().enumerate() {
                    for i in 0..n {
                        residual[c * n + i] += va[i] * g[c * dd + a];
                    }
                    if let Some(j) = jacobian.as_mut() {
                        for c2 in 0..nc {
                            for (b, vb) in site.directions.iter().enumerate() {
                                let jab = je[(c * dd + a, c2 * dd + b)];
                                if jab != 0.0 {
                                    for i in 0..n {
                                        if va[i] != 0.0 {
                                            for l in 0..n {
                                                j[(c * n + i, c2 * n + l)] += va[i] * jab * vb[l];
                                            }
                                        }
                                    }
                                }
                            }
                        }
                    }
                }
            }
        }
        Ok(())
    }
}
