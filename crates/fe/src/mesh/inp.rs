//! Abaqus/CalculiX `.inp` decks: the subset real modal decks use (see docs/fe.md).
//!
//! The deck is read in two passes: lines (with `*INCLUDE` expanded, comments dropped and
//! continued keyword lines joined) are grouped into keyword blocks, then each block is applied
//! to the mesh in order. Sections are resolved at the end (a material may follow its section).

use std::collections::{BTreeMap, HashMap};
use std::path::{Path, PathBuf};

use super::{Equation, Material, Mesh, MeshError, Origin, PointElement, RigidCoupling, Solid};
use crate::element::SolidKind;

/// Most ids one `*NSET`/`*ELSET, GENERATE` line may produce (400 MB of ids): far more than any
/// mesh this reader is meant for, small enough to allocate.
const MAX_GENERATED: u64 = 50_000_000;

/// Read a deck from a file (`*INCLUDE` paths are relative to the including file).
pub fn read(path: impl AsRef<Path>) -> Result<Mesh, MeshError> {
    let mut lines = Vec::new();
    let mut files = Vec::new();
    load(path.as_ref(), &mut files, &mut lines, 0)?;
    Parser::new(files).run(&lines)
}

/// Read a deck from a string (`*INCLUDE` paths are relative to the working directory).
pub fn parse(text: &str, name: &str) -> Result<Mesh, MeshError> {
    let mut lines = Vec::new();
    let mut files = vec![PathBuf::from(name)];
    split(text, 0, Path::new("."), &mut files, &mut lines, 0)?;
    Parser::new(files).run(&lines)
}

/// One line of the deck: text, file index, 1-based line number.
struct Line {
    text: String,
    file: usize,
    line: usize,
}

const MAX_INCLUDE_DEPTH: usize = 20;

fn load(path: &Path, files: &mut Vec<PathBuf>, out: &mut Vec<Line>, depth: usize) -> Result<(), MeshError> {
    let text = std::fs::read_to_string(path).map_err(|source| MeshError::Io { file: path.into(), source })?;
    files.push(path.to_path_buf());
    let dir = path.parent().unwrap_or(Path::new(".")).to_path_buf();
    split(&text, files.len() - 1, &dir, files, out, depth)
}

fn split(
    text: &str,
    file: usize,
    dir: &Path,
    files: &mut Vec<PathBuf>,
    out: &mut Vec<Line>,
    depth: usize,
) -> Result<(), MeshError> {
    let mut pending: Option<Line> = None;
    for (i, raw) in text.lines().enumerate() {
        let t = raw.trim();
        if t.starts_with("**") {
            continue;
        }
        if let Some(mut p) = pending.take() {
            // A keyword line ending with a comma continues on the next line.
            p.text.push_str(t);
            if t.ends_with(',') {
                pending = Some(p);
            } else {
                out.push(p);
            }
            continue;
        }
        let line = Line { text: t.to_string(), file, line: i + 1 };
        if t.starts_with('*') {
            let (name, params) = keyword(t);
            if name == "INCLUDE" {
                let at = Origin { file: files[file].clone(), line: i + 1 };
                let input = params
                    .get("INPUT")
                    .ok_or_else(|| MeshError::Syntax { at: at.clone(), msg: "*INCLUDE needs INPUT=file".into() })?;
                if depth >= MAX_INCLUDE_DEPTH {
                    return Err(MeshError::Syntax { at, msg: "*INCLUDE nested too deeply (a cycle?)".into() });
                }
                load(&dir.join(input.trim_matches('"')), files, out, depth + 1)?;
                continue;
            }
            if t.ends_with(',') {
                pending = Some(line);
                continue;
            }
        }
        out.push(line);
    }
    if let Some(p) = pending {
        out.push(p);
    }
    Ok(())
}

/// Keyword name (upper case, single spaces) and parameters (keys upper case, values as written).
fn keyword(line: &str) -> (String, HashMap<String, String>) {
    let mut parts = line[1..].split(',');
    let name = parts.next().unwrap_or("").split_whitespace().collect::<Vec<_>>().join(" ").to_uppercase();
    let mut params = HashMap::new();
    for p in parts {
        let p = p.trim();
        if p.is_empty() {
            continue;
        }
        match p.split_once('=') {
            Some((k, v)) => params.insert(k.trim().to_uppercase(), v.trim().to_string()),
            None => params.insert(p.to_uppercase(), String::new()),
        };
    }
    (name, params)
}

/// Keywords accepted and ignored: output requests, step bookkeeping, headings.
const IGNORED: &[&str] = &[
    "HEADING",
    "PREPRINT",
    "RESTART",
    "END STEP",
    "NODE FILE",
    "EL FILE",
    "NODE PRINT",
    "EL PRINT",
    "NODE OUTPUT",
    "ELEMENT OUTPUT",
    "OUTPUT",
    "CONTACT FILE",
    "CONTACT PRINT",
    "PART",
    "END PART",
    "ASSEMBLY",
    "END ASSEMBLY",
    "INSTANCE",
    "END INSTANCE",
];

