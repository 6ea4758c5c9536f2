//! Contact patches between two conforming surfaces of a mesh: the node-to-node pairs of two node
//! sets (each node of one set with the node of the other at the same position), each pair's
//! tributary area, the interface's normal and tangential directions, and the static pre-step
//! that gives each pair its normal load at rest.
//!
//! **Tributary area**: the element faces whose nodes all belong to the first set and that are
//! seen by one element only (boundary faces) make the surface; each face's area is split
//! equally among its nodes (corners and mid-edge nodes alike, so that no node gets the
//! negative share the serendipity shape functions give a quadratic face's corners). The areas
//! of the pairs sum to the area of the surface.
//!
//! **Directions**: the normal points out of the first set's body, into the second's, so that
//! the approach `(U_a − U_b)·n` grows as the surfaces press together; the two tangential
//! directions complete an orthonormal, right-handed frame `(t1, t2, n)`.

use faer::sparse::{SparseColMat, Triplet};
use faer::Mat;
use stickslip_core::model::Matrix;

use crate::assembly::FeModel;
use crate::eigen::{to_sparse, EigenError, ShiftedFactor};
use crate::element::shape::{HEX20_EDGES, TET10_EDGES};
use crate::element::SolidKind;
use crate::mesh::Mesh;

/// Largest number of node ids an error lists.
const LISTED: usize = 10;

/// Pairing tolerance relative to the shortest edge of the first set's faces: conforming
/// meshes put paired nodes at the same coordinates to round-off, and a thousandth of an edge
/// cannot reach a neighbouring node.
const RELATIVE_TOLERANCE: f64 = 1e-3;

/// What stops a patch from being built, naming the sets, nodes or pairs.
#[derive(Debug, thiserror::Error)]
pub enum PatchError {
    #[error("no node set {set:?} in the mesh (its sets are: {known})")]
    UnknownSet { set: String, known: String },
    #[error("node set {set:?} is empty")]
    EmptySet { set: String },
    #[error("node sets {set:?} and {other:?} do not pair up: {count} node(s) of {set:?} have no node of {other:?} at the same position (within {tolerance:.3e} m): nodes {nodes}")]
    Unpaired { set: String, other: String, count: usize, tolerance: f64, nodes: String },
    #[error("node sets {a:?} and {b:?} do not pair up one to one: node(s) {nodes} of {b:?} sit at the position of several nodes of {a:?}")]
    Ambiguous { a: String, b: String, nodes: String },
    #[error("node(s) {nodes} belong to both {a:?} and {b:?}: a node cannot touch itself; the two surfaces must be meshed apart, with coincident nodes")]
    SharedNodes { a: String, b: String, nodes: String },
    #[error("{count} node(s) of {set:?} lie on no element face whose nodes are all in the set, so they have no contact area: nodes {nodes} (the set must be a surface of the mesh)")]
    NoArea { set: String, count: usize, nodes: String },
    #[error("normal of the patch {a:?}–{b:?}: {message}")]
    Direction { a: String, b: String, message: String },
    #[error("node {node} of the patch has no independent DOF in direction {direction} and neither has its partner {partner}: the pair cannot move")]
    Immobile { node: u64, partner: u64, direction: String },
    #[error("{count} pair(s) are not pressed together at rest after the static pre-step (normal force <= 0 N: the preload opens them): {pairs}")]
    Tension { count: usize, pairs: String },
    #[error("static pre-step: the structure with its contacts closed cannot carry the preload: {0}")]
    Static(#[from] EigenError),
    #[error("static pre-step: the preload force vector has {got} values, the model {expected} DOFs")]
    LoadSize { got: usize, expected: usize },
}

/// One node-to-node contact: node `a` of the first set against node `b` of the second (mesh
/// node indices), with its tributary area (m²).
#[derive(Clone, Debug, PartialEq)]
pub struct ContactPair {
    pub a: usize,
    pub b: usize,
    pub area: f64,
}

/// The pairs of a patch and its frame: `normal` out of the first set's body, `tangents`
/// orthonormal to it (`t1 × t2 = n`).
#[derive(Clone, Debug, PartialEq)]
pub struct Patch {
    pub pairs: Vec<ContactPair>,
    pub normal: [f64; 3],
    pub tangents: [[f64; 3]; 2],
}

impl Patch {
    /// Area of the patch (m²): the sum of the tributary areas.
    pub fn area(&self) -> f64 {
        self.pairs.iter().map(|p| p.area).sum()
    }
}

/// A boundary face of a solid: its nodes (corners first), area (m²) and area vector pointing
/// out of the solid (m²).
struct Face {
    nodes: Vec<usize>,
    area: f64,
    outward: [f64; 3],
    shortest_edge: f64,
}

/// Corner lists of the faces of each solid kind (Abaqus node order).
fn corner_faces(kind: SolidKind) -> &'static [&'static [usize]] {
    if kind.is_tet() {
        &[&[0, 1, 2], &[0, 1, 3], &[1, 2, 3], &[0, 2, 3]]
    } else {
        &[&[0, 1, 2, 3], &[4, 5, 6, 7], &[0, 1, 5, 4], &[1, 2, 6, 5], &[2, 3, 7, 6], &[3, 0, 4, 7]]
    }
}

