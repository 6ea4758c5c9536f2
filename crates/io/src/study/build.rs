//! From a validated [`Study`] to the objects the solver works on: the [`NonlinearModel`] of
//! paper Eq. 12, the [`Excitation`] and the [`OutputSpec`]s.

use std::path::Path;

use faer::Side;
use stickslip_core::elements::{Contact, CubicSpring, Element, Iwan, Jenkins, RegularizedCoulomb};
use stickslip_core::model::{
    relative_direction, stiffness_along, Damping, DofLabel, ElementSite, LinearModel, Matrix, ModelError, NamedVector,
    NonlinearModel, RigidContact,
};
use stickslip_fe::assembly::FeModel;
use stickslip_fe::eigen::EigenOptions;
use stickslip_fe::mesh::Material;
use stickslip_fe::patch::{
    normal_forces, pair_sets, pair_vectors, spread_force, static_displacement, with_springs, ContactPair, Spring,
};
use stickslip_fe::reduction::{self, Reduction, ReductionOptions, Release};

use super::*;

/// The harmonic force `levels_n[i] · pattern · cos(Ωt)` (paper Eq. 12), one run per level.
#[derive(Clone, Debug)]
pub struct Excitation {
    /// Name of the load.
    pub load: String,
    /// Force pattern over the model's DOFs, in N per unit level (scale included).
    pub pattern: Vec<f64>,
    /// Force levels (N).
    pub levels_n: Vec<f64>,
}

/// A reported output: the displacement `vectorᵀ U` (m), named by the user.
#[derive(Clone, Debug)]
pub struct OutputSpec {
    pub name: String,
    pub vector: Vec<f64>,
}

/// Largest model for which outputs default to every DOF when no `[[output]]` is given.
const MAX_DEFAULT_OUTPUTS: usize = 20;

/// What a study's linear base depends on: the model, the reduction, a damping matrix and,
/// for the enriched reduction, the joints it releases (name, placement, replaced stiffness).
/// Everything else — joint laws and thresholds, a joint's own stiffness, Rayleigh or modal
/// damping, loads, excitation levels, outputs, sweep, harmonic balance and continuation
/// settings — is applied on top of the base.
#[derive(Clone, Debug, PartialEq)]
pub struct LinearPart {
    model: ModelSpec,
    reduction: Option<ReductionSpec>,
    damping_matrix: Option<DampingSpec>,
    releases: Vec<(String, Placement, JointStiffness)>,
    /// Patches are paired, preloaded and retained by the reduction on the full mesh.
    patches: Vec<PatchSpec>,
}

/// The linear model the nonlinear analysis runs on (the model as given, or its reduction),
/// before loads, joints and outputs are put on it, with the full model's DOF names (which
/// loads, joints and outputs name) and the reduction that projects their vectors.
#[derive(Clone, Debug)]
pub struct LinearBase {
    full_dofs: Vec<DofLabel>,
    linear: LinearModel,
    reduction: Option<Reduction>,
    model_at: ModelLocations,
    part: LinearPart,
    patches: Vec<BuiltPatch>,
}

/// A `[[patch]]` paired on the mesh: its contacts' parameters and directions.
#[derive(Clone, Debug)]
struct BuiltPatch {
    name: String,
    tangential_directions: usize,
    friction: f64,
    pairs: Vec<BuiltPair>,
    at: Location,
}

/// One contact of a patch.
#[derive(Clone, Debug)]
struct BuiltPair {
    /// Id of the pair's node in the first set (names the element).
    node: u64,
    normal_stiffness: f64,
    tangential_stiffness: f64,
    /// Normal load at rest (N).
    preload: f64,
    /// Tangential directions then the normal: `(U_a − U_b)·d` as sparse vectors over the full
    /// model's DOFs.
    directions: Vec<Vec<(usize, f64)>>,
    /// `contact2d`: the second tangential direction, held by a linear spring of the tangential
    /// stiffness (the contact slides along its one tangential direction only).
    held: Option<Vec<(usize, f64)>>,
}

impl BuiltPair {
    /// Stiffness of the contact along its direction `i` (tangential ones first, then normal).
    fn stiffness(&self, i: usize) -> f64 {
        if i + 1 < self.directions.len() {
            self.tangential_stiffness
        } else {
            self.normal_stiffness
        }
    }
}

/// Most contact pairs of all patches together: each is a 3-direction element of the condensed
/// balance, whose dense Jacobian grows with the square of their number.
const MAX_PATCH_PAIRS: usize = 5000;

impl LinearBase {
    /// The study inputs the base was built from.
    pub fn part(&self) -> &LinearPart {
        &self.part
    }

    /// Number of DOFs of the analysed (possibly reduced) model.
    pub fn n_dofs(&self) -> usize {
        self.linear.n_dofs()
    }
}

impl Study {
    /// Read the matrix files (if any), check the model (sizes, symmetry, M positive definite by
    /// a Cholesky factorisation) and build the nonlinear model, the excitation and the outputs.
    pub fn build_model(&self) -> Result<(NonlinearModel, Excitation, Vec<OutputSpec>), StudyError> {
        self.build_model_timed(&mut Vec::new())
    }

    /// The mesh of a model that stickslip generates (`[model.harmony]`), for writing it as
    /// `.inp` and `.msh`; `None` for models read from files or given inline.
    pub fn generated_mesh(&self) -> Result<Option<stickslip_fe::mesh::Mesh>, StudyError> {
        match &self.model {
            ModelSpec::Harmony { design, at } => {
                design.build(stickslip_fe::harmony::Configuration::Assembly).map(Some).map_err(|source| {
                    self.error(Some(at.section), StudyErrorKind::Invalid(format!("[model.harmony]: {source}")))
                })
            }
            _ => Ok(None),
        }
    }

