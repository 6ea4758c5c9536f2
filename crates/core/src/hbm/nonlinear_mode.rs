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
//!
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
//! (with a damping matrix, `p_r1 = −W_r0 η_1 − W_rG G_1`, below), so that `a` measures the
//! motion, not only the target mode's share of it, which falls where slipping joints move the
//! other modes (on a model with many modes it can even fall while the motion grows). The continuation parameter is `λ = log10 a`, so a branch spans decades of
//! amplitude with steps of even relative size.
//!
//! # A damping matrix
//!
//! A damping matrix that is not diagonal in the modes (`C = Φᵀ D Φ` full) couples every modal
//! equation. Per harmonic, with `Z = Λ − (kΩ)² + i kΩ (C − ξ S)` (S the identity, or the
//! target alone) split into the target (*) and the rest (r), the condensed modes are
//! `p_r = −W_r0 η − W_rG G` with `W = Z_rr⁻¹ [Z_r*, A_rᵀ]` (one complex LU of size m − 1 per
//! harmonic and evaluation), and the balance keeps its form with three coefficients:
//!
//! ```text
//! R_u,k = u_k − b_k η_k + H_k G_k,      b_k = a_* − A_r W_r0,   H_k = A_r W_rG
//! R_η,k = z_k η_k + c_kᵀ G_k,           z_k = Z_** − Z_*r W_r0,  c_k = a_* − (Z_*r W_rG)ᵀ
//! ```
//!
//! With diagonal damping `Z_r* = 0`, so that `b = c = a_*`, `z_k` is the target's own dynamic
//! stiffness and `H_k` the modal sum above. The derivatives in Ω and ξ reuse the LU
//! (`∂W = Z_rr⁻¹ ([∂Z_r*, 0] − ∂Z_rr W)`). The linear limit is no longer `(ω_*, c_*)` but the
//! root of `z_1(Ω, ξ) = 0` ([`NonlinearMode::linear_limit`]).
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

use faer::linalg::solvers::Solve;
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
    /// The linear part with damping diagonal in the modes, as the forced balance has it: the
    /// condensed modes' receptance as a modal sum. `None` with a damping matrix.
    linear: Option<ModalReceptance>,
    /// Every mode: ω_r, the diagonal of the modal damping `Φᵀ D Φ`, `A = Vᵀ Φ` (q × m) and the
    /// mass-normalised shapes (n × m).
    omega_r: Vec<f64>,
    c_r: Vec<f64>,
    a_all: Mat<f64>,
    shapes: Mat<f64>,
    /// With a damping matrix, the full `C = Φᵀ D Φ` (m × m), which couples the modes.
    coupled: Option<Mat<f64>>,
    /// Per harmonic 0..=N: how the target mode meets the joints through the condensed modes
    /// (module documentation), at the last evaluation.
    coupling: Vec<TargetCoupling>,
    /// `W` of harmonic 1 (m × (1 + q), zero row at the target), so that the condensed modes'
    /// harmonic 1 is `p_r1 = −W_r0 η_1 − Σ_j W_rj G_1j`; and its ∂/∂Ω, ∂/∂ξ.
    w1: [Mat<c64>; 3],
    /// `p_r1 / a` at the last evaluation (m), and `G_1 / a` (q).
    p1: Vec<c64>,
    g1: Vec<c64>,
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
    /// `∂R_a/∂Ĝ_c1` then `∂R_a/∂Ĝ_s1` (2q), with `Ĝ = G/a`.
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