/// Local index of the mid-edge node between corners `c` and `d`, for quadratic kinds.
fn mid_edge(kind: SolidKind, c: usize, d: usize) -> Option<usize> {
    let (edges, first): (&[(usize, usize)], usize) = match kind {
        SolidKind::Tet10 => (&TET10_EDGES, 4),
        SolidKind::Hex20 | SolidKind::Hex20R => (&HEX20_EDGES, 8),
        SolidKind::Tet4 | SolidKind::Hex8 => return None,
    };
    edges.iter().position(|&(x, y)| (x, y) == (c, d) || (x, y) == (d, c)).map(|e| first + e)
}

fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]
}

fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

fn norm(a: [f64; 3]) -> f64 {
    dot(a, a).sqrt()
}

/// Area and area vector of a face through its corners: a triangle, or the bilinear surface of
/// a quadrilateral integrated by 2×2 Gauss points (exact for flat faces with straight edges).
fn face_area(x: &[[f64; 3]]) -> (f64, [f64; 3]) {
    if x.len() == 3 {
        let v = cross(sub(x[1], x[0]), sub(x[2], x[0])).map(|c| 0.5 * c);
        return (norm(v), v);
    }
    let g = 1.0 / 3f64.sqrt();
    let (mut area, mut vector) = (0.0, [0.0; 3]);
    for (s, t) in [(-g, -g), (g, -g), (g, g), (-g, g)] {
        // ∂x/∂ξ and ∂x/∂η of x = Σ N_i x_i, N_i = (1 ± ξ)(1 ± η)/4 (corners counter-clockwise).
        let dxi = [-(1.0 - t), 1.0 - t, 1.0 + t, -(1.0 + t)].map(|c| 0.25 * c);
        let deta = [-(1.0 - s), -(1.0 + s), 1.0 + s, 1.0 - s].map(|c| 0.25 * c);
        let combine = |w: [f64; 4]| [0, 1, 2].map(|d| (0..4).map(|i| w[i] * x[i][d]).sum::<f64>());
        let j = cross(combine(dxi), combine(deta));
        area += norm(j);
        vector = [0, 1, 2].map(|d| vector[d] + j[d]);
    }
    (area, vector)
}

/// The boundary faces of the mesh whose nodes all lie in `members` (indexed by mesh node).
fn surface_faces(mesh: &Mesh, members: &[bool]) -> Vec<Face> {
    // Ordered, so that the areas (sums over faces) round the same on every run.
    let mut seen: std::collections::BTreeMap<Vec<usize>, (usize, Option<Face>)> = std::collections::BTreeMap::new();
    for s in &mesh.solids {
        let centroid = {
            let corners = &s.nodes[..s.kind.n_corners()];
            let sum = corners.iter().fold([0.0; 3], |acc, &n| [0, 1, 2].map(|d| acc[d] + mesh.nodes[n].xyz[d]));
            sum.map(|c| c / corners.len() as f64)
        };
        for corners in corner_faces(s.kind) {
            let mut key: Vec<usize> = corners.iter().map(|&c| s.nodes[c]).collect();
            key.sort_unstable();
            let entry = seen.entry(key).or_insert((0, None));
            entry.0 += 1;
            if entry.0 > 1 {
                continue;
            }
            let mut nodes: Vec<usize> = corners.iter().map(|&c| s.nodes[c]).collect();
            for (i, &c) in corners.iter().enumerate() {
                if let Some(m) = mid_edge(s.kind, c, corners[(i + 1) % corners.len()]) {
                    nodes.push(s.nodes[m]);
                }
            }
            if !nodes.iter().all(|&n| members[n]) {
                continue;
            }
            let x: Vec<[f64; 3]> = corners.iter().map(|&c| mesh.nodes[s.nodes[c]].xyz).collect();
            let (area, mut vector) = face_area(&x);
            let centre = x.iter().fold([0.0; 3], |acc, p| [0, 1, 2].map(|d| acc[d] + p[d] / x.len() as f64));
            if dot(vector, sub(centre, centroid)) < 0.0 {
                vector = vector.map(|c| -c);
            }
            let shortest_edge =
                (0..x.len()).map(|i| norm(sub(x[(i + 1) % x.len()], x[i]))).fold(f64::INFINITY, f64::min);
            entry.1 = Some(Face { nodes, area, outward: vector, shortest_edge });
        }
    }
    // A face seen twice is inside the body (between two of its elements): not a surface.
    seen.into_values().filter(|(count, _)| *count == 1).filter_map(|(_, f)| f).collect()
}

