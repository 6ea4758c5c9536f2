//! Results at a converged point (paper Sections 4.4, 5): harmonics and FRFs of any physical
//! DOF (recovered by Eq. 27), the elements' hysteresis loops, stick fraction, slider velocity
//! (Eq. 33) and the energy balance over one cycle.

use faer::c64;

use crate::hbm::condensed::{complex_amplitude, CondensedHbm, HbmError};
use crate::hbm::dlft::DlftHbm;
use crate::hbm::fourier::{amplitude_phase, cos_index, sin_index, AftPlan};
use crate::hbm::receptance::{Outputs, Receptance};

/// A quantity to report: a name and the vector `o` such that the reported motion is `oᵀ U`
/// (a unit vector for a DOF).
#[derive(Clone, Debug)]
pub struct OutputSelector {
    pub name: String,
    pub vector: Vec<f64>,
}

/// Motion of one output over a period.
#[derive(Clone, Debug)]
pub struct OutputResult {
    pub name: String,
    /// Coefficient vector `[c0, c1, s1, ...]` (m).
    pub coeffs: Vec<f64>,
    /// Displacement samples over one period at θ_j = 2πj/n_t (m).
    pub displacement: Vec<f64>,
    /// Velocity samples (m/s).
    pub velocity: Vec<f64>,
    /// max_j |x(θ_j)| (m).
    pub peak: f64,
}

impl OutputResult {
    /// Amplitude (m) and phase (rad, relative to the force's cos Ωt) of harmonic `k ≥ 1`;
    /// for `k = 0`, the mean and 0.
    pub fn harmonic(&self, k: usize) -> (f64, f64) {
        if k == 0 {
            (self.coeffs[0], 0.0)
        } else {
            amplitude_phase(&self.coeffs, k)
        }
    }
}

/// Response of one element over a period.
#[derive(Clone, Debug)]
pub struct ElementResult {
    pub name: String,
    /// Energy dissipated per cycle, `∮ gᵀ du` summed over the directions (J).
    pub energy_per_cycle: f64,
    /// Energy per cycle of each direction, `∮ g_a du_a` (J): a contact's normal direction
    /// dissipates nothing, its tangential ones share the friction work.
    pub direction_energy: Vec<f64>,
    /// Fraction of the period during which the element sticks (a contact that is open or
    /// slips does not).
    pub stick_fraction: f64,
    /// Relative displacement `u_a = V_aᵀ U` over the period (m), one series per direction.
    pub displacement: Vec<Vec<f64>>,
    /// The joint's own force (N) per direction: `f = g + K_r u` for a paper-form element
    /// (Eq. 11, `K_r` the replaced d×d stiffness).
    pub force: Vec<Vec<f64>>,
    /// Slider velocity (Eq. 33) per direction: 0 when stuck, `u̇_a` when slipping (m/s).
    pub slider_velocity: Vec<Vec<f64>>,
}

/// Everything reported at one converged point.
#[derive(Clone, Debug)]
pub struct PointResult {
    /// Fundamental circular frequency (rad/s).
    pub omega: f64,
    /// Force level λ_F (N per unit pattern).
    pub level: f64,
    pub outputs: Vec<OutputResult>,
    pub elements: Vec<ElementResult>,
    /// Work of the excitation per cycle (J).
    pub excitation_work: f64,
    /// Energy dissipated per cycle by viscous damping (J).
    pub viscous_dissipation: f64,
}

impl PointResult {
    pub fn frequency_hz(&self) -> f64 {
        self.omega / (2.0 * std::f64::consts::PI)
    }

    /// Energy balance defect per cycle relative to the excitation work:
    /// `(W_F − W_visc − Σ W_e) / W_F`.
    pub fn energy_balance_error(&self) -> f64 {
        let friction: f64 = self.elements.iter().map(|e| e.energy_per_cycle).sum();
        (self.excitation_work - self.viscous_dissipation - friction) / self.excitation_work
    }
}

