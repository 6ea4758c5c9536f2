//! Sparse shift-invert Lanczos against closed forms and the dense solver.
mod eigen_models;

use eigen_models::*;
use stickslip_core::model::{Damping, DofLabel, LinearModel, Matrix};
use stickslip_fe::eigen::{self, EigenError, EigenOptions, ShiftedFactor};

fn opts(count: usize) -> EigenOptions {
    EigenOptions { count, ..Default::default() }
}

#[test]
fn grounded_chain_matches_closed_form() {
    let (n, k, m) = (400, 2.0e5, 0.3);
    let (ks, ms) = chain(n, k, m, true);
    let sol = eigen::solve(&ks, &ms, &opts(12)).unwrap();
    let exact = chain_fixed_free_omega2(n, k, m);
    for (r, w) in sol.modes.omega.iter().enumerate() {
        // Closed form in exact arithmetic; the solver converges to ~1e-14 relative, the
        // closed form itself is evaluated to ~1e-15: 1e-10 leaves a wide margin.
        assert!((w * w / exact[r] - 1.0).abs() < 1e-10, "mode {r}: {} vs {}", w * w, exact[r]);
    }
    assert!(sol.residuals.iter().all(|r| *r < 1e-8), "{:?}", sol.residuals);
    assert_eq!(sol.below_shift, 0);
    // Mass-normalised: φᵀ M φ = 1 and M-orthogonal, to round-off.
    let phi = &sol.modes.shapes;
    let mphi = Matrix::Sparse(ms.clone()).to_dense() * phi;
    let g = phi.transpose() * &mphi;
    for i in 0..g.nrows() {
        for j in 0..g.ncols() {
            let e = if i == j { 1.0 } else { 0.0 };
            assert!((g[(i, j)] - e).abs() < 1e-10, "Φᵀ M Φ ({i},{j}) = {}", g[(i, j)]);
        }
    }
}

#[test]
fn laplacian_2d_with_consistent_mass_matches_closed_form() {
    let (k, m, exact) = laplacian_2d(30, 23);
    // The default block method, and the thick-restart fallback forced by a small subspace.
    let block = eigen::solve(&k, &m, &opts(20)).unwrap();
    let restarted =
        eigen::solve(&k, &m, &EigenOptions { count: 20, subspace: Some(30), ..Default::default() }).unwrap();
    assert!(restarted.restarts > 0);
    for sol in [block, restarted] {
        for (r, w) in sol.modes.omega.iter().enumerate() {
            // Separate eigenvalues of an exactly known discrete problem: 1e-10 relative.
            assert!((w * w / exact[r] - 1.0).abs() < 1e-10, "mode {r}: {} vs {}", w * w, exact[r]);
        }
    }
}

#[test]
fn free_free_chain_has_a_rigid_mode_at_zero() {
    let (n, k, m) = (200, 1.0e4, 0.5);
    let (ks, ms) = chain(n, k, m, false);
    let sol = eigen::solve(&ks, &ms, &opts(4)).unwrap();
    // The rigid-body mode: ω = 0 up to round-off of the eigenvalue (ω² ~ 1e-16 k/m).
    assert!(sol.modes.omega[0] < 1e-5 * (k / m).sqrt(), "{}", sol.modes.omega[0]);
    // Free-free chain: ω_r = 2 √(k/m) sin(rπ / (2n)).
    for r in 1..4 {
        let exact = 2.0 * (k / m).sqrt() * (r as f64 * std::f64::consts::PI / (2.0 * n as f64)).sin();
        assert!((sol.modes.omega[r] / exact - 1.0).abs() < 1e-10, "mode {r}");
    }
    // Its shape is uniform, mass-normalised: φ_i = 1/√(n m).
    let phi0 = sol.modes.shapes.col(0);
    for i in 0..n {
        assert!((phi0[i].abs() - 1.0 / (n as f64 * m).sqrt()).abs() < 1e-8);
    }
}

