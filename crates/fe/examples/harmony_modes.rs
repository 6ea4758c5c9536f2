//! Calibration of the Harmony-like model (paper Tables 3-5): masses, the modes of the assembly
//! with blades stuck and slipping and of the two substructures, and the checks of Tables 4-5.
//!
//! `cargo run --release -p stickslip-fe --example harmony_modes -- [REFINEMENT] [KEY=VALUE ...]`
//!
//! KEY=VALUE overrides a dimension of the design (m): `diaphragm_thickness`, `blade_thickness`,
//! `blade_length`, `shaker_zone_radius`, `hub_outer_radius`, `screw_radius_1`, `screw_radius_2`,
//! and the geometry of the body and blades (docs/harmony.md): `blade_rise`,
//! `body_flange_radius`, `top_disk_thickness`, `rim_width`, `top_disk_inner_radius`,
//! `top_disk_inner_thickness`, `blade_height`.

use std::time::Instant;

use stickslip_fe::assembly::FeModel;
use stickslip_fe::eigen::{solve, to_sparse, EigenOptions};
use stickslip_fe::harmony::{self, Configuration, Design};

/// One configuration's modes: frequencies (Hz) and, per mode, the vertical motion of the body
/// top, the base centre, the three envelope-top sensors and the four blade tips (mass-normalised
/// shapes; NaN where the part is absent).
struct Modes {
    f: Vec<f64>,
    body: Vec<f64>,
    base: Vec<f64>,
    envelope: Vec<[f64; 3]>,
    tips: Vec<[f64; 4]>,
    /// Largest translation of each blade tip (any direction).
    tips_any: Vec<[f64; 4]>,
}

fn set(design: &mut Design, key: &str, v: f64) {
    match key {
        "diaphragm_thickness" => design.diaphragm_thickness = v,
        "blade_thickness" => design.blade_thickness = v,
        "shaker_zone_radius" => design.shaker_zone_radius = v,
        "hub_outer_radius" => design.hub_outer_radius = v,
        "screw_radius_1" => design.screw_radii[0] = v,
        "screw_radius_2" => design.screw_radii[1] = v,
        "body_flange_radius" => design.variant.body_flange_radius = Some(v),
        "top_disk_thickness" => design.variant.top_disk_thickness = Some(v),
        "rim_width" => design.variant.rim_width = v,
        "top_disk_inner_radius" => {
            design.variant.top_disk_inner = Some((v, design.variant.top_disk_inner.map_or(0.0, |i| i.1)));
        }
        "top_disk_inner_thickness" => {
            design.variant.top_disk_inner = Some((design.variant.top_disk_inner.map_or(0.0, |i| i.0), v));
        }
        "blade_height" => design.variant.blade_height = Some(v),
        "blade_rise" => design.variant.blade_rise = v,
        "blade_length" => design.blade_length = v,
        other => panic!("unknown key {other}"),
    }
}

