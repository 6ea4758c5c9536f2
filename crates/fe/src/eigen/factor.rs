//! Sparse LDLᵀ factorisation of `K − σM`, the operator of shift-invert eigensolvers and of
//! static condensation. The symbolic analysis (ordering, elimination tree, supernodes) is
//! done once per sparsity pattern and shared; new shifts only redo the numeric part.
//! Fill-reducing ordering: METIS's nested dissection (minimum degree on small models).
use std::sync::Arc;

use faer::dyn_stack::{MemBuffer, MemStack};
use faer::sparse::linalg::cholesky::{
    factorize_symbolic_cholesky, supernodal::SupernodalLdltRef, CholeskySymbolicParams, LdltRef, SymbolicCholesky,
    SymbolicCholeskyRaw, SymmetricOrdering,
};
use faer::sparse::{SparseColMat, SparseColMatRef};
use faer::{Conj, MatMut, Par, Side};

use super::EigenError;

/// A pivot smaller than this fraction of its diagonal entry means `K − σM` is singular to
/// working precision: a mechanism (rigid-body motion at σ = 0) or a shift on an eigenvalue.
/// Genuine pivots of FE matrices, even with connectors 1e6 times stiffer than the solid, stay
/// above ~1e-8 of their diagonal; cancellation in a true singular pivot leaves ~1e-13.
const SINGULAR_PIVOT_RATIO: f64 = 1e-10;

/// `(K − σM)⁻¹` applied to blocks of vectors: what a shift-invert eigensolver needs of a
/// factorisation ([`ShiftedFactor`], or a low-rank update of one, [`super::LowRankUpdate`]).
pub trait ShiftInvert: Sync {
    /// The shift σ in rad²/s².
    fn shift(&self) -> f64;
    /// Number of eigenvalues of `(K, M)` below σ.
    fn eigenvalues_below_shift(&self) -> usize;
    /// Overwrite each column of `rhs` with `(K − σM)⁻¹ rhs`.
    fn solve_in_place(&self, rhs: MatMut<'_, f64>);
}

impl ShiftInvert for ShiftedFactor {
    fn shift(&self) -> f64 {
        ShiftedFactor::shift(self)
    }
    fn eigenvalues_below_shift(&self) -> usize {
        ShiftedFactor::eigenvalues_below_shift(self)
    }
    fn solve_in_place(&self, rhs: MatMut<'_, f64>) {
        ShiftedFactor::solve_in_place(self, rhs)
    }
}

/// Up to this order the minimum-degree ordering is analysed beside METIS's (its analysis costs
/// 4.4 s at 306k DOFs, where it never wins on a 3-D mesh).
const AMD_ALSO_BELOW: usize = 100_000;

/// `K − σM = P L D Lᵀ Pᵀ` with the symbolic part reusable for another shift.
pub struct ShiftedFactor {
    symbolic: Arc<SymbolicCholesky<usize>>,
    values: Vec<f64>,
    shift: f64,
    negative_pivots: usize,
    par: Par,
    /// Whether the analysed pattern holds M's (false after a factorisation of K alone).
    pattern_has_mass: bool,
}

impl ShiftedFactor {
    /// Symbolic analysis and numeric factorisation of `K − σM` (`mass` may be `None` for K
    /// alone). Both matrices are full symmetric CSC with sorted row indices; only the lower
    /// triangle is read.
    pub fn new(
        stiffness: SparseColMatRef<'_, usize, f64>,
        mass: Option<SparseColMatRef<'_, usize, f64>>,
        shift: f64,
    ) -> Result<Self, EigenError> {
        // At σ = 0 K itself is factorised: no copy of it (0.66 GB at 306k DOFs), and a pattern
        // that may lack M's entries (see `refactor`).
        let owned;
        let (a, pattern_has_mass) = match mass {
            Some(m) if shift != 0.0 => {
                owned = shifted(stiffness, Some(m), shift)?;
                (owned.as_ref(), true)
            }
            _ => (stiffness, mass.is_none()),
        };
        let symbolic = analyse(a)?;
        // Reported before the numeric factorisation allocates it: on a large model the
        // factor is the largest single allocation (1.8 GB at 306k DOFs).
        let entries = symbolic.len_val();
        crate::memory::note(&format!(
            "factor of {}: {:.1} M entries, {:.2} GB (symbolic analysis, before factorising)",
            if shift == 0.0 { "K" } else { "K - sigma M" },
            entries as f64 / 1e6,
            8.0 * entries as f64 / 1e9
        ));
        crate::memory::stage("symbolic analysis");
        check_memory(entries, available_memory())?;
        let mut f = ShiftedFactor {
            symbolic: Arc::new(symbolic),
            values: Vec::new(),
            shift,
            negative_pivots: 0,
            par: Par::rayon(0),
            pattern_has_mass,
        };
        f.factor_numeric(a)?;
        crate::memory::stage("numeric factorisation");
        Ok(f)
    }

