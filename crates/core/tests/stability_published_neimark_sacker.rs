//! A published Neimark-Sacker case: the forced two-DOF oscillator with cubic springs of Krack &
//! Gross, *Harmonic Balance for Nonlinear Vibration Problems* (Springer 2019), distributed with
//! the book as NLvib's example `twoDOFoscillator_cubicSpring` (NLvib 1.3, Krack & Gross, GPL),
//! whose description says that "besides the well-known occurrence of turning points in the
//! amplitude-frequency curve, the system exhibits Neimark-Sacker bifurcations".
//!
//! A primary oscillator (mass 1, spring 1 and damper 0.002 to the ground, cubic spring 1) carries
//! a light attachment (mass 0.05, spring 0.0453 and damper 0.013, cubic spring 0.0042 between
//! the two), driven by 0.11 cos Ωt on the primary mass over 0.8-1.4 rad/s, N = 7. The dampers
//! sit on the springs, not in proportion to them: a general damping matrix, which Hill's method
//! takes in modal coordinates (`Φᵀ D Φ`, full).
//!
//! The example locates its bifurcations by shooting: the monodromy matrix of each point of a
//! continuation, a bifurcation placed halfway between the two points where the leading
//! multiplier leaves the unit circle. The reference values below are that method's result made
//! exact (`bench/peer/nlvib_neimark_sacker.py`: shooting with the monodromy matrix from the
//! variational equations integrated to 1e-12, and the crossing located by bisection in Ω), and
//! NLvib's own run of the example (GNU Octave, the published script unchanged but for its
//! plots and the form of its solver options) is quoted beside them.
use faer::Mat;
use stickslip_core::continuation::{Accepted, Options, PointObserver, Problem, TerminationReason, TestFunctions};
use stickslip_core::elements::{CubicSpring, Element};
use stickslip_core::hbm::bifurcation::is_stable;
use stickslip_core::hbm::{
    floquet_bifurcations, folds_and_branch_points, stability_at, sweep_frequency, BifurcationKind, CondensedHbm,
    FrequencySweep, HbmSettings, Hill, HillSettings,
};
use stickslip_core::model::{Damping, DofLabel, ElementSite, LinearModel, Matrix, NonlinearModel};

const HARMONICS: usize = 7;
const FORCE: f64 = 0.11;
const BAND: [f64; 2] = [0.8, 1.4];

/// The chain of NLvib's `ChainOfOscillators(mi, di, ki)`: masses `mi`, springs and dampers
/// `ki`, `di` from the ground to the first mass and between the two (none from the second to
/// the ground).
fn model() -> NonlinearModel {
    let (k1, k2) = (1.0, 0.0453);
    let (d1, d2) = (0.002, 0.013);
    let chain = |a: f64, b: f64| Mat::from_fn(2, 2, |i, j| [[a + b, -b], [-b, b]][i][j]);
    let linear = LinearModel::new(
        Matrix::Dense(Mat::from_fn(2, 2, |i, j| [[1.0, 0.0], [0.0, 0.05]][i][j])),
        Matrix::Dense(chain(k1, k2)),
        Damping::Matrix(Matrix::Dense(chain(d1, d2))),
        vec![DofLabel::named("x1"), DofLabel::named("x2")],
        vec![],
    )
    .unwrap();
    let cubic = |name: &str, k3: f64, direction: Vec<f64>| {
        let law: Box<dyn Element> = Box::new(CubicSpring::new(k3).unwrap());
        ElementSite { name: name.into(), law, directions: vec![direction] }
    };
    let elements = vec![cubic("ground", 1.0, vec![1.0, 0.0]), cubic("between", 0.0042, vec![1.0, -1.0])];
    NonlinearModel::new(linear, elements).unwrap()
}

/// Keeps the test functions of every accepted point (the folds).
#[derive(Default)]
struct Tests(Vec<Option<TestFunctions>>);

impl<P: Problem + ?Sized> PointObserver<P> for Tests {
    fn on_accepted(&mut self, accepted: &mut Accepted<'_, P>) {
        self.0.push(accepted.test_functions().unwrap().cloned());
    }
}