fn main() {
    let mut args = std::env::args().skip(1);
    let refinement: f64 = args.next().map(|a| a.parse().expect("a number")).unwrap_or(1.0);
    let mut design = Design::refined(refinement);
    for kv in args {
        let (key, value) = kv.split_once('=').expect("KEY=VALUE");
        set(&mut design, key, value.parse().expect("a number"));
    }
    let d = design.dimensions().expect("a buildable design");
    println!("dimensions: {d:?}\ndesign: {design:?}");
    let mut all = Vec::new();
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
        println!("\n{name}: {n} DOFs, solid mass {:.3} kg, {:.1} s", fe.solid_mass, t.elapsed().as_secs_f64());
        let at = |node: u64| fe.dof(node, 3).ok();
        let shape = |dof: Option<usize>, j: usize| dof.map_or(f64::NAN, |i| sol.modes.shapes[(i, j)]);
        let (body, base) = (at(harmony::accelerometer(0)), at(harmony::accelerometer(1)));
        let envelope = [2, 3, 4].map(|k| at(harmony::accelerometer(k)));
        let tips = [1, 2, 3, 4].map(|i| at(harmony::top_blade(i)));
        let tips_xy = [1, 2, 3, 4].map(|i| [1, 2].map(|dir| fe.dof(harmony::top_blade(i), dir).ok()));
        let f = sol.modes.frequencies_hz();
        let mut modes =
            Modes { f: f.clone(), body: vec![], base: vec![], envelope: vec![], tips: vec![], tips_any: vec![] };
        for (j, f) in f.iter().enumerate() {
            modes.body.push(shape(body, j));
            modes.base.push(shape(base, j));
            modes.envelope.push(envelope.map(|e| shape(e, j)));
            modes.tips.push(tips.map(|t| shape(t, j)));
            let z = modes.tips[j];
            let mut any = [0.0; 4];
            for (i, a) in any.iter_mut().enumerate() {
                let [x, y] = tips_xy[i].map(|t| shape(t, j));
                *a = (x * x + y * y + z[i] * z[i]).sqrt();
            }
            modes.tips_any.push(any);
            let (e, t) = (modes.envelope[j], modes.tips[j]);
            println!(
                "  mode {:2}: {:8.1} Hz  z: body top {:7.3} base {:7.3} envelope top {:7.3} {:7.3} {:7.3} blade tips {:7.3} {:7.3} {:7.3} {:7.3}",
                j + 1,
                f,
                modes.body[j],
                modes.base[j],
                e[0],
                e[1],
                e[2],
                t[0],
                t[1],
                t[2],
                t[3]
            );
        }
        all.push(modes);
    }

    // Checks against the paper. Axial modes: the body top (or, without the body, the base
    // centre) moves vertically by more than a tenth of the most it does among these modes, and
    // the envelope-top sensors move alike (axisymmetric).
    let axial = |m: &Modes, probe: &[f64]| -> Vec<f64> {
        let largest = probe.iter().skip(1).map(|v| v.abs()).fold(0.0, f64::max);
        (1..m.f.len())
            .filter(|&j| {
                let e = m.envelope[j];
                probe[j].abs() > 0.1 * largest
                    && (e[0].is_nan()
                        || ((e[0] - e[1]).abs() <= 0.05 * e[0].abs() + 1e-9
                            && (e[0] - e[2]).abs() <= 0.05 * e[0].abs() + 1e-9))
            })
            .map(|j| m.f[j])
            .collect()
    };
    let dev = |f: f64, target: f64| format!("{f:.1} Hz ({:+.1} %)", 100.0 * (f / target - 1.0));
    // In the assembly, the modes where the body top moves and those where the base centre does.
    let both = |m: &Modes| {
        let mut f = axial(m, &m.body);
        f.extend(axial(m, &m.base));
        f.sort_by(f64::total_cmp);
        f.dedup();
        f
    };
    let stuck = both(&all[0]);
    let slipping = axial(&all[1], &all[1].body);
    let envelope = axial(&all[2], &all[2].base);
    println!("\nTable 5, assembly with blades stuck: axial modes {stuck:.1?} Hz");
    println!("  1st axial: {} against 237.6 Hz", dev(stuck[0], 237.6));
    if stuck.len() > 1 {
        let second = stuck[1..].iter().copied().min_by(|a, b| (a - 878.4).abs().total_cmp(&(b - 878.4).abs())).unwrap();
        println!("  2nd axial (nearest): {} against 878.4 Hz", dev(second, 878.4));
    }
    println!("Section 5.1, blades slipping: 1st axial {} against ~190 Hz", dev(slipping[0], 190.0));
    match envelope.first() {
        Some(&f) => println!(
            "Table 4, envelope on the shaker: 1st vertical mode {} against 880.4 Hz (test 889 Hz)",
            dev(f, 880.4)
        ),
        None => println!("Table 4, envelope on the shaker: no vertical mode among the 30 computed"),
    }
    // Body + blades, modes below 1 kHz: synchronous when the body top moves (a tenth of the most
    // it does) and the four tips vertically alike; asynchronous when the tips move (a tenth of
    // the most they do) and not alike.
    let b = &all[3];
    let below: Vec<usize> = (0..b.f.len()).filter(|&j| b.f[j] < 1000.0).collect();
    let body_largest = below.iter().map(|&j| b.body[j].abs()).fold(0.0, f64::max);
    let tip_largest = below.iter().flat_map(|&j| b.tips_any[j]).fold(0.0, f64::max);
    let mut sync = Vec::new();
    let mut asynchronous = Vec::new();
    for &j in &below {
        let t = b.tips[j];
        let alike = t.iter().all(|v| (v - t[0]).abs() <= 0.05 * t[0].abs());
        if b.body[j].abs() > 0.1 * body_largest && alike {
            sync.push(b.f[j]);
        } else if !alike && b.tips_any[j].iter().copied().fold(0.0, f64::max) > 0.1 * tip_largest {
            asynchronous.push(b.f[j]);
        }
    }
    match sync.first() {
        Some(&f) => println!(
            "Table 4, body + blades: synchronous axial mode {} against 210.8 Hz (test 218.7 Hz)",
            dev(f, 210.8)
        ),
        None => println!("Table 4, body + blades: no synchronous mode among the 30 computed"),
    }
    let in_band = asynchronous.iter().filter(|&&f| (254.0..=260.0).contains(&f)).count();
    println!(
        "  modes with the blade tips moving asynchronously: {asynchronous:.1?} Hz; in [254, 260] Hz (paper: 4): {in_band}"
    );
}
