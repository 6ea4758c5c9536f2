//! Round trips through the writers: a mesh written as a `.inp` deck and read back assembles to
//! the same K, M and DOF labels; a mesh written as a Gmsh `.msh` file and read back has the
//! same nodes, solids and node sets and, with the same materials, the same K and M.
//!
//! Tolerance: both writers print every number in its shortest round-trip form, which parses
//! back to the same f64 (the deck's 20-character fields hold every coordinate and value these
//! meshes have, see `inp_writer`), and keep the order of nodes, solids and point elements, so
//! the matrices come out the same to the last bit. 1e-14 relative to the largest entry is the
//! bound this crate uses for "the same matrix" (as against CalculiX's exported matrices): a
//! few ulps of the largest entry, far below any modelling change.

use std::collections::BTreeSet;
use std::path::PathBuf;

use stickslip_core::model::Matrix;
use stickslip_fe::assembly::FeModel;
use stickslip_fe::element::SolidKind;
use stickslip_fe::mesh::generate::box_mesh;
use stickslip_fe::mesh::{
    gmsh, gmsh_writer, inp, inp_writer, Equation, Material, Mesh, MeshError, PointElement, RigidCoupling,
};

const STEEL: Material = Material { young: 210e9, poisson: 0.3, density: 7800.0 };
const ALU: Material = Material { young: 70e9, poisson: 0.33, density: 2700.0 };
const KINDS: [SolidKind; 4] = [SolidKind::Hex8, SolidKind::Hex20, SolidKind::Tet4, SolidKind::Tet10];

fn out_path(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join(name)
}

/// Indices of the nodes of `mesh` at `x` (within 1e-12) with `y`, `z` inside the box.
fn nodes_where(mesh: &Mesh, f: impl Fn([f64; 3]) -> bool) -> Vec<usize> {
    (0..mesh.nodes.len()).filter(|&n| f(mesh.nodes[n].xyz)).collect()
}

/// A 0.3 × 0.1 × 0.07 m box of `kind` in two materials, clamped at x = 0, its x = 0.3 face
/// rigidly coupled to a reference node joined by a six-component connector to a second node
/// (with a point mass, a partly grounded connector, an axial spring), which is itself rigidly
/// coupled (rotations too) to a third, grounded reference node; plus a grounded spring, a
/// two-DOF spring, an equation and node sets. Point element ids 1..=7 collide with solid ids.
fn decorated(kind: SolidKind) -> Mesh {
    let mut mesh = box_mesh([0.3, 0.1, 0.07], [4, 2, 2], kind, STEEL);
    // Second material on the solids left of x = 0.1.
    let left: Vec<usize> = (0..mesh.solids.len())
        .filter(|&s| {
            let nodes = &mesh.solids[s].nodes;
            nodes.iter().map(|&n| mesh.nodes[n].xyz[0]).sum::<f64>() / (nodes.len() as f64) < 0.1
        })
        .collect();
    mesh.element_sets.insert("LEFT".into(), left);
    mesh.assign_material(Some("LEFT"), "ALU", ALU).unwrap();

    let xmin = mesh.node_set("XMIN").unwrap().to_vec();
    let xmax = mesh.node_set("XMAX").unwrap().to_vec();
    for &n in &xmin {
        mesh.fixed.extend([(n, 1), (n, 2), (n, 3)]);
    }
    let r1 = mesh.add_node(9001, [0.35, 0.05, 0.035]).unwrap();
    let r2 = mesh.add_node(9002, [0.45, 0.05, 0.035]).unwrap();
    let r3 = mesh.add_node(9003, [0.55, 0.05, 0.035]).unwrap();
    let dofs: Vec<u8> = (1..=6).collect();
    mesh.couplings.push(RigidCoupling { reference: r1, nodes: xmax, dofs: dofs.clone(), at: Default::default() });
    // r2 carries rotations (its connectors have rotational stiffness): its coupled rotations
    // are eliminated too.
    mesh.couplings.push(RigidCoupling { reference: r3, nodes: vec![r2], dofs, at: Default::default() });
    mesh.points.push(PointElement::Connector {
        id: 1,
        a: r1,
        b: Some(r2),
        stiffness: [1e10, 2e10, 3e10, 1e8, 2e8, 3e8],
    });
    mesh.points.push(PointElement::Connector { id: 2, a: r2, b: None, stiffness: [0.0, 5e5, 0.0, 0.0, 0.0, 7.5e3] });
    mesh.points.push(PointElement::Mass { id: 3, node: r2, mass: 0.5 });
    mesh.points.push(PointElement::Connector { id: 4, a: r3, b: None, stiffness: [1e6, 2e6, 3e6, 4e4, 5e4, 6e4] });
    // Nodes on the y = 0.1 face away from the constrained ends.
    let free = nodes_where(&mesh, |x| (x[1] - 0.1).abs() < 1e-12 && x[0] > 1e-12 && x[0] < 0.3 - 1e-12);
    assert!(free.len() >= 6, "{kind:?}: expected free nodes on the y = 0.1 face");
    mesh.points.push(PointElement::Spring { id: 5, a: free[0], dir_a: 2, b: None, stiffness: 1.234567e6 });
    mesh.points.push(PointElement::Spring { id: 6, a: free[1], dir_a: 1, b: Some((free[2], 3)), stiffness: 3.3e7 });
    mesh.points.push(PointElement::AxialSpring { id: 7, a: free[3], b: r2, stiffness: 4.4e5 });
    mesh.equations.push(Equation {
        terms: vec![(free[4], 3, 1.0), (free[5], 3, -0.3), (free[3], 3, -0.7)],
        at: Default::default(),
    });
    mesh.add_node_set("REFERENCES", [r1, r2, r3]);
    mesh.add_node_set("corner", [0]);
    mesh.modes_requested = Some(12);
    mesh
}

