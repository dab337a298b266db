//! The values' slopes in the parameters of the residual, from their adjoints and the
//! residual's derivative (`ehl::driver::adjoint`): the films' exponents in eta_R Ue
//! (`output.speed_exponents`): d ln hc / d ln(eta_R Ue) and d ln hm / d ln(eta_R Ue) of the
//! converged discrete solution; and the slopes of hc, hm, fx and fz in the cavitation
//! penalty xi, from which the adaptive loop estimates the penalty's own error.
//!
//! They are what a tribologist reads off a film formula (Hamrock and Dowson: 0.67 and
//! 0.68) for this operating point, at the cost of one LU and two transposed solves instead
//! of two more runs; a finite difference of two runs at eta_R Ue (1 +- eps) on the same
//! mesh checks them (`tests/accuracy.rs`).
use super::estimate::PenaltySlopes;
use super::marking::{film_weights, Goal};
use super::Context;
use crate::ehl::driver::{film_derivative, Adjoint, Parameter};
use crate::ehl::post::{FieldsOnFace, FilmStats};
use crate::error::Error;
use serde_json::json;
use std::path::Path;

/// The exponents of hc and hm in eta_R Ue at the adjoint's state. Collective.
pub(super) fn speed_exponents(ctx: &Context, adjoint: &mut Adjoint, fields: &FieldsOnFace, st: &FilmStats) -> Result<[f64; 2], Error> {
    let df = adjoint.residual_derivative(Parameter::Speed)?;
    let zc = adjoint.film(ctx, &film_weights(fields, [0.0, 0.0])?)?;
    let zm = adjoint.film(ctx, &film_weights(fields, st.hm_at)?)?;
    Ok([film_derivative(&zc, &df) / st.hc, film_derivative(&zm, &df) / st.hm])
}

/// The slopes d ln q / d ln xi in the cavitation penalty xi of the goals' values at the
/// adjoint's state ([`super::estimate::PenaltySlopes`]): -z . dF/d ln xi over the
/// Reynolds rows, the only ones xi enters. Collective.
pub(super) fn penalty_slopes(adjoint: &mut Adjoint, goals: &[Goal]) -> Result<PenaltySlopes, Error> {
    let df = adjoint.residual_derivative(Parameter::Penalty)?;
    let df = adjoint.pressure_part(&df);
    let slope = |name: &str| goals.iter().find(|g| g.name == name).map(|g| film_derivative(&g.z, &df) / g.scale);
    let films = [slope("hc"), slope("hm")];
    let [Some(hc), Some(hm)] = films else { return Err(Error::numerical("the penalty slopes need the goals hc and hm")) };
    // On a half domain fz vanishes by symmetry, and is no goal.
    let friction = slope("fx").map(|fx| [fx, slope("fz").unwrap_or(0.0)]);
    Ok(PenaltySlopes { films: [hc, hm], friction })
}

/// The exponents at the converged state `x` of a solver, logged, as the summary's value
/// (None when the scene does not ask for them). A failure is reported, not fatal: the film
/// result stands without them. Collective.
pub(super) fn of_state(
    ctx: &Context,
    scene: &crate::case::Scene,
    solver: &crate::ehl::driver::EhlSolver,
    mesh: &crate::mesh::Mesh,
    layout: &crate::ehl::layout::Layout,
    x: &[f64],
) -> Option<serde_json::Value> {
    if !scene.output.speed_exponents {
        return None;
    }
    let fields = FieldsOnFace::new(mesh, layout, x);
    let st = fields.stats();
    let got =
        crate::collective::agree(&ctx.world, solver.adjoint(ctx, scene, x).and_then(|mut a| speed_exponents(ctx, &mut a, &fields, &st)));
    Some(report(ctx, got))
}

/// Logs the exponents (or why they are missing) and returns the summary's value.
pub(super) fn report(ctx: &Context, got: Result<[f64; 2], Error>) -> serde_json::Value {
    match got {
        Ok([hc, hm]) => {
            ctx.log(format!("speed exponents: d ln hc / d ln(eta_R Ue) = {hc:.5}, d ln hm / d ln(eta_R Ue) = {hm:.5} (adjoint)"));
            json!({ "hc": hc, "hm": hm, "method": "adjoint of hc and hm against the residual's derivative in lambda_bar" })
        }
        Err(e) => {
            ctx.log(format!("warning: the speed exponents asked for by output.speed_exponents were not computed: {e}"));
            json!({ "failed": e.to_string() })
        }
    }
}

/// Adds `speed_exponents` to the summary.json in `dir` (rank 0; nothing without a value).
pub(super) fn add_to_summary(ctx: &Context, dir: &Path, value: Option<&serde_json::Value>) -> Result<(), Error> {
    match value {
        Some(v) => ctx.amend_summary(dir, |summary| summary["speed_exponents"] = v.clone()),
        None => Ok(()),
    }
}
