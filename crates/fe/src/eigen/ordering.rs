//! Fill-reducing ordering of the graph of a sparse symmetric matrix: METIS's nested
//! dissection, through its C library (built from source by `metis-sys`).
//!
//! faer offers approximate minimum degree, which on 3-D meshes of a few hundred thousand DOFs
//! leaves far more fill than nested dissection (the ordering of METIS and SPOOLES): 299 M
//! against 220 M factor entries on the 306k-DOF Harmony model (`benches/ordering.rs`). A
//! breadth-first nested dissection written here before did worse than both (816 M) and was
//! replaced by METIS.
use faer::sparse::SymbolicSparseColMatRef;

/// METIS's multilevel nested dissection (`METIS_NodeND`, Karypis & Kumar, SIAM J. Sci. Comput.
/// 20, 1998): `fwd[i]` = original index of the vertex eliminated `i`-th. METIS compresses the
/// vertices of identical adjacency (the three DOFs of a node) itself. `None` when the graph is
/// too large for METIS's 32-bit indices or METIS fails; the caller then uses another ordering.
pub fn metis_nested_dissection(a: SymbolicSparseColMatRef<'_, usize>) -> Option<Vec<usize>> {
    let n = a.ncols();
    let mut xadj: Vec<i32> = Vec::with_capacity(n + 1);
    let mut adjncy: Vec<i32> = Vec::with_capacity(a.compute_nnz());
    xadj.push(0);
    for j in 0..n {
        adjncy.extend(a.row_idx_of_col_raw(j).iter().filter(|&&i| i != j).map(|&i| i as i32));
        xadj.push(i32::try_from(adjncy.len()).ok()?);
    }
    let mut nvtxs = i32::try_from(n).ok()?;
    let mut options = [0i32; metis_sys::METIS_NOPTIONS as usize];
    let mut perm = vec![0i32; n];
    let mut iperm = vec![0i32; n];
    // SAFETY: METIS reads `nvtxs`, `xadj` (n + 1 offsets) and `adjncy` (their targets, all in
    // 0..n: the pattern's row indices) and writes n entries into `perm` and `iperm`; `options`
    // has METIS_NOPTIONS entries, set to the defaults first; no weights (null).
    let status = unsafe {
        metis_sys::METIS_SetDefaultOptions(options.as_mut_ptr());
        metis_sys::METIS_NodeND(
            &mut nvtxs,
            xadj.as_mut_ptr(),
            adjncy.as_mut_ptr(),
            std::ptr::null_mut(),
            options.as_mut_ptr(),
            perm.as_mut_ptr(),
            iperm.as_mut_ptr(),
        )
    };
    if status != metis_sys::rstatus_et_METIS_OK {
        return None;
    }
    // METIS's `perm[i]` is the original index of row i of the permuted matrix.
    let fwd: Vec<usize> = perm.into_iter().map(|p| p as usize).collect();
    let mut seen = vec![false; n];
    fwd.iter().all(|&f| f < n && !std::mem::replace(&mut seen[f], true)).then_some(fwd)
}

/// Inverse of a permutation.
pub fn inverse(fwd: &[usize]) -> Vec<usize> {
    let mut inv = vec![0; fwd.len()];
    for (i, &f) in fwd.iter().enumerate() {
        inv[f] = i;
    }
    inv
}

#[cfg(test)]
mod tests {
    use faer::sparse::{SparseColMat, Triplet};

    /// 5-point grid graph of `nx × ny` vertices.
    fn grid(nx: usize, ny: usize) -> SparseColMat<usize, f64> {
        let id = |i: usize, j: usize| i + nx * j;
        let mut t = Vec::new();
        for j in 0..ny {
            for i in 0..nx {
                t.push(Triplet::new(id(i, j), id(i, j), 4.0));
                if i + 1 < nx {
                    t.push(Triplet::new(id(i, j), id(i + 1, j), -1.0));
                    t.push(Triplet::new(id(i + 1, j), id(i, j), -1.0));
                }
                if j + 1 < ny {
                    t.push(Triplet::new(id(i, j), id(i, j + 1), -1.0));
                    t.push(Triplet::new(id(i, j + 1), id(i, j), -1.0));
                }
            }
        }
        SparseColMat::try_new_from_triplets(nx * ny, nx * ny, &t).unwrap()
    }

    #[test]
    fn is_a_permutation_and_beats_the_natural_order() {
        let a = grid(60, 40);
        let fwd = super::metis_nested_dissection(a.symbolic()).expect("METIS orders a grid");
        let mut seen = vec![false; fwd.len()];
        for &f in &fwd {
            assert!(!seen[f], "index {f} twice");
            seen[f] = true;
        }
        assert!(seen.iter().all(|s| *s));
        // Fill: nested dissection of a 2-D grid gives O(n log n) entries in the factor, the
        // natural (banded) order n × 60 here; require less than half of it.
        use faer::sparse::linalg::cholesky::{factorize_symbolic_cholesky, SymmetricOrdering};
        let inv = super::inverse(&fwd);
        let perm = faer::perm::PermRef::new_checked(&fwd, &inv, fwd.len());
        let fill =
            |o| factorize_symbolic_cholesky(a.symbolic(), faer::Side::Lower, o, Default::default()).unwrap().len_val();
        let (nd, natural) = (fill(SymmetricOrdering::Custom(perm)), fill(SymmetricOrdering::Identity));
        assert!(2 * nd < natural, "nested dissection {nd} vs natural {natural}");
    }
}
