//! The sparse eigensolver on a clamped tet10 slab (0.4 × 0.2 × 0.1 m, steel) for a number of
//! modes: wall time of the factorisation and of the iteration, block solves, restarts and the
//! worst residual `‖Kφ − ω²Mφ‖ / ‖Kφ‖`.
//!
//! `cargo bench -p stickslip-fe --bench eigen -- [COUNT ...] [--cells NX,NY,NZ]`
//! (default: 34 100 300 modes of the 20 × 10 × 5-cell slab, 25,830 DOFs).
use std::time::Instant;

use stickslip_fe::assembly::FeModel;
use stickslip_fe::eigen::{modes_with_factor, to_sparse, EigenOptions, ShiftedFactor};
use stickslip_fe::element::SolidKind;
use stickslip_fe::mesh::generate::box_mesh;
use stickslip_fe::mesh::Material;

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let mut cells = [20, 10, 5];
    let mut counts = Vec::new();
    let mut it = args.iter();
    while let Some(a) = it.next() {
        if a == "--cells" {
            let v: Vec<usize> = it.next().expect("NX,NY,NZ").split(',').map(|x| x.parse().expect("a count")).collect();
            cells = [v[0], v[1], v[2]];
        } else if let Ok(c) = a.parse::<usize>() {
            counts.push(c);
        }
    }
    if counts.is_empty() {
        counts = vec![34, 100, 300];
    }
    let steel = Material { young: 2.1e11, poisson: 0.3, density: 7800.0 };
    let mut mesh = box_mesh([0.4, 0.2, 0.1], cells, SolidKind::Tet10, steel);
    for i in mesh.node_set("ZMIN").expect("box meshes name their faces").to_vec() {
        for d in 1..=3 {
            mesh.fixed.push((i, d));
        }
    }
    let fe = FeModel::assemble(mesh).expect("assembly");
    let (k, m) = (to_sparse(&fe.model.stiffness), to_sparse(&fe.model.mass));
    let (k, m) = (k.into_owned(), m.into_owned());
    let t = Instant::now();
    let factor = ShiftedFactor::new(k.as_ref(), Some(m.as_ref()), 0.0).expect("factor");
    println!(
        "slab {cells:?}: {} DOFs, factor {:.1} M entries in {:.2} s",
        k.nrows(),
        factor.factor_entries() as f64 / 1e6,
        t.elapsed().as_secs_f64()
    );
    for count in counts {
        let t = Instant::now();
        match modes_with_factor(&k, &m, &factor, &EigenOptions { count, ..Default::default() }) {
            Ok(sol) => println!(
                "  {count:4} modes: {:7.2} s, {:5} solves, {:3} restarts, worst residual {:.1e}, f1 {:.3} Hz, f{count} {:.3} Hz",
                t.elapsed().as_secs_f64(),
                sol.solves,
                sol.restarts,
                sol.residuals.iter().cloned().fold(0.0, f64::max),
                sol.modes.frequencies_hz()[0],
                sol.modes.frequencies_hz()[count - 1],
            ),
            Err(e) => println!("  {count:4} modes: {:7.2} s, error: {e}", t.elapsed().as_secs_f64()),
        }
    }
}
