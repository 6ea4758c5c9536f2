//! Fuzz-style property tests of every reader of stickslip-io (issue 9): valid sample inputs,
//! mutated (see `fuzz_support`), must give an error or finite values, never a panic, an abort
//! on a huge allocation or a hang. `STICKSLIP_FUZZ_CASES=100000 cargo test -p stickslip-io
//! --test fuzz_readers` runs more.

mod fuzz_support;

use std::path::{Path, PathBuf};

use fuzz_support::{debug_has_non_finite, fuzz};
use num_complex::Complex64;
use stickslip_io::matrix::{abaqus, calculix, dmig, mtx, LabelledMatrix};
use stickslip_io::records;
use stickslip_io::study::Study;
use stickslip_io::uff::{self, Abscissa, Dataset58, Encoding, Ordinate};

fn repo() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../..")
}

fn matrix_data(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/matrix_data").join(name)
}

/// A scratch folder of this process for the readers that take a path.
fn scratch(target: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("stickslip-fuzz-{target}-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// Run `check` on mutations of `seeds`; a panic or a failed assertion fails the test with
/// the seed and the mutations.
fn sparse_finite(m: &LabelledMatrix) -> bool {
    let a = m.matrix.as_ref();
    (0..a.ncols()).all(|j| a.val_of_col(j).iter().all(|v| v.is_finite()))
}

#[test]
fn study_files() {
    let paths: Vec<PathBuf> = ["jenkins-1dof", "jenkins-2dof", "blade-joint", "harmony", "rigid-contact"]
        .iter()
        .map(|e| repo().join("examples").join(e).join("study.toml"))
        .collect();
    let seeds: Vec<Vec<u8>> = paths.iter().map(|p| std::fs::read(p).unwrap()).collect();
    fuzz("study (TOML)", &seeds, |seed, input| {
        if let Ok(study) = Study::parse(&String::from_utf8_lossy(input), &paths[seed]) {
            assert!(!debug_has_non_finite(&format!("{study:?}")), "a non-finite value was accepted");
        }
    });
}

#[test]
fn matrix_market() {
    let seeds: Vec<Vec<u8>> = ["dense_general.mtx", "dense_sym.mtx", "general_3x2.mtx", "spring_chain_sym.mtx"]
        .iter()
        .map(|n| std::fs::read(matrix_data(n)).unwrap())
        .collect();
    let file = scratch("mtx").join("m.mtx");
    fuzz("Matrix Market .mtx", &seeds, |_, input| {
        std::fs::write(&file, input).unwrap();
        if let Ok(m) = mtx::read(&file) {
            assert!(m.is_finite(), "non-finite entries accepted");
        }
    });
}

#[test]
fn abaqus_matrices() {
    let seeds: Vec<Vec<u8>> =
        ["tiny_STIF1.mtx", "tiny_MASS1.mtx"].iter().map(|n| std::fs::read(matrix_data(n)).unwrap()).collect();
    let file = scratch("abaqus").join("m.mtx");
    fuzz("Abaqus matrix", &seeds, |_, input| {
        std::fs::write(&file, input).unwrap();
        if let Ok(m) = abaqus::read(&file) {
            assert!(sparse_finite(&m), "non-finite entries accepted");
        }
    });
}

#[test]
fn nastran_dmig() {
    let seeds: Vec<Vec<u8>> =
        ["sample.pch", "free_field.bdf"].iter().map(|n| std::fs::read(matrix_data(n)).unwrap()).collect();
    let file = scratch("dmig").join("m.pch");
    fuzz("Nastran DMIG", &seeds, |_, input| {
        std::fs::write(&file, input).unwrap();
        if let Ok(matrices) = dmig::read(&file) {
            assert!(matrices.iter().all(|m| sparse_finite(&m.matrix)), "non-finite entries accepted");
        }
        let _ = dmig::read_model(&file, "KAAX", "MAAX");
    });
}

#[test]
fn calculix_matrices() {
    // One seed per file of the job: the other two stay valid.
    let files = ["sti", "mas", "dof"];
    let seeds: Vec<Vec<u8>> =
        files.iter().map(|e| std::fs::read(matrix_data(&format!("tiny_ccx.{e}"))).unwrap()).collect();
    let dir = scratch("ccx");
    fuzz("CalculiX .sti/.mas/.dof", &seeds, |seed, input| {
        for (i, e) in files.iter().enumerate() {
            let path = dir.join(format!("job.{e}"));
            std::fs::write(&path, if i == seed { input } else { &seeds[i] }).unwrap();
        }
        if let Ok(model) = calculix::read_job(&dir.join("job")) {
            assert!(model.mass.is_finite() && model.stiffness.is_finite(), "non-finite entries accepted");
        }
    });
}

const TIME_CSV: &str = "# bench test\ntime_s,force_N,top_m_s2\n0,1.5,0.1\n0.001,1.2,-0.2\n0.002,0.3,0.25\n0.003,-0.9,0.1\n0.004,-1.4,-3e-2\n";
const FRF_CSV: &str =
    "level_N,frequency_Hz,top_amp_m_s2_per_N,top_phase_rad\n10,100,1e-3,0.1\n10,110,2e-3,-0.5\n10,120,5e-4,-2.5\n\
                       20,100,1.1e-3,0.1\n20,110,1.5e-3,-0.7\n20,120,6e-4,-2.4\n";
const SIMULATED_CSV: &str =
    "level_N,frequency_Hz,newton_iterations,residual_rel,tip_disp_frf_m_per_N\n1,10,3,1e-9,1e-6\n1,11,2,2e-10,3e-6\n";

fn check_records(path: &Path) {
    if let Ok(t) = records::read_table(path) {
        assert!(t.data.iter().flatten().all(|v| v.is_finite()), "non-finite table value accepted");
    }
    if let Ok(r) = records::read_time_csv(path) {
        assert!(r.sample_rate_hz.is_finite() && r.sample_rate_hz > 0.0 && r.start_s.is_finite());
        assert!(r.channels.iter().flat_map(|c| &c.values).all(|v| v.is_finite()), "non-finite sample accepted");
    }
    if let Ok(sets) = records::read_frf_csv(path) {
        check_frf_sets(&sets);
    }
}

fn check_frf_sets(sets: &[records::FrfSet]) {
    for s in sets {
        assert!(s.level_n.is_none_or(f64::is_finite));
        assert!(s.frequency_hz.iter().all(|f| f.is_finite()), "non-finite frequency accepted");
        assert!(s.frequency_hz.windows(2).all(|w| w[0] < w[1]), "unordered frequencies accepted: {:?}", s.frequency_hz);
        for c in &s.curves {
            assert!(c.values.iter().all(|v| v.re.is_finite() && v.im.is_finite()), "non-finite FRF accepted");
        }
    }
}

#[test]
fn csv_records_and_frf_tables() {
    let seeds: Vec<Vec<u8>> = [TIME_CSV, FRF_CSV, SIMULATED_CSV].iter().map(|s| s.as_bytes().to_vec()).collect();
    let file = scratch("csv").join("records.csv");
    fuzz("CSV records and FRF tables", &seeds, |_, input| {
        std::fs::write(&file, input).unwrap();
        check_records(&file);
    });
}

fn finite_dataset(d: &Dataset58) -> bool {
    let ordinate = match &d.ordinate {
        Ordinate::Real(v) => v.iter().all(|x| x.is_finite()),
        Ordinate::Complex(v) => v.iter().all(|x| x.re.is_finite() && x.im.is_finite()),
    };
    let abscissa = match &d.abscissa {
        Abscissa::Even { min, increment } => min.is_finite() && increment.is_finite(),
        Abscissa::Uneven(x) => x.iter().all(|v| v.is_finite()) && x.windows(2).all(|w| w[0] < w[1]),
    };
    ordinate && abscissa && d.z_value.is_finite()
}

#[test]
fn uff_58() {
    let uff_data = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/data/uff");
    let mut seeds: Vec<Vec<u8>> = [
        "non_ascii_header.uff",
        "dataset_milestone_in_header.uff",
        "binary8byte.uff",
        "heat_engine_housing.uff",
        "time-history-not-all-columns-filled.uff",
    ]
    .iter()
    .map(|n| std::fs::read(uff_data.join(n)).unwrap())
    .collect();
    let frf = Dataset58::frf("tip", "m/N", vec![10.0, 20.0, 30.0], vec![Complex64::new(1.0, 0.5); 3]);
    let time = Dataset58::time_record("force", "N", 1e-3, vec![1.0, -2.0, 0.5, 0.25]);
    for encoding in [Encoding::Ascii, Encoding::Binary] {
        seeds.push(uff::to_bytes(&[frf.clone(), time.clone()], encoding).unwrap());
    }
    fuzz("UFF 58", &seeds, |_, input| {
        if let Ok(file) = uff::parse(input, "fuzz.uff") {
            assert!(file.datasets.iter().all(finite_dataset), "non-finite or unordered dataset accepted");
            check_frf_sets(&records::frf_sets_from_uff(&file.datasets, "fuzz.uff"));
            if let Ok(r) = records::time_records_from_uff(&file.datasets, "fuzz.uff") {
                assert!(r.sample_rate_hz.is_finite() && r.sample_rate_hz > 0.0, "sample rate {}", r.sample_rate_hz);
            }
        }
    });
}
