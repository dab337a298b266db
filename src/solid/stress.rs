//! Stress recovery from a P2 displacement field (pure Rust, no PETSc).
//!
//! - [`element_stress`]: the Cauchy stress of one P2 tetrahedron at a point (linear in the
//!   element, discontinuous across faces).
//! - [`recover_nodal`]: a continuous field, one tensor per P2 node: the average of the
//!   element stresses at that node over the tetrahedra sharing it, weighted by their volume
//!   (docs/subsurface.md compares it with the element values).
//! - [`eval_p2`]: the recovered field inside a tetrahedron, by P2 interpolation.
//! - [`von_mises`], [`principal`], [`tresca`]: invariants.
//!
//! Tensors are stored as `[xx, yy, zz, xy, yz, xz]` (VTK's symmetric-tensor order).
use crate::fem::elasticity::stress_from_grad;
use crate::fem::geometry::AffineTet;
use crate::fem::p2tet::{p2_tet_basis_bary, p2_tet_grads_bary, P2_TET_REF_NODES};

/// Symmetric tensor `[xx, yy, zz, xy, yz, xz]`.
pub type Sym = [f64; 6];

/// The Cauchy stress of the P2 displacement `u` (30 node-major values) of the tetrahedron
/// `verts` at the point with barycentric coordinates `bary`, for Lamé parameters
/// `(lambda, mu)`.
pub fn element_stress(verts: &[[f64; 3]; 4], u: &[f64; 30], bary: [f64; 4], lambda: f64, mu: f64) -> Sym {
    let geo = AffineTet::new(verts);
    let d = p2_tet_grads_bary(bary, &geo.grad_bary);
    let mut g = [[0.0; 3]; 3];
    for a in 0..10 {
        for c in 0..3 {
            for k in 0..3 {
                g[c][k] += u[3 * a + c] * d[a][k];
            }
        }
    }
    let s = stress_from_grad(&g, lambda, mu);
    [s[0][0], s[1][1], s[2][2], s[0][1], s[1][2], s[0][2]]
}

/// Barycentric coordinates of the 10 P2 nodes of a tetrahedron.
pub fn node_bary(k: usize) -> [f64; 4] {
    let x = P2_TET_REF_NODES[k];
    [1.0 - x[0] - x[1] - x[2], x[0], x[1], x[2]]
}

/// Volume-weighted nodal averaging of the element stresses.
///
/// `tets`: P2 connectivity; `verts(t)`: the 4 vertices of tet `t`; `u(t)`: its 30 nodal
/// displacements; `wanted[n]`: whether node `n` needs a value. Returns one tensor per node
/// (zero where not wanted) and the number of tetrahedra evaluated.
pub fn recover_nodal(
    n_nodes: usize,
    tets: &[[u32; 10]],
    verts: &dyn Fn(usize) -> [[f64; 3]; 4],
    u: &dyn Fn(usize) -> [f64; 30],
    wanted: &[bool],
    lambda: f64,
    mu: f64,
) -> (Vec<Sym>, usize) {
    let mut sum = vec![[0.0; 6]; n_nodes];
    let mut weight = vec![0.0; n_nodes];
    let mut evaluated = 0;
    for (t, tet) in tets.iter().enumerate() {
        if !tet.iter().any(|&n| wanted[n as usize]) {
            continue;
        }
        evaluated += 1;
        let v = verts(t);
        let ue = u(t);
        let w = AffineTet::new(&v).abs_det() / 6.0;
        for (k, &n) in tet.iter().enumerate() {
            let n = n as usize;
            if !wanted[n] {
                continue;
            }
            let s = element_stress(&v, &ue, node_bary(k), lambda, mu);
            for c in 0..6 {
                sum[n][c] += w * s[c];
            }
            weight[n] += w;
        }
    }
    for (s, w) in sum.iter_mut().zip(&weight) {
        if *w > 0.0 {
            for c in s.iter_mut() {
                *c /= w;
            }
        }
    }
    (sum, evaluated)
}