/// How the target mode meets the joints at one harmonic through the condensed modes: the
/// motion along the joints `u_k = b_k η_k − H_k G_k`, and the target's balance
/// `z_k η_k + c_kᵀ G_k = 0` (module documentation). With damping diagonal in the modes,
/// `b = c = a_*` and `z_k` is the target's own dynamic stiffness. Each as value, ∂/∂Ω, ∂/∂ξ.
#[derive(Clone, Debug)]
struct TargetCoupling {
    b: [Vec<c64>; 3],
    z: [c64; 3],
    c: [Vec<c64>; 3],
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
    /// Modal amplitude a (m·√kg): the mass norm of harmonic 1 of the whole motion,
    /// `a² = X_1ᴴ M X_1` (Krack 2015, Eq. 4).
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
    /// Did the branch reach the last amplitude? (A backbone that turned back at a branch point
    /// came back to the first one instead.)
    pub fn complete(&self) -> bool {
        self.termination == TerminationReason::ReachedEnd
    }

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
        let directions: Vec<&[f64]> = model.application_vectors().map(|v| v.as_slice()).collect();
        let q = directions.len();
        let unforced = vec![0.0; model.linear.n_dofs()];
        let (linear, omega_r, c_r, a_all, shapes, coupled) =
            match Receptance::new(&model.linear, &directions, &unforced)? {
                Receptance::Modal(l) => {
                    let (omega_r, c_r) = (l.natural_frequencies().to_vec(), l.damping_coefficients().to_vec());
                    let (a, shapes) = (l.participation().to_owned(), l.modes().shapes.clone());
                    (Some(l), omega_r, c_r, a, shapes, None)
                }
                Receptance::Direct(d) => {
                    let c = d.modal_damping();
                    let omega_r = d.natural_frequencies().to_vec();
                    let c_r = (0..omega_r.len()).map(|r| c[(r, r)]).collect();
                    (None, omega_r, c_r, d.participation().to_owned(), d.modes().shapes.clone(), Some(c))
                }
            };
        let m = omega_r.len();
        if settings.mode >= m {
            return Err(NonlinearModeError::ModeOutOfRange { mode: settings.mode + 1, available: m });
        }
        let plan = AftPlan::new(settings.hbm.harmonics, settings.hbm.samples)?;
        let target = settings.mode;
        let nc = plan.n_coeffs();
        let joints = JointForces::new(model, &plan);
        let nh = plan.n_harmonics();
        let zeros = || (0..=nh).map(|_| Mat::<c64>::zeros(q, q)).collect::<Vec<_>>();
        let a_t: Vec<f64> = (0..q).map(|i| a_all[(i, target)]).collect();
        let real = |v: &[f64]| v.iter().map(|&x| c64::new(x, 0.0)).collect::<Vec<_>>();
        let coupling = TargetCoupling {
            b: [real(&a_t), vec![c64::new(0.0, 0.0); q], vec![c64::new(0.0, 0.0); q]],
            z: [c64::new(0.0, 0.0); 3],
            c: [real(&a_t), vec![c64::new(0.0, 0.0); q], vec![c64::new(0.0, 0.0); q]],
        };
        Ok(NonlinearMode {
            model,
            target,
            omega_t: omega_r[target],
            c_t: c_r[target],
            a_t,
            linear,
            omega_r,
            c_r,
            a_all,
            shapes,
            coupled,
            coupling: vec![coupling; nh + 1],
            w1: [Mat::zeros(m, q + 1), Mat::zeros(m, q + 1), Mat::zeros(m, q + 1)],
            p1: vec![c64::new(0.0, 0.0); m],
            g1: vec![c64::new(0.0, 0.0); q],
            shift_all: settings.negative_damping == NegativeDamping::MassProportional,
            q,
            joints,
            u: vec![0.0; q * nc],
            h: zeros(),
            dh_domega: zeros(),
            dh_dxi: zeros(),
            t: vec![0.0; q * nc],
            ng: vec![0.0; 2 * q],
            plan,
            evaluations: 0,
        })
    }

    pub fn plan(&self) -> &AftPlan {
        &self.plan
    }

    /// The undamped target mode's circular frequency ω_* (rad/s), the scale of the unknowns;
    /// the damped linear limit, where the branch starts, is [`Self::linear_limit`].
    pub fn linear_omega(&self) -> f64 {
        self.omega_t
    }

    /// The undamped target mode's damping ratio `c_* / (2 ω_*)` (`c_*` the diagonal of `Φᵀ D Φ`);
    /// with damping diagonal in the modes, that of the linear limit.
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

    /// The linear limit of the damped mode: Ω and ξ where the target's balance with every
    /// joint stuck, `z_1(Ω, ξ) = 0`, holds (Newton's method on the complex equation from the
    /// undamped mode). With damping diagonal in the modes it is `(ω_*, c_*)` exactly; a damping
    /// matrix couples the target to the other modes and moves both slightly.
    pub fn linear_limit(&self) -> (f64, f64) {
        let (mut omega, mut xi) = (self.omega_t, self.c_t);
        for _ in 0..50 {
            let (_, z) = self.coupling_at(1, omega, xi);
            let det = z[1].re * z[2].im - z[2].re * z[1].im;
            let d_omega = -(z[0].re * z[2].im - z[2].re * z[0].im) / det;
            let d_xi = -(z[1].re * z[0].im - z[0].re * z[1].im) / det;
            omega += d_omega;
            xi += d_xi;
            if d_omega.abs() <= 1e-15 * omega && d_xi.abs() <= 1e-15 * omega {
                break;
            }
        }
        (omega, xi)
    }

    /// The linear mode at any amplitude, as scaled unknowns: every joint stuck (`G = 0`), Ω
    /// and ξ at the linear limit, the target's harmonic 1 and the condensed modes' (dragged
    /// along by the damping coupling; none with diagonal damping) sharing the amplitude, and
    /// the joints' motion `u_1 = b_1 η_1`. The exact solution while every joint sticks.
    pub fn linear_guess(&self) -> Vec<f64> {
        let mut y = vec![0.0; self.dimension()];
        let (omega, xi) = self.linear_limit();
        let (w, _) = self.coupling_at(1, omega, xi);
        let m = self.omega_r.len();
        let e1 = 1.0 / (1.0 + (0..m).map(|r| w[0][(r, 0)].norm_sqr()).sum::<f64>()).sqrt();
        for i in 0..self.q {
            let b = c64::new(self.a_t[i], 0.0) - (0..m).map(|r| w[0][(r, 0)] * self.a_all[(i, r)]).sum::<c64>();
            y[cos_index(1) * self.q + i] = (b * e1).re;
            y[sin_index(1) * self.q + i] = -(b * e1).im;
        }
        y[self.eta_column(cos_index(1)).expect("c1 is an unknown")] = e1;
        let iw = self.i_omega();
        y[iw] = omega / self.omega_t;
        y[iw + 1] = xi / self.omega_t;
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

    /// The damping that `−ξ` acts on, `S_rs`: the identity with
    /// [`NegativeDamping::MassProportional`], the target mode alone otherwise.
    fn shifted(&self, r: usize, s: usize) -> f64 {
        f64::from(r == s && (self.shift_all || r == self.target))
    }

    /// The condensed modes at harmonic k with a damping matrix: with the modal dynamic stiffness
    /// `Z = Λ − (kΩ)² + i kΩ (C − ξ S)` split into the target (*) and the rest (r),
    /// `W = Z_rr⁻¹ [Z_r*, A_rᵀ]` (m × (1 + q), zero row at the target) and its ∂/∂Ω (the factor
    /// k included) and ∂/∂ξ; and `z_k = Z_** − Z_*r W_r0` with its derivatives. With damping
    /// diagonal in the modes, `W_r0 = 0`, `W_rj = a_jr / den_r` and `z_k` the target's own
    /// dynamic stiffness, in closed form.
    fn coupling_at(&self, k: usize, omega: f64, xi: f64) -> ([Mat<c64>; 3], [c64; 3]) {
        let (q, m) = (self.q, self.omega_r.len());
        let mut w = [Mat::zeros(m, q + 1), Mat::zeros(m, q + 1), Mat::zeros(m, q + 1)];
        let z = self.coupling_into(k, omega, xi, true, &mut w);
        (w, z)
    }

    /// [`Self::coupling_at`] into `w` (three m × (1 + q) matrices, the target's row left as it
    /// is, zero); without `derivatives`, `w[1]`, `w[2]` and `z[1..]` are not computed.
    fn coupling_into(&self, k: usize, omega: f64, xi: f64, derivatives: bool, w: &mut [Mat<c64>; 3]) -> [c64; 3] {
        let (q, m, t) = (self.q, self.omega_r.len(), self.target);
        let (kf, kw) = (k as f64, k as f64 * omega);
        let zero = c64::new(0.0, 0.0);
        let damping = |r: usize, s: usize| match &self.coupled {
            Some(c) => c[(r, s)],
            None if r == s => self.c_r[r],
            None => 0.0,
        };
        let z = |r: usize, s: usize| {
            let diag = if r == s { self.omega_r[r] * self.omega_r[r] - kw * kw } else { 0.0 };
            c64::new(diag, kw * (damping(r, s) - xi * self.shifted(r, s)))
        };
        let dz_omega = |r: usize, s: usize| {
            let diag = if r == s { -2.0 * kf * kw } else { 0.0 };
            c64::new(diag, kf * (damping(r, s) - xi * self.shifted(r, s)))
        };
        let dz_xi = |r: usize, s: usize| c64::new(0.0, -kw * self.shifted(r, s));
        if self.coupled.is_none() || k == 0 {
            // `W_rj = a_jr / den_r`, `∂W = −W ∂den / den`: one division a mode.
            for r in (0..m).filter(|&r| r != t) {
                let inv = c64::new(1.0, 0.0) / z(r, r);
                let (dw, dx) = (dz_omega(r, r) * inv, dz_xi(r, r) * inv);
                w[0][(r, 0)] = zero;
                for j in 0..q {
                    let v = inv * self.a_all[(j, r)];
                    w[0][(r, j + 1)] = v;
                    if derivatives {
                        w[1][(r, j + 1)] = -v * dw;
                        w[2][(r, j + 1)] = -v * dx;
                    }
                }
            }
            return [z(t, t), dz_omega(t, t), dz_xi(t, t)];
        }
        let rest: Vec<usize> = (0..m).filter(|&r| r != t).collect();
        let n = rest.len();
        let zrr = Mat::from_fn(n, n, |i, j| z(rest[i], rest[j]));
        let rhs =
            Mat::from_fn(
                n,
                q + 1,
                |i, j| if j == 0 { z(rest[i], t) } else { c64::new(self.a_all[(j - 1, rest[i])], 0.0) },
            );
        let lu = zrr.partial_piv_lu();
        let sol = lu.solve(&rhs);
        let mut out = [zero; 3];
        out[0] = z(t, t) - (0..n).map(|i| z(t, rest[i]) * sol[(i, 0)]).sum::<c64>();
        if derivatives {
            for (d, dz) in [(1usize, &dz_omega as &dyn Fn(usize, usize) -> c64), (2, &dz_xi)] {
                // dW = Z_rr⁻¹ ([dZ_r*, 0] − dZ_rr W).
                let drhs = Mat::from_fn(n, q + 1, |i, j| {
                    let own = if j == 0 { dz(rest[i], t) } else { zero };
                    own - (0..n).map(|l| dz(rest[i], rest[l]) * sol[(l, j)]).sum::<c64>()
                });
                let dsol = lu.solve(&drhs);
                out[d] =
                    dz(t, t) - (0..n).map(|i| dz(t, rest[i]) * sol[(i, 0)] + z(t, rest[i]) * dsol[(i, 0)]).sum::<c64>();
                for (i, &r) in rest.iter().enumerate() {
                    for j in 0..=q {
                        w[d][(r, j)] = dsol[(i, j)];
                    }
                }
            }
        }
        for (i, &r) in rest.iter().enumerate() {
            for j in 0..=q {
                w[0][(r, j)] = sol[(i, j)];
            }
        }
        out
    }

    /// The linear part at Ω and ξ for every harmonic: `H_k` (into `h`, with its derivatives),
    /// the target's coupling `b_k`, `z_k`, `c_k` and harmonic 1's `W`. With damping diagonal in
    /// the modes, `H_k` comes from the modal sum ([`ModalReceptance::matrix_with`], the target
    /// left out, `−ξ M` added for [`NegativeDamping::MassProportional`]; `∂/∂Ω = k ∂/∂ω`,
    /// `∂/∂ξ = −∂/∂α`); with a damping matrix, from `W` ([`Self::coupling_at`]):
    /// `H = A_r W_rG`, `b = a_* − A_r W_r0`, `c_j = a_*j − Z_*r W_rj`.
    fn linear_part(&mut self, omega: f64, xi: f64) {
        let (q, nh, t) = (self.q, self.plan.n_harmonics(), self.target);
        let m = self.omega_r.len();
        if let Some(linear) = &self.linear {
            let variation = LinearVariation {
                mass_damping: if self.shift_all { -xi } else { 0.0 },
                stiffness_damping: 0.0,
                without_mode: Some(t),
            };
            let parameters: &[LinearParameter] = match self.shift_all {
                true => &[LinearParameter::Frequency, LinearParameter::MassDamping],
                false => &[LinearParameter::Frequency],
            };
            for k in 0..=nh {
                let kf = k as f64;
                let (h, dw, dx) = (self.h[k].as_mut(), &mut self.dh_domega[k], &mut self.dh_dxi[k]);
                match self.shift_all {
                    true => linear.matrix_with(kf * omega, &variation, parameters, h, &mut [dw.as_mut(), dx.as_mut()]),
                    false => {
                        linear.matrix_with(kf * omega, &variation, parameters, h, &mut [dw.as_mut()]);
                        dx.fill(c64::new(0.0, 0.0));
                    }
                }
                dw.col_iter_mut().flat_map(|c| c.iter_mut()).for_each(|v| *v *= kf);
                dx.col_iter_mut().flat_map(|c| c.iter_mut()).for_each(|v| *v = -*v);
                self.coupling[k].z = self.target_stiffness(k, omega, xi);
            }
            // Harmonic 1's W in place (the closed form, no allocation).
            let mut w1 = std::mem::replace(&mut self.w1, [Mat::zeros(0, 0), Mat::zeros(0, 0), Mat::zeros(0, 0)]);
            self.coupling_into(1, omega, xi, true, &mut w1);
            self.w1 = w1;
            return;
        }
        for k in 0..=nh {
            let (w, z) = self.coupling_at(k, omega, xi);
            // Z_*r, its derivatives: the damping coupling of the target to mode r.
            let kw = k as f64 * omega;
            let c = self.coupled.as_ref().expect("a damping matrix");
            let z_tr: Vec<[c64; 3]> = (0..m)
                .map(|r| {
                    if r == t {
                        return [c64::new(0.0, 0.0); 3];
                    }
                    let v = c[(t, r)] - xi * self.shifted(t, r);
                    [c64::new(0.0, kw * v), c64::new(0.0, k as f64 * v), c64::new(0.0, -kw * self.shifted(t, r))]
                })
                .collect();
            let cp = &mut self.coupling[k];
            cp.z = z;
            for d in 0..3 {
                for i in 0..q {
                    let bi: c64 = (0..m).map(|r| w[d][(r, 0)] * self.a_all[(i, r)]).sum();
                    cp.b[d][i] = if d == 0 { c64::new(self.a_t[i], 0.0) - bi } else { -bi };
                    let mut ci: c64 = (0..m).map(|r| z_tr[r][0] * w[d][(r, i + 1)]).sum();
                    if d > 0 {
                        ci += (0..m).map(|r| z_tr[r][d] * w[0][(r, i + 1)]).sum::<c64>();
                    }
                    cp.c[d][i] = if d == 0 { c64::new(self.a_t[i], 0.0) - ci } else { -ci };
                }
                let hk = match d {
                    0 => &mut self.h[k],
                    1 => &mut self.dh_domega[k],
                    _ => &mut self.dh_dxi[k],
                };
                for i in 0..q {
                    for j in 0..q {
                        hk[(i, j)] = (0..m).map(|r| w[d][(r, j + 1)] * self.a_all[(i, r)]).sum();
                    }
                }
            }
            if k == 1 {
                self.w1 = w;
            }
        }
    }

    /// `z_k` of the target with damping diagonal in the modes, in closed form (and its ∂/∂Ω,
    /// ∂/∂ξ): `ω_*² − (kΩ)² + i kΩ (c_* − ξ)`.
    fn target_stiffness(&self, k: usize, omega: f64, xi: f64) -> [c64; 3] {
        let (kf, kw) = (k as f64, k as f64 * omega);
        let c = self.c_t - xi;
        [c64::new(self.omega_t * self.omega_t - kw * kw, kw * c), c64::new(-2.0 * kf * kw, kf * c), c64::new(0.0, -kw)]
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
        let m = self.omega_r.len();
        let n = self.model.linear.n_dofs();
        let pi = std::f64::consts::PI;
        // Modal coordinates of every mode, harmonic by harmonic: η for the target,
        // `−W_r0 η_k − Σ_j W_rj G_kj` for the others (the condensed modes, recovered).
        let mut modal = vec![vec![c64::new(0.0, 0.0); nh + 1]; m];
        let mut w = [Mat::zeros(m, q + 1), Mat::zeros(0, 0), Mat::zeros(0, 0)];
        for k in 0..=nh {
            // W of this harmonic (the closed form, or the LU of the other modes with a damping
            // matrix), without derivatives.
            self.coupling_into(k, omega, xi, false, &mut w);
            let gk: Vec<c64> = (0..q)
                .map(|i| {
                    if k == 0 {
                        c64::new(self.joints.g[i], 0.0)
                    } else {
                        c64::new(self.joints.g[cos_index(k) * q + i], -self.joints.g[sin_index(k) * q + i])
                    }
                })
                .collect();
            let eta = if k == 0 {
                c64::new(amplitude * self.eta(y, 0), 0.0)
            } else {
                c64::new(self.eta(y, cos_index(k)), -self.eta(y, sin_index(k))) * amplitude
            };
            for r in 0..m {
                modal[r][k] = if r == self.target {
                    eta
                } else {
                    -w[0][(r, 0)] * eta - (0..q).map(|i| w[0][(r, i + 1)] * gk[i]).sum::<c64>()
                };
            }
        }
        // Work of −ξ M U̇ and of D over a cycle: ∮ ṗᵀ C ṗ dt = π Ω Σ_k k² Re(P_kᴴ C P_k).
        let mut supplied = 0.0;
        let mut viscous = 0.0;
        for k in 1..=nh {
            let kk = (k * k) as f64 * pi * omega;
            for r in 0..m {
                let p = modal[r][k];
                if self.shift_all || r == self.target {
                    supplied += xi * kk * p.norm_sqr();
                }
                viscous += match &self.coupled {
                    Some(c) => kk * (0..m).map(|s| c[(r, s)] * (p.conj() * modal[s][k]).re).sum::<f64>(),
                    None => kk * self.c_r[r] * p.norm_sqr(),
                };
            }
        }
        let shapes = &self.shapes;
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
        let m = self.omega_r.len();
        let amplitude = 10f64.powf(lambda);
        let iw = self.i_omega();
        let (w, xih) = (y[iw], y[iw + 1]);
        let (omega, xi) = (w * self.omega_t, xih * self.omega_t);
        let w2 = self.omega_t * self.omega_t;
        let want = jacobian.is_some();
        self.element_forces(y, amplitude, omega, want).map_err(|e| ProblemError::at_trial_iterate(e.to_string()))?;
        self.linear_part(omega, xi);
        let inv_a = 1.0 / amplitude;
        let base = q * nc;
        let (c1, s1) = (cos_index(1), sin_index(1));
        let row_a = base + nc;
        // A complex harmonic `v (x_c − i x_s)` as its (cos, sin) parts.
        let times = |v: c64, xc: f64, xs: f64| (v.re * xc + v.im * xs, -v.im * xc + v.re * xs);
        let g = &self.joints.g;
        // R_u (scaled by 1/a): û − b η̂ + H G/a.
        for k in 0..=nh {
            let (h, b) = (&self.h[k], &self.coupling[k].b[0]);
            if k == 0 {
                let e0 = self.eta(y, 0);
                for i in 0..q {
                    let mut r = y[i] - b[i].re * e0;
                    for j in 0..q {
                        r += h[(i, j)].re * g[j] * inv_a;
                    }
                    residual[i] = r;
                }
                continue;
            }
            let (ic, is) = (cos_index(k), sin_index(k));
            let (ec, es) = (self.eta(y, ic), self.eta(y, is));
            for i in 0..q {
                let (bc, bs) = times(b[i], ec, es);
                let (mut rc, mut rs) = (y[ic * q + i] - bc, y[is * q + i] - bs);
                for j in 0..q {
                    let (hc, hs) = times(h[(i, j)], g[ic * q + j] * inv_a, g[is * q + j] * inv_a);
                    rc += hc;
                    rs += hs;
                }
                residual[ic * q + i] = rc;
                residual[is * q + i] = rs;
            }
        }
        // R_η (scaled by 1/(a ω_*²)): z_k η̂_k / ω_*² + c_kᵀ G_k/(a ω_*²).
        for k in 0..=nh {
            let cp = &self.coupling[k];
            let zz = cp.z[0] / w2;
            if k == 0 {
                let e0 = self.eta(y, 0);
                residual[base] = zz.re * e0 + (0..q).map(|i| cp.c[0][i].re * g[i]).sum::<f64>() * inv_a / w2;
                continue;
            }
            let (ic, is) = (cos_index(k), sin_index(k));
            let (mut rc, mut rs) = times(zz, self.eta(y, ic), self.eta(y, is));
            for i in 0..q {
                let (gc, gs) = times(cp.c[0][i], g[ic * q + i] * inv_a / w2, g[is * q + i] * inv_a / w2);
                rc += gc;
                rs += gs;
            }
            residual[base + ic] = rc;
            residual[base + is] = rs;
        }
        // R_a = |η̂_1|² + Σ_{r≠*} |p̂_r1|² − 1, p̂_r1 = −W_r0 η̂_1 − Σ_j W_rj Ĝ_1j: the mass norm
        // of harmonic 1 of the whole motion, `X_1ᴴ M X_1 = Σ_r |p_r1|²` in mass-normalised
        // modes, is a² (Krack 2015, Eq. 4).
        let e1 = self.eta(y, c1);
        for j in 0..q {
            self.g1[j] = c64::new(g[c1 * q + j], -g[s1 * q + j]) * inv_a;
        }
        let g1 = &self.g1;
        for r in 0..m {
            self.p1[r] = -self.w1[0][(r, 0)] * e1 - (0..q).map(|j| self.w1[0][(r, j + 1)] * g1[j]).sum::<c64>();
        }
        residual[row_a] = e1 * e1 + self.p1.iter().map(|p| p.norm_sqr()).sum::<f64>() - 1.0;
        let Some((mut dy, dl)) = jacobian else { return Ok(()) };

        // ∂R_a/∂Ĝ_1: 2 Re(p̂ᴴ ∂p̂/∂Ĝ), ∂p̂/∂ĝ_c = −W_rj, ∂p̂/∂ĝ_s = i W_rj.
        for j in 0..q {
            let v: c64 = (0..m).map(|r| self.p1[r].conj() * self.w1[0][(r, j + 1)]).sum();
            self.ng[j] = -2.0 * v.re;
            self.ng[q + j] = -2.0 * v.im;
        }
        // ∂/∂û: I + H ∂G/∂u on R_u, cᵀ ∂G/∂u / ω_*² on R_η (∂(G(aû)/a)/∂û = ∂G/∂u), and R_a's.
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
                for bb in 0..d {
                    let col = c2 * q + off + bb;
                    let ecol = c2 * d + bb;
                    let ub = y[col];
                    for c in 0..nc {
                        for a in 0..d {
                            self.t[c * q + off + a] += je[(c * d + a, ecol)] * ub;
                        }
                    }
                    // R_η rows, harmonic 0 then k ≥ 1.
                    let c0 = &self.coupling[0].c[0];
                    dy[(base, col)] += (0..d).map(|a| c0[off + a].re * je[(a, ecol)]).sum::<f64>() / w2;
                    for k in 1..=nh {
                        let ck = &self.coupling[k].c[0];
                        let (ic, is) = (cos_index(k), sin_index(k));
                        let (mut vc, mut vs) = (0.0, 0.0);
                        for a in 0..d {
                            let (pc, ps) = times(ck[off + a], je[(ic * d + a, ecol)], je[(is * d + a, ecol)]);
                            vc += pc;
                            vs += ps;
                        }
                        dy[(base + ic, col)] += vc / w2;
                        dy[(base + is, col)] += vs / w2;
                    }
                    // R_a row.
                    let v: f64 = (0..d)
                        .map(|a| {
                            self.ng[off + a] * je[(c1 * d + a, ecol)] + self.ng[q + off + a] * je[(s1 * d + a, ecol)]
                        })
                        .sum();
                    dy[(row_a, col)] += v;
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
                                let (pc, ps) = times(h[(i, off + a)], je[(ic * d + a, ecol)], je[(is * d + a, ecol)]);
                                vc += pc;
                                vs += ps;
                            }
                            dy[(ic * q + i, col)] += vc;
                            dy[(is * q + i, col)] += vs;
                        }
                    }
                }
            }
        }
        // ∂/∂η̂ (free coefficients): −b on R_u, z/ω_*² on R_η; 2 η̂_c1 + 2 Re(p̂ᴴ(−W_r0)) on R_a.
        for c in 0..nc {
            let Some(col) = self.eta_column(c) else { continue };
            let k = c.div_ceil(2);
            let cp = &self.coupling[k];
            if k == 0 {
                for i in 0..q {
                    dy[(i, col)] = -cp.b[0][i].re;
                }
                dy[(base, col)] = cp.z[0].re / w2;
                continue;
            }
            let (ic, is) = (cos_index(k), sin_index(k));
            // The column of η̂_c (x_c = 1) or η̂_s (x_s = 1).
            let (xc, xs) = if c == ic { (1.0, 0.0) } else { (0.0, 1.0) };
            for i in 0..q {
                let (vc, vs) = times(cp.b[0][i], xc, xs);
                dy[(ic * q + i, col)] = -vc;
                dy[(is * q + i, col)] = -vs;
            }
            let (vc, vs) = times(cp.z[0] / w2, xc, xs);
            dy[(base + ic, col)] = vc;
            dy[(base + is, col)] = vs;
        }
        let pw0: c64 = (0..m).map(|r| self.p1[r].conj() * self.w1[0][(r, 0)]).sum();
        dy[(row_a, self.eta_column(c1).expect("c1 is an unknown"))] = 2.0 * e1 - 2.0 * pw0.re;
        // ∂/∂w = ω_* ∂/∂Ω and ∂/∂ξ̂ = ω_* ∂/∂ξ.
        let wt = self.omega_t;
        let dg = &self.joints.dg_domega;
        for k in 0..=nh {
            let (h, dh, dx) = (&self.h[k], &self.dh_domega[k], &self.dh_dxi[k]);
            let cp = &self.coupling[k];
            if k == 0 {
                for i in 0..q {
                    let v: f64 = (0..q).map(|j| h[(i, j)].re * dg[j]).sum();
                    dy[(i, iw)] += wt * v * inv_a;
                }
                dy[(base, iw)] += wt * (0..q).map(|i| cp.c[0][i].re * dg[i]).sum::<f64>() * inv_a / w2;
                continue;
            }
            let (ic, is) = (cos_index(k), sin_index(k));
            let (ec, es) = (self.eta(y, ic), self.eta(y, is));
            for i in 0..q {
                // R_u: −∂b η̂ + ∂H Ĝ + H ∂Ĝ/∂Ω.
                let (bwc, bws) = times(cp.b[1][i], ec, es);
                let (bxc, bxs) = times(cp.b[2][i], ec, es);
                let (mut wc, mut ws, mut xc, mut xs) = (-bwc, -bws, -bxc, -bxs);
                for j in 0..q {
                    let (gc, gs) = (g[ic * q + j] * inv_a, g[is * q + j] * inv_a);
                    let (dgc, dgs) = (dg[ic * q + j] * inv_a, dg[is * q + j] * inv_a);
                    let (a1, a2) = times(dh[(i, j)], gc, gs);
                    let (b1, b2) = times(h[(i, j)], dgc, dgs);
                    let (x1, x2) = times(dx[(i, j)], gc, gs);
                    wc += a1 + b1;
                    ws += a2 + b2;
                    xc += x1;
                    xs += x2;
                }
                dy[(ic * q + i, iw)] += wt * wc;
                dy[(is * q + i, iw)] += wt * ws;
                dy[(ic * q + i, iw + 1)] += wt * xc;
                dy[(is * q + i, iw + 1)] += wt * xs;
            }
            // R_η: ∂z η̂ + ∂cᵀ Ĝ + cᵀ ∂Ĝ/∂Ω, over ω_*².
            let (mut wc, mut ws) = times(cp.z[1], ec, es);
            let (mut xc, mut xs) = times(cp.z[2], ec, es);
            for i in 0..q {
                let (gc, gs) = (g[ic * q + i] * inv_a, g[is * q + i] * inv_a);
                let (dgc, dgs) = (dg[ic * q + i] * inv_a, dg[is * q + i] * inv_a);
                let (a1, a2) = times(cp.c[1][i], gc, gs);
                let (b1, b2) = times(cp.c[0][i], dgc, dgs);
                let (x1, x2) = times(cp.c[2][i], gc, gs);
                wc += a1 + b1;
                ws += a2 + b2;
                xc += x1;
                xs += x2;
            }
            dy[(base + ic, iw)] += wt * wc / w2;
            dy[(base + is, iw)] += wt * ws / w2;
            dy[(base + ic, iw + 1)] += wt * xc / w2;
            dy[(base + is, iw + 1)] += wt * xs / w2;
        }
        // R_a: 2 Re(p̂ᴴ (−∂W_r0 η̂_1 − ∂W_rG Ĝ_1)) + ∂R_a/∂Ĝ ∂Ĝ/∂Ω.
        let dp = |d: usize| -> f64 {
            let v: c64 = (0..m)
                .map(|r| {
                    let dpr = -self.w1[d][(r, 0)] * e1 - (0..q).map(|j| self.w1[d][(r, j + 1)] * g1[j]).sum::<c64>();
                    self.p1[r].conj() * dpr
                })
                .sum();
            2.0 * v.re
        };
        let cross = |v: &[f64], scale: f64| -> f64 {
            (0..q).map(|i| self.ng[i] * v[c1 * q + i] + self.ng[q + i] * v[s1 * q + i]).sum::<f64>() * scale
        };
        dy[(row_a, iw)] += wt * (dp(1) + cross(dg, inv_a));
        dy[(row_a, iw + 1)] += wt * dp(2);
        // ∂/∂λ = ln 10 [H t; cᵀ t / ω_*²; ∂R_a/∂Ĝ t].
        for k in 0..=nh {
            let (h, cp) = (&self.h[k], &self.coupling[k]);
            if k == 0 {
                for i in 0..q {
                    dl[i] = LN_10 * (0..q).map(|j| h[(i, j)].re * self.t[j]).sum::<f64>();
                }
                dl[base] = LN_10 * (0..q).map(|i| cp.c[0][i].re * self.t[i]).sum::<f64>() / w2;
                continue;
            }
            let (ic, is) = (cos_index(k), sin_index(k));
            for i in 0..q {
                let (mut vc, mut vs) = (0.0, 0.0);
                for j in 0..q {
                    let (a1, a2) = times(h[(i, j)], self.t[ic * q + j], self.t[is * q + j]);
                    vc += a1;
                    vs += a2;
                }
                dl[ic * q + i] = LN_10 * vc;
                dl[is * q + i] = LN_10 * vs;
            }
            let (mut vc, mut vs) = (0.0, 0.0);
            for i in 0..q {
                let (a1, a2) = times(cp.c[0][i], self.t[ic * q + i], self.t[is * q + i]);
                vc += a1;
                vs += a2;
            }
            dl[base + ic] = LN_10 * vc / w2;
            dl[base + is] = LN_10 * vs / w2;
        }
        dl[row_a] = LN_10 * cross(&self.t, 1.0);
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
    let (w0, xi0) = problem.linear_limit();
    let z0 = xi0 / (2.0 * w0);
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
        shapes: problem.shapes.clone(),
    })
}

