//! Turning the bisected linear mesh into the public P2 [`Mesh`]: orientation,
//! edge-midpoint nodes, contact triangles and boundary flags.

use super::refine::{det6, edge_key, Bisector, U64Map, TET_EDGES};
use super::{Mesh, MeshSpec};

/// Local vertex triples of the faces of a tet (face `k` is opposite vertex `k`).
const TET_FACES: [[usize; 3]; 4] = [[1, 2, 3], [0, 2, 3], [0, 1, 3], [0, 1, 2]];

/// Builds the P2 mesh from the refined vertex mesh.
pub(crate) fn assemble(b: Bisector, spec: &MeshSpec, h: f64) -> Mesh {
    let n_vertices = b.verts.len();
    let vtets: Vec<[u32; 4]> = b.tets.iter().map(|t| orient_positive(&b.verts, *t)).collect();
    let mut nodes = b.verts;
    let (tets, edge_nodes) = add_edge_nodes(&mut nodes, &vtets);
    let (contact_tris, contact_tri_tet) = contact_triangles(&nodes, &tets, &edge_nodes, spec);
    let mut contact_nodes: Vec<u32> = contact_tris.iter().flatten().copied().collect();
    contact_nodes.sort_unstable();
    contact_nodes.dedup();
    let (lo, hi) = spec.bounds();
    let tol = 1e-12 * spec.cube_edge.max(spec.depth);
    let clamped = nodes.iter().map(|p| (p[1] - lo[1]).abs() <= tol).collect();
    let symmetry = nodes.iter().map(|p| spec.half_z && (p[2] - hi[2]).abs() <= tol).collect();
    Mesh { nodes, n_vertices, tets, contact_tris, contact_tri_tet, contact_nodes, clamped, symmetry, contact_size: h, spec: spec.clone() }
}

/// Swaps `v0` and `v1` if needed so that `det[v1-v0, v2-v0, v3-v0] > 0`.
fn orient_positive(v: &[[f64; 3]], t: [u32; 4]) -> [u32; 4] {
    if det6(t.map(|i| &v[i as usize])) < 0.0 {
        [t[1], t[0], t[2], t[3]]
    } else {
        t
    }
}

/// Appends one node per unique edge (numbered in tet order, VTK edge order)
/// and returns the 10-node tets plus the edge -> node map.
fn add_edge_nodes(nodes: &mut Vec<[f64; 3]>, vtets: &[[u32; 4]]) -> (Vec<[u32; 10]>, U64Map<u32>) {
    let mut map = U64Map::default();
    map.reserve(vtets.len() * 7 / 5 + 16);
    let mut tets = Vec::with_capacity(vtets.len());
    for t in vtets {
        let mut q = [0u32; 10];
        q[..4].copy_from_slice(t);
        for (e, &(a, b)) in TET_EDGES.iter().enumerate() {
            let (pa, pb) = (nodes[t[a] as usize], nodes[t[b] as usize]);
            let next = nodes.len() as u32;
            let id = *map.entry(edge_key(t[a], t[b])).or_insert(next);
            if id == next {
                nodes.push([0, 1, 2].map(|c| 0.5 * (pa[c] + pb[c])));
            }
            q[4 + e] = id;
        }
        tets.push(q);
    }
    (tets, map)
}

/// Top-face (`y = 0`) triangles lying in the contact rectangle, as P2
/// triangles `v0, v1, v2, mid(0,1), mid(1,2), mid(2,0)` with positive
/// orientation in the `(x, z)` plane, plus the owning tet of each.
fn contact_triangles(nodes: &[[f64; 3]], tets: &[[u32; 10]], edge_nodes: &U64Map<u32>, spec: &MeshSpec) -> (Vec<[u32; 6]>, Vec<u32>) {
    let tol = 1e-12 * spec.cube_edge;
    let on_contact = |i: u32| {
        let p = nodes[i as usize];
        p[1].abs() <= tol && spec.contact.contains(p[0], p[2], tol)
    };
    let mut tris = Vec::new();
    let mut owner = Vec::new();
    for (ti, t) in tets.iter().enumerate() {
        for f in TET_FACES {
            let v = f.map(|k| t[k]);
            if v.iter().all(|&i| on_contact(i)) {
                let v = orient_xz(nodes, v);
                let m = |a: u32, b: u32| edge_nodes[&edge_key(a, b)];
                tris.push([v[0], v[1], v[2], m(v[0], v[1]), m(v[1], v[2]), m(v[2], v[0])]);
                owner.push(ti as u32);
            }
        }
    }
    (tris, owner)
}

/// Signed area of triangle `v` in the `(x, z)` plane.
pub(crate) fn area_xz(nodes: &[[f64; 3]], v: [u32; 3]) -> f64 {
    let [a, b, c] = v.map(|i| nodes[i as usize]);
    0.5 * ((b[0] - a[0]) * (c[2] - a[2]) - (c[0] - a[0]) * (b[2] - a[2]))
}

/// Reorders a triangle so that its `(x, z)` signed area is positive.
fn orient_xz(nodes: &[[f64; 3]], v: [u32; 3]) -> [u32; 3] {
    if area_xz(nodes, v) < 0.0 {
        [v[0], v[2], v[1]]
    } else {
        v
    }
}
