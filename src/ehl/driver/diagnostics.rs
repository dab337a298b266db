//! Diagnostics of the Newton solve: where and why the film closed, and a finite-difference
//! check of the exact Jacobian (`-ehl_check_jacobian`).
use crate::ehl::layout::Layout;
use crate::ehl::system::EhlSystem;
use crate::petsc::{self, Matrix, Vector};

/// Words of a failure whose film closed at a spin pole inside the Hertz circle: the model
/// has no film there, on any mesh (a caller that would refine and retry checks for them).
pub const POLE_COLLAPSE: &str = "next to the spin pole";

/// A Newton solve stopped because the film closed.
#[derive(Clone, Copy, Debug)]
pub(super) struct Collapse {
    /// Where (X, Z in units of a).
    pub(super) at: [f64; 2],
    /// Z of the solved problem's spin pole (units of a), with spin kinematics.
    pub(super) pole: Option<f64>,
}

impl Collapse {
    /// If the film closed within 0.25 a of a spin pole inside the Hertz circle: why, in
    /// words. At the pole the mean surface velocity vanishes, so the isothermal Reynolds
    /// equation has no entrainment there to carry a film (README "Strong spin").
    pub(super) fn at_pole(&self) -> Option<String> {
        let zc = self.pole?;
        let [x, z] = self.at;
        (zc.abs() < 1.0 && x.hypot(z - zc) <= 0.25).then(|| {
            format!("the film closes at ({x:.3}, {z:.3})a, {POLE_COLLAPSE} (0, {zc:.3})a inside the Hertz circle, where the mean surface velocity vanishes: the isothermal Reynolds equation has no entrainment there to carry a film (README \"Strong spin\")")
        })
    }
}

/// Directional finite-difference check of the exact Jacobian, block by block:
/// for a random direction v restricted to one column block (U, P or H0), compares J v with
/// (F(x + d v) - F(x - d v)) / (2 d) on each row block. Returns (row block, column block,
/// relative error) for the 9 pairs. Collective.
pub fn check_jacobian(
    system: &mut EhlSystem,
    layout: &Layout,
    rank: usize,
    x0: &[f64],
    j: &Matrix,
) -> petsc::Result<Vec<(String, String, f64)>> {
    use crate::petsc::snes::Problem;
    let comm = petsc::comm_world();
    let n = layout.total();
    let block_of = |i: usize| -> usize {
        if i as i32 == layout.h0 {
            return 2;
        }
        let r = layout.ranges.partition_point(|&s| s <= i) - 1;
        if i - layout.ranges[r] < layout.n_u[r] {
            0
        } else {
            1
        }
    };
    let names = ["U", "P", "H0"];
    // A generic point near the start: the Hertz start has P = 0 exactly at every node
    // outside the Hertz circle, on the kink of the cavitation penalty (pen'' jumps from
    // 1/delta to 0), where central differences straddle the kink and are wrong by
    // xi h / (4 delta). A P-perturbation of 1e-3 >> the FD step moves every node off it
    // (and puts some inside the penalty's quadratic zone, so that is checked too).
    // Deterministic pseudo-random numbers in [-0.5, 0.5) for the point and the direction.
    let mut seed: u64 = 12345;
    let mut rnd = || {
        seed = seed.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
        ((seed >> 11) as f64 / (1u64 << 53) as f64) - 0.5
    };
    let x0: Vec<f64> = x0.iter().enumerate().map(|(i, &v)| v + if block_of(i) == 1 { 2e-3 * rnd() } else { 0.0 }).collect();
    let x0 = &x0[..];
    system.jacobian(x0, j)?;
    j.assemble()?;
    let (lo, hi) = (layout.ranges[rank], layout.ranges[rank + 1]);
    let mut out = Vec::new();
    let dir_all: Vec<f64> = (0..n).map(|_| rnd()).collect();
    for cb in 0..3 {
        let v: Vec<f64> = (0..n).map(|i| if block_of(i) == cb { dir_all[i] } else { 0.0 }).collect();
        let vmax = v.iter().fold(0.0f64, |a, b| a.max(b.abs()));
        let d = 1e-7 / vmax.max(1e-300);
        let vv = Vector::new(comm, layout.local(rank))?;
        vv.set_local_values(&v[lo..hi])?;
        let jv = vv.duplicate()?;
        j.mult(&vv, &jv)?;
        let jv = jv.gather_all()?;
        let eval = |s: &mut EhlSystem, xs: &[f64]| -> petsc::Result<Vec<f64>> {
            let f = Vector::new(comm, layout.local(rank))?;
            f.set_all(0.0)?;
            s.residual(xs, &f)?;
            f.assemble()?;
            f.gather_all()
        };
        let xp: Vec<f64> = x0.iter().zip(&v).map(|(a, b)| a + d * b).collect();
        let xm: Vec<f64> = x0.iter().zip(&v).map(|(a, b)| a - d * b).collect();
        let (fp, fm) = (eval(system, &xp)?, eval(system, &xm)?);
        for rb in 0..3 {
            let (mut num, mut den) = (0.0f64, 0.0f64);
            for i in 0..n {
                if block_of(i) != rb {
                    continue;
                }
                let fd = (fp[i] - fm[i]) / (2.0 * d);
                num = num.max((fd - jv[i]).abs());
                den = den.max(jv[i].abs().max(fd.abs()));
            }
            out.push((names[rb].to_string(), names[cb].to_string(), if den > 0.0 { num / den } else { 0.0 }));
        }
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::Collapse;

    #[test]
    fn a_collapse_is_blamed_on_the_spin_pole_only_next_to_a_pole_inside_the_contact() {
        // The strong-spin scene at lambda = 0.297 deg: pole at Z = -0.871 (kinematics test),
        // the film closed at the node (0, -0.906).
        let c = Collapse { at: [0.0, -0.906], pole: Some(-0.871) };
        assert!(c.at_pole().unwrap().contains("spin pole (0, -0.871)a"));
        // Far from the pole, the pole outside the Hertz circle, or no spin: no such claim.
        assert!(Collapse { at: [0.6, -0.5], pole: Some(-0.871) }.at_pole().is_none());
        assert!(Collapse { at: [0.0, -0.95], pole: Some(-1.2) }.at_pole().is_none());
        assert!(Collapse { at: [0.0, -0.9], pole: None }.at_pole().is_none());
    }
}
