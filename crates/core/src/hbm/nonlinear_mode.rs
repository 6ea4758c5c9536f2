//! Nonlinear modes by the extended periodic motion concept (EPMC, Krack 2015, "Nonlinear modal
//! analysis of nonconservative systems: extension of the periodic motion concept", J. Sound
//! Vib. 154, Eqs. 2-5).
//!
//! The damped nonlinear mode is the periodic motion of the unforced system to which a negative,
//! mass-proportional damping `−ξ M U̇` is added, just large enough to compensate the energy
//! dissipated over a cycle (Krack 2015, Eq. 2):
//!
//! ```text
//! M Ü + (D − ξ M) U̇ + K U + V g(u) = 0,      u = Vᵀ U
//! ```
//!
//! The frequency Ω and ξ are unknowns; the modal damping ratio is `ζ = ξ / (2Ω)` (Eq. 5).
//!
//! # Formulation: one modal coordinate kept, the other modes condensed
//!
//! With mass-normalised modes `φ_r` of `(K, M)`, modal damping `c_r` and `a_r = Vᵀ φ_r`, every
//! modal coordinate obeys `p̈_r + (c_r − ξ) ṗ_r + ω_r² p_r + a_rᵀ g = 0`. The target mode's
//! coordinate η keeps its 2N+1 real harmonics as unknowns; every other mode is condensed on the
//! q nonlinear directions through its receptance, as in the forced balance
//! ([`super::condensed`]), here with the damping shifted by −ξ. For harmonic k (complex
//! amplitudes `X_k = c_k − i s_k`, [`super::fourier`]):
//!
//! ```text
//! R_u,k = u_k − a_* η_k + H_rest(kΩ; ξ) G_k                                   (q equations)
//! R_η,k = [ω_*² − (kΩ)² + i kΩ (c_* − ξ)] η_k + a_*ᵀ G_k                       (1 equation)
//! H_rest(ω; ξ) = Σ_{r ≠ *} a_r a_rᵀ / (ω_r² − ω² + i ω (c_r − ξ))
//! ```
//!
//! With [`NegativeDamping::TargetMode`] the condensed modes keep `c_r` (ξ acts on η only).
//! `G` are the harmonics of the element forces by AFT ([`super::element_aft`]). Elements in the
//! paper's form (Eq. 11) return forces net of the stiffness they replace in K, so a stuck joint
//! gives `G = 0` and the linear mode solves the balance exactly.
//!
//! The phase is fixed by `η_s1 = 0` (a fixed value, not an unknown) and the amplitude by the
//! mass norm of harmonic 1 of the whole motion (Krack 2015, Eqs. 3-4):
//!
//! ```text
//! R_a = X_1ᴴ M X_1 / a² − 1 = |η_1|² / a² + Σ_{r≠*} |p_r1|² / a² − 1,    p_r1 = −a_rᵀ G_1 / den_r(Ω; ξ)
//! ```
//!
//! so that `a` measures the motion, not only the target mode's share of it, which falls where
//! slipping joints move the other modes (on a model with many modes it can even fall while the
//! motion grows). The continuation parameter is `λ = log10 a`, so a branch spans decades of
//! amplitude with steps of even relative size.
//!
//! # Scaled unknowns
//!
//! Motions are divided by the amplitude and frequencies by ω_*, so that every unknown and
//! residual is of order one from the linear regime (a → 0) to full slip:
//!
//! ```text
//! y = [u/a (q(2N+1)),  η/a without s1 (2N),  w = Ω/ω_*,  ξ̂ = ξ/ω_*]
//! R = [R_u / a,  R_η / (a ω_*²),  R_a]
//! ```
//!
//! The Jacobian is analytic; the λ-derivative follows from `d(G(a û)/a)/dλ = ln 10 (∂G/∂u û −
//! G/a)`.

use faer::{c64, Mat, MatMut};

use super::condensed::HbmSettings;
use super::element_aft::AftError;
use super::fourier::{cos_index, sin_index, AftPlan, FourierError};
use super::joint_forces::JointForces;
use super::receptance::{LinearParameter, LinearVariation, ModalReceptance, Receptance};
use crate::continuation::{
    continue_branch, singular_points, Accepted, Branch, ContinuationError, Options, PointObserver, Problem,
    ProblemError, Scales, SingularKind, TerminationReason, TestFunctions,
};
use crate::model::{ModelError, NonlinearModel};

const LN_10: f64 = std::f64::consts::LN_10;

/// Largest relative departure of the first point from the linear mode (its frequency, and its
/// damping ratio relative to the linear one) accepted as "still linear". A stuck Jenkins joint
/// leaves the linear mode exactly (to the Newton tolerance, 1e-10); 1e-4 flags a start where a
/// joint already slips on a noticeable part of the cycle.
pub const LINEAR_START_TOLERANCE: f64 = 1e-4;

