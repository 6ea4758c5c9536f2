//! CalculiX, Abaqus and Nastran matrix imports from hand-written samples with known values;
//! the NPZ writer read back; bad input named by file and line.
use std::path::{Path, PathBuf};

use faer::Mat;
use stickslip_core::model::{Damping, DofLabel, LinearModel, Matrix};
use stickslip_io::matrix::{abaqus, calculix, dmig, model_from_pair, npz, MatrixFileError};

fn sample(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/matrix_data").join(name)
}

fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("stickslip-matrix-formats-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir.join(name)
}

/// Entries are decimal strings of exactly representable values: the parse must be exact.
fn assert_matrix(m: &Matrix, expected: &[&[f64]]) {
    let d = m.to_dense();
    assert_eq!(d.nrows(), expected.len());
    for (i, row) in expected.iter().enumerate() {
        for (j, &v) in row.iter().enumerate() {
            assert_eq!(d[(i, j)], v, "entry ({i}, {j})");
        }
    }
}

fn names(model: &LinearModel) -> Vec<&str> {
    model.dofs.iter().map(|d| d.name.as_str()).collect()
}

#[test]
fn calculix_job_sample() {
    let model = calculix::read_job(&sample("tiny_ccx")).unwrap();
    assert_eq!(names(&model), ["3.1", "3.2", "3.3", "8.3"]);
    assert_eq!(model.dofs[3], DofLabel::nodal(8, 3));
    assert_matrix(
        &model.stiffness,
        &[
            &[1.0e6, -2.0e5, 0.0, 0.0],
            &[-2.0e5, 8.0e5, 1.0e5, 0.0],
            &[0.0, 1.0e5, 6.0e5, -6.0e5],
            &[0.0, 0.0, -6.0e5, 9.0e5],
        ],
    );
    assert_matrix(
        &model.mass,
        &[&[0.25, 0.0, 0.0, 0.0], &[0.0, 0.25, 0.0, 0.0], &[0.0, 0.0, 0.25, 0.05], &[0.0, 0.0, 0.05, 0.125]],
    );
    // Any of the three files names the job too.
    assert_eq!(calculix::read_job(&sample("tiny_ccx.sti")).unwrap().n_dofs(), 4);
}

#[test]
fn calculix_entry_beyond_the_dof_list_names_file_and_line() {
    match calculix::read_job(&sample("bad_ccx/tiny_ccx")) {
        Err(MatrixFileError::Parse { path, line, message }) => {
            assert!(path.ends_with("bad_ccx/tiny_ccx.sti"));
            assert_eq!(line, 7);
            assert!(message.contains("row 5") && message.contains("lists 4 DOFs"), "{message}");
        }
        other => panic!("expected a parse error, got {other:?}"),
    }
    let bad_dof = scratch("bad.dof");
    std::fs::write(&bad_dof, "1.1\n1.x\n").unwrap();
    assert!(matches!(calculix::read_dof(&bad_dof), Err(MatrixFileError::Parse { line: 2, .. })));
    let bad_sti = scratch("job.sti");
    std::fs::write(scratch("job.dof"), "1.1\n1.2\n").unwrap();
    std::fs::write(scratch("job.mas"), "1 1 1.0\n2 2 1.0\n").unwrap();
    std::fs::write(&bad_sti, "1 1 1.0\n1 2 abc\n").unwrap();
    match calculix::read_job(&scratch("job")) {
        Err(e @ MatrixFileError::Parse { line: 2, .. }) => assert!(e.to_string().contains("job.sti:2:"), "{e}"),
        other => panic!("expected a parse error, got {other:?}"),
    }
}

#[test]
fn abaqus_matrix_generate_sample() {
    let k = abaqus::read(&sample("tiny_STIF1.mtx")).unwrap();
    let m = abaqus::read(&sample("tiny_MASS1.mtx")).unwrap();
    let model = model_from_pair(k, m).unwrap();
    assert_eq!(names(&model), ["1.1", "1.2", "7.3"]);
    assert_matrix(&model.stiffness, &[&[4.0e3, -1.0e3, 0.0], &[-1.0e3, 2.0e3, -250.0], &[0.0, -250.0, 1.0e3]]);
    assert_matrix(&model.mass, &[&[2.0, 0.0, 0.0], &[0.0, 2.0, 0.0], &[0.0, 0.0, 0.5]]);
}

#[test]
fn abaqus_bad_lines() {
    let path = scratch("bad_STIF1.mtx");
    std::fs::write(&path, "** header\n1,1,1,1, 1.0\n1,2,1,1\n").unwrap();
    assert!(matches!(abaqus::read(&path), Err(MatrixFileError::Parse { line: 3, .. })));
    std::fs::write(&path, "1,1,1,1, 1.0\n1,9,1,1, 2.0\n").unwrap();
    match abaqus::read(&path) {
        Err(MatrixFileError::Parse { line: 2, message, .. }) => assert!(message.contains("DOF 1..=6"), "{message}"),
        other => panic!("{other:?}"),
    }
}