/// A point element read from `*ELEMENT`, waiting for its `*MASS`/`*SPRING` card.
#[derive(Clone, Copy, PartialEq)]
enum PointKind {
    Mass,
    Spring1,
    Spring2,
    SpringA,
}

#[derive(Clone, Copy)]
enum ElemRef {
    Solid(usize),
    Point(usize),
}

struct PendingPoint {
    id: u64,
    kind: PointKind,
    nodes: Vec<usize>,
    done: bool,
    at: Origin,
}

struct Section {
    elset: String,
    material: String,
    at: Origin,
}

struct Parser {
    files: Vec<PathBuf>,
    mesh: Mesh,
    element_ids: HashMap<u64, ElemRef>,
    elsets: BTreeMap<String, Vec<ElemRef>>,
    pending_points: Vec<PendingPoint>,
    sections: Vec<Section>,
    /// Node-based surfaces: name → nodes.
    surfaces: HashMap<String, Vec<usize>>,
    current_material: Option<usize>,
    /// Incomplete materials: index → origin of *MATERIAL.
    material_at: Vec<Origin>,
    /// The last `*COUPLING` waiting for its `*KINEMATIC`: reference node, nodes, origin.
    coupling: Option<(usize, Vec<usize>, Origin)>,
    /// `*RIGID BODY` rotation nodes: rotation node → (its reference node, origin). CalculiX
    /// gives a rigid body's rotations to the translations 1-3 of its ROT NODE; here they are the
    /// reference node's DOFs 4-6, so the rotation nodes leave the mesh once the deck is read.
    rotation_nodes: BTreeMap<usize, (usize, Origin)>,
}

/// The numbers of a data line (empty fields skipped).
fn fields(text: &str) -> impl Iterator<Item = &str> {
    text.split(',').map(str::trim).filter(|f| !f.is_empty())
}

impl Parser {
    fn new(files: Vec<PathBuf>) -> Self {
        Parser {
            files,
            mesh: Mesh::default(),
            element_ids: HashMap::new(),
            elsets: BTreeMap::new(),
            pending_points: Vec::new(),
            sections: Vec::new(),
            surfaces: HashMap::new(),
            current_material: None,
            material_at: Vec::new(),
            coupling: None,
            rotation_nodes: BTreeMap::new(),
        }
    }

    fn at(&self, l: &Line) -> Origin {
        Origin { file: self.files[l.file].clone(), line: l.line }
    }

    fn syntax(&self, l: &Line, msg: impl Into<String>) -> MeshError {
        MeshError::Syntax { at: self.at(l), msg: msg.into() }
    }

    fn num<T: std::str::FromStr>(&self, l: &Line, f: &str, what: &str) -> Result<T, MeshError> {
        f.parse::<T>().map_err(|_| self.syntax(l, format!("expected {what}, got {f:?}")))
    }

    fn float(&self, l: &Line, f: &str, what: &str) -> Result<f64, MeshError> {
        // Fortran-style exponents (1.0D3) appear in older decks.
        let x = f
            .replace(['d', 'D'], "e")
            .parse::<f64>()
            .map_err(|_| self.syntax(l, format!("expected {what}, got {f:?}")))?;
        // `nan`, `inf` and overflowing literals (1e999) parse, but are no coordinate or property.
        if !x.is_finite() {
            return Err(self.syntax(l, format!("expected {what}, got {f:?}, which is not finite")));
        }
        Ok(x)
    }

    fn node_ref(&self, l: &Line, id: u64, what: &str) -> Result<usize, MeshError> {
        self.mesh.node(id).ok_or_else(|| MeshError::UndefinedNode { at: self.at(l), what: what.into(), node: id })
    }

    /// Nodes named by a data field: a node id or a node set name.
    fn nodes_of(&self, l: &Line, f: &str, what: &str) -> Result<Vec<usize>, MeshError> {
        if let Ok(id) = f.parse::<u64>() {
            return Ok(vec![self.node_ref(l, id, what)?]);
        }
        self.mesh.node_sets.get(&f.to_uppercase()).cloned().ok_or_else(|| MeshError::UndefinedSet {
            at: self.at(l),
            what: what.into(),
            set: f.into(),
        })
    }

    fn run(mut self, lines: &[Line]) -> Result<Mesh, MeshError> {
        let mut i = 0;
        while i < lines.len() {
            let l = &lines[i];
            if l.text.is_empty() {
                i += 1;
                continue;
            }
            if !l.text.starts_with('*') {
                return Err(self.syntax(l, format!("data line outside a keyword block: {:?}", l.text)));
            }
            let mut j = i + 1;
            while j < lines.len() && !lines[j].text.starts_with('*') {
                j += 1;
            }
            self.block(l, &lines[i + 1..j])?;
            i = j;
        }
        self.finish()
    }

