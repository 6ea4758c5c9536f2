//! The study file (TOML): what to compute, on which model, and what to write.
//!
//! [`Study::load`] parses and validates the file into plain structs ([`Study`], [`SweepSettings`],
//! [`HbmSettings`], ...); [`Study::build_model`] reads the matrices it refers to and builds the
//! [`NonlinearModel`] (paper Eq. 12), the excitation and the output selectors. Every key, unit and
//! default is documented in `docs/study-file.md`.
//!
//! Every error names the file, the line and column, the section and key, and what is expected,
//! e.g. `study.toml:12:13: [[joint]] "blade1": threshold must be > 0 N, got -3`.

mod build;
mod raw;
mod validate;

use std::fmt;
use std::path::{Path, PathBuf};

use faer::Mat;

pub use build::{Excitation, OutputSpec};
pub use stickslip_core::model::NonlinearModel;

/// A validated study.
#[derive(Clone, Debug)]
pub struct Study {
    /// The study file; relative paths inside it resolve against its folder.
    pub path: PathBuf,
    pub model: ModelSpec,
    /// Reduction of the model before the nonlinear analysis (paper Section 3.3); `None` keeps
    /// the model as it is.
    pub reduction: Option<ReductionSpec>,
    pub damping: DampingSpec,
    pub loads: Vec<LoadSpec>,
    pub joints: Vec<JointSpec>,
    pub excitation: ExcitationSpec,
    pub sweep: SweepSettings,
    pub hbm: HbmSettings,
    pub continuation: ContinuationSettings,
    /// Requested outputs; empty means "every DOF of the model" (allowed for small models only).
    pub outputs: Vec<OutputSelector>,
    pub output_options: OutputOptions,
}

/// Line and column (both from 1) of a key in the study file.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Location {
    pub line: usize,
    pub column: usize,
}

/// Where the linear model comes from.
#[derive(Clone, Debug)]
pub enum ModelSpec {
    /// Small matrices written in the study file (kg, N/m), with their DOF names.
    Inline { dofs: Vec<String>, mass: Mat<f64>, stiffness: Mat<f64>, at: ModelLocations },
    /// Matrix Market files (paths already resolved against the study folder) and optional DOF
    /// names (a `dof_file` or an inline `dofs` list; otherwise the DOFs are named "1", "2", ...).
    Files { mass: PathBuf, stiffness: PathBuf, dofs: DofNames, at: ModelLocations },
    /// A finite element mesh (Abaqus/CalculiX `.inp` or Gmsh `.msh`) assembled by
    /// `stickslip-fe`; its DOFs are named `node.direction`. `material` is assigned to every
    /// solid (required for `.msh`, which carries no material).
    Mesh { path: PathBuf, material: Option<MaterialSpec>, at: ModelLocations },
}

/// Isotropic elastic material: Young's modulus (Pa), Poisson's ratio, density (kg/m³).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MaterialSpec {
    pub young: f64,
    pub poisson: f64,
    pub density: f64,
}

/// Reduction basis (paper Section 3.3).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ReductionMethod {
    /// Constraint modes + fixed-interface modes (Craig-Bampton, Eqs. 3-4).
    CraigBampton,
    /// Constraint modes + free modes cleaned on the retained DOFs (the paper's, Eq. 5).
    FreeModes,
    /// The free-mode basis enriched with `release_modes` modes of the structure with the
    /// joints that replace stiffness released.
    Enriched { release_modes: usize },
}

/// `[reduction]`.
#[derive(Clone, Debug, PartialEq)]
pub struct ReductionSpec {
    pub method: ReductionMethod,
    /// Retained DOFs: node sets of the mesh (all DOFs of their nodes) or DOF names.
    pub retain: Vec<String>,
    /// Number of modes in the basis.
    pub modes: usize,
    pub at: Location,
}

/// Where the `[model]` section and its mass and stiffness keys are, for errors found when the
/// model is built.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ModelLocations {
    pub section: Location,
    pub mass: Location,
    pub stiffness: Location,
}

/// DOF names of a model read from files.
#[derive(Clone, Debug)]
pub enum DofNames {
    Numbered,
    Inline(Vec<String>),
    File(PathBuf),
}

