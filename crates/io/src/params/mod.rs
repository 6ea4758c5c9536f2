//! Parameter studies: one study run for many values of some of its numbers (a joint's
//! threshold, the damping, a force level...), over a grid or a seeded Latin hypercube.
//!
//! The study is held as its TOML table; a sample writes its values at dotted key paths
//! ([`KeyPath`]) and goes through the study's own validation ([`Study::from_table`]), so a
//! sample is exactly the study file one would write by hand. Each sample is summarised per
//! force level ([`SummaryRow`]: the peak of the first harmonic of an output, its frequency and
//! the energy the joints dissipate there); the full curves are kept on request. A
//! [`SampleRunner`] keeps the linear model (and its reduction) of one sample for the next ones
//! that share it.
//!
//! The command line shards the samples over batch jobs and merges their tables
//! ([`files`]); the Python package schedules the same samples on processes or Dask.

mod design;
pub mod files;
mod keys;

use std::path::{Path, PathBuf};

pub use design::{design, Design, Values, Vary};
pub use keys::{KeyPath, NumberKind};

use crate::analysis::LevelSweeper;
use crate::output::LevelResult;
use crate::study::{LinearBase, Study, StudyError};

/// What is wrong with a parameter study.
#[derive(Debug, thiserror::Error)]
pub enum ParamError {
    /// A `KEY=SPEC` that does not parse.
    #[error("--vary {spec}: {message}")]
    Spec { spec: String, message: String },
    /// A key that is not in the study or not a number.
    #[error("--vary {key}: {message}")]
    Key { key: String, message: String },
    /// A value the study does not accept (the study's message).
    #[error("--vary {key}: the value {value} is not accepted: {message}")]
    Value { key: String, value: f64, message: String },
    #[error("{0}")]
    Design(String),
    #[error(transparent)]
    Study(#[from] StudyError),
    #[error("{}: {message}", path.display())]
    File { path: PathBuf, message: String },
}

/// A study and the samples to run it at.
#[derive(Clone, Debug)]
pub struct ParamStudy {
    /// The study as a table, without any sample's values.
    pub base: toml::Table,
    /// Names the study in errors and anchors its relative paths (as a study file's path).
    pub path: PathBuf,
    pub keys: Vec<KeyPath>,
    pub kinds: Vec<NumberKind>,
    /// One row per sample, one value per key (integer keys already rounded).
    pub samples: Vec<Vec<f64>>,
    pub method: String,
}

/// One force level of one sample, summarised.
#[derive(Clone, Debug, PartialEq)]
pub struct SummaryRow {
    pub level_n: f64,
    /// Frequency of the point of largest first-harmonic amplitude (Hz).
    pub peak_frequency_hz: f64,
    /// That amplitude |X₁| of the summarised output (m).
    pub peak_amplitude_m: f64,
    /// Energy dissipated per cycle by all joints at that point (J).
    pub peak_energy_j: f64,
    pub points: usize,
    /// Did the branch cross the whole band?
    pub complete: bool,
    /// Why the branch ended, in words.
    pub ending: String,
}

/// The result of one sample: its summary rows (one per level), or the error that stopped it.
#[derive(Clone, Debug, PartialEq)]
pub struct SampleOutcome {
    pub index: usize,
    pub values: Vec<f64>,
    pub rows: Vec<SummaryRow>,
    /// The full curves, when asked for.
    pub levels: Option<Vec<LevelResult>>,
    pub error: Option<String>,
}

impl ParamStudy {
    /// Read a study file and set up its samples.
    pub fn load(
        path: impl AsRef<Path>,
        varies: &[Vary],
        samples: Option<usize>,
        seed: u64,
    ) -> Result<Self, ParamError> {
        let path = path.as_ref();
        let text = std::fs::read_to_string(path).map_err(|e| ParamError::File {
            path: path.to_path_buf(),
            message: format!("cannot read the file: {e}"),
        })?;
        // The file is validated as a file first, so that its errors carry line and column.
        Study::parse(&text, path)?;
        let base: toml::Table = toml::from_str(&text).expect("a study that validates is a TOML table");
        ParamStudy::new(base, path, varies, samples, seed)
    }