    fn block(&mut self, kw: &Line, data: &[Line]) -> Result<(), MeshError> {
        let (name, params) = keyword(&kw.text);
        // Most blocks ignore blank lines; *SPRING of SPRINGA needs its (possibly blank) first line.
        let nonblank: Vec<&Line> = data.iter().filter(|l| !l.text.is_empty()).collect();
        // Every block reads its fields by position: a line of separators only has none.
        if let Some(l) = nonblank.iter().find(|l| fields(&l.text).next().is_none()) {
            return Err(
                self.syntax(l, format!("a *{name} data line with no value (only commas): expected values or no line"))
            );
        }
        let param = |k: &str| params.get(k).map(|s| s.as_str());
        let required = |k: &str| {
            params.get(k).map(|s| s.as_str()).ok_or_else(|| self.syntax(kw, format!("*{name} needs {k}=...")))
        };
        match name.as_str() {
            "NODE" => {
                let mut added = Vec::with_capacity(nonblank.len());
                for l in &nonblank {
                    let f: Vec<&str> = fields(&l.text).collect();
                    if f.len() < 2 || f.len() > 4 {
                        return Err(self.syntax(l, "expected a node line: id, x, y, z"));
                    }
                    let id = self.num::<u64>(l, f[0], "a node id")?;
                    let mut xyz = [0.0; 3];
                    for k in 1..f.len() {
                        xyz[k - 1] = self.float(l, f[k], "a coordinate")?;
                    }
                    let n = self
                        .mesh
                        .add_node(id, xyz)
                        .map_err(|node| MeshError::DuplicateNode { at: self.at(l), node })?;
                    added.push(n);
                }
                if let Some(set) = param("NSET") {
                    self.mesh.add_node_set(set, added);
                }
            }
            "ELEMENT" => self.elements(kw, &nonblank, required("TYPE")?, param("ELSET"))?,
            "NSET" => {
                let set = required("NSET")?.to_string();
                let what = format!("*NSET NSET={set}");
                let mut nodes = Vec::new();
                if params.contains_key("ELSET") {
                    return Err(self.syntax(kw, "*NSET with ELSET= is not supported; list the nodes"));
                }
                for l in &nonblank {
                    if params.contains_key("GENERATE") {
                        for id in self.generate(l)? {
                            nodes.push(self.node_ref(l, id, &what)?);
                        }
                    } else {
                        for f in fields(&l.text) {
                            nodes.extend(self.nodes_of(l, f, &what)?);
                        }
                    }
                }
                self.mesh.add_node_set(&set, nodes);
            }
            "ELSET" => {
                let set = required("ELSET")?.to_uppercase();
                let what = format!("*ELSET ELSET={set}");
                let mut members = Vec::new();
                for l in &nonblank {
                    let ids: Vec<Result<u64, String>> = if params.contains_key("GENERATE") {
                        self.generate(l)?.into_iter().map(Ok).collect()
                    } else {
                        fields(&l.text).map(|f| f.parse::<u64>().map_err(|_| f.to_string())).collect()
                    };
                    for id in ids {
                        match id {
                            Ok(id) => members.push(*self.element_ids.get(&id).ok_or_else(|| {
                                MeshError::UndefinedElement { at: self.at(l), what: what.clone(), element: id }
                            })?),
                            Err(name) => members.extend(self.elsets.get(&name.to_uppercase()).ok_or_else(|| {
                                MeshError::UndefinedSet { at: self.at(l), what: what.clone(), set: name.clone() }
                            })?),
                        }
                    }
                }
                self.elsets.entry(set).or_default().extend(members);
            }
            "MATERIAL" => {
                let mname = required("NAME")?.to_uppercase();
                let idx = match self.mesh.material(&mname) {
                    Some(i) => i,
                    None => {
                        let m = Material { young: f64::NAN, poisson: f64::NAN, density: f64::NAN };
                        self.mesh.materials.push((mname, m));
                        self.material_at.push(self.at(kw));
                        self.mesh.materials.len() - 1
                    }
                };
                self.current_material = Some(idx);
            }
            "ELASTIC" => {
                let m = self.current_material.ok_or_else(|| self.syntax(kw, "*ELASTIC outside a *MATERIAL"))?;
                if let Some(t) = param("TYPE") {
                    if !t.eq_ignore_ascii_case("ISO") {
                        return Err(self.syntax(kw, format!("*ELASTIC TYPE={t} is not supported (isotropic only)")));
                    }
                }
                let l = nonblank.first().ok_or_else(|| self.syntax(kw, "*ELASTIC needs a line: E, nu"))?;
                let f: Vec<&str> = fields(&l.text).collect();
                if f.len() < 2 || f.len() > 3 {
                    return Err(self.syntax(l, "expected E, nu (isotropic, no temperature dependence)"));
                }
                if nonblank.len() > 1 {
                    return Err(self.syntax(nonblank[1], "temperature-dependent *ELASTIC is not supported"));
                }
                let e = self.float(l, f[0], "Young's modulus")?;
                let nu = self.float(l, f[1], "Poisson's ratio")?;
                // Written so that NaN fails too.
                if !(e > 0.0 && -1.0 < nu && nu < 0.5) {
                    return Err(self.syntax(l, format!("need E > 0 and -1 < nu < 0.5, got E = {e}, nu = {nu}")));
                }
                self.mesh.materials[m].1.young = e;
                self.mesh.materials[m].1.poisson = nu;
            }
            "DENSITY" => {
                let m = self.current_material.ok_or_else(|| self.syntax(kw, "*DENSITY outside a *MATERIAL"))?;
                let l = nonblank.first().ok_or_else(|| self.syntax(kw, "*DENSITY needs a line: rho"))?;
                let f: Vec<&str> = fields(&l.text).collect();
                let rho = self.float(l, f.first().copied().unwrap_or(""), "a density")?;
                if rho.is_nan() || rho <= 0.0 {
                    return Err(self.syntax(l, format!("need a density > 0, got {rho}")));
                }
                self.mesh.materials[m].1.density = rho;
            }
            "SOLID SECTION" => {
                let elset = required("ELSET")?.to_uppercase();
                let material = required("MATERIAL")?.to_uppercase();
                if !self.elsets.contains_key(&elset) {
                    return Err(MeshError::UndefinedSet { at: self.at(kw), what: "*SOLID SECTION".into(), set: elset });
                }
                self.sections.push(Section { elset, material, at: self.at(kw) });
            }
            "BOUNDARY" => {
                for l in &nonblank {
                    let f: Vec<&str> = fields(&l.text).collect();
                    if f.len() < 2 {
                        return Err(self.syntax(l, "expected node or set, first DOF[, last DOF[, value]]"));
                    }
                    let nodes = self.nodes_of(l, f[0], "*BOUNDARY")?;
                    let first = self.dof(l, f[1])?;
                    let last = if f.len() > 2 { self.dof(l, f[2])? } else { first };
                    if f.len() > 3 && self.float(l, f[3], "a prescribed value")? != 0.0 {
                        return Err(
                            self.syntax(l, "only homogeneous *BOUNDARY (value 0) is supported in a modal model")
                        );
                    }
                    for n in nodes {
                        for d in first..=last {
                            self.mesh.fixed.push((n, d));
                        }
                    }
                }
            }
            "EQUATION" => {
                let mut k = 0;
                while k < nonblank.len() {
                    let l = nonblank[k];
                    let nterms: usize = self.num(l, fields(&l.text).next().unwrap_or(""), "the number of terms")?;
                    if nterms < 1 {
                        return Err(self.syntax(l, "an *EQUATION needs at least one term"));
                    }
                    let mut terms = Vec::with_capacity(nterms);
                    k += 1;
                    while terms.len() < nterms {
                        let l =
                            nonblank.get(k).ok_or_else(|| self.syntax(kw, "*EQUATION: fewer terms than announced"))?;
                        let f: Vec<&str> = fields(&l.text).collect();
                        if !f.len().is_multiple_of(3) || f.is_empty() {
                            return Err(self.syntax(l, "expected terms node, DOF, coefficient"));
                        }
                        for t in f.chunks(3) {
                            let id = self.num::<u64>(l, t[0], "a node id")?;
                            let node = self.node_ref(l, id, "*EQUATION")?;
                            let d = self.dof(l, t[1])?;
                            let c = self.float(l, t[2], "a coefficient")?;
                            terms.push((node, d, c));
                        }
                        k += 1;
                    }
                    if terms.len() != nterms {
                        return Err(self.syntax(l, format!("*EQUATION announced {nterms} terms, got {}", terms.len())));
                    }
                    if terms[0].2 == 0.0 {
                        return Err(self.syntax(l, "the first coefficient of an *EQUATION (its dependent DOF) is zero"));
                    }
                    self.mesh.equations.push(Equation { terms, at: self.at(l) });
                }
            }
            "MASS" => {
                let elset = required("ELSET")?.to_uppercase();
                let l = nonblank.first().ok_or_else(|| self.syntax(kw, "*MASS needs a line: mass"))?;
                let m = self.float(l, fields(&l.text).next().unwrap_or(""), "a mass")?;
                for p in self.points_of(kw, &elset, "*MASS")? {
                    if self.pending_points[p].kind != PointKind::Mass {
                        let id = self.pending_points[p].id;
                        return Err(self.syntax(kw, format!("*MASS on element {id} which is not a MASS element")));
                    }
                    let pp = &mut self.pending_points[p];
                    pp.done = true;
                    let (id, node) = (pp.id, pp.nodes[0]);
                    self.mesh.points.push(PointElement::Mass { id, node, mass: m });
                }
            }
            "SPRING" => {
                if params.contains_key("NONLINEAR") {
                    return Err(self.syntax(kw, "*SPRING, NONLINEAR is not supported (linear springs only)"));
                }
                let elset = required("ELSET")?.to_uppercase();
                for p in self.points_of(kw, &elset, "*SPRING")? {
                    let (id, kind, nodes) = {
                        let pp = &self.pending_points[p];
                        (pp.id, pp.kind, pp.nodes.clone())
                    };
                    let card: Vec<&Line> = match kind {
                        PointKind::SpringA => data.iter().filter(|l| !l.text.is_empty()).collect(),
                        _ => nonblank.clone(),
                    };
                    let stiff_line = *card.last().ok_or_else(|| self.syntax(kw, "*SPRING needs its stiffness line"))?;
                    let k = self.float(stiff_line, fields(&stiff_line.text).next().unwrap_or(""), "a stiffness")?;
                    let dof_line = || {
                        if card.len() < 2 {
                            Err(self.syntax(kw, "*SPRING for SPRING1/SPRING2 needs a DOF line, then the stiffness"))
                        } else {
                            Ok(card[0])
                        }
                    };
                    let point = match kind {
                        PointKind::Spring1 => {
                            let l = dof_line()?;
                            let d = self.dof(l, fields(&l.text).next().unwrap_or(""))?;
                            PointElement::Spring { id, a: nodes[0], dir_a: d, b: None, stiffness: k }
                        }
                        PointKind::Spring2 => {
                            let l = dof_line()?;
                            let f: Vec<&str> = fields(&l.text).collect();
                            if f.len() < 2 {
                                return Err(self.syntax(l, "SPRING2 needs two DOFs: first node's, second node's"));
                            }
                            let (da, db) = (self.dof(l, f[0])?, self.dof(l, f[1])?);
                            PointElement::Spring { id, a: nodes[0], dir_a: da, b: Some((nodes[1], db)), stiffness: k }
                        }
                        PointKind::SpringA => PointElement::AxialSpring { id, a: nodes[0], b: nodes[1], stiffness: k },
                        PointKind::Mass => {
                            return Err(self.syntax(kw, format!("*SPRING on element {id} which is a MASS element")))
                        }
                    };
                    self.pending_points[p].done = true;
                    self.mesh.points.push(point);
                }
            }
            "SURFACE" => {
                let sname = required("NAME")?.to_uppercase();
                let node_type = param("TYPE").map(|t| t.eq_ignore_ascii_case("NODE")).unwrap_or(false);
                let mut nodes = Vec::new();
                for l in &nonblank {
                    let f: Vec<&str> = fields(&l.text).collect();
                    if node_type {
                        nodes.extend(self.nodes_of(l, f[0], &format!("*SURFACE NAME={sname}"))?);
                    } else {
                        if f.len() < 2 {
                            return Err(self.syntax(l, "expected element or element set, face (S1..S6)"));
                        }
                        nodes.extend(self.face_nodes(l, f[0], f[1], &sname)?);
                    }
                }
                nodes.sort_unstable();
                nodes.dedup();
                self.surfaces.insert(sname, nodes);
            }
            "KINEMATIC COUPLING" | "RIGID BODY" => {
                let (rid, what) = (required("REF NODE")?, format!("*{name}"));
                let rid = self.num::<u64>(kw, rid, "a reference node id")?;
                let reference = self.node_ref(kw, rid, &what)?;
                if name == "RIGID BODY" {
                    let set = required("NSET")?;
                    let nodes = self.nodes_of(kw, set, &what)?;
                    if let Some(rot) = param("ROT NODE") {
                        let rot = self.num::<u64>(kw, rot, "a rotation node id")?;
                        let rot = self.node_ref(kw, rot, "*RIGID BODY, ROT NODE=")?;
                        self.rotation_node(kw, rot, reference)?;
                    }
                    self.mesh.couplings.push(RigidCoupling {
                        reference,
                        nodes,
                        dofs: (1..=6).collect(),
                        at: self.at(kw),
                    });
                } else {
                    for l in &nonblank {
                        let f: Vec<&str> = fields(&l.text).collect();
                        let nodes = self.nodes_of(l, f[0], &what)?;
                        let dofs = self.dof_range(l, &f[1..])?;
                        self.mesh.couplings.push(RigidCoupling { reference, nodes, dofs, at: self.at(l) });
                    }
                }
            }
            "COUPLING" => {
                let rid = self.num::<u64>(kw, required("REF NODE")?, "a reference node id")?;
                let reference = self.node_ref(kw, rid, "*COUPLING")?;
                let surf = required("SURFACE")?.to_uppercase();
                let nodes = self.surfaces.get(&surf).cloned().ok_or_else(|| MeshError::UndefinedSet {
                    at: self.at(kw),
                    what: "*COUPLING".into(),
                    set: surf.clone(),
                })?;
                self.coupling = Some((reference, nodes, self.at(kw)));
            }
            "KINEMATIC" => {
                let (reference, nodes, at) =
                    self.coupling.take().ok_or_else(|| self.syntax(kw, "*KINEMATIC must follow a *COUPLING"))?;
                let mut dofs = Vec::new();
                for l in &nonblank {
                    let f: Vec<&str> = fields(&l.text).collect();
                    dofs.extend(self.dof_range(l, &f)?);
                }
                if nonblank.is_empty() {
                    dofs = (1..=6).collect();
                }
                dofs.sort_unstable();
                dofs.dedup();
                self.mesh.couplings.push(RigidCoupling { reference, nodes, dofs, at });
            }
            "DISTRIBUTING" => {
                return Err(self.syntax(kw, "*DISTRIBUTING coupling is not supported (use *KINEMATIC)"));
            }
            "STEP" => {}
            "FREQUENCY" => {
                if let Some(l) = nonblank.first() {
                    let f = fields(&l.text).next().unwrap_or("");
                    self.mesh.modes_requested = Some(self.num(l, f, "the number of modes")?);
                } else {
                    return Err(self.syntax(kw, "*FREQUENCY needs a line with the number of modes"));
                }
            }
            k if IGNORED.contains(&k) => {}
            _ => return Err(MeshError::UnknownKeyword { at: self.at(kw), keyword: name.clone() }),
        }
        Ok(())
    }

