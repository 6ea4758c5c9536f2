//! Time-integrated steady states against the harmonic balance (N = 7): the two methods share
//! only the element laws, so agreement checks both.
mod timesim_common;

use faer::Mat;
use stickslip_core::elements::Jenkins;
use stickslip_core::hbm::{CondensedHbm, HbmSettings};
use stickslip_core::model::{relative_direction, Damping, DofLabel, ElementSite, LinearModel, Matrix, NonlinearModel};
use stickslip_core::timesim::{steady_state, SteadyState, SteadyStateOptions};
use timesim_common::*;

const TWO_PI: f64 = 2.0 * std::f64::consts::PI;
const N_HARMONICS: usize = 7;

/// Four Table 6 oscillators (10 kg; 2.24e7 N/m to the ground of which 8.11e6 N/m is a
/// Jenkins joint in the paper's form, thresholds 1000, 900, 800, 700 N; 350 N·s/m) coupled in
/// a line by 2e6 N/m springs, forced on the first (1000 N) and last (600 N) masses. Its four
/// modes lie between 238 and 262 Hz stuck, so the harmonics 3..7 of the friction forces fall
/// far above every mode, as in the paper's structure near its first mode.
///
/// (A chain whose joints are stiff links between light masses is a different matter: there the
/// element directions have local modes near 8Ω, the friction forces excite them, and the
/// N = 7 balance is not converged — measured on an 8-DOF chain, harmonic 1 of N = 7 differs
/// from the time solution by up to 100 %, N = 15 by 0.1 %, N = 31 by 1e-4, as in the paper's
/// 2-DOF model of Fig. 16.)
fn four_joint_model() -> (NonlinearModel, Vec<f64>) {
    let n = 4;
    let (k, kc) = (K_TOTAL, 2.0e6);
    let mass = Mat::from_fn(n, n, |i, j| if i == j { MASS } else { 0.0 });
    let stiff = Mat::from_fn(n, n, |i, j| {
        if i == j {
            k + kc * if i == 0 || i == n - 1 { 1.0 } else { 2.0 }
        } else if i.abs_diff(j) == 1 {
            -kc
        } else {
            0.0
        }
    });
    let damp = Mat::from_fn(n, n, |i, j| if i == j { DAMPING } else { 0.0 });
    let linear = LinearModel::new(
        Matrix::Dense(mass),
        Matrix::Dense(stiff),
        Damping::Matrix(Matrix::Dense(damp)),
        (0..n).map(|i| DofLabel::named(format!("x{i}"))).collect(),
        vec![],
    )
    .unwrap();
    let sites = [1000.0, 900.0, 800.0, 700.0]
        .iter()
        .enumerate()
        .map(|(e, &fc)| ElementSite {
            name: format!("joint{e}"),
            law: Box::new(Jenkins::replacing_stiffness(K_JENKINS, fc).unwrap()),
            directions: vec![relative_direction(n, e, None)],
        })
        .collect();
    (NonlinearModel::new(linear, sites).unwrap(), vec![1000.0, 0.0, 0.0, 600.0])
}

/// Coefficient-major harmonics `x[c·q + a]` of the element displacements of a steady state.
fn element_harmonics(s: &SteadyState, q: usize) -> Vec<f64> {
    let nc = 2 * N_HARMONICS + 1;
    let mut x = vec![0.0; nc * q];
    for a in 0..q {
        let c = SteadyState::harmonics(&s.records.elements.displacement[a], N_HARMONICS).unwrap();
        for (k, v) in c.iter().enumerate() {
            x[k * q + a] = *v;
        }
    }
    x
}

fn pair(x: &[f64], q: usize, k: usize, a: usize) -> (f64, f64) {
    (x[(2 * k - 1) * q + a], x[2 * k * q + a])
}

/// Energy dissipated per cycle by direction `a` from harmonics of u and g:
/// `∮ g du = π Σ_k k (g_ck s_k − g_sk c_k)`.
fn dissipation(x: &[f64], g: &[f64], q: usize, a: usize) -> f64 {
    (1..=N_HARMONICS)
        .map(|k| {
            let (c, s) = pair(x, q, k, a);
            let (gc, gs) = pair(g, q, k, a);
            std::f64::consts::PI * k as f64 * (gc * s - gs * c)
        })
        .sum()
}

/// Compare the time solution with the HBM solution at `f`: harmonic 1 within 0.5 %,
/// harmonics 3 and 5 within 2 % of harmonic 1's amplitude, element dissipation within 1 %.
fn compare(model: &NonlinearModel, load: &[f64], f: f64) {
    let q = model.n_directions();
    let mut o = SteadyStateOptions::new(f, load.to_vec());
    // 512 steps per period: the time discretisation error on harmonic 1 is < 1e-3 (measured
    // 6e-4 at worst on Table 6, second order), a fifth of the 0.5 % allowed.
    o.steps_per_period = 512;
    o.tolerance = 1e-9;
    let s = steady_state(model, &o).unwrap();
    let xt = element_harmonics(&s, q);
    // The HBM (the paper's N = 7 with 300 AFT samples) solved by Newton from the time
    // solution's harmonics: Newton converges to the balance's own solution, wherever it starts.
    let mut hbm = CondensedHbm::new(model, load, HbmSettings { harmonics: N_HARMONICS, samples: 300 }).unwrap();
    let (xh, _) = hbm.solve(TWO_PI * f, 1.0, &xt, 1e-10, 50).unwrap();
    let gh = hbm.element_force_harmonics().to_vec();
    for a in 0..q {
        let h1 = |x: &[f64]| pair(x, q, 1, a);
        let (ct, st) = h1(&xt);
        let (ch, sh) = h1(&xh);
        let a1 = ch.hypot(sh);
        let e1 = (ct - ch).hypot(st - sh) / a1;
        assert!(
            e1 < 5e-3,
            "{f} Hz, direction {a}: harmonic 1 differs by {e1:.3e} (time {ct:e},{st:e}; HBM {ch:e},{sh:e})"
        );
        for k in [3, 5] {
            let (ct, st) = pair(&xt, q, k, a);
            let (ch, sh) = pair(&xh, q, k, a);
            let ek = (ct - ch).hypot(st - sh) / a1;
            assert!(ek < 2e-2, "{f} Hz, direction {a}: harmonic {k} differs by {ek:.3e} of harmonic 1");
        }
        let w_hbm = dissipation(&xh, &gh, q, a);
        let w_time = s.energy.elements[a];
        let ew = (w_time - w_hbm).abs() / w_hbm.abs().max(1e-300);
        assert!(w_hbm > 0.0, "{f} Hz, direction {a}: the element must slip for this comparison");
        assert!(ew < 1e-2, "{f} Hz, direction {a}: dissipation time {w_time:e}, HBM {w_hbm:e}");
    }
}

#[test]
fn table6_time_solution_matches_hbm_n7() {
    let model = table6();
    for f in [200.0, 215.0, 230.0, 245.0, 260.0] {
        compare(&model, &[F_EXCIT], f);
    }
}

#[test]
fn four_joint_model_time_solution_matches_hbm_n7() {
    let (model, load) = four_joint_model();
    // Where all four joints slip over part of the cycle (21-45 % of it).
    for f in [234.0, 241.0, 248.0, 255.0, 262.0] {
        compare(&model, &load, f);
    }
}
