//! The state one run shares on one rank (communicator, rank, output folder, log) and the
//! writes every part of the program makes through it. Below `app` so that the solver's
//! modules can log and agree without depending on the program.
use crate::collective;
use mpi::topology::SimpleCommunicator;
use std::path::PathBuf;
use std::time::Instant;

/// Shared state of one run on one rank.
pub struct Context {
    pub world: SimpleCommunicator,
    pub rank: usize,
    pub size: usize,
    pub out_dir: PathBuf,
    pub quiet: bool,
    pub start: Instant,
}

impl Context {
    /// Prints a progress line on rank 0 (stdout), with the elapsed time.
    pub fn log(&self, msg: impl AsRef<str>) {
        if self.rank == 0 && !self.quiet {
            println!("[{:7.2} s] {}", self.start.elapsed().as_secs_f64(), msg.as_ref());
        }
    }
}

impl Context {
    /// Writes summary.json into the output folder (rank 0 calls it, once, after success;
    /// atomically, so a failed run leaves no summary behind).
    pub fn write_summary(&self, summary: &serde_json::Value) -> Result<(), String> {
        self.write_summary_to(&self.out_dir.clone(), summary)
    }

    /// Creates the output subfolder `dir` (rank 0; the outcome is shared). Collective.
    pub fn create_dir(&self, dir: &std::path::Path) -> Result<(), String> {
        let made = if self.rank == 0 { std::fs::create_dir_all(dir).map_err(|e| format!("cannot create {}: {e}", dir.display())) } else { Ok(()) };
        collective::agree(&self.world, made)
    }

    /// Writes summary.json into `dir` (atomically; see [`Context::write_summary`]).
    pub fn write_summary_to(&self, dir: &std::path::Path, summary: &serde_json::Value) -> Result<(), String> {
        let path = dir.join("summary.json");
        let text = serde_json::to_string_pretty(summary).map_err(|e| e.to_string())?;
        crate::output::write_atomic(&path, text.as_bytes()).map_err(|e| format!("cannot write {}: {e}", path.display()))?;
        self.log(format!("wrote {}", path.display()));
        Ok(())
    }
}
