//! Result files: summary.json (written once, atomically, only after success), CSV tables,
//! VTU fields for ParaView and PNG plots.
pub mod csv;
pub mod plot;
pub mod summary;
pub mod vtu;

use crate::error::{Error, IoAction};
use std::io::Write;
use std::path::{Path, PathBuf};

/// The temporary name a file is written under before its final rename (same folder).
fn temporary_path(path: &Path) -> std::path::PathBuf {
    let dir = path.parent().unwrap_or(Path::new("."));
    let name = path.file_name().and_then(|n| n.to_str()).unwrap_or("out");
    dir.join(format!(".{name}.tmp-{}", std::process::id()))
}

/// Writes `bytes` to `path` through a temporary file in the same folder and a rename, so a
/// reader never sees a half-written file and a failed run leaves no file behind.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> std::io::Result<()> {
    let tmp = temporary_path(path);
    let result = (|| {
        let mut f = std::fs::File::create(&tmp)?;
        f.write_all(bytes)?;
        f.sync_all()?;
        std::fs::rename(&tmp, path)
    })();
    if result.is_err() {
        let _ = std::fs::remove_file(&tmp);
    }
    result
}

/// As [`write_atomic`] for writers that take a path (plots, VTU): `write` fills the
/// temporary file, which is then renamed to `path`, or removed on failure.
pub fn write_atomic_with(path: &Path, write: impl FnOnce(&Path) -> Result<(), Error>) -> Result<(), Error> {
    let tmp = temporary_path(path);
    let result = write(&tmp).and_then(|()| std::fs::rename(&tmp, path).map_err(Error::writing(path)));
    if result.is_err() {
        let _ = std::fs::remove_file(&tmp);
    }
    result
}

/// Name of the lock file a run keeps in its output folder while it runs.
pub const LOCK_FILE: &str = ".ehl-petsc.lock";

/// An output folder claimed by this run: created if needed, locked against other runs.
#[derive(Debug)]
pub struct OutputClaim {
    dir: PathBuf,
    /// The outermost folder this run created (None: the folder existed).
    created: Option<PathBuf>,
    lock: PathBuf,
}

fn host_name() -> String {
    let mut buf = [0u8; 256];
    // SAFETY: gethostname writes at most buf.len() bytes into buf.
    if unsafe { libc::gethostname(buf.as_mut_ptr() as *mut libc::c_char, buf.len()) } != 0 {
        return "?".into();
    }
    let end = buf.iter().position(|&b| b == 0).unwrap_or(buf.len());
    String::from_utf8_lossy(&buf[..end]).into_owned()
}

/// Claims `dir` for this run (rank 0, before any solve): creates it (and its missing
/// parents) and writes the lock file [`LOCK_FILE`] with this process's id and host, which
/// doubles as the test that the folder is writable. A folder whose lock names a live
/// process (on this host) or another host is in use: refused. A lock left by a process
/// that no longer exists (killed) is taken over.
pub fn claim_output_dir(dir: &Path) -> Result<OutputClaim, Error> {
    let mut created = None;
    let mut a = Some(dir);
    while let Some(p) = a.filter(|p| !p.as_os_str().is_empty() && !p.exists()) {
        created = Some(p.to_path_buf());
        a = p.parent();
    }
    std::fs::create_dir_all(dir).map_err(Error::io(IoAction::CreateOutputFolder, dir))?;
    let claim = OutputClaim { dir: dir.to_path_buf(), created, lock: dir.join(LOCK_FILE) };
    let me = format!("{} {}\n", std::process::id(), host_name());
    for attempt in 0..2 {
        match std::fs::OpenOptions::new().write(true).create_new(true).open(&claim.lock) {
            Ok(mut f) => {
                if let Err(e) = f.write_all(me.as_bytes()).and_then(|()| f.sync_all()) {
                    drop(f);
                    claim.release(false);
                    return Err(Error::io(IoAction::OutputFolderNotWritable, dir)(e));
                }
                return Ok(claim);
            }
            Err(e) if e.kind() == std::io::ErrorKind::AlreadyExists && attempt == 0 => {
                let text = std::fs::read_to_string(&claim.lock).unwrap_or_default();
                let mut w = text.split_whitespace();
                let (pid, host) = (w.next().and_then(|p| p.parse::<u32>().ok()), w.next().unwrap_or(""));
                let alive = match pid {
                    Some(pid) if host == host_name() => Path::new(&format!("/proc/{pid}")).exists(),
                    // Another host (a shared file system): cannot tell, so it is in use.
                    Some(_) => true,
                    None => false,
                };
                if alive {
                    return Err(Error::invalid(format!(
                        "output folder '{}' is in use by another run (process {} on host {host}; lock file {}); choose another folder with --output, or remove the lock file if no run uses the folder",
                        dir.display(),
                        pid.map_or("?".into(), |p| p.to_string()),
                        claim.lock.display()
                    )));
                }
                // A stale lock (its process has ended, e.g. SIGKILLed by mpirun's
                // teardown): take it over, with what that process left half-done.
                if let Some(pid) = pid {
                    remove_leftovers(dir, pid);
                }
                let _ = std::fs::remove_file(&claim.lock);
            }
            Err(e) => {
                claim.release(false);
                return Err(Error::io(IoAction::OutputFolderNotWritable, dir)(e));
            }
        }
    }
    Err(Error::invalid(format!("output folder '{}': cannot take its lock file {}", dir.display(), claim.lock.display())))
}

