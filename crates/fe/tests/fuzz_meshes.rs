//! Fuzz-style property tests of the mesh readers (issue 9): `.inp` decks and Gmsh `.msh`
//! files, ASCII and binary, mutated (see `fuzz_support`), must give an error or a mesh of
//! finite values whose elements refer to its nodes, never a panic, an abort on a huge
//! allocation or a hang. `STICKSLIP_FUZZ_CASES=100000` runs more.

#[path = "../../io/tests/fuzz_support/mod.rs"]
mod fuzz_support;
mod gmsh_binary;

use std::path::{Path, PathBuf};

use fuzz_support::{debug_has_non_finite, fuzz};
use stickslip_fe::mesh::{gmsh, inp, Mesh};

fn data(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/data").join(name)
}

/// A mesh read from a damaged file is still consistent: finite numbers, elements and sets on
/// existing nodes.
fn check_mesh(mesh: &Mesh) {
    let n = mesh.nodes.len();
    assert!(mesh.nodes.iter().all(|node| node.xyz.iter().all(|x| x.is_finite())), "non-finite coordinate accepted");
    assert!(mesh.solids.iter().all(|s| s.nodes.len() == s.kind.n_nodes() && s.nodes.iter().all(|&i| i < n)));
    assert!(mesh.node_sets.values().flatten().all(|&i| i < n));
    assert!(!debug_has_non_finite(&format!("{:?}", mesh.materials)), "non-finite material accepted");
    assert!(!debug_has_non_finite(&format!("{:?}", mesh.points)), "non-finite point element accepted");
}

/// A small deck: materials, sections, sets, a coupling, a mass, springs and boundaries.
const DECK: &str = "*NODE\n1, 0, 0, 0\n2, 1, 0, 0\n3, 0, 1, 0\n4, 0, 0, 1\n5, 2, 0, 0\n\
*ELEMENT, TYPE=C3D4, ELSET=SOLID\n1, 1, 2, 3, 4\n*NSET, NSET=FIX\n1, 3\n*ELSET, ELSET=E\n1\n\
*MATERIAL, NAME=STEEL\n*ELASTIC\n210e9, 0.3\n*DENSITY\n7800\n*SOLID SECTION, ELSET=SOLID, MATERIAL=STEEL\n\
*ELEMENT, TYPE=MASS, ELSET=M\n10, 5\n*MASS, ELSET=M\n2.5\n*ELEMENT, TYPE=SPRINGA, ELSET=S\n11, 2, 5\n\
*SPRING, ELSET=S\n\n1e6\n*BOUNDARY\nFIX, 1, 3\n";

/// A reference node whose rotations a rotation node carries (`*RIGID BODY ... ROT NODE`), with
/// a spring and a boundary on the rotation node's DOFs.
const ROT_NODE_DECK: &str = "*NODE\n1, 0, 0, 0\n2, 1, 0, 0\n3, 0, 1, 0\n4, 0, 0, 1\n5, 0, 0, 2\n6, 0, 0, 2\n\
*ELEMENT, TYPE=C3D4, ELSET=SOLID\n1, 1, 2, 3, 4\n*NSET, NSET=TOP\n4\n\
*MATERIAL, NAME=STEEL\n*ELASTIC\n210e9, 0.3\n*DENSITY\n7800\n*SOLID SECTION, ELSET=SOLID, MATERIAL=STEEL\n\
*RIGID BODY, NSET=TOP, REF NODE=5, ROT NODE=6\n*ELEMENT, TYPE=SPRING1, ELSET=R\n11, 6\n\
*SPRING, ELSET=R\n2, 2\n1e4\n*BOUNDARY\n6, 3, 3\n1, 1, 3\n";

#[test]
fn inp_decks() {
    let seeds = [
        DECK.as_bytes().to_vec(),
        ROT_NODE_DECK.as_bytes().to_vec(),
        std::fs::read(data("deck_mesh.inp")).unwrap(),
        std::fs::read(data("deck_main.inp")).unwrap(),
    ];
    // Decks are parsed as if they sat in the data folder, so that *INCLUDE finds its file.
    let name = data("fuzz.inp").display().to_string();
    fuzz(".inp deck", &seeds, |_, input| {
        if let Ok(mesh) = inp::parse(&String::from_utf8_lossy(input), &name) {
            check_mesh(&mesh);
        }
    });
}

#[test]
fn gmsh_ascii_and_binary() {
    let one_tet = "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$PhysicalNames\n1\n3 1 \"SOLID\"\n$EndPhysicalNames\n\
                   $Entities\n0 0 0 1\n1 0 0 0 1 1 1 1 1 0\n$EndEntities\n$Nodes\n1 4 1 4\n3 1 0 4\n1\n2\n3\n4\n\
                   0 0 0\n1 0 0\n0 1 0\n0 0 1\n$EndNodes\n$Elements\n1 1 1 1\n3 1 4 1\n1 1 2 3 4\n$EndElements\n";
    let hex20 = std::fs::read_to_string(data("box_hex20_ascii.msh")).unwrap();
    let seeds = [
        one_tet.as_bytes().to_vec(),
        hex20.as_bytes().to_vec(),
        gmsh_binary::to_binary(one_tet, false),
        gmsh_binary::to_binary(one_tet, true),
        gmsh_binary::to_binary(&hex20, false),
        std::fs::read(data("box_hex8_binary.msh")).unwrap(),
    ];
    fuzz(".msh (ASCII and binary)", &seeds, |_, input| {
        if let Ok(mesh) = gmsh::parse(input, Path::new("fuzz.msh")) {
            check_mesh(&mesh);
        }
    });
}

/// What the fuzz targets found, kept as plain regression tests.
#[test]
fn found_by_fuzzing() {
    // A node coordinate of `nan` (or 1e999) was accepted by the .inp reader.
    let e = inp::parse(&DECK.replace("2, 1, 0, 0\n", "2, nan, 0, 0\n"), "nan.inp").unwrap_err().to_string();
    assert!(e.starts_with("nan.inp:3:") && e.contains("\"nan\", which is not finite"), "{e}");
    // A physical tag of i64::MIN overflowed `abs` in the .msh reader.
    let text =
        "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$Entities\n1 0 0 0\n1 0 0 0 1 -9223372036854775808\n$EndEntities\n";
    let e = gmsh::parse(text.as_bytes(), Path::new("tag.msh")).unwrap_err().to_string();
    assert!(e.starts_with("tag.msh:6: a physical tag -9223372036854775808 is not a 32-bit integer"), "{e}");
}

/// The fuzz seed with a rotation node reads as a deck (so that its mutations exercise that
/// path, not only the error of a broken seed).
#[test]
fn the_rotation_node_seed_is_a_valid_deck() {
    let mesh = inp::parse(ROT_NODE_DECK, &data("fuzz.inp").display().to_string()).unwrap();
    assert!(mesh.nodes.iter().all(|n| n.id != 6), "the rotation node is folded into its reference node");
}
