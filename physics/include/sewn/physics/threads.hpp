#pragma once
// How many threads the physics kernels use: spring forces and Jacobians, the block-sparse
// product and the vector passes of block-Jacobi CG. Work is split into one contiguous range
// per thread and per-thread partial results are combined in thread order, so a run is
// deterministic for a given thread count; with different counts results agree to round-off
// (reductions regroup), the Jacobian assembly and the product are bitwise equal.
//
// One thread unless asked: the count changes results in the last bits, so a program opts in,
// through set_thread_count() or the environment variable SEWN_THREADS (read when the count is
// first needed). Without OpenMP at build time (SEWN_WITH_OPENMP=OFF, or no OpenMP found) the
// same per-thread split is run one range after the other: results equal those of a parallel
// build with that count, only not faster.

#include <cstdint>

namespace sewn::physics {

/// Largest thread count accepted.
inline constexpr int max_threads = 256;

/// The thread count in force (>= 1): the last set_thread_count(), else SEWN_THREADS, else 1.
/// Throws InputError naming SEWN_THREADS if it is set to anything but an integer in
/// [1, max_threads] and no count was set.
[[nodiscard]] int thread_count();
/// Sets the thread count for every later physics call of this process. Throws InputError
/// (count unchanged) outside [1, max_threads]. Not to be called while a step runs.
void set_thread_count(int threads);
/// Parses a thread count as SEWN_THREADS and the tool's `threads` key give it; throws
/// InputError naming `what` on anything but an integer in [1, max_threads].
[[nodiscard]] int parse_thread_count(const char* text, const char* what);
/// True if this build runs ranges in parallel (OpenMP found at build time).
[[nodiscard]] bool parallel_build();
/// How many regions the physics kernels called from this thread have split into more than one
/// range so far (a kernel below its size threshold splits none): for tests and diagnostics.
/// A split region forks a team unless the thread is backing off: when a region's team came
/// late (the join 250 µs or more later than running its ranges one after the other: other
/// work held a core), no region forks for 50 times the time it lost, doubling after each late
/// try up to 2 s and forgotten after an on-time one. Results do not change (the ranges are the
/// count's), only where they run. O(1).
[[nodiscard]] std::uint64_t split_regions();

/// The team CHOLMOD's OpenMP regions ask for: its build fixes num_threads(4) (counted with a
/// GOMP_parallel shim on the frisbee's factorizations), not settable through its API.
inline constexpr int cholmod_team = 4;

/// While alive, unless thread_count() >= `library_team`, the OpenMP regions of the libraries we
/// call run on the calling thread alone. CHOLMOD's supernodal factorization opens its regions
/// with a fixed num_threads(4), which neither OMP_NUM_THREADS nor omp_set_num_threads()
/// overrides: a "single thread" run then woke three more threads for every supernode (35 % of
/// the frisbee's CPU time went to their wake-ups and spins), and a 2-thread run put 4 threads
/// on 2 cores (the frisbee 27x slower beside a busy core). Only a team of one can be forced
/// from outside, so below 4 threads CHOLMOD runs serially: on 2 vCPUs its team of 4 was slower
/// than one thread at every size measured (docs/solvers.md, Threads). Nests (restores the
/// previous setting); not thread-safe, like the solvers it guards. It sets our OpenMP runtime's
/// setting: with g++ that is the libgomp CHOLMOD uses; a clang build (libomp) cannot reach
/// CHOLMOD's regions this way. O(1).
class SerialLibraryRegions {
 public:
  explicit SerialLibraryRegions(int library_team = cholmod_team);
  ~SerialLibraryRegions();
  SerialLibraryRegions(const SerialLibraryRegions&) = delete;
  SerialLibraryRegions& operator=(const SerialLibraryRegions&) = delete;

 private:
  int saved_ = -1;  // the max-active-levels setting to restore, -1: unchanged
};

/// The team an OpenMP region opened here with num_threads(requested) gets (1 without OpenMP):
/// what SerialLibraryRegions controls, for tests and diagnostics. O(one region).
[[nodiscard]] int library_team_size(int requested);

}  // namespace sewn::physics
