//! Point elements: translational masses, springs between two DOFs or to ground, axial springs
//! and 6-component connectors, as lists of entries `((node, dir), (node, dir), value)`.

use crate::mesh::{Node, PointElement};

/// A matrix entry between DOF `(node index, direction 1..=6)` pairs.
pub type Entry = ((usize, u8), (usize, u8), f64);

/// Entries of a two-DOF spring `½ k (u_a − u_b)²` (or `½ k u_a²` to ground).
fn spring(a: (usize, u8), b: Option<(usize, u8)>, k: f64, out: &mut Vec<Entry>) {
    out.push((a, a, k));
    if let Some(b) = b {
        out.push((b, b, k));
        out.push((a, b, -k));
        out.push((b, a, -k));
    }
}

/// Stiffness entries of `p`; `None` for an axial spring between coincident nodes (no axis).
pub fn stiffness(p: &PointElement, nodes: &[Node], out: &mut Vec<Entry>) -> Option<()> {
    match *p {
        PointElement::Mass { .. } => {}
        PointElement::Spring { a, dir_a, b, stiffness, .. } => spring((a, dir_a), b, stiffness, out),
        PointElement::Connector { a, b, stiffness, .. } => {
            for (d, &k) in stiffness.iter().enumerate() {
                if k != 0.0 {
                    let dir = d as u8 + 1;
                    spring((a, dir), b.map(|b| (b, dir)), k, out);
                }
            }
        }
        PointElement::AxialSpring { a, b, stiffness, .. } => {
            let (xa, xb) = (nodes[a].xyz, nodes[b].xyz);
            let d = [xb[0] - xa[0], xb[1] - xa[1], xb[2] - xa[2]];
            let len = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
            if len == 0.0 {
                return None;
            }
            let n = d.map(|v| v / len);
            // K = k [n nᵀ, −n nᵀ; −n nᵀ, n nᵀ] on the translations.
            for i in 0..3 {
                for j in 0..3 {
                    let v = stiffness * n[i] * n[j];
                    if v != 0.0 {
                        let (di, dj) = (i as u8 + 1, j as u8 + 1);
                        out.push(((a, di), (a, dj), v));
                        out.push(((b, di), (b, dj), v));
                        out.push(((a, di), (b, dj), -v));
                        out.push(((b, di), (a, dj), -v));
                    }
                }
            }
        }
    }
    Some(())
}

/// Mass entries of `p` (a point mass acts on the three translations).
pub fn mass(p: &PointElement, out: &mut Vec<Entry>) {
    if let PointElement::Mass { node, mass, .. } = *p {
        for d in 1..=3 {
            out.push(((node, d), (node, d), mass));
        }
    }
}
