//! Thick-restart Lanczos (Wu & Simon, SIAM J. Matrix Anal. Appl. 22, 2000), in blocks and
//! single-vector, for the shift-invert operator `OP = (K − σM)⁻¹ M`, self-adjoint in the M
//! inner product. Its largest eigenvalues θ = 1/(λ − σ) are the eigenvalues λ = ω² nearest σ.
//!
//! Both `V` and `MV` are kept, so every step costs one solve and two products with M; the
//! basis is fully reorthogonalised (twice, which is enough in floating point) because the
//! Krylov spaces here are small (tens to hundreds of vectors) next to the cost of a solve.
use faer::linalg::matmul::matmul;
use faer::reborrow::{Reborrow, ReborrowMut};
use faer::sparse::SparseColMat;
use faer::{Accum, Mat, MatMut, MatRef, Par, Side};
use rayon::prelude::*;
use stickslip_core::model::{symmetric_eigen, Modes};

use super::product::{symmetric_product, Stiffness};
use super::{EigenError, EigenOptions, EigenSolution, ShiftInvert};

pub(super) fn check_sizes(k: &Stiffness<'_>, m: &SparseColMat<usize, f64>) -> Result<(), EigenError> {
    if k.nrows() != k.ncols() || m.nrows() != m.ncols() || k.nrows() != m.nrows() {
        return Err(EigenError::Size { k_rows: k.nrows(), k_cols: k.ncols(), m_rows: m.nrows(), m_cols: m.ncols() });
    }
    Ok(())
}

