//! `stickslip reduce MODEL --retain ... --modes N --method cb|free|enriched --out DIR`: a
//! reduced model (paper Section 3.3) written as Matrix Market (`M.mtx`, `K.mtx`, `D.mtx`),
//! NumPy (`reduced.npz`) and the DOF map (`dofs.csv`).
use std::path::PathBuf;
use std::time::Instant;

use anyhow::{bail, Context};
use stickslip_core::model::{Damping, LinearModel};
use stickslip_fe::eigen::EigenOptions;
use stickslip_fe::reduction::{self, Reduction, ReductionOptions, Release};
use stickslip_io::matrix::{mtx, npz};

use super::modes::{lambda_from_hz, load, parse_band, shift_from_hz, Loaded, ModelArgs};

#[derive(Clone, Copy, clap::ValueEnum)]
pub enum MethodArg {
    /// Craig-Bampton: constraint modes + fixed-interface modes (Eqs. 3-4).
    Cb,
    /// The paper's variant: constraint modes + free modes cleaned on the retained DOFs (Eq. 5).
    Free,
    /// The free variant enriched with the modes of the structure with joints released.
    Enriched,
}

#[derive(clap::Args)]
pub struct Args {
    #[command(flatten)]
    pub model: ModelArgs,
    /// Retained DOFs, comma-separated: DOF names `node.direction` (e.g. `12.3`), node sets of
    /// a mesh (`TOP`: all their DOFs) or node sets with directions (`TOP:3`, `SCREW:123`).
    #[arg(long, required = true)]
    pub retain: String,
    /// Number of (free or fixed-interface) modes in the basis.
    #[arg(long, default_value_t = 20)]
    pub modes: usize,
    /// Instead of --modes: every (free or fixed-interface) mode with F1 <= f <= F2 (Hz, F1:F2,
    /// e.g. 0:3000), however many there are, counted by the inertia of K - sigma M at both ends
    /// as `stickslip modes --band` does. Not with --modes or --shift.
    #[arg(long, value_name = "F1:F2", conflicts_with_all = ["modes", "shift"], allow_hyphen_values = true)]
    pub band: Option<String>,
    #[arg(long, value_enum, default_value = "free")]
    pub method: MethodArg,
    /// A joint to release for `--method enriched`: `A-B@K` (connector of stiffness K N/m
    /// between DOFs A and B, e.g. `12.3-40.3@1e8`) or `A@K` (to the ground). Repeatable.
    #[arg(long)]
    pub release: Vec<String>,
    /// Number of released-structure modes added by `--method enriched` (default: --modes;
    /// required with --band).
    #[arg(long)]
    pub release_modes: Option<usize>,
    /// Shift (Hz) of the eigensolver: modes nearest it (default: the lowest modes).
    #[arg(long)]
    pub shift: Option<f64>,
    /// Output directory.
    #[arg(long)]
    pub out: PathBuf,
}

/// The retained DOFs named by `--retain`, in the order given.
fn retained_dofs(spec: &str, loaded: &Loaded) -> anyhow::Result<Vec<usize>> {
    let model = &loaded.model;
    let mut out = Vec::new();
    for item in spec.split(',').map(str::trim).filter(|s| !s.is_empty()) {
        if let Ok(i) = model.dof_index(item) {
            out.push(i);
            continue;
        }
        let (set, dirs) = match item.split_once(':') {
            Some((s, d)) => (s, Some(d)),
            None => (item, None),
        };
        let Some(fe) = &loaded.fe else {
            bail!("--retain: no DOF named {item:?} in the model (DOFs are named node.direction, e.g. 12.3)");
        };
        let wanted: Option<Vec<u8>> = match dirs {
            None => None,
            Some(d) => Some(
                d.chars()
                    .map(|c| c.to_digit(10).filter(|v| (1..=6).contains(v)).map(|v| v as u8))
                    .collect::<Option<Vec<u8>>>()
                    .with_context(|| {
                        format!("--retain {item:?}: directions are digits 1..=6, e.g. TOP:3 or TOP:123")
                    })?,
            ),
        };
        let dofs = fe.set_dofs(&set.to_ascii_uppercase()).with_context(|| {
            format!("--retain {item:?}: neither a DOF name (node.direction) nor a node set of the mesh")
        })?;
        let before = out.len();
        out.extend(
            dofs.into_iter()
                .filter(|&i| wanted.as_ref().is_none_or(|w| model.dofs[i].direction.is_some_and(|d| w.contains(&d)))),
        );
        if out.len() == before {
            bail!("--retain {item:?}: the set has no independent DOF in those directions");
        }
    }
    Ok(out)
}

