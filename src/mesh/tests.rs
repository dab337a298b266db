//! Whole-mesh tests: conformity, hanging nodes, contact face, P2 nodes,
//! orientation, quality, determinism, half domain and partition.

use super::refine::{bbox_distance, edge_key, longest_edge, U64Map, TET_EDGES};
use super::*;
use std::collections::HashSet;
use std::sync::OnceLock;
use std::time::Instant;

/// The default mesh, generated once for all tests.
fn default_mesh() -> &'static Mesh {
    static M: OnceLock<Mesh> = OnceLock::new();
    M.get_or_init(|| generate(&MeshSpec::paper_default()).unwrap())
}

/// Offset contact rectangle `[-4.5, 1.5] x [-3, 3]`.
fn offset_spec() -> MeshSpec {
    let mut s = MeshSpec::paper_default();
    s.contact = Rect { x0: -4.5, x1: 1.5, z0: -3.0, z1: 3.0 };
    s
}

/// Half domain `z in [-30, 0]`, contact `[-3, 3] x [-3, 0]`.
fn half_spec() -> MeshSpec {
    let mut s = MeshSpec::paper_default();
    s.half_z = true;
    s.contact = Rect { x0: -3.0, x1: 3.0, z0: -3.0, z1: 0.0 };
    s
}

fn rel_close(a: f64, b: f64, rel: f64) -> bool {
    (a - b).abs() <= rel * b.abs().max(1e-300)
}

/// Exact key of a point (coordinates are dyadic, midpoints exact).
fn point_key(p: &[f64; 3]) -> [u64; 3] {
    p.map(|c| (c + 0.0).to_bits())
}

/// True if the three points all lie on one face of the box `[lo, hi]`.
fn on_box_face(p: &[[f64; 3]; 3], lo: &[f64; 3], hi: &[f64; 3]) -> bool {
    (0..3).any(|c| p.iter().all(|q| q[c] == lo[c]) || p.iter().all(|q| q[c] == hi[c]))
}

/// Area of a 3D triangle.
fn tri_area(p: &[[f64; 3]; 3]) -> f64 {
    let u = [0, 1, 2].map(|c| p[1][c] - p[0][c]);
    let v = [0, 1, 2].map(|c| p[2][c] - p[0][c]);
    let n = [u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]];
    0.5 * (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt()
}

/// Faces shared by exactly 2 tets inside, 1 on the boundary; boundary area
/// equals box surface; volume equals box volume.
fn check_conformity(m: &Mesh) {
    let (lo, hi) = m.spec.bounds();
    let mut faces: U64Map<(u32, [u32; 3])> = U64Map::default();
    for q in &m.tets {
        for skip in 0..4 {
            let mut f: Vec<u32> = (0..4).filter(|&k| k != skip).map(|k| q[k]).collect();
            f.sort_unstable();
            let key = (u64::from(f[0]) << 42) | (u64::from(f[1]) << 21) | u64::from(f[2]);
            assert!(f[2] < 1 << 21);
            faces.entry(key).or_insert((0, [f[0], f[1], f[2]])).0 += 1;
        }
    }
    let mut boundary_area = 0.0;
    for (count, f) in faces.values() {
        let p = f.map(|i| m.nodes[i as usize]);
        match count {
            1 => {
                assert!(on_box_face(&p, &lo, &hi), "boundary face {p:?} not on the box surface");
                boundary_area += tri_area(&p);
            }
            2 => assert!(!on_box_face(&p, &lo, &hi), "interior face on box surface"),
            _ => panic!("face {f:?} shared by {count} tets"),
        }
    }
    assert!(rel_close(boundary_area, m.spec.box_surface(), 1e-10), "{boundary_area}");
    assert!(rel_close(m.volume(), m.spec.box_volume(), 1e-10), "{}", m.volume());
}