/// The largest `|a − b|` over all entries relative to the largest `|a|`, after checking that
/// both have the same shape and sparsity pattern.
fn relative_difference(a: &Matrix, b: &Matrix, what: &str) -> f64 {
    let (Matrix::Sparse(a), Matrix::Sparse(b)) = (a, b) else { panic!("{what}: expected sparse matrices") };
    assert_eq!((a.nrows(), a.ncols()), (b.nrows(), b.ncols()), "{what}: shapes differ");
    let (a, b) = (a.as_ref(), b.as_ref());
    let (mut max, mut diff) = (0.0f64, 0.0f64);
    for j in 0..a.ncols() {
        assert_eq!(
            a.symbolic().row_idx_of_col_raw(j),
            b.symbolic().row_idx_of_col_raw(j),
            "{what}: sparsity patterns differ in column {j}"
        );
        for (x, y) in a.val_of_col(j).iter().zip(b.val_of_col(j)) {
            max = max.max(x.abs());
            diff = diff.max((x - y).abs());
        }
    }
    diff / max
}

fn assert_same_model(original: &FeModel, read: &FeModel, what: &str) {
    assert_eq!(original.model.dofs, read.model.dofs, "{what}: DOF labels differ");
    for (name, a, b) in
        [("K", &original.model.stiffness, &read.model.stiffness), ("M", &original.model.mass, &read.model.mass)]
    {
        let d = relative_difference(a, b, &format!("{what} {name}"));
        println!("{what}: {} DOFs, {name} differs by {d:.1e} relative", original.model.n_dofs());
        assert!(d <= 1e-14, "{what}: {name} differs by {d:.3e} relative");
    }
}

fn assert_same_solids(original: &Mesh, read: &Mesh, what: &str) {
    assert_eq!(original.nodes, read.nodes, "{what}: nodes differ (ids, coordinates or order)");
    assert_eq!(original.solids.len(), read.solids.len(), "{what}: solid count");
    for (a, b) in original.solids.iter().zip(&read.solids) {
        assert_eq!((a.id, a.kind, &a.nodes), (b.id, b.kind, &b.nodes), "{what}: solid {} differs", a.id);
    }
}

