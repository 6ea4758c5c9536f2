//! Benchmark of the chain mesh → K, M → lowest modes → reduced model (paper Section 3.3) on
//! clamped tet10 slabs of ~30k and ~280k DOFs (the paper's model has 278,848 DOFs and keeps 34
//! modes and 103 retained DOFs).
//!
//! `cargo bench -p stickslip-fe --bench reduction -- [30k|280k|all] [--repeat N] [--inp DIR]`
//! prints, per size, the median wall time of each stage and the peak resident memory of the
//! assembly and of the modes + reduction (`VmHWM`, reset between them through
//! `/proc/self/clear_refs`). `--inp DIR` also writes the same mesh as a CalculiX deck
//! (`DIR/slab_<size>.inp`, 10 modes) for a side-by-side run of `ccx`.
use std::io::Write;
use std::time::Instant;

use stickslip_fe::assembly::FeModel;
use stickslip_fe::eigen::EigenOptions;
use stickslip_fe::element::SolidKind;
use stickslip_fe::mesh::generate::box_mesh;
use stickslip_fe::mesh::{Material, Mesh};
use stickslip_fe::reduction::{self, ReductionOptions};

const STEEL: Material = Material { young: 2.1e11, poisson: 0.3, density: 7800.0 };
const MODES: usize = 34;
/// 34 nodes × 3 directions = 102 retained DOFs (the paper retains 103).
const RETAINED_NODES: usize = 34;

struct Size {
    name: &'static str,
    cells: [usize; 3],
}

const SIZES: [Size; 2] = [Size { name: "30k", cells: [20, 10, 5] }, Size { name: "280k", cells: [44, 22, 11] }];

/// A clamped slab 0.4 × 0.2 × 0.1 m: the ZMIN face fixed.
fn mesh(size: &Size) -> Mesh {
    let mut mesh = box_mesh([0.4, 0.2, 0.1], size.cells, SolidKind::Tet10, STEEL);
    let clamped = mesh.node_set("ZMIN").expect("box meshes name their faces").to_vec();
    for i in clamped {
        for d in 1..=3 {
            mesh.fixed.push((i, d));
        }
    }
    mesh
}

fn peak_rss_reset() {
    // Writing 5 resets the peak RSS counter (Linux ≥ 4.0); best effort.
    let _ = std::fs::write("/proc/self/clear_refs", "5");
}

fn peak_rss_mib() -> f64 {
    let status = std::fs::read_to_string("/proc/self/status").unwrap_or_default();
    status
        .lines()
        .find_map(|l| l.strip_prefix("VmHWM:"))
        .and_then(|v| v.trim().trim_end_matches("kB").trim().parse::<f64>().ok())
        .map(|kb| kb / 1024.0)
        .unwrap_or(f64::NAN)
}

