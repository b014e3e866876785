// Builders from indexed meshes: every cell type, grids, mixed meshes, orientation, bad input.
#include <doctest/doctest.h>

#include <string>

#include "check.hpp"
#include "sewn/cmap/build.hpp"
#include "sewn/cmap/cmap.hpp"

namespace test_build {

using namespace sewn;
using sewn::test::check_map;
using sewn::test::counts;

using UMap1 = CMap<1, std::uint32_t>;
using UMap2 = CMap<2, std::uint32_t>;
using UMap3 = CMap<3, std::uint32_t>;
using UMap4 = CMap<4, std::uint32_t>;

namespace {

template <class M>
BuildResult build_with_points(M& m, const IndexedMesh& mesh, BuildOptions opt = {}) {
  auto r = build(m, mesh, opt);
  m.template create_attributes<0>([&](Dart d) { return r.vertex_of_dart[d.index()]; });
  return r;
}

std::uint32_t hex_grid_edges(std::uint32_t x, std::uint32_t y, std::uint32_t z) {
  return x * (y + 1) * (z + 1) + (x + 1) * y * (z + 1) + (x + 1) * (y + 1) * z;
}
std::uint32_t hex_grid_faces(std::uint32_t x, std::uint32_t y, std::uint32_t z) {
  return x * y * (z + 1) + x * (y + 1) * z + (x + 1) * y * z;
}

}  // namespace

TEST_CASE("hexahedral grids of any size and spacing") {
  for (const auto& size : {std::array<std::uint32_t, 3>{1, 1, 1}, {3, 2, 4}, {8, 8, 10}, {1, 5, 1}}) {
    const std::uint32_t x = size[0], y = size[1], z = size[2];  // CAPTURE cannot take bindings (clang 14)
    CAPTURE(x);
    CAPTURE(y);
    CAPTURE(z);
    UMap3 m;
    const auto mesh = hex_grid(x, y, z, GridSpec{{0.5, 2.0, 0.1}, {1, 2, 3}});
    CHECK(mesh.points[mesh.num_points() - 1] == Point3{1 + 0.5 * x, 2 + 2.0 * y, 3 + 0.1 * z});
    const auto r = build_with_points(m, mesh);
    const auto n = check_map(m);
    CHECK(n == counts<4>({(x + 1) * (y + 1) * (z + 1), hex_grid_edges(x, y, z), hex_grid_faces(x, y, z), x * y * z}));
    CHECK(m.euler_characteristic() == 1);
    CHECK(r.sewn_facets == hex_grid_faces(x, y, z) - 2 * (x * y + y * z + x * z));
    CHECK(m.boundary_facets().size() == 2 * (x * y + y * z + x * z));
    CHECK(m.count_components() == 1);
    // every dart's 0-attribute names the mesh point it starts at; cell_dart runs 0 -> 1
    const Dart d0 = r.cell_dart[0];
    CHECK(m.value(m.attribute<0>(d0)) == mesh.cell(0)[0]);
    CHECK(m.value(m.attribute<0>(m.beta(d0, 1))) == mesh.cell(0)[1]);
  }
  CHECK_THROWS_AS(hex_grid(0, 1, 1), MeshError);
  CHECK_THROWS_AS(hex_grid(1, 1, 1, GridSpec{{1, -1, 1}, {}}), MeshError);
}

TEST_CASE("the paper's tetrahedral beam: 5x7x9 cells, 6 tetrahedra each") {
  UMap3 m;
  const auto mesh = tet_grid(5, 7, 9, TetSplit::kuhn6);
  CHECK(mesh.num_cells() == 1890);
  build_with_points(m, mesh);
  const auto n = check_map(m);
  CHECK(n[0] == 480);
  CHECK(n[1] == 2655);  // the 2013 paper's spring count: every edge a spring
  CHECK(n[3] == 1890);
  CHECK(m.euler_characteristic() == 1);
}

TEST_CASE("a cube as five tetrahedra, and a conforming grid of them") {
  UMap3 m;
  build_with_points(m, tet_grid(1, 1, 1, TetSplit::five));
  CHECK(check_map(m) == counts<4>({8, 18, 16, 5}));  // 12 edges + 6 face diagonals: 18 springs
  UMap3 g;
  const auto r = build_with_points(g, tet_grid(3, 2, 2, TetSplit::five));
  check_map(g);
  CHECK(g.euler_characteristic() == 1);
  CHECK(r.nonmanifold_facets == 0);
  CHECK(g.boundary_facets().size() == 2 * 2 * (3 * 2 + 2 * 2 + 3 * 2));  // two triangles per boundary square
}

TEST_CASE("quad and triangle grids in a 2-map and as surfaces in a 3-map") {
  UMap2 q2;
  build_with_points(q2, quad_grid(4, 3));
  CHECK(check_map(q2) == counts<3>({20, 31, 12}));
  UMap2 t2;
  build_with_points(t2, tri_grid(4, 3));
  CHECK(check_map(t2) == counts<3>({20, 43, 24}));
  UMap3 q3;
  build_with_points(q3, quad_grid(4, 3));
  CHECK(check_map(q3) == counts<4>({20, 31, 12, 1}));  // one surface: a single 3-cell (open)
}

TEST_CASE("polylines in 1-, 2- and 3-maps") {
  UMap1 m1;
  build_with_points(m1, polyline_x(5));
  auto n1 = check_map(m1);
  CHECK(n1[1] == 5);
  CHECK(m1.count_components() == 1);
  UMap2 m2;
  build_with_points(m2, polyline_x(5));
  CHECK(check_map(m2) == counts<3>({6, 5, 2}));  // the forward and backward chains are two open 2-cells
  UMap3 m3;
  build_with_points(m3, polyline_x(5));
  CHECK(check_map(m3) == counts<4>({6, 5, 2, 1}));
}

TEST_CASE("mixed cell types in one solid: hexahedron, prism, pyramid, tetrahedron") {
  IndexedMesh mesh;
  // a unit cube 0..7, a prism on its +x face, a pyramid on its top, a tetrahedron on the
  // pyramid's +y triangle
  for (Point3 p : {Point3{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}, {0, 0, 1}, {1, 0, 1}, {1, 1, 1}, {0, 1, 1}})
    mesh.points.push_back(p);
  mesh.points.push_back({2, 0, 0});      // 8
  mesh.points.push_back({2, 0, 1});      // 9
  mesh.points.push_back({0.5, 0.5, 2});  // 10: apex
  mesh.points.push_back({0.5, 1.5, 1.5});  // 11
  mesh.add_cell(CellType::hexahedron, {0, 1, 2, 3, 4, 5, 6, 7});
  // prism with triangles (1,8,2) and (5,9,6): the quad (1,2,6,5) is shared with the cube
  mesh.add_cell(CellType::prism, {1, 2, 8, 5, 6, 9});
  mesh.add_cell(CellType::pyramid, {4, 5, 6, 7, 10});
  mesh.add_cell(CellType::tetrahedron, {6, 7, 10, 11});
  UMap3 m;
  const auto r = build_with_points(m, mesh);
  CHECK(r.sewn_facets == 3);
  const auto n = check_map(m);
  CHECK(n[3] == 4);
  CHECK(n[0] == 12);
  CHECK(m.euler_characteristic() == 1);
  CHECK(m.count_components() == 1);
}

TEST_CASE("mixed dimensions: a solid, a shell on it and a rod share points but not darts") {
  IndexedMesh mesh = hex_grid(1, 1, 1);
  mesh.add_cell(CellType::quad, {4, 5, 6, 7});  // a shell covering the top face
  mesh.points.push_back({0.5, 0.5, 2});
  mesh.add_cell(CellType::segment, {6, 8});  // a rod standing on a corner
  mesh.points.push_back({0.5, 0.5, 3});
  mesh.add_cell(CellType::segment, {8, 9});
  UMap3 m;
  const auto r = build_with_points(m, mesh);
  check_map(m);
  CHECK(m.count_components() == 3);
  CHECK(r.sewn_facets == 1);  // only the two rod segments are chained
  CHECK(m.num_darts() == 24 + 4 + 4);
}

TEST_CASE("surface cells with inconsistent orientation are reversed and glued") {
  IndexedMesh mesh = tri_grid(3, 3);
  // reverse every other triangle
  for (std::uint32_t c = 0; c < mesh.num_cells(); c += 2) std::swap(mesh.conn[mesh.offsets[c] + 1], mesh.conn[mesh.offsets[c] + 2]);
  UMap2 m;
  const auto r = build_with_points(m, mesh);
  CHECK(check_map(m) == counts<3>({16, 33, 18}));
  std::uint32_t flipped = 0;
  for (bool f : r.flipped) flipped += f ? 1u : 0u;
  CHECK(flipped == 9);  // half of the 18 triangles disagree with the first one
  CHECK(r.unorientable_edges == 0);
  BuildOptions no_orient;
  no_orient.orient_surfaces = false;
  UMap2 raw;
  const auto r2 = build_with_points(raw, mesh, no_orient);
  check_map(raw);
  CHECK(r2.unorientable_edges > 0);  // left unsewn, reported
}

TEST_CASE("a map of dimension 4 holds hexahedra glued by faces") {
  UMap4 m;
  build_with_points(m, hex_grid(2, 1, 1));
  const auto n = check_map(m);
  CHECK(n[0] == 12);
  CHECK(n[3] == 2);
  CHECK(n[4] == 1);
}

TEST_CASE("building into a map that already has darts") {
  UMap3 m;
  m.make_hexahedron();
  const auto r = build(m, hex_grid(2, 1, 1));
  CHECK(r.vertex_of_dart[0] == Dart::null_index);
  CHECK(r.vertex_of_dart[r.cell_dart[0].index()] == 0);
  m.create_attributes<0>([](Dart) { return 0u; });
  CHECK(check_map(m)[3] == 3);
}

TEST_CASE("sew_coincident_faces glues free facets through the same points, and only those") {
  auto point_of = [](auto& m) { return [&m](Dart d) { return m.value(m.template attribute<0>(d)); }; };
  SUBCASE("the cells of a hexahedral grid made apart, then glued: the same map as build() makes") {
    const IndexedMesh mesh = hex_grid(3, 2, 2);
    UMap3 apart, together;
    build_with_points(apart, mesh, BuildOptions{.sew = false});
    build_with_points(together, mesh);
    CHECK(check_map(apart)[3] == 12);
    const auto rep = sew_coincident_faces(apart, point_of(apart), mesh.num_points());
    CHECK(rep.sewn == hex_grid_faces(3, 2, 2) - 2 * (3 * 2 + 2 * 2 + 3 * 2));
    CHECK(rep.nonmanifold == 0);
    CHECK(rep.mismatched == 0);
    CHECK(check_map(apart) == check_map(together));  // the vertex attributes merged as the cells were sewn
    CHECK(apart.count_components() == 1);
    CHECK(sew_coincident_faces(apart, point_of(apart), mesh.num_points()).sewn == 0);  // nothing left to glue
  }
  SUBCASE("a grid cut through its middle plane is put back together") {
    UMap3 m;
    build_with_points(m, hex_grid(4, 2, 2));
    const auto before = check_map(m);
    auto on_plane = [&](Dart d) { return m.value(m.attribute<0>(d)) % 5 == 2; };  // x = 2: point i + 5(j + 3k), i = 2
    std::vector<Dart> plane;
    for (Dart d : m.cells<2>())
      if (!m.is_free(d, 3) && on_plane(d) && on_plane(m.beta(d, 1)) && on_plane(m.beta(d, 1, 1))) plane.push_back(d);
    REQUIRE(plane.size() == 4);
    for (Dart d : plane) m.unsew<3>(d);
    CHECK(m.count_components() == 2);
    const auto rep = sew_coincident_faces(m, point_of(m), 45);
    CHECK(rep.sewn == 4);
    CHECK(check_map(m) == before);
  }
  SUBCASE("three faces through the same points are left free; so is a pair with the same orientation") {
    IndexedMesh mesh;
    for (std::uint32_t p = 0; p < 8; ++p) mesh.points.push_back({double(p & 1), double((p >> 1) & 1), double(p >> 2)});
    for (int c = 0; c < 3; ++c) mesh.add_cell(CellType::hexahedron, {0, 1, 3, 2, 4, 5, 7, 6});  // three times the same cube
    UMap3 m;
    build_with_points(m, mesh, BuildOptions{.sew = false});
    const auto rep = sew_coincident_faces(m, point_of(m), 8);
    CHECK(rep == SewCoincidentReport{0, 6, 0});
    CHECK(check_map(m)[3] == 3);
    UMap3 twice;
    mesh.conn.resize(16);
    mesh.offsets.resize(3);
    mesh.types.resize(2);
    mesh.tags.resize(2);
    build_with_points(twice, mesh, BuildOptions{.sew = false});  // two copies of one cube: each face twice, same orientation
    CHECK(sew_coincident_faces(twice, point_of(twice), 8) == SewCoincidentReport{0, 0, 6});
    check_map(twice);
  }
  SUBCASE("quads of a 2-map glued along their edges") {
    const IndexedMesh mesh = quad_grid(3, 2);
    UMap2 apart, together;
    build_with_points(apart, mesh, BuildOptions{.sew = false});
    build_with_points(together, mesh);
    const auto rep = sew_coincident_faces(apart, point_of(apart), mesh.num_points());
    CHECK(rep.sewn == 3 * 1 + 2 * 2);  // inner edges of a 3x2 grid
    CHECK(check_map(apart) == check_map(together));
  }
  SUBCASE("a point out of range is refused, the map unchanged") {
    UMap3 m;
    build_with_points(m, hex_grid(2, 1, 1), BuildOptions{.sew = false});
    const auto before = check_map(m);
    CHECK_THROWS_WITH_AS(sew_coincident_faces(m, point_of(m), 5), doctest::Contains("outside [0, 5)"), TopologyError);
    CHECK(check_map(m) == before);
  }
}

TEST_CASE("bad meshes are refused with the cell named") {
  auto message_of = [](auto&& f) {
    try {
      f();
    } catch (const MeshError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  IndexedMesh mesh = hex_grid(2, 1, 1);
  SUBCASE("index out of range") {
    mesh.conn[9] = 99;
    UMap3 m;
    const auto msg = message_of([&] { build(m, mesh); });
    CHECK(msg.find("cell 1") != std::string::npos);
    CHECK(msg.find("99") != std::string::npos);
    CHECK(m.num_darts() == 0);
  }
  SUBCASE("repeated point") {
    mesh.conn[1] = mesh.conn[0];
    UMap3 m;
    CHECK(message_of([&] { build(m, mesh); }).find("twice") != std::string::npos);
  }
  SUBCASE("a volume in a 2-map") {
    UMap2 m;
    CHECK(message_of([&] { build(m, mesh); }).find("dimension 2") != std::string::npos);
  }
  SUBCASE("an inverted hexahedron next to a correct one") {
    // mirror cell 1 (swap its bottom and top): its shared face now runs the same way as cell 0's
    auto c1 = std::vector<std::uint32_t>(mesh.cell(1).begin(), mesh.cell(1).end());
    for (int k = 0; k < 4; ++k) mesh.conn[mesh.offsets[1] + k] = c1[static_cast<std::size_t>(k + 4)],
                                mesh.conn[mesh.offsets[1] + k + 4] = c1[static_cast<std::size_t>(k)];
    UMap3 m;
    const auto msg = message_of([&] { build(m, mesh); });
    CHECK(msg.find("inverted") != std::string::npos);
    CHECK(msg.find("cell 0") != std::string::npos);
    CHECK(msg.find("cell 1") != std::string::npos);
  }
  SUBCASE("a face shared by three volumes") {
    IndexedMesh t;
    t.points = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}, {0, 0, -1}, {0.3, 0.3, 0.5}};
    t.add_cell(CellType::tetrahedron, {0, 1, 2, 3});
    t.add_cell(CellType::tetrahedron, {0, 2, 1, 4});
    t.add_cell(CellType::tetrahedron, {0, 1, 2, 5});
    UMap3 m;
    BuildOptions strict;
    strict.allow_nonmanifold = false;
    strict.source = "three.msh";
    const auto msg = message_of([&] { build(m, t, strict); });
    CHECK(msg.find("three.msh") != std::string::npos);
    CHECK(msg.find("non-manifold") != std::string::npos);
    // the cells apart, for a caller that numbers them as its files do
    try {
      UMap3 again;
      build(again, t, strict);
      FAIL("no error");
    } catch (const MeshCellError& e) {
      CHECK(e.message().refs().size() == 2);
      const std::string renamed = e.message().render([](const IndexedMessage::Ref& r) { return "element " + std::to_string(r.index + 10); });
      CHECK_MESSAGE(renamed == "3 cells share one face, among them element 10 (tetrahedron) and element 11 (tetrahedron) "
                               "(a non-manifold face where a manifold is required)", renamed);
      CHECK(std::string(e.what()) == "three.msh: " + e.message().str());
    }
    UMap3 lax;
    const auto r = build_with_points(lax, t);
    CHECK(r.nonmanifold_facets == 1);
    CHECK(r.sewn_facets == 0);
    check_map(lax);
  }
  SUBCASE("three quads on one edge (a book of three pages), and a fourth glued to one page") {
    IndexedMesh book;
    book.points = {{0, 0, 0}, {0, 0, 1}, {1, 0, 0}, {1, 0, 1}, {0, 1, 0}, {0, 1, 1}, {-1, 0, 0}, {-1, 0, 1}, {2, 0, 0}, {2, 0, 1}};
    book.add_cell(CellType::quad, {0, 2, 3, 1});
    book.add_cell(CellType::quad, {0, 4, 5, 1});
    book.add_cell(CellType::quad, {0, 6, 7, 1});
    book.add_cell(CellType::quad, {3, 9, 8, 2});  // runs 2 -> 3 as page 0 does: reversed to be glued
    UMap3 m;
    BuildOptions strict;
    strict.allow_nonmanifold = false;
    strict.source = "book.msh";
    const auto msg = message_of([&] { build(m, book, strict); });
    CHECK(msg.find("book.msh") != std::string::npos);
    CHECK(msg.find("non-manifold edge") != std::string::npos);
    CHECK(msg.find("cell 0 (quad)") != std::string::npos);
    UMap3 lax;
    const auto r = build_with_points(lax, book);
    CHECK(r.nonmanifold_facets == 1);
    CHECK(r.sewn_facets == 1);  // the fourth page to the first
    CHECK(r.flipped[3]);
    CHECK(check_map(lax)[2] == 4);
    CHECK(lax.count_components() == 3);
  }
}

TEST_CASE("discs, cylinders and polylines through points") {
  const IndexedMesh frisbee = disc(0.15, 8, 8);
  CHECK(frisbee.num_points() == 289);  // the 2019 paper's nylon frisbee
  CHECK(frisbee.num_cells() == 512);
  UMap2 d;
  build_with_points(d, frisbee);
  const auto n = check_map(d);
  CHECK(n == counts<3>({289, 289 + 512 - 1, 512}));  // a disc: V - E + F = 1
  CHECK(d.boundary_facets().size() == 64);          // the rim: 64 rod edges in the paper
  for (std::uint32_t c = 0; c < frisbee.num_cells(); ++c) {  // every triangle counter-clockwise
    const auto v = frisbee.cell(c);
    const auto &a = frisbee.points[v[0]], &b = frisbee.points[v[1]], &e = frisbee.points[v[2]];
    CHECK((b[0] - a[0]) * (e[1] - a[1]) - (b[1] - a[1]) * (e[0] - a[0]) > 0);
  }
  const IndexedMesh cyl = cylinder(0.1, 0.5, 3, 6, 4);
  UMap3 c;
  const auto r = build_with_points(c, cyl);
  check_map(c);
  CHECK(cyl.num_cells() == 3 * 4 * disc(0.1, 3, 6).num_cells());
  CHECK(r.nonmanifold_facets == 0);
  CHECK(c.euler_characteristic() == 1);  // conforming: one solid ball-like body
  CHECK(c.count_components() == 1);
  const Point3 pts[] = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}};
  CHECK(polyline(pts).num_cells() == 2);
  const Point3 dup[] = {{0, 0, 0}, {0, 0, 0}};
  CHECK_THROWS_AS(polyline(dup), MeshError);
}

