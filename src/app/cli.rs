//! The command line before clap sees it: our double-dash options wherever they stand,
//! PETSc's single-dash options (with their values) and everything after `--`.
//!
//! Rules (docs/robustness.md):
//! - a word starting with `--` is one of our options (`--output DIR`, `--output=DIR`,
//!   `--check`, ...); an unknown one is an error naming it, with the closest known option;
//! - a word starting with a single `-` followed by a letter is a PETSc option; the word
//!   after it is its value unless it is itself an option (`-ksp_type cg`, `-ksp_rtol 1e-9`,
//!   `-mat_mumps_cntl_1 -1`: a dash followed by a digit or a dot is a value);
//! - everything after a bare `--` goes to PETSc unchanged;
//! - exactly one other word, the scene file; a second one is an error naming it.
use crate::error::Error;

/// Our options that take a value, and those that do not.
const WITH_VALUE: &[&str] = &["--output", "--set", "--start-from", "--convergence-study", "--ladder", "--first-size"];
const FLAGS: &[&str] = &["--check", "--quiet", "--sequence", "--scene-reference", "--help", "--version"];

/// The command line split into our arguments (for clap, without the program name) and
/// PETSc's.
#[derive(Debug, Default, PartialEq)]
pub struct Split {
    pub ours: Vec<String>,
    pub petsc: Vec<String>,
}

/// Whether `w` is a PETSc option name (`-name`, not a negative number).
fn is_petsc_option(w: &str) -> bool {
    let mut c = w.chars();
    c.next() == Some('-') && c.next().is_some_and(|c| c.is_ascii_alphabetic() || c == '_')
}

/// Splits the arguments (without the program name). Errors name the offending word.
pub fn split(args: &[String]) -> Result<Split, Error> {
    let mut out = Split::default();
    let mut scene: Option<&str> = None;
    let mut i = 0;
    while i < args.len() {
        let w = args[i].as_str();
        if w == "--" {
            out.petsc.extend(args[i + 1..].iter().cloned());
            break;
        }
        if let Some(body) = w.strip_prefix("--") {
            let name = format!("--{}", body.split('=').next().unwrap_or(""));
            if FLAGS.contains(&name.as_str()) {
                if body.contains('=') {
                    return Err(Error::invalid(format!("option '{name}' takes no value (found '{w}')")));
                }
                out.ours.push(w.to_string());
            } else if WITH_VALUE.contains(&name.as_str()) {
                out.ours.push(w.to_string());
                if !body.contains('=') {
                    let v = args.get(i + 1).ok_or_else(|| Error::invalid(format!("option '{name}' needs a value")))?;
                    if v.starts_with("--") {
                        return Err(Error::invalid(format!("option '{name}' needs a value (found the option '{v}'; write {name}=VALUE for a value that starts with two dashes)")));
                    }
                    out.ours.push(v.clone());
                    i += 1;
                }
            } else {
                let hint = crate::case::spec::closest(&name, WITH_VALUE.iter().chain(FLAGS).copied())
                    .map(|c| format!(" (did you mean '{c}'?)"))
                    .unwrap_or_default();
                return Err(Error::invalid(format!(
                    "unknown option '{name}'{hint}; PETSc options take a single dash (e.g. -ksp_view) or follow '--'"
                )));
            }
        } else if is_petsc_option(w) {
            out.petsc.push(w.to_string());
            if let Some(v) = args.get(i + 1).filter(|v| !v.starts_with("--") && !is_petsc_option(v)) {
                if v.ends_with(".toml") && w != "-options_file" {
                    // A scene file, not a PETSc value: the first one is the scene.
                    if let Some(first) = scene {
                        return Err(Error::invalid(format!(
                            "unexpected argument '{v}' after the PETSc option '{w}': the scene file is already '{first}' (one scene per run)"
                        )));
                    }
                } else {
                    out.petsc.push(v.clone());
                    i += 1;
                }
            }
        } else if w == "-" || w.starts_with('-') {
            return Err(Error::invalid(format!("'{w}' is neither an option of ehl-petsc nor a PETSc option")));
        } else if let Some(first) = scene {
            return Err(Error::invalid(format!(
                "unexpected argument '{w}': the scene file is already '{first}' (one scene per run; PETSc options take a single dash)"
            )));
        } else {
            scene = Some(w);
            out.ours.push(w.to_string());
        }
        i += 1;
    }
    Ok(out)
}

/// Checks what PETSc would otherwise fail on inside `PetscInitialize`, where a failure on
/// one rank leaves the others waiting: the files of `-options_file` and
/// `-options_file_yaml` must be readable regular files.
pub fn check_petsc_args(petsc: &[String]) -> Result<(), Error> {
    for (k, w) in petsc.iter().enumerate() {
        if w == "-options_file" || w == "-options_file_yaml" {
            let Some(f) = petsc.get(k + 1).filter(|v| !is_petsc_option(v)) else {
                return Err(Error::invalid(format!("PETSc option '{w}' needs a file name")));
            };
            match std::fs::metadata(f) {
                Ok(m) if m.is_file() => {}
                Ok(_) => return Err(Error::invalid(format!("PETSc option '{w} {f}': not a regular file"))),
                Err(e) => return Err(Error::invalid(format!("PETSc option '{w} {f}': {e}"))),
            }
        }
    }
    Ok(())
}