#[test]
fn matches_dense_solver_on_a_small_3d_lattice() {
    let (k, m) = lattice_3d(4, 3, 5, 5.0e5);
    let n = k.nrows();
    let dofs = (0..n).map(|i| DofLabel::nodal((i / 3) as u64 + 1, (i % 3) as u8 + 1)).collect();
    let model =
        LinearModel::new(Matrix::Sparse(m.clone()), Matrix::Sparse(k.clone()), Damping::None, dofs, vec![]).unwrap();
    let dense = model.dense_modes().unwrap();
    let sol = eigen::solve(&k, &m, &opts(25)).unwrap();
    for r in 0..25 {
        // Two independent double-precision solvers of a well-conditioned problem: 1e-10.
        let rel = (sol.modes.omega[r] / dense.omega[r] - 1.0).abs();
        assert!(rel < 1e-10, "mode {r}: {} vs {} ({rel:.1e})", sol.modes.omega[r], dense.omega[r]);
        // Same shapes up to sign: |φ_sparseᵀ M φ_dense| = 1.
        let md = Matrix::Sparse(m.clone());
        let a: Vec<f64> = (0..n).map(|i| sol.modes.shapes[(i, r)]).collect();
        let b: Vec<f64> = (0..n).map(|i| dense.shapes[(i, r)]).collect();
        assert!((md.bilinear(&a, &b).abs() - 1.0).abs() < 1e-8, "shape {r}");
    }
}

#[test]
fn interior_shift_finds_the_nearest_modes_and_counts_those_below() {
    let (n, k, m) = (300, 2.0e5, 0.3);
    let (ks, ms) = chain(n, k, m, true);
    let exact = chain_fixed_free_omega2(n, k, m);
    // Shift between modes 40 and 41 (0-based 39 and 40).
    let sigma = 0.5 * (exact[39] + exact[40]);
    let sol = eigen::solve(&ks, &ms, &EigenOptions { count: 6, shift: Some(sigma), ..Default::default() }).unwrap();
    // Sylvester's inertia: exactly 40 eigenvalues below σ.
    assert_eq!(sol.below_shift, 40);
    let got: Vec<f64> = sol.modes.omega.iter().map(|w| w * w).collect();
    for (g, e) in got.iter().zip(&exact[37..43]) {
        assert!((g / e - 1.0).abs() < 1e-10, "{g} vs {e}");
    }
}

#[test]
fn mechanism_at_zero_shift_is_a_clear_error() {
    let (ks, ms) = chain(50, 1.0e4, 0.5, false);
    let err = eigen::solve(&ks, &ms, &EigenOptions { count: 3, shift: Some(0.0), ..Default::default() }).unwrap_err();
    assert!(matches!(err, EigenError::Singular { .. }), "{err}");
    assert!(err.to_string().contains("mechanism"), "{err}");
    // A shift exactly on an eigenvalue is singular too.
    let (ks, ms) = chain(3, 1.0, 1.0, true);
    let exact = chain_fixed_free_omega2(3, 1.0, 1.0);
    assert!(matches!(ShiftedFactor::new(ks.as_ref(), Some(ms.as_ref()), exact[1]), Err(EigenError::Singular { .. })));
}

#[test]
fn too_many_modes_is_an_error() {
    let (ks, ms) = chain(5, 1.0, 1.0, true);
    assert!(matches!(eigen::solve(&ks, &ms, &opts(6)), Err(EigenError::TooManyModes { .. })));
    // All of them is fine (the Krylov space is the whole space).
    let sol = eigen::solve(&ks, &ms, &opts(5)).unwrap();
    let exact = chain_fixed_free_omega2(5, 1.0, 1.0);
    for (w, e) in sol.modes.omega.iter().zip(&exact) {
        assert!((w * w / e - 1.0).abs() < 1e-10, "{} vs {e}", w * w);
    }
}

