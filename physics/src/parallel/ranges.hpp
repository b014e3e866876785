#pragma once
// The one way physics kernels go parallel (sewn/physics/threads.hpp): `parts` contiguous
// ranges, range t run by thread t, fixed by the count alone so that results are deterministic.
// Without OpenMP the ranges run one after the other, with the same results.

#include <algorithm>
#include <array>
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

/// One call site's record of its forked regions: how many regions to run unforked before
/// forking again, and the back-off that follows the next late one (threads.cpp).
struct RegionPacing {
  int skip = 0;
  int backoff = 0;
};

/// Whether the next region of a call site is to fork, or to run its ranges on the calling
/// thread while the site backs off after a region whose team came late. Counts the region
/// (split_regions()); false without OpenMP.
bool fork_next_region(RegionPacing& pacing);
/// Reports a forked region: seconds from the fork to the join, and the sum of its ranges'
/// own durations (what running them one after the other would have cost).
void region_done(RegionPacing& pacing, double region_s, double ranges_s);

/// Calls body(t) for t in [0, parts), on `parts` threads when OpenMP is built in. body must
/// not throw (an exception cannot leave an OpenMP region): kernels record failures instead.
/// The ranges are fixed by `parts` alone, so running them on fewer threads (the runtime's
/// team, or one while the site backs off on a loaded machine) changes no result.
template <class Body>
void run_parts(int parts, const Body& body) {
  if (parts <= 1) {
    body(0);
    return;
  }
  // One per call site (each passes a lambda of its own type) and per stepping thread.
  static thread_local RegionPacing pacing;
  if (!fork_next_region(pacing)) {
    for (int t = 0; t < parts; ++t) body(t);
    return;
  }
#ifdef SEWN_HAVE_OPENMP
  using clock = std::chrono::steady_clock;
  const clock::time_point start = clock::now();
  std::array<double, max_threads> took{};
#pragma omp parallel num_threads(parts)
  {
    // Each range exactly once, whatever number of threads the runtime granted.
#pragma omp for schedule(static, 1)
    for (int t = 0; t < parts; ++t) {
      const clock::time_point begin = clock::now();
      body(t);
      took[static_cast<std::size_t>(t)] = std::chrono::duration<double>(clock::now() - begin).count();
    }
  }
  const double region_s = std::chrono::duration<double>(clock::now() - start).count();
  double ranges_s = 0.0;
  for (int t = 0; t < parts; ++t) ranges_s += took[static_cast<std::size_t>(t)];
  region_done(pacing, region_s, ranges_s);
#endif
}

}  // namespace sewn::physics::detail
