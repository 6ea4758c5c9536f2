//! Upper-triangle contributions to two matrices with one pattern (K and M) → full symmetric
//! CSC matrices (M without the zeros of K's pattern).
//!
//! Hand-written rather than faer's `try_new_from_triplets` because K and M share a pattern and
//! are symmetric: contributions are counted per column first, then scattered straight into
//! their column's bucket (one `u32` row and both values, upper triangle only), so no triplet
//! list is ever stored; buckets are sorted and summed column block by column block in
//! parallel, and the upper triangle is mirrored at the end.

use faer::sparse::{SparseColMat, SymbolicSparseColMat};
use rayon::prelude::*;

/// One upper-triangle contribution (`row <= col`) to K and M.
#[derive(Clone, Copy, Debug, Default)]
pub struct Entry {
    pub row: u32,
    pub col: u32,
    pub k: f64,
    pub m: f64,
}

#[derive(Clone, Copy, Debug, Default)]
struct Slot {
    row: u32,
    k: f64,
    m: f64,
}

/// Column buckets of known sizes, filled by [`Builder::push`].
pub struct Builder {
    n: usize,
    ptr: Vec<usize>,
    next: Vec<usize>,
    slots: Vec<Slot>,
}

impl Builder {
    /// Buckets for a matrix of size `n` receiving `counts[j]` contributions in column `j`.
    pub fn new(counts: &[usize]) -> Self {
        let n = counts.len();
        let mut ptr = vec![0usize; n + 1];
        for j in 0..n {
            ptr[j + 1] = ptr[j] + counts[j];
        }
        let next = ptr[..n].to_vec();
        Builder { n, slots: vec![Slot::default(); ptr[n]], ptr, next }
    }

    /// Add one contribution; its column must have room left (as counted).
    pub fn push(&mut self, e: Entry) {
        let p = &mut self.next[e.col as usize];
        assert!(
            *p < self.ptr[e.col as usize + 1],
            "expected {} contributions in column {}, got more",
            self.ptr[e.col as usize + 1] - self.ptr[e.col as usize],
            e.col
        );
        self.slots[*p] = Slot { row: e.row, k: e.k, m: e.m };
        *p += 1;
    }

    /// Sum the contributions and mirror the upper triangle: full symmetric `(K, M)`.
    pub fn finish(self) -> (SparseColMat<usize, f64>, SparseColMat<usize, f64>) {
        let Builder { n, ptr, next, mut slots } = self;
        debug_assert!((0..n).all(|j| next[j] == ptr[j + 1]), "fewer contributions than counted");
        // Sort each column by row and sum duplicates in place, in parallel over blocks of
        // columns; `unique[j]` is the number of distinct rows left at the start of column j.
        let blocks = 64.min(n.max(1));
        let bounds: Vec<usize> = (0..=blocks).map(|b| b * n / blocks).collect();
        let mut pieces = Vec::with_capacity(blocks);
        let mut rest = slots.as_mut_slice();
        for b in 0..blocks {
            let (head, tail) = rest.split_at_mut(ptr[bounds[b + 1]] - ptr[bounds[b]]);
            pieces.push((bounds[b], bounds[b + 1], head));
            rest = tail;
        }
        let unique: Vec<Vec<usize>> = pieces
            .into_par_iter()
            .map(|(c0, c1, piece)| {
                let base = ptr[c0];
                (c0..c1)
                    .map(|j| {
                        let col = &mut piece[ptr[j] - base..ptr[j + 1] - base];
                        col.sort_unstable_by_key(|s| s.row);
                        let mut w = 0;
                        for r in 0..col.len() {
                            if w > 0 && col[w - 1].row == col[r].row {
                                col[w - 1].k += col[r].k;
                                col[w - 1].m += col[r].m;
                            } else {
                                col[w] = col[r];
                                w += 1;
                            }
                        }
                        w
                    })
                    .collect()
            })
            .collect();
        let unique: Vec<usize> = unique.into_iter().flatten().collect();
        // M keeps its non-zeros only: a solid's consistent mass couples a DOF with the same
        // direction of the element's nodes alone, so two thirds of K's pattern are zeros of M
        // (0.44 GB at 306k DOFs). A zero entry adds nothing to a product, so products with M
        // are the same to the last bit.
        let k = mirrored(n, &ptr, &unique, &slots, |s| Some(s.k));
        let m = mirrored(n, &ptr, &unique, &slots, |s| (s.m != 0.0).then_some(s.m));
        drop(slots);
        (k, m)
    }
}

/// The full symmetric matrix of the summed upper-triangle slots, with the entries `value` gives
/// (`None`: not stored). Column i = its upper entries (rows <= i, written at step j = i), then
/// the mirrored entries of the later columns j > i (rows j > i, written in increasing j): each
/// column comes out sorted.
fn mirrored(
    n: usize,
    ptr: &[usize],
    unique: &[usize],
    slots: &[Slot],
    value: impl Fn(&Slot) -> Option<f64>,
) -> SparseColMat<usize, f64> {
    let mut full_ptr = vec![0usize; n + 1];
    for j in 0..n {
        for s in slots[ptr[j]..ptr[j] + unique[j]].iter().filter(|s| value(s).is_some()) {
            full_ptr[j + 1] += 1;
            if s.row as usize != j {
                full_ptr[s.row as usize + 1] += 1;
            }
        }
    }
    for j in 0..n {
        full_ptr[j + 1] += full_ptr[j];
    }
    let nnz = full_ptr[n];
    let mut row_idx = vec![0usize; nnz];
    let mut val = vec![0.0; nnz];
    let mut fill = full_ptr[..n].to_vec();
    for j in 0..n {
        for s in &slots[ptr[j]..ptr[j] + unique[j]] {
            let Some(v) = value(s) else { continue };
            let i = s.row as usize;
            let q = fill[j];
            (row_idx[q], val[q]) = (i, v);
            fill[j] += 1;
            if i != j {
                let q = fill[i];
                (row_idx[q], val[q]) = (j, v);
                fill[i] += 1;
            }
        }
    }
    SparseColMat::new(SymbolicSparseColMat::new_checked(n, n, full_ptr, None, row_idx), val)
}