/// The `opts.count` modes of `(K, M)` nearest the shift of `factor`, an existing
/// factorisation of `K − σM` or an update of one.
pub fn modes_with_factor(
    k: &Stiffness<'_>,
    m: &SparseColMat<usize, f64>,
    factor: &dyn ShiftInvert,
    opts: &EigenOptions,
) -> Result<EigenSolution, EigenError> {
    check_sizes(k, m)?;
    let n = k.nrows();
    let nev = opts.count;
    if nev == 0 || nev > n {
        return Err(EigenError::TooManyModes { requested: nev, available: n });
    }
    if opts.subspace.is_none() {
        if let Some(solution) = block_krylov(k, m, factor, opts)? {
            return Ok(solution);
        }
    }
    let sigma = factor.shift();
    let ncv = opts.subspace.unwrap_or((2 * nev + 20).max(nev + 30)).clamp(nev + 1, n.max(nev + 1));
    // A full-size space needs no Lanczos: fall back on ncv = n with one cycle.
    let ncv = ncv.min(n);
    let par = Par::rayon(0);
    let mut v = Mat::<f64>::zeros(n, ncv + 1);
    let mut mv = Mat::<f64>::zeros(n, ncv + 1);
    let mut h = Mat::<f64>::zeros(ncv + 1, ncv);
    let mut coef = Mat::<f64>::zeros(ncv + 1, 1);
    let mut solves = 0;

    // Start: OP applied to a deterministic pseudo-random vector puts it in the range of OP.
    {
        let mut x = Mat::<f64>::from_fn(n, 1, |i, _| pseudo_random(i));
        let mut mx = Mat::<f64>::zeros(n, 1);
        symmetric_product(mx.as_mut(), m.as_ref(), x.as_ref());
        factor.solve_in_place(mx.as_mut());
        solves += 1;
        x.copy_from(&mx);
        symmetric_product(mx.as_mut(), m.as_ref(), x.as_ref());
        let norm = dot(x.as_ref(), mx.as_ref()).sqrt();
        v.col_mut(0).copy_from(x.col(0) / norm);
        mv.col_mut(0).copy_from(mx.col(0) / norm);
    }

    let mut start = 0;
    let mut restarts = 0;
    loop {
        for j in start..ncv {
            // w = OP v_j = (K − σM)⁻¹ (M v_j); z = M w.
            let (done, mut next) = v.as_mut().split_at_col_mut(j + 1);
            let mut w = next.rb_mut().subcols_mut(0, 1);
            w.copy_from(mv.col(j).as_mat());
            factor.solve_in_place(w.rb_mut());
            solves += 1;
            let (mdone, mut mnext) = mv.as_mut().split_at_col_mut(j + 1);
            let mut z = mnext.rb_mut().subcols_mut(0, 1);
            symmetric_product(z.rb_mut(), m.as_ref(), w.rb());
            // Two passes of classical Gram-Schmidt in the M inner product.
            for _ in 0..2 {
                let mut c = coef.as_mut().subrows_mut(0, j + 1);
                matmul(c.rb_mut(), Accum::Replace, done.rb().transpose(), z.rb(), 1.0, par);
                matmul(w.rb_mut(), Accum::Add, done.rb(), c.rb(), -1.0, par);
                matmul(z.rb_mut(), Accum::Add, mdone.rb(), c.rb(), -1.0, par);
                for i in 0..=j {
                    h[(i, j)] += c[(i, 0)];
                }
            }
            // M w afresh: after cancellation the updated z is not accurate enough to
            // normalise with when β is small (near-invariant subspaces, clustered modes).
            symmetric_product(z.rb_mut(), m.as_ref(), w.rb());
            let beta = dot(w.rb(), z.rb()).max(0.0).sqrt();
            h[(j + 1, j)] = beta;
            let scale = h[(j, j)].abs().max(f64::MIN_POSITIVE);
            if beta <= 1e-14 * scale {
                // Invariant subspace: continue with a fresh direction orthogonal to the basis.
                restart_direction(m, &mut v, &mut mv, j + 1);
                h[(j + 1, j)] = 0.0;
            } else {
                let (mut w, mut z) = (w, z);
                w.copy_from(w.rb() / beta);
                z.copy_from(z.rb() / beta);
            }
        }

        // Rayleigh-Ritz on the projected operator (symmetric up to round-off).
        let s = Mat::<f64>::from_fn(ncv, ncv, |i, j| 0.5 * (h[(i, j)] + h[(j, i)]));
        let (theta, y) = symmetric_eigen(s.as_ref()).ok_or_else(projection_failed)?;
        // Largest |θ| first: the eigenvalues nearest the shift.
        let mut order: Vec<usize> = (0..ncv).collect();
        order.sort_by(|&a, &b| theta[b].abs().total_cmp(&theta[a].abs()));
        let beta_m = h[(ncv, ncv - 1)];
        let residual = |i: usize| (beta_m * y[(ncv - 1, i)]).abs() / theta[i].abs().max(f64::MIN_POSITIVE);
        let converged = order[..nev].iter().filter(|&&i| residual(i) <= opts.tolerance).count();
        if converged == nev || ncv == n {
            let shapes = ritz_vectors(v.as_ref(), y.as_ref(), &theta, &order[..nev], sigma);
            drop((v, mv));
            return finish(k, m, shapes, factor, solves, restarts, opts);
        }
        if restarts == opts.max_restarts {
            let worst = order[..nev].iter().map(|&i| residual(i)).fold(0.0, f64::max);
            return Err(EigenError::NotConverged { restarts, converged, requested: nev, worst });
        }
        // Thick restart: keep the best Ritz vectors, the residual direction follows them.
        restarts += 1;
        let keep = (nev + (ncv - nev) / 2).min(ncv - 1);
        let y_keep = Mat::<f64>::from_fn(ncv, keep, |i, c| y[(i, order[c])]);
        combine_in_place(v.as_mut(), y_keep.as_ref());
        combine_in_place(mv.as_mut(), y_keep.as_ref());
        let last = v.col(ncv).to_owned();
        let mlast = mv.col(ncv).to_owned();
        v.col_mut(keep).copy_from(&last);
        mv.col_mut(keep).copy_from(&mlast);
        h.fill(0.0);
        for c in 0..keep {
            let i = order[c];
            h[(c, c)] = theta[i];
            h[(keep, c)] = beta_m * y[(ncv - 1, i)];
        }
        start = keep;
    }
}

/// The wanted Ritz vectors `V y_i` in increasing order of their eigenvalue `σ + 1/θ_i`.
fn ritz_vectors(v: MatRef<'_, f64>, y: MatRef<'_, f64>, theta: &[f64], wanted: &[usize], sigma: f64) -> Mat<f64> {
    crate::memory::stage("Lanczos iteration");
    let ncv = y.nrows();
    let mut pairs: Vec<(f64, usize)> = wanted.iter().map(|&i| (sigma + 1.0 / theta[i], i)).collect();
    pairs.sort_by(|a, b| a.0.total_cmp(&b.0));
    let ysel = Mat::<f64>::from_fn(ncv, pairs.len(), |r, c| y[(r, pairs[c].1)]);
    v.subcols(0, ncv) * &ysel
}

