//! `stickslip reduce --band F1:F2`: the basis holds every mode of the band, as `--modes` holds
//! the lowest ones; `--band` with `--modes` is refused.
mod common;
use std::process::Output;

use common::{repo, scratch, stickslip};

fn reduce(dir: &std::path::Path, out: &str, options: &[&str]) -> Output {
    stickslip()
        .args(["reduce", "--retain", "TOP_BLADE,MID", "--method", "free"])
        .args(options)
        .arg("--out")
        .arg(dir.join(out))
        .arg(repo().join("examples/blade-joint/blade.inp"))
        .output()
        .unwrap()
}

/// The basis frequencies (Hz) of the table `reduce` prints.
fn basis_hz(o: &Output) -> Vec<f64> {
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    String::from_utf8_lossy(&o.stdout)
        .lines()
        .skip(1)
        .map(|l| l.split_whitespace().nth(1).unwrap().parse().unwrap())
        .collect()
}

#[test]
fn a_band_puts_its_modes_in_the_basis() {
    let dir = scratch("reduce-band");
    std::fs::create_dir_all(&dir).unwrap();
    let lowest = basis_hz(&reduce(&dir, "lowest", &["--modes", "10"]));
    assert_eq!(lowest.len(), 10);
    let between = |i: usize| 0.5 * (lowest[i] + lowest[i + 1]);
    // 0:F gives the modes up to F, the same reduced model as --modes with their count.
    let upto = basis_hz(&reduce(&dir, "upto", &["--band", &format!("0:{}", between(7))]));
    assert_eq!(upto.len(), 8, "{upto:?}");
    for (a, b) in upto.iter().zip(&lowest) {
        assert!((a - b).abs() <= 1e-6 * b, "{a} vs {b} Hz");
    }
    let eight = basis_hz(&reduce(&dir, "eight", &["--modes", "8"]));
    assert_eq!(eight.len(), 8);
    // The same reduced stiffness, up to the signs of the modal coordinates (each solver
    // normalises its modes' signs its own way).
    let (k_band, k_count) = (values(&dir.join("upto/K.mtx")), values(&dir.join("eight/K.mtx")));
    assert_eq!(k_band.len(), k_count.len());
    let scale = k_count.iter().fold(0.0f64, |s, v| s.max(v.abs()));
    for (a, b) in k_band.iter().zip(&k_count) {
        assert!((a.abs() - b.abs()).abs() <= 1e-8 * scale, "K: {a:e} vs {b:e}");
    }
    // A band above the lowest modes: those inside it only.
    let inside = basis_hz(&reduce(&dir, "inside", &["--band", &format!("{}:{}", between(2), between(7))]));
    assert_eq!(inside.len(), 5, "{inside:?}");
    for (a, b) in inside.iter().zip(&lowest[3..8]) {
        assert!((a - b).abs() <= 1e-6 * b, "{a} vs {b} Hz");
    }
    // --band replaces --modes.
    let o = reduce(&dir, "both", &["--band", "0:500", "--modes", "4"]);
    assert!(!o.status.success());
    assert!(String::from_utf8_lossy(&o.stderr).contains("cannot be used with"));
    std::fs::remove_dir_all(&dir).unwrap();
}

/// The values of a Matrix Market coordinate file, in file order.
fn values(path: &std::path::Path) -> Vec<f64> {
    std::fs::read_to_string(path)
        .unwrap()
        .lines()
        .filter(|l| !l.starts_with('%'))
        .skip(1)
        .map(|l| l.split_whitespace().last().unwrap().parse().unwrap())
        .collect()
}

/// The thread count (given, or the default taken from the machine's load) changes no result
/// beyond round-off: the same basis and reduced matrices on one and two workers.
#[test]
fn results_do_not_depend_on_the_thread_count() {
    let dir = scratch("reduce-threads");
    std::fs::create_dir_all(&dir).unwrap();
    let mut hz = Vec::new();
    for threads in ["1", "2"] {
        let o = stickslip()
            .args(["--threads", threads, "reduce", "--retain", "TOP_BLADE,MID", "--method", "free", "--modes", "8"])
            .arg("--out")
            .arg(dir.join(threads))
            .arg(repo().join("examples/blade-joint/blade.inp"))
            .output()
            .unwrap();
        hz.push(basis_hz(&o));
    }
    assert_eq!(hz[0], hz[1]);
    for file in ["K.mtx", "M.mtx"] {
        let (a, b) = (values(&dir.join("1").join(file)), values(&dir.join("2").join(file)));
        assert_eq!(a.len(), b.len());
        let scale = a.iter().fold(0.0f64, |s, v| s.max(v.abs()));
        for (x, y) in a.iter().zip(&b) {
            assert!((x - y).abs() <= 1e-10 * scale, "{file}: {x:e} vs {y:e}");
        }
    }
    std::fs::remove_dir_all(&dir).unwrap();
}
