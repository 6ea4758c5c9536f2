//! Element matrices (paper Section 3.1): isotropic linear elastic solids with consistent mass
//! (tet4, tet10, hex8, hex20, hex20R) and point elements (masses, springs, connectors).
//!
//! Solid matrices are in node-major DOF order (`3a + i` for direction `i` of node `a`). The
//! mass is stored as the scalar `ρ ∫ N_a N_b dV` (the 3×3 block of nodes a, b is that times I).

pub mod point;
pub mod shape;

use crate::mesh::Material;

/// The solid element types, named as in Abaqus/CalculiX.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum SolidKind {
    /// C3D4: linear tetrahedron.
    Tet4,
    /// C3D10: quadratic tetrahedron.
    Tet10,
    /// C3D8: trilinear hexahedron, full 2×2×2 integration.
    Hex8,
    /// C3D20: quadratic serendipity hexahedron, full 3×3×3 integration.
    Hex20,
    /// C3D20R: C3D20 with reduced 2×2×2 integration.
    Hex20R,
}

impl SolidKind {
    pub const ALL: [SolidKind; 5] =
        [SolidKind::Tet4, SolidKind::Tet10, SolidKind::Hex8, SolidKind::Hex20, SolidKind::Hex20R];

    pub fn n_nodes(self) -> usize {
        match self {
            SolidKind::Tet4 => 4,
            SolidKind::Tet10 => 10,
            SolidKind::Hex8 => 8,
            SolidKind::Hex20 | SolidKind::Hex20R => 20,
        }
    }

    /// The Abaqus/CalculiX name (`C3D10`, ...).
    pub fn abaqus_name(self) -> &'static str {
        match self {
            SolidKind::Tet4 => "C3D4",
            SolidKind::Tet10 => "C3D10",
            SolidKind::Hex8 => "C3D8",
            SolidKind::Hex20 => "C3D20",
            SolidKind::Hex20R => "C3D20R",
        }
    }

    /// The kind named `name` (case-insensitive Abaqus/CalculiX name).
    pub fn from_abaqus(name: &str) -> Option<SolidKind> {
        SolidKind::ALL.into_iter().find(|k| k.abaqus_name().eq_ignore_ascii_case(name))
    }

    /// Is it a tetrahedron (natural coordinates in the unit simplex) or a hexahedron ([−1, 1]³)?
    pub fn is_tet(self) -> bool {
        matches!(self, SolidKind::Tet4 | SolidKind::Tet10)
    }

    /// Number of corner (vertex) nodes.
    pub fn n_corners(self) -> usize {
        if self.is_tet() {
            4
        } else {
            8
        }
    }
}

/// How the consistent mass `ρ ∫ N_a N_b dV` is integrated.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum MassRule {
    /// With the stiffness points, as CalculiX does (C3D4: 1 point, C3D10: 4 points, C3D8 and
    /// C3D20R: 2×2×2, C3D20: 3×3×3), so that a deck gives CalculiX's frequencies. Exact for
    /// C3D8 and C3D20 on affine elements, under-integrated for C3D4, C3D10 and C3D20R.
    #[default]
    CalculiX,
    /// Exactly for affine elements (and to higher order on curved ones).
    Exact,
}

/// Shape functions and natural derivatives tabulated at the quadrature points of one kind.
#[derive(Clone, Debug)]
pub struct Tabulated {
    pub kind: SolidKind,
    n_nodes: usize,
    stiffness: Vec<Point>,
    mass: Vec<Point>,
}

#[derive(Clone, Debug)]
struct Point {
    weight: f64,
    n: Vec<f64>,
    dn: Vec<[f64; 3]>,
}

fn tabulate(kind: SolidKind, rule: &[([f64; 3], f64)]) -> Vec<Point> {
    let nn = kind.n_nodes();
    rule.iter()
        .map(|&(p, weight)| {
            let mut n = vec![0.0; nn];
            let mut dn = vec![[0.0; 3]; nn];
            shape::eval(kind, p, &mut n, &mut dn);
            Point { weight, n, dn }
        })
        .collect()
}

impl Tabulated {
    pub fn new(kind: SolidKind, mass_rule: MassRule) -> Self {
        let stiffness = tabulate(kind, &shape::rule(kind));
        let mass = match mass_rule {
            MassRule::CalculiX => stiffness.clone(),
            MassRule::Exact => {
                let rule = match kind {
                    SolidKind::Tet4 => shape::duffy_tet(3),
                    SolidKind::Tet10 => shape::duffy_tet(4),
                    SolidKind::Hex8 => shape::gauss_hex(3),
                    SolidKind::Hex20 | SolidKind::Hex20R => shape::gauss_hex(4),
                };
                tabulate(kind, &rule)
            }
        };
        Tabulated { kind, n_nodes: kind.n_nodes(), stiffness, mass }
    }

    pub fn n_nodes(&self) -> usize {
        self.n_nodes
    }
}

/// The element is inverted or degenerate: the Jacobian determinant at a quadrature point is
/// not positive.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BadJacobian {
    pub det: f64,
}

