//! The generated Harmony-like assembly against the paper's figures (Tables 1, 3-5), at the
//! coarse refinement that CI affords (element size 60 mm, ~31k DOFs). The default refinement
//! (30 mm, 63,700 DOFs) is calibrated to the paper; docs/harmony.md gives the mesh convergence and
//! the substructures of Table 4.

use stickslip_fe::assembly::FeModel;
use stickslip_fe::eigen::{solve, to_sparse, EigenOptions};
use stickslip_fe::harmony::{self, BodyVariant, Configuration, Design, TipContact};
use stickslip_fe::mesh::structured::GenerateError;
use stickslip_fe::patch::pair_sets;

/// Frequencies (Hz) of the axial modes among the lowest `count`: those where the top of the
/// central body (accelerometer 101) or the centre of the base plate (102) moves vertically more
/// than a tenth of the most it does.
fn axial_modes(design: &Design, count: usize) -> (Vec<f64>, f64) {
    let mesh = design.build(Configuration::Assembly).expect("a buildable design");
    let fe = FeModel::assemble(mesh).expect("assembly");
    let (k, m) = (to_sparse(&fe.model.stiffness), to_sparse(&fe.model.mass));
    let (k, m) = (k.into_owned(), m.into_owned());
    let sol = solve(&k, &m, &EigenOptions { count, ..Default::default() }).expect("modes");
    let f = sol.modes.frequencies_hz();
    let mut axial = Vec::new();
    for probe in [0, 1] {
        let dof = fe.dof(harmony::accelerometer(probe), 3).expect("sensor DOF");
        let amp: Vec<f64> = (0..count).map(|j| sol.modes.shapes[(dof, j)].abs()).collect();
        // The first mode is the whole structure on the shaker's soft spring (~2.7 Hz).
        let largest = amp.iter().skip(1).copied().fold(0.0, f64::max);
        axial.extend((1..count).filter(|&j| amp[j] > 0.1 * largest).map(|j| f[j]));
    }
    axial.sort_by(f64::total_cmp);
    axial.dedup();
    (axial, fe.solid_mass)
}

#[test]
fn coarse_assembly_has_the_paper_axial_modes_and_masses() {
    let design = Design::refined(0.5);
    let (stuck, mass) = axial_modes(&design, 24);
    println!("stuck axial modes {stuck:.1?} Hz");
    // Table 1: 9.47 + 44.88 + 11.92 + 4 x 0.1086 kg; the parts' dimensions are set from these
    // masses on the exact geometry, the mesh differs by the arcs' quadratic interpolation.
    let table1 = 9.47 + 44.88 + 11.92 + 4.0 * 0.1086;
    assert!((mass - table1).abs() < 5e-3 * table1, "solid mass {mass} kg vs Table 1 {table1} kg");
    // Table 5: 237.6 Hz and 878.4 Hz. The coarse mesh is stiffer than the calibrated default
    // (measured: 250.0 Hz, +5.2 % on the first mode, against 237.9 Hz at the default
    // refinement, see docs/harmony.md): 6 % covers it, and a change of the model that moves the
    // mode by more than the mesh error fails.
    assert!(stuck.len() >= 2, "axial modes found: {stuck:?}");
    assert!((stuck[0] / 237.6 - 1.0).abs() < 0.06, "first axial mode {} Hz", stuck[0]);
    assert!((stuck[1] / 878.4 - 1.0).abs() < 0.05, "second axial mode {} Hz", stuck[1]);
    // All blades slipping (contact connectors released vertically): the paper's asymptote near
    // 190 Hz (Section 5.1); coarse mesh 198.1 Hz, +4.3 %.
    let released = Design { contact_vertical_stiffness: 0.0, ..design };
    let (slipping, _) = axial_modes(&released, 6);
    assert!((slipping[0] / 190.0 - 1.0).abs() < 0.06, "all-slipping axial mode {} Hz", slipping[0]);
    assert!(slipping[0] < 0.9 * stuck[0]);
}

