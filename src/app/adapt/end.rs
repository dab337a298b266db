//! The end of an adaptive run: its result written, reached or short of the target.

use super::level::accuracy_report;
use super::{written, Adapted, Level, Solved};
use crate::app::estimate::Estimate;
use crate::app::point::post_point;
use crate::app::{Context, Outcome};
use crate::case::Scene;
use crate::error::Error;

/// After level `k` stopped with `e`: when the time budget was spent (and a level converged
/// before), the last converged level's result, labelled as short of its target; any other
/// error (a signal, a failure outside Newton) stops the run.
pub(super) fn out_of_time(
    ctx: &Context,
    scene: &Scene,
    prev: Option<&Solved>,
    k: usize,
    levels: &[Level],
    e: Error,
) -> Result<Adapted, Error> {
    match prev {
        // (`finish` clears the spent budget before it writes.)
        Some(prev) if crate::interrupt::agreed() == crate::interrupt::DEADLINE => {
            let acc = scene.accuracy;
            let why = format!("the time budget accuracy.max_seconds = {} s was spent during level {k}", acc.max_seconds);
            let why = short_of(acc.target, &why, levels);
            finish(ctx, scene, prev, acc.target, levels, Some(why))
        }
        _ => Err(e),
    }
}

/// The message of a run that stops short of `target`: why, and which level's result is
/// written with which estimate.
pub(super) fn short_of(target: f64, why: &str, levels: &[Level]) -> String {
    let (level, written) = written(levels);
    let est = written.est;
    format!(
        "accuracy: target {target} not reached: {why}; the result of level {level} is written with its estimated error ({})",
        describe(est)
    )
}

/// The estimate, or "none: a single level" without one.
pub(super) fn describe(est: Option<Estimate>) -> String {
    est.map_or("none: a single level".to_string(), |e| e.describe())
}

/// Writes the result of `done` (the last level solved) with the accuracy report; with a
/// `shortfall` the report says the target was not reached and the run exits 4.
pub(super) fn finish(
    ctx: &Context,
    scene: &Scene,
    done: &Solved,
    target: f64,
    levels: &[Level],
    shortfall: Option<String>,
) -> Result<Adapted, Error> {
    // The budget bounds the refinement, not the writing of its result.
    crate::interrupt::clear_deadline();
    crate::interrupt::check("the Newton solve")?;
    // The scene written with the result is the one its level was solved with.
    let mut scene = scene.clone();
    scene.reynolds.gradient_jump = done.gradient_jump;
    scene.effects.cavitation = done.cavitation;
    let scene = &scene;
    let pmax_change = crate::app::estimate::pmax_change(levels);
    if let Some(c) = &pmax_change {
        ctx.log(super::level::pmax_note(c, target));
    }
    let point = ctx.write_results(|dir| {
        let point = post_point(ctx, scene, &done.setup, &done.sol, done.condensation_s, done.friction.clone(), dir)?;
        ctx.amend_summary(dir, |summary| {
            summary["accuracy"] = accuracy_report(target, levels, shortfall.as_deref());
            if let Some(e) = &done.exponents {
                summary["speed_exponents"] = e.clone();
            }
        })?;
        Ok(point)
    })?;
    let outcome = match shortfall {
        Some(why) => {
            ctx.log(&why);
            Outcome::ShortOfTarget(why)
        }
        None => Outcome::Done,
    };
    let (_, last) = written(levels);
    Ok(Adapted {
        outcome,
        point,
        estimate: last.est,
        levels: levels.len(),
        unknowns: last.unknowns(),
        newton_iterations: levels.iter().map(|l| l.newton_iterations).sum(),
        pmax_change: pmax_change.map(|c| c.relative),
    })
}