    /// As [`Study::build_model`], recording the time of each stage (name, seconds): mesh,
    /// assembly, modes and reduction, as far as the study has them.
    pub fn build_model_timed(
        &self,
        timings: &mut Vec<(String, f64)>,
    ) -> Result<(NonlinearModel, Excitation, Vec<OutputSpec>), StudyError> {
        let base = self.build_linear_base(timings)?;
        self.build_model_on(&base)
    }

    /// What of this study its linear base depends on: studies with equal parts can share one
    /// [`LinearBase`] (see [`Study::build_model_on`]).
    pub fn linear_part(&self) -> LinearPart {
        let enriched = matches!(&self.reduction, Some(r) if matches!(r.method, ReductionMethod::Enriched { .. }));
        // The enriched basis has the modes of the structure with the joints that replace
        // stiffness released: their directions and the stiffness they remove shape it.
        let releases = if enriched {
            self.joints
                .iter()
                .filter_map(|j| match &j.law {
                    LawSpec::Jenkins { stiffness, .. } | LawSpec::Iwan { stiffness, .. } => match stiffness {
                        JointStiffness::Own(_) => None,
                        s => Some((j.name.clone(), j.placement.clone(), *s)),
                    },
                    _ => None,
                })
                .collect()
        } else {
            Vec::new()
        };
        LinearPart {
            model: self.model.clone(),
            reduction: self.reduction.clone(),
            // Rayleigh and modal damping are descriptions that a reduction carries over
            // unchanged (Tᵀ(αM + βK)T = αM_r + βK_r; modal ratios apply to the reduced model's
            // modes): they are set on the base when it is used. A damping matrix is projected
            // by the reduction, so it belongs to the base.
            damping_matrix: match &self.damping {
                d @ (DampingSpec::Matrix(_) | DampingSpec::File(_)) => Some(d.clone()),
                _ => None,
            },
            releases,
            patches: self.patches.clone(),
        }
    }

    /// The linear model the nonlinear analysis runs on, before loads, joints and outputs:
    /// the model as given or its reduction (mesh, assembly, modes and reduction are timed in
    /// `timings`).
    pub fn build_linear_base(&self, timings: &mut Vec<(String, f64)>) -> Result<LinearBase, StudyError> {
        let err = |at: Location, kind: StudyErrorKind| self.error(Some(at), kind);
        let (mut full, model_at) = self.full_model(timings)?;
        // Reduction (Section 3.3): the nonlinear analysis runs on the reduced model; loads,
        // joints and outputs name DOFs of the full model and are projected (Eqs. 7-8:
        // u = Vᵀ U = (Tᵀ V)ᵀ q).
        let full_dofs = full.linear().dofs.clone();
        self.check_placements(&full_dofs)?;
        let started = std::time::Instant::now();
        let (patches, patch_dofs) = self.contact_patches(full.fe_mut())?;
        if !patches.is_empty() {
            timings.push(("contact patches".into(), started.elapsed().as_secs_f64()));
        }
        let (linear, reduction) = match &self.reduction {
            None => (full.into_linear(), None),
            Some(r) => {
                let releases = self.releases(full.linear())?;
                let started = std::time::Instant::now();
                let red = reduce(&full, r, &releases, &patch_dofs).map_err(|k| err(r.at, k))?;
                timings.push(("modes and reduction".into(), started.elapsed().as_secs_f64()));
                stickslip_fe::memory::stage("modes and reduction");
                timings.extend(red.stages.iter().map(|(stage, secs)| (format!("  {stage}"), *secs)));
                (red.model.clone(), Some(red))
            }
        };
        Ok(LinearBase { full_dofs, linear, reduction, model_at, part: self.linear_part(), patches })
    }

    /// Every DOF that a load, joint or output names exists in the full model, and every vector
    /// has its size: checked before the modes and the reduction, which take minutes at the
    /// paper's size, so that a misspelt DOF is reported at once (the same error as later).
    fn check_placements(&self, full_dofs: &[DofLabel]) -> Result<(), StudyError> {
        let space = DofSpace { dofs: full_dofs, reduction: None };
        let placements = (self.loads.iter().map(|l| (&l.placement, format!("[[load]] {:?}", l.name), l.at)))
            .chain(self.joints.iter().map(|j| (&j.placement, format!("[[joint]] {:?}", j.name), j.at)))
            .chain(self.outputs.iter().map(|o| (&o.placement, format!("[[output]] {:?}", o.name), o.at)));
        for (placement, ctx, at) in placements {
            full_vector(&space, placement, &ctx).map_err(|kind| self.error(Some(at), kind))?;
        }
        Ok(())
    }

