//! Calibration of the Harmony-like model (paper Tables 3-5): masses, the modes of the
//! substructures and of the assembly with blades stuck and slipping, at a refinement.
//!
//! `cargo run --release -p stickslip-fe --example harmony_modes -- [REFINEMENT]`

use std::time::Instant;

use stickslip_fe::assembly::FeModel;
use stickslip_fe::eigen::{solve, to_sparse, EigenOptions};
use stickslip_fe::harmony::{Configuration, Design};

fn main() {
    let refinement: f64 = std::env::args().nth(1).map(|a| a.parse().expect("a number")).unwrap_or(1.0);
    // Optional overrides for calibration: diaphragm thickness, blade thickness, shaker zone
    // radius (m).
    let arg = |i: usize| std::env::args().nth(i).map(|a| a.parse::<f64>().expect("a number"));
    let mut design = Design::refined(refinement);
    if let Some(t) = arg(2) {
        design.diaphragm_thickness = t;
    }
    if let Some(t) = arg(3) {
        design.blade_thickness = t;
    }
    if let Some(r) = arg(4) {
        design.shaker_zone_radius = r;
    }
    let d = design.dimensions().expect("a buildable design");
    println!("dimensions: {d:?}\ndesign: {design:?}");
    for (name, config, released) in [
        ("assembly, blades stuck", Configuration::Assembly, false),
        ("assembly, blades slipping", Configuration::Assembly, true),
        ("envelope on the shaker", Configuration::Envelope, false),
        ("body + blades, clamped", Configuration::BodyWithBlades, false),
    ] {
        let t = Instant::now();
        let design = Design { contact_vertical_stiffness: if released { 0.0 } else { 1e10 }, ..design.clone() };
        let mesh = design.build(config).expect("mesh");
        let fe = FeModel::assemble(mesh).expect("assembly");
        let n = fe.model.n_dofs();
        let (k, m) = (to_sparse(&fe.model.stiffness), to_sparse(&fe.model.mass));
        let (k, m) = (k.into_owned(), m.into_owned());
        let sol = solve(&k, &m, &EigenOptions { count: 30, ..Default::default() }).expect("modes");
        // Effective masses along x, y, z: (φᵀ M r)² for the rigid translations r.
        let mut eff = Vec::new();
        for j in 0..sol.modes.omega.len() {
            let mut out = [0.0; 3];
            for (dir, o) in out.iter_mut().enumerate() {
                let r: Vec<f64> =
                    fe.model.dofs.iter().map(|l| if l.direction == Some(dir as u8 + 1) { 1.0 } else { 0.0 }).collect();
                let mut mr = vec![0.0; n];
                fe.model.mass.mul_vec(&r, &mut mr);
                *o = (0..n).map(|i| sol.modes.shapes[(i, j)] * mr[i]).sum::<f64>().powi(2);
            }
            eff.push(out);
        }
        println!("\n{name}: {n} DOFs, solid mass {:.3} kg, {:.1} s", fe.solid_mass, t.elapsed().as_secs_f64());
        // Axial character: vertical motion of the body top, the base centre and the envelope top
        // (mass-normalised shapes, so comparable between modes).
        let at = |name: &str| fe.model.dofs.iter().position(|l| l.name == name);
        let probes = [at("101.3"), at("102.3"), at("103.3"), at("103.1")];
        for (j, f) in sol.modes.frequencies_hz().iter().enumerate() {
            let p = probes.map(|i| i.map(|i| sol.modes.shapes[(i, j)]).unwrap_or(f64::NAN));
            println!(
                "  mode {:2}: {:9.2} Hz  eff. mass x {:7.3} y {:7.3} z {:7.3} kg  body top z {:9.2e} base z {:9.2e} env. top z {:9.2e} x {:9.2e}",
                j + 1,
                f,
                eff[j][0],
                eff[j][1],
                eff[j][2],
                p[0],
                p[1],
                p[2],
                p[3]
            );
        }
    }
}
