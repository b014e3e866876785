// bench_refine, the map part of the 1:8 subdivision alone (refine/subdivision/map/<beam>/ours):
// the same subdivision as CGAL's side (cgal_subdivide.cpp, whose header describes it) on a
// CMap<3, Point3>, points only, no physics, made by the map's batch pass
// (CMap::subdivide_hexahedra: all new darts allocated at once and linked from a per-hexahedron
// table, the map the insertions would make; tests/cmap/test_subdivide_hex.cpp compares the two).
// Registered under the same case name as the CGAL peer; subdivision/all/<beam> is refine_all,
// which builds the physics and the hierarchy too.
#include <array>
#include <cstdint>
#include <memory>
#include <set>
#include <string>

#include "sewn/cmap/build.hpp"
#include "sewn/cmap/cmap.hpp"
#include "sewn/cmap/mesh.hpp"
#include "sewn_bench.hpp"
#include "subdivision_cases.hpp"

namespace sewn::bench::refine_suite::map_only {
namespace {

using Map = CMap<3, Point3>;

Map build_beam(const IndexedMesh& mesh) {
  Map map;
  const BuildResult built = build(map, mesh);
  map.create_attributes<0>([&](Dart d) { return mesh.points[built.vertex_of_dart[d.index()]]; });
  return map;
}

Point3 middle(const Point3& a, const Point3& b) { return {(a[0] + b[0]) / 2, (a[1] + b[1]) / 2, (a[2] + b[2]) / 2}; }

// Empty if the subdivided beam is the fine grid: a valid map with its cell counts, 24 darts per
// volume and one vertex per fine grid point.
std::string check(const Map& m, std::uint32_t fine) {
  if (const auto report = m.validate(); !report.ok()) return report.str(3);
  const std::uint64_t nx = 2 * fine, ny = fine, nz = fine;
  const std::array<std::uint64_t, 4> want{(nx + 1) * (ny + 1) * (nz + 1),
                                          nx * (ny + 1) * (nz + 1) + (nx + 1) * ny * (nz + 1) + (nx + 1) * (ny + 1) * nz,
                                          nx * ny * (nz + 1) + nx * (ny + 1) * nz + (nx + 1) * ny * nz, nx * ny * nz};
  const auto got = m.count_all();
  for (std::size_t i = 0; i < 4; ++i)
    if (got[i] != want[i]) return std::to_string(i) + "-cells: expected " + std::to_string(want[i]) + ", got " + std::to_string(got[i]);
  if (m.num_darts() != 24 * want[3]) return "not 24 darts per volume: " + std::to_string(m.num_darts());
  std::set<Point3> points;
  for (Dart v : m.cells<0>()) points.insert(m.value(m.attribute<0>(v)));
  if (points.size() != want[0]) return "vertices at " + std::to_string(points.size()) + " distinct points";
  return {};
}

void bench_subdivide(benchmark::State& st, const SubdivisionCase& c) {
  const Map proto = build_beam(beam_mesh(c.refined));
  std::unique_ptr<Map> work;
  for (auto _ : st) {
    {
      const Untimed pause(st);
      work = std::make_unique<Map>(proto);
    }
    work->subdivide_hexahedra(middle);
  }
  st.counters["hexahedra"] = static_cast<double>(work->count<3>());
  if (first_time("subdivision/map/" + c.name))
    if (std::string e = check(*work, 2u << c.refined); !e.empty()) st.SkipWithError(("map-only subdivision: " + e).c_str());
}

void register_map_only() {
  for (const SubdivisionCase& c : subdivision_cases())
    ours("refine", "subdivision/map/" + c.name.substr(c.name.find('/') + 1),
         [c](benchmark::State& st) { bench_subdivide(st, c); });
}

const Registration reg(&register_map_only);

}  // namespace
}  // namespace sewn::bench::refine_suite::map_only