/// Many modes of a real mesh: 60 and 300 of the 627 DOFs of the example blade (hex20, clamped
/// root, tip spring), against the dense solution of the same matrices.
#[test]
fn many_modes_of_the_example_blade_equal_the_dense_solution() {
    use stickslip_fe::assembly::FeModel;
    use stickslip_fe::mesh::inp;
    let path = std::path::PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../examples/blade-joint/blade.inp");
    let fe = FeModel::assemble(inp::read(path).unwrap()).unwrap();
    let dense = fe.model.dense_modes().unwrap().omega;
    let (k, m) = (eigen::to_sparse(&fe.model.stiffness), eigen::to_sparse(&fe.model.mass));
    let (k, m) = (k.into_owned(), m.into_owned());
    assert_eq!(k.nrows(), 627);
    for count in [60, 300] {
        let sol = eigen::solve(&k, &m, &opts(count)).unwrap();
        // The block Lanczos converges each Ritz value to 1e-10 relative residual (eigenvalue
        // error ~1e-20); the dense solution is accurate to a few ε of the largest eigenvalue,
        // so ~1e-12 relative at the 60th mode and better below. 1e-9 leaves a margin.
        for (r, (w, e)) in sol.modes.omega.iter().zip(&dense).enumerate() {
            assert!((w / e - 1.0).abs() < 1e-9, "{count} modes, mode {}: {w} vs {e}", r + 1);
        }
        let worst = sol.residuals.iter().cloned().fold(0.0, f64::max);
        assert!(worst < 1e-8, "{count} modes: worst residual {worst:.2e}");
    }
}

/// 300 modes of a 25,830-DOF tet10 mesh (the clamped slab of `benches/reduction.rs`) against
/// CalculiX 2.20's 300 modes of the same deck (`reference/slab_30k_c3d10_300.freq`).
#[test]
fn three_hundred_modes_of_a_30k_dof_mesh_equal_calculix() {
    use stickslip_fe::assembly::FeModel;
    use stickslip_fe::element::SolidKind;
    use stickslip_fe::mesh::generate::box_mesh;
    use stickslip_fe::mesh::Material;
    let steel = Material { young: 2.1e11, poisson: 0.3, density: 7800.0 };
    let mut mesh = box_mesh([0.4, 0.2, 0.1], [20, 10, 5], SolidKind::Tet10, steel);
    for i in mesh.node_set("ZMIN").unwrap().to_vec() {
        for d in 1..=3 {
            mesh.fixed.push((i, d));
        }
    }
    let fe = FeModel::assemble(mesh).unwrap();
    let (k, m) = (eigen::to_sparse(&fe.model.stiffness), eigen::to_sparse(&fe.model.mass));
    let (k, m) = (k.into_owned(), m.into_owned());
    assert_eq!(k.nrows(), 25_830);
    let path = std::path::PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("reference/slab_30k_c3d10_300.freq");
    let calculix: Vec<f64> = std::fs::read_to_string(path)
        .unwrap()
        .lines()
        .filter(|l| !l.starts_with('#'))
        .map(|l| l.split_whitespace().nth(1).unwrap().parse().unwrap())
        .collect();
    assert_eq!(calculix.len(), 300);
    let sol = eigen::solve(&k, &m, &opts(300)).unwrap();
    let worst = sol.residuals.iter().cloned().fold(0.0, f64::max);
    assert!(worst < 1e-8, "worst residual {worst:.2e}");
    // CalculiX prints 7 significant digits (half a unit of the last: 7e-8 to 1e-6 relative).
    for (r, (f, c)) in sol.modes.frequencies_hz().iter().zip(&calculix).enumerate() {
        assert!((f / c - 1.0).abs() < 1e-6, "mode {}: {f} Hz vs CalculiX {c} Hz", r + 1);
    }
}