#[test]
fn default_refinement_has_the_paper_first_axial_mode_within_one_percent() {
    // The example's refinement (63,700 DOFs), where the design is calibrated: Table 5's
    // 237.6 Hz within 1 % (measured 237.85 Hz, +0.1 %; docs/harmony.md), the second axial mode
    // within 5 % of 878.4 Hz (measured 896.7 Hz, +2.1 %).
    let (stuck, _) = axial_modes(&Design::refined(1.0), 24);
    println!("stuck axial modes {stuck:.2?} Hz");
    assert!((stuck[0] / 237.6 - 1.0).abs() < 0.01, "first axial mode {} Hz", stuck[0]);
    assert!(stuck.iter().any(|&f| (f / 878.4 - 1.0).abs() < 0.05), "no second axial mode near 878.4 Hz: {stuck:?}");
}

/// Modes of a configuration: frequencies (Hz) and the mass-normalised shapes' vertical motion at
/// the given nodes, mode by mode.
fn modes(design: &Design, config: Configuration, count: usize, nodes: &[u64]) -> (Vec<f64>, Vec<Vec<f64>>, f64) {
    let fe = FeModel::assemble(design.build(config).expect("a buildable design")).expect("assembly");
    let (k, m) = (to_sparse(&fe.model.stiffness), to_sparse(&fe.model.mass));
    let (k, m) = (k.into_owned(), m.into_owned());
    let sol = solve(&k, &m, &EigenOptions { count, ..Default::default() }).expect("modes");
    let dofs: Vec<usize> = nodes.iter().map(|&n| fe.dof(n, 3).expect("node")).collect();
    let z = (0..count).map(|j| dofs.iter().map(|&i| sol.modes.shapes[(i, j)]).collect()).collect();
    (sol.modes.frequencies_hz(), z, fe.solid_mass)
}

/// The coarse design with an optional body geometry.
fn variant(v: BodyVariant) -> Design {
    Design { variant: Box::new(v), ..Design::refined(0.5) }
}

#[test]
fn coarse_envelope_substructure_has_the_paper_first_vertical_mode() {
    // Table 4: the envelope's first vertical mode, 880.4 Hz (test 889 Hz). Base plate and
    // envelope on the shaker, coupled to it within 37 mm of the axis: the two bounce on the base
    // plate's bending. Measured 868.4 Hz here, 869.0 Hz at the default refinement (-1.3 %); 3 %
    // leaves room for the mesh, not for a change of the coupled zone (39 mm: 897 Hz at the
    // default refinement, the nodes of the next ring coupled).
    let nodes = [harmony::accelerometer(1), harmony::accelerometer(2), harmony::accelerometer(3)];
    let (f, z, mass) = modes(&Design::refined(0.5), Configuration::Envelope, 14, &nodes);
    assert!((mass - (9.47 + 44.88)).abs() < 5e-3 * 54.35, "base plate + envelope {mass} kg");
    // Vertical: the base centre moves, the envelope top moves alike at 45 and 135 degrees.
    let largest = z.iter().skip(1).map(|v| v[0].abs()).fold(0.0, f64::max);
    let first = (1..f.len())
        .find(|&j| z[j][0].abs() > 0.1 * largest && (z[j][1] - z[j][2]).abs() < 0.05 * z[j][1].abs())
        .expect("a vertical mode");
    assert!((f[first] / 880.4 - 1.0).abs() < 0.03, "envelope's first vertical mode {} Hz", f[first]);
}

