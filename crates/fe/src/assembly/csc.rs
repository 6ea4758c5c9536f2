//! Upper-triangle triplets of two matrices with one pattern (K and M) → full symmetric CSC.
//!
//! Hand-written rather than faer's `try_new_from_triplets` because K and M share a pattern and
//! are symmetric: storing each contribution once (upper triangle, `u32` indices, both values)
//! halves the triplet memory, which dominates the peak of a 280k-DOF assembly.

use faer::sparse::{SparseColMat, SymbolicSparseColMat};

/// One upper-triangle contribution (`row <= col`) to K and M.
#[derive(Clone, Copy, Debug, Default)]
pub struct Entry {
    pub row: u32,
    pub col: u32,
    pub k: f64,
    pub m: f64,
}

/// Sum the contributions and mirror the upper triangle: full symmetric `(K, M)` of size `n`.
pub fn build(n: usize, entries: Vec<Entry>) -> (SparseColMat<usize, f64>, SparseColMat<usize, f64>) {
    // Counting sort by column.
    let mut ptr = vec![0usize; n + 1];
    for e in &entries {
        ptr[e.col as usize + 1] += 1;
    }
    for j in 0..n {
        ptr[j + 1] += ptr[j];
    }
    let mut next = ptr.clone();
    let mut rows = vec![0u32; entries.len()];
    let mut vals = vec![(0.0f64, 0.0f64); entries.len()];
    for e in &entries {
        let p = &mut next[e.col as usize];
        rows[*p] = e.row;
        vals[*p] = (e.k, e.m);
        *p += 1;
    }
    drop(entries);
    // Sort each column by row and sum duplicates, compacting in place.
    let mut upper_ptr = vec![0usize; n + 1];
    let mut w = 0;
    let mut perm: Vec<usize> = Vec::new();
    let mut tmp: Vec<(u32, f64, f64)> = Vec::new();
    for j in 0..n {
        let (s, e) = (ptr[j], ptr[j + 1]);
        perm.clear();
        perm.extend(s..e);
        perm.sort_unstable_by_key(|&p| rows[p]);
        tmp.clear();
        for &p in &perm {
            match tmp.last_mut() {
                Some(last) if last.0 == rows[p] => {
                    last.1 += vals[p].0;
                    last.2 += vals[p].1;
                }
                _ => tmp.push((rows[p], vals[p].0, vals[p].1)),
            }
        }
        for &(r, k, m) in &tmp {
            rows[w] = r;
            vals[w] = (k, m);
            w += 1;
        }
        upper_ptr[j + 1] = w;
    }
    rows.truncate(w);
    vals.truncate(w);
    // Full pattern: column i = its upper entries (rows <= i, written at step j = i), then the
    // mirrored entries of the later columns j > i (rows j > i, written in increasing j): each
    // column comes out sorted.
    let mut full_count = vec![0usize; n + 1];
    for j in 0..n {
        for p in upper_ptr[j]..upper_ptr[j + 1] {
            let i = rows[p] as usize;
            full_count[j + 1] += 1;
            if i != j {
                full_count[i + 1] += 1;
            }
        }
    }
    for j in 0..n {
        full_count[j + 1] += full_count[j];
    }
    let nnz = full_count[n];
    let mut row_idx = vec![0usize; nnz];
    let mut kval = vec![0.0; nnz];
    let mut mval = vec![0.0; nnz];
    let mut fill = full_count.clone();
    for j in 0..n {
        for p in upper_ptr[j]..upper_ptr[j + 1] {
            let q = fill[j];
            row_idx[q] = rows[p] as usize;
            (kval[q], mval[q]) = vals[p];
            fill[j] += 1;
        }
        // Mirror column j's strictly upper entries into the columns of their rows.
        for p in upper_ptr[j]..upper_ptr[j + 1] {
            let i = rows[p] as usize;
            if i != j {
                let q = fill[i];
                row_idx[q] = j;
                (kval[q], mval[q]) = vals[p];
                fill[i] += 1;
            }
        }
    }
    let symbolic = SymbolicSparseColMat::new_checked(n, n, full_count, None, row_idx);
    let k = SparseColMat::new(symbolic.clone(), kval);
    let m = SparseColMat::new(symbolic, mval);
    (k, m)
}