/// No vertex sits at the midpoint of a tet edge (geometric check).
fn check_no_hanging(m: &Mesh) {
    let verts: HashSet<[u64; 3]> = m.nodes[..m.n_vertices].iter().map(point_key).collect();
    assert_eq!(verts.len(), m.n_vertices, "duplicate vertices");
    for q in &m.tets {
        for &(a, b) in &TET_EDGES {
            let (pa, pb) = (m.nodes[q[a] as usize], m.nodes[q[b] as usize]);
            let mid = [0, 1, 2].map(|c| 0.5 * (pa[c] + pb[c]));
            assert!(!verts.contains(&point_key(&mid)), "hanging node at {mid:?}");
        }
    }
}

/// Positive orientation, exact P2 midpoints, one node per edge shared by all
/// tets containing it, vertices first.
fn check_p2(m: &Mesh) {
    let mut edge_node: U64Map<u32> = U64Map::default();
    for (t, q) in m.tets.iter().enumerate() {
        assert!(m.tet_volume(t) > 0.0, "tet {t} not positively oriented");
        assert!(q[..4].iter().all(|&v| (v as usize) < m.n_vertices));
        for (e, &(a, b)) in TET_EDGES.iter().enumerate() {
            let node = q[4 + e];
            assert!(node as usize >= m.n_vertices);
            let (pa, pb) = (m.nodes[q[a] as usize], m.nodes[q[b] as usize]);
            assert_eq!(m.nodes[node as usize], [0, 1, 2].map(|c| 0.5 * (pa[c] + pb[c])));
            let prev = *edge_node.entry(edge_key(q[a], q[b])).or_insert(node);
            assert_eq!(prev, node, "edge node not shared");
        }
    }
    assert_eq!(edge_node.len(), m.nodes.len() - m.n_vertices, "unused or duplicate edge nodes");
    let distinct: HashSet<u32> = edge_node.values().copied().collect();
    assert_eq!(distinct.len(), edge_node.len());
}

/// Contact triangles tile R, lie at y = 0, are oriented, and their vertices
/// form the full uniform grid of spacing h_c over R.
fn check_contact(m: &Mesh) {
    let r = m.spec.contact;
    let h = m.contact_size;
    let (nx, nz) = (((r.x1 - r.x0) / h).round() as usize, ((r.z1 - r.z0) / h).round() as usize);
    assert_eq!(m.contact_tris.len(), 2 * nx * nz);
    assert!(rel_close(m.top_face_area_in_contact(), r.area(), 1e-12));
    let mut grid = HashSet::new();
    for (k, c) in m.contact_tris.iter().enumerate() {
        assert!(m.contact_tri_area(k) > 0.0);
        let face: HashSet<u32> = c[..3].iter().copied().collect();
        let owner = &m.tets[m.contact_tri_tet[k] as usize];
        assert!(c.iter().all(|v| owner.contains(v)), "triangle {k} not a face of its tet");
        assert_eq!(face.len(), 3);
        for (i, &v) in c.iter().enumerate() {
            let p = m.nodes[v as usize];
            assert_eq!(p[1], 0.0);
            assert!(r.contains(p[0], p[2], 0.0));
            if i < 3 {
                let (ix, iz) = ((p[0] - r.x0) / h, (p[2] - r.z0) / h);
                assert_eq!((ix.fract(), iz.fract()), (0.0, 0.0), "vertex off the h_c grid");
                grid.insert((ix as usize, iz as usize));
            }
        }
    }
    assert_eq!(grid.len(), (nx + 1) * (nz + 1), "contact vertex grid incomplete");
    let mut expect: Vec<u32> = m.contact_tris.iter().flatten().copied().collect();
    expect.sort_unstable();
    expect.dedup();
    assert_eq!(m.contact_nodes, expect);
    assert_eq!(m.contact_nodes.len(), (2 * nx + 1) * (2 * nz + 1));
}

/// Boundary flags agree with coordinates.
fn check_flags(m: &Mesh) {
    let (lo, hi) = m.spec.bounds();
    for (i, p) in m.nodes.iter().enumerate() {
        assert_eq!(m.clamped[i], p[1] == lo[1]);
        assert_eq!(m.symmetry[i], m.spec.half_z && p[2] == 0.0);
        assert_eq!(p[2] == hi[2], m.symmetry[i] || !m.spec.half_z && p[2] == hi[2]);
    }
    assert!(m.clamped.iter().any(|&c| c));
}

