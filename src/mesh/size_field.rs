//! A target element size on the top face, sampled on a uniform grid of cells, graded so
//! that it grows by at most `growth` per unit distance (a Lipschitz bound), for adaptive
//! refinement: the sizes come from an error estimate on a previous mesh's contact
//! triangles, and the mesher ([`super::generate`]) bisects every tetrahedron longer than
//! the field under it plus `growth` times its depth. A pyramid of block minima answers
//! that question for a large tetrahedron without reading every cell under it.
//!
//! All lengths in units of the Hertz radius `a`.

use super::spec::Rect;

/// Most cells a field may have (8 M cells: 64 MB and a third more for the pyramid; a half
/// face of 6 a x 3 a at 1/512 a). Sizes finer than the cells are kept all the same: the
/// cells under a small triangle take its size, so the field is over-refined by at most a
/// cell around it.
const MAX_CELLS: usize = 1 << 23;

/// Most cells [`SizeField::min_over`] reads for one box.
const MAX_READS: usize = 4096;

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
    /// Minima over blocks of 2^l x 2^l cells, l = 1, 2, ... (built by [`SizeField::grade`]),
    /// so that a large box reads a few blocks instead of every cell under it.
    pyramid: Vec<Level>,
}

/// One level of [`SizeField`]'s pyramid: the minimum of each block of cells.
#[derive(Clone, PartialEq)]
struct Level {
    nx: usize,
    min: Vec<f64>,
}

impl std::fmt::Debug for SizeField {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "SizeField({}x{} cells of {} a, sizes {}..{} a)",
            self.nx,
            self.nz,
            self.step,
            self.size.iter().cloned().fold(f64::INFINITY, f64::min),
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
        SizeField { region, step, nx, nz, size: vec![coarse; nx * nz], growth, pyramid: Vec::new() }
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
        // The cells under the vertices and the centroid, which a triangle smaller than a
        // cell may leave without a centre inside it.
        let centroid = [(t[0][0] + t[1][0] + t[2][0]) / 3.0, (t[0][1] + t[1][1] + t[2][1]) / 3.0];
        for p in t.iter().chain(std::iter::once(&centroid)) {
            let i = (((p[0] - self.region.x0) / self.step).floor().max(0.0) as usize).min(self.nx - 1);
            let k = (((p[1] - self.region.z0) / self.step).floor().max(0.0) as usize).min(self.nz - 1);
            let s = &mut self.size[k * self.nx + i];
            *s = s.min(size);
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
        self.build_pyramid();
    }

    /// Halves the grid until one block is left, each block the minimum of the (up to) four
    /// below it.
    fn build_pyramid(&mut self) {
        self.pyramid.clear();
        let (mut nx, mut nz) = (self.nx, self.nz);
        while nx > 1 || nz > 1 {
            let below = self.pyramid.last().map_or(&self.size, |l| &l.min);
            let (cx, cz) = (nx.div_ceil(2), nz.div_ceil(2));
            let mut min = vec![f64::INFINITY; cx * cz];
            for k in 0..nz {
                for i in 0..nx {
                    let m = &mut min[(k / 2) * cx + i / 2];
                    *m = m.min(below[k * nx + i]);
                }
            }
            self.pyramid.push(Level { nx: cx, min });
            (nx, nz) = (cx, cz);
        }
    }

    /// The smallest size over the cells meeting the box `[lo, hi]` (X, Z), plus `growth`
    /// times the distance from the box to the field's rectangle when it lies (partly)
    /// outside. A box of more than [`MAX_READS`] cells gets a lower bound from the pyramid.
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
        // Up to 64 x 64 cells, every cell; beyond, the first level of the pyramid on which
        // the box spans at most 64 blocks each way. Its blocks cover the box and at most one
        // block more on each side, so their minimum is a lower bound of the box's, below it
        // by at most growth times a block's diagonal (the field is graded): a tetrahedron is
        // refined at most a little more than needed.
        let mut level = 0;
        if (i1 - i0) * (k1 - k0) > MAX_READS {
            let span = |a: usize, b: usize, l: usize| ((b - 1) >> l) - (a >> l) + 1;
            while level < self.pyramid.len() && (span(i0, i1, level) > 64 || span(k0, k1, level) > 64) {
                level += 1;
            }
        }
        let (cells, nx) = if level == 0 { (&self.size, self.nx) } else { (&self.pyramid[level - 1].min, self.pyramid[level - 1].nx) };
        let mut m = f64::INFINITY;
        for k in (k0 >> level)..=((k1 - 1) >> level) {
            for i in (i0 >> level)..=((i1 - 1) >> level) {
                m = m.min(cells[k * nx + i]);
            }
        }
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
    fn a_large_box_gets_a_lower_bound_within_a_block_of_its_minimum() {
        let mut f = SizeField::new(square(), 0.002, 1.0, 0.5);
        f.impose_triangle(&[[0.3, 0.3], [0.31, 0.3], [0.3, 0.31]], 0.004);
        f.impose_triangle(&[[-0.5, -0.2], [-0.45, -0.2], [-0.5, -0.1]], 0.01);
        f.grade();
        let exact = |lo: [f64; 2], hi: [f64; 2]| {
            let (i0, i1) = f.cell_range(lo[0], hi[0], f.region.x0, f.nx);
            let (k0, k1) = f.cell_range(lo[1], hi[1], f.region.z0, f.nz);
            let mut m = f64::INFINITY;
            for k in k0..k1.max(k0 + 1) {
                for i in i0..i1.max(i0 + 1) {
                    m = m.min(f.size[k * f.nx + i]);
                }
            }
            m
        };
        for (lo, hi) in [([-0.9, -0.9], [0.9, 0.9]), ([0.2, -0.4], [0.45, 0.1]), ([-0.7, -0.6], [-0.52, 0.3]), ([0.0, 0.0], [0.05, 0.9])] {
            let (bound, m) = (f.min_over(lo, hi), exact(lo, hi));
            // Blocks of at most 1/32 of the box's width (it spans 33-64 of them), one more
            // on each side: the bound is within growth times a block's diagonal.
            let slack = (hi[0] - lo[0]).max(hi[1] - lo[1]) / 32.0 * std::f64::consts::SQRT_2;
            assert!(bound <= m && bound >= m - slack, "box {lo:?}..{hi:?}: bound {bound}, minimum {m}");
        }
    }

    #[test]
    fn a_triangle_smaller_than_a_cell_still_sets_its_cell() {
        // Cells of 0.05 a; a triangle of 0.004 a near a cell corner, whose enlarged outline
        // holds no cell centre.
        let mut f = SizeField::new(square(), 0.05, 1.0, 0.5);
        f.impose_triangle(&[[0.001, 0.001], [0.005, 0.001], [0.001, 0.005]], 0.004);
        f.grade();
        assert_eq!(f.at(0.003, 0.002), 0.004);
        assert_eq!(f.min_over([0.0, 0.0], [0.01, 0.01]), 0.004);
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
