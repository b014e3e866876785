// subdivide_hexahedra (the batch 1:8 pass) must make the map the insertion operations make:
// every edge split, every face cut in 4, every volume cut by its three middle planes, done here
// operation by operation as the CGAL-LCC peer of bench/refine does it. The two are compared up
// to dart numbering (an isomorphism matching β0..β3, free links and vertices, with their points),
// on seeded random voxel shapes with perturbed points, refined once and twice, with and without
// erased dart slots to reuse. Bad input is refused with the map unchanged.
#include <doctest/doctest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <map>
#include <optional>
#include <random>
#include <span>
#include <string>
#include <unordered_map>
#include <vector>

#include "sewn/cmap/build.hpp"
#include "sewn/cmap/cmap.hpp"
#include "sewn/cmap/mesh.hpp"

namespace test_subdivide_hex {
namespace {

using sewn::Dart;
using sewn::Point3;
using Map = sewn::CMap<3, Point3>;

Point3 mid(const Point3& a, const Point3& b) { return {(a[0] + b[0]) / 2, (a[1] + b[1]) / 2, (a[2] + b[2]) / 2}; }

Map build_map(const sewn::IndexedMesh& mesh) {
  Map map;
  const sewn::BuildResult built = sewn::build(map, mesh);
  map.create_attributes<0>([&](Dart d) { return mesh.points[built.vertex_of_dart[d.index()]]; });
  return map;
}

// ---- the operation-by-operation path (the walks of bench/refine's CGAL peer, on our map)
Dart b0(const Map& m, Dart d) { return m.beta<0>(d); }
Dart b1(const Map& m, Dart d) { return m.beta<1>(d); }
Dart b2(const Map& m, Dart d) { return m.beta<2>(d); }
Dart turn(const Map& m, Dart d) { return b1(m, b2(m, d)); }
Dart straight(const Map& m, Dart p) { return b1(m, b2(m, b1(m, p))); }
const Point3& point(const Map& m, Dart d) { return m.value(m.attribute<0>(d)); }

void split_edge(Map& m, Dart d) { (void)m.insert_vertex_in_edge(d, mid(point(m, d), point(m, b1(m, d)))); }

void split_in_four(Map& m, Dart d) {
  const Dart a = b1(m, d), b = b1(m, b1(m, b1(m, b1(m, a))));
  split_edge(m, m.insert_edge_in_face(a, b));
  (void)m.insert_edge_in_face(b0(m, a), b1(m, b1(m, a)));
  (void)m.insert_edge_in_face(b0(m, b), b1(m, b1(m, b)));
}

std::vector<Dart> insert_plane(Map& m, Dart p0) {
  std::vector<Dart> path{p0};
  const auto start = m.attribute<0>(p0);
  while (m.attribute<0>(b1(m, path.back())) != start && path.size() < 8) path.push_back(straight(m, path.back()));
  (void)m.insert_face_in_volume(path);
  return path;
}

void subdivide_by_insertions(Map& m) {
  struct Hex {
    Dart x, y, a1, a2;
  };
  std::vector<Hex> hexes;
  for (Dart x : m.cells<3>()) {
    const Dart w = b2(m, x);
    hexes.push_back({x, b1(m, x), b1(m, b1(m, w)), b1(m, b1(m, b1(m, w)))});
  }
  std::vector<Dart> faces, edges;
  for (Dart f : m.cells<2>()) faces.push_back(f);
  for (Dart e : m.cells<1>()) edges.push_back(e);
  for (Dart e : edges) split_edge(m, e);
  for (Dart f : faces) split_in_four(m, f);
  for (const Hex& h : hexes) {
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
}

// ---- isomorphism up to dart numbering
bool near(const Point3& a, const Point3& b) {
  for (std::size_t i = 0; i < 3; ++i)
    if (std::abs(a[i] - b[i]) > 1e-12 * (1 + std::abs(a[i]))) return false;
  return true;
}

// Extends the matching a0 -> b0 over a0's component; false (and the tentative pairs undone) at
// the first β link, free link, point or vertex that differs.
bool match_component(const Map& a, const Map& b, Dart a0, Dart b0d, std::vector<std::uint32_t>& to_b,
                     std::vector<std::uint32_t>& to_a, std::unordered_map<std::uint32_t, std::uint32_t>& vertex) {
  std::vector<std::pair<Dart, Dart>> stack, made;
  auto undo = [&] {
    for (auto [x, y] : made) to_b[x.index()] = to_a[y.index()] = Dart::null_index;
    return false;
  };
  auto pair = [&](Dart x, Dart y) {
    if (x.is_null() != y.is_null()) return false;
    if (x.is_null()) return true;
    if (to_b[x.index()] != Dart::null_index || to_a[y.index()] != Dart::null_index)
      return to_b[x.index()] == y.index();
    if (!near(point(a, x), point(b, y))) return false;
    to_b[x.index()] = y.index();
    to_a[y.index()] = x.index();
    made.emplace_back(x, y);
    stack.emplace_back(x, y);
    return true;
  };
  if (!pair(a0, b0d)) return false;
  while (!stack.empty()) {
    const auto [x, y] = stack.back();
    stack.pop_back();
    for (int i = 0; i <= 3; ++i)
      if (!pair(a.beta(x, i), b.beta(y, i))) return undo();
  }
  // same vertices: a's vertex attributes correspond one to one with b's
  for (auto [x, y] : made) {
    const auto [it, fresh] = vertex.emplace(a.attribute<0>(x).index(), b.attribute<0>(y).index());
    if (!fresh && it->second != b.attribute<0>(y).index()) return undo();
  }
  return true;
}

std::string isomorphism_problem(const Map& a, const Map& b) {
  if (a.num_darts() != b.num_darts()) return "dart counts differ";
  if (a.count_all() != b.count_all()) return "cell counts differ";
  std::vector<std::uint32_t> to_b(a.dart_capacity(), Dart::null_index), to_a(b.dart_capacity(), Dart::null_index);
  std::unordered_map<std::uint32_t, std::uint32_t> vertex;
  for (Dart x : a.darts()) {
    if (to_b[x.index()] != Dart::null_index) continue;
    bool found = false;
    for (Dart y : b.darts())
      if (to_a[y.index()] == Dart::null_index && near(point(a, x), point(b, y)) &&
          near(point(a, b1(a, x)), point(b, b1(b, y))) && match_component(a, b, x, y, to_b, to_a, vertex)) {
        found = true;
        break;
      }
    if (!found) return "no image for the component of dart " + std::to_string(x.index());
  }
  std::vector<std::uint32_t> images;
  for (const auto& kv : vertex) images.push_back(kv.second);
  std::sort(images.begin(), images.end());
  if (std::adjacent_find(images.begin(), images.end()) != images.end()) return "two vertices map to one";
  return {};
}

// A seeded voxel shape: a few random lattice boxes, points moved off the lattice.
sewn::IndexedMesh random_shape(std::mt19937& rng) {
  std::uniform_int_distribution<int> lo(0, 2), len(1, 2), count(1, 3);
  std::vector<sewn::LatticeBox> boxes(static_cast<std::size_t>(count(rng)));
  for (auto& box : boxes)
    for (std::size_t a = 0; a < 3; ++a) {
      box.lo[a] = lo(rng);
      box.hi[a] = box.lo[a] + len(rng);
    }
  sewn::IndexedMesh mesh = sewn::box_union(boxes);
  std::uniform_real_distribution<double> jitter(-0.2, 0.2);
  for (Point3& p : mesh.points)
    for (double& c : p) c += jitter(rng);
  return mesh;
}

void make_holes(Map& m, int n) {
  std::vector<Dart> made;
  for (int k = 0; k < n; ++k) made.push_back(m.create_dart());
  for (Dart d : made) m.erase_dart(d);
}

TEST_CASE("subdivide_hexahedra makes the map the insertion operations make") {
  for (std::uint32_t seed = 1; seed <= 12; ++seed) {
    CAPTURE(seed);
    std::mt19937 rng(seed);
    const sewn::IndexedMesh mesh = random_shape(rng);
    Map ops = build_map(mesh), batch = build_map(mesh);
    const bool holes = seed % 3 == 0;  // erased slots: the new darts reuse them first
    const int passes = seed % 2 == 0 ? 2 : 1;
    for (int pass = 0; pass < passes; ++pass) {
      CAPTURE(pass);
      const auto hexes = batch.count<3>();
      if (holes) make_holes(batch, 37);
      subdivide_by_insertions(ops);
      batch.subdivide_hexahedra(mid);
      REQUIRE(ops.validate().ok());
      const auto report = batch.validate();
      REQUIRE_MESSAGE(report.ok(), report.str(3));
      CHECK(batch.count<3>() == 8 * hexes);
      CHECK(batch.num_darts() == 8 * 24 * hexes);
      const std::string problem = isomorphism_problem(ops, batch);
      CHECK_MESSAGE(problem.empty(), problem);
    }
  }
}

TEST_CASE("subdivide_hexahedra keeps the darts it had: each starts the first half of its edge") {
  Map m = build_map(sewn::hex_grid(2, 1, 1));
  std::vector<std::pair<Dart, Point3>> before;
  for (Dart d : m.darts()) before.emplace_back(d, mid(point(m, d), point(m, b1(m, d))));
  m.subdivide_hexahedra(mid);
  for (const auto& [d, middle] : before) CHECK(point(m, b1(m, d)) == middle);
}

TEST_CASE("subdivide_hexahedra with edge and volume attributes: every fine cell gets its own, from its parent's") {
  using Full = sewn::CMap<3, Point3, long, int, long>;  // faces carry none: none is made for them
  for (int erased : {0, 1}) {
    CAPTURE(erased);
    Full m;
    const sewn::IndexedMesh mesh = sewn::hex_grid(2, 2, 1);
    const sewn::BuildResult built = sewn::build(m, mesh);
    m.create_attributes<0>([&](Dart d) { return mesh.points[built.vertex_of_dart[d.index()]]; });
    if (erased == 1) m.erase_dart(m.create_dart());  // a free slot for the pass to reuse
    long next = 0;
    (void)m.create_attributes<1>([&](Dart) { return 100 * ++next; });
    (void)m.create_attributes<3>([&](Dart) { return 1000 * ++next; });
    const std::uint32_t edges0 = m.num_attributes<1>(), volumes0 = m.num_attributes<3>();
    std::map<long, Dart> recorded;  // each parent edge's value and the dart its attribute records
    for (auto a : m.attributes<1>()) recorded[m.value(a)] = m.dart_of(a);
    int halves = 0, inner = 0;
    m.subdivide_hexahedra(mid, [&](auto dim, const sewn::FineCell& c) {
      constexpr int I = decltype(dim)::value;
      if constexpr (I == 1) {
        (c.parent == Dart::null_index ? inner : halves) += 1;
        return c.parent == Dart::null_index ? std::optional<long>(-1) : std::optional<long>(m.attribute_container<1>().value(c.parent) + c.piece);
      } else if constexpr (I == 3) {
        REQUIRE(c.parent != Dart::null_index);
        REQUIRE(c.darts.size() == 24);
        REQUIRE(c.parent_darts.size() == 24);
        CHECK(c.darts[static_cast<std::size_t>(3 * c.piece)] == c.parent_darts[static_cast<std::size_t>(3 * c.piece)]);
        return std::optional<long>(m.attribute_container<3>().value(c.parent) + c.piece);
      } else {
        FAIL("faces carry no attribute: none is asked for");
        return std::optional<int>();
      }
    });
    const auto report = m.validate();
    INFO(report.str());
    REQUIRE(report.ok());
    CHECK(halves == static_cast<int>(2 * edges0));
    CHECK(m.num_attributes<1>() == m.count_all()[1]);
    CHECK(m.num_attributes<1>() == static_cast<std::uint32_t>(halves + inner));
    CHECK(m.num_attributes<3>() == 8 * volumes0);
    CHECK(m.num_attributes<2>() == 0);
    // every fine edge's value names its parent (a multiple of 100) and its half, each half once
    std::map<long, int> seen;
    for (auto a : m.attributes<1>()) ++seen[m.value(a)];
    for (const auto& [v, n] : seen) CHECK(n == (v == -1 ? inner : 1));
    // piece 0 is the half holding the parent's recorded dart (the parent's darts are kept)
    for (const auto& [v, d] : recorded) CHECK(m.value(m.attribute<1>(d)) == v);
    for (Dart d : m.cells<1>()) CHECK(m.attribute<1>(d));
  }
}

TEST_CASE("subdivide_hexahedra refuses anything but closed hexahedra of quads, the map unchanged") {
  auto unchanged = [](Map& m, const char* what) {
    CAPTURE(what);
    const auto darts = m.num_darts();
    const auto cells = m.count_all();
    CHECK_THROWS_AS(m.subdivide_hexahedra(mid), sewn::TopologyError);
    CHECK(m.num_darts() == darts);
    CHECK(m.count_all() == cells);
    CHECK(m.validate().ok());
  };
  {
    Map m = build_map(sewn::tet_grid(1, 1, 1, sewn::TetSplit::kuhn6));
    unchanged(m, "tetrahedra");
  }
  {
    Map m = build_map(sewn::hex_grid(2, 1, 1));
    const Dart d = *m.darts().begin();
    (void)m.insert_vertex_in_edge(d, mid(point(m, d), point(m, b1(m, d))));
    unchanged(m, "an edge split already");
  }
  {
    sewn::IndexedMesh mesh = sewn::hex_grid(1, 1, 1);
    sewn::append(mesh, sewn::tet_grid(1, 1, 1, sewn::TetSplit::five));
    Map m = build_map(mesh);
    unchanged(m, "a hexahedron beside tetrahedra");
  }
}

}  // namespace
}  // namespace test_subdivide_hex
