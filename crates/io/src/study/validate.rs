//! From the TOML text to a validated [`Study`]: every check that does not need the model's
//! matrices (values, units, exclusive keys, sizes of inline matrices).

use std::ops::Range;
use std::path::Path;

use faer::Mat;

use super::raw::{self, RawMatrix, RawStudy, S};
use super::*;

/// The file being validated: turns byte spans into line/column errors.
pub(crate) struct Source<'a> {
    pub file: &'a Path,
    pub text: &'a str,
}

impl Source<'_> {
    pub fn location(&self, span: &Range<usize>) -> Location {
        location_of(self.text, span.start)
    }

    pub fn invalid(&self, span: &Range<usize>, message: impl Into<String>) -> StudyError {
        StudyError {
            file: self.file.to_path_buf(),
            location: Some(self.location(span)),
            kind: Box::new(StudyErrorKind::Invalid(message.into())),
        }
    }
}

/// Line and column (from 1, column in characters) of byte `offset` of `text`.
pub(crate) fn location_of(text: &str, offset: usize) -> Location {
    let offset = offset.min(text.len());
    let before = &text[..offset];
    let line = before.matches('\n').count() + 1;
    let line_start = before.rfind('\n').map_or(0, |i| i + 1);
    Location { line, column: before[line_start..].chars().count() + 1 }
}

/// The table header (`[model]`, `[[joint]]`, ...) in force at byte `offset`, to say where a
/// parser error is when its message does not.
fn section_at(text: &str, offset: usize) -> Option<&str> {
    let line_start = text[..offset.min(text.len())].rfind('\n').map_or(0, |i| i + 1);
    let line = text[line_start..].lines().next().unwrap_or("").trim_start();
    // An error on a header line itself is about the header: no prefix.
    if is_header(line) {
        return None;
    }
    text[..line_start].lines().rev().map(str::trim).find(|l| is_header(l)).map(|l| match l.rfind(']') {
        Some(end) => &l[..=end],
        None => l,
    })
}

/// `[name]` or `[[name]]`, not a row of a matrix written over several lines (`[1.0, 2.0]`).
fn is_header(line: &str) -> bool {
    line.starts_with('[') && line.trim_start_matches('[').starts_with(|c: char| c.is_ascii_alphabetic() || c == '_')
}

/// Most frequencies of a `[grid]` (each is a solve of its own).
const MAX_GRID: usize = 100_000;

pub(crate) fn parse(text: &str, file: &Path) -> Result<Study, StudyError> {
    let src = Source { file, text };
    let raw: RawStudy = toml::from_str(text).map_err(|e| {
        let message = e.message().trim_end();
        let message = match e.span().and_then(|s| section_at(text, s.start)) {
            Some(section) => format!("{section}: {message}"),
            None => message.to_string(),
        };
        StudyError {
            file: file.to_path_buf(),
            location: e.span().map(|s| src.location(&s)),
            kind: Box::new(StudyErrorKind::Syntax(message)),
        }
    })?;
    let folder = file.parent().unwrap_or(Path::new("")).to_path_buf();
    let resolve = |p: &str| folder.join(p);

    let (model, file_damping) = model(&src, &raw.model, &resolve)?;
    let n_inline = match &model {
        ModelSpec::Inline { dofs, .. } => Some(dofs.len()),
        ModelSpec::Files { dofs: DofNames::Inline(d), .. } => Some(d.len()),
        ModelSpec::Files { .. } | ModelSpec::Mesh { .. } | ModelSpec::Harmony { .. } => None,
    };
    let damping = damping(&src, raw.damping.as_ref(), file_damping, n_inline)?;
    let reduction = raw.reduction.as_ref().map(|r| reduction(&src, r)).transpose()?;

    let mut loads = Vec::new();
    for l in &raw.load {
        let ctx = format!("[[load]] {:?}", l.get_ref().name.get_ref());
        let r = l.get_ref();
        check_name(&src, &r.name, "[[load]]")?;
        let placement = match (&r.dof, &r.values) {
            (Some(d), None) => Placement::Dof(d.get_ref().clone()),
            (None, Some(v)) => Placement::Vector(finite_list(&src, v, &ctx, "values")?),
            _ => return Err(src.invalid(&l.span(), format!("{ctx}: give exactly one of `dof` or `values`"))),
        };
        let scale = match &r.scale {
            Some(s) => finite(&src, s, &ctx, "scale")?,
            None => 1.0,
        };
        let at = src.location(&r.dof.as_ref().map(|d| d.span()).unwrap_or(l.span()));
        loads.push(LoadSpec { name: r.name.get_ref().clone(), placement, scale, at });
    }
    unique_names(&src, raw.load.iter().map(|l| &l.get_ref().name), "[[load]]")?;

    // The harmonic balance first: its contact method decides what a contact joint takes.
    let hbm = hbm(&src, raw.harmonic_balance.as_ref())?;
    let rigid = hbm.contact_method == ContactMethod::Dlft;
    let mut joints = Vec::new();
    for j in &raw.joint {
        joints.push(joint(&src, j, rigid)?);
    }
    unique_names(&src, raw.joint.iter().map(|j| &j.get_ref().name), "[[joint]]")?;
    let mesh_model = matches!(model, ModelSpec::Mesh { .. } | ModelSpec::Harmony { .. });
    let mut patches = Vec::with_capacity(raw.patch.len());
    for p in &raw.patch {
        patches.push(patch(&src, p, mesh_model)?);
    }
    unique_names(&src, raw.patch.iter().map(|p| &p.get_ref().name), "[[patch]]")?;
    if rigid {
        dlft_scope(&src, &raw, &joints)?;
    }

    let excitation = excitation(&src, &raw.excitation, &loads)?;
    let sweep = sweep(&src, &raw.sweep)?;
    let continuation = continuation(&src, raw.continuation.as_ref(), &sweep)?;

    let mut outputs = Vec::new();
    for o in &raw.output {
        let r = o.get_ref();
        check_name(&src, &r.name, "[[output]]")?;
        let ctx = format!("[[output]] {:?}", r.name.get_ref());
        let (placement, span) = match (&r.dof, &r.vector) {
            (Some(d), None) => (Placement::Dof(d.get_ref().clone()), d.span()),
            (None, Some(v)) => (Placement::Vector(finite_list(&src, v, &ctx, "vector")?), v.span()),
            _ => return Err(src.invalid(&o.span(), format!("{ctx}: give exactly one of `dof` or `vector`"))),
        };
        outputs.push(OutputSelector { name: r.name.get_ref().clone(), placement, at: src.location(&span) });
    }
    unique_names(&src, raw.output.iter().map(|o| &o.get_ref().name), "[[output]]")?;
    let output_options = output_options(&src, raw.output_options.as_ref())?;
    let grid_hz = match &raw.grid {
        None => Vec::new(),
        Some(g) => {
            const CTX: &str = "[grid]";
            let f = &g.get_ref().frequencies_hz;
            let values = finite_list(&src, f, CTX, "frequencies_hz")?;
            if values.is_empty() || values.len() > MAX_GRID || values.iter().any(|v| *v <= 0.0) {
                return Err(src.invalid(
                    &f.span(),
                    format!(
                        "{CTX}: frequencies_hz must be 1 to {MAX_GRID} frequencies > 0 Hz, got {} values",
                        values.len()
                    ),
                ));
            }
            values
        }
    };
    let mut snapshots = Vec::with_capacity(raw.snapshot.len());
    for s in &raw.snapshot {
        let r = s.get_ref();
        const CTX: &str = "[[snapshot]]";
        snapshots.push(Snapshot {
            frequency_hz: positive(&src, &r.frequency_hz, CTX, "frequency_hz", " Hz")?,
            level: positive(&src, &r.level, CTX, "level", " N")?,
            at: src.location(&s.span()),
        });
    }

    let nonlinear_mode = raw.nonlinear_mode.as_ref().map(|m| nonlinear_mode(&src, m, &outputs)).transpose()?;

    Ok(Study {
        path: file.to_path_buf(),
        model,
        reduction,
        damping,
        loads,
        joints,
        patches,
        excitation,
        sweep,
        hbm,
        continuation,
        outputs,
        output_options,
        snapshots,
        grid_hz,
        nonlinear_mode,
    })
}