/// Up to [`LISTED`] node ids, and how many more.
fn listed(mesh: &Mesh, nodes: &[usize]) -> String {
    let mut ids: Vec<u64> = nodes.iter().map(|&n| mesh.nodes[n].id).collect();
    ids.sort_unstable();
    let shown: Vec<String> = ids.iter().take(LISTED).map(u64::to_string).collect();
    if ids.len() > LISTED {
        format!("{}, ... ({} in all)", shown.join(", "), ids.len())
    } else {
        shown.join(", ")
    }
}

fn set_of<'m>(mesh: &'m Mesh, name: &str) -> Result<&'m [usize], PatchError> {
    let nodes = mesh.node_set(name).ok_or_else(|| PatchError::UnknownSet {
        set: name.into(),
        known: mesh.node_sets.keys().cloned().collect::<Vec<_>>().join(", "),
    })?;
    if nodes.is_empty() {
        return Err(PatchError::EmptySet { set: name.into() });
    }
    Ok(nodes)
}

/// Pair the nodes of sets `a` and `b` node to node and give each pair its tributary area.
///
/// `normal` (any length, pointing from `a`'s body into `b`'s) overrides the average outward
/// normal of `a`'s faces; `tangent` (any vector not along the normal) sets the first
/// tangential direction, projected onto the interface plane. Errors name the sets and up to
/// ten of the offending nodes: nodes without a partner, nodes in both sets, nodes of `a` on no
/// face of the set, a normal that points into `a`'s body.
pub fn pair_sets(
    mesh: &Mesh,
    a: &str,
    b: &str,
    normal: Option<[f64; 3]>,
    tangent: Option<[f64; 3]>,
) -> Result<Patch, PatchError> {
    let (set_a, set_b) = (set_of(mesh, a)?, set_of(mesh, b)?);
    let shared: Vec<usize> = set_a.iter().copied().filter(|n| set_b.binary_search(n).is_ok()).collect();
    if !shared.is_empty() {
        return Err(PatchError::SharedNodes { a: a.into(), b: b.into(), nodes: listed(mesh, &shared) });
    }
    let mut members = vec![false; mesh.nodes.len()];
    set_a.iter().for_each(|&n| members[n] = true);
    let faces = surface_faces(mesh, &members);
    let mut area = vec![0.0; mesh.nodes.len()];
    for f in &faces {
        for &n in &f.nodes {
            area[n] += f.area / f.nodes.len() as f64;
        }
    }
    let bare: Vec<usize> = set_a.iter().copied().filter(|&n| area[n] == 0.0).collect();
    if !bare.is_empty() {
        return Err(PatchError::NoArea { set: a.into(), count: bare.len(), nodes: listed(mesh, &bare) });
    }
    let tolerance = RELATIVE_TOLERANCE * faces.iter().map(|f| f.shortest_edge).fold(f64::INFINITY, f64::min);

    // Nodes of b sorted by x: each node of a looks at the b nodes within the tolerance in x.
    let mut by_x: Vec<usize> = set_b.to_vec();
    by_x.sort_by(|&p, &q| mesh.nodes[p].xyz[0].total_cmp(&mesh.nodes[q].xyz[0]));
    let mut partner_of_b = vec![None::<usize>; mesh.nodes.len()];
    let (mut pairs, mut unpaired, mut twice) = (Vec::new(), Vec::new(), Vec::new());
    for &na in set_a {
        let x = mesh.nodes[na].xyz;
        let start = by_x.partition_point(|&n| mesh.nodes[n].xyz[0] < x[0] - tolerance);
        let nearest = by_x[start..]
            .iter()
            .take_while(|&&n| mesh.nodes[n].xyz[0] <= x[0] + tolerance)
            .map(|&n| (n, norm(sub(mesh.nodes[n].xyz, x))))
            .filter(|&(_, d)| d <= tolerance)
            .min_by(|p, q| p.1.total_cmp(&q.1));
        match nearest {
            None => unpaired.push(na),
            Some((nb, _)) => {
                if partner_of_b[nb].replace(na).is_some() {
                    twice.push(nb);
                }
                pairs.push(ContactPair { a: na, b: nb, area: area[na] });
            }
        }
    }
    // Nodes of `set` without a partner in `other`.
    let unpaired_error = |set: &str, other: &str, nodes: &[usize]| PatchError::Unpaired {
        set: set.into(),
        other: other.into(),
        count: nodes.len(),
        tolerance,
        nodes: listed(mesh, nodes),
    };
    if !unpaired.is_empty() {
        return Err(unpaired_error(a, b, &unpaired));
    }
    if !twice.is_empty() {
        return Err(PatchError::Ambiguous { a: a.into(), b: b.into(), nodes: listed(mesh, &twice) });
    }
    let alone: Vec<usize> = set_b.iter().copied().filter(|&n| partner_of_b[n].is_none()).collect();
    if !alone.is_empty() {
        return Err(unpaired_error(b, a, &alone));
    }

    let direction_error = |message: String| PatchError::Direction { a: a.into(), b: b.into(), message };
    let total: f64 = faces.iter().map(|f| f.area).sum();
    let outward = faces.iter().fold([0.0; 3], |acc, f| [0, 1, 2].map(|d| acc[d] + f.outward[d]));
    let normal = match normal {
        Some(n) => {
            let length = norm(n);
            if !(length.is_finite() && length > 0.0) {
                return Err(direction_error(format!("the given normal {n:?} has no direction")));
            }
            if dot(n, outward) < 0.0 {
                return Err(direction_error(format!(
                    "the given normal {n:?} points into the body of {a:?}; it must point from {a:?} into {b:?}, so that the approach grows as the surfaces press together"
                )));
            }
            n.map(|c| c / length)
        }
        // A surface that turns (more than ~60° between its ends) has no single normal.
        None if norm(outward) < 0.5 * total => {
            return Err(direction_error(format!(
                "the faces of {a:?} are not flat enough for one normal (|Σ area vectors| = {:.3e} m² of {total:.3e} m²); give the normal",
                norm(outward)
            )))
        }
        None => outward.map(|c| c / norm(outward)),
    };
    let first = match tangent {
        Some(t) => t,
        // The coordinate axis least aligned with the normal.
        None => {
            let axis = (0..3).min_by(|&i, &j| normal[i].abs().total_cmp(&normal[j].abs())).unwrap_or(0);
            let mut e = [0.0; 3];
            e[axis] = 1.0;
            e
        }
    };
    let in_plane = sub(first, normal.map(|c| c * dot(first, normal)));
    let length = norm(in_plane);
    if !(length.is_finite() && length > 1e-9 * norm(first)) {
        return Err(direction_error(format!("the tangential direction {first:?} lies along the normal {normal:?}")));
    }
    let t1 = in_plane.map(|c| c / length);
    let t2 = cross(normal, t1);
    Ok(Patch { pairs, normal, tangents: [t1, t2] })
}

