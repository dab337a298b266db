//! The Reynolds mesh alone, for rigid solids (`effects.elasticity = "rigid"`): a uniform
//! P2 triangulation of the Reynolds rectangle on the plane y = 0, with no tetrahedra and
//! no elastic unknowns (every node is marked clamped, so the elastic dof map is empty).
use super::{partition::morton_order, Mesh, MeshSpec, Partition};
use crate::error::Error;

/// Uniform grid of squares of size close to `spec.contact_size` (the rectangle's sides
/// divided into whole numbers of cells), each cut into two triangles along alternating
/// diagonals (a criss-cross-free "union jack" pattern keeps the mesh symmetric about the
/// rectangle's centre lines), P2 mid-side nodes added.
pub fn face_mesh(spec: &MeshSpec) -> Result<Mesh, Error> {
    let r = spec.contact;
    let h = spec.contact_size;
    if !(h > 0.0) || !(r.x1 > r.x0) || !(r.z1 > r.z0) {
        return Err(Error::invalid(format!("face mesh: bad rectangle {r:?} or element size {h}")));
    }
    let nx = ((r.x1 - r.x0) / h).round().max(1.0) as usize;
    let nz = ((r.z1 - r.z0) / h).round().max(1.0) as usize;
    // A (2 nx + 1) x (2 nz + 1) lattice holds every P2 node: vertices at even indices.
    let (mx, mz) = (2 * nx + 1, 2 * nz + 1);
    let id = |i: usize, j: usize| (i + mx * j) as u32;
    let nodes: Vec<[f64; 3]> = (0..mz)
        .flat_map(|j| (0..mx).map(move |i| (i, j)))
        .map(|(i, j)| [r.x0 + (r.x1 - r.x0) * i as f64 / (mx - 1) as f64, 0.0, r.z0 + (r.z1 - r.z0) * j as f64 / (mz - 1) as f64])
        .collect();
    let mut tris = Vec::with_capacity(2 * nx * nz);
    for cj in 0..nz {
        for ci in 0..nx {
            let (i, j) = (2 * ci, 2 * cj);
            let (a, b, c, d) = ((i, j), (i + 2, j), (i + 2, j + 2), (i, j + 2));
            let mid = |p: (usize, usize), q: (usize, usize)| id((p.0 + q.0) / 2, (p.1 + q.1) / 2);
            let v = |p: (usize, usize)| id(p.0, p.1);
            // Diagonal a-c or b-d, alternating like a chessboard.
            let halves = if (ci + cj) % 2 == 0 { [[a, b, c], [a, c, d]] } else { [[a, b, d], [b, c, d]] };
            for t in halves {
                // Counter-clockwise in (x, z): positive signed area as the 3D mesh's faces.
                tris.push([v(t[0]), v(t[1]), v(t[2]), mid(t[0], t[1]), mid(t[1], t[2]), mid(t[2], t[0])]);
            }
        }
    }
    let mut used = vec![false; nodes.len()];
    for t in &tris {
        for &n in t {
            used[n as usize] = true;
        }
    }
    // Lattice centres of the cells on the other diagonal are not nodes of any triangle;
    // they stay in the node list (unused, zero unknowns) to keep the numbering simple.
    let contact_nodes: Vec<u32> = (0..nodes.len() as u32).filter(|&n| used[n as usize]).collect();
    let n = nodes.len();
    Ok(Mesh {
        n_vertices: (nx + 1) * (nz + 1),
        symmetry: nodes.iter().map(|p| spec.half_z && p[2].abs() < 1e-12).collect(),
        nodes,
        tets: Vec::new(),
        contact_tri_tet: vec![u32::MAX; tris.len()],
        contact_tris: tris,
        contact_nodes,
        clamped: vec![true; n],
        contact_size: h,
        spec: spec.clone(),
    })
}

/// Partition of a face mesh: nodes in Morton order, split into equal runs.
pub fn face_partition(mesh: &Mesh, nranks: usize) -> Partition {
    let order = morton_order(mesh);
    let n = order.len();
    let mut node_rank = vec![0u32; n];
    for (pos, &i) in order.iter().enumerate() {
        node_rank[i as usize] = (pos * nranks / n.max(1)) as u32;
    }
    Partition { tet_rank: Vec::new(), node_rank, node_order: order }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn face_mesh_covers_the_rectangle_with_positive_triangles() {
        let mut spec = MeshSpec::paper_default();
        spec.contact_size = 0.5;
        let m = face_mesh(&spec).unwrap();
        assert_eq!(m.contact_tris.len(), 2 * 12 * 12);
        let mut area = 0.0f64;
        for k in 0..m.contact_tris.len() {
            let a = m.contact_tri_area(k);
            assert!(a > 0.0, "triangle {k} has area {a}");
            area += a;
            // Mid-side nodes are the midpoints.
            let t = m.contact_tris[k];
            for (e, [i, j]) in [[0, 1], [1, 2], [2, 0]].iter().enumerate() {
                let (p, q, mnode) = (m.nodes[t[*i] as usize], m.nodes[t[*j] as usize], m.nodes[t[3 + e] as usize]);
                assert!((0.5 * (p[0] + q[0]) - mnode[0]).abs() < 1e-12 && (0.5 * (p[2] + q[2]) - mnode[2]).abs() < 1e-12);
            }
        }
        assert!((area - 36.0).abs() < 1e-12);
        assert!(m.tets.is_empty() && m.clamped.iter().all(|&c| c));
        let part = face_partition(&m, 3);
        assert_eq!(part.node_order.len(), m.nodes.len());
        assert!(part.node_rank.iter().all(|&r| r < 3));
    }
}