    /// The nonlinear model, excitation and outputs of this study on a linear base built by a
    /// study with the same [`LinearPart`] (this one or another sample of a parameter study):
    /// the same result as [`Study::build_model`], without rebuilding the linear model.
    ///
    /// # Panics
    /// If `base` was built from a study with another linear part (a misuse: compare
    /// [`Study::linear_part`] with [`LinearBase::part`] first).
    pub fn build_model_on(
        &self,
        base: &LinearBase,
    ) -> Result<(NonlinearModel, Excitation, Vec<OutputSpec>), StudyError> {
        assert!(
            base.part == self.linear_part(),
            "expected a linear base built from the same model, reduction and damping matrix"
        );
        let err = |at: Location, kind: StudyErrorKind| self.error(Some(at), kind);
        let model_error = |source: ModelError| StudyErrorKind::Model { context: "[model]".into(), source };
        let model_at = base.model_at;
        let mut linear = base.linear.clone();
        match &self.damping {
            DampingSpec::None => linear.damping = Damping::None,
            DampingSpec::Rayleigh { alpha, beta } => linear.damping = Damping::Rayleigh { alpha: *alpha, beta: *beta },
            DampingSpec::Modal { ratios } => linear.damping = Damping::Modal { ratios: ratios.clone() },
            // Part of the base (equal by the assertion above).
            DampingSpec::Matrix(_) | DampingSpec::File(_) => {}
        }
        let space = DofSpace { dofs: &base.full_dofs, reduction: base.reduction.as_ref() };

        for l in &self.loads {
            let ctx = format!("[[load]] {:?}", l.name);
            let v = vector(&space, &l.placement, &ctx).map_err(|k| err(l.at, k))?;
            linear.loads.push(NamedVector { name: l.name.clone(), values: v.iter().map(|x| x * l.scale).collect() });
        }

        let mut sites = Vec::with_capacity(self.joints.len());
        let mut rigid = Vec::new();
        let mut replaced = Vec::new();
        for j in &self.joints {
            match self.joint_site(&linear, &space, j).map_err(|k| err(j.at, k))? {
                BuiltJoint::Element(site, replaced_k) => {
                    if let Some(k) = replaced_k {
                        replaced.push((j, k, site.directions[0].clone()));
                    }
                    sites.push(site);
                }
                BuiltJoint::Rigid(contact) => rigid.push(contact),
            }
        }
        check_slipped_stiffness(&linear, &replaced).map_err(|(at, m)| err(at, StudyErrorKind::Invalid(m)))?;
        for p in &base.patches {
            patch_sites(p, &space, &mut sites).map_err(|k| err(p.at, k))?;
        }

        let load_name = match &self.excitation.load {
            Some(name) => name.clone(),
            None => self.loads[0].name.clone(),
        };
        let pattern = linear.load(&load_name).map_err(|e| err(self.excitation.at, model_error(e)))?.values.clone();
        let excitation = Excitation { load: load_name, pattern, levels_n: self.excitation.levels.clone() };

        let outputs = if self.outputs.is_empty() {
            if linear.n_dofs() > MAX_DEFAULT_OUTPUTS {
                return Err(self.error(
                    None,
                    StudyErrorKind::Invalid(format!(
                        "[[output]]: the model has {} DOFs; say which to report with [[output]] sections (every DOF is reported by default only up to {MAX_DEFAULT_OUTPUTS})",
                        linear.n_dofs()
                    )),
                ));
            }
            (0..linear.n_dofs())
                .map(|i| OutputSpec {
                    name: sanitized(&linear.dofs[i].name),
                    vector: relative_direction(linear.n_dofs(), i, None),
                })
                .collect()
        } else {
            let mut outs = Vec::with_capacity(self.outputs.len());
            for o in &self.outputs {
                let ctx = format!("[[output]] {:?}", o.name);
                let v = vector(&space, &o.placement, &ctx).map_err(|k| err(o.at, k))?;
                outs.push(OutputSpec { name: o.name.clone(), vector: v });
            }
            outs
        };

        // Validation keeps rigid contacts (contact_method = "dlft") apart from every element.
        let model = if rigid.is_empty() {
            NonlinearModel::new(linear, sites)
        } else {
            debug_assert!(sites.is_empty(), "rigid contacts come without elements");
            NonlinearModel::with_rigid_contacts(linear, rigid)
        }
        .map_err(|e| err(model_at.section, model_error(e)))?;
        Ok((model, excitation, outputs))
    }

    fn error(&self, location: Option<Location>, kind: StudyErrorKind) -> StudyError {
        StudyError { file: self.path.clone(), location, kind: Box::new(kind) }
    }

    /// The model as given (before any reduction), checked: M positive definite; inline and
    /// file models also for sizes and symmetry (assembled meshes are symmetric by construction).
    fn full_model(&self, timings: &mut Vec<(String, f64)>) -> Result<(FullModel, ModelLocations), StudyError> {
        let err = |at: Location, kind: StudyErrorKind| self.error(Some(at), kind);
        let model_error = |source: ModelError| StudyErrorKind::Model { context: "[model]".into(), source };
        let damping = |at: Location| -> Result<Damping, StudyError> {
            Ok(match &self.damping {
                DampingSpec::None => Damping::None,
                DampingSpec::Rayleigh { alpha, beta } => Damping::Rayleigh { alpha: *alpha, beta: *beta },
                DampingSpec::Modal { ratios } => Damping::Modal { ratios: ratios.clone() },
                DampingSpec::Matrix(d) => Damping::Matrix(Matrix::Dense(d.clone())),
                DampingSpec::File(path) => {
                    Damping::Matrix(read_matrix(path, "[model] damping_file").map_err(|k| err(at, k))?)
                }
            })
        };
        let (mass, stiffness, dofs, at) = match &self.model {
            ModelSpec::Inline { dofs, mass, stiffness, at } => (
                Matrix::Dense(mass.clone()),
                Matrix::Dense(stiffness.clone()),
                dofs.iter().map(|d| dof_label(d)).collect::<Vec<_>>(),
                *at,
            ),
            ModelSpec::Files { mass, stiffness, dofs, at } => {
                let m = read_matrix(mass, "[model] mass_file").map_err(|k| err(at.mass, k))?;
                let k = read_matrix(stiffness, "[model] stiffness_file").map_err(|k| err(at.stiffness, k))?;
                let labels = match dofs {
                    DofNames::Numbered => (1..=m.nrows()).map(|i| DofLabel::named(i.to_string())).collect(),
                    DofNames::Inline(names) => names.iter().map(|d| dof_label(d)).collect(),
                    DofNames::File(path) => read_dof_file(path).map_err(|k| err(at.section, k))?,
                };
                (m, k, labels, *at)
            }
            ModelSpec::Harmony { design, at } => {
                let started = std::time::Instant::now();
                let mesh = design
                    .build(stickslip_fe::harmony::Configuration::Assembly)
                    .map_err(|source| err(at.section, StudyErrorKind::Invalid(format!("[model.harmony]: {source}"))))?;
                timings.push(("mesh".into(), started.elapsed().as_secs_f64()));
                stickslip_fe::memory::stage("mesh");
                let started = std::time::Instant::now();
                let mut fe = FeModel::assemble(mesh).map_err(|source| {
                    err(at.section, StudyErrorKind::Assembly { context: "[model.harmony]".into(), source })
                })?;
                timings.push(("assembly".into(), started.elapsed().as_secs_f64()));
                fe.model.damping = damping(at.section)?;
                return Ok((FullModel::Mesh(fe), *at));
            }
            ModelSpec::Mesh { path, material, fixed, at } => {
                let started = std::time::Instant::now();
                let mut fe = read_mesh(path, material.as_ref(), fixed).map_err(|k| err(at.mass, k))?;
                timings.push(("mesh reading and assembly".into(), started.elapsed().as_secs_f64()));
                fe.model.damping = damping(at.section)?;
                check_mass_positive_definite(&fe.model.mass).map_err(|e| err(at.mass, model_error(e)))?;
                return Ok((FullModel::Mesh(fe), *at));
            }
        };
        // Point at the matrix a model error is about.
        let error_at = |e: &ModelError| match e {
            ModelError::MassNotPositiveDefinite => at.mass,
            ModelError::WrongSize { what, .. }
            | ModelError::NotSymmetric { what, .. }
            | ModelError::NotFinite { what }
                if what.starts_with('M') =>
            {
                at.mass
            }
            ModelError::WrongSize { what, .. }
            | ModelError::NotSymmetric { what, .. }
            | ModelError::NotFinite { what }
                if what.starts_with('K') =>
            {
                at.stiffness
            }
            _ => at.section,
        };
        let linear = LinearModel::new(mass, stiffness, damping(at.section)?, dofs, Vec::new())
            .map_err(|e| err(error_at(&e), model_error(e)))?;
        check_mass_positive_definite(&linear.mass).map_err(|e| err(error_at(&e), model_error(e)))?;
        Ok((FullModel::Matrices(linear), at))
    }