/// The modes from the Ritz vectors `shapes` (see [`ritz_vectors`]), checked and refined. The
/// Krylov basis is freed before: the products here are n × count blocks, and with the basis
/// (0.7 GB at 306k DOFs and 34 modes) they made the peak of the eigensolution.
fn finish(
    k: &Stiffness<'_>,
    m: &SparseColMat<usize, f64>,
    mut shapes: Mat<f64>,
    factor: &dyn ShiftInvert,
    solves: usize,
    restarts: usize,
    opts: &EigenOptions,
) -> Result<EigenSolution, EigenError> {
    let sigma = factor.shift();
    // The Ritz estimates bound the residual of the Krylov recurrence; the true residual also
    // carries the error of the solves, which on large models with 1e10 N/m connectors can
    // exceed the limit (seen: 1.05e-6 on the 2.7 Hz suspension mode of the 306k-DOF Harmony
    // model). Subspace iteration on the block with the same factor, followed by Rayleigh-Ritz,
    // reduces that error (each pass multiplies the components outside the block by
    // |λ − σ| / |λ_out − σ|, λ_out the nearest eigenvalue outside it); two passes at most.
    let mut passes = 0;
    let (omega, residuals) = loop {
        let (omega, residuals) = rayleigh_quotients(k, m, &mut shapes, sigma);
        let worst = residuals.iter().enumerate().max_by(|a, b| a.1.total_cmp(b.1)).map(|(c, &r)| (c, r));
        match worst {
            Some((c, r)) if r > opts.residual_limit => {
                if passes == REFINEMENT_PASSES {
                    return Err(EigenError::Inaccurate { mode: c + 1, residual: r, tolerance: opts.residual_limit });
                }
                refine(k, m, factor, &mut shapes)?;
                passes += 1;
            }
            _ => break (omega, residuals),
        }
    };
    Ok(EigenSolution {
        modes: Modes { omega, shapes },
        residuals,
        shift: sigma,
        below_shift: factor.eigenvalues_below_shift(),
        solves,
        restarts,
    })
}

/// Subspace iterations that may follow the Lanczos iteration (see [`finish`]).
const REFINEMENT_PASSES: usize = 2;

/// Mass-normalise each column of `shapes` and return its circular frequency (from the
/// Rayleigh quotient, more accurate than σ + 1/θ) and its relative residual
/// `‖Kφ − ω²Mφ‖ / max(‖Kφ‖, |σ| ‖Mφ‖)` (rigid-body modes, whose `Kφ` vanishes, are measured
/// against the shift).
fn rayleigh_quotients(
    k: &Stiffness<'_>,
    m: &SparseColMat<usize, f64>,
    shapes: &mut Mat<f64>,
    sigma: f64,
) -> (Vec<f64>, Vec<f64>) {
    let (n, p) = (shapes.nrows(), shapes.ncols());
    let mut kx = Mat::<f64>::zeros(n, p);
    let mut mx = Mat::<f64>::zeros(n, p);
    k.product(kx.as_mut(), shapes.as_ref());
    symmetric_product(mx.as_mut(), m.as_ref(), shapes.as_ref());
    let mut omega = Vec::with_capacity(p);
    let mut residuals = Vec::with_capacity(p);
    for c in 0..p {
        let mass = dot(shapes.col(c).as_mat(), mx.col(c).as_mat());
        let s = 1.0 / mass.sqrt();
        let lambda = dot(shapes.col(c).as_mat(), kx.col(c).as_mat()) / mass;
        let (mut r2, mut k2, mut m2) = (0.0, 0.0, 0.0);
        for i in 0..n {
            let (kv, mv) = (kx[(i, c)] * s, mx[(i, c)] * s);
            r2 += (kv - lambda * mv).powi(2);
            k2 += kv * kv;
            m2 += mv * mv;
        }
        let denom = k2.sqrt().max(sigma.abs() * m2.sqrt()).max(f64::MIN_POSITIVE);
        residuals.push(r2.sqrt() / denom);
        shapes.col_mut(c).iter_mut().for_each(|x| *x *= s);
        // Rigid-body modes come out at |λ| ~ round-off: report them as 0 rad/s.
        omega.push(lambda.max(0.0).sqrt());
    }
    (omega, residuals)
}

