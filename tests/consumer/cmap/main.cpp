// The map taken alone by an outside project: a hexahedral grid built into a 3-map with a
// per-vertex attribute, one face unsewn, checked by validate() and by its cell counts.
#include <cstdint>
#include <cstdio>

#include "sewn/cmap/build.hpp"
#include "sewn/cmap/cmap.hpp"

int main() {
  sewn::CMap<3, std::uint32_t> map;
  const auto built = sewn::build(map, sewn::hex_grid(2, 1, 1));
  map.create_attributes<0>([&](sewn::Dart d) { return built.vertex_of_dart[d.index()]; });
  // the one face between the two cubes: the only 3-sewn darts
  sewn::Dart inner;
  for (sewn::Dart d : map.darts())
    if (map.beta(d, 3)) inner = d;
  map.unsew<3>(inner);
  const auto report = map.validate();
  const auto n = map.count_all();
  std::printf("consumer_cmap: %u vertices, %u edges, %u faces, %u volumes, %u components; %s\n", n[0], n[1], n[2], n[3],
              map.count_components(), report.ok() ? "valid" : report.str().c_str());
  // unsewing splits the shared face and its vertices and edges: two free cubes
  return report.ok() && n[0] == 16 && n[1] == 24 && n[2] == 12 && n[3] == 2 && map.count_components() == 2 ? 0 : 1;
}
