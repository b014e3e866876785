#include "sewn/physics/threads.hpp"

#include <algorithm>
#include <cerrno>
#include <chrono>
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

namespace {
// SEWN_THREADS as first read: its count, or the error to throw at every call. Read once because
// getenv scans the whole environment, and kernels ask for the count several times a step: on a
// one-hexahedron model that was a large share of a sub-microsecond step.
struct EnvCount {
  int count = 1;
  std::string error;
};
const EnvCount& env_count() {
  static const EnvCount once = [] {
    EnvCount e;
    const char* env = std::getenv("SEWN_THREADS");  // NOLINT(concurrency-mt-unsafe): read once, read-only
    if (env == nullptr) return e;
    try {
      e.count = parse_thread_count(env, "SEWN_THREADS");
    } catch (const InputError& x) {
      e.error = x.what();
    }
    return e;
  }();
  return once;
}
}  // namespace

int thread_count() {
  if (chosen > 0) return chosen;
  const EnvCount& e = env_count();
  if (!e.error.empty()) throw InputError(e.error);
  return e.count;
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
using pacing_clock = std::chrono::steady_clock;
thread_local std::uint64_t split = 0;
// Back-off of the calling thread's regions: none forks before next_try while wait_s > 0. A late
// team is the machine's state, not one kernel's, so one late region holds back every kernel.
thread_local double wait_s = 0.0;
thread_local pacing_clock::time_point next_try{};
// A late region loses about a time slice of the late thread (milliseconds, against tens of
// microseconds of work): waiting 50 times what it lost keeps the tries under 2 % of the time
// on a machine that stays loaded; doubling after each late try, up to 2 s, and forgetting it
// after an on-time one, a run forks again within seconds of the load going.
constexpr double wait_per_lost = 50.0, max_wait_s = 2.0;
// Only a loss of the order of a time slice means the team came late. A fork and join costs
// microseconds: a small region that loses that much on a quiet machine must not stop every
// kernel of the thread from forking (that took 32^3 semi-implicit at 2 threads from 1.3x to
// 0.9x of one thread).
constexpr double late_loss_s = 250e-6;
}  // namespace

std::uint64_t split_regions() { return split; }

bool detail::fork_next_region() {
  ++split;
#ifdef SEWN_HAVE_OPENMP
  return wait_s == 0.0 || pacing_clock::now() >= next_try;
#else
  return false;
#endif
}

void detail::region_done(double region_s, double serial_s) {
  if (region_s - serial_s < late_loss_s) {
    wait_s = 0.0;
    return;
  }
  wait_s = std::min(std::max(2.0 * wait_s, wait_per_lost * (region_s - serial_s)), max_wait_s);
  next_try = pacing_clock::now() + std::chrono::duration_cast<pacing_clock::duration>(std::chrono::duration<double>(wait_s));
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