/// Most points of a backbone.
const MAX_BACKBONE_POINTS: i64 = 100_000;

fn nonlinear_mode(
    src: &Source,
    m: &S<raw::RawNonlinearMode>,
    outputs: &[OutputSelector],
) -> Result<NonlinearModeSpec, StudyError> {
    const CTX: &str = "[nonlinear_mode]";
    let r = m.get_ref();
    let mode = count(src, &r.mode, CTX, "mode", 1)?;
    let amplitude_start = positive(src, &r.amplitude_start, CTX, "amplitude_start", " m·√kg")?;
    let amplitude_end = positive(src, &r.amplitude_end, CTX, "amplitude_end", " m·√kg")?;
    if amplitude_end <= amplitude_start {
        return Err(src.invalid(
            &r.amplitude_end.span(),
            format!(
                "{CTX}: amplitude_end must be larger than amplitude_start (the branch starts from the linear mode at small amplitude), got {amplitude_end} <= {amplitude_start}"
            ),
        ));
    }
    let names = match &r.outputs {
        None => Vec::new(),
        Some(list) => {
            for name in list.get_ref() {
                if !outputs.iter().any(|o| &o.name == name) {
                    let known: Vec<&str> = outputs.iter().map(|o| o.name.as_str()).collect();
                    return Err(src.invalid(
                        &list.span(),
                        format!(
                            "{CTX}: outputs names {name:?}, which is no [[output]] (outputs are: {})",
                            if known.is_empty() { "none".to_string() } else { known.join(", ") }
                        ),
                    ));
                }
            }
            list.get_ref().clone()
        }
    };
    let max_points = match &r.max_points {
        Some(v) => count_at_most(src, v, CTX, "max_points", 2, MAX_BACKBONE_POINTS)?,
        None => 1000,
    };
    let target_mode_only = match &r.negative_damping {
        None => false,
        Some(v) => match v.get_ref().as_str() {
            "mass" => false,
            "target_mode" => true,
            other => {
                return Err(src.invalid(
                    &v.span(),
                    format!("{CTX}: negative_damping must be \"mass\" or \"target_mode\", got {other:?}"),
                ))
            }
        },
    };
    Ok(NonlinearModeSpec {
        mode,
        amplitude_start,
        amplitude_end,
        outputs: names,
        max_points,
        target_mode_only,
        at: src.location(&m.span()),
    })
}

/// Names of loads, joints and outputs become column names: ASCII letters, digits, `_`, `-`.
fn check_name(src: &Source, name: &S<String>, section: &str) -> Result<(), StudyError> {
    let n = name.get_ref();
    if n.is_empty() || !n.chars().all(|c| c.is_ascii_alphanumeric() || c == '_' || c == '-') {
        return Err(src.invalid(
            &name.span(),
            format!("{section}: name {n:?} must be non-empty and use only ASCII letters, digits, `_` and `-` (it names result columns)"),
        ));
    }
    Ok(())
}

fn unique_names<'a>(src: &Source, names: impl Iterator<Item = &'a S<String>>, section: &str) -> Result<(), StudyError> {
    let mut seen = std::collections::HashSet::new();
    for n in names {
        if !seen.insert(n.get_ref().as_str()) {
            return Err(src.invalid(&n.span(), format!("{section}: name {:?} is used twice", n.get_ref())));
        }
    }
    Ok(())
}

/// `fixed = { SET = [directions], ... }`: each set's directions in 1..=6, at least one, no
/// repeat; the sets themselves are checked against the mesh when it is read.
fn fixed_sets(src: &Source, fixed: &S<raw::RawFixed>) -> Result<Vec<FixedSet>, StudyError> {
    if fixed.get_ref().is_empty() {
        return Err(src.invalid(
            &fixed.span(),
            "[model] fixed: no node set given; write e.g. `fixed = { ROOT = [1, 2, 3] }` (directions 1..6 = ux, uy, uz, rx, ry, rz)",
        ));
    }
    let mut sets = Vec::new();
    for (set, directions) in fixed.get_ref() {
        let ctx = format!("[model] fixed.{set}");
        if directions.get_ref().is_empty() {
            return Err(src.invalid(
                &directions.span(),
                format!("{ctx}: no direction; give the fixed directions, e.g. [1, 2, 3] (ux, uy, uz)"),
            ));
        }
        let mut dirs: Vec<u8> = Vec::new();
        for d in directions.get_ref() {
            let v = *d.get_ref();
            if !(1..=6).contains(&v) {
                return Err(
                    src.invalid(&d.span(), format!("{ctx}: direction {v} is not one of 1..6 (ux, uy, uz, rx, ry, rz)"))
                );
            }
            if dirs.contains(&(v as u8)) {
                return Err(src.invalid(&d.span(), format!("{ctx}: direction {v} is given twice")));
            }
            dirs.push(v as u8);
        }
        sets.push(FixedSet { set: set.clone(), directions: dirs });
    }
    Ok(sets)
}

fn finite(src: &Source, v: &S<f64>, ctx: &str, key: &str) -> Result<f64, StudyError> {
    let x = *v.get_ref();
    if !x.is_finite() {
        return Err(src.invalid(&v.span(), format!("{ctx}: {key} must be a finite number, got {x}")));
    }
    Ok(x)
}

/// A value that must be `> 0` (`unit` is said in the message).
fn positive(src: &Source, v: &S<f64>, ctx: &str, key: &str, unit: &str) -> Result<f64, StudyError> {
    let x = *v.get_ref();
    if !(x.is_finite() && x > 0.0) {
        return Err(src.invalid(&v.span(), format!("{ctx}: {key} must be > 0{unit}, got {x}")));
    }
    Ok(x)
}

fn non_negative(src: &Source, v: &S<f64>, ctx: &str, key: &str, unit: &str) -> Result<f64, StudyError> {
    let x = *v.get_ref();
    if !(x.is_finite() && x >= 0.0) {
        return Err(src.invalid(&v.span(), format!("{ctx}: {key} must be >= 0{unit}, got {x}")));
    }
    Ok(x)
}

/// Bounds of the harmonic balance's sizes: memory and time per point grow with
/// samples × directions × (2 harmonics + 1) (the AFT's derivative arrays), so 100 harmonics and
/// 16384 samples (~100 MB per joint direction) are far beyond any friction study (the paper:
/// 7 and 300) yet keep a mistyped value from exhausting the memory.
const MAX_HARMONICS: i64 = 100;
const MAX_SAMPLES: i64 = 16384;
const MAX_ITERATIONS: i64 = 10_000;

/// An integer in `min..=max`.
fn count_at_most(src: &Source, v: &S<i64>, ctx: &str, key: &str, min: i64, max: i64) -> Result<usize, StudyError> {
    let x = *v.get_ref();
    if x > max {
        return Err(src.invalid(&v.span(), format!("{ctx}: {key} must be at most {max}, got {x}")));
    }
    count(src, v, ctx, key, min)
}

fn count(src: &Source, v: &S<i64>, ctx: &str, key: &str, min: i64) -> Result<usize, StudyError> {
    let x = *v.get_ref();
    if x < min {
        return Err(src.invalid(&v.span(), format!("{ctx}: {key} must be an integer >= {min}, got {x}")));
    }
    Ok(x as usize)
}