    /// Record `rot` as the rotation node of `reference` (one rotation node per reference; a
    /// reference may head several rigid bodies with the same one).
    fn rotation_node(&mut self, kw: &Line, rot: usize, reference: usize) -> Result<(), MeshError> {
        let id = |n: usize| self.mesh.nodes[n].id;
        if rot == reference {
            return Err(self.syntax(kw, format!("ROT NODE={} is the REF NODE: expected a node of its own", id(rot))));
        }
        if let Some((&other, _)) = self.rotation_nodes.iter().find(|(&r, (f, _))| *f == reference && r != rot) {
            return Err(self.syntax(
                kw,
                format!(
                    "REF NODE={} already has ROT NODE={}: expected the same rotation node",
                    id(reference),
                    id(other)
                ),
            ));
        }
        if self.rotation_nodes.contains_key(&reference) {
            return Err(self.syntax(kw, format!("REF NODE={} is another rigid body's ROT NODE", id(reference))));
        }
        match self.rotation_nodes.get(&rot) {
            Some((r, _)) if *r != reference => {
                Err(self
                    .syntax(kw, format!("ROT NODE={} already carries the rotations of REF NODE={}", id(rot), id(*r))))
            }
            _ => {
                self.rotation_nodes.insert(rot, (reference, self.at(kw)));
                Ok(())
            }
        }
    }