/// The relative displacement `(U_a − U_b)·direction` of mesh nodes `a` and `b` as a sparse
/// vector over the model's independent DOFs (`(index, coefficient)`, through the DOF map: fixed
/// DOFs contribute nothing, coupled ones their masters).
pub fn relative_vector(fe: &FeModel, a: usize, b: usize, direction: [f64; 3]) -> Vec<(usize, f64)> {
    let mut dense: std::collections::BTreeMap<usize, f64> = std::collections::BTreeMap::new();
    for (node, sign) in [(a, 1.0), (b, -1.0)] {
        for (d, &c) in direction.iter().enumerate() {
            if c == 0.0 {
                continue;
            }
            let Some(p) = fe.dofs.full(node, d as u8 + 1) else { continue };
            for (r, coefficient) in fe.dofs.row(p) {
                *dense.entry(r as usize).or_insert(0.0) += sign * c * coefficient;
            }
        }
    }
    dense.into_iter().filter(|&(_, v)| v != 0.0).collect()
}

/// The relative vectors of a pair along `directions`, refused when one is zero (both nodes
/// fixed in that direction).
pub fn pair_vectors(
    fe: &FeModel,
    pair: &ContactPair,
    directions: &[([f64; 3], &str)],
) -> Result<Vec<Vec<(usize, f64)>>, PatchError> {
    directions
        .iter()
        .map(|&(dir, name)| {
            let v = relative_vector(fe, pair.a, pair.b, dir);
            if v.is_empty() {
                Err(PatchError::Immobile {
                    node: fe.mesh.nodes[pair.a].id,
                    partner: fe.mesh.nodes[pair.b].id,
                    direction: name.into(),
                })
            } else {
                Ok(v)
            }
        })
        .collect()
}

