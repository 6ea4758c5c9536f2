//! Patch tests, rigid-body modes and mass of every solid element, on distorted meshes.

mod element_support;

use element_support::Lcg;
use faer::linalg::solvers::Solve;
use faer::{Mat, Side};
use stickslip_fe::assembly::{FeModel, Options};
use stickslip_fe::element::shape::{HEX20_EDGES, TET10_EDGES};
use stickslip_fe::element::{MassRule, SolidKind};
use stickslip_fe::mesh::generate::box_mesh;
use stickslip_fe::mesh::{Material, Mesh};

const STEEL: Material = Material { young: 210e9, poisson: 0.3, density: 7800.0 };
const SIZE: [f64; 3] = [1.0, 0.8, 0.6];

/// A 3×3×3-cell box whose interior nodes are moved by up to 8 % of a cell, so the elements
/// are general: non-affine, curved-edged hex20. Tet10 and hex20R edges are kept straight
/// (mid-edge nodes back at the midpoints): their rules (CalculiX's 4 points and 2×2×2) are
/// exact for straight-edged elements only; curved, they do not even get the volume right.
fn distorted(kind: SolidKind) -> (Mesh, Vec<bool>) {
    let mut mesh = box_mesh(SIZE, [3, 3, 3], kind, STEEL);
    let mut boundary = vec![false; mesh.nodes.len()];
    for set in ["XMIN", "XMAX", "YMIN", "YMAX", "ZMIN", "ZMAX"] {
        for &n in mesh.node_set(set).unwrap() {
            boundary[n] = true;
        }
    }
    let mut rng = Lcg(7);
    for (n, node) in mesh.nodes.iter_mut().enumerate() {
        if !boundary[n] {
            for (x, size) in node.xyz.iter_mut().zip(SIZE) {
                *x += 0.08 * size / 3.0 * rng.next();
            }
        }
    }
    if matches!(kind, SolidKind::Tet10 | SolidKind::Hex20R) {
        let edges: &[(usize, usize)] = if kind == SolidKind::Tet10 { &TET10_EDGES } else { &HEX20_EDGES };
        let first_mid = kind.n_corners();
        for s in 0..mesh.solids.len() {
            for (e, &(a, b)) in edges.iter().enumerate() {
                let nodes = &mesh.solids[s].nodes;
                let (na, nb, mid) = (nodes[a], nodes[b], nodes[first_mid + e]);
                mesh.nodes[mid].xyz = [0, 1, 2].map(|d| 0.5 * (mesh.nodes[na].xyz[d] + mesh.nodes[nb].xyz[d]));
            }
        }
    }
    (mesh, boundary)
}

/// Displacements `u = A x + b` of every node, in model DOF order.
fn linear_field(fe: &FeModel, a: [[f64; 3]; 3], b: [f64; 3]) -> Vec<f64> {
    let mut u = vec![0.0; fe.model.n_dofs()];
    for node in &fe.mesh.nodes {
        for i in 0..3 {
            let v = b[i] + (0..3).map(|j| a[i][j] * node.xyz[j]).sum::<f64>();
            u[fe.dof(node.id, i as u8 + 1).unwrap()] = v;
        }
    }
    u
}

#[test]
fn patch_test_reproduces_a_constant_strain_field() {
    let a = [[1e-3, 2e-4, -3e-4], [5e-4, -2e-3, 1e-4], [-4e-4, 3e-4, 1.5e-3]];
    let b = [1e-4, -2e-4, 3e-4];
    for kind in SolidKind::ALL {
        let (mesh, boundary) = distorted(kind);
        let fe = FeModel::assemble(mesh).unwrap();
        let exact = linear_field(&fe, a, b);
        // Interior DOFs solve K_II u_I = −K_IB u_B with the boundary on the exact field.
        let mut is_boundary = vec![false; fe.model.n_dofs()];
        for (n, node) in fe.mesh.nodes.iter().enumerate() {
            for d in 1..=3 {
                is_boundary[fe.dof(node.id, d).unwrap()] = boundary[n];
            }
        }
        let interior: Vec<usize> = (0..exact.len()).filter(|&i| !is_boundary[i]).collect();
        let k = fe.model.stiffness.to_dense();
        let kii = Mat::from_fn(interior.len(), interior.len(), |i, j| k[(interior[i], interior[j])]);
        let mut rhs = Mat::from_fn(interior.len(), 1, |i, _| {
            -(0..exact.len()).filter(|&j| is_boundary[j]).map(|j| k[(interior[i], j)] * exact[j]).sum::<f64>()
        });
        kii.llt(Side::Lower).unwrap().solve_in_place(rhs.as_mut());
        let scale = exact.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        let err = interior.iter().enumerate().map(|(i, &g)| (rhs[(i, 0)] - exact[g]).abs()).fold(0.0, f64::max);
        println!("{kind:?}: {} interior DOFs, patch-test error {:.2e}", interior.len(), err / scale);
        // The linear field is in every element's span: only round-off of a well-conditioned
        // solve (~1e-14 here) separates the result from it.
        assert!(err / scale < 1e-10, "{kind:?}: patch-test error {:.3e}", err / scale);
    }
}

