//! The memory a level of an adaptive run may use ([`super::adapt`], step 5).
//!
//! A level the machine cannot hold is killed by the kernel, and every rank with it: the run
//! ends with no result after its most expensive level. Predicted instead, the level is cut
//! to what fits or not begun, and the run ends with the last level's result and its
//! estimated error (exit 4), as at the unknowns budget.
//!
//! The prediction: the next level's peak resident memory per rank from the last level's
//! own (the largest rank's, from the kernel's high-water mark restarted at each level),
//! grown with the unknowns at [`LEVEL_MEMORY_EXPONENT`]
//! ([`CONDENSED_MEMORY_EXPONENT`] for a level that will be condensed). What a
//! rank may reach: `-ehl_memory_per_rank`, or else its present resident memory plus its
//! share of what the node has free (`MemAvailable`, or less where a cgroup v2 limit leaves
//! less), shared among the run's ranks on the node. On a node with room for the scene's
//! unknowns budget the memory never binds, and a scene's levels do not depend on the
//! machine.

/// Exponent of a monolithic level's peak memory in its unknowns (block low-rank LU, 2
/// ranks). Between consecutive adaptive levels of cases/hard/heavy-3gpa (137,155 to
/// 1,081,612 unknowns; peaks 1.1, 1.3, 2.2, 3.0, 4.9 and 9.0 GB per rank) it was 0.7-1.7,
/// and 1.09 and 1.01 over the two largest steps (predicted 5 % and 12 % high); on table2-ue2 1.05-1.11 (156,208 ->
/// 501,986 -> 738,218 unknowns: 1.2, 4.1, 6.3 GB). A prediction too high cuts a level that
/// would have fitted (heavy-3gpa's level 5, 18 GB on a node of 24 GB: at 1.3 its budget
/// was within 1.5 % of it), one too low loses the run; [`MEMORY_FILL`] holds the steps
/// above 1.2 at the small sizes where they were seen.
pub const LEVEL_MEMORY_EXPONENT: f64 = 1.2;

/// The same for a level solved with the condensed coupling, whose dense Schur complement
/// grows with the square of the face's unknowns (the adaptive loop condenses only levels
/// of fewer than 4,000 pressure unknowns, where the square is far from any room; a scene
/// that sets `reynolds.coupling = "condensed"` keeps it: cases/paper/case2's 0.03125 a ring
/// took 10.9 GB per rank on 2 ranks with 14,513 pressure unknowns, docs/performance.md).
pub const CONDENSED_MEMORY_EXPONENT: f64 = 2.0;

/// The share of a rank's room a level is planned to fill: the rest is for what the
/// prediction does not see (MUMPS's workspace grown after delayed pivots, the page cache
/// other processes need).
pub const MEMORY_FILL: f64 = 0.9;

/// A rank's room for the next level.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MemoryLeft {
    /// The resident memory the rank may reach (MB).
    pub room_mb: f64,
    /// The last level's unknowns.
    pub before: u64,
    /// The last level's peak resident memory per rank (MB).
    pub peak_mb: f64,
    /// How the peak grows with the unknowns ([`LEVEL_MEMORY_EXPONENT`],
    /// [`CONDENSED_MEMORY_EXPONENT`]).
    pub exponent: f64,
}

impl MemoryLeft {
    /// The peak resident memory a level of `n` unknowns is expected to reach (MB).
    pub fn predicted(&self, n: u64) -> f64 {
        super::marking::grown(self.peak_mb, self.before, n, self.exponent)
    }

    /// The most unknowns a level may have and be expected to fit [`MEMORY_FILL`] of the
    /// room.
    pub fn unknowns(&self) -> u64 {
        super::marking::unknowns_within(self.before, self.peak_mb, MEMORY_FILL * self.room_mb, self.exponent)
    }
}

/// `MemAvailable` of /proc/meminfo's text (MB): memory the kernel can give without
/// swapping (free pages and reclaimable caches).
fn mem_available_mb(meminfo: &str) -> Option<f64> {
    let line = meminfo.lines().find(|l| l.starts_with("MemAvailable:"))?;
    let kb: f64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kb / 1024.0)
}

/// The room under a cgroup v2 memory limit (MB): `memory.max` less `memory.current`, None
/// without a limit (`max`).
fn cgroup_room_mb(max: &str, current: &str) -> Option<f64> {
    let max: f64 = max.trim().parse().ok()?;
    let current: f64 = current.trim().parse().ok()?;
    Some((max - current).max(0.0) / (1024.0 * 1024.0))
}

