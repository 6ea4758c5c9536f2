//! Neimark-Sacker bifurcations of forced responses: a complex pair of Floquet exponents crossing
//! the imaginary axis, found by [`floquet_bifurcations`] and checked against the monodromy
//! matrix of the variational equations integrated in time, and found on a branch that is
//! unstable already.
//!
//! Two identical Duffing oscillators (`ẍᵢ + α ẋᵢ + xᵢ + x³ᵢ` with a spring `kc` between them),
//! the first one driven: their in-phase (1 rad/s) and out-of-phase (`√(1 + 2kc)` rad/s) modes
//! are close, and where the hardening of the driven motion brings it near the out-of-phase
//! mode, the two exchange energy (a 1:1 internal resonance) and the periodic response loses
//! stability to an amplitude-modulated, quasi-periodic one over a band bounded by two
//! Neimark-Sacker bifurcations.
//!
//! A third oscillator, a Duffing with its own force and no coupling to the pair, makes the
//! second case: its exponents join the pair's unchanged, and its resonance, whose folds lie
//! below and above the pair's band, makes the continuation go through that band three times:
//! with the third oscillator on its resonant branch, back along its middle branch (a real
//! exponent positive: the whole system unstable), and forward along its lower branch. The
//! pair's Neimark-Sacker bifurcations must be found on all three passes at the same frequency,
//! the second time on a branch that is unstable on both sides, where the stable flag does not
//! change.
use faer::{c64, Mat};
use stickslip_core::continuation::{Options, Point, Silent, TerminationReason};
use stickslip_core::elements::{CubicSpring, Element};
use stickslip_core::hbm::bifurcation::is_stable;
use stickslip_core::hbm::fourier::{cos_index, sin_index};
use stickslip_core::hbm::{
    floquet_bifurcations, stability_at, sweep_frequency, Bifurcation, BifurcationKind, CondensedHbm, HbmSettings, Hill,
    HillSettings, Stability, UnstableCounts,
};
use stickslip_core::model::{Damping, DofLabel, ElementSite, LinearModel, Matrix, NonlinearModel};

const HARMONICS: usize = 7;
/// Mass-proportional damping (1/s): 0.5 % of critical at 1 rad/s.
const ALPHA: f64 = 0.01;
const KC: f64 = 0.1;
const K3: f64 = 1.0;
/// Force on the first oscillator of the pair (N).
const F: f64 = 0.01;
/// The third oscillator: stiffness (its linear mode at 0.89 rad/s) and force, its folds near
/// 0.95 and 1.33 rad/s, around the pair's bifurcations (1.14 and 1.16 rad/s).
const K_THIRD: f64 = 0.8;
const F_THIRD: f64 = 0.015;
const BAND: [f64; 2] = [0.5, 2.0];

/// Unit masses with stiffness `k`, a cubic spring to the ground on every DOF.
fn oscillators(k: Mat<f64>) -> NonlinearModel {
    let n = k.nrows();
    let linear = LinearModel::new(
        Matrix::Dense(Mat::identity(n, n)),
        Matrix::Dense(k),
        Damping::Rayleigh { alpha: ALPHA, beta: 0.0 },
        (0..n).map(|i| DofLabel::named(format!("x{i}"))).collect(),
        vec![],
    )
    .unwrap();
    let spring = |i: usize| {
        let law: Box<dyn Element> = Box::new(CubicSpring::new(K3).unwrap());
        ElementSite {
            name: format!("k3_{i}"),
            law,
            directions: vec![(0..n).map(|j| f64::from(u8::from(i == j))).collect()],
        }
    };
    NonlinearModel::new(linear, (0..n).map(spring).collect()).unwrap()
}

/// The stiffness of the pair, after `offset` uncoupled DOFs of stiffness `K_THIRD`.
fn stiffness(offset: usize) -> Mat<f64> {
    Mat::from_fn(offset + 2, offset + 2, |i, j| match (i, j) {
        (i, j) if i < offset || j < offset => {
            if i == j {
                K_THIRD
            } else {
                0.0
            }
        }
        (i, j) if i == j => 1.0 + KC,
        _ => -KC,
    })
}

struct Swept {
    points: Vec<Point>,
    stabilities: Vec<Stability>,
    found: Vec<Bifurcation>,
}