/// Removes what a killed run with process id `pid` left in `dir`: its staging folder
/// (`.partial-PID`, results not yet published) and its temporary files (`.NAME.tmp-PID`).
/// Nothing of another process is touched.
fn remove_leftovers(dir: &Path, pid: u32) {
    let _ = std::fs::remove_dir_all(dir.join(format!(".partial-{pid}")));
    let suffix = format!(".tmp-{pid}");
    for e in std::fs::read_dir(dir).into_iter().flatten().flatten() {
        let name = e.file_name().to_string_lossy().into_owned();
        if name.starts_with('.') && name.ends_with(&suffix) {
            let _ = std::fs::remove_file(e.path());
        }
    }
}

impl OutputClaim {
    /// The claimed folder.
    pub fn dir(&self) -> &Path {
        &self.dir
    }

    /// Removes the lock; after a failed run also the folders this run created, when they
    /// hold nothing (a failed run leaves nothing it created).
    pub fn release(&self, success: bool) {
        let _ = std::fs::remove_file(&self.lock);
        if success {
            return;
        }
        if let Some(top) = &self.created {
            let mut d = Some(self.dir.as_path());
            while let Some(p) = d {
                if std::fs::remove_dir(p).is_err() || p == top.as_path() {
                    break;
                }
                d = p.parent();
            }
        }
    }
}

/// Moves every file of `staging` into `dir` (an old summary.json removed first, the new
/// one moved last, so that a summary always describes the files next to it) and removes
/// `staging`.
pub fn publish(staging: &Path, dir: &Path) -> Result<(), Error> {
    let err = |e| Error::io(IoAction::MoveResults { to: dir.to_path_buf() }, staging)(e);
    let mut names: Vec<std::ffi::OsString> =
        std::fs::read_dir(staging).map_err(err)?.filter_map(|e| e.ok()).map(|e| e.file_name()).collect();
    names.sort_by_key(|n| n == "summary.json");
    let _ = std::fs::remove_file(dir.join("summary.json"));
    for n in names {
        std::fs::rename(staging.join(&n), dir.join(&n)).map_err(err)?;
    }
    std::fs::remove_dir(staging).map_err(err)
}

/// The process's peak before the last [`restart_peak`] (kB): the kernel's mark that
/// getrusage reads starts again there.
static EARLIER_PEAK_KB: std::sync::atomic::AtomicI64 = std::sync::atomic::AtomicI64::new(0);

/// Peak resident memory of this process in MiB (getrusage ru_maxrss, and the peaks before
/// any [`restart_peak`]).
pub fn peak_rss_mb() -> f64 {
    match max_rss_kb() {
        Some(kb) => kb.max(EARLIER_PEAK_KB.load(std::sync::atomic::Ordering::Relaxed)) as f64 / 1024.0,
        None => f64::NAN,
    }
}

/// getrusage's ru_maxrss of this process (kB): the kernel's high-water mark.
fn max_rss_kb() -> Option<i64> {
    let mut usage: libc::rusage = unsafe { std::mem::zeroed() };
    (unsafe { libc::getrusage(libc::RUSAGE_SELF, &mut usage) } == 0).then_some(usage.ru_maxrss)
}

