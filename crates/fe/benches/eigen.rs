//! The sparse eigensolver on a clamped tet10 slab (0.4 × 0.2 × 0.1 m, steel) for a number of
//! modes: wall time of the factorisation and of the iteration, block solves, restarts and the
//! worst residual `‖Kφ − ω²Mφ‖ / ‖Kφ‖`.
//!
//! `cargo bench -p stickslip-fe --bench eigen -- [COUNT ...] [--cells NX,NY,NZ]`
//! (default: 34 100 300 modes of the 20 × 10 × 5-cell slab, 25,830 DOFs).
//!
//! `-- --band LO,HI [--runs R]`: the modes LO..=HI (1-based) as a frequency band
//! ([`solve_band`], its three factorisations included) against all HI lowest modes (factor
//! included), R runs each interleaved, CPU time of the process (user + system) and wall time,
//! medians.
use std::time::Instant;

use stickslip_fe::assembly::FeModel;
use stickslip_fe::eigen::{modes_with_factor, solve, solve_band, to_sparse, EigenOptions, ShiftedFactor};
use stickslip_fe::element::SolidKind;
use stickslip_fe::mesh::generate::box_mesh;
use stickslip_fe::mesh::Material;

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let mut cells = [20, 10, 5];
    let mut counts = Vec::new();
    let mut band = None;
    let mut runs = 3;
    let mut it = args.iter();
    while let Some(a) = it.next() {
        if a == "--cells" {
            let v: Vec<usize> = it.next().expect("NX,NY,NZ").split(',').map(|x| x.parse().expect("a count")).collect();
            cells = [v[0], v[1], v[2]];
        } else if a == "--band" {
            let v: Vec<usize> =
                it.next().expect("LO,HI").split(',').map(|x| x.parse().expect("a mode number")).collect();
            band = Some((v[0], v[1]));
        } else if a == "--runs" {
            runs = it.next().expect("R").parse().expect("a number of runs");
        } else if let Ok(c) = a.parse::<usize>() {
            counts.push(c);
        }
    }
    if counts.is_empty() {
        counts = vec![34, 100, 300];
    }
    let steel = Material { young: 2.1e11, poisson: 0.3, density: 7800.0 };
    let mut mesh = box_mesh([0.4, 0.2, 0.1], cells, SolidKind::Tet10, steel);
    for i in mesh.node_set("ZMIN").expect("box meshes name their faces").to_vec() {
        for d in 1..=3 {
            mesh.fixed.push((i, d));
        }
    }
    let fe = FeModel::assemble(mesh).expect("assembly");
    let (k, m) = (to_sparse(&fe.model.stiffness), to_sparse(&fe.model.mass));
    let (k, m) = (k.into_owned(), m.into_owned());
    if let Some((lo, hi)) = band {
        compare_band(&k, &m, lo, hi, runs);
        return;
    }
    let t = Instant::now();
    let factor = ShiftedFactor::new(k.as_ref(), Some(m.as_ref()), 0.0).expect("factor");
    println!(
        "slab {cells:?}: {} DOFs, factor {:.1} M entries in {:.2} s",
        k.nrows(),
        factor.factor_entries() as f64 / 1e6,
        t.elapsed().as_secs_f64()
    );
    for count in counts {
        let t = Instant::now();
        match modes_with_factor(&k, &m, &factor, &EigenOptions { count, ..Default::default() }) {
            Ok(sol) => println!(
                "  {count:4} modes: {:7.2} s, {:5} solves, {:3} restarts, worst residual {:.1e}, f1 {:.3} Hz, f{count} {:.3} Hz",
                t.elapsed().as_secs_f64(),
                sol.solves,
                sol.restarts,
                sol.residuals.iter().cloned().fold(0.0, f64::max),
                sol.modes.frequencies_hz()[0],
                sol.modes.frequencies_hz()[count - 1],
            ),
            Err(e) => println!("  {count:4} modes: {:7.2} s, error: {e}", t.elapsed().as_secs_f64()),
        }
    }
}

/// CPU time of this process (user + system), seconds, from `/proc/self/stat` (Linux).
fn cpu_seconds() -> f64 {
    let stat = std::fs::read_to_string("/proc/self/stat").unwrap_or_default();
    // Fields after the command name (in parentheses): utime and stime are the 12th and 13th.
    let rest = stat.rsplit_once(')').map(|(_, r)| r).unwrap_or("");
    let f: Vec<f64> = rest.split_whitespace().filter_map(|x| x.parse().ok()).collect();
    if f.len() < 13 {
        return f64::NAN;
    }
    (f[11] + f[12]) / 100.0
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

/// Modes `lo..=hi` as a band against the `hi` lowest modes.
fn compare_band(
    k: &faer::sparse::SparseColMat<usize, f64>,
    m: &faer::sparse::SparseColMat<usize, f64>,
    lo: usize,
    hi: usize,
    runs: usize,
) {
    let mut all = (Vec::new(), Vec::new());
    let mut banded = (Vec::new(), Vec::new());
    let load = std::fs::read_to_string("/proc/loadavg").unwrap_or_default();
    println!("{} DOFs, modes {lo}..={hi}, load average before: {}", k.nrows(), load.trim());
    for run in 0..runs {
        let (c, t) = (cpu_seconds(), Instant::now());
        let sol = solve(k, m, &EigenOptions { count: hi, ..Default::default() }).expect("lowest modes");
        all.0.push(cpu_seconds() - c);
        all.1.push(t.elapsed().as_secs_f64());
        let f = sol.modes.omega.iter().map(|w| w * w).collect::<Vec<_>>();
        // Band ends halfway to the neighbouring modes.
        let lower = 0.5 * (f[lo - 2] + f[lo - 1]);
        let upper = if hi < k.nrows() { f[hi - 1] * (1.0 + 1e-6) } else { f[hi - 1] };
        let (c, t) = (cpu_seconds(), Instant::now());
        let b = solve_band(k, m, lower, upper, &EigenOptions::default()).expect("band");
        banded.0.push(cpu_seconds() - c);
        banded.1.push(t.elapsed().as_secs_f64());
        let worst = b.residuals.iter().cloned().fold(0.0, f64::max);
        let agree =
            b.modes.omega.iter().zip(&sol.modes.omega[lo - 1..]).map(|(a, e)| (a / e - 1.0).abs()).fold(0.0, f64::max);
        println!(
            "  run {run}: {hi} lowest {:.1} s CPU {:.1} s wall; band {} modes ({:.1}..{:.1} Hz) {:.1} s CPU {:.1} s wall, {} solves, worst residual {worst:.1e}, largest difference {agree:.1e}",
            all.0[run],
            all.1[run],
            b.modes.omega.len(),
            lower.sqrt() / std::f64::consts::TAU,
            upper.sqrt() / std::f64::consts::TAU,
            banded.0[run],
            banded.1[run],
            b.solves
        );
    }
    println!(
        "median: {hi} lowest {:.1} s CPU ({:.1} s wall), band {:.1} s CPU ({:.1} s wall)",
        median(all.0),
        median(all.1),
        median(banded.0),
        median(banded.1)
    );
}
