//! Gmsh `.msh` 4.1 ASCII files from a [`Mesh`]: the nodes (all of them, in mesh order), the
//! solids (in mesh order, as Gmsh types 4, 11, 5, 17 with the node order converted from
//! Abaqus's to Gmsh's), the element sets as physical volumes and the node sets as physical
//! points, so that [`super::gmsh::read`] gives back the same nodes, solids and node sets.
//!
//! Layout: the solids are split into volume entities by the element sets and materials they
//! belong to (solids in the same sets with the same material share an entity), so each element
//! set is a physical volume made of whole entities. When the solids use several materials and a
//! material's solids are not exactly an element set, a physical volume named after the material
//! is added (`SOLIDS_<name>` if that name is an element set already), so that the materials can
//! be given back with [`Mesh::assign_material`] per group. Each node that is in a node set is a
//! point entity carrying one point element (type 15), tagged with the physical points of its
//! sets. All nodes are listed in one node block of the first volume entity; point element tags
//! follow the largest solid id.
//!
//! What a `.msh` file cannot hold, and is not written: point elements (masses, springs,
//! connectors), rigid couplings, fixed DOFs, equations, materials and the number of modes
//! asked; give materials back with [`Mesh::assign_material`] and the rest in code (or write a
//! deck with [`super::inp_writer`], which holds everything). Empty node and element sets are
//! lost (Gmsh has no empty physical group). C3D20R solids are written as Gmsh's 20-node
//! hexahedron (type 17) and read back as C3D20 (full integration). The reader also makes a node
//! set of each physical volume (the nodes of its elements): reading back gives the mesh's node
//! sets plus one per element set, and a node set and an element set of the same name merge.

use std::collections::{BTreeMap, HashMap, HashSet};
use std::fmt::Write as _;
use std::path::Path;

use super::gmsh::abaqus_order;
use super::{Mesh, MeshError, Origin};
use crate::element::SolidKind;

/// Write `mesh` as a Gmsh 4.1 ASCII file to `path` (nothing is written if the mesh cannot be
/// expressed, e.g. a set name with a quote).
pub fn write(mesh: &Mesh, path: impl AsRef<Path>) -> Result<(), MeshError> {
    super::write_text(path.as_ref(), &to_string(mesh)?)
}

/// Gmsh element type of a solid kind.
fn gmsh_type(kind: SolidKind) -> u32 {
    match kind {
        SolidKind::Tet4 => 4,
        SolidKind::Tet10 => 11,
        SolidKind::Hex8 => 5,
        SolidKind::Hex20 | SolidKind::Hex20R => 17,
    }
}

fn unwritable(msg: String) -> MeshError {
    MeshError::Syntax { at: Origin::default(), msg: format!("cannot write the mesh as a Gmsh file: {msg}") }
}

/// A physical name must fit between the quotes of its `$PhysicalNames` line.
fn check_name(what: &str, name: &str) -> Result<(), MeshError> {
    if name.trim().is_empty() || name.chars().any(|c| c == '"' || c.is_control()) {
        return Err(unwritable(format!("{what} name {name:?} is empty or holds a quote or a control character")));
    }
    Ok(())
}

/// A volume entity: its physical volumes and its solids' bounding box.
struct Volume {
    physicals: Vec<usize>,
    min: [f64; 3],
    max: [f64; 3],
}