/// Why a nonlinear mode could not be computed.
#[derive(Debug, thiserror::Error)]
pub enum NonlinearModeError {
    #[error(transparent)]
    Model(#[from] ModelError),
    #[error(transparent)]
    Fourier(#[from] FourierError),
    #[error(transparent)]
    Continuation(#[from] ContinuationError),
    #[error("mode {mode} was asked for, but the model has {available} modes (modes are numbered from 1)")]
    ModeOutOfRange { mode: usize, available: usize },
    #[error("nonlinear modes need damping that is diagonal in the undamped modes (none, Rayleigh or modal ratios); the model has a general damping matrix")]
    GeneralDamping,
    #[error("the amplitude range [{start:e}, {end:e}] is not valid: give two positive finite amplitudes, the first the smaller (the branch starts from the linear mode)")]
    InvalidAmplitudes { start: f64, end: f64 },
    #[error("the amplitude range starts in the nonlinear regime: at amplitude {amplitude:e} the mode's frequency departs from the linear {linear_hz:.6} Hz by {frequency_shift:.2e} (relative) and its damping ratio from {linear_ratio:.4e} by {damping_shift:.2e} (relative; accepted: {LINEAR_START_TOLERANCE:e}); start at a smaller amplitude")]
    NonlinearStart { amplitude: f64, linear_hz: f64, frequency_shift: f64, linear_ratio: f64, damping_shift: f64 },
    #[error("no periodic solution at the first amplitude {amplitude:e} (the linear mode did not converge: {reason}); start at a smaller amplitude")]
    FirstPointFailed { amplitude: f64, reason: String },
    #[error("the converged point at amplitude {amplitude:e} could not be evaluated again for its results: {reason}")]
    PostProcessing { amplitude: f64, reason: String },
}

/// The EPMC balance of one mode of a model, as a continuation [`Problem`] in `λ = log10 a`.
pub struct NonlinearMode<'m> {
    model: &'m NonlinearModel,
    plan: AftPlan,
    /// Target mode (0-based) and its circular frequency, modal damping `c_*` and `a_* = Vᵀ φ_*`.
    target: usize,
    omega_t: f64,
    c_t: f64,
    a_t: Vec<f64>,
    /// The linear part: every mode (frequencies, damping, `A = Vᵀ Φ` q × m, the shapes for
    /// recovery), as the forced balance has it.
    linear: ModalReceptance,
    /// The condensed modes see `−ξ` too ([`NegativeDamping::MassProportional`]).
    shift_all: bool,
    q: usize,
    /// The nonlinear part: the joints' forces by AFT.
    joints: JointForces,
    // Work buffers, allocated once.
    u: Vec<f64>,
    /// `H_rest` per harmonic 0..=N and its derivatives in Ω (harmonic factor included) and ξ.
    h: Vec<Mat<c64>>,
    dh_domega: Vec<Mat<c64>>,
    dh_dxi: Vec<Mat<c64>>,
    /// `∂G/∂u û − G/a` (the amplitude derivative of the scaled forces, over ln 10).
    t: Vec<f64>,
    /// The condensed modes' share of the amplitude: `N = Σ_{r≠*} a_r a_rᵀ / |den_r(Ω; ξ)|²`
    /// (q × q) and its derivatives in Ω and ξ (see [`NonlinearMode::amplitude_weights`]).
    n_w: Mat<f64>,
    dn_domega: Mat<f64>,
    dn_dxi: Mat<f64>,
    /// `N Ĝ_c1` then `N Ĝ_s1` (2q), with `Ĝ = G/a`.
    ng: Vec<f64>,
    /// Residual and Jacobian evaluations since creation.
    pub evaluations: usize,
}

/// Which modes the negative damping `−ξ` acts on.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum NegativeDamping {
    /// `−ξ M U̇` (Krack 2015, Eq. 2): every mode's damping is shifted by −ξ. With damping
    /// proportional to M (the paper's `D = αM`) the other modes are then undamped at the linear
    /// limit, and a dense spectrum puts some of them near a harmonic kΩ of the mode: the
    /// condensed flexibility is nearly singular there.
    #[default]
    MassProportional,
    /// `−ξ M φ_* φ_*ᵀ M U̇`: only the target mode is de-damped, the condensed modes keep their
    /// damping. The same backbone where the other modes hardly move (a one-mode motion, e.g. a
    /// 1-DOF system), and robust on models with many modes.
    TargetMode,
}

/// A mode, a harmonic balance and where the branch goes.
#[derive(Clone, Debug, PartialEq)]
pub struct NonlinearModeSettings {
    /// Target mode, 0-based (mode 1 of a study file is 0 here).
    pub mode: usize,
    pub hbm: HbmSettings,
    pub negative_damping: NegativeDamping,
}

/// One point of a backbone: the damped nonlinear mode at one amplitude.
#[derive(Clone, Debug)]
pub struct BackbonePoint {
    /// Modal amplitude a: the cosine of harmonic 1 of the mass-normalised modal coordinate
    /// (m·√kg).
    pub amplitude: f64,
    /// Ω (rad/s).
    pub omega: f64,
    /// The negative mass-proportional damping ξ (1/s).
    pub xi: f64,
    /// Energy dissipated per cycle by viscous damping and joints (J); equals the work of `ξ M U̇`.
    pub energy_per_cycle: f64,
    /// Work of `ξ M U̇` over a cycle (J): the energy the negative damping supplies, which
    /// balances `energy_per_cycle` at a solution (a check of the balance).
    pub supplied_energy: f64,
    /// Energy dissipated per cycle by each joint (J).
    pub joint_energy: Vec<f64>,
    /// Fraction of the period each joint sticks.
    pub stick_fraction: Vec<f64>,
    /// Coefficient vectors `[c0, c1, s1, ...]` (m) of each requested output.
    pub outputs: Vec<Vec<f64>>,
    /// Harmonic 1 of every modal coordinate, `p_r1 = c − i s` (m·√kg, the modes of
    /// [`Backbone::shapes`]): `Σ_r |p_r1|² = a²`, the amplitude condition.
    pub modal_harmonic1: Vec<c64>,
    /// The scaled unknowns of the balance (see the module documentation).
    pub y: Vec<f64>,
}

impl BackbonePoint {
    pub fn frequency_hz(&self) -> f64 {
        self.omega / (2.0 * std::f64::consts::PI)
    }

    /// Modal damping ratio ζ = ξ / (2Ω) (Krack 2015, Eq. 5).
    pub fn damping_ratio(&self) -> f64 {
        self.xi / (2.0 * self.omega)
    }