fn finite_list(src: &Source, v: &S<Vec<f64>>, ctx: &str, key: &str) -> Result<Vec<f64>, StudyError> {
    if let Some((i, x)) = v.get_ref().iter().enumerate().find(|(_, x)| !x.is_finite()) {
        return Err(src.invalid(&v.span(), format!("{ctx}: {key}[{i}] must be a finite number, got {x}")));
    }
    if v.get_ref().is_empty() {
        return Err(src.invalid(&v.span(), format!("{ctx}: {key} must not be empty")));
    }
    Ok(v.get_ref().clone())
}

/// An inline matrix of size `n × n` (rows, or diagonal values).
fn matrix(src: &Source, m: &S<RawMatrix>, n: usize, ctx: &str, key: &str) -> Result<Mat<f64>, StudyError> {
    let span = m.span();
    let mat = match m.get_ref() {
        RawMatrix::Diagonal(d) => {
            if d.len() != n {
                return Err(src.invalid(
                    &span,
                    format!("{ctx}: {key} has {} diagonal values, expected {n} (one per DOF)", d.len()),
                ));
            }
            Mat::from_fn(n, n, |i, j| if i == j { d[i] } else { 0.0 })
        }
        RawMatrix::Rows(rows) => {
            if rows.len() != n {
                return Err(
                    src.invalid(&span, format!("{ctx}: {key} has {} rows, expected {n} (one per DOF)", rows.len()))
                );
            }
            if let Some((i, r)) = rows.iter().enumerate().find(|(_, r)| r.len() != n) {
                return Err(src.invalid(
                    &span,
                    format!("{ctx}: {key} row {} has {} values, expected {n} (one per DOF)", i + 1, r.len()),
                ));
            }
            Mat::from_fn(n, n, |i, j| rows[i][j])
        }
    };
    for j in 0..n {
        for i in 0..n {
            let x = mat[(i, j)];
            if !x.is_finite() {
                return Err(src.invalid(&span, format!("{ctx}: {key}[{}][{}] must be finite, got {x}", i + 1, j + 1)));
            }
        }
    }
    Ok(mat)
}

/// Largest generated model accepted (DOFs, estimated before meshing): about 8 GiB for the
/// assembly, the factor of K − σM and the reduction at the paper's element density.
const MAX_HARMONY_DOFS: usize = 1_000_000;

/// `[model.harmony]`: the calibrated design with the values the study changes.
fn harmony(src: &Source, h: &S<raw::RawHarmony>) -> Result<stickslip_fe::harmony::Design, StudyError> {
    use stickslip_fe::element::SolidKind;
    use stickslip_fe::harmony::Design;
    const CTX: &str = "[model.harmony]";
    let r = h.get_ref();
    let refinement = match &r.refinement {
        Some(v) => positive(src, v, CTX, "refinement", "")?,
        None => 1.0,
    };
    let mut d = Design::refined(refinement);
    if let Some(e) = &r.element {
        d.kind = match e.get_ref().to_ascii_lowercase().as_str() {
            "hex20" | "c3d20" => SolidKind::Hex20,
            "hex8" | "c3d8" => SolidKind::Hex8,
            other => {
                return Err(
                    src.invalid(&e.span(), format!("{CTX}: element must be \"hex20\" or \"hex8\", got {other:?}"))
                )
            }
        };
    }
    if let Some(t) = &r.tip_contact {
        d.tip_contact = t.get_ref().parse().map_err(|e| src.invalid(&t.span(), format!("{CTX}: {e}")))?;
    }
    let lengths: [(&str, &Option<S<f64>>, &mut f64, &str); 10] = [
        ("diaphragm_thickness", &r.diaphragm_thickness, &mut d.diaphragm_thickness, " m"),
        ("blade_thickness", &r.blade_thickness, &mut d.blade_thickness, " m"),
        ("blade_length", &r.blade_length, &mut d.blade_length, " m"),
        ("envelope_height", &r.envelope_height, &mut d.envelope_height, " m"),
        ("base_radius", &r.base_radius, &mut d.base_radius, " m"),
        ("shaker_mass", &r.shaker_mass, &mut d.shaker_mass, " kg"),
        ("shaker_spring", &r.shaker_spring, &mut d.shaker_spring, " N/m"),
        ("shaker_zone_radius", &r.shaker_zone_radius, &mut d.shaker_zone_radius, " m"),
        ("connector_stiffness", &r.connector_stiffness, &mut d.connector_stiffness, " N/m"),
        ("screw_zone_radius", &r.screw_zone_radius, &mut d.screw_zone_radius, " m"),
    ];
    for (key, given, slot, unit) in lengths {
        if let Some(v) = given {
            *slot = positive(src, v, CTX, key, unit)?;
        }
    }
    if r.connector_stiffness.is_some() {
        d.contact_vertical_stiffness = d.connector_stiffness;
    }
    if let Some(v) = &r.screw_radii {
        let radii = finite_list(src, v, CTX, "screw_radii")?;
        let [inner, outer] = radii[..] else {
            return Err(
                src.invalid(&v.span(), format!("{CTX}: screw_radii must give 2 radii (m), got {}", radii.len()))
            );
        };
        d.screw_radii = [inner, outer];
    }
    if let Some(v) = &r.blade_rise {
        d.variant.blade_rise = non_negative(src, v, CTX, "blade_rise", " m")?;
    }
    if let Some(v) = &r.body_flange_radius {
        d.variant.body_flange_radius = Some(positive(src, v, CTX, "body_flange_radius", " m")?);
    }
    if let Some(v) = &r.top_disk_thickness {
        d.variant.top_disk_thickness = Some(positive(src, v, CTX, "top_disk_thickness", " m")?);
    }
    // Geometry that cannot be built, and refinements out of reach, are refused here, before
    // anything is meshed.
    let estimate = d.estimated_dofs().map_err(|e| src.invalid(&h.span(), format!("{CTX}: {e}")))?;
    if estimate > MAX_HARMONY_DOFS {
        return Err(src.invalid(
            &h.span(),
            format!(
                "{CTX}: refinement {refinement} would make about {estimate} DOFs (about {:.1} GiB to assemble, factorise and reduce); at most {MAX_HARMONY_DOFS} are accepted: lower `refinement`",
                estimate as f64 * 8.0e3 / (1u64 << 30) as f64
            ),
        ));
    }
    Ok(d)
}

