//! `stickslip modes MODEL`: the lowest modes of a mesh or of imported matrices, with their
//! effective masses and residuals; `modes.csv` and the mode shapes (VTK for meshes).
use std::io::Write;
use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::{bail, Context};
use stickslip_core::model::LinearModel;
use stickslip_fe::assembly::FeModel;
use stickslip_fe::eigen::{self, to_sparse, EigenOptions, EigenSolution};
use stickslip_io::matrix::{abaqus, calculix, dmig, model_from_pair, mtx, LabelledMatrix};

/// How MODEL is read (by its extension, or by what exists next to it):
///
/// - `deck.inp`: an Abaqus/CalculiX deck, meshed and assembled;
/// - `mesh.msh`: a Gmsh mesh with `--young`, `--poisson` and `--density` (it has no material);
/// - `job` or `job.sti` / `job.mas` / `job.dof`: CalculiX's exported matrices;
/// - `K.mtx --mass M.mtx`: Matrix Market files (first line `%%MatrixMarket`), or Abaqus
///   `*MATRIX GENERATE` output (`job_STIF1.mtx --mass job_MASS1.mtx`);
/// - `model.pch` / `.bdf` / `.dat`: Nastran DMIG matrices (`--dmig KAAX,MAAX` by default).
#[derive(clap::Args)]
pub struct ModelArgs {
    /// Model: a .inp deck, a Gmsh .msh (with --young, --poisson, --density), a CalculiX matrix job prefix, a stiffness .mtx (with --mass), or a
    /// Nastran punch/bulk file with DMIG matrices.
    pub model: PathBuf,
    /// Mass matrix file for a stiffness given as .mtx (Matrix Market or Abaqus).
    #[arg(long)]
    pub mass: Option<PathBuf>,
    /// Names of the stiffness and mass DMIG matrices.
    #[arg(long, default_value = "KAAX,MAAX")]
    pub dmig: String,
    /// Young's modulus (Pa) of every solid of a mesh: required with --poisson and --density for
    /// a Gmsh .msh, which carries no material; replaces an .inp deck's materials.
    #[arg(long, requires_all = ["poisson", "density"])]
    pub young: Option<f64>,
    /// Poisson's ratio of every solid of a mesh, in (-1, 0.5).
    #[arg(long, requires_all = ["young", "density"], allow_negative_numbers = true)]
    pub poisson: Option<f64>,
    /// Density (kg/m^3) of every solid of a mesh.
    #[arg(long, requires_all = ["young", "poisson"])]
    pub density: Option<f64>,
    /// Fix DOFs of a mesh's node set (a Gmsh physical group, an .inp *NSET): SET=DIRECTIONS,
    /// directions 1..6 = ux, uy, uz, rx, ry, rz, e.g. --fix ROOT=1,2,3. Repeatable.
    #[arg(long, value_name = "SET=DIRECTIONS")]
    pub fix: Vec<String>,
}

/// `--fix SET=DIRECTIONS`: the set's name and its directions, each in 1..=6.
fn parse_fix(text: &str) -> anyhow::Result<(String, Vec<u8>)> {
    let usage = "expected SET=DIRECTIONS with directions 1..6 (ux, uy, uz, rx, ry, rz), e.g. --fix ROOT=1,2,3";
    let Some((set, directions)) = text.split_once('=') else { bail!("--fix {text}: {usage}") };
    if set.trim().is_empty() {
        bail!("--fix {text}: no set named; {usage}");
    }
    let directions = directions
        .split(',')
        .map(|d| match d.trim().parse::<u8>() {
            Ok(d @ 1..=6) => Ok(d),
            _ => Err(anyhow::anyhow!("--fix {text}: direction `{}` is not one of 1..6; {usage}", d.trim())),
        })
        .collect::<anyhow::Result<Vec<u8>>>()?;
    Ok((set.trim().to_string(), directions))
}

