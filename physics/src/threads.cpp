#include "sewn/physics/threads.hpp"

#include <algorithm>
#include <cerrno>
#include <cstdlib>
#include <string>

#include "sewn/physics/errors.hpp"
#include "parallel/ranges.hpp"

#ifdef SEWN_HAVE_OPENMP
#include <omp.h>
#endif

namespace sewn::physics {

namespace {
int chosen = 0;  // 0: not set, SEWN_THREADS decides
}  // namespace

int parse_thread_count(const char* text, const char* what) {
  const std::string s = text != nullptr ? text : "";
  char* end = nullptr;
  errno = 0;
  const long v = std::strtol(s.c_str(), &end, 10);
  // strtol would skip leading blanks and take a sign: only plain digits are a count
  if (s.empty() || s[0] < '0' || s[0] > '9' || end != s.c_str() + s.size() || errno != 0 || v < 1 || v > max_threads)
    throw InputError(std::string(what) + ": expected a thread count, an integer from 1 to " + std::to_string(max_threads) +
                     ", got '" + s + "'");
  return static_cast<int>(v);
}

int thread_count() {
  if (chosen > 0) return chosen;
  const char* env = std::getenv("SEWN_THREADS");  // NOLINT(concurrency-mt-unsafe): read-only use
  return env == nullptr ? 1 : parse_thread_count(env, "SEWN_THREADS");
}

void set_thread_count(int threads) {
  if (threads < 1 || threads > max_threads)
    throw InputError("set_thread_count: expected an integer from 1 to " + std::to_string(max_threads) + ", got " +
                     std::to_string(threads));
  chosen = threads;
}

bool parallel_build() {
#ifdef SEWN_HAVE_OPENMP
  return true;
#else
  return false;
#endif
}

namespace {
thread_local std::uint64_t split = 0;
// A site's first back-off after a late region, in regions, and the most it grows to: a late
// try costs about one time slice of the late thread, so on a machine that stays loaded the
// tries cost a few percent of the regions' time, and after the load goes a site forks again
// within 4096 regions (a second or so of steps).
constexpr int first_backoff = 4, max_backoff = 4096;
}  // namespace

std::uint64_t split_regions() { return split; }

bool detail::fork_next_region(RegionPacing& pacing) {
  ++split;
#ifdef SEWN_HAVE_OPENMP
  if (pacing.skip == 0) return true;
  --pacing.skip;
#else
  (void)pacing;
#endif
  return false;
}

void detail::region_done(RegionPacing& pacing, double region_s, double ranges_s) {
  if (region_s <= ranges_s) {
    pacing.backoff = 0;
    return;
  }
  pacing.backoff = pacing.backoff == 0 ? first_backoff : std::min(2 * pacing.backoff, max_backoff);
  pacing.skip = pacing.backoff;
}

SerialLibraryRegions::SerialLibraryRegions(int library_team) {
#ifdef SEWN_HAVE_OPENMP
  // The run asked for as many threads as the library's team: its regions may use them.
  if (thread_count() >= library_team) return;
  // No active level allowed: every parallel region, whatever its num_threads clause, gets a
  // team of one (the only OpenMP setting a library's explicit clause does not override).
  saved_ = omp_get_max_active_levels();
  omp_set_max_active_levels(0);
#else
  (void)library_team;
#endif
}

SerialLibraryRegions::~SerialLibraryRegions() {
#ifdef SEWN_HAVE_OPENMP
  if (saved_ >= 0) omp_set_max_active_levels(saved_);
#endif
}

int library_team_size(int requested) {
  int team = 1;
#ifdef SEWN_HAVE_OPENMP
#pragma omp parallel num_threads(requested)
  {
#pragma omp single
    team = omp_get_num_threads();
  }
#else
  (void)requested;
#endif
  return team;
}

}  // namespace sewn::physics