/// Sweep the band at force `F` with `forces` per DOF (relative to `F`), with every point's
/// stability and the Floquet bifurcations.
fn sweep(model: &NonlinearModel, forces: &[f64]) -> Swept {
    let settings = HbmSettings { harmonics: HARMONICS, samples: 64 };
    let mut hbm = CondensedHbm::new(model, forces, settings).unwrap();
    let branch = sweep_frequency(&mut hbm, F, BAND[0], BAND[1], &Options::default(), &mut Silent).unwrap();
    assert_eq!(branch.termination, TerminationReason::ReachedEnd);
    let hill = Hill::new(hbm.receptance(), HillSettings::for_band(HARMONICS, BAND[1])).unwrap();
    let stabilities: Vec<_> =
        branch.points.iter().map(|p| stability_at(&mut hbm, &hill, &p.x, p.lambda).unwrap()).collect();
    let found = floquet_bifurcations(&mut hbm, &hill, F, &branch.points, &stabilities, 1e-10);
    Swept { points: branch.points, stabilities, found }
}

/// The `n` displacements x(t) from the harmonics of the balance (the springs' directions are
/// the DOFs, coefficient-major).
fn displacements(x: &[f64], n: usize, omega: f64, t: f64) -> Vec<f64> {
    (0..n)
        .map(|d| {
            let mut u = x[d];
            for k in 1..=HARMONICS {
                let phase = k as f64 * omega * t;
                u += x[cos_index(k) * n + d] * phase.cos() + x[sin_index(k) * n + d] * phase.sin();
            }
            u
        })
        .collect()
}

/// Floquet multipliers of the pair alone from the monodromy matrix of its variational
/// equations `ÿ + α ẏ + (K + 3 k3 diag(x(t)²)) y = 0` about the solution `x`, integrated over
/// one period by classical Runge-Kutta (4 × 4 state `[y; ẏ]`).
fn monodromy_multipliers(x: &[f64], omega: f64) -> Vec<c64> {
    let k = stiffness(0);
    let period = 2.0 * std::f64::consts::PI / omega;
    let steps = 8_000;
    let h = period / steps as f64;
    let rhs = |t: f64, z: &[f64; 4]| -> [f64; 4] {
        let u = displacements(x, 2, omega, t);
        let mut dz = [z[2], z[3], 0.0, 0.0];
        for i in 0..2 {
            let spring = (0..2).map(|j| k[(i, j)] * z[j]).sum::<f64>() + 3.0 * K3 * u[i] * u[i] * z[i];
            dz[2 + i] = -ALPHA * z[2 + i] - spring;
        }
        dz
    };
    let mut monodromy = Mat::<f64>::zeros(4, 4);
    for column in 0..4 {
        let mut z = [0.0; 4];
        z[column] = 1.0;
        for step in 0..steps {
            let t = step as f64 * h;
            let add = |z: &[f64; 4], d: &[f64; 4], s: f64| -> [f64; 4] { std::array::from_fn(|i| z[i] + s * d[i]) };
            let k1 = rhs(t, &z);
            let k2 = rhs(t + h / 2.0, &add(&z, &k1, h / 2.0));
            let k3 = rhs(t + h / 2.0, &add(&z, &k2, h / 2.0));
            let k4 = rhs(t + h, &add(&z, &k3, h));
            z = std::array::from_fn(|i| z[i] + h / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]));
        }
        for row in 0..4 {
            monodromy[(row, column)] = z[row];
        }
    }
    monodromy.eigenvalues().unwrap()
}

/// The largest distance from a multiplier of `hill` to the nearest of `monodromy`.
fn mismatch(hill: &[c64], monodromy: &[c64]) -> f64 {
    hill.iter().map(|a| monodromy.iter().map(|b| (a - b).norm()).fold(f64::INFINITY, f64::min)).fold(0.0, f64::max)
}