    /// Move what acts on rotation nodes' translations to their references' rotations (DOF
    /// d → d + 3), then drop the rotation nodes. A rotation node takes springs, boundary
    /// conditions and equation terms on DOFs 1-3 only: anything else on it (a solid, a mass, an
    /// axial spring, a coupling, a rotation DOF) has no meaning and is an error.
    fn resolve_rotation_nodes(&mut self) -> Result<(), MeshError> {
        if self.rotation_nodes.is_empty() {
            return Ok(());
        }
        let rot = &self.rotation_nodes;
        let nodes = &self.mesh.nodes;
        let misuse = |n: usize, what: String| {
            let (r, at) = &rot[&n];
            MeshError::Syntax {
                at: at.clone(),
                msg: format!(
                    "{what} node {}, the ROT NODE of REF NODE={}: a rotation node takes only springs, \
                     *BOUNDARY and *EQUATION terms on its DOFs 1-3 (the reference's rotations)",
                    nodes[n].id, nodes[*r].id
                ),
            }
        };
        let map = |n: usize, d: u8, what: &dyn Fn() -> String| -> Result<(usize, u8), MeshError> {
            match rot.get(&n) {
                None => Ok((n, d)),
                Some(&(r, _)) if d <= 3 => Ok((r, d + 3)),
                Some(_) => Err(misuse(n, format!("{} acts on DOF {d} of", what()))),
            }
        };
        if let Some(s) = self.mesh.solids.iter().find(|s| s.nodes.iter().any(|n| rot.contains_key(n))) {
            let n = *s.nodes.iter().find(|n| rot.contains_key(n)).expect("found above");
            return Err(misuse(n, format!("solid element {} uses", s.id)));
        }
        for p in &mut self.mesh.points {
            match p {
                PointElement::Spring { id, a, dir_a, b, .. } => {
                    let what = || format!("spring element {id}");
                    (*a, *dir_a) = map(*a, *dir_a, &what)?;
                    if let Some((b, db)) = b {
                        (*b, *db) = map(*b, *db, &what)?;
                    }
                }
                PointElement::Mass { id, node: n, .. } if rot.contains_key(n) => {
                    return Err(misuse(*n, format!("mass element {id} is on")))
                }
                PointElement::AxialSpring { id, a, b, .. } => {
                    if let Some(n) = [*a, *b].into_iter().find(|n| rot.contains_key(n)) {
                        return Err(misuse(n, format!("SPRINGA element {id} uses")));
                    }
                }
                _ => {}
            }
        }
        for (n, d) in &mut self.mesh.fixed {
            (*n, *d) = map(*n, *d, &|| "*BOUNDARY".to_string())?;
        }
        for e in &mut self.mesh.equations {
            let at = e.at.clone();
            for (n, d, _) in &mut e.terms {
                (*n, *d) = map(*n, *d, &|| format!("the *EQUATION at {at}"))?;
            }
        }
        for c in &self.mesh.couplings {
            if let Some(n) = std::iter::once(&c.reference).chain(&c.nodes).find(|n| rot.contains_key(n)) {
                return Err(misuse(*n, format!("the coupling at {} uses", c.at)));
            }
        }
        let mut drop = vec![false; self.mesh.nodes.len()];
        for &n in self.rotation_nodes.keys() {
            drop[n] = true;
        }
        self.mesh.remove_nodes(&drop);
        Ok(())
    }

