//! The first level of the adaptive loop when it fails on its mesh: the finer mesh it is
//! solved again on (annuli around the radii where the film closed), the gradient-jump term
//! switched off after a closed film, and the state a retry starts from (where the failed
//! try got). docs/accuracy.md, "The loop", step 1.
use super::lubricated::Setup;
use super::marking::{field_of_sizes, longest_edges, next_field, within_bands, within_radius};
use super::Context;
use crate::case::Scene;
use crate::collective;
use crate::ehl::driver::{Coarser, EhlSolution, EhlSolver, Milder, RampLimits, Start, Tries};
use crate::ehl::post::FieldsOnFace;
use crate::error::{Error, Reached};
use crate::mesh::size_field::SizeField;
use crate::mesh::spec::dyadic_size;
use std::sync::Arc;

/// How many times a first level that does not converge is solved again on a finer mesh
/// (cases/hard/heavy-3gpa converges on the second retry: 0.25 a, then 0.0625 a and 0.03125 a
/// annuli where the film closed).
pub(super) const FIRST_LEVEL_RETRIES: usize = 2;
/// Radius (units of a) of the zone a retried first level halves: the Hertz circle with the
/// outlet constriction and the side lobes (r up to about 1.1 a).
pub(super) const FIRST_RETRY_RADIUS: f64 = 1.3;
/// Smallest half width (units of a) of the annulus a retried first level refines around
/// each radius where Newton's iterates closed the film; it is at least the size of the
/// element the film closed in. The constriction of a circular contact (side lobes and
/// outlet) follows the Hertz circle, and a film closed on a coarse mesh is a node of it,
/// up to about one element from the thinnest film: cases/hard/heavy-3gpa closes at r =
/// 0.90-0.91 a on 0.25 a, at 0.95 a on 0.125 a, at 0.99 a on 0.0625 a; its minimum film
/// lies at 0.994 a. The narrow ring its hand-made mesh had was 0.92 <= r <= 1.02.
pub(super) const CLOSURE_BAND: f64 = 0.05;
/// Once the places where the film closed are known, the rest of the zone is halved only
/// down to this size (units of a), and the annulus one step further: the film needs the
/// finer elements at the constriction only. On heavy-3gpa the zone at 0.0625 a (87,804
/// unknowns) spent 7 minutes in a load continuation that failed where the film closed,
/// while 0.125 a with 0.03125 a on 0.92 <= r <= 1.02 converged (90,453 unknowns, 289 s).
pub(super) const FIRST_RETRY_CORE: f64 = 0.125;

/// The size field of a first level solved again, logged with `why` the try failed. Without
/// places where the film closed, `mesh`'s contact triangles within r <=
/// [`FIRST_RETRY_RADIUS`] are halved. With them (`closed`, X and Z in units of a), the
/// rest of that zone is halved down to [`FIRST_RETRY_CORE`], and the triangles of an
/// annulus around each radius where the film closed (half width: the size of the element
/// it closed in, at least [`CLOSURE_BAND`]) are quartered while coarser than
/// [`FIRST_RETRY_CORE`], halved after.
pub(super) fn first_level_again(ctx: &Context, mesh: &crate::mesh::Mesh, growth: f64, why: &str, closed: &[[f64; 2]]) -> Arc<SizeField> {
    let edges = longest_edges(mesh);
    let zone = within_radius(mesh, FIRST_RETRY_RADIUS);
    if closed.is_empty() {
        ctx.log(format!("accuracy: the first level {why}; again with the contact triangles within r <= {FIRST_RETRY_RADIUS} a halved"));
        return Arc::new(next_field(mesh, &edges, &zone, growth));
    }
    // (radius, half width) of each annulus; radii closer than a hundredth of a are one.
    let mut bands: Vec<(f64, f64)> = closed
        .iter()
        .map(|c| {
            let size = mesh.locate_contact(c[0], c[1]).map_or(0.0, |(k, _)| dyadic_size(edges[k]));
            (c[0].hypot(c[1]), size.max(CLOSURE_BAND))
        })
        .collect();
    bands.sort_by(|a, b| a.0.total_cmp(&b.0));
    bands.dedup_by(|a, b| (a.0 - b.0).abs() < 0.01 && a.1 == b.1);
    let in_band = within_bands(mesh, &bands);
    let coarse = |e: f64| dyadic_size(e) > FIRST_RETRY_CORE * (1.0 + 1e-9);
    let sizes: Vec<f64> = (0..edges.len())
        .map(|t| {
            let e = edges[t];
            match (in_band[t], zone[t]) {
                (true, _) if coarse(e) => 0.25 * e,
                (true, _) => 0.5 * e,
                (false, true) if coarse(e) => 0.5 * e,
                _ => e,
            }
        })
        .collect();
    let shown: Vec<String> = bands.iter().map(|(r, w)| format!("{r:.3} +- {w}")).collect();
    ctx.log(format!(
        "accuracy: the first level {why}; again with the contact triangles within r <= {FIRST_RETRY_RADIUS} a halved down to {FIRST_RETRY_CORE} a, and those in the annuli r = {} a (where the film closed) one step further",
        shown.join(", ")
    ));
    Arc::new(field_of_sizes(mesh, &sizes, growth))
}

