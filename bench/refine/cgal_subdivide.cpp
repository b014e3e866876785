// bench_refine, CGAL's side: the 1:8 subdivision of every hexahedron of a Table 1 beam done with
// the insertion operations of CGAL's Linear_cell_complex_for_combinatorial_map<3>, as the 2014
// paper built its subdivision (seed 001 §5). Written from CGAL's documented LCC API only
// (insert_barycenter_in_cell<1>, insert_cell_1_in_cell_2, insert_cell_2_in_cell_3, beta).
//
// The subdivision, in three passes over the map (each shared cell split once):
//   1. every edge split at its midpoint (insert_barycenter_in_cell<1>);
//   2. every face, now an 8-gon corner/midpoint/corner..., cut into 4 quads: an edge between two
//      opposite midpoints, its midpoint inserted (the face centre), the centre joined to the two
//      other midpoints (a 3-sewn face is split on both sides by each insertion);
//   3. every volume cut by its three middle planes, each plane a closed path of darts walked on
//      the volume's boundary and inserted with insert_cell_2_in_cell_3: the first (an 8-gon
//      through 4 edge midpoints and 4 face centres) is then cut into 4 quads like a face in
//      pass 2 (its centre is the volume's centre); the second cuts each half (a hexagon, split
//      by one edge from the centre), the third each quarter (a quad).
// Every path is found topologically, never by coordinates: on the boundary of a box split into
// quads every vertex of a middle plane's trace has 4 edges, so "straight on" from a dart p is
// β1(β2(β1(p))), and each plane starts at the midpoint of an edge leaving a corner of the box
// (darts keep their source vertex through the insertions, so the corner darts collected before
// pass 1 still leave those corners afterwards).
//
// Ours (refine.cpp) refines the same beam with refine::refine_all, which also builds the
// physics (particles, masses, springs, rest lengths) and the hierarchy; this side builds the
// map and the points only. Both run on a fresh copy of the beam made with the clock paused.
#include <CGAL/Linear_cell_complex_for_combinatorial_map.h>
#include <CGAL/Linear_cell_complex_incremental_builder.h>
#include <CGAL/version.h>

#include <array>
#include <cstdint>
#include <memory>
#include <set>
#include <string>
#include <tuple>
#include <vector>

#include "sewn/cmap/mesh.hpp"
#include "sewn_bench.hpp"
#include "subdivision_cases.hpp"