fn model(
    src: &Source,
    m: &S<raw::RawModel>,
    resolve: &dyn Fn(&str) -> std::path::PathBuf,
) -> Result<(ModelSpec, Option<std::path::PathBuf>), StudyError> {
    const CTX: &str = "[model]";
    let r = m.get_ref();
    let at = src.location(&m.span());
    let inline = r.mass.is_some() || r.stiffness.is_some();
    let files = r.mass_file.is_some() || r.stiffness_file.is_some();
    let damping_file = r.damping_file.as_ref().map(|p| resolve(p.get_ref()));
    if [inline, files, r.mesh.is_some(), r.harmony.is_some()].iter().filter(|x| **x).count() > 1 {
        return Err(src.invalid(
            &m.span(),
            format!(
                "{CTX}: give one model: inline `mass` and `stiffness`, `mass_file` and `stiffness_file`, a `mesh`, or `harmony`"
            ),
        ));
    }
    if let Some(h) = &r.harmony {
        for (key, given) in [
            ("dofs", r.dofs.is_some()),
            ("dof_file", r.dof_file.is_some()),
            ("damping_file", damping_file.is_some()),
            ("material", r.material.is_some()),
        ] {
            if given {
                return Err(src.invalid(
                    &h.span(),
                    format!("{CTX}: `{key}` does not go with `harmony` (the generated assembly has its own DOFs and materials)"),
                ));
            }
        }
        let here = src.location(&h.span());
        let at = ModelLocations { section: at, mass: here, stiffness: here };
        return Ok((ModelSpec::Harmony { design: harmony(src, h)?, at }, None));
    }
    if let Some(mat) = &r.material {
        if r.mesh.is_none() {
            return Err(src.invalid(&mat.span(), format!("{CTX}: `material` goes with a `mesh`")));
        }
    }
    if let Some(fixed) = &r.fixed {
        if r.mesh.is_none() {
            return Err(src.invalid(
                &fixed.span(),
                format!("{CTX}: `fixed` goes with a `mesh` (matrices are given without their fixed DOFs)"),
            ));
        }
    }
    if let Some(mesh) = &r.mesh {
        for (key, given) in
            [("dofs", r.dofs.is_some()), ("dof_file", r.dof_file.is_some()), ("damping_file", damping_file.is_some())]
        {
            if given {
                return Err(src.invalid(
                    &mesh.span(),
                    format!(
                        "{CTX}: `{key}` does not go with a `mesh` (its DOFs are named node.direction, e.g. \"12.3\")"
                    ),
                ));
            }
        }
        let material = match &r.material {
            Some(mat) => {
                let ctx = format!("{CTX} material");
                let mr = mat.get_ref();
                let young = positive(src, &mr.young, &ctx, "young", " Pa")?;
                let density = positive(src, &mr.density, &ctx, "density", " kg/m^3")?;
                let poisson = finite(src, &mr.poisson, &ctx, "poisson")?;
                if !(-1.0 < poisson && poisson < 0.5) {
                    return Err(
                        src.invalid(&mr.poisson.span(), format!("{ctx}: poisson must be in (-1, 0.5), got {poisson}"))
                    );
                }
                Some(MaterialSpec { young, poisson, density })
            }
            None => None,
        };
        let path = resolve(mesh.get_ref());
        let ext = path.extension().and_then(|e| e.to_str()).map(str::to_ascii_lowercase);
        if !matches!(ext.as_deref(), Some("inp" | "msh")) {
            return Err(src.invalid(
                &mesh.span(),
                format!("{CTX}: mesh {:?} must be an Abaqus/CalculiX .inp or a Gmsh .msh file", mesh.get_ref()),
            ));
        }
        let fixed = match &r.fixed {
            Some(f) => fixed_sets(src, f)?,
            None => Vec::new(),
        };
        let here = src.location(&mesh.span());
        let at = ModelLocations { section: at, mass: here, stiffness: here };
        return Ok((ModelSpec::Mesh { path, material, fixed, at }, None));
    }
    if inline {
        let (Some(dofs), Some(mass), Some(stiffness)) = (&r.dofs, &r.mass, &r.stiffness) else {
            return Err(src.invalid(
                &m.span(),
                format!("{CTX}: an inline model needs `dofs` (names), `mass` (kg) and `stiffness` (N/m)"),
            ));
        };
        if let Some(f) = &r.dof_file {
            return Err(src.invalid(
                &f.span(),
                format!("{CTX}: `dof_file` goes with matrix files; inline models name their DOFs in `dofs`"),
            ));
        }
        let names = dof_names(src, dofs)?;
        let n = names.len();
        let at = ModelLocations {
            section: at,
            mass: src.location(&mass.span()),
            stiffness: src.location(&stiffness.span()),
        };
        let mass = matrix(src, mass, n, CTX, "mass")?;
        let stiffness = matrix(src, stiffness, n, CTX, "stiffness")?;
        return Ok((ModelSpec::Inline { dofs: names, mass, stiffness, at }, damping_file));
    }
    if files {
        let (Some(mf), Some(kf)) = (&r.mass_file, &r.stiffness_file) else {
            return Err(src
                .invalid(&m.span(), format!("{CTX}: a model from files needs both `mass_file` and `stiffness_file`")));
        };
        let dofs = match (&r.dofs, &r.dof_file) {
            (Some(_), Some(f)) => {
                return Err(src
                    .invalid(&f.span(), format!("{CTX}: give DOF names either in `dofs` or in `dof_file`, not both")))
            }
            (Some(d), None) => DofNames::Inline(dof_names(src, d)?),
            (None, Some(f)) => DofNames::File(resolve(f.get_ref())),
            (None, None) => DofNames::Numbered,
        };
        let at = ModelLocations { section: at, mass: src.location(&mf.span()), stiffness: src.location(&kf.span()) };
        return Ok((
            ModelSpec::Files { mass: resolve(mf.get_ref()), stiffness: resolve(kf.get_ref()), dofs, at },
            damping_file,
        ));
    }
    Err(src.invalid(
        &m.span(),
        format!("{CTX}: no model: give `dofs`, `mass` and `stiffness` inline, `mass_file` and `stiffness_file` (Matrix Market), or a `mesh`"),
    ))
}

fn reduction(src: &Source, r: &S<raw::RawReduction>) -> Result<ReductionSpec, StudyError> {
    const CTX: &str = "[reduction]";
    let raw = r.get_ref();
    let (modes, up_to_hz) = match (&raw.modes, &raw.modes_up_to_hz) {
        (Some(n), None) => (count(src, n, CTX, "modes", 0)?, None),
        (None, Some(f)) => (0, Some(positive(src, f, CTX, "modes_up_to_hz", " Hz")?)),
        (Some(_), Some(f)) => {
            return Err(src.invalid(
                &f.span(),
                format!("{CTX}: give either `modes` (a number of modes) or `modes_up_to_hz` (every mode up to a frequency), not both"),
            ))
        }
        (None, None) => {
            return Err(src.invalid(
                &r.span(),
                format!("{CTX}: needs `modes` (a number of modes) or `modes_up_to_hz` (every mode up to a frequency in Hz)"),
            ))
        }
    };
    let method = match raw.method.get_ref().as_str() {
        "cb" => ReductionMethod::CraigBampton,
        "free" => ReductionMethod::FreeModes,
        "enriched" => ReductionMethod::Enriched {
            release_modes: match &raw.release_modes {
                Some(n) => count(src, n, CTX, "release_modes", 1)?,
                None => {
                    return Err(src.invalid(&raw.method.span(), format!("{CTX}: method \"enriched\" needs `release_modes`")))
                }
            },
        },
        other => {
            return Err(src.invalid(
                &raw.method.span(),
                format!("{CTX}: unknown method {other:?}, expected \"cb\" (Craig-Bampton), \"free\" (free modes, the paper's) or \"enriched\""),
            ))
        }
    };
    if let (Some(n), false) = (&raw.release_modes, matches!(method, ReductionMethod::Enriched { .. })) {
        return Err(src.invalid(&n.span(), format!("{CTX}: release_modes goes with method = \"enriched\"")));
    }
    if let (true, Some(n)) =
        (matches!(method, ReductionMethod::FreeModes | ReductionMethod::Enriched { .. }), &raw.modes)
    {
        if modes == 0 {
            return Err(src.invalid(&n.span(), format!("{CTX}: the free-mode methods need modes >= 1")));
        }
    }
    if raw.retain.get_ref().is_empty() {
        return Err(src.invalid(&raw.retain.span(), format!("{CTX}: retain must name at least one node set or DOF")));
    }
    Ok(ReductionSpec {
        method,
        retain: raw.retain.get_ref().clone(),
        modes,
        up_to_hz,
        at: src.location(&raw.retain.span()),
    })
}

fn dof_names(src: &Source, dofs: &S<Vec<String>>) -> Result<Vec<String>, StudyError> {
    let names = dofs.get_ref();
    if names.is_empty() {
        return Err(src.invalid(&dofs.span(), "[model]: dofs must list at least one DOF name"));
    }
    let mut seen = std::collections::HashSet::new();
    for n in names {
        if n.trim().is_empty() {
            return Err(src.invalid(&dofs.span(), "[model]: DOF names must not be empty"));
        }
        if !seen.insert(n) {
            return Err(src.invalid(&dofs.span(), format!("[model]: DOF {n:?} appears twice in dofs")));
        }
    }
    Ok(names.clone())
}