#[test]
fn a_complex_pair_crosses_the_unit_circle_at_the_neimark_sacker_bifurcations_of_two_coupled_oscillators() {
    let model = oscillators(stiffness(0));
    let swept = sweep(&model, &[1.0, 0.0]);
    let Swept { points, stabilities, found } = &swept;
    // Into the quasi-periodic band and out of it.
    assert_eq!(found.len(), 2, "{found:?}");
    for b in found {
        assert_eq!(b.kind, BifurcationKind::NeimarkSacker);
        assert!(b.located);
        let s = b.exponent.unwrap();
        // Located to 1e-10 of a step (~0.02 rad/s), where the real part moves by ~1 1/s per
        // rad/s: the crossing exponent's real part is ~1e-12 at most (measured 1.5e-13 and
        // below), its imaginary part the modulation's frequency.
        assert!(s.re.abs() <= 1e-10 && s.im > 0.01, "{s}");
    }
    assert!(found[0].omega < found[1].omega);
    // Measured 1.140240 and 1.157695 rad/s (N = 7).
    assert!((1.13..1.15).contains(&found[0].omega) && (1.15..1.17).contains(&found[1].omega), "{found:?}");

    for b in found {
        let (i, j) = (b.after_point, b.after_point + 1);
        // Between two points the pair crosses: the multipliers of the monodromy matrix equal
        // Hill's on either side, and one side is unstable, the other not. Both linearise the
        // same motion (the balance's x(t)); Runge-Kutta's error at 8000 steps a period is
        // ~(hΩ)⁴ ~ 1e-13, Hill's truncation at N = 7 as small for this smooth motion: measured
        // 2e-13 at most.
        for p in [i, j] {
            let (point, stability) = (&points[p], &stabilities[p]);
            let hill_multipliers = stability.multipliers(point.lambda);
            let monodromy = monodromy_multipliers(&point.x, point.lambda);
            let error = mismatch(&hill_multipliers, &monodromy);
            assert!(error <= 1e-9, "multipliers at {} rad/s differ by {error:.1e}", point.lambda);
        }
        assert_ne!(is_stable(&stabilities[i], points[i].lambda), is_stable(&stabilities[j], points[j].lambda));
        // At the located point the monodromy matrix itself has a complex pair on the unit
        // circle, at the angle of Hill's exponent: e^{±i Im(s) T}.
        let monodromy = monodromy_multipliers(&b.x, b.omega);
        let period = 2.0 * std::f64::consts::PI / b.omega;
        let on_circle = (c64::new(0.0, b.exponent.unwrap().im * period)).exp();
        let nearest =
            monodromy.iter().min_by(|a, c| (*a - on_circle).norm().total_cmp(&(*c - on_circle).norm())).unwrap();
        // Measured 1.5e-13 and 4.4e-13 (|μ| − 1 as much).
        assert!((nearest - on_circle).norm() <= 1e-9, "{nearest} against {on_circle}");
        assert!(nearest.im.abs() > 1e-3, "a complex multiplier: {nearest}");
    }
}

#[test]
fn a_neimark_sacker_bifurcation_is_found_on_a_branch_that_is_unstable_already() {
    let pair = sweep(&oscillators(stiffness(0)), &[1.0, 0.0]);
    let whole = sweep(&oscillators(stiffness(1)), &[F_THIRD / F, 1.0, 0.0]);
    let Swept { points, stabilities, found } = &whole;
    let counts = |i: usize| UnstableCounts::of(&stabilities[i], points[i].lambda);
    // Three passes through the pair's band: up, back (the third oscillator on its middle
    // branch), up again; the second pass meets the bifurcations in the other order.
    let order = [0, 1, 1, 0, 0, 1];
    assert_eq!(found.len(), order.len(), "{found:?}");
    for (b, &which) in found.iter().zip(&order) {
        assert_eq!(b.kind, BifurcationKind::NeimarkSacker);
        assert!(b.located);
        // The same frequency as the pair alone: the third oscillator changes none of the pair's
        // exponents. Each is located to 1e-10 of its own steps (~0.02 rad/s, different in the
        // two sweeps), 2e-12 of Ω: measured 2e-14 apart at most.
        let alone = pair.found[which].omega;
        assert!((b.omega - alone).abs() <= 1e-10 * alone, "{} rad/s, the pair alone {alone}", b.omega);
    }
    for (n, b) in found.iter().enumerate() {
        let (before, after) = (counts(b.after_point), counts(b.after_point + 1));
        // One complex pair crosses and nothing else changes.
        assert_eq!(before.real, after.real);
        assert_eq!(before.complex_pairs.abs_diff(after.complex_pairs), 1);
        let stable = |i: usize| is_stable(&stabilities[i], points[i].lambda);
        if (2..4).contains(&n) {
            // On the middle branch of the third oscillator: a real exponent positive on both
            // sides, unstable before and after, the stable flag unchanged.
            assert_eq!(before.real, 1);
            assert!(!stable(b.after_point) && !stable(b.after_point + 1));
        } else {
            assert_eq!(before.real, 0);
        }
    }
}
