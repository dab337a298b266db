//! Global numbering of the displacement unknowns of the equivalent solid.
//!
//! Every rank holds the whole (small, deterministic) mesh, so every rank computes the same
//! numbering: nodes in the partition's order (grouped by owning rank), three components
//! per node, constrained components (clamped bottom face, symmetry plane) left out.
//! Rank r owns the contiguous range `ranges[r]..ranges[r+1]`.
use crate::mesh::{Mesh, Partition};

/// Displacement DOF numbering.
#[derive(Debug, Clone)]
pub struct DofMap {
    /// Global index of component c of node n, or -1 when that component is constrained.
    pub node_dof: Vec<[i32; 3]>,
    /// Owned ranges: rank r owns `ranges[r]..ranges[r + 1]`.
    pub ranges: Vec<usize>,
}

impl DofMap {
    /// Numbers the free displacement components. `symmetry_z`: u_z = 0 on the nodes flagged
    /// by `mesh.symmetry` (half domain).
    pub fn new(mesh: &Mesh, part: &Partition, nranks: usize) -> DofMap {
        let mut node_dof = vec![[-1i32; 3]; mesh.nodes.len()];
        let mut ranges = vec![0usize; nranks + 1];
        let mut next: i32 = 0;
        let mut rank = 0usize;
        for &n in &part.node_order {
            let n = n as usize;
            let owner = part.node_rank[n] as usize;
            while rank < owner {
                rank += 1;
                ranges[rank] = next as usize;
            }
            if mesh.clamped[n] {
                continue;
            }
            for (c, dof) in node_dof[n].iter_mut().enumerate() {
                if c == 2 && mesh.symmetry[n] {
                    continue;
                }
                *dof = next;
                next += 1;
            }
        }
        while rank < nranks {
            rank += 1;
            ranges[rank] = next as usize;
        }
        DofMap { node_dof, ranges }
    }

    /// Total number of unknowns.
    pub fn total(&self) -> usize {
        *self.ranges.last().unwrap()
    }

    /// Number of unknowns owned by `rank`.
    pub fn local(&self, rank: usize) -> usize {
        self.ranges[rank + 1] - self.ranges[rank]
    }

    /// The 30 global indices of a P2 tetrahedron (node-major, -1 for constrained).
    pub fn tet_dofs(&self, tet: &[u32; 10]) -> [i32; 30] {
        let mut d = [-1i32; 30];
        for (i, &n) in tet.iter().enumerate() {
            d[3 * i..3 * i + 3].copy_from_slice(&self.node_dof[n as usize]);
        }
        d
    }
}

/// Node-to-node adjacency (nodes sharing a tetrahedron), built for the nodes a rank owns.
pub fn owned_node_neighbours(mesh: &Mesh, part: &Partition, rank: usize) -> Vec<(u32, Vec<u32>)> {
    let n = mesh.nodes.len();
    // node -> incident tets (CSR)
    let mut count = vec![0u32; n + 1];
    for t in &mesh.tets {
        for &v in t {
            count[v as usize + 1] += 1;
        }
    }
    for i in 0..n {
        count[i + 1] += count[i];
    }
    let mut fill = count.clone();
    let mut inc = vec![0u32; count[n] as usize];
    for (k, t) in mesh.tets.iter().enumerate() {
        for &v in t {
            inc[fill[v as usize] as usize] = k as u32;
            fill[v as usize] += 1;
        }
    }
    let mut out = Vec::new();
    for node in 0..n {
        if part.node_rank[node] as usize != rank {
            continue;
        }
        let mut nb: Vec<u32> = Vec::with_capacity(64);
        for &t in &inc[count[node] as usize..count[node + 1] as usize] {
            nb.extend_from_slice(&mesh.tets[t as usize]);
        }
        nb.sort_unstable();
        nb.dedup();
        out.push((node as u32, nb));
    }
    out
}

/// Exact AIJ preallocation for the displacement block: (d_nnz, o_nnz) per owned row.
pub fn preallocation(mesh: &Mesh, part: &Partition, dofs: &DofMap, rank: usize) -> (Vec<i32>, Vec<i32>) {
    let (lo, hi) = (dofs.ranges[rank] as i32, dofs.ranges[rank + 1] as i32);
    let nloc = (hi - lo) as usize;
    let mut d_nnz = vec![0i32; nloc];
    let mut o_nnz = vec![0i32; nloc];
    for (node, nb) in owned_node_neighbours(mesh, part, rank) {
        let (mut d, mut o) = (0, 0);
        for &m in &nb {
            for &col in &dofs.node_dof[m as usize] {
                if col < 0 {
                    continue;
                }
                if (lo..hi).contains(&col) {
                    d += 1
                } else {
                    o += 1
                }
            }
        }
        for &row in &dofs.node_dof[node as usize] {
            if row >= 0 {
                d_nnz[(row - lo) as usize] = d;
                o_nnz[(row - lo) as usize] = o;
            }
        }
    }
    (d_nnz, o_nnz)
}
