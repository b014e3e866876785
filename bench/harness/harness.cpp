#include <cstdio>
#include <cstdlib>
#include <set>
#include <string>
#include <vector>

#include "sewn/physics/solve/blas_kernels.hpp"
#include "sewn_bench.hpp"

namespace sewn::bench {

namespace {

std::vector<void (*)()>& registrations() {
  static std::vector<void (*)()> fns;
  return fns;
}

benchmark::internal::Benchmark* add(std::string_view suite, std::string_view case_name, const char* side,
                                    Body body) {
  std::string name;
  name.append(suite).append("/").append(case_name).append("/").append(side);
  return benchmark::RegisterBenchmark(name.c_str(), std::move(body))->Unit(benchmark::kMillisecond);
}

}  // namespace

Scale scale() {
  const char* s = std::getenv("SEWN_BENCH_SCALE");
  if (s == nullptr || std::string_view(s) == "full" || *s == '\0') return Scale::full;
  if (std::string_view(s) == "small") return Scale::small;
  if (std::string_view(s) == "smoke") return Scale::smoke;
  std::fprintf(stderr, "SEWN_BENCH_SCALE=%s: expected smoke, small or full\n", s);
  std::exit(2);
}

const char* to_string(Scale s) {
  switch (s) {
    case Scale::smoke: return "smoke";
    case Scale::small: return "small";
    case Scale::full: return "full";
  }
  return "?";
}

benchmark::internal::Benchmark* ours(std::string_view suite, std::string_view case_name, Body body) {
  return add(suite, case_name, "ours", std::move(body));
}

benchmark::internal::Benchmark* peer(std::string_view suite, std::string_view case_name, std::string peer_name,
                                     Body body) {
  // The label is set after the body so that a body cannot overwrite the peer's name.
  return add(suite, case_name, "peer", [body = std::move(body), peer_name = std::move(peer_name)](benchmark::State& s) {
    body(s);
    s.SetLabel(peer_name);
  });
}

Registration::Registration(void (*fn)()) { registrations().push_back(fn); }

bool first_time(const std::string& key) {
  static std::set<std::string> seen;
  return seen.insert(key).second;
}

}  // namespace sewn::bench

int main(int argc, char** argv) {
  // the kernels `sewn run` factors with (blas_kernels.hpp), so the reports measure what it gets
  sewn::physics::solve::restart_with_cpu_kernels(argv);
  const sewn::bench::Scale scale = sewn::bench::scale();
  benchmark::AddCustomContext("sewn_build", SEWN_BENCH_BUILD);
  if (const std::string kernels = sewn::physics::solve::openblas_kernels(); !kernels.empty())
    benchmark::AddCustomContext("sewn_blas", "OpenBLAS, " + kernels + " kernels");
  benchmark::AddCustomContext("sewn_scale", sewn::bench::to_string(scale));
  for (auto fn : sewn::bench::registrations()) fn();
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
