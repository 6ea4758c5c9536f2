//! Mode shapes (or any nodal vectors) to a VTK legacy unstructured grid (`.vtk`), which
//! ParaView and VisIt open: the solids as cells, one point-vector field per shape.

use std::io::{self, Write};

use super::{Node, Solid};
use crate::element::SolidKind;

/// VTK cell type of a solid; VTK's quadratic tetra and hexahedron number their mid-edge nodes
/// as Abaqus does, so the node lists are written unchanged.
fn cell_type(kind: SolidKind) -> u8 {
    match kind {
        SolidKind::Tet4 => 10,
        SolidKind::Tet10 => 24,
        SolidKind::Hex8 => 12,
        SolidKind::Hex20 | SolidKind::Hex20R => 25,
    }
}

/// Write `nodes`, `solids` and the per-node vectors `fields` (name, one `[x, y, z]` per node;
/// names must not contain white space) as ASCII VTK legacy.
pub fn write(
    out: &mut impl Write,
    title: &str,
    nodes: &[Node],
    solids: &[Solid],
    fields: &[(String, Vec<[f64; 3]>)],
) -> io::Result<()> {
    // Nothing written where a value is not finite: ParaView would read NaN as a shape.
    let refuse =
        |what: String| Err(io::Error::new(io::ErrorKind::InvalidData, format!("{what}: refusing to write it")));
    if let Some(n) = super::non_finite_node(nodes) {
        return refuse(format!("node {} has coordinates {:?}, not finite", n + 1, nodes[n].xyz));
    }
    for (name, values) in fields {
        if let Some(n) = values.iter().position(|v| v.iter().any(|x| !x.is_finite())) {
            return refuse(format!("field `{name}` is {:?} at node {}, not finite", values[n], n + 1));
        }
    }
    writeln!(out, "# vtk DataFile Version 3.0")?;
    writeln!(out, "{}", title.lines().next().unwrap_or(""))?;
    writeln!(out, "ASCII\nDATASET UNSTRUCTURED_GRID")?;
    writeln!(out, "POINTS {} double", nodes.len())?;
    for n in nodes {
        writeln!(out, "{:e} {:e} {:e}", n.xyz[0], n.xyz[1], n.xyz[2])?;
    }
    let size: usize = solids.iter().map(|s| s.nodes.len() + 1).sum();
    writeln!(out, "CELLS {} {}", solids.len(), size)?;
    for s in solids {
        write!(out, "{}", s.nodes.len())?;
        for n in &s.nodes {
            write!(out, " {n}")?;
        }
        writeln!(out)?;
    }
    writeln!(out, "CELL_TYPES {}", solids.len())?;
    for s in solids {
        writeln!(out, "{}", cell_type(s.kind))?;
    }
    if !fields.is_empty() {
        writeln!(out, "POINT_DATA {}", nodes.len())?;
    }
    for (name, values) in fields {
        assert_eq!(values.len(), nodes.len(), "expected one vector per node ({}), got {}", nodes.len(), values.len());
        let name: String = name.chars().map(|c| if c.is_whitespace() { '_' } else { c }).collect();
        writeln!(out, "VECTORS {name} double")?;
        for v in values {
            writeln!(out, "{:e} {:e} {:e}", v[0], v[1], v[2])?;
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_field_that_is_not_finite_is_refused_and_nothing_written() {
        let nodes: Vec<Node> = (0..2).map(|i| Node { id: i + 1, xyz: [i as f64, 0.0, 0.0] }).collect();
        let fields = vec![("mode1".to_string(), vec![[0.0, 1.0, 0.0], [0.0, f64::NAN, 0.0]])];
        let mut out = Vec::new();
        let e = write(&mut out, "t", &nodes, &[], &fields).unwrap_err().to_string();
        assert!(e.contains("field `mode1` is [0.0, NaN, 0.0] at node 2, not finite: refusing to write it"), "{e}");
        assert!(out.is_empty(), "{}", String::from_utf8_lossy(&out));
    }
}
