//! The PETSc options database: defaults that the user's flags can override.
use super::error::Result;
use crate::pcall;
use std::ffi::CString;

fn cstr(s: &str) -> CString {
    CString::new(s).expect("option string without NUL")
}

/// True when the option was given (command line, PETSC_OPTIONS or set earlier).
pub fn has(name: &str) -> Result<bool> {
    let n = cstr(name);
    let mut set: super::ffi::PetscBool = 0;
    pcall!(super::ffi::PetscOptionsHasName(std::ptr::null_mut(), std::ptr::null(), n.as_ptr(), &mut set))?;
    Ok(set != 0)
}

/// The options our own code set (the rest of the database is the user's).
static OURS: std::sync::Mutex<std::collections::BTreeSet<String>> = std::sync::Mutex::new(std::collections::BTreeSet::new());

fn set_value(name: &str, value: &str) -> Result<()> {
    let (n, v) = (cstr(name), cstr(value));
    pcall!(super::ffi::PetscOptionsSetValue(
        std::ptr::null_mut(),
        n.as_ptr(),
        if value.is_empty() { std::ptr::null() } else { v.as_ptr() }
    ))?;
    OURS.lock().unwrap_or_else(|e| e.into_inner()).insert(name.to_string());
    Ok(())
}

/// Sets `name value` unless `name` is already set (by the user, or by an earlier default):
/// our defaults stay overridable.
pub fn set_default(name: &str, value: &str) -> Result<()> {
    if has(name)? {
        return Ok(());
    }
    set_value(name, value)
}

/// True when the user gave `name` (on the command line or in the options file), not our code.
pub fn user_set(name: &str) -> Result<bool> {
    Ok(has(name)? && !OURS.lock().unwrap_or_else(|e| e.into_inner()).contains(name))
}

/// Sets `name value` unless the user gave `name`; a value our own code set earlier is
/// replaced. For defaults that depend on what is being solved, when one process solves
/// several systems (a convergence study switching from the condensed to the monolithic
/// coupling needs MUMPS where the condensed path had set ScaLAPACK).
pub fn set_ours(name: &str, value: &str) -> Result<()> {
    if user_set(name)? {
        return Ok(());
    }
    set_value(name, value)
}

/// The options in the database that our code did not set, as PETSc lists them
/// (`PetscOptionsGetAll`: `-name value` words): the command line's, and those of
/// `PETSC_OPTIONS` and of options files, which the program's own arguments do not show.
pub fn given() -> Result<Vec<String>> {
    let mut all: *mut std::os::raw::c_char = std::ptr::null_mut();
    pcall!(super::ffi::PetscOptionsGetAll(std::ptr::null_mut(), &mut all))?;
    if all.is_null() {
        return Ok(Vec::new());
    }
    let text = unsafe { std::ffi::CStr::from_ptr(all) }.to_string_lossy().into_owned();
    // PetscFree(all): PetscFreeA takes the address of each pointer it frees and sets it to
    // null (line, function and file are for PETSc's malloc debugging only).
    let (func, file) = (cstr("options::given"), cstr(file!()));
    pcall!(super::ffi::PetscFreeA(1, line!() as i32, func.as_ptr(), file.as_ptr(), (&mut all as *mut *mut std::os::raw::c_char).cast()))?;
    Ok(users_words(&text, &OURS.lock().unwrap_or_else(|e| e.into_inner())))
}

/// The words of PETSc's option listing `text` without the options named in `ours` (with
/// their values).
fn users_words(text: &str, ours: &std::collections::BTreeSet<String>) -> Vec<String> {
    let mut out = Vec::new();
    let mut skip = false;
    for w in text.split_whitespace() {
        let is_name = w.starts_with('-') && w.len() > 1 && !w[1..].starts_with(|c: char| c.is_ascii_digit() || c == '.');
        if is_name {
            skip = ours.contains(w);
        }
        if !skip {
            out.push(w.to_string());
        }
    }
    out
}

/// Reads an option's value as a string, if set.
pub fn get_string(name: &str) -> Result<Option<String>> {
    let n = cstr(name);
    let mut buf = vec![0 as std::os::raw::c_char; 512];
    let mut set: super::ffi::PetscBool = 0;
    pcall!(super::ffi::PetscOptionsGetString(std::ptr::null_mut(), std::ptr::null(), n.as_ptr(), buf.as_mut_ptr(), buf.len(), &mut set))?;
    if set == 0 {
        return Ok(None);
    }
    Ok(Some(unsafe { std::ffi::CStr::from_ptr(buf.as_ptr()) }.to_string_lossy().into_owned()))
}

/// A group of options read with PETSc's `PetscOptionsBegin`/`End`: each query returns the
/// value from the database (marking the option used, so `-options_left` does not list it)
/// and, under `-help`, prints the option with its default and description. Collective on
/// `comm`.
pub struct Group {
    items: Box<super::ffi::PetscOptionItems>,
}

/// A PETSc error of reading option `name`, which takes `allowed`: named, so that the user
/// sees which option and what it takes (PETSc's message has the value given).
fn option_error(name: &str, allowed: &str, e: super::PetscError) -> super::PetscError {
    super::PetscError { code: e.code, message: format!("{name} takes {allowed} ({})", e.message) }
}

