// insert_vertex_in_face and insert_face_in_hole: counts, validate(), attributes and hooks, the
// topology they must keep, and the inputs they refuse.
#include <doctest/doctest.h>

#include <string>
#include <utility>
#include <vector>

#include "check.hpp"
#include "sewn/cmap/build.hpp"
#include "sewn/cmap/cmap.hpp"
#include "sewn/cmap/topology.hpp"

namespace test_ops_faces {

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

namespace {

// insert_vertex_in_face as the sequence of smaller insertions it was first written as (an edge
// from d's start to the next vertex, split by the new vertex, then an edge from it to each other
// vertex): the reference the one-pass version is compared with.
template <class M>
Dart star_by_smaller_insertions(M& m, Dart d) {
  std::vector<Dart> c;
  for (Dart x = d;;) {
    c.push_back(x);
    x = m.beta(x, 1);
    if (x == d) break;
  }
  const Dart h = m.insert_edge_in_face(c[0], c[1]);
  const Dart w = m.insert_vertex_in_edge(h);
  Dart a = w;
  for (std::size_t j = 2; j < c.size(); ++j) a = m.insert_edge_in_face(a, c[j]);
  return w;
}

// Empty if a and b, copies of one map that each made new darts, are the same map: the darts both
// had keep their indices, and a walk from them along every βi pairs each new dart of a with one
// of b (the pairing must stay one-to-one), starting from the pair (wa, wb). Each pair must hold
// the same attribute values (or none) in every dimension and the same per-dart info.
template <class M>
std::string same_map(const M& a, const M& b, std::uint32_t old_capacity, Dart wa, Dart wb) {
  constexpr int D = M::dimension;
  if (a.num_darts() != b.num_darts()) return "dart counts differ";
  std::vector<std::uint32_t> to_b(a.dart_capacity(), Dart::null_index), to_a(b.dart_capacity(), Dart::null_index);
  std::vector<std::pair<Dart, Dart>> queue;
  auto pair = [&](Dart x, Dart y) {
    if (!x || !y) return x.is_null() == y.is_null();
    if (x.index() < old_capacity || y.index() < old_capacity) return x == y;
    if (to_b[x.index()] == Dart::null_index && to_a[y.index()] == Dart::null_index) {
      to_b[x.index()] = y.index();
      to_a[y.index()] = x.index();
      queue.emplace_back(x, y);
      return true;
    }
    return to_b[x.index()] == y.index();
  };
  for (Dart x : a.darts())
    if (x.index() < old_capacity) queue.emplace_back(x, x);
  if (!pair(wa, wb)) return "the returned darts differ";
  for (std::size_t q = 0; q < queue.size(); ++q) {
    const Dart x = queue[q].first, y = queue[q].second;  // no structured binding: clang 14 cannot capture one
    for (int i = 0; i <= D; ++i)
      if (!pair(a.beta(x, i), b.beta(y, i)))
        return "beta" + std::to_string(i) + " of dart " + std::to_string(x.index()) + " differs";
    std::string diff;
    [&]<int... I>(std::integer_sequence<int, I...>) {
      (
          [&] {
            if constexpr (M::template has_attribute<I>) {
              const auto ax = a.template attribute<I>(x), by = b.template attribute<I>(y);
              if (ax.is_null() != by.is_null() || (ax && a.value(ax) != b.value(by)))
                diff = std::to_string(I) + "-attribute of dart " + std::to_string(x.index()) + " differs";
            }
          }(),
          ...);
    }(std::make_integer_sequence<int, D + 1>{});
    if (!diff.empty()) return diff;
    if constexpr (M::has_dart_info)
      if (a.info(x) != b.info(y)) return "info of dart " + std::to_string(x.index()) + " differs";
  }
  if (queue.size() != a.num_darts()) return "some new darts are not reached from the old ones";
  return {};
}

// Runs both versions on copies of m at dart d and compares them; also the split hooks (one per
// triangle but d's) and validate().
template <class M>
void check_against_smaller_insertions(const M& m, Dart d) {
  M one = m, ref = m;
  int splits = 0;
  if constexpr (M::template has_attribute<2>) one.template on_split<2>([&](AttrId<2>, AttrId<2>) { ++splits; });
  const auto k = static_cast<int>(m.template orbit<1>(d).size());
  const Dart w1 = one.insert_vertex_in_face(d);
  const Dart w2 = star_by_smaller_insertions(ref, d);
  REQUIRE(one.validate().ok());
  REQUIRE(ref.validate().ok());
  CHECK(one.count_all() == ref.count_all());
  const std::string diff = same_map(one, ref, m.dart_capacity(), w1, w2);
  CHECK_MESSAGE(diff.empty(), diff);
  if constexpr (M::template has_attribute<2>)
    if (m.template attribute<2>(d)) {
      CHECK(splits == k - 1);
      CHECK(one.template attribute<2>(d) == m.template attribute<2>(d));  // d's triangle keeps it
    }
}

using Map2 = CMap<2, DartInfo<std::uint32_t>, int, int, int>;
using Map3 = CMap<3, DartInfo<std::uint32_t>, int, int, int, int>;
using Map4 = CMap<4, int, int, int, int, int>;

template <class M>
void label(M& m) {
  sewn::test::label_all_cells(m);
  if constexpr (M::has_dart_info)
    for (Dart x : m.darts()) m.info(x) = x.index() + 1;
}

TEST_CASE("insert_vertex_in_face in one pass makes the map its smaller insertions make") {
  SUBCASE("2-maps: every face of a grid, a pentagon, a 2-gon") {
    Map2 m;
    build(m, quad_grid(3, 2));
    m.make_polygon(5);
    m.make_polygon(2);
    label(m);
    for (Dart d : m.darts()) check_against_smaller_insertions(m, d);
  }
  SUBCASE("3-maps: every face of a grid, inner faces on both sides") {
    Map3 m;
    build(m, hex_grid(2, 2, 1));
    label(m);
    for (Dart d : m.darts()) check_against_smaller_insertions(m, d);
  }
  SUBCASE("faces without attributes split into triangles without attributes") {
    Map3 m;
    build(m, hex_grid(2, 1, 1));
    for (Dart d : m.darts()) check_against_smaller_insertions(m, d);
  }
  SUBCASE("4-maps: a face with copies across beta3 and beta4") {
    Map4 m;
    const Dart a = m.make_hexahedron(), b = m.make_hexahedron(), c = m.make_hexahedron(), e = m.make_hexahedron();
    m.sew<3>(a, b);
    m.sew<3>(c, e);
    m.sew<4>(a, c);
    m.sew<4>(b, e);
    REQUIRE(m.validate().ok());
    label(m);
    REQUIRE(m.beta(a, 3, 4) == m.beta(a, 4, 3));
    for (Dart d : {a, m.beta(a, 1), b, m.beta(c, 0)}) check_against_smaller_insertions(m, d);
    const auto before = m.count_all();
    m.insert_vertex_in_face(a);
    CHECK(m.count_all() == std::array<std::uint32_t, 5>{before[0] + 1, before[1] + 4, before[2] + 3, before[3], before[4]});
  }
}

TEST_CASE("insert_vertex_in_face with a value gives the new vertex one attribute") {
  CMap<3, int> m;
  build(m, hex_grid(2, 1, 1));
  m.create_attributes<0>([](Dart) { return 1; });
  Dart inner;
  for (Dart x : m.darts())
    if (m.beta(x, 3)) inner = x;
  const Dart w = m.insert_vertex_in_face(inner, 42);
  CHECK(m.validate().ok());
  REQUIRE(m.attribute<0>(w));
  CHECK(m.value(m.attribute<0>(w)) == 42);
  CHECK(m.cell<0>(w).size() == 8);  // four new edges, two sides each
  for (Dart x : m.cell<0>(w)) CHECK(m.attribute<0>(x) == m.attribute<0>(w));
  CHECK(m.num_attributes<0>() == 13);
}

TEST_CASE("insert_vertex_in_face refuses a face sewn to itself") {
  CMap<3> m;
  const Dart p = m.make_polygon(2);
  m.link_beta<3>(p, m.beta(p, 1));
  REQUIRE(m.validate().ok());
  CHECK_FALSE(m.is_insertable_vertex_in_face(p));
  CHECK_THROWS_AS(m.insert_vertex_in_face(p), TopologyError);
  CHECK(m.num_darts() == 2);
}

}  // namespace

}  // namespace test_ops_faces
