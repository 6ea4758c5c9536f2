#[path = "../benches/common/mod.rs"]
#[allow(dead_code)]
mod common;
use common::chain_with_joints;
use faer::linalg::solvers::Solve;
use faer::Mat;
use std::time::Instant;
use stickslip_core::elements::{Contact, Element};
use stickslip_core::hbm::fourier::{cos_index, sin_index};
use stickslip_core::hbm::{CondensedHbm, HbmSettings, Jacobians};
use stickslip_core::model::{relative_direction, ElementSite, NonlinearModel};
const TWO_PI: f64 = 2.0 * std::f64::consts::PI;

fn harmonic_of(c: usize) -> usize {
    (c + 1) / 2
}

fn gmres(a: &dyn Fn(&[f64]) -> Vec<f64>, m: &dyn Fn(&[f64]) -> Vec<f64>, b: &[f64], tol: f64, max: usize) -> usize {
    // right-preconditioned full GMRES, returns iterations
    let n = b.len();
    let nb = b.iter().map(|v| v * v).sum::<f64>().sqrt();
    let mut v: Vec<Vec<f64>> = vec![b.iter().map(|x| x / nb).collect()];
    let mut h = vec![vec![0.0; max + 1]; max];
    let (mut cs, mut sn) = (vec![0.0; max], vec![0.0; max]);
    let mut g = vec![0.0; max + 1];
    g[0] = nb;
    for j in 0..max {
        let mut w = a(&m(&v[j]));
        for i in 0..=j {
            let d: f64 = w.iter().zip(&v[i]).map(|(p, q)| p * q).sum();
            h[j][i] = d;
            for k in 0..n {
                w[k] -= d * v[i][k];
            }
        }
        let nw = w.iter().map(|v| v * v).sum::<f64>().sqrt();
        h[j][j + 1] = nw;
        for i in 0..j {
            let t = cs[i] * h[j][i] + sn[i] * h[j][i + 1];
            h[j][i + 1] = -sn[i] * h[j][i] + cs[i] * h[j][i + 1];
            h[j][i] = t;
        }
        let r = (h[j][j].powi(2) + h[j][j + 1].powi(2)).sqrt();
        cs[j] = h[j][j] / r;
        sn[j] = h[j][j + 1] / r;
        h[j][j] = r;
        h[j][j + 1] = 0.0;
        g[j + 1] = -sn[j] * g[j];
        g[j] = cs[j] * g[j];
        if g[j + 1].abs() <= tol * nb {
            return j + 1;
        }
        v.push(w.iter().map(|x| x / nw).collect());
    }
    max
}

