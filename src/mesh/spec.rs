//! Mesh specification: box geometry, contact rectangle, grading law, and
//! validation of all of it (including the coarse tensor grid breakpoints).
//!
//! All lengths are dimensionless, in units of the Hertz radius `a`.
use crate::error::Error;

/// Edge length of the coarse tensor-grid cells (units of `a`).
pub const COARSE_CELL: f64 = 16.0;

/// Maximum number of halvings of [`COARSE_CELL`] allowed for the contact size.
pub const MAX_LEVEL: u32 = 20;

/// The element size the mesher uses for a requested `size` (units of a): the largest
/// 16/2^L <= size (to 1e-5 relative, so 0.0625 stays 0.0625 and a size written with six
/// significant digits, 0.00195312 for 2^-9, is that size and not the next level down),
/// 0 <= L <= MAX_LEVEL. Every refinement level of the Kuhn grid halves the cell, so only
/// these sizes exist.
pub fn dyadic_size(size: f64) -> f64 {
    let mut h = COARSE_CELL;
    let mut level = 0;
    while h > size * (1.0 + 1e-5) && level < MAX_LEVEL {
        h *= 0.5;
        level += 1;
    }
    h
}

/// Axis-aligned rectangle `[x0, x1] x [z0, z1]` on the top face `y = 0`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Rect {
    pub x0: f64,
    pub x1: f64,
    pub z0: f64,
    pub z1: f64,
}

impl Rect {
    /// Area of the rectangle.
    pub fn area(&self) -> f64 {
        (self.x1 - self.x0) * (self.z1 - self.z0)
    }

    /// True if every edge is finite and the rectangle has a positive width along x and z.
    pub fn is_proper(&self) -> bool {
        [self.x0, self.x1, self.z0, self.z1].iter().all(|v| v.is_finite()) && self.x0 < self.x1 && self.z0 < self.z1
    }

    /// True if `(x, z)` lies in the rectangle enlarged by `tol` on each side.
    pub fn contains(&self, x: f64, z: f64, tol: f64) -> bool {
        x >= self.x0 - tol && x <= self.x1 + tol && z >= self.z0 - tol && z <= self.z1 + tol
    }
}

/// Parameters of the graded tetrahedral mesh of the equivalent solid.
///
/// The box is `x in [-W/2, W/2]`, `y in [-D, 0]`, `z in [-W/2, z_hi]` with
/// `W = cube_edge`, `D = depth`, `z_hi = 0` if `half_z` else `W/2`.
/// The target element size at distance `d` from the contact rectangle is
/// `h(d) = contact_size + growth * d`.
#[derive(Clone, Debug, PartialEq)]
pub struct MeshSpec {
    pub cube_edge: f64,
    pub depth: f64,
    pub half_z: bool,
    pub contact: Rect,
    pub contact_size: f64,
    pub growth: f64,
    /// Optional finer core: a rectangle inside `contact` meshed with size `core.1`
    /// (rounded down to 16/2^k), grading away from it at the same growth.
    pub core: Option<(Rect, f64)>,
    /// Depth of the core (units of a): with `core_depth > 0` the core is the box of the
    /// rectangle times `-core_depth <= Y <= 0` (the stresses below the contact), otherwise
    /// the rectangle on the face.
    pub core_depth: f64,
    /// Optional finer ring: the annulus `inner <= sqrt(X^2 + Z^2) <= outer` meshed with
    /// size `size` (rounded down to 16/2^k), grading away from it at the same growth.
    /// It follows the Hertz circle, where the inlet build-up, the side lobes and the
    /// outlet spike sit.
    pub ring: Option<Ring>,
    /// Optional finer patch: a rectangle of the top face (it may reach outside `contact`)
    /// meshed with size `patch.1` (rounded down to 16/2^k), grading away from it at the same
    /// growth. For a feature that is small and placed: the outlet constriction, the film
    /// next to a spin pole.
    pub patch: Option<(Rect, f64)>,
    /// Optional radial limits `(r_min, r_max)` of the patch: only the part of the rectangle
    /// with `r_min <= sqrt(X^2 + Z^2) <= r_max` is refined (a sector of an annulus, for a
    /// side lobe that follows the contact edge).
    pub patch_radii: Option<(f64, f64)>,
    /// Optional graded size field on the top face (adaptive refinement: sizes from an
    /// error estimate on an earlier mesh); the tetrahedra under it are refined to it plus
    /// `growth` times their depth.
    pub size_field: Option<std::sync::Arc<super::size_field::SizeField>>,
}

