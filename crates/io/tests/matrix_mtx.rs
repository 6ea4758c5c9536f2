//! Matrix Market: hand-written sample files with known values, round trips, bad input.
use std::path::{Path, PathBuf};

use faer::sparse::{SparseColMat, Triplet};
use faer::Mat;
use stickslip_core::model::Matrix;
use stickslip_io::matrix::{mtx, MatrixFileError};

fn sample(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/matrix_data").join(name)
}

fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("stickslip-matrix-mtx-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir.join(name)
}

fn assert_dense_eq(m: &Matrix, expected: &[&[f64]]) {
    let d = m.to_dense();
    assert_eq!((d.nrows(), d.ncols()), (expected.len(), expected[0].len()));
    for (i, row) in expected.iter().enumerate() {
        for (j, &v) in row.iter().enumerate() {
            // Every sample value is exactly representable: the parse must be exact.
            assert_eq!(d[(i, j)], v, "entry ({i}, {j})");
        }
    }
}

#[test]
fn reads_symmetric_coordinate_sample() {
    let k = mtx::read(&sample("spring_chain_sym.mtx")).unwrap();
    assert!(matches!(k, Matrix::Sparse(_)));
    assert_dense_eq(&k, &[&[3000.0, -2000.0, 0.0], &[-2000.0, 5000.0, -3000.0], &[0.0, -3000.0, 3000.0]]);
}

#[test]
fn reads_general_coordinate_sample_summing_duplicates() {
    let a = mtx::read(&sample("general_3x2.mtx")).unwrap();
    assert_dense_eq(&a, &[&[1.0, 0.0], &[0.0, 2.5], &[-4.0, 0.0]]);
}

#[test]
fn reads_array_samples() {
    let m = mtx::read(&sample("dense_sym.mtx")).unwrap();
    assert!(matches!(m, Matrix::Dense(_)));
    assert_dense_eq(&m, &[&[2.0, 0.5, 0.0], &[0.5, 3.0, 0.25], &[0.0, 0.25, 4.0]]);
    let a = mtx::read(&sample("dense_general.mtx")).unwrap();
    assert_dense_eq(&a, &[&[1.0, 2.0], &[3.0, 4.0]]);
}

/// Values that need all 17 significant digits, tiny and huge magnitudes.
fn awkward(i: usize, j: usize) -> f64 {
    (1.0 + (i * 7 + j * 13) as f64).sqrt() * 10f64.powi((i as i32 - j as i32) * 40) / 3.0
}

#[test]
fn sparse_round_trip_is_bit_exact() {
    let n = 6;
    let mut sym = Vec::new();
    let mut gen = Vec::new();
    for i in 0..n {
        for j in 0..n {
            if (i + j) % 3 != 1 {
                sym.push(Triplet::new(i, j, awkward(i.max(j), i.min(j))));
                gen.push(Triplet::new(i, j, awkward(i, j)));
            }
        }
    }
    for (name, t) in [("sym.mtx", sym), ("gen.mtx", gen)] {
        let m = Matrix::Sparse(SparseColMat::try_new_from_triplets(n, n, &t).unwrap());
        let path = scratch(name);
        mtx::write(&path, &m).unwrap();
        let back = mtx::read(&path).unwrap();
        assert!(matches!(back, Matrix::Sparse(_)));
        // Shortest round-trip formatting: the read-back must be identical, not just close.
        assert_eq!(back.to_dense(), m.to_dense(), "{name}");
    }
    let head = std::fs::read_to_string(scratch("sym.mtx")).unwrap();
    assert!(head.starts_with("%%MatrixMarket matrix coordinate real symmetric"));
}

#[test]
fn dense_round_trip_is_bit_exact() {
    let sym = Mat::from_fn(5, 5, |i, j| awkward(i.max(j), i.min(j)));
    let rect = Mat::from_fn(4, 3, awkward);
    for (name, m) in [("dsym.mtx", sym), ("drect.mtx", rect)] {
        let path = scratch(name);
        mtx::write(&path, &Matrix::Dense(m.clone())).unwrap();
        let back = mtx::read(&path).unwrap();
        assert!(matches!(back, Matrix::Dense(_)));
        assert_eq!(back.to_dense(), m, "{name}");
    }
}

fn parse_error(name: &str) -> (usize, String) {
    match mtx::read(&sample(name)) {
        Err(MatrixFileError::Parse { path, line, message }) => {
            assert!(path.ends_with(name));
            let shown = MatrixFileError::Parse { path, line, message: message.clone() }.to_string();
            assert!(shown.contains(&format!("{name}:{line}:")), "{shown}");
            (line, message)
        }
        other => panic!("expected a parse error for {name}, got {other:?}"),
    }
}

#[test]
fn bad_input_names_file_and_line() {
    let (line, msg) = parse_error("bad_value.mtx");
    assert_eq!(line, 4);
    assert!(msg.contains("abc"), "{msg}");
    let (line, msg) = parse_error("bad_count.mtx");
    assert_eq!(line, 4);
    assert!(msg.contains("3 entries"), "{msg}");
    let (line, msg) = parse_error("bad_index.mtx");
    assert_eq!(line, 4);
    assert!(msg.contains("row 3"), "{msg}");
}

#[test]
fn inline_bad_files() {
    let cases: &[(&str, usize, &str)] = &[
        ("%%MatrixMarket matrix coordinate complex general\n1 1 1\n1 1 1 0\n", 1, "complex"),
        ("%%MatrixMarket matrix coordinate real symmetric\n2 3 1\n1 1 1\n", 2, "square"),
        ("%%MatrixMarket matrix coordinate real symmetric\n2 2 2\n2 1 1\n1 2 1\n", 4, "one triangle"),
        ("%%MatrixMarket matrix array real general\n2 2\n1 2 3\n", 3, "needs 4 values"),
        ("%%MatrixMarket matrix array real general\n1 1\n1\n2\n", 4, "more values"),
        ("not a header\n", 1, "header"),
    ];
    for (k, (text, line, needle)) in cases.iter().enumerate() {
        let path = scratch(&format!("bad{k}.mtx"));
        std::fs::write(&path, text).unwrap();
        match mtx::read(&path) {
            Err(MatrixFileError::Parse { line: l, message, .. }) => {
                assert_eq!(l, *line, "case {k}: {message}");
                assert!(message.contains(needle), "case {k}: {message}");
            }
            other => panic!("case {k}: expected a parse error, got {other:?}"),
        }
    }
    assert!(matches!(mtx::read(&scratch("absent.mtx")), Err(MatrixFileError::Io { .. })));
}

#[test]
fn matrices_that_are_not_finite_are_refused_naming_the_entry() {
    let mut dense = Mat::from_fn(3, 3, |i, j| (i + 2 * j) as f64);
    dense[(1, 2)] = f64::INFINITY;
    let sparse = Matrix::Sparse(
        SparseColMat::try_new_from_triplets(3, 3, &[Triplet::new(0, 0, 1.0), Triplet::new(2, 1, f64::NAN)]).unwrap(),
    );
    for (name, m, entry) in [
        ("inf.mtx", Matrix::Dense(dense), "holds inf at row 2, column 3"),
        ("nan.mtx", sparse, "holds NaN at row 3, column 2"),
    ] {
        let path = scratch(name);
        let _ = std::fs::remove_file(&path);
        let e = mtx::write(&path, &m).unwrap_err().to_string();
        assert!(e.contains(name) && e.contains(entry) && e.contains("refusing to write"), "{e}");
        assert!(!path.exists(), "{name} written");
    }
}
