//! The study file as written: one serde struct per TOML section, every value wrapped in
//! [`Spanned`] so that validation errors can point at the line and column of the offending key.
//! Unknown keys are rejected everywhere (`deny_unknown_fields`): a misspelt option must never be
//! silently ignored.

use serde::Deserialize;
use toml::Spanned;

pub(crate) type S<T> = Spanned<T>;

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct RawStudy {
    pub model: S<RawModel>,
    pub reduction: Option<S<RawReduction>>,
    pub damping: Option<S<RawDamping>>,
    #[serde(default)]
    pub load: Vec<S<RawLoad>>,
    #[serde(default)]
    pub joint: Vec<S<RawJoint>>,
    #[serde(default)]
    pub patch: Vec<S<RawPatch>>,
    pub excitation: S<RawExcitation>,
    pub sweep: S<RawSweep>,
    pub harmonic_balance: Option<S<RawHarmonicBalance>>,
    pub continuation: Option<S<RawContinuation>>,
    #[serde(default)]
    pub output: Vec<S<RawOutput>>,
    pub output_options: Option<S<RawOutputOptions>>,
    #[serde(default)]
    pub snapshot: Vec<S<RawSnapshot>>,
    pub grid: Option<S<RawGrid>>,
    pub nonlinear_mode: Option<S<RawNonlinearMode>>,
}