/// The linear mode at the ends of the amplitude range (a model without joints): the linear
/// limit of the balance ([`NonlinearMode::linear_limit`], which a damping matrix moves off the
/// undamped mode), its motion recovered at both amplitudes.
fn linear_backbone(
    model: &NonlinearModel,
    settings: &NonlinearModeSettings,
    amplitude_start: f64,
    amplitude_end: f64,
    outputs: &[&[f64]],
) -> Result<Backbone, NonlinearModeError> {
    let mut problem = NonlinearMode::new(model, settings)?;
    let y = problem.linear_guess();
    let (omega, xi) = problem.linear_limit();
    let points = [amplitude_start, amplitude_end]
        .iter()
        .map(|a| problem.point(&y, a.log10(), outputs))
        .collect::<Result<Vec<_>, _>>()?;
    let r = settings.mode;
    Ok(Backbone {
        mode: r,
        linear_omega: omega,
        linear_damping_ratio: xi / (2.0 * omega),
        points,
        termination: TerminationReason::ReachedEnd,
        singular_points: Vec::new(),
        turned_back_at: None,
        notes: vec![format!(
            "the model has no joints: its nonlinear mode {} is the linear mode at every amplitude ({:.6} Hz, damping ratio {:.4e})",
            r + 1,
            omega / (2.0 * std::f64::consts::PI),
            xi / (2.0 * omega)
        )],
        branch: None,
        viscous: problem.c_t,
        shapes: problem.shapes.clone(),
    })
}
