// Insertion, removal and contraction, in 1D to 4D maps, with validation and counts at each step.
#include <doctest/doctest.h>

#include <vector>

#include "check.hpp"
#include "sewn/cmap/cmap.hpp"

namespace test_ops {

using namespace sewn;
using sewn::test::check_map;
using sewn::test::counts;
using sewn::test::label_all_cells;

using Map1 = CMap<1, int, int>;
using Map2 = CMap<2, int, int, int>;
using Map3 = CMap<3, int, int, int, int>;
using Map4 = CMap<4, int, int, int, int, int>;

namespace {

template <class M>
std::array<std::uint32_t, M::dimension + 1> plus(std::array<std::uint32_t, M::dimension + 1> a,
                                                 std::initializer_list<int> delta) {
  std::size_t k = 0;
  for (int d : delta) a[k] = static_cast<std::uint32_t>(static_cast<int>(a[k]) + d), ++k;
  return a;
}

}  // namespace

TEST_CASE_TEMPLATE("insert a vertex in an edge splits the edge attribute once", M, Map1, Map2, Map3, Map4) {
  M m;
  const Dart p = m.make_polygon(3);
  label_all_cells(m);
  int splits = 0;
  m.template on_split<1>([&](AttrId<1> a, AttrId<1> b) {
    CHECK(m.value(a) == m.value(b));
    ++splits;
  });
  const auto before = check_map(m);
  const Dart v = m.insert_vertex_in_edge(p);
  CHECK(m.beta(p, 1) == v);
  const auto after = check_map(m);
  CHECK(after[0] == before[0] + 1);
  CHECK(after[1] == before[1] + 1);
  CHECK(splits == 1);
  CHECK(m.template attribute<0>(v).is_null());  // the new vertex has no attribute until given one
  CHECK(m.template attribute<1>(v) != m.template attribute<1>(p));
  // removing the new vertex (degree two) merges the halves back
  int merges = 0;
  m.template on_merge<1>([&](AttrId<1>, AttrId<1>) { ++merges; });
  REQUIRE(m.template is_removable<0>(v));
  m.template remove_cell<0>(v);
  CHECK(check_map(m) == before);
  CHECK(merges == 1);
}

TEST_CASE_TEMPLATE("insert a vertex in an edge shared by several faces and volumes", M, Map3, Map4) {
  M m;
  const Dart a = m.make_hexahedron(), b = m.make_hexahedron();
  Dart partner;
  for (Dart x : m.template cell<2>(b))
    if (m.template is_sewable<3>(a, x)) partner = x;
  m.template sew<3>(a, partner);
  label_all_cells(m);
  const auto before = check_map(m);
  const std::uint32_t darts = m.num_darts();
  m.insert_vertex_in_edge(a);  // an edge of the shared face: 3 faces, 4 darts around it
  const auto after = check_map(m);
  CHECK(m.num_darts() == darts + 4);
  CHECK(after == plus<M>(before, {1, 1}));
}

TEST_CASE_TEMPLATE("insert a vertex in an edge with a value gives the whole new vertex one attribute", M, Map1, Map2,
                   Map3, Map4) {
  M m;
  Dart e = m.make_polygon(3);
  if constexpr (M::dimension >= 3) {  // an edge of a face shared by two volumes: 4 darts around it
    const Dart a = m.make_hexahedron(), b = m.make_hexahedron();
    Dart partner;
    for (Dart x : m.template cell<2>(b))
      if (m.template is_sewable<3>(a, x)) partner = x;
    m.template sew<3>(a, partner);
    e = a;
  }
  label_all_cells(m);
  int splits = 0;
  m.template on_split<1>([&](AttrId<1>, AttrId<1>) { ++splits; });
  const auto before = check_map(m);
  const std::uint32_t vertices = m.template num_attributes<0>(), darts = m.num_darts();
  const Dart v = m.insert_vertex_in_edge(e, 77);
  CHECK(m.beta(e, 1) == v);
  const auto after = check_map(m);  // validates: every dart of the vertex carries its attribute
  CHECK(after == plus<M>(before, {1, 1}));
  CHECK(splits == 1);
  const AttrId<0> a = m.template attribute<0>(v);
  REQUIRE(!a.is_null());
  CHECK(m.value(a) == 77);
  CHECK(m.template num_attributes<0>() == vertices + 1);
  const auto vertex = m.template cell<0>(v);
  CHECK(vertex.size() == m.num_darts() - darts);  // the new darts, and only they
  for (Dart x : vertex) CHECK(m.template attribute<0>(x) == a);
  // a dead dart is refused before anything is made
  m.template remove_cell<0>(v);
  CHECK_THROWS_AS(m.insert_vertex_in_edge(v, 5), TopologyError);
  CHECK(m.template num_attributes<0>() == vertices);
  CHECK(check_map(m) == before);
}

TEST_CASE("insert an edge in a face: 2D, and a face shared by two volumes") {
  SUBCASE("a quad becomes two triangles") {
    Map2 m;
    const Dart q = m.make_quad();
    label_all_cells(m);
    int splits = 0;
    m.on_split<2>([&](AttrId<2>, AttrId<2>) { ++splits; });
    const Dart e = m.insert_edge_in_face(q, m.beta(q, 1, 1));
    const auto n = check_map(m);
    CHECK(n == counts<3>({4, 5, 2}));
    CHECK(splits == 1);
    CHECK(m.cell<2>(q).size() == 3);
    CHECK(m.cell<2>(e).size() == 3);
    CHECK(m.attribute<2>(q) != m.attribute<2>(e));
    CHECK(m.attribute<1>(e).is_null());
    CHECK_FALSE(m.is_insertable_edge_in_face(q, q));
    CHECK_THROWS_AS(m.insert_edge_in_face(q, q), TopologyError);
  }
  SUBCASE("both sides of a 3-sewn face are split") {
    Map3 m;
    const Dart a = m.make_hexahedron(), b = m.make_hexahedron();
    Dart partner;
    for (Dart x : m.cell<2>(b))
      if (m.is_sewable<3>(a, x)) partner = x;
    m.sew<3>(a, partner);
    label_all_cells(m);
    const auto before = check_map(m);
    const std::uint32_t darts = m.num_darts();
    const Dart e = m.insert_edge_in_face(a, m.beta(a, 1, 1));
    const auto after = check_map(m);
    CHECK(m.num_darts() == darts + 4);
    CHECK(after == plus<Map3>(before, {0, 1, 1, 0}));
    CHECK(m.beta(e, 3));  // the new edge is 3-sewn to its copy in the other volume
  }
  SUBCASE("a face shared by two 4-cells (D = 4) is split in both") {
    Map4 m;
    const Dart a = m.make_hexahedron(), b = m.make_hexahedron();
    m.sew<4>(a, b);
    label_all_cells(m);
    const auto before = check_map(m);
    const Dart e = m.insert_edge_in_face(a, m.beta(a, 1, 1));
    CHECK(check_map(m) == plus<Map4>(before, {0, 1, 1, 0, 0}));
    CHECK(m.beta(e, 4));
  }
}

TEST_CASE_TEMPLATE("insert a face in a volume along a belt of new edges splits the hexahedron", M, Map3, Map4) {
  M m;
  const Dart h = m.make_hexahedron();
  label_all_cells(m);
  int vol_splits = 0;
  m.template on_split<3>([&](AttrId<3>, AttrId<3>) { ++vol_splits; });
  // 1) a new vertex in each of the 4 vertical edges: the edges leaving the bottom face upward
  const Dart bottom = m.beta(h, 2);  // h runs 0->1 on face {0,1,5,4}; its β2 lies on the bottom face
  std::vector<Dart> mids;
  Dart x = bottom;
  for (int k = 0; k < 4; ++k, x = m.beta(x, 1)) {
    // the vertical edge leaving x's start vertex: within the volume, β2 then β1 climbs up
    mids.push_back(m.insert_vertex_in_edge(m.beta(x, 2, 1)));
  }
  check_map(m);
  // 2) in each side face, an edge between its two new vertices
  std::vector<Dart> belt;
  for (Dart mid : mids) {
    Dart other = m.beta(mid, 1);
    while (m.template attribute<0>(other).is_null() == false) other = m.beta(other, 1);
    belt.push_back(m.insert_edge_in_face(mid, other));
  }
  const auto before = check_map(m);
  auto hex = counts<M::dimension + 1>({8, 12, 6, 1});
  if constexpr (M::dimension == 4) hex[4] = 1;
  CHECK(before == plus<M>(hex, {4, 8, 4}));
  // 3) the belt as a closed chain of darts of the volume, then the face
  std::vector<Dart> path;
  std::vector<Dart> pool;
  for (Dart e : belt) {
    pool.push_back(e);
    pool.push_back(m.beta(e, 2));
  }
  path.push_back(pool[0]);
  while (path.size() < 4) {
    const Dart end = m.beta(path.back(), 1);
    Dart next;
    for (Dart c : pool)
      if (m.template same_cell<0>(c, end) && !m.template same_cell<1>(c, path.back())) next = c;
    REQUIRE(next);
    path.push_back(next);
  }
  REQUIRE(m.is_insertable_face_in_volume(path));
  const Dart f = m.insert_face_in_volume(path);
  const auto after = check_map(m);
  CHECK(after == plus<M>(before, {0, 0, 1, 1}));
  CHECK(vol_splits == 1);
  CHECK(m.template cell<3>(f).size() == 24);  // each half is a hexahedron again
  CHECK(m.template cell<3>(path[0]).size() == m.template cell<3>(f).size());
  CHECK(m.template attribute<2>(f).is_null());
  CHECK_FALSE(m.is_insertable_face_in_volume(std::vector<Dart>{path[0], path[1]}));
}

TEST_CASE("remove cells in 2D: an edge between two faces, a degree-two vertex") {
  Map2 m;
  const Dart p = m.make_quad(), q = m.make_quad();
  m.sew<2>(p, q);
  label_all_cells(m);
  int merges = 0;
  m.on_merge<2>([&](AttrId<2> kept, AttrId<2> gone) {
    CHECK(kept != gone);
    ++merges;
  });
  check_map(m);
  CHECK(m.is_removable<1>(p));
  m.remove_cell<1>(p);
  CHECK(check_map(m) == counts<3>({6, 6, 1}));
  CHECK(merges == 1);
  // the two vertices of the removed edge now have degree two
  Dart deg2;
  for (Dart d : m.cells<0>())
    if (m.cell<0>(d).size() == 1 && m.is_removable<0>(d)) deg2 = d;
  REQUIRE(deg2);
  m.remove_cell<0>(deg2);
  CHECK(check_map(m) == counts<3>({5, 5, 1}));
}

TEST_CASE("remove cells in 3D: the face between two hexahedra, then a whole volume") {
  Map3 m;
  const Dart a = m.make_hexahedron(), b = m.make_hexahedron(), c = m.make_hexahedron();
  Dart pb, pc;
  for (Dart x : m.cell<2>(b))
    if (m.is_sewable<3>(a, x)) pb = x;
  m.sew<3>(a, pb);
  // c against the face of b opposite to the shared one
  const Dart opposite = m.beta(pb, 2, 1, 1, 2);
  for (Dart x : m.cell<2>(c))
    if (m.is_sewable<3>(opposite, x)) pc = x;
  REQUIRE(pc);
  m.sew<3>(opposite, pc);
  label_all_cells(m);
  CHECK(check_map(m) == counts<4>({16, 28, 16, 3}));
  int vol_merges = 0;
  m.on_merge<3>([&](AttrId<3>, AttrId<3>) { ++vol_merges; });
  REQUIRE(m.is_removable<2>(a));
  m.remove_cell<2>(a);  // a and b become one volume with 10 faces
  CHECK(check_map(m) == counts<4>({16, 28, 15, 2}));
  CHECK(vol_merges == 1);
  int erased = 0;
  m.on_erase<3>([&](AttrId<3>) { ++erased; });
  m.remove_cell<3>(c);
  CHECK(check_map(m) == counts<4>({12, 20, 10, 1}));
  CHECK(erased == 1);
  CHECK(m.boundary_facets().size() == 10);
}

TEST_CASE("is_removable refuses cells with more than two neighbours") {
  Map3 m;
  const Dart h = m.make_hexahedron();
  CHECK_FALSE(m.is_removable<0>(h));  // a corner: three edges
  CHECK(m.is_removable<1>(h));        // an edge of a lone hexahedron: two faces
  CHECK_THROWS_AS(m.remove_cell<0>(h), TopologyError);
  check_map(m);
}

TEST_CASE_TEMPLATE("remove and contract in 1-maps and 4-maps", M, Map1, Map4) {
  M m;
  const Dart p = m.make_polygon(4);
  label_all_cells(m);
  m.template contract_cell<1>(m.beta(p, 1));
  auto n = check_map(m);
  CHECK(n[0] == 3);
  CHECK(n[1] == 3);
  m.template remove_cell<0>(p);
  n = check_map(m);
  CHECK(n[0] == 2);
  if constexpr (M::dimension == 4) {
    // two hexahedra 4-sewn: removing their shared 3-cell merges the two 4-cells
    M h;
    const Dart a = h.make_hexahedron(), b = h.make_hexahedron();
    h.template sew<4>(a, b);
    label_all_cells(h);
    CHECK(check_map(h) == counts<5>({8, 12, 6, 1, 2}));
    h.template remove_cell<3>(a);
    CHECK(check_map(h) == counts<5>({0, 0, 0, 0, 0}));
    CHECK(h.num_darts() == 0);
  }
}

TEST_CASE("contract an edge: its two vertices merge with on_merge") {
  Map2 m;
  const Dart q = m.make_quad();
  label_all_cells(m);
  std::vector<std::pair<int, int>> merged;
  m.on_merge<0>([&](AttrId<0> kept, AttrId<0> gone) { merged.emplace_back(m.value(kept), m.value(gone)); });
  m.contract_cell<1>(q);
  CHECK(check_map(m) == counts<3>({3, 3, 1}));
  CHECK(merged.size() == 1);
}

TEST_CASE("contract a two-edge face between two triangles: the triangles become neighbours") {
  Map2 m;
  const Dart bigon = m.make_polygon(2), t1 = m.make_triangle(), t2 = m.make_triangle();
  m.sew<2>(bigon, t1);
  m.sew<2>(m.beta(bigon, 1), t2);
  label_all_cells(m);
  CHECK(check_map(m) == counts<3>({4, 6, 3}));
  CHECK(m.is_contractible<2>(bigon));
  CHECK_FALSE(m.is_contractible<2>(t1));
  m.contract_cell<2>(bigon);
  CHECK(check_map(m) == counts<3>({4, 5, 2}));
  CHECK(m.beta(t1, 2) == t2);
  CHECK_THROWS_AS(m.contract_cell<2>(t1), TopologyError);
}

TEST_CASE("contract a pillow volume between two hexahedra: they become 3-sewn") {
  Map3 m;
  const Dart a = m.make_hexahedron(), b = m.make_hexahedron();
  const std::uint32_t f0[] = {0, 1, 2, 3}, f1[] = {0, 3, 2, 1};
  const std::span<const std::uint32_t> faces[] = {f0, f1};
  const Dart pillow = m.make_cell(faces);
  const Dart other = m.beta(pillow, 2);
  Dart pa, pb;
  for (Dart x : m.cell<2>(a))
    if (!pa && m.is_sewable<3>(pillow, x)) pa = x;
  REQUIRE(pa);
  m.sew<3>(pillow, pa);
  for (Dart x : m.cell<2>(b))
    if (!pb && m.is_sewable<3>(other, x)) pb = x;
  REQUIRE(pb);
  m.sew<3>(other, pb);
  label_all_cells(m);
  CHECK(check_map(m) == counts<4>({12, 20, 12, 3}));
  REQUIRE(m.is_contractible<3>(pillow));
  m.contract_cell<3>(pillow);
  CHECK(check_map(m) == counts<4>({12, 20, 11, 2}));
  CHECK(m.beta(pa, 3));
}

TEST_CASE("contract an edge shared by two hexahedra") {
  Map3 m;
  const Dart a = m.make_hexahedron(), b = m.make_hexahedron();
  Dart pb;
  for (Dart x : m.cell<2>(b))
    if (m.is_sewable<3>(a, x)) pb = x;
  m.sew<3>(a, pb);
  label_all_cells(m);
  const auto before = check_map(m);
  m.contract_cell<1>(a);
  const auto after = check_map(m);
  CHECK(after[0] == before[0] - 1);
  CHECK(after[1] == before[1] - 1);
  CHECK(after[2] == before[2]);
  CHECK(after[3] == 2);
}

}  // namespace test_ops
