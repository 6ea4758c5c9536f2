//! Abaqus/CalculiX `.inp` decks from a [`Mesh`]: a complete modal deck that CalculiX runs and
//! that [`super::inp::read`] reads back to the same model (same nodes in the same order, same
//! solids, materials, sets, point elements, constraints, hence the same K, M and DOF labels).
//!
//! The deck holds, in this order: `*NODE`; one `*ELEMENT` block per run of consecutive solids
//! of one kind (C3D4, C3D10, C3D8, C3D20, C3D20R) with an element set per kind; `*NSET` and
//! `*ELSET` for every set (16 ids a line); `*MATERIAL` with `*ELASTIC` and `*DENSITY` for every
//! material and one `*SOLID SECTION` per material the solids use (on an existing element set
//! holding exactly that material's solids, else on a new one); the point elements, each in its
//! own element set since a `*MASS`/`*SPRING` card gives one value per set (`MASS` + `*MASS`,
//! `SPRING1`/`SPRING2` + `*SPRING`, `SPRINGA`, and a connector as one `SPRING2` per nonzero
//! component with DOF pair d,d, or `SPRING1` when grounded); `*BOUNDARY` (consecutive DOFs of a
//! node as ranges); the rigid couplings; `*EQUATION`; and a `*STEP` with `*FREQUENCY`
//! ([`Mesh::modes_requested`], or 10).
//!
//! Rigid couplings are written as CalculiX and Abaqus both read them: `*SURFACE, TYPE=NODE` on
//! the slave nodes, `*COUPLING, REF NODE=, SURFACE=, CONSTRAINT NAME=` and `*KINEMATIC` with the
//! coupled translations as DOF ranges (CalculiX's `*KINEMATIC` takes DOFs 1–3 only; the coupled
//! translations still follow the reference node's rotations). Coupled rotations matter only for
//! slave nodes that carry rotations (see [`super::RigidCoupling`]); for those they are written
//! as `*EQUATION`s `θ_s − θ_r = 0`, which eliminate the same DOFs.
//!
//! A reference node whose rotations something else names (a rotational spring or connector
//! component, a fixed rotation, an equation term: the screws' moment stiffness and the shaker's
//! held rotations of the Harmony model) is written as CalculiX honours it, provided its couplings
//! all tie the three translations: `*RIGID BODY, NSET=, REF NODE=, ROT NODE=` on the union of
//! their slave nodes, with a new rotation node (at the reference's position, ids above every node
//! id) whose DOFs 1–3 stand for the reference's rotations 4–6 in every spring, `*BOUNDARY` and
//! `*EQUATION` of the deck. A rigid body also ties the rotations of slaves that carry them (as
//! Abaqus and the stickslip reader take it), so such couplings are written this way only when
//! they tie those rotations too. The reader maps the rotation nodes back and drops them, so the
//! round trip still gives the same model.
//!
//! Numbers: CalculiX reads the first 20 characters of a numeric field (Fortran `f20.0`) and
//! takes a stiffness line under `*SPRING` without a decimal point for a DOF line, so every real
//! is written with a decimal point in at most 20 characters ([`format_real`]). It keeps the
//! shortest digits that read back to the same `f64` (Rust's shortest round-trip formatting), so
//! that the read-back is bit-identical, whenever they fit: always for up to 15 significant
//! digits (with a two-digit exponent at most), and for 16 or 17 digits down to magnitudes of
//! about 1e-3 (1e-2 for negative numbers). Smaller 16–17-digit numbers, such as the round-off
//! coordinates mesh generators leave near zero, are rounded to as many digits as fit: at least
//! 15 between 1e-10 and 1e19 and 14 between 1e-99 and 1e99 (relative changes below 5e-15 and
//! 5e-14).
//!
//! CalculiX 2.20 runs the decks of meshes whose springs, connectors and equations act on
//! translations (checked by hand on the rewritten reference decks of `crates/fe/reference/`:
//! the same frequencies as the original decks) or on the rotations of references written as
//! rigid bodies (the Harmony deck, `crates/fe/reference/harmony_coarse.freq`). Other nodes have
//! no rotations there: springs, connector components and equations on their DOFs 4–6 are
//! written as Abaqus and the stickslip reader take them (with a comment in the deck saying so),
//! and CalculiX ignores or rejects them.
//!
//! The deck adds sets of its own, named so as not to collide with the mesh's: one element set
//! per solid kind (`C3D8`, ...), one per material when no existing set fits (`SOLIDS_<name>`),
//! one per point element (`MASS_<id>`, `SPRING_<id>`, `SPRINGA_<id>`, `CONNECTOR_<id>_<dof>`)
//! and a node set per coupling or rigid body whose slaves match no node set (`COUPLING_<n>`); reading the deck
//! back gives the mesh's sets plus these. Point element ids are kept unless one collides with a
//! solid id or another point element's id: then all point elements are numbered from the
//! largest solid id + 1. Connector components after the first take new ids above every id.
//! Names of sets and materials must be at most 80 characters of printable ASCII without blanks,
//! commas, `=`, `*` or quotes.

