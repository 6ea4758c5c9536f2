//! A model from Matrix Market files, with DOF names from a file, all relative to the study.

use std::path::PathBuf;

use faer::Mat;
use stickslip_core::model::Matrix;
use stickslip_io::matrix::mtx;
use stickslip_io::study::Study;

fn scratch_dir(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("stickslip-io-{name}-{}", std::process::id()));
    std::fs::create_dir_all(dir.join("mats")).unwrap();
    dir
}

#[test]
fn matrix_files_resolve_against_the_study_folder() {
    let dir = scratch_dir("study-files");
    let m = Mat::from_fn(3, 3, |i, j| if i == j { 1.0 + i as f64 } else { 0.0 });
    let k = Mat::from_fn(3, 3, |i, j| match (i as i64 - j as i64).abs() {
        0 => 2.0e4,
        1 => -1.0e4,
        _ => 0.0,
    });
    mtx::write(&dir.join("mats/m.mtx"), &Matrix::Dense(m.clone())).unwrap();
    mtx::write(&dir.join("mats/k.mtx"), &Matrix::Dense(k.clone())).unwrap();
    mtx::write(&dir.join("mats/d.mtx"), &Matrix::Dense(Mat::from_fn(3, 3, |i, j| 0.01 * k[(i, j)]))).unwrap();
    std::fs::write(dir.join("mats/dofs.txt"), "# node.direction\n10.3\n11.3\n\ntip\n").unwrap();
    let study = r#"
[model]
mass_file = "mats/m.mtx"
stiffness_file = "mats/k.mtx"
damping_file = "mats/d.mtx"
dof_file = "mats/dofs.txt"

[[load]]
name = "tip_force"
dof = "tip"
scale = 2.5

[[joint]]
name = "j"
law = "jenkins"
between = ["10.3", "11.3"]
stiffness = 1.0e4
replaces_stiffness = true
threshold = 3.0

[excitation]
levels = [1.0]

[sweep]
start_hz = 40.0
end_hz = 20.0

[[output]]
name = "root"
dof = "10.3"
"#;
    std::fs::write(dir.join("study.toml"), study).unwrap();
    // Loaded from another working directory on purpose: paths follow the study file.
    let study = Study::load(dir.join("study.toml")).unwrap();
    assert!(study.sweep.is_downward());
    let (model, excitation, outputs) = study.build_model().unwrap();
    let lin = &model.linear;
    assert_eq!(lin.dofs.iter().map(|d| d.name.as_str()).collect::<Vec<_>>(), ["10.3", "11.3", "tip"]);
    assert_eq!((lin.dofs[0].node, lin.dofs[0].direction), (Some(10), Some(3)));
    // Matrix Market round-trips f64 exactly.
    assert_eq!(lin.stiffness.to_dense(), k);
    assert_eq!(lin.damping_dense(None)[(0, 1)], -100.0);
    assert_eq!(excitation.pattern, vec![0.0, 0.0, 2.5]);
    assert_eq!(outputs[0].vector, vec![1.0, 0.0, 0.0]);
    // Paper form with the coupling spring replaced: stuck, the element adds nothing; in gross
    // slip it gives F_c − k u (exact in binary here).
    let law = &model.elements[0].law;
    let (mut state, mut g) = (vec![0.0; law.n_state()], [0.0]);
    law.update(&[1.0], &[0.0], &mut state, &mut g, None);
    assert_eq!(g[0], 3.0 - 1.0e4);
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn a_dof_file_of_the_wrong_length_is_rejected() {
    let dir = scratch_dir("study-dofs");
    mtx::write(&dir.join("mats/m.mtx"), &Matrix::Dense(Mat::identity(2, 2))).unwrap();
    std::fs::write(dir.join("mats/dofs.txt"), "a\nb\nc\n").unwrap();
    let study = "[model]\nmass_file = \"mats/m.mtx\"\nstiffness_file = \"mats/m.mtx\"\ndof_file = \"mats/dofs.txt\"\n\
                 [[load]]\nname = \"p\"\ndof = \"a\"\n[excitation]\nlevels = [1.0]\n[sweep]\nstart_hz = 1.0\nend_hz = 2.0\n";
    std::fs::write(dir.join("study.toml"), study).unwrap();
    let msg = Study::load(dir.join("study.toml")).unwrap().build_model().unwrap_err().to_string();
    assert!(msg.contains("study.toml:2:13: [model]: M (mass) is 2x2, expected 3x3"), "{msg}");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn an_indefinite_sparse_mass_is_rejected() {
    use faer::sparse::{SparseColMat, Triplet};
    let dir = scratch_dir("study-sparse");
    // diag(1, −1): a Cholesky of the sparse (coordinate) matrix fails at the second pivot.
    let sparse = |d1: f64| {
        Matrix::Sparse(
            SparseColMat::try_new_from_triplets(2, 2, &[Triplet::new(0, 0, 1.0), Triplet::new(1, 1, d1)]).unwrap(),
        )
    };
    mtx::write(&dir.join("mats/m.mtx"), &sparse(-1.0)).unwrap();
    mtx::write(&dir.join("mats/k.mtx"), &sparse(1.0)).unwrap();
    let study = "[model]\nmass_file = \"mats/m.mtx\"\nstiffness_file = \"mats/k.mtx\"\n\
                 [[load]]\nname = \"p\"\ndof = \"1\"\n[excitation]\nlevels = [1.0]\n[sweep]\nstart_hz = 1.0\nend_hz = 2.0\n";
    std::fs::write(dir.join("study.toml"), study).unwrap();
    let parsed = Study::load(dir.join("study.toml")).unwrap();
    let msg = parsed.build_model().unwrap_err().to_string();
    assert!(msg.contains("study.toml:2:13: [model]: the mass matrix is not positive definite"), "{msg}");
    // The same files with a positive mass build, the DOFs numbered from 1.
    mtx::write(&dir.join("mats/m.mtx"), &sparse(2.0)).unwrap();
    let (model, _, outputs) = parsed.build_model().unwrap();
    assert!(matches!(model.linear.mass, Matrix::Sparse(_)));
    assert_eq!(outputs.iter().map(|o| o.name.as_str()).collect::<Vec<_>>(), ["1", "2"]);
    std::fs::remove_dir_all(&dir).unwrap();
}
