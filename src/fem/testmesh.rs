//! Structured P2 test meshes (Kuhn / Freudenthal subdivision of a box).
use super::p2tet::TET_EDGES;

/// Structured P2 tetrahedral mesh of the box `[lo, hi]` with `n[0] x n[1] x n[2]` cells,
/// each split into the 6 Kuhn tetrahedra sharing the cell diagonal from the low corner to
/// the high corner (same orientation in every cell, so the mesh is conforming).
///
/// Returns `(nodes, tets)`:
/// * nodes: the `(n0+1)(n1+1)(n2+1)` vertices first, vertex `(i, j, k)` having index
///   `i + (n0+1) (j + (n1+1) k)`, then the midside nodes (numbered in order of first
///   appearance). Every midside node is shared by all tets containing its edge.
/// * tets: 10 node indices each, VTK quadratic-tet order (`v0..v3`, then
///   `mid(0,1), mid(1,2), mid(0,2), mid(0,3), mid(1,3), mid(2,3)`), positively oriented
///   (`det J > 0`).
///
/// Midside-node coordinates are exactly the edge midpoints (the mesh is straight-sided).
pub fn kuhn_box_mesh(n: [usize; 3], lo: [f64; 3], hi: [f64; 3]) -> (Vec<[f64; 3]>, Vec<[u32; 10]>) {
    assert!(n.iter().all(|&m| m >= 1), "kuhn_box_mesh: need at least one cell per direction");
    let nv = [n[0] + 1, n[1] + 1, n[2] + 1];
    let nf = [2 * n[0] + 1, 2 * n[1] + 1, 2 * n[2] + 1];
    let total_fine = nf[0] * nf[1] * nf[2];
    assert!(total_fine < u32::MAX as usize, "kuhn_box_mesh: too many nodes for u32");
    // Coordinate of fine-grid index f in direction d (fine grid = half spacing).
    let coord = |d: usize, f: usize| -> f64 {
        if f == 2 * n[d] {
            hi[d]
        } else {
            lo[d] + (hi[d] - lo[d]) * (f as f64) / ((2 * n[d]) as f64)
        }
    };
    let mut nodes = Vec::with_capacity(total_fine);
    for k in 0..nv[2] {
        for j in 0..nv[1] {
            for i in 0..nv[0] {
                nodes.push([coord(0, 2 * i), coord(1, 2 * j), coord(2, 2 * k)]);
            }
        }
    }
    // Every P2 node lies on the fine grid; map fine index -> node id for midside nodes.
    let mut mid_id = vec![u32::MAX; total_fine];
    let fine = |f: [usize; 3]| f[0] + nf[0] * (f[1] + nf[1] * f[2]);

    // The 6 Kuhn tets of the unit cube: path 0 -> e_s0 -> e_s0 + e_s1 -> (1,1,1) for every
    // permutation s; det = sign(s), odd permutations get vertices 1 and 2 swapped.
    const PERMS: [([usize; 3], bool); 6] =
        [([0, 1, 2], true), ([1, 2, 0], true), ([2, 0, 1], true), ([0, 2, 1], false), ([2, 1, 0], false), ([1, 0, 2], false)];
    let mut local: [[[usize; 3]; 4]; 6] = [[[0; 3]; 4]; 6];
    for (t, (s, even)) in PERMS.iter().enumerate() {
        let p0 = [0usize; 3];
        let mut p1 = p0;
        p1[s[0]] = 1;
        let mut p2 = p1;
        p2[s[1]] = 1;
        let p3 = [1usize; 3];
        local[t] = if *even { [p0, p1, p2, p3] } else { [p0, p2, p1, p3] };
    }

    let mut tets = Vec::with_capacity(6 * n[0] * n[1] * n[2]);
    for ck in 0..n[2] {
        for cj in 0..n[1] {
            for ci in 0..n[0] {
                for lt in &local {
                    let mut tet = [0u32; 10];
                    let mut fv = [[0usize; 3]; 4];
                    for (m, p) in lt.iter().enumerate() {
                        let (i, j, k) = (ci + p[0], cj + p[1], ck + p[2]);
                        tet[m] = (i + nv[0] * (j + nv[1] * k)) as u32;
                        fv[m] = [2 * i, 2 * j, 2 * k];
                    }
                    for (e, [a, b]) in TET_EDGES.iter().enumerate() {
                        let fm = [(fv[*a][0] + fv[*b][0]) / 2, (fv[*a][1] + fv[*b][1]) / 2, (fv[*a][2] + fv[*b][2]) / 2];
                        let slot = &mut mid_id[fine(fm)];
                        if *slot == u32::MAX {
                            *slot = nodes.len() as u32;
                            nodes.push([coord(0, fm[0]), coord(1, fm[1]), coord(2, fm[2])]);
                        }
                        tet[4 + e] = *slot;
                    }
                    tets.push(tet);
                }
            }
        }
    }
    (nodes, tets)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fem::geometry::tet_signed_volume;
    use std::collections::HashMap;

    #[test]
    fn kuhn_mesh_properties() {
        let (n, lo, hi) = ([3, 2, 4], [-1.0, 0.5, 2.0], [2.0, 1.5, 3.0]);
        let (nodes, tets) = kuhn_box_mesh(n, lo, hi);
        assert_eq!(tets.len(), 6 * 24);
        // Every fine-grid point is a P2 node.
        assert_eq!(nodes.len(), 7 * 5 * 9);
        let mut vol = 0.0;
        let mut edge_mid: HashMap<(u32, u32), u32> = HashMap::new();
        let mut face_count: HashMap<[u32; 3], usize> = HashMap::new();
        for t in &tets {
            let v: [[f64; 3]; 4] = std::array::from_fn(|m| nodes[t[m] as usize]);
            let sv = tet_signed_volume(&v);
            assert!(sv > 0.0);
            vol += sv;
            for (e, [a, b]) in TET_EDGES.iter().enumerate() {
                let (ia, ib) = (t[*a], t[*b]);
                let key = (ia.min(ib), ia.max(ib));
                let m = t[4 + e];
                assert!(m as usize >= 4 * 3 * 5, "midside node numbered among vertices");
                assert_eq!(*edge_mid.entry(key).or_insert(m), m, "midside node not shared");
                for c in 0..3 {
                    let want = 0.5 * (nodes[ia as usize][c] + nodes[ib as usize][c]);
                    assert!((nodes[m as usize][c] - want).abs() < 1e-14);
                }
            }
            for f in [[0, 1, 2], [0, 1, 3], [0, 2, 3], [1, 2, 3]] {
                let mut key = [t[f[0]], t[f[1]], t[f[2]]];
                key.sort();
                *face_count.entry(key).or_insert(0) += 1;
            }
        }
        assert!((vol - 3.0 * 1.0 * 1.0).abs() < 1e-12);
        // Conformity: every face is shared by at most 2 tets; boundary faces count = 2 * 2 * (sum of face cells).
        assert!(face_count.values().all(|&c| c <= 2));
        let boundary = face_count.values().filter(|&&c| c == 1).count();
        assert_eq!(boundary, 2 * 2 * (3 * 2 + 2 * 4 + 3 * 4));
        // Vertex numbering.
        let (i, j, k) = (2, 1, 3);
        let id = i + 4 * (j + 3 * k);
        assert_eq!(nodes[id], [1.0, 1.0, 2.75]);
        assert_eq!(nodes[4 * 3 * 5 - 1], hi);
    }
}