/// One subspace iteration `X ← (K − σM)⁻¹ M X` on the block, then Rayleigh-Ritz: the modes of
/// `(Xᵀ K X, Xᵀ M X)` in increasing order.
fn refine(
    k: &Stiffness<'_>,
    m: &SparseColMat<usize, f64>,
    factor: &dyn ShiftInvert,
    shapes: &mut Mat<f64>,
) -> Result<(), EigenError> {
    let (n, p) = (shapes.nrows(), shapes.ncols());
    let mut x = Mat::<f64>::zeros(n, p);
    symmetric_product(x.as_mut(), m.as_ref(), shapes.as_ref());
    factor.solve_in_place(x.as_mut());
    let mut kx = Mat::<f64>::zeros(n, p);
    let mut mx = Mat::<f64>::zeros(n, p);
    k.product(kx.as_mut(), x.as_ref());
    symmetric_product(mx.as_mut(), m.as_ref(), x.as_ref());
    let kr = x.transpose() * &kx;
    let mr = x.transpose() * &mx;
    let mr = Mat::from_fn(p, p, |i, j| 0.5 * (mr[(i, j)] + mr[(j, i)]));
    let failed = || EigenError::Factorisation("the refined block lost its rank (Rayleigh-Ritz)".into());
    let llt = mr.llt(Side::Lower).map_err(|_| failed())?;
    // A = L⁻¹ Kr L⁻ᵀ, symmetric; its eigenvectors Q give X L⁻ᵀ Q.
    let l = llt.L();
    let mut a = kr.clone();
    faer::linalg::triangular_solve::solve_lower_triangular_in_place(l, a.as_mut(), Par::Seq);
    let mut a = a.transpose().to_owned();
    faer::linalg::triangular_solve::solve_lower_triangular_in_place(l, a.as_mut(), Par::Seq);
    let a = Mat::from_fn(p, p, |i, j| 0.5 * (a[(i, j)] + a[(j, i)]));
    let (lambda, u) = symmetric_eigen(a.as_ref()).ok_or_else(failed)?;
    let mut order: Vec<usize> = (0..p).collect();
    order.sort_by(|&a, &b| lambda[a].total_cmp(&lambda[b]));
    let mut q = Mat::<f64>::from_fn(p, p, |r, c| u[(r, order[c])]);
    faer::linalg::triangular_solve::solve_upper_triangular_in_place(l.transpose(), q.as_mut(), Par::Seq);
    *shapes = &x * &q;
    Ok(())
}

/// Replace column `j` of `v` by a new M-normalised vector M-orthogonal to columns `0..j`.
fn restart_direction(m: &SparseColMat<usize, f64>, v: &mut Mat<f64>, mv: &mut Mat<f64>, j: usize) {
    let n = v.nrows();
    for attempt in 0..8 {
        let mut x = Mat::<f64>::from_fn(n, 1, |i, _| pseudo_random(i + (attempt + 1) * (j + 7) * 7919));
        let mut mx = Mat::<f64>::zeros(n, 1);
        for _ in 0..2 {
            symmetric_product(mx.as_mut(), m.as_ref(), x.as_ref());
            let c = v.subcols(0, j).transpose() * &mx;
            x -= v.subcols(0, j) * &c;
        }
        symmetric_product(mx.as_mut(), m.as_ref(), x.as_ref());
        let norm = dot(x.as_ref(), mx.as_ref()).max(0.0).sqrt();
        if norm > 1e-8 {
            v.col_mut(j).copy_from(x.col(0) / norm);
            mv.col_mut(j).copy_from(mx.col(0) / norm);
            return;
        }
    }
}

