//! Meshes: nodes, solid elements, point elements (masses, springs), sets, materials and the
//! constraints of a modal deck (paper Section 3.1), read from Abaqus/CalculiX `.inp` decks
//! ([`inp`]) or Gmsh `.msh` 4.1 files ([`gmsh`]), or generated ([`generate`]).
//!
//! Conventions: node and element ids are the file's (1-based, not necessarily contiguous);
//! set, material and section names are stored upper-case (keywords and names are
//! case-insensitive in `.inp` decks); DOF directions follow CalculiX: 1, 2, 3 translations,
//! 4, 5, 6 rotations.

pub mod generate;
pub mod gmsh;
pub mod gmsh_writer;
pub mod inp;
pub mod inp_writer;
pub mod lap_joint;
pub mod structured;
pub mod vtk;

use std::collections::{BTreeMap, HashMap};
use std::path::PathBuf;

use crate::element::SolidKind;

/// Where a mesh item came from, for error messages: `file:line`.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Origin {
    pub file: PathBuf,
    pub line: usize,
}

impl std::fmt::Display for Origin {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        if self.file.as_os_str().is_empty() {
            f.write_str("(generated)")
        } else {
            write!(f, "{}:{}", self.file.display(), self.line)
        }
    }
}

/// What is wrong with a mesh or deck, naming the file and line, node, element or set.
#[derive(Debug, thiserror::Error)]
pub enum MeshError {
    #[error("cannot read {file}: {source}")]
    Io { file: PathBuf, source: std::io::Error },
    #[error("cannot write {file}: {source}")]
    Write { file: PathBuf, source: std::io::Error },
    #[error("{at}: {msg}")]
    Syntax { at: Origin, msg: String },
    #[error("{at}: unknown keyword *{keyword} (supported keywords are listed in docs/fe.md)")]
    UnknownKeyword { at: Origin, keyword: String },
    #[error("{at}: unsupported element type {kind} (supported: solids C3D4, C3D10, C3D8, C3D20, C3D20R, i.e. Gmsh types 4, 11, 5, 17; MASS, SPRING1, SPRING2, SPRINGA in decks)")]
    UnsupportedElement { at: Origin, kind: String },
    #[error("{at}: element {element} has {got} nodes, {kind} needs {expected}")]
    WrongNodeCount { at: Origin, element: u64, kind: String, got: usize, expected: usize },
    #[error("{at}: {what} refers to node {node}, which is not defined")]
    UndefinedNode { at: Origin, what: String, node: u64 },
    #[error("{at}: {what} refers to element {element}, which is not defined")]
    UndefinedElement { at: Origin, what: String, element: u64 },
    #[error("{at}: {what} refers to set {set:?}, which is not defined")]
    UndefinedSet { at: Origin, what: String, set: String },
    #[error("{at}: node {node} is defined twice")]
    DuplicateNode { at: Origin, node: u64 },
    #[error("{at}: element {element} is defined twice")]
    DuplicateElement { at: Origin, element: u64 },
    #[error("{at}: section on element set {elset:?} uses material {material:?}, which is not defined")]
    MissingMaterial { at: Origin, elset: String, material: String },
    #[error("{at}: material {material:?} lacks {what}")]
    IncompleteMaterial { at: Origin, material: String, what: String },
    #[error("element {element} ({kind}) has no section (no *SOLID SECTION covers it, so it has no material)")]
    NoSection { element: u64, kind: String },
    #[error("{at}: {what} element set {elset:?} has no property card (*MASS or *SPRING)")]
    NoProperty { at: Origin, what: String, elset: String },
}

/// Write the text of a mesh file (the writers build it whole first, so that nothing is written
/// when the mesh cannot be expressed).
fn write_text(path: &std::path::Path, text: &str) -> Result<(), MeshError> {
    std::fs::write(path, text).map_err(|source| MeshError::Write { file: path.to_path_buf(), source })
}

/// Isotropic linear elastic material.
#[derive(Clone, Debug, PartialEq)]
pub struct Material {
    /// Young's modulus in Pa.
    pub young: f64,
    /// Poisson's ratio.
    pub poisson: f64,
    /// Density in kg/m³.
    pub density: f64,
}

/// A mesh node.
#[derive(Clone, Debug, PartialEq)]
pub struct Node {
    pub id: u64,
    pub xyz: [f64; 3],
}