#[test]
fn decks_read_back_to_the_same_model() {
    for kind in KINDS {
        let what = format!("{kind:?} deck");
        let mesh = decorated(kind);
        let path = out_path(&format!("writers_{}.inp", kind.abaqus_name()));
        inp_writer::write(&mesh, &path).unwrap();
        let read = inp::read(&path).unwrap_or_else(|e| panic!("{what}: {e}"));
        // CalculiX reads 20 characters of a field.
        let text = std::fs::read_to_string(&path).unwrap();
        for line in text.lines().filter(|l| !l.starts_with('*')) {
            assert!(line.split(',').all(|f| f.trim().len() <= 20), "{what}: a field of {line:?} is too long");
        }

        assert_same_solids(&mesh, &read, &what);
        assert_eq!(mesh.materials, read.materials, "{what}: materials");
        for (a, b) in mesh.solids.iter().zip(&read.solids) {
            assert_eq!(a.material, b.material, "{what}: material of solid {}", a.id);
        }
        for (name, nodes) in &mesh.node_sets {
            assert_eq!(read.node_set(name), Some(nodes.as_slice()), "{what}: node set {name}");
        }
        for (name, solids) in &mesh.element_sets {
            assert_eq!(read.element_sets.get(name), Some(solids), "{what}: element set {name}");
        }
        assert_eq!(read.fixed, mesh.fixed, "{what}: fixed DOFs");
        assert_eq!(read.modes_requested, Some(12), "{what}: *FREQUENCY");
        // Connectors become one spring per nonzero component: 6 + 2 + 6, plus 4 others.
        assert_eq!(read.points.len(), 18, "{what}: point elements");
        let max_solid = mesh.solids.iter().map(|s| s.id).max().unwrap();
        let ids: BTreeSet<u64> = read
            .points
            .iter()
            .map(|p| match *p {
                PointElement::Mass { id, .. }
                | PointElement::Spring { id, .. }
                | PointElement::AxialSpring { id, .. }
                | PointElement::Connector { id, .. } => id,
            })
            .collect();
        assert_eq!(ids, (max_solid + 1..=max_solid + 18).collect(), "{what}: point ids renumbered above the solids");
        // Two rigid bodies (the references' rotations carry connector springs), the second
        // tying node 9002's rotations too; the mesh's own equation.
        assert_eq!(read.couplings.len(), 2, "{what}: couplings");
        assert_eq!(read.equations.len(), 1, "{what}: equations");
        assert_eq!(text.matches("\n*RIGID BODY,").count(), 2, "{what}: rigid bodies");

        let original = FeModel::assemble(mesh).unwrap();
        let read = FeModel::assemble(read).unwrap();
        assert!(original.model.dofs.iter().any(|d| d.node == Some(9003) && d.direction == Some(6)));
        assert_same_model(&original, &read, &what);
    }
}

#[test]
fn point_element_ids_are_kept_when_they_do_not_collide() {
    let mut mesh = box_mesh([0.1, 0.1, 0.1], [1, 1, 1], SolidKind::Hex8, STEEL);
    let r = mesh.add_node(100, [0.2, 0.05, 0.05]).unwrap();
    mesh.points.push(PointElement::Mass { id: 500, node: r, mass: 1.0 });
    mesh.points.push(PointElement::Connector { id: 501, a: r, b: Some(0), stiffness: [1e9, 0.0, 2e9, 0.0, 0.0, 0.0] });
    mesh.points.push(PointElement::AxialSpring { id: 9, a: r, b: 1, stiffness: 1e7 });
    let text = inp_writer::to_string(&mesh).unwrap();
    let read = inp::parse(&text, "kept.inp").unwrap();
    let ids: Vec<u64> = read
        .points
        .iter()
        .map(|p| match *p {
            PointElement::Mass { id, .. }
            | PointElement::Spring { id, .. }
            | PointElement::AxialSpring { id, .. }
            | PointElement::Connector { id, .. } => id,
        })
        .collect();
    // The connector's second component takes the next id above every id (501).
    assert_eq!(ids, [500, 501, 502, 9]);
    assert_same_model(&FeModel::assemble(mesh).unwrap(), &FeModel::assemble(read).unwrap(), "kept ids");
}

