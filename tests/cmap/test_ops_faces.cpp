// insert_vertex_in_face and insert_face_in_hole: counts, validate(), attributes and hooks, the
// topology they must keep, and the inputs they refuse.
#include <doctest/doctest.h>

#include <vector>

#include "sewn/cmap/build.hpp"
#include "sewn/cmap/cmap.hpp"
#include "sewn/cmap/topology.hpp"

using namespace sewn;

namespace {

// The 2-free darts around the hole that d borders, as a closed chain (each ends where the next
// starts): from a 2-free dart, the next is found by turning around its end vertex inside the
// volume until a 2-free dart comes up.
template <class M>
std::vector<Dart> hole_ring(const M& m, Dart d) {
  std::vector<Dart> ring;
  Dart x = d;
  do {
    ring.push_back(x);
    Dart y = m.beta(x, 1);
    while (m.beta(y, 2)) y = m.beta(y, 2, 1);
    x = y;
  } while (x != d && ring.size() < 1000);
  return ring;
}

std::uint32_t face_size(const auto& m, Dart d) { return static_cast<std::uint32_t>(m.template orbit<1>(d).size()); }

}  // namespace

TEST_CASE("insert_vertex_in_face makes a star of triangles") {
  SUBCASE("a quad of a 2-map, with attributes and hooks") {
    CMap<2, int, int, int> m;
    build(m, quad_grid(2, 1));
    m.create_attributes<2>([](Dart) { return 7; });
    int splits = 0;
    m.on_split<2>([&](AttrId<2> a, AttrId<2> b) {
      CHECK(m.value(a) == m.value(b));
      ++splits;
    });
    const auto n = m.count_all();
    const auto betti = topology(m).total.betti;
    const Dart d = *m.cells<2>().begin();
    const AttrId<2> face = m.attribute<2>(d);
    REQUIRE(m.is_insertable_vertex_in_face(d));
    const Dart v = m.insert_vertex_in_face(d);
    CHECK(m.validate().ok());
    CHECK(m.count_all() == std::array<std::uint32_t, 3>{n[0] + 1, n[1] + 4, n[2] + 3});
    CHECK(splits == 3);
    CHECK(m.attribute<2>(d) == face);
    CHECK(m.attribute<0>(v).is_null());
    CHECK(m.same_cell<0>(m.beta(v, 1), m.beta(d, 1)));
    CHECK(m.cell<0>(v).size() == 4);  // four edges around the new vertex
    for (Dart x : m.cell<0>(v)) CHECK(face_size(m, x) == 3);
    CHECK(topology(m).total.betti == betti);
  }
  SUBCASE("a face between two hexahedra, both sides") {
    CMap<3> m;
    build(m, hex_grid(2, 1, 1));
    Dart inner;
    for (Dart x : m.darts())
      if (m.beta(x, 3)) inner = x;
    REQUIRE(inner);
    const auto n = m.count_all();
    const Dart v = m.insert_vertex_in_face(inner);
    CHECK(m.validate().ok());
    CHECK(m.count_all() == std::array<std::uint32_t, 4>{n[0] + 1, n[1] + 4, n[2] + 3, n[3]});
    CHECK(m.beta(v, 3));
    const Topology t = topology(m);
    CHECK(t.total.betti == std::array<std::int64_t, 4>{1, 0, 0, 0});
  }
  SUBCASE("a 2-gon becomes two triangles") {
    CMap<2> m;
    const Dart d = m.make_polygon(2);
    m.insert_vertex_in_face(d);
    CHECK(m.validate().ok());
    CHECK(m.count_all() == std::array<std::uint32_t, 3>{3, 4, 2});
  }
  SUBCASE("refused: a face of one dart, a dead dart") {
    CMap<2> m;
    const Dart d = m.make_polygon(1);
    CHECK_FALSE(m.is_insertable_vertex_in_face(d));
    CHECK_THROWS_AS(m.insert_vertex_in_face(d), TopologyError);
    CHECK_FALSE(m.is_insertable_vertex_in_face(Dart(99)));
    CHECK(m.validate().ok());
  }
}