use std::collections::{BTreeSet, HashSet};
use std::fmt::Write as _;
use std::path::Path;

use super::{Mesh, MeshError, Origin, PointElement};

/// Width of a numeric field as CalculiX reads it (Fortran `f20.0`): longer fields are cut.
pub const FIELD_WIDTH: usize = 20;

/// Ids or numbers on a data line, at most (the Abaqus limit).
const PER_LINE: usize = 16;

/// Longest set or material name CalculiX accepts.
const MAX_NAME: usize = 80;

/// Write `mesh` as a deck to the file `path`. Nothing is written if the mesh cannot be
/// expressed as a deck (a solid without material, a name that cannot be written, ...).
pub fn write(mesh: &Mesh, path: impl AsRef<Path>) -> Result<(), MeshError> {
    super::write_text(path.as_ref(), &to_string(mesh)?)
}

/// The deck for `mesh`.
pub fn to_string(mesh: &Mesh) -> Result<String, MeshError> {
    check(mesh)?;
    let mut deck = Deck {
        mesh,
        out: String::new(),
        names: Names::new(mesh),
        equations: Vec::new(),
        rotation_nodes: rotation_nodes(mesh),
    };
    deck.header();
    deck.nodes();
    let kind_sets = deck.solids();
    deck.sets();
    deck.materials(&kind_sets);
    deck.points();
    deck.boundaries();
    deck.couplings();
    deck.equations();
    deck.step();
    Ok(deck.out)
}

/// `x` with a decimal point in at most [`FIELD_WIDTH`] characters: the shortest round-trip
/// digits when they fit (then it parses back to exactly `x`), else `x` rounded to the most
/// digits that fit. Non-finite values are written as Rust does (`NaN`, `inf`).
pub fn format_real(x: f64) -> String {
    if !x.is_finite() {
        return format!("{x:?}");
    }
    let (neg, digits, exp) = decompose(&format!("{x:e}"));
    let readable = readable(neg, &digits, exp);
    if readable.len() <= FIELD_WIDTH {
        return readable;
    }
    let shortest = compact(neg, &digits, exp);
    if shortest.len() <= FIELD_WIDTH {
        return shortest;
    }
    // No exact form fits: round to fewer significant digits until one does (one always does).
    for n in (1..digits.len()).rev() {
        let (neg, digits, exp) = decompose(&format!("{:.*e}", n - 1, x));
        let s = compact(neg, digits.trim_end_matches('0'), exp);
        if s.len() <= FIELD_WIDTH {
            return s;
        }
    }
    unreachable!("one significant digit always fits in {FIELD_WIDTH} characters")
}

/// Sign, significant digits (no leading zero unless the value is zero) and decimal exponent of
/// the digits' first digit, from Rust's `{:e}` output (`-1.25e-3` → (true, "125", -3)).
fn decompose(s: &str) -> (bool, String, i32) {
    let (mantissa, exp) = s.split_once('e').expect("{:e} output has an exponent");
    let neg = mantissa.starts_with('-');
    let digits: String = mantissa.chars().filter(char::is_ascii_digit).collect();
    let digits = match digits.trim_end_matches('0') {
        "" => "0".to_string(),
        d => d.to_string(),
    };
    (neg, digits, exp.parse().expect("{:e} exponent is an integer"))
}

/// `0.075`, `7800.0`, `2.1e11`, `1.0e-5`: plain between 1e-4 and 1e7, else scientific.
fn readable(neg: bool, digits: &str, exp: i32) -> String {
    let sign = if neg { "-" } else { "" };
    if (-4..7).contains(&exp) {
        if exp >= 0 {
            let int_len = exp as usize + 1;
            if digits.len() <= int_len {
                format!("{sign}{digits}{}.0", "0".repeat(int_len - digits.len()))
            } else {
                format!("{sign}{}.{}", &digits[..int_len], &digits[int_len..])
            }
        } else {
            format!("{sign}0.{}{digits}", "0".repeat((-exp - 1) as usize))
        }
    } else {
        let rest = if digits.len() > 1 { &digits[1..] } else { "0" };
        format!("{sign}{}.{rest}e{exp}", &digits[..1])
    }
}

