// Topology invariants on known spaces, each built with the map's builders: Betti numbers over
// Z/2, χ, orientability, boundary components and their genus, manifoldness.
#include <doctest/doctest.h>

#include <algorithm>
#include <array>
#include <map>
#include <string>
#include <vector>

#include "check.hpp"
#include "sewn/cmap/build.hpp"
#include "sewn/cmap/cmap.hpp"
#include "sewn/cmap/topology.hpp"

namespace test_topology {

using namespace sewn;

namespace {

using B = std::array<std::int64_t, 4>;

// The quads bounding a hexahedral mesh (faces of one cell only), oriented outward.
IndexedMesh surface_of(const IndexedMesh& solid) {
  std::map<std::array<std::uint32_t, 4>, std::pair<int, std::array<std::uint32_t, 4>>> faces;
  for (std::uint32_t c = 0; c < solid.num_cells(); ++c) {
    const auto v = solid.cell(c);
    for (auto f : cell_faces(solid.types[c])) {
      std::array<std::uint32_t, 4> q{v[f[0]], v[f[1]], v[f[2]], v[f[3]]}, key = q;
      std::sort(key.begin(), key.end());
      auto& e = faces[key];
      ++e.first;
      e.second = q;
    }
  }
  IndexedMesh s;
  s.points = solid.points;
  for (const auto& [key, e] : faces)
    if (e.first == 1) s.add_cell(CellType::quad, {e.second[0], e.second[1], e.second[2], e.second[3]});
  return s;
}

IndexedMesh without_cell(const IndexedMesh& m, std::uint32_t skip) {
  IndexedMesh out;
  out.points = m.points;
  for (std::uint32_t c = 0; c < m.num_cells(); ++c)
    if (c != skip) out.add_cell(m.types[c], m.cell(c));
  return out;
}

// An n × m quad grid whose sides are identified: (i + n, j) with (i, j), or with (i, m - j)
// when `twist_i`; (i, j + m) with (i, j) when `wrap_j`.
IndexedMesh wrapped_grid(std::uint32_t n, std::uint32_t m, bool twist_i, bool wrap_j) {
  IndexedMesh g;
  const std::uint32_t rows = wrap_j ? m : m + 1;
  g.points.resize(std::size_t{n} * rows);
  auto id = [&](std::uint32_t i, std::uint32_t j) {
    if (i == n) {
      i = 0;
      if (twist_i) j = (m - j) % (wrap_j ? m : m + 1);
    }
    if (wrap_j) j %= m;
    return i + n * j;
  };
  for (std::uint32_t j = 0; j < m; ++j)
    for (std::uint32_t i = 0; i < n; ++i) g.add_cell(CellType::quad, {id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1)});
  return g;
}

template <int D>
struct Built {
  CMap<D> map;
  BuildResult res;
  explicit Built(const IndexedMesh& mesh) : res(build(map, mesh)) { REQUIRE(map.validate().ok()); }
  Topology own() const { return topology(map); }
  Topology by_points() const { return topology(map, {res.vertex_of_dart}); }
};

using test::str;

// Not inlined: GCC 12.2 at -O2 with AVX-512 (-march=native here) builds the constant argument
// {1, 1, 0, 0} of an inlined call as {1, 1, 1, 1} (SLP vectorizer; -fno-tree-slp-vectorize or
// a call that is not inlined avoids it).
[[gnu::noinline]] void check_betti(const Topology& t, const B& betti, std::int64_t components) {
  const std::string got = str(t.total.betti), cells = str(t.total.cells), want = str(betti);
  INFO("betti: ", got, " cells: ", cells, " expected ", want);
  CHECK(t.total.betti == betti);
  CHECK(static_cast<std::int64_t>(t.components.size()) == components);
  std::int64_t alt = 0;
  for (int i = 0; i <= t.dim; ++i) alt += (i % 2 == 0 ? 1 : -1) * t.total.betti[static_cast<std::size_t>(i)];
  CHECK(alt == t.total.euler);
}

}  // namespace