    /// Amplitude of harmonic `k ≥ 1` of output `o` (m).
    pub fn output_amplitude(&self, o: usize, k: usize) -> f64 {
        self.outputs[o][cos_index(k)].hypot(self.outputs[o][sin_index(k)])
    }
}

/// A backbone: the nonlinear mode over a range of amplitudes.
#[derive(Clone, Debug)]
pub struct Backbone {
    /// Target mode, 0-based.
    pub mode: usize,
    /// The linear mode's circular frequency (rad/s) and damping ratio.
    pub linear_omega: f64,
    pub linear_damping_ratio: f64,
    pub points: Vec<BackbonePoint>,
    /// Why the branch ended (reaching the last amplitude is [`TerminationReason::ReachedEnd`]).
    pub termination: TerminationReason,
    /// Remarks for the user (e.g. a model without joints).
    pub notes: Vec<String>,
    /// The folds in amplitude and the branch points met along the backbone, in branch order.
    pub singular_points: Vec<BackboneSingularPoint>,
    /// Where the continuation turned back along the backbone at a branch point and came back
    /// to the first amplitude: the points after it, which only went back, are left out (the
    /// raw `branch` keeps them).
    pub turned_back_at: Option<BackboneSingularPoint>,
    /// The raw continuation branch (call counts, residuals); `None` without joints.
    pub branch: Option<Branch>,
    /// The target mode's viscous modal coefficient `c_*` (1/s) and the model's mass-normalised
    /// modes (n × m, those of [`BackbonePoint::modal_harmonic1`]): what the forced response
    /// synthesised from the backbone needs ([`Backbone::single_mode_response`]).
    pub viscous: f64,
    pub shapes: Mat<f64>,
}

/// A fold in amplitude or a branch point of a backbone, located between two of its points
/// from the continuation's test functions ([`singular_points`]): at a fold the amplitude turns
/// back along the branch; at a branch point another family of periodic motions crosses it (on
/// a structure with alike joints, one where the joints stop moving alike).
#[derive(Clone, Debug, PartialEq)]
pub struct BackboneSingularPoint {
    pub kind: SingularKind,
    /// Modal amplitude a (m·√kg), Ω (rad/s) and ξ (1/s) there.
    pub amplitude: f64,
    pub omega: f64,
    pub xi: f64,
    /// Index of the backbone point just before it.
    pub after_point: usize,
    /// False when it could not be located between its two points (then it is the second).
    pub located: bool,
}

impl BackboneSingularPoint {
    /// Modal damping ratio ζ = ξ / (2Ω) there.
    pub fn damping_ratio(&self) -> f64 {
        self.xi / (2.0 * self.omega)
    }
}

/// Precision of a located fold or branch point on the chord between its two points (scaled
/// arclength), as the forced sweeps locate theirs.
const SINGULAR_TOLERANCE: f64 = 1e-10;

/// Hands every accepted point on to `inner`, keeping its test functions (from the
/// corrector's last factorisation) for the backbone's folds and branch points.
struct TestRecorder<'o, O: ?Sized> {
    inner: &'o mut O,
    tests: Vec<Option<TestFunctions>>,
}

impl<'m, O: PointObserver<NonlinearMode<'m>> + ?Sized> PointObserver<NonlinearMode<'m>> for TestRecorder<'_, O> {
    fn on_accepted(&mut self, accepted: &mut Accepted<'_, NonlinearMode<'m>>) {
        self.tests.push(accepted.test_functions_estimate().ok().flatten().cloned());
        self.inner.on_accepted(accepted);
    }
}

/// One point of a forced response synthesised from a backbone.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SynthesisedPoint {
    /// Excitation frequency Ω (rad/s).
    pub omega: f64,
    /// The backbone point it comes from (its modal amplitude is the response's).
    pub point: usize,
}

impl Backbone {
    /// The forced response near the mode's resonance under `level · load cos Ωt`, from the
    /// backbone alone (single nonlinear mode theory, Krack 2015, Section 5): the structure is
    /// assumed to move in the nonlinear mode, whose amplitude `a` answers the force as
    ///
    /// ```text
    /// [ω(a)² − Ω² + i (Ω c_* + ω(a) (ξ(a) − c_*))] a = ψ_1ᴴF e^{iψ},   ψ_1 = X_1 / a
    /// ```
    ///
    /// with the viscous damping `c_*` acting at the forcing frequency and the joints' part
    /// `ξ − c_*` (rate independent) at the mode's, where it was computed. For each backbone
    /// point the frequencies Ω below and above `ω(a)` solving the modulus of this equation
    /// (bisection: the left side is monotone on each side); a point above the peak of this force
    /// has none. The response at an output is the backbone point's own (same modal amplitude).
    /// Returned in frequency order along the curve: the lower side by rising amplitude, then
    /// the upper side by falling amplitude.
    pub fn single_mode_response(&self, load: &[f64], level: f64) -> Vec<SynthesisedPoint> {
        // `b_r = φ_rᵀ F`; the mode's force at a point is `|ψ_1ᴴ F|` with `ψ_1 = X_1 / a` its
        // harmonic-1 shape, mass-normalised (`ψ_1ᴴ M ψ_1 = 1`): `Σ_r conj(p_r1) b_r / a`.
        let (n, m) = (self.shapes.nrows(), self.shapes.ncols());
        let b: Vec<f64> = (0..m).map(|r| (0..n).map(|l| self.shapes[(l, r)] * load[l]).sum()).collect();
        let c = self.viscous;
        let (mut lower, mut upper) = (Vec::new(), Vec::new());
        for (i, p) in self.points.iter().enumerate() {
            let force = level * p.modal_harmonic1.iter().zip(&b).map(|(pr, br)| pr.conj() * br).sum::<c64>().norm()
                / p.amplitude;
            let (w, beta) = (p.omega, p.omega * (p.xi - c));
            let f = |o: f64| (w * w - o * o).powi(2) + (o * c + beta).powi(2) - (force / p.amplitude).powi(2);
            if f(w) >= 0.0 || f(w).is_nan() {
                continue;
            }
            for (side, (lo, hi)) in [(&mut lower, (0.0, w)), (&mut upper, (w, 2.0 * w))] {
                if f(lo) * f(hi) > 0.0 {
                    continue;
                }
                let (mut lo, mut hi) = (lo, hi);
                let rising = f(hi) > f(lo);
                for _ in 0..100 {
                    let mid = 0.5 * (lo + hi);
                    if (f(mid) > 0.0) == rising {
                        hi = mid;
                    } else {
                        lo = mid;
                    }
                }
                side.push(SynthesisedPoint { omega: 0.5 * (lo + hi), point: i });
            }
        }
        upper.reverse();
        lower.extend(upper);
        lower
    }
}

impl<'m> NonlinearMode<'m> {
    /// Set up the balance of mode `settings.mode` (0-based) of `model`. The model needs at least
    /// one element (see [`nonlinear_mode`] for a model without) and modal damping.
    pub fn new(model: &'m NonlinearModel, settings: &NonlinearModeSettings) -> Result<Self, NonlinearModeError> {
        model.check_no_rigid_contacts("the nonlinear mode")?;
        if !model.linear.damping.is_modal() {
            return Err(NonlinearModeError::GeneralDamping);
        }
        let directions: Vec<&[f64]> = model.application_vectors().map(|v| v.as_slice()).collect();
        let q = directions.len();
        let unforced = vec![0.0; model.linear.n_dofs()];
        let Receptance::Modal(linear) = Receptance::new(&model.linear, &directions, &unforced)? else {
            return Err(NonlinearModeError::GeneralDamping);
        };
        let m = linear.natural_frequencies().len();
        if settings.mode >= m {
            return Err(NonlinearModeError::ModeOutOfRange { mode: settings.mode + 1, available: m });
        }
        let plan = AftPlan::new(settings.hbm.harmonics, settings.hbm.samples)?;
        let target = settings.mode;
        let nc = plan.n_coeffs();
        let joints = JointForces::new(model, &plan);
        let nh = plan.n_harmonics();
        let zeros = || (0..=nh).map(|_| Mat::<c64>::zeros(q, q)).collect::<Vec<_>>();
        Ok(NonlinearMode {
            model,
            target,
            omega_t: linear.natural_frequencies()[target],
            c_t: linear.damping_coefficients()[target],
            a_t: (0..q).map(|i| linear.participation()[(i, target)]).collect(),
            linear,
            shift_all: settings.negative_damping == NegativeDamping::MassProportional,
            q,
            joints,
            u: vec![0.0; q * nc],
            h: zeros(),
            dh_domega: zeros(),
            dh_dxi: zeros(),
            t: vec![0.0; q * nc],
            n_w: Mat::zeros(q, q),
            dn_domega: Mat::zeros(q, q),
            dn_dxi: Mat::zeros(q, q),
            ng: vec![0.0; 2 * q],
            plan,
            evaluations: 0,
        })
    }