    /// The `[[patch]]`es paired on the mesh, with their contacts' stiffnesses, preloads and
    /// directions, and the DOFs of their node sets (which a reduction keeps). The contacts'
    /// stiffnesses, closed and stuck, are added to the model's K (the paper form, Eq. 11: each
    /// contact element replaces its own), so that the linear model holds the assembled structure
    /// (a part held by the contacts alone is not free in it) and a reduction's modes are those
    /// of the joint stuck.
    fn contact_patches(&self, fe: Option<&mut FeModel>) -> Result<(Vec<BuiltPatch>, Vec<usize>), StudyError> {
        let Some(first) = self.patches.first() else { return Ok((Vec::new(), Vec::new())) };
        let Some(fe) = fe else {
            return Err(self.error(
                Some(first.at),
                StudyErrorKind::Invalid(format!("[[patch]] {:?}: a patch pairs node sets of a mesh model", first.name)),
            ));
        };
        let patch_error = |spec: &PatchSpec, source| {
            self.error(Some(spec.at), StudyErrorKind::Patch { context: format!("[[patch]] {:?}", spec.name), source })
        };
        let (mut built, mut retained, mut n_pairs) = (Vec::new(), Vec::new(), 0);
        for spec in &self.patches {
            let patch = pair_sets(&fe.mesh, &spec.sets[0], &spec.sets[1], spec.normal, spec.tangential)
                .map_err(|e| patch_error(spec, e))?;
            n_pairs += patch.pairs.len();
            if n_pairs > MAX_PATCH_PAIRS {
                return Err(self.error(
                    Some(spec.at),
                    StudyErrorKind::Invalid(format!(
                        "[[patch]] {:?}: the patches have {n_pairs} contact pairs or more; at most {MAX_PATCH_PAIRS} are accepted (each is a contact element of the harmonic balance): mesh the interface coarser",
                        spec.name
                    )),
                ));
            }
            let names = ["t1", "t2"];
            let directions: Vec<([f64; 3], &str)> = (0..spec.tangential_directions)
                .map(|i| (patch.tangents[i], names[i]))
                .chain([(patch.normal, "normal")])
                .collect();
            let mut pairs = Vec::with_capacity(patch.pairs.len());
            for p in &patch.pairs {
                let held = if spec.tangential_directions == 1 {
                    let mut v = pair_vectors(fe, p, &[(patch.tangents[1], "t2")]).map_err(|e| patch_error(spec, e))?;
                    v.pop()
                } else {
                    None
                };
                pairs.push(BuiltPair {
                    held,
                    node: fe.mesh.nodes[p.a].id,
                    normal_stiffness: spec.normal_stiffness_per_area * p.area,
                    tangential_stiffness: spec.tangential_stiffness_per_area * p.area,
                    preload: match spec.preload {
                        PatchPreload::Pressure(pressure) => pressure * p.area,
                        // From the static pre-step below.
                        PatchPreload::Forces(_) => 0.0,
                    },
                    directions: pair_vectors(fe, p, &directions).map_err(|e| patch_error(spec, e))?,
                });
            }
            for set in &spec.sets {
                for d in fe.set_dofs(set).map_err(|source| {
                    self.error(
                        Some(spec.at),
                        StudyErrorKind::Assembly { context: format!("[[patch]] {:?}", spec.name), source },
                    )
                })? {
                    if !retained.contains(&d) {
                        retained.push(d);
                    }
                }
            }
            built.push((
                BuiltPatch {
                    name: spec.name.clone(),
                    tangential_directions: spec.tangential_directions,
                    friction: spec.friction,
                    pairs,
                    at: spec.at,
                },
                patch.pairs,
            ));
        }
        let closed = {
            let mut springs = Vec::new();
            for (patch, _) in &built {
                for pair in &patch.pairs {
                    for (i, v) in pair.directions.iter().enumerate() {
                        springs.push(Spring { stiffness: pair.stiffness(i), vector: v });
                    }
                    if let Some(v) = &pair.held {
                        springs.push(Spring { stiffness: pair.tangential_stiffness, vector: v });
                    }
                }
            }
            with_springs(&fe.model.stiffness, &springs)
        };
        fe.model.stiffness = Matrix::Sparse(closed);
        if self.patches.iter().any(|p| matches!(p.preload, PatchPreload::Forces(_))) {
            self.static_pre_step(fe, &mut built)?;
        }
        Ok((built.into_iter().map(|(b, _)| b).collect(), retained))
    }

