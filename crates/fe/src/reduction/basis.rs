//! The reduction bases: constraint modes (Eqs. 3-4), cleaning of dynamic vectors on the
//! retained DOFs (Eq. 5), orthogonalisation, projection.
use std::time::Instant;

use faer::prelude::Solve;
use faer::reborrow::Reborrow;
use faer::sparse::{SparseColMat, SymbolicSparseColMat, Triplet};
use faer::{Mat, Side};
use rayon::prelude::*;
use stickslip_core::model::{symmetric_eigen, LinearModel, Matrix};

use super::{reduced_model, Method, Reduction, ReductionError, ReductionOptions, Release};
use crate::eigen::{self, symmetric_times, to_sparse, EigenOptions, EigenSolution, LowRankUpdate, ShiftedFactor};

/// Retained (r) and eliminated (e) DOFs.
struct Partition {
    retained: Vec<usize>,
    interior: Vec<usize>,
    /// Position of each full DOF in the interior list (`None` for retained DOFs).
    interior_pos: Vec<Option<usize>>,
}

fn partition(model: &LinearModel, retained: &[usize]) -> Result<Partition, ReductionError> {
    let n = model.n_dofs();
    if retained.is_empty() {
        return Err(ReductionError::NothingRetained);
    }
    let mut is_retained = vec![false; n];
    for &i in retained {
        if i >= n {
            return Err(ReductionError::RetainedOutOfRange { index: i, n });
        }
        if is_retained[i] {
            return Err(ReductionError::RetainedTwice(model.dofs[i].name.clone()));
        }
        is_retained[i] = true;
    }
    let interior: Vec<usize> = (0..n).filter(|&i| !is_retained[i]).collect();
    let mut interior_pos = vec![None; n];
    for (p, &i) in interior.iter().enumerate() {
        interior_pos[i] = Some(p);
    }
    Ok(Partition { retained: retained.to_vec(), interior, interior_pos })
}

/// `A[e, e]` as a sparse matrix (interior order is increasing, so row indices stay sorted).
fn interior_block(a: &SparseColMat<usize, f64>, part: &Partition) -> SparseColMat<usize, f64> {
    let a = a.as_ref();
    let ne = part.interior.len();
    let mut col_ptr = Vec::with_capacity(ne + 1);
    let mut rows = Vec::new();
    let mut vals = Vec::new();
    col_ptr.push(0);
    for &j in &part.interior {
        for (&i, &v) in a.symbolic().row_idx_of_col_raw(j).iter().zip(a.val_of_col(j)) {
            if let Some(p) = part.interior_pos[i] {
                rows.push(p);
                vals.push(v);
            }
        }
        col_ptr.push(rows.len());
    }
    SparseColMat::new(SymbolicSparseColMat::new_checked(ne, ne, col_ptr, None, rows), vals)
}

/// Constraint modes (Eqs. 3-4): `Ψ = [−K_ee⁻¹ K_er; I]`, one column per retained DOF, in the
/// full DOF order.
fn constraint_modes(k: &SparseColMat<usize, f64>, part: &Partition, kee: &ShiftedFactor) -> Mat<f64> {
    let k = k.as_ref();
    let (n, ne, nr) = (k.nrows(), part.interior.len(), part.retained.len());
    let mut rhs = Mat::<f64>::zeros(ne, nr);
    for (c, &j) in part.retained.iter().enumerate() {
        for (&i, &v) in k.symbolic().row_idx_of_col_raw(j).iter().zip(k.val_of_col(j)) {
            if let Some(p) = part.interior_pos[i] {
                rhs[(p, c)] = -v;
            }
        }
    }
    kee.solve_in_place(rhs.as_mut());
    let mut psi = Mat::<f64>::zeros(n, nr);
    for c in 0..nr {
        for (p, &i) in part.interior.iter().enumerate() {
            psi[(i, c)] = rhs[(p, c)];
        }
        psi[(part.retained[c], c)] = 1.0;
    }
    psi
}