/// The structural checks of a mesh whose contact face is refined locally (a ring or a
/// patch; no uniform grid over the rectangle): the triangles still tile it.
fn check_graded(m: &Mesh) {
    check_conformity(m);
    check_no_hanging(m);
    check_p2(m);
    check_flags(m);
    assert!(rel_close(m.top_face_area_in_contact(), m.spec.contact.area(), 1e-12));
}

/// All structural checks.
fn check_all(m: &Mesh) {
    check_conformity(m);
    check_no_hanging(m);
    check_p2(m);
    check_contact(m);
    check_flags(m);
}

#[test]
fn default_mesh_is_valid() {
    let m = default_mesh();
    check_all(m);
    assert_eq!(m.contact_size, 0.25);
    assert!(m.symmetry.iter().all(|&s| !s));
}

/// Edge-map check: no leaf of the refined mesh has a bisected edge, and every
/// leaf satisfies the size criterion.
#[test]
fn no_hanging_nodes_in_edge_map() {
    for spec in [MeshSpec::paper_default(), offset_spec(), half_spec()] {
        let h = spec.validate().unwrap();
        let b = refined_bisector(&spec, h);
        assert!((0..b.tets.len()).all(|i| !b.has_hanging(i)));
        let n_coarse: usize = spec.coarse_grid().iter().map(Vec::len).product();
        assert_eq!(b.verts.len(), n_coarse + b.mids.len());
        let r = spec.contact;
        for t in &b.tets {
            let d = bbox_distance(&b.verts, t, &[r.x0, 0.0, r.z0], &[r.x1, 0.0, r.z1]);
            assert!(longest_edge(&b.verts, t) <= 3f64.sqrt() * (h + spec.growth * d) * (1.0 + 1e-9));
        }
    }
}

#[test]
fn default_has_vertex_at_x_equals_a() {
    let m = default_mesh();
    let (k, l) = m.locate_contact(1.0, 0.0).unwrap();
    let c = &m.contact_tris[k];
    let hit = (0..3).find(|&i| (l[i] - 1.0).abs() < 1e-12).expect("(1,0) is not a vertex");
    assert_eq!(m.nodes[c[hit] as usize], [1.0, 0.0, 0.0]);
    assert!(m.nodes[..m.n_vertices].contains(&[1.0, 0.0, 0.25]));
}

#[test]
fn offset_contact_mesh_is_valid() {
    check_all(&generate(&offset_spec()).unwrap());
}

#[test]
fn half_domain_mesh_is_valid() {
    let m = generate(&half_spec()).unwrap();
    check_all(&m);
    let zmin = m.nodes.iter().map(|p| p[2]).fold(f64::INFINITY, f64::min);
    let zmax = m.nodes.iter().map(|p| p[2]).fold(f64::NEG_INFINITY, f64::max);
    assert_eq!((zmin, zmax), (-30.0, 0.0));
    assert!(rel_close(m.volume(), 60.0 * 60.0 * 30.0, 1e-12));
    // every node on z = 0 flagged, including contact nodes on the symmetry edge
    let n_sym = m.symmetry.iter().filter(|&&s| s).count();
    assert!(n_sym > 0);
    assert!(m.contact_nodes.iter().any(|&i| m.symmetry[i as usize]));
}

#[test]
fn finer_contact_size_is_valid() {
    let mut s = MeshSpec::paper_default();
    s.contact_size = 0.125;
    check_all(&generate(&s).unwrap());
}

#[test]
fn non_dyadic_contact_size_rounds_down() {
    let mut s = MeshSpec::paper_default();
    s.contact_size = 0.4;
    let m = generate(&s).unwrap();
    assert_eq!(m.contact_size, 0.25);
    assert_eq!(m, *default_mesh_with_size(0.4));
}

