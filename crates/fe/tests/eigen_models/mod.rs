//! Sparse test structures with known modes, built by hand.
#![allow(dead_code)]
use faer::sparse::{SparseColMat, Triplet};

pub type Sparse = SparseColMat<usize, f64>;

pub fn sparse(n: usize, t: &[Triplet<usize, usize, f64>]) -> Sparse {
    SparseColMat::try_new_from_triplets(n, n, t).unwrap()
}

/// Add spring `k` between DOFs `i` and `j` (or to the ground).
pub fn spring(t: &mut Vec<Triplet<usize, usize, f64>>, i: usize, j: Option<usize>, k: f64) {
    t.push(Triplet::new(i, i, k));
    if let Some(j) = j {
        t.push(Triplet::new(j, j, k));
        t.push(Triplet::new(i, j, -k));
        t.push(Triplet::new(j, i, -k));
    }
}

/// `n` equal masses `m` in a chain of springs `k`, the first grounded (fixed-free) or not.
pub fn chain(n: usize, k: f64, m: f64, grounded: bool) -> (Sparse, Sparse) {
    let mut kt = Vec::new();
    if grounded {
        spring(&mut kt, 0, None, k);
    }
    for i in 1..n {
        spring(&mut kt, i - 1, Some(i), k);
    }
    let mt: Vec<_> = (0..n).map(|i| Triplet::new(i, i, m)).collect();
    (sparse(n, &kt), sparse(n, &mt))
}

/// Exact eigenvalues ω² of the grounded (fixed-free) uniform chain:
/// `ω_r = 2 √(k/m) sin((2r − 1)π / (2(2n + 1)))`.
pub fn chain_fixed_free_omega2(n: usize, k: f64, m: f64) -> Vec<f64> {
    (1..=n)
        .map(|r| {
            let s = ((2 * r - 1) as f64 * std::f64::consts::PI / (2.0 * (2 * n + 1) as f64)).sin();
            4.0 * k / m * s * s
        })
        .collect()
}

/// 2-D Laplacian on an `nx × ny` grid of interior points with Dirichlet boundary, unit
/// spacing, with a consistent-like mass `M = I + L/12` (banded, not diagonal, so that the
/// generalised problem is exercised). Eigenvalues: `λ = μ / (1 + μ/12)` with
/// `μ = 4 sin²(iπ/(2(nx+1))) + 4 sin²(jπ/(2(ny+1)))`.
pub fn laplacian_2d(nx: usize, ny: usize) -> (Sparse, Sparse, Vec<f64>) {
    let n = nx * ny;
    let id = |i: usize, j: usize| i + nx * j;
    let mut kt = Vec::new();
    let mut mt = Vec::new();
    for j in 0..ny {
        for i in 0..nx {
            let p = id(i, j);
            kt.push(Triplet::new(p, p, 4.0));
            mt.push(Triplet::new(p, p, 1.0 + 4.0 / 12.0));
            let mut nb = Vec::new();
            if i + 1 < nx {
                nb.push(id(i + 1, j));
            }
            if i > 0 {
                nb.push(id(i - 1, j));
            }
            if j + 1 < ny {
                nb.push(id(i, j + 1));
            }
            if j > 0 {
                nb.push(id(i, j - 1));
            }
            for q in nb {
                kt.push(Triplet::new(p, q, -1.0));
                mt.push(Triplet::new(p, q, -1.0 / 12.0));
            }
        }
    }
    let mut exact = Vec::new();
    for j in 1..=ny {
        for i in 1..=nx {
            let sx = (i as f64 * std::f64::consts::PI / (2.0 * (nx + 1) as f64)).sin();
            let sy = (j as f64 * std::f64::consts::PI / (2.0 * (ny + 1) as f64)).sin();
            let mu = 4.0 * sx * sx + 4.0 * sy * sy;
            exact.push(mu / (1.0 + mu / 12.0));
        }
    }
    exact.sort_by(f64::total_cmp);
    (sparse(n, &kt), sparse(n, &mt), exact)
}

/// A 3-D lattice of point masses (3 DOFs each) joined by axial springs to their 6 neighbours
/// and by weaker diagonal springs in each face plane (which make it stiff in shear), grounded
/// at the `z = 0` layer through springs `k_ground`: a crude elastic block with a few hundred
/// DOFs and coupled directions. DOF `3 p + d` is node `p`, direction `d`.
pub fn lattice_3d(nx: usize, ny: usize, nz: usize, k_ground: f64) -> (Sparse, Sparse) {
    let n_nodes = nx * ny * nz;
    let n = 3 * n_nodes;
    let id = |i: usize, j: usize, k: usize| i + nx * (j + ny * k);
    let pos = |p: usize| [(p % nx) as f64, ((p / nx) % ny) as f64, (p / (nx * ny)) as f64];
    let mut kt = Vec::new();
    let mut bar = |a: usize, b: usize, stiffness: f64| {
        let (pa, pb) = (pos(a), pos(b));
        let d: Vec<f64> = (0..3).map(|c| pb[c] - pa[c]).collect();
        let len = d.iter().map(|x| x * x).sum::<f64>().sqrt();
        let e: Vec<f64> = d.iter().map(|x| x / len).collect();
        for r in 0..3 {
            for c in 0..3 {
                let v = stiffness / len * e[r] * e[c];
                kt.push(Triplet::new(3 * a + r, 3 * a + c, v));
                kt.push(Triplet::new(3 * b + r, 3 * b + c, v));
                kt.push(Triplet::new(3 * a + r, 3 * b + c, -v));
                kt.push(Triplet::new(3 * b + r, 3 * a + c, -v));
            }
        }
    };
    for k in 0..nz {
        for j in 0..ny {
            for i in 0..nx {
                let p = id(i, j, k);
                if i + 1 < nx {
                    bar(p, id(i + 1, j, k), 1.0e6);
                }
                if j + 1 < ny {
                    bar(p, id(i, j + 1, k), 1.0e6);
                }
                if k + 1 < nz {
                    bar(p, id(i, j, k + 1), 1.2e6);
                }
                if i + 1 < nx && j + 1 < ny {
                    bar(p, id(i + 1, j + 1, k), 3.0e5);
                    bar(id(i + 1, j, k), id(i, j + 1, k), 3.0e5);
                }
                if i + 1 < nx && k + 1 < nz {
                    bar(p, id(i + 1, j, k + 1), 3.0e5);
                    bar(id(i + 1, j, k), id(i, j, k + 1), 3.0e5);
                }
                if j + 1 < ny && k + 1 < nz {
                    bar(p, id(i, j + 1, k + 1), 3.0e5);
                    bar(id(i, j + 1, k), id(i, j, k + 1), 3.0e5);
                }
            }
        }
    }
    if k_ground > 0.0 {
        for j in 0..ny {
            for i in 0..nx {
                let p = id(i, j, 0);
                for d in 0..3 {
                    kt.push(Triplet::new(3 * p + d, 3 * p + d, k_ground));
                }
            }
        }
    }
    // Masses vary a little from node to node so that no frequency is repeated by symmetry.
    let mt: Vec<_> = (0..n).map(|i| Triplet::new(i, i, 1.0 + 0.1 * ((i / 3 * 7919) % 13) as f64 / 13.0)).collect();
    (sparse(n, &kt), sparse(n, &mt))
}