TEST_CASE("insert_face_in_hole closes an open volume with one face") {
  SUBCASE("a hexahedron with a face removed, with attributes") {
    CMap<3, int, int, int, int> m;
    build(m, hex_grid(1, 1, 1));
    int next = 0;
    m.create_attributes<0>([&](Dart) { return next++; });
    m.create_attributes<1>([&](Dart) { return next++; });
    m.create_attributes<3>([&](Dart) { return next++; });
    int hooks = 0;
    m.on_merge<0>([&](AttrId<0>, AttrId<0>) { ++hooks; });
    m.on_split<1>([&](AttrId<1>, AttrId<1>) { ++hooks; });
    const Dart f = *m.cells<2>().begin();
    const Dart open = m.beta(f, 2);
    m.remove_cell<2>(f);
    REQUIRE(m.validate().ok());
    REQUIRE(m.is_free(open, 2));
    CHECK_THROWS_AS(topology(m), TopologyError);  // an open volume is not a cell
    const auto ring = hole_ring(m, open);
    REQUIRE(ring.size() == 4);
    REQUIRE(m.is_insertable_face_in_hole(ring));
    hooks = 0;
    const Dart p = m.insert_face_in_hole(ring);
    CHECK(hooks == 0);
    CHECK(m.validate().ok());
    CHECK(m.beta(ring[0], 2) == p);
    CHECK(m.is_free(p, 3));
    CHECK(m.attribute<1>(p) == m.attribute<1>(ring[0]));
    CHECK(m.attribute<3>(p) == m.attribute<3>(ring[0]));
    CHECK(m.attribute<0>(p) == m.attribute<0>(ring[1]));
    CHECK(m.count_all() == std::array<std::uint32_t, 4>{8, 12, 6, 1});
    const Topology t = topology(m);
    CHECK(t.total.betti == std::array<std::int64_t, 4>{1, 0, 0, 0});
    REQUIRE(t.boundary.size() == 1);
    CHECK(t.boundary[0].genus == 0);
  }
  SUBCASE("refused: sewn darts, an open chain, a dart twice") {
    CMap<3> m;
    const Dart h = m.make_hexahedron();
    const std::vector<Dart> face = m.orbit<1>(h).size() == 4 ? std::vector<Dart>{h, m.beta(h, 1), m.beta(h, 1, 1), m.beta(h, 0)}
                                                             : std::vector<Dart>{};
    CHECK_FALSE(m.is_insertable_face_in_hole(face));  // 2-sewn darts
    CHECK_THROWS_AS(m.insert_face_in_hole(face), TopologyError);
    const Dart f = m.beta(h, 2);
    m.remove_cell<2>(f);
    const auto ring = hole_ring(m, h);
    REQUIRE(ring.size() == 4);
    CHECK_FALSE(m.is_insertable_face_in_hole(std::vector<Dart>(ring.begin(), ring.begin() + 3)));
    CHECK_FALSE(m.is_insertable_face_in_hole(std::vector<Dart>{ring[0], ring[1], ring[2], ring[3], ring[0]}));
    CHECK(m.is_insertable_face_in_hole(ring));
    CHECK(m.validate().ok());
  }
}

TEST_CASE("insert_dangling_edge_in_face adds an edge to a new vertex inside the face") {
  SUBCASE("2-map, attributes") {
    CMap<2, int, int, int> m;
    build(m, quad_grid(2, 2));
    int next = 0;
    m.create_attributes<0>([&](Dart) { return next++; });
    m.create_attributes<2>([&](Dart) { return next++; });
    int hooks = 0;
    m.on_split<2>([&](AttrId<2>, AttrId<2>) { ++hooks; });
    m.on_merge<0>([&](AttrId<0>, AttrId<0>) { ++hooks; });
    const auto n = m.count_all();
    const Dart d = *m.cells<2>().begin();
    const Dart a = m.insert_dangling_edge_in_face(d);
    CHECK(m.validate().ok());
    CHECK(hooks == 0);
    CHECK(m.count_all() == std::array<std::uint32_t, 3>{n[0] + 1, n[1] + 1, n[2]});
    CHECK(m.same_cell<0>(a, d));
    CHECK(m.attribute<0>(a) == m.attribute<0>(d));
    CHECK(m.attribute<0>(m.beta(a, 1)).is_null());
    CHECK(m.attribute<2>(a) == m.attribute<2>(d));
    CHECK(m.beta(a, 1, 1) == d);
    CHECK(face_size(m, d) == 6);
    CHECK(topology(m).total.betti == std::array<std::int64_t, 4>{1, 0, 0, 0});
  }
  SUBCASE("3-map, a face between two volumes, then a vertex in the same face") {
    CMap<3> m;
    build(m, hex_grid(2, 1, 1));
    Dart inner;
    for (Dart x : m.darts())
      if (m.beta(x, 3)) inner = x;
    const auto n = m.count_all();
    const Dart a = m.insert_dangling_edge_in_face(inner);
    CHECK(m.validate().ok());
    CHECK(m.count_all() == std::array<std::uint32_t, 4>{n[0] + 1, n[1] + 1, n[2], n[3]});
    CHECK(m.cell<1>(a).size() == 4);
    CHECK(topology(m).total.betti == std::array<std::int64_t, 4>{1, 0, 0, 0});
    m.insert_vertex_in_face(inner);
    CHECK(m.validate().ok());
    CHECK(topology(m).total.betti == std::array<std::int64_t, 4>{1, 0, 0, 0});
  }
  SUBCASE("refused: a dead dart") {
    CMap<2> m;
    m.make_polygon(3);
    CHECK_FALSE(m.is_insertable_dangling_edge_in_face(Dart(40)));
    CHECK_THROWS_AS(m.insert_dangling_edge_in_face(Dart(40)), TopologyError);
  }
}
