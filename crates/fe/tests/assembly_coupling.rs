//! Rigid couplings, connectors, springs, point masses and linear MPCs against closed-form
//! frequencies.

mod element_support;

use std::f64::consts::PI;

use stickslip_fe::assembly::FeModel;
use stickslip_fe::element::SolidKind;
use stickslip_fe::mesh::generate::box_mesh;
use stickslip_fe::mesh::{inp, Material, PointElement, RigidCoupling};

const STEEL: Material = Material { young: 210e9, poisson: 0.3, density: 7800.0 };

fn hz(omega2: f64) -> f64 {
    omega2.sqrt() / (2.0 * PI)
}

#[test]
fn rigid_body_on_a_six_component_connector_has_the_analytic_frequencies() {
    // A 0.3 × 0.2 × 0.1 m steel block, every node rigidly coupled to a reference node at its
    // centroid, held to ground by a connector with one stiffness per direction (the paper's
    // reference-node + connector layout): six uncoupled rigid-body oscillators.
    let size = [0.3, 0.2, 0.1];
    let mut mesh = box_mesh(size, [3, 2, 2], SolidKind::Hex8, STEEL);
    let all: Vec<usize> = (0..mesh.nodes.len()).collect();
    let reference = mesh.add_node(9999, size.map(|s| 0.5 * s)).unwrap();
    mesh.couplings.push(RigidCoupling { reference, nodes: all, dofs: (1..=6).collect(), at: Default::default() });
    let k = [1e6, 2e6, 3e6, 4e4, 5e4, 6e4];
    mesh.points.push(PointElement::Connector { id: 1, a: reference, b: None, stiffness: k });
    let fe = FeModel::assemble(mesh).unwrap();
    assert_eq!(fe.model.n_dofs(), 6, "only the reference node's six DOFs remain");
    let m = STEEL.density * size[0] * size[1] * size[2];
    let [a, b, c] = size;
    let inertia = [m * (b * b + c * c) / 12.0, m * (a * a + c * c) / 12.0, m * (a * a + b * b) / 12.0];
    let mut expected: Vec<f64> = (0..6).map(|i| hz(k[i] / if i < 3 { m } else { inertia[i - 3] })).collect();
    expected.sort_by(|x, y| x.partial_cmp(y).unwrap());
    let ours = element_support::dense_frequencies(&fe.model);
    for (o, e) in ours.iter().zip(&expected) {
        println!("{o:.6} Hz (analytic {e:.6} Hz)");
        // The 2×2×2 mass rule integrates the rigid-body kinetic energy of a box exactly:
        // only round-off remains.
        assert!((o / e - 1.0).abs() < 1e-10, "{o} Hz vs analytic {e} Hz");
    }
    // The DOF of the reference node is found by node id and direction.
    assert_eq!(fe.dof(9999, 3).unwrap(), 2);
    assert!(fe.dof(1, 1).is_err(), "a coupled node's DOFs are eliminated");
}

#[test]
fn two_rigid_bodies_joined_by_a_stiff_connector_move_as_one() {
    // Two blocks, each rigidly driving its reference node; the reference nodes are joined by a
    // 1e10 N/m connector (the paper's contact and screw connectors) and one is grounded in z
    // by a soft spring: the lowest z mode is the total mass on that spring.
    let mut mesh = box_mesh([0.2, 0.1, 0.1], [2, 1, 1], SolidKind::Hex8, STEEL);
    let n1 = mesh.nodes.len();
    let other = box_mesh([0.2, 0.1, 0.1], [2, 1, 1], SolidKind::Hex8, STEEL);
    for node in &other.nodes {
        mesh.add_node(1000 + node.id, [node.xyz[0] + 0.25, node.xyz[1], node.xyz[2]]).unwrap();
    }
    for s in &other.solids {
        let mut s = s.clone();
        s.id += 1000;
        s.nodes.iter_mut().for_each(|n| *n += n1);
        mesh.solids.push(s);
    }
    let r1 = mesh.add_node(5001, [0.1, 0.05, 0.05]).unwrap();
    let r2 = mesh.add_node(5002, [0.35, 0.05, 0.05]).unwrap();
    let dofs: Vec<u8> = (1..=6).collect();
    mesh.couplings.push(RigidCoupling {
        reference: r1,
        nodes: (0..n1).collect(),
        dofs: dofs.clone(),
        at: Default::default(),
    });
    mesh.couplings.push(RigidCoupling {
        reference: r2,
        nodes: (n1..n1 + other.nodes.len()).collect(),
        dofs,
        at: Default::default(),
    });
    mesh.points.push(PointElement::Connector { id: 1, a: r1, b: Some(r2), stiffness: [1e10; 6] });
    // Ground both bodies softly in every direction except z, and in z with k_z at r1 only.
    let kz = 1e4;
    mesh.points.push(PointElement::Connector { id: 2, a: r1, b: None, stiffness: [1e5, 1e5, kz, 1e4, 1e4, 1e4] });
    let fe = FeModel::assemble(mesh).unwrap();
    let total = 2.0 * STEEL.density * 0.2 * 0.1 * 0.1;
    let f = element_support::dense_frequencies(&fe.model);
    let expected = hz(kz / total);
    // Both centroids lie on the line through r1 along x, so the z translation of the pair is
    // a principal motion on k_z; the 1e10 N/m connector's flexibility shifts it by ~k_z/1e10.
    let closest =
        f.iter().copied().min_by(|a, b| (a - expected).abs().partial_cmp(&(b - expected).abs()).unwrap()).unwrap();
    println!("z mode {closest:.6} Hz, rigid-assembly value {expected:.6} Hz");
    assert!((closest / expected - 1.0).abs() < 1e-5, "{closest} vs {expected}");
}