    /// The static pre-step on the model with every patch closed and stuck: the `preload_forces`
    /// of every patch applied together; each pair of a patch preloaded by forces takes its
    /// normal force there, and a pair not pressed is an error naming it.
    fn static_pre_step(&self, fe: &FeModel, built: &mut [(BuiltPatch, Vec<ContactPair>)]) -> Result<(), StudyError> {
        let mut force = vec![0.0; fe.model.n_dofs()];
        for spec in &self.patches {
            let PatchPreload::Forces(forces) = &spec.preload else { continue };
            for (set, total) in forces {
                let Some(nodes) = fe.mesh.node_set(set) else {
                    let known: Vec<&String> = fe.mesh.node_sets.keys().collect();
                    return Err(self.error(
                        Some(spec.at),
                        StudyErrorKind::Invalid(format!(
                            "[[patch]] {:?}: preload_forces: no node set {set:?} in the mesh; its sets are {known:?}",
                            spec.name
                        )),
                    ));
                };
                let f = spread_force(fe, nodes, *total);
                force.iter_mut().zip(f).for_each(|(x, y)| *x += y);
            }
        }
        // `built` follows `self.patches`.
        let by_forces = |i: usize| matches!(self.patches[i].preload, PatchPreload::Forces(_));
        let at = (0..built.len()).find(|&i| by_forces(i)).map(|i| built[i].0.at);
        let u = static_displacement(&fe.model.stiffness, &force).map_err(|source| {
            self.error(at, StudyErrorKind::Patch { context: "[[patch]] preload_forces".into(), source })
        })?;
        for (i, (patch, pairs)) in built.iter_mut().enumerate() {
            if !by_forces(i) {
                continue;
            }
            let normals: Vec<&[(usize, f64)]> =
                patch.pairs.iter().map(|p| p.directions.last().expect("a normal direction").as_slice()).collect();
            let kn: Vec<f64> = patch.pairs.iter().map(|p| p.normal_stiffness).collect();
            let n0 = normal_forces(fe, pairs, &normals, &kn, &u).map_err(|source| {
                self.error(
                    Some(patch.at),
                    StudyErrorKind::Patch { context: format!("[[patch]] {:?}", patch.name), source },
                )
            })?;
            patch.pairs.iter_mut().zip(n0).for_each(|(p, n)| p.preload = n);
        }
        Ok(())
    }

    /// The joints that replace stiffness of the full model, as releases for the enriched
    /// reduction (their connector `k d dᵀ` removed from K).
    fn releases(&self, full: &LinearModel) -> Result<Vec<Release>, StudyError> {
        let err = |at: Location, kind: StudyErrorKind| self.error(Some(at), kind);
        let space = DofSpace { dofs: &full.dofs, reduction: None };
        let mut out = Vec::new();
        for j in &self.joints {
            let stiffness = match &j.law {
                LawSpec::Jenkins { stiffness, .. } | LawSpec::Iwan { stiffness, .. } => *stiffness,
                _ => continue,
            };
            let ctx = format!("[[joint]] {:?}", j.name);
            let mut v = full_vector(&space, &j.placement, &ctx).map_err(|k| err(j.at, k))?;
            normalise_user_vector(&mut v, &j.placement, &ctx).map_err(|k| err(j.at, k))?;
            let k = match stiffness {
                JointStiffness::Own(_) => continue,
                JointStiffness::Replaces(k) => k,
                JointStiffness::ReplacesComputed => replaced_stiffness(full, &v),
            };
            out.push(Release { name: j.name.clone(), direction: v, stiffness: k });
        }
        Ok(out)
    }