/// Starts a new peak (Linux 4.0 and later: "5" to /proc/self/clear_refs resets the
/// high-water mark of the resident memory, and nothing else), so that [`peak_since_mb`]
/// gives the peak of what follows; [`peak_rss_mb`] keeps the process's. Without it the
/// peak since is the process's.
///
/// glibc's heap keeps the pages of small blocks freed between blocks still in use (MUMPS's
/// block low-rank LU frees thousands of them with each factorisation) and counts them in
/// the resident memory; the next level may reuse them or not, so its peak varied by up to
/// a third from run to run on the same values (docs/performance.md, "Memory and time of the
/// largest runs"). They are given back to the kernel first (`malloc_trim`).
pub fn restart_peak() {
    // SAFETY: malloc_trim only returns free pages of glibc's arenas to the kernel.
    unsafe { libc::malloc_trim(0) };
    if let Some(kb) = max_rss_kb() {
        EARLIER_PEAK_KB.fetch_max(kb, std::sync::atomic::Ordering::Relaxed);
        let _ = std::fs::write("/proc/self/clear_refs", "5");
    }
}

/// Peak resident memory since the last [`restart_peak`] (MiB; `VmHWM` of /proc/self/status),
/// or the process's where that cannot be read.
pub fn peak_since_mb() -> f64 {
    status_kb("VmHWM:").map_or_else(peak_rss_mb, |kb| kb / 1024.0)
}

/// This process's present resident memory (MiB; `VmRSS` of /proc/self/status).
pub fn resident_mb() -> Option<f64> {
    status_kb("VmRSS:").map(|kb| kb / 1024.0)
}

/// A `field` of /proc/self/status given in kB.
fn status_kb(field: &str) -> Option<f64> {
    let s = std::fs::read_to_string("/proc/self/status").ok()?;
    s.lines().find(|l| l.starts_with(field))?.split_whitespace().nth(1)?.parse().ok()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_restarted_peak_counts_what_follows_and_the_process_keeps_its_own() {
        // 64 MB touched and freed before the restart raise the process's peak, not the new one.
        let before = {
            let v = vec![1u8; 64 << 20];
            std::hint::black_box(&v);
            peak_rss_mb()
        };
        restart_peak();
        let since = peak_since_mb();
        assert!(peak_rss_mb() >= before, "{} < {before}", peak_rss_mb());
        assert!(since <= peak_rss_mb(), "{since} > {}", peak_rss_mb());
        // 32 MB touched after it are in the new peak.
        let v = vec![1u8; 32 << 20];
        std::hint::black_box(&v);
        assert!(peak_since_mb() >= since, "{} < {since}", peak_since_mb());
        assert!(peak_since_mb() > 30.0, "{}", peak_since_mb());
    }

    #[test]
    fn a_restarted_peak_starts_from_the_memory_in_use_not_what_the_heap_kept() {
        // 48 MB in blocks of 8 kB (below glibc's mmap threshold: on its heap), all freed but
        // the last, which keeps the heap from shrinking at its top by itself.
        let mut blocks: Vec<Vec<u8>> = (0..6144).map(|_| vec![1u8; 8 << 10]).collect();
        let last = blocks.pop();
        std::hint::black_box(&blocks);
        drop(blocks);
        let kept = resident_mb().unwrap();
        restart_peak();
        let given_back = kept - resident_mb().unwrap();
        std::hint::black_box(&last);
        assert!(given_back > 24.0, "{given_back} MB of 48 MB freed given back");
    }

    #[test]
    fn a_stale_lock_is_taken_over_with_the_dead_runs_leftovers_and_nothing_else() {
        let dir = std::env::temp_dir().join(format!("ehl-claim-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(dir.join(".partial-999999999")).unwrap();
        std::fs::write(dir.join(".partial-999999999/film_map.png"), b"x").unwrap();
        std::fs::write(dir.join(".summary.json.tmp-999999999"), b"{").unwrap();
        std::fs::write(dir.join(".summary.json.tmp-1"), b"{").unwrap();
        std::fs::write(dir.join("summary.json"), b"{}").unwrap();
        // Process 999999999 is above Linux's largest pid (2^22): it does not exist.
        std::fs::write(dir.join(LOCK_FILE), format!("999999999 {}\n", host_name())).unwrap();
        let claim = claim_output_dir(&dir).unwrap();
        let mut left: Vec<String> =
            std::fs::read_dir(&dir).unwrap().map(|e| e.unwrap().file_name().to_string_lossy().into_owned()).collect();
        left.sort();
        assert_eq!(left, [".ehl-petsc.lock", ".summary.json.tmp-1", "summary.json"]);
        claim.release(true);
        assert!(!dir.join(LOCK_FILE).exists());
        let _ = std::fs::remove_dir_all(&dir);
    }
}
