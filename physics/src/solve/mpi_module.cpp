// The entry point of the MPI backends' module (mpi_module.hpp): what it offers, by pointers.

#include "mpi_module.hpp"

#include "backends.hpp"
#include "mpi_session.hpp"

extern "C" __attribute__((visibility("default"))) const sewn::physics::solve::detail::MpiBackends* sewn_mpi_backends() {
  using namespace sewn::physics::solve::detail;
  static const MpiBackends backends{
#ifdef SEWN_HAVE_HYPRE
      &make_hypre_pcg,
#else
      nullptr,
#endif
#ifdef SEWN_HAVE_PETSC
      &make_petsc,
#else
      nullptr,
#endif
      &mpi_ranks};
  return &backends;
}