const DECK: &str = "\
** Two masses on springs along x, one held in y: MASS, SPRING1, SPRING2, SPRINGA
*node
1, 0., 0., 0.
2, 1., 0., 0.
3, 2., 0., 0.
*Element, type=MASS, elset=M1
10, 2
*Element, type=MASS, elset=M2
11, 3
*Mass, elset=M1
2.
*Mass, elset=M2
1.
*Element, type=SPRINGA, elset=SA
20, 1, 2
*Spring, elset=SA

1000.
*Element, type=SPRING2, elset=S2
21, 2, 3
*Spring, elset=S2
1, 1
500.
*Element, type=SPRING1, elset=S1
22, 3
*Spring, elset=S1
2
300.
*Boundary
1, 1, 3
2, 2, 3
3, 3
";

#[test]
fn masses_and_springs_of_a_deck_give_the_closed_form_frequencies() {
    let fe = FeModel::assemble(inp::parse(DECK, "springs.inp").unwrap()).unwrap();
    assert_eq!(fe.model.n_dofs(), 3);
    // x: M = diag(2, 1), K = [[1500, −500], [−500, 500]]: det(K − λM) = 0 gives
    // 2λ² − 2500λ + 500000 = 0; y of node 3: λ = 300 / 1.
    let disc = (2500.0f64 * 2500.0 - 4.0 * 2.0 * 500000.0).sqrt();
    let mut expected = vec![hz((2500.0 - disc) / 4.0), hz((2500.0 + disc) / 4.0), hz(300.0)];
    expected.sort_by(|a, b| a.partial_cmp(b).unwrap());
    let ours = element_support::dense_frequencies(&fe.model);
    for (o, e) in ours.iter().zip(&expected) {
        assert!((o / e - 1.0).abs() < 1e-12, "{o} Hz vs closed form {e} Hz");
    }
}

#[test]
fn an_equation_ties_two_dofs() {
    // u_3x − u_2x = 0: both masses move together on the SPRINGA, λ = 1000 / 3.
    let deck = format!("{DECK}*EQUATION\n2\n3, 1, 1., 2, 1, -1.\n");
    let fe = FeModel::assemble(inp::parse(&deck, "equation.inp").unwrap()).unwrap();
    assert_eq!(fe.model.n_dofs(), 2);
    let ours = element_support::dense_frequencies(&fe.model);
    let mut expected = [hz(1000.0 / 3.0), hz(300.0)];
    expected.sort_by(|a, b| a.partial_cmp(b).unwrap());
    for (o, e) in ours.iter().zip(&expected) {
        assert!((o / e - 1.0).abs() < 1e-12, "{o} Hz vs closed form {e} Hz");
    }
}

