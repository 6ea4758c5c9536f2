//! The same decks solved by CalculiX 2.20 (reference files in crates/fe/reference/, made by
//! its regenerate.sh): our first 10 frequencies agree to 1e-4 relative, and our K and M equal
//! CalculiX's exported matrices entry by entry.
//!
//! Frequencies come from `element_support::dense_frequencies` (eigenvalues only): faer 0.24's
//! `self_adjoint_eigen` with eigenvectors returned a wrong lowest eigenpair on the 270-DOF C3D8
//! block (8e-4 off in frequency), which `LinearModel::dense_modes` inherits.

mod element_support;

use std::collections::HashMap;
use std::path::PathBuf;

use stickslip_fe::assembly::FeModel;
use stickslip_fe::mesh::inp;

fn reference(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("reference").join(name)
}

fn read_frequencies(name: &str) -> Vec<f64> {
    let text = std::fs::read_to_string(reference(&format!("{name}.freq"))).unwrap();
    text.lines()
        .filter(|l| !l.starts_with('#'))
        .map(|l| l.split_whitespace().nth(1).unwrap().parse().unwrap())
        .collect()
}

/// A CalculiX matrix file (`i j value`, 1-based upper triangle) as a map.
fn read_matrix(path: PathBuf) -> HashMap<(usize, usize), f64> {
    let text = std::fs::read_to_string(path).unwrap();
    text.lines()
        .map(|l| {
            let f: Vec<&str> = l.split_whitespace().collect();
            ((f[0].parse::<usize>().unwrap() - 1, f[1].parse::<usize>().unwrap() - 1), f[2].parse::<f64>().unwrap())
        })
        .collect()
}

fn compare_frequencies(name: &str) {
    let fe = FeModel::assemble(inp::read(reference(&format!("{name}.inp"))).unwrap()).unwrap();
    let ours = element_support::dense_frequencies(&fe.model);
    let theirs = read_frequencies(name);
    assert_eq!(theirs.len(), 10, "{name}: expected 10 CalculiX frequencies");
    assert_eq!(fe.mesh.modes_requested, Some(10), "{name}: *FREQUENCY asks for 10 modes");
    let worst = ours.iter().zip(&theirs).map(|(a, b)| (a / b - 1.0).abs()).fold(0.0, f64::max);
    println!("{name}: {} DOFs, worst relative frequency difference {worst:.2e}", fe.model.n_dofs());
    for (a, b) in ours.iter().zip(&theirs) {
        println!("  {a:12.4} Hz  CalculiX {b:12.4} Hz");
    }
    // The issue asks for 1e-4. CalculiX prints 7 significant digits (5e-8) and its ARPACK
    // stops at ~4e-7 here: 1e-6 holds with margin and catches any element-level change.
    assert!(worst < 1e-6, "{name}: frequencies differ by {worst:.3e} relative");
}

fn compare_matrices(name: &str) {
    let fe = FeModel::assemble(inp::read(reference(&format!("{name}.inp"))).unwrap()).unwrap();
    let dofs = std::fs::read_to_string(reference(&format!("{name}.dof"))).unwrap();
    // CalculiX row r is DOF "node.direction": our index for it.
    let map: Vec<usize> = dofs
        .lines()
        .map(|l| {
            let (node, dir) = l.trim().split_once('.').unwrap();
            fe.dof(node.parse().unwrap(), dir.parse().unwrap()).unwrap()
        })
        .collect();
    assert_eq!(map.len(), fe.model.n_dofs(), "{name}: same number of DOFs as CalculiX");
    for (ext, ours) in [("sti", &fe.model.stiffness), ("mas", &fe.model.mass)] {
        let ours = ours.to_dense();
        let theirs = read_matrix(reference(&format!("{name}.{ext}")));
        let scale = theirs.values().fold(0.0f64, |m, v| m.max(v.abs()));
        let mut worst = 0.0f64;
        for (&(i, j), &v) in &theirs {
            worst = worst.max((ours[(map[i], map[j])] - v).abs());
        }
        // Entries CalculiX does not store must be zero in ours.
        let mut inverse = vec![0; map.len()];
        for (r, &m) in map.iter().enumerate() {
            inverse[m] = r;
        }
        for j in 0..ours.ncols() {
            for i in 0..=j {
                let (a, b) = (inverse[i].min(inverse[j]), inverse[i].max(inverse[j]));
                if !theirs.contains_key(&(a, b)) {
                    worst = worst.max(ours[(i, j)].abs());
                }
            }
        }
        println!("{name}.{ext}: {} entries, worst difference {:.2e} of the largest", theirs.len(), worst / scale);
        // CalculiX writes 14 significant digits; its element integration is the same as ours.
        assert!(worst / scale < 1e-11, "{name}.{ext}: differs by {:.3e} of the largest entry", worst / scale);
    }
}

#[test]
fn tet4_frequencies_and_matrices_match_calculix() {
    compare_matrices("block_c3d4");
    compare_frequencies("block_c3d4");
}

#[test]
fn tet10_frequencies_and_matrices_match_calculix() {
    compare_matrices("block_c3d10");
    compare_frequencies("block_c3d10");
}

#[test]
fn hex8_frequencies_and_matrices_match_calculix() {
    compare_matrices("block_c3d8");
    compare_frequencies("block_c3d8");
}

#[test]
fn hex20_frequencies_and_matrices_match_calculix() {
    compare_matrices("block_c3d20");
    compare_frequencies("block_c3d20");
}

#[test]
fn hex20r_frequencies_and_matrices_match_calculix() {
    compare_matrices("block_c3d20r");
    compare_frequencies("block_c3d20r");
}

#[test]
fn rigid_coupling_springs_and_mass_match_calculix() {
    // CalculiX carries the reference node's rotations on an extra node, so only the
    // frequencies are compared.
    compare_frequencies("coupled_c3d8");
}

/// `LinearModel::dense_modes` on the 270-DOF C3D8 block: faer 0.24.4's `self_adjoint_eigen`
/// (eigenvalues with vectors) returns wrong eigenvectors here (lowest frequency 8e-4 above
/// CalculiX's); `dense_modes` detects it by the residuals and falls back on the SVD.
#[test]
fn dense_modes_match_calculix_on_the_hex8_block() {
    let fe = FeModel::assemble(inp::read(reference("block_c3d8.inp")).unwrap()).unwrap();
    let modes = fe.model.dense_modes().unwrap();
    let theirs = read_frequencies("block_c3d8");
    let ours = modes.frequencies_hz();
    let worst = ours.iter().zip(&theirs).map(|(a, b)| (a / b - 1.0).abs()).fold(0.0, f64::max);
    assert!(worst < 1e-6, "dense_modes differs from CalculiX by {worst:.3e} relative");
}
