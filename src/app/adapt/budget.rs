//! Step 5 of the adaptive loop before a level is solved: the budgets of unknowns, time
//! and memory, and the level cut to them.

use super::{written, Budget, Cut, Level, Loop, Solved, Step};
use crate::app::estimate::Estimate;
use crate::app::lubricated::Setup;
use crate::app::marking::{cut_count, longest_edges, Marking, NextMesh, TimeLeft, MIN_BUDGET_SHARE};
use crate::app::memory::{self, MemoryLeft};
use crate::app::Context;
use crate::case::schema::Accuracy;
use crate::case::{CavitationModel, Scene};
use crate::collective;
use crate::ehl::driver::Coupling;

/// Meshes tried for a level cut to the budget (each a fraction of a second at 600,000
/// unknowns): a cut that still exceeds it is cut again from the meshes tried ([`cut_count`]).
const MAX_CUTS: usize = 6;

/// The cut a level over its budget leads to, before it is decided: the marking it refines
/// a part of (`marked` triangles), the meshes tried for it with the last one over the
/// budget (count refined, unknowns), and the `count` of largest indicator to refine with
/// their `share` of the marked indicator ([`cut_count`]).
struct PlannedCut<'a> {
    marking: &'a Marking,
    marked: usize,
    tried: Vec<(usize, u64)>,
    count: usize,
    share: f64,
}

impl<'a> PlannedCut<'a> {
    /// From `marking`, the meshes tried so far (`over`), the cut the last of them refined
    /// (None: the whole marking), its `n` unknowns, the level before's `before` unknowns and
    /// the `budget`. None when the marking has no ranking (zone marking).
    fn of(marking: &'a Marking, over: &[(usize, u64)], cut: Option<Cut>, n: u64, before: u64, budget: u64) -> Option<Self> {
        let marked = marking.ranked.as_ref()?.len();
        let mut tried = over.to_vec();
        tried.push((cut.map_or(marked, |c| c.count), n));
        let count = cut_count(before, &tried, budget);
        Some(PlannedCut { marking, marked, tried, count, share: marking.indicator_share(count) })
    }
}