/// Constraint modes from a factorisation of the whole `K` (no factorisation of `K_ee`):
/// `G = K⁻¹ E` for the retained-DOF selector `E` satisfies `K G = E`, so `G (G_rr)⁻¹` is unit on
/// the retained DOFs with zero forces on the others: Eqs. 3-4 exactly (`G_rr` is the
/// flexibility at the retained DOFs, positive definite).
fn constraint_modes_from_full(part: &Partition, n: usize, k: &ShiftedFactor) -> Option<Mat<f64>> {
    let nr = part.retained.len();
    let mut g = Mat::<f64>::zeros(n, nr);
    for (c, &i) in part.retained.iter().enumerate() {
        g[(i, c)] = 1.0;
    }
    k.solve_in_place(g.as_mut());
    let grr = Mat::<f64>::from_fn(nr, nr, |a, b| 0.5 * (g[(part.retained[a], b)] + g[(part.retained[b], a)]));
    let llt = grr.llt(Side::Lower).ok()?;
    // Ψ = G G_rr⁻¹, i.e. Ψᵀ = G_rr⁻¹ Gᵀ (G_rr symmetric), in place by blocks of rows of G: no
    // second and third n × r block (250 MB each at 306k DOFs and 103 retained DOFs) while the
    // factor of K is held.
    let mut blocks = Vec::with_capacity(n.div_ceil(4096));
    let mut rest = g.as_mut();
    while rest.nrows() > 0 {
        let rows = 4096.min(rest.nrows());
        let (head, tail) = rest.split_at_row_mut(rows);
        blocks.push(head);
        rest = tail;
    }
    blocks.into_par_iter().for_each(|mut block| {
        let mut t = block.rb().transpose().to_owned();
        llt.solve_in_place(t.as_mut());
        block.copy_from(t.transpose());
    });
    let mut psi = g;
    for (c, &i) in part.retained.iter().enumerate() {
        for cc in 0..nr {
            psi[(i, cc)] = if c == cc { 1.0 } else { 0.0 };
        }
    }
    Some(psi)
}

/// Eq. 5: `Φ* = Φ − Σ_r Φ_r Ψ_r`, zero on the retained DOFs (set exactly).
fn clean(phi: &Mat<f64>, psi: &Mat<f64>, part: &Partition) -> Mat<f64> {
    let phi_r = Mat::<f64>::from_fn(part.retained.len(), phi.ncols(), |r, c| phi[(part.retained[r], c)]);
    let mut out = phi - psi * &phi_r;
    for &i in &part.retained {
        for c in 0..out.ncols() {
            out[(i, c)] = 0.0;
        }
    }
    out
}

/// Columns of the basis multiplied by a sparse matrix at a time in [`project_matrix`].
const PROJECTION_SLAB: usize = 32;

/// `Tᵀ A T`, symmetrised (A is symmetric; this removes round-off asymmetry). For a sparse A
/// the product is formed as `Tᵀ (A T)`, `A T` by [`symmetric_times`] (one pass over A).
pub(super) fn project_matrix(a: &Matrix, t: &Mat<f64>) -> Mat<f64> {
    let p = match a {
        Matrix::Dense(d) => t.transpose() * (d * t),
        Matrix::Sparse(s) => {
            // By slabs of columns of T: `A T` whole is an n × m temporary (365 MB for the
            // 149-vector basis at 306k DOFs).
            let m = t.ncols();
            let mut p = Mat::<f64>::zeros(m, m);
            for c0 in (0..m).step_by(PROJECTION_SLAB) {
                let w = PROJECTION_SLAB.min(m - c0);
                let at = symmetric_times(s.as_ref(), t.subcols(c0, w));
                p.subcols_mut(c0, w).copy_from(t.transpose() * at);
            }
            p
        }
    };
    Mat::from_fn(p.nrows(), p.ncols(), |i, j| 0.5 * (p[(i, j)] + p[(j, i)]))
}

/// Linear dependence threshold: a vector whose M-norm, once the span of the others is removed,
/// is below 1e-10 of its own adds nothing but round-off to the basis (squared: 1e-20 on the
/// eigenvalues of the M-Gram matrix of M-normalised vectors; 1e-14 keeps a margin above
/// round-off of that Gram matrix).
const DEPENDENCE: f64 = 1e-14;