/// A matrix written inline: a list of rows, or a list of diagonal values.
#[derive(Deserialize, Clone)]
#[serde(untagged)]
pub(crate) enum RawMatrix {
    Rows(Vec<Vec<f64>>),
    Diagonal(Vec<f64>),
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct RawModel {
    pub dofs: Option<S<Vec<String>>>,
    pub mass: Option<S<RawMatrix>>,
    pub stiffness: Option<S<RawMatrix>>,
    pub mass_file: Option<S<String>>,
    pub stiffness_file: Option<S<String>>,
    pub damping_file: Option<S<String>>,
    pub dof_file: Option<S<String>>,
    pub mesh: Option<S<String>>,
    pub material: Option<S<RawMaterial>>,
    pub fixed: Option<S<RawFixed>>,
    pub harmony: Option<S<RawHarmony>>,
}

/// `fixed = { SET = [directions] }`: node sets (physical groups of a `.msh`) → directions
/// fixed to zero.
pub(crate) type RawFixed = std::collections::BTreeMap<String, S<Vec<S<i64>>>>;

/// `[model.harmony]`: the generated Harmony-like assembly and the design values a study may
/// change (the others keep the calibrated defaults of `stickslip_fe::harmony::Design`).
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct RawHarmony {
    pub refinement: Option<S<f64>>,
    pub element: Option<S<String>>,
    pub diaphragm_thickness: Option<S<f64>>,
    pub blade_thickness: Option<S<f64>>,
    pub blade_length: Option<S<f64>>,
    pub envelope_height: Option<S<f64>>,
    pub base_radius: Option<S<f64>>,
    pub shaker_mass: Option<S<f64>>,
    pub shaker_spring: Option<S<f64>>,
    pub shaker_zone_radius: Option<S<f64>>,
    pub connector_stiffness: Option<S<f64>>,
    pub screw_zone_radius: Option<S<f64>>,
    pub screw_radii: Option<S<Vec<f64>>>,
    pub blade_rise: Option<S<f64>>,
    pub body_flange_radius: Option<S<f64>>,
    pub top_disk_thickness: Option<S<f64>>,
    pub tip_contact: Option<S<String>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct RawMaterial {
    pub young: S<f64>,
    pub poisson: S<f64>,
    pub density: S<f64>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct RawReduction {
    pub method: S<String>,
    pub retain: S<Vec<String>>,
    pub modes: Option<S<i64>>,
    pub modes_up_to_hz: Option<S<f64>>,
    pub release_modes: Option<S<i64>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct RawDamping {
    pub alpha: Option<S<f64>>,
    pub beta: Option<S<f64>>,
    pub modal_ratios: Option<S<Vec<f64>>>,
    pub matrix: Option<S<RawMatrix>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct RawLoad {
    pub name: S<String>,
    pub dof: Option<S<String>>,
    pub scale: Option<S<f64>>,
    pub values: Option<S<Vec<f64>>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct RawJoint {
    pub name: S<String>,
    pub law: S<String>,
    pub between: Option<S<Vec<String>>>,
    pub dof: Option<S<String>>,
    pub vector: Option<S<Vec<f64>>>,
    pub threshold: Option<S<f64>>,
    pub stiffness: Option<S<f64>>,
    pub replaces_stiffness: Option<S<bool>>,
    pub slip_force: Option<S<f64>>,
    pub sliders: Option<S<i64>>,
    pub velocity_scale: Option<S<f64>>,
    pub k3: Option<S<f64>>,
    pub tangential: Option<S<Vec<Vec<String>>>>,
    pub normal: Option<S<Vec<String>>>,
    pub preload: Option<S<f64>>,
    pub normal_stiffness: Option<S<f64>>,
    pub tangential_stiffness: Option<S<f64>>,
    pub friction: Option<S<f64>>,
}

/// `[[patch]]`: node-to-node contacts between two node sets of a mesh.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct RawPatch {
    pub name: S<String>,
    pub between: S<Vec<String>>,
    pub law: S<String>,
    pub friction: Option<S<f64>>,
    pub normal_stiffness_per_area: Option<S<f64>>,
    pub tangential_stiffness_per_area: Option<S<f64>>,
    pub pressure: Option<S<f64>>,
    pub preload_forces: Option<S<Vec<S<RawPreloadForce>>>>,
    pub normal: Option<S<Vec<f64>>>,
    pub tangential: Option<S<Vec<f64>>>,
}

/// `{ set = "BOLT", force = [fx, fy, fz] }`: a static force (N) spread over a node set.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct RawPreloadForce {
    pub set: S<String>,
    pub force: S<Vec<f64>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct RawExcitation {
    pub load: Option<S<String>>,
    pub levels: S<Vec<f64>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct RawSweep {
    pub start_hz: S<f64>,
    pub end_hz: S<f64>,
    pub step_hz: Option<S<f64>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct RawHarmonicBalance {
    pub harmonics: Option<S<i64>>,
    pub samples: Option<S<i64>>,
    pub tolerance: Option<S<f64>>,
    pub max_iterations: Option<S<i64>>,
    pub stability: Option<S<bool>>,
    pub contact_method: Option<S<String>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct RawContinuation {
    pub predictor: Option<S<String>>,
    pub min_step_hz: Option<S<f64>>,
    pub max_step_hz: Option<S<f64>>,
    pub max_points: Option<S<i64>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct RawOutput {
    pub name: S<String>,
    pub dof: Option<S<String>>,
    pub vector: Option<S<Vec<f64>>>,
}

/// `[[snapshot]]`: one periodic response at a fixed frequency and level.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct RawSnapshot {
    pub frequency_hz: S<f64>,
    pub level: S<f64>,
}

/// `[grid]`: frequencies solved one by one at every level.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct RawGrid {
    pub frequencies_hz: S<Vec<f64>>,
}

/// `time_data = "none" | "all"` or an integer k (every k-th point).
#[derive(Deserialize)]
#[serde(untagged)]
pub(crate) enum RawTimeData {
    Every(i64),
    Word(String),
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct RawOutputOptions {
    pub time_data: Option<S<RawTimeData>>,
    pub plot_format: Option<S<String>>,
}

/// `[nonlinear_mode]`: the backbone of one mode (extended periodic motion concept).
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct RawNonlinearMode {
    pub mode: S<i64>,
    pub amplitude_start: S<f64>,
    pub amplitude_end: S<f64>,
    pub outputs: Option<S<Vec<String>>>,
    pub max_points: Option<S<i64>>,
    pub negative_damping: Option<S<String>>,
}
