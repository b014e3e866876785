#pragma once
// Internal: the hypre and PETSc backends live in a module of their own (libsewn_mpi_solvers.so,
// built with the library), loaded the first time a program asks for one of them or for
// solver_ranks(). MPI, hypre and PETSc pull in ~100 shared libraries whose loading took 40 of
// the 43 ms of every `sewn` start on the Xeon of our reports; a program that never solves with
// them no longer loads them. The module resolves the few symbols of ours it calls (the solver
// base class, BlockMatrix, the PCG loop) in the executable, which exports sewn::physics's
// symbols for it (physics/CMakeLists.txt).

#include <memory>

#include "sewn/physics/solve/linear_solver.hpp"

namespace sewn::physics::solve::detail {

struct MpiBackends {
  std::unique_ptr<LinearSolver> (*make_hypre_pcg)(SolverOptions) = nullptr;  ///< null: built without hypre
  std::unique_ptr<LinearSolver> (*make_petsc)(SolverOptions) = nullptr;      ///< null: built without PETSc
  int (*ranks)() = nullptr;                                                  ///< MPI_COMM_WORLD's size, MPI started if needed
};

/// The name of the module's entry point, `extern "C" const MpiBackends* sewn_mpi_backends()`.
inline constexpr const char* mpi_backends_entry = "sewn_mpi_backends";

/// The module's backends, loaded on the first call (from SEWN_MPI_SOLVERS if set, else where the
/// build put it, else where it installs). Throws SolverError naming the paths tried and the
/// loader's message if it cannot be loaded. O(1) after the first call.
const MpiBackends& mpi_backends();

}  // namespace sewn::physics::solve::detail
