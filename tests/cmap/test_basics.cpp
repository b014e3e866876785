// Darts, β access, marks, attributes, compaction and the make_* builders.
#include <doctest/doctest.h>

#include <algorithm>
#include <set>
#include <vector>

#include "check.hpp"
#include "sewn/cmap/build.hpp"
#include "sewn/cmap/cmap.hpp"

namespace test_basics {

using namespace sewn;
using sewn::test::check_map;

using Map1 = CMap<1, int, int>;
using Map2 = CMap<2, int, int, int>;
using Map3 = CMap<3, int, int, int, int>;
using Map4 = CMap<4, int, int, int, int, int>;
using Bare3 = CMap<3>;

TEST_CASE_TEMPLATE("darts are created, linked, erased and reused", M, Map1, Map2, Map3, Map4, Bare3) {
  M m;
  const Dart a = m.create_dart(), b = m.create_dart();
  CHECK(m.num_darts() == 2);
  CHECK(m.is_free(a, 1));
  m.template link_beta<1>(a, b);
  CHECK(m.beta(a, 1) == b);
  CHECK(m.beta(b, 0) == a);
  CHECK(m.template beta<0>(b) == a);
  CHECK(m.beta(a, 1, 0) == a);
  CHECK_THROWS_AS(m.erase_dart(a), TopologyError);  // still linked
  m.template unlink_beta<1>(a);
  CHECK(m.is_free(b, 0));
  m.erase_dart(a);
  CHECK(m.num_darts() == 1);
  CHECK_FALSE(m.is_alive(a));
  CHECK_THROWS_AS((void)m.beta(a, 1), TopologyError);
  CHECK_THROWS_AS((void)m.beta(Dart(999), 1), TopologyError);
  CHECK_THROWS_AS((void)m.beta(null_dart, 1), TopologyError);
  CHECK_THROWS_AS((void)m.beta(b, M::dimension + 1), TopologyError);
  const Dart c = m.create_dart();
  CHECK(c == a);  // the free slot is reused
  check_map(m);
}

TEST_CASE_TEMPLATE("polygons and polylines", M, Map1, Map2, Map3, Map4) {
  M m;
  const Dart p = m.make_polygon(5);
  auto n = check_map(m);
  CHECK(n[0] == 5);
  CHECK(n[1] == 5);
  CHECK(m.component(p).size() == 5);
  const Dart l = m.make_polyline(3);
  n = check_map(m);
  if constexpr (M::dimension == 1) {
    CHECK(m.num_darts() == 8);
    CHECK(n[1] == 8);  // one dart per edge in a 1-map
    CHECK(m.beta(l, 1, 1));
    CHECK_FALSE(m.beta(l, 1, 1, 1));
  } else {
    CHECK(m.num_darts() == 11);
    CHECK(n[0] == 5 + 4);  // an open chain of 3 edges has 4 vertices
    CHECK(n[1] == 5 + 3);
    CHECK(m.beta(l, 1, 2, 1) == m.beta(l, 2));  // backward darts run in reverse
  }
  CHECK_THROWS_AS(m.make_polygon(0), TopologyError);
}

TEST_CASE_TEMPLATE("polyhedra have the expected cells", M, Map3, Map4, Bare3) {
  M m;
  SUBCASE("tetrahedron") {
    m.make_tetrahedron();
    const auto n = check_map(m);
    CHECK(n[0] == 4);
    CHECK(n[1] == 6);
    CHECK(n[2] == 4);
    CHECK(n[3] == 1);
    CHECK(m.num_darts() == 12);
  }
  SUBCASE("hexahedron") {
    const Dart d = m.make_hexahedron();
    const auto n = check_map(m);
    CHECK(n[0] == 8);
    CHECK(n[1] == 12);
    CHECK(n[2] == 6);
    CHECK(n[3] == 1);
    CHECK(m.num_darts() == 24);
    CHECK(m.template incident<3, 0>(d).size() == 8);
    CHECK(m.template incident<0, 1>(d).size() == 3);
    CHECK(m.template incident<1, 2>(d).size() == 2);
    CHECK(m.template adjacent<2>(d).size() == 4);
    CHECK(m.template adjacent<0>(d).size() == 3);
    CHECK(m.boundary_facets().size() == (M::dimension == 3 ? 6u : 1u));  // (D-1)-cells with a D-free dart
  }
  SUBCASE("prism and pyramid") {
    m.make_prism();
    m.make_pyramid();
    const auto n = check_map(m);
    CHECK(n[0] == 6 + 5);
    CHECK(n[1] == 9 + 8);
    CHECK(n[2] == 5 + 5);
    CHECK(n[3] == 2);
    CHECK(m.count_components() == 2);
  }
}

TEST_CASE("make_cell refuses malformed face tables without touching the map") {
  Map3 m;
  const std::uint32_t f0[] = {0, 1, 2}, f1[] = {0, 2, 1}, f2[] = {0, 1, 3};
  const std::span<const std::uint32_t> open[] = {f0, f2};            // edges in one face only
  const std::span<const std::uint32_t> same_dir[] = {f0, f0};        // not outward
  const std::span<const std::uint32_t> pillow[] = {f0, f1};          // a valid 2-face cell
  CHECK_THROWS_AS(m.make_cell(open), TopologyError);
  CHECK_THROWS_AS(m.make_cell(same_dir), TopologyError);
  CHECK(m.num_darts() == 0);
  m.make_cell(pillow);
  const auto n = check_map(m);
  CHECK(n[2] == 2);
  CHECK(n[3] == 1);
}

TEST_CASE("marks: reservation, RAII, O(1) unmark-all and exhaustion") {
  Map3 m;
  m.make_hexahedron();
  m.make_hexahedron();
  {
    ScopedMark<Map3> mark(m);
    CHECK(m.num_reserved_marks() == 1);
    for (Dart d : m.darts()) m.mark(d, mark);
    CHECK(m.num_marked(mark) == 48);
    m.unmark_all(mark);  // all marked: polarity flip
    for (Dart d : m.darts()) CHECK_FALSE(m.is_marked(d, mark));
    m.mark(Dart(3), mark);
    m.unmark_all(mark);  // partial: plane cleared
    CHECK_FALSE(m.is_marked(Dart(3), mark));
    for (Dart d : m.darts()) m.mark(d, mark);
  }  // freed with every dart marked
  CHECK(m.num_reserved_marks() == 0);
  {
    ScopedMark<Map3> mark(m);  // the same plane comes back clean
    for (Dart d : m.darts()) CHECK_FALSE(m.is_marked(d, mark));
    ScopedMarker<Map3> few(m);
    CHECK(few.mark(Dart(5)));
    CHECK_FALSE(few.mark(Dart(5)));
    CHECK(few.is_marked(Dart(5)));
    CHECK(m.num_reserved_marks() == 2);
  }
  // A dart erased while marked is unmarked, and comes back unmarked when reused.
  {
    ScopedMark<Map3> mark(m);
    const Dart x = m.create_dart();
    m.mark(x, mark);
    m.erase_dart(x);
    CHECK(m.num_marked(mark) == 0);
    const Dart y = m.create_dart();
    CHECK(y == x);
    CHECK_FALSE(m.is_marked(y, mark));
    m.erase_dart(y);
  }
  std::vector<Mark> all;
  for (int k = 0; k < detail::MarkPlanes::max_marks; ++k) all.push_back(m.reserve_mark());
  CHECK_THROWS_AS((void)m.reserve_mark(), CapacityError);
  for (Mark k : all) m.free_mark(k);
  CHECK_THROWS_AS(m.free_mark(all[0]), TopologyError);
  check_map(m);
}

TEST_CASE("traversal ranges never leak marks, even on early break") {
  Map3 m;
  for (int k = 0; k < 3; ++k) m.make_hexahedron();
  int seen = 0;
  for (Dart d : m.cells<0>()) {
    (void)d;
    if (++seen == 5) break;
  }
  CHECK(m.num_reserved_marks() == 0);
  std::set<std::uint32_t> starts;
  for (Dart d : m.cells<2>()) starts.insert(d.index());
  CHECK(starts.size() == 18);
  CHECK(m.num_reserved_marks() == 0);
  // nested traversals each take their own mark
  int pairs = 0;
  for (Dart v : m.cells<3>())
    for (Dart f : m.incident<3, 2>(v)) {
      (void)f;
      ++pairs;
    }
  CHECK(pairs == 18);
  CHECK(m.num_reserved_marks() == 0);
  check_map(m);
}

TEST_CASE("attributes: assignment, iteration without darts, hooks can be paused") {
  Map3 m;
  const Dart h = m.make_hexahedron();
  CHECK(m.create_attributes<0>([&](Dart d) { return static_cast<int>(d.index()); }) == 8);
  CHECK(m.create_attributes<0>([](Dart) { return 0; }) == 0);  // every vertex has one now
  CHECK(m.num_attributes<0>() == 8);
  int sum = 0;
  for (AttrId<0> a : m.attributes<0>()) {
    sum += 1;
    CHECK(m.attribute<0>(m.dart_of(a)) == a);
  }
  CHECK(sum == 8);
  const AttrId<3> vol = m.set_attribute<3>(h, 42);
  CHECK(m.value(vol) == 42);
  for (Dart d : m.cell<3>(h)) CHECK(m.attribute<3>(d) == vol);
  int erased = 0;
  m.on_erase<3>([&](AttrId<3>) { ++erased; });
  m.set_attribute<3>(h, 7);  // replaces: the old one is freed
  CHECK(erased == 1);
  CHECK(m.num_attributes<3>() == 1);
  {
    HooksPaused<Map3> pause(m);
    m.set_attribute<3>(h, 8);
  }
  CHECK(erased == 1);
  CHECK(m.hooks_enabled());
  CHECK_THROWS_AS((void)m.value(AttrId<3>(99)), TopologyError);
  CHECK_THROWS_AS((void)m.value(AttrId<3>()), TopologyError);
  check_map(m);
}

TEST_CASE("compact renumbers darts and keeps attributes attached") {
  Map3 m;
  const Dart a = m.make_hexahedron();
  const Dart b = m.make_hexahedron();
  m.set_attribute<3>(b, 5);
  m.create_attributes<0>([](Dart d) { return static_cast<int>(d.index()); });
  // erase the first volume dart by dart
  auto darts = m.cell<3>(a);
  for (Dart d : darts) {
    m.unlink_beta<1>(d);
    m.unlink_beta<2>(d);
  }
  for (Dart d : darts) m.erase_dart(d);
  CHECK(m.num_darts() == 24);
  const auto old_to_new = m.compact();
  CHECK(m.dart_capacity() == 24);
  CHECK(old_to_new[a.index()].is_null());
  const Dart nb = old_to_new[b.index()];
  CHECK(m.value(m.attribute<3>(nb)) == 5);
  const auto n = check_map(m);
  CHECK(n[0] == 8);
  CHECK(n[3] == 1);
  ScopedMark<Map3> held(m);
  CHECK_THROWS_AS(m.compact(), TopologyError);
}

TEST_CASE("a map without attributes stores only beta links") {
  Bare3 bare;
  Map3 full;
  for (int k = 0; k < 100; ++k) {
    bare.make_hexahedron();
    full.make_hexahedron();
  }
  CHECK(bare.memory_bytes() < full.memory_bytes());
  CHECK(bare.memory_bytes() >= 2400 * 16);
  CHECK(bare.memory_bytes() < 2400 * 16 * 2 + 4096);  // vector slack at most 2x, marks a few words
}

TEST_CASE("the darts of an edge of a 3-map come in chain order, closed or open") {
  // From d: β2, β3, β2, ... until back at d or at a free dart, then β3, β2, ... from d.
  auto chain = [](const CMap<3>& m, Dart d) {
    std::vector<Dart> out{d};
    for (int first = 2; first <= 3; ++first) {
      Dart y = d;
      for (int j = first;; j = 5 - j) {
        y = m.beta(y, j);
        if (y.is_null()) break;
        if (y == d) return out;
        out.push_back(y);
      }
    }
    return out;
  };
  CMap<3> m;
  build(m, hex_grid(3, 2, 2));  // interior, boundary and corner edges
  std::size_t closed = 0, open = 0;
  for (Dart d : m.darts()) {
    const DartList got = m.cell<1>(d);
    const std::vector<Dart> want = chain(m, d);
    CHECK(std::vector<Dart>(got.begin(), got.end()) == want);
    (m.beta<3>(want.back()).is_null() || m.beta<2>(want.back()).is_null() ? open : closed) += 1;
  }
  CHECK(closed > 0);
  CHECK(open > 0);
}

namespace {
// A generic size over a range held by const&, as a user's template would write it.
template <class R>
std::size_t size_of(const R& r) {
  std::size_t n = 0;
  for (Dart d : r) n += d ? 1 : 0;
  return n;
}
}  // namespace

TEST_CASE("cells<I>() of every dimension iterates through const&, more than once") {
  Map3 m;
  build(m, hex_grid(2, 3, 1));
  const auto want = m.count_all();
  [&]<int... I>(std::integer_sequence<int, I...>) {
    (
        [&] {
          const auto& r = m.template cells<I>();
          CHECK(size_of(r) == want[I]);
          CHECK(size_of(r) == want[I]);  // a second pass sees every cell again
        }(),
        ...);
  }(std::make_integer_sequence<int, 4>{});
  CHECK(m.num_reserved_marks() == 0);
  // a pass cut short, then a full one
  const auto& v = m.cells<0>();
  for (Dart d : v) {
    (void)d;
    break;
  }
  CHECK(size_of(v) == want[0]);
}

}  // namespace test_basics
