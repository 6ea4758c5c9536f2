//! Structured box meshes of hex8, hex20, tet4 and tet10 elements with named face node sets.
