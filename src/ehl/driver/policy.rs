//! The solver-option policy: which coupling a scene gets, and the PETSc options (Newton,
//! line search, linear solver) each solve sets as overridable defaults.
use super::start::Start;
use crate::case::Scene;
use crate::petsc;

/// How the elastic unknowns enter Newton.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Coupling {
    /// The elastic block condensed onto the contact face (a dense face compliance): Newton
    /// on (P, H0) with a dense Jacobian.
    Condensed,
    /// U, P and H0 in one sparse system.
    Monolithic,
    /// Rigid solids: no elastic unknowns, H = H0 + (X^2 + Z^2)/2; sparse Newton on (P, H0).
    Rigid,
}

impl Coupling {
    /// The coupling for `scene` with `n_p` pressure unknowns: rigid solids are rigid, else
    /// the scene's `reynolds.coupling` (`monolithic`).
    pub fn of_scene(scene: &Scene, n_p: usize) -> Coupling {
        if scene.effects.elasticity == crate::case::ElasticityModel::Rigid {
            Coupling::Rigid
        } else if monolithic(scene.reynolds.coupling, n_p, scene.is_sweep()) {
            Coupling::Monolithic
        } else {
            Coupling::Condensed
        }
    }

    /// "condensed", "monolithic" or "rigid" (the name in summary.json and the study tables).
    pub fn name(self) -> &'static str {
        match self {
            Coupling::Condensed => "condensed",
            Coupling::Monolithic => "monolithic",
            Coupling::Rigid => "rigid",
        }
    }
}

/// Whether `coupling` with `n_p` pressure unknowns (in a `sweep` or not) means the
/// monolithic system.
pub(super) fn monolithic(coupling: crate::case::Coupling, n_p: usize, sweep: bool) -> bool {
    use crate::case::Coupling as C;
    match coupling {
        C::Monolithic => true,
        C::Condensed => false,
        C::Auto => n_p > if sweep { crate::case::AUTO_MONOLITHIC_ABOVE_SWEEP } else { crate::case::AUTO_MONOLITHIC_ABOVE },
    }
}

/// What Newton does from a start ([`Policy::for_start`]).
#[derive(Clone, Copy)]
pub(super) struct Policy {
    /// Newton's failure leads to the automatic continuation.
    pub(super) continues: bool,
    /// A stiff cavitation penalty (xi > 1e3) is reached through xi = 1e3.
    pub(super) stages_penalty: bool,
    /// PETSc's line search (`-snes_linesearch_type` unless the user gave one). From another
    /// mesh's pressure "l2" (the step minimising the residual norm along the direction,
    /// from the norms at steps 1 and 1/2): there a full step overshoots at a few nodes of a
    /// thin side lobe, the backtracking "bt" then takes its smallest step (0.1) every
    /// iteration and Newton crawls (heavy-3gpa's annular patch 0.0039 a -> 0.002 a: 24
    /// iterations from residual 8e-2 to 1.3e-2, stopped; with l2, 13 + 7 iterations to
    /// convergence). From the Hertz start "bt": l2 stops there at once on a closed film
    /// (DIVERGED_FUNCTION_DOMAIN: it does not backtrack out of the film's domain), and on
    /// the Table 2 scenes it costs 0-2 iterations more.
    pub(super) line_search: &'static str,
    /// The MUMPS LU is rebuilt every third Newton step, GMRES solving on it in between
    /// ([`set_newton_linear_solver`]); otherwise an LU at every step (exact Newton). Only
    /// on the monolithic coupling and from a start near the solution (another mesh's
    /// pressure, a previous operating point): from the Hertz start the inexact steps cost
    /// the hard scenes their convergence (spin-0.33deg: plain Newton ran out of its 30
    /// iterations at residual 5e-4, where exact Newton converges in 24, and every
    /// continuation after it failed; that run predates the tilt continuation on the
    /// monolithic coupling).
    pub(super) reuses_lu: bool,
}