/// Superconvergent patch recovery (Zienkiewicz-Zhu) of the element stresses.
///
/// For every vertex a polynomial is fitted by least squares to the element stresses at the
/// 4 points of the degree-2 rule of every tetrahedron sharing the vertex: quadratic (10
/// terms) when the patch has at least 24 samples, linear otherwise. The vertex value is
/// the fit at the vertex; a midside node takes the mean of its two vertices' fits there.
/// Arguments as [`recover_nodal`]; `n_vertices`: the vertices are the nodes `0..n_vertices`.
#[allow(clippy::too_many_arguments)]
pub fn recover_spr(
    nodes: &[[f64; 3]],
    n_vertices: usize,
    tets: &[[u32; 10]],
    verts: &dyn Fn(usize) -> [[f64; 3]; 4],
    u: &dyn Fn(usize) -> [f64; 30],
    wanted: &[bool],
    lambda: f64,
    mu: f64,
) -> (Vec<Sym>, usize) {
    use crate::fem::p2tet::TET_EDGES;
    use crate::fem::quadrature::TET4_BARY;
    let n_nodes = nodes.len();
    // Vertices whose fit is needed: every vertex of a tetrahedron holding a wanted node.
    let mut fit_vertex = vec![false; n_vertices];
    for tet in tets {
        if tet.iter().any(|&n| wanted[n as usize]) {
            for &v in &tet[..4] {
                fit_vertex[v as usize] = true;
            }
        }
    }
    // Vertex -> tetrahedra (CSR) for the fitted vertices.
    let mut start = vec![0usize; n_vertices + 1];
    for tet in tets {
        for &v in &tet[..4] {
            if fit_vertex[v as usize] {
                start[v as usize + 1] += 1;
            }
        }
    }
    for i in 0..n_vertices {
        start[i + 1] += start[i];
    }
    let mut fill = start.clone();
    let mut inc = vec![0u32; start[n_vertices]];
    for (t, tet) in tets.iter().enumerate() {
        for &v in &tet[..4] {
            if fit_vertex[v as usize] {
                inc[fill[v as usize]] = t as u32;
                fill[v as usize] += 1;
            }
        }
    }
    // Sampled stresses of every tetrahedron a fit needs (computed once).
    let mut samples: std::collections::HashMap<u32, [([f64; 3], Sym); 4]> = std::collections::HashMap::new();
    let mut evaluated = 0;
    let mut sample = |t: u32| -> [([f64; 3], Sym); 4] {
        *samples.entry(t).or_insert_with(|| {
            evaluated += 1;
            let v = verts(t as usize);
            let ue = u(t as usize);
            TET4_BARY.map(|l| {
                let x: [f64; 3] = std::array::from_fn(|c| (0..4).map(|k| l[k] * v[k][c]).sum());
                (x, element_stress(&v, &ue, l, lambda, mu))
            })
        })
    };
    // Fitted polynomial coefficients per vertex: (centre, scale, coefficients per component).
    type Fit = ([f64; 3], f64, Vec<[f64; 6]>);
    let basis = |d: [f64; 3], quadratic: bool| -> Vec<f64> {
        let mut b = vec![1.0, d[0], d[1], d[2]];
        if quadratic {
            b.extend([d[0] * d[0], d[1] * d[1], d[2] * d[2], d[0] * d[1], d[1] * d[2], d[0] * d[2]]);
        }
        b
    };
    let mut fits: Vec<Option<Fit>> = vec![None; n_vertices];
    for v in 0..n_vertices {
        if !fit_vertex[v] {
            continue;
        }
        let patch = &inc[start[v]..start[v + 1]];
        let pts: Vec<([f64; 3], Sym)> = patch.iter().flat_map(|&t| sample(t)).collect();
        let c = nodes[v];
        let scale = pts.iter().map(|(x, _)| (0..3).map(|k| (x[k] - c[k]).abs()).fold(0.0, f64::max)).fold(1e-300, f64::max);
        // Quadratic when the patch determines it (well conditioned), linear otherwise (a
        // patch on the boundary may leave a quadratic vanishing at every sample).
        let mut fitted = None;
        for quadratic in [true, false] {
            let nb = if quadratic { 10 } else { 4 };
            if pts.len() < nb || (quadratic && pts.len() < 24) {
                continue;
            }
            let mut ata = nalgebra::DMatrix::<f64>::zeros(nb, nb);
            let mut atb = nalgebra::DMatrix::<f64>::zeros(nb, 6);
            for (x, s) in &pts {
                let b = basis(std::array::from_fn(|k| (x[k] - c[k]) / scale), quadratic);
                for i in 0..nb {
                    for j in 0..nb {
                        ata[(i, j)] += b[i] * b[j];
                    }
                    for k in 0..6 {
                        atb[(i, k)] += b[i] * s[k];
                    }
                }
            }
            let svd = ata.svd(true, true);
            let smax = svd.singular_values.iter().fold(0.0f64, |a, &b| a.max(b));
            let smin = svd.singular_values.iter().fold(f64::INFINITY, |a, &b| a.min(b));
            if smin < 1e-8 * smax {
                continue;
            }
            if let Ok(coef) = svd.solve(&atb, 0.0) {
                fitted = Some((0..nb).map(|i| std::array::from_fn(|k| coef[(i, k)])).collect::<Vec<[f64; 6]>>());
                break;
            }
        }
        let Some(coefs) = fitted else { continue };
        fits[v] = Some((c, scale, coefs));
    }
    let eval = |f: &Fit, x: [f64; 3]| -> Sym {
        let (c, scale, coefs) = f;
        let b = basis(std::array::from_fn(|k| (x[k] - c[k]) / scale), coefs.len() == 10);
        std::array::from_fn(|k| (0..coefs.len()).map(|i| b[i] * coefs[i][k]).sum())
    };
    let mut out = vec![[0.0; 6]; n_nodes];
    let mut done = vec![false; n_nodes];
    for tet in tets {
        if !tet.iter().any(|&n| wanted[n as usize]) {
            continue;
        }
        for k in 0..10 {
            let n = tet[k] as usize;
            if !wanted[n] || done[n] {
                continue;
            }
            let ends: Vec<usize> = if k < 4 { vec![n] } else { TET_EDGES[k - 4].iter().map(|&i| tet[i] as usize).collect() };
            let vals: Vec<Sym> = ends.iter().filter_map(|&v| fits[v].as_ref().map(|f| eval(f, nodes[n]))).collect();
            if vals.is_empty() {
                continue;
            }
            out[n] = std::array::from_fn(|c| vals.iter().map(|s| s[c]).sum::<f64>() / vals.len() as f64);
            done[n] = true;
        }
    }
    (out, evaluated)
}