namespace sewn::bench::refine_suite::cgal {
namespace {

using Lcc = CGAL::Linear_cell_complex_for_combinatorial_map<3>;
using Dart = Lcc::Dart_handle;

Lcc build(const IndexedMesh& mesh) {
  Lcc lcc;
  CGAL::Linear_cell_complex_incremental_builder_3<Lcc> builder(lcc);
  for (const Point3& p : mesh.points) builder.add_vertex(Lcc::Point(p[0], p[1], p[2]));
  for (std::uint32_t c = 0; c < mesh.num_cells(); ++c) {
    builder.begin_surface();
    for (auto face : cell_faces(mesh.types[c])) {
      builder.begin_facet();
      for (std::uint32_t l : face) builder.add_vertex_to_facet(mesh.cell(c)[l]);
      builder.end_facet();
    }
    builder.end_surface();
  }
  return lcc;
}

Dart b1(Lcc& l, Dart d) { return l.beta<1>(d); }
Dart b2(Lcc& l, Dart d) { return l.beta<2>(d); }
Dart b0(Lcc& l, Dart d) { return l.beta<0>(d); }
// The next dart leaving d's source in d's volume, turning about that vertex.
Dart turn(Lcc& l, Dart d) { return b1(l, b2(l, d)); }
// The dart continuing p straight on through p's target (a vertex of 4 edges on the boundary).
Dart straight(Lcc& l, Dart p) { return b1(l, b2(l, b1(l, p))); }

// An 8-gon whose dart d leaves a "corner" (corner, middle, corner, ... around it) cut into 4
// quads through a new centre.
void split_in_four(Lcc& l, Dart d) {
  const Dart a = b1(l, d), b = b1(l, b1(l, b1(l, b1(l, a))));
  l.insert_barycenter_in_cell<1>(l.insert_cell_1_in_cell_2(a, b));
  l.insert_cell_1_in_cell_2(b0(l, a), b1(l, b1(l, a)));
  l.insert_cell_1_in_cell_2(b0(l, b), b1(l, b1(l, b)));
}

// Inserts the face along the straight path that starts with p0 and closes on p0's source.
std::vector<Dart> insert_plane(Lcc& l, Dart p0) {
  std::vector<Dart> path{p0};
  while (l.vertex_attribute(l.other_extremity(path.back())) != l.vertex_attribute(p0) && path.size() < 8)
    path.push_back(straight(l, path.back()));  // at most 8 darts: check() catches a wrong walk
  l.insert_cell_2_in_cell_3(path.begin(), path.end());
  return path;
}

// The darts of one hexahedron a pass 3 needs, taken before pass 1: x leaves corner c0 along
// edge e; from the face of x, y leaves e's other end; from the face of β2(x), a1 and a2 leave
// the two corners of that face away from c0's edge e (see the header comment).
struct Hex {
  Dart x, y, a1, a2;
};

void split_volume(Lcc& l, const Hex& h) {
  // the darts leaving a corner of each half and quarter along the next plane's axis, taken
  // before any plane is inserted (they turn about corners, across the hexahedron's own edges);
  // both halves' darts lie in the face of β2(x), whose centre is on the first plane, so that
  // their paths meet the centre and the opposite face centre at the same places (p[1], p[4])
  const Dart half_low = turn(l, h.x), half_high = h.a2;
  const std::array<Dart, 4> quarter{turn(l, half_low), h.y, turn(l, h.a1), turn(l, h.a2)};
  const std::vector<Dart> first = insert_plane(l, b1(l, h.x));
  split_in_four(l, b2(l, first.back()));
  for (Dart axis : {half_low, half_high}) {
    const std::vector<Dart> p = insert_plane(l, b1(l, axis));
    l.insert_cell_1_in_cell_2(b2(l, p[1]), b2(l, p[4]));
  }
  for (Dart axis : quarter) (void)insert_plane(l, b1(l, axis));
}

void subdivide(Lcc& l) {
  std::vector<Hex> hexes;
  for (auto& v : l.one_dart_per_cell<3>()) {
    const Dart x = l.darts().iterator_to(v), w = b2(l, x);
    hexes.push_back({x, b1(l, x), b1(l, b1(l, w)), b1(l, b1(l, b1(l, w)))});
  }
  std::vector<Dart> faces, edges;
  for (auto& f : l.one_dart_per_cell<2>()) faces.push_back(l.darts().iterator_to(f));
  for (auto& e : l.one_dart_per_cell<1>()) edges.push_back(l.darts().iterator_to(e));
  for (Dart e : edges) l.insert_barycenter_in_cell<1>(e);
  for (Dart f : faces) split_in_four(l, f);
  for (const Hex& h : hexes) split_volume(l, h);
}

// Empty if the subdivided beam is the fine grid: a valid map with the fine grid's cell counts,
// 24 darts (6 quads) per volume and one vertex per fine grid point.
std::string check(const Lcc& l, std::uint32_t fine) {
  if (!l.is_valid()) return "is_valid() is false";
  const std::uint64_t nx = 2 * fine, ny = fine, nz = fine;
  const std::array<std::uint64_t, 4> want{(nx + 1) * (ny + 1) * (nz + 1),
                                          nx * (ny + 1) * (nz + 1) + (nx + 1) * ny * (nz + 1) + (nx + 1) * (ny + 1) * nz,
                                          nx * ny * (nz + 1) + nx * (ny + 1) * nz + (nx + 1) * ny * nz, nx * ny * nz};
  const std::vector<unsigned> got = l.count_all_cells();
  for (std::size_t i = 0; i < 4; ++i)
    if (got[i] != want[i])
      return std::to_string(i) + "-cells: expected " + std::to_string(want[i]) + ", got " + std::to_string(got[i]);
  if (l.number_of_darts() != 24 * want[3]) return "not 24 darts per volume: " + std::to_string(l.number_of_darts());
  std::set<std::tuple<double, double, double>> points;
  for (auto& v : l.one_dart_per_cell<0>()) {
    const Lcc::Point& p = l.point(l.darts().iterator_to(v));
    points.emplace(p.x(), p.y(), p.z());
  }
  if (points.size() != want[0]) return "vertices at " + std::to_string(points.size()) + " distinct points";
  return {};
}

void bench_subdivide(benchmark::State& st, const SubdivisionCase& c) {
  const Lcc proto = build(beam_mesh(c.refined));
  std::unique_ptr<Lcc> work;
  for (auto _ : st) {
    {
      const Untimed pause(st);
      work = std::make_unique<Lcc>(proto);
    }
    subdivide(*work);
  }
  st.counters["hexahedra"] = static_cast<double>(work->one_dart_per_cell<3>().size());
  if (first_time("subdivision/peer/" + c.name))
    if (std::string e = check(*work, 2u << c.refined); !e.empty()) st.SkipWithError(("CGAL subdivision: " + e).c_str());
}

void register_peer() {
  // the same peer twice: against refine_all (all/<beam>, ours with the physics) and against our
  // map alone (map/<beam>, map_subdivide.cpp: the map and its points, by the batch pass)
  for (const SubdivisionCase& c : subdivision_cases())
    for (const std::string against : {"all/", "map/"})
      peer("refine", "subdivision/" + against + c.name.substr(c.name.find('/') + 1),
           "CGAL " CGAL_VERSION_STR " Linear_cell_complex_for_combinatorial_map<3>",
           [c](benchmark::State& st) { bench_subdivide(st, c); });
}

const Registration reg(&register_peer);

}  // namespace
}  // namespace sewn::bench::refine_suite::cgal