#[test]
fn coarse_body_substructure_has_the_paper_synchronous_mode_and_four_blade_modes() {
    // Table 4, central body + blades (clamped on the flange's circle, tips free): the first
    // vertical mode with blades and body synchronous at 210.8 Hz (test 218.7 Hz), then four
    // modes involving the blades asynchronously at 254-260 Hz (test 247-251.5 Hz). Measured
    // here 219.3 Hz (+4.0 %) and 260.4, 261.6, 261.6, 269.5 Hz; at the default refinement
    // 210.4 Hz (-0.2 %) and 257.3, 258.4, 258.4, 265.5 Hz (docs/harmony.md). 6 % and the band
    // widened by 5 % cover the coarse mesh's stiffness (as the assembly's first mode, +5.2 %).
    let nodes = [
        harmony::accelerometer(0),
        harmony::top_blade(1),
        harmony::top_blade(2),
        harmony::top_blade(3),
        harmony::top_blade(4),
    ];
    let (f, z, mass) = modes(&Design::refined(0.5), Configuration::BodyWithBlades, 12, &nodes);
    assert!((mass - (11.92 + 4.0 * 0.1086)).abs() < 1e-2 * 12.35, "body + blades {mass} kg");
    // Synchronous: the body top and the four tips move up together.
    let sync = (0..f.len())
        .find(|&j| z[j][0].abs() > 0.1 && z[j][1..].iter().all(|t| t * z[j][0] > 0.0))
        .expect("the synchronous axial mode");
    assert!((f[sync] / 210.8 - 1.0).abs() < 0.06, "synchronous mode {} Hz", f[sync]);
    // The next four: the blades' bending, the tips moving at least ten times the body top.
    for j in sync + 1..sync + 5 {
        assert!(f[j] > 0.95 * 254.0 && f[j] < 1.05 * 260.0, "blade mode {} Hz", f[j]);
        let tip = z[j][1..].iter().map(|t| t.abs()).fold(0.0, f64::max);
        assert!(tip > 10.0 * z[j][0].abs(), "mode {} Hz: tips {:?}, body top {}", f[j], &z[j][1..], z[j][0]);
    }
    assert!(f[sync + 5] > 400.0, "a fifth mode near the blades' at {} Hz", f[sync + 5]);
}

#[test]
fn upright_blades_give_four_asynchronous_blade_modes_in_the_body_substructure() {
    // The variant of docs/harmony.md (not the default): Table 1's blade as a 65 mm high,
    // 118 mm long plate standing on edge (1.82 mm thick from its mass). Clamped body, free tips:
    // the blades' four tangential bending modes lie within 3 % of each other (paper: four modes
    // at 254-260 Hz; here ~285 Hz with the default screws), between the body's synchronous
    // axial mode and the top disk's modes.
    let design = variant(BodyVariant { blade_height: Some(0.065), blade_rise: 0.0, ..Default::default() });
    let d = design.dimensions().unwrap();
    assert!((d.blade_width - 1.82e-3).abs() < 0.02e-3, "blade thickness {} m", d.blade_width);
    let (f, z, mass) = modes(&design, Configuration::BodyWithBlades, 16, &[harmony::accelerometer(0)]);
    // 12.43 kg (+0.6 %, as the default design's body: the quadratic arcs and the diaphragm's
    // ring under the hub, counted once in the thickness from the mass).
    assert!((mass - (11.92 + 4.0 * 0.1086)).abs() < 1e-2 * 12.35, "body + blades {mass} kg");
    // The body top does not move in the blade modes; the four nearest modes above the
    // synchronous one are the blades'.
    let sync = (0..f.len()).find(|&j| z[j][0].abs() > 0.1).expect("the synchronous axial mode");
    let blades = &f[sync + 1..sync + 5];
    assert!(blades.iter().all(|&b| (b / blades[0] - 1.0).abs() < 0.03), "blade modes {blades:?} Hz");
    assert!((z[sync + 1..sync + 5]).iter().all(|v| v[0].abs() < 0.01));
}