fn damping(
    src: &Source,
    d: Option<&S<raw::RawDamping>>,
    file: Option<std::path::PathBuf>,
    n_inline: Option<usize>,
) -> Result<DampingSpec, StudyError> {
    const CTX: &str = "[damping]";
    let Some(d) = d else {
        return Ok(file.map_or(DampingSpec::None, DampingSpec::File));
    };
    let r = d.get_ref();
    let given = [r.alpha.is_some() || r.beta.is_some(), r.modal_ratios.is_some(), r.matrix.is_some(), file.is_some()];
    if given.iter().filter(|g| **g).count() > 1 {
        return Err(src.invalid(
            &d.span(),
            format!("{CTX}: give one kind of damping: Rayleigh `alpha`/`beta`, `modal_ratios`, `matrix`, or [model] `damping_file`"),
        ));
    }
    if r.alpha.is_some() || r.beta.is_some() {
        let alpha = r.alpha.as_ref().map(|a| non_negative(src, a, CTX, "alpha", " 1/s")).transpose()?.unwrap_or(0.0);
        let beta = r.beta.as_ref().map(|b| non_negative(src, b, CTX, "beta", " s")).transpose()?.unwrap_or(0.0);
        return Ok(DampingSpec::Rayleigh { alpha, beta });
    }
    if let Some(z) = &r.modal_ratios {
        let ratios = finite_list(src, z, CTX, "modal_ratios")?;
        if let Some(x) = ratios.iter().find(|x| **x < 0.0) {
            return Err(src.invalid(&z.span(), format!("{CTX}: modal_ratios must be >= 0, got {x}")));
        }
        return Ok(DampingSpec::Modal { ratios });
    }
    if let Some(m) = &r.matrix {
        let Some(n) = n_inline else {
            return Err(src.invalid(&m.span(), format!("{CTX}: an inline damping `matrix` needs the DOF names in [model] `dofs`; use [model] `damping_file` with matrix files")));
        };
        return Ok(DampingSpec::Matrix(matrix(src, m, n, CTX, "matrix")?));
    }
    Ok(file.map_or(DampingSpec::None, DampingSpec::File))
}

fn placement(
    src: &Source,
    r: &raw::RawJoint,
    whole: &Range<usize>,
    ctx: &str,
) -> Result<(Placement, Range<usize>), StudyError> {
    match (&r.between, &r.dof, &r.vector) {
        (Some(b), None, None) => {
            let pair = b.get_ref();
            if pair.len() != 2 || pair[0] == pair[1] {
                return Err(src.invalid(&b.span(), format!("{ctx}: between must name two different DOFs, got {pair:?}")));
            }
            Ok((Placement::Between(pair[0].clone(), pair[1].clone()), b.span()))
        }
        (None, Some(d), None) => Ok((Placement::Dof(d.get_ref().clone()), d.span())),
        (None, None, Some(v)) => Ok((Placement::Vector(finite_list(src, v, ctx, "vector")?), v.span())),
        _ => Err(src.invalid(
            whole,
            format!("{ctx}: place the joint with exactly one of `between = [\"a\", \"b\"]`, `dof = \"a\"` (to the ground) or `vector = [...]`"),
        )),
    }
}

/// A contact joint's directions: `tangential = [["a", "b"], ...]` (one pair for contact2d, two
/// for contact3d) and `normal = ["a", "b"]`, each pair `[a, b]` meaning `U_a − U_b` and a single
/// name a DOF against the ground. Its placement is the first tangential direction.
fn contact_directions(
    src: &Source,
    r: &raw::RawJoint,
    whole: &Range<usize>,
    ctx: &str,
) -> Result<(Vec<Placement>, Placement, Range<usize>), StudyError> {
    if let Some(span) =
        [&r.between.as_ref().map(|v| v.span()), &r.dof.as_ref().map(|v| v.span()), &r.vector.as_ref().map(|v| v.span())]
            .into_iter()
            .flatten()
            .next()
    {
        return Err(src.invalid(span, format!("{ctx}: a contact is placed by `tangential = [[\"a\", \"b\"], ...]` and `normal = [\"a\", \"b\"]`, not by `between`, `dof` or `vector`")));
    }
    let pair = |names: &[String], span: &Range<usize>, key: &str| -> Result<Placement, StudyError> {
        match names {
            [a] => Ok(Placement::Dof(a.clone())),
            [a, b] if a != b => Ok(Placement::Between(a.clone(), b.clone())),
            _ => Err(src.invalid(span, format!("{ctx}: each direction of `{key}` is [\"a\", \"b\"] (U_a − U_b) or [\"a\"] (U_a against the ground) with different DOF names, got {names:?}"))),
        }
    };
    let expected = if r.law.get_ref() == "contact2d" { 1 } else { 2 };
    let Some(t) = &r.tangential else {
        return Err(src.invalid(
            whole,
            format!(
                "{ctx}: law {:?} needs `tangential`, {expected} DOF pair(s) such as [[\"a_x\", \"b_x\"]]",
                r.law.get_ref()
            ),
        ));
    };
    if t.get_ref().len() != expected {
        return Err(src.invalid(
            &t.span(),
            format!(
                "{ctx}: law {:?} needs {expected} tangential direction(s), got {}",
                r.law.get_ref(),
                t.get_ref().len()
            ),
        ));
    }
    let tangential = t.get_ref().iter().map(|p| pair(p, &t.span(), "tangential")).collect::<Result<Vec<_>, _>>()?;
    let Some(n) = &r.normal else {
        return Err(src.invalid(whole, format!("{ctx}: law {:?} needs `normal`, a DOF pair [\"a\", \"b\"] whose U_a − U_b grows as the surfaces press together", r.law.get_ref())));
    };
    let normal = pair(n.get_ref(), &n.span(), "normal")?;
    Ok((tangential, normal, t.span()))
}

fn contact_placement(
    src: &Source,
    r: &raw::RawJoint,
    whole: &Range<usize>,
    ctx: &str,
) -> Result<(Placement, Range<usize>), StudyError> {
    let (tangential, _, span) = contact_directions(src, r, whole, ctx)?;
    Ok((tangential[0].clone(), span))
}

/// The contact law's parameters: stiffnesses > 0 (none for a `rigid` contact), friction
/// coefficient in [0, 10], a preload that closes the contact at rest.
fn contact_law(
    src: &Source,
    r: &raw::RawJoint,
    whole: &Range<usize>,
    ctx: &str,
    law: &str,
    rigid: bool,
) -> Result<LawSpec, StudyError> {
    let (tangential, normal, _) = contact_directions(src, r, whole, ctx)?;
    let need = |v: &Option<S<f64>>, key: &str, unit: &str| -> Result<f64, StudyError> {
        match v {
            Some(v) => positive(src, v, ctx, key, unit),
            None => Err(src.invalid(whole, format!("{ctx}: law {law:?} needs `{key}`{unit}"))),
        }
    };
    let friction = match &r.friction {
        None => {
            return Err(src.invalid(whole, format!("{ctx}: law {law:?} needs `friction`, the friction coefficient μ")))
        }
        Some(f) => friction_coefficient(src, f, ctx)?,
    };
    let preload = match &r.preload {
        None => {
            return Err(src.invalid(whole, format!("{ctx}: law {law:?} needs `preload`, the normal load at rest (N)")))
        }
        Some(p) => {
            let x = *p.get_ref();
            if !(x.is_finite() && x > 0.0) {
                return Err(src.invalid(
                    &p.span(),
                    format!("{ctx}: preload must be > 0 N, got {x}: the contact would be open at rest"),
                ));
            }
            x
        }
    };
    let stiffness = if rigid {
        // A stiffness given for a rigid contact would be silently unused: refused.
        for (key, given) in
            [("normal_stiffness", &r.normal_stiffness), ("tangential_stiffness", &r.tangential_stiffness)]
        {
            if let Some(v) = given {
                return Err(src.invalid(
                    &v.span(),
                    format!("{ctx}: `{key}` does not apply with [harmonic_balance] contact_method = \"dlft\": the contact is rigid (no penetration, no elastic slip); remove it, or use contact_method = \"penalty\" for a contact with stiffness"),
                ));
            }
        }
        None
    } else {
        Some(ContactStiffness {
            normal: need(&r.normal_stiffness, "normal_stiffness", " N/m")?,
            tangential: need(&r.tangential_stiffness, "tangential_stiffness", " N/m")?,
        })
    };
    Ok(LawSpec::Contact(ContactSpec { tangential, normal, preload, stiffness, friction }))
}

