//! Models shared by the harmonic balance benchmarks: dense matrices, the Table 6 oscillator and
//! the paper-size chain with joints.
#![allow(dead_code)]

use faer::Mat;
use stickslip_core::elements::{Element, Jenkins};
use stickslip_core::model::{
    relative_direction, stiffness_along, Damping, DofLabel, ElementSite, LinearModel, Matrix, NonlinearModel,
};

const TWO_PI: f64 = 2.0 * std::f64::consts::PI;

pub fn dense(n: usize, f: impl Fn(usize, usize) -> f64) -> Matrix {
    Matrix::Dense(Mat::from_fn(n, n, f))
}

/// Table 6 1-DOF (/work/shared/reference/table6-jenkins.toml), paper form.
pub fn table6() -> NonlinearModel {
    let linear = LinearModel::new(
        dense(1, |_, _| 10.0),
        dense(1, |_, _| 2.24e7),
        Damping::Rayleigh { alpha: 35.0, beta: 0.0 },
        vec![DofLabel::named("M")],
        vec![],
    )
    .unwrap();
    let law: Box<dyn Element> = Box::new(Jenkins::replacing_stiffness(8.11e6, 1000.0).unwrap());
    NonlinearModel::new(linear, vec![ElementSite { name: "joint".into(), law, directions: vec![vec![1.0]] }]).unwrap()
}

/// A chain of `n` masses (0.5 kg, 68 kg in all for n = 137, about Harmony's) grounded at DOF 0,
/// its stiffness scaled so that the first mode is at 238 Hz (Harmony's first vertical mode),
/// damping D = αM with 1 % at that mode, and `q` Jenkins joints in the paper's form, each on the
/// normalised relative motion of a pair of neighbours (Eqs. 7-8) and replacing 40 % of that
/// spring, threshold 290 N (the paper's updated F_Coulomb).
pub fn chain_with_joints(n: usize, q: usize, grounded: bool) -> NonlinearModel {
    let kc = 1.0e8;
    let k = |i: usize, j: usize| {
        if i == j {
            // Springs to the ground at every DOF keep long chains well conditioned.
            let ground = if grounded { kc } else { 0.0 };
            ground + if i + 1 < n { 2.0 * kc } else { kc }
        } else if i.abs_diff(j) == 1 {
            -kc
        } else {
            0.0
        }
    };
    let probe = LinearModel::new(
        dense(n, |i, j| if i == j { 0.5 } else { 0.0 }),
        dense(n, k),
        Damping::None,
        labels(n),
        vec![],
    )
    .unwrap();
    let w1 = probe.dense_modes().unwrap().omega[0];
    let scale = (TWO_PI * 238.0 / w1).powi(2);
    let alpha = 2.0 * 0.01 * TWO_PI * 238.0;
    let linear = LinearModel::new(
        dense(n, |i, j| if i == j { 0.5 } else { 0.0 }),
        dense(n, |i, j| scale * k(i, j)),
        Damping::Rayleigh { alpha, beta: 0.0 },
        labels(n),
        vec![],
    )
    .unwrap();
    let sites = (0..q)
        .map(|e| {
            let i = (e + 1) * (n - 1) / (q + 1);
            let mut v = relative_direction(n, i, Some(i + 1));
            v.iter_mut().for_each(|x| *x /= std::f64::consts::SQRT_2);
            // 40 % of the spring between i and i+1: k_J = 0.4 Vᵀ K_spring V with V normalised.
            let kj = 0.4 * stiffness_along(&linear, &v).min(2.0 * scale * kc);
            let law: Box<dyn Element> = Box::new(Jenkins::replacing_stiffness(kj, 290.0).unwrap());
            ElementSite { name: format!("joint{e}"), law, directions: vec![v] }
        })
        .collect();
    NonlinearModel::new(linear, sites).unwrap()
}

pub fn labels(n: usize) -> Vec<DofLabel> {
    (0..n).map(|i| DofLabel::named(format!("x{i}"))).collect()
}

/// A square patch of `side × side` nodes pressed on a rigid ground, each node a 3-D contact
/// (two tangential directions, then the normal): a plate of 3 DOFs per node (0.5 kg each),
/// neighbours tied by springs of 2e7 N/m per direction, softly supported (1e5 N/m per DOF), with
/// contacts of k_t = 2.5e6 N/m, k_n = 5e6 N/m, μ = 0.5 and a preload that falls from 400 N at
/// the centre to 40 N at the corners, as under a bolt. The patch slides on its stuck contacts
/// at about 360 Hz. Forced tangentially at a corner node (its first DOF): at a moderate level
/// the centre sticks while the edges slip and lift off, as in a real joint.
pub fn contact_patch(side: usize) -> (NonlinearModel, Vec<f64>) {
    use stickslip_core::elements::Contact;
    let nodes = side * side;
    let n = 3 * nodes;
    let (kc, ks) = (2.0e7, 1.0e5);
    let mut k = Mat::<f64>::zeros(n, n);
    for node in 0..nodes {
        let (x, y) = (node % side, node / side);
        for dof in 0..3 {
            k[(3 * node + dof, 3 * node + dof)] += ks;
        }
        let mut tie = |other: usize| {
            for dof in 0..3 {
                let (a, b) = (3 * node + dof, 3 * other + dof);
                k[(a, a)] += kc;
                k[(b, b)] += kc;
                k[(a, b)] -= kc;
                k[(b, a)] -= kc;
            }
        };
        if x + 1 < side {
            tie(node + 1);
        }
        if y + 1 < side {
            tie(node + side);
        }
    }
    let alpha = 2.0 * 0.01 * TWO_PI * 300.0;
    let linear = LinearModel::new(
        dense(n, |i, j| if i == j { 0.5 } else { 0.0 }),
        Matrix::Dense(k),
        Damping::Rayleigh { alpha, beta: 0.0 },
        labels(n),
        vec![],
    )
    .unwrap();
    let centre = (side as f64 - 1.0) / 2.0;
    let sites = (0..nodes)
        .map(|node| {
            let (x, y) = ((node % side) as f64 - centre, (node / side) as f64 - centre);
            let r2 = (x * x + y * y) / (2.0 * centre * centre).max(1.0);
            let preload = 40.0 + 360.0 * (1.0 - r2);
            let law: Box<dyn Element> = Box::new(Contact::new_3d(2.5e6, 5e6, 0.5, preload).unwrap());
            let directions = (0..3).map(|a| relative_direction(n, 3 * node + a, None)).collect();
            ElementSite { name: format!("contact{node}"), law, directions }
        })
        .collect();
    let mut force = vec![0.0; n];
    force[0] = 1.0;
    (NonlinearModel::new(linear, sites).unwrap(), force)
}