/// Rayleigh-Ritz on the span of `x`: an M-orthonormal, K-orthogonal basis of it (the
/// K-orthogonalisation of the paper's Section 3.3), vectors ordered by increasing
/// `φᵀKφ`. Linearly dependent vectors are dropped.
fn orthonormalise(model: &LinearModel, x: Mat<f64>) -> Result<Mat<f64>, ReductionError> {
    if x.ncols() == 0 {
        return Ok(x);
    }
    let mut gm = project_matrix(&model.mass, &x);
    // Unit M-norm columns first, so that the dependence test is scale-free.
    let scale: Vec<f64> = (0..x.ncols()).map(|c| 1.0 / gm[(c, c)].max(f64::MIN_POSITIVE).sqrt()).collect();
    for i in 0..gm.nrows() {
        for j in 0..gm.ncols() {
            gm[(i, j)] *= scale[i] * scale[j];
        }
    }
    let (mu, u) = symmetric_eigen(gm.as_ref()).ok_or_else(gram_failed)?;
    let mu_max = mu.iter().cloned().fold(0.0, f64::max);
    let kept: Vec<usize> = (0..mu.len()).filter(|&i| mu[i] > DEPENDENCE * mu_max).collect();
    let q = Mat::<f64>::from_fn(x.ncols(), kept.len(), |r, c| u[(r, kept[c])] * scale[r] / mu[kept[c]].sqrt());
    let z = &x * &q;
    let gk = project_matrix(&model.stiffness, &z);
    let (kappa, u) = symmetric_eigen(gk.as_ref()).ok_or_else(gram_failed)?;
    let mut order: Vec<usize> = (0..kappa.len()).collect();
    order.sort_by(|&a, &b| kappa[a].total_cmp(&kappa[b]));
    Ok(&z * Mat::<f64>::from_fn(u.nrows(), u.ncols(), |r, c| u[(r, order[c])]))
}

fn gram_failed() -> ReductionError {
    ReductionError::Model(stickslip_core::model::ModelError::Invalid(
        "the Gram matrices of the reduction basis have no accurate eigendecomposition (a basis of nearly dependent vectors)".into(),
    ))
}

fn eigen_options(opts: &ReductionOptions, count: usize) -> EigenOptions {
    EigenOptions { count, ..opts.eigen.clone() }
}

/// The free modes that go into the basis: the `modes` lowest, or all of a band's.
fn kept_modes(opts: &ReductionOptions, sol: &EigenSolution) -> usize {
    match opts.band {
        Some(_) => sol.modes.omega.len(),
        None => opts.modes,
    }
}

fn frequencies(sol: &EigenSolution) -> (Vec<f64>, Vec<f64>) {
    (sol.modes.frequencies_hz(), sol.residuals.clone())
}