    pub fn plan(&self) -> &AftPlan {
        &self.plan
    }

    /// The linear mode's circular frequency ω_* (rad/s).
    pub fn linear_omega(&self) -> f64 {
        self.omega_t
    }

    /// The linear mode's damping ratio `c_* / (2 ω_*)`.
    pub fn linear_damping_ratio(&self) -> f64 {
        self.c_t / (2.0 * self.omega_t)
    }

    /// Number of nonlinear directions q.
    pub fn n_directions(&self) -> usize {
        self.q
    }

    /// Index of the scaled frequency `w = Ω/ω_*` in the unknowns (`ξ̂` follows it).
    fn i_omega(&self) -> usize {
        self.dimension() - 2
    }

    /// `η_c / a` for coefficient c: the phase condition fixes s1 at 0.
    fn eta(&self, y: &[f64], c: usize) -> f64 {
        self.eta_column(c).map_or(0.0, |col| y[col])
    }

    /// Column of the unknown `η_c / a` (`None` for the fixed s1).
    fn eta_column(&self, c: usize) -> Option<usize> {
        let base = self.q * self.plan.n_coeffs();
        match c {
            2 => None,
            0 | 1 => Some(base + c),
            _ => Some(base + c - 1),
        }
    }

    /// The condensed modes' part of the amplitude condition. Their harmonic 1 is
    /// `p_r1 = −a_rᵀ G_1 / den_r(Ω)`, so `Σ_{r≠*} |p_r1|² = G_1ᴴ N G_1` with the real symmetric
    ///
    /// ```text
    /// N(Ω, ξ) = Σ_{r≠*} a_r a_rᵀ / |den_r|²,   |den_r|² = (ω_r² − Ω²)² + Ω² (c_r − ξ_r)²
    /// ```
    ///
    /// (`ξ_r = ξ` with [`NegativeDamping::MassProportional`], 0 otherwise); `n_w`, `dn_domega`
    /// and `dn_dxi` receive N, ∂N/∂Ω and ∂N/∂ξ.
    fn amplitude_weights(&mut self, omega: f64, xi: f64) {
        let q = self.q;
        let (omega_r, c_r) = (self.linear.natural_frequencies(), self.linear.damping_coefficients());
        let a = self.linear.participation();
        let shift = if self.shift_all { xi } else { 0.0 };
        self.n_w.fill(0.0);
        self.dn_domega.fill(0.0);
        self.dn_dxi.fill(0.0);
        let o2 = omega * omega;
        for r in (0..omega_r.len()).filter(|&r| r != self.target) {
            let (s, c) = (omega_r[r] * omega_r[r] - o2, c_r[r] - shift);
            let den2 = s * s + o2 * c * c;
            let inv = 1.0 / den2;
            // ∂(1/|den|²) = −∂|den|² / |den|⁴.
            let d_omega = -(-4.0 * omega * s + 2.0 * omega * c * c) * inv * inv;
            let d_xi = if self.shift_all { 2.0 * o2 * c * inv * inv } else { 0.0 };
            for j in 0..q {
                for i in 0..q {
                    let aa = a[(i, r)] * a[(j, r)];
                    self.n_w[(i, j)] += aa * inv;
                    self.dn_domega[(i, j)] += aa * d_omega;
                    self.dn_dxi[(i, j)] += aa * d_xi;
                }
            }
        }
    }

    /// The linear mode at any amplitude, as scaled unknowns: `u/a = a_*` on harmonic 1, `Ω = ω_*`,
    /// `ξ = c_*`. The exact solution while every joint sticks.
    pub fn linear_guess(&self) -> Vec<f64> {
        let mut y = vec![0.0; self.dimension()];
        for i in 0..self.q {
            y[cos_index(1) * self.q + i] = self.a_t[i];
        }
        y[self.eta_column(cos_index(1)).expect("c1 is an unknown")] = 1.0;
        let iw = self.i_omega();
        y[iw] = 1.0;
        y[iw + 1] = self.c_t / self.omega_t;
        y
    }

    /// Ω (rad/s) and ξ (1/s) of scaled unknowns `y`.
    pub fn frequency_and_xi(&self, y: &[f64]) -> (f64, f64) {
        let iw = self.i_omega();
        (y[iw] * self.omega_t, y[iw + 1] * self.omega_t)
    }

    /// AFT of every element at `u = a û` and Ω: G, and if `want`, each element's ∂G/∂u, ∂G/∂Ω.
    fn element_forces(&mut self, y: &[f64], amplitude: f64, omega: f64, want: bool) -> Result<(), AftError> {
        for (u, v) in self.u.iter_mut().zip(y) {
            *u = amplitude * v;
        }
        self.joints.evaluate(self.model, &self.plan, &self.u, omega, want, false)
    }

