//! A target element size on the top face, sampled on a uniform grid of cells, graded so
//! that it grows by at most `growth` per unit distance (a Lipschitz bound), for adaptive
//! refinement: the sizes come from an error estimate on a previous mesh's contact
//! triangles, and the mesher ([`super::generate`]) bisects every tetrahedron longer than
//! the field under it plus `growth` times its depth.
//!
//! All lengths in units of the Hertz radius `a`.

use super::spec::Rect;

/// Most cells a field may have (4 M cells: 32 MB).
const MAX_CELLS: usize = 1 << 22;

/// A graded size field on a rectangle of the top face.
#[derive(Clone, PartialEq)]
pub struct SizeField {
    region: Rect,
    step: f64,
    nx: usize,
    nz: usize,
    /// Size at each cell (row-major in x), after [`SizeField::grade`].
    size: Vec<f64>,
    growth: f64,
    /// Smallest size imposed.
    min_size: f64,
}

impl std::fmt::Debug for SizeField {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "SizeField({}x{} cells of {} a, sizes {}..{} a)",
            self.nx,
            self.nz,
            self.step,
            self.min_size,
            self.size.iter().cloned().fold(0.0, f64::max)
        )
    }
}

impl SizeField {
    /// A field of `region` with cells of about `step` (enlarged if the grid would exceed
    /// [`MAX_CELLS`]), every cell at `coarse`.
    pub fn new(region: Rect, step: f64, growth: f64, coarse: f64) -> Self {
        let (w, d) = (region.x1 - region.x0, region.z1 - region.z0);
        let mut step = step;
        while ((w / step).ceil() * (d / step).ceil()) as usize > MAX_CELLS {
            step *= 2.0;
        }
        let nx = ((w / step).ceil() as usize).max(1);
        let nz = ((d / step).ceil() as usize).max(1);
        SizeField { region, step, nx, nz, size: vec![coarse; nx * nz], growth, min_size: coarse }
    }

    /// Smallest size of the field.
    pub fn min_size(&self) -> f64 {
        self.min_size
    }

    /// Cell spacing.
    pub fn step(&self) -> f64 {
        self.step
    }

    fn centre(&self, i: usize, k: usize) -> [f64; 2] {
        [self.region.x0 + (i as f64 + 0.5) * self.step, self.region.z0 + (k as f64 + 0.5) * self.step]
    }

    fn cell_range(&self, lo: f64, hi: f64, origin: f64, n: usize) -> (usize, usize) {
        let a = ((lo - origin) / self.step).floor().max(0.0) as usize;
        let b = (((hi - origin) / self.step).ceil().max(0.0) as usize).min(n);
        (a.min(n), b)
    }

    /// Lowers the size to at most `size` on every cell whose centre lies in the triangle
    /// `t` (X, Z vertices) enlarged by half a cell, so that no triangle is missed.
    pub fn impose_triangle(&mut self, t: &[[f64; 2]; 3], size: f64) {
        let (xl, xh) = (t.iter().map(|p| p[0]).fold(f64::INFINITY, f64::min), t.iter().map(|p| p[0]).fold(f64::NEG_INFINITY, f64::max));
        let (zl, zh) = (t.iter().map(|p| p[1]).fold(f64::INFINITY, f64::min), t.iter().map(|p| p[1]).fold(f64::NEG_INFINITY, f64::max));
        let (i0, i1) = self.cell_range(xl - self.step, xh + self.step, self.region.x0, self.nx);
        let (k0, k1) = self.cell_range(zl - self.step, zh + self.step, self.region.z0, self.nz);
        let area2 = (t[1][0] - t[0][0]) * (t[2][1] - t[0][1]) - (t[2][0] - t[0][0]) * (t[1][1] - t[0][1]);
        if area2 == 0.0 {
            return;
        }
        let tol = 0.5 * self.step;
        for k in k0..k1 {
            for i in i0..i1 {
                let c = self.centre(i, k);
                // Signed distances of the centre to the three edges (positive inside).
                let inside = (0..3).all(|e| {
                    let (p, q) = (t[e], t[(e + 1) % 3]);
                    let len = ((q[0] - p[0]).powi(2) + (q[1] - p[1]).powi(2)).sqrt();
                    let cross = (q[0] - p[0]) * (c[1] - p[1]) - (q[1] - p[1]) * (c[0] - p[0]);
                    cross * area2.signum() / len >= -tol
                });
                if inside {
                    let s = &mut self.size[k * self.nx + i];
                    *s = s.min(size);
                }
            }
        }
        self.min_size = self.min_size.min(size);
    }

    /// Grades the field: size(x) <= size(y) + growth |x - y| for all cells (two chamfer
    /// sweeps with the 8 neighbours; the diagonal distance is exact, the others are
    /// bounded by it, so the result is within 8 % of the Euclidean grading and never above
    /// an imposed size).
    pub fn grade(&mut self) {
        let (nx, nz) = (self.nx as isize, self.nz as isize);
        let (d1, d2) = (self.growth * self.step, self.growth * self.step * std::f64::consts::SQRT_2);
        let fwd = [(-1isize, 0isize, d1), (0, -1, d1), (-1, -1, d2), (1, -1, d2)];
        let mut sweep = |order: &mut dyn Iterator<Item = (isize, isize)>, sign: isize| {
            for (i, k) in order {
                let mut best = self.size[(k * nx + i) as usize];
                for &(di, dk, d) in &fwd {
                    let (ii, kk) = (i + sign * di, k + sign * dk);
                    if ii >= 0 && ii < nx && kk >= 0 && kk < nz {
                        best = best.min(self.size[(kk * nx + ii) as usize] + d);
                    }
                }
                self.size[(k * nx + i) as usize] = best;
            }
        };
        sweep(&mut (0..nz).flat_map(|k| (0..nx).map(move |i| (i, k))), 1);
        sweep(&mut (0..nz).rev().flat_map(|k| (0..nx).rev().map(move |i| (i, k))), -1);
    }