/// The modes of a stiffness changed by rank-one terms through `LowRankUpdate` (Woodbury on the
/// factor of the unchanged K) equal those of a factorisation of the changed stiffness; a
/// change that opens a mechanism at the shift is refused as singular.
#[test]
fn low_rank_update_equals_a_new_factorisation() {
    use faer::sparse::{SparseColMat, Triplet};
    let (n, k, m) = (300, 2.0e5, 0.3);
    let (ks, ms) = chain(n, k, m, true);
    let factor = ShiftedFactor::new(ks.as_ref(), Some(ms.as_ref()), 0.0).unwrap();
    // Spring i–(i+1) is k (e_i − e_{i+1})(e_i − e_{i+1})ᵀ = 2k d dᵀ with d unit: removing
    // k d dᵀ halves it; removing 2k d dᵀ cuts the chain.
    let direction = |i: usize| {
        let s = std::f64::consts::FRAC_1_SQRT_2;
        faer::Mat::<f64>::from_fn(n, 1, |r, _| {
            if r == i {
                s
            } else if r == i + 1 {
                -s
            } else {
                0.0
            }
        })
    };
    let changed = |i: usize, c: f64| {
        let t = [(i, i, 0.5 * c), (i + 1, i + 1, 0.5 * c), (i, i + 1, -0.5 * c), (i + 1, i, -0.5 * c)];
        let d = SparseColMat::try_new_from_triplets(n, n, &t.map(|(a, b, v)| Triplet::new(a, b, v))).unwrap();
        faer::sparse::ops::binary_op(ks.as_ref(), d.as_ref(), |a, b| {
            a.copied().unwrap_or(0.0) - b.copied().unwrap_or(0.0)
        })
        .unwrap()
    };
    let i = 40;
    let update = eigen::LowRankUpdate::new(&factor, direction(i), &[k]).unwrap();
    let k_half = changed(i, k);
    let by_update = eigen::modes_with_factor(&k_half, &ms, &update, &opts(10)).unwrap();
    let direct = eigen::solve(&k_half, &ms, &opts(10)).unwrap();
    for (a, b) in by_update.modes.omega.iter().zip(&direct.modes.omega) {
        // Both converge to 1e-10 Ritz residuals (eigenvalue errors ~1e-20); the update loses a
        // few digits in S = 1/k − dᵀ A⁻¹ d (here 1/k against 1/(2k) + the rest: none).
        assert!((a / b - 1.0).abs() < 1e-10, "{a} vs {b}");
    }
    assert!(by_update.residuals.iter().all(|r| *r < 1e-8), "{:?}", by_update.residuals);
    assert_eq!(by_update.below_shift, 0);
    // Cutting the grounded chain leaves its far part free: singular at σ = 0.
    assert!(matches!(eigen::LowRankUpdate::new(&factor, direction(i), &[2.0 * k]), Err(EigenError::Singular { .. })));
}

/// ω² of the dense solution of `(K, M)` (faer's dense symmetric eigensolver on
/// `L⁻¹ K L⁻ᵀ`, `M = L Lᵀ`), lowest first; rigid-body modes at ±round-off.
fn dense_lambda(k: &faer::sparse::SparseColMat<usize, f64>, m: &faer::sparse::SparseColMat<usize, f64>) -> Vec<f64> {
    use faer::linalg::triangular_solve::solve_lower_triangular_in_place;
    let n = k.nrows();
    let (kd, md) = (k.to_dense(), m.to_dense());
    let llt = md.llt(faer::Side::Lower).unwrap();
    let mut x = kd.clone();
    solve_lower_triangular_in_place(llt.L(), x.as_mut(), faer::Par::Seq);
    let mut a = x.transpose().to_owned();
    solve_lower_triangular_in_place(llt.L(), a.as_mut(), faer::Par::Seq);
    let a = faer::Mat::from_fn(n, n, |i, j| 0.5 * (a[(i, j)] + a[(j, i)]));
    let (mut lambda, _) = stickslip_core::model::symmetric_eigen(a.as_ref()).unwrap();
    lambda.sort_by(f64::total_cmp);
    lambda
}

