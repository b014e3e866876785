// MPI for the hypre and PETSc backends (mpi_session.hpp).

#include "mpi_session.hpp"

#include <mpi.h>

#include <cstdlib>
#include <string>

#include "sewn/physics/errors.hpp"

namespace sewn::physics::solve::detail {

void ensure_mpi() {
  int finalized = 0;
  MPI_Finalized(&finalized);
  if (finalized) throw SolverError("MPI was already finalised: the hypre and PETSc solvers need it running", 0, 0);
  int initialized = 0;
  MPI_Initialized(&initialized);
  if (initialized) return;
  // The solvers are called from one thread at a time (the stepping thread); OpenMP kernels
  // around them make no MPI calls.
  int provided = 0;
  int status = MPI_SUCCESS;
  {
    const LeakCheckPause pause;
    status = MPI_Init_thread(nullptr, nullptr, MPI_THREAD_FUNNELED, &provided);
  }
  if (status != MPI_SUCCESS) throw SolverError("MPI_Init_thread failed: the hypre and PETSc solvers cannot start", 0, 0);
  std::atexit([] {
    int done = 0;
    MPI_Finalized(&done);
    const LeakCheckPause pause;
    if (!done) MPI_Finalize();
  });
}

int mpi_ranks() {
  ensure_mpi();
  int size = 1;
  MPI_Comm_size(MPI_COMM_WORLD, &size);
  return size;
}

}  // namespace sewn::physics::solve::detail