fn releases(specs: &[String], model: &LinearModel) -> anyhow::Result<Vec<Release>> {
    specs
        .iter()
        .map(|s| {
            let (dofs, k) =
                s.split_once('@').with_context(|| format!("--release {s:?}: expected A-B@STIFFNESS or A@STIFFNESS"))?;
            let stiffness: f64 =
                k.trim().parse().with_context(|| format!("--release {s:?}: stiffness {k:?} is not a number"))?;
            let mut direction = vec![0.0; model.n_dofs()];
            let (a, b) = match dofs.split_once('-') {
                Some((a, b)) => (a, Some(b)),
                None => (dofs, None),
            };
            direction[model.dof_index(a.trim()).with_context(|| format!("--release {s:?}"))?] = 1.0;
            if let Some(b) = b {
                direction[model.dof_index(b.trim()).with_context(|| format!("--release {s:?}"))?] -= 1.0;
            }
            Ok(Release { name: s.clone(), direction, stiffness })
        })
        .collect()
}

pub fn main(args: Args) -> anyhow::Result<()> {
    let loaded = load(&args.model)?;
    let retained = retained_dofs(&args.retain, &loaded)?;
    eprintln!("retained: {} DOFs", retained.len());
    let band = args.band.as_deref().map(parse_band).transpose()?;
    if band.is_some() && matches!(args.method, MethodArg::Enriched) && args.release_modes.is_none() {
        bail!("--band with --method enriched: give the number of released-structure modes (--release-modes)");
    }
    let opts = ReductionOptions {
        retained,
        modes: args.modes,
        band: band.map(|(f1, f2)| (lambda_from_hz(f1), lambda_from_hz(f2))),
        eigen: EigenOptions { shift: shift_from_hz(args.shift), ..Default::default() },
    };
    let start = Instant::now();
    if let Some((f1, f2)) = band {
        eprintln!("basis modes: every one between {f1} and {f2} Hz");
    }
    let red = match args.method {
        MethodArg::Cb => reduction::craig_bampton(&loaded.model, &opts)?,
        MethodArg::Free => reduction::free_modes(&loaded.model, &opts)?,
        MethodArg::Enriched => {
            if args.release.is_empty() {
                bail!("--method enriched needs at least one --release A-B@STIFFNESS");
            }
            let rel = releases(&args.release, &loaded.model)?;
            reduction::enriched(&loaded.model, &opts, &rel, args.release_modes.unwrap_or(args.modes))?
        }
    };
    for (stage, secs) in &red.stages {
        eprintln!("  {stage}: {secs:.2} s");
    }
    eprintln!(
        "reduced to {} DOFs ({} retained + {} modal) in {:.2} s",
        red.n_reduced(),
        red.retained.len(),
        red.n_reduced() - red.retained.len(),
        start.elapsed().as_secs_f64()
    );
    println!("{:>5} {:>16} {:>10}", "mode", "basis f (Hz)", "residual");
    for (r, (f, res)) in red.basis_frequencies_hz.iter().zip(&red.basis_residuals).enumerate() {
        println!("{:>5} {:>16.6} {:>10.2e}", r + 1, f, res);
    }
    write(&args.out, &red)
}

/// Entries of the basis written into the NPZ when it is no larger than this (80 MB).
const BASIS_NPZ_LIMIT: usize = 10_000_000;

fn write(dir: &std::path::Path, red: &Reduction) -> anyhow::Result<()> {
    std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
    let model = &red.model;
    let mut written = vec![dir.join("M.mtx"), dir.join("K.mtx"), dir.join("reduced.npz"), dir.join("dofs.csv")];
    mtx::write(&dir.join("M.mtx"), &model.mass)?;
    mtx::write(&dir.join("K.mtx"), &model.stiffness)?;
    if let Damping::Matrix(d) = &model.damping {
        mtx::write(&dir.join("D.mtx"), d)?;
        written.push(dir.join("D.mtx"));
    }
    let basis = (red.basis.nrows() * red.basis.ncols() <= BASIS_NPZ_LIMIT).then_some(&red.basis);
    npz::write(&dir.join("reduced.npz"), model, &npz::NpzExtras { basis, retained: &red.retained })?;
    npz::write_dof_csv(&dir.join("dofs.csv"), model, &red.retained)?;
    eprintln!(
        "wrote M.mtx, K.mtx, reduced.npz{} and dofs.csv to {}",
        if basis.is_some() { " (with the basis T)" } else { "" },
        dir.display()
    );
    // A D.mtx of an earlier reduction would be read as this model's damping.
    for old in stickslip_io::output::replace_previous_run(dir, "reduce", &written)? {
        eprintln!("removed {} (written by the previous reduce, not by this one)", old.display());
    }
    Ok(())
}