#[test]
fn gmsh_files_read_back_to_the_same_nodes_solids_and_sets() {
    for kind in KINDS {
        let what = format!("{kind:?} .msh");
        let mesh = decorated(kind);
        let path = out_path(&format!("writers_{}.msh", kind.abaqus_name()));
        gmsh_writer::write(&mesh, &path).unwrap();
        let mut read = gmsh::read(&path).unwrap_or_else(|e| panic!("{what}: {e}"));

        assert_same_solids(&mesh, &read, &what);
        for (name, nodes) in &mesh.node_sets {
            assert_eq!(read.node_set(name), Some(nodes.as_slice()), "{what}: node set {name}");
        }
        for (name, solids) in &mesh.element_sets {
            assert_eq!(read.element_sets.get(name), Some(solids), "{what}: element set {name}");
        }
        // The reader adds a node set per physical volume: the element sets and the group of
        // the first material, whose solids (right of x = 0.1) are no element set.
        let extra: BTreeSet<&str> =
            read.node_sets.keys().filter(|k| !mesh.node_sets.contains_key(*k)).map(|k| k.as_str()).collect();
        assert_eq!(extra, BTreeSet::from(["ALL", "LEFT", "MATERIAL"]), "{what}: extra node sets");
        let right: Vec<usize> = (0..mesh.solids.len()).filter(|&s| mesh.solids[s].material == Some(0)).collect();
        assert_eq!(read.element_sets.get("MATERIAL"), Some(&right), "{what}: material group");

        // Same materials by group, same matrices (the .msh holds no point elements,
        // couplings, boundaries or equations: compare with the mesh without them).
        read.assign_material(Some("MATERIAL"), "MATERIAL", STEEL).unwrap();
        read.assign_material(Some("LEFT"), "ALU", ALU).unwrap();
        let mut bare = mesh.clone();
        bare.points.clear();
        bare.couplings.clear();
        bare.fixed.clear();
        bare.equations.clear();
        for (a, b) in bare.solids.iter().zip(&read.solids) {
            assert_eq!(a.material, b.material, "{what}: material of solid {}", a.id);
        }
        assert_same_model(&FeModel::assemble(bare).unwrap(), &FeModel::assemble(read).unwrap(), &what);
    }
}

#[test]
fn gmsh_files_store_c3d20r_as_c3d20() {
    let mesh = box_mesh([0.2, 0.1, 0.1], [2, 1, 1], SolidKind::Hex20R, STEEL);
    let text = gmsh_writer::to_string(&mesh).unwrap();
    let read = gmsh::parse(text.as_bytes(), std::path::Path::new("c3d20r.msh")).unwrap();
    assert!(read.solids.iter().all(|s| s.kind == SolidKind::Hex20));
    for (a, b) in mesh.solids.iter().zip(&read.solids) {
        assert_eq!(a.nodes, b.nodes, "the node order survives the conversion to Gmsh's and back");
    }
}