#[test]
fn rigid_body_motions_store_no_strain_energy() {
    for kind in SolidKind::ALL {
        let (mesh, _) = distorted(kind);
        let fe = FeModel::assemble(mesh).unwrap();
        let n = fe.model.n_dofs();
        let k_norm = fe.model.stiffness.to_dense().norm_max();
        // Three translations and three infinitesimal rotations u = θ × x.
        let skew = |t: [f64; 3]| [[0.0, -t[2], t[1]], [t[2], 0.0, -t[0]], [-t[1], t[0], 0.0]];
        let motions = [
            linear_field(&fe, [[0.0; 3]; 3], [1.0, 0.0, 0.0]),
            linear_field(&fe, [[0.0; 3]; 3], [0.0, 1.0, 0.0]),
            linear_field(&fe, [[0.0; 3]; 3], [0.0, 0.0, 1.0]),
            linear_field(&fe, skew([1.0, 0.0, 0.0]), [0.0; 3]),
            linear_field(&fe, skew([0.0, 1.0, 0.0]), [0.0; 3]),
            linear_field(&fe, skew([0.0, 0.0, 1.0]), [0.0; 3]),
        ];
        for u in &motions {
            let mut ku = vec![0.0; n];
            fe.model.stiffness.mul_vec(u, &mut ku);
            let u_norm = u.iter().fold(0.0f64, |m, v| m.max(v.abs()));
            let r = ku.iter().fold(0.0f64, |m, v| m.max(v.abs())) / (k_norm * u_norm);
            // Round-off of sums of ~100 terms of size |K|·|u|.
            assert!(r < 1e-12, "{kind:?}: |K u_rigid| / (|K| |u|) = {r:.3e}");
        }
    }
}

#[test]
fn mass_matrix_holds_density_times_volume_and_the_rotary_inertia() {
    let volume = SIZE[0] * SIZE[1] * SIZE[2];
    for kind in SolidKind::ALL {
        for rule in [MassRule::CalculiX, MassRule::Exact] {
            // Translation: Σ M = ρ V for any rule integrating Σ N_a = 1 (all do), distorted or not.
            let (mesh, _) = distorted(kind);
            let fe = FeModel::assemble_with(mesh, Options { mass_rule: rule }).unwrap();
            let ux = linear_field(&fe, [[0.0; 3]; 3], [1.0, 0.0, 0.0]);
            let m = fe.model.mass.bilinear(&ux, &ux);
            assert!((m / (STEEL.density * volume) - 1.0).abs() < 1e-12, "{kind:?} {rule:?}: mass {m}");
            assert!((fe.volume / volume - 1.0).abs() < 1e-12, "{kind:?}: volume {}", fe.volume);
            // Rotation about z through the origin of an undistorted box: uᵀ M u = ρ ∫ (x² + y²)
            // = ρ V (Lx² + Ly²) / 3, exact when the mass is integrated exactly.
            if rule == MassRule::Exact {
                let fe = FeModel::assemble_with(box_mesh(SIZE, [3, 2, 2], kind, STEEL), Options { mass_rule: rule })
                    .unwrap();
                let rz = linear_field(&fe, [[0.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0; 3]], [0.0; 3]);
                let i_zz = fe.model.mass.bilinear(&rz, &rz);
                let exact = STEEL.density * volume * (SIZE[0].powi(2) + SIZE[1].powi(2)) / 3.0;
                assert!((i_zz / exact - 1.0).abs() < 1e-12, "{kind:?}: I_zz {i_zz} vs {exact}");
            }
        }
    }
}

#[test]
fn inverted_element_is_reported_by_id() {
    let mut mesh = box_mesh([1.0; 3], [2, 1, 1], SolidKind::Hex8, STEEL);
    // Mirror element 2's nodes through its bottom face: a negative Jacobian everywhere.
    mesh.solids[1].nodes.rotate_left(4);
    let err = FeModel::assemble(mesh).unwrap_err().to_string();
    assert!(err.contains("element 2") && err.contains("inverted"), "{err}");
    let mut mesh = box_mesh([1.0; 3], [1, 1, 1], SolidKind::Tet4, STEEL);
    // A flat tetrahedron: its fourth node moved into the plane of the first three.
    let face = mesh.solids[3].nodes[..3].to_vec();
    let apex = mesh.solids[3].nodes[3];
    let c = [0, 1, 2].map(|d| face.iter().map(|&n| mesh.nodes[n].xyz[d]).sum::<f64>() / 3.0);
    mesh.nodes[apex].xyz = c;
    let err = FeModel::assemble(mesh).unwrap_err().to_string();
    assert!(err.contains("inverted or degenerate"), "{err}");
}
