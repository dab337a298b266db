//! SIGINT and SIGTERM: a run stops on every rank at the next check, with a clear message,
//! and writes no result of the interrupted solve.
//!
//! The signal handler only stores the signal number (async-signal-safe). The run checks
//! it at points every rank reaches together (after the mesh; on the dry path after the
//! assembly and the elastic solve; after the elastic condensation; at each Newton residual
//! evaluation; after Newton; before each sweep point and study level; and after the
//! friction pass and the output files, before they are moved into place) through an MPI
//! reduction, so a signal that reaches one rank only (a batch system killing one task)
//! stops all of them at the same point instead of leaving the others waiting in a
//! collective call. Results are written only after a converged solve, each file through a
//! temporary name and a rename ([`crate::output::write_atomic`]), and a single solve's
//! files through a staging folder ([`crate::app::Context::write_results`]): an interrupted
//! run leaves the files of earlier runs (or of the sweep points it completed) and nothing
//! of its own.
//!
//! Installed after `PetscInitialize`, so it replaces PETSc's own handler for these two
//! signals (which would abort without cleaning up). Exit code 128 + signal number.
use crate::error::Error;
use std::sync::atomic::{AtomicI32, Ordering};

/// The signal this process received (0: none).
static LOCAL: AtomicI32 = AtomicI32::new(0);
/// The signal every rank agreed on at the last collective check (0: none).
static AGREED: AtomicI32 = AtomicI32::new(0);

extern "C" fn on_signal(sig: libc::c_int) {
    LOCAL.store(sig, Ordering::SeqCst);
}

/// Installs the handler for SIGINT and SIGTERM.
pub fn install() {
    for sig in [libc::SIGINT, libc::SIGTERM] {
        // SAFETY: a zeroed sigaction with a plain handler is valid; the handler only does an
        // atomic store.
        unsafe {
            let mut act: libc::sigaction = std::mem::zeroed();
            act.sa_sigaction = on_signal as extern "C" fn(libc::c_int) as usize;
            act.sa_flags = libc::SA_RESTART;
            libc::sigemptyset(&mut act.sa_mask);
            libc::sigaction(sig, &act, std::ptr::null_mut());
        }
    }
}

/// The agreed "signal" of a spent time budget ([`set_deadline`]). SIGHUP's number: it is not
/// handled here, and any real signal (SIGINT 2, SIGTERM 15) outranks it in the reduction.
pub const DEADLINE: i32 = 1;

/// The time budget's end (None: no budget).
static END: std::sync::Mutex<Option<std::time::Instant>> = std::sync::Mutex::new(None);

/// Sets (or clears) the time budget: from `end` on, every collective check stops the run
/// as a signal would, with [`DEADLINE`] agreed. The caller decides what a spent budget
/// means (the adaptive loop writes its last converged level).
pub fn set_deadline(end: Option<std::time::Instant>) {
    *END.lock().unwrap_or_else(|e| e.into_inner()) = end;
}

/// Forgets a spent budget once its caller has handled it (the budget itself is cleared
/// too), so that the checks of what follows (writing the result) pass.
pub fn clear_deadline() {
    set_deadline(None);
    let _ = AGREED.compare_exchange(DEADLINE, 0, Ordering::SeqCst, Ordering::SeqCst);
}

fn deadline_passed() -> bool {
    END.lock().unwrap_or_else(|e| e.into_inner()).is_some_and(|end| std::time::Instant::now() >= end)
}

/// Name of a signal for messages.
pub fn signal_name(sig: i32) -> String {
    match sig {
        DEADLINE => "the time budget accuracy.max_seconds".into(),
        libc::SIGINT => "SIGINT".into(),
        libc::SIGTERM => "SIGTERM".into(),
        s => format!("signal {s}"),
    }
}

/// The message of an interrupted run.
pub fn message(sig: i32, during: &str) -> String {
    format!("interrupted by {} during {during}; stopped on every rank, no result of this solve was written", signal_name(sig))
}

/// Collective over MPI_COMM_WORLD (PETSc's world communicator): the largest signal number any rank received (0 if
/// none). Every rank must call it at the same point.
pub fn collective_signal() -> i32 {
    let mut local = LOCAL.load(Ordering::SeqCst);
    if local == 0 && deadline_passed() {
        local = DEADLINE;
    }
    let mut all: i32 = 0;
    // SAFETY: plain MPI reduction of one int over the world communicator, which PETSc and
    // every rank share; called collectively.
    unsafe {
        mpi::ffi::MPI_Allreduce(
            &local as *const i32 as *const std::ffi::c_void,
            &mut all as *mut i32 as *mut std::ffi::c_void,
            1,
            mpi::ffi::RSMPI_INT32_T,
            mpi::ffi::RSMPI_MAX,
            mpi::ffi::RSMPI_COMM_WORLD,
        );
    }
    if all != 0 {
        AGREED.store(all, Ordering::SeqCst);
    }
    all
}

/// Collective check: [`Error::Interrupted`] with a clear message when any rank received a
/// signal.
pub fn check(during: &str) -> Result<(), Error> {
    match collective_signal() {
        0 => Ok(()),
        signal => Err(Error::Interrupted { signal, message: message(signal, during) }),
    }
}

/// The signal agreed at a collective check (0: none); local, no communication. Used to
/// stop retries and fall-backs after an interruption and to choose the exit code.
pub fn agreed() -> i32 {
    AGREED.load(Ordering::SeqCst)
}