/// Retained DOFs: the x, y, z DOFs of `RETAINED_NODES` nodes spread over the free faces.
fn retained(fe: &FeModel) -> Vec<usize> {
    let top = fe.mesh.node_set("ZMAX").unwrap();
    let step = top.len() / RETAINED_NODES;
    let mut out = Vec::new();
    for k in 0..RETAINED_NODES {
        let id = fe.mesh.nodes[top[k * step + step / 2]].id;
        for d in 1..=3 {
            out.push(fe.dof(id, d).unwrap());
        }
    }
    out
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

fn write_inp(path: &std::path::Path, mesh: &Mesh) -> std::io::Result<()> {
    let mut w = std::io::BufWriter::new(std::fs::File::create(path)?);
    writeln!(w, "** Clamped tet10 slab 0.4 x 0.2 x 0.1 m, steel (stickslip reduction benchmark)")?;
    writeln!(w, "*NODE, NSET=NALL")?;
    for n in &mesh.nodes {
        writeln!(w, "{}, {:.12e}, {:.12e}, {:.12e}", n.id, n.xyz[0], n.xyz[1], n.xyz[2])?;
    }
    writeln!(w, "*ELEMENT, TYPE=C3D10, ELSET=EALL")?;
    for s in &mesh.solids {
        let ids: Vec<String> = s.nodes.iter().map(|&i| mesh.nodes[i].id.to_string()).collect();
        writeln!(w, "{}, {}", s.id, ids[..7].join(", "))?;
        writeln!(w, "{}", ids[7..].join(", "))?;
    }
    writeln!(w, "*NSET, NSET=CLAMP")?;
    for chunk in mesh.node_set("ZMIN").unwrap().chunks(12) {
        let ids: Vec<String> = chunk.iter().map(|&i| mesh.nodes[i].id.to_string()).collect();
        writeln!(w, "{},", ids.join(", "))?;
    }
    writeln!(w, "*BOUNDARY\nCLAMP, 1, 3")?;
    writeln!(w, "*MATERIAL, NAME=STEEL\n*ELASTIC\n{:e}, {}\n*DENSITY\n{}", STEEL.young, STEEL.poisson, STEEL.density)?;
    writeln!(w, "*SOLID SECTION, ELSET=EALL, MATERIAL=STEEL")?;
    writeln!(w, "*STEP\n*FREQUENCY\n10\n*END STEP")?;
    w.flush()
}

fn run(size: &Size, repeat: usize, inp_dir: Option<&std::path::Path>) {
    let mut t_asm = Vec::new();
    let mut t_modes = Vec::new();
    let mut t_red = Vec::new();
    let (mut m_asm, mut m_red) = (0.0f64, 0.0f64);
    let mut summary = String::new();
    for r in 0..repeat {
        let mesh = mesh(size);
        if r == 0 {
            if let Some(dir) = inp_dir {
                let path = dir.join(format!("slab_{}.inp", size.name));
                write_inp(&path, &mesh).expect("writing the CalculiX deck");
                eprintln!("wrote {}", path.display());
            }
        }
        peak_rss_reset();
        let start = Instant::now();
        let fe = FeModel::assemble(mesh).expect("assembly");
        t_asm.push(start.elapsed().as_secs_f64());
        m_asm = m_asm.max(peak_rss_mib());
        let opts =
            ReductionOptions { retained: retained(&fe), modes: MODES, band: None, eigen: EigenOptions::default() };
        peak_rss_reset();
        let red = reduction::free_modes(&fe.model, &opts).expect("reduction");
        m_red = m_red.max(peak_rss_mib());
        let stage = |name: &str| red.stages.iter().filter(|s| s.0 == name).map(|s| s.1).sum::<f64>();
        let modes = stage("free modes") + stage("factorisation of K");
        t_modes.push(modes);
        t_red.push(red.stages.iter().map(|s| s.1).sum::<f64>() - modes);
        let worst = red.basis_residuals.iter().cloned().fold(0.0, f64::max);
        summary = format!(
            "{} DOFs, {} retained + {} modes; f1 = {:.3} Hz, f34 = {:.3} Hz; worst residual {:.1e}",
            fe.model.n_dofs(),
            red.retained.len(),
            red.n_reduced() - red.retained.len(),
            red.basis_frequencies_hz[0],
            red.basis_frequencies_hz[MODES - 1],
            worst
        );
        eprintln!("{} run {}: {:?}", size.name, r + 1, red.stages);
    }
    println!("## {}: {summary}", size.name);
    println!("| stage | median time (s) | peak RSS (MiB) |");
    println!("|---|---|---|");
    println!("| assembly | {:.2} | {:.0} |", median(t_asm.clone()), m_asm);
    println!(
        "| 34 lowest modes (LDLᵀ + Lanczos) | {:.2} | {:.0} (modes + reduction) |",
        median(t_modes.clone()),
        m_red
    );
    println!(
        "| reduction (constraint modes Eq. 4, Eq. 5, orthogonalisation, projection) | {:.2} | |",
        median(t_red.clone())
    );
    let total: Vec<f64> = (0..t_asm.len()).map(|i| t_asm[i] + t_modes[i] + t_red[i]).collect();
    println!("| total | {:.2} | {:.0} |", median(total), m_asm.max(m_red));
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).filter(|a| a != "--bench").collect();
    let mut which = "30k".to_string();
    let mut repeat = None;
    let mut inp = None;
    let mut i = 0;
    while i < args.len() {
        match args[i].as_str() {
            "--repeat" => {
                repeat = args.get(i + 1).and_then(|v| v.parse().ok());
                i += 1;
            }
            "--inp" => {
                inp = args.get(i + 1).map(std::path::PathBuf::from);
                i += 1;
            }
            other => which = other.to_string(),
        }
        i += 1;
    }
    for size in &SIZES {
        if which == "all" || which == size.name {
            // Three repeats by default for the small model, one for the paper-size one.
            let n = repeat.unwrap_or(if size.name == "30k" { 3 } else { 1 });
            run(size, n, inp.as_deref());
        }
    }
}