    /// The smallest size over the cells meeting the box `[lo, hi]` (X, Z), plus `growth`
    /// times the distance from the box to the field's rectangle when it lies (partly)
    /// outside. A box of many cells gets a lower bound (the centre cell's size less
    /// `growth` times the half diagonal), which refines at most a little more than needed.
    pub fn min_over(&self, lo: [f64; 2], hi: [f64; 2]) -> f64 {
        let r = &self.region;
        let gap_x = (r.x0 - hi[0]).max(lo[0] - r.x1).max(0.0);
        let gap_z = (r.z0 - hi[1]).max(lo[1] - r.z1).max(0.0);
        let outside = self.growth * gap_x.hypot(gap_z);
        let cl = [lo[0].clamp(r.x0, r.x1), lo[1].clamp(r.z0, r.z1)];
        let ch = [hi[0].clamp(r.x0, r.x1), hi[1].clamp(r.z0, r.z1)];
        let (i0, i1) = self.cell_range(cl[0], ch[0], r.x0, self.nx);
        let (k0, k1) = self.cell_range(cl[1], ch[1], r.z0, self.nz);
        let (i1, k1) = (i1.max(i0 + 1).min(self.nx), k1.max(k0 + 1).min(self.nz));
        let (i0, k0) = (i0.min(self.nx - 1), k0.min(self.nz - 1));
        let cells = (i1 - i0) * (k1 - k0);
        let m = if cells <= 4096 {
            let mut m = f64::INFINITY;
            for k in k0..k1 {
                for i in i0..i1 {
                    m = m.min(self.size[k * self.nx + i]);
                }
            }
            m
        } else {
            let (ic, kc) = ((i0 + i1) / 2, (k0 + k1) / 2);
            let half_diag = 0.5 * self.step * (((i1 - i0) as f64).hypot((k1 - k0) as f64));
            (self.size[kc * self.nx + ic] - self.growth * half_diag).max(self.min_size)
        };
        m + outside
    }

    /// The size at a point (the cell containing it; clamped to the rectangle).
    pub fn at(&self, x: f64, z: f64) -> f64 {
        self.min_over([x, z], [x, z])
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn square() -> Rect {
        Rect { x0: -1.0, x1: 1.0, z0: -1.0, z1: 1.0 }
    }

    #[test]
    fn a_triangle_lowers_its_cells_and_grading_bounds_the_growth() {
        let mut f = SizeField::new(square(), 0.01, 0.5, 0.25);
        f.impose_triangle(&[[0.0, 0.0], [0.1, 0.0], [0.0, 0.1]], 0.01);
        f.grade();
        assert_eq!(f.at(0.02, 0.02), 0.01);
        // Far from the triangle: the coarse size.
        assert_eq!(f.at(-0.9, -0.9), 0.25);
        // 0.3 a from its nearest point: 0.01 + 0.5 * 0.3, within the chamfer's 8 %.
        let s = f.at(-0.3, 0.05);
        assert!((s - 0.16).abs() < 0.08 * 0.15 + 0.01, "graded size {s}");
        // Lipschitz everywhere: neighbouring cells differ by at most growth * diagonal.
        for k in 0..f.nz - 1 {
            for i in 0..f.nx - 1 {
                let (a, b, c) = (f.size[k * f.nx + i], f.size[k * f.nx + i + 1], f.size[(k + 1) * f.nx + i]);
                assert!((a - b).abs() <= 0.5 * f.step * 1.0000001 && (a - c).abs() <= 0.5 * f.step * 1.0000001);
            }
        }
    }

    #[test]
    fn a_box_sees_its_smallest_cell_and_the_distance_from_outside() {
        let mut f = SizeField::new(square(), 0.05, 1.0, 0.5);
        f.impose_triangle(&[[0.5, 0.5], [0.6, 0.5], [0.5, 0.6]], 0.05);
        f.grade();
        assert_eq!(f.min_over([0.0, 0.0], [0.55, 0.55]), 0.05);
        // A box right of the rectangle, 1 a away: the edge cells' size plus 1 a.
        let edge = f.min_over([1.0, 0.5], [1.0, 0.6]);
        assert!((f.min_over([2.0, 0.5], [2.5, 0.6]) - (edge + 1.0)).abs() < 1e-12);
        // A box over the whole field: a lower bound, never above the true minimum.
        let mut g = SizeField::new(square(), 0.001, 1.0, 0.5);
        g.impose_triangle(&[[0.5, 0.5], [0.6, 0.5], [0.5, 0.6]], 0.05);
        g.grade();
        assert!(g.min_over([-1.0, -1.0], [1.0, 1.0]) <= 0.05);
    }
}