impl Loop<'_> {
    /// Step 5 before the solve: a level over `accuracy.max_unknowns`, the time left or the
    /// memory a rank may reach is meshed again with its quartered triangles halved, cut to
    /// the budget, or not begun (the run ends with the level before's result).
    pub(super) fn within_budgets(&mut self, scene: &Scene, setup: &Setup, k: usize) -> Step<()> {
        let (ctx, acc, target, growth) = (self.ctx, self.acc, self.acc.target, scene.mesh.growth);
        let (n_u, n_p) = setup.layout.counts();
        let n = (n_u + n_p + 1) as u64;
        // The time budget as a bound on the level's unknowns: what the level before's cost
        // per unknown lets end in the time left. A level that would not end in it is cut
        // or not begun, rather than abandoned at the deadline after most of its cost.
        let time = time_left(ctx, acc, &self.levels, self.previous.as_ref());
        let by_time = time.filter(|t| t.unknowns() < acc.max_unknowns);
        let budget = by_time.map_or(acc.max_unknowns, |t| t.unknowns());
        // The memory as a bound too: a level the node cannot hold is cut or not begun,
        // rather than killed with the run.
        let condensed = Coupling::of_scene(scene, n_p, self.previous.is_some()) == Coupling::Condensed;
        let by_memory = memory_left(ctx, &self.levels, self.previous.as_ref(), condensed).filter(|m| m.unknowns() < budget);
        let by_time = by_time.filter(|_| by_memory.is_none());
        let budget = by_memory.map_or(budget, |m| m.unknowns());
        let budget_by = match (by_memory, by_time) {
            (Some(_), _) => Budget::Memory,
            (None, Some(_)) => Budget::Seconds,
            (None, None) => Budget::Unknowns,
        };
        // Quartering saves a level; over a budget the level it would save is not reached
        // anyway, and halving leaves room for the rest of the marking
        // (cases/hard/spin-0.5deg: quartered, level 4 would have had 998,894 unknowns).
        // The marking then halves, here and in a cut below.
        // A level solved again on its own mesh was within its budget.
        let over_budget = n > budget && self.again_of.is_none();
        if let Some(prev) = self.previous.as_mut().filter(|p| over_budget && p.marking.as_ref().is_some_and(|m| m.quartered() > 0)) {
            ctx.log(format!(
                "accuracy: level {k} would have {n} unknowns, above its budget of {budget} ({}); again with its {} quartered triangles halved",
                budget_by.key(),
                prev.marking.as_ref().map_or(0, |m| m.quartered())
            ));
            self.next = prev.halved_marking(growth);
            return Step::Again;
        }
        let (Some(prev), true) = (&self.previous, over_budget) else { return Step::On(()) };
        // The level is cut to the budget: the marked triangles of largest indicator that
        // fit, once per run (a cut level is the last, below), and not when even the next
        // full level's change could not take every estimate below the target.
        let before = if self.levels.is_empty() { 0 } else { written(&self.levels).1.unknowns() as u64 };
        let over_what = match (by_memory, by_time) {
            (Some(m), _) => format!(
                "level {k} would have {n} unknowns and need about {:.1} GB per rank from level {}'s peak ({:.1} GB at {} unknowns), more than {:.0} % of the {:.1} GB a rank may reach ({})",
                m.predicted(n) / 1024.0,
                k - 1,
                m.peak_mb / 1024.0,
                m.before,
                100.0 * super::memory::MEMORY_FILL,
                m.room_mb / 1024.0,
                match crate::ehl_options::get().memory_per_rank_gb {
                    Some(_) => "-ehl_memory_per_rank".to_string(),
                    None => "its memory now and its share of the node's free memory; -ehl_memory_per_rank sets it".to_string(),
                }
            ) + out_of_core_hint(),
            (None, Some(t)) => format!(
                "level {k} would have {n} unknowns and take about {:.0} s at level {}'s cost ({} unknowns in {:.0} s), more than the {:.0} s left of accuracy.max_seconds = {} s",
                t.predicted(n),
                k - 1,
                t.before,
                t.seconds,
                t.left.max(0.0),
                acc.max_seconds
            ),
            (None, None) => format!("level {k} would have {n} unknowns, above accuracy.max_unknowns = {}", acc.max_unknowns),
        };
        // The cut this mesh leads to (none without a ranked marking, or after
        // [`MAX_CUTS`] meshes).
        let planned = prev
            .marking
            .as_ref()
            .filter(|_| self.over.len() < MAX_CUTS)
            .and_then(|m| PlannedCut::of(m, &self.over, self.cut, n, before, budget))
            .filter(|p| p.count > 0);
        let hopeful = planned.as_ref().is_some_and(|p| {
            Estimate::cut_worth_solving(&self.levels, target, scene.effects.cavitation == CavitationModel::Penalty, p.share)
        });
        // A cut level kept from the target by the cavitation penalty's part alone: the
        // level before is solved again as complementarity, and the cut is gated and
        // estimated on that sequence (below, step 7 of the module documentation).
        let penalty_alone = planned.is_some()
            && !hopeful
            && scene.effects.cavitation == CavitationModel::Penalty
            && self.levels.last().is_some_and(|l| l.penalty.is_some())
            && Estimate::cut_could_reach(&self.levels, target, false);
        if penalty_alone {
            let why = format!("{over_what}, and the cavitation penalty's part alone keeps a level cut to it from the target");
            let back = self.before.take();
            self.switch_to_complementarity(back, &why);
            return Step::Again;
        }
        let refused = planned.as_ref().filter(|_| !hopeful).map(|p| {
            format!(
                " (a level cut to it, the {} of the {} marked triangles with the largest indicator, {:.0} % of it, could not take every estimate below the target)",
                p.count,
                p.marked,
                100.0 * p.share
            )
        });
        if let Some(PlannedCut { marking, marked, tried, count, share }) = planned.filter(|_| hopeful) {
            self.over = tried;
            if share >= MIN_BUDGET_SHARE {
                ctx.log(format!(
                    "accuracy: {over_what}; it refines the {count} of the {marked} marked triangles with the largest indicator instead ({:.0} % of their indicator)",
                    100.0 * share
                ));
                self.next = Some(NextMesh::marked(&prev.setup.mesh, &longest_edges(&prev.setup.mesh), marking, Some(count), growth));
                self.cut = Some(Cut { count, share, by: budget_by });
                return Step::Again;
            }
        }
        self.short(scene, prev, &format!("{over_what}{}", refused.unwrap_or_default()))
    }
}