impl Policy {
    /// How Newton proceeds from `start`; `reuse_lu`: the monolithic coupling may reuse
    /// its LU over Newton steps (see `Policy::reuses_lu`).
    pub(super) fn for_start(start: &Start, reuse_lu: bool) -> Policy {
        Policy {
            // Only from the Hertz start: another start falls back to the Hertz start instead.
            continues: matches!(start, Start::Hertz),
            // From the Hertz start and from another mesh's pressure (its cavitation boundary
            // is the coarser mesh's), not from a previous state of the same mesh (a sweep).
            stages_penalty: !matches!(start, Start::Previous(_)),
            line_search: match start {
                Start::Pressure { .. } => "l2",
                _ => "bt",
            },
            reuses_lu: reuse_lu && !matches!(start, Start::Hertz),
        }
    }
}

/// Options prefix of the condensed Newton Jacobian (`-condensed_mat_type aij` with
/// `-pc_factor_mat_solver_type mumps` returns to the sparse-format MUMPS LU).
pub const CONDENSED_PREFIX: &std::ffi::CStr = c"condensed_";

/// Newton defaults (overridable by PETSc options).
pub fn set_newton_defaults() -> petsc::Result<()> {
    use petsc::options::set_default;
    set_default("-snes_type", "newtonls")?;
    set_default("-snes_linesearch_type", "bt")?;
    set_default("-snes_max_it", "30")?;
    set_default("-snes_rtol", "1e-10")?;
    set_default("-snes_atol", "1e-11")?;
    // A tiny step is not convergence: only the residual norm decides.
    set_default("-snes_stol", "0")?;
    Ok(())
}

/// The linear solve of a Newton step (each overridable by PETSc options).
///
/// `reuse_lu` (the monolithic coupling from a start near the solution, see
/// `Policy::reuses_lu`): the MUMPS LU of the sparse Jacobian is rebuilt every third Newton step and
/// GMRES solves on the last one, to the Eisenstat-Walker tolerance (inexact Newton: loose
/// while the residual is large, tight near the solution). The LU is 87 % of a monolithic
/// step (table2-ue2, narrow ring 0.015625 a: 5.1 s per factorisation, 0.16 s per
/// triangular solve); from level 1's pressure this took 10-11 iterations and 41-42 s
/// instead of 9 and 66-71 s, to the same film (README "Solver options"). From the Hertz
/// start it took 17 iterations and 59 s instead of 13 and 102 s there, but it made
/// spin-0.33deg fail, so the Hertz start keeps exact Newton (the user can ask for the
/// reuse everywhere: `-snes_lag_preconditioner 3 -ksp_type gmres -snes_ksp_ew`, and for
/// exact Newton everywhere: `-snes_lag_preconditioner 1 -ksp_type preonly -snes_ksp_ew false`).
///
/// Otherwise a fresh LU every step and one back-substitution: the condensed coupling (the
/// ScaLAPACK LU of the Table 2 scenes is 0.4 s, about what a stale LU costs in GMRES
/// iterations) and the Hertz start.
///
/// Set with `set_ours` before every solve, so that each solve of a process gets its own,
/// while the user's flags stay.
pub fn set_newton_linear_solver(reuse_lu: bool) -> petsc::Result<()> {
    use petsc::options::set_ours;
    let settings: &[(&str, &str)] = if reuse_lu {
        &[("-ksp_type", "gmres"), ("-ksp_gmres_restart", "100"), ("-snes_lag_preconditioner", "3"), ("-snes_ksp_ew", "true")]
    } else {
        &[("-ksp_type", "preonly"), ("-snes_lag_preconditioner", "1"), ("-snes_ksp_ew", "false")]
    };
    for (k, v) in settings {
        set_ours(k, v)?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    #[test]
    fn auto_coupling_switches_to_monolithic_above_the_measured_crossover() {
        use crate::case::{Coupling, AUTO_MONOLITHIC_ABOVE as N, AUTO_MONOLITHIC_ABOVE_SWEEP as NS};
        assert!(!super::monolithic(Coupling::Auto, N, false));
        assert!(super::monolithic(Coupling::Auto, N + 1, false));
        assert!(!super::monolithic(Coupling::Auto, N + 1, true));
        assert!(super::monolithic(Coupling::Auto, NS + 1, true));
        assert!(!super::monolithic(Coupling::Condensed, 100 * N, false));
        assert!(super::monolithic(Coupling::Monolithic, 10, true));
    }
}
