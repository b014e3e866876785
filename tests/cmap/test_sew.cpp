// sew / unsew / link in every dimension, attribute merge and split, the hook order, and the
// 2013 paper's Fig. 5 example.
#include <doctest/doctest.h>

#include <algorithm>
#include <map>
#include <random>
#include <set>
#include <string>
#include <vector>

#include "check.hpp"
#include "sewn/cmap/build.hpp"
#include "sewn/cmap/cmap.hpp"

namespace test_sew {

using namespace sewn;
using sewn::test::check_map;
using sewn::test::counts;
using sewn::test::label_all_cells;

using Map1 = CMap<1, int, int>;
using Map2 = CMap<2, int, int, int>;
using Map3 = CMap<3, int, int, int, int>;
using Map4 = CMap<4, int, int, int, int, int>;

TEST_CASE("1-sew in a 1-map joins two darts into a path and back") {
  Map1 m;
  const Dart a = m.create_dart(), b = m.create_dart();
  label_all_cells(m);
  CHECK(m.is_sewable<1>(a, b));
  m.sew<1>(a, b);
  CHECK(m.beta(a, 1) == b);
  CHECK(check_map(m) == counts<2>({2, 2}));
  CHECK_FALSE(m.is_sewable<1>(a, b));
  CHECK_THROWS_AS(m.sew<1>(a, b), TopologyError);
  m.unsew<1>(a);
  CHECK(m.is_free(a, 1));
  CHECK_THROWS_AS(m.unsew<1>(a), TopologyError);
  check_map(m);
  m.sew<1>(a, a);  // a loop: a polygon of one edge
  CHECK(check_map(m) == counts<2>({2, 2}));
}

TEST_CASE_TEMPLATE("2-sew two squares along an edge, then unsew", M, Map2, Map3, Map4) {
  M m;
  const Dart p = m.make_quad(), q = m.make_quad();
  label_all_cells(m);
  auto n0 = check_map(m);
  CHECK(n0[0] == 8);
  m.template sew<2>(p, q);
  auto n = check_map(m);
  CHECK(n[0] == 6);
  CHECK(n[1] == 7);
  CHECK(n[2] == 2);
  CHECK(m.template num_attributes<0>() == 6);
  CHECK(m.template num_attributes<1>() == 7);
  CHECK_FALSE(m.template is_sewable<2>(p, q));
  CHECK_FALSE(m.template is_sewable<2>(m.beta(p, 1), m.beta(p, 1)));  // no fixed points
  m.template unsew<2>(p);
  CHECK(check_map(m) == n0);
  CHECK(m.template num_attributes<0>() == 8);
}

TEST_CASE_TEMPLATE("3-sew two hexahedra along a face, then unsew", M, Map3, Map4) {
  M m;
  const Dart a = m.make_hexahedron(), b = m.make_hexahedron();
  label_all_cells(m);
  const auto before = check_map(m);
  // a's face {0,1,5,4} against a face of b: any dart of b's faces that makes the orbits match.
  Dart partner;
  for (Dart x : m.template cell<2>(b))
    if (m.template is_sewable<3>(a, x)) partner = x;
  REQUIRE(partner);
  m.template sew<3>(a, partner);
  const auto n = check_map(m);
  CHECK(n[0] == 12);
  CHECK(n[1] == 20);
  CHECK(n[2] == 11);
  CHECK(n[3] == 2);
  CHECK(m.boundary_facets().size() == (M::dimension == 3 ? 10u : 2u));  // D = 4: both hexahedra are 4-free
  m.template unsew<3>(a);
  CHECK(check_map(m) == before);
}

TEST_CASE("4-sew two hexahedra into one 4-map component, then unsew") {
  Map4 m;
  const Dart a = m.make_hexahedron(), b = m.make_hexahedron();
  label_all_cells(m);
  const auto before = check_map(m);
  CHECK(m.is_sewable<4>(a, b));  // a hexahedron is its own mirror image
  m.sew<4>(a, b);
  const auto n = check_map(m);
  CHECK(n == counts<5>({8, 12, 6, 1, 2}));
  CHECK(m.count_components() == 1);
  m.unsew<4>(a);
  CHECK(check_map(m) == before);
}

TEST_CASE("is_sewable refuses orbits of different shape and leaves the map unchanged") {
  Map3 m;
  const Dart tri = m.make_tetrahedron(), hex = m.make_hexahedron();
  label_all_cells(m);
  const auto before = check_map(m);
  for (Dart x : m.cell<2>(hex)) CHECK_FALSE(m.is_sewable<3>(tri, x));  // triangle vs quad
  CHECK_THROWS_AS(m.sew<3>(tri, hex), TopologyError);
  CHECK(check_map(m) == before);
  CHECK_FALSE(m.is_sewable<3>(tri, Dart(9999)));
  CHECK_FALSE(m.is_sewable<3>(tri, m.beta(tri, 1)));  // a face onto itself
}

TEST_CASE("link / unlink change links only; validate() reports the attribute mismatch") {
  Map2 m;
  const Dart p = m.make_quad(), q = m.make_quad();
  label_all_cells(m);
  m.link<2>(p, q);
  const auto report = m.validate();
  CHECK_FALSE(report.ok());
  bool mismatch = false;
  for (const auto& i : report.issues())
    if (i.kind == ValidationIssue::Kind::attribute_mismatch) mismatch = true;
  CHECK(mismatch);
  CHECK(report.str().find("carry") != std::string::npos);
  m.unlink<2>(p);
  check_map(m);
}

TEST_CASE("validate() names a broken involution and its dart") {
  Map2 m;
  const Dart p = m.make_quad(), q = m.make_quad(), r = m.make_quad();
  m.link_beta<2>(p, q);
  m.link_beta<2>(r, q);  // q now points at r, p still points at q
  const auto report = m.validate();
  REQUIRE_FALSE(report.ok());
  CHECK(report.issues()[0].kind == ValidationIssue::Kind::not_involution);
  CHECK(report.issues()[0].dart == p.index());
  CHECK(report.str().find("dart " + std::to_string(p.index())) != std::string::npos);
}

// ------------------------------------------------------------------------- hooks

struct Event {
  std::string kind;
  int dim;
  std::uint32_t a, b;
  bool operator==(const Event&) const = default;
};

template <class T>
struct attr_dim;
template <int I>
struct attr_dim<AttrId<I>> {
  static constexpr int value = I;
};

TEST_CASE("Fig. 5 of the 2013 paper: 3-unsewing the face between the two upper hexahedra") {
  // A 2x1x2 block: two hexahedra below (z in [0,1]) and two above (z in [1,2]); the face
  // between the upper ones has vertices v1 = (1,0,2), v2 = (1,1,2), v3 = (1,1,1), v4 = (1,0,1).
  Map3 m;
  const IndexedMesh mesh = hex_grid(2, 1, 2);
  const auto built = build(m, mesh);
  m.create_attributes<0>([&](Dart d) { return static_cast<int>(built.vertex_of_dart[d.index()]); });
  int next = 1000;
  m.create_attributes<1>([&](Dart) { return next++; });
  m.create_attributes<2>([&](Dart) { return next++; });
  m.create_attributes<3>([&](Dart d) { return static_cast<int>(built.cell_of_dart[d.index()]); });
  const auto before = check_map(m);
  CHECK(before == counts<4>({18, 33, 20, 4}));

  std::vector<Event> events;
  auto log = [&](const char* kind, int dim) {
    return [&events, &m, kind, dim](auto a, auto b) {
      constexpr int I = attr_dim<decltype(a)>::value;
      if (std::string(kind) == "split") {  // after the copy got its darts and orig's value
        CHECK(m.value(b) == m.value(a));
        CHECK(m.template attribute<I>(m.dart_of(b)) == b);
      } else {  // before `gone` (b) is relabelled: both still carried by their darts
        CHECK(m.template attribute<I>(m.dart_of(a)) == a);
        CHECK(m.template attribute<I>(m.dart_of(b)) == b);
      }
      events.push_back({kind, dim, a.index(), b.index()});
    };
  };
  m.on_split<0>(log("split", 0));
  m.on_split<1>(log("split", 1));
  m.on_split<2>(log("split", 2));
  m.on_split<3>(log("split", 3));
  m.on_merge<0>(log("merge", 0));
  m.on_merge<1>(log("merge", 1));
  m.on_merge<2>(log("merge", 2));
  m.on_merge<3>(log("merge", 3));

  // the dart of the upper-left hexahedron (cell 2) on its face x = 1
  auto point = [&](Dart d) { return mesh.points[built.vertex_of_dart[d.index()]]; };
  Dart on_face;
  for (Dart d : m.darts())
    if (built.cell_of_dart[d.index()] == 2 && point(d)[0] == 1.0 && point(m.beta(d, 1))[0] == 1.0 &&
        point(m.beta(d, 1, 1))[0] == 1.0)
      on_face = d;
  REQUIRE(on_face);
  const Dart partner = m.beta(on_face, 3);
  REQUIRE(partner);
  m.unsew<3>(on_face);
  const auto after = check_map(m);
  CHECK(after == counts<4>({20, 36, 21, 4}));  // +2 vertices, +3 edges, the face in two

  // exactly: two vertex splits (v1, v2), three edge splits, one face split, nothing else
  int vs = 0, es = 0, fs = 0;
  std::set<int> split_points;
  for (const auto& e : events) {
    CHECK(e.kind == "split");
    if (e.dim == 0) {
      ++vs;
      split_points.insert(m.value(AttrId<0>(e.a)));
      CHECK(m.value(AttrId<0>(e.b)) == m.value(AttrId<0>(e.a)));
    }
    es += e.dim == 1;
    fs += e.dim == 2;
    CHECK(e.dim != 3);
  }
  CHECK(vs == 2);
  CHECK(es == 3);
  CHECK(fs == 1);
  std::set<std::array<double, 3>> pts;
  for (int p : split_points) pts.insert(mesh.points[static_cast<std::size_t>(p)]);
  CHECK(pts == std::set<std::array<double, 3>>{{1.0, 0.0, 2.0}, {1.0, 1.0, 2.0}});
  // hooks fire dimension by dimension
  for (std::size_t k = 1; k < events.size(); ++k) CHECK(events[k - 1].dim <= events[k].dim);
  // the copies sit on the unsewn dart's partner side, the originals on on_face's side
  for (Dart d : m.cell<0>(on_face)) CHECK(built.cell_of_dart[d.index()] != 3);

  // sewing back merges exactly what was split, keeping the first argument's attributes
  events.clear();
  REQUIRE(m.is_sewable<3>(on_face, partner));
  const AttrId<0> kept = m.attribute<0>(on_face);
  m.sew<3>(on_face, partner);
  CHECK(check_map(m) == before);
  CHECK(m.attribute<0>(on_face) == kept);
  int merges = 0;
  for (const auto& e : events) {
    CHECK(e.kind == "merge");
    ++merges;
  }
  CHECK(merges == 2 + 3 + 1);
}

TEST_CASE("unsew_all leaves the cells, links and attribute values of the unsews one by one") {
  // A third of the inner faces of a 6x5x5 block, at random: many vertices and edges are shared
  // by several of them, and the update processes more cells than the claims' list holds. One
  // face is listed twice and one from both sides.
  const IndexedMesh mesh = hex_grid(6, 5, 5);
  Map3 one, all;
  for (Map3* m : {&one, &all}) {
    (void)build(*m, mesh);
    label_all_cells(*m);
  }
  std::vector<Dart> faces;
  for (Dart d : one.cells<2>())
    if (one.beta(d, 3)) faces.push_back(d);
  std::mt19937 rng(4);
  std::shuffle(faces.begin(), faces.end(), rng);
  faces.resize(faces.size() / 3);
  faces.push_back(faces.front());
  faces.push_back(one.beta(faces[1], 3));
  std::array<int, 4> splits_one{}, splits_all{};
  auto count_splits = [](Map3& m, std::array<int, 4>& n) {
    m.on_split<0>([&n](AttrId<0>, AttrId<0>) { ++n[0]; });
    m.on_split<1>([&n](AttrId<1>, AttrId<1>) { ++n[1]; });
    m.on_split<2>([&n](AttrId<2>, AttrId<2>) { ++n[2]; });
    m.on_split<3>([&n](AttrId<3>, AttrId<3>) { ++n[3]; });
  };
  count_splits(one, splits_one);
  count_splits(all, splits_all);
  std::uint32_t unsewn = 0;
  for (Dart d : faces)
    if (one.beta(d, 3)) {
      one.unsew<3>(d);
      ++unsewn;
    }
  CHECK(all.unsew_all<3>(faces) == unsewn);
  CHECK(unsewn == faces.size() - 2);
  CHECK(check_map(all) == check_map(one));
  CHECK(splits_all == splits_one);
  CHECK(splits_one[0] > 0);
  // same links, the same values on every dart, and darts that share an attribute in one map
  // share it in the other
  auto same_partition = [&](auto k) {
    constexpr int I = decltype(k)::value;
    std::map<std::uint32_t, std::uint32_t> to_all;
    for (Dart d : one.darts()) {
      const std::uint32_t a = one.attribute<I>(d).index(), b = all.attribute<I>(d).index();
      CHECK(one.value(AttrId<I>(a)) == all.value(AttrId<I>(b)));
      const auto [it, fresh] = to_all.emplace(a, b);
      CHECK(it->second == b);
    }
    std::set<std::uint32_t> images;
    for (const auto& [a, b] : to_all) images.insert(b);
    CHECK(images.size() == to_all.size());
  };
  for (Dart d : one.darts())
    for (int j = 0; j <= 3; ++j) REQUIRE(one.beta(d, j) == all.beta(d, j));
  same_partition(std::integral_constant<int, 0>{});
  same_partition(std::integral_constant<int, 1>{});
  same_partition(std::integral_constant<int, 2>{});
  same_partition(std::integral_constant<int, 3>{});
}

}  // namespace test_sew