/// The shortest string with a decimal point that denotes exactly the decimal `d.ddd × 10^exp`
/// (`digits` = "dddd"): the point placed anywhere in the digits (or before them after leading
/// zeros, or after them after trailing zeros), with an exponent if needed.
fn compact(neg: bool, digits: &str, exp: i32) -> String {
    let sign = if neg { "-" } else { "" };
    let n = digits.len() as i32;
    let mut best: Option<String> = None;
    let mut consider = |s: String| {
        if best.as_ref().is_none_or(|b| s.len() < b.len()) {
            best = Some(s);
        }
    };
    // Plain forms: ".00123", "12.3", "12300.".
    if exp < 0 {
        consider(format!("{sign}.{}{digits}", "0".repeat((-exp - 1) as usize)));
    } else if exp + 1 >= n {
        consider(format!("{sign}{digits}{}.", "0".repeat((exp + 1 - n) as usize)));
    } else {
        let k = (exp + 1) as usize;
        consider(format!("{sign}{}.{}", &digits[..k], &digits[k..]));
    }
    // Scientific forms: k digits before the point, exponent exp + 1 − k.
    for k in 0..=digits.len() {
        let e = exp + 1 - k as i32;
        if e != 0 {
            consider(format!("{sign}{}.{}e{e}", &digits[..k], &digits[k..]));
        }
    }
    best.expect("at least one form")
}

/// Reject what a deck cannot express before writing anything.
fn check(mesh: &Mesh) -> Result<(), MeshError> {
    let mut ids = HashSet::with_capacity(mesh.solids.len());
    for s in &mesh.solids {
        if !ids.insert(s.id) {
            return Err(MeshError::DuplicateElement { at: Origin::default(), element: s.id });
        }
        if s.material.is_none_or(|m| m >= mesh.materials.len()) {
            return Err(MeshError::NoSection { element: s.id, kind: s.kind.abaqus_name().into() });
        }
    }
    // A deck holding NaN or inf reads back as nothing a solver can use: refused, named.
    if let Some(n) = super::non_finite_node(&mesh.nodes).map(|i| &mesh.nodes[i]) {
        return Err(unwritable(format!("node {} has coordinates {:?}, not finite", n.id, n.xyz)));
    }
    if let Some((name, m)) =
        mesh.materials.iter().find(|(_, m)| [m.young, m.poisson, m.density].iter().any(|x| !x.is_finite()))
    {
        return Err(unwritable(format!("material {name:?} has {m:?}, not finite")));
    }
    for p in &mesh.points {
        let (id, values): (u64, &[f64]) = match p {
            PointElement::Mass { id, mass, .. } => (*id, std::slice::from_ref(mass)),
            PointElement::Spring { id, stiffness, .. } | PointElement::AxialSpring { id, stiffness, .. } => {
                (*id, std::slice::from_ref(stiffness))
            }
            PointElement::Connector { id, stiffness, .. } => (*id, stiffness),
        };
        if values.iter().any(|x| !x.is_finite()) {
            return Err(unwritable(format!("element {id} has the value(s) {values:?}, not finite")));
        }
    }
    let mut materials = HashSet::new();
    for (name, _) in &mesh.materials {
        check_name("material", name)?;
        if !materials.insert(name.to_uppercase()) {
            return Err(unwritable(format!("two materials are named {name:?} (names are case-insensitive)")));
        }
    }
    for name in mesh.node_sets.keys() {
        check_name("node set", name)?;
    }
    for name in mesh.element_sets.keys() {
        check_name("element set", name)?;
    }
    Ok(())
}

fn unwritable(msg: String) -> MeshError {
    MeshError::Syntax { at: Origin::default(), msg: format!("cannot write the mesh as a deck: {msg}") }
}

fn check_name(what: &str, name: &str) -> Result<(), MeshError> {
    let bad = |c: char| !c.is_ascii_graphic() || matches!(c, ',' | '=' | '*' | '"');
    if name.is_empty() || name.len() > MAX_NAME || name.chars().any(bad) {
        return Err(unwritable(format!(
            "{what} name {name:?} is not 1 to {MAX_NAME} printable ASCII characters without blanks, commas, '=', '*' or quotes"
        )));
    }
    Ok(())
}

/// Names in use (upper case), to give new sets names that collide with none.
struct Names(HashSet<String>);

impl Names {
    fn new(mesh: &Mesh) -> Self {
        let mut taken: HashSet<String> = mesh.node_sets.keys().map(|k| k.to_uppercase()).collect();
        taken.extend(mesh.element_sets.keys().map(|k| k.to_uppercase()));
        Names(taken)
    }

    /// `base` (upper case, shortened to fit), or `base_2`, `base_3`, ... if taken.
    fn unique(&mut self, base: &str) -> String {
        let mut base: String = base
            .to_uppercase()
            .chars()
            .map(|c| if c.is_ascii_graphic() && !",=*\"".contains(c) { c } else { '_' })
            .collect();
        base.truncate(MAX_NAME - 8);
        let mut name = base.clone();
        let mut k = 2;
        while !self.0.insert(name.clone()) {
            name = format!("{base}_{k}");
            k += 1;
        }
        name
    }
}