/// The band's modes equal the dense eigenvalues in `[lower, upper]`: same count, ω within
/// 1e-9 relative (absolute against the first elastic mode for rigid-body modes), residuals
/// checked, M-orthonormal across the parts of a split band.
fn assert_band_equals_dense(
    k: &faer::sparse::SparseColMat<usize, f64>,
    m: &faer::sparse::SparseColMat<usize, f64>,
    dense: &[f64],
    (lower, upper): (f64, f64),
    per_shift: usize,
) -> usize {
    let sol = eigen::solve_band_split(k, m, lower, upper, &EigenOptions::default(), per_shift).unwrap();
    let expected: Vec<f64> = dense.iter().copied().filter(|&l| l >= lower && l <= upper).collect();
    // Dense rigid-body modes come out at ±round-off: inside a band from 0.
    let expected: Vec<f64> =
        if lower == 0.0 { dense.iter().copied().filter(|&l| l <= upper).collect() } else { expected };
    assert_eq!(sol.modes.omega.len(), expected.len(), "band [{lower:e}, {upper:e}], {per_shift} per shift");
    let elastic = dense.iter().copied().find(|&l| l > 1e-6 * dense[dense.len() - 1]).unwrap().sqrt();
    for (r, (w, e)) in sol.modes.omega.iter().zip(&expected).enumerate() {
        let e = e.max(0.0).sqrt();
        if e < 1e-6 * elastic {
            assert!(*w < 1e-5 * elastic, "rigid mode {r}: {w} rad/s");
        } else {
            assert!((w / e - 1.0).abs() < 1e-9, "mode {r} of the band: {w} vs {e} rad/s");
        }
    }
    // Residuals: 1e-7 for elastic modes (the Ritz residual of the shift-invert operator, 1e-10,
    // grows with the distance to the shift); a rigid-body mode's `Kφ` vanishes and its
    // residual is measured against `|σ| ‖Mφ‖`, σ ~1e-4 of the frequencies of interest: the
    // solver's limit, 1e-6.
    for (r, (res, w)) in sol.residuals.iter().zip(&sol.modes.omega).enumerate() {
        let limit = if *w < 1e-5 * elastic { 1e-6 } else { 1e-7 };
        assert!(*res < limit, "mode {r} of the band ({w} rad/s): residual {res:.1e}");
    }
    let phi = &sol.modes.shapes;
    let g = phi.transpose() * (Matrix::Sparse(m.clone()).to_dense() * phi);
    for i in 0..g.nrows() {
        for j in 0..g.ncols() {
            let e = if i == j { 1.0 } else { 0.0 };
            assert!((g[(i, j)] - e).abs() < 1e-8, "Φᵀ M Φ ({i},{j}) = {}", g[(i, j)]);
        }
    }
    sol.modes.omega.len()
}

#[test]
fn band_equals_the_dense_modes_in_it_on_a_3d_lattice() {
    let (k, m) = lattice_3d(4, 3, 5, 5.0e5);
    let d = dense_lambda(&k, &m);
    let mid = |i: usize| 0.5 * (d[i] + d[i + 1]);
    // Between modes 30 and 61 (1-based), at one shift and split in five.
    assert_eq!(assert_band_equals_dense(&k, &m, &d, (mid(29), mid(59)), 300), 30);
    assert_eq!(assert_band_equals_dense(&k, &m, &d, (mid(29), mid(59)), 7), 30);
    // Ends on eigenvalues: both included.
    assert_eq!(assert_band_equals_dense(&k, &m, &d, (d[40], d[50]), 300), 11);
    // From 0: the lowest modes, without a count.
    assert_eq!(assert_band_equals_dense(&k, &m, &d, (0.0, mid(9)), 300), 10);
    // The whole spectrum.
    assert_eq!(assert_band_equals_dense(&k, &m, &d, (0.0, 2.0 * d[d.len() - 1]), 300), d.len());
}