/// Helper: same as the default mesh but with another requested size.
fn default_mesh_with_size(h: f64) -> &'static Mesh {
    static M: OnceLock<Mesh> = OnceLock::new();
    M.get_or_init(|| {
        let mut s = MeshSpec::paper_default();
        s.contact_size = h;
        generate(&s).unwrap()
    })
}

#[test]
fn generation_is_deterministic() {
    let a = generate(&MeshSpec::paper_default()).unwrap();
    assert_eq!(&a, default_mesh());
}

#[test]
fn coarse_mesh_without_contact_refinement() {
    // h_c = 16: no refinement near R beyond the coarse grid; still valid.
    let mut s = MeshSpec::paper_default();
    s.contact = Rect { x0: -16.0, x1: 16.0, z0: -16.0, z1: 16.0 };
    s.contact_size = 16.0;
    s.growth = 10.0;
    let m = generate(&s).unwrap();
    assert_eq!(m.tets.len(), 4 * 4 * 4 * 6);
    check_all(&m);
}

#[test]
fn invalid_specs_are_rejected() {
    let mut s = MeshSpec::paper_default();
    s.contact.z1 = 3.1;
    assert!(generate(&s).unwrap_err().to_string().contains("multiple"));
    s = MeshSpec::paper_default();
    s.cube_edge = f64::NAN;
    assert!(generate(&s).unwrap_err().to_string().contains("cube_edge"));
}

/// Kuhn bisection produces finitely many shapes per coarse cell (3
/// similarity classes per box shape). Over cubic cells the minimum dihedral
/// angle is 45 deg (see `quality::tests::bisection_shapes_of_cube`); the
/// anisotropic boundary cells of the default box (14 x 12 x 16 etc.) lower it
/// to atan(12/16) = 36.87 deg, which is what we check.
#[test]
fn quality_is_bounded() {
    for m in [default_mesh(), &generate(&half_spec()).unwrap()] {
        let q = quality(m);
        assert!(q.min_volume > 0.0);
        let expect = (12.0f64 / 16.0).atan().to_degrees();
        assert!((q.min_dihedral_deg - expect).abs() < 1e-9, "{q:?}");
        assert!(q.max_aspect_ratio < 4.0, "{q:?}");
    }
}

#[test]
fn locate_contact_finds_points() {
    let m = default_mesh();
    let loc = ContactLocator::new(m);
    let mut s = 12345u64;
    let mut rnd = || {
        s = s.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
        (s >> 11) as f64 / (1u64 << 53) as f64
    };
    for _ in 0..500 {
        let (x, z) = (-3.0 + 6.0 * rnd(), -3.0 + 6.0 * rnd());
        let (k, l) = m.locate_contact(x, z).unwrap();
        let c = &m.contact_tris[k];
        let p = [c[0], c[1], c[2]].map(|i| m.nodes[i as usize]);
        let xr = l[0] * p[0][0] + l[1] * p[1][0] + l[2] * p[2][0];
        let zr = l[0] * p[0][2] + l[1] * p[1][2] + l[2] * p[2][2];
        assert!((xr - x).abs() < 1e-12 && (zr - z).abs() < 1e-12);
        let (k2, l2) = loc.locate(m, x, z).unwrap();
        assert!(l2.iter().all(|&v| v >= -1e-12));
        assert!(k2 == k || l.iter().any(|&v| v.abs() < 1e-12), "locator disagrees inside");
    }
    assert!(m.locate_contact(3.5, 0.0).is_none());
    assert!(loc.locate(m, 0.0, -3.5).is_none());
    assert!(loc.locate(m, 3.0, 3.0).is_some());
}

