//! Assemble a generated box mesh and report its size and the time of each stage; run under
//! `/usr/bin/time -v` for the peak memory:
//!
//! `cargo run --release -p stickslip-fe --example assemble_box -- tet10 64 14 12`
//! (64 × 14 × 12 cells of six tet10: 280,575 DOFs, the paper's model size).

use std::time::Instant;

use stickslip_fe::assembly::FeModel;
use stickslip_fe::element::SolidKind;
use stickslip_fe::mesh::generate::box_mesh;
use stickslip_fe::mesh::Material;

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let usage =
        "usage: assemble_box KIND NX NY NZ (KIND: C3D4, C3D10, C3D8, C3D20, C3D20R or tet4, tet10, hex8, hex20)";
    if args.len() != 4 {
        eprintln!("{usage}");
        std::process::exit(2);
    }
    let kind = match args[0].to_lowercase().as_str() {
        "tet4" => Some(SolidKind::Tet4),
        "tet10" => Some(SolidKind::Tet10),
        "hex8" => Some(SolidKind::Hex8),
        "hex20" => Some(SolidKind::Hex20),
        other => SolidKind::from_abaqus(other),
    }
    .unwrap_or_else(|| {
        eprintln!("{usage}");
        std::process::exit(2)
    });
    let cells: Vec<usize> = args[1..].iter().map(|a| a.parse().expect("cell counts are integers")).collect();
    let steel = Material { young: 210e9, poisson: 0.3, density: 7800.0 };
    let t = Instant::now();
    let mut mesh = box_mesh([1.0, 0.2, 0.2], [cells[0], cells[1], cells[2]], kind, steel);
    let clamped: Vec<usize> = mesh.node_set("XMIN").unwrap().to_vec();
    mesh.fixed = clamped.iter().flat_map(|&n| (1..=3).map(move |d| (n, d))).collect();
    let t_mesh = t.elapsed();
    let (n_nodes, n_elements) = (mesh.nodes.len(), mesh.solids.len());
    let t = Instant::now();
    let fe = FeModel::assemble(mesh).expect("assembly");
    let t_assembly = t.elapsed();
    let nnz = match &fe.model.stiffness {
        stickslip_core::model::Matrix::Sparse(k) => k.compute_nnz(),
        _ => unreachable!(),
    };
    println!(
        "{kind:?} {cells:?}: {n_nodes} nodes, {n_elements} elements, {} DOFs, {nnz} nonzeros in K (and M); \
         mesh {:.3} s, assembly of K and M {:.3} s ({} threads)",
        fe.model.n_dofs(),
        t_mesh.as_secs_f64(),
        t_assembly.as_secs_f64(),
        rayon::current_num_threads()
    );
}
