//! Contact patches from a mesh: node-to-node pairing of two conforming surfaces, tributary
//! areas, the interface frame, errors naming the sets and nodes, and the static pre-step's
//! normal loads against hand computations.

use stickslip_fe::assembly::FeModel;
use stickslip_fe::element::SolidKind;
use stickslip_fe::mesh::generate::box_mesh;
use stickslip_fe::mesh::lap_joint::LapJoint;
use stickslip_fe::mesh::{Material, Mesh};
use stickslip_fe::patch::{
    normal_forces, pair_sets, pair_vectors, spread_force, static_displacement, with_springs, PatchError, Spring,
};

const STEEL: Material = Material { young: 2.1e11, poisson: 0.3, density: 7800.0 };

fn lap(kind: SolidKind, overlap_cells: usize, cells_across: usize) -> LapJoint {
    LapJoint {
        length: 0.2,
        width: 0.03,
        thickness: 0.005,
        cells_along: 10,
        overlap_cells,
        cells_across,
        cells_through: 1,
        kind,
    }
}

fn clamped(mut mesh: Mesh) -> FeModel {
    let clamp = mesh.node_set("CLAMP").unwrap().to_vec();
    mesh.fixed.extend(clamp.iter().flat_map(|&n| (1..=3).map(move |d| (n, d))));
    FeModel::assemble(mesh).unwrap()
}

#[test]
fn lap_joint_pairs_with_areas_summing_to_the_overlap() {
    // hex8, 4 × 3 overlap cells: 5 × 4 = 20 pairs; hex20, 2 × 2 cells: 5 × 5 − 4 = 21 pairs
    // (serendipity faces have no centre node).
    for (kind, cells, across, expected) in [(SolidKind::Hex8, 4, 3, 20), (SolidKind::Hex20, 2, 2, 21)] {
        let design = lap(kind, cells, across);
        let mesh = design.build(STEEL).unwrap();
        let patch = pair_sets(&mesh, "A_CONTACT", "B_CONTACT", None, None).unwrap();
        assert_eq!(patch.pairs.len(), expected, "{kind:?}");
        let exact = design.overlap() * design.width;
        let err = (patch.area() - exact).abs() / exact;
        assert!(err < 1e-12, "{kind:?}: area {} vs {exact} ({err:.2e})", patch.area());
        for p in &patch.pairs {
            let (xa, xb) = (mesh.nodes[p.a].xyz, mesh.nodes[p.b].xyz);
            assert!((0..3).all(|d| (xa[d] - xb[d]).abs() < 1e-15), "pair at {xa:?} and {xb:?}");
            assert!(mesh.node_set("A_CONTACT").unwrap().contains(&p.a) && p.area > 0.0);
        }
        // Out of A (the lower plate) into B: +z; the tangents complete a right-handed frame.
        assert!((0..3).all(|d| (patch.normal[d] - [0.0, 0.0, 1.0][d]).abs() < 1e-15), "{:?}", patch.normal);
        let [t1, t2] = patch.tangents;
        let dot = |a: [f64; 3], b: [f64; 3]| a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
        assert!(dot(t1, t1) - 1.0 < 1e-15 && dot(t2, t2) - 1.0 < 1e-15 && dot(t1, t2).abs() < 1e-15);
        assert!(dot(t1, patch.normal).abs() < 1e-15 && dot(t2, patch.normal).abs() < 1e-15);
        let c = [t1[1] * t2[2] - t1[2] * t2[1], t1[2] * t2[0] - t1[0] * t2[2], t1[0] * t2[1] - t1[1] * t2[0]];
        assert!((0..3).all(|d| (c[d] - patch.normal[d]).abs() < 1e-15));
    }
    // hex8: a corner of the overlap carries a quarter cell, an edge node half a cell, an
    // inner node a whole cell (cells 0.02 m × 0.01 m).
    let mesh = lap(SolidKind::Hex8, 4, 3).build(STEEL).unwrap();
    let patch = pair_sets(&mesh, "A_CONTACT", "B_CONTACT", None, None).unwrap();
    let cell = 0.02 * 0.01;
    let mut areas: Vec<f64> = patch.pairs.iter().map(|p| p.area / cell).collect();
    areas.sort_by(f64::total_cmp);
    let count = |x: f64| areas.iter().filter(|a| (**a - x).abs() < 1e-12).count();
    assert_eq!((count(0.25), count(0.5), count(1.0)), (4, 10, 6));
}