impl Group {
    /// Starts a group titled `title` (the heading `-help` prints) in manual section `section`.
    pub fn begin(comm: super::ffi::MPI_Comm, title: &str, section: &str) -> Result<Group> {
        let mut items: Box<super::ffi::PetscOptionItems> = Box::default();
        // PetscOptionsBegin's loop runs once, with count 1, unless a GUI publishes options.
        items.count = 1;
        let (t, s) = (cstr(title), cstr(section));
        pcall!(super::ffi::PetscOptionsBegin_Private(&mut *items, comm, std::ptr::null(), t.as_ptr(), s.as_ptr()))?;
        Ok(Group { items })
    }

    /// A boolean option (`-name`, `-name true|false`).
    pub fn bool(&mut self, name: &str, help: &str, default: bool) -> Result<bool> {
        let (n, h, m) = (cstr(name), cstr(help), cstr("EhlOptions"));
        let mut v: super::ffi::PetscBool = default as super::ffi::PetscBool;
        pcall!(super::ffi::PetscOptionsBool_Private(
            &mut *self.items,
            n.as_ptr(),
            h.as_ptr(),
            m.as_ptr(),
            default as super::ffi::PetscBool,
            &mut v,
            std::ptr::null_mut()
        ))
        .map_err(|e| option_error(name, "true or false", e))?;
        Ok(v != 0)
    }

    /// A real option; None if not given.
    pub fn real(&mut self, name: &str, help: &str, default: f64) -> Result<Option<f64>> {
        let (n, h, m) = (cstr(name), cstr(help), cstr("EhlOptions"));
        let (mut v, mut set) = (default, 0 as super::ffi::PetscBool);
        pcall!(super::ffi::PetscOptionsReal_Private(&mut *self.items, n.as_ptr(), h.as_ptr(), m.as_ptr(), default, &mut v, &mut set))
            .map_err(|e| option_error(name, "a real number", e))?;
        Ok((set != 0).then_some(v))
    }

    /// An integer option; None if not given.
    pub fn int(&mut self, name: &str, help: &str, default: i32) -> Result<Option<i32>> {
        let (n, h, m) = (cstr(name), cstr(help), cstr("EhlOptions"));
        let (mut v, mut set) = (default, 0 as super::ffi::PetscBool);
        pcall!(super::ffi::PetscOptionsInt_Private(
            &mut *self.items,
            n.as_ptr(),
            h.as_ptr(),
            m.as_ptr(),
            default,
            &mut v,
            &mut set,
            i32::MIN,
            i32::MAX
        ))
        .map_err(|e| option_error(name, "an integer", e))?;
        Ok((set != 0).then_some(v))
    }

    /// A string option; None if not given.
    pub fn string(&mut self, name: &str, help: &str, default: &str) -> Result<Option<String>> {
        let (n, h, m, d) = (cstr(name), cstr(help), cstr("EhlOptions"), cstr(default));
        let mut buf = vec![0 as std::os::raw::c_char; 4096];
        let mut set: super::ffi::PetscBool = 0;
        pcall!(super::ffi::PetscOptionsString_Private(
            &mut *self.items,
            n.as_ptr(),
            h.as_ptr(),
            m.as_ptr(),
            d.as_ptr(),
            buf.as_mut_ptr(),
            buf.len(),
            &mut set
        ))
        .map_err(|e| option_error(name, "a string of at most 4095 bytes", e))?;
        Ok((set != 0).then(|| unsafe { std::ffi::CStr::from_ptr(buf.as_ptr()) }.to_string_lossy().into_owned()))
    }

    /// Ends the group.
    pub fn end(mut self) -> Result<()> {
        pcall!(super::ffi::PetscOptionsEnd_Private(&mut *self.items))?;
        Ok(())
    }
}

/// The options of the database that nobody queried (`-options_left` style), without those
/// our own code set as defaults: the user's misspelt or irrelevant options. Names with
/// their leading dash, values if any.
pub fn unused() -> Result<Vec<(String, Option<String>)>> {
    let mut n: super::ffi::PetscInt = 0;
    let mut names: *mut *mut std::os::raw::c_char = std::ptr::null_mut();
    let mut values: *mut *mut std::os::raw::c_char = std::ptr::null_mut();
    pcall!(super::ffi::PetscOptionsLeftGet(std::ptr::null_mut(), &mut n, &mut names, &mut values))?;
    let text = |p: *mut std::os::raw::c_char| (!p.is_null()).then(|| unsafe { std::ffi::CStr::from_ptr(p) }.to_string_lossy().into_owned());
    let ours = OURS.lock().unwrap_or_else(|e| e.into_inner()).clone();
    let mut out = Vec::new();
    for k in 0..n.max(0) as usize {
        // SAFETY: PETSc returned arrays of n entries (names non-null, values may be null).
        let (name, value) = unsafe { (text(*names.add(k)), if values.is_null() { None } else { text(*values.add(k)) }) };
        let Some(name) = name else { continue };
        let name = format!("-{}", name.trim_start_matches('-'));
        if !ours.contains(&name) {
            out.push((name, value));
        }
    }
    pcall!(super::ffi::PetscOptionsLeftRestore(std::ptr::null_mut(), &mut n, &mut names, &mut values))?;
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_users_options_are_the_listing_without_ours() {
        let ours: std::collections::BTreeSet<String> = ["-pc_type".to_string(), "-ksp_rtol".to_string()].into();
        let text = "-ksp_rtol 1e-9 -pc_type lu -snes_max_it abc -ehl_shift -1.5 -snes_monitor -pc_factor_shift_amount -.5";
        assert_eq!(
            users_words(text, &ours),
            ["-snes_max_it", "abc", "-ehl_shift", "-1.5", "-snes_monitor", "-pc_factor_shift_amount", "-.5"]
        );
    }
}
