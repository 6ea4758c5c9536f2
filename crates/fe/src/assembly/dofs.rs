//! The DOF map: which nodal DOFs exist, which are fixed, which depend on others through rigid
//! couplings and `*EQUATION`s, and the sparse transformation `u_full = T q` onto the
//! independent DOFs `q` (so that `K_red = Tᵀ K T`, `M_red = Tᵀ M T`).

use std::collections::HashMap;

use super::AssemblyError;
use crate::mesh::{Mesh, PointElement};

/// Rows of `T` in compressed form: full DOF `p` is `Σ val[k] q[idx[k]]` over `k ∈ ptr[p]..ptr[p+1]`.
#[derive(Clone, Debug)]
pub struct DofMap {
    /// First full DOF of each node.
    pub offset: Vec<usize>,
    /// Number of DOFs of each node: 3, or 6 for nodes with rotations (reference nodes).
    pub n_dirs: Vec<u8>,
    pub ptr: Vec<usize>,
    pub idx: Vec<u32>,
    pub val: Vec<f64>,
    /// Independent DOFs: (node index, direction 1..=6), in the model's order.
    pub independent: Vec<(usize, u8)>,
    /// Reduced index of each full DOF that is independent.
    pub reduced: Vec<Option<u32>>,
}

#[derive(Clone, Debug)]
enum Status {
    Inactive,
    Free,
    Fixed,
    /// Depends linearly on other full DOFs; the string says which constraint.
    Dependent(Vec<(usize, f64)>, String),
}

impl DofMap {
    pub fn full(&self, node: usize, dir: u8) -> Option<usize> {
        (dir >= 1 && dir <= self.n_dirs[node]).then(|| self.offset[node] + dir as usize - 1)
    }

