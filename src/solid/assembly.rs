//! Assembly of the equivalent solid's elasticity system into PETSc objects.
//!
//! Dimensionless form (docs/model.md sections 5-6): X = x/a, U = u R/a^2, P = p/p_H. With
//! sigma = E_eq C~(nu_eq) : eps, the weak form becomes
//!   integral C~ eps(U) : eps(V) dX = -(E'/(pi E_eq)) integral_{Omega_c} P V_y dS,
//! so the stiffness uses a unit Young's modulus and the traction carries the factor
//! E'/(pi E_eq) = 2/(pi (1 - nu_eq^2)). A Hertzian P on a half-space then gives
//! U_y = -(1 - (X^2 + Z^2)/2) inside the contact.
use super::dofmap::{preallocation, DofMap};
use crate::fem;
use crate::mesh::{Mesh, Partition};
use crate::petsc::{ffi, Matrix, Result, Vector};

/// Factor E'/(pi E_eq) that turns the dimensionless pressure into the dimensionless traction.
pub fn traction_factor(nu_eq: f64) -> f64 {
    2.0 / (std::f64::consts::PI * (1.0 - nu_eq * nu_eq))
}

/// The four vertex coordinates of a P2 tetrahedron.
pub fn tet_vertices(mesh: &Mesh, tet: &[u32; 10]) -> [[f64; 3]; 4] {
    [0, 1, 2, 3].map(|i| mesh.nodes[tet[i] as usize])
}

/// Assembles the dimensionless stiffness matrix (unit Young's modulus, Poisson ratio `nu`)
/// from the tetrahedra this rank owns; off-rank rows travel through PETSc's stash.
pub fn assemble_stiffness(comm: ffi::MPI_Comm, mesh: &Mesh, part: &Partition, dofs: &DofMap, rank: usize, nu: f64) -> Result<Matrix> {
    let (d_nnz, o_nnz) = preallocation(mesh, part, dofs, rank);
    let a = Matrix::new_aij(comm, dofs.local(rank), &d_nnz, &o_nnz)?;
    add_stiffness(&a, mesh, part, rank, nu, |tet| dofs.tet_dofs(tet))?;
    a.assemble()?;
    a.set_symmetric(true)?;
    Ok(a)
}

/// Adds the element stiffness matrices of this rank's tetrahedra into `a`, with the 30
/// global indices of each element given by `index` (-1 for constrained components).
pub fn add_stiffness(
    a: &Matrix,
    mesh: &Mesh,
    part: &Partition,
    rank: usize,
    nu: f64,
    index: impl Fn(&[u32; 10]) -> [i32; 30],
) -> Result<()> {
    let (lambda, mu) = fem::elasticity::lame(1.0, nu);
    let mut ke = [0.0; 900];
    for (k, tet) in mesh.tets.iter().enumerate() {
        if part.tet_rank[k] as usize != rank {
            continue;
        }
        fem::elasticity::elasticity_stiffness_flat(&tet_vertices(mesh, tet), lambda, mu, &mut ke);
        let idx = index(tet);
        a.add_values(&idx, &idx, &ke)?;
    }
    Ok(())
}

/// Assembles the load vector of a normal pressure on the contact face:
/// F_i = -factor * integral P N_i dS on the y component, P integrated by `integrate`
/// (which returns the 6 P2-weighted integrals over one contact triangle).
pub fn assemble_pressure_load(
    comm: ffi::MPI_Comm,
    mesh: &Mesh,
    part: &Partition,
    dofs: &DofMap,
    rank: usize,
    factor: f64,
    integrate: &dyn Fn(&[[f64; 2]; 3]) -> [f64; 6],
) -> Result<Vector> {
    let b = Vector::new(comm, dofs.local(rank))?;
    b.set_all(0.0)?;
    for (t, tri) in mesh.contact_tris.iter().enumerate() {
        if part.tet_rank[mesh.contact_tri_tet[t] as usize] as usize != rank {
            continue;
        }
        let v = [0, 1, 2].map(|i| {
            let p = mesh.nodes[tri[i] as usize];
            [p[0], p[2]]
        });
        let fe = integrate(&v);
        let mut idx = Vec::with_capacity(6);
        let mut val = Vec::with_capacity(6);
        for i in 0..6 {
            let d = dofs.node_dof[tri[i] as usize][1];
            if d >= 0 {
                idx.push(d);
                val.push(-factor * fe[i]);
            }
        }
        b.set_values(&idx, &val, true)?;
    }
    b.assemble()?;
    Ok(b)
}