/// Block shift-invert Lanczos with thick restart (the block form of Wu & Simon's restart, as in
/// block Krylov-Schur, Zhou & Saad, SIAM J. Matrix Anal. Appl. 29, 2008): blocks of `b`
/// vectors, so that every solve with the factor serves `b` right-hand sides at once (a sparse
/// triangular solve is bound by memory traffic through the factor: one block solve costs a few
/// single ones), fully reorthogonalised in the M inner product. When the basis is full, the
/// best Ritz vectors and the last block are kept and the recurrence goes on from them, so the
/// block solves carry the whole iteration. `None` when the Krylov space closes before the
/// wanted modes are in it (the caller falls back on single-vector thick restart).
fn block_krylov(
    k: &Stiffness<'_>,
    m: &SparseColMat<usize, f64>,
    factor: &dyn ShiftInvert,
    opts: &EigenOptions,
) -> Result<Option<EigenSolution>, EigenError> {
    let n = k.nrows();
    let nev = opts.count;
    let b = opts.block.unwrap_or(nev.div_ceil(3).clamp(1, 16)).clamp(1, n);
    // Basis size before a restart: the wanted vectors and twice as many again (eight blocks
    // at least) for the unwanted part of the spectrum that the restarts filter out; a block
    // recurrence needs several blocks between restarts to filter (measured on a 25,830-DOF
    // slab: with room for two blocks per cycle 100 modes did not converge in 200 restarts).
    let max_dim = (3 * nev).max(nev + 8 * b).min(n);
    let mut v = Mat::<f64>::zeros(n, max_dim + b);
    let mut mv = Mat::<f64>::zeros(n, max_dim + b);
    let mut h = Mat::<f64>::zeros(max_dim + b, max_dim + b);
    let mut solves = 0;
    let mut restarts = 0;
    // Start block: OP applied to pseudo-random vectors.
    let mut w = Mat::<f64>::from_fn(n, b, |i, j| pseudo_random(i + j * n));
    let mut mw = Mat::<f64>::zeros(n, b);
    symmetric_product(mw.as_mut(), m.as_ref(), w.as_ref());
    factor.solve_in_place(mw.as_mut());
    solves += b;
    let mut dim = append_block(m, &mut v, &mut mv, 0, mw);
    // Columns [start, dim) form the last block.
    let mut start = 0;
    while dim > start {
        // W = OP V_j = (K − σM)⁻¹ M V_j for the last block.
        let nb = dim - start;
        w = mv.subcols(start, nb).to_owned();
        factor.solve_in_place(w.as_mut());
        solves += nb;
        let new_dim = append_block(m, &mut v, &mut mv, dim, w.clone());
        // H[0..new_dim, block] = (M V)ᵀ W: the projection of OP on the basis.
        let coef = mv.subcols(0, new_dim).transpose() * &w;
        for c in 0..nb {
            for r in 0..new_dim {
                h[(r, start + c)] = coef[(r, c)];
            }
        }
        // Rayleigh-Ritz on the first `dim` vectors.
        let s = Mat::<f64>::from_fn(dim, dim, |i, j| 0.5 * (h[(i, j)] + h[(j, i)]));
        let (theta, y) = symmetric_eigen(s.as_ref()).ok_or_else(projection_failed)?;
        let mut order: Vec<usize> = (0..dim).collect();
        order.sort_by(|&a, &b| theta[b].abs().total_cmp(&theta[a].abs()));
        // ‖OP x − θ x‖_M = ‖H[next block, last block] y_last‖: the kept Ritz vectors of a
        // restart couple to the last block only, so this holds after restarts too.
        let coupling = |i: usize| -> Vec<f64> {
            (dim..new_dim).map(|row| (start..dim).map(|c| h[(row, c)] * y[(c, i)]).sum()).collect()
        };
        let residual =
            |i: usize| coupling(i).iter().map(|x| x * x).sum::<f64>().sqrt() / theta[i].abs().max(f64::MIN_POSITIVE);
        if dim >= nev && order[..nev].iter().all(|&i| residual(i) <= opts.tolerance) {
            let sigma = factor.shift();
            let shapes = ritz_vectors(v.as_ref(), y.as_ref(), &theta, &order[..nev], sigma);
            drop((v, mv));
            return finish(k, m, shapes, factor, solves, restarts, opts).map(Some);
        }
        if new_dim == dim {
            return Ok(None);
        }
        let nb_new = new_dim - dim;
        if new_dim + b <= v.ncols() {
            start = dim;
            dim = new_dim;
            continue;
        }
        if restarts == opts.max_restarts {
            let converged = order[..nev.min(dim)].iter().filter(|&&i| residual(i) <= opts.tolerance).count();
            let worst = order[..nev.min(dim)].iter().map(|&i| residual(i)).fold(0.0, f64::max);
            return Err(EigenError::NotConverged { restarts, converged, requested: nev, worst });
        }
        // Thick restart: the `keep` best Ritz vectors, then the new block, which is
        // M-orthogonal to them; H becomes their Ritz values bordered by their coupling.
        restarts += 1;
        let keep = (nev + (max_dim - nev) / 3).min(dim).min(v.ncols() - nb_new - b);
        let y = Mat::<f64>::from_fn(dim, keep, |r, c| y[(r, order[c])]);
        let couplings: Vec<Vec<f64>> = (0..keep).map(|c| coupling(order[c])).collect();
        combine_in_place(v.as_mut(), y.as_ref());
        combine_in_place(mv.as_mut(), y.as_ref());
        let last = v.subcols(dim, nb_new).to_owned();
        let mlast = mv.subcols(dim, nb_new).to_owned();
        v.subcols_mut(keep, nb_new).copy_from(&last);
        mv.subcols_mut(keep, nb_new).copy_from(&mlast);
        h.fill(0.0);
        for (c, coupling) in couplings.iter().enumerate() {
            h[(c, c)] = theta[order[c]];
            for (r, &x) in coupling.iter().enumerate() {
                h[(keep + r, c)] = x;
                h[(c, keep + r)] = x;
            }
        }
        start = keep;
        dim = keep + nb_new;
    }
    Ok(None)
}