/// After the first level's film closed: the retries and the levels after them are solved
/// without the gradient-jump term (`own.reynolds.gradient_jump` set to 0, logged). A first
/// level's elements at the constriction of a heavily loaded contact are where the term is at
/// its full strength (h = a/32), and there it closes the film: cases/hard/heavy-3gpa on
/// 0.125 a with 0.03125 a on 0.92 <= r <= 1.02 converges at 67.1 kN without it, and with
/// c_J = 0.01 its load continuation ends with the film closed above 47 kN.
pub(super) fn without_gradient_jump(ctx: &Context, own: &mut Scene) {
    if own.reynolds.gradient_jump > 0.0 {
        ctx.log(format!(
            "accuracy: the film closed on the first level: the gradient-jump term (reynolds.gradient_jump = {}) is off for the retries and the levels after them",
            own.reynolds.gradient_jump
        ));
        own.reynolds.gradient_jump = 0.0;
    }
}

/// Where Newton's iterates closed the film in the failure `e` (X, Z in units of a; none
/// when it says nothing of it), the same on every rank. Collective.
pub(super) fn closures(ctx: &Context, e: &Error) -> Vec<[f64; 2]> {
    let local: Vec<f64> = match e.root() {
        Error::FilmClosed { closed, .. } => closed.iter().flatten().copied().collect(),
        _ => Vec::new(),
    };
    collective::from_rank0(&ctx.world, &local).chunks_exact(2).map(|c| [c[0], c[1]]).collect()
}

/// The furthest state of the continuation in the failure `e`, if it got past its start,
/// the same on every rank (each rank gathered the same state; rank 0's is taken so that a
/// rank that failed otherwise cannot disagree). Collective.
pub(super) fn reached(ctx: &Context, e: &Error) -> Option<Reached> {
    let local = e.reached();
    let t = collective::from_rank0(&ctx.world, &local.map_or(vec![], |r| vec![r.t]));
    let x = collective::from_rank0(&ctx.world, local.map_or(&[][..], |r| &r.x));
    let parameter = local.map_or("", |r| r.parameter);
    t.first().map(|&t| Reached { parameter, t, x })
}

/// Where a retried first level starts instead of the Hertz start.
pub(super) enum Onward {
    /// The furthest state of the failed try's continuation, on the try's mesh.
    Reached(Setup, Reached),
    /// The try's converged state, whose film was not positive everywhere, on its mesh.
    Converged(Setup, Vec<f64>),
}

/// The first level's solve: from the Hertz start, or on from an earlier try (`from`).
/// - After a try whose continuation got part of the way: that continuation's milder
///   problem solved from the try's state and ramped to the scene, with no plain Newton
///   before it and no Hertz start after it. Plain Newton and the pressure-viscosity search
///   had failed from the Hertz start on every try of cases/hard/heavy-3gpa (241 s of its
///   141,301-unknown try), and the load continuation is the one that got anywhere.
/// - After a try that converged to a film not positive everywhere: from that state, as a
///   coarser level's (plain Newton, the continuation from it, then the Hertz start).
///   cases/hard/spin-0.33deg's retry (166,728 unknowns) spent 305 s in plain Newton from
///   the Hertz start and did not converge.
pub(super) fn onward<'a>(ctx: &'a Context, scene: &Scene, solver: &EhlSolver<'a>, from: Option<&Onward>) -> Result<EhlSolution, Error> {
    let label = |setup: &Setup| format!("the failed try's state ({} contact triangles)", setup.mesh.contact_tris.len());
    match from {
        None => solver.solve(ctx, scene, None),
        Some(Onward::Reached(setup, r)) => from_reached(ctx, scene, solver, setup, r, &label(setup), false),
        Some(Onward::Converged(setup, x)) => {
            let f = FieldsOnFace::new(&setup.mesh, &setup.layout, x);
            let p = |x: f64, z: f64| f.at(x, z).map_or(0.0, |v| v.0);
            let label = label(setup);
            solver.solve_from(ctx, scene, Start::from_pressure(&p, f.stats().hc, &label))
        }
    }
}

/// Solves from `r`, the furthest state (on `setup`'s mesh, described by `label`) of a
/// continuation that did not reach the scene: that continuation's milder problem from the
/// state, ramped to the scene, with no plain Newton before it and no last resorts after it
/// (the caller has its own next try). `same_mesh`: `r` is a state of the solver's own mesh
/// (a level solved again), whose displacement then starts a monolithic solve as it is.
pub(super) fn from_reached<'a>(
    ctx: &'a Context,
    scene: &Scene,
    solver: &EhlSolver<'a>,
    setup: &Setup,
    r: &Reached,
    label: &str,
    same_mesh: bool,
) -> Result<EhlSolution, Error> {
    let f = FieldsOnFace::new(&setup.mesh, &setup.layout, &r.x);
    let p = |x: f64, z: f64| f.at(x, z).map_or(0.0, |v| v.0);
    let hc = f.stats().hc;
    let ts = [r.t];
    let milder = Milder { parameter: r.parameter, ts: &ts, p: &p, hc, label };
    let coarser = same_mesh.then_some(Coarser { mesh: &setup.mesh, layout: &setup.layout, x: &r.x });
    // A level solved again on its own mesh has had the gradient-jump factor raised: no
    // remedy is left but the last resorts, and its ramp takes smaller steps before it gives up.
    let ramp = if same_mesh { RampLimits::PATIENT } else { RampLimits::DEFAULT };
    solver.solve_from(
        ctx,
        scene,
        Start::Pressure { p: &p, hc, label, tries: Tries::Continuation, milder: Some(milder), last_resorts: false, ramp, coarser },
    )
}