/// Jacobian `J[k][l] = ∂x_l/∂ξ_k`, its determinant and the physical gradients `g_a = J⁻¹ ∂N_a/∂ξ`.
fn gradients(xyz: &[[f64; 3]], dn: &[[f64; 3]], g: &mut [[f64; 3]]) -> f64 {
    let mut j = [[0.0; 3]; 3];
    for (x, d) in xyz.iter().zip(dn) {
        for k in 0..3 {
            for l in 0..3 {
                j[k][l] += d[k] * x[l];
            }
        }
    }
    let det = j[0][0] * (j[1][1] * j[2][2] - j[1][2] * j[2][1]) - j[0][1] * (j[1][0] * j[2][2] - j[1][2] * j[2][0])
        + j[0][2] * (j[1][0] * j[2][1] - j[1][1] * j[2][0]);
    let inv = [
        [
            j[1][1] * j[2][2] - j[1][2] * j[2][1],
            j[0][2] * j[2][1] - j[0][1] * j[2][2],
            j[0][1] * j[1][2] - j[0][2] * j[1][1],
        ],
        [
            j[1][2] * j[2][0] - j[1][0] * j[2][2],
            j[0][0] * j[2][2] - j[0][2] * j[2][0],
            j[0][2] * j[1][0] - j[0][0] * j[1][2],
        ],
        [
            j[1][0] * j[2][1] - j[1][1] * j[2][0],
            j[0][1] * j[2][0] - j[0][0] * j[2][1],
            j[0][0] * j[1][1] - j[0][1] * j[1][0],
        ],
    ];
    for (ga, d) in g.iter_mut().zip(dn) {
        for l in 0..3 {
            ga[l] = (inv[l][0] * d[0] + inv[l][1] * d[1] + inv[l][2] * d[2]) / det;
        }
    }
    det
}

/// Relative size below which a Jacobian determinant counts as degenerate (flat element):
/// round-off of a well-shaped element is ~1e-16 of the element's scale.
const DEGENERATE: f64 = 1e-12;

/// Stiffness `k` (3n × 3n, row-major) and scalar mass `m` (n × n, row-major) of a solid with
/// node coordinates `xyz`; returns the volume. Overwrites `k` and `m`.
///
/// `K_{ai,bj} = ∫ λ g_a,i g_b,j + μ g_a,j g_b,i + μ δ_ij g_a·g_b dV` (isotropic Hooke's law
/// written node pair by node pair, no B matrix), `m_ab = ρ ∫ N_a N_b dV`.
pub fn solid_matrices(
    tab: &Tabulated,
    xyz: &[[f64; 3]],
    material: &Material,
    k: &mut [f64],
    m: &mut [f64],
) -> Result<f64, BadJacobian> {
    let nn = tab.n_nodes;
    let nd = 3 * nn;
    assert_eq!(xyz.len(), nn, "expected {nn} node coordinates, got {}", xyz.len());
    let (e, nu) = (material.young, material.poisson);
    let lambda = e * nu / ((1.0 + nu) * (1.0 - 2.0 * nu));
    let mu = e / (2.0 * (1.0 + nu));
    let scale = element_scale(xyz);
    k[..nd * nd].iter_mut().for_each(|v| *v = 0.0);
    m[..nn * nn].iter_mut().for_each(|v| *v = 0.0);
    let mut g = [[0.0; 3]; 20];
    let mut volume = 0.0;
    for p in &tab.stiffness {
        let det = gradients(xyz, &p.dn, &mut g[..nn]);
        if det.is_nan() || det <= DEGENERATE * scale {
            return Err(BadJacobian { det });
        }
        let w = p.weight * det;
        volume += w;
        for a in 0..nn {
            let ga = g[a];
            for b in a..nn {
                let gb = g[b];
                let dot = mu * (ga[0] * gb[0] + ga[1] * gb[1] + ga[2] * gb[2]);
                for i in 0..3 {
                    let row = &mut k[(3 * a + i) * nd + 3 * b..(3 * a + i) * nd + 3 * b + 3];
                    for j in 0..3 {
                        let mut v = lambda * ga[i] * gb[j] + mu * ga[j] * gb[i];
                        if i == j {
                            v += dot;
                        }
                        row[j] += w * v;
                    }
                }
            }
        }
    }
    // Mirror the upper node blocks (K_ba = K_abᵀ).
    for a in 0..nn {
        for b in a + 1..nn {
            for i in 0..3 {
                for j in 0..3 {
                    k[(3 * b + j) * nd + 3 * a + i] = k[(3 * a + i) * nd + 3 * b + j];
                }
            }
        }
    }
    let rho = material.density;
    for p in &tab.mass {
        let det = gradients(xyz, &p.dn, &mut g[..nn]);
        if det.is_nan() || det <= DEGENERATE * scale {
            return Err(BadJacobian { det });
        }
        let w = rho * p.weight * det;
        for a in 0..nn {
            for b in a..nn {
                m[a * nn + b] += w * p.n[a] * p.n[b];
            }
        }
    }
    for a in 0..nn {
        for b in a + 1..nn {
            m[b * nn + a] = m[a * nn + b];
        }
    }
    Ok(volume)
}

/// Cube of the element's bounding-box diagonal: the scale of a Jacobian determinant.
fn element_scale(xyz: &[[f64; 3]]) -> f64 {
    let mut lo = [f64::INFINITY; 3];
    let mut hi = [f64::NEG_INFINITY; 3];
    for x in xyz {
        for k in 0..3 {
            lo[k] = lo[k].min(x[k]);
            hi[k] = hi[k].max(x[k]);
        }
    }
    let d2: f64 = (0..3).map(|k| (hi[k] - lo[k]).powi(2)).sum();
    d2.powf(1.5)
}