    fn dof(&self, l: &Line, f: &str) -> Result<u8, MeshError> {
        match f.parse::<u8>() {
            Ok(d @ 1..=6) => Ok(d),
            _ => Err(self.syntax(l, format!("expected a DOF 1..6, got {f:?}"))),
        }
    }

    /// `first[, last]` DOF range; all six when empty.
    fn dof_range(&self, l: &Line, f: &[&str]) -> Result<Vec<u8>, MeshError> {
        Ok(match f {
            [] => (1..=6).collect(),
            [a] => {
                let a = self.dof(l, a)?;
                vec![a]
            }
            [a, b, ..] => (self.dof(l, a)?..=self.dof(l, b)?).collect(),
        })
    }

    fn generate(&self, l: &Line) -> Result<Vec<u64>, MeshError> {
        let f: Vec<&str> = fields(&l.text).collect();
        if f.len() < 2 || f.len() > 3 {
            return Err(self.syntax(l, "GENERATE expects first, last[, increment]"));
        }
        let a: u64 = self.num(l, f[0], "a first id")?;
        let b: u64 = self.num(l, f[1], "a last id")?;
        let s: u64 = if f.len() == 3 { self.num(l, f[2], "an increment")? } else { 1 };
        if s == 0 || b < a {
            return Err(self.syntax(l, "GENERATE needs first <= last and increment >= 1"));
        }
        // The ids are materialised: a range from the file is bounded before it is collected
        // (a fuzzed `1, 1000000000000000000` aborted on the allocation).
        let count = (b - a) / s + 1;
        if count > MAX_GENERATED {
            return Err(self.syntax(
                l,
                format!("GENERATE of {count} ids exceeds the limit of {MAX_GENERATED} ids per line (check first, last, increment)"),
            ));
        }
        Ok((a..=b).step_by(usize::try_from(s).unwrap_or(usize::MAX)).collect())
    }