fn check_partition(m: &Mesh, nranks: usize) {
    let p = partition(m, nranks);
    assert_eq!(p.tet_rank.len(), m.tets.len());
    let mut counts = vec![0usize; nranks];
    for &r in &p.tet_rank {
        counts[r as usize] += 1;
    }
    let (mn, mx) = (counts.iter().min().unwrap(), counts.iter().max().unwrap());
    assert!(mx - mn <= 1, "{counts:?}");
    let mut owner = vec![u32::MAX; m.nodes.len()];
    for (t, q) in m.tets.iter().enumerate() {
        for &v in q {
            owner[v as usize] = owner[v as usize].min(p.tet_rank[t]);
        }
    }
    assert_eq!(owner, p.node_rank);
    let mut seen = vec![false; m.nodes.len()];
    for &v in &p.node_order {
        assert!(!std::mem::replace(&mut seen[v as usize], true));
    }
    assert!(seen.iter().all(|&s| s));
    assert!(p.node_order.windows(2).all(|w| p.node_rank[w[0] as usize] <= p.node_rank[w[1] as usize]));
    assert_eq!(p, partition(m, nranks), "not deterministic");
}

#[test]
fn partition_is_balanced_and_consistent() {
    let m = default_mesh();
    for n in [1, 2, 3, 4, 7, 16] {
        check_partition(m, n);
    }
    let p = partition(m, 4);
    // Morton chunks are spatially compact: each rank owns some nodes
    for r in 0..4 {
        assert!(p.node_rank.contains(&r));
    }
}

/// Prints counts, quality and timing for the report sizes:
/// `cargo test --release --lib mesh::tests::report -- --ignored --nocapture`.
#[test]
#[ignore]
fn report() {
    let sized = |h: f64| {
        let mut s = MeshSpec::paper_default();
        s.contact_size = h;
        (format!("h_c={h}"), s)
    };
    let cases =
        [sized(0.25), sized(0.125), sized(0.0625), ("offset R".to_string(), offset_spec()), ("half domain".to_string(), half_spec())];
    for (name, s) in cases {
        let t0 = Instant::now();
        let m = generate(&s).unwrap();
        let dt = t0.elapsed();
        let q = quality(&m);
        let t1 = Instant::now();
        let _ = partition(&m, 8);
        println!(
            "{name}: tets={} vertices={} P2 nodes={} contact tris={} contact nodes={} \
             min dihedral={:.2} max aspect={:.2} generate={:.3}s partition(8)={:.3}s",
            m.tets.len(),
            m.n_vertices,
            m.nodes.len(),
            m.contact_tris.len(),
            m.contact_nodes.len(),
            q.min_dihedral_deg,
            q.max_aspect_ratio,
            dt.as_secs_f64(),
            t1.elapsed().as_secs_f64()
        );
    }
}

/// The corners of contact triangle `c` and its longest edge in the (x, z) plane.
fn face_triangle(m: &Mesh, c: &[u32; 6]) -> (Vec<[f64; 3]>, f64) {
    let p: Vec<[f64; 3]> = c[..3].iter().map(|&v| m.nodes[v as usize]).collect();
    let edge = |a: usize, b: usize| ((p[a][0] - p[b][0]).powi(2) + (p[a][2] - p[b][2]).powi(2)).sqrt();
    let longest = edge(0, 1).max(edge(1, 2)).max(edge(2, 0));
    (p, longest)
}

/// The smallest and largest radius sqrt(x^2 + z^2) of the points.
fn radius_range(p: &[[f64; 3]]) -> (f64, f64) {
    p.iter().map(|q| q[0].hypot(q[2])).fold((f64::INFINITY, 0.0f64), |(a, b), x| (a.min(x), b.max(x)))
}

#[test]
fn ring_refines_only_around_the_hertz_circle() {
    // Half domain, h_c = 0.25 with a 0.0625 ring on 0.85 <= r <= 1.15.
    let mut s = half_spec();
    s.ring = Some(Ring { inner: 0.85, outer: 1.15, size: 0.0625 });
    let m = generate(&s).unwrap();
    check_graded(&m);
    let (mut in_ring, mut centre) = (0, 0);
    for c in &m.contact_tris {
        let (p, longest) = face_triangle(&m, c);
        let (rmin, rmax) = radius_range(&p);
        if rmax >= 0.85 && rmin <= 1.15 {
            // A triangle touching the ring has legs of at most the ring size.
            assert!(longest <= 0.0625 * 2f64.sqrt() * (1.0 + 1e-12), "triangle at r in [{rmin}, {rmax}] has edge {longest}");
            in_ring += 1;
        }
        if rmax < 0.4 {
            // Far from the ring (distance >= 0.45) the mesh is coarser than the ring.
            assert!(longest > 0.0625 * 2f64.sqrt() * (1.0 + 1e-12), "triangle at r <= {rmax} has edge {longest}");
            centre += 1;
        }
    }
    assert!(in_ring > 500 && centre > 0, "{in_ring} {centre}");
}