TEST_CASE("unions of lattice boxes: overlaps counted once, touching boxes glued") {
  // an L of two overlapping boxes on a negative-going lattice, and a third box glued to its end
  const LatticeBox boxes[] = {{{-2, 0, 0}, {2, 1, 1}}, {{1, 0, 0}, {2, 3, 1}}, {{2, 2, 0}, {4, 3, 2}}};
  const IndexedMesh mesh = box_union(boxes, GridSpec{{0.5, 0.5, 0.5}, {1, 0, 0}});
  CHECK(mesh.num_cells() == 4 + 2 + 4);  // the overlap cell (1, 0, 0) once
  for (std::uint32_t c = 0; c < mesh.num_cells(); ++c) CHECK(mesh.types[c] == CellType::hexahedron);
  CHECK(mesh.points[mesh.cell(0)[0]] == Point3{0, 0, 0});  // cell (-2, 0, 0) starts at origin - 2 spacings
  UMap3 m;
  const auto r = build_with_points(m, mesh);
  check_map(m);
  CHECK(r.nonmanifold_facets == 0);
  CHECK(m.count_components() == 1);  // shared points: every box is sewn to the next
  CHECK(m.euler_characteristic() == 1);
  CHECK(r.sewn_facets == 3 + 2 + 1 + 4);  // inside the first box, along the arm, arm to third box, inside the third
  // the same cells from one box each: the same mesh up to point numbering
  const LatticeBox single[] = {{{0, 0, 0}, {3, 2, 1}}};
  CHECK(box_union(single).num_points() == hex_grid(3, 2, 1).num_points());
  CHECK(box_union(single).num_cells() == 6);
  const LatticeBox inverted[] = {{{0, 0, 0}, {1, 1, 1}}, {{0, 2, 0}, {1, 2, 1}}};
  CHECK_THROWS_WITH_AS(box_union(inverted), doctest::Contains("box 1 is empty or inverted along axis 1"), MeshError);
  CHECK_THROWS_AS(box_union(std::span<const LatticeBox>{}), MeshError);
  const LatticeBox huge[] = {{{-1000000000, -1000000000, 0}, {1000000000, 1000000000, 1}}};
  CHECK_THROWS_WITH_AS(box_union(huge), doctest::Contains("2^28"), MeshError);
  CHECK_THROWS_AS(box_union(single, GridSpec{{1, 0, 1}, {}}), MeshError);
}

}  // namespace test_build