/// The material of `--young`, `--poisson` and `--density`, checked; `None` when not given.
fn material(args: &ModelArgs) -> anyhow::Result<Option<stickslip_fe::mesh::Material>> {
    let (Some(young), Some(poisson), Some(density)) = (args.young, args.poisson, args.density) else {
        return Ok(None);
    };
    if !(young.is_finite() && young > 0.0) {
        bail!("--young: Young's modulus must be a finite value > 0 in Pa, got {young}");
    }
    if !(density.is_finite() && density > 0.0) {
        bail!("--density: the density must be a finite value > 0 in kg/m^3, got {density}");
    }
    if !(-1.0 < poisson && poisson < 0.5) {
        bail!("--poisson: Poisson's ratio must be in (-1, 0.5), got {poisson}");
    }
    Ok(Some(stickslip_fe::mesh::Material { young, poisson, density }))
}

/// Read and assemble a mesh, its solids given `material` when there is one.
fn assemble_mesh(mut mesh: stickslip_fe::mesh::Mesh, path: &Path, args: &ModelArgs) -> anyhow::Result<Loaded> {
    if let Some(m) = material(args)? {
        mesh.assign_material(None, "COMMAND_LINE", m).with_context(|| format!("{}: the material", path.display()))?;
    }
    for fix in &args.fix {
        let (set, directions) = parse_fix(fix)?;
        if !mesh.fix_node_set(&set, &directions) {
            let sets: Vec<&String> = mesh.node_sets.keys().collect();
            bail!("--fix {fix}: no node set (physical group) `{set}` in {}; its sets are {sets:?}", path.display());
        }
    }
    eprintln!("assembling {} ...", path.display());
    let fe = FeModel::assemble(mesh).with_context(|| format!("assembling {}", path.display()))?;
    Ok(Loaded { model: fe.model.clone(), fe: Some(fe) })
}

#[derive(clap::Args)]
pub struct Args {
    #[command(flatten)]
    pub model: ModelArgs,
    /// Number of modes.
    #[arg(long, default_value_t = 10)]
    pub count: usize,
    /// Find the modes nearest this frequency (Hz) instead of the lowest ones.
    #[arg(long)]
    pub shift: Option<f64>,
    /// Every mode with F1 <= f <= F2 (Hz, F1:F2, e.g. 2000:3000), however many there are: the
    /// inertia of K - sigma M at both ends counts them, so none is missed. 0:F2 gives every mode
    /// up to F2, rigid-body modes included. Not with --count or --shift.
    #[arg(long, value_name = "F1:F2", conflicts_with_all = ["count", "shift"], allow_hyphen_values = true)]
    pub band: Option<String>,
    /// Directory for modes.csv and the mode shapes.
    #[arg(long)]
    pub out: Option<PathBuf>,
}

/// A loaded model, with its mesh when it came from one.
pub struct Loaded {
    pub model: LinearModel,
    pub fe: Option<FeModel>,
}