fn finish(
    model: &LinearModel,
    part: &Partition,
    psi: Mat<f64>,
    dynamic: Mat<f64>,
    method: Method,
    modes: (Vec<f64>, Vec<f64>),
    mut stages: Vec<(&'static str, f64)>,
) -> Result<Reduction, ReductionError> {
    let start = Instant::now();
    let (nr, nd) = (psi.ncols(), dynamic.ncols());
    let mut t = Mat::<f64>::zeros(psi.nrows(), nr + nd);
    t.subcols_mut(0, nr).copy_from(&psi);
    t.subcols_mut(nr, nd).copy_from(&dynamic);
    drop((psi, dynamic));
    let reduced = reduced_model(model, &t, &part.retained)?;
    stages.push(("projection", start.elapsed().as_secs_f64()));
    crate::memory::stage("projection");
    Ok(Reduction {
        model: reduced,
        basis: t,
        retained: part.retained.clone(),
        method,
        basis_frequencies_hz: modes.0,
        basis_residuals: modes.1,
        stages,
    })
}

/// The number of modes with ω² ≤ `upper` (rad²/s²) that a reduction would keep, from the
/// inertia of `K − σM` (Sylvester's law, no mode computed): of `(K_ee, M_ee)` with the
/// retained DOFs clamped for Craig-Bampton (`fixed_interface`), of the whole `(K, M)` for the
/// free-mode bases.
pub fn modes_up_to(
    model: &LinearModel,
    retained: &[usize],
    fixed_interface: bool,
    upper: f64,
) -> Result<usize, ReductionError> {
    let (k, m) = (to_sparse(&model.stiffness), to_sparse(&model.mass));
    if fixed_interface {
        let part = partition(model, retained)?;
        let (kee, mee) = (interior_block(&k, &part), interior_block(&m, &part));
        Ok(eigen::count_in_band(&kee, &mee, 0.0, upper)?)
    } else {
        Ok(eigen::count_in_band(&k, &m, 0.0, upper)?)
    }
}

/// Craig-Bampton: constraint modes + the `opts.modes` lowest fixed-interface modes (modes of
/// `(K_ee, M_ee)`, retained DOFs clamped). One LDLᵀ of `K_ee` serves both: the eigensolver
/// works at shift 0, which `K_ee` allows whenever the constraint modes exist.
pub fn craig_bampton(model: &LinearModel, opts: &ReductionOptions) -> Result<Reduction, ReductionError> {
    let part = partition(model, &opts.retained)?;
    let (k, m) = (to_sparse(&model.stiffness), to_sparse(&model.mass));
    let (k, m) = (&*k, &*m);
    let start = Instant::now();
    let (kee, mee) = (interior_block(k, &part), interior_block(m, &part));
    let factor =
        ShiftedFactor::new(kee.as_ref(), Some(mee.as_ref()), 0.0).map_err(ReductionError::InteriorMechanism)?;
    let psi = constraint_modes(k, &part, &factor);
    let mut stages = vec![("constraint modes", start.elapsed().as_secs_f64())];
    crate::memory::stage("constraint modes");
    let start = Instant::now();
    let sol = match opts.band {
        // A band has its own shifts: the factor of K_ee is freed first (one factor at a time).
        Some((lower, upper)) => {
            drop(factor);
            Some(eigen::solve_band(&kee, &mee, lower, upper, &opts.eigen)?)
        }
        None if opts.modes > 0 => {
            Some(eigen::modes_with_factor(&kee, &mee, &factor, &eigen_options(opts, opts.modes))?)
        }
        None => None,
    };
    let (dynamic, freqs) = if let Some(sol) = sol.filter(|s| !s.modes.omega.is_empty()) {
        let count = sol.modes.omega.len();
        let mut phi = Mat::<f64>::zeros(model.n_dofs(), count);
        for (p, &i) in part.interior.iter().enumerate() {
            for c in 0..count {
                phi[(i, c)] = sol.modes.shapes[(p, c)];
            }
        }
        (phi, frequencies(&sol))
    } else {
        (Mat::zeros(model.n_dofs(), 0), (vec![], vec![]))
    };
    stages.push(("fixed-interface modes", start.elapsed().as_secs_f64()));
    crate::memory::stage("fixed-interface modes");
    finish(model, &part, psi, dynamic, Method::CraigBampton, freqs, stages)
}

/// The paper's variant (Section 3.3): constraint modes + the `opts.modes` lowest free modes
/// of the whole structure cleaned on the retained DOFs (Eq. 5) and orthogonalised. The span
/// holds the free modes exactly, so the reduced model has the same first `opts.modes`
/// eigenfrequencies as the full one.
pub fn free_modes(model: &LinearModel, opts: &ReductionOptions) -> Result<Reduction, ReductionError> {
    let (k, m) = (to_sparse(&model.stiffness), to_sparse(&model.mass));
    let (k, m) = (&*k, &*m);
    let (part, psi, sol, mut stages, _) = static_and_free_modes(model, k, m, opts)?;
    let start = Instant::now();
    let phi = sol.modes.shapes.subcols(0, kept_modes(opts, &sol)).to_owned();
    let dynamic = orthonormalise(model, clean(&phi, &psi, &part))?;
    stages.push(("cleaning and orthogonalisation", start.elapsed().as_secs_f64()));
    crate::memory::stage("cleaning and orthogonalisation");
    let freqs = frequencies(&sol);
    finish(model, &part, psi, dynamic, Method::FreeModes, freqs, stages)
}

/// Wall-clock seconds per named stage.
type Stages = Vec<(&'static str, f64)>;
/// The partition, the constraint modes, the free modes, the stage times and the factorisation
/// of K when one served both (kept for the released modes of [`enriched`]).
type StaticAndFree = (Partition, Mat<f64>, EigenSolution, Stages, Option<ShiftedFactor>);

/// Constraint modes and the free modes. When no shift is asked and K is positive definite, a
/// single LDLᵀ of K serves both (shift 0 is then below the spectrum); otherwise (a free-free
/// structure, a given shift) the modes use `K − σM` and the constraint modes `K_ee`.
fn static_and_free_modes(
    model: &LinearModel,
    k: &SparseColMat<usize, f64>,
    m: &SparseColMat<usize, f64>,
    opts: &ReductionOptions,
) -> Result<StaticAndFree, ReductionError> {
    let part = partition(model, &opts.retained)?;
    if let Some((lower, upper)) = opts.band {
        // The band's modes first, at their own shifts, so that one factor is held at a time;
        // then the constraint modes as below, from the factor of K when K is positive definite
        // (kept for the released modes of `enriched`), otherwise from K_ee.
        let start = Instant::now();
        let sol = eigen::solve_band(k, m, lower, upper, &opts.eigen)?;
        let t_modes = start.elapsed().as_secs_f64();
        crate::memory::stage("free modes");
        let start = Instant::now();
        if let Ok(factor) = ShiftedFactor::new(k.as_ref(), Some(m.as_ref()), 0.0) {
            let t_factor = start.elapsed().as_secs_f64();
            let start = Instant::now();
            if let Some(psi) = constraint_modes_from_full(&part, model.n_dofs(), &factor) {
                crate::memory::stage("constraint modes");
                let stages = vec![
                    ("free modes", t_modes),
                    ("factorisation of K", t_factor),
                    ("constraint modes", start.elapsed().as_secs_f64()),
                ];
                return Ok((part, psi, sol, stages, Some(factor)));
            }
        }
        let (part, psi, mut stages) = static_part(model, k, &opts.retained)?;
        stages.insert(0, ("free modes", t_modes));
        return Ok((part, psi, sol, stages, None));
    }
    let eig = eigen_options(opts, opts.modes.max(1));
    if opts.eigen.shift.is_none() {
        let start = Instant::now();
        if let Ok(factor) = ShiftedFactor::new(k.as_ref(), Some(m.as_ref()), 0.0) {
            let t_factor = start.elapsed().as_secs_f64();
            let start = Instant::now();
            let sol = eigen::modes_with_factor(k, m, &factor, &eig)?;
            let t_modes = start.elapsed().as_secs_f64();
            let start = Instant::now();
            if let Some(psi) = constraint_modes_from_full(&part, model.n_dofs(), &factor) {
                crate::memory::stage("constraint modes");
                let stages = vec![
                    ("factorisation of K", t_factor),
                    ("free modes", t_modes),
                    ("constraint modes", start.elapsed().as_secs_f64()),
                ];
                return Ok((part, psi, sol, stages, Some(factor)));
            }
        }
    }
    let (part, psi, mut stages) = static_part(model, k, &opts.retained)?;
    let start = Instant::now();
    let sol = eigen::solve(k, m, &eig)?;
    stages.push(("free modes", start.elapsed().as_secs_f64()));
    crate::memory::stage("free modes");
    Ok((part, psi, sol, stages, None))
}

fn static_part(
    model: &LinearModel,
    k: &SparseColMat<usize, f64>,
    retained: &[usize],
) -> Result<(Partition, Mat<f64>, Stages), ReductionError> {
    let part = partition(model, retained)?;
    let start = Instant::now();
    let kee = interior_block(k, &part);
    let factor = ShiftedFactor::new(kee.as_ref(), None, 0.0).map_err(ReductionError::InteriorMechanism)?;
    let psi = constraint_modes(k, &part, &factor);
    Ok((part, psi, vec![("constraint modes", start.elapsed().as_secs_f64())]))
}

/// The free-mode variant enriched with the `release_modes` lowest modes of the structure with
/// the given joints released (Zucca & Epureanu): `K − Σ k_j d_j d_jᵀ`. The released modes are
/// cleaned on the retained DOFs like the free ones and orthogonalised together with them;
/// vectors already in the span are dropped. The kept free modes stay exact.
pub fn enriched(
    model: &LinearModel,
    opts: &ReductionOptions,
    releases: &[Release],
    release_modes: usize,
) -> Result<Reduction, ReductionError> {
    let n = model.n_dofs();
    let (k, m) = (to_sparse(&model.stiffness), to_sparse(&model.mass));
    let (k, m) = (&*k, &*m);
    let (part, psi, sol, mut stages, factor) = static_and_free_modes(model, k, m, opts)?;
    let start = Instant::now();
    check_releases(releases, n)?;
    let eig = eigen_options(opts, release_modes.max(1));
    // The factor of K serves the released structure too, through a rank-r update
    // (`LowRankUpdate`), and the products with the released stiffness are K's less the
    // rank-one terms: no second matrix. When the release opens a mechanism at that shift,
    // `K_released` is formed and factorised at the default (negative) shift instead, once the
    // factor of K is freed.
    let updated = factor.as_ref().and_then(|f| {
        let directions = Mat::<f64>::from_fn(n, releases.len(), |i, j| releases[j].direction[i]);
        let stiffness: Vec<f64> = releases.iter().map(|r| r.stiffness).collect();
        LowRankUpdate::new(f, directions, &stiffness).ok()
    });
    let rel = updated.as_ref().map(|update| eigen::modes_of_update(k, m, update, &eig)).transpose()?;
    drop(updated);
    drop(factor);
    let rel = match rel {
        Some(rel) => rel,
        None => eigen::solve(&released_stiffness(k, releases, n)?, m, &eig)?,
    };
    stages.push(("released modes", start.elapsed().as_secs_f64()));
    crate::memory::stage("released modes");
    let start = Instant::now();
    let (nf, nrel) = (kept_modes(opts, &sol), release_modes.min(rel.modes.omega.len()));
    let mut x = Mat::<f64>::zeros(n, nf + nrel);
    x.subcols_mut(0, nf).copy_from(sol.modes.shapes.subcols(0, nf));
    x.subcols_mut(nf, nrel).copy_from(rel.modes.shapes.subcols(0, nrel));
    let dynamic = orthonormalise(model, clean(&x, &psi, &part))?;
    stages.push(("cleaning and orthogonalisation", start.elapsed().as_secs_f64()));
    crate::memory::stage("cleaning and orthogonalisation");
    let (mut f, mut r) = frequencies(&sol);
    f.truncate(nf);
    r.truncate(nf);
    f.extend(rel.modes.frequencies_hz().into_iter().take(nrel));
    r.extend(rel.residuals.iter().take(nrel));
    finish(model, &part, psi, dynamic, Method::Enriched, (f, r), stages)
}

/// Each release's direction is over the `n` DOFs and not zero, its stiffness finite and positive.
fn check_releases(releases: &[Release], n: usize) -> Result<(), ReductionError> {
    for r in releases {
        let bad = |message: String| ReductionError::Release { name: r.name.clone(), message };
        if r.direction.len() != n {
            return Err(bad(format!("direction has length {}, expected {n} (one value per DOF)", r.direction.len())));
        }
        if !(r.stiffness.is_finite() && r.stiffness > 0.0) {
            return Err(bad(format!("stiffness must be finite and positive, got {}", r.stiffness)));
        }
        if r.direction.iter().all(|v| *v == 0.0) {
            return Err(bad("direction is zero".into()));
        }
    }
    Ok(())
}

/// `K − Σ_j k_j d_j d_jᵀ` (the releases checked by [`check_releases`]), for a factorisation of
/// its own where the update of K's factor cannot serve.
fn released_stiffness(
    k: &SparseColMat<usize, f64>,
    releases: &[Release],
    n: usize,
) -> Result<SparseColMat<usize, f64>, ReductionError> {
    let mut t = Vec::new();
    for r in releases {
        let support: Vec<(usize, f64)> =
            r.direction.iter().enumerate().filter(|(_, v)| **v != 0.0).map(|(i, v)| (i, *v)).collect();
        for &(i, a) in &support {
            for &(j, b) in &support {
                t.push(Triplet::new(i, j, r.stiffness * a * b));
            }
        }
    }
    let d = SparseColMat::try_new_from_triplets(n, n, &t).expect("indices checked");
    faer::sparse::ops::binary_op(k.as_ref(), d.as_ref(), |a, b| a.copied().unwrap_or(0.0) - b.copied().unwrap_or(0.0))
        .map_err(|e| ReductionError::Release { name: "all".into(), message: format!("cannot form K: {e:?}") })
}