fn main() {
    let c: usize = std::env::args().nth(1).map(|s| s.parse().unwrap()).unwrap_or(32);
    let level: f64 = std::env::args().nth(2).map(|s| s.parse().unwrap()).unwrap_or(3000.0);
    let harmonics = 7;
    let n = 3 * c + 10;
    let linear = chain_with_joints(n, 0, true).linear;
    let sites = (0..c)
        .map(|e| {
            let i = 3 * e + 5;
            let law: Box<dyn Element> = Box::new(Contact::new_3d(2e7, 4e7, 0.5, 200.0).unwrap());
            let directions = (0..3).map(|a| relative_direction(n, i + a, Some(i + a + 1))).collect();
            ElementSite { name: format!("contact{e}"), law, directions }
        })
        .collect();
    let model = NonlinearModel::new(linear, sites).unwrap();
    let mut force = vec![0.0; n];
    force[n - 1] = 1.0;
    let mut hbm = CondensedHbm::new(&model, &force, HbmSettings { harmonics, samples: 300 }).unwrap();
    let dim = hbm.dimension();
    let q = hbm.n_directions();
    let omega = TWO_PI * 230.0;
    let x = hbm.linear_solution(omega, level);
    let mut r = vec![0.0; dim];
    let mut jac = Mat::zeros(dim, dim);
    hbm.evaluate(&x, omega, level, &mut r, Some(Jacobians { dx: jac.as_mut(), domega: None, dlevel: None })).unwrap();
    let b = hbm.element_force_jacobian(&x, omega).unwrap();
    // H B = J - I ; P = I + H Bbar ; H Bbar = (J - I) restricted... compute H from J: not possible; compute HBbar via J - H(B - Bbar)
    // Simplest: H = (J - I) B^+ not possible. Build Bbar, D = B - Bbar, and note H Bbar = (J-I) - H D; need H: get it from receptance.
    let rec = hbm.receptance();
    let mut hfull = Mat::<f64>::zeros(dim, dim);
    let mut hr = stickslip_core::hbm::receptance::HarmonicReceptance::new(q);
    rec.evaluate(0.0, &mut hr);
    for i in 0..q {
        for j in 0..q {
            hfull[(i, j)] = hr.h[(i, j)].re;
        }
    }
    for k in 1..=harmonics {
        rec.evaluate(k as f64 * omega, &mut hr);
        let (ic, is) = (cos_index(k) * q, sin_index(k) * q);
        for i in 0..q {
            for j in 0..q {
                let h = hr.h[(i, j)];
                hfull[(ic + i, ic + j)] = h.re;
                hfull[(ic + i, is + j)] = h.im;
                hfull[(is + i, ic + j)] = -h.im;
                hfull[(is + i, is + j)] = h.re;
            }
        }
    }
    let check = &hfull * &b - (&jac - Mat::<f64>::identity(dim, dim));
    println!("dim {dim}: |HB - (J-I)| = {:.2e}, |J| = {:.2e}", check.norm_max(), jac.norm_max());
    let mut bbar = b.clone();
    for i in 0..dim {
        for j in 0..dim {
            if harmonic_of(i / q) != harmonic_of(j / q) {
                bbar[(i, j)] = 0.0;
            }
        }
    }
    let p = Mat::<f64>::identity(dim, dim) + &hfull * &bbar;
    let plu = p.partial_piv_lu();
    let t = Instant::now();
    let jlu = jac.partial_piv_lu();
    println!("dense LU {:.3} s", t.elapsed().as_secs_f64());
    let av = |v: &[f64]| {
        let m = &jac * Mat::from_fn(dim, 1, |i, _| v[i]);
        (0..dim).map(|i| m[(i, 0)]).collect::<Vec<_>>()
    };
    let pinv = |v: &[f64]| {
        let m = plu.solve(Mat::from_fn(dim, 1, |i, _| v[i]));
        (0..dim).map(|i| m[(i, 0)]).collect::<Vec<_>>()
    };
    let ident = |v: &[f64]| v.to_vec();
    println!("GMRES unpreconditioned: {} its", gmres(&av, &ident, &r, 1e-10, 400));
    println!("GMRES harmonic-block precond: {} its", gmres(&av, &pinv, &r, 1e-10, 400));
    // stale LU from a neighbouring point (Omega + 0.5%, level*1.02)
    let omega2 = omega * 1.005;
    let x2 = hbm.linear_solution(omega2, level * 1.02);
    let mut jac2 = Mat::zeros(dim, dim);
    hbm.evaluate(
        &x2,
        omega2,
        level * 1.02,
        &mut r.clone(),
        Some(Jacobians { dx: jac2.as_mut(), domega: None, dlevel: None }),
    )
    .unwrap();
    let lu2 = jac2.partial_piv_lu();
    let stale = |v: &[f64]| {
        let m = lu2.solve(Mat::from_fn(dim, 1, |i, _| v[i]));
        (0..dim).map(|i| m[(i, 0)]).collect::<Vec<_>>()
    };
    println!("GMRES stale-LU precond: {} its", gmres(&av, &stale, &r, 1e-10, 400));
    let _ = jlu;
    // how many contacts are in each state
}