/// Read MODEL as [`ModelArgs`] says.
pub fn load(args: &ModelArgs) -> anyhow::Result<Loaded> {
    let path = &args.model;
    let ext = path.extension().and_then(|e| e.to_str()).unwrap_or("").to_ascii_lowercase();
    let start = Instant::now();
    if args.young.is_some() && !matches!(ext.as_str(), "inp" | "msh") {
        bail!(
            "{}: --young, --poisson and --density give the material of a mesh (.inp or .msh); matrices have theirs",
            path.display()
        );
    }
    if !args.fix.is_empty() && !matches!(ext.as_str(), "inp" | "msh") {
        bail!(
            "{}: --fix fixes DOFs of a mesh's node sets (.inp or .msh); a matrix model's DOFs are fixed where it was exported",
            path.display()
        );
    }
    let loaded = match ext.as_str() {
        "inp" => {
            let mesh = stickslip_fe::mesh::inp::read(path).with_context(|| format!("reading {}", path.display()))?;
            assemble_mesh(mesh, path, args)?
        }
        "msh" => {
            if args.young.is_none() {
                bail!(
                    "{}: a Gmsh mesh carries no material: give --young PA --poisson NU --density KG_M3 (e.g. steel: --young 2.1e11 --poisson 0.3 --density 7800)",
                    path.display()
                );
            }
            let mesh = stickslip_fe::mesh::gmsh::read(path).with_context(|| format!("reading {}", path.display()))?;
            assemble_mesh(mesh, path, args)?
        }
        "mtx" => {
            let mass = args.mass.as_ref().with_context(|| {
                format!("{} is a stiffness matrix: give its mass matrix with --mass FILE", path.display())
            })?;
            let read = |p: &Path| -> anyhow::Result<LabelledMatrix> {
                if is_matrix_market(p)? {
                    let m = mtx::read(p)?;
                    if m.nrows() != m.ncols() {
                        bail!(
                            "{}: the matrix is {}x{}; a stiffness or mass matrix must be square",
                            p.display(),
                            m.nrows(),
                            m.ncols()
                        );
                    }
                    let n = m.nrows();
                    let dofs =
                        (0..n).map(|i| stickslip_core::model::DofLabel::named(format!("dof{}", i + 1))).collect();
                    Ok(LabelledMatrix { dofs, matrix: to_sparse(&m).into_owned() })
                } else {
                    Ok(abaqus::read(p)?)
                }
            };
            let (k, m) = (read(path)?, read(mass)?);
            if is_matrix_market(path)? && k.matrix.nrows() != m.matrix.nrows() {
                bail!(
                    "{} is {}x{} but {} is {}x{}",
                    path.display(),
                    k.matrix.nrows(),
                    k.matrix.ncols(),
                    mass.display(),
                    m.matrix.nrows(),
                    m.matrix.ncols()
                );
            }
            let model = model_from_pair(k, m)
                .with_context(|| format!("stiffness {} and mass {}", path.display(), mass.display()))?;
            Loaded { model, fe: None }
        }
        "pch" | "bdf" | "dat" | "nas" => {
            let (k, m) = args.dmig.split_once(',').context("--dmig expects STIFFNESS,MASS matrix names")?;
            Loaded { model: dmig::read_model(path, k.trim(), m.trim())?, fe: None }
        }
        _ => {
            let (sti, _, _) = calculix::job_files(path);
            if !sti.exists() {
                bail!(
                    "{}: not a known model (.inp deck, CalculiX job prefix with {}, .mtx with --mass, or DMIG .pch)",
                    path.display(),
                    sti.display()
                );
            }
            Loaded { model: calculix::read_job(path)?, fe: None }
        }
    };
    eprintln!("model: {} DOFs ({:.2} s)", loaded.model.n_dofs(), start.elapsed().as_secs_f64());
    Ok(loaded)
}

fn is_matrix_market(path: &Path) -> anyhow::Result<bool> {
    let text = std::fs::read(path).with_context(|| format!("reading {}", path.display()))?;
    Ok(text.starts_with(b"%%MatrixMarket") || text.starts_with(b"%%matrixmarket"))
}

/// Shift in rad²/s² from a frequency in Hz.
pub fn shift_from_hz(hz: Option<f64>) -> Option<f64> {
    hz.map(|f| (2.0 * std::f64::consts::PI * f).powi(2) * f.signum())
}

/// ω² in rad²/s² of a frequency in Hz.
pub fn lambda_from_hz(f: f64) -> f64 {
    (std::f64::consts::TAU * f).powi(2)
}

/// `--band F1:F2` (or `F1,F2`) in Hz: two finite frequencies, `0 <= F1 <= F2`.
pub fn parse_band(text: &str) -> anyhow::Result<(f64, f64)> {
    let usage = "expected two frequencies in Hz, F1:F2 with 0 <= F1 <= F2 (e.g. --band 2000:3000)";
    let Some((a, b)) = text.split_once(':').or_else(|| text.split_once(',')) else {
        bail!("--band {text}: {usage}");
    };
    let parse = |x: &str| x.trim().parse::<f64>().ok().filter(|v| v.is_finite());
    let (Some(f1), Some(f2)) = (parse(a), parse(b)) else {
        bail!("--band {text}: the ends must be finite numbers; {usage}");
    };
    if f1 < 0.0 {
        bail!("--band {text}: the lower end is negative; {usage}");
    }
    if f2 < f1 {
        bail!("--band {text}: the ends are reversed; {usage}");
    }
    Ok((f1, f2))
}