    /// `H_rest(kΩ; ξ)` for k = 0..=N and its derivatives in Ω and ξ: the linear part with the
    /// target mode left out and, for [`NegativeDamping::MassProportional`], the damping
    /// `−ξ M` added ([`ModalReceptance::matrix_with`]; `∂/∂Ω = k ∂/∂ω`, `∂/∂ξ = −∂/∂α`).
    fn receptances(&mut self, omega: f64, xi: f64) {
        let variation = LinearVariation {
            mass_damping: if self.shift_all { -xi } else { 0.0 },
            stiffness_damping: 0.0,
            without_mode: Some(self.target),
        };
        let parameters: &[LinearParameter] = match self.shift_all {
            true => &[LinearParameter::Frequency, LinearParameter::MassDamping],
            false => &[LinearParameter::Frequency],
        };
        for k in 0..=self.plan.n_harmonics() {
            let kf = k as f64;
            let (h, dw, dx) = (self.h[k].as_mut(), &mut self.dh_domega[k], &mut self.dh_dxi[k]);
            match self.shift_all {
                true => self.linear.matrix_with(kf * omega, &variation, parameters, h, &mut [dw.as_mut(), dx.as_mut()]),
                false => {
                    self.linear.matrix_with(kf * omega, &variation, parameters, h, &mut [dw.as_mut()]);
                    dx.fill(c64::new(0.0, 0.0));
                }
            }
            dw.col_iter_mut().flat_map(|c| c.iter_mut()).for_each(|v| *v *= kf);
            dx.col_iter_mut().flat_map(|c| c.iter_mut()).for_each(|v| *v = -*v);
        }
    }

    /// Post-process the solution `y` at `λ = log10 a`: frequency, ξ, energies, stick fractions
    /// and the harmonics along each of `outputs` (vectors over the model's DOFs).
    pub fn point(&mut self, y: &[f64], lambda: f64, outputs: &[&[f64]]) -> Result<BackbonePoint, NonlinearModeError> {
        let amplitude = 10f64.powf(lambda);
        let (omega, xi) = self.frequency_and_xi(y);
        let mut r = vec![0.0; self.dimension()];
        self.evaluate(y, lambda, &mut r, None)
            .map_err(|e| NonlinearModeError::PostProcessing { amplitude, reason: e.message })?;
        let q = self.q;
        let (nh, nc, nt) = (self.plan.n_harmonics(), self.plan.n_coeffs(), self.plan.n_samples());
        let m = self.linear.natural_frequencies().len();
        let n = self.model.linear.n_dofs();
        let pi = std::f64::consts::PI;
        let (omega_r, c_r) = (self.linear.natural_frequencies(), self.linear.damping_coefficients());
        let (a, shapes) = (self.linear.participation(), &self.linear.modes().shapes);
        // Modal coordinates of every mode, harmonic by harmonic: η for the target,
        // −a_rᵀ G_k / den_r(kΩ) for the others (the condensed modes, recovered).
        let mut modal = vec![vec![c64::new(0.0, 0.0); nh + 1]; m];
        for k in 0..=nh {
            let w = k as f64 * omega;
            let gk: Vec<c64> = (0..q)
                .map(|i| {
                    if k == 0 {
                        c64::new(self.joints.g[i], 0.0)
                    } else {
                        c64::new(self.joints.g[cos_index(k) * q + i], -self.joints.g[sin_index(k) * q + i])
                    }
                })
                .collect();
            for r in 0..m {
                modal[r][k] = if r == self.target {
                    if k == 0 {
                        c64::new(amplitude * self.eta(y, 0), 0.0)
                    } else {
                        c64::new(self.eta(y, cos_index(k)), -self.eta(y, sin_index(k))) * amplitude
                    }
                } else {
                    let shift = if self.shift_all { xi } else { 0.0 };
                    let den = c64::new(omega_r[r] * omega_r[r] - w * w, w * (c_r[r] - shift));
                    let load: c64 = (0..q).map(|i| gk[i] * a[(i, r)]).sum();
                    -load / den
                };
            }
        }
        // Work of −ξ M U̇ and of D over a cycle: ∮ ṗ² dt = π Ω Σ_k k² |P_k|² per mode.
        let mut supplied = 0.0;
        let mut viscous = 0.0;
        for r in 0..m {
            let s: f64 = (1..=nh).map(|k| (k * k) as f64 * modal[r][k].norm_sqr()).sum::<f64>() * pi * omega;
            if self.shift_all || r == self.target {
                supplied += xi * s;
            }
            viscous += c_r[r] * s;
        }
        let mut joint_energy = Vec::with_capacity(self.model.elements.len());
        let mut stick_fraction = Vec::with_capacity(self.model.elements.len());
        for (e, site) in self.model.elements.iter().enumerate() {
            let off = self.joints.offsets[e];
            // ∮ g du = π Σ_k k (s_k g_ck − c_k g_sk), exact for the truncated motion.
            let w: f64 = (off..off + site.law.n_dirs())
                .map(|i| {
                    (1..=nh)
                        .map(|k| {
                            let (ic, is) = (cos_index(k) * q + i, sin_index(k) * q + i);
                            pi * k as f64 * (self.u[is] * self.joints.g[ic] - self.u[ic] * self.joints.g[is])
                        })
                        .sum::<f64>()
                })
                .sum();
            joint_energy.push(w);
            let aft = &self.joints.afts[e];
            stick_fraction.push(aft.slipping.iter().filter(|s| !**s).count() as f64 / nt as f64);
        }
        let energy_per_cycle = viscous + joint_energy.iter().sum::<f64>();
        let outputs = outputs
            .iter()
            .map(|o| {
                let proj: Vec<f64> = (0..m).map(|r| (0..n).map(|l| o[l] * shapes[(l, r)]).sum()).collect();
                let mut c = vec![0.0; nc];
                for k in 0..=nh {
                    let v: c64 = (0..m).map(|r| modal[r][k] * proj[r]).sum();
                    if k == 0 {
                        c[0] = v.re;
                    } else {
                        c[cos_index(k)] = v.re;
                        c[sin_index(k)] = -v.im;
                    }
                }
                c
            })
            .collect();
        Ok(BackbonePoint {
            amplitude,
            omega,
            xi,
            energy_per_cycle,
            supplied_energy: supplied,
            joint_energy,
            stick_fraction,
            outputs,
            modal_harmonic1: modal.iter().map(|p| p[1]).collect(),
            y: y.to_vec(),
        })
    }
}