/// A `[[joint]]`; `rigid`: contacts are rigid (`contact_method = "dlft"`) and take no stiffness.
fn joint(src: &Source, j: &S<raw::RawJoint>, rigid: bool) -> Result<JointSpec, StudyError> {
    let r = j.get_ref();
    check_name(src, &r.name, "[[joint]]")?;
    let ctx = format!("[[joint]] {:?}", r.name.get_ref());
    let law_name = r.law.get_ref().as_str();
    let is_contact = matches!(law_name, "contact2d" | "contact3d");
    let (placement, pspan) =
        if is_contact { contact_placement(src, r, &j.span(), &ctx)? } else { placement(src, r, &j.span(), &ctx)? };
    // Keys each law accepts, to reject parameters of another law (a likely mix-up).
    let allowed: &[&str] = match law_name {
        "jenkins" => &["threshold", "stiffness", "replaces_stiffness"],
        "iwan" => &["stiffness", "replaces_stiffness", "slip_force", "sliders"],
        "coulomb" => &["threshold", "velocity_scale"],
        "cubic" => &["k3"],
        "contact2d" | "contact3d" => &["preload", "normal_stiffness", "tangential_stiffness", "friction"],
        other => {
            return Err(src.invalid(
                &r.law.span(),
                format!("{ctx}: unknown law {other:?}, expected one of \"jenkins\", \"iwan\", \"coulomb\", \"cubic\", \"contact2d\", \"contact3d\""),
            ))
        }
    };
    let present: [(&str, Option<Range<usize>>); 11] = [
        ("preload", r.preload.as_ref().map(|v| v.span())),
        ("normal_stiffness", r.normal_stiffness.as_ref().map(|v| v.span())),
        ("tangential_stiffness", r.tangential_stiffness.as_ref().map(|v| v.span())),
        ("friction", r.friction.as_ref().map(|v| v.span())),
        ("threshold", r.threshold.as_ref().map(|v| v.span())),
        ("stiffness", r.stiffness.as_ref().map(|v| v.span())),
        ("replaces_stiffness", r.replaces_stiffness.as_ref().map(|v| v.span())),
        ("slip_force", r.slip_force.as_ref().map(|v| v.span())),
        ("sliders", r.sliders.as_ref().map(|v| v.span())),
        ("velocity_scale", r.velocity_scale.as_ref().map(|v| v.span())),
        ("k3", r.k3.as_ref().map(|v| v.span())),
    ];
    for (key, span) in &present {
        if let Some(span) = span {
            if !allowed.contains(key) {
                return Err(src.invalid(
                    span,
                    format!(
                        "{ctx}: `{key}` is not a parameter of law {law_name:?}, which takes: {}",
                        allowed.join(", ")
                    ),
                ));
            }
        }
    }
    let need = |v: &Option<S<f64>>, key: &str, unit: &str| -> Result<f64, StudyError> {
        match v {
            Some(v) => positive(src, v, &ctx, key, unit),
            None => Err(src.invalid(&j.span(), format!("{ctx}: law {law_name:?} needs `{key}`{unit}"))),
        }
    };
    let hysteretic_stiffness = || -> Result<JointStiffness, StudyError> {
        let replaces = r.replaces_stiffness.as_ref().map(|b| *b.get_ref());
        match (&r.stiffness, replaces) {
            (Some(k), Some(true)) => Ok(JointStiffness::Replaces(positive(src, k, &ctx, "stiffness", " N/m")?)),
            (Some(k), None | Some(false)) => Ok(JointStiffness::Own(positive(src, k, &ctx, "stiffness", " N/m")?)),
            (None, None | Some(true)) => Ok(JointStiffness::ReplacesComputed),
            (None, Some(false)) => Err(src.invalid(
                &r.replaces_stiffness.as_ref().map(|b| b.span()).unwrap_or(j.span()),
                format!("{ctx}: replaces_stiffness = false needs the joint's own `stiffness` (N/m)"),
            )),
        }
    };
    let law = match law_name {
        "jenkins" => {
            LawSpec::Jenkins { threshold: need(&r.threshold, "threshold", " N")?, stiffness: hysteretic_stiffness()? }
        }
        "iwan" => LawSpec::Iwan {
            stiffness: hysteretic_stiffness()?,
            slip_force: need(&r.slip_force, "slip_force", " N")?,
            sliders: match &r.sliders {
                Some(s) => count(src, s, &ctx, "sliders", 1)?,
                None => 10,
            },
        },
        "coulomb" => LawSpec::Coulomb {
            threshold: need(&r.threshold, "threshold", " N")?,
            velocity_scale: need(&r.velocity_scale, "velocity_scale", " m/s")?,
        },
        "contact2d" | "contact3d" => contact_law(src, r, &j.span(), &ctx, law_name, rigid)?,
        _ => LawSpec::Cubic {
            k3: match &r.k3 {
                Some(k) => finite(src, k, &ctx, "k3")?,
                None => return Err(src.invalid(&j.span(), format!("{ctx}: law \"cubic\" needs `k3` (N/m^3)"))),
            },
        },
    };
    Ok(JointSpec { name: r.name.get_ref().clone(), law, placement, at: src.location(&pspan) })
}

/// A friction coefficient in [0, MAX_FRICTION_COEFFICIENT].
fn friction_coefficient(src: &Source, f: &S<f64>, ctx: &str) -> Result<f64, StudyError> {
    let mu = *f.get_ref();
    let max = stickslip_core::elements::MAX_FRICTION_COEFFICIENT;
    if !(mu.is_finite() && (0.0..=max).contains(&mu)) {
        return Err(src.invalid(
            &f.span(),
            format!("{ctx}: friction must lie in [0, {max}] (a coefficient, not a force), got {mu}"),
        ));
    }
    Ok(mu)
}

/// A direction `[x, y, z]`: three finite values, not all zero.
fn direction(src: &Source, v: &S<Vec<f64>>, ctx: &str, key: &str) -> Result<[f64; 3], StudyError> {
    let x = finite_list(src, v, ctx, key)?;
    match x[..] {
        [a, b, c] if a != 0.0 || b != 0.0 || c != 0.0 => Ok([a, b, c]),
        _ => Err(src.invalid(&v.span(), format!("{ctx}: {key} must be a direction [x, y, z], not zero, got {x:?}"))),
    }
}

/// Most static forces of one patch's pre-step.
const MAX_PRELOAD_FORCES: usize = 1000;