TEST_CASE("a ball: the solid cube") {
  Built<3> b(hex_grid(3, 3, 3));
  const Topology t = b.own();
  check_betti(t, {1, 0, 0, 0}, 1);
  CHECK(t.total.euler == 1);
  CHECK(t.orientable);
  REQUIRE(t.boundary.size() == 1);
  CHECK(t.boundary[0].euler == 2);
  CHECK(t.boundary[0].genus == 0);
  CHECK(t.boundary[0].surface);
  CHECK(t.boundary[0].cells[2] == 54);
  CHECK(t.nonmanifold.empty());
  // the same with cells identified by points: nothing changes on a glued manifold mesh
  const Topology q = b.by_points();
  CHECK(q.total.betti == t.total.betti);
  CHECK(q.total.cells == t.total.cells);
  CHECK(q.nonmanifold.empty());
}

TEST_CASE("a ball of tetrahedra") {
  Built<3> b(tet_grid(3, 2, 2, TetSplit::kuhn6));
  const Topology t = b.own();
  check_betti(t, {1, 0, 0, 0}, 1);
  REQUIRE(t.boundary.size() == 1);
  CHECK(t.boundary[0].genus == 0);
  CHECK(t.nonmanifold.empty());
}

TEST_CASE("a sphere: the surface of the cube") {
  Built<2> b(surface_of(hex_grid(3, 2, 4)));
  const Topology t = b.own();
  check_betti(t, {1, 0, 1, 0}, 1);
  CHECK(t.total.euler == 2);
  CHECK(t.orientable);
  CHECK(t.boundary.empty());
  CHECK(t.components[0].genus == 0);
  CHECK(t.nonmanifold.empty());
}

TEST_CASE("a torus and a double torus, as surfaces and as solids") {
  SUBCASE("flat torus") {
    Built<2> b(wrapped_grid(4, 3, false, true));
    const Topology t = b.own();
    check_betti(t, {1, 2, 1, 0}, 1);
    CHECK(t.total.euler == 0);
    CHECK(t.orientable);
    CHECK(t.components[0].genus == 1);
    CHECK(t.nonmanifold.empty());
  }
  // a 3 x 3 frame of voxels around a hole: a solid torus; 3 x 5 around two holes: genus 2
  const std::array<LatticeBox, 4> frame1{{{{0, 0, 0}, {3, 1, 1}}, {{0, 2, 0}, {3, 3, 1}}, {{0, 0, 0}, {1, 3, 1}}, {{2, 0, 0}, {3, 3, 1}}}};
  const std::array<LatticeBox, 5> frame2{{{{0, 0, 0}, {3, 1, 1}}, {{0, 2, 0}, {3, 3, 1}}, {{0, 4, 0}, {3, 5, 1}}, {{0, 0, 0}, {1, 5, 1}}, {{2, 0, 0}, {3, 5, 1}}}};
  SUBCASE("solid torus") {
    Built<3> b(box_union(frame1));
    const Topology t = b.own();
    check_betti(t, {1, 1, 0, 0}, 1);
    REQUIRE(t.boundary.size() == 1);
    CHECK(t.boundary[0].euler == 0);
    CHECK(t.boundary[0].genus == 1);
    CHECK(t.boundary[0].orientable);
    CHECK(t.nonmanifold.empty());
  }
  SUBCASE("torus surface of the frame") {
    Built<2> b(surface_of(box_union(frame1)));
    const Topology t = b.own();
    check_betti(t, {1, 2, 1, 0}, 1);
    CHECK(t.components[0].genus == 1);
  }
  SUBCASE("solid double torus") {
    Built<3> b(box_union(frame2));
    const Topology t = b.own();
    check_betti(t, {1, 2, 0, 0}, 1);
    REQUIRE(t.boundary.size() == 1);
    CHECK(t.boundary[0].euler == -2);
    CHECK(t.boundary[0].genus == 2);
  }
  SUBCASE("double torus surface") {
    Built<2> b(surface_of(box_union(frame2)));
    const Topology t = b.own();
    check_betti(t, {1, 4, 1, 0}, 1);
    CHECK(t.total.euler == -2);
    CHECK(t.orientable);
    CHECK(t.components[0].genus == 2);
    CHECK(t.nonmanifold.empty());
  }
}

TEST_CASE("a hollow cube: the shell around one removed cell") {
  Built<3> b(without_cell(hex_grid(3, 3, 3), 13));
  const Topology t = b.own();
  check_betti(t, {1, 0, 1, 0}, 1);
  CHECK(t.total.euler == 2);
  REQUIRE(t.boundary.size() == 2);
  for (const auto& s : t.boundary) {
    CHECK(s.genus == 0);
    CHECK(s.orientable);
  }
  CHECK(t.components[0].boundary_components == 2);
  CHECK(t.nonmanifold.empty());
}

