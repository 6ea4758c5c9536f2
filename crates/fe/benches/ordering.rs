//! Fill-reducing orderings on the Harmony-like assembly (paper Section 3.1): factor entries,
//! and times of the LDLᵀ of `K` for faer's approximate minimum degree and METIS's nested
//! dissection (`eigen::ordering`).
//!
//! `cargo bench -p stickslip-fe --bench ordering -- [REFINEMENT ...]` (default 1.0).
use std::time::Instant;

use faer::dyn_stack::{MemBuffer, MemStack};
use faer::sparse::linalg::cholesky::{factorize_symbolic_cholesky, SymmetricOrdering};
use faer::{Par, Side};
use stickslip_fe::assembly::FeModel;
use stickslip_fe::eigen::{ordering, to_sparse};
use stickslip_fe::harmony::{Configuration, Design};

/// An ordering: `None` for faer's minimum degree, else the elimination order.
type Ordering<'a> = dyn Fn() -> Option<Vec<usize>> + 'a;

fn main() {
    let refinements: Vec<f64> = std::env::args().skip(1).filter_map(|a| a.parse().ok()).collect();
    for r in if refinements.is_empty() { vec![1.0] } else { refinements } {
        let mesh = Design::refined(r).build(Configuration::Assembly).expect("mesh");
        let fe = FeModel::assemble(mesh).expect("assembly");
        let k = to_sparse(&fe.model.stiffness).into_owned();
        let n = k.nrows();
        println!("refinement {r}: {n} DOFs, {} stored entries of K", k.compute_nnz());
        let orderings: Vec<(&str, Box<Ordering>)> = vec![
            ("approximate minimum degree (faer)", Box::new(|| None)),
            ("METIS nested dissection", Box::new(|| ordering::metis_nested_dissection(k.symbolic()))),
        ];
        for (name, order) in orderings {
            let t = Instant::now();
            let fwd = order();
            let t_order = t.elapsed().as_secs_f64();
            let t = Instant::now();
            let inv = fwd.as_ref().map(|f| ordering::inverse(f));
            let how = match (&fwd, &inv) {
                (Some(f), Some(i)) => SymmetricOrdering::Custom(faer::perm::PermRef::new_checked(f, i, n)),
                _ => SymmetricOrdering::Amd,
            };
            let sym =
                factorize_symbolic_cholesky(k.symbolic(), Side::Lower, how, Default::default()).expect("symbolic");
            let t_sym = t.elapsed().as_secs_f64();
            let t = Instant::now();
            let mut values = vec![0.0; sym.len_val()];
            let par = Par::rayon(0);
            let mut mem = MemBuffer::new(sym.factorize_numeric_ldlt_scratch::<f64>(par, Default::default()));
            sym.factorize_numeric_ldlt(
                &mut values,
                k.as_ref(),
                Side::Lower,
                Default::default(),
                par,
                MemStack::new(&mut mem),
                Default::default(),
            )
            .expect("numeric");
            let t_num = t.elapsed().as_secs_f64();
            println!(
                "  {name:36} factor {:6.1} M entries ({:5.0} MiB)  ordering {t_order:6.2} s  symbolic {t_sym:6.2} s  numeric {t_num:6.2} s",
                sym.len_val() as f64 / 1e6,
                sym.len_val() as f64 * 8.0 / 1048576.0
            );
        }
    }
}
