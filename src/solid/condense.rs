//! Static condensation of the equivalent solid onto its contact face (exact, done once).
//!
//! The elastic block of the EHL system is linear and constant, and the Reynolds equation
//! sees the solid only through U_y on the contact face. Eliminating every other
//! displacement unknown gives the face compliance
//! ```text
//!   U_y(face) = C P,      C = -c S^{-1} M,
//! ```
//! where S is the Schur complement of the stiffness K onto the U_y unknowns of the face
//! nodes, M (face nodes x pressure nodes) the P2 face mass matrix (integral N_i N_j) and
//! c = E'/(pi E_eq) the traction factor. This is the same discrete model as the monolithic
//! system (no approximation, only a different elimination order), as in Habchi's "exact
//! model order reduction" of the full-system EHL approach.
//!
//! MUMPS computes S during one sparse factorisation of K (ICNTL(19)); PETSc only supports
//! that sequentially, so rank 0 does it on the whole (replicated) mesh and broadcasts C.
use super::assembly::assemble_stiffness;
use super::dofmap::DofMap;
use crate::mesh::{partition, Mesh};
use crate::pcall;
use crate::petsc::error::rust_error;
use crate::petsc::{ffi, Result};
use mpi::topology::SimpleCommunicator;
use mpi::traits::*;

/// Face compliance: `c[i * cols.len() + j]` = U_y at face node `rows[i]` per unit P at
/// pressure node `cols[j]` (dimensionless).
pub struct Compliance {
    /// Face nodes (mesh node ids), in `mesh.contact_nodes` order.
    pub rows: Vec<u32>,
    /// Pressure nodes (mesh node ids).
    pub cols: Vec<u32>,
    /// Row-major dense matrix, rows.len() x cols.len().
    pub c: Vec<f64>,
    /// Seconds spent (rank 0: assembly, factorisation with Schur complement, dense solve).
    pub seconds: f64,
    /// Unknowns of the eliminated elastic problem.
    pub elastic_unknowns: usize,
}

impl Compliance {
    /// The compliance of rigid solids: U_y = 0 whatever the pressure (no matrix stored).
    pub fn rigid(rows: Vec<u32>, cols: Vec<u32>) -> Compliance {
        Compliance { rows, cols, c: Vec::new(), seconds: 0.0, elastic_unknowns: 0 }
    }

    /// Whether this is the rigid (zero) compliance.
    pub fn is_rigid(&self) -> bool {
        self.c.is_empty()
    }

    /// U_y at every face node for the nodal pressures `p` (in `cols` order).
    pub fn apply(&self, p: &[f64]) -> Vec<f64> {
        if self.is_rigid() {
            return vec![0.0; self.rows.len()];
        }
        let n = self.cols.len();
        self.c.chunks_exact(n).map(|row| row.iter().zip(p).map(|(a, b)| a * b).sum()).collect()
    }
}

/// Owned PETSc objects destroyed on drop.
struct OwnedMat(ffi::Mat);
impl Drop for OwnedMat {
    fn drop(&mut self) {
        if !self.0.is_null() {
            unsafe { ffi::MatDestroy(&mut self.0) };
        }
    }
}
struct OwnedIs(ffi::IS);
impl Drop for OwnedIs {
    fn drop(&mut self) {
        if !self.0.is_null() {
            unsafe { ffi::ISDestroy(&mut self.0) };
        }
    }
}

/// The P2 face mass matrix `B[i][j]` = integral over the face of N_i N_j for face rows
/// `rows` and pressure columns `cols` (dense, row-major).
fn face_mass(mesh: &Mesh, rows: &[u32], cols: &[u32]) -> Vec<f64> {
    let mut row_of = vec![-1i64; mesh.nodes.len()];
    for (i, &n) in rows.iter().enumerate() {
        row_of[n as usize] = i as i64;
    }
    let mut col_of = vec![-1i64; mesh.nodes.len()];
    for (j, &n) in cols.iter().enumerate() {
        col_of[n as usize] = j as i64;
    }
    let nc = cols.len();
    let mut b = vec![0.0; rows.len() * nc];
    for tri in &mesh.contact_tris {
        let xz = |n: u32| {
            let c = mesh.nodes[n as usize];
            [c[0], c[2]]
        };
        let m = crate::fem::p2tri::p2_tri_mass(crate::fem::p2tri::tri_area(&[xz(tri[0]), xz(tri[1]), xz(tri[2])]));
        for a in 0..6 {
            let i = row_of[tri[a] as usize];
            if i < 0 {
                continue;
            }
            for (bb, &mab) in m[a].iter().enumerate() {
                let j = col_of[tri[bb] as usize];
                if j >= 0 {
                    b[i as usize * nc + j as usize] += mab;
                }
            }
        }
    }
    b
}