/// The user's PETSc options (`-name value` in `petsc`) whose value PETSc's error message
/// `error` quotes as one it could not take: "Input string abc has no numeric value",
/// "Unknown logical value: maybe", "Unable to find requested SNES type foo". PETSc reads
/// an option only when the object it belongs to is set up, often minutes into a run, and
/// its message does not name the option: this names it.
pub fn options_quoted(petsc: &[String], error: &str) -> Vec<String> {
    // The word after `marker`, without the ';' that joins PETSc's messages.
    let after = |marker: &str| -> Vec<&str> {
        error
            .match_indices(marker)
            .filter_map(|(i, _)| error[i + marker.len()..].split_whitespace().next())
            .map(|w| w.trim_end_matches([';', ',']))
            .collect()
    };
    let mut quoted: Vec<&str> = after("Input string ");
    quoted.extend(after("Unknown logical value: "));
    for (i, _) in error.match_indices("Unable to find requested ") {
        let rest = &error[i..];
        let clause = rest.split(';').next().unwrap_or(rest);
        if let Some(v) = clause.split(" type ").nth(1).and_then(|t| t.split_whitespace().next()) {
            quoted.push(v);
        }
    }
    let mut out = Vec::new();
    for w in petsc.windows(2) {
        if is_petsc_option(&w[0]) && quoted.contains(&w[1].as_str()) {
            let o = format!("{} {}", w[0], w[1]);
            if !out.contains(&o) {
                out.push(o);
            }
        }
    }
    out
}

/// The rank of this process as the MPI launcher numbers it (0 when not launched by one),
/// read before MPI is initialised so that a usage error is printed once, by rank 0.
pub fn launcher_rank() -> usize {
    ["OMPI_COMM_WORLD_RANK", "PMIX_RANK", "PMI_RANK", "SLURM_PROCID"].iter().find_map(|k| std::env::var(k).ok()?.parse().ok()).unwrap_or(0)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_petsc_value_petsc_rejected_is_named_with_its_option() {
        let args = s(&["-snes_max_it", "abc", "-ksp_view", "-snes_type", "foo", "-pc_type", "lu"]);
        // PETSc's messages as this PETSc (3.18) writes them.
        let int = "PetscOptionsStringToInt (options.c:2176): Input string abc has no integer value (do not include . in it); PetscOptionsGetInt (options.c:2515): Argument out of range";
        assert_eq!(options_quoted(&args, int), ["-snes_max_it abc"]);
        let ty = "SNESSetType (snes.c:4792): Unable to find requested SNES type foo; SNESSetFromOptions (snes.c:951): Unknown type. Check for miss-spelling";
        assert_eq!(options_quoted(&args, ty), ["-snes_type foo"]);
        let b = s(&["-snes_converged_reason", "maybe"]);
        assert_eq!(
            options_quoted(&b, "PetscOptionsStringToBool (options.c:2147): Unknown logical value: maybe; PetscOptionsGetBool"),
            ["-snes_converged_reason maybe"]
        );
        // A message that quotes no value, or a value no option has: nothing named.
        assert!(options_quoted(&args, "MatLUFactorNumeric: Zero pivot in LU factorization").is_empty());
        assert!(options_quoted(&args, "Input string xyz has no numeric value").is_empty());
    }

    fn s(v: &[&str]) -> Vec<String> {
        v.iter().map(|x| x.to_string()).collect()
    }

    #[test]
    fn our_options_anywhere_petsc_options_with_values() {
        let r =
            split(&s(&["a.toml", "-ksp_type", "cg", "--check", "-ksp_view", "--set", "x.y=1", "-mat_mumps_cntl_1", "-1", "--output=o"]))
                .unwrap();
        assert_eq!(r.ours, s(&["a.toml", "--check", "--set", "x.y=1", "--output=o"]));
        assert_eq!(r.petsc, s(&["-ksp_type", "cg", "-ksp_view", "-mat_mumps_cntl_1", "-1"]));
    }

    #[test]
    fn everything_after_double_dash_is_petsc() {
        let r = split(&s(&["--quiet", "a.toml", "--", "--check", "b"])).unwrap();
        assert_eq!(r.ours, s(&["--quiet", "a.toml"]));
        assert_eq!(r.petsc, s(&["--check", "b"]));
    }

    #[test]
    fn misuses_are_named() {
        let e = split(&s(&["a.toml", "--sett", "x=1"])).unwrap_err().to_string();
        assert!(e.contains("'--sett'") && e.contains("--set"), "{e}");
        let e = split(&s(&["a.toml", "b.toml"])).unwrap_err().to_string();
        assert!(e.contains("'b.toml'"), "{e}");
        let e = split(&s(&["a.toml", "-ksp_view", "b.toml"])).unwrap_err().to_string();
        assert!(e.contains("'b.toml'"), "{e}");
        let r = split(&s(&["-log_view", "a.toml", "-ksp_type", "cg"])).unwrap();
        assert_eq!((r.ours, r.petsc), (s(&["a.toml"]), s(&["-log_view", "-ksp_type", "cg"])));
        let e = split(&s(&["a.toml", "--output"])).unwrap_err().to_string();
        assert!(e.contains("'--output' needs a value"), "{e}");
        let e = split(&s(&["a.toml", "--check=yes"])).unwrap_err().to_string();
        assert!(e.contains("'--check' takes no value"), "{e}");
        assert!(split(&s(&["a.toml", "-"])).unwrap_err().to_string().contains("'-'"));
    }
}