/// A square grid: every eigenvalue with i ≠ j is (at least) double.
#[test]
fn band_finds_every_copy_of_repeated_eigenvalues() {
    let (k, m, mut exact) = laplacian_2d(20, 20);
    exact.sort_by(f64::total_cmp);
    let repeated = exact.windows(2).filter(|w| (w[1] / w[0] - 1.0).abs() < 1e-12).count();
    assert!(repeated > 100, "{repeated}");
    for (lo, hi, per_shift) in
        [(0.0, exact[60] * 1.0001, 300), (exact[100], exact[180], 300), (exact[100], exact[180], 13)]
    {
        assert_band_equals_dense(&k, &m, &exact, (lo, hi), per_shift);
    }
}

/// A free-free steel cube (hex8, 192 DOFs): 6 rigid-body modes at 0 and the cube's repeated
/// elastic modes, in bands from 0 (rigid modes only, then with elastic ones) and above.
#[test]
fn band_from_zero_includes_the_six_rigid_modes_of_a_free_free_cube() {
    use stickslip_fe::assembly::FeModel;
    use stickslip_fe::element::SolidKind;
    use stickslip_fe::mesh::generate::box_mesh;
    use stickslip_fe::mesh::Material;
    let steel = Material { young: 2.1e11, poisson: 0.3, density: 7800.0 };
    let fe = FeModel::assemble(box_mesh([0.1, 0.1, 0.1], [3, 3, 3], SolidKind::Hex8, steel)).unwrap();
    let (k, m) = (eigen::to_sparse(&fe.model.stiffness).into_owned(), eigen::to_sparse(&fe.model.mass).into_owned());
    let d = dense_lambda(&k, &m);
    assert!(d[5] < 1e-6 * d[6] && d[6] > 0.0, "{:?}", &d[..8]);
    // Band ends between distinct eigenvalues: the cube's are double and triple.
    let gap = |mut i: usize| {
        while d[i + 1] - d[i] < 1e-6 * d[i + 1] {
            i += 1;
        }
        i
    };
    let mid = |i: usize| 0.5 * (d[gap(i)] + d[gap(i) + 1]);
    let repeated = d[6..].windows(2).filter(|w| w[1] - w[0] < 1e-9 * w[1]).count();
    assert!(repeated > 20, "{repeated}");
    assert_eq!(assert_band_equals_dense(&k, &m, &d, (0.0, mid(5)), 300), 6);
    assert_eq!(assert_band_equals_dense(&k, &m, &d, (0.0, mid(29)), 300), gap(29) + 1);
    assert_eq!(assert_band_equals_dense(&k, &m, &d, (0.0, mid(29)), 8), gap(29) + 1);
    assert_eq!(assert_band_equals_dense(&k, &m, &d, (mid(19), mid(79)), 300), gap(79) - gap(19));
}

#[test]
fn band_without_modes_is_empty_and_bad_ends_are_errors() {
    let (k, m) = lattice_3d(4, 3, 5, 5.0e5);
    let d = dense_lambda(&k, &m);
    let (lo, hi) = (0.6 * d[30] + 0.4 * d[31], 0.3 * d[30] + 0.7 * d[31]);
    let sol = eigen::solve_band(&k, &m, lo, hi, &EigenOptions::default()).unwrap();
    assert!(sol.modes.omega.is_empty() && sol.residuals.is_empty() && sol.modes.shapes.ncols() == 0);
    assert_eq!(sol.below_shift, 31);
    for (lo, hi, says) in [
        (-1.0, 10.0, "lower end must be >= 0"),
        (10.0, 1.0, "must not exceed the upper"),
        (f64::NAN, 1.0, "finite"),
        (0.0, f64::INFINITY, "finite"),
    ] {
        let e = eigen::solve_band(&k, &m, lo, hi, &EigenOptions::default()).unwrap_err();
        assert!(matches!(e, EigenError::Band(_)) && e.to_string().contains(says), "{e}");
    }
}