/// Computes the face compliance of the equivalent solid (Poisson ratio `nu`, traction
/// factor `traction`) for the pressure nodes `cols`. Collective over `world`; the result
/// is on every rank.
///
/// Rank 0 computes the Schur complement S (MUMPS supports it only sequentially) and
/// broadcasts it; then every rank solves S X = -c M for its share of the pressure columns
/// (dense Cholesky: S is symmetric positive definite) and the shares are gathered.
pub fn face_compliance(world: &SimpleCommunicator, mesh: &Mesh, nu: f64, traction: f64, cols: &[u32]) -> Result<Compliance> {
    let t0 = std::time::Instant::now();
    let rows: Vec<u32> = mesh.contact_nodes.clone();
    let (nr, nc) = (rows.len(), cols.len());
    let part = partition(mesh, 1);
    let dofs = DofMap::new(mesh, &part, 1);
    let mut s = vec![0.0; nr * nr];
    let mut status: i32 = 0;
    let mut failure = None;
    if world.rank() == 0 {
        match schur_complement(mesh, &part, &dofs, nu, &rows) {
            Ok(v) => s = v,
            Err(e) => {
                status = 1;
                failure = Some(e);
            }
        }
    }
    world.process_at_rank(0).broadcast_into(&mut status);
    if status != 0 {
        // Every rank fails; rank 0 keeps PETSc's message, which the program prints once.
        return Err(failure.unwrap_or_else(|| rust_error("static condensation of the elastic block failed on rank 0")));
    }
    world.process_at_rank(0).broadcast_into(&mut s[..]);
    let dbg = crate::ehl_options::get().monitor;
    if dbg && world.rank() == 0 {
        eprintln!("condense: S on every rank {:.2} s", t0.elapsed().as_secs_f64());
    }
    // This rank's columns: equal blocks, the last rank the remainder.
    let size = world.size() as usize;
    let blocks = crate::mesh::equal_blocks(nc, size);
    let span = |r: usize| (blocks[r], blocks[r + 1]);
    let (c0, c1) = span(world.rank() as usize);
    let mine = solve_columns(&mut s, nr, &face_mass(mesh, &rows, &cols[c0..c1]), traction)?;
    drop(s);
    // Gather the column blocks (column-major, nr x block) and store C row-major.
    let counts: Vec<i32> = (0..size).map(|r| ((span(r).1 - span(r).0) * nr) as i32).collect();
    let displs: Vec<i32> = counts.iter().scan(0, |acc, &n| Some(std::mem::replace(acc, *acc + n))).collect();
    let mut xcol = vec![0.0; nr * nc];
    {
        let mut part = mpi::datatype::PartitionMut::new(&mut xcol[..], &counts[..], &displs[..]);
        world.all_gather_varcount_into(&mine[..], &mut part);
    }
    let mut c = vec![0.0; nr * nc];
    for (j, col) in xcol.chunks_exact(nr).enumerate() {
        for (i, &v) in col.iter().enumerate() {
            c[i * nc + j] = v;
        }
    }
    if dbg && world.rank() == 0 {
        eprintln!("condense: compliance on every rank {:.2} s", t0.elapsed().as_secs_f64());
    }
    Ok(Compliance { rows, cols: cols.to_vec(), c, seconds: t0.elapsed().as_secs_f64(), elastic_unknowns: dofs.total() })
}

/// X = -c S^{-1} M for the face mass block `m` (row-major, nr x k): dense Cholesky of S
/// (overwritten by its factor) and a solve with k right-hand sides; X column-major.
fn solve_columns(s: &mut [f64], nr: usize, m: &[f64], traction: f64) -> Result<Vec<f64>> {
    let selfc = unsafe { ffi::RSMPI_COMM_SELF };
    let k = m.len() / nr.max(1);
    let mut bcol = vec![0.0; nr * k];
    for i in 0..nr {
        for j in 0..k {
            bcol[j * nr + i] = -traction * m[i * k + j];
        }
    }
    let mut x = vec![0.0; nr * k];
    if k == 0 {
        return Ok(x);
    }
    let mut sm = OwnedMat(std::ptr::null_mut());
    pcall!(ffi::MatCreateSeqDense(selfc, nr as i32, nr as i32, s.as_mut_ptr(), &mut sm.0))?;
    let mut b = OwnedMat(std::ptr::null_mut());
    pcall!(ffi::MatCreateSeqDense(selfc, nr as i32, k as i32, bcol.as_mut_ptr(), &mut b.0))?;
    let mut xm = OwnedMat(std::ptr::null_mut());
    pcall!(ffi::MatCreateSeqDense(selfc, nr as i32, k as i32, x.as_mut_ptr(), &mut xm.0))?;
    let mut info: ffi::MatFactorInfo = unsafe { std::mem::zeroed() };
    pcall!(ffi::MatFactorInfoInitialize(&mut info))?;
    // SPD: LAPACK potrf/potrs (without the flag PETSc takes the indefinite sytrf path).
    pcall!(ffi::MatSetOption(sm.0, ffi::MatOption_MAT_SPD, ffi::PetscBool_PETSC_TRUE))?;
    pcall!(ffi::MatCholeskyFactor(sm.0, std::ptr::null_mut(), &info))?;
    pcall!(ffi::MatMatSolve(sm.0, b.0, xm.0))?;
    // The matrices wrap the Rust buffers: destroy them before the buffers move.
    drop(xm);
    drop(b);
    drop(sm);
    Ok(x)
}

