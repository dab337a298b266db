//! PETSc error codes as Rust errors carrying PETSc's own message.
use super::ffi;
use std::cell::RefCell;
use std::ffi::CStr;
use std::os::raw::{c_char, c_int, c_void};

pub use crate::error::PetscError;

pub type Result<T> = std::result::Result<T, PetscError>;

thread_local! {
    static TRACE: RefCell<Vec<String>> = const { RefCell::new(Vec::new()) };
}

/// PETSc error handler that records the message instead of printing a traceback,
/// so the error reaches the caller as a Rust value.
pub(crate) unsafe extern "C" fn record_error(
    _comm: ffi::MPI_Comm,
    line: c_int,
    func: *const c_char,
    file: *const c_char,
    code: ffi::PetscErrorCode,
    _kind: ffi::PetscErrorType,
    mess: *const c_char,
    _ctx: *mut c_void,
) -> ffi::PetscErrorCode {
    let s = |p: *const c_char| if p.is_null() { String::new() } else { CStr::from_ptr(p).to_string_lossy().into_owned() };
    let mut text = s(mess);
    if text.trim().is_empty() {
        let mut generic: *const c_char = std::ptr::null();
        if ffi::PetscErrorMessage(code, &mut generic, std::ptr::null_mut()) == 0 && !generic.is_null() {
            text = s(generic);
        }
    }
    let entry = format!("{} ({}:{}): {}", s(func), s(file), line, text.trim());
    TRACE.with(|t| {
        let mut t = t.borrow_mut();
        if t.len() < 32 {
            t.push(entry)
        }
    });
    code
}

/// Converts a PETSc return code into a `Result`, attaching the recorded messages.
pub fn check(code: ffi::PetscErrorCode) -> Result<()> {
    if code == 0 {
        TRACE.with(|t| t.borrow_mut().clear());
        return Ok(());
    }
    let trace = TRACE.with(|t| std::mem::take(&mut *t.borrow_mut()));
    let message = if trace.is_empty() { generic_message(code) } else { trace.join("; ") };
    Err(PetscError { code, message })
}

fn generic_message(code: ffi::PetscErrorCode) -> String {
    let mut text: *const c_char = std::ptr::null();
    unsafe {
        if ffi::PetscErrorMessage(code, &mut text, std::ptr::null_mut()) == 0 && !text.is_null() {
            return CStr::from_ptr(text).to_string_lossy().into_owned();
        }
    }
    "unknown PETSc error".into()
}

/// An error raised by the Rust layer (not by PETSc).
pub fn rust_error(message: impl Into<String>) -> PetscError {
    PetscError { code: 0, message: message.into() }
}

/// Calls a PETSc function and converts its return code. The unsafe block is the point of
/// the macro: every argument is an FFI call into PETSc, whose safety its caller argues.
/// (Hence the crate-level allow of clippy's `macro_metavars_in_unsafe` in `lib.rs`.)
#[macro_export]
macro_rules! pcall {
    ($e:expr) => {
        $crate::petsc::error::check(unsafe { $e })
    };
}