/// Effective masses `(φᵀ M r_d)²` of a mass-normalised mode along the rigid translations
/// `r_d` (1 on every DOF of direction `d`), d = x, y, z; `None` without nodal labels.
pub fn effective_masses(model: &LinearModel, sol: &EigenSolution) -> Option<Vec<[f64; 3]>> {
    if model.dofs.iter().all(|d| d.direction.is_none()) {
        return None;
    }
    let n = model.n_dofs();
    let mut mr = Vec::new();
    for d in 1..=3u8 {
        let r: Vec<f64> = model.dofs.iter().map(|l| if l.direction == Some(d) { 1.0 } else { 0.0 }).collect();
        let mut out = vec![0.0; n];
        model.mass.mul_vec(&r, &mut out);
        mr.push(out);
    }
    let shapes = &sol.modes.shapes;
    Some(
        (0..shapes.ncols())
            .map(|c| {
                let mut e = [0.0; 3];
                for (d, v) in mr.iter().enumerate() {
                    let g: f64 = (0..n).map(|i| shapes[(i, c)] * v[i]).sum();
                    e[d] = g * g;
                }
                e
            })
            .collect(),
    )
}

pub fn main(args: Args) -> anyhow::Result<()> {
    let loaded = load(&args.model)?;
    let model = &loaded.model;
    let (k, m) = (to_sparse(&model.stiffness), to_sparse(&model.mass));
    let (k, m) = (&*k, &*m);
    let band = args.band.as_deref().map(parse_band).transpose()?;
    let start = Instant::now();
    let sol = match band {
        Some((f1, f2)) => {
            eprintln!("solving for every mode between {f1} and {f2} Hz ...");
            let sol = eigen::solve_band(k, m, lambda_from_hz(f1), lambda_from_hz(f2), &EigenOptions::default())
                .map_err(|e| match e {
                    eigen::EigenError::Band(what) => anyhow::anyhow!("--band {f1}:{f2}: {what}"),
                    e => e.into(),
                })?;
            eprintln!(
                "modes: {:.2} s ({} solves, {} restarts, {} eigenvalues below {f1} Hz and {} in the band, counted by the inertia of K - sigma M at its ends)",
                start.elapsed().as_secs_f64(),
                sol.solves,
                sol.restarts,
                sol.below_shift,
                sol.modes.omega.len()
            );
            if sol.modes.omega.is_empty() {
                eprintln!("no mode between {f1} and {f2} Hz: modes.csv holds its header only");
            }
            sol
        }
        None => {
            let opts = EigenOptions { count: args.count, shift: shift_from_hz(args.shift), ..Default::default() };
            eprintln!("solving for {} modes ...", args.count);
            let sol = eigen::solve(k, m, &opts)?;
            eprintln!(
                "modes: {:.2} s ({} solves, {} restarts, shift {:.4e} rad^2/s^2, {} eigenvalues below it)",
                start.elapsed().as_secs_f64(),
                sol.solves,
                sol.restarts,
                sol.shift,
                sol.below_shift
            );
            sol
        }
    };
    let eff = effective_masses(model, &sol);
    let freqs = sol.modes.frequencies_hz();
    // The solver refuses non-finite modes; a table of NaN is never written with success.
    if let Some(r) = (0..freqs.len()).find(|&r| !(freqs[r].is_finite() && sol.residuals[r].is_finite())) {
        bail!("mode {}: frequency {} Hz, residual {}: not finite, nothing written", r + 1, freqs[r], sol.residuals[r]);
    }
    // Nor shapes (modes.vtk, shapes.csv) or effective masses holding a value that is not finite.
    let shapes = &sol.modes.shapes;
    if let Some((i, r)) = (0..shapes.ncols())
        .flat_map(|r| (0..shapes.nrows()).map(move |i| (i, r)))
        .find(|&(i, r)| !shapes[(i, r)].is_finite())
    {
        let dof = model.dofs.get(i).map_or_else(|| format!("{}", i + 1), |d| d.name.clone());
        bail!("mode {}: its shape is {} at DOF {dof}: not finite, nothing written", r + 1, shapes[(i, r)]);
    }
    if let Some((r, e)) = eff.iter().flatten().enumerate().find(|(_, e)| e.iter().any(|v| !v.is_finite())) {
        bail!("mode {}: effective masses {e:?} kg: not finite, nothing written", r + 1);
    }
    let mut table = String::new();
    table.push_str("mode,frequency_hz,eff_mass_x_kg,eff_mass_y_kg,eff_mass_z_kg,residual\n");
    println!(
        "{:>5} {:>16} {:>12} {:>12} {:>12} {:>10}",
        "mode", "frequency (Hz)", "m_eff x (kg)", "m_eff y (kg)", "m_eff z (kg)", "residual"
    );
    for (r, f) in freqs.iter().enumerate() {
        let e = eff.as_ref().map(|e| e[r]);
        let cell = |d: usize| e.map(|e| format!("{:.6e}", e[d])).unwrap_or_default();
        println!(
            "{:>5} {:>16.6} {:>12} {:>12} {:>12} {:>10.2e}",
            r + 1,
            f,
            cell(0),
            cell(1),
            cell(2),
            sol.residuals[r]
        );
        table.push_str(&format!("{},{:.12e},{},{},{},{:.3e}\n", r + 1, f, cell(0), cell(1), cell(2), sol.residuals[r]));
    }
    if let Some(eff) = &eff {
        let total: [f64; 3] = [0, 1, 2].map(|d| eff.iter().map(|e| e[d]).sum());
        println!("sum of effective masses (kg): x {:.6e}, y {:.6e}, z {:.6e}", total[0], total[1], total[2]);
    }
    if let Some(dir) = &args.out {
        std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
        let csv = dir.join("modes.csv");
        std::fs::write(&csv, table).with_context(|| format!("writing {}", csv.display()))?;
        let shapes = write_shapes(dir, &loaded, &sol)?;
        eprintln!("wrote {} and the mode shapes", csv.display());
        for old in stickslip_io::output::replace_previous_run(dir, "modes", &[csv, shapes])? {
            eprintln!("removed {} (written by the previous modes, not by this one)", old.display());
        }
    }
    Ok(())
}

