//! Time to write the result tables of a sweep against their size: `frf.npz` and `frf.csv` of
//! 10^3 to 10^5 points (one output and one joint, N = 7 harmonics: 4 + 3 + 16 + 2 = 25 columns
//! and two 8-column harmonic arrays).
//!
//! `cargo bench -p stickslip-io --bench outputs` (median of 7 writes per size).

use std::time::Instant;

use stickslip_io::output::{
    harmonics_from_coefficients, write_frf_csv, write_frf_npz, ElementRecord, LevelResult, OutputRecord, PointRecord,
};

/// Numbers of every magnitude and sign, as a solve gives (nothing a compressor finds easy).
fn value(seed: usize) -> f64 {
    let x = (seed as f64 + 1.0) * std::f64::consts::PI / 7.0;
    x.sin() * 10f64.powi((seed % 17) as i32 - 8) / 3.0
}

fn levels(points: usize) -> Vec<LevelResult> {
    let point = |i: usize| PointRecord {
        frequency_hz: 150.0 + 200.0 * i as f64 / points as f64,
        iterations: i % 5,
        residual: value(i).abs(),
        outputs: vec![OutputRecord {
            name: "mass".into(),
            disp_frf: value(i + 1),
            accel_frf: value(i + 2),
            peak: value(i + 3),
            harmonics: harmonics_from_coefficients(&(0..15).map(|k| value(i + k)).collect::<Vec<_>>()),
            ..Default::default()
        }],
        elements: vec![ElementRecord {
            name: "joint".into(),
            energy_j: value(i + 4),
            stick_fraction: value(i + 5).abs(),
            ..Default::default()
        }],
        input_energy_j: 0.0,
        viscous_energy_j: 0.0,
        stability: None,
    };
    // Four levels, as the Table 6 study.
    (0..4)
        .map(|l| LevelResult {
            level_n: [100.0, 1000.0, 3000.0, 10000.0][l],
            points: (l * points / 4..(l + 1) * points / 4).map(point).collect(),
            ..Default::default()
        })
        .collect()
}

fn median_ms(mut f: impl FnMut()) -> f64 {
    let mut times: Vec<f64> = (0..7)
        .map(|_| {
            let started = Instant::now();
            f();
            started.elapsed().as_secs_f64() * 1e3
        })
        .collect();
    times.sort_by(f64::total_cmp);
    times[times.len() / 2]
}

fn main() {
    let dir = std::env::temp_dir().join(format!("stickslip-bench-outputs-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    println!("| points | frf.npz | size | frf.csv | size |");
    println!("|---|---|---|---|---|");
    for points in [1_000, 10_000, 100_000] {
        let levels = levels(points);
        let (npz, csv) = (dir.join("frf.npz"), dir.join("frf.csv"));
        let npz_ms = median_ms(|| write_frf_npz(&npz, &levels).unwrap());
        let csv_ms = median_ms(|| write_frf_csv(&csv, &levels).unwrap());
        let size = |p: &std::path::Path| std::fs::metadata(p).unwrap().len() as f64 / 1e6;
        println!("| {points} | {npz_ms:.1} ms | {:.2} MB | {csv_ms:.1} ms | {:.2} MB |", size(&npz), size(&csv));
    }
    std::fs::remove_dir_all(&dir).unwrap();
}