/// Post-process a converged solution `x` of `hbm` at (Ω, λ_F): evaluate the balance there
/// (unless it was last evaluated there), then [`point_result`].
pub fn evaluate_point(
    hbm: &mut CondensedHbm<'_>,
    x: &[f64],
    omega: f64,
    level: f64,
    outputs: &[OutputSelector],
) -> Result<PointResult, HbmError> {
    // Fills the elements' time samples and force harmonics at x.
    hbm.evaluate_unless_at(x, omega, level)?;
    point_result(hbm, x, outputs)
}

/// Amplitude of harmonic `k ≥ 1` of the output prepared in `output` (one selector of
/// [`crate::hbm::Receptance::outputs`]) at the solution `x` of `hbm` at (Ω, λ_F): the quantity a
/// located peak maximises, recovered alone (Eq. 27 at one harmonic, no time series).
pub fn output_amplitude(
    hbm: &mut CondensedHbm<'_>,
    x: &[f64],
    omega: f64,
    level: f64,
    output: &Outputs,
    k: usize,
) -> Result<f64, HbmError> {
    hbm.evaluate_unless_at(x, omega, level)?;
    let q = hbm.n_directions();
    let g = hbm.element_force_harmonics();
    let gk: Vec<c64> = (0..q).map(|i| complex_amplitude(g, q, k, i)).collect();
    let lk = if k == 1 { level } else { 0.0 };
    let (amplitudes, _) = hbm.receptance().recover(k as f64 * omega, lk, &gk, output);
    Ok(amplitudes[0].norm())
}

/// Post-process the solution `x` at which `hbm` was last evaluated (the converged evaluation
/// of a continuation, handed to its observer): the elements' forces and time samples are
/// read as that evaluation left them, not computed again. An error if the last evaluation
/// was not at `x`.
pub fn point_result(hbm: &CondensedHbm<'_>, x: &[f64], outputs: &[OutputSelector]) -> Result<PointResult, HbmError> {
    point_result_with(hbm, x, outputs, TimeSeries::Kept)
}

/// Whether a [`PointResult`] carries the time series over the period (outputs' displacement and
/// velocity, the elements' displacement, force and slider velocity) or only what a table of
/// points needs (harmonics, peak, energies, stick fractions), which the series would otherwise
/// cost several times over at every point of a sweep.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TimeSeries {
    Kept,
    /// The series are left empty; every other value is the same, bit for bit.
    Skipped,
}

/// [`point_result`], with the time series kept or skipped.
pub fn point_result_with(
    hbm: &CondensedHbm<'_>,
    x: &[f64],
    outputs: &[OutputSelector],
    series: TimeSeries,
) -> Result<PointResult, HbmError> {
    let Some((omega, level)) = hbm.last_evaluation().filter(|&(w, l)| hbm.evaluated_at(x, w, l)) else {
        return Err(HbmError::NotEvaluated);
    };
    let nt = hbm.plan().n_samples();
    let mut offset = 0;
    let mut elements = Vec::with_capacity(hbm.model().elements.len());
    for (e, site) in hbm.model().elements.iter().enumerate() {
        let d = site.law.n_dirs();
        let aft = hbm.element_aft(e);
        let law = site.law.as_ref();
        // The joint's own force: f = g + K_r u (Eq. 11).
        let force = match series {
            TimeSeries::Kept => (0..d * nt)
                .map(|i| {
                    let (a, j) = (i / nt, i % nt);
                    aft.g[i] + (0..d).map(|b| law.replaced_stiffness(a, b) * aft.u[b * nt + j]).sum::<f64>()
                })
                .collect(),
            TimeSeries::Skipped => Vec::new(),
        };
        elements.push(ElementSamples {
            name: &site.name,
            offset,
            dirs: d,
            displacement: if series == TimeSeries::Kept { aft.u.clone() } else { Vec::new() },
            force,
            slipping: &aft.slipping,
        });
        offset += d;
    }
    let linear = Linear { receptance: hbm.receptance(), force: hbm.force(), plan: hbm.plan(), q: hbm.n_directions() };
    Ok(recovered_result(&linear, x, hbm.element_force_harmonics(), omega, level, outputs, elements, series))
}

