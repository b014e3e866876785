// What the divergence watchdog costs (issue 17): the SOFA mesh (8×8×10 hexahedra, bottom face
// clamped, the paper's viscosity) stepped semi-implicitly at 0.9× its stable-step bound, so
// that the run is a usable simulation and the watchdog never fires. "ours" runs the library's
// default health checks (finite check, energy check every 100 steps and whenever the fastest
// velocity component has grown by √2 since the last check); the peer runs the same integrator
// with the energy checks off (finite check kept), so the ratio is the watchdog's whole cost.
// Both restart from rest every 10 000 steps (untimed), so every repetition times the same motion:
// the release and sag of the beam under gravity.
//
//   hard/watchdog/sofa_8x8x10/semi_implicit/{ours,peer}
//   hard/inversion_count/sofa_8x8x10/{ours,peer}   counting inverted elements / one step

#include <benchmark/benchmark.h>

#include <memory>
#include <string>

#include "model.hpp"
#include "ours.hpp"
#include "sewn_bench.hpp"
#include "sewn/physics/solids/inversion.hpp"

namespace sewn::bench::mss {

namespace {

constexpr int restart = 10000;

struct Watched {
  std::unique_ptr<Ours> model;
  double h = 0;
};

Watched& beam() {
  static Watched w = [] {
    ModelSpec s;
    s.name = scale() == Scale::smoke ? "2x2x3 hexahedra" : "8x8x10 hexahedra";
    GridSpec g;
    g.spacing = {0.0125, 0.0125, 0.0125};
    s.mesh = scale() == Scale::smoke ? hex_grid(2, 2, 3, g) : hex_grid(8, 8, 10, g);
    clamp_plane(s, 2, 0.0);
    Watched out;
    out.model = std::make_unique<Ours>(s);
    out.model->save();
    out.h = 0.9 * out.model->system().stable_step().h_max;
    return out;
  }();
  return w;
}

void run(benchmark::State& st, bool watch) {
  Watched& w = beam();
  physics::SymplecticEulerOptions o;
  o.enforce_stable_step = false;  // h is below the bound; the refusal's own re-checks are not the watchdog's cost
  if (!watch) o.health.energy_check_interval = 0;
  w.model->restore();
  physics::SymplecticEuler se(o);
  int k = 0;
  for (auto _ : st) {
    (void)se.step(w.model->system(), w.h);
    if (++k == restart) {
      const Untimed untimed(st);
      w.model->restore();
      se.reset();
      k = 0;
    }
  }
  w.model->restore();
  st.counters["_h"] = w.h;
}

// What counting inverted elements costs, against one semi-implicit step of the same mesh at
// rest (the peer): the ratio is the count's cost in steps.
void inversion(benchmark::State& st, bool count) {
  Watched& w = beam();
  w.model->restore();
  physics::SymplecticEulerOptions o;
  o.enforce_stable_step = false;
  o.health.energy_check_interval = 0;
  physics::SymplecticEuler se(o);
  physics::InversionMonitor monitor;
  for (auto _ : st) {
    if (count) {
      benchmark::DoNotOptimize(monitor.count(w.model->model()).elements);
    } else {
      (void)se.step(w.model->system(), w.h);  // below the bound: stable, no restart needed
    }
  }
  w.model->restore();
}

void register_watchdog() {
  const std::string inv = scale() == Scale::smoke ? "inversion_count/sofa_2x2x3" : "inversion_count/sofa_8x8x10";
  ours("hard", inv, [](benchmark::State& st) { inversion(st, true); })->Unit(benchmark::kMicrosecond);
  peer("hard", inv, "one semi-implicit step", [](benchmark::State& st) { inversion(st, false); })->Unit(benchmark::kMicrosecond);
  const std::string name = scale() == Scale::smoke ? "watchdog/sofa_2x2x3/semi_implicit" : "watchdog/sofa_8x8x10/semi_implicit";
  ours("hard", name, [](benchmark::State& st) { run(st, true); })->Unit(benchmark::kMicrosecond);
  peer("hard", name, "no energy checks", [](benchmark::State& st) { run(st, false); })->Unit(benchmark::kMicrosecond);
}

const Registration watchdog_registration(&register_watchdog);

}  // namespace

}  // namespace sewn::bench::mss