    fn elements(&mut self, kw: &Line, data: &[&Line], kind: &str, elset: Option<&str>) -> Result<(), MeshError> {
        let solid = SolidKind::from_abaqus(kind);
        let point = match kind.to_uppercase().as_str() {
            "MASS" => Some((PointKind::Mass, 1)),
            "SPRING1" => Some((PointKind::Spring1, 1)),
            "SPRING2" => Some((PointKind::Spring2, 2)),
            "SPRINGA" => Some((PointKind::SpringA, 2)),
            _ => None,
        };
        let n_nodes = match (solid, point) {
            (Some(s), _) => s.n_nodes(),
            (None, Some((_, n))) => n,
            _ => return Err(MeshError::UnsupportedElement { at: self.at(kw), kind: kind.to_string() }),
        };
        let mut refs = Vec::with_capacity(data.len());
        let mut k = 0;
        while k < data.len() {
            // An element's node list may continue on the following lines.
            let first = data[k];
            let mut f: Vec<&str> = fields(&first.text).collect();
            while f.len() < n_nodes + 1 && data[k].text.ends_with(',') && k + 1 < data.len() {
                k += 1;
                f.extend(fields(&data[k].text));
            }
            k += 1;
            let id = self.num::<u64>(first, f[0], "an element id")?;
            if f.len() != n_nodes + 1 {
                return Err(MeshError::WrongNodeCount {
                    at: self.at(first),
                    element: id,
                    kind: kind.to_uppercase(),
                    got: f.len() - 1,
                    expected: n_nodes,
                });
            }
            let what = format!("element {id}");
            let mut nodes = Vec::with_capacity(n_nodes);
            for x in &f[1..] {
                let nid = self.num::<u64>(first, x, "a node id")?;
                nodes.push(self.node_ref(first, nid, &what)?);
            }
            let r = match (solid, point) {
                (Some(kind), _) => {
                    self.mesh.solids.push(Solid { id, kind, nodes, material: None });
                    ElemRef::Solid(self.mesh.solids.len() - 1)
                }
                (None, Some((kind, _))) => {
                    self.pending_points.push(PendingPoint { id, kind, nodes, done: false, at: self.at(first) });
                    ElemRef::Point(self.pending_points.len() - 1)
                }
                _ => unreachable!(),
            };
            if self.element_ids.insert(id, r).is_some() {
                return Err(MeshError::DuplicateElement { at: self.at(first), element: id });
            }
            refs.push(r);
        }
        if let Some(set) = elset {
            self.elsets.entry(set.to_uppercase()).or_default().extend(refs);
        }
        Ok(())
    }

    /// Point elements of an element set (for `*MASS`, `*SPRING`).
    fn points_of(&self, kw: &Line, elset: &str, what: &str) -> Result<Vec<usize>, MeshError> {
        let set = self.elsets.get(elset).ok_or_else(|| MeshError::UndefinedSet {
            at: self.at(kw),
            what: what.into(),
            set: elset.into(),
        })?;
        set.iter()
            .map(|r| match *r {
                ElemRef::Point(p) => Ok(p),
                ElemRef::Solid(s) => Err(self.syntax(
                    kw,
                    format!("{what} on element set {elset} which contains solid element {}", self.mesh.solids[s].id),
                )),
            })
            .collect()
    }