/// What the node has free for this process's group (MB): `MemAvailable`, or the room under
/// the cgroup's limit where that is less. None where neither can be read.
pub fn node_free_mb() -> Option<f64> {
    let read = |p: &str| std::fs::read_to_string(p).ok();
    let available = read("/proc/meminfo").and_then(|s| mem_available_mb(&s));
    let cgroup = match (read("/sys/fs/cgroup/memory.max"), read("/sys/fs/cgroup/memory.current")) {
        (Some(m), Some(c)) => cgroup_room_mb(&m, &c),
        _ => None,
    };
    match (available, cgroup) {
        (Some(a), Some(c)) => Some(a.min(c)),
        (a, c) => a.or(c),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_prediction_holds_the_measured_levels_and_what_fits_is_what_it_allows() {
        // cases/hard/heavy-3gpa, 2 ranks: level 4 597,932 unknowns at 4,938 MB per rank,
        // level 5 1,081,612 at 8,991 MB. The prediction lies above, within 15 %.
        let m = MemoryLeft { room_mb: 12_000.0, before: 597_932, peak_mb: 4_938.0, exponent: LEVEL_MEMORY_EXPONENT };
        let p = m.predicted(1_081_612);
        assert!(p > 8_991.0 && p < 1.15 * 8_991.0, "predicted {p} MB");
        // table2-ue2 at target 0.001, levels of 501,986 and 738,218 unknowns (4.1, 6.3 GB).
        let t = MemoryLeft { room_mb: 12_000.0, before: 501_986, peak_mb: 4_100.0, exponent: LEVEL_MEMORY_EXPONENT }.predicted(738_218);
        assert!(t > 6_300.0 && t < 1.1 * 6_300.0, "predicted {t} MB");
        // The unknowns that fit are predicted at the fill, and a few more are not.
        let n = m.unknowns();
        assert!(m.predicted(n) <= MEMORY_FILL * m.room_mb * (1.0 + 1e-9));
        assert!(m.predicted(n + 100) > MEMORY_FILL * m.room_mb);
        // 12 GB per rank hold level 5 (the 0.9 of it, 10.8 GB, above the predicted 10.1).
        assert!(n > 1_081_612);
        // 8 GB do not.
        assert!(MemoryLeft { room_mb: 8_000.0, ..m }.unknowns() < 1_081_612);
        // No room: nothing fits; no measure: nothing binds.
        assert_eq!(MemoryLeft { room_mb: 0.0, ..m }.unknowns(), 0);
        assert_eq!(MemoryLeft { room_mb: f64::INFINITY, ..m }.unknowns(), u64::MAX);
        assert_eq!(MemoryLeft { peak_mb: 0.0, ..m }.unknowns(), u64::MAX);
        // After a condensed level the square: twice the unknowns, four times the memory.
        let c = MemoryLeft { exponent: CONDENSED_MEMORY_EXPONENT, ..m };
        assert!((c.predicted(2 * 597_932) / (4.0 * 4_938.0) - 1.0).abs() < 1e-12);
    }

    #[test]
    fn free_memory_is_read_from_meminfo_and_a_cgroup_limit() {
        let meminfo = "MemTotal:       24683656 kB\nMemFree:         1000000 kB\nMemAvailable:   24148796 kB\n";
        assert!((mem_available_mb(meminfo).unwrap() - 24148796.0 / 1024.0).abs() < 1e-9);
        assert_eq!(mem_available_mb("MemTotal: 1 kB\n"), None);
        // 8 GiB limit, 2 GiB used: 6 GiB of room.
        assert_eq!(cgroup_room_mb("8589934592\n", "2147483648\n"), Some(6144.0));
        assert_eq!(cgroup_room_mb("max\n", "2147483648\n"), None);
        // Over the limit (reclaim pending): no room, not a negative one.
        assert_eq!(cgroup_room_mb("1048576", "2097152"), Some(0.0));
    }

    #[test]
    fn this_process_has_a_resident_memory_and_the_node_some_free() {
        let r = crate::output::resident_mb().expect("/proc/self/status");
        assert!(r > 0.0 && r < 1e6, "{r} MB");
        assert!(node_free_mb().is_some_and(|f| f >= 0.0));
    }
}
