//! Sparse symmetric assembly of K and M from a mesh (paper Section 3.1) into a
//! [`LinearModel`] over the independent DOFs: fixed DOFs removed, the slave DOFs of rigid
//! couplings and `*EQUATION`s eliminated through `u = T q` (`K_red = Tᵀ K T`), applied element
//! by element so that the full matrices are never formed.

mod csc;
pub mod dofs;

use rayon::prelude::*;
use stickslip_core::model::{Damping, DofLabel, LinearModel, Matrix};

use crate::element::{self, MassRule, SolidKind, Tabulated};
use crate::mesh::{Mesh, MeshError, Solid};
use csc::{Builder, Entry};
pub use dofs::DofMap;

/// What stops an assembly, naming the element, node or set.
#[derive(Debug, thiserror::Error)]
pub enum AssemblyError {
    #[error(transparent)]
    Mesh(#[from] MeshError),
    #[error("element {element} ({kind}) is inverted or degenerate: Jacobian determinant {det:.3e} at a quadrature point (check its node order and coordinates)")]
    InvertedElement { element: u64, kind: &'static str, det: f64 },
    #[error("element {element} ({kind}) has no material (no section covers it)")]
    NoMaterial { element: u64, kind: &'static str },
    #[error("axial spring element {element} joins two coincident nodes: its axis is undefined")]
    ZeroLengthSpring { element: u64 },
    #[error("DOF {dir} of node {node} is constrained twice: by {first} and by {second}")]
    DoublyConstrained { node: u64, dir: u8, first: String, second: String },
    #[error("DOF {dir} of node {node} depends on itself through a cycle of couplings/equations")]
    CyclicConstraint { node: u64, dir: u8 },
    #[error("the model has no free DOF (everything is fixed or no element is defined)")]
    Empty,
    #[error("no node {0} in the mesh")]
    UnknownNode(u64),
    #[error("DOF {dir} of node {node} is not an independent DOF of the model (it is fixed, eliminated by a constraint, or absent)")]
    NotIndependent { node: u64, dir: u8 },
    #[error("no node set {0:?} in the mesh")]
    UnknownSet(String),
}

/// Assembly options.
#[derive(Clone, Copy, Debug, Default)]
pub struct Options {
    pub mass_rule: MassRule,
}

/// An assembled model with the mesh and DOF bookkeeping needed to find DOFs by node and set and
/// to recover nodal displacements.
#[derive(Clone, Debug)]
pub struct FeModel {
    pub model: LinearModel,
    pub mesh: Mesh,
    pub dofs: DofMap,
    /// Total volume and mass of the solids (m³, kg).
    pub volume: f64,
    pub solid_mass: f64,
}

impl FeModel {
    /// Assemble `mesh` with the default options (CalculiX mass integration).
    pub fn assemble(mesh: Mesh) -> Result<FeModel, AssemblyError> {
        Self::assemble_with(mesh, Options::default())
    }

    pub fn assemble_with(mesh: Mesh, options: Options) -> Result<FeModel, AssemblyError> {
        let dofs = DofMap::build(&mesh)?;
        let n = dofs.independent.len();
        if n == 0 {
            return Err(AssemblyError::Empty);
        }
        for s in &mesh.solids {
            if s.material.is_none() {
                return Err(AssemblyError::NoMaterial { element: s.id, kind: s.kind.abaqus_name() });
            }
        }
        let points = point_entries(&mesh, &dofs)?;
        let mut counts = solid_counts(&mesh, &dofs);
        for e in &points {
            counts[e.col as usize] += 1;
        }
        let mut builder = Builder::new(&counts);
        drop(counts);
        let (volume, solid_mass) = solid_entries(&mesh, &dofs, options.mass_rule, &mut builder)?;
        for e in points {
            builder.push(e);
        }
        crate::memory::stage("element contributions");
        let (k, m) = builder.finish();
        crate::memory::stage("assembly");
        let labels = dofs.independent.iter().map(|&(node, d)| DofLabel::nodal(mesh.nodes[node].id, d)).collect();
        // Built directly: K and M are symmetric by construction, and LinearModel::new's
        // symmetry check works on dense copies, out of reach at FE sizes.
        let model = LinearModel {
            mass: Matrix::Sparse(m),
            stiffness: Matrix::Sparse(k),
            damping: Damping::None,
            dofs: labels,
            loads: Vec::new(),
        };
        Ok(FeModel { model, mesh, dofs, volume, solid_mass })
    }

    /// Index in the model of DOF `dir` (1..=6) of the node with id `node`.
    pub fn dof(&self, node: u64, dir: u8) -> Result<usize, AssemblyError> {
        let i = self.mesh.node(node).ok_or(AssemblyError::UnknownNode(node))?;
        self.dofs
            .full(i, dir)
            .and_then(|p| self.dofs.reduced[p])
            .map(|r| r as usize)
            .ok_or(AssemblyError::NotIndependent { node, dir })
    }

    /// Model indices of all independent DOFs of the nodes of set `name`, node by node.
    pub fn set_dofs(&self, name: &str) -> Result<Vec<usize>, AssemblyError> {
        let set = self.mesh.node_set(name).ok_or_else(|| AssemblyError::UnknownSet(name.into()))?;
        let mut out = Vec::new();
        for &i in set {
            for d in 1..=self.dofs.n_dirs[i] {
                if let Some(r) = self.dofs.full(i, d).and_then(|p| self.dofs.reduced[p]) {
                    out.push(r as usize);
                }
            }
        }
        Ok(out)
    }

    /// Translations of every mesh node for the model vector `q` (`u = T q`): zero on fixed
    /// and inactive DOFs, the rigid motion on coupled nodes.
    pub fn nodal_displacements(&self, q: &[f64]) -> Vec<[f64; 3]> {
        assert_eq!(q.len(), self.model.n_dofs(), "expected a vector of {} DOFs, got {}", self.model.n_dofs(), q.len());
        (0..self.mesh.nodes.len())
            .map(|i| {
                let mut u = [0.0; 3];
                for (d, ud) in u.iter_mut().enumerate() {
                    let p = self.dofs.offset[i] + d;
                    *ud = self.dofs.row(p).map(|(r, c)| c * q[r as usize]).sum();
                }
                u
            })
            .collect()
    }
}

impl FeModel {
    /// Write the solids and one displacement field per model vector (e.g. mode shapes, named
    /// with their frequency) as a VTK legacy unstructured grid.
    pub fn write_vtk(
        &self,
        out: &mut impl std::io::Write,
        title: &str,
        shapes: &[(String, Vec<f64>)],
    ) -> std::io::Result<()> {
        let fields: Vec<(String, Vec<[f64; 3]>)> =
            shapes.iter().map(|(name, q)| (name.clone(), self.nodal_displacements(q))).collect();
        crate::mesh::vtk::write(out, title, &self.mesh.nodes, &self.mesh.solids, &fields)
    }
}

/// Elements per parallel work unit: large enough to amortise the scheduling, small enough to
/// balance the threads and keep each unit's contributions (~10 MB for tet10) in cache-sized
/// buffers.
const CHUNK: usize = 1024;

/// Rows of `T` for the DOFs of a solid, node-major: `rows[ptr[p]..ptr[p + 1]]` for DOF `p`.
fn element_rows(s: &Solid, dofs: &DofMap, rows: &mut Vec<(u32, f64)>, ptr: &mut Vec<usize>) {
    rows.clear();
    ptr.clear();
    ptr.push(0);
    for &a in &s.nodes {
        for i in 0..3 {
            rows.extend(dofs.row(dofs.offset[a] + i));
            ptr.push(rows.len());
        }
    }
}

/// Number of upper-triangle contributions of the solids to each column.
fn solid_counts(mesh: &Mesh, dofs: &DofMap) -> Vec<usize> {
    let n = dofs.independent.len();
    mesh.solids
        .par_chunks(CHUNK)
        .map(|chunk| {
            let mut counts = vec![0usize; n];
            let (mut rows, mut ptr) = (Vec::new(), Vec::new());
            for s in chunk {
                element_rows(s, dofs, &mut rows, &mut ptr);
                for &(ra, _) in &rows {
                    for &(rb, _) in &rows {
                        if ra <= rb {
                            counts[rb as usize] += 1;
                        }
                    }
                }
            }
            counts
        })
        .reduce(
            || vec![0usize; n],
            |mut a, b| {
                a.iter_mut().zip(b).for_each(|(x, y)| *x += y);
                a
            },
        )
}

/// Contributions, volume and mass of one chunk of elements.
type ChunkOutput = (Vec<Entry>, f64, f64);

/// Upper-triangle contributions of all solids, computed in parallel over chunks of elements
/// (a few chunks per thread at a time) and scattered into the builder; returns the volume and
/// mass.
fn solid_entries(
    mesh: &Mesh,
    dofs: &DofMap,
    mass_rule: MassRule,
    builder: &mut Builder,
) -> Result<(f64, f64), AssemblyError> {
    let tabs: Vec<Tabulated> = SolidKind::ALL.iter().map(|&k| Tabulated::new(k, mass_rule)).collect();
    let tab_of = |k: SolidKind| &tabs[SolidKind::ALL.iter().position(|&x| x == k).unwrap()];
    let chunks: Vec<&[Solid]> = mesh.solids.chunks(CHUNK).collect();
    let batch = 2 * rayon::current_num_threads();
    let (mut volume, mut mass) = (0.0, 0.0);
    for group in chunks.chunks(batch) {
        let results: Vec<Result<ChunkOutput, AssemblyError>> = group
            .par_iter()
            .map(|chunk| {
                let mut k = vec![0.0; 60 * 60];
                let mut m = vec![0.0; 20 * 20];
                let mut xyz = [[0.0; 3]; 20];
                let (mut rows, mut row_ptr) = (Vec::with_capacity(64), Vec::with_capacity(61));
                let (mut volume, mut mass) = (0.0, 0.0);
                let mut out = Vec::new();
                for s in chunk.iter() {
                    let nn = s.nodes.len();
                    for (x, &a) in xyz.iter_mut().zip(&s.nodes) {
                        *x = mesh.nodes[a].xyz;
                    }
                    let mat = &mesh.materials[s.material.expect("checked before")].1;
                    let v = element::solid_matrices(tab_of(s.kind), &xyz[..nn], mat, &mut k, &mut m).map_err(|e| {
                        AssemblyError::InvertedElement { element: s.id, kind: s.kind.abaqus_name(), det: e.det }
                    })?;
                    volume += v;
                    mass += v * mat.density;
                    element_rows(s, dofs, &mut rows, &mut row_ptr);
                    let nd = 3 * nn;
                    if rows.len() == nd && rows.iter().all(|r| r.1 == 1.0) {
                        // Every DOF free (no fixed or coupled node): one contribution per pair.
                        for p in 0..nd {
                            let ra = rows[p].0;
                            let mrow = &m[(p / 3) * nn..(p / 3) * nn + nn];
                            for (q, &kpq) in k[p * nd..(p + 1) * nd].iter().enumerate() {
                                let rb = rows[q].0;
                                if ra <= rb {
                                    let mpq = if p % 3 == q % 3 { mrow[q / 3] } else { 0.0 };
                                    out.push(Entry { row: ra, col: rb, k: kpq, m: mpq });
                                }
                            }
                        }
                        continue;
                    }
                    for p in 0..nd {
                        for q in 0..nd {
                            let kpq = k[p * nd + q];
                            let mpq = if p % 3 == q % 3 { m[(p / 3) * nn + q / 3] } else { 0.0 };
                            for &(ra, ca) in &rows[row_ptr[p]..row_ptr[p + 1]] {
                                for &(rb, cb) in &rows[row_ptr[q]..row_ptr[q + 1]] {
                                    if ra <= rb {
                                        let c = ca * cb;
                                        out.push(Entry { row: ra, col: rb, k: c * kpq, m: c * mpq });
                                    }
                                }
                            }
                        }
                    }
                }
                Ok((out, volume, mass))
            })
            .collect();
        for r in results {
            let (entries, v, m) = r?;
            volume += v;
            mass += m;
            for e in entries {
                builder.push(e);
            }
        }
    }
    Ok((volume, mass))
}

/// Upper-triangle contributions of the point elements (masses, springs, connectors).
fn point_entries(mesh: &Mesh, dofs: &DofMap) -> Result<Vec<Entry>, AssemblyError> {
    let mut out = Vec::new();
    let mut ke = Vec::new();
    let mut me = Vec::new();
    for p in &mesh.points {
        ke.clear();
        me.clear();
        if element::point::stiffness(p, &mesh.nodes, &mut ke).is_none() {
            let crate::mesh::PointElement::AxialSpring { id, .. } = p else { unreachable!() };
            return Err(AssemblyError::ZeroLengthSpring { element: *id });
        }
        element::point::mass(p, &mut me);
        for (list, is_mass) in [(&ke, false), (&me, true)] {
            for &((na, da), (nb, db), v) in list.iter() {
                let (pa, pb) = (dofs.full(na, da).unwrap(), dofs.full(nb, db).unwrap());
                for (ra, ca) in dofs.row(pa) {
                    for (rb, cb) in dofs.row(pb) {
                        if ra <= rb {
                            let x = ca * cb * v;
                            let (k, m) = if is_mass { (0.0, x) } else { (x, 0.0) };
                            out.push(Entry { row: ra, col: rb, k, m });
                        }
                    }
                }
            }
        }
    }
    Ok(out)
}
