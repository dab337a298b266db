//! What the adaptive loop records of each level, and the `accuracy` report of summary.json
//! made from it.
use crate::app::estimate::{pmax_change, Estimate, PenaltyError, PmaxChange};
use serde_json::json;

/// One level of the adaptive loop.
#[derive(Debug, Clone)]
pub struct Level {
    pub elastic_unknowns: usize,
    pub pressure_unknowns: usize,
    pub contact_triangles: usize,
    pub min_size: f64,
    /// Newton iterations of the attempt that converged.
    pub newton_iterations: usize,
    /// Wall time of the level: every attempt, its adjoint and the next level's marking.
    pub seconds: f64,
    /// The part of `seconds` spent in attempts that did not converge (the level solved
    /// again on the same or another mesh).
    pub failed_seconds: f64,
    /// hc, hm (m), pmax (Pa).
    pub hc: f64,
    pub hm: f64,
    /// Where hm lies (units of a): on a full domain the minimum can move from one side
    /// lobe to the other between levels.
    pub hm_at: [f64; 2],
    pub pmax: f64,
    /// Where pmax lies (units of a).
    pub pmax_at: [f64; 2],
    /// Friction coefficients fx, fz (scenes with friction).
    pub friction: Option<[f64; 2]>,
    /// Estimated errors (None on level 0).
    pub est: Option<Estimate>,
    /// How the level was cut to a budget (None: it refined all its marked triangles).
    pub cut: Option<Cut>,
    /// How many halvings of the level before its finest refinement made: 2 where that
    /// level's marking quartered triangles ([`crate::app::marking::QUARTER_RATIO`]), else 1. The
    /// estimate's crossing guard allows a change to contract by that many steps.
    pub halvings: u32,
    /// The cavitation penalty the level was solved at and its estimated error (where the
    /// penalty was staged, [`crate::app::estimate::PenaltyError`]).
    pub penalty: Option<PenaltyError>,
    /// The level is the mesh of level `again_of` solved again, as complementarity: the
    /// cavitation penalty's own error stood in the way of the last penalty level
    /// ([`crate::app::estimate::penalty_in_the_way`]), whose mesh and the one before it are
    /// solved so. In the estimate's sequence it takes that level's place, and the levels
    /// before the first mesh solved both ways count less the penalty's error measured there
    /// (`estimate::sequence`).
    pub again_of: Option<usize>,
    /// How many triangles the level's marking refines for the next level (after any
    /// widening; None before it marks, or without a marking).
    pub marked: Option<usize>,
    /// The level's peak resident memory per rank, the largest of the ranks (MB), from the
    /// start of its last attempt to its friction pass (`output::restart_peak`).
    pub peak_memory_mb: f64,
}

impl Level {
    /// The level's unknowns: elastic, pressure and H0.
    pub fn unknowns(&self) -> usize {
        self.elastic_unknowns + self.pressure_unknowns + 1
    }

    /// The log's line of level `k`.
    pub(super) fn log_line(&self, k: usize) -> String {
        format!(
            "accuracy: level {k}{}: {} contact triangles (smallest {:.4} a){}, {} unknowns, {} Newton its, {:.1} s{}: hc = {:.5e} m, hm = {:.5e} m at ({:.3}a, {:.3}a), pmax = {:.4e} Pa{}{}; estimated error {}",
            self.again_of.map_or(String::new(), |j| format!(" (level {j}'s mesh as complementarity)")),
            self.contact_triangles,
            self.min_size,
            self.cut.map_or(String::new(), |c| format!(
                " (cut to the budget {}: {:.0} % of the marked indicator)",
                c.by.key(),
                100.0 * c.share
            )),
            self.unknowns(),
            self.newton_iterations,
            self.seconds,
            if self.failed_seconds > 0.0 { format!(" ({:.1} s of them in attempts that failed)", self.failed_seconds) } else { String::new() },
            self.hc,
            self.hm,
            self.hm_at[0],
            self.hm_at[1],
            self.pmax,
            self.friction.map_or(String::new(), |f| format!(", fx = {:.5e}, fz = {:.5e}", f[0], f[1])),
            self.penalty.filter(|p| p.short()).map_or(String::new(), |p| format!(" (cavitation penalty xi = {:.3e}, short of the scene's {:e})", p.xi, p.scene_xi)),
            match (self.est, self.again_of) {
                (Some(e), _) => e.describe(),
                (None, Some(_)) => "- (it serves the estimate of the finer mesh's film, next line)".to_string(),
                (None, None) => "- (first level)".to_string(),
            }
        )
    }
}

/// A level cut to a budget: it refined the `count` marked triangles of largest indicator,
/// which carry `share` of the marked indicator, because all of them would have exceeded
/// the budget `by`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Cut {
    pub count: usize,
    pub share: f64,
    pub by: Budget,
}

/// The budget a level is cut to: `accuracy.max_unknowns`, the unknowns the time left of
/// `accuracy.max_seconds` allows, or those the memory a rank may reach holds
/// ([`super::memory`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Budget {
    Unknowns,
    Seconds,
    Memory,
}

impl Budget {
    /// The scene key or option that sets it.
    pub fn key(self) -> &'static str {
        match self {
            Budget::Unknowns => "accuracy.max_unknowns",
            Budget::Seconds => "accuracy.max_seconds",
            Budget::Memory => "-ehl_memory_per_rank",
        }
    }
}