TEST_CASE("a Möbius strip and a Klein bottle are non-orientable once identified by points") {
  SUBCASE("Möbius strip") {
    Built<2> b(wrapped_grid(5, 1, true, false));
    CHECK(b.res.unorientable_edges == 1);
    // the map alone is the strip cut open along the clashing edge: a disc
    const Topology own = b.own();
    check_betti(own, {1, 0, 0, 0}, 1);
    CHECK(own.orientable);
    const Topology t = b.by_points();
    check_betti(t, {1, 1, 0, 0}, 1);
    CHECK(t.total.euler == 0);
    CHECK_FALSE(t.orientable);
    CHECK_FALSE(t.components[0].orientable);
    CHECK(std::all_of(t.orientation.begin(), t.orientation.end(), [](std::int8_t s) { return s == 0; }));
    REQUIRE(t.boundary.size() == 1);  // one boundary circle, twice as long as the core
    CHECK(t.boundary[0].cells[1] == 10);
    CHECK(t.nonmanifold.empty());
  }
  SUBCASE("Klein bottle") {
    Built<2> b(wrapped_grid(4, 4, true, true));
    const Topology t = b.by_points();
    check_betti(t, {1, 2, 1, 0}, 1);
    CHECK(t.total.euler == 0);
    CHECK_FALSE(t.orientable);
    CHECK(t.boundary.empty());
    CHECK(t.components[0].genus == 2);  // two cross-caps
    CHECK(t.nonmanifold.empty());
  }
  SUBCASE("the torus stays orientable through the same path") {
    Built<2> b(wrapped_grid(4, 4, false, true));
    const Topology t = b.by_points();
    check_betti(t, {1, 2, 1, 0}, 1);
    CHECK(t.orientable);
    // the orientation found is consistent: opposite across every shared edge
    CHECK(std::all_of(t.orientation.begin(), t.orientation.end(), [](std::int8_t s) { return s == 1 || s == -1; }));
  }
}

TEST_CASE("a pinched vertex: two bodies sharing one point") {
  SUBCASE("two tetrahedra") {
    IndexedMesh m;
    m.points.resize(7);
    m.add_cell(CellType::tetrahedron, {0, 1, 2, 3});
    m.add_cell(CellType::tetrahedron, {3, 4, 5, 6});
    Built<3> b(m);
    const Topology own = b.own();
    check_betti(own, {2, 0, 0, 0}, 2);
    CHECK(own.nonmanifold.empty());
    const Topology t = b.by_points();
    check_betti(t, {1, 0, 0, 0}, 1);
    REQUIRE(t.nonmanifold.size() == 1);
    CHECK(t.nonmanifold[0].dim == 0);
    CHECK(b.res.vertex_of_dart[t.nonmanifold[0].dart.index()] == 3);
    CHECK(t.nonmanifold[0].why.find("2 pieces") != std::string::npos);
    // the two spheres bounding them touch at the point: one boundary piece, not a surface
    REQUIRE(t.boundary.size() == 1);
    CHECK_FALSE(t.boundary[0].surface);
    CHECK(t.boundary[0].genus == -1);
    CHECK(own.boundary.size() == 2);
    CHECK(own.boundary[0].surface);
  }
  SUBCASE("two triangles") {
    IndexedMesh m;
    m.points.resize(5);
    m.add_cell(CellType::triangle, {0, 1, 2});
    m.add_cell(CellType::triangle, {2, 3, 4});
    Built<2> b(m);
    const Topology t = b.by_points();
    check_betti(t, {1, 0, 0, 0}, 1);
    REQUIRE(t.nonmanifold.size() == 1);
    CHECK(t.nonmanifold[0].dim == 0);
  }
  SUBCASE("three triangles on one edge") {
    IndexedMesh m;
    m.points.resize(5);
    m.add_cell(CellType::triangle, {0, 1, 2});
    m.add_cell(CellType::triangle, {1, 0, 3});
    m.add_cell(CellType::triangle, {0, 1, 4});
    Built<2> b(m);
    const Topology t = b.by_points();
    check_betti(t, {1, 0, 0, 0}, 1);
    const auto edges = std::count_if(t.nonmanifold.begin(), t.nonmanifold.end(), [](const NonManifoldCell& c) { return c.dim == 1; });
    CHECK(edges == 1);
  }
}