/// A spring `k (vᵀ u)²/2` on a sparse vector `v` over the model's DOFs.
pub struct Spring<'v> {
    pub stiffness: f64,
    pub vector: &'v [(usize, f64)],
}

/// `K + Σ k v vᵀ`: the stiffness with the springs added (the structure with its contacts
/// closed and stuck, each contact's stiffnesses as springs), sparse.
pub fn with_springs(stiffness: &Matrix, springs: &[Spring]) -> SparseColMat<usize, f64> {
    let n = stiffness.nrows();
    let k = to_sparse(stiffness);
    let k = k.as_ref().as_ref();
    let mut triplets: Vec<Triplet<usize, usize, f64>> = Vec::with_capacity(k.compute_nnz());
    for j in 0..n {
        for (&i, &v) in k.symbolic().row_idx_of_col_raw(j).iter().zip(k.val_of_col(j)) {
            triplets.push(Triplet::new(i, j, v));
        }
    }
    for s in springs {
        for &(i, vi) in s.vector {
            for &(j, vj) in s.vector {
                triplets.push(Triplet::new(i, j, s.stiffness * vi * vj));
            }
        }
    }
    // Duplicates (K's entry and the springs' at one position) are summed.
    SparseColMat::try_new_from_triplets(n, n, &triplets).expect("indices of the model's DOFs are in range")
}

/// Static displacement `u` of `K u = F` under the preload `F` (N), `K` the stiffness of the
/// structure with its contacts closed ([`with_springs`]).
pub fn static_displacement(stiffness: &Matrix, force: &[f64]) -> Result<Vec<f64>, PatchError> {
    let n = stiffness.nrows();
    if force.len() != n {
        return Err(PatchError::LoadSize { got: force.len(), expected: n });
    }
    let k = to_sparse(stiffness);
    let factor = ShiftedFactor::new(k.as_ref().as_ref(), None, 0.0)?;
    if factor.eigenvalues_below_shift() > 0 {
        return Err(PatchError::Static(EigenError::Singular { shift: 0.0, dof: None }));
    }
    let mut u = Mat::from_fn(n, 1, |i, _| force[i]);
    factor.solve_in_place(u.as_mut());
    Ok((0..n).map(|i| u[(i, 0)]).collect())
}

/// Normal forces (N, compression positive) of the pairs in the static state `u`: `k_n` of each
/// pair times its approach; a pair that is not pressed (force ≤ 0) is an error naming the
/// pairs (node of the first set – node of the second, and the force).
pub fn normal_forces(
    fe: &FeModel,
    pairs: &[ContactPair],
    normal_vectors: &[&[(usize, f64)]],
    normal_stiffness: &[f64],
    u: &[f64],
) -> Result<Vec<f64>, PatchError> {
    let forces: Vec<f64> = normal_vectors
        .iter()
        .zip(normal_stiffness)
        .map(|(v, k)| k * v.iter().map(|&(i, c)| c * u[i]).sum::<f64>())
        .collect();
    let open: Vec<String> = pairs
        .iter()
        .zip(&forces)
        .filter(|(_, f)| f.is_nan() || **f <= 0.0)
        .map(|(p, f)| format!("{}–{} ({f:.3e} N)", fe.mesh.nodes[p.a].id, fe.mesh.nodes[p.b].id))
        .collect();
    if !open.is_empty() {
        let count = open.len();
        let mut shown = open.into_iter().take(LISTED).collect::<Vec<_>>().join(", ");
        if count > LISTED {
            shown.push_str(", ...");
        }
        return Err(PatchError::Tension { count, pairs: shown });
    }
    Ok(forces)
}

/// The force vector over the model's DOFs (N) of a total force `total` (N, x y z) spread
/// equally over the mesh nodes `nodes` (through the DOF map: `F_q = Tᵀ F`).
pub fn spread_force(fe: &FeModel, nodes: &[usize], total: [f64; 3]) -> Vec<f64> {
    let mut f = vec![0.0; fe.model.n_dofs()];
    let share = 1.0 / nodes.len().max(1) as f64;
    for &node in nodes {
        for (d, &c) in total.iter().enumerate() {
            let Some(p) = fe.dofs.full(node, d as u8 + 1) else { continue };
            for (r, coefficient) in fe.dofs.row(p) {
                f[r as usize] += share * c * coefficient;
            }
        }
    }
    f
}