struct Deck<'a> {
    mesh: &'a Mesh,
    out: String,
    names: Names,
    /// Equations made for coupled rotations, written after the mesh's own.
    equations: Vec<Vec<(usize, u8, f64)>>,
    /// Id of each node's rotation node, for the references written as `*RIGID BODY`.
    rotation_nodes: Vec<Option<u64>>,
}

impl Deck<'_> {
    fn line(&mut self, s: &str) {
        self.out.push_str(s);
        self.out.push('\n');
    }

    fn node_id(&self, n: usize) -> u64 {
        self.mesh.nodes[n].id
    }

    /// The deck's node and DOF for DOF `d` of node `n`: a rotation of a reference with a
    /// rotation node is that node's translation.
    fn dof(&self, n: usize, d: u8) -> (u64, u8) {
        match self.rotation_nodes[n] {
            Some(rot) if d > 3 => (rot, d - 3),
            _ => (self.node_id(n), d),
        }
    }

    /// Whether DOF `d` of node `n` is a rotation CalculiX has no DOF for.
    fn rotation_without_node(&self, n: usize, d: u8) -> bool {
        d > 3 && self.rotation_nodes[n].is_none()
    }

    /// Ids, at most [`PER_LINE`] a line.
    fn id_lines(&mut self, ids: impl IntoIterator<Item = u64>) {
        let ids: Vec<u64> = ids.into_iter().collect();
        for chunk in ids.chunks(PER_LINE) {
            let line = chunk.iter().map(u64::to_string).collect::<Vec<_>>().join(", ");
            self.line(&line);
        }
    }

    fn header(&mut self) {
        let m = self.mesh;
        let text = format!(
            "** Written by stickslip-fe: {} nodes, {} solids, {} point elements, {} materials",
            m.nodes.len(),
            m.solids.len(),
            m.points.len(),
            m.materials.len()
        );
        self.line(&text);
    }

    fn nodes(&mut self) {
        if self.mesh.nodes.is_empty() {
            return;
        }
        self.line("*NODE");
        for node in &self.mesh.nodes {
            let [x, y, z] = node.xyz.map(format_real);
            let _ = writeln!(self.out, "{}, {x}, {y}, {z}", node.id);
        }
        if self.rotation_nodes.iter().any(Option::is_some) {
            self.line("** Rotation nodes of the *RIGID BODY cards: their DOFs 1-3 are the rotations");
            self.line("** (DOFs 4-6) of the reference nodes at the same places.");
            for (n, rot) in self.rotation_nodes.iter().enumerate() {
                if let Some(rot) = rot {
                    let [x, y, z] = self.mesh.nodes[n].xyz.map(format_real);
                    let _ = writeln!(self.out, "{rot}, {x}, {y}, {z}");
                }
            }
        }
    }

    /// `*ELEMENT` blocks, one per run of consecutive solids of one kind (keeping the solids'
    /// order); returns the element set of each kind and its solids.
    fn solids(&mut self) -> Vec<(String, Vec<usize>)> {
        let mesh = self.mesh;
        let mut kind_sets: Vec<(crate::element::SolidKind, String, Vec<usize>)> = Vec::new();
        let mut start = 0;
        while start < mesh.solids.len() {
            let kind = mesh.solids[start].kind;
            let end = start + mesh.solids[start..].iter().take_while(|s| s.kind == kind).count();
            let k = match kind_sets.iter().position(|(k, _, _)| *k == kind) {
                Some(k) => k,
                None => {
                    let name = self.names.unique(kind.abaqus_name());
                    kind_sets.push((kind, name, Vec::new()));
                    kind_sets.len() - 1
                }
            };
            kind_sets[k].2.extend(start..end);
            let _ = writeln!(self.out, "*ELEMENT, TYPE={}, ELSET={}", kind.abaqus_name(), kind_sets[k].1);
            for s in &mesh.solids[start..end] {
                // The id and up to 15 nodes, then up to 16 nodes a line; a line ending with a
                // comma continues.
                let mut fields = vec![s.id.to_string()];
                fields.extend(s.nodes.iter().map(|&n| self.node_id(n).to_string()));
                let lines: Vec<String> = fields.chunks(PER_LINE).map(|c| c.join(", ")).collect();
                let _ = writeln!(self.out, "{}", lines.join(",\n"));
            }
            start = end;
        }
        kind_sets.into_iter().map(|(_, name, members)| (name, members)).collect()
    }

    fn sets(&mut self) {
        let mesh = self.mesh;
        for (name, nodes) in &mesh.node_sets {
            let _ = writeln!(self.out, "*NSET, NSET={name}");
            self.id_lines(nodes.iter().map(|&n| mesh.nodes[n].id));
        }
        for (name, solids) in &mesh.element_sets {
            let _ = writeln!(self.out, "*ELSET, ELSET={name}");
            self.id_lines(solids.iter().map(|&s| mesh.solids[s].id));
        }
    }

    /// Every material (in order, so that they keep their indices) and one section per material
    /// the solids use.
    fn materials(&mut self, kind_sets: &[(String, Vec<usize>)]) {
        let mesh = self.mesh;
        let mut members: Vec<BTreeSet<usize>> = vec![BTreeSet::new(); mesh.materials.len()];
        for (i, s) in mesh.solids.iter().enumerate() {
            members[s.material.expect("checked")].insert(i);
        }
        // Candidate sets: the mesh's element sets, then the kind sets.
        let candidates: Vec<(String, BTreeSet<usize>)> = mesh
            .element_sets
            .iter()
            .map(|(n, v)| (n.clone(), v.iter().copied().collect()))
            .chain(kind_sets.iter().map(|(n, v)| (n.clone(), v.iter().copied().collect())))
            .collect();
        let mut sections = Vec::new();
        for (m, solids) in members.iter().enumerate() {
            if solids.is_empty() {
                continue;
            }
            let material = &mesh.materials[m].0;
            let elset = match candidates.iter().find(|(_, set)| set == solids) {
                Some((name, _)) => name.clone(),
                None => {
                    let name = self.names.unique(&format!("SOLIDS_{material}"));
                    let _ = writeln!(self.out, "*ELSET, ELSET={name}");
                    self.id_lines(solids.iter().map(|&s| mesh.solids[s].id));
                    name
                }
            };
            sections.push((elset, material.to_uppercase()));
        }
        for (name, mat) in &mesh.materials {
            let _ = writeln!(self.out, "*MATERIAL, NAME={}", name.to_uppercase());
            let _ = writeln!(self.out, "*ELASTIC\n{}, {}", format_real(mat.young), format_real(mat.poisson));
            let _ = writeln!(self.out, "*DENSITY\n{}", format_real(mat.density));
        }
        for (elset, material) in sections {
            let _ = writeln!(self.out, "*SOLID SECTION, ELSET={elset}, MATERIAL={material}");
        }
    }

    fn points(&mut self) {
        let mesh = self.mesh;
        let solid_ids: HashSet<u64> = mesh.solids.iter().map(|s| s.id).collect();
        let max_solid = mesh.solids.iter().map(|s| s.id).max().unwrap_or(0);
        let mut seen = HashSet::new();
        let mut renumber = false;
        let mut max_id = max_solid;
        for p in &mesh.points {
            let id = point_id(p);
            renumber |= solid_ids.contains(&id) || !seen.insert(id);
            max_id = max_id.max(id);
        }
        // Without renumbering, new ids (connector components after the first) start above every
        // id; with it, every point element takes the next id above the solids'.
        let mut next = if renumber { max_solid + 1 } else { max_id + 1 };
        let mut take = |own: Option<u64>| match own {
            Some(id) if !renumber => id,
            _ => {
                next += 1;
                next - 1
            }
        };
        let rotational = mesh.points.iter().any(|p| match *p {
            PointElement::Spring { a, dir_a, b, .. } => {
                self.rotation_without_node(a, dir_a) || b.is_some_and(|(b, d)| self.rotation_without_node(b, d))
            }
            PointElement::Connector { a, b, stiffness, .. } => {
                stiffness[3..].iter().any(|k| *k != 0.0)
                    && (self.rotation_without_node(a, 4) || b.is_some_and(|b| self.rotation_without_node(b, 4)))
            }
            _ => false,
        });
        if rotational {
            self.line("** Springs on DOFs 4-6 below are rotational springs for Abaqus and stickslip;");
            self.line("** CalculiX 2.20 springs act on translations only (it ignores or rejects these).");
        }
        for p in &mesh.points {
            match *p {
                PointElement::Mass { id, node, mass } => {
                    let eid = take(Some(id));
                    let set = self.names.unique(&format!("MASS_{eid}"));
                    let _ = writeln!(self.out, "*ELEMENT, TYPE=MASS, ELSET={set}\n{eid}, {}", self.node_id(node));
                    let _ = writeln!(self.out, "*MASS, ELSET={set}\n{}", format_real(mass));
                }
                PointElement::Spring { id, a, dir_a, b, stiffness } => {
                    let eid = take(Some(id));
                    let set = self.names.unique(&format!("SPRING_{eid}"));
                    self.spring(eid, &set, (a, dir_a), b, stiffness);
                }
                PointElement::AxialSpring { id, a, b, stiffness } => {
                    let eid = take(Some(id));
                    let set = self.names.unique(&format!("SPRINGA_{eid}"));
                    let (na, nb) = (self.node_id(a), self.node_id(b));
                    let _ = writeln!(self.out, "*ELEMENT, TYPE=SPRINGA, ELSET={set}\n{eid}, {na}, {nb}");
                    // CalculiX takes a first line with a decimal point as the SPRINGA stiffness.
                    let _ = writeln!(self.out, "*SPRING, ELSET={set}\n{}", format_real(stiffness));
                }
                PointElement::Connector { id, a, b, stiffness } => {
                    let mut own = Some(id);
                    for (d, &k) in stiffness.iter().enumerate() {
                        if k == 0.0 {
                            continue;
                        }
                        let dir = d as u8 + 1;
                        let eid = take(own.take());
                        let set = self.names.unique(&format!("CONNECTOR_{id}_{dir}"));
                        self.spring(eid, &set, (a, dir), b.map(|b| (b, dir)), k);
                    }
                }
            }
        }
    }

    /// A SPRING1 (to ground) or SPRING2 element in its own set, with its `*SPRING` card: the DOF
    /// line, then the stiffness (with a decimal point, which tells CalculiX it is not a DOF).
    /// Rotations of references with a rotation node act on that node's translations.
    fn spring(&mut self, eid: u64, set: &str, a: (usize, u8), b: Option<(usize, u8)>, k: f64) {
        let (na, da) = self.dof(a.0, a.1);
        match b {
            None => {
                let _ = writeln!(self.out, "*ELEMENT, TYPE=SPRING1, ELSET={set}\n{eid}, {na}");
                let _ = writeln!(self.out, "*SPRING, ELSET={set}\n{da}\n{}", format_real(k));
            }
            Some((b, db)) => {
                let (nb, db) = self.dof(b, db);
                let _ = writeln!(self.out, "*ELEMENT, TYPE=SPRING2, ELSET={set}\n{eid}, {na}, {nb}");
                let _ = writeln!(self.out, "*SPRING, ELSET={set}\n{da}, {db}\n{}", format_real(k));
            }
        }
    }

    /// `node, first, last` lines, consecutive DOFs of a node merged (the order is kept).
    fn boundaries(&mut self) {
        let fixed: Vec<(u64, u8)> = self.mesh.fixed.iter().map(|&(n, d)| self.dof(n, d)).collect();
        if fixed.is_empty() {
            return;
        }
        self.line("*BOUNDARY");
        let mut i = 0;
        while i < fixed.len() {
            let (n, first) = fixed[i];
            let mut last = first;
            while i + 1 < fixed.len() && fixed[i + 1] == (n, last + 1) {
                last += 1;
                i += 1;
            }
            let _ = writeln!(self.out, "{n}, {first}, {last}");
            i += 1;
        }
    }

    /// A node set holding exactly `slaves`: an existing named one, else `COUPLING_<c + 1>`.
    fn slave_set(&mut self, c: usize, slaves: &BTreeSet<usize>) -> String {
        let mesh = self.mesh;
        let existing = mesh.node_sets.iter().find(|(name, nodes)| {
            name.parse::<u64>().is_err() && nodes.len() == slaves.len() && nodes.iter().all(|n| slaves.contains(n))
        });
        match existing {
            Some((name, _)) => name.clone(),
            None => {
                let name = self.names.unique(&format!("COUPLING_{}", c + 1));
                let _ = writeln!(self.out, "*NSET, NSET={name}");
                self.id_lines(slaves.iter().map(|&s| mesh.nodes[s].id));
                name
            }
        }
    }

    fn couplings(&mut self) {
        let mesh = self.mesh;
        let rotations = nodes_with_rotations(mesh);
        let mut rigid_body_written = vec![false; mesh.nodes.len()];
        for (c, coupling) in mesh.couplings.iter().enumerate() {
            let r = coupling.reference;
            let slaves: BTreeSet<usize> = coupling.nodes.iter().copied().filter(|&s| s != r).collect();
            let dofs: BTreeSet<u8> = coupling.dofs.iter().copied().collect();
            if slaves.is_empty() || dofs.is_empty() {
                continue;
            }
            let translations: Vec<u8> = dofs.iter().copied().filter(|&d| d <= 3).collect();
            if let Some(rot) = self.rotation_nodes[r] {
                // All couplings of `r` tie every translation (see `rotation_nodes`): one rigid
                // body on all their slaves is the same constraint.
                if !std::mem::replace(&mut rigid_body_written[r], true) {
                    let all: BTreeSet<usize> = mesh
                        .couplings
                        .iter()
                        .filter(|k| k.reference == r)
                        .flat_map(|k| k.nodes.iter().copied())
                        .filter(|&s| s != r)
                        .collect();
                    let set = self.slave_set(c, &all);
                    let _ = writeln!(self.out, "*RIGID BODY, NSET={set}, REF NODE={}, ROT NODE={rot}", self.node_id(r));
                }
            } else if !translations.is_empty() {
                let set = self.slave_set(c, &slaves);
                let _ = writeln!(self.out, "*SURFACE, NAME={set}, TYPE=NODE\n{set}");
                let _ = writeln!(
                    self.out,
                    "*COUPLING, REF NODE={}, SURFACE={set}, CONSTRAINT NAME=C{}\n*KINEMATIC",
                    self.node_id(r),
                    c + 1
                );
                let mut i = 0;
                while i < translations.len() {
                    let first = translations[i];
                    while i + 1 < translations.len() && translations[i + 1] == translations[i] + 1 {
                        i += 1;
                    }
                    let _ = writeln!(self.out, "{first}, {}", translations[i]);
                    i += 1;
                }
            }
            if self.rotation_nodes[r].is_some() {
                continue;
            }
            for &s in slaves.iter().filter(|&&s| rotations[s]) {
                for &d in dofs.iter().filter(|&&d| d > 3) {
                    self.equations.push(vec![(s, d, 1.0), (r, d, -1.0)]);
                }
            }
        }
    }

    fn equations(&mut self) {
        let mesh = self.mesh;
        let all: Vec<Vec<(usize, u8, f64)>> =
            mesh.equations.iter().map(|e| e.terms.clone()).chain(std::mem::take(&mut self.equations)).collect();
        if all.is_empty() {
            return;
        }
        if all.iter().flatten().any(|&(n, d, _)| self.rotation_without_node(n, d)) {
            self.line("** Equations on DOFs 4-6 tie rotations, for Abaqus and stickslip; CalculiX 2.20");
            self.line("** has rotations only at the reference nodes of couplings and may reject them.");
        }
        self.line("*EQUATION");
        for terms in all {
            let _ = writeln!(self.out, "{}", terms.len());
            // Four terms a line (12 fields), as Abaqus reads them.
            for chunk in terms.chunks(4) {
                let line: Vec<String> = chunk
                    .iter()
                    .map(|&(n, d, c)| {
                        let (id, d) = self.dof(n, d);
                        format!("{id}, {d}, {}", format_real(c))
                    })
                    .collect();
                self.line(&line.join(", "));
            }
        }
    }

    fn step(&mut self) {
        let modes = self.mesh.modes_requested.unwrap_or(10);
        let _ = writeln!(self.out, "*STEP\n*FREQUENCY\n{modes}\n*NODE FILE\nU\n*END STEP");
    }
}

