# Environment for running ehl-petsc under mpirun on this kind of machine (sourced by ci/*).
# OpenMPI refuses to run as root without these; 3+ ranks on 2 cores need oversubscription;
# one BLAS thread per MPI rank.
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
export OMPI_MCA_rmaps_base_oversubscribe=1
export OPENBLAS_NUM_THREADS=1 OMP_NUM_THREADS=1