#[test]
fn nastran_dmig_small_and_large_field_sample() {
    let all = dmig::read(&sample("sample.pch")).unwrap();
    assert_eq!(all.iter().map(|m| m.name.as_str()).collect::<Vec<_>>(), ["KAAX", "MAAX"]);
    assert!(all.iter().all(|m| m.symmetric));
    let model = dmig::read_model(&sample("sample.pch"), "KAAX", "MAAX").unwrap();
    assert_eq!(names(&model), ["10.3", "20.1", "20.3"]);
    assert_matrix(&model.stiffness, &[&[2.0e3, -1.0e3, 0.0], &[-1.0e3, 3.0e3, -500.0], &[0.0, -500.0, 500.0]]);
    assert_matrix(&model.mass, &[&[1.5, 0.0, 0.0], &[0.0, 0.25, 0.0], &[0.0, 0.0, 0.75]]);
}

#[test]
fn nastran_dmig_free_field_square_matrix() {
    let all = dmig::read(&sample("free_field.bdf")).unwrap();
    assert_eq!(all.len(), 1);
    assert!(!all[0].symmetric);
    assert_matrix(&Matrix::Sparse(all[0].matrix.matrix.clone()), &[&[1.0, 2.0], &[3.0, 4.0]]);
}

#[test]
fn nastran_bad_value_and_missing_matrix() {
    match dmig::read(&sample("bad_value.pch")) {
        Err(e @ MatrixFileError::Parse { line: 6, .. }) => assert!(e.to_string().contains("-1.0x3"), "{e}"),
        other => panic!("expected a parse error on line 6, got {other:?}"),
    }
    let err = dmig::read_model(&sample("sample.pch"), "KAAX", "MZZ").unwrap_err();
    assert!(err.to_string().contains("MZZ") && err.to_string().contains("KAAX"), "{err}");
}

#[test]
fn npz_round_trip() {
    let m = Mat::from_fn(3, 3, |i, j| if i == j { 1.0 + i as f64 } else { 0.1 / (1 + i + j) as f64 });
    let k = Mat::from_fn(3, 3, |i, j| if i == j { 1e6 * (1 + i) as f64 } else { -1e5 / 3.0 });
    let d = Mat::from_fn(3, 3, |i, j| 1e-3 * (i + j) as f64);
    let dofs = vec![DofLabel::nodal(12, 3), DofLabel::nodal(40, 1), DofLabel::modal(0)];
    let model = LinearModel::new(
        Matrix::Dense(m.clone()),
        Matrix::Dense(k.clone()),
        Damping::Matrix(Matrix::Dense(d.clone())),
        dofs,
        vec![],
    )
    .unwrap();
    let t = Mat::from_fn(5, 3, |i, j| (i * 3 + j) as f64 / 7.0);
    let path = scratch("model.npz");
    npz::write(&path, &model, &npz::NpzExtras { basis: Some(&t), retained: &[4, 0] }).unwrap();
    let mut archive = npyz::npz::NpzArchive::open(&path).unwrap();
    let mut read = |name: &str| {
        let arr = archive.by_name(name).unwrap().unwrap_or_else(|| panic!("no array {name}"));
        let shape = arr.shape().to_vec();
        (shape, arr.into_vec::<f64>().unwrap())
    };
    for (name, expected) in [("M", &m), ("K", &k), ("D", &d), ("T", &t)] {
        let (shape, values) = read(name);
        assert_eq!(shape, [expected.nrows() as u64, expected.ncols() as u64]);
        for i in 0..expected.nrows() {
            for j in 0..expected.ncols() {
                // float64 stored as is: exact.
                assert_eq!(values[i * expected.ncols() + j], expected[(i, j)], "{name} ({i}, {j})");
            }
        }
    }
    let mut ints = |name: &str| archive.by_name(name).unwrap().unwrap().into_vec::<i64>().unwrap();
    assert_eq!(ints("dof_node"), [12, 40, -1]);
    assert_eq!(ints("dof_direction"), [3, 1, -1]);
    assert_eq!(ints("retained_index"), [4, 0]);
    let csv = scratch("dofs.csv");
    npz::write_dof_csv(&csv, &model, &[4, 0]).unwrap();
    let text = std::fs::read_to_string(&csv).unwrap();
    assert_eq!(text, "index,name,node,direction,full_index\n0,12.3,12,3,4\n1,40.1,40,1,0\n2,mode1,,,\n");
}

#[test]
fn npz_refuses_a_basis_that_is_not_finite_and_writes_nothing() {
    let model = LinearModel::new(
        Matrix::Dense(Mat::identity(2, 2)),
        Matrix::Dense(Mat::from_fn(2, 2, |i, j| if i == j { 2.0 } else { -1.0 })),
        Damping::None,
        vec![DofLabel::nodal(1, 1), DofLabel::nodal(2, 1)],
        vec![],
    )
    .unwrap();
    let mut t = Mat::from_fn(4, 2, |i, j| (i + j) as f64);
    t[(2, 1)] = f64::NAN;
    let path = scratch("not_finite.npz");
    let _ = std::fs::remove_file(&path);
    let e = npz::write(&path, &model, &npz::NpzExtras { basis: Some(&t), retained: &[0, 1] }).unwrap_err().to_string();
    assert!(e.contains("not_finite.npz") && e.contains("T holds NaN at row 3, column 2: refusing to write"), "{e}");
    assert!(!path.exists(), "a half-written archive was left");
}
