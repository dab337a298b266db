//! Exact AIJ preallocation of the monolithic EHL matrix. The dense parts are one row (the
//! load balance, over all P) and one column (dR/dH0, over all P rows): 2 N_p entries in all,
//! counted exactly like the rest.
use super::layout::Layout;
use crate::mesh::{Mesh, Partition};
use crate::solid::dofmap::owned_node_neighbours;
use std::collections::HashMap;

/// Contact-face neighbours of each contact node: nodes sharing a contact triangle, and
/// with the gradient-jump term (`jumps`) the nodes of the triangles across each edge.
pub fn contact_neighbours(mesh: &Mesh, jumps: bool) -> HashMap<u32, Vec<u32>> {
    let mut nb = crate::fem::p2tri::node_rings(&mesh.contact_tris);
    if jumps {
        for (a, b, _) in crate::reynolds::jump::interior_edges(&mesh.contact_tris) {
            let (ta, tb) = (mesh.contact_tris[a], mesh.contact_tris[b]);
            for &n in &ta {
                nb.entry(n).or_default().extend_from_slice(&tb);
            }
            for &n in &tb {
                nb.entry(n).or_default().extend_from_slice(&ta);
            }
        }
        for v in nb.values_mut() {
            v.sort_unstable();
            v.dedup();
        }
    }
    nb
}

/// (d_nnz, o_nnz) for the rows this rank owns.
pub fn preallocation(mesh: &Mesh, part: &Partition, layout: &Layout, rank: usize, jumps: bool) -> (Vec<i32>, Vec<i32>) {
    let (lo, hi) = (layout.ranges[rank] as i32, layout.ranges[rank + 1] as i32);
    let n = (hi - lo) as usize;
    let (mut d_nnz, mut o_nnz) = (vec![0i32; n], vec![0i32; n]);
    let contact = contact_neighbours(mesh, jumps);
    let mut count = |row: i32, cols: &[i32]| {
        if row < lo || row >= hi {
            return;
        }
        let (mut d, mut o) = (0, 0);
        for &c in cols {
            if c < 0 {
                continue;
            }
            if c >= lo && c < hi {
                d += 1
            } else {
                o += 1
            }
        }
        d_nnz[(row - lo) as usize] = d;
        o_nnz[(row - lo) as usize] = o;
    };
    let mut cols: Vec<i32> = Vec::with_capacity(256);
    for (node, nb) in owned_node_neighbours(mesh, part, rank) {
        let cn = contact.get(&node);
        for comp in 0..3 {
            let row = layout.u[node as usize][comp];
            if row < 0 {
                continue;
            }
            cols.clear();
            for &m in &nb {
                cols.extend_from_slice(&layout.u[m as usize]);
            }
            if comp == 1 {
                if let Some(cn) = cn {
                    cols.extend(cn.iter().map(|&m| layout.p[m as usize]));
                }
            }
            count(row, &cols);
        }
        if let Some(cn) = contact.get(&node) {
            let row = layout.p[node as usize];
            if row >= 0 {
                cols.clear();
                cols.extend(cn.iter().map(|&m| layout.p[m as usize]));
                cols.extend(cn.iter().map(|&m| layout.u[m as usize][1]));
                cols.push(layout.h0);
                count(row, &cols);
            }
        }
    }
    if layout.h0 >= lo && layout.h0 < hi {
        let all_p: Vec<i32> = layout.p.iter().copied().filter(|&p| p >= 0).collect();
        count(layout.h0, &all_p);
    }
    (d_nnz, o_nnz)
}