/// Viscous damping of the linear model.
#[derive(Clone, Debug)]
pub enum DampingSpec {
    None,
    /// `D = α M + β K` (α in 1/s, β in s; the paper uses `D = α M`).
    Rayleigh {
        alpha: f64,
        beta: f64,
    },
    /// Modal damping ratios ζ_r (dimensionless), lowest mode first; the last applies to the rest.
    Modal {
        ratios: Vec<f64>,
    },
    /// An inline damping matrix (N·s/m).
    Matrix(Mat<f64>),
    /// A Matrix Market damping matrix (N·s/m).
    File(PathBuf),
}

/// A reference to the model's DOFs: where a load, a joint or an output acts.
#[derive(Clone, Debug, PartialEq)]
pub enum Placement {
    /// One DOF (for a joint: between this DOF and the ground).
    Dof(String),
    /// Between two DOFs: relative displacement `U_a − U_b`.
    Between(String, String),
    /// An explicit vector over the DOFs.
    Vector(Vec<f64>),
}

/// A named force pattern (N per unit excitation level).
#[derive(Clone, Debug)]
pub struct LoadSpec {
    pub name: String,
    pub placement: Placement,
    /// Multiplies the pattern (dimensionless).
    pub scale: f64,
    pub at: Location,
}

/// Stiffness of a hysteretic joint (Jenkins, Iwan).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum JointStiffness {
    /// Its own stiffness (N/m), in parallel with the linear model.
    Own(f64),
    /// Paper form (Eq. 11): this stiffness (N/m) is part of K and the joint replaces it.
    Replaces(f64),
    /// Paper form with `k = Vᵀ K V` (Eq. 7) computed from the model.
    ReplacesComputed,
}

/// The law of a joint and its parameters (SI).
#[derive(Clone, Debug, PartialEq)]
pub enum LawSpec {
    Jenkins { threshold: f64, stiffness: JointStiffness },
    Iwan { stiffness: JointStiffness, slip_force: f64, sliders: usize },
    Coulomb { threshold: f64, velocity_scale: f64 },
    Cubic { k3: f64 },
}

/// A joint: a nonlinear element on an application vector.
#[derive(Clone, Debug)]
pub struct JointSpec {
    pub name: String,
    pub law: LawSpec,
    pub placement: Placement,
    pub at: Location,
}

/// Which load excites the structure and at which levels.
#[derive(Clone, Debug)]
pub struct ExcitationSpec {
    /// Name of a `[[load]]`; `None` when there is exactly one load.
    pub load: Option<String>,
    /// Force levels (N): the load pattern is multiplied by each.
    pub levels: Vec<f64>,
    pub at: Location,
}

/// The frequency band, swept from `start_hz` to `end_hz` (down when `end_hz < start_hz`).
#[derive(Clone, Debug, PartialEq)]
pub struct SweepSettings {
    pub start_hz: f64,
    pub end_hz: f64,
    /// Initial frequency step (Hz, > 0); default `|end − start| / 100`.
    pub step_hz: f64,
}

impl SweepSettings {
    /// Is the sweep going down in frequency?
    pub fn is_downward(&self) -> bool {
        self.end_hz < self.start_hz
    }
}

/// Harmonic balance settings.
#[derive(Clone, Debug, PartialEq)]
pub struct HbmSettings {
    /// Number of harmonics N (default 7, as in the paper).
    pub harmonics: usize,
    /// Time samples per period n_t for the AFT (default 300, as in the paper).
    pub samples: usize,
    /// Newton convergence: residual relative to the excitation (default 1e-8).
    pub tolerance: f64,
    /// Newton iterations per point before the step is cut (default 20).
    pub max_iterations: usize,
}

impl Default for HbmSettings {
    fn default() -> Self {
        HbmSettings { harmonics: 7, samples: 300, tolerance: 1e-8, max_iterations: 20 }
    }
}

/// Predictor of the pseudo-arclength continuation.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Predictor {
    /// Secant through the last two points.
    Secant,
    /// Tangent from the Jacobian's null space.
    Tangent,
    /// Second-degree Lagrange extrapolation through the last three points (the paper's).
    Lagrange,
}