#[test]
fn unwritable_paths_are_write_errors_naming_the_file() {
    let mesh = decorated(SolidKind::Hex8);
    let path = out_path("no_such_directory/deck.inp");
    match inp_writer::write(&mesh, &path) {
        Err(e @ MeshError::Write { .. }) => {
            let MeshError::Write { file, .. } = &e else { unreachable!() };
            assert_eq!(file, &path);
            assert!(
                e.to_string().starts_with("cannot write") && e.to_string().contains("no_such_directory/deck.inp"),
                "{e}"
            );
        }
        other => panic!("expected an I/O error, got {other:?}"),
    }
    let path = out_path("no_such_directory/mesh.msh");
    match gmsh_writer::write(&mesh, &path) {
        Err(MeshError::Write { file, .. }) => assert_eq!(file, path),
        other => panic!("expected an I/O error, got {other:?}"),
    }
}

#[test]
fn meshes_a_deck_cannot_express_are_errors() {
    // A Gmsh mesh has no materials: a deck needs a section for every solid.
    let text = gmsh_writer::to_string(&box_mesh([0.1, 0.1, 0.1], [1, 1, 1], SolidKind::Tet4, STEEL)).unwrap();
    let no_material = gmsh::parse(text.as_bytes(), std::path::Path::new("no_material.msh")).unwrap();
    assert!(matches!(inp_writer::to_string(&no_material), Err(MeshError::NoSection { element: 1, .. })));
    // A set name with a comma would split the keyword line.
    let mut mesh = box_mesh([0.1, 0.1, 0.1], [1, 1, 1], SolidKind::Hex8, STEEL);
    mesh.add_node_set("A,B", [0]);
    let err = inp_writer::to_string(&mesh).unwrap_err();
    assert!(err.to_string().contains("\"A,B\""), "{err}");
}

#[test]
fn reference_decks_read_back_to_the_same_model() {
    // The CalculiX reference decks (one per solid kind, and a coupled deck with springs, a
    // mass and a *COUPLING/*KINEMATIC), rewritten: same K, M and labels.
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("reference");
    for name in ["block_c3d4", "block_c3d10", "block_c3d8", "block_c3d20", "block_c3d20r", "coupled_c3d8"] {
        let mesh = inp::read(dir.join(format!("{name}.inp"))).unwrap();
        let path = out_path(&format!("rewritten_{name}.inp"));
        inp_writer::write(&mesh, &path).unwrap();
        let read = inp::read(&path).unwrap_or_else(|e| panic!("{name}: {e}"));
        assert_same_solids(&mesh, &read, name);
        assert_eq!(read.modes_requested, mesh.modes_requested, "{name}: *FREQUENCY");
        assert_same_model(&FeModel::assemble(mesh).unwrap(), &FeModel::assemble(read).unwrap(), name);
    }
}

#[test]
fn coordinates_that_are_not_finite_are_refused_by_both_writers() {
    let mut mesh = box_mesh([0.1, 0.1, 0.1], [1, 1, 1], SolidKind::Hex8, STEEL);
    mesh.nodes[3].xyz[1] = f64::NAN;
    let id = mesh.nodes[3].id;
    let e = gmsh_writer::to_string(&mesh).unwrap_err().to_string();
    assert!(e.contains(&format!("node {id} has coordinates")) && e.contains("NaN"), "{e}");
    let e = inp_writer::to_string(&mesh).unwrap_err().to_string();
    assert!(e.contains(&format!("node {id} has coordinates")) && e.contains("NaN"), "{e}");
    let mut mesh = box_mesh([0.1, 0.1, 0.1], [1, 1, 1], SolidKind::Hex8, STEEL);
    mesh.materials[0].1.density = f64::INFINITY;
    let e = inp_writer::to_string(&mesh).unwrap_err().to_string();
    assert!(e.contains("density: inf") && e.contains("not finite"), "{e}");
    let mut mesh = box_mesh([0.1, 0.1, 0.1], [1, 1, 1], SolidKind::Hex8, STEEL);
    mesh.points.push(stickslip_fe::mesh::PointElement::Mass { id: 99, node: 0, mass: f64::NAN });
    let e = inp_writer::to_string(&mesh).unwrap_err().to_string();
    assert!(e.contains("element 99 has the value(s) [NaN], not finite"), "{e}");
}