fn point_id(p: &PointElement) -> u64 {
    match *p {
        PointElement::Mass { id, .. }
        | PointElement::Spring { id, .. }
        | PointElement::AxialSpring { id, .. }
        | PointElement::Connector { id, .. } => id,
    }
}

/// The rotation node id of each reference node written as a `*RIGID BODY` (else `None`): those
/// whose rotations the deck names elsewhere (a spring, connector, fixed DOF or equation on DOFs
/// 4-6, or the coupled rotations of a slave that carries rotations), since CalculiX has rotation
/// DOFs only on a rigid body's ROT NODE, and whose couplings all tie what a rigid body ties: the
/// three translations, and the three rotations of slaves that carry rotations. New ids above
/// every node id, in the order of the references.
fn rotation_nodes(mesh: &Mesh) -> Vec<Option<u64>> {
    let nn = mesh.nodes.len();
    let carries = nodes_with_rotations(mesh);
    let mut named = rotations_named_by_points_and_equations(mesh);
    for &(n, d) in &mesh.fixed {
        named[n] |= d > 3;
    }
    let mut rigid = vec![None::<bool>; nn];
    for c in &mesh.couplings {
        let r = c.reference;
        if c.nodes.iter().all(|&s| s == r) || c.dofs.is_empty() {
            continue;
        }
        named[r] |= c.dofs.iter().any(|&d| d > 3) && c.nodes.iter().any(|&s| s != r && carries[s]);
        // A rigid body ties the translations, and the rotations of slaves that carry them.
        let slaves_rotate = c.nodes.iter().any(|&s| s != r && carries[s]);
        let as_rigid_body =
            (1..=3).all(|d| c.dofs.contains(&d)) && (!slaves_rotate || (4..=6).all(|d| c.dofs.contains(&d)));
        rigid[r] = Some(rigid[r].unwrap_or(true) && as_rigid_body);
    }
    let mut next = mesh.nodes.iter().map(|n| n.id).max().unwrap_or(0);
    (0..nn)
        .map(|n| {
            (named[n] && rigid[n] == Some(true)).then(|| {
                next += 1;
                next
            })
        })
        .collect()
}