/// NLvib's shooting continuation, run as published (GNU Octave 7.3; only its plots left out and
/// `optimset` given its options directly, which Octave's does not take from `@fsolve`): each
/// bifurcation lies between two of its points, Ω (rad/s) before and after, and the example
/// reports it at their midpoint.
const NLVIB_NEIMARK_SACKER: [[f64; 2]; 2] = [[1.107774, 1.116695], [1.189617, 1.196836]];
const NLVIB_FOLDS: [[f64; 2]; 2] = [[1.214009, 1.214545], [1.207039, 1.206160]];
/// The same crossings located to round-off by shooting (`bench/peer/nlvib_neimark_sacker.py`):
/// Ω (rad/s) and the angle of the complex multiplier on the unit circle (rad).
const SHOOTING: [(f64, f64); 2] = [(1.112_711_239, 0.560_218), (1.195_736_669, 0.476_273)];

#[test]
fn the_neimark_sacker_bifurcations_of_krack_and_gross_two_dof_example_are_found_where_shooting_finds_them() {
    let model = model();
    // 4N + 1 samples: the AFT of a cubic law is then exact (as in the example).
    let settings = HbmSettings { harmonics: HARMONICS, samples: 4 * HARMONICS + 1 };
    let mut hbm = CondensedHbm::new(&model, &[1.0, 0.0], settings).unwrap();
    let mut tests = Tests::default();
    let branch = sweep_frequency(&mut hbm, FORCE, BAND[0], BAND[1], &Options::default(), &mut tests).unwrap();
    assert_eq!(branch.termination, TerminationReason::ReachedEnd);
    let points = &branch.points;
    let hill = Hill::new(hbm.receptance(), HillSettings::for_band(HARMONICS, BAND[1])).unwrap();
    assert_eq!(hill.n_modes(), 2, "every mode kept: Hill's method exact in modal coordinates");
    let stabilities: Vec<_> = points.iter().map(|p| stability_at(&mut hbm, &hill, &p.x, p.lambda).unwrap()).collect();
    let found = floquet_bifurcations(&mut hbm, &hill, FORCE, points, &stabilities, 1e-10);
    let stable = |i: usize| is_stable(&stabilities[i], points[i].lambda);

    // Into the quasi-periodic band and out of it, before the resonance's folds.
    assert_eq!(found.len(), 2, "{found:?}");
    for ((b, [before, after]), (omega, angle)) in found.iter().zip(NLVIB_NEIMARK_SACKER).zip(SHOOTING) {
        assert_eq!(b.kind, BifurcationKind::NeimarkSacker);
        assert!(b.located);
        // The measure: within 1 % of the published example's value, its midpoint
        // (measured 0.04 % and 0.21 %, the half-widths of its brackets 0.4 % and 0.3 %), and
        // inside its bracket.
        let midpoint = 0.5 * (before + after);
        assert!((b.omega - midpoint).abs() <= 0.01 * midpoint, "{} rad/s against NLvib's {midpoint}", b.omega);
        assert!(b.omega > before.min(after) && b.omega < before.max(after), "{} rad/s", b.omega);
        // Against shooting to round-off: the harmonic balance at N = 7 with an exact AFT, and
        // Hill's method with every mode kept, differ from the exact periodic motion by the
        // truncated harmonics only: measured 7e-11 and 1.0e-10 of Ω (shooting's value is given
        // to 1e-9 rad/s); asserted 1e-8 of Ω.
        assert!((b.omega - omega).abs() <= 1e-8 * omega, "{} rad/s against shooting's {omega}", b.omega);
        // The crossing pair's angle on the unit circle, Im(s) T, is shooting's multiplier's
        // (given to 6 decimals; measured 4.2e-7 rad apart).
        let s = b.exponent.unwrap();
        assert!(s.re.abs() <= 1e-10 * b.omega, "{s}");
        let on_circle = s.im * 2.0 * std::f64::consts::PI / b.omega;
        assert!((on_circle - angle).abs() <= 1e-6, "{on_circle} rad against shooting's {angle}");
    }
    assert!(stable(found[0].after_point) && !stable(found[0].after_point + 1));
    assert!(!stable(found[1].after_point) && stable(found[1].after_point + 1));

    // The resonance's two folds, from the tangent, at NLvib's: within 0.1 % of its midpoints
    // (measured 0.03 % both). Its shooting integrates by Newmark's average acceleration at 256
    // steps a period, a relative error of ~(hΩ)²/12 ~ 5e-5 in the motion's frequency, which
    // moves a fold, where the branch turns, by as much: the second fold lies a little inside
    // NLvib's bracket rather than beyond it.
    let folds = folds_and_branch_points(&mut FrequencySweep { hbm: &mut hbm, level: FORCE }, points, &tests.0, 1e-10);
    assert_eq!(folds.len(), 2, "{folds:?}");
    for (fold, [before, after]) in folds.iter().zip(NLVIB_FOLDS) {
        assert_eq!(fold.kind, BifurcationKind::Fold);
        assert!(fold.located);
        let midpoint = 0.5 * (before + after);
        assert!((fold.omega - midpoint).abs() <= 1e-3 * midpoint, "fold at {} rad/s, NLvib's {midpoint}", fold.omega);
    }
}

