//! A lap joint: two flat plates of hexahedra, the upper one laid over the end of the lower one,
//! meshed apart with coincident nodes on the overlap (a conforming interface for node-to-node
//! contact patches, [`crate::patch`]).
//!
//! The lower plate A spans `x ∈ [0, L]`, `z ∈ [0, t]`; the upper plate B spans
//! `x ∈ [L − o, 2L − o]`, `z ∈ [t, 2t]`; both `y ∈ [0, W]`. Node sets:
//!
//! - `A_CONTACT`, `B_CONTACT`: the nodes of each plate on the overlap `x ∈ [L − o, L]`, `z = t`;
//! - `CLAMP`: the end `x = 0` of plate A;
//! - `BOLT_TOP`, `BOLT_BOTTOM`: the overlap's nodes on the top of B (`z = 2t`) and on the bottom
//!   of A (`z = 0`), where a bolt's clamping force acts;
//! - `TIP`: one node at the free end of B, `(2L − o, 0, 2t)`.

use super::structured::{placed_box, GenerateError, Part};
use super::{Material, Mesh};
use crate::element::SolidKind;

/// Dimensions (m) and mesh of a lap joint.
#[derive(Clone, Debug, PartialEq)]
pub struct LapJoint {
    /// Length L of each plate.
    pub length: f64,
    pub width: f64,
    /// Thickness t of each plate.
    pub thickness: f64,
    /// Cells along each plate's length; the overlap takes `overlap_cells` of them.
    pub cells_along: usize,
    pub overlap_cells: usize,
    pub cells_across: usize,
    pub cells_through: usize,
    pub kind: SolidKind,
}

impl LapJoint {
    /// Overlap length o (m).
    pub fn overlap(&self) -> f64 {
        self.length * self.overlap_cells as f64 / self.cells_along as f64
    }

    /// The mesh of both plates, of `material`, with the node sets of the module docs.
    pub fn build(&self, material: Material) -> Result<Mesh, GenerateError> {
        let fail = |msg: String| GenerateError::Geometry { part: "LAP_JOINT".into(), msg };
        if !(self.overlap_cells >= 1 && self.overlap_cells < self.cells_along) {
            return Err(fail(format!(
                "overlap_cells must lie in 1..{} (cells_along), got {}",
                self.cells_along, self.overlap_cells
            )));
        }
        for (name, v) in [("length", self.length), ("width", self.width), ("thickness", self.thickness)] {
            if !(v.is_finite() && v > 0.0) {
                return Err(fail(format!("{name} must be > 0 m, got {v}")));
            }
        }
        let (l, w, t, o) = (self.length, self.width, self.thickness, self.overlap());
        // Coincident nodes are a cell apart at least: a thousandth of the smallest cell merges
        // nothing that should stay apart.
        let h = (l / self.cells_along as f64).min(w / self.cells_across as f64).min(t / self.cells_through as f64);
        let tolerance = 1e-3 * h;
        let cells = [self.cells_along, self.cells_across, self.cells_through];
        let edges = [[l, 0.0, 0.0], [0.0, w, 0.0], [0.0, 0.0, t]];
        let mut mesh = Mesh::default();
        let mut first_node = 1u64;
        let mut first_element = 1u64;
        let near = |a: f64, b: f64| (a - b).abs() <= tolerance;
        for (name, origin) in [("PLATE_A", [0.0, 0.0, 0.0]), ("PLATE_B", [l - o, 0.0, t])] {
            let mut part = Part::new(name, self.kind, tolerance)?;
            part.add_block(&placed_box(origin, edges, cells, name))?;
            let ids: Vec<u64> = (first_node..first_node + part.nodes.len() as u64).collect();
            let index = part.add_to(&mut mesh, &ids, first_element, &[(name, "PLATE", material.clone())])?;
            first_node += part.nodes.len() as u64;
            first_element += part.elements.len() as u64;
            let on_overlap = |x: [f64; 3]| x[0] >= l - o - tolerance && x[0] <= l + tolerance;
            let set = |pred: &dyn Fn([f64; 3]) -> bool| -> Vec<usize> {
                part.nodes_where(pred).into_iter().map(|n| index[n]).collect()
            };
            if name == "PLATE_A" {
                mesh.add_node_set("A_CONTACT", set(&|x| on_overlap(x) && near(x[2], t)));
                mesh.add_node_set("BOLT_BOTTOM", set(&|x| on_overlap(x) && near(x[2], 0.0)));
                mesh.add_node_set("CLAMP", set(&|x| near(x[0], 0.0)));
            } else {
                mesh.add_node_set("B_CONTACT", set(&|x| on_overlap(x) && near(x[2], t)));
                mesh.add_node_set("BOLT_TOP", set(&|x| on_overlap(x) && near(x[2], 2.0 * t)));
                mesh.add_node_set("TIP", [index[part.nearest([2.0 * l - o, 0.0, 2.0 * t])]]);
            }
        }
        Ok(mesh)
    }
}
