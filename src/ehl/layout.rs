//! The unknowns of the full EHL system in one PETSc vector (docs/model.md sections 5-6):
//! the displacements U of the equivalent solid, the pressure P at the P2 nodes of the
//! contact face strictly inside the Reynolds rectangle (P = 0 on its edges), and H0.
//!
//! Rank r owns one contiguous block `[U of rank r][P of rank r]`; the last rank also owns
//! H0, the last unknown. A node's unknowns belong to the rank that owns the node.
use crate::mesh::{Mesh, Partition};
use crate::solid::dofmap::DofMap;

/// Global numbering of (U, P, H0).
#[derive(Debug, Clone)]
pub struct Layout {
    /// Global index of each displacement component (-1 if constrained).
    pub u: Vec<[i32; 3]>,
    /// Global index of the pressure at each node (-1 if the node carries no pressure unknown).
    pub p: Vec<i32>,
    /// Global index of H0.
    pub h0: i32,
    /// Rank r owns `ranges[r]..ranges[r + 1]`.
    pub ranges: Vec<usize>,
    /// Per rank: number of displacement unknowns (the first ones of its block).
    pub n_u: Vec<usize>,
    /// Per rank: number of pressure unknowns.
    pub n_p: Vec<usize>,
}

/// True if the contact node at (x, z) lies on an edge of the Reynolds rectangle where
/// P = 0 is imposed (a symmetry edge z = 0 of a half domain is not such an edge).
fn on_dirichlet_edge(x: f64, z: f64, rect: &crate::mesh::Rect, symmetric_z0: bool) -> bool {
    let tol = 1e-9;
    (x - rect.x0).abs() < tol
        || (x - rect.x1).abs() < tol
        || (z - rect.z0).abs() < tol
        || ((z - rect.z1).abs() < tol && !(symmetric_z0 && z.abs() < tol))
}

impl Layout {
    /// Numbers the unknowns. `rect` is the Reynolds rectangle; `symmetric_z0`: half domain
    /// with the symmetry plane z = 0 as an edge (no P = 0 there).
    pub fn new(mesh: &Mesh, part: &Partition, dofs: &DofMap, rect: &crate::mesh::Rect, symmetric_z0: bool, nranks: usize) -> Layout {
        // Pressure nodes per owning rank, in the partition's node order.
        let mut is_p = vec![false; mesh.nodes.len()];
        for &n in &mesh.contact_nodes {
            let c = mesh.nodes[n as usize];
            is_p[n as usize] = !on_dirichlet_edge(c[0], c[2], rect, symmetric_z0);
        }
        let mut n_p = vec![0usize; nranks];
        for n in 0..mesh.nodes.len() {
            if is_p[n] {
                n_p[part.node_rank[n] as usize] += 1;
            }
        }
        let n_u: Vec<usize> = (0..nranks).map(|r| dofs.local(r)).collect();
        let mut ranges = vec![0usize; nranks + 1];
        for r in 0..nranks {
            ranges[r + 1] = ranges[r] + n_u[r] + n_p[r] + usize::from(r == nranks - 1);
        }
        // Displacements: shift the DofMap numbering into each rank's block.
        let u = dofs
            .node_dof
            .iter()
            .enumerate()
            .map(|(n, d)| {
                let r = part.node_rank[n] as usize;
                d.map(|i| if i < 0 { -1 } else { (i as usize - dofs.ranges[r] + ranges[r]) as i32 })
            })
            .collect();
        let mut p = vec![-1i32; mesh.nodes.len()];
        let mut next: Vec<usize> = (0..nranks).map(|r| ranges[r] + n_u[r]).collect();
        for &n in &part.node_order {
            let n = n as usize;
            if is_p[n] {
                let r = part.node_rank[n] as usize;
                p[n] = next[r] as i32;
                next[r] += 1;
            }
        }
        let h0 = (ranges[nranks] - 1) as i32;
        Layout { u, p, h0, ranges, n_u, n_p }
    }

    /// Total number of unknowns.
    pub fn total(&self) -> usize {
        *self.ranges.last().unwrap()
    }

    /// Number of unknowns owned by `rank`.
    pub fn local(&self, rank: usize) -> usize {
        self.ranges[rank + 1] - self.ranges[rank]
    }

    /// Value of an unknown at global index `d` of the iterate `x` (0 for -1: eliminated).
    pub fn value(x: &[f64], d: i32) -> f64 {
        if d < 0 {
            0.0
        } else {
            x[d as usize]
        }
    }

    /// Normal displacement U_y of node `n` in the iterate `x`.
    pub fn uy(&self, x: &[f64], n: u32) -> f64 {
        Self::value(x, self.u[n as usize][1])
    }

    /// The rigid gap of the ball at a node, (X^2 + Z^2)/2 (Eq. 5, dimensionless).
    pub fn gap(c: [f64; 3]) -> f64 {
        0.5 * (c[0] * c[0] + c[2] * c[2])
    }

    /// Film thickness H = H0 + (X^2 + Z^2)/2 - U_y at contact node `n` (docs/model.md section 5).
    pub fn film(&self, mesh: &Mesh, x: &[f64], n: u32) -> f64 {
        x[self.h0 as usize] + Self::gap(mesh.nodes[n as usize]) - self.uy(x, n)
    }

    /// Total displacement and pressure unknown counts.
    pub fn counts(&self) -> (usize, usize) {
        (self.n_u.iter().sum(), self.n_p.iter().sum())
    }
}