impl Problem for NonlinearMode<'_> {
    fn dimension(&self) -> usize {
        (self.q + 1) * self.plan.n_coeffs() + 1
    }

    fn evaluate(
        &mut self,
        y: &[f64],
        lambda: f64,
        residual: &mut [f64],
        jacobian: Option<(MatMut<'_, f64>, &mut [f64])>,
    ) -> Result<(), ProblemError> {
        self.evaluations += 1;
        let q = self.q;
        let nc = self.plan.n_coeffs();
        let nh = self.plan.n_harmonics();
        let amplitude = 10f64.powf(lambda);
        let iw = self.i_omega();
        let (w, xih) = (y[iw], y[iw + 1]);
        let (omega, xi) = (w * self.omega_t, xih * self.omega_t);
        let ct = self.c_t / self.omega_t;
        let w2 = self.omega_t * self.omega_t;
        let want = jacobian.is_some();
        self.element_forces(y, amplitude, omega, want).map_err(|e| ProblemError::at_trial_iterate(e.to_string()))?;
        self.receptances(omega, xi);
        self.amplitude_weights(omega, xi);
        let inv_a = 1.0 / amplitude;
        let base = q * nc;
        // R_u (scaled by 1/a): û − a_* η̂ + H_rest G/a.
        for k in 0..=nh {
            let h = &self.h[k];
            if k == 0 {
                let e0 = self.eta(y, 0);
                for i in 0..q {
                    let mut r = y[i] - self.a_t[i] * e0;
                    for j in 0..q {
                        r += h[(i, j)].re * self.joints.g[j] * inv_a;
                    }
                    residual[i] = r;
                }
                continue;
            }
            let (ic, is) = (cos_index(k), sin_index(k));
            let (ec, es) = (self.eta(y, ic), self.eta(y, is));
            for i in 0..q {
                let mut rc = y[ic * q + i] - self.a_t[i] * ec;
                let mut rs = y[is * q + i] - self.a_t[i] * es;
                for j in 0..q {
                    let (gc, gs) = (self.joints.g[ic * q + j] * inv_a, self.joints.g[is * q + j] * inv_a);
                    rc += h[(i, j)].re * gc + h[(i, j)].im * gs;
                    rs += -h[(i, j)].im * gc + h[(i, j)].re * gs;
                }
                residual[ic * q + i] = rc;
                residual[is * q + i] = rs;
            }
        }
        // R_η (scaled by 1/(a ω_*²)): D_k η̂_k + a_*ᵀ G_k/(a ω_*²), D_k/ω_*² = 1 − (kw)² + i kw(c̃ − ξ̂).
        let proj = |g: &[f64], c: usize| -> f64 { (0..q).map(|i| self.a_t[i] * g[c * q + i]).sum::<f64>() };
        residual[base] = self.eta(y, 0) + proj(&self.joints.g, 0) * inv_a / w2;
        for k in 1..=nh {
            let kw = k as f64 * w;
            let (zr, zi) = (1.0 - kw * kw, kw * (ct - xih));
            let (ic, is) = (cos_index(k), sin_index(k));
            let (ec, es) = (self.eta(y, ic), self.eta(y, is));
            residual[base + ic] = zr * ec + zi * es + proj(&self.joints.g, ic) * inv_a / w2;
            residual[base + is] = -zi * ec + zr * es + proj(&self.joints.g, is) * inv_a / w2;
        }
        // R_a = |η̂_1|² + Ĝ_1ᴴ N Ĝ_1 − 1: the mass norm of harmonic 1 of the whole motion,
        // `X_1ᴴ M X_1 = Σ_r |p_r1|²` in mass-normalised modes, is a² (Krack 2015, Eq. 4).
        let (c1, s1) = (cos_index(1), sin_index(1));
        let row_a = base + nc;
        let g_hat = |g: &[f64], part: usize, j: usize| g[part * q + j] * inv_a;
        for i in 0..q {
            self.ng[i] = (0..q).map(|j| self.n_w[(i, j)] * g_hat(&self.joints.g, c1, j)).sum();
            self.ng[q + i] = (0..q).map(|j| self.n_w[(i, j)] * g_hat(&self.joints.g, s1, j)).sum();
        }
        let quadratic = |n: &Mat<f64>, g: &[f64]| -> f64 {
            [c1, s1]
                .iter()
                .map(|&part| {
                    (0..q)
                        .map(|i| g_hat(g, part, i) * (0..q).map(|j| n[(i, j)] * g_hat(g, part, j)).sum::<f64>())
                        .sum::<f64>()
                })
                .sum()
        };
        let e1 = self.eta(y, c1);
        residual[row_a] = e1 * e1 + quadratic(&self.n_w, &self.joints.g) - 1.0;
        let Some((mut dy, dl)) = jacobian else { return Ok(()) };

        // ∂/∂û: I + H_rest ∂G/∂u on R_u, a_*ᵀ ∂G/∂u / ω_*² on R_η (∂(G(aû)/a)/∂û = ∂G/∂u).
        // ∂G/∂u is block diagonal over elements; t = ∂G/∂u û − G/a is built on the way.
        for i in 0..base {
            dy[(i, i)] = 1.0;
            self.t[i] = -self.joints.g[i] * inv_a;
        }
        for (e, site) in self.model.elements.iter().enumerate() {
            let d = site.law.n_dirs();
            let off = self.joints.offsets[e];
            let je = &self.joints.elem_jac[e];
            for c2 in 0..nc {
                for b in 0..d {
                    let col = c2 * q + off + b;
                    let ecol = c2 * d + b;
                    let ub = y[col];
                    for c in 0..nc {
                        for a in 0..d {
                            self.t[c * q + off + a] += je[(c * d + a, ecol)] * ub;
                        }
                    }
                    // R_η rows.
                    for c in 0..nc {
                        let v: f64 = (0..d).map(|a| self.a_t[off + a] * je[(c * d + a, ecol)]).sum();
                        dy[(base + c, col)] += v / w2;
                    }
                    // R_a row: 2 (N Ĝ_1)ᴴ ∂G_1/∂u.
                    let v: f64 = (0..d)
                        .map(|a| {
                            self.ng[off + a] * je[(c1 * d + a, ecol)] + self.ng[q + off + a] * je[(s1 * d + a, ecol)]
                        })
                        .sum();
                    dy[(row_a, col)] += 2.0 * v;
                    // R_u rows, harmonic 0 then k ≥ 1.
                    for i in 0..q {
                        let v: f64 = (0..d).map(|a| self.h[0][(i, off + a)].re * je[(a, ecol)]).sum();
                        dy[(i, col)] += v;
                    }
                    for k in 1..=nh {
                        let h = &self.h[k];
                        let (ic, is) = (cos_index(k), sin_index(k));
                        for i in 0..q {
                            let (mut vc, mut vs) = (0.0, 0.0);
                            for a in 0..d {
                                let hh = h[(i, off + a)];
                                let (gc, gs) = (je[(ic * d + a, ecol)], je[(is * d + a, ecol)]);
                                vc += hh.re * gc + hh.im * gs;
                                vs += -hh.im * gc + hh.re * gs;
                            }
                            dy[(ic * q + i, col)] += vc;
                            dy[(is * q + i, col)] += vs;
                        }
                    }
                }
            }
        }
        // ∂/∂η̂ (free coefficients): −a_* on R_u, D_k/ω_*² on R_η.
        for c in 0..nc {
            if let Some(col) = self.eta_column(c) {
                for i in 0..q {
                    dy[(c * q + i, col)] = -self.a_t[i];
                }
            }
        }
        dy[(base, base)] = 1.0;
        for k in 1..=nh {
            let kw = k as f64 * w;
            let (zr, zi) = (1.0 - kw * kw, kw * (ct - xih));
            let (ic, is) = (cos_index(k), sin_index(k));
            if let Some(cc) = self.eta_column(ic) {
                dy[(base + ic, cc)] = zr;
                dy[(base + is, cc)] = -zi;
            }
            if let Some(cs) = self.eta_column(is) {
                dy[(base + ic, cs)] = zi;
                dy[(base + is, cs)] = zr;
            }
        }
        dy[(row_a, self.eta_column(c1).expect("c1 is an unknown"))] = 2.0 * e1;
        // ∂/∂w = ω_* ∂/∂Ω and ∂/∂ξ̂ = ω_* ∂/∂ξ.
        let wt = self.omega_t;
        for k in 0..=nh {
            let (h, dh, dx) = (&self.h[k], &self.dh_domega[k], &self.dh_dxi[k]);
            if k == 0 {
                for i in 0..q {
                    let v: f64 = (0..q).map(|j| h[(i, j)].re * self.joints.dg_domega[j]).sum();
                    dy[(i, iw)] += wt * v * inv_a;
                }
                continue;
            }
            let (ic, is) = (cos_index(k), sin_index(k));
            for i in 0..q {
                let (mut wc, mut ws, mut xc, mut xs) = (0.0, 0.0, 0.0, 0.0);
                for j in 0..q {
                    let (gc, gs) = (self.joints.g[ic * q + j] * inv_a, self.joints.g[is * q + j] * inv_a);
                    let (dgc, dgs) =
                        (self.joints.dg_domega[ic * q + j] * inv_a, self.joints.dg_domega[is * q + j] * inv_a);
                    let (hh, dd, xx) = (h[(i, j)], dh[(i, j)], dx[(i, j)]);
                    wc += dd.re * gc + dd.im * gs + hh.re * dgc + hh.im * dgs;
                    ws += -dd.im * gc + dd.re * gs - hh.im * dgc + hh.re * dgs;
                    xc += xx.re * gc + xx.im * gs;
                    xs += -xx.im * gc + xx.re * gs;
                }
                dy[(ic * q + i, iw)] += wt * wc;
                dy[(is * q + i, iw)] += wt * ws;
                dy[(ic * q + i, iw + 1)] += wt * xc;
                dy[(is * q + i, iw + 1)] += wt * xs;
            }
        }
        dy[(base, iw)] += wt * proj(&self.joints.dg_domega, 0) * inv_a / w2;
        for k in 1..=nh {
            let kf = k as f64;
            let (ic, is) = (cos_index(k), sin_index(k));
            let (ec, es) = (self.eta(y, ic), self.eta(y, is));
            // d(D_k/ω_*²)/dw = −2k²w + i k (c̃ − ξ̂); d(D_k/ω_*²)/dξ̂ = −i k w.
            let (zr, zi) = (-2.0 * kf * kf * w, kf * (ct - xih));
            dy[(base + ic, iw)] += zr * ec + zi * es + wt * proj(&self.joints.dg_domega, ic) * inv_a / w2;
            dy[(base + is, iw)] += -zi * ec + zr * es + wt * proj(&self.joints.dg_domega, is) * inv_a / w2;
            let zi = -kf * w;
            dy[(base + ic, iw + 1)] += zi * es;
            dy[(base + is, iw + 1)] += -zi * ec;
        }
        // ∂/∂λ = ln 10 [H_rest t; a_*ᵀ t / ω_*²].
        for k in 0..=nh {
            let h = &self.h[k];
            if k == 0 {
                for i in 0..q {
                    dl[i] = LN_10 * (0..q).map(|j| h[(i, j)].re * self.t[j]).sum::<f64>();
                }
                continue;
            }
            let (ic, is) = (cos_index(k), sin_index(k));
            for i in 0..q {
                let (mut vc, mut vs) = (0.0, 0.0);
                for j in 0..q {
                    let (tc, ts) = (self.t[ic * q + j], self.t[is * q + j]);
                    vc += h[(i, j)].re * tc + h[(i, j)].im * ts;
                    vs += -h[(i, j)].im * tc + h[(i, j)].re * ts;
                }
                dl[ic * q + i] = LN_10 * vc;
                dl[is * q + i] = LN_10 * vs;
            }
        }
        for c in 0..nc {
            dl[base + c] = LN_10 * proj(&self.t, c) / w2;
        }
        // R_a in w, ξ̂ and λ: ∂Ĝ/∂Ω = ∂G/∂Ω / a, ∂Ĝ/∂λ = ln 10 t.
        let cross = |g: &[f64], scale: f64| -> f64 {
            (0..q).map(|i| self.ng[i] * g[c1 * q + i] + self.ng[q + i] * g[s1 * q + i]).sum::<f64>() * scale
        };
        dy[(row_a, iw)] +=
            wt * (2.0 * cross(&self.joints.dg_domega, inv_a) + quadratic(&self.dn_domega, &self.joints.g));
        dy[(row_a, iw + 1)] += wt * quadratic(&self.dn_dxi, &self.joints.g);
        dl[row_a] = 2.0 * LN_10 * cross(&self.t, 1.0);
        Ok(())
    }

    fn scales(&self) -> Scales {
        // Residuals are scaled to order one (module documentation), whatever the amplitude.
        Scales { unknowns: None, residual: Some(1.0) }
    }
}