#[test]
fn kinematic_coupling_keywords_build_the_same_model() {
    // *KINEMATIC COUPLING, *COUPLING + *KINEMATIC and *RIGID BODY tie a node set to a
    // reference node identically.
    let base = "*NODE\n1, 0., 0., 0.\n2, 1., 0., 0.\n3, 1., 1., 0.\n4, 0., 0., 1.\n100, 0.3, 0.3, 0.3\n\
                *ELEMENT, TYPE=C3D4, ELSET=E\n1, 1, 2, 3, 4\n*NSET, NSET=TOP\n4, 3\n\
                *MATERIAL, NAME=S\n*ELASTIC\n1e9, 0.3\n*DENSITY\n1000.\n*SOLID SECTION, ELSET=E, MATERIAL=S\n\
                *BOUNDARY\n1, 1, 3\n2, 2, 3\n";
    let decks = [
        format!("{base}*KINEMATIC COUPLING, REF NODE=100\nTOP, 1, 6\n"),
        format!("{base}*SURFACE, NAME=S, TYPE=NODE\nTOP\n*COUPLING, REF NODE=100, SURFACE=S, CONSTRAINT NAME=C\n*KINEMATIC\n1, 3\n"),
        format!("{base}*RIGID BODY, NSET=TOP, REF NODE=100\n"),
    ];
    let models: Vec<FeModel> =
        decks.iter().map(|d| FeModel::assemble(inp::parse(d, "c.inp").unwrap()).unwrap()).collect();
    let k0 = models[0].model.stiffness.to_dense();
    let m0 = models[0].model.mass.to_dense();
    for fe in &models[1..] {
        assert_eq!(fe.model.dofs, models[0].model.dofs);
        let dk = (&fe.model.stiffness.to_dense() - &k0).norm_max() / k0.norm_max();
        let dm = (&fe.model.mass.to_dense() - &m0).norm_max() / m0.norm_max();
        assert!(dk < 1e-15 && dm < 1e-15, "models differ: {dk:e} {dm:e}");
    }
    // Node 2 keeps u_x; node 1 is fixed; nodes 3, 4 follow the reference node's 6 DOFs.
    assert_eq!(models[0].model.n_dofs(), 7);
    // Coupling u_x alone: the slaves keep u_y, u_z, and the reference node keeps only the DOFs
    // u_x follows (u_x, θ_y, θ_z), so no massless DOF is left in the model.
    let fe = FeModel::assemble(
        inp::parse(&format!("{base}*KINEMATIC COUPLING, REF NODE=100\nTOP, 1, 1\n"), "x.inp").unwrap(),
    )
    .unwrap();
    let names: Vec<&str> = fe.model.dofs.iter().map(|d| d.name.as_str()).collect();
    assert_eq!(names, ["2.1", "3.2", "3.3", "4.2", "4.3", "100.1", "100.5", "100.6"]);
    let m = fe.model.mass.to_dense();
    assert!((0..names.len()).all(|i| m[(i, i)] > 0.0), "every DOF has mass");
}

#[test]
fn rigid_body_rotation_node_stands_for_the_reference_rotations() {
    // CalculiX's form of a rotational spring on a rigid body: the ROT NODE's DOFs 1-3 are the
    // reference's rotations, so a spring on its DOF 1 and a held DOF 2 are the reference's θ_x
    // spring and held θ_y.
    let base = "*NODE\n1, 0., 0., 0.\n2, 1., 0., 0.\n3, 1., 1., 0.\n4, 0., 0., 1.\n100, 0.3, 0.3, 0.3\n\
                *ELEMENT, TYPE=C3D4, ELSET=E\n1, 1, 2, 3, 4\n*NSET, NSET=TOP\n4, 3\n\
                *MATERIAL, NAME=S\n*ELASTIC\n1e9, 0.3\n*DENSITY\n1000.\n*SOLID SECTION, ELSET=E, MATERIAL=S\n\
                *BOUNDARY\n1, 1, 3\n2, 2, 3\n";
    let spring =
        |node: u64, dof: u8| format!("*ELEMENT, TYPE=SPRING1, ELSET=K\n7, {node}\n*SPRING, ELSET=K\n{dof}\n2.5e6\n");
    let direct = format!("{base}*RIGID BODY, NSET=TOP, REF NODE=100\n{}*BOUNDARY\n100, 5\n", spring(100, 4));
    let rotation_node = format!(
        "{}{}*BOUNDARY\n101, 2\n*RIGID BODY, NSET=TOP, REF NODE=100, ROT NODE=101\n",
        base.replace("100, 0.3, 0.3, 0.3\n", "100, 0.3, 0.3, 0.3\n101, 0.3, 0.3, 0.3\n"),
        spring(101, 1)
    );
    let read = inp::parse(&rotation_node, "rot.inp").unwrap();
    assert!(read.node(101).is_none(), "the rotation node leaves the mesh");
    let a = FeModel::assemble(inp::parse(&direct, "direct.inp").unwrap()).unwrap();
    let b = FeModel::assemble(read).unwrap();
    assert_eq!(a.model.dofs, b.model.dofs);
    assert!(a.model.dofs.iter().all(|d| d.name != "100.5"), "θ_y held");
    let (ka, kb) = (a.model.stiffness.to_dense(), b.model.stiffness.to_dense());
    assert!((&ka - &kb).norm_max() <= 1e-15 * ka.norm_max());
    assert_eq!(a.model.mass.to_dense(), b.model.mass.to_dense());

    // What a rotation node cannot carry is refused, naming the rigid body's line.
    let with_rot = base.replace("100, 0.3, 0.3, 0.3\n", "100, 0.3, 0.3, 0.3\n101, 0.3, 0.3, 0.3\n");
    let rigid = "*RIGID BODY, NSET=TOP, REF NODE=100, ROT NODE=101\n";
    for (extra, expected) in [
        (spring(101, 4), "spring element 7 acts on DOF 4 of node 101, the ROT NODE of REF NODE=100"),
        ("*ELEMENT, TYPE=MASS, ELSET=M\n8, 101\n*MASS, ELSET=M\n1.\n".to_string(), "mass element 8 is on node 101"),
        ("*BOUNDARY\n101, 6\n".to_string(), "*BOUNDARY acts on DOF 6 of node 101"),
    ] {
        let err = inp::parse(&format!("{with_rot}{extra}{rigid}"), "bad.inp").unwrap_err().to_string();
        assert!(err.contains(expected) && err.contains("bad.inp:"), "{err}");
    }
    let err = inp::parse(&format!("{base}*RIGID BODY, NSET=TOP, REF NODE=100, ROT NODE=100\n"), "same.inp")
        .unwrap_err()
        .to_string();
    assert!(err.contains("ROT NODE=100 is the REF NODE"), "{err}");
}

