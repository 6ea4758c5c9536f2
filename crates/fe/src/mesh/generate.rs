//! Structured box meshes of hex8, hex20, tet4 and tet10 elements with named face node sets,
//! for tests and benchmarks.
//!
//! Nodes sit on a lattice with `order` (1 or 2) points per cell edge; hexahedra take the
//! lattice cells, tetrahedra split each cell into the six tetrahedra around its main diagonal
//! (Kuhn's subdivision, conforming because every cell is split the same way); quadratic
//! elements take their mid-edge nodes from the lattice, and unused lattice points are dropped.

use super::{Material, Mesh, Solid};
use crate::element::shape::{HEX_NODES, TET10_EDGES};
use crate::element::SolidKind;

/// Name of the material given to generated meshes.
pub const MATERIAL: &str = "MATERIAL";

/// A box `[0, lengths[0]] × [0, lengths[1]] × [0, lengths[2]]` with `cells` cells per
/// direction, of elements `kind` and material `material`. Node sets `XMIN`, `XMAX`, `YMIN`,
/// `YMAX`, `ZMIN`, `ZMAX` hold the nodes of each face; element set `ALL` holds every element.
pub fn box_mesh(lengths: [f64; 3], cells: [usize; 3], kind: SolidKind, material: Material) -> Mesh {
    assert!(cells.iter().all(|&c| c > 0), "expected at least one cell per direction, got {cells:?}");
    let order = match kind {
        SolidKind::Tet4 | SolidKind::Hex8 => 1,
        _ => 2,
    };
    let dims = cells.map(|c| order * c + 1);
    let lattice = |p: [usize; 3]| p[0] + dims[0] * (p[1] + dims[1] * p[2]);
    let mut elements: Vec<Vec<usize>> = Vec::new();
    for k in 0..cells[2] {
        for j in 0..cells[1] {
            for i in 0..cells[0] {
                let base = [order * i, order * j, order * k];
                // Lattice point at natural coordinates ξ ∈ {−1, 0, 1}³ of the cell.
                let at = |xi: [f64; 3]| {
                    lattice([0, 1, 2].map(|d| base[d] + ((xi[d] + 1.0) * 0.5 * order as f64).round() as usize))
                };
                match kind {
                    SolidKind::Hex8 | SolidKind::Hex20 | SolidKind::Hex20R => {
                        elements.push(HEX_NODES[..kind.n_nodes()].iter().map(|&xi| at(xi)).collect());
                    }
                    SolidKind::Tet4 | SolidKind::Tet10 => {
                        for perm in [[0, 1, 2], [0, 2, 1], [1, 0, 2], [1, 2, 0], [2, 0, 1], [2, 1, 0]] {
                            // Corners in cell units: 0, e_p0, e_p0 + e_p1, (1, 1, 1).
                            let mut c = [[0usize; 3]; 4];
                            c[1][perm[0]] = 1;
                            c[2] = c[1];
                            c[2][perm[1]] = 1;
                            c[3] = [1, 1, 1];
                            // Odd permutations give negative volumes: swap two corners.
                            if matches!(perm, [0, 2, 1] | [1, 0, 2] | [2, 1, 0]) {
                                c.swap(1, 2);
                            }
                            let corner = |v: [usize; 3]| [0, 1, 2].map(|d| base[d] + order * v[d]);
                            let mut nodes: Vec<usize> = c.iter().map(|&v| lattice(corner(v))).collect();
                            if kind == SolidKind::Tet10 {
                                for &(a, b) in &TET10_EDGES {
                                    let (pa, pb) = (corner(c[a]), corner(c[b]));
                                    nodes.push(lattice([0, 1, 2].map(|d| (pa[d] + pb[d]) / 2)));
                                }
                            }
                            elements.push(nodes);
                        }
                    }
                }
            }
        }
    }
    // Keep the lattice points the elements use, numbered in lattice order from 1.
    let n_lattice = dims[0] * dims[1] * dims[2];
    let mut index = vec![usize::MAX; n_lattice];
    for e in &elements {
        for &p in e {
            index[p] = 0;
        }
    }
    let mut mesh = Mesh::default();
    let spacing = [0, 1, 2].map(|d| lengths[d] / (dims[d] - 1) as f64);
    let mut faces: [Vec<usize>; 6] = Default::default();
    for (p, slot) in index.iter_mut().enumerate() {
        if *slot == usize::MAX {
            continue;
        }
        let ijk = [p % dims[0], (p / dims[0]) % dims[1], p / (dims[0] * dims[1])];
        let n = mesh.add_node(mesh.nodes.len() as u64 + 1, [0, 1, 2].map(|d| ijk[d] as f64 * spacing[d])).unwrap();
        *slot = n;
        for d in 0..3 {
            if ijk[d] == 0 {
                faces[2 * d].push(n);
            }
            if ijk[d] == dims[d] - 1 {
                faces[2 * d + 1].push(n);
            }
        }
    }
    for (name, nodes) in ["XMIN", "XMAX", "YMIN", "YMAX", "ZMIN", "ZMAX"].iter().zip(faces) {
        mesh.add_node_set(name, nodes);
    }
    mesh.materials.push((MATERIAL.into(), material));
    for (e, nodes) in elements.into_iter().enumerate() {
        let nodes = nodes.into_iter().map(|p| index[p]).collect();
        mesh.solids.push(Solid { id: e as u64 + 1, kind, nodes, material: Some(0) });
    }
    mesh.element_sets.insert("ALL".into(), (0..mesh.solids.len()).collect());
    mesh
}