    /// Check the study and the varied keys, and draw the samples: every key must exist (or be
    /// a key of a section the study has) and hold a number, and the extreme values of every
    /// key must be accepted by the study's validation.
    pub fn new(
        base: toml::Table,
        path: impl AsRef<Path>,
        varies: &[Vary],
        samples: Option<usize>,
        seed: u64,
    ) -> Result<Self, ParamError> {
        let path = path.as_ref().to_path_buf();
        Study::from_table(&base, &path)?;
        let mut keys = Vec::new();
        let mut kinds = Vec::new();
        for v in varies {
            let key = KeyPath::parse(&v.key)?;
            if keys.contains(&key) {
                return Err(ParamError::Key { key: v.key.clone(), message: "is varied twice".into() });
            }
            let kind = key.kind(&base)?;
            for x in v.extremes() {
                let mut table = base.clone();
                key.set(&mut table, x, kind)?;
                if let Err(e) = Study::from_table(&table, &path) {
                    return Err(ParamError::Value { key: v.key.clone(), value: x, message: e.kind.to_string() });
                }
            }
            keys.push(key);
            kinds.push(kind);
        }
        let d = design(varies, samples, seed)?;
        let samples = d
            .samples
            .into_iter()
            .map(|row| {
                row.into_iter()
                    .zip(&kinds)
                    .map(|(x, k)| if *k == NumberKind::Integer { x.round() } else { x })
                    .collect()
            })
            .collect();
        Ok(ParamStudy { base, path, keys, kinds, samples, method: d.method })
    }

    /// A study run at samples given value by value (a design made elsewhere): the keys are
    /// checked as in [`ParamStudy::new`]; a sample whose values the study refuses is recorded
    /// as failed when it runs, with the study's message, and the others go on.
    pub fn with_samples(
        base: toml::Table,
        path: impl AsRef<Path>,
        keys: &[String],
        samples: Vec<Vec<f64>>,
    ) -> Result<Self, ParamError> {
        let path = path.as_ref().to_path_buf();
        Study::from_table(&base, &path)?;
        let mut parsed = Vec::new();
        let mut kinds = Vec::new();
        for k in keys {
            let key = KeyPath::parse(k)?;
            if parsed.contains(&key) {
                return Err(ParamError::Key { key: k.clone(), message: "is varied twice".into() });
            }
            kinds.push(key.kind(&base)?);
            parsed.push(key);
        }
        if let Some((i, row)) = samples.iter().enumerate().find(|(_, r)| r.len() != keys.len()) {
            return Err(ParamError::Design(format!(
                "sample {i} has {} value(s), expected {} (one per key)",
                row.len(),
                keys.len()
            )));
        }
        Ok(ParamStudy { base, path, keys: parsed, kinds, samples, method: "given samples".into() })
    }

    /// An identifier of the study without its samples' values (its table, written out, and
    /// the folder its relative paths resolve against): finished samples stored under another
    /// identifier belong to another study and are never mixed with this one's.
    pub fn study_id(&self) -> String {
        let text = toml::to_string(&self.base).expect("a table writes as TOML");
        let folder = self.path.parent().map(|p| p.display().to_string()).unwrap_or_default();
        format!("{:016x}", fnv1a(format!("{folder}\n{text}").as_bytes()))
    }

    /// An identifier of sample `values` of this study: the study's identifier, the keys and
    /// the values' bits.
    pub fn sample_id(&self, values: &[f64]) -> String {
        let mut text = self.study_id();
        for (k, v) in self.keys.iter().zip(values) {
            text.push_str(&format!("\n{k}={:016x}", v.to_bits()));
        }
        format!("{:016x}", fnv1a(text.as_bytes()))
    }

    /// The table of the study with `values` written at the varied keys.
    pub fn sample_table(&self, values: &[f64]) -> Result<toml::Table, ParamError> {
        let mut table = self.base.clone();
        for ((key, kind), x) in self.keys.iter().zip(&self.kinds).zip(values) {
            key.set(&mut table, *x, *kind)?;
        }
        Ok(table)
    }

    /// Run sample `index`, building its model from scratch. A failure (a value the study
    /// refuses, a solver error) is recorded in the outcome, never returned: the other samples
    /// go on.
    pub fn run_sample(&self, index: usize, output: Option<&str>, curves: bool) -> SampleOutcome {
        SampleRunner::new(self).run(index, output, curves)
    }
}

/// Runs samples of a study one after the other and keeps the last linear model it built (the
/// model as given or its reduction, [`LinearBase`]) for the next samples that share it.
///
/// Building a meshed model and its reduction costs far more than the sweeps of a sample
/// (Harmony: ~20 s against ~2 s). A sample shares the base of the previous one when their
/// [`LinearPart`](crate::study::LinearPart)s are equal: the varied keys are outside `[model]`, `[reduction]`, a damping
/// matrix (`damping.matrix`, `model.damping_file`) and, with `method = "enriched"`, the
/// placement and the replaced stiffness of the joints it releases. So joint thresholds, slip
/// forces, friction, a joint's own stiffness, Rayleigh `damping.alpha`/`beta`, modal ratios,
/// load scales, excitation levels, outputs, sweep, harmonic balance and continuation settings
/// all reuse it; the outcome is the same as [`ParamStudy::run_sample`]'s, number for number.
pub struct SampleRunner<'a> {
    study: &'a ParamStudy,
    base: Option<LinearBase>,
    /// Number of linear bases built so far (one per change of the linear part).
    pub builds: usize,
}