    /// The element of one joint on its application vector and the stiffness it replaces in K
    /// (paper form, Eq. 11), if any; or a rigid contact.
    fn joint_site(&self, linear: &LinearModel, space: &DofSpace, j: &JointSpec) -> Result<BuiltJoint, StudyErrorKind> {
        let ctx = format!("[[joint]] {:?}", j.name);
        let mut v = vector(space, &j.placement, &ctx)?;
        normalise_user_vector(&mut v, &j.placement, &ctx)?;
        let element_error = |source| StudyErrorKind::Element { context: ctx.clone(), source };
        // Paper Eq. 7: the stuck stiffness seen along V; it must be positive to be replaced.
        let stuck = |s: JointStiffness| -> Result<(f64, bool), StudyErrorKind> {
            match s {
                JointStiffness::Own(k) => Ok((k, false)),
                JointStiffness::Replaces(k) => Ok((k, true)),
                JointStiffness::ReplacesComputed => {
                    let k = replaced_stiffness(linear, &v);
                    if k > 0.0 {
                        Ok((k, true))
                    } else {
                        Err(StudyErrorKind::Invalid(format!(
                            "{ctx}: the stiffness VᵀKV along the joint is {k:e} N/m; give the joint's own `stiffness` (N/m)"
                        )))
                    }
                }
            }
        };
        let mut replaced = None;
        let law: Box<dyn Element> = match &j.law {
            LawSpec::Jenkins { threshold, stiffness } => {
                let (k, replaces) = stuck(*stiffness)?;
                replaced = replaces.then_some(k);
                let law =
                    if replaces { Jenkins::replacing_stiffness(k, *threshold) } else { Jenkins::new(k, *threshold) };
                Box::new(law.map_err(element_error)?)
            }
            LawSpec::Iwan { stiffness, slip_force, sliders } => {
                let (k, replaces) = stuck(*stiffness)?;
                replaced = replaces.then_some(k);
                let law = Iwan::uniform(k, *slip_force, *sliders).map_err(element_error)?;
                Box::new(if replaces { law.replacing_stiffness() } else { law })
            }
            LawSpec::Coulomb { threshold, velocity_scale } => {
                Box::new(RegularizedCoulomb::new(*threshold, *velocity_scale).map_err(element_error)?)
            }
            LawSpec::Cubic { k3 } => Box::new(CubicSpring::new(*k3).map_err(element_error)?),
            LawSpec::Contact(ContactSpec { tangential, normal, preload, stiffness, friction }) => {
                // Directions tangential first, then normal, as the element expects; a pair is
                // U_a − U_b (no normalisation: the stiffnesses act on that difference).
                let directions =
                    tangential.iter().chain([normal]).map(|p| vector(space, p, &ctx)).collect::<Result<Vec<_>, _>>()?;
                let Some(ContactStiffness { normal: kn, tangential: kt }) = *stiffness else {
                    let contact =
                        RigidContact { name: j.name.clone(), directions, friction: *friction, preload: *preload };
                    return Ok(BuiltJoint::Rigid(contact));
                };
                let law = if tangential.len() == 1 {
                    Contact::new_2d(kt, kn, *friction, *preload)
                } else {
                    Contact::new_3d(kt, kn, *friction, *preload)
                };
                let law = Box::new(law.map_err(element_error)?);
                return Ok(BuiltJoint::Element(ElementSite { name: j.name.clone(), law, directions }, None));
            }
        };
        Ok(BuiltJoint::Element(ElementSite { name: j.name.clone(), law, directions: vec![v] }, replaced))
    }
}

/// A joint built on the analysed model: an element of the penalty balance with the stiffness it
/// replaces in K (if any), or a rigid contact of the DLFT balance.
enum BuiltJoint {
    Element(ElementSite, Option<f64>),
    Rigid(RigidContact),
}

/// The contact elements of a patch, one per pair, named `patch-node` (the id of the pair's
/// node in the first set), on their directions projected onto the analysed model.
fn patch_sites(patch: &BuiltPatch, space: &DofSpace, sites: &mut Vec<ElementSite>) -> Result<(), StudyErrorKind> {
    let ctx = format!("[[patch]] {:?}", patch.name);
    let n = space.dofs.len();
    for pair in &patch.pairs {
        let name = format!("{}-{}", patch.name, pair.node);
        if sites.iter().any(|s| s.name == name) {
            return Err(StudyErrorKind::Invalid(format!(
                "{ctx}: its contact {name:?} has the name of another joint or contact; rename the patch or the joint"
            )));
        }
        let directions = pair
            .directions
            .iter()
            .map(|sparse| {
                let mut v = vec![0.0; n];
                sparse.iter().for_each(|&(i, c)| v[i] = c);
                match space.reduction {
                    Some(r) => r.project(&v),
                    None => v,
                }
            })
            .collect();
        let (kt, kn) = (pair.tangential_stiffness, pair.normal_stiffness);
        let element_error = |source| StudyErrorKind::Element { context: format!("{ctx} contact {name:?}"), source };
        let law = if patch.tangential_directions == 1 {
            Contact::new_2d(kt, kn, patch.friction, pair.preload)
        } else {
            Contact::new_3d(kt, kn, patch.friction, pair.preload)
        }
        .map_err(element_error)?;
        // K holds the contact's stiffnesses along its own directions (see `contact_patches`).
        let d = pair.directions.len();
        let replaced: Vec<f64> =
            (0..d * d).map(|e| if e % (d + 1) == 0 { pair.stiffness(e / d) } else { 0.0 }).collect();
        let law = law.replacing_stiffness(&replaced).map_err(element_error)?;
        sites.push(ElementSite { name, law: Box::new(law), directions });
    }
    Ok(())
}

/// Largest model on which the slipped stiffness is checked (a dense symmetric eigensolution).
const MAX_SLIPPED_CHECK_DOFS: usize = 3000;

/// Joints that replace part of K (paper Eq. 11) leave `K − Σ k_e V_e V_eᵀ` when they all slip.
/// It must stay positive semi-definite: a joint cannot remove more stiffness than the model
/// has along its direction (the slipped structure would have a negative stiffness).
fn check_slipped_stiffness(
    linear: &LinearModel,
    replaced: &[(&JointSpec, f64, Vec<f64>)],
) -> Result<(), (Location, String)> {
    let n = linear.n_dofs();
    if replaced.is_empty() || n > MAX_SLIPPED_CHECK_DOFS {
        return Ok(());
    }
    let mut k = linear.stiffness.to_dense();
    let scale = (0..n).map(|i| k[(i, i)].abs()).fold(0.0, f64::max);
    for (_, kj, v) in replaced {
        for c in 0..n {
            for r in 0..n {
                k[(r, c)] -= kj * v[r] * v[c];
            }
        }
    }
    let Ok(eigenvalues) = k.self_adjoint_eigenvalues(Side::Lower) else { return Ok(()) };
    let lowest = eigenvalues.iter().copied().fold(f64::INFINITY, f64::min);
    // Round-off of an exact cancellation (k_J = VᵀKV of a 1-DOF model) is ~1e-16 of the
    // diagonal; 1e-9 leaves room for stiffnesses typed with 10 digits.
    if lowest < -1e-9 * scale {
        let names: Vec<String> = replaced.iter().map(|(j, k, _)| format!("{:?} ({k:e} N/m)", j.name)).collect();
        return Err((
            replaced[0].0.at,
            format!(
                "[[joint]] {:?}: with the joints {} slipping, the stiffness left, K − Σ k V Vᵀ, has a negative eigenvalue ({lowest:.3e} N/m): they replace more stiffness than the model has along their directions; give each the part of K it replaces with `stiffness`, or make it a separate element with replaces_stiffness = false",
                replaced[0].0.name,
                names.join(", ")
            ),
        ));
    }
    Ok(())
}

