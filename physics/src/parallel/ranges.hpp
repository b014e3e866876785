#pragma once
// The one way physics kernels go parallel (sewn/physics/threads.hpp): `parts` contiguous
// ranges, range t run by thread t, fixed by the count alone so that results are deterministic.
// Without OpenMP the ranges run one after the other, with the same results.

#include <algorithm>
#include <chrono>
#include <cstddef>

#include "sewn/physics/threads.hpp"

namespace sewn::physics::detail {

/// How many ranges to split `items` into: the thread count, but no range under `grain`
/// items (a fork and join costs a few microseconds; below that, one thread is faster).
inline int parts_for(std::size_t items, std::size_t grain) {
  const std::size_t most = std::max<std::size_t>(1, items / std::max<std::size_t>(1, grain));
  return static_cast<int>(std::min<std::size_t>(static_cast<std::size_t>(thread_count()), most));
}

/// Start of range t of `parts` over [0, items); range t is [range_begin(t), range_begin(t + 1)).
inline std::size_t range_begin(std::size_t items, int parts, int t) {
  return items / static_cast<std::size_t>(parts) * static_cast<std::size_t>(t) +
         std::min(items % static_cast<std::size_t>(parts), static_cast<std::size_t>(t));
}

/// Whether the next split region is to fork, or to run its ranges on the calling thread while
/// this thread backs off after a region whose team came late (threads.cpp). Counts the region
/// (split_regions()); false without OpenMP.
bool fork_next_region();
/// Reports a forked region: seconds from the fork to the join, and an estimate of what running
/// its ranges one after the other would have cost.
void region_done(double region_s, double serial_s);

#ifdef SEWN_HAVE_OPENMP
// One phase of a forked region: range t of `parts` on the team, each exactly once whatever
// number of threads the runtime granted; range 0 is the calling thread's (the static
// schedule's first iteration goes to thread 0), its time added to first_s. The worksharing
// loop ends at a barrier: a phase starts once every range of the one before is done.
template <class Phase>
void run_phase_on_team(int parts, const Phase& phase, double& first_s) {
  using clock = std::chrono::steady_clock;
#pragma omp for schedule(static, 1)
  for (int t = 0; t < parts; ++t) {
    if (t != 0) {
      phase(t);
      continue;
    }
    const clock::time_point begin = clock::now();
    phase(0);
    first_s += std::chrono::duration<double>(clock::now() - begin).count();
  }
}
#endif

/// Calls phase(t) for t in [0, parts), for each phase in turn, on `parts` threads when OpenMP is
/// built in: every range of a phase is done before the next phase starts (one fork, a barrier
/// between phases). Phases must not throw (an exception cannot leave an OpenMP region):
/// kernels record failures instead. The ranges are fixed by `parts` alone, so running them on
/// fewer threads (the runtime's team, or one while backing off on a loaded machine: each phase's
/// ranges one after the other) changes no result.
template <class... Phases>
void run_parts(int parts, const Phases&... phases) {
  if (parts <= 1) {
    (phases(0), ...);
    return;
  }
  const auto serially = [parts](const auto& phase) {
    for (int t = 0; t < parts; ++t) phase(t);
  };
  if (!fork_next_region()) {
    (serially(phases), ...);
    return;
  }
#ifdef SEWN_HAVE_OPENMP
  using clock = std::chrono::steady_clock;
  const clock::time_point start = clock::now();
  double first_s = 0.0;
#pragma omp parallel num_threads(parts)
  {
    (run_phase_on_team(parts, phases, first_s), ...);
  }
  // The ranges are of one size: the calling thread's time, times their count, is what running
  // them one after the other would cost. Not the sum of every range's time: a worker
  // preempted midway keeps its clock running, and its late region would look on time.
  region_done(std::chrono::duration<double>(clock::now() - start).count(), first_s * parts);
#endif
}

}  // namespace sewn::physics::detail
