//! A time step allocates nothing (dense and sparse paths, with elements): counted by the
//! allocations of the stepping thread (`allocation_counter`), so that another thread of the
//! process (the test harness, a pool starting up) cannot make the count.
mod allocation_counter;
use allocation_counter::allocations;

use faer::sparse::{SparseColMat, Triplet};
use faer::Mat;
use stickslip_core::elements::Jenkins;
use stickslip_core::model::{relative_direction, Damping, DofLabel, ElementSite, LinearModel, Matrix, NonlinearModel};
use stickslip_core::timesim::{Integrator, Scheme};

/// A chain of `n` unit masses with two Jenkins joints, dense or sparse.
fn model(n: usize, sparse: bool) -> NonlinearModel {
    let k = 1.0e6;
    let entries: Vec<(usize, usize, f64)> = (0..n)
        .flat_map(|i| {
            let mut v = vec![(i, i, if i + 1 < n { 2.0 * k } else { k })];
            if i + 1 < n {
                v.push((i, i + 1, -k));
                v.push((i + 1, i, -k));
            }
            v
        })
        .collect();
    let build = |diag_only: bool, scale: f64| -> Matrix {
        let e: Vec<_> = entries.iter().filter(|(i, j, _)| !diag_only || i == j).collect();
        if sparse {
            let t: Vec<_> = e.iter().map(|&&(i, j, v)| Triplet::new(i, j, if diag_only { scale } else { v })).collect();
            Matrix::Sparse(SparseColMat::try_new_from_triplets(n, n, &t).unwrap())
        } else {
            let mut m = Mat::zeros(n, n);
            for &&(i, j, v) in &e {
                m[(i, j)] = if diag_only { scale } else { v };
            }
            Matrix::Dense(m)
        }
    };
    let linear = LinearModel::new(
        build(true, 1.0),
        build(false, 0.0),
        Damping::Rayleigh { alpha: 5.0, beta: 1e-6 },
        (0..n).map(|i| DofLabel::named(format!("x{i}"))).collect(),
        vec![],
    )
    .unwrap();
    let sites = [(0, None), (n / 2, Some(n / 2 - 1))]
        .iter()
        .map(|&(i, j)| ElementSite {
            name: format!("j{i}"),
            law: Box::new(Jenkins::replacing_stiffness(k, 5.0).unwrap()),
            directions: vec![relative_direction(n, i, j)],
        })
        .collect();
    NonlinearModel::new(linear, sites).unwrap()
}

#[test]
fn steps_do_not_allocate() {
    for (n, sparse, scheme) in [
        (20, false, Scheme::AverageAcceleration),
        (20, false, Scheme::Hht { alpha: -0.1 }),
        (500, true, Scheme::Hht { alpha: -0.1 }),
    ] {
        let m = model(n, sparse);
        let mut load = vec![0.0; n];
        load[n / 2] = 100.0;
        let h = 1e-4;
        let mut it = Integrator::new(&m, scheme, h).unwrap();
        let at_start = allocations();
        let mut state = it.start(0.0, &vec![0.0; n], &vec![0.0; n], &load, 1.0).unwrap();
        let before = allocations();
        // The counter counts: building the state allocates its vectors.
        assert!(before > at_start);
        for k in 1..=200 {
            let e = (300.0 * k as f64 * h).cos();
            it.step(&mut state, &load, e, e).unwrap();
        }
        let count = allocations() - before;
        assert!(state.slipping.iter().any(|s| *s), "n = {n}: the joints must slip for the test to mean anything");
        assert_eq!(count, 0, "n = {n}, sparse = {sparse}: {count} allocations in 200 steps");
    }
}