/// Continuation settings. Steps are measured as the frequency change of a step along a flat
/// branch (the arclength is scaled automatically, Eq. 31).
#[derive(Clone, Debug, PartialEq)]
pub struct ContinuationSettings {
    pub predictor: Predictor,
    /// Smallest step (Hz) before the continuation gives up; default `step_hz / 1000`.
    pub min_step_hz: f64,
    /// Largest step (Hz); default `10 step_hz`.
    pub max_step_hz: f64,
    /// Largest number of points per level (default 10000).
    pub max_points: usize,
}

/// A requested output: a DOF or a combination of DOFs.
#[derive(Clone, Debug)]
pub struct OutputSelector {
    pub name: String,
    pub placement: Placement,
    pub at: Location,
}

/// Which per-point time data to write.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TimeData {
    None,
    All,
    /// Every k-th converged point of each level (first point included).
    Every(usize),
}

impl TimeData {
    /// Is the time data of point `index` (from 0) of a level written?
    pub fn keeps(&self, index: usize) -> bool {
        match self {
            TimeData::None => false,
            TimeData::All => true,
            TimeData::Every(k) => index.is_multiple_of(*k),
        }
    }
}

/// Image format of the plots.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PlotFormat {
    Png,
    Svg,
}

impl PlotFormat {
    /// File extension, without the dot.
    pub fn extension(&self) -> &'static str {
        match self {
            PlotFormat::Png => "png",
            PlotFormat::Svg => "svg",
        }
    }
}

/// `[output_options]`.
#[derive(Clone, Debug, PartialEq)]
pub struct OutputOptions {
    /// Default: none.
    pub time_data: TimeData,
    /// Default: png.
    pub plot_format: PlotFormat,
}

impl Default for OutputOptions {
    fn default() -> Self {
        OutputOptions { time_data: TimeData::None, plot_format: PlotFormat::Png }
    }
}

/// A study file error: the file, where in it, and what is wrong.
#[derive(Debug, thiserror::Error)]
pub struct StudyError {
    pub file: PathBuf,
    pub location: Option<Location>,
    pub kind: Box<StudyErrorKind>,
}

/// What is wrong with a study file.
#[derive(Debug, thiserror::Error)]
pub enum StudyErrorKind {
    #[error("cannot read the file: {0}")]
    Io(#[from] std::io::Error),
    /// TOML syntax, unknown key, wrong type or missing key (the parser's message).
    #[error("{0}")]
    Syntax(String),
    /// A value that parses but is not acceptable.
    #[error("{0}")]
    Invalid(String),
    #[error("{context}: {source}")]
    MatrixFile {
        context: String,
        #[source]
        source: crate::matrix::MatrixFileError,
    },
    #[error("{context}: {source}")]
    Model {
        context: String,
        #[source]
        source: stickslip_core::model::ModelError,
    },
    #[error("{context}: {source}")]
    Mesh {
        context: String,
        #[source]
        source: stickslip_fe::mesh::MeshError,
    },
    #[error("{context}: {source}")]
    Assembly {
        context: String,
        #[source]
        source: stickslip_fe::assembly::AssemblyError,
    },
    #[error("{context}: {source}")]
    Reduction {
        context: String,
        #[source]
        source: stickslip_fe::reduction::ReductionError,
    },
    #[error("{context}: {source}")]
    Element {
        context: String,
        #[source]
        source: stickslip_core::elements::ElementError,
    },
}

impl fmt::Display for StudyError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}", self.file.display())?;
        if let Some(l) = self.location {
            write!(f, ":{}:{}", l.line, l.column)?;
        }
        write!(f, ": {}", self.kind)
    }
}

impl Study {
    /// Read, parse and validate a study file.
    pub fn load(path: impl AsRef<Path>) -> Result<Study, StudyError> {
        let path = path.as_ref();
        let text = std::fs::read_to_string(path).map_err(|e| StudyError {
            file: path.to_path_buf(),
            location: None,
            kind: Box::new(e.into()),
        })?;
        Study::parse(&text, path)
    }

    /// Parse and validate the text of a study file; `path` names it in errors and anchors its
    /// relative paths.
    pub fn parse(text: &str, path: impl AsRef<Path>) -> Result<Study, StudyError> {
        validate::parse(text, path.as_ref())
    }
}