/// The level that solved level `i`'s mesh again as complementarity ([`Level::again_of`]).
pub fn replacement(levels: &[Level], i: usize) -> Option<(usize, &Level)> {
    levels.iter().enumerate().find(|(_, l)| l.again_of == Some(i))
}

/// The level whose result a run that ends after `levels` writes, with its index: the last
/// level of the estimate's sequence, one per mesh (the last penalty level, or the level
/// that solved its mesh again as complementarity). It is the last level but after the
/// mesh before the last penalty level's was solved again, which only serves its estimate.
pub fn written(levels: &[Level]) -> (usize, &Level) {
    let last = levels.len() - 1;
    match levels.iter().rposition(|l| l.again_of.is_none()) {
        Some(p) => replacement(levels, p).unwrap_or((p, &levels[p])),
        None => (last, &levels[last]),
    }
}

/// The log line of pmax's last change ([`pmax_change`]): pmax is reported, not a target,
/// and a change of at least `target` says the marking left the place that holds it coarse.
pub(super) fn pmax_note(c: &PmaxChange, target: f64) -> String {
    let mut s = format!("accuracy: pmax is not a target: the last level moved it by {:+.2} %", 100.0 * c.relative);
    if c.relative.abs() >= target {
        s += &format!(
            " (its place from ({:.3}a, {:.3}a) to ({:.3}a, {:.3}a)), more than the target: the pressure spike that holds it is resolved only as far as the targets need it (docs/accuracy.md, \"pmax is not a target\")",
            c.from[0], c.from[1], c.to[0], c.to[1]
        );
    }
    s
}

/// The `accuracy` object of summary.json: target, estimates, levels.
pub(super) fn accuracy_report(target: f64, levels: &[Level], shortfall: Option<&str>) -> serde_json::Value {
    let (_, last) = written(levels);
    let mut report = json!({
        "target": target,
        "reached": shortfall.is_none(),
        "estimator": format!("change between the last two levels times max(1, rho/(1-rho)), rho the ratio of the last two changes (capped at 0.8; over two changes after a change below 1/8 of the one before it, 1/64 on a level made by quartering), and at least that fraction of the change before the last; after a level cut to the budget, the level before's estimate less the cut level's change, and at least that change; each adds the cavitation penalty's own error c xi^(-p) of values converging like q_inf + c xi^(-p): |d ln q / d ln xi| / p with the slope from the value's adjoint, p from the slope and the change from the staged penalty xi = 1e3 (0.1 to 1; {} where the penalty was not staged; fx and fz at the slower of hc's and hm's orders); a level solved again as complementarity on the mesh of a penalty level takes that level's place in the sequence, the coarser levels' values shifted by the change measured between the two, and adds the part of that change the penalty's estimate does not explain (the two models' own difference on the mesh); where that part alone keeps it from the target, the mesh of the penalty level before is solved again too, and the estimate of the finer film takes its last change between the two complementarity films, with nothing added", crate::app::estimate::ASSUMED_PENALTY_ORDER),
        "levels": levels.iter().enumerate().map(|(k, l)| {
            let mut v = json!({
                "level": k, "elastic_unknowns": l.elastic_unknowns, "pressure_unknowns": l.pressure_unknowns,
                "contact_triangles": l.contact_triangles, "smallest_size_a": l.min_size,
                "newton_iterations": l.newton_iterations, "seconds": l.seconds, "failed_attempts_seconds": l.failed_seconds,
                "halvings": l.halvings, "hc_m": l.hc, "hm_m": l.hm, "hm_at_a": l.hm_at, "pmax_pa": l.pmax, "pmax_at_a": l.pmax_at,
                "peak_memory_per_rank_mb": l.peak_memory_mb,
            });
            // The first level has no estimate: the key is left out (summary.json holds no null).
            if let Some(e) = l.est {
                v["estimated_error"] = e.json();
                if let Some(g) = e.models_gap_json() {
                    v["change_from_penalty_beyond_its_estimate"] = g;
                }
            }
            if let Some([fx, fz]) = l.friction {
                v["fx"] = json!(fx);
                v["fz"] = json!(fz);
            }
            if let Some(c) = l.cut {
                v["budget_share"] = json!(c.share);
                v["cut_by"] = json!(c.by.key());
            }
            if let Some(p) = l.penalty {
                v["penalty"] = p.json();
            }
            // The mesh of an earlier level, solved again as complementarity.
            if let Some(j) = l.again_of {
                v["complementarity_on_the_mesh_of_level"] = json!(j);
            }
            v
        }).collect::<Vec<_>>(),
    });
    if let Some(e) = last.est {
        report["estimated_error"] = e.json();
    }
    if let Some(c) = pmax_change(levels) {
        report["pmax_last_change"] = json!({ "relative": c.relative, "from_a": c.from, "to_a": c.to });
    }
    if let Some(why) = shortfall {
        report["not_reached_because"] = json!(why);
    }
    report
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pmax_notes_its_place_when_it_moved_by_more_than_the_target() {
        let c = PmaxChange { relative: 0.1032, from: [0.203, -0.891], to: [0.453, -0.734] };
        let s = pmax_note(&c, 0.01);
        assert!(s.starts_with("accuracy: pmax is not a target: the last level moved it by +10.32 % (its place from (0.203a, -0.891a) to (0.453a, -0.734a)), more than the target"), "{s}");
        let s = pmax_note(&PmaxChange { relative: -0.0005, ..c }, 0.01);
        assert_eq!(s, "accuracy: pmax is not a target: the last level moved it by -0.05 %");
    }
}
