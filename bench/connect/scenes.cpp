// bench_connect's scene rows: the 2019 paper's Table 1 scenes (scenes/s04_*.json), each run by
// the scene runner (app::run, what `sewn run` does) over the scene's whole duration (small and
// smoke scales: its first frames), single thread and on 2 threads.
//
//   connect/scenes/<scene>/ours            1 thread: counters "s/frame" (the steps' wall time
//                                           per 1/30 s of simulated time), "CPU s/frame" (their
//                                           process CPU time: on a busy machine, the work alone),
//                                           "h (ms)", the Newton and CG iterations per frame
//   connect/scenes/<scene>/2_threads/ours  the same on 2 threads (the solver's multi-core path)
//
// The paper gives no frame rate or time step; a frame is taken as 1/30 s (bench/connect/notes.md).
// Each repetition loads the scene and runs it from rest; only the steps are timed (the
// summary's `stepping`), assembly and output are not. The published times are Table 1's totals
// over its frame counts, whole animations: the full scale likewise averages over the whole run,
// not over its first frames, whose start from rest costs the most Newton iterations.

#include <exception>
#include <filesystem>
#include <string>
#include <unistd.h>

#include "sewn/apps/runner.hpp"
#include "sewn/apps/scene.hpp"
#include "sewn_bench.hpp"

namespace sewn::bench::connect_scenes {

namespace {

constexpr const char* suite = "connect";
constexpr double frame = 1.0 / 30;

// frames: how many 1/30 s frames to run, 0 for the scene's whole duration.
void run_scene(benchmark::State& st, const std::string& name, std::uint32_t threads, std::uint32_t frames) {
  app::Scene scene = app::load_scene(std::string(SEWN_SOURCE_DIR) + "/scenes/s04_" + name + ".json");
  scene.threads = threads;
  scene.write_picture = false;
  scene.write_vtu = false;
  scene.write_csv = false;
  app::RunOptions opt;
  opt.out = std::filesystem::temp_directory_path() / ("sewn_bench_connect_" + std::to_string(::getpid()) + "_" + name);
  opt.frames = 1;
  if (frames > 0) opt.until = frames * frame;
  opt.quiet = true;
  app::RunSummary sum;
  double stepping = 0, stepping_cpu = 0;
  bool failed = false;
  for (auto _ : st) {
    try {
      sum = app::run(scene, opt);
    } catch (const std::exception& e) {  // a step Newton could not converge: no number for this row
      st.SkipWithError(e.what());
      failed = true;
      break;
    }
    stepping += sum.stepping;
    stepping_cpu += sum.stepping_cpu;
  }
  std::filesystem::remove_all(opt.out);
  if (failed) return;
  const double runs = static_cast<double>(st.iterations());
  const double per_run = sum.simulated / frame;  // frames simulated per run
  st.counters["s/frame"] = stepping / runs / per_run;
  st.counters["CPU s/frame"] = stepping_cpu / runs / per_run;
  st.counters["h (ms)"] = scene.step * 1e3;
  st.counters["Newton tolerance (m/s)"] = scene.newton_tolerance;
  st.counters["Newton iterations/frame"] = static_cast<double>(sum.newton_iterations) / per_run;
  st.counters["CG iterations/frame"] = static_cast<double>(sum.linear_iterations) / per_run;
  st.counters["threads"] = threads;
}

void register_all() {
  const Scale sc = scale();
  // frames per run: the whole scene at full scale; the first frames only at the quick scales
  const std::uint32_t frames = sc == Scale::smoke ? 1 : sc == Scale::small ? 2 : 0;
  for (const char* name : {"frisbee", "sticky_hands", "toy_ball", "sandwich", "jellyfish", "umbrella", "toy_tunnel", "anglerfish"}) {
    if (sc == Scale::smoke && std::string(name) != "frisbee") continue;
    for (const std::uint32_t threads : {1u, 2u}) {
      const std::string c = std::string("scenes/") + name + (threads == 2 ? "/2_threads" : "");
      ours(suite, c, [name = std::string(name), threads, frames](benchmark::State& st) { run_scene(st, name, threads, frames); })
          ->Iterations(1)
          ->UseRealTime()
          ->Unit(benchmark::kSecond);
    }
  }
}

const Registration reg(&register_all);

}  // namespace

}  // namespace sewn::bench::connect_scenes