/// The `.msh` text for `mesh`.
pub fn to_string(mesh: &Mesh) -> Result<String, MeshError> {
    if let Some(n) = super::non_finite_node(&mesh.nodes).map(|i| &mesh.nodes[i]) {
        return Err(unwritable(format!("node {} has coordinates {:?}, not finite", n.id, n.xyz)));
    }
    let mut ids = HashSet::with_capacity(mesh.solids.len());
    for s in &mesh.solids {
        if !ids.insert(s.id) {
            return Err(MeshError::DuplicateElement { at: Origin::default(), element: s.id });
        }
    }
    for name in mesh.node_sets.keys() {
        check_name("node set", name)?;
    }
    for name in mesh.element_sets.keys() {
        check_name("element set", name)?;
    }

    // Physical volumes: the non-empty element sets, then materials not described by one.
    let mut volume_groups: Vec<(String, Vec<usize>)> = mesh
        .element_sets
        .iter()
        .filter(|(_, v)| !v.is_empty())
        .map(|(name, v)| {
            let mut v = v.clone();
            v.sort_unstable();
            v.dedup();
            (name.to_uppercase(), v)
        })
        .collect();
    let mut by_material: BTreeMap<usize, Vec<usize>> = BTreeMap::new();
    for (i, s) in mesh.solids.iter().enumerate() {
        if let Some(m) = s.material {
            by_material.entry(m).or_default().push(i);
        }
    }
    if by_material.len() > 1 {
        let mut taken: HashSet<String> = volume_groups.iter().map(|(n, _)| n.clone()).collect();
        for (m, solids) in by_material {
            if volume_groups.iter().any(|(_, v)| *v == solids) {
                continue;
            }
            let material =
                mesh.materials.get(m).map(|(n, _)| n.to_uppercase()).unwrap_or_else(|| format!("MATERIAL{m}"));
            check_name("material", &material)?;
            let mut name = material.clone();
            if taken.contains(&name) {
                name = format!("SOLIDS_{material}");
                let mut k = 2;
                while taken.contains(&name) {
                    name = format!("SOLIDS_{material}_{k}");
                    k += 1;
                }
            }
            taken.insert(name.clone());
            volume_groups.push((name, solids));
        }
    }
    let mut solid_groups: Vec<Vec<usize>> = vec![Vec::new(); mesh.solids.len()];
    for (g, (_, solids)) in volume_groups.iter().enumerate() {
        for &s in solids {
            solid_groups[s].push(g + 1);
        }
    }

    // Volume entities, numbered in order of first appearance; the entity of each solid.
    let mut volumes: Vec<Volume> = Vec::new();
    let mut entity_of: HashMap<(Option<usize>, &[usize]), usize> = HashMap::new();
    let mut solid_entity = Vec::with_capacity(mesh.solids.len());
    for (s, solid) in mesh.solids.iter().enumerate() {
        let key = (solid.material, solid_groups[s].as_slice());
        let e = *entity_of.entry(key).or_insert_with(|| {
            volumes.push(Volume { physicals: key.1.to_vec(), min: [f64::INFINITY; 3], max: [f64::NEG_INFINITY; 3] });
            volumes.len() - 1
        });
        for &n in &solid.nodes {
            let v = &mut volumes[e];
            for d in 0..3 {
                v.min[d] = v.min[d].min(mesh.nodes[n].xyz[d]);
                v.max[d] = v.max[d].max(mesh.nodes[n].xyz[d]);
            }
        }
        solid_entity.push(e + 1);
    }
    if volumes.is_empty() {
        // No solid: one empty volume still carries the node block.
        volumes.push(Volume { physicals: Vec::new(), min: [f64::INFINITY; 3], max: [f64::NEG_INFINITY; 3] });
        for node in &mesh.nodes {
            for d in 0..3 {
                volumes[0].min[d] = volumes[0].min[d].min(node.xyz[d]);
                volumes[0].max[d] = volumes[0].max[d].max(node.xyz[d]);
            }
        }
    }
    for v in &mut volumes {
        if v.min[0] > v.max[0] {
            (v.min, v.max) = ([0.0; 3], [0.0; 3]);
        }
    }

    // Physical points: the non-empty node sets; a point entity per node in any of them.
    let point_groups: Vec<(&String, &Vec<usize>)> = mesh.node_sets.iter().filter(|(_, v)| !v.is_empty()).collect();
    let mut node_groups: Vec<Vec<usize>> = vec![Vec::new(); mesh.nodes.len()];
    for (g, (_, nodes)) in point_groups.iter().enumerate() {
        for &n in nodes.iter() {
            if node_groups[n].last() != Some(&(g + 1)) {
                node_groups[n].push(g + 1);
            }
        }
    }
    let points: Vec<usize> = (0..mesh.nodes.len()).filter(|&n| !node_groups[n].is_empty()).collect();

    let mut out = String::new();
    out.push_str("$MeshFormat\n4.1 0 8\n$EndMeshFormat\n");

    let n_names = point_groups.len() + volume_groups.len();
    if n_names > 0 {
        let _ = writeln!(out, "$PhysicalNames\n{n_names}");
        for (g, (name, _)) in point_groups.iter().enumerate() {
            let _ = writeln!(out, "0 {} \"{}\"", g + 1, name.to_uppercase());
        }
        for (g, (name, _)) in volume_groups.iter().enumerate() {
            let _ = writeln!(out, "3 {} \"{name}\"", g + 1);
        }
        out.push_str("$EndPhysicalNames\n");
    }

    let _ = writeln!(out, "$Entities\n{} 0 0 {}", points.len(), volumes.len());
    let tags = |t: &[usize]| t.iter().map(|g| format!(" {g}")).collect::<String>();
    for (p, &n) in points.iter().enumerate() {
        let [x, y, z] = mesh.nodes[n].xyz;
        let g = &node_groups[n];
        let _ = writeln!(out, "{} {x:?} {y:?} {z:?} {}{}", p + 1, g.len(), tags(g));
    }
    for (e, v) in volumes.iter().enumerate() {
        let ([x0, y0, z0], [x1, y1, z1]) = (v.min, v.max);
        let _ = writeln!(
            out,
            "{} {x0:?} {y0:?} {z0:?} {x1:?} {y1:?} {z1:?} {}{} 0",
            e + 1,
            v.physicals.len(),
            tags(&v.physicals)
        );
    }
    out.push_str("$EndEntities\n");

    let n_nodes = mesh.nodes.len();
    let (min_tag, max_tag) = mesh.nodes.iter().fold((u64::MAX, 0), |(a, b), n| (a.min(n.id), b.max(n.id)));
    let blocks = usize::from(n_nodes > 0);
    let _ = writeln!(out, "$Nodes\n{blocks} {n_nodes} {} {max_tag}", if n_nodes > 0 { min_tag } else { 0 });
    if n_nodes > 0 {
        let _ = writeln!(out, "3 1 0 {n_nodes}");
        for node in &mesh.nodes {
            let _ = writeln!(out, "{}", node.id);
        }
        for node in &mesh.nodes {
            let [x, y, z] = node.xyz;
            let _ = writeln!(out, "{x:?} {y:?} {z:?}");
        }
    }
    out.push_str("$EndNodes\n");

    // Element blocks: runs of consecutive solids of one entity and type (keeping the solids'
    // order), then one point element per point entity.
    let mut runs: Vec<(usize, usize)> = Vec::new();
    let mut start = 0;
    while start < mesh.solids.len() {
        let key = (solid_entity[start], gmsh_type(mesh.solids[start].kind));
        let len = (start..mesh.solids.len())
            .take_while(|&s| (solid_entity[s], gmsh_type(mesh.solids[s].kind)) == key)
            .count();
        runs.push((start, start + len));
        start += len;
    }
    let max_solid = mesh.solids.iter().map(|s| s.id).max().unwrap_or(0);
    let min_solid = mesh.solids.iter().map(|s| s.id).min().unwrap_or(max_solid + 1);
    let n_elements = mesh.solids.len() + points.len();
    let (min_el, max_el) = match (mesh.solids.is_empty(), points.is_empty()) {
        (true, true) => (0, 0),
        (true, false) => (max_solid + 1, max_solid + points.len() as u64),
        (false, true) => (min_solid, max_solid),
        (false, false) => (min_solid, max_solid + points.len() as u64),
    };
    let _ = writeln!(out, "$Elements\n{} {n_elements} {min_el} {max_el}", runs.len() + points.len());
    let mut gmsh_nodes = [0u64; 20];
    for &(a, b) in &runs {
        let first = &mesh.solids[a];
        let _ = writeln!(out, "3 {} {} {}", solid_entity[a], gmsh_type(first.kind), b - a);
        for s in &mesh.solids[a..b] {
            // The reader takes Abaqus node i from Gmsh position order[i]: put it back there.
            let order = abaqus_order(s.kind);
            for (i, &n) in s.nodes.iter().enumerate() {
                gmsh_nodes[order[i]] = mesh.nodes[n].id;
            }
            let _ = write!(out, "{}", s.id);
            for id in &gmsh_nodes[..s.nodes.len()] {
                let _ = write!(out, " {id}");
            }
            out.push('\n');
        }
    }
    for (p, &n) in points.iter().enumerate() {
        let _ = writeln!(out, "0 {} 15 1\n{} {}", p + 1, max_solid + 1 + p as u64, mesh.nodes[n].id);
    }
    out.push_str("$EndElements\n");
    Ok(out)
}
