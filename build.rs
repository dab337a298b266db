//! Build script: generates Rust bindings to Debian's PETSc (petsc-dev) with bindgen and checks
//! that PETSc is configured as ehl-petsc expects (32-bit PetscInt, real double scalars, MUMPS).
//!
//! PETSc is found with pkg-config (`PETSc`); the MPI include directory comes from
//! `pkg-config ompi-c` or, failing that, `mpicc --showme:compile`.
use std::env;
use std::path::{Path, PathBuf};
use std::process::Command;

const INSTALL_HINT: &str = "install the system packages with `sudo ci/setup` \
(apt-get install petsc-dev libclang-dev pkg-config libopenblas0-serial)";

fn fail(msg: &str) -> ! {
    eprintln!("\nerror: ehl-petsc build: {msg}\n");
    panic!("ehl-petsc build: {msg}");
}

/// Include directories of MPI (PETSc's pkg-config file does not list them).
fn mpi_include_dirs() -> Vec<PathBuf> {
    if let Ok(lib) = pkg_config::Config::new().cargo_metadata(false).probe("ompi-c") {
        return lib.include_paths;
    }
    match Command::new("mpicc").arg("--showme:compile").output() {
        Ok(out) if out.status.success() => {
            String::from_utf8_lossy(&out.stdout).split_whitespace().filter_map(|f| f.strip_prefix("-I").map(PathBuf::from)).collect()
        }
        _ => fail(&format!("MPI headers not found (neither `pkg-config ompi-c` nor `mpicc`): {INSTALL_HINT}")),
    }
}

/// Checks petscconf.h: the Rust side assumes PetscInt = i32 and PetscScalar = f64, and MUMPS.
fn check_petsc_config(include_dirs: &[PathBuf]) {
    let conf = include_dirs
        .iter()
        .map(|d| d.join("petscconf.h"))
        .find(|p| p.exists())
        .unwrap_or_else(|| fail("petscconf.h not found in PETSc's include directories"));
    let text = std::fs::read_to_string(&conf).unwrap_or_else(|e| fail(&format!("cannot read {}: {e}", conf.display())));
    let defined = |name: &str| text.lines().any(|l| l.trim_start().starts_with(&format!("#define {name} ")));
    if defined("PETSC_USE_64BIT_INDICES") {
        fail(&format!("{} has 64-bit indices; ehl-petsc needs 32-bit PetscInt (Debian's petsc-dev)", conf.display()));
    }
    if !defined("PETSC_USE_REAL_DOUBLE") || defined("PETSC_USE_COMPLEX") {
        fail(&format!(
            "{} is not a real double-precision build; ehl-petsc needs PetscScalar = double (petsc-dev's real flavour)",
            conf.display()
        ));
    }
    if !defined("PETSC_HAVE_MUMPS") {
        fail(&format!("{} was built without MUMPS; ehl-petsc's direct solver needs it", conf.display()));
    }
    println!("cargo:rerun-if-changed={}", conf.display());
}

fn main() {
    println!("cargo:rerun-if-changed=build.rs");
    println!("cargo:rerun-if-changed=src/petsc/wrapper.h");
    let petsc =
        pkg_config::Config::new().probe("PETSc").unwrap_or_else(|e| fail(&format!("PETSc not found by pkg-config ({e}); {INSTALL_HINT}")));
    check_petsc_config(&petsc.include_paths);
    for dir in &petsc.link_paths {
        // Debian keeps libpetsc_real outside the default loader path: embed an rpath.
        println!("cargo:rustc-link-arg=-Wl,-rpath,{}", dir.display());
    }

    let mut clang_args: Vec<String> = Vec::new();
    for dir in petsc.include_paths.iter().chain(mpi_include_dirs().iter()) {
        clang_args.push(format!("-I{}", dir.display()));
    }
    let bindings = bindgen::Builder::default()
        .header("src/petsc/wrapper.h")
        .clang_args(&clang_args)
        .allowlist_function("(Petsc|Vec|Mat|KSP|PC|SNES|IS|ISLocalToGlobalMapping)[A-Z].*")
        .allowlist_var("PETSC_.*|MAT[A-Z_]+|KSP[A-Z_]+|PC[A-Z_]+|SNES[A-Z_]+|VEC[A-Z_]+")
        .allowlist_type("Petsc.*|Vec|Mat|KSP|PC|SNES|IS|InsertMode|NormType|MatAssemblyType|MatOption|ScatterMode|SNESConvergedReason|KSPConvergedReason|MatReuse|MatFactorType")
        .blocklist_item("MPI_.*|ompi_.*|MPIR_.*")
        .default_enum_style(bindgen::EnumVariation::Consts)
        .layout_tests(false)
        .derive_default(true)
        .generate_comments(false)
        .generate()
        .unwrap_or_else(|e| fail(&format!("bindgen failed on PETSc's headers ({e}); is libclang-dev installed? {INSTALL_HINT}")));
    let out = PathBuf::from(env::var("OUT_DIR").unwrap()).join("petsc_bindings.rs");
    bindings.write_to_file(Path::new(&out)).unwrap_or_else(|e| fail(&format!("cannot write {}: {e}", out.display())));
}