#[test]
fn optional_body_geometry_keeps_table_1_masses() {
    // The variants docs/harmony.md measures for Table 4: the body's flange clamped on a circle
    // inside the envelope's web, a thin or stepped top disk, a rim, blades on edge.
    let variants = [
        BodyVariant { body_flange_radius: Some(0.13), ..Default::default() },
        BodyVariant { top_disk_thickness: Some(0.0037), rim_width: 0.0, ..Default::default() },
        BodyVariant {
            top_disk_thickness: Some(0.0045),
            rim_width: 0.0,
            top_disk_inner: Some((0.10, 0.0035)),
            body_flange_radius: Some(0.13),
            ..Default::default()
        },
        BodyVariant { top_disk_thickness: Some(0.004), rim_width: 0.02, ..Default::default() },
        BodyVariant { blade_height: Some(0.065), blade_rise: 0.0, ..Default::default() },
        BodyVariant { blade_rise: 0.0, body_flange_radius: None, top_disk_thickness: None, ..Default::default() },
    ]
    .map(variant);
    let table1 = 9.47 + 44.88 + 11.92 + 4.0 * 0.1086;
    for design in variants {
        let fe = FeModel::assemble(design.build(Configuration::Assembly).unwrap()).unwrap();
        assert!((fe.solid_mass - table1).abs() < 5e-3 * table1, "{design:?}: {} kg", fe.solid_mass);
        for config in [Configuration::Envelope, Configuration::BodyWithBlades] {
            assert!(design.build(config).is_ok());
        }
    }
}

#[test]
fn paper_retained_set_has_103_dofs() {
    let mesh = Design::refined(0.5).build(Configuration::Assembly).unwrap();
    let fe = FeModel::assemble(mesh).unwrap();
    let count: usize = ["ACCELEROMETERS", "SHAKER", "BLADE_SCREWS", "CONTACT_ZONES"]
        .iter()
        .map(|s| fe.set_dofs(s).unwrap().len())
        .sum();
    // 10 tri-axial accelerometers, the shaker's vertical DOF, 3 reference nodes x 6 per blade.
    assert_eq!(count, 103);
    // The blade tips (Top_Blade) exist, with 6 DOFs, and are not in the retained sets.
    for i in 1..=4 {
        assert!(fe.dof(harmony::top_blade(i), 3).is_ok());
    }
}

#[test]
fn geometry_that_cannot_be_built_is_refused_naming_the_key() {
    let cases: Vec<(Design, &str)> = vec![
        (Design { diaphragm_thickness: -0.001, ..Design::default() }, "diaphragm_thickness"),
        (Design { base_radius: -0.2, ..Design::default() }, "base_radius"),
        (Design { diaphragm_thickness: 0.05, ..Design::default() }, "diaphragm_thickness"),
        (Design { blade_length: 0.3, ..Design::default() }, "blade_length"),
        (Design { blade_thickness: 0.2, ..Design::default() }, "blade"),
        (Design { element_size: f64::NAN, ..Design::default() }, "element_size"),
    ];
    for (design, key) in cases {
        match design.build(Configuration::Assembly) {
            Err(GenerateError::Geometry { msg, .. }) => assert!(msg.contains(key), "{key}: {msg}"),
            other => panic!("{key}: expected a geometry error, got {:?}", other.map(|m| m.nodes.len())),
        }
    }
}

/// Which connected body (solids sharing nodes) each mesh node belongs to; nodes on no solid
/// (reference nodes) get their own.
fn bodies(mesh: &stickslip_fe::mesh::Mesh) -> Vec<usize> {
    let mut parent: Vec<usize> = (0..mesh.nodes.len()).collect();
    fn root(parent: &mut [usize], mut n: usize) -> usize {
        while parent[n] != n {
            parent[n] = parent[parent[n]];
            n = parent[n];
        }
        n
    }
    for s in &mesh.solids {
        for &n in &s.nodes[1..] {
            let (a, b) = (root(&mut parent, s.nodes[0]), root(&mut parent, n));
            parent[a] = b;
        }
    }
    (0..mesh.nodes.len()).map(|n| root(&mut parent, n)).collect()
}