/// Options prefix of the elastic factorisation of the condensation (`-elastic_mat_mumps_...`).
pub const ELASTIC_PREFIX: &std::ffi::CStr = c"elastic_";

/// Rank 0's work: K on PETSC_COMM_SELF, MUMPS Cholesky with the Schur complement S on the
/// face U_y unknowns (dense nr x nr, symmetric: row- and column-major alike).
fn schur_complement(mesh: &Mesh, part: &crate::mesh::Partition, dofs: &DofMap, nu: f64, rows: &[u32]) -> Result<Vec<f64>> {
    let selfc = unsafe { ffi::RSMPI_COMM_SELF };
    let t = std::time::Instant::now();
    let k = assemble_stiffness(selfc, mesh, part, dofs, 0, nu)?;
    let dbg = crate::ehl_options::get().monitor;
    if dbg {
        eprintln!("condense: K assembled {:.2} s", t.elapsed().as_secs_f64());
    }
    // K is symmetric positive definite (clamped base): MUMPS LDL^T without pivoting.
    pcall!(ffi::MatSetOption(k.raw(), ffi::MatOption_MAT_SPD, ffi::PetscBool_PETSC_TRUE))?;
    // Schur indices: the U_y unknowns of the face nodes (MUMPS keeps the given order).
    let idx: Vec<i32> = rows.iter().map(|&n| dofs.node_dof[n as usize][1]).collect();
    if idx.iter().any(|&d| d < 0) {
        return Err(rust_error("a contact face node has a constrained U_y"));
    }
    let nr = rows.len();
    let mut is = OwnedIs(std::ptr::null_mut());
    pcall!(ffi::ISCreateGeneral(selfc, nr as i32, idx.as_ptr(), ffi::PetscCopyMode_PETSC_COPY_VALUES, &mut is.0))?;
    let mut f = OwnedMat(std::ptr::null_mut());
    pcall!(ffi::MatGetFactor(k.raw(), ffi::MATSOLVERMUMPS.as_ptr() as *const _, ffi::MatFactorType_MAT_FACTOR_CHOLESKY, &mut f.0))?;
    // Own options prefix: the 3D elastic factorisation takes PORD (-elastic_mat_mumps_icntl_7 4,
    // the fastest Debian MUMPS ordering on 3D elasticity) whatever the options of the Newton
    // matrix say (docs/performance.md "Solver options").
    pcall!(ffi::MatSetOptionsPrefix(f.0, ELASTIC_PREFIX.as_ptr()))?;
    pcall!(ffi::MatFactorSetSchurIS(f.0, is.0))?;
    let mut info: ffi::MatFactorInfo = unsafe { std::mem::zeroed() };
    pcall!(ffi::MatFactorInfoInitialize(&mut info))?;
    pcall!(ffi::MatCholeskyFactorSymbolic(f.0, k.raw(), std::ptr::null_mut(), &info))?;
    pcall!(ffi::MatCholeskyFactorNumeric(f.0, k.raw(), &info))?;
    let mut s = OwnedMat(std::ptr::null_mut());
    let mut st: ffi::MatFactorSchurStatus = 0;
    pcall!(ffi::MatFactorCreateSchurComplement(f.0, &mut s.0, &mut st))?;
    if dbg {
        eprintln!("condense: factor + Schur {:.2} s", t.elapsed().as_secs_f64());
    }
    drop(f);
    drop(k);
    let mut lda: ffi::PetscInt = 0;
    pcall!(ffi::MatDenseGetLDA(s.0, &mut lda))?;
    let lda = lda as usize;
    let mut ptr: *const f64 = std::ptr::null();
    pcall!(ffi::MatDenseGetArrayRead(s.0, &mut ptr))?;
    let a = unsafe { std::slice::from_raw_parts(ptr, lda * nr) };
    let out = (0..nr).flat_map(|j| a[j * lda..j * lda + nr].iter().copied()).collect();
    pcall!(ffi::MatDenseRestoreArrayRead(s.0, &mut ptr))?;
    Ok(out)
}
