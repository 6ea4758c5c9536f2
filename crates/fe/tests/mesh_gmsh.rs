//! Gmsh .msh 4.1 meshes written by Gmsh 4.15 (tests/data/make_msh.py), ASCII and binary.

mod gmsh_binary;

use std::path::{Path, PathBuf};

use stickslip_fe::assembly::FeModel;
use stickslip_fe::element::shape::{HEX20_EDGES, TET10_EDGES};
use stickslip_fe::element::SolidKind;
use stickslip_fe::mesh::{gmsh, Material, Mesh};

const STEEL: Material = Material { young: 210e9, poisson: 0.3, density: 7800.0 };
const VOLUME: f64 = 1.0 * 0.5 * 0.25;

fn read(name: &str) -> Mesh {
    gmsh::read(PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/data").join(name)).unwrap()
}

/// Every mid-edge node lies at the midpoint of the two corners Abaqus's numbering puts it
/// between (the box's edges are straight): checks the Gmsh → Abaqus reordering.
fn check_mid_edge_nodes(mesh: &Mesh) {
    for s in &mesh.solids {
        let edges: &[(usize, usize)] = match s.kind {
            SolidKind::Tet10 => &TET10_EDGES,
            SolidKind::Hex20 => &HEX20_EDGES,
            _ => &[],
        };
        for (e, &(a, b)) in edges.iter().enumerate() {
            let (xa, xb, xm) = (
                mesh.nodes[s.nodes[a]].xyz,
                mesh.nodes[s.nodes[b]].xyz,
                mesh.nodes[s.nodes[s.kind.n_corners() + e]].xyz,
            );
            for d in 0..3 {
                // Gmsh writes coordinates with 16 significant digits.
                assert!((0.5 * (xa[d] + xb[d]) - xm[d]).abs() < 1e-12, "element {} edge {e}", s.id);
            }
        }
    }
}

fn check_box(name: &str, kind: SolidKind) -> FeModel {
    let mut mesh = read(name);
    assert!(!mesh.solids.is_empty() && mesh.solids.iter().all(|s| s.kind == kind), "{name}: all {kind:?}");
    check_mid_edge_nodes(&mesh);
    // The Fixed face holds exactly the nodes at x = 0; the unnamed point group its corner.
    let fixed = mesh.node_set("FIXED").unwrap();
    let at_zero = mesh.nodes.iter().filter(|n| n.xyz[0].abs() < 1e-12).count();
    assert_eq!(fixed.len(), at_zero, "{name}: FIXED set");
    assert!(fixed.iter().all(|&n| mesh.nodes[n].xyz[0].abs() < 1e-12));
    let corner = mesh.node_set("GROUP0_7").unwrap();
    assert_eq!(corner.len(), 1);
    assert_eq!(mesh.nodes[corner[0]].xyz, [1.0, 0.5, 0.25]);
    assert_eq!(mesh.element_sets["SOLID"].len(), mesh.solids.len());
    mesh.assign_material(Some("solid"), "steel", STEEL).unwrap();
    // Positive Jacobians everywhere (else assembly fails) and the exact volume.
    let fe = FeModel::assemble(mesh).unwrap();
    assert!((fe.volume / VOLUME - 1.0).abs() < 1e-12, "{name}: volume {}", fe.volume);
    fe
}

#[test]
fn reads_tet10_ascii_and_binary_identically() {
    let ascii = check_box("box_tet10_ascii.msh", SolidKind::Tet10);
    let binary = check_box("box_tet10_binary.msh", SolidKind::Tet10);
    assert_eq!(ascii.mesh.nodes.len(), binary.mesh.nodes.len());
    for (a, b) in ascii.mesh.nodes.iter().zip(&binary.mesh.nodes) {
        // ASCII coordinates carry 16 significant digits, binary ones all 17.
        assert!(a.id == b.id && (0..3).all(|d| (a.xyz[d] - b.xyz[d]).abs() < 1e-15), "node {} differs", a.id);
    }
    assert!(ascii.mesh.solids == binary.mesh.solids, "elements differ");
    assert!(ascii.mesh.node_sets == binary.mesh.node_sets, "node sets differ");
}

#[test]
fn reads_hex20_tet4_and_binary_hex8() {
    check_box("box_hex20_ascii.msh", SolidKind::Hex20);
    check_box("box_tet4_ascii.msh", SolidKind::Tet4);
    let fe = check_box("box_hex8_binary.msh", SolidKind::Hex8);
    assert_eq!(fe.mesh.nodes.len(), 27);
}

#[test]
fn unsupported_elements_and_versions_are_reported() {
    let prism = "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$Nodes\n1 6 1 6\n3 1 0 6\n1\n2\n3\n4\n5\n6\n\
                 0 0 0\n1 0 0\n0 1 0\n0 0 1\n1 0 1\n0 1 1\n$EndNodes\n$Elements\n1 1 1 1\n3 1 6 1\n1 1 2 3 4 5 6\n$EndElements\n";
    let e = gmsh::parse(prism.as_bytes(), "prism.msh".as_ref()).unwrap_err().to_string();
    assert!(e.contains("prism.msh:22") && e.contains("prism"), "{e}");
    let old = "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n";
    let e = gmsh::parse(old.as_bytes(), "old.msh".as_ref()).unwrap_err().to_string();
    assert!(e.contains("old.msh:2") && e.contains("4.1"), "{e}");
    let missing = "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$Nodes\n1 1 1 1\n3 1 0 1\n1\n0 0 0\n$EndNodes\n\
                   $Elements\n1 1 1 1\n3 1 4 1\n1 1 2 3 4\n$EndElements\n";
    let e = gmsh::parse(missing.as_bytes(), "m.msh".as_ref()).unwrap_err().to_string();
    assert!(e.contains("element 1") && e.contains("node 2"), "{e}");
}

fn data(name: &str) -> String {
    std::fs::read_to_string(PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/data").join(name)).unwrap()
}

#[test]
fn binary_twins_of_the_ascii_meshes_read_identically_in_both_byte_orders() {
    for name in ["box_tet10_ascii.msh", "box_hex20_ascii.msh", "box_tet4_ascii.msh"] {
        let ascii = gmsh::parse(data(name).as_bytes(), Path::new(name)).unwrap();
        for big_endian in [false, true] {
            let bytes = gmsh_binary::to_binary(&data(name), big_endian);
            let binary = gmsh::parse(&bytes, Path::new(name)).unwrap_or_else(|e| panic!("{name}: {e}"));
            assert!(ascii.nodes == binary.nodes, "{name} (big endian {big_endian}): nodes differ");
            assert!(ascii.solids == binary.solids, "{name} (big endian {big_endian}): elements differ");
            assert!(ascii.node_sets == binary.node_sets, "{name} (big endian {big_endian}): node sets differ");
        }
    }
}

/// A one-tet ASCII mesh with `nodes` and `elements` as the headers of the two sections.
fn one_tet(node_block: &str, element_block: &str) -> String {
    format!(
        "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$Nodes\n1 4 1 4\n{node_block}\n1\n2\n3\n4\n\
         0 0 0\n1 0 0\n0 1 0\n0 0 1\n$EndNodes\n$Elements\n1 1 1 1\n{element_block}\n1 1 2 3 4\n$EndElements\n"
    )
}

#[test]
fn counts_the_file_cannot_hold_are_refused_before_any_allocation() {
    // Each count once near usize::MAX (capacity overflow) and once merely too large (an abort
    // on an allocation of terabytes): both are refused, naming the line.
    for huge in ["18446744073709551615", "1000000000000"] {
        let text = one_tet(&format!("3 1 0 {huge}"), "3 1 4 1");
        let e = gmsh::parse(text.as_bytes(), "nodes.msh".as_ref()).unwrap_err().to_string();
        assert!(e.starts_with("nodes.msh:6: a block size") && e.contains("more than the rest of the file"), "{e}");
        let text = one_tet("3 1 0 4", &format!("3 1 4 {huge}"));
        let e = gmsh::parse(text.as_bytes(), "elements.msh".as_ref()).unwrap_err().to_string();
        assert!(e.starts_with("elements.msh:18: a block size") && e.contains("more than the rest"), "{e}");
    }
    let names = "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$PhysicalNames\n99999999999\n3 1 \"A\"\n$EndPhysicalNames\n";
    let e = gmsh::parse(names.as_bytes(), "names.msh".as_ref()).unwrap_err().to_string();
    assert!(e.starts_with("names.msh:5: the number of names 99999999999 is more"), "{e}");
    // Binary: a block size of 2^62 nodes in the twin of a real mesh.
    let mut bytes = gmsh_binary::to_binary(&one_tet("3 1 0 4", "3 1 4 1"), false);
    let at = bytes.windows(7).position(|w| w == b"$Nodes\n").unwrap() + 7 + 32 + 12;
    bytes[at..at + 8].copy_from_slice(&(1u64 << 62).to_le_bytes());
    let e = gmsh::parse(&bytes, "binary.msh".as_ref()).unwrap_err().to_string();
    assert!(e.starts_with("binary.msh:6: a block size 4611686018427387904 is more"), "{e}");
    let mut bytes = gmsh_binary::to_binary(&data("box_tet4_ascii.msh"), false);
    let at = bytes.windows(10).position(|w| w == b"$Entities\n").unwrap() + 10 + 32 + 4 + 24;
    bytes[at..at + 8].copy_from_slice(&u64::MAX.to_le_bytes());
    let e = gmsh::parse(&bytes, "entities.msh".as_ref()).unwrap_err().to_string();
    assert!(e.contains("a number of physical tags 18446744073709551615 is more"), "{e}");
}

#[test]
fn element_types_beyond_i32_and_non_finite_coordinates_are_refused() {
    // 2^32 + 11 once wrapped onto 11, a tet10.
    let text = one_tet("3 1 0 4", "3 1 4294967307 1");
    let e = gmsh::parse(text.as_bytes(), "type.msh".as_ref()).unwrap_err().to_string();
    assert!(e.starts_with("type.msh:18: an element type 4294967307 is not a 32-bit integer"), "{e}");
    let text = one_tet("3 1 0 4", "3 1 4 1").replace("1 0 0\n", "1e999 0 0\n");
    let e = gmsh::parse(text.as_bytes(), "inf.msh".as_ref()).unwrap_err().to_string();
    assert!(e.starts_with("inf.msh:12: x is inf, expected a finite number"), "{e}");
    let text = one_tet("3 1 0 4", "3 1 4 1").replace("0 1 0\n", "0 NaN 0\n");
    let e = gmsh::parse(text.as_bytes(), "nan.msh".as_ref()).unwrap_err().to_string();
    assert!(e.starts_with("nan.msh:13: y is NaN, expected a finite number"), "{e}");
}