    /// Nodes of face `face` (S1..S6) of an element or of every element of a set.
    fn face_nodes(&self, l: &Line, elems: &str, face: &str, surface: &str) -> Result<Vec<usize>, MeshError> {
        let what = format!("*SURFACE NAME={surface}");
        let refs: Vec<ElemRef> = match elems.parse::<u64>() {
            Ok(id) => vec![*self.element_ids.get(&id).ok_or_else(|| MeshError::UndefinedElement {
                at: self.at(l),
                what: what.clone(),
                element: id,
            })?],
            Err(_) => self.elsets.get(&elems.to_uppercase()).cloned().ok_or_else(|| MeshError::UndefinedSet {
                at: self.at(l),
                what: what.clone(),
                set: elems.into(),
            })?,
        };
        let face_no = match face.to_uppercase().strip_prefix('S').and_then(|s| s.parse::<usize>().ok()) {
            Some(f @ 1..=6) => f,
            _ => return Err(self.syntax(l, format!("expected a face S1..S6, got {face:?}"))),
        };
        let mut out = Vec::new();
        for r in refs {
            let ElemRef::Solid(s) = r else { continue };
            let s = &self.mesh.solids[s];
            let local = face_local_nodes(s.kind, face_no).ok_or_else(|| {
                self.syntax(l, format!("element {} ({}) has no face S{face_no}", s.id, s.kind.abaqus_name()))
            })?;
            out.extend(local.into_iter().map(|a| s.nodes[a]));
        }
        Ok(out)
    }

    fn finish(mut self) -> Result<Mesh, MeshError> {
        for (i, (name, m)) in self.mesh.materials.iter().enumerate() {
            let at = self.material_at[i].clone();
            if m.young.is_nan() {
                return Err(MeshError::IncompleteMaterial { at, material: name.clone(), what: "*ELASTIC".into() });
            }
            if m.density.is_nan() {
                return Err(MeshError::IncompleteMaterial {
                    at,
                    material: name.clone(),
                    what: "*DENSITY (a modal model needs mass)".into(),
                });
            }
        }
        for s in &self.sections {
            let m = self.mesh.material(&s.material).ok_or_else(|| MeshError::MissingMaterial {
                at: s.at.clone(),
                elset: s.elset.clone(),
                material: s.material.clone(),
            })?;
            for r in &self.elsets[&s.elset] {
                if let ElemRef::Solid(e) = *r {
                    self.mesh.solids[e].material = Some(m);
                }
            }
        }
        for s in &self.mesh.solids {
            if s.material.is_none() {
                return Err(MeshError::NoSection { element: s.id, kind: s.kind.abaqus_name().into() });
            }
        }
        if let Some(p) = self.pending_points.iter().find(|p| !p.done) {
            let elset = self
                .elsets
                .iter()
                .find(|(_, v)| v.iter().any(|r| matches!(r, ElemRef::Point(q) if self.pending_points[*q].id == p.id)))
                .map(|(k, _)| k.clone())
                .unwrap_or_default();
            return Err(MeshError::NoProperty { at: p.at.clone(), what: format!("element {}:", p.id), elset });
        }
        for (name, refs) in &self.elsets {
            let solids: Vec<usize> =
                refs.iter().filter_map(|r| if let ElemRef::Solid(s) = r { Some(*s) } else { None }).collect();
            self.mesh.element_sets.insert(name.clone(), solids);
        }
        for (name, nodes) in std::mem::take(&mut self.surfaces) {
            self.mesh.node_sets.entry(name).or_insert(nodes);
        }
        self.resolve_rotation_nodes()?;
        Ok(self.mesh)
    }
}

/// Local node indices of Abaqus face `face` (1..=6) of a solid: its corners, then the
/// mid-edge nodes whose two corners are on the face.
pub fn face_local_nodes(kind: SolidKind, face: usize) -> Option<Vec<usize>> {
    use crate::element::shape::{HEX20_EDGES, TET10_EDGES};
    const TET: [[usize; 3]; 4] = [[0, 1, 2], [0, 3, 1], [1, 3, 2], [2, 3, 0]];
    const HEX: [[usize; 4]; 6] = [[0, 1, 2, 3], [4, 7, 6, 5], [0, 4, 5, 1], [1, 5, 6, 2], [2, 6, 7, 3], [3, 7, 4, 0]];
    let corners: Vec<usize> = if kind.is_tet() { TET.get(face - 1)?.to_vec() } else { HEX.get(face - 1)?.to_vec() };
    let mut out = corners.clone();
    let edges: &[(usize, usize)] = match kind {
        SolidKind::Tet10 => &TET10_EDGES,
        SolidKind::Hex20 | SolidKind::Hex20R => &HEX20_EDGES,
        _ => &[],
    };
    let first_mid = kind.n_corners();
    for (e, &(a, b)) in edges.iter().enumerate() {
        if corners.contains(&a) && corners.contains(&b) {
            out.push(first_mid + e);
        }
    }
    Some(out)
}