    /// Factorise `K − σ'M` for a new shift, reusing the symbolic analysis.
    pub fn refactor(
        &mut self,
        stiffness: SparseColMatRef<'_, usize, f64>,
        mass: Option<SparseColMatRef<'_, usize, f64>>,
        shift: f64,
    ) -> Result<(), EigenError> {
        let a = shifted(stiffness, mass, shift)?;
        if mass.is_some() && !self.pattern_has_mass {
            self.symbolic = Arc::new(analyse(a.as_ref())?);
            self.pattern_has_mass = true;
        }
        self.shift = shift;
        self.factor_numeric(a.as_ref())
    }

    fn factor_numeric(&mut self, a: SparseColMatRef<'_, usize, f64>) -> Result<(), EigenError> {
        let symbolic = &*self.symbolic;
        self.values.clear();
        self.values.resize(symbolic.len_val(), 0.0);
        let mut mem = MemBuffer::new(symbolic.factorize_numeric_ldlt_scratch::<f64>(self.par, Default::default()));
        symbolic
            .factorize_numeric_ldlt(
                &mut self.values,
                a,
                Side::Lower,
                Default::default(),
                self.par,
                MemStack::new(&mut mem),
                Default::default(),
            )
            .map_err(|_| EigenError::Singular { shift: self.shift, dof: None })?;
        // Inspect D: its signs count the eigenvalues below σ (Sylvester's law of inertia) and
        // a pivot at round-off level of its diagonal means a singular matrix.
        let n = a.nrows();
        let mut diag_a = vec![0.0; n];
        for (j, d) in diag_a.iter_mut().enumerate() {
            let rows = a.symbolic().row_idx_of_col_raw(j);
            if let Ok(p) = rows.binary_search(&j) {
                *d = a.val_of_col(j)[p];
            }
        }
        let pivots = self.pivots();
        let fwd: Vec<usize> = match symbolic.perm() {
            Some(p) => p.arrays().0.to_vec(),
            None => (0..n).collect(),
        };
        self.negative_pivots = 0;
        for (i, &d) in pivots.iter().enumerate() {
            let original = fwd[i];
            let scale = diag_a[original].abs();
            if d.abs() <= SINGULAR_PIVOT_RATIO * scale || d == 0.0 || !d.is_finite() {
                return Err(EigenError::Singular { shift: self.shift, dof: Some(original) });
            }
            if d < 0.0 {
                self.negative_pivots += 1;
            }
        }
        Ok(())
    }

    /// The diagonal `D` in elimination order.
    fn pivots(&self) -> Vec<f64> {
        let symbolic = &*self.symbolic;
        let mut d = Vec::with_capacity(symbolic.nrows());
        match symbolic.raw() {
            SymbolicCholeskyRaw::Simplicial(s) => {
                let factor = s.factor();
                for j in 0..s.nrows() {
                    let range = factor.col_range(j);
                    let rows = &s.row_idx()[range.clone()];
                    let pos = rows.iter().position(|&i| i == j).map(|p| range.start + p);
                    d.push(pos.map(|p| self.values[p]).unwrap_or(0.0));
                }
            }
            SymbolicCholeskyRaw::Supernodal(s) => {
                let ldlt = SupernodalLdltRef::new(s, &self.values);
                for k in 0..s.n_supernodes() {
                    let block = ldlt.supernode(k).val();
                    for i in 0..block.ncols() {
                        d.push(block[(i, i)]);
                    }
                }
            }
        }
        d
    }

    /// The shift σ of the factorised `K − σM`, in rad²/s².
    pub fn shift(&self) -> f64 {
        self.shift
    }

    /// Number of eigenvalues of `(K, M)` below σ (negative pivots of D).
    pub fn eigenvalues_below_shift(&self) -> usize {
        self.negative_pivots
    }

    /// Order of the matrix.
    pub fn n(&self) -> usize {
        self.symbolic.nrows()
    }

    /// Stored entries of the factor (memory is 8 bytes each).
    pub fn factor_entries(&self) -> usize {
        self.values.len()
    }