fn patch(src: &Source, p: &S<raw::RawPatch>, mesh_model: bool) -> Result<PatchSpec, StudyError> {
    let r = p.get_ref();
    check_name(src, &r.name, "[[patch]]")?;
    let ctx = format!("[[patch]] {:?}", r.name.get_ref());
    if !mesh_model {
        return Err(src.invalid(
            &p.span(),
            format!("{ctx}: a patch pairs node sets of a mesh; the [model] must be a `mesh` or `harmony` (for matrices, place contacts with [[joint]] law = \"contact3d\")"),
        ));
    }
    let sets = match &r.between.get_ref()[..] {
        [a, b] if !a.eq_ignore_ascii_case(b) => [a.clone(), b.clone()],
        other => {
            return Err(src.invalid(
                &r.between.span(),
                format!("{ctx}: between must name two different node sets [\"A\", \"B\"] (the normal points from A into B), got {other:?}"),
            ))
        }
    };
    let law = r.law.get_ref().as_str();
    let tangential_directions = match law {
        "contact2d" => 1,
        "contact3d" => 2,
        other => {
            return Err(
                src.invalid(&r.law.span(), format!("{ctx}: law must be \"contact2d\" or \"contact3d\", got {other:?}"))
            )
        }
    };
    let need = |v: &Option<S<f64>>, key: &str, what: &str| -> Result<f64, StudyError> {
        match v {
            Some(v) => positive(src, v, &ctx, key, " N/m^3"),
            None => Err(src.invalid(&p.span(), format!("{ctx}: needs `{key}` (N/m^3), {what}"))),
        }
    };
    let normal_stiffness_per_area =
        need(&r.normal_stiffness_per_area, "normal_stiffness_per_area", "the normal contact stiffness per unit area")?;
    let tangential_stiffness_per_area = need(
        &r.tangential_stiffness_per_area,
        "tangential_stiffness_per_area",
        "the tangential contact stiffness per unit area",
    )?;
    let friction = match &r.friction {
        Some(f) => friction_coefficient(src, f, &ctx)?,
        None => return Err(src.invalid(&p.span(), format!("{ctx}: needs `friction`, the friction coefficient μ"))),
    };
    let preload = match (&r.pressure, &r.preload_forces) {
        (Some(pr), None) => {
            let x = *pr.get_ref();
            if !(x.is_finite() && x > 0.0) {
                return Err(src.invalid(
                    &pr.span(),
                    format!("{ctx}: pressure must be > 0 Pa, got {x}: the contact would be open at rest"),
                ));
            }
            PatchPreload::Pressure(x)
        }
        (None, Some(list)) => {
            if list.get_ref().is_empty() || list.get_ref().len() > MAX_PRELOAD_FORCES {
                return Err(src.invalid(
                    &list.span(),
                    format!("{ctx}: preload_forces must list 1 to {MAX_PRELOAD_FORCES} forces {{ set = \"BOLT\", force = [fx, fy, fz] }} (N)"),
                ));
            }
            let mut forces = Vec::with_capacity(list.get_ref().len());
            for f in list.get_ref() {
                let f = f.get_ref();
                forces.push((f.set.get_ref().clone(), direction(src, &f.force, &ctx, "preload_forces force")?));
            }
            PatchPreload::Forces(forces)
        }
        _ => {
            return Err(src.invalid(
                &p.span(),
                format!("{ctx}: give the load at rest as exactly one of `pressure` (Pa, uniform) or `preload_forces = [{{ set = \"BOLT\", force = [fx, fy, fz] }}]` (N, a static pre-step)"),
            ))
        }
    };
    let normal = r.normal.as_ref().map(|v| direction(src, v, &ctx, "normal")).transpose()?;
    let tangential = r.tangential.as_ref().map(|v| direction(src, v, &ctx, "tangential")).transpose()?;
    if tangential_directions == 1 && tangential.is_none() {
        return Err(src.invalid(
            &r.law.span(),
            format!("{ctx}: law \"contact2d\" needs `tangential = [x, y, z]`, the direction of sliding"),
        ));
    }
    Ok(PatchSpec {
        name: r.name.get_ref().clone(),
        sets,
        tangential_directions,
        friction,
        normal_stiffness_per_area,
        tangential_stiffness_per_area,
        preload,
        normal,
        tangential,
        at: src.location(&r.between.span()),
    })
}

fn excitation(src: &Source, e: &S<raw::RawExcitation>, loads: &[LoadSpec]) -> Result<ExcitationSpec, StudyError> {
    const CTX: &str = "[excitation]";
    let r = e.get_ref();
    let load = match &r.load {
        Some(l) => {
            if !loads.iter().any(|x| &x.name == l.get_ref()) {
                let known: Vec<&str> = loads.iter().map(|x| x.name.as_str()).collect();
                return Err(src.invalid(
                    &l.span(),
                    format!("{CTX}: no [[load]] named {:?} (loads are: {})", l.get_ref(), known.join(", ")),
                ));
            }
            Some(l.get_ref().clone())
        }
        None if loads.len() == 1 => None,
        None => {
            return Err(src.invalid(
                &e.span(),
                format!(
                    "{CTX}: say which [[load]] excites the structure with `load = \"name\"` ({} loads defined)",
                    loads.len()
                ),
            ))
        }
    };
    let levels = finite_list(src, &r.levels, CTX, "levels")?;
    if let Some(x) = levels.iter().find(|x| **x <= 0.0) {
        return Err(src.invalid(&r.levels.span(), format!("{CTX}: levels must be > 0 N, got {x}")));
    }
    Ok(ExcitationSpec { load, levels, at: src.location(&e.span()) })
}

fn sweep(src: &Source, s: &S<raw::RawSweep>) -> Result<SweepSettings, StudyError> {
    const CTX: &str = "[sweep]";
    let r = s.get_ref();
    let start_hz = positive(src, &r.start_hz, CTX, "start_hz", " Hz")?;
    let end_hz = positive(src, &r.end_hz, CTX, "end_hz", " Hz")?;
    if start_hz == end_hz {
        return Err(src.invalid(
            &r.end_hz.span(),
            format!("{CTX}: empty band: start_hz and end_hz are both {start_hz} Hz; give two different frequencies (end_hz < start_hz sweeps down)"),
        ));
    }
    let band = (end_hz - start_hz).abs();
    let step_hz = match &r.step_hz {
        Some(st) => {
            let x = positive(src, st, CTX, "step_hz", " Hz")?;
            if x > band {
                return Err(
                    src.invalid(&st.span(), format!("{CTX}: step_hz ({x} Hz) is larger than the band ({band} Hz)"))
                );
            }
            x
        }
        None => band / 100.0,
    };
    Ok(SweepSettings { start_hz, end_hz, step_hz })
}

/// What `contact_method = "dlft"` can solve: the DLFT balance (core `hbm::dlft`) imposes rigid
/// point contacts on the linear model and has no other element, no stability analysis and no
/// nonlinear mode; its patches would need the contacts' stiffness in K (a part held by a patch
/// alone is free without it) and a static pre-step of rigid contacts. Each refusal names the
/// key and what is expected.
fn dlft_scope(src: &Source, raw: &RawStudy, joints: &[JointSpec]) -> Result<(), StudyError> {
    const WHY: &str = "[harmonic_balance] contact_method = \"dlft\" solves rigid point contacts only";
    let method_span = raw
        .harmonic_balance
        .as_ref()
        .and_then(|h| h.get_ref().contact_method.as_ref())
        .map(|m| m.span())
        .unwrap_or(0..0);
    for (j, raw_joint) in joints.iter().zip(&raw.joint) {
        if !matches!(j.law, LawSpec::Contact(_)) {
            let law = raw_joint.get_ref().law.get_ref();
            return Err(src.invalid(
                &raw_joint.get_ref().law.span(),
                format!(
                    "[[joint]] {:?}: law {law:?} cannot be mixed with rigid contacts ({WHY}): with it every [[joint]] must be law = \"contact2d\" or \"contact3d\"; for other laws use contact_method = \"penalty\" (the default) with penalty contacts",
                    j.name
                ),
            ));
        }
    }
    if let Some(p) = raw.patch.first() {
        return Err(src.invalid(
            &p.span(),
            format!(
                "[[patch]] {:?}: patches are not solved with rigid contacts ({WHY}, given as [[joint]] law = \"contact2d\"/\"contact3d\"): a patch's contacts hold its parts through their stiffness; use contact_method = \"penalty\" for patches",
                p.get_ref().name.get_ref()
            ),
        ));
    }
    if joints.is_empty() {
        return Err(src.invalid(
            &method_span,
            format!("{WHY}, and the study has none: add [[joint]] sections with law = \"contact2d\" or \"contact3d\""),
        ));
    }
    if let Some(m) = &raw.nonlinear_mode {
        return Err(src.invalid(
            &m.span(),
            format!("[nonlinear_mode]: not available with rigid contacts ({WHY}, by forced sweeps): remove [nonlinear_mode] or use contact_method = \"penalty\""),
        ));
    }
    Ok(())
}

