//! Mode shapes written as VTK legacy files: read back, the file holds the mesh and the
//! nodal displacements of each mode.

use stickslip_fe::assembly::FeModel;
use stickslip_fe::element::SolidKind;
use stickslip_fe::mesh::generate::box_mesh;
use stickslip_fe::mesh::Material;

#[test]
fn writes_mesh_and_mode_shapes() {
    let steel = Material { young: 210e9, poisson: 0.3, density: 7800.0 };
    let mut mesh = box_mesh([1.0, 0.2, 0.1], [4, 1, 1], SolidKind::Hex20, steel);
    let clamped = mesh.node_set("XMIN").unwrap().to_vec();
    mesh.fixed = clamped.iter().flat_map(|&n| (1..=3).map(move |d| (n, d))).collect();
    let fe = FeModel::assemble(mesh).unwrap();
    let modes = fe.model.dense_modes().unwrap();
    let f = modes.frequencies_hz();
    let shapes: Vec<(String, Vec<f64>)> = (0..2)
        .map(|r| {
            (format!("mode{}_{:.1}Hz", r + 1, f[r]), (0..fe.model.n_dofs()).map(|i| modes.shapes[(i, r)]).collect())
        })
        .collect();
    let mut out = Vec::new();
    fe.write_vtk(&mut out, "cantilever modes", &shapes).unwrap();
    let text = String::from_utf8(out).unwrap();
    let lines: Vec<&str> = text.lines().collect();
    assert_eq!(lines[0], "# vtk DataFile Version 3.0");
    assert!(lines.contains(&format!("POINTS {} double", fe.mesh.nodes.len()).as_str()));
    let cells = lines.iter().position(|l| l.starts_with("CELLS")).unwrap();
    assert_eq!(lines[cells], format!("CELLS {} {}", fe.mesh.solids.len(), 21 * fe.mesh.solids.len()));
    let types = lines.iter().position(|l| l.starts_with("CELL_TYPES")).unwrap();
    assert!(lines[types + 1..types + 1 + fe.mesh.solids.len()].iter().all(|l| *l == "25"), "VTK quadratic hexahedra");
    // The second mode's vectors are the nodal translations u = T q (zero on the clamped face).
    let start = lines.iter().position(|l| l.starts_with(&format!("VECTORS {} double", shapes[1].0))).unwrap();
    let u = fe.nodal_displacements(&shapes[1].1);
    for (n, line) in lines[start + 1..start + 1 + u.len()].iter().enumerate() {
        let v: Vec<f64> = line.split_whitespace().map(|x| x.parse().unwrap()).collect();
        for d in 0..3 {
            // Written with 17 significant digits ({:e} round-trips f64).
            assert_eq!(v[d], u[n][d]);
        }
    }
    assert!(clamped.iter().all(|&n| u[n] == [0.0; 3]));
}