/// An annulus on the top face, centred on the origin, with its element size.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Ring {
    pub inner: f64,
    pub outer: f64,
    pub size: f64,
}

impl MeshSpec {
    /// The paper's setup: 60 x 60 x 60 cube, contact `[-3,3]^2`, `h_c = 0.25`, growth 0.5.
    pub fn paper_default() -> Self {
        MeshSpec {
            cube_edge: 60.0,
            depth: 60.0,
            half_z: false,
            contact: Rect { x0: -3.0, x1: 3.0, z0: -3.0, z1: 3.0 },
            contact_size: 0.25,
            growth: 0.5,
            core: None,
            core_depth: 0.0,
            ring: None,
            patch: None,
            patch_radii: None,
            size_field: None,
        }
    }

    /// Box corners `(lo, hi)` as `[x, y, z]`.
    ///
    /// Full domain: `z in [-W/2, W/2]`. Half domain (`half_z`): `z in [-W/2, 0]`,
    /// the symmetry plane `z = 0` being the upper z face.
    pub fn bounds(&self) -> ([f64; 3], [f64; 3]) {
        let w2 = 0.5 * self.cube_edge;
        let z_hi = if self.half_z { 0.0 } else { w2 };
        ([-w2, -self.depth, -w2], [w2, 0.0, z_hi])
    }

    /// Box volume.
    pub fn box_volume(&self) -> f64 {
        let (lo, hi) = self.bounds();
        (0..3).map(|a| hi[a] - lo[a]).product()
    }

    /// Box surface area.
    pub fn box_surface(&self) -> f64 {
        let (lo, hi) = self.bounds();
        let l: Vec<f64> = (0..3).map(|a| hi[a] - lo[a]).collect();
        2.0 * (l[0] * l[1] + l[1] * l[2] + l[0] * l[2])
    }

    /// Actual contact size: the largest `16 / 2^L <= contact_size` (L >= 0).
    pub fn actual_contact_size(&self) -> f64 {
        dyadic_size(self.contact_size)
    }

    /// Coarse grid breakpoints along the three axes.
    pub fn coarse_grid(&self) -> [Vec<f64>; 3] {
        let (lo, hi) = self.bounds();
        [0, 1, 2].map(|a| coarse_breaks(lo[a], hi[a], COARSE_CELL))
    }

    /// Validates the spec; returns the actual contact size on success.
    pub fn validate(&self) -> Result<f64, Error> {
        self.validate_scalars()?;
        let h = self.actual_contact_size();
        self.validate_rect(h)?;
        Ok(h)
    }

    /// Checks positivity / finiteness of the scalar parameters.
    fn validate_scalars(&self) -> Result<(), Error> {
        let pos = |name: &str, v: f64| {
            if v.is_finite() && v > 0.0 {
                Ok(())
            } else {
                Err(Error::invalid(format!("mesh spec: {name} must be finite and > 0 (got {v})")))
            }
        };
        pos("cube_edge", self.cube_edge)?;
        pos("depth", self.depth)?;
        pos("contact_size", self.contact_size)?;
        pos("growth", self.growth)?;
        if let Some(r) = self.ring {
            pos("ring size", r.size)?;
            if !(r.inner.is_finite() && r.outer.is_finite() && r.inner >= 0.0 && r.outer > r.inner) {
                return Err(Error::invalid(format!(
                    "mesh spec: ring radii must satisfy 0 <= inner < outer (got inner {}, outer {})",
                    r.inner, r.outer
                )));
            }
        }
        if let Some((r, size)) = self.patch {
            pos("patch size", size)?;
            if !r.is_proper() {
                return Err(Error::invalid(format!("mesh spec: patch rectangle {r:?} is empty or not finite")));
            }
        }
        if let Some((r0, r1)) = self.patch_radii {
            if !(r0.is_finite() && r1.is_finite() && r0 >= 0.0 && r1 > r0) {
                return Err(Error::invalid(format!("mesh spec: patch radii must satisfy 0 <= r_min < r_max (got r_min {r0}, r_max {r1})")));
            }
        }
        if self.contact_size < COARSE_CELL / f64::from(1u32 << MAX_LEVEL) {
            return Err(Error::invalid(format!("mesh spec: contact_size {} is below the minimum 16/2^{MAX_LEVEL}", self.contact_size)));
        }
        Ok(())
    }

