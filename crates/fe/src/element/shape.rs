//! Shape functions and their natural derivatives of the solid elements, in Abaqus/CalculiX
//! node order.

use super::SolidKind;

/// Natural coordinates of the hex8/hex20 nodes, Abaqus order: the bottom face (ζ = −1)
/// counter-clockwise, the top face, then the mid-edge nodes of the bottom, top and vertical edges.
pub const HEX_NODES: [[f64; 3]; 20] = [
    [-1.0, -1.0, -1.0],
    [1.0, -1.0, -1.0],
    [1.0, 1.0, -1.0],
    [-1.0, 1.0, -1.0],
    [-1.0, -1.0, 1.0],
    [1.0, -1.0, 1.0],
    [1.0, 1.0, 1.0],
    [-1.0, 1.0, 1.0],
    [0.0, -1.0, -1.0],
    [1.0, 0.0, -1.0],
    [0.0, 1.0, -1.0],
    [-1.0, 0.0, -1.0],
    [0.0, -1.0, 1.0],
    [1.0, 0.0, 1.0],
    [0.0, 1.0, 1.0],
    [-1.0, 0.0, 1.0],
    [-1.0, -1.0, 0.0],
    [1.0, -1.0, 0.0],
    [1.0, 1.0, 0.0],
    [-1.0, 1.0, 0.0],
];

/// Corner pairs of the tet10 mid-edge nodes 4..9 (Abaqus C3D10 order).
pub const TET10_EDGES: [(usize, usize); 6] = [(0, 1), (1, 2), (2, 0), (0, 3), (1, 3), (2, 3)];

/// Corner pairs of the hex20 mid-edge nodes 8..19 (Abaqus C3D20 order).
pub const HEX20_EDGES: [(usize, usize); 12] =
    [(0, 1), (1, 2), (2, 3), (3, 0), (4, 5), (5, 6), (6, 7), (7, 4), (0, 4), (1, 5), (2, 6), (3, 7)];

