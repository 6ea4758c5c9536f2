//! The meshes of examples/lap-joint are those of the lap joint generator: the plates with the
//! contact patch's node sets (`lap-joint.inp`), and the same plates with each contact surface
//! rigidly coupled to a reference node, the two reference nodes joined by a connector that
//! carries the patch's total stiffnesses (`lap-joint-jenkins.inp`, the 1-D simplification).
//! `STICKSLIP_WRITE_EXAMPLES=1` rewrites them.

use std::path::PathBuf;

use stickslip_fe::element::SolidKind;
use stickslip_fe::mesh::lap_joint::LapJoint;
use stickslip_fe::mesh::{inp_writer, Material, Mesh, PointElement, RigidCoupling};
use stickslip_fe::patch::pair_sets;

/// Steel plates 0.2 × 0.03 × 0.005 m, hex20, overlap 0.04 m (3 × 2 cells: 29 contact pairs).
fn design() -> LapJoint {
    LapJoint {
        length: 0.2,
        width: 0.03,
        thickness: 0.005,
        cells_along: 15,
        overlap_cells: 3,
        cells_across: 2,
        cells_through: 1,
        kind: SolidKind::Hex20,
    }
}

const STEEL: Material = Material { young: 2.1e11, poisson: 0.3, density: 7800.0 };

/// The study's contact stiffnesses per area (N/m³), as in examples/lap-joint/study.toml.
const NORMAL_PER_AREA: f64 = 1.0e12;
const TANGENTIAL_PER_AREA: f64 = 5.0e11;

/// The 1-D simplification: reference nodes 10001 (on A) and 10002 (on B) at the patch's
/// centre, every contact node of each side rigidly coupled to its reference node, and a
/// connector with the patch's total stiffnesses (the sums of the pairs' k A over the patch):
/// tangential along y, normal along z, rotations Σ k_n A (y − y_c)², Σ k_n A (x − x_c)² and
/// Σ k_t A r². Along x (the lap's length) the study's Jenkins element replaces Σ k_t A.
fn jenkins_mesh() -> (Mesh, f64) {
    let mut mesh = design().build(STEEL).unwrap();
    let patch = pair_sets(&mesh, "A_CONTACT", "B_CONTACT", None, None).unwrap();
    let area = patch.area();
    let centre = patch.pairs.iter().fold([0.0; 3], |c, p| {
        let x = mesh.nodes[p.a].xyz;
        [0, 1, 2].map(|d| c[d] + x[d] * p.area / area)
    });
    let (mut krx, mut kry, mut krz) = (0.0, 0.0, 0.0);
    for p in &patch.pairs {
        let x = mesh.nodes[p.a].xyz;
        let (dx, dy) = (x[0] - centre[0], x[1] - centre[1]);
        krx += NORMAL_PER_AREA * p.area * dy * dy;
        kry += NORMAL_PER_AREA * p.area * dx * dx;
        krz += TANGENTIAL_PER_AREA * p.area * (dx * dx + dy * dy);
    }
    let ra = mesh.add_node(10001, centre).unwrap();
    let rb = mesh.add_node(10002, centre).unwrap();
    for (reference, set) in [(ra, "A_CONTACT"), (rb, "B_CONTACT")] {
        let nodes = mesh.node_set(set).unwrap().to_vec();
        mesh.couplings.push(RigidCoupling { reference, nodes, dofs: vec![1, 2, 3, 4, 5, 6], at: Default::default() });
    }
    let kt = TANGENTIAL_PER_AREA * area;
    mesh.points.push(PointElement::Connector {
        id: 10001,
        a: ra,
        b: Some(rb),
        stiffness: [kt, kt, NORMAL_PER_AREA * area, krx, kry, krz],
    });
    mesh.add_node_set("REFERENCES", [ra, rb]);
    (mesh, area)
}

fn check(name: &str, mesh: &Mesh) {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../examples/lap-joint").join(name);
    let text = inp_writer::to_string(mesh).unwrap();
    if std::env::var_os("STICKSLIP_WRITE_EXAMPLES").is_some() {
        std::fs::write(&path, &text).unwrap();
    }
    let shipped = std::fs::read_to_string(&path).unwrap_or_default();
    assert!(
        shipped == text,
        "{} differs from the generator; rewrite it with STICKSLIP_WRITE_EXAMPLES=1",
        path.display()
    );
}

#[test]
fn example_meshes_are_the_generators() {
    let mesh = design().build(STEEL).unwrap();
    let patch = pair_sets(&mesh, "A_CONTACT", "B_CONTACT", None, None).unwrap();
    assert_eq!(patch.pairs.len(), 29);
    check("lap-joint.inp", &mesh);
    let (jenkins, area) = jenkins_mesh();
    assert!((area - 0.04 * 0.03).abs() < 1e-15);
    check("lap-joint-jenkins.inp", &jenkins);
}