/// The P2 interpolant of 10 nodal tensors at barycentric coordinates `bary`.
pub fn eval_p2(nodal: &[Sym; 10], bary: [f64; 4]) -> Sym {
    let n = p2_tet_basis_bary(bary);
    let mut s = [0.0; 6];
    for a in 0..10 {
        for c in 0..6 {
            s[c] += n[a] * nodal[a][c];
        }
    }
    s
}

/// Von Mises equivalent stress.
pub fn von_mises(s: &Sym) -> f64 {
    let d = (s[0] - s[1]).powi(2) + (s[1] - s[2]).powi(2) + (s[2] - s[0]).powi(2);
    (0.5 * d + 3.0 * (s[3] * s[3] + s[4] * s[4] + s[5] * s[5])).sqrt()
}

/// Principal stresses, largest first (closed-form eigenvalues of the symmetric 3x3 matrix,
/// trigonometric form).
pub fn principal(s: &Sym) -> [f64; 3] {
    let off = s[3] * s[3] + s[4] * s[4] + s[5] * s[5];
    let q = (s[0] + s[1] + s[2]) / 3.0;
    let (a, b, c) = (s[0] - q, s[1] - q, s[2] - q);
    let p2 = a * a + b * b + c * c + 2.0 * off;
    if p2 <= 1e-300 {
        return [q; 3];
    }
    let p = (p2 / 6.0).sqrt();
    // det((S - q I)/p) / 2, clamped to [-1, 1] against round-off.
    let det = a * (b * c - s[4] * s[4]) - s[3] * (s[3] * c - s[4] * s[5]) + s[5] * (s[3] * s[4] - b * s[5]);
    let r = (det / (2.0 * p * p * p)).clamp(-1.0, 1.0);
    let phi = r.acos() / 3.0;
    let e1 = q + 2.0 * p * phi.cos();
    let e3 = q + 2.0 * p * (phi + 2.0 * std::f64::consts::PI / 3.0).cos();
    let e2 = 3.0 * q - e1 - e3;
    [e1, e2, e3]
}

