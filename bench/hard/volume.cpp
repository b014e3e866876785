// What the volume term costs (issue 17): one linearly implicit step (h = 1 ms) of the SOFA mesh
// (8×8×10 hexahedra of 12.5 mm, bottom face clamped, E = 100 kPa, sagging under gravity) with
// the volume term at κ = 100 E on every hexahedron (ours) against the same step without it
// (peer). Both restart from rest every 1000 steps (untimed), so each repetition times the same
// motion.
//
//   hard/volume_term/sofa_8x8x10/implicit/{ours,peer}

#include <benchmark/benchmark.h>

#include <memory>
#include <string>
#include <vector>

#include "sewn/physics/integrators.hpp"
#include "sewn/physics/mss_model.hpp"
#include "sewn/physics/solids/volume_term.hpp"
#include "sewn_bench.hpp"

namespace sewn::bench::hard {

namespace {

constexpr double young = 1e5;

struct Column {
  std::unique_ptr<physics::MssModel<3>> model;
  std::vector<double> x0;
};

Column make(bool volume) {
  const std::uint32_t nz = scale() == Scale::smoke ? 3 : 10, nxy = scale() == Scale::smoke ? 2 : 8;
  Column c;
  c.model = std::make_unique<physics::MssModel<3>>(hex_grid(nxy, nxy, nz, {{0.0125, 0.0125, 0.0125}, {}}),
                                                   std::vector<physics::MaterialParams>{{young, 0.3, 1000}},
                                                   std::vector<std::uint32_t>{});
  physics::NodeTable& n = c.model->nodes();
  for (physics::Index i = 0; i < n.size(); ++i)
    if (c.model->rest_position(i).z() <= 1e-12) n.fix(i);
  if (volume) (void)physics::solids::add_volume_preservation(*c.model, std::vector<double>{100 * young});
  c.x0.assign(n.x().begin(), n.x().end());
  return c;
}

void rest(Column& c) {
  physics::NodeTable& n = c.model->nodes();
  std::copy(c.x0.begin(), c.x0.end(), n.x().begin());
  std::fill(n.v().begin(), n.v().end(), 0.0);
}

void step(benchmark::State& st, bool volume) {
  static Column with = make(true), without = make(false);
  Column& c = volume ? with : without;
  rest(c);
  physics::LinearlyImplicitEuler euler;
  int k = 0, cg = 0;
  for (auto _ : st) {
    cg += euler.step(c.model->system(), 1e-3).cg_iterations;
    if (++k % 1000 == 0) {
      const Untimed untimed(st);
      rest(c);
      euler.reset();
    }
  }
  st.counters["_cg"] = static_cast<double>(cg) / static_cast<double>(std::max(k, 1));
  rest(c);
}

void register_volume() {
  const std::string name = scale() == Scale::smoke ? "volume_term/sofa_2x2x3/implicit" : "volume_term/sofa_8x8x10/implicit";
  ours("hard", name, [](benchmark::State& st) { step(st, true); })->Unit(benchmark::kMicrosecond);
  peer("hard", name, "no volume term", [](benchmark::State& st) { step(st, false); })->Unit(benchmark::kMicrosecond);
}

const Registration registration(&register_volume);

}  // namespace

}  // namespace sewn::bench::hard
