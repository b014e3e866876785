// bench_refine, the map part of the 1:8 subdivision alone (refine/subdivision/map/<beam>/ours):
// the same three passes as CGAL's side (cgal_subdivide.cpp, whose header describes them) done
// with our map's own insertions (insert_vertex_in_edge with the midpoint as the new vertex's
// point, insert_edge_in_face, insert_face_in_volume) on a CMap<3, Point3>, points only, no
// physics. It is the like-for-like row against CGAL LCC (registered under the same case name
// there); subdivision/all/<beam> is refine_all, which builds the physics and the hierarchy too.
#include <array>
#include <cstdint>
#include <memory>
#include <set>
#include <string>
#include <vector>

#include "sewn/cmap/build.hpp"
#include "sewn/cmap/cmap.hpp"
#include "sewn/cmap/mesh.hpp"
#include "sewn_bench.hpp"
#include "subdivision_cases.hpp"

namespace sewn::bench::refine_suite::map_only {
namespace {

using Map = CMap<3, Point3>;

Map build_beam(const IndexedMesh& mesh, std::vector<Dart>& cell_darts) {
  Map map;
  const BuildResult built = build(map, mesh);
  map.create_attributes<0>([&](Dart d) { return mesh.points[built.vertex_of_dart[d.index()]]; });
  cell_darts = built.cell_dart;
  return map;
}

Dart b0(const Map& m, Dart d) { return m.beta<0>(d); }
Dart b1(const Map& m, Dart d) { return m.beta<1>(d); }
Dart b2(const Map& m, Dart d) { return m.beta<2>(d); }
Dart turn(const Map& m, Dart d) { return b1(m, b2(m, d)); }
Dart straight(const Map& m, Dart p) { return b1(m, b2(m, b1(m, p))); }

const Point3& point(const Map& m, Dart d) { return m.value(m.attribute<0>(d)); }

// The edge of d split at its midpoint.
void split_edge(Map& m, Dart d) {
  const Point3 a = point(m, d), b = point(m, b1(m, d));
  (void)m.insert_vertex_in_edge(d, Point3{(a[0] + b[0]) / 2, (a[1] + b[1]) / 2, (a[2] + b[2]) / 2});
}

// An 8-gon whose dart d leaves a corner (corner, middle, corner, ...) cut into 4 quads through
// a new centre: the middle of the edge between two opposite midpoints.
void split_in_four(Map& m, Dart d) {
  const Dart a = b1(m, d), b = b1(m, b1(m, b1(m, b1(m, a))));
  split_edge(m, m.insert_edge_in_face(a, b));
  (void)m.insert_edge_in_face(b0(m, a), b1(m, b1(m, a)));
  (void)m.insert_edge_in_face(b0(m, b), b1(m, b1(m, b)));
}

// The face along the straight path starting with p0 and closing on p0's source, inserted.
std::vector<Dart> insert_plane(Map& m, Dart p0) {
  std::vector<Dart> path{p0};
  const auto start = m.attribute<0>(p0);
  while (m.attribute<0>(b1(m, path.back())) != start && path.size() < 8) path.push_back(straight(m, path.back()));
  (void)m.insert_face_in_volume(path);
  return path;
}

struct Hex {
  Dart x, y, a1, a2;
};

// As cgal_subdivide.cpp's split_volume: the three middle planes of one hexahedron.
void split_volume(Map& m, const Hex& h) {
  const Dart half_low = turn(m, h.x), half_high = h.a2;
  const std::array<Dart, 4> quarter{turn(m, half_low), h.y, turn(m, h.a1), turn(m, h.a2)};
  const std::vector<Dart> first = insert_plane(m, b1(m, h.x));
  split_in_four(m, b2(m, first.back()));
  for (Dart axis : {half_low, half_high}) {
    const std::vector<Dart> p = insert_plane(m, b1(m, axis));
    (void)m.insert_edge_in_face(b2(m, p[1]), b2(m, p[4]));
  }
  for (Dart axis : quarter) (void)insert_plane(m, b1(m, axis));
}

void subdivide(Map& m, const std::vector<Dart>& cell_darts) {
  std::vector<Hex> hexes;
  hexes.reserve(cell_darts.size());
  for (Dart x : cell_darts) {
    const Dart w = b2(m, x);
    hexes.push_back({x, b1(m, x), b1(m, b1(m, w)), b1(m, b1(m, b1(m, w)))});
  }
  std::vector<Dart> faces, edges;
  for (Dart f : m.cells<2>()) faces.push_back(f);
  for (Dart e : m.cells<1>()) edges.push_back(e);
  for (Dart e : edges) split_edge(m, e);
  for (Dart f : faces) split_in_four(m, f);
  for (const Hex& h : hexes) split_volume(m, h);
}

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
  for (Dart v : m.cells<0>()) points.insert(point(m, v));
  if (points.size() != want[0]) return "vertices at " + std::to_string(points.size()) + " distinct points";
  return {};
}

void bench_subdivide(benchmark::State& st, const SubdivisionCase& c) {
  std::vector<Dart> cell_darts;
  const Map proto = build_beam(beam_mesh(c.refined), cell_darts);
  std::unique_ptr<Map> work;
  for (auto _ : st) {
    {
      const Untimed pause(st);
      work = std::make_unique<Map>(proto);
    }
    subdivide(*work, cell_darts);
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