/// The time budget as it bears on the next level (with `max_seconds` set): the seconds left
/// and the cost of the last level, when that level is a guide: solved from a coarser level
/// (level 0 starts from the Hertz pressure) and monolithic, as every level after it is (a
/// level condensed onto the face has another cost per unknown: on the M = 10 point the
/// condensed level 2 took 4.2 s for 48,396 unknowns and the monolithic level 3 33 s for
/// 122,746).
fn time_left(ctx: &Context, acc: Accuracy, levels: &[Level], previous: Option<&Solved>) -> Option<TimeLeft> {
    let monolithic = previous.is_some_and(|p| p.condensation_s.is_none());
    if levels.len() < 2 || !monolithic || acc.max_seconds <= 0.0 {
        return None;
    }
    let last = written(levels).1;
    // Each rank has its own clock: rank 0's times decide for all, or the ranks could part
    // ways over a level that fits on one and not on another.
    let t = collective::from_rank0(&ctx.world, &[ctx.start.elapsed().as_secs_f64(), last.seconds - last.failed_seconds]);
    Some(TimeLeft { left: acc.max_seconds - t[0], before: last.unknowns() as u64, seconds: t[1] })
}

/// The memory as it bears on the next level: the rank whose room holds the fewest unknowns
/// ([`MemoryLeft`]), from the last level's own peak (the largest rank's), grown as the next
/// level's coupling grows (`condensed`). Collective: every rank gets the same bound.
fn memory_left(ctx: &Context, levels: &[Level], previous: Option<&Solved>, condensed: bool) -> Option<MemoryLeft> {
    previous?;
    let last = written(levels).1;
    let exponent = if condensed { memory::CONDENSED_MEMORY_EXPONENT } else { memory::LEVEL_MEMORY_EXPONENT };
    let before = last.unknowns() as u64;
    let room = match crate::ehl_options::get().memory_per_rank_gb {
        Some(gb) => gb * 1024.0,
        None => {
            use mpi::traits::Communicator;
            let here = ctx.world.split_shared(0).size().max(1) as f64;
            match (crate::output::resident_mb(), memory::node_free_mb()) {
                (Some(r), Some(f)) => r + f / here,
                _ => f64::INFINITY,
            }
        }
    };
    let peak_mb = last.peak_memory_mb;
    let rooms = collective::all_gather_f64(&ctx.world, &[room]);
    rooms.iter().map(|&room_mb| MemoryLeft { room_mb, before, peak_mb, exponent }).min_by_key(|m| m.unknowns())
}

/// What to try when the memory bounds a level: MUMPS's factors out of core, unless the
/// user runs so already (docs/performance.md, "Factors out of core": 22 % less peak for 27 %
/// more wall on table2-ue2 at 0.001).
fn out_of_core_hint() -> &'static str {
    match crate::petsc::options::get_string("-mat_mumps_icntl_22") {
        Ok(Some(v)) if v.trim() != "0" => "",
        _ => " (-mat_mumps_icntl_22 1 puts MUMPS's factors on disk: about a fifth less memory for a quarter more time)",
    }
}
