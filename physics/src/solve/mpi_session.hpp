#pragma once
// Internal: MPI for the backends built on MPI libraries (hypre, PETSc; not installed).

#if defined(__has_feature)
#if __has_feature(address_sanitizer)
#define SEWN_LSAN 1
#endif
#endif
#if defined(__SANITIZE_ADDRESS__)
#define SEWN_LSAN 1
#endif
#ifdef SEWN_LSAN
#include <sanitizer/lsan_interface.h>
#endif

namespace sewn::physics::solve::detail {

/// Leak checking paused for its lifetime (sanitizer builds only): OpenMPI, hypre and PETSc
/// keep allocations of their start and end (plugins, hardware maps) past exit, which
/// LeakSanitizer would report. Only their initialisation and finalisation run under it; every
/// object our solvers create is still checked.
class LeakCheckPause {
 public:
#ifdef SEWN_LSAN
  LeakCheckPause() { __lsan_disable(); }
  ~LeakCheckPause() { __lsan_enable(); }
#else
  LeakCheckPause() {}  // user-provided (not = default): an instance is not an "unused variable"
#endif
  LeakCheckPause(const LeakCheckPause&) = delete;
  LeakCheckPause& operator=(const LeakCheckPause&) = delete;
};

/// Initialises MPI unless the program did (a serial program becomes a singleton rank), and
/// finalises it at exit if it was initialised here. Throws SolverError if MPI was already
/// finalised or cannot start. O(1) after the first call (the first costs ~0.5 s with OpenMPI).
void ensure_mpi();

/// MPI_COMM_WORLD's size, MPI started first if needed (solve::solver_ranks()).
int mpi_ranks();

}  // namespace sewn::physics::solve::detail