    /// Checks that the contact rectangle is non-empty, inside the top face,
    /// has edges on the dyadic grid of spacing `h`, and lies in full-size
    /// (16 x 16 x 16) coarse cells so that the mesh over it is a uniform
    /// Kuhn grid of spacing `h`.
    fn validate_rect(&self, h: f64) -> Result<(), Error> {
        let r = self.contact;
        if !r.is_proper() {
            return Err(Error::invalid(format!("mesh spec: contact rectangle {r:?} is empty or not finite")));
        }
        let (lo, hi) = self.bounds();
        let tol = 1e-12 * self.cube_edge;
        if r.x0 < lo[0] - tol || r.x1 > hi[0] + tol || r.z0 < lo[2] - tol || r.z1 > hi[2] + tol {
            return Err(Error::invalid(format!(
                "mesh spec: contact rectangle {r:?} is not inside the top face \
                 x in [{}, {}], z in [{}, {}]",
                lo[0], hi[0], lo[2], hi[2]
            )));
        }
        for v in [r.x0, r.x1, r.z0, r.z1] {
            if !on_dyadic_grid(v, h) {
                return Err(Error::invalid(format!(
                    "mesh spec: contact rectangle edge {v} is not a multiple of the actual \
                     contact size {h} (requested {})",
                    self.contact_size
                )));
            }
        }
        self.validate_full_cells(h)
    }

    /// Checks that all coarse cells under the rectangle are full 16-cubes.
    fn validate_full_cells(&self, _h: f64) -> Result<(), Error> {
        let r = self.contact;
        let g = self.coarse_grid();
        let top = g[1][g[1].len() - 2..].to_vec();
        if (top[1] - top[0] - COARSE_CELL).abs() > 1e-12 {
            return Err(Error::invalid(format!(
                "mesh spec: depth {} too small: the top coarse layer must be {COARSE_CELL} thick \
                 (need depth >= {})",
                self.depth,
                1.5 * COARSE_CELL
            )));
        }
        for (axis, (a, b)) in [(0usize, (r.x0, r.x1)), (2, (r.z0, r.z1))] {
            for w in g[axis].windows(2) {
                let overlaps = w[1] > a && w[0] < b;
                if overlaps && (w[1] - w[0] - COARSE_CELL).abs() > 1e-12 {
                    return Err(Error::invalid(format!(
                        "mesh spec: contact rectangle {r:?} overlaps the coarse cell [{}, {}] \
                         along axis {} which is not a full {COARSE_CELL}-cell; enlarge the box",
                        w[0],
                        w[1],
                        ["x", "y", "z"][axis]
                    )));
                }
            }
        }
        Ok(())
    }
}

/// True if `v` is an integer multiple of `h` (up to round-off).
fn on_dyadic_grid(v: f64, h: f64) -> bool {
    let q = v / h;
    (q - q.round()).abs() < 1e-9
}

