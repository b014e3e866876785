// The cmap suite, topology invariants (cmap/topology.hpp): Betti numbers over Z/2 and
// orientability, with the boundary, of hexahedral grids and of tetrahedral grids (6 tetrahedra
// per cube) at three sizes each, up to ~10^6 darts. The goal (issue 18) is ≤ 1 s per 10^6 darts
// on one core and linear growth; each case reports its time per 10^6 darts. No CGAL twin: CGAL
// computes no homology of a map.

#include <map>
#include <memory>

#include "grids.hpp"
#include "sewn/cmap/build.hpp"
#include "sewn/cmap/cmap.hpp"
#include "sewn/cmap/topology.hpp"

namespace sewn::bench::cmap {
namespace {

std::vector<std::uint32_t> topo_hex_sizes(Scale s) {
  switch (s) {
    case Scale::smoke: return {3};
    case Scale::small: return {8, 16};
    case Scale::full: return {8, 16, 32};
  }
  return {};
}
// 72 darts per cube: 24³ cubes make 995 328 darts
std::vector<std::uint32_t> topo_tet_sizes(Scale s) {
  switch (s) {
    case Scale::smoke: return {2};
    case Scale::small: return {8, 12};
    case Scale::full: return {12, 17, 24};
  }
  return {};
}

template <class Mesh>
void bench_topology(benchmark::State& state, const Mesh& make, const std::string& key) {
  CMap<3> map;
  build(map, make());
  Topology t;
  for (auto _ : state) {
    t = topology(map, {{}, false});
    benchmark::DoNotOptimize(t.total.betti);
  }
  state.counters["darts"] = map.num_darts();
  state.counters["s/1e6 darts"] = benchmark::Counter(map.num_darts() / 1e6, benchmark::Counter::kIsIterationInvariantRate |
                                                                                benchmark::Counter::kInvert);
  // a grid is a ball: one component, nothing else, orientable, one boundary sphere
  if (first_time(key) && (t.total.betti != std::array<std::int64_t, 4>{1, 0, 0, 0} || !t.orientable ||
                          t.boundary.size() != 1 || t.boundary[0].genus != 0))
    state.SkipWithError("the grid's invariants are not those of a ball");
}

void register_topology() {
  for (std::uint32_t n : topo_hex_sizes(scale())) {
    const std::string c = "hex" + std::to_string(n) + "/betti_orientability";
    ours(suite, c, [n, key = c](benchmark::State& s) { bench_topology(s, [n] { return hex_grid(n, n, n); }, key); });
  }
  for (std::uint32_t n : topo_tet_sizes(scale())) {
    const std::string c = "tet" + std::to_string(n) + "/betti_orientability";
    ours(suite, c, [n, key = c](benchmark::State& s) {
      bench_topology(s, [n] { return tet_grid(n, n, n, TetSplit::kuhn6); }, key);
    });
  }
}

const Registration topology_registration(&register_topology);

}  // namespace
}  // namespace sewn::bench::cmap