/// The first node whose coordinates are not all finite, by index: what the writers refuse to
/// write (a file holding NaN or inf reads back as nothing a solver can use).
pub(crate) fn non_finite_node(nodes: &[Node]) -> Option<usize> {
    nodes.iter().position(|n| n.xyz.iter().any(|x| !x.is_finite()))
}

/// A continuum element; `nodes` are indices into [`Mesh::nodes`] in Abaqus/CalculiX order.
#[derive(Clone, Debug, PartialEq)]
pub struct Solid {
    pub id: u64,
    pub kind: SolidKind,
    pub nodes: Vec<usize>,
    /// Index into [`Mesh::materials`], set by the sections.
    pub material: Option<usize>,
}

/// A point element: a mass or a spring (CalculiX MASS, SPRING1, SPRING2, SPRINGA) or a
/// 6-component connector between two nodes or to ground.
#[derive(Clone, Debug, PartialEq)]
pub enum PointElement {
    /// Translational point mass `m` (kg) on a node.
    Mass { id: u64, node: usize, mass: f64 },
    /// Spring of stiffness `k` between DOF `dir_a` of node `a` and DOF `dir_b` of node `b`
    /// (`b = None`: to ground): energy `½ k (u_a − u_b)²`.
    Spring { id: u64, a: usize, dir_a: u8, b: Option<(usize, u8)>, stiffness: f64 },
    /// Axial spring along the line joining two nodes (CalculiX SPRINGA).
    AxialSpring { id: u64, a: usize, b: usize, stiffness: f64 },
    /// Connector between two nodes (or to ground) with one stiffness per DOF direction 1..=6
    /// (the paper's 1e10 N/m connectors between reference nodes); zero components are absent.
    Connector { id: u64, a: usize, b: Option<usize>, stiffness: [f64; 6] },
}

/// A rigid (kinematic) coupling: the listed DOFs of every node of `nodes` follow the rigid
/// motion of `reference` (`u_s = u_r + θ_r × (x_s − x_r)`).
#[derive(Clone, Debug, PartialEq)]
pub struct RigidCoupling {
    pub reference: usize,
    pub nodes: Vec<usize>,
    /// Constrained directions 1..=6 (rotations of 3-DOF slave nodes are ignored).
    pub dofs: Vec<u8>,
    pub at: Origin,
}

/// A homogeneous linear constraint `Σ c_k u(node_k, dir_k) = 0`; its first term is the
/// dependent DOF (as in `*EQUATION`).
#[derive(Clone, Debug, PartialEq)]
pub struct Equation {
    pub terms: Vec<(usize, u8, f64)>,
    pub at: Origin,
}

/// A mesh with everything a modal deck says about it.
#[derive(Clone, Debug, Default)]
pub struct Mesh {
    pub nodes: Vec<Node>,
    pub solids: Vec<Solid>,
    pub points: Vec<PointElement>,
    pub materials: Vec<(String, Material)>,
    /// Node sets: name (upper case) → node indices.
    pub node_sets: BTreeMap<String, Vec<usize>>,
    /// Element sets: name (upper case) → indices into `solids`.
    pub element_sets: BTreeMap<String, Vec<usize>>,
    /// Fixed DOFs (node index, direction 1..=6), all fixed to zero.
    pub fixed: Vec<(usize, u8)>,
    pub couplings: Vec<RigidCoupling>,
    pub equations: Vec<Equation>,
    /// Number of modes asked by `*FREQUENCY`, if any.
    pub modes_requested: Option<usize>,
    node_index: HashMap<u64, usize>,
}

impl Mesh {
    /// Add a node; errors if its id exists.
    pub fn add_node(&mut self, id: u64, xyz: [f64; 3]) -> Result<usize, u64> {
        if self.node_index.contains_key(&id) {
            return Err(id);
        }
        self.node_index.insert(id, self.nodes.len());
        self.nodes.push(Node { id, xyz });
        Ok(self.nodes.len() - 1)
    }

    /// Index of the node with id `id`.
    pub fn node(&self, id: u64) -> Option<usize> {
        self.node_index.get(&id).copied()
    }

    /// Node indices of the set `name` (case-insensitive).
    pub fn node_set(&self, name: &str) -> Option<&[usize]> {
        self.node_sets.get(&name.to_uppercase()).map(|v| v.as_slice())
    }