fn hbm(src: &Source, h: Option<&S<raw::RawHarmonicBalance>>) -> Result<HbmSettings, StudyError> {
    const CTX: &str = "[harmonic_balance]";
    let mut out = HbmSettings::default();
    let Some(h) = h else { return Ok(out) };
    let r = h.get_ref();
    if let Some(m) = &r.contact_method {
        out.contact_method = match m.get_ref().as_str() {
            "penalty" => ContactMethod::Penalty,
            "dlft" => ContactMethod::Dlft,
            other => {
                return Err(src.invalid(
                    &m.span(),
                    format!("{CTX}: contact_method must be \"penalty\" (contacts with stiffness, the default) or \"dlft\" (rigid contacts), got {other:?}"),
                ))
            }
        };
    }
    if let Some(n) = &r.harmonics {
        out.harmonics = count_at_most(src, n, CTX, "harmonics", 1, MAX_HARMONICS)?;
    }
    let collocated = 2 * out.harmonics + 1;
    if out.contact_method == ContactMethod::Dlft {
        // One sample per unknown coefficient: the DLFT constraints then hold exactly at the
        // samples and the solution does not depend on the DLFT penalty ε (module docs of core
        // `hbm::dlft`); with more samples it moves with ε by the truncation error, and ε is a
        // numerical setting the study does not choose. Hence the default and the only value.
        out.samples = collocated;
        if let Some(s) = &r.samples {
            if *s.get_ref() != collocated as i64 {
                return Err(src.invalid(
                    &s.span(),
                    format!(
                        "{CTX}: with contact_method = \"dlft\", samples must be 2 harmonics + 1 = {collocated} (the default), got {}: with one sample per unknown the rigid contact's constraints hold exactly at the samples and the result does not depend on the DLFT penalty; leave samples out",
                        s.get_ref()
                    ),
                ));
            }
        }
        if let Some(b) = r.stability.as_ref().filter(|b| *b.get_ref()) {
            return Err(src.invalid(
                &b.span(),
                format!("{CTX}: stability = true is not available with contact_method = \"dlft\" (Hill's method is written for the penalty balance's elements); remove it"),
            ));
        }
    }
    if let Some(s) = &r.samples {
        out.samples = count_at_most(src, s, CTX, "samples", 1, MAX_SAMPLES)?;
    }
    let min = collocated;
    if out.samples < min {
        let span = r.samples.as_ref().map(|s| s.span()).unwrap_or(h.span());
        return Err(src.invalid(
            &span,
            format!("{CTX}: {} samples cannot resolve {} harmonics: samples must be >= 2 harmonics + 1 = {min} (the paper uses 300 for 7)", out.samples, out.harmonics),
        ));
    }
    if let Some(t) = &r.tolerance {
        out.tolerance = positive(src, t, CTX, "tolerance", "")?;
    }
    if let Some(m) = &r.max_iterations {
        out.max_iterations = count_at_most(src, m, CTX, "max_iterations", 1, MAX_ITERATIONS)?;
    }
    if let Some(b) = &r.stability {
        out.stability = *b.get_ref();
    }
    Ok(out)
}

fn continuation(
    src: &Source,
    c: Option<&S<raw::RawContinuation>>,
    sweep: &SweepSettings,
) -> Result<ContinuationSettings, StudyError> {
    const CTX: &str = "[continuation]";
    let mut out = ContinuationSettings {
        predictor: Predictor::Secant,
        min_step_hz: sweep.step_hz / 1000.0,
        max_step_hz: sweep.step_hz * 10.0,
        max_points: 0,
    };
    // Default: room for 50 bands at the largest step. Arclength steps are in x as well as in
    // the frequency: across a resonance the response turns through half a circle while the
    // frequency hardly moves, so a sweep takes several times band / max_step points, the more
    // the finer the steps a user asks (a flat friction peak at 0.005 Hz steps took 10,000 points
    // before 210 Hz of a 150-350 Hz band).
    let default_points = |max_step_hz: f64| {
        let band = (sweep.end_hz - sweep.start_hz).abs();
        ((50.0 * band / max_step_hz).ceil() as usize).clamp(10_000, 10_000_000)
    };
    let Some(c) = c else {
        out.max_points = default_points(out.max_step_hz);
        return Ok(out);
    };
    let r = c.get_ref();
    if let Some(p) = &r.predictor {
        out.predictor = match p.get_ref().as_str() {
            "secant" => Predictor::Secant,
            "tangent" => Predictor::Tangent,
            "lagrange" => Predictor::Lagrange,
            other => {
                return Err(src.invalid(
                    &p.span(),
                    format!(
                        "{CTX}: unknown predictor {other:?}, expected one of \"secant\", \"tangent\", \"lagrange\""
                    ),
                ))
            }
        };
    }
    if let Some(m) = &r.min_step_hz {
        out.min_step_hz = positive(src, m, CTX, "min_step_hz", " Hz")?;
    }
    if let Some(m) = &r.max_step_hz {
        out.max_step_hz = positive(src, m, CTX, "max_step_hz", " Hz")?;
    }
    if !(out.min_step_hz <= sweep.step_hz && sweep.step_hz <= out.max_step_hz) {
        return Err(src.invalid(
            &c.span(),
            format!(
                "{CTX}: need min_step_hz <= [sweep] step_hz <= max_step_hz, got {} <= {} <= {} Hz",
                out.min_step_hz, sweep.step_hz, out.max_step_hz
            ),
        ));
    }
    out.max_points = match &r.max_points {
        Some(m) => count(src, m, CTX, "max_points", 2)?,
        None => default_points(out.max_step_hz),
    };
    Ok(out)
}

fn output_options(src: &Source, o: Option<&S<raw::RawOutputOptions>>) -> Result<OutputOptions, StudyError> {
    const CTX: &str = "[output_options]";
    let mut out = OutputOptions::default();
    let Some(o) = o else { return Ok(out) };
    let r = o.get_ref();
    if let Some(t) = &r.time_data {
        out.time_data = match t.get_ref() {
            raw::RawTimeData::Word(w) if w == "none" => TimeData::None,
            raw::RawTimeData::Word(w) if w == "all" => TimeData::All,
            raw::RawTimeData::Every(k) if *k >= 1 => TimeData::Every(*k as usize),
            raw::RawTimeData::Every(k) => {
                return Err(src.invalid(
                    &t.span(),
                    format!("{CTX}: time_data = k writes every k-th point and needs k >= 1, got {k}"),
                ))
            }
            raw::RawTimeData::Word(w) => {
                return Err(src.invalid(
                    &t.span(),
                    format!(
                        "{CTX}: time_data must be \"none\", \"all\" or an integer k >= 1 (every k-th point), got {w:?}"
                    ),
                ))
            }
        };
    }
    if let Some(p) = &r.plot_format {
        out.plot_format = match p.get_ref().as_str() {
            "png" => PlotFormat::Png,
            "svg" => PlotFormat::Svg,
            other => {
                return Err(
                    src.invalid(&p.span(), format!("{CTX}: plot_format must be \"png\" or \"svg\", got {other:?}"))
                )
            }
        };
    }
    Ok(out)
}