TEST_CASE("several components, each with its own numbers") {
  IndexedMesh m = hex_grid(2, 2, 2);
  append(m, without_cell(hex_grid(3, 3, 3), 13));
  Built<3> b(m);
  const Topology t = b.own();
  check_betti(t, {2, 0, 1, 0}, 2);
  CHECK(t.components[0].betti == B{1, 0, 0, 0});
  CHECK(t.components[1].betti == B{1, 0, 1, 0});
  CHECK(t.components[0].boundary_components == 1);
  CHECK(t.components[1].boundary_components == 2);
  CHECK(t.boundary.size() == 3);
}

TEST_CASE("open faces and volumes are refused with the dart named") {
  CMap<2> m2;
  m2.make_polyline(3);
  CHECK_THROWS_WITH_AS(topology(m2), doctest::Contains("open face"), TopologyError);
  CMap<3> m3;
  m3.make_polygon(4);
  CHECK_THROWS_WITH_AS(topology(m3), doctest::Contains("2-free"), TopologyError);
  CMap<2> q;
  const auto built = build(q, quad_grid(2, 2));
  std::vector<std::uint32_t> pts = built.vertex_of_dart;
  pts[0] = pts[q.b(0, 1)];  // a dart moved onto its edge's other end
  CHECK_THROWS_AS(topology(q, {pts}), TopologyError);
  pts.resize(3);
  CHECK_THROWS_WITH_AS(topology(q, {pts}), doctest::Contains("no point"), TopologyError);
}

namespace {

// One dart per d-sewn facet of a built grid (D = 2: edges, D = 3: faces) all of whose darts start
// at points where `keep` holds.
template <int D, class Keep>
std::vector<Dart> sewn_facets_where(const Built<D>& b, const IndexedMesh& mesh, Keep keep) {
  std::vector<Dart> out;
  for (Dart d : b.map.template cells<D - 1>()) {
    if (b.map.is_free(d, D)) continue;
    bool all = true;
    for (Dart x : b.map.template cell<D - 1>(d)) all = all && keep(mesh.points[b.res.vertex_of_dart[x.index()]]);
    if (all) out.push_back(d);
  }
  return out;
}

TEST_CASE("a cut through a body adds one to b0; a crack inside it adds a b_{D-1}, so chi changes") {
  SUBCASE("hexahedra cut along the plane x = 1") {
    const IndexedMesh mesh = hex_grid(2, 2, 2);
    Built<3> b(mesh);
    const auto plane = sewn_facets_where(b, mesh, [](const Point3& p) { return p[0] == 1.0; });
    REQUIRE(plane.size() == 4);
    b.map.unsew_all<3>(plane);
    REQUIRE(b.map.validate().ok());
    check_betti(b.own(), {2, 0, 0, 0}, 2);
  }
  SUBCASE("one inner face of a 3x3x3 block unsewn: its edges and vertices stay shared") {
    const IndexedMesh mesh = hex_grid(3, 3, 3);
    Built<3> b(mesh);
    const auto face = sewn_facets_where(b, mesh, [](const Point3& p) {
      return p[0] == 1.0 && p[1] >= 1.0 && p[1] <= 2.0 && p[2] >= 1.0 && p[2] <= 2.0;
    });
    REQUIRE(face.size() == 1);
    const auto before = b.map.count_all();
    CHECK(b.own().total.euler == 1);
    b.map.unsew<3>(face[0]);
    CHECK(b.map.count_all() == std::array<std::uint32_t, 4>{before[0], before[1], before[2] + 1, before[3]});
    const Topology t = b.own();
    check_betti(t, {1, 0, 1, 0}, 1);  // a flat cavity: a sphere of boundary inside the ball
    CHECK(t.total.euler == 2);
    CHECK(t.boundary.size() == 2);
  }
  SUBCASE("one inner edge of a 3x3 quad grid unsewn: a slit") {
    const IndexedMesh mesh = quad_grid(3, 3);
    Built<2> b(mesh);
    const auto edge = sewn_facets_where(b, mesh, [](const Point3& p) { return p[0] == 1.0 && p[1] >= 1.0 && p[1] <= 2.0; });
    REQUIRE(edge.size() == 1);
    b.map.unsew<2>(edge[0]);
    const Topology t = b.own();
    check_betti(t, {1, 1, 0, 0}, 1);
    CHECK(t.total.euler == 0);
  }
}

}  // namespace

}  // namespace test_topology