#[test]
fn tetrahedral_surface_areas_sum_to_the_face() {
    // A box of tet10 (faces are triangles with mid-edge nodes), paired with a copy of its
    // top face's nodes: the areas sum to the face, 0.3 × 0.2 m.
    let mut mesh = box_mesh([0.3, 0.2, 0.1], [3, 2, 2], SolidKind::Tet10, STEEL);
    let top = mesh.node_set("ZMAX").unwrap().to_vec();
    let first = mesh.nodes.len() as u64 + 1;
    let copies: Vec<usize> =
        top.iter().enumerate().map(|(i, &n)| mesh.add_node(first + i as u64, mesh.nodes[n].xyz).unwrap()).collect();
    mesh.add_node_set("COPY", copies);
    let patch = pair_sets(&mesh, "ZMAX", "COPY", None, Some([1.0, 1.0, 5.0])).unwrap();
    assert!((patch.area() - 0.06).abs() < 1e-12 * 0.06, "area {}", patch.area());
    assert_eq!(patch.normal, [0.0, 0.0, 1.0]);
    // The given tangent, projected on the plane: (1, 1, 0)/√2.
    let s = 0.5f64.sqrt();
    assert!((patch.tangents[0][0] - s).abs() < 1e-15 && (patch.tangents[0][1] - s).abs() < 1e-15);
}

#[test]
fn sets_that_do_not_pair_up_are_refused_naming_the_nodes() {
    let mut mesh = lap(SolidKind::Hex8, 4, 3).build(STEEL).unwrap();
    let error = |mesh: &Mesh, a: &str, b: &str, normal| pair_sets(mesh, a, b, normal, None).unwrap_err().to_string();

    // B without one node: the A node at its position is named.
    let b = mesh.node_set("B_CONTACT").unwrap().to_vec();
    let dropped = b[7];
    mesh.node_sets.insert("B_SHORT".into(), b.iter().copied().filter(|&n| n != dropped).collect());
    let twin = mesh
        .node_set("A_CONTACT")
        .unwrap()
        .iter()
        .copied()
        .find(|&n| (0..3).all(|d| (mesh.nodes[n].xyz[d] - mesh.nodes[dropped].xyz[d]).abs() < 1e-12));
    let message = error(&mesh, "A_CONTACT", "B_SHORT", None);
    println!("{message}");
    assert!(message.contains("\"A_CONTACT\" and \"B_SHORT\" do not pair up"), "{message}");
    assert!(message.contains(&format!("nodes {}", mesh.nodes[twin.unwrap()].id)), "{message}");

    // B with an extra node: that node is named.
    let mut extra = b.clone();
    let top = mesh.node_set("BOLT_TOP").unwrap()[0];
    extra.push(top);
    extra.sort_unstable();
    mesh.node_sets.insert("B_LONG".into(), extra);
    let message = error(&mesh, "A_CONTACT", "B_LONG", None);
    assert!(message.contains("1 node(s) of \"B_LONG\"") && message.contains(&mesh.nodes[top].id.to_string()));

    // A whole set elsewhere: at most ten ids, and the count.
    let message = error(&mesh, "A_CONTACT", "BOLT_TOP", None);
    println!("{message}");
    assert!(message.contains("20 node(s) of \"A_CONTACT\"") && message.contains("(20 in all)"), "{message}");

    // A set with itself; an unknown set; a normal pointing into A; a set that is no surface.
    assert!(error(&mesh, "A_CONTACT", "A_CONTACT", None).contains("belong to both"));
    let message = error(&mesh, "A_CONTACT", "NOPE", None);
    assert!(message.contains("no node set \"NOPE\"") && message.contains("B_CONTACT"), "{message}");
    let message = error(&mesh, "A_CONTACT", "B_CONTACT", Some([0.0, 0.0, -1.0]));
    assert!(message.contains("points into the body of \"A_CONTACT\""), "{message}");
    let message = error(&mesh, "TIP", "B_CONTACT", None);
    assert!(message.contains("no contact area"), "{message}");
}

