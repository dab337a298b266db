//! PETSc start and finish on rsmpi's world communicator.
use super::error::{check, record_error, Result};
use super::ffi;
use std::ffi::{CStr, CString};
use std::os::raw::c_char;

/// An initialised PETSc. Create it after `mpi::initialize()` and drop it before the rsmpi
/// `Universe` (PetscFinalize must run before MPI_Finalize). All PETSc objects must be
/// dropped before it.
pub struct Petsc {
    _args: Vec<CString>,
    _argv: Vec<*mut c_char>,
}

impl Petsc {
    /// Initialises PETSc with the given command-line arguments (program name first, then
    /// PETSc options such as `-ksp_view`). `PETSC_OPTIONS` from the environment also applies.
    pub fn init(args: &[String]) -> Result<Petsc> {
        let args: Vec<CString> = args.iter().map(|a| CString::new(a.as_str()).unwrap_or_else(|_| CString::new("?").unwrap())).collect();
        let mut argv: Vec<*mut c_char> = args.iter().map(|a| a.as_ptr() as *mut c_char).collect();
        argv.push(std::ptr::null_mut());
        let mut argc = args.len() as i32;
        let mut argv_ptr = argv.as_mut_ptr();
        check(unsafe { ffi::PetscInitialize(&mut argc, &mut argv_ptr, std::ptr::null(), std::ptr::null()) })?;
        check(unsafe { ffi::PetscPushErrorHandler(Some(record_error), std::ptr::null_mut()) })?;
        Ok(Petsc { _args: args, _argv: argv })
    }

    /// PETSc's version string.
    pub fn version(&self) -> String {
        let mut buf = [0 as c_char; 256];
        unsafe {
            ffi::PetscGetVersion(buf.as_mut_ptr(), buf.len());
            CStr::from_ptr(buf.as_ptr()).to_string_lossy().into_owned()
        }
    }
}

impl Drop for Petsc {
    fn drop(&mut self) {
        unsafe {
            ffi::PetscPopErrorHandler();
            ffi::PetscFinalize();
        }
    }
}

/// PETSc's world communicator (rsmpi's MPI_COMM_WORLD unless changed before init).
pub fn comm_world() -> ffi::MPI_Comm {
    unsafe { ffi::PETSC_COMM_WORLD }
}
