#pragma once
// The one way physics kernels go parallel (sewn/physics/threads.hpp): `parts` contiguous
// ranges, range t run by thread t, fixed by the count alone so that results are deterministic.
// Without OpenMP the ranges run one after the other, with the same results.

#include <algorithm>
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

/// Calls body(t) for t in [0, parts), on `parts` threads when OpenMP is built in. body must
/// not throw (an exception cannot leave an OpenMP region): kernels record failures instead.
template <class Body>
void run_parts(int parts, const Body& body) {
  if (parts <= 1) {
    body(0);
    return;
  }
#ifdef SEWN_HAVE_OPENMP
#pragma omp parallel num_threads(parts)
  {
    // Each range exactly once, whatever number of threads the runtime granted.
#pragma omp for schedule(static, 1)
    for (int t = 0; t < parts; ++t) body(t);
  }
#else
  for (int t = 0; t < parts; ++t) body(t);
#endif
}

}  // namespace sewn::physics::detail