/// The backbone of mode `settings.mode` (0-based) of `model` from modal amplitude
/// `amplitude_start` to `amplitude_end` (m·√kg, both positive, the first the smaller), with
/// the harmonics of `outputs` (vectors over the DOFs) at every point.
///
/// The branch starts from the linear mode, which must still hold at `amplitude_start` (else
/// [`NonlinearModeError::NonlinearStart`]). A model without joints has only its linear mode:
/// it is returned at the two ends of the range, with a note.
pub fn nonlinear_mode<'m, O: PointObserver<NonlinearMode<'m>> + ?Sized>(
    model: &'m NonlinearModel,
    settings: &NonlinearModeSettings,
    amplitude_start: f64,
    amplitude_end: f64,
    outputs: &[&[f64]],
    options: &Options,
    observer: &mut O,
) -> Result<Backbone, NonlinearModeError> {
    let valid = |a: f64| a.is_finite() && a > 0.0;
    if !(valid(amplitude_start) && valid(amplitude_end) && amplitude_start < amplitude_end) {
        return Err(NonlinearModeError::InvalidAmplitudes { start: amplitude_start, end: amplitude_end });
    }
    model.check_no_rigid_contacts("the nonlinear mode")?;
    if model.elements.is_empty() {
        return linear_backbone(model, settings, amplitude_start, amplitude_end, outputs);
    }
    let mut problem = NonlinearMode::new(model, settings)?;
    let guess = problem.linear_guess();
    let (l0, l1) = (amplitude_start.log10(), amplitude_end.log10());
    let mut recorder = TestRecorder { inner: observer, tests: Vec::new() };
    let branch = continue_branch(&mut problem, &guess, l0, l1, options, &mut recorder)?;
    if let TerminationReason::FirstPointFailed { .. } | TerminationReason::ProblemError { last_lambda: None, .. } =
        &branch.termination
    {
        return Err(NonlinearModeError::FirstPointFailed {
            amplitude: amplitude_start,
            reason: branch.termination.to_string(),
        });
    }
    let first = &branch.points[0];
    let (omega, xi) = problem.frequency_and_xi(&first.x);
    let (w0, z0) = (problem.linear_omega(), problem.linear_damping_ratio());
    let frequency_shift = (omega / w0 - 1.0).abs();
    let zeta = xi / (2.0 * omega);
    let damping_shift = (zeta - z0).abs() / z0.max(1e-3);
    if frequency_shift > LINEAR_START_TOLERANCE || damping_shift > LINEAR_START_TOLERANCE {
        return Err(NonlinearModeError::NonlinearStart {
            amplitude: amplitude_start,
            linear_hz: w0 / (2.0 * std::f64::consts::PI),
            frequency_shift,
            linear_ratio: z0,
            damping_shift,
        });
    }
    let mut points = Vec::with_capacity(branch.points.len());
    for p in &branch.points {
        points.push(problem.point(&p.x, p.lambda, outputs)?);
    }
    let mut singular: Vec<BackboneSingularPoint> =
        singular_points(&mut problem, &branch.points, &recorder.tests, SINGULAR_TOLERANCE)
            .into_iter()
            .map(|s| {
                let (omega, xi) = problem.frequency_and_xi(&s.x);
                BackboneSingularPoint {
                    kind: s.kind,
                    amplitude: 10f64.powf(s.lambda),
                    omega,
                    xi,
                    after_point: s.after_point,
                    located: s.located,
                }
            })
            .collect();
    // Near a branch point the continuation's small steps can turn it onto the crossing branch
    // and back, until it runs back along the backbone to the first amplitude (seen on a
    // structure with four alike joints, where the crossing motions are those in which the
    // joints stop moving alike). What follows the branch point is then only the way back.
    let mut turned_back_at = None;
    if branch.termination == TerminationReason::ReturnedToStart {
        if let Some(bp) = singular.iter().find(|s| s.kind == SingularKind::BranchPoint).cloned() {
            points.truncate(bp.after_point + 1);
            singular.retain(|s| s.after_point < bp.after_point);
            singular.push(bp.clone());
            turned_back_at = Some(bp);
        }
    }
    Ok(Backbone {
        mode: settings.mode,
        linear_omega: w0,
        linear_damping_ratio: z0,
        points,
        termination: branch.termination.clone(),
        notes: Vec::new(),
        singular_points: singular,
        turned_back_at,
        branch: Some(branch),
        viscous: problem.c_t,
        shapes: problem.linear.modes().shapes.clone(),
    })
}

