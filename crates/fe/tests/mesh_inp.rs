//! Reading Abaqus/CalculiX decks: the keyword subset, and bad input reported with its file
//! and line.

use std::path::PathBuf;

use stickslip_fe::assembly::{AssemblyError, FeModel};
use stickslip_fe::element::SolidKind;
use stickslip_fe::mesh::{inp, MeshError};

fn data(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/data").join(name)
}

#[test]
fn reads_a_deck_with_includes_generate_continuations_and_mixed_case() {
    let mesh = inp::read(data("deck_main.inp")).unwrap();
    assert_eq!(mesh.nodes.len(), 12);
    assert_eq!(mesh.solids.len(), 2);
    assert!(mesh.solids.iter().all(|s| s.kind == SolidKind::Hex8 && s.material == Some(0)));
    // Element 1's node list continues on a second line.
    assert_eq!(mesh.solids[0].nodes.len(), 8);
    assert_eq!(mesh.node_set("base").unwrap(), &[0, 1, 2, 3]);
    assert_eq!(mesh.element_sets["SOLID"], vec![0, 1]);
    assert_eq!(mesh.modes_requested, Some(5));
    assert_eq!(mesh.fixed.len(), 12);
    let fe = FeModel::assemble(mesh).unwrap();
    assert_eq!(fe.model.n_dofs(), 24);
    // Mass of the 2 m³ of steel.
    assert!((fe.solid_mass / (2.0 * 7800.0) - 1.0).abs() < 1e-14);
    assert_eq!(fe.set_dofs("BASE").unwrap().len(), 0, "the fixed base has no free DOF");
}

/// Parse a deck that must fail; return the error text.
fn error_of(deck: &str) -> String {
    let mesh = inp::parse(deck, "bad.inp");
    match mesh {
        Err(e) => e.to_string(),
        Ok(m) => FeModel::assemble(m).map(|_| ()).unwrap_err().to_string(),
    }
}

const NODES: &str = "*NODE\n1, 0., 0., 0.\n2, 1., 0., 0.\n3, 0., 1., 0.\n4, 0., 0., 1.\n";
const MATERIAL: &str = "*MATERIAL, NAME=S\n*ELASTIC\n1e9, 0.3\n*DENSITY\n1000.\n";

#[test]
fn unsupported_element_type_names_the_type_and_line() {
    let e = error_of(&format!("{NODES}*ELEMENT, TYPE=C3D6, ELSET=E\n1, 1, 2, 3, 4, 1, 2\n"));
    assert!(e.contains("bad.inp:6") && e.contains("unsupported element type C3D6"), "{e}");
}

#[test]
fn unknown_keyword_names_the_keyword_and_line() {
    let e = error_of(&format!("{NODES}*ORIENTATION, NAME=O\n1., 0., 0., 0., 1., 0.\n"));
    assert!(e.contains("bad.inp:6") && e.contains("*ORIENTATION"), "{e}");
}

#[test]
fn missing_material_names_the_section_and_material() {
    let e = error_of(&format!(
        "{NODES}*ELEMENT, TYPE=C3D4, ELSET=E\n1, 1, 2, 3, 4\n{MATERIAL}*SOLID SECTION, ELSET=E, MATERIAL=ALU\n"
    ));
    assert!(e.contains("bad.inp:13") && e.contains("\"ALU\"") && e.contains("\"E\""), "{e}");
}

#[test]
fn element_without_section_is_named() {
    let e = error_of(&format!("{NODES}*ELEMENT, TYPE=C3D4, ELSET=E\n1, 1, 2, 3, 4\n{MATERIAL}"));
    assert!(e.contains("element 1") && e.contains("no section"), "{e}");
}

#[test]
fn set_naming_an_absent_node_names_the_set_node_and_line() {
    let e = error_of(&format!("{NODES}*NSET, NSET=TOP\n1, 2, 77\n"));
    assert!(e.contains("bad.inp:7") && e.contains("NSET=TOP") && e.contains("node 77"), "{e}");
    let e = error_of(&format!("{NODES}*ELEMENT, TYPE=C3D4\n1, 1, 2, 3, 99\n"));
    assert!(e.contains("element 1") && e.contains("node 99"), "{e}");
    let e = error_of(&format!("{NODES}*BOUNDARY\nCLAMP, 1, 3\n"));
    assert!(e.contains("bad.inp:7") && e.contains("\"CLAMP\""), "{e}");
}

#[test]
fn wrong_node_count_and_bad_numbers_are_reported() {
    let e = error_of(&format!("{NODES}*ELEMENT, TYPE=C3D10\n1, 1, 2, 3, 4\n"));
    assert!(e.contains("element 1 has 4 nodes, C3D10 needs 10"), "{e}");
    let e = error_of("*NODE\n1, 0., abc, 0.\n");
    assert!(e.contains("bad.inp:2") && e.contains("\"abc\""), "{e}");
    let e = error_of(&format!("{NODES}*NODE\n3, 5., 5., 5.\n"));
    assert!(e.contains("node 3 is defined twice"), "{e}");
}

#[test]
fn inverted_element_is_an_assembly_error_naming_it() {
    // Nodes 2 and 3 swapped: negative volume.
    let deck =
        format!("{NODES}*ELEMENT, TYPE=C3D4, ELSET=E\n7, 1, 3, 2, 4\n{MATERIAL}*SOLID SECTION, ELSET=E, MATERIAL=S\n");
    let err = FeModel::assemble(inp::parse(&deck, "bad.inp").unwrap()).unwrap_err();
    assert!(matches!(err, AssemblyError::InvertedElement { element: 7, .. }), "{err}");
}

#[test]
fn missing_include_file_is_named() {
    let e = inp::parse("*INCLUDE, INPUT=/nonexistent/mesh.inp\n", "bad.inp").unwrap_err();
    assert!(matches!(e, MeshError::Io { .. }) && e.to_string().contains("/nonexistent/mesh.inp"), "{e}");
}

#[test]
fn point_element_without_property_card_is_named() {
    let e = error_of(&format!("{NODES}*ELEMENT, TYPE=MASS, ELSET=SHAKER\n9, 1\n"));
    assert!(e.contains("bad.inp:7") && e.contains("element 9") && e.contains("\"SHAKER\""), "{e}");
}

#[test]
fn data_lines_of_commas_only_are_refused_with_their_line() {
    // Each block reads its fields by position; a line of separators has none (it used to
    // index an empty field list and panic in *ELEMENT and *SURFACE).
    for block in ["*ELEMENT, TYPE=C3D8, ELSET=E", "*SURFACE, NAME=S, TYPE=NODE", "*NSET, NSET=A", "*NODE"] {
        let e = inp::parse(&format!("*NODE\n1, 0, 0, 0\n{block}\n , ,,\n"), "bad.inp").unwrap_err().to_string();
        assert!(e.starts_with("bad.inp:4: ") && e.contains("only commas"), "{block}: {e}");
    }
}

/// A GENERATE range read from the file is bounded before its ids are collected (a fuzzed
/// `1, 1000000000000000000` aborted on the allocation).
#[test]
fn a_huge_generate_range_is_refused_naming_the_line() {
    let deck = "*NODE\n1, 0, 0, 0\n*NSET, NSET=ALL, GENERATE\n1, 1000000000000000000\n";
    let e = inp::parse(deck, "bad.inp").unwrap_err().to_string();
    assert!(e.contains("bad.inp:4") && e.contains("GENERATE") && e.contains("limit"), "{e}");
}
