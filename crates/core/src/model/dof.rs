use std::fmt;

/// Name of one degree of freedom. Models from a mesh know the node and direction (1..=6:
/// ux, uy, uz, rx, ry, rz); models written by hand only have a name.
#[derive(Clone, Debug, PartialEq, Eq, Hash, serde::Serialize, serde::Deserialize)]
pub struct DofLabel {
    pub name: String,
    pub node: Option<u64>,
    pub direction: Option<u8>,
}

impl DofLabel {
    /// A DOF known only by its name (inline study files, imported matrices without a map).
    pub fn named(name: impl Into<String>) -> Self {
        DofLabel { name: name.into(), node: None, direction: None }
    }

    /// A nodal DOF; its name is `node.direction` as in CalculiX `.dof` files (e.g. `12.3`).
    pub fn nodal(node: u64, direction: u8) -> Self {
        DofLabel { name: format!("{node}.{direction}"), node: Some(node), direction: Some(direction) }
    }

    /// A generalised (modal) coordinate of a reduced model.
    pub fn modal(index: usize) -> Self {
        DofLabel::named(format!("mode{}", index + 1))
    }
}

impl fmt::Display for DofLabel {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.name)
    }
}