/// Mode shapes: `modes.vtk` (one point vector per mode) for a mesh, `shapes.csv` (one row per
/// DOF) for matrices. Returns the file written.
fn write_shapes(dir: &Path, loaded: &Loaded, sol: &EigenSolution) -> anyhow::Result<PathBuf> {
    let shapes = &sol.modes.shapes;
    let freqs = sol.modes.frequencies_hz();
    if let Some(fe) = &loaded.fe {
        let path = dir.join("modes.vtk");
        let fields: Vec<(String, Vec<[f64; 3]>)> = (0..shapes.ncols())
            .map(|c| {
                let q: Vec<f64> = (0..shapes.nrows()).map(|i| shapes[(i, c)]).collect();
                (format!("mode{}_{:.3}Hz", c + 1, freqs[c]), fe.nodal_displacements(&q))
            })
            .collect();
        let mut w = std::io::BufWriter::new(
            std::fs::File::create(&path).with_context(|| format!("creating {}", path.display()))?,
        );
        stickslip_fe::mesh::vtk::write(&mut w, "stickslip modes", &fe.mesh.nodes, &fe.mesh.solids, &fields)
            .and_then(|_| w.flush())
            .with_context(|| format!("writing {}", path.display()))?;
        Ok(path)
    } else {
        let path = dir.join("shapes.csv");
        let mut w = std::io::BufWriter::new(
            std::fs::File::create(&path).with_context(|| format!("creating {}", path.display()))?,
        );
        let header: Vec<String> = (0..shapes.ncols()).map(|c| format!("mode{}", c + 1)).collect();
        writeln!(w, "dof,{}", header.join(","))?;
        for (i, d) in loaded.model.dofs.iter().enumerate() {
            let row: Vec<String> = (0..shapes.ncols()).map(|c| format!("{:e}", shapes[(i, c)])).collect();
            writeln!(w, "{},{}", d.name, row.join(","))?;
        }
        w.flush()?;
        Ok(path)
    }
}
