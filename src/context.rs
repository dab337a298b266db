//! The state one run shares on one rank (communicator, rank, output folder, log) and the
//! writes every part of the program makes through it. Below `app` so that the solver's
//! modules can log and agree without depending on the program.
use crate::collective;
use crate::error::{Error, IoAction};
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
    pub fn write_summary(&self, summary: &serde_json::Value) -> Result<(), Error> {
        self.write_summary_to(&self.out_dir.clone(), summary)
    }

    /// Writes the results of one solve through a staging folder: `write` fills the staging
    /// folder (rank 0 writes, the other ranks take part in its collective steps), then every
    /// rank checks for an interruption together, and only then rank 0 moves the files into
    /// the output folder. A failure or a signal before that leaves no result file.
    /// Collective.
    pub fn write_results<T>(&self, write: impl FnOnce(&std::path::Path) -> Result<T, Error>) -> Result<T, Error> {
        let staging = self.out_dir.join(format!(".partial-{}", std::process::id()));
        self.create_dir(&staging)?;
        let written = collective::agree(&self.world, write(&staging));
        let result = written.and_then(|v| crate::interrupt::check("the post-processing (friction pass, output files)").map(|()| v));
        let published = if self.rank == 0 {
            match &result {
                Ok(_) => crate::output::publish(&staging, &self.out_dir),
                Err(_) => {
                    let _ = std::fs::remove_dir_all(&staging);
                    Ok(())
                }
            }
        } else {
            Ok(())
        };
        let published = collective::agree(&self.world, published);
        if result.is_ok() && published.is_ok() {
            self.log(format!("results moved into {}", self.out_dir.display()));
        }
        result.and_then(|v| published.map(|()| v))
    }

    /// Creates the output subfolder `dir` (rank 0; the outcome is shared). Collective.
    pub fn create_dir(&self, dir: &std::path::Path) -> Result<(), Error> {
        let made = if self.rank == 0 { std::fs::create_dir_all(dir).map_err(Error::io(IoAction::Create, dir)) } else { Ok(()) };
        collective::agree(&self.world, made)
    }

    /// Reads the summary.json that a post-processing step wrote into `dir`, lets `change`
    /// add to it, and writes it again (rank 0; the other ranks do nothing).
    pub fn amend_summary(&self, dir: &std::path::Path, change: impl FnOnce(&mut serde_json::Value)) -> Result<(), Error> {
        if self.rank != 0 {
            return Ok(());
        }
        let path = dir.join("summary.json");
        let text = std::fs::read_to_string(&path).map_err(Error::reading(&path))?;
        let mut summary: serde_json::Value = serde_json::from_str(&text).map_err(|e| Error::format(format!("{}: {e}", path.display())))?;
        change(&mut summary);
        self.write_summary_to(dir, &summary)
    }

    /// Writes summary.json into `dir` (atomically; see [`Context::write_summary`]).
    pub fn write_summary_to(&self, dir: &std::path::Path, summary: &serde_json::Value) -> Result<(), Error> {
        let path = dir.join("summary.json");
        // serde_json writes a NaN or an infinity as null: a result with such a number is
        // never written, let alone marked converged.
        let bad = crate::output::summary::null_paths(summary);
        if !bad.is_empty() {
            return Err(Error::numerical(format!("the result holds numbers that are not finite ({}); no result written", bad.join(", "))));
        }
        let text = serde_json::to_string_pretty(summary).map_err(|e| Error::other(e.to_string()))?;
        crate::output::write_atomic(&path, text.as_bytes()).map_err(Error::writing(&path))?;
        self.log(format!("wrote {}", path.display()));
        Ok(())
    }
}