/// Post-process a converged solution `x` of the DLFT balance at (Ω, λ_F) as
/// [`evaluate_point`] does a penalty balance's: outputs recovered from the contact forces `λ`
/// (Eq. 27, `U = Z⁻¹(λ_F F − V λ)`), and per contact the relative displacement `x` over the
/// period (synthesised from its harmonics: the correction law's own samples are `y = λ_u/ε`),
/// the contact force variations `(T, N − N0)` at the samples (the corrected forces), the
/// stick fraction (samples where the correction's slider does not move: closed and stuck) and
/// the slider velocity.
pub fn evaluate_dlft_point(
    dlft: &mut DlftHbm,
    x: &[f64],
    omega: f64,
    level: f64,
    outputs: &[OutputSelector],
) -> Result<PointResult, HbmError> {
    let mut residual = vec![0.0; dlft.dimension()];
    dlft.evaluate(x, omega, level, &mut residual, None)?;
    let (q, plan) = (dlft.n_directions(), dlft.plan());
    let (nc, nt) = (plan.n_coeffs(), plan.n_samples());
    let mut scratch = plan.scratch();
    let mut offset = 0;
    let mut elements = Vec::with_capacity(dlft.contacts().len());
    for (e, contact) in dlft.contacts().iter().enumerate() {
        let d = contact.directions.len();
        let mut displacement = vec![0.0; d * nt];
        for a in 0..d {
            let coeffs: Vec<f64> = (0..nc).map(|c| x[c * q + offset + a]).collect();
            plan.synthesize(&coeffs, &mut displacement[a * nt..(a + 1) * nt], &mut scratch);
        }
        let aft = dlft.contact_aft(e);
        elements.push(ElementSamples {
            name: &contact.name,
            offset,
            dirs: d,
            displacement,
            force: aft.g.clone(),
            slipping: &aft.slipping,
        });
        offset += d;
    }
    let linear = Linear { receptance: dlft.receptance(), force: dlft.force(), plan, q };
    Ok(recovered_result(&linear, x, dlft.contact_forces(), omega, level, outputs, elements, TimeSeries::Kept))
}

/// The linear part of a balance, which recovers outputs from the forces on its q directions.
struct Linear<'a> {
    receptance: &'a Receptance,
    force: &'a [f64],
    plan: &'a AftPlan,
    q: usize,
}

/// One element (or rigid contact) after the evaluation at the point: its directions
/// `offset..offset + dirs` among the q, its displacement and force samples (`[a * nt + j]`)
/// and whether it slips at each sample.
struct ElementSamples<'a> {
    name: &'a str,
    offset: usize,
    dirs: usize,
    displacement: Vec<f64>,
    force: Vec<f64>,
    slipping: &'a [bool],
}