/// M-orthonormalise the block `w` against `v[:, 0..dim]` and within itself (twice: classical
/// Gram-Schmidt and an eigen-decomposition of the block's Gram matrix, which drops directions
/// already in the basis), store it at column `dim` of `v` (and `M v` in `mv`); returns the new
/// number of basis vectors.
fn append_block(
    m: &SparseColMat<usize, f64>,
    v: &mut Mat<f64>,
    mv: &mut Mat<f64>,
    dim: usize,
    mut w: Mat<f64>,
) -> usize {
    let n = w.nrows();
    let mut mw = Mat::<f64>::zeros(n, w.ncols());
    symmetric_product(mw.as_mut(), m.as_ref(), w.as_ref());
    let reference = (0..w.ncols()).map(|c| dot(w.col(c).as_mat(), mw.col(c).as_mat())).fold(0.0, f64::max);
    for pass in 0..2 {
        if dim > 0 {
            for _ in 0..2 {
                let c = mv.subcols(0, dim).transpose() * &w;
                w -= v.subcols(0, dim) * &c;
                mw -= mv.subcols(0, dim) * &c;
            }
        }
        if pass == 1 {
            // M w afresh once: after cancellation the updated M w is not accurate enough for
            // the Gram matrix of a block nearly inside the basis. The first pass's update
            // suffices to drop and scale its directions (two products with M instead of four).
            symmetric_product(mw.as_mut(), m.as_ref(), w.as_ref());
        }
        let g = w.transpose() * &mw;
        let g = Mat::<f64>::from_fn(g.nrows(), g.ncols(), |i, j| 0.5 * (g[(i, j)] + g[(j, i)]));
        let Some((mu, u)) = symmetric_eigen(g.as_ref()) else {
            return dim;
        };
        // Directions whose M-norm fell below 1e-10 of the block's are already in the basis.
        let kept: Vec<usize> = (0..g.nrows()).filter(|&i| mu[i] > 1e-20 * reference).collect();
        if kept.is_empty() || dim + kept.len() > v.ncols() {
            return dim;
        }
        let q = Mat::<f64>::from_fn(g.nrows(), kept.len(), |r, c| u[(r, kept[c])] / mu[kept[c]].sqrt());
        w = &w * &q;
        mw = &mw * &q;
    }
    let nb = w.ncols();
    v.subcols_mut(dim, nb).copy_from(&w);
    mv.subcols_mut(dim, nb).copy_from(&mw);
    dim + nb
}

/// `V[:, 0..keep] ← V[:, 0..dim] Y` for `Y` of `dim × keep` (`keep ≤ dim`), in place by blocks
/// of rows: a row of the product needs only the same row of V, so the restart forms no
/// `n × keep` temporary (two of 161 MB, for V and M V, at 306k DOFs and 66 kept vectors).
fn combine_in_place(v: MatMut<'_, f64>, y: MatRef<'_, f64>) {
    const ROWS: usize = 2048;
    let (dim, keep) = (y.nrows(), y.ncols());
    debug_assert!(keep <= dim && dim <= v.ncols());
    let mut blocks = Vec::with_capacity(v.nrows().div_ceil(ROWS));
    let mut rest = v;
    while rest.nrows() > 0 {
        let rows = ROWS.min(rest.nrows());
        let (head, tail) = rest.split_at_row_mut(rows);
        blocks.push(head);
        rest = tail;
    }
    blocks.into_par_iter().for_each(|block| {
        let product = block.rb().subcols(0, dim) * y;
        block.subcols_mut(0, keep).copy_from(&product);
    });
}

fn projection_failed() -> EigenError {
    EigenError::Factorisation("the projected eigenproblem did not converge".into())
}

fn dot(a: MatRef<'_, f64>, b: MatRef<'_, f64>) -> f64 {
    (0..a.nrows()).map(|i| a[(i, 0)] * b[(i, 0)]).sum()
}

/// Deterministic values in (-0.5, 0.5) (SplitMix64), so runs are reproducible.
fn pseudo_random(i: usize) -> f64 {
    let mut z = (i as u64).wrapping_add(0x9E37_79B9_7F4A_7C15);
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^= z >> 31;
    (z >> 11) as f64 / (1u64 << 53) as f64 - 0.5
}
