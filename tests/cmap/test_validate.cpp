// validate(): each invariant the public API can break is reported, with its kind and its dart.
// (Reference counts, orphan or dead attributes, the free list and marks cannot be broken through
// the public API: every operation keeps them, so they are not exercised here.)
#include <doctest/doctest.h>

#include <string>
#include <vector>

#include "sewn/cmap/build.hpp"
#include "sewn/cmap/cmap.hpp"

namespace test_validate {

using namespace sewn;
using Kind = ValidationIssue::Kind;

namespace {

// The first issue of kind k, or nullptr.
const ValidationIssue* find(const ValidationReport& r, Kind k) {
  for (const auto& i : r.issues())
    if (i.kind == k) return &i;
  return nullptr;
}

}  // namespace

TEST_CASE("validate: a link to an erased dart is dangling") {
  CMap<2> m;
  const Dart a = m.create_dart(), q = m.create_dart(), r = m.create_dart();
  m.link_beta<2>(a, q);
  m.link_beta<2>(r, q);    // q now pairs with r; a still points at q
  m.unlink_beta<2>(q);     // frees q and r; a still points at q
  m.erase_dart(q);
  const auto report = m.validate();
  const ValidationIssue* i = find(report, Kind::dangling_link);
  REQUIRE(i != nullptr);
  CHECK(i->dart == a.index());
  CHECK(i->index == 2);
}

TEST_CASE("validate: beta0 not the inverse of beta1") {
  CMap<2> m;
  const Dart a = m.create_dart(), b = m.create_dart(), c = m.create_dart();
  m.link_beta<1>(a, b);
  m.link_beta<1>(c, b);  // beta0(b) = c, but beta1(a) = b
  const auto report = m.validate();
  const ValidationIssue* i = find(report, Kind::beta0_beta1);
  REQUIRE(i != nullptr);
  CHECK(i->dart == a.index());
}

TEST_CASE("validate: a fixed point of beta2 is not an involution") {
  CMap<2> m;
  const Dart a = m.make_quad();
  m.link_beta<2>(a, a);
  const auto report = m.validate();
  const ValidationIssue* i = find(report, Kind::not_involution);
  REQUIRE(i != nullptr);
  CHECK(i->dart == a.index());
  CHECK(report.str().find("fixed point") != std::string::npos);
}

TEST_CASE("validate: beta2 not an involution, each broken dart named once") {
  CMap<2> m;
  const Dart a = m.create_dart(), q = m.create_dart(), r = m.create_dart();
  m.link_beta<2>(a, q);
  m.link_beta<2>(r, q);  // beta2(a) = q but beta2(q) = r
  const auto report = m.validate();
  std::vector<std::uint32_t> darts;
  for (const auto& i : report.issues()) {
    CHECK(i.kind == Kind::not_involution);
    darts.push_back(i.dart);
  }
  CHECK(darts == std::vector<std::uint32_t>{a.index()});
}

TEST_CASE("validate: beta1 o beta3 and beta2 o beta4 must be involutions") {
  {
    CMap<3> m;
    const Dart p = m.make_triangle(), q = m.make_triangle();
    m.link_beta<3>(p, q);  // one pair only: beta3(beta1(p)) is null but beta0(beta3(p)) is not
    const auto report = m.validate();
    const ValidationIssue* i = find(report, Kind::composition);
    REQUIRE(i != nullptr);
    CHECK(i->index == 3);
  }
  {
    CMap<4> m;
    const Dart p = m.make_quad(), q = m.make_quad(), r = m.make_quad();
    m.link_beta<2>(p, q);
    m.link_beta<4>(p, r);  // beta4(beta2(p)) is null but beta2(beta4(p)) is not
    const auto report = m.validate();
    const ValidationIssue* i = find(report, Kind::composition);
    REQUIRE(i != nullptr);
    CHECK(i->index == 4);
  }
}

TEST_CASE("validate: one attribute carried by two cells, and a recorded dart outside the cell") {
  CMap<2, int, int> m;
  const Dart p = m.make_quad(), q = m.make_quad();
  m.create_attributes<1>([](Dart) { return 0; });
  m.sew<2>(p, q);
  REQUIRE(m.validate().ok());
  const AttrId<1> edge = m.attribute<1>(p);
  m.unlink<2>(p);  // the edge falls in two, both halves keep the one attribute
  {
    const auto report = m.validate();
    const ValidationIssue* i = find(report, Kind::attribute_two_cells);
    REQUIRE(i != nullptr);
    CHECK(i->index == 1);
    CHECK((i->dart == p.index() || i->dart == q.index()));
  }
  // Give the half holding the attribute's recorded dart an attribute of its own: the other half
  // keeps `edge`, whose recorded dart now carries another attribute.
  const Dart rec = m.dart_of(edge);
  m.set_attribute<1>(rec, 7);
  const auto report = m.validate();
  const ValidationIssue* i = find(report, Kind::attribute_dart);
  REQUIRE(i != nullptr);
  CHECK(i->dart == rec.index());
  CHECK(find(report, Kind::attribute_two_cells) == nullptr);
}

TEST_CASE("validate: darts of one cell carrying different attributes are named") {
  CMap<3, int> m;
  const Dart a = m.make_hexahedron(), b = m.make_hexahedron();
  m.create_attributes<0>([](Dart d) { return static_cast<int>(d.index()); });
  m.link<3>(a, b);  // vertices merge, their attributes do not
  const auto report = m.validate();
  const ValidationIssue* i = find(report, Kind::attribute_mismatch);
  REQUIRE(i != nullptr);
  CHECK(i->index == 0);
  CHECK(report.str().find("carry") != std::string::npos);
}

// Vertices of a 2-map and edges of a 3-map are chain cells, whose attributes validate() first
// checks dart by dart with their neighbours, walking only one cell per attribute.
TEST_CASE("validate: chain cells carrying different attributes, or one attribute in two cells, are named") {
  SUBCASE("vertices of a 2-map merged by a link") {
    CMap<2, int> m;
    const Dart p = m.make_quad(), q = m.make_quad();
    m.create_attributes<0>([](Dart d) { return static_cast<int>(d.index()); });
    m.link<2>(p, q);
    const auto report = m.validate();
    const ValidationIssue* i = find(report, Kind::attribute_mismatch);
    REQUIRE(i != nullptr);
    CHECK(i->index == 0);
  }
  SUBCASE("vertices of a 2-map split by an unlink") {
    CMap<2, int> m;
    const Dart p = m.make_quad(), q = m.make_quad();
    m.sew<2>(p, q);
    m.create_attributes<0>([](Dart d) { return static_cast<int>(d.index()); });
    REQUIRE(m.validate().ok());
    m.unlink<2>(p);
    const auto report = m.validate();
    const ValidationIssue* i = find(report, Kind::attribute_two_cells);
    REQUIRE(i != nullptr);
    CHECK(i->index == 0);
  }
  SUBCASE("edges of a 3-map merged by a link, then split by an unlink") {
    CMap<3, void, int> m;
    const Dart a = m.make_hexahedron(), b = m.make_hexahedron();
    Dart partner;
    for (Dart x : m.cell<2>(b))
      if (m.is_sewable<3>(a, x)) partner = x;
    m.create_attributes<1>([](Dart d) { return static_cast<int>(d.index()); });
    m.link<3>(a, partner);
    const auto merged = m.validate();
    const ValidationIssue* i = find(merged, Kind::attribute_mismatch);
    REQUIRE(i != nullptr);
    CHECK(i->index == 1);
    m.unlink<3>(a);
    REQUIRE(m.validate().ok());
    m.sew<3>(a, partner);
    REQUIRE(m.validate().ok());
    m.unlink<3>(a);
    const auto split = m.validate();
    i = find(split, Kind::attribute_two_cells);
    REQUIRE(i != nullptr);
    CHECK(i->index == 1);
  }
}

TEST_CASE("validate: a built grid is valid, and stays valid through cuts") {
  CMap<3, int, int, int, int> m;
  build(m, hex_grid(3, 3, 3));
  m.create_attributes<0>([](Dart) { return 0; });
  m.create_attributes<1>([](Dart) { return 1; });
  m.create_attributes<2>([](Dart) { return 2; });
  m.create_attributes<3>([](Dart) { return 3; });
  CHECK(m.validate().ok());
  std::vector<Dart> faces;
  for (Dart d : m.cells<2>()) faces.push_back(d);
  for (Dart d : faces) {
    if (m.beta<3>(d).is_null()) continue;
    m.unsew<3>(d);
    const auto report = m.validate();
    INFO(report.str());
    REQUIRE(report.ok());
  }
}

TEST_CASE("traversals end on a map whose links are inconsistent") {
  // beta1 made non-injective with the low-level link: a beta1 walk from `a` runs into a cycle
  // that does not come back to it.
  CMap<2> m;
  const Dart a = m.create_dart(), b = m.create_dart(), c = m.create_dart();
  m.link_beta<1>(a, b);
  m.link_beta<1>(b, c);
  m.link_beta<1>(c, b);
  CHECK_FALSE(m.validate().ok());
  CHECK(m.count<2>() >= 1);
  std::uint32_t n = 0;
  for (Dart d : m.cells<2>()) n += d ? 1u : 0u;
  CHECK(n >= 1);
  (void)m.count_all();
  CHECK(m.num_reserved_marks() == 0);
}

namespace {

// The darts of a 3-map from which no smaller dart is reached by β0, β1 and β3, found by a
// search of their own from each dart: in a valid map the smallest dart of each face; with
// inconsistent links, where "face" loses its meaning, the darts cells<2>() must still yield.
std::vector<std::uint32_t> face_roots(const CMap<3>& m) {
  const std::uint32_t cap = m.dart_capacity();
  std::vector<std::uint32_t> roots;
  for (std::uint32_t s = 0; s < cap; ++s) {
    if (!m.is_alive(Dart(s))) continue;
    std::vector<char> seen(cap, 0);
    std::vector<std::uint32_t> todo{s};
    seen[s] = 1;
    bool least = true;
    while (!todo.empty() && least) {
      const std::uint32_t x = todo.back();
      todo.pop_back();
      least = x >= s;
      for (int i : {0, 1, 3}) {
        const std::uint32_t y = m.b(x, i);
        if (y != Dart::null_index && !seen[y]) {
          seen[y] = 1;
          todo.push_back(y);
        }
      }
    }
    if (least) roots.push_back(s);
  }
  return roots;
}

std::vector<std::uint32_t> ranged_faces(const CMap<3>& m) {
  std::vector<std::uint32_t> out;
  for (Dart d : m.cells<2>()) out.push_back(d.index());
  return out;
}

}  // namespace

TEST_CASE("faces of a 3-map whose links low-level calls left inconsistent are still found exactly") {
  // A pentagon (darts 0-4) and two squares q (5-8) and u (9-12), q and u 3-sewn as a valid face.
  CMap<3> m;
  (void)m.make_polygon(5);
  const Dart q = m.make_polygon(4), u = m.make_polygon(4);
  REQUIRE(q.index() == 5);
  REQUIRE(u.index() == 9);
  m.sew<3>(q, u);
  REQUIRE(m.validate().ok());
  CHECK(face_roots(m) == std::vector<std::uint32_t>{0, 5});
  CHECK(ranged_faces(m) == std::vector<std::uint32_t>{0, 5});
  // Splice dart 0 into u's cycle (β1(12) = 0, β1(0) = 9): q and u's face now reaches 0 through
  // β1 of a partner dart, though every dart of q and each β3 of them is larger than 5. Only a
  // walk that checks the links' shape (or a mark) sees that 5 is not the smallest of its face.
  m.link_beta<1>(Dart(12), Dart(0));
  m.link_beta<1>(Dart(0), Dart(9));
  const std::vector<std::uint32_t> want = face_roots(m);
  CHECK(want == std::vector<std::uint32_t>{0});
  CHECK(ranged_faces(m) == want);
  CHECK(m.count<2>() == want.size());
  // A grid built into the same map keeps its links sound, but must not vouch for the rest.
  (void)build(m, hex_grid(2, 1, 1));
  CHECK(face_roots(m).size() == 1 + 11);
  CHECK(ranged_faces(m) == face_roots(m));
  CHECK_FALSE(m.validate().ok());
  CHECK(ranged_faces(m) == face_roots(m));
  // Repaired by hand: each ring closed again on its own.
  m.link_beta<1>(Dart(0), Dart(1));
  m.link_beta<1>(Dart(4), Dart(0));
  m.link_beta<1>(Dart(12), Dart(9));
  REQUIRE(m.validate().ok());
  const std::vector<std::uint32_t> roots = face_roots(m);
  REQUIRE(roots.size() == 2 + 11);
  CHECK(roots[0] == 0);
  CHECK(roots[1] == 5);
  CHECK(ranged_faces(m) == roots);
  CHECK(m.count<2>() == roots.size());
  CHECK(m.num_reserved_marks() == 0);
}

}  // namespace test_validate
