// Builds a small hexahedral beam with the installed library and checks it.
#include <cstdio>

#include "sewn/cmap/build.hpp"
#include "sewn/cmap/cmap.hpp"
#include "sewn/io/geometry.hpp"
#include "sewn/io/render.hpp"

int main() {
  sewn::CMap<3, std::uint32_t> map;
  const auto mesh = sewn::hex_grid(3, 2, 2);
  const auto built = sewn::build(map, mesh);
  sewn::io::check_mesh_geometry(mesh, "consumer beam");  // links sewn::io and, through it, cairo
  (void)sewn::io::boundary_faces(sewn::io::CellsView::of(mesh));
  map.create_attributes<0>([&](sewn::Dart d) { return built.vertex_of_dart[d.index()]; });
  const auto report = map.validate();
  const auto n = map.count_all();
  std::printf("consumer: %u vertices, %u edges, %u faces, %u volumes, %s\n", n[0], n[1], n[2], n[3],
              report.ok() ? "valid" : report.str().c_str());
  return report.ok() && n[3] == 12 && n[0] == 36 ? 0 : 1;
}