/// Normal forces of the lap joint's pairs (and their sum) after the static pre-step with the
/// contacts closed (stiffnesses per area k_n = 1e14, k_t = 5e13 N/m³), a force `force_top` (N)
/// down on BOLT_TOP and `force_bottom` up on BOLT_BOTTOM.
fn preload(fe: &FeModel, force_top: f64, force_bottom: f64) -> Result<(Vec<f64>, f64), PatchError> {
    let patch = pair_sets(&fe.mesh, "A_CONTACT", "B_CONTACT", None, None)?;
    let (kn, kt) = (1e14, 5e13);
    let dirs = [(patch.tangents[0], "t1"), (patch.tangents[1], "t2"), (patch.normal, "normal")];
    let vectors: Vec<_> = patch.pairs.iter().map(|p| pair_vectors(fe, p, &dirs).unwrap()).collect();
    let areas: Vec<f64> = patch.pairs.iter().map(|p| p.area).collect();
    let mut springs = Vec::new();
    for (v, area) in vectors.iter().zip(&areas) {
        springs.push(Spring { stiffness: kt * area, vector: &v[0] });
        springs.push(Spring { stiffness: kt * area, vector: &v[1] });
        springs.push(Spring { stiffness: kn * area, vector: &v[2] });
    }
    let mut f = spread_force(fe, fe.mesh.node_set("BOLT_TOP").unwrap(), [0.0, 0.0, -force_top]);
    let bottom = spread_force(fe, fe.mesh.node_set("BOLT_BOTTOM").unwrap(), [0.0, 0.0, force_bottom]);
    f.iter_mut().zip(bottom).for_each(|(x, y)| *x += y);
    let closed = stickslip_core::model::Matrix::Sparse(with_springs(&fe.model.stiffness, &springs));
    let u = static_displacement(&closed, &f)?;
    let normals: Vec<&[(usize, f64)]> = vectors.iter().map(|v| v[2].as_slice()).collect();
    let kn_pairs: Vec<f64> = areas.iter().map(|a| kn * a).collect();
    let forces = normal_forces(fe, &patch.pairs, &normals, &kn_pairs, &u)?;
    Ok((forces.clone(), forces.iter().sum()))
}

#[test]
fn static_pre_step_normal_loads_match_hand_computations() {
    // One cube on another, the lower one clamped at its base, 4 kN down spread over the top
    // of the upper one: by equilibrium of the upper cube and the symmetry of the square, each
    // of the four pairs carries 1 kN.
    let mut lower = box_mesh([0.01; 3], [1, 1, 1], SolidKind::Hex8, STEEL);
    let upper = box_mesh([0.01; 3], [1, 1, 1], SolidKind::Hex8, STEEL);
    let n0 = lower.nodes.len();
    for n in &upper.nodes {
        lower.add_node(100 + n.id, [n.xyz[0], n.xyz[1], n.xyz[2] + 0.01]).unwrap();
    }
    for s in &upper.solids {
        let mut s = s.clone();
        s.id += 100;
        s.nodes.iter_mut().for_each(|n| *n += n0);
        lower.solids.push(s);
    }
    let top_of_lower = lower.node_set("ZMAX").unwrap().to_vec();
    let base = lower.node_set("ZMIN").unwrap().to_vec();
    lower.node_sets.clear();
    lower.add_node_set("A_CONTACT", top_of_lower);
    lower.add_node_set("B_CONTACT", upper.node_set("ZMIN").unwrap().iter().map(|&n| n + n0));
    lower.add_node_set("BOLT_TOP", upper.node_set("ZMAX").unwrap().iter().map(|&n| n + n0));
    lower.add_node_set("BOLT_BOTTOM", base.clone());
    lower.fixed.extend(base.iter().flat_map(|&n| (1..=3).map(move |d| (n, d))));
    let fe = FeModel::assemble(lower).unwrap();
    let (forces, total) = preload(&fe, 4000.0, 0.0).unwrap();
    assert_eq!(forces.len(), 4);
    for f in &forces {
        assert!((f - 1000.0).abs() < 1e-9 * 1000.0, "pair force {f} N, expected 1000 N");
    }
    assert!((total - 4000.0).abs() < 1e-9 * 4000.0);

    // The lap joint clamped by a bolt (2 kN on B's top, 2 kN up on A's bottom over the overlap):
    // B is held by the contacts alone, so their normal forces sum to the bolt force; the
    // distribution is not uniform, but every pair is pressed.
    let fe = clamped(lap(SolidKind::Hex8, 4, 3).build(STEEL).unwrap());
    let (forces, total) = preload(&fe, 2000.0, 2000.0).unwrap();
    println!("lap joint pair forces: {forces:.1?}");
    assert!((total - 2000.0).abs() < 1e-8 * 2000.0, "sum of normal forces {total} N");
    assert!(forces.iter().all(|f| *f > 0.0));

    // Pulling the plates apart leaves the pairs in tension: refused, naming them.
    let message = preload(&fe, -2000.0, -2000.0).unwrap_err().to_string();
    println!("{message}");
    assert!(message.contains("not pressed together at rest") && message.contains("N)"), "{message}");
}