#[test]
fn element_face_surfaces_collect_corner_and_mid_edge_nodes() {
    // A C3D10 and a C3D20 in one deck; face S1 of each, coupled to reference nodes.
    let deck = "*NODE\n1, 0., 0., 0.\n2, 1., 0., 0.\n3, 0., 1., 0.\n4, 0., 0., 1.\n5, .5, 0., 0.\n6, .5, .5, 0.\n\
                7, 0., .5, 0.\n8, 0., 0., .5\n9, .5, 0., .5\n10, 0., .5, .5\n100, .2, .2, 0.\n\
                *ELEMENT, TYPE=C3D10, ELSET=E\n1, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10\n\
                *SURFACE, NAME=BOTTOM\nE, S1\n*COUPLING, REF NODE=100, SURFACE=BOTTOM, CONSTRAINT NAME=C\n*KINEMATIC\n1, 3\n\
                *MATERIAL, NAME=S\n*ELASTIC\n1e9, 0.3\n*DENSITY\n1000.\n*SOLID SECTION, ELSET=E, MATERIAL=S\n";
    let mesh = inp::parse(deck, "faces.inp").unwrap();
    // S1 of a tetrahedron is the face of nodes 1-2-3 and its mid-edge nodes 5, 6, 7.
    let ids: Vec<u64> = mesh.couplings[0].nodes.iter().map(|&n| mesh.nodes[n].id).collect();
    assert_eq!(ids, vec![1, 2, 3, 5, 6, 7]);
    assert_eq!(mesh.node_set("bottom").unwrap().len(), 6);
    let fe = FeModel::assemble(mesh).unwrap();
    // Free: node 4, 8, 9, 10 (3 DOFs each) and the reference node (6).
    assert_eq!(fe.model.n_dofs(), 4 * 3 + 6);
    let hex = stickslip_fe::mesh::inp::face_local_nodes(SolidKind::Hex20, 3).unwrap();
    // S3 of a hexahedron: corners 1-5-6-2 (0-based 0, 4, 5, 1) and the mid-edge nodes of its
    // edges (0,1), (4,5), (0,4), (1,5).
    assert_eq!(hex, vec![0, 4, 5, 1, 8, 12, 16, 17]);
}

#[test]
fn conflicting_constraints_are_reported_by_node_and_dof() {
    // Node 3's u_x is the dependent DOF of two equations.
    let deck = format!("{DECK}*EQUATION\n2\n3, 1, 1., 2, 1, -1.\n2\n3, 1, 1., 1, 1, -1.\n");
    let err = FeModel::assemble(inp::parse(&deck, "twice.inp").unwrap()).unwrap_err().to_string();
    assert!(err.contains("DOF 1 of node 3 is constrained twice") && err.contains("twice.inp:"), "{err}");
    // u_3x = u_2x and u_2x = u_3x: a cycle.
    let deck = format!("{DECK}*EQUATION\n2\n3, 1, 1., 2, 1, -1.\n2\n2, 1, 1., 3, 1, -1.\n");
    let err = FeModel::assemble(inp::parse(&deck, "cycle.inp").unwrap()).unwrap_err().to_string();
    assert!(err.contains("through a cycle"), "{err}");
    // A fixed slave.
    let deck = format!("{DECK}*EQUATION\n2\n2, 2, 1., 3, 2, -1.\n");
    let err = FeModel::assemble(inp::parse(&deck, "fixed.inp").unwrap()).unwrap_err().to_string();
    assert!(err.contains("DOF 2 of node 2") && err.contains("*BOUNDARY"), "{err}");
}