/// Tresca equivalent stress `sigma_1 - sigma_3` (twice the largest shear stress).
pub fn tresca(s: &Sym) -> f64 {
    let p = principal(s);
    p[0] - p[2]
}

/// The band below the largest value (a fraction of it) within which a flat maximum is
/// sampled for [`peak_vertex`].
pub const PEAK_BAND: f64 = 0.005;

/// Where a flat maximum lies: the vertex of the least-squares quadratic
/// `c0 + c1 x + c2 y + c3 x^2 + c4 x y + c5 y^2` through `samples` ((x, y), value), or None
/// when fewer than 6 samples are given or the fit has no maximum (its Hessian is not
/// negative definite). Fitted over the samples within a fraction of the largest value, the
/// vertex averages out an error of the field that varies from element to element, where
/// the largest sample follows that error (a field within 1 % of its maximum over a tenth of
/// the contact moves its largest sample by the field's error over its curvature).
pub fn peak_vertex(samples: &[([f64; 2], f64)]) -> Option<[f64; 2]> {
    if samples.len() < 6 {
        return None;
    }
    // Centred and scaled coordinates keep the normal equations well conditioned.
    let n = samples.len() as f64;
    let c = [samples.iter().map(|s| s.0[0]).sum::<f64>() / n, samples.iter().map(|s| s.0[1]).sum::<f64>() / n];
    let r = samples.iter().map(|s| (s.0[0] - c[0]).abs().max((s.0[1] - c[1]).abs())).fold(0.0, f64::max);
    if r <= 0.0 {
        return None;
    }
    let mut ata = nalgebra::Matrix6::<f64>::zeros();
    let mut atb = nalgebra::Vector6::<f64>::zeros();
    for &([x, y], v) in samples {
        let (u, w) = ((x - c[0]) / r, (y - c[1]) / r);
        let row = nalgebra::Vector6::new(1.0, u, w, u * u, u * w, w * w);
        ata += row * row.transpose();
        atb += row * v;
    }
    let k = ata.lu().solve(&atb)?;
    // Gradient (k1 + 2 k3 u + k4 w, k2 + k4 u + 2 k5 w) = 0; a maximum needs the Hessian
    // [[2 k3, k4], [k4, 2 k5]] negative definite.
    let (a, b, d) = (2.0 * k[3], k[4], 2.0 * k[5]);
    let det = a * d - b * b;
    if !(a < 0.0 && det > 0.0) {
        return None;
    }
    let u = (-k[1] * d + k[2] * b) / det;
    let w = (-k[2] * a + k[1] * b) / det;
    Some([c[0] + r * u, c[1] + r * w])
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fem::elasticity::lame;
    use crate::fem::p2tet::p2_tet_node_coords;
    use nalgebra::Matrix3;

    #[test]
    fn the_peak_of_a_quadratic_is_its_vertex_whatever_the_samples() {
        let f = |x: f64, y: f64| 2.0 - 3.0 * (x - 0.3).powi(2) - 0.5 * (x - 0.3) * (y + 0.4) - 7.0 * (y + 0.4).powi(2);
        let samples: Vec<([f64; 2], f64)> = (0..40)
            .map(|i| (i as f64 * 0.61803).fract())
            .zip((0..40).map(|i| (i as f64 * 0.75488).fract()))
            .map(|(u, v)| ([u, -v], f(u, -v)))
            .collect();
        let p = peak_vertex(&samples).unwrap();
        assert!((p[0] - 0.3).abs() < 1e-10 && (p[1] + 0.4).abs() < 1e-10, "{p:?}");
        // A saddle or a minimum has no peak.
        let bowl: Vec<([f64; 2], f64)> = samples.iter().map(|&(q, _)| (q, q[0] * q[0] + q[1] * q[1])).collect();
        assert!(peak_vertex(&bowl).is_none());
        assert!(peak_vertex(&samples[..5]).is_none());
    }

    #[test]
    fn the_peak_vertex_of_hamiltons_field_is_its_maximum() {
        // The estimator applied to the exact von Mises field of a sliding Hertz contact
        // (samples every 0.01 a within 1 % of the maximum, as the subsurface search takes
        // them): its bias is the part of the position error the method itself adds.
        use crate::solid::hertz_stress::{hamilton_sliding, sliding_von_mises_max, von_mises as vm};
        for mu in [0.1, 0.3] {
            let (vmax, x0, z0) = sliding_von_mises_max(0.3, mu);
            let f = |x: f64, z: f64| vm(&hamilton_sliding(x, 0.0, z.max(0.0), 0.3, mu));
            let mut samples = Vec::new();
            for i in -30..=30 {
                for j in -30..=30 {
                    let (x, z) = ((x0 * 100.0).round() / 100.0 + 0.01 * i as f64, (z0 * 100.0).round() / 100.0 + 0.01 * j as f64);
                    let v = f(x, z);
                    if v >= (1.0 - PEAK_BAND) * vmax {
                        samples.push(([x, z], v));
                    }
                }
            }
            let p = peak_vertex(&samples).unwrap();
            let d = (p[0] - x0).hypot(p[1] - z0);
            eprintln!(
                "mu = {mu}: {} samples, vertex ({:.4}, {:.4}) a, maximum ({x0:.4}, {z0:.4}) a, distance {d:.4} a",
                samples.len(),
                p[0],
                p[1]
            );
            assert!(d < 0.0025, "mu = {mu}: vertex {p:?} vs maximum ({x0}, {z0}), distance {d}");
        }
    }

    fn verts() -> [[f64; 3]; 4] {
        [[0.1, -0.2, 0.3], [1.3, 0.1, 0.2], [0.2, 0.9, -0.1], [0.4, 0.3, 1.1]]
    }

    /// u_c = sum_d A[c][d] x_d + quadratic part (gradient given analytically).
    fn field(x: [f64; 3]) -> ([f64; 3], [[f64; 3]; 3]) {
        let u = [
            0.3 * x[0] - 0.2 * x[1] + 0.5 * x[2] + 0.7 * x[0] * x[1],
            0.1 * x[0] + 0.4 * x[1] - 0.7 * x[2] - 0.3 * x[2] * x[2],
            0.6 * x[0] + 0.2 * x[1] - 0.1 * x[2] + 0.2 * x[0] * x[0],
        ];
        let g = [[0.3 + 0.7 * x[1], -0.2 + 0.7 * x[0], 0.5], [0.1, 0.4, -0.7 - 0.6 * x[2]], [0.6 + 0.4 * x[0], 0.2, -0.1]];
        (u, g)
    }

    fn nodal_u(v: &[[f64; 3]; 4]) -> [f64; 30] {
        let x = p2_tet_node_coords(v);
        let mut u = [0.0; 30];
        for a in 0..10 {
            u[3 * a..3 * a + 3].copy_from_slice(&field(x[a]).0);
        }
        u
    }

    #[test]
    fn element_stress_of_a_quadratic_field_is_exact() {
        let (l, m) = lame(2.0, 0.3);
        let v = verts();
        let u = nodal_u(&v);
        for bary in [[0.25; 4], [0.1, 0.2, 0.3, 0.4], node_bary(7)] {
            let x: [f64; 3] = std::array::from_fn(|c| (0..4).map(|k| bary[k] * v[k][c]).sum());
            let s = stress_from_grad(&field(x).1, l, m);
            let e = element_stress(&v, &u, bary, l, m);
            let want = [s[0][0], s[1][1], s[2][2], s[0][1], s[1][2], s[0][2]];
            for c in 0..6 {
                assert!((e[c] - want[c]).abs() < 1e-12, "component {c}: {} vs {}", e[c], want[c]);
            }
        }
    }

    /// A linear stress field (quadratic displacement) is recovered exactly at every node by
    /// the averaging (each element already has it exactly), and P2 interpolation of the
    /// nodal values reproduces it inside.
    #[test]
    fn recovery_of_a_linear_stress_field_is_exact() {
        let (nodes, tets) = crate::fem::kuhn_box_mesh([2, 2, 2], [0.0; 3], [1.0, 1.0, 1.0]);
        let (l, m) = lame(1.0, 0.25);
        let verts = |t: usize| [0, 1, 2, 3].map(|k| nodes[tets[t][k] as usize]);
        let u = |t: usize| {
            let mut out = [0.0; 30];
            for (a, &n) in tets[t].iter().enumerate() {
                out[3 * a..3 * a + 3].copy_from_slice(&field(nodes[n as usize]).0);
            }
            out
        };
        let wanted = vec![true; nodes.len()];
        let (s, count) = recover_nodal(nodes.len(), &tets, &verts, &u, &wanted, l, m);
        assert_eq!(count, tets.len());
        for (n, x) in nodes.iter().enumerate() {
            let e = stress_from_grad(&field(*x).1, l, m);
            assert!((s[n][0] - e[0][0]).abs() < 1e-12 && (s[n][4] - e[1][2]).abs() < 1e-12, "node {n}");
        }
        let t = 5;
        let nodal: [Sym; 10] = tets[t].map(|n| s[n as usize]);
        let b = [0.1, 0.2, 0.3, 0.4];
        let v = verts(t);
        let x: [f64; 3] = std::array::from_fn(|c| (0..4).map(|k| b[k] * v[k][c]).sum());
        let e = stress_from_grad(&field(x).1, l, m);
        let r = eval_p2(&nodal, b);
        assert!((r[2] - e[2][2]).abs() < 1e-12 && (r[5] - e[0][2]).abs() < 1e-12);
        // The patch recovery reproduces a linear field too (a polynomial of its basis).
        let (s, _) = recover_spr(&nodes, vertex_count(&tets), &tets, &verts, &u, &wanted, l, m);
        for (n, x) in nodes.iter().enumerate() {
            let e = stress_from_grad(&field(*x).1, l, m);
            assert!((s[n][0] - e[0][0]).abs() < 1e-10 && (s[n][4] - e[1][2]).abs() < 1e-10, "SPR node {n}: {:?}", s[n]);
        }
    }

    /// kuhn_box_mesh numbers the vertices first? Count the nodes that are tet corners and
    /// check they are the first ones.
    fn vertex_count(tets: &[[u32; 10]]) -> usize {
        let nv = tets.iter().flat_map(|t| t[..4].iter()).map(|&v| v as usize + 1).max().unwrap();
        assert!(tets.iter().all(|t| t[4..].iter().all(|&m| m as usize >= nv)), "vertices first");
        nv
    }

    #[test]
    fn invariants_match_an_eigen_decomposition() {
        for s in [
            [1.0, -2.0, 0.5, 0.3, -0.7, 1.1],
            [-1.0, -1.0, -1.0, 0.0, 0.0, 0.0],
            [3.0, 1.0, 1.0, 0.0, 0.0, 0.0],
            [0.0, 0.0, 0.0, 1.0, 0.0, 0.0],
        ] {
            let mat = Matrix3::new(s[0], s[3], s[5], s[3], s[1], s[4], s[5], s[4], s[2]);
            let mut ev: Vec<f64> = mat.symmetric_eigen().eigenvalues.iter().copied().collect();
            ev.sort_by(|a, b| b.partial_cmp(a).unwrap());
            let p = principal(&s);
            // acos loses half the digits near a double eigenvalue: 1e-8 relative is ample.
            for k in 0..3 {
                assert!((p[k] - ev[k]).abs() < 1e-7, "{s:?}: {p:?} vs {ev:?}");
            }
            assert!((tresca(&s) - (ev[0] - ev[2])).abs() < 1e-7);
            let vm = (0.5 * ((ev[0] - ev[1]).powi(2) + (ev[1] - ev[2]).powi(2) + (ev[2] - ev[0]).powi(2))).sqrt();
            assert!((von_mises(&s) - vm).abs() < 1e-12);
        }
        // Pure shear tau: von Mises sqrt(3) tau, Tresca 2 tau.
        let s = [0.0, 0.0, 0.0, 2.0, 0.0, 0.0];
        assert!((von_mises(&s) - 2.0 * 3f64.sqrt()).abs() < 1e-14);
        assert!((tresca(&s) - 4.0).abs() < 1e-14);
    }
}