/// Coarse breakpoints of `[lo, hi]`: `lo`, the multiples of `c` strictly
/// inside, `hi`; an end interval shorter than `c/2` is merged with its
/// neighbour (when there is one).
pub fn coarse_breaks(lo: f64, hi: f64, c: f64) -> Vec<f64> {
    let mut b = vec![lo];
    let mut k = (lo / c).floor() as i64 + 1;
    while (k as f64) * c < hi {
        let v = (k as f64) * c;
        if v > lo {
            b.push(v);
        }
        k += 1;
    }
    b.push(hi);
    if b.len() > 2 && b[1] - b[0] < 0.5 * c {
        b.remove(1);
    }
    let n = b.len();
    if n > 2 && b[n - 1] - b[n - 2] < 0.5 * c {
        b.remove(n - 2);
    }
    b
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn breaks_match_examples() {
        assert_eq!(coarse_breaks(-30.0, 30.0, 16.0), vec![-30.0, -16.0, 0.0, 16.0, 30.0]);
        assert_eq!(coarse_breaks(-60.0, 0.0, 16.0), vec![-60.0, -48.0, -32.0, -16.0, 0.0]);
        assert_eq!(coarse_breaks(-30.0, 0.0, 16.0), vec![-30.0, -16.0, 0.0]);
        // remainder 2 < 8 merged with its neighbour
        assert_eq!(coarse_breaks(-34.0, 34.0, 16.0), vec![-34.0, -16.0, 0.0, 16.0, 34.0]);
        assert_eq!(coarse_breaks(-20.0, 0.0, 16.0), vec![-20.0, 0.0]);
    }

    #[test]
    fn actual_size_is_dyadic_floor() {
        let mut s = MeshSpec::paper_default();
        assert_eq!(s.actual_contact_size(), 0.25);
        s.contact_size = 0.3;
        assert_eq!(s.actual_contact_size(), 0.25);
        s.contact_size = 100.0;
        assert_eq!(s.actual_contact_size(), 16.0);
        s.contact_size = 0.0625;
        assert_eq!(s.actual_contact_size(), 0.0625);
        assert_eq!(dyadic_size(0.0625 * (1.0 - 1e-14)), 0.0625);
        assert_eq!(dyadic_size(0.07), 0.0625);
        // Six significant digits of 2^-9 (what `awk '{print r / 2}'` wrote for half of
        // 2^-8) are 2^-9, not 2^-10; 0.1 % below a level is the level below.
        assert_eq!(dyadic_size(0.00195312), 0.001953125);
        assert_eq!(dyadic_size(0.0625 * 0.999), 0.03125);
        assert_eq!(dyadic_size(100.0), 16.0);
        assert_eq!(dyadic_size(0.0), COARSE_CELL / f64::from(1u32 << MAX_LEVEL));
    }

    #[test]
    fn half_domain_bounds() {
        let mut s = MeshSpec::paper_default();
        s.half_z = true;
        let (lo, hi) = s.bounds();
        assert_eq!(lo, [-30.0, -60.0, -30.0]);
        assert_eq!(hi, [30.0, 0.0, 0.0]);
    }

    #[test]
    fn validation_accepts_paper_cases() {
        let mut s = MeshSpec::paper_default();
        assert_eq!(s.validate().unwrap(), 0.25);
        s.contact = Rect { x0: -4.5, x1: 1.5, z0: -3.0, z1: 3.0 };
        assert!(s.validate().is_ok());
        s.half_z = true;
        s.contact = Rect { x0: -3.0, x1: 3.0, z0: -3.0, z1: 0.0 };
        assert!(s.validate().is_ok());
    }

    #[test]
    fn validation_rejects_bad_specs() {
        let base = MeshSpec::paper_default();
        let mut s = base.clone();
        s.growth = 0.0;
        assert!(s.validate().unwrap_err().to_string().contains("growth"));
        let mut s = base.clone();
        s.contact_size = -1.0;
        assert!(s.validate().unwrap_err().to_string().contains("contact_size"));
        let mut s = base.clone();
        s.contact.x0 = -3.1;
        assert!(s.validate().unwrap_err().to_string().contains("multiple"));
        let mut s = base.clone();
        s.contact.x1 = 40.0;
        assert!(s.validate().unwrap_err().to_string().contains("inside"));
        let mut s = base.clone();
        s.contact.x1 = 20.0;
        assert!(s.validate().unwrap_err().to_string().contains("full"));
        let mut s = base.clone();
        s.depth = 20.0;
        assert!(s.validate().unwrap_err().to_string().contains("depth"));
        let mut s = base.clone();
        s.half_z = true; // R = [-3,3]^2 sticks out of z in [-30, 0]
        assert!(s.validate().unwrap_err().to_string().contains("inside"));
        let mut s = base;
        s.contact.x0 = 3.0;
        assert!(s.validate().unwrap_err().to_string().contains("empty"));
    }
}
