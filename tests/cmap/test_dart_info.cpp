// Per-dart data (DartInfo<T>): what each operation does with it, as cmap.hpp's info() states.
#include <doctest/doctest.h>

#include <cstdint>
#include <string>
#include <vector>

#include "sewn/cmap/build.hpp"
#include "sewn/cmap/cmap.hpp"

namespace test_dart_info {

using namespace sewn;

namespace dart_info_test {

template <class M>
void require_valid(const M& m) {
  const auto r = m.validate();
  REQUIRE_MESSAGE(r.ok(), r.str());
}

// Gives every live dart its index + 1 as info (0 is the default value).
template <class M>
void tag_by_index(M& m) {
  for (Dart d : m.darts()) m.info(d) = d.index() + 1;
}

}  // namespace dart_info_test

using dart_info_test::require_valid;
using dart_info_test::tag_by_index;

TEST_CASE("dart info: created default, kept by sew and unsew, dropped with erased darts") {
  CMap<2, DartInfo<std::uint32_t>, int> m;
  static_assert(decltype(m)::has_dart_info && decltype(m)::has_attribute<0> && !decltype(m)::has_attribute<1>);
  const Dart a = m.make_triangle(), b = m.make_triangle();
  for (Dart d : m.darts()) CHECK(m.info(d) == 0u);
  tag_by_index(m);
  m.sew<2>(a, b);
  require_valid(m);
  for (Dart d : m.darts()) CHECK(m.info(d) == d.index() + 1);
  m.unsew<2>(a);
  require_valid(m);
  for (Dart d : m.darts()) CHECK(m.info(d) == d.index() + 1);
  // erase one triangle: its slots are reused by the next darts, which must not see old values
  m.remove_cell<2>(b);
  require_valid(m);
  const Dart c = m.make_triangle();
  require_valid(m);
  bool reused = false;
  for (Dart d : m.orbit<1>(c)) {
    reused = reused || d.index() < 6;
    CHECK(m.info(d) == 0u);
  }
  CHECK(reused);  // the test exercises a reused slot
  for (Dart d : m.orbit<1>(a)) CHECK(m.info(d) == d.index() + 1);
  CHECK_THROWS_AS((void)m.info(Dart(1000)), TopologyError);
}

TEST_CASE("dart info: insertions copy the argument dart, per the rule in cmap.hpp") {
  SUBCASE("insert_vertex_in_edge: each new dart copies the dart it was split from") {
    CMap<2, DartInfo<std::uint32_t>> m;
    build(m, quad_grid(2, 1));
    tag_by_index(m);
    const Dart d = *m.cells<1>().begin();
    const auto edge = m.cell<1>(d);
    m.insert_vertex_in_edge(d);
    require_valid(m);
    for (Dart x : edge) CHECK(m.info(m.beta(x, 1)) == x.index() + 1);
  }
  SUBCASE("insert_edge_in_face across a 3-sewn face: each side copies its own argument") {
    CMap<3, DartInfo<std::uint32_t>> m;
    build(m, hex_grid(2, 1, 1));
    tag_by_index(m);
    Dart a = null_dart;
    for (Dart x : m.darts())
      if (!m.is_free(x, 3)) {
        a = x;
        break;
      }
    REQUIRE(a);
    const Dart a3 = m.beta(a, 3);
    const Dart n1 = m.insert_edge_in_face(a, m.beta(a, 1, 1));
    require_valid(m);
    CHECK(m.info(n1) == a.index() + 1);
    CHECK(m.info(m.beta(n1, 2)) == a.index() + 1);
    CHECK(m.info(m.beta(n1, 3)) == a3.index() + 1);
    CHECK(m.info(m.beta(n1, 2, 3)) == a3.index() + 1);
  }
  SUBCASE("insert_vertex_in_face and insert_dangling_edge_in_face: every new dart copies d") {
    CMap<2, DartInfo<std::uint32_t>> m;
    const Dart d = m.make_quad();
    tag_by_index(m);
    const Dart w = m.insert_vertex_in_face(d);
    require_valid(m);
    CHECK(m.num_darts() == 12u);
    std::uint32_t copies = 0;
    for (Dart x : m.darts())
      if (x.index() >= 4) copies += m.info(x) == d.index() + 1 ? 1u : 0u;
    CHECK(copies == 8u);
    CHECK(m.info(w) == d.index() + 1);
    const Dart e = m.insert_dangling_edge_in_face(w);
    require_valid(m);
    CHECK(m.info(e) == d.index() + 1);
    CHECK(m.info(m.beta(e, 2)) == d.index() + 1);
  }
  SUBCASE("insert_face_in_volume and insert_face_in_hole: the new darts copy their path dart") {
    CMap<3, DartInfo<std::uint32_t>> m;
    const Dart h = m.make_hexahedron();
    tag_by_index(m);
    // a face inserted along the cycle of one of the volume's faces (the operation allows it)
    std::vector<Dart> cyc{h};
    for (Dart x = m.beta(h, 1); x != h; x = m.beta(x, 1)) cyc.push_back(x);
    REQUIRE(m.is_insertable_face_in_volume(cyc));
    std::vector<std::uint32_t> before;
    for (Dart x : cyc) before.push_back(m.info(x));
    const Dart p0 = m.insert_face_in_volume(cyc);
    require_valid(m);
    CHECK(p0 == m.beta(cyc[0], 2));
    for (std::size_t i = 0; i < cyc.size(); ++i) {
      CHECK(m.info(cyc[i]) == before[i]);
      CHECK(m.info(m.beta(cyc[i], 2)) == before[i]);
      CHECK(m.info(m.beta(cyc[i], 2, 3)) == before[i]);
    }
    // remove a face of a fresh hexahedron, then close the hole
    CMap<3, DartInfo<std::uint32_t>> k;
    const Dart f = k.make_hexahedron();
    tag_by_index(k);
    std::vector<Dart> hole;
    Dart x = f;
    do {  // the hole's ring is the face's β2 partners, in reverse order
      hole.insert(hole.begin(), k.beta(x, 2));
      x = k.beta(x, 1);
    } while (x != f);
    k.remove_cell<2>(f);
    require_valid(k);
    REQUIRE(k.is_insertable_face_in_hole(hole));
    k.insert_face_in_hole(hole);
    require_valid(k);
    for (Dart r : hole) CHECK(k.info(k.beta(r, 2)) == r.index() + 1);
  }
}

// "d<i>", built by appending: GCC 12 reports a false -Wrestrict overlap in the inlined
// `"d" + std::string&&` (its bug 105329) once this test shares a unity file with others.
std::string label(std::uint32_t i) {
  std::string s(1, 'd');
  s += std::to_string(i);
  return s;
}

TEST_CASE("dart info: contraction, compaction and copies keep each dart's value") {
  CMap<2, DartInfo<std::string>> m;  // a value that owns memory
  build(m, quad_grid(3, 3));
  for (Dart d : m.darts()) m.info(d) = label(d.index());
  const Dart e = *m.cells<1>().begin();
  REQUIRE(m.is_contractible<1>(e));
  const std::uint32_t before = m.num_darts(), gone = static_cast<std::uint32_t>(m.cell<1>(e).size());
  m.contract_cell<1>(e);
  require_valid(m);
  CHECK(m.num_darts() == before - gone);
  for (Dart x : m.darts()) CHECK(m.info(x) == label(x.index()));
  const CMap<2, DartInfo<std::string>> copy = m;
  const std::vector<Dart> to = m.compact();
  require_valid(m);
  for (std::uint32_t old = 0; old < to.size(); ++old) {
    if (to[old].is_null()) continue;
    CHECK(m.info(to[old]) == label(old));
    CHECK(copy.info(Dart(old)) == label(old));
  }
  // the contracted edge's slots were compacted away: new darts start empty
  const Dart t = m.make_triangle();
  for (Dart x : m.orbit<1>(t)) CHECK(m.info(x).empty());
}

TEST_CASE("dart info: a map without it stores nothing more per dart") {
  CMap<3> plain;
  CMap<3, DartInfo<std::uint32_t>> tagged;
  build(plain, hex_grid(4, 4, 4));
  build(tagged, hex_grid(4, 4, 4));
  REQUIRE(plain.num_darts() == tagged.num_darts());
  // the only difference is one value per dart slot
  const std::size_t extra = tagged.memory_bytes() - plain.memory_bytes();
  CHECK(extra >= std::size_t{tagged.dart_capacity()} * sizeof(std::uint32_t));
  CHECK(extra < std::size_t{tagged.dart_capacity()} * sizeof(std::uint32_t) * 2);
  CHECK(sizeof(CMap<3>) < sizeof(CMap<3, DartInfo<std::uint32_t>>));
}

}  // namespace test_dart_info