/// Nodes that carry rotational DOFs in the assembled model: reference nodes of couplings and
/// nodes whose rotations a spring, connector or equation names (as the DOF map decides).
fn nodes_with_rotations(mesh: &Mesh) -> Vec<bool> {
    let mut rot = rotations_named_by_points_and_equations(mesh);
    for c in &mesh.couplings {
        rot[c.reference] = true;
    }
    rot
}

/// Nodes whose rotations a spring, a connector's rotational component or an equation names.
fn rotations_named_by_points_and_equations(mesh: &Mesh) -> Vec<bool> {
    let mut rot = vec![false; mesh.nodes.len()];
    for p in &mesh.points {
        match *p {
            PointElement::Spring { a, dir_a, b, .. } => {
                rot[a] |= dir_a > 3;
                if let Some((b, db)) = b {
                    rot[b] |= db > 3;
                }
            }
            PointElement::Connector { a, b, stiffness, .. } if stiffness[3..].iter().any(|k| *k != 0.0) => {
                rot[a] = true;
                if let Some(b) = b {
                    rot[b] = true;
                }
            }
            _ => {}
        }
    }
    for &(n, d, _) in mesh.equations.iter().flat_map(|e| &e.terms) {
        rot[n] |= d > 3;
    }
    rot
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A small deterministic generator (xorshift) for the formatting checks.
    fn xorshift(state: &mut u64) -> u64 {
        *state ^= *state << 13;
        *state ^= *state >> 7;
        *state ^= *state << 17;
        *state
    }

    #[test]
    fn reals_have_a_point_fit_the_field_and_read_back_exactly_when_they_can() {
        // (value, text, whether the text reads back exactly)
        for (x, s, exact) in [
            (0.0, "0.0", true),
            (-0.0, "-0.0", true),
            (1.0, "1.0", true),
            (0.075, "0.075", true),
            (7800.0, "7800.0", true),
            (210e9, "2.1e11", true),
            (1e10, "1.0e10", true),
            (1e-5, "1.0e-5", true),
            (0.30000000000000004, "0.30000000000000004", true),
            (0.052500000000000005, "0.052500000000000005", true),
            (-0.052500000000000005, "-.052500000000000005", true),
            (1.2345678901234567e-5, ".1234567890123457e-4", false),
            // 17 digits below 1e-3 and negative: no exact 20-character form, rounded to 16.
            (-0.0012345678901234567, "-.001234567890123457", false),
        ] {
            let got = format_real(x);
            assert_eq!(got, s, "{x:e}");
            assert_eq!(got.parse::<f64>().unwrap().to_bits() == x.to_bits(), exact, "{x:e} → {got}");
        }
        let (mut state, mut exact, mut total, mut rounded_mesh_like) = (0x9e3779b97f4a7c15u64, 0, 0, 0);
        for i in 0..200_000 {
            // Random bit patterns (every magnitude) and values of mesh-like magnitudes.
            let x = if i % 2 == 0 {
                f64::from_bits(xorshift(&mut state))
            } else {
                (xorshift(&mut state) as f64 / u64::MAX as f64 - 0.5)
                    * 10f64.powi((xorshift(&mut state) % 12) as i32 - 4)
            };
            if !x.is_finite() {
                continue;
            }
            let s = format_real(x);
            assert!(s.len() <= FIELD_WIDTH && s.contains('.'), "{x:e} → {s:?}");
            let y: f64 = s.parse().unwrap();
            total += 1;
            if y.to_bits() == x.to_bits() {
                exact += 1;
            } else {
                // 15 digits or more fit with a one-digit exponent, 14 with two, 13 with three.
                let bound = match x.abs() {
                    a if (1e-10..1e19).contains(&a) => 5e-15,
                    a if (1e-99..1e99).contains(&a) => 5e-14,
                    _ => 5e-13,
                };
                assert!(((y - x) / x).abs() < bound, "{x:e} → {s:?}");
                if i % 2 == 1 {
                    rounded_mesh_like += 1;
                }
                // Only numbers whose shortest form has no 20-character spelling are rounded.
                let (neg, digits, exp) = decompose(&format!("{x:e}"));
                assert!(compact(neg, &digits, exp).len() > FIELD_WIDTH, "{x:e} → {s:?}");
            }
        }
        println!(
            "{exact} of {total} random reals written exactly; {rounded_mesh_like} of the 100000 mesh-like ones rounded"
        );
    }
}