/// The model before reduction; a mesh keeps its assembly, which knows the node sets.
// One value per build, moved once: the size difference of the variants costs nothing.
#[allow(clippy::large_enum_variant)]
enum FullModel {
    Matrices(LinearModel),
    Mesh(FeModel),
}

impl FullModel {
    fn linear(&self) -> &LinearModel {
        match self {
            FullModel::Matrices(m) => m,
            FullModel::Mesh(fe) => &fe.model,
        }
    }

    fn fe(&self) -> Option<&FeModel> {
        match self {
            FullModel::Matrices(_) => None,
            FullModel::Mesh(fe) => Some(fe),
        }
    }

    fn fe_mut(&mut self) -> Option<&mut FeModel> {
        match self {
            FullModel::Matrices(_) => None,
            FullModel::Mesh(fe) => Some(fe),
        }
    }

    fn into_linear(self) -> LinearModel {
        match self {
            FullModel::Matrices(m) => m,
            FullModel::Mesh(fe) => fe.model,
        }
    }
}

/// The DOFs that loads, joints and outputs name (those of the full model), and the reduction
/// that maps their vectors to the analysed model.
struct DofSpace<'a> {
    dofs: &'a [DofLabel],
    reduction: Option<&'a Reduction>,
}

impl DofSpace<'_> {
    fn index(&self, name: &str, ctx: &str) -> Result<usize, StudyErrorKind> {
        self.dofs.iter().position(|d| d.name == name).ok_or_else(|| {
            let shown: Vec<&str> = self.dofs.iter().take(12).map(|d| d.name.as_str()).collect();
            let known = if self.dofs.len() > 12 {
                format!("{}, ... ({} in all)", shown.join(", "), self.dofs.len())
            } else {
                shown.join(", ")
            };
            StudyErrorKind::Model {
                context: ctx.to_string(),
                source: ModelError::UnknownDof { name: name.into(), known },
            }
        })
    }
}

/// The vector over the full model's DOFs that a placement stands for.
fn full_vector(space: &DofSpace, p: &Placement, ctx: &str) -> Result<Vec<f64>, StudyErrorKind> {
    let n = space.dofs.len();
    match p {
        Placement::Dof(a) => Ok(relative_direction(n, space.index(a, ctx)?, None)),
        Placement::Between(a, b) => Ok(relative_direction(n, space.index(a, ctx)?, Some(space.index(b, ctx)?))),
        Placement::Vector(v) if v.len() != n => Err(StudyErrorKind::Invalid(format!(
            "{ctx}: vector has {} values, expected {n} (one per DOF of the model)",
            v.len()
        ))),
        Placement::Vector(v) => Ok(v.clone()),
    }
}

/// The vector over the analysed model's DOFs: projected by the reduction (`Tᵀ v`) if any.
fn vector(space: &DofSpace, p: &Placement, ctx: &str) -> Result<Vec<f64>, StudyErrorKind> {
    let v = full_vector(space, p, ctx)?;
    Ok(match space.reduction {
        Some(r) => r.project(&v),
        None => v,
    })
}

/// The paper normalises an application vector given by the user (Section 3.4), after its
/// projection on a reduced basis: the threshold is then a force along a unit direction.
fn normalise_user_vector(v: &mut [f64], p: &Placement, ctx: &str) -> Result<(), StudyErrorKind> {
    if let Placement::Vector(_) = p {
        let norm = v.iter().map(|x| x * x).sum::<f64>().sqrt();
        if norm == 0.0 {
            return Err(StudyErrorKind::Invalid(format!("{ctx}: vector is zero (on the analysed model's DOFs)")));
        }
        v.iter_mut().for_each(|x| *x /= norm);
    }
    Ok(())
}

/// All the stiffness the model has along `v` (paper Eq. 7). Eq. 7 is written for a unit
/// vector: k_n = V_nᵀ K V_n with V_n = V/|V|. The element sees u = Vᵀ U = |V| u_n, so the same
/// energy needs k = k_n / |V|² = VᵀKV / |V|⁴ (for `between`, |V|² = 2; for `dof` and
/// normalised vectors, 1).
fn replaced_stiffness(linear: &LinearModel, v: &[f64]) -> f64 {
    let norm2: f64 = v.iter().map(|x| x * x).sum();
    stiffness_along(linear, v) / (norm2 * norm2)
}

/// Read and assemble a mesh; `material` goes to every solid, `fixed` fixes DOFs by node set.
fn read_mesh(path: &Path, material: Option<&MaterialSpec>, fixed: &[FixedSet]) -> Result<FeModel, StudyErrorKind> {
    let mesh_error = |source| StudyErrorKind::Mesh { context: "[model] mesh".into(), source };
    let is_msh = path.extension().and_then(|e| e.to_str()).is_some_and(|e| e.eq_ignore_ascii_case("msh"));
    let mut mesh = if is_msh {
        stickslip_fe::mesh::gmsh::read(path).map_err(mesh_error)?
    } else {
        stickslip_fe::mesh::inp::read(path).map_err(mesh_error)?
    };
    if let Some(m) = material {
        let material = Material { young: m.young, poisson: m.poisson, density: m.density };
        mesh.assign_material(None, "STUDY", material).map_err(mesh_error)?;
    }
    for f in fixed {
        if !mesh.fix_node_set(&f.set, &f.directions) {
            let sets: Vec<&String> = mesh.node_sets.keys().collect();
            return Err(StudyErrorKind::Invalid(format!(
                "[model] fixed.{}: no node set (physical group) `{}` in {}; its sets are {sets:?}",
                f.set,
                f.set,
                path.display()
            )));
        }
    }
    FeModel::assemble(mesh).map_err(|source| StudyErrorKind::Assembly { context: "[model] mesh".into(), source })
}