/// The example's masses and springs with proportional damping `α M + β K`, as Rayleigh
/// coefficients or as the same matrix.
fn proportional(as_matrix: bool) -> NonlinearModel {
    let (alpha, beta) = (0.004, 0.01);
    let mass = Mat::from_fn(2, 2, |i, j| [[1.0, 0.0], [0.0, 0.05]][i][j]);
    let stiffness = Mat::from_fn(2, 2, |i, j| [[1.0453, -0.0453], [-0.0453, 0.0453]][i][j]);
    let damping = if as_matrix {
        Damping::Matrix(Matrix::Dense(Mat::from_fn(2, 2, |i, j| alpha * mass[(i, j)] + beta * stiffness[(i, j)])))
    } else {
        Damping::Rayleigh { alpha, beta }
    };
    let linear = LinearModel::new(
        Matrix::Dense(mass),
        Matrix::Dense(stiffness),
        damping,
        vec![DofLabel::named("x1"), DofLabel::named("x2")],
        vec![],
    )
    .unwrap();
    let law: Box<dyn Element> = Box::new(CubicSpring::new(1.0).unwrap());
    NonlinearModel::new(linear, vec![ElementSite { name: "ground".into(), law, directions: vec![vec![1.0, 0.0]] }])
        .unwrap()
}

#[test]
fn hill_with_a_damping_matrix_equals_hill_with_the_same_damping_given_as_rayleigh_coefficients() {
    // Proportional damping two ways: diagonal modal coefficients, or the matrix projected on
    // the modes (Φᵀ D Φ, diagonal to round-off). Same motion, same Jacobian of the joints.
    let (rayleigh, matrix) = (proportional(false), proportional(true));
    let settings = HbmSettings { harmonics: HARMONICS, samples: 4 * HARMONICS + 1 };
    let mut hbm = CondensedHbm::new(&rayleigh, &[1.0, 0.0], settings).unwrap();
    let by_matrix = CondensedHbm::new(&matrix, &[1.0, 0.0], settings).unwrap();
    let branch =
        sweep_frequency(&mut hbm, FORCE, BAND[0], BAND[1], &Options::default(), &mut Tests::default()).unwrap();
    let hill = HillSettings::for_band(HARMONICS, BAND[1]);
    let (modal, general) =
        (Hill::new(hbm.receptance(), hill).unwrap(), Hill::new(by_matrix.receptance(), hill).unwrap());
    let mut largest = 0.0_f64;
    for p in &branch.points {
        let a = stability_at(&mut hbm, &modal, &p.x, p.lambda).unwrap().exponents;
        let b = stability_at(&mut hbm, &general, &p.x, p.lambda).unwrap().exponents;
        assert_eq!(a.len(), b.len());
        for (a, b) in a.iter().zip(&b) {
            largest = largest.max((a - b).norm() / p.lambda);
        }
    }
    // Both eigenproblems are the same to the round-off of Φᵀ D Φ (~1e-16 of D): measured
    // 8.8e-15 of Ω at most; asserted 1e-10 of Ω.
    assert!(largest <= 1e-10, "exponents differ by {largest:.1e} of Ω");
}