    /// Fix `directions` (1..=6) of every node of the set `name` (a boundary condition by node
    /// set or physical group), once each. False, the mesh unchanged, if there is no such set.
    pub fn fix_node_set(&mut self, name: &str, directions: &[u8]) -> bool {
        let Some(nodes) = self.node_sets.get(&name.to_uppercase()) else { return false };
        for &n in nodes {
            for &d in directions {
                if !self.fixed.contains(&(n, d)) {
                    self.fixed.push((n, d));
                }
            }
        }
        true
    }

    /// Index of the material named `name` (case-insensitive).
    pub fn material(&self, name: &str) -> Option<usize> {
        let name = name.to_uppercase();
        self.materials.iter().position(|(n, _)| *n == name)
    }

    /// Give every solid of `elset` (all solids if `None`) the material `name`, adding it.
    pub fn assign_material(&mut self, elset: Option<&str>, name: &str, material: Material) -> Result<(), MeshError> {
        let idx = match self.material(name) {
            Some(i) => {
                self.materials[i].1 = material;
                i
            }
            None => {
                self.materials.push((name.to_uppercase(), material));
                self.materials.len() - 1
            }
        };
        match elset {
            None => self.solids.iter_mut().for_each(|s| s.material = Some(idx)),
            Some(set) => {
                let members = self.element_sets.get(&set.to_uppercase()).ok_or_else(|| MeshError::UndefinedSet {
                    at: Origin::default(),
                    what: "material assignment".into(),
                    set: set.into(),
                })?;
                for &e in members {
                    self.solids[e].material = Some(idx);
                }
            }
        }
        Ok(())
    }

    /// Add a node set (name stored upper case), merging with an existing one.
    pub fn add_node_set(&mut self, name: &str, nodes: impl IntoIterator<Item = usize>) {
        let set = self.node_sets.entry(name.to_uppercase()).or_default();
        set.extend(nodes);
        set.sort_unstable();
        set.dedup();
    }

    /// Remove the nodes flagged in `drop` (indexed like [`Mesh::nodes`]), renumbering the
    /// indices everything else holds. The dropped nodes leave the node sets; no solid, point
    /// element, fixed DOF, coupling or equation may refer to them (the caller checks).
    pub fn remove_nodes(&mut self, drop: &[bool]) {
        let mut new_index = vec![usize::MAX; self.nodes.len()];
        let mut kept = Vec::with_capacity(self.nodes.len());
        for (n, node) in std::mem::take(&mut self.nodes).into_iter().enumerate() {
            if !drop[n] {
                new_index[n] = kept.len();
                kept.push(node);
            }
        }
        self.nodes = kept;
        self.node_index = self.nodes.iter().enumerate().map(|(i, n)| (n.id, i)).collect();
        let at = |n: usize| {
            let i = new_index[n];
            assert!(i != usize::MAX, "a removed node is still referred to");
            i
        };
        for s in &mut self.solids {
            s.nodes.iter_mut().for_each(|n| *n = at(*n));
        }
        for p in &mut self.points {
            match p {
                PointElement::Mass { node, .. } => *node = at(*node),
                PointElement::Spring { a, b, .. } => {
                    *a = at(*a);
                    if let Some((b, _)) = b {
                        *b = at(*b);
                    }
                }
                PointElement::AxialSpring { a, b, .. } => {
                    *a = at(*a);
                    *b = at(*b);
                }
                PointElement::Connector { a, b, .. } => {
                    *a = at(*a);
                    if let Some(b) = b {
                        *b = at(*b);
                    }
                }
            }
        }
        for set in self.node_sets.values_mut() {
            *set = set.iter().filter(|&&n| !drop[n]).map(|&n| new_index[n]).collect();
        }
        self.fixed.iter_mut().for_each(|(n, _)| *n = at(*n));
        for c in &mut self.couplings {
            c.reference = at(c.reference);
            c.nodes.iter_mut().for_each(|n| *n = at(*n));
        }
        for e in &mut self.equations {
            e.terms.iter_mut().for_each(|(n, _, _)| *n = at(*n));
        }
    }

    /// Sorted, unique nodes used by the solids.
    pub fn solid_nodes(&self) -> Vec<usize> {
        let mut used = vec![false; self.nodes.len()];
        for s in &self.solids {
            for &n in &s.nodes {
                used[n] = true;
            }
        }
        (0..self.nodes.len()).filter(|&i| used[i]).collect()
    }
}