    /// `(reduced index, coefficient)` terms of full DOF `p`.
    pub fn row(&self, p: usize) -> impl Iterator<Item = (u32, f64)> + '_ {
        (self.ptr[p]..self.ptr[p + 1]).map(|k| (self.idx[k], self.val[k]))
    }

    pub fn n_full(&self) -> usize {
        self.ptr.len() - 1
    }

    pub fn build(mesh: &Mesh) -> Result<DofMap, AssemblyError> {
        let nn = mesh.nodes.len();
        let mut n_dirs = vec![3u8; nn];
        let mut wants = |node: usize, dir: u8| {
            if dir > 3 {
                n_dirs[node] = 6;
            }
        };
        for c in &mesh.couplings {
            wants(c.reference, 6);
        }
        for p in &mesh.points {
            match *p {
                PointElement::Spring { a, dir_a, b, .. } => {
                    wants(a, dir_a);
                    if let Some((b, db)) = b {
                        wants(b, db);
                    }
                }
                PointElement::Connector { a, b, stiffness, .. } if stiffness[3..].iter().any(|k| *k != 0.0) => {
                    wants(a, 6);
                    if let Some(b) = b {
                        wants(b, 6);
                    }
                }
                _ => {}
            }
        }
        for e in &mesh.equations {
            for &(n, d, _) in &e.terms {
                wants(n, d);
            }
        }
        let mut offset = Vec::with_capacity(nn);
        let mut total = 0;
        for &d in &n_dirs {
            offset.push(total);
            total += d as usize;
        }
        let full = |node: usize, dir: u8| offset[node] + dir as usize - 1;
        let mut status = vec![Status::Inactive; total];
        // Active DOFs: those an element or a constraint acts on.
        for s in &mesh.solids {
            for &n in &s.nodes {
                for d in 1..=3 {
                    status[full(n, d)] = Status::Free;
                }
            }
        }
        let mut entries = Vec::new();
        for p in &mesh.points {
            entries.clear();
            crate::element::point::stiffness(p, &mesh.nodes, &mut entries);
            crate::element::point::mass(p, &mut entries);
            for &((n, d), _, _) in &entries {
                status[full(n, d)] = Status::Free;
            }
        }
        for e in &mesh.equations {
            for &(n, d, _) in &e.terms {
                status[full(n, d)] = Status::Free;
            }
        }
        let node_id = |n: usize| mesh.nodes[n].id;
        // Dependent DOFs: rigid couplings, then equations.
        for c in &mesh.couplings {
            let r = c.reference;
            let xr = mesh.nodes[r].xyz;
            for &s in &c.nodes {
                if s == r {
                    continue;
                }
                let xs = mesh.nodes[s].xyz;
                let a = [xs[0] - xr[0], xs[1] - xr[1], xs[2] - xr[2]];
                for &d in &c.dofs {
                    if d > n_dirs[s] {
                        continue;
                    }
                    // u_s = u_r + θ_r × a: (θ × a)_x = θ_y a_z − θ_z a_y, and cyclic.
                    let mut terms = vec![(full(r, d), 1.0)];
                    if d <= 3 {
                        let (j, k) = match d {
                            1 => (1, 2),
                            2 => (2, 0),
                            _ => (0, 1),
                        };
                        terms.push((full(r, 4 + j as u8), a[k]));
                        terms.push((full(r, 4 + k as u8), -a[j]));
                    }
                    // The reference DOFs a slave follows are active (only those: a coupling
                    // of DOF 1 alone leaves the reference's u_y, u_z, θ_x massless and out).
                    for &(q, c) in &terms {
                        if c != 0.0 && matches!(status[q], Status::Inactive) {
                            status[q] = Status::Free;
                        }
                    }
                    let p = full(s, d);
                    if let Status::Dependent(_, by) = &status[p] {
                        return Err(AssemblyError::DoublyConstrained {
                            node: node_id(s),
                            dir: d,
                            first: by.clone(),
                            second: format!("the rigid coupling at {}", c.at),
                        });
                    }
                    status[p] = Status::Dependent(terms, format!("the rigid coupling at {}", c.at));
                }
            }
        }
        for e in &mesh.equations {
            let (n0, d0, c0) = e.terms[0];
            let p = full(n0, d0);
            if let Status::Dependent(_, by) = &status[p] {
                return Err(AssemblyError::DoublyConstrained {
                    node: node_id(n0),
                    dir: d0,
                    first: by.clone(),
                    second: format!("the *EQUATION at {}", e.at),
                });
            }
            let terms = e.terms[1..].iter().map(|&(n, d, c)| (full(n, d), -c / c0)).collect();
            status[p] = Status::Dependent(terms, format!("the *EQUATION at {}", e.at));
        }
        for &(n, d) in &mesh.fixed {
            if d > n_dirs[n] {
                continue; // e.g. rotations of a node without rotational DOFs
            }
            let p = full(n, d);
            match &status[p] {
                Status::Dependent(_, by) => {
                    return Err(AssemblyError::DoublyConstrained {
                        node: node_id(n),
                        dir: d,
                        first: by.clone(),
                        second: "*BOUNDARY (fix the independent DOFs instead)".into(),
                    })
                }
                Status::Free => status[p] = Status::Fixed,
                _ => {}
            }
        }
        // Reduced numbering: independent free DOFs in node order.
        let mut reduced = vec![None; total];
        let mut independent = Vec::new();
        for (n, &dirs) in n_dirs.iter().enumerate() {
            for d in 1..=dirs {
                let p = full(n, d);
                if matches!(status[p], Status::Free) {
                    reduced[p] = Some(independent.len() as u32);
                    independent.push((n, d));
                }
            }
        }
        // Resolve dependent DOFs recursively (a slave may depend on a DOF that is itself
        // dependent), detecting cycles.
        let mut resolved: HashMap<usize, Vec<(u32, f64)>> = HashMap::new();
        let mut ptr = Vec::with_capacity(total + 1);
        let mut idx = Vec::new();
        let mut val = Vec::new();
        ptr.push(0);
        let dof_name = |p: usize| {
            let n = offset.partition_point(|&o| o <= p) - 1;
            (node_id(n), (p - offset[n] + 1) as u8)
        };
        for p in 0..total {
            match &status[p] {
                Status::Free => {
                    idx.push(reduced[p].unwrap());
                    val.push(1.0);
                }
                Status::Dependent(..) => {
                    let mut stack = Vec::new();
                    let terms = resolve(p, &status, &reduced, &mut resolved, &mut stack).map_err(|q| {
                        let (node, dir) = dof_name(q);
                        AssemblyError::CyclicConstraint { node, dir }
                    })?;
                    for (i, v) in terms {
                        idx.push(i);
                        val.push(v);
                    }
                }
                _ => {}
            }
            ptr.push(idx.len());
        }
        Ok(DofMap { offset, n_dirs, ptr, idx, val, independent, reduced })
    }
}

/// Terms of full DOF `p` over the independent DOFs; `Err(q)` names a DOF on a cycle.
fn resolve(
    p: usize,
    status: &[Status],
    reduced: &[Option<u32>],
    memo: &mut HashMap<usize, Vec<(u32, f64)>>,
    stack: &mut Vec<usize>,
) -> Result<Vec<(u32, f64)>, usize> {
    match &status[p] {
        Status::Free => return Ok(vec![(reduced[p].unwrap(), 1.0)]),
        Status::Fixed | Status::Inactive => return Ok(Vec::new()),
        Status::Dependent(..) => {}
    }
    if let Some(t) = memo.get(&p) {
        return Ok(t.clone());
    }
    if stack.contains(&p) {
        return Err(p);
    }
    stack.push(p);
    let Status::Dependent(terms, _) = &status[p] else { unreachable!() };
    let mut acc: Vec<(u32, f64)> = Vec::new();
    for &(q, c) in terms {
        if c == 0.0 {
            continue;
        }
        for (i, v) in resolve(q, status, reduced, memo, stack)? {
            match acc.iter_mut().find(|t| t.0 == i) {
                Some(t) => t.1 += c * v,
                None => acc.push((i, c * v)),
            }
        }
    }
    acc.retain(|t| t.1 != 0.0);
    acc.sort_unstable_by_key(|t| t.0);
    stack.pop();
    memo.insert(p, acc.clone());
    Ok(acc)
}