/// Shape functions `n[a]` and derivatives `dn[a] = ∂N_a/∂(ξ, η, ζ)` at `p`.
pub fn eval(kind: SolidKind, p: [f64; 3], n: &mut [f64], dn: &mut [[f64; 3]]) {
    let [x, y, z] = p;
    match kind {
        SolidKind::Tet4 => {
            n[..4].copy_from_slice(&[1.0 - x - y - z, x, y, z]);
            dn[..4].copy_from_slice(&[[-1.0, -1.0, -1.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]);
        }
        SolidKind::Tet10 => {
            // Barycentric coordinates and their natural gradients.
            let l = [1.0 - x - y - z, x, y, z];
            let dl = [[-1.0, -1.0, -1.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
            for a in 0..4 {
                n[a] = l[a] * (2.0 * l[a] - 1.0);
                for k in 0..3 {
                    dn[a][k] = (4.0 * l[a] - 1.0) * dl[a][k];
                }
            }
            for (e, &(i, j)) in TET10_EDGES.iter().enumerate() {
                n[4 + e] = 4.0 * l[i] * l[j];
                for k in 0..3 {
                    dn[4 + e][k] = 4.0 * (dl[i][k] * l[j] + l[i] * dl[j][k]);
                }
            }
        }
        SolidKind::Hex8 => {
            for a in 0..8 {
                let [xa, ya, za] = HEX_NODES[a];
                let (fx, fy, fz) = (1.0 + x * xa, 1.0 + y * ya, 1.0 + z * za);
                n[a] = 0.125 * fx * fy * fz;
                dn[a] = [0.125 * xa * fy * fz, 0.125 * fx * ya * fz, 0.125 * fx * fy * za];
            }
        }
        SolidKind::Hex20 | SolidKind::Hex20R => {
            for a in 0..20 {
                let [xa, ya, za] = HEX_NODES[a];
                let (fx, fy, fz) = (1.0 + x * xa, 1.0 + y * ya, 1.0 + z * za);
                if a < 8 {
                    let s = x * xa + y * ya + z * za - 2.0;
                    n[a] = 0.125 * fx * fy * fz * s;
                    dn[a] = [
                        0.125 * xa * fy * fz * (s + fx),
                        0.125 * ya * fx * fz * (s + fy),
                        0.125 * za * fx * fy * (s + fz),
                    ];
                } else if xa == 0.0 {
                    n[a] = 0.25 * (1.0 - x * x) * fy * fz;
                    dn[a] = [-0.5 * x * fy * fz, 0.25 * (1.0 - x * x) * ya * fz, 0.25 * (1.0 - x * x) * fy * za];
                } else if ya == 0.0 {
                    n[a] = 0.25 * (1.0 - y * y) * fx * fz;
                    dn[a] = [0.25 * (1.0 - y * y) * xa * fz, -0.5 * y * fx * fz, 0.25 * (1.0 - y * y) * fx * za];
                } else {
                    n[a] = 0.25 * (1.0 - z * z) * fx * fy;
                    dn[a] = [0.25 * (1.0 - z * z) * xa * fy, 0.25 * (1.0 - z * z) * fx * ya, -0.5 * z * fx * fy];
                }
            }
        }
    }
}

/// A quadrature rule on the reference element: points and weights.
pub fn rule(kind: SolidKind) -> Vec<([f64; 3], f64)> {
    match kind {
        // One point: exact for the constant strain of tet4 (CalculiX C3D4 uses it for K and M).
        SolidKind::Tet4 => vec![([0.25; 3], 1.0 / 6.0)],
        // Four points, degree 2: exact for the tet10 stiffness of straight-edged elements
        // (CalculiX C3D10 uses it for K and M).
        SolidKind::Tet10 => tet4_point(),
        SolidKind::Hex8 | SolidKind::Hex20R => gauss_hex(2),
        SolidKind::Hex20 => gauss_hex(3),
    }
}

fn tet4_point() -> Vec<([f64; 3], f64)> {
    let a = 0.585_410_196_624_968_5;
    let b = 0.138_196_601_125_010_5;
    let w = 1.0 / 24.0;
    vec![([b, b, b], w), ([a, b, b], w), ([b, a, b], w), ([b, b, a], w)]
}

/// Gauss-Legendre points and weights on [−1, 1].
fn gauss_1d(n: usize) -> Vec<(f64, f64)> {
    match n {
        1 => vec![(0.0, 2.0)],
        2 => {
            let p = 1.0 / 3f64.sqrt();
            vec![(-p, 1.0), (p, 1.0)]
        }
        3 => {
            let p = (0.6f64).sqrt();
            vec![(-p, 5.0 / 9.0), (0.0, 8.0 / 9.0), (p, 5.0 / 9.0)]
        }
        4 => {
            let a = (3.0 / 7.0 - 2.0 / 7.0 * (6.0f64 / 5.0).sqrt()).sqrt();
            let b = (3.0 / 7.0 + 2.0 / 7.0 * (6.0f64 / 5.0).sqrt()).sqrt();
            let wa = (18.0 + 30f64.sqrt()) / 36.0;
            let wb = (18.0 - 30f64.sqrt()) / 36.0;
            vec![(-b, wb), (-a, wa), (a, wa), (b, wb)]
        }
        _ => panic!("expected 1 to 4 Gauss points, got {n}"),
    }
}

/// Tensor-product Gauss rule with `n` points per direction on the cube [−1, 1]³.
pub fn gauss_hex(n: usize) -> Vec<([f64; 3], f64)> {
    let g = gauss_1d(n);
    let mut out = Vec::with_capacity(n * n * n);
    for &(z, wz) in &g {
        for &(y, wy) in &g {
            for &(x, wx) in &g {
                out.push(([x, y, z], wx * wy * wz));
            }
        }
    }
    out
}

/// Collapsed-cube (Duffy) rule on the unit tetrahedron with `n` Gauss points per direction:
/// exact for polynomials of degree `2n − 3` (the Jacobian `(1−u)²(1−v)` adds two degrees);
/// used for the exactly integrated mass.
pub fn duffy_tet(n: usize) -> Vec<([f64; 3], f64)> {
    let g: Vec<(f64, f64)> = gauss_1d(n).into_iter().map(|(x, w)| (0.5 * (x + 1.0), 0.5 * w)).collect();
    let mut out = Vec::with_capacity(n * n * n);
    for &(u, wu) in &g {
        for &(v, wv) in &g {
            for &(w, ww) in &g {
                let p = [u, (1.0 - u) * v, (1.0 - u) * (1.0 - v) * w];
                out.push((p, wu * wv * ww * (1.0 - u) * (1.0 - u) * (1.0 - v)));
            }
        }
    }
    out
}