#[test]
fn patch_tips_meet_the_wall_on_coincident_nodes_of_separate_bodies() {
    let design = Design { tip_contact: TipContact::Patch, ..Design::refined(0.5) };
    let mesh = design.build(Configuration::Assembly).unwrap();
    let body = bodies(&mesh);
    let revolved = body[mesh.node(harmony::accelerometer(0)).unwrap()];
    for i in 1..=4 {
        let tip = mesh.node_set(&format!("TIP_FACE_{i}")).unwrap();
        let wall = mesh.node_set(&format!("WALL_FACE_{i}")).unwrap();
        // Hex20, 3 cells across the 65 mm blade and 1 through its thickness: 4 × 2 corners,
        // 3 + 3 + 4 mid-edge nodes.
        assert_eq!((tip.len(), wall.len()), (18, 18), "blade {i}");
        let blade = body[tip[0]];
        assert_ne!(blade, revolved);
        for &t in tip {
            let x = mesh.nodes[t].xyz;
            let partner: Vec<usize> = wall
                .iter()
                .copied()
                .filter(|&w| (0..3).map(|d| (mesh.nodes[w].xyz[d] - x[d]).powi(2)).sum::<f64>().sqrt() < 1e-12)
                .collect();
            assert_eq!(
                partner.len(),
                1,
                "blade {i}: tip node {} has {} wall nodes at {x:?}",
                mesh.nodes[t].id,
                partner.len()
            );
            assert_ne!(partner[0], t);
            assert_eq!(body[t], blade);
            assert_eq!(
                body[partner[0]], revolved,
                "blade {i}: wall node {} is not the envelope's",
                mesh.nodes[partner[0]].id
            );
        }
        // The patch pairing finds the same 18 pairs, with the tip face's area and a radial normal.
        let patch = pair_sets(&mesh, &format!("TIP_FACE_{i}"), &format!("WALL_FACE_{i}"), None, None).unwrap();
        assert_eq!(patch.pairs.len(), 18);
        // The tip face is shaped to the wall: its width is the arc 2 R asin(w / 2R) (+0.45 % on
        // the 65 mm blade).
        let d = design.dimensions().unwrap();
        let r = d.envelope_inner_radius;
        let arc = 2.0 * r * (0.5 * d.blade_width / r).asin() * design.blade_thickness;
        assert!((patch.area() - arc).abs() < 1e-3 * arc, "blade {i}: tip area {} m² vs {arc} m²", patch.area());
        let (c, s) = [(1.0, 0.0), (0.0, 1.0), (-1.0, 0.0), (0.0, -1.0)][i - 1];
        assert!((patch.normal[0] - c).abs() < 1e-12 && (patch.normal[1] - s).abs() < 1e-12, "{:?}", patch.normal);
        // Named centre nodes: Top_Blade on the tip, Contact_Zone on the wall, at one position.
        let (p, b) = (mesh.node(harmony::top_blade(i)).unwrap(), mesh.node(harmony::contact_zone(i)).unwrap());
        assert!(tip.contains(&p) && wall.contains(&b));
        assert!((0..3).all(|k| (mesh.nodes[p].xyz[k] - mesh.nodes[b].xyz[k]).abs() < 1e-12));
    }
    // No reference nodes, couplings or connectors at the tips: the screws' (8 per blade pair
    // of references, 16 couplings) and the shaker's remain.
    assert!(mesh.node_set("TOP_BLADES").is_none() && mesh.node_set("CONTACT_ZONES").is_none());
    assert_eq!(mesh.couplings.len(), 4 * 4 + 1);
}

#[test]
fn tip_contact_takes_connector_or_patch_only() {
    assert_eq!("patch".parse::<TipContact>().unwrap(), TipContact::Patch);
    assert_eq!("connector".parse::<TipContact>().unwrap(), TipContact::Connector);
    assert_eq!(Design::default().tip_contact, TipContact::Connector);
    match "glued".parse::<TipContact>() {
        Err(GenerateError::Geometry { msg, .. }) => {
            assert_eq!(msg, "tip_contact must be \"connector\" or \"patch\", got \"glued\"")
        }
        other => panic!("expected an error, got {other:?}"),
    }
}