/// The linear mode at the ends of the amplitude range (a model without joints).
fn linear_backbone(
    model: &NonlinearModel,
    settings: &NonlinearModeSettings,
    amplitude_start: f64,
    amplitude_end: f64,
    outputs: &[&[f64]],
) -> Result<Backbone, NonlinearModeError> {
    if !model.linear.damping.is_modal() {
        return Err(NonlinearModeError::GeneralDamping);
    }
    let modes = model.linear.dense_modes()?;
    let r = settings.mode;
    if r >= modes.omega.len() {
        return Err(NonlinearModeError::ModeOutOfRange { mode: r + 1, available: modes.omega.len() });
    }
    let omega = modes.omega[r];
    let c = model.linear.damping.modal_coefficient(r, omega).expect("modal damping");
    let n = model.linear.n_dofs();
    let nc = 2 * settings.hbm.harmonics + 1;
    let points = [amplitude_start, amplitude_end]
        .iter()
        .map(|&a| BackbonePoint {
            amplitude: a,
            omega,
            xi: c,
            // ∮ c ṗ² dt = π c ω a² for p = a cos ωt.
            energy_per_cycle: std::f64::consts::PI * c * omega * a * a,
            supplied_energy: std::f64::consts::PI * c * omega * a * a,
            joint_energy: Vec::new(),
            stick_fraction: Vec::new(),
            outputs: outputs
                .iter()
                .map(|o| {
                    let mut v = vec![0.0; nc];
                    v[cos_index(1)] = a * (0..n).map(|l| o[l] * modes.shapes[(l, r)]).sum::<f64>();
                    v
                })
                .collect(),
            modal_harmonic1: (0..modes.omega.len()).map(|s| c64::new(if s == r { a } else { 0.0 }, 0.0)).collect(),
            y: Vec::new(),
        })
        .collect();
    Ok(Backbone {
        mode: r,
        linear_omega: omega,
        linear_damping_ratio: c / (2.0 * omega),
        points,
        termination: TerminationReason::ReachedEnd,
        singular_points: Vec::new(),
        turned_back_at: None,
        notes: vec![format!(
            "the model has no joints: its nonlinear mode {} is the linear mode at every amplitude ({:.6} Hz, damping ratio {:.4e})",
            r + 1,
            omega / (2.0 * std::f64::consts::PI),
            c / (2.0 * omega)
        )],
        branch: None,
        viscous: c,
        shapes: modes.shapes.clone(),
    })
}