/// The results at a point of relative displacement harmonics `x` and force harmonics `g` on
/// the q directions (coefficient-major), whatever balance found them: outputs and the
/// excitation's work by recovery (Eq. 27), energies from the harmonics, loops from the samples
/// (with [`TimeSeries::Skipped`] the outputs' displacement is synthesised for its peak only, and
/// no series is kept).
#[allow(clippy::too_many_arguments)]
fn recovered_result(
    linear: &Linear<'_>,
    x: &[f64],
    g: &[f64],
    omega: f64,
    level: f64,
    outputs: &[OutputSelector],
    elements: Vec<ElementSamples<'_>>,
    series: TimeSeries,
) -> PointResult {
    let kept = series == TimeSeries::Kept;
    let (q, plan, receptance) = (linear.q, linear.plan, linear.receptance);
    let (nh, nc, nt) = (plan.n_harmonics(), plan.n_coeffs(), plan.n_samples());
    let pi = std::f64::consts::PI;

    // Outputs and the excitation pattern, recovered harmonic by harmonic (Eq. 27).
    let mut selectors: Vec<&[f64]> = outputs.iter().map(|o| o.vector.as_slice()).collect();
    selectors.push(linear.force);
    let prepared = receptance.outputs(&selectors);
    let mut coeffs = vec![vec![0.0; nc]; selectors.len()];
    let mut viscous = 0.0;
    let g0: Vec<c64> = (0..q).map(|i| c64::new(g[i], 0.0)).collect();
    let (mean, _) = receptance.recover(0.0, 0.0, &g0, &prepared);
    for (c, m) in coeffs.iter_mut().zip(&mean) {
        c[0] = m.re;
    }
    for k in 1..=nh {
        let gk: Vec<c64> = (0..q).map(|i| complex_amplitude(g, q, k, i)).collect();
        let lk = if k == 1 { level } else { 0.0 };
        let (amps, udu) = receptance.recover(k as f64 * omega, lk, &gk, &prepared);
        // ∫₀ᵀ U̇ᵀ D U̇ dt = π Ω Σ_k k² Uᴴ D U.
        viscous += pi * omega * (k * k) as f64 * udu;
        for (c, a) in coeffs.iter_mut().zip(&amps) {
            c[cos_index(k)] = a.re;
            c[sin_index(k)] = -a.im;
        }
    }
    // W_F = λ_F ∫ cos θ Fᵀ dU/dθ dθ = π λ_F Fᵀ s_1.
    let excitation_work = pi * level * coeffs.last().expect("pattern row")[sin_index(1)];

    let mut scratch = plan.scratch();
    let mut output_results = Vec::with_capacity(outputs.len());
    for (o, c) in outputs.iter().zip(&coeffs) {
        let mut displacement = vec![0.0; nt];
        plan.synthesize(c, &mut displacement, &mut scratch);
        let peak = displacement.iter().fold(0.0f64, |m, x| m.max(x.abs()));
        let velocity = if kept {
            let mut velocity = vec![0.0; nt];
            plan.synthesize_derivative(c, &mut velocity, &mut scratch);
            velocity.iter_mut().for_each(|v| *v *= omega);
            velocity
        } else {
            displacement = Vec::new();
            Vec::new()
        };
        output_results.push(OutputResult { name: o.name.clone(), coeffs: c.clone(), displacement, velocity, peak });
    }

    let mut element_results = Vec::with_capacity(elements.len());
    for e in elements {
        let (offset, d) = (e.offset, e.dirs);
        // ∮ g du = π Σ_k k (s_k g_ck − c_k g_sk), exact for the truncated motion.
        let direction_energy: Vec<f64> = (offset..offset + d)
            .map(|a| {
                (1..=nh)
                    .map(|k| {
                        let (ic, is) = (cos_index(k) * q + a, sin_index(k) * q + a);
                        pi * k as f64 * (x[is] * g[ic] - x[ic] * g[is])
                    })
                    .sum()
            })
            .collect();
        // The series per direction (one empty series per direction when skipped).
        let (displacement, force, slider_velocity) = if kept {
            // The velocity samples as the AFT computes them, Ω du/dθ (it skips them for the
            // rate-independent laws, whose update never reads them).
            let mut rate = vec![0.0; nt];
            let slider_velocity = (0..d)
                .map(|a| {
                    let coeffs: Vec<f64> = (0..nc).map(|c| x[c * q + offset + a]).collect();
                    plan.synthesize_derivative(&coeffs, &mut rate, &mut scratch);
                    (0..nt).map(|j| if e.slipping[j] { omega * rate[j] } else { 0.0 }).collect()
                })
                .collect();
            let per_direction = |samples: &[f64]| samples.chunks(nt).map(<[f64]>::to_vec).collect::<Vec<_>>();
            (per_direction(&e.displacement), per_direction(&e.force), slider_velocity)
        } else {
            (vec![Vec::new(); d], vec![Vec::new(); d], vec![Vec::new(); d])
        };
        let stuck = e.slipping.iter().filter(|s| !**s).count();
        element_results.push(ElementResult {
            name: e.name.to_string(),
            energy_per_cycle: direction_energy.iter().sum(),
            direction_energy,
            stick_fraction: stuck as f64 / nt as f64,
            displacement,
            force,
            slider_velocity,
        });
    }
    PointResult {
        omega,
        level,
        outputs: output_results,
        elements: element_results,
        excitation_work,
        viscous_dissipation: viscous,
    }
}