impl<'a> SampleRunner<'a> {
    pub fn new(study: &'a ParamStudy) -> Self {
        SampleRunner { study, base: None, builds: 0 }
    }

    /// A runner that starts from a base kept from an earlier runner of the same study (a
    /// worker's next batch); it is used only if the samples share it.
    pub fn with_base(study: &'a ParamStudy, base: Option<LinearBase>) -> Self {
        SampleRunner { study, base, builds: 0 }
    }

    /// The base built or kept last, for a later runner of the same study.
    pub fn into_base(self) -> Option<LinearBase> {
        self.base
    }

    /// Run sample `index`; a failure is recorded in the outcome (as `run_sample`).
    pub fn run(&mut self, index: usize, output: Option<&str>, curves: bool) -> SampleOutcome {
        let values = self.study.samples[index].clone();
        let mut outcome = SampleOutcome { index, values, rows: Vec::new(), levels: None, error: None };
        let result = self.study.sample_table(&outcome.values).and_then(|t| self.run_table(&t, output, curves));
        match result {
            Ok((rows, levels)) => {
                outcome.rows = rows;
                outcome.levels = levels;
            }
            Err(e) => outcome.error = Some(e.to_string()),
        }
        outcome
    }

    /// Build and run the study of `table` at every level, summarised.
    fn run_table(
        &mut self,
        table: &toml::Table,
        output: Option<&str>,
        curves: bool,
    ) -> Result<(Vec<SummaryRow>, Option<Vec<LevelResult>>), ParamError> {
        let study = Study::from_table(table, &self.study.path)?;
        let part = study.linear_part();
        if self.base.as_ref().is_none_or(|b| *b.part() != part) {
            // Dropped first: two bases of a large model need not be held at once.
            self.base = None;
            self.base = Some(study.build_linear_base(&mut Vec::new())?);
            self.builds += 1;
        }
        let base = self.base.as_ref().expect("built above");
        let (model, excitation, outputs) = study.build_model_on(base)?;
        let which = match output {
            None => 0,
            Some(name) => outputs.iter().position(|o| o.name == name).ok_or_else(|| {
                let names: Vec<&str> = outputs.iter().map(|o| o.name.as_str()).collect();
                ParamError::Design(format!("no output named {name:?} to summarise (outputs: {})", names.join(", ")))
            })?,
        };
        let mut rows = Vec::new();
        let mut levels = Vec::new();
        let sweeper = LevelSweeper::new(&study, &model, &excitation, &outputs)
            .map_err(|e| ParamError::Design(format!("setting up the harmonic balance: {e}")))?;
        for &level in &excitation.levels_n {
            let run = sweeper
                .run(level, &mut |_: &_, _: f64| {})
                .map_err(|e| ParamError::Design(format!("level {level} N: {e}")))?;
            rows.push(summarise(&run.result, which, run.is_complete(), run.ending()));
            if curves {
                levels.push(run.result);
            }
        }
        Ok((rows, curves.then_some(levels)))
    }
}

/// The peak of output `which`'s first harmonic over a level's points.
pub fn summarise(level: &LevelResult, which: usize, complete: bool, ending: String) -> SummaryRow {
    let amplitude = |p: &crate::output::PointRecord| p.outputs.get(which).map_or(f64::NAN, |o| o.harmonics[1].0);
    let peak =
        level.points.iter().max_by(|a, b| amplitude(a).partial_cmp(&amplitude(b)).unwrap_or(std::cmp::Ordering::Equal));
    SummaryRow {
        level_n: level.level_n,
        peak_frequency_hz: peak.map_or(f64::NAN, |p| p.frequency_hz),
        peak_amplitude_m: peak.map_or(f64::NAN, amplitude),
        peak_energy_j: peak.map_or(f64::NAN, |p| p.elements.iter().map(|e| e.energy_j).sum()),
        points: level.points.len(),
        complete,
        ending,
    }
}

/// 64-bit FNV-1a: a stable hash (the same on every machine and version, unlike the standard
/// library's) to name studies and samples; collisions are not a security concern here.
fn fnv1a(bytes: &[u8]) -> u64 {
    bytes.iter().fold(0xcbf2_9ce4_8422_2325, |h, b| (h ^ *b as u64).wrapping_mul(0x0000_0100_0000_01b3))
}