#[test]
fn patch_refines_only_its_rectangle() {
    // Half domain, h_c = 0.25, a 0.03125 patch on -0.4 <= X <= 0.4, -1.02 <= Z <= -0.94
    // (a thin outlet constriction): triangles touching it have legs <= 0.03125, triangles
    // more than 0.25 away from it are coarser, and the mesh outside stays conforming.
    let mut s = half_spec();
    let r = Rect { x0: -0.4, x1: 0.4, z0: -1.02, z1: -0.94 };
    s.patch = Some((r, 0.03125));
    let m = generate(&s).unwrap();
    check_graded(&m);
    let (mut inside, mut far) = (0, 0);
    let fine = 0.03125 * 2f64.sqrt() * (1.0 + 1e-12);
    for c in &m.contact_tris {
        let (p, longest) = face_triangle(&m, c);
        let (x0, x1) = p.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), q| (a.min(q[0]), b.max(q[0])));
        let (z0, z1) = p.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), q| (a.min(q[2]), b.max(q[2])));
        let gap = (r.x0 - x1).max(x0 - r.x1).max(0.0).hypot((r.z0 - z1).max(z0 - r.z1).max(0.0));
        if gap == 0.0 {
            assert!(longest <= fine, "triangle touching the patch has edge {longest}");
            inside += 1;
        } else if gap > 0.25 {
            assert!(longest > fine, "triangle {gap} away from the patch has edge {longest}");
            far += 1;
        }
    }
    // The patch holds 0.8 x 0.08 / (0.03125^2 / 2) = 131 triangles at least.
    assert!(inside >= 131 && far > 100, "{inside} {far}");
}

#[test]
fn patch_with_radii_refines_only_its_annular_part() {
    // The patch rectangle -0.4 <= X <= 0.4, -1.1 <= Z <= -0.3 limited to 0.97 <= r <= 1.0
    // (a side lobe along the contact edge): triangles touching that part have legs <=
    // 0.03125; triangles of the rectangle more than 0.25 away from the annulus are
    // coarser, so the limit is honoured; the mesh stays conforming.
    let mut s = half_spec();
    let r = Rect { x0: -0.4, x1: 0.4, z0: -1.1, z1: -0.3 };
    s.patch = Some((r, 0.03125));
    s.patch_radii = Some((0.97, 1.0));
    let m = generate(&s).unwrap();
    check_graded(&m);
    let (mut inside, mut away) = (0, 0);
    let fine = 0.03125 * 2f64.sqrt() * (1.0 + 1e-12);
    for c in &m.contact_tris {
        let (p, longest) = face_triangle(&m, c);
        let in_rect = p.iter().all(|q| q[0] >= r.x0 && q[0] <= r.x1 && q[2] >= r.z0 && q[2] <= r.z1);
        let (rmin, rmax) = radius_range(&p);
        if in_rect && rmax >= 0.97 && rmin <= 1.0 {
            assert!(longest <= fine, "triangle across the annular patch has edge {longest}");
            inside += 1;
        } else if in_rect && (0.97 - rmax).max(rmin - 1.0) > 0.25 {
            assert!(longest > fine, "triangle of the rectangle {}a off the annulus has edge {longest}", (0.97 - rmax).max(rmin - 1.0));
            away += 1;
        }
    }
    // The annular part: about 0.8 x 0.03 / (0.03125^2 / 2) = 49 triangles at least.
    assert!(inside >= 49 && away >= 4, "{inside} {away}");
}
