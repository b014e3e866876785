#pragma once
// The harness every benchmark suite shares (it also provides main()).
//
// Naming is the contract with bench/report.py: a benchmark is "<suite>/<case>/ours" or
// "<suite>/<case>/peer", where <case> may contain slashes ("hex32/build"). The report pairs the
// two sides of a case and prints one row per metric: the time (in the benchmark's time unit),
// then one row per user counter, the counter's name being the metric ("bytes/dart"). Lower is
// better unless the metric's name says "higher is better". A peer benchmark carries the peer's
// name as its label. Sizes come from the scale (SEWN_BENCH_SCALE), so a suite registers its
// benchmarks from a Registration, run by main() once the scale is known.

#include <benchmark/benchmark.h>

#include <functional>
#include <string>
#include <string_view>

namespace sewn::bench {

/// smoke: tiny cases that only prove the code runs (CI); small: quick, human-sized cases;
/// full: the sizes the suite's issue asks for, the ones in bench/results.
enum class Scale { smoke, small, full };

/// The scale named by the environment variable SEWN_BENCH_SCALE (default full). main() exits
/// with a message on any other value, before any benchmark runs.
Scale scale();
const char* to_string(Scale s);

using Body = std::function<void(benchmark::State&)>;

/// Registers "<suite>/<case_name>/ours", timed in milliseconds (change it on the result).
benchmark::internal::Benchmark* ours(std::string_view suite, std::string_view case_name, Body body);
/// Registers "<suite>/<case_name>/peer", labelled peer_name, timed in milliseconds.
benchmark::internal::Benchmark* peer(std::string_view suite, std::string_view case_name, std::string peer_name,
                                     Body body);

/// A registration function run by main(): `const sewn::bench::Registration reg(&register_all);`
/// at namespace scope in any translation unit of a suite.
class Registration {
 public:
  explicit Registration(void (*fn)());
};

/// True the first time it is called with `key` in this process. For correctness checks too
/// slow to repeat in every run of a benchmark (one per case is enough: operations are
/// deterministic, and a failed check fails the whole report).
bool first_time(const std::string& key);

/// Pauses the benchmark's clock for its lifetime: setup and teardown inside the timed loop.
/// Costs two clock reads on each side, so use it only around work much longer than that.
class Untimed {
 public:
  explicit Untimed(benchmark::State& s) : state_(s) { state_.PauseTiming(); }
  ~Untimed() { state_.ResumeTiming(); }
  Untimed(const Untimed&) = delete;
  Untimed& operator=(const Untimed&) = delete;

 private:
  benchmark::State& state_;
};

}  // namespace sewn::bench