/// The reduction of `[reduction]`: retained DOFs from node sets (mesh) or DOF names.
/// `patch_dofs`, the DOFs of the contact patches' node sets, are retained besides `retain`.
fn reduce(
    full: &FullModel,
    spec: &ReductionSpec,
    releases: &[Release],
    patch_dofs: &[usize],
) -> Result<Reduction, StudyErrorKind> {
    let (fe, full) = (full.fe(), full.linear());
    const CTX: &str = "[reduction] retain";
    let space = DofSpace { dofs: &full.dofs, reduction: None };
    let mut retained: Vec<usize> = patch_dofs.to_vec();
    for name in &spec.retain {
        let set = fe.and_then(|fe| fe.mesh.node_set(name).map(|_| fe.set_dofs(name)));
        let dofs = match set {
            Some(dofs) => dofs.map_err(|source| StudyErrorKind::Assembly { context: CTX.into(), source })?,
            None => vec![space.index(name, &format!("{CTX} (neither a node set of the mesh nor a DOF)"))?],
        };
        for d in dofs {
            if !retained.contains(&d) {
                retained.push(d);
            }
        }
    }
    let reduction_error = |source| StudyErrorKind::Reduction { context: "[reduction]".into(), source };
    let modes = match spec.up_to_hz {
        None => spec.modes,
        Some(hz) => {
            // Counted by the inertia of K − σM (fixed-interface for Craig-Bampton): every mode
            // up to the frequency, none guessed.
            let upper = (std::f64::consts::TAU * hz).powi(2);
            let cb = matches!(spec.method, ReductionMethod::CraigBampton);
            let n = reduction::modes_up_to(full, &retained, cb, upper).map_err(|source| StudyErrorKind::Reduction {
                context: format!("[reduction] modes_up_to_hz = {hz}"),
                source,
            })?;
            if n == 0 && !cb {
                return Err(StudyErrorKind::Invalid(format!(
                    "[reduction] modes_up_to_hz = {hz}: the model has no mode up to {hz} Hz, and the free-mode methods need at least one: raise it"
                )));
            }
            n
        }
    };
    let options = ReductionOptions { retained, modes, band: None, eigen: EigenOptions::default() };
    match spec.method {
        ReductionMethod::CraigBampton => reduction::craig_bampton(full, &options),
        ReductionMethod::FreeModes => reduction::free_modes(full, &options),
        ReductionMethod::Enriched { release_modes } => {
            if releases.is_empty() {
                return Err(StudyErrorKind::Invalid(
                    "[reduction]: method \"enriched\" releases the joints that replace stiffness (paper form), and there are none".into(),
                ));
            }
            reduction::enriched(full, &options, releases, release_modes)
        }
    }
    .map_err(reduction_error)
}

/// `node.direction` names (as in CalculiX `.dof` files) become nodal labels.
fn dof_label(name: &str) -> DofLabel {
    if let Some((node, dir)) = name.split_once('.') {
        if let (Ok(node), Ok(dir)) = (node.parse::<u64>(), dir.parse::<u8>()) {
            if (1..=6).contains(&dir) {
                return DofLabel::nodal(node, dir);
            }
        }
    }
    DofLabel::named(name)
}

/// An output name derived from a DOF name (result columns allow ASCII letters, digits, `_`, `-`).
fn sanitized(name: &str) -> String {
    name.chars().map(|c| if c.is_ascii_alphanumeric() || c == '_' || c == '-' { c } else { '_' }).collect()
}

/// DOF names, one per line; or the `dofs.csv` that `stickslip reduce` writes (a CSV table with
/// a header, the names in its `name` column), so that a reduced model is read as written.
fn read_dof_file(path: &Path) -> Result<Vec<DofLabel>, StudyErrorKind> {
    let text = std::fs::read_to_string(path)
        .map_err(|e| StudyErrorKind::Invalid(format!("[model] dof_file: cannot read {}: {e}", path.display())))?;
    let mut lines = text.lines().map(str::trim).filter(|l| !l.is_empty() && !l.starts_with('#')).peekable();
    let column = lines.peek().and_then(|header| header.split(',').position(|c| c.trim() == "name"));
    let Some(column) = column else { return Ok(lines.map(dof_label).collect()) };
    lines
        .skip(1)
        .enumerate()
        .map(|(i, l)| match l.split(',').nth(column).map(str::trim) {
            Some(name) if !name.is_empty() => Ok(dof_label(name)),
            _ => Err(StudyErrorKind::Invalid(format!(
                "[model] dof_file: {}: row {} has no value in the `name` column (column {})",
                path.display(),
                i + 1,
                column + 1
            ))),
        })
        .collect()
}

fn read_matrix(path: &Path, context: &str) -> Result<Matrix, StudyErrorKind> {
    crate::matrix::mtx::read(path).map_err(|source| StudyErrorKind::MatrixFile { context: context.into(), source })
}

/// M must be positive definite (every DOF has mass): a Cholesky factorisation succeeds.
fn check_mass_positive_definite(mass: &Matrix) -> Result<(), ModelError> {
    let ok = match mass {
        Matrix::Dense(m) => m.llt(Side::Lower).is_ok(),
        Matrix::Sparse(m) => m.sp_cholesky(Side::Lower).is_ok(),
    };
    if ok {
        Ok(())
    } else {
        Err(ModelError::MassNotPositiveDefinite)
    }
}