    /// Overwrite each column of `rhs` with `(K − σM)⁻¹ rhs`.
    pub fn solve_in_place(&self, rhs: MatMut<'_, f64>) {
        let ldlt = LdltRef::new(&self.symbolic, &self.values);
        let mut mem = MemBuffer::new(self.symbolic.solve_in_place_scratch::<f64>(rhs.ncols(), self.par));
        ldlt.solve_in_place_with_conj(Conj::No, rhs, self.par, MemStack::new(&mut mem));
    }
}

/// Symbolic analysis of the pattern of `a`: ordering, elimination tree, supernodes.
fn analyse(a: SparseColMatRef<'_, usize, f64>) -> Result<SymbolicCholesky<usize>, EigenError> {
    // METIS's nested dissection leaves the smallest factor on 3-D meshes (Harmony at
    // 306k DOFs: 220 M entries against 299 M for minimum degree, numeric factorisation
    // 10 s against 34 s; BENCHMARKS.md). Minimum degree can win on small or thin models,
    // where its analysis is cheap: both are analysed there and the smaller factor kept.
    let analyse_with = |ordering: SymmetricOrdering<'_, usize>| {
        factorize_symbolic_cholesky(a.symbolic(), Side::Lower, ordering, CholeskySymbolicParams::default())
            .map_err(|e| EigenError::Factorisation(format!("symbolic analysis failed: {e:?}")))
    };
    let metis = super::ordering::metis_nested_dissection(a.symbolic()).map(|fwd| {
        let inv = super::ordering::inverse(&fwd);
        (fwd, inv)
    });
    Ok(match &metis {
        Some((fwd, inv)) => {
            let nd = analyse_with(SymmetricOrdering::Custom(faer::perm::PermRef::new_checked(fwd, inv, a.nrows())))?;
            if a.nrows() <= AMD_ALSO_BELOW {
                let amd = analyse_with(SymmetricOrdering::Amd)?;
                if amd.len_val() < nd.len_val() {
                    amd
                } else {
                    nd
                }
            } else {
                nd
            }
        }
        None => analyse_with(SymmetricOrdering::Amd)?,
    })
}

/// The factor's size is known once the symbolic analysis is done: refuse it, with the estimate,
/// when it would not fit in the memory available, instead of being killed or aborting on the
/// allocation. Half the available memory is left for K, M and the eigensolver's blocks.
fn check_memory(entries: usize, available_bytes: Option<u64>) -> Result<(), EigenError> {
    let Some(available) = available_bytes else { return Ok(()) };
    let needed = 8.0 * entries as f64;
    if needed > 0.5 * available as f64 {
        return Err(EigenError::FactorTooLarge {
            entries,
            needed_gb: needed / 1e9,
            available_gb: available as f64 / 1e9,
        });
    }
    Ok(())
}

/// `MemAvailable` of `/proc/meminfo` in bytes (Linux); `None` where it cannot be read.
fn available_memory() -> Option<u64> {
    let info = std::fs::read_to_string("/proc/meminfo").ok()?;
    let kb: u64 = info
        .lines()
        .find_map(|l| l.strip_prefix("MemAvailable:"))?
        .trim()
        .trim_end_matches("kB")
        .trim()
        .parse()
        .ok()?;
    Some(kb * 1024)
}

/// `K − σM` on the union of the two patterns (`K` alone without mass).
fn shifted(
    k: SparseColMatRef<'_, usize, f64>,
    m: Option<SparseColMatRef<'_, usize, f64>>,
    sigma: f64,
) -> Result<SparseColMat<usize, f64>, EigenError> {
    let built = match m {
        // The union pattern even for σ = 0, so that a later shift reuses the symbolic part.
        Some(m) => {
            faer::sparse::ops::binary_op(k, m, |a, b| a.copied().unwrap_or(0.0) - sigma * b.copied().unwrap_or(0.0))
        }
        None => k.transpose().to_col_major(), // K is symmetric: its transpose is itself
    };
    built.map_err(|e| EigenError::Factorisation(format!("cannot form K - sigma M: {e:?}")))
}

#[cfg(test)]
mod tests {
    use super::{available_memory, check_memory};
    use crate::eigen::EigenError;

    #[test]
    fn a_factor_larger_than_half_the_available_memory_is_refused_with_its_size() {
        // 300 M entries (2.4 GB) with 4 GB available: refused, naming both figures.
        let e = check_memory(300_000_000, Some(4_000_000_000)).unwrap_err();
        assert!(matches!(e, EigenError::FactorTooLarge { entries: 300_000_000, .. }));
        let text = e.to_string();
        assert!(text.contains("2.4 GB") && text.contains("4.0 GB"), "{text}");
        // With 24 GB it fits; without a reading nothing is refused.
        assert!(check_memory(300_000_000, Some(24_000_000_000)).is_ok());
        assert!(check_memory(usize::MAX / 16, None).is_ok());
        // This machine reports its available memory (Linux).
        if cfg!(target_os = "linux") {
            assert!(available_memory().is_some_and(|b| b > 0));
        }
    }
}
