// 1:8 refinement of hexahedra (the 2014 paper, PHYSICS_NOTES §2.4-2.5): the refined model must be
// the model built directly at the finer size, and the hierarchy invariants must hold throughout.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <random>
#include <tuple>
#include <utility>
#include <vector>

#include "sewn/physics/integrators.hpp"
#include "sewn/refine/coarsen.hpp"
#include "sewn/refine/cut.hpp"
#include "sewn/refine/hierarchy.hpp"
#include "sewn/refine/subdivide.hpp"
#include "support.hpp"

namespace test_refine_hex {

using namespace sewn;
using namespace sewn::physics;
using namespace sewn::refine;
using namespace refine_test;
using Eigen::Vector3d;

namespace {

const MaterialParams material{1e5, 0.3, 100};

const Vector3d h{0.2, 0.15, 0.125};

IndexedMesh grid(std::uint32_t nx, std::uint32_t ny, std::uint32_t nz, double scale) {
  return hex_grid(nx, ny, nz, {{h.x() * scale, h.y() * scale, h.z() * scale}, {0.1, -0.2, 0.3}});
}

Vector3d momentum(const NodeTable& n) {
  Vector3d p = Vector3d::Zero();
  for (Index i = 0; i < n.size(); ++i)
    if (n.is_alive(i)) p += n.mass(i) * n.velocity(i);
  return p;
}

using Key = std::array<long, 3>;
Key key(const Vector3d& r) {
  const Vector3d q = (r - Vector3d(0.1, -0.2, 0.3)).cwiseQuotient(h) * 64;
  return {std::lround(q.x()), std::lround(q.y()), std::lround(q.z())};
}

struct Snapshot {
  std::map<Key, Index> node;
  std::map<std::tuple<Key, Key, int>, std::array<double, 3>> spring;
};

Snapshot snapshot(const MssModel<3>& m) {
  Snapshot s;
  for (Index i = 0; i < m.nodes().size(); ++i)
    if (m.nodes().is_alive(i)) REQUIRE(s.node.emplace(key(m.rest_position(i)), i).second);
  const Springs& sp = m.springs();
  for (Index k = 0; k < sp.size(); ++k) {
    if (!sp.is_alive(k)) continue;
    Key a = key(m.rest_position(sp.node_i(k))), b = key(m.rest_position(sp.node_j(k)));
    if (b < a) std::swap(a, b);
    REQUIRE(s.spring.emplace(std::make_tuple(a, b, static_cast<int>(sp.kind(k))), std::array{sp.stiffness(k), sp.rest_length(k), sp.viscosity(k)})
                .second);
  }
  return s;
}

bool close(double a, double b) { return std::abs(a - b) <= 1e-12 * std::max(std::abs(a), std::abs(b)); }

void same_model(const MssModel<3>& refined, const MssModel<3>& fine) {
  const Snapshot a = snapshot(refined), b = snapshot(fine);
  REQUIRE(a.node.size() == b.node.size());
  REQUIRE(a.spring.size() == b.spring.size());
  for (const auto& node : a.node) {
    const auto& k = node.first;
    const Index i = node.second;
    REQUIRE(b.node.count(k) == 1);
    const Index j = b.node.at(k);
    CHECK(close(refined.nodes().mass(i), fine.nodes().mass(j)));
    CHECK((refined.nodes().position(i) - fine.nodes().position(j)).norm() <= 1e-12);
    CHECK((refined.nodes().velocity(i) - fine.nodes().velocity(j)).norm() <= 1e-12);
  }
  for (const auto& spring : a.spring) {
    const auto& k = spring.first;
    const auto& v = spring.second;
    REQUIRE(b.spring.count(k) == 1);
    const auto& w = b.spring.at(k);
    INFO("spring kind " << std::get<2>(k));
    CHECK(close(v[0], w[0]));
    CHECK(close(v[1], w[1]));
    CHECK(close(v[2], w[2]));
  }
}

void affine_state(MssModel<3>& m) {
  Eigen::Matrix3d F, G;
  F << 1.1, 0.2, 0, -0.1, 0.9, 0.05, 0.05, 0.1, 1;
  G << 0.3, -1.0, 0.2, 0.5, 0.2, 0, 0.1, 0.4, -0.3;
  for (Index i = 0; i < m.nodes().size(); ++i) {
    const Vector3d r = m.rest_position(i);
    m.nodes().set_position(i, F * r + Vector3d(0.01, 0.02, 0.03));
    m.nodes().set_velocity(i, G * r + Vector3d(1, -2, 0.5));
  }
}

std::vector<Index> live(const MssModel<3>& m) {
  std::vector<Index> out;
  for (Index e = 0; e < m.elements().size(); ++e)
    if (m.elements()[e].alive) out.push_back(e);
  return out;
}

// Live elements matched by rest centroid: same level, measure, stiffnesses, corner particles (by
// rest place) and parent (by its rest centroid).
void same_elements(const MssModel<3>& a, const MssModel<3>& b) {
  std::map<Key, Index> in_b;
  for (Index e : live(b)) REQUIRE(in_b.emplace(key(b.element_centroid(e)), e).second);
  REQUIRE(live(a).size() == in_b.size());
  for (Index e : live(a)) {
    CAPTURE(e);
    REQUIRE(in_b.count(key(a.element_centroid(e))) == 1);
    const Index f = in_b.at(key(a.element_centroid(e)));
    const Element &x = a.elements()[e], &y = b.elements()[f];
    CHECK(x.level == y.level);
    CHECK(close(x.measure, y.measure));
    CHECK(close(x.diagonal_k, y.diagonal_k));
    for (std::size_t k = 0; k < 12; ++k) CHECK(close(x.edge_k[k], y.edge_k[k]));
    const auto na = a.element_nodes(e), nb = b.element_nodes(f);
    for (std::size_t k = 0; k < 8; ++k) CHECK(key(a.rest_position(na[k])) == key(b.rest_position(nb[k])));
    REQUIRE((x.parent == invalid_index) == (y.parent == invalid_index));
    if (x.parent != invalid_index) CHECK(key(a.element_centroid(x.parent)) == key(b.element_centroid(y.parent)));
  }
}

// As same_model, where a cut has duplicated particles (several at one rest place): particles and
// springs compared as sorted lists (by rest places, then values), pairwise to round-off.
void same_model_cut(const MssModel<3>& a, const MssModel<3>& b) {
  using NodeRow = std::tuple<Key, double, std::array<double, 6>>;
  using SpringRow = std::tuple<Key, Key, int, std::array<double, 3>>;
  auto rows = [](const MssModel<3>& m) {
    std::vector<NodeRow> nodes;
    for (Index i = 0; i < m.nodes().size(); ++i)
      if (m.nodes().is_alive(i)) {
        const Vector3d x = m.nodes().position(i), v = m.nodes().velocity(i);
        nodes.emplace_back(key(m.rest_position(i)), m.nodes().mass(i), std::array{x.x(), x.y(), x.z(), v.x(), v.y(), v.z()});
      }
    std::vector<SpringRow> springs;
    const Springs& sp = m.springs();
    for (Index k = 0; k < sp.size(); ++k) {
      if (!sp.is_alive(k)) continue;
      Key i = key(m.rest_position(sp.node_i(k))), j = key(m.rest_position(sp.node_j(k)));
      if (j < i) std::swap(i, j);
      springs.emplace_back(i, j, static_cast<int>(sp.kind(k)), std::array{sp.stiffness(k), sp.rest_length(k), sp.viscosity(k)});
    }
    std::sort(nodes.begin(), nodes.end());
    std::sort(springs.begin(), springs.end());
    return std::make_pair(nodes, springs);
  };
  const auto [na, sa] = rows(a);
  const auto [nb, sb] = rows(b);
  REQUIRE(na.size() == nb.size());
  REQUIRE(sa.size() == sb.size());
  for (std::size_t i = 0; i < na.size(); ++i) {
    REQUIRE(std::get<0>(na[i]) == std::get<0>(nb[i]));
    CHECK(close(std::get<1>(na[i]), std::get<1>(nb[i])));
    for (std::size_t c = 0; c < 6; ++c) CHECK(std::abs(std::get<2>(na[i])[c] - std::get<2>(nb[i])[c]) <= 1e-12);
  }
  for (std::size_t i = 0; i < sa.size(); ++i) {
    REQUIRE(std::get<0>(sa[i]) == std::get<0>(sb[i]));
    REQUIRE(std::get<1>(sa[i]) == std::get<1>(sb[i]));
    REQUIRE(std::get<2>(sa[i]) == std::get<2>(sb[i]));
    for (std::size_t c = 0; c < 3; ++c) CHECK(close(std::get<3>(sa[i])[c], std::get<3>(sb[i])[c]));
  }
}

// The held axes of every particle, by rest place.
std::multimap<Key, AxisMask> held(const MssModel<3>& m) {
  std::vector<std::pair<Key, AxisMask>> out;
  for (Index i = 0; i < m.nodes().size(); ++i)
    if (m.nodes().is_alive(i)) out.emplace_back(key(m.rest_position(i)), m.nodes().fixed(i));
  std::sort(out.begin(), out.end());
  return {out.begin(), out.end()};
}

// Element by element, the reference for refine_all's batch pass.
void refine_each(MssModel<3>& m) {
  for (Index e : live(m)) (void)refine_element(m, e);
}

}  // namespace

TEST_CASE("refine_all on a conforming hexahedral model: the batch pass makes the model element-by-element refinement makes") {
  for (int cuts : {0, 2}) {
    CAPTURE(cuts);
    MssOptions o;  // gravity and the paper's viscous damping: masses and viscosities matter
    MssModel<3> batch(grid(3, 2, 2, 1.0), {material}, {}, o), each(grid(3, 2, 2, 1.0), {material}, {}, o);
    for (MssModel<3>* m : {&batch, &each}) {
      affine_state(*m);
      for (Index i = 0; i < m->nodes().size(); ++i)
        if (m->rest_position(i).x() < 0.15) m->nodes().fix(i, i % 2 == 0 ? all_axes : axis_y);  // some held, some on one axis
      const std::vector<Facet> inner = inner_facets(*m);
      for (int c = 0; c < cuts; ++c) (void)cut(*m, std::vector<Facet>{inner[static_cast<std::size_t>(5 * c + 1)]});
    }
    const double mass0 = batch.node_mass();
    const Vector3d p0 = momentum(batch.nodes());
    for (int pass = 1; pass <= 2; ++pass) {
      CAPTURE(pass);
      REQUIRE(refines_in_one_pass(batch));
      const RefineReport r = refine_all(batch);
      refine_each(each);
      check_all(batch);
      check_all(each);
      CHECK(r.children.size() == 8 * r.elements);
      CHECK(batch.system().slaves().empty());
      if (cuts == 0) same_model(batch, each);
      same_model_cut(batch, each);
      same_elements(batch, each);
      CHECK(held(batch) == held(each));
      CHECK(std::abs(batch.node_mass() - mass0) <= 1e-13 * mass0);
      CHECK((momentum(batch.nodes()) - p0).norm() <= 1e-12 * p0.norm());
      for (Index e : live(batch)) CHECK(level_index(batch.elements()[e].level) == 1 + pass);
    }
  }
}

TEST_CASE("refine_all: the batch pass k times is the grid built at the fine size; T-junctions take the element path") {
  for (int k = 1; k <= 2; ++k) {
    CAPTURE(k);
    MssModel<3> m(grid(2, 1, 1, 1.0), {material}, {}, no_gravity());
    affine_state(m);
    for (int pass = 0; pass < k; ++pass) {
      REQUIRE(refines_in_one_pass(m));
      (void)refine_all(m);
      check_all(m);
    }
    const std::uint32_t n = 1u << k;
    MssModel<3> fine(grid(2 * n, n, n, 1.0 / n), {material}, {}, no_gravity());
    affine_state(fine);
    same_model(m, fine);
  }
  MssModel<3> m(grid(2, 1, 1, 1.0), {material}, {}, no_gravity());
  (void)refine_element(m, 0);
  CHECK_FALSE(refines_in_one_pass(m));  // element 1 has T-junctions on the shared face
  const RefineReport r = refine_all(m);
  CHECK(r.elements == 9);
  check_all(m);
  check_constraints_fresh(m);
}

TEST_CASE("refine_all: a level beyond the maximum is refused before the batch pass, the model unchanged") {
  MssModel<3> m(grid(2, 1, 1, 1.0), {material}, {}, no_gravity());
  RefineOptions o;
  o.max_level = 2;
  (void)refine_all(m, o);
  const auto darts = m.map().num_darts();
  const auto nodes = m.nodes().num_alive();
  const auto springs = m.springs().num_alive();
  CHECK_THROWS_WITH_AS(refine_all(m, o), doctest::Contains("maximum level 2"), InputError);
  CHECK(m.map().num_darts() == darts);
  CHECK(m.nodes().num_alive() == nodes);
  CHECK(m.springs().num_alive() == springs);
  check_all(m);
}

TEST_CASE("refine hexahedra: uniform refinement k times is the grid built at the fine size") {
  for (int k = 1; k <= 2; ++k) {
    CAPTURE(k);
    MssModel<3> m(grid(2, 1, 1, 1.0), {material}, {}, no_gravity());
    affine_state(m);
    const double mass0 = m.node_mass();
    const Vector3d p0 = momentum(m.nodes());
    for (int pass = 0; pass < k; ++pass)
      for (Index e : live(m)) {
        const RefineReport r = refine_element(m, e);
        CHECK(r.children.size() == 8);
        check_all(m);
        CHECK(std::abs(m.node_mass() - mass0) <= 1e-13 * mass0);
        CHECK((momentum(m.nodes()) - p0).norm() <= 1e-12 * p0.norm());
      }
    const std::uint32_t n = 1u << k;
    MssModel<3> fine(grid(2 * n, n, n, 1.0 / n), {material}, {}, no_gravity());
    affine_state(fine);
    same_model(m, fine);
    for (Index e : live(m)) CHECK(level_index(m.elements()[e].level) == 1 + k);
  }
}

TEST_CASE("refine hexahedra: one refinement adds the paper's 19 particles, 42 edges and 28 diagonals") {
  MssModel<3> m(grid(1, 1, 1, 1.0), {material}, {}, no_gravity());
  const RefineReport r = refine_element(m, 0);
  check_all(m);
  CHECK(r.particles == 19);
  CHECK(m.nodes().num_alive() == 27);
  Index edges = 0, diagonals = 0;
  for (Index s = 0; s < m.springs().size(); ++s)
    if (m.springs().is_alive(s)) (m.springs().kind(s) == SpringKind::diagonal ? diagonals : edges) += 1;
  CHECK(edges == 54);
  CHECK(diagonals == 32);
}

TEST_CASE("refine hexahedra: local and nested refinement keep the hierarchy, mass and momentum") {
  MssModel<3> m(grid(3, 2, 2, 1.0), {material}, {}, no_gravity());
  affine_state(m);
  const double mass0 = m.node_mass();
  const Vector3d p0 = momentum(m.nodes());
  const RefineReport r1 = refine_element(m, 0);
  check_all(m);
  const RefineReport r2 = refine_element(m, r1.children[6]);  // the child at the parent's inner corner
  check_all(m);
  (void)refine_element(m, 1);  // the neighbour: reuses the face already split, next to level 3
  check_all(m);
  (void)refine_element(m, r2.children[6]);
  check_all(m);
  CHECK(std::abs(m.node_mass() - mass0) <= 1e-13 * mass0);
  CHECK((momentum(m.nodes()) - p0).norm() <= 1e-12 * p0.norm());
}

TEST_CASE("refine hexahedra: seeded random refinement sequences keep every invariant") {
  for (unsigned seed : {1u, 2u}) {
    CAPTURE(seed);
    std::mt19937 rng(seed);
    MssModel<3> m(grid(2, 2, 1, 1.0), {material}, {}, no_gravity());
    std::uniform_real_distribution<double> u(-1, 1);
    for (Index i = 0; i < m.nodes().size(); ++i) m.nodes().set_velocity(i, Vector3d(u(rng), u(rng), u(rng)));
    const double mass0 = m.node_mass();
    const Vector3d p0 = momentum(m.nodes());
    RefineOptions o;
    o.max_level = 3;
    for (int step = 0; step < 10; ++step) {
      std::vector<Index> can;
      for (Index e : live(m))
        if (level_index(m.elements()[e].level) < o.max_level) can.push_back(e);
      (void)refine_element(m, can[std::uniform_int_distribution<std::size_t>(0, can.size() - 1)(rng)], o);
      check_all(m);
      CHECK(std::abs(m.node_mass() - mass0) <= 1e-13 * mass0);
      CHECK((momentum(m.nodes()) - p0).norm() <= 1e-12 * std::max(1.0, p0.norm()));
    }
  }
}

TEST_CASE("refine hexahedra: tetrahedra and quads of a 3-map are refused, the model unchanged") {
  MssModel<3> tets(tet_grid(1, 1, 1, TetSplit::five), {material}, {}, no_gravity());
  const auto darts = tets.map().num_darts();
  CHECK_THROWS_WITH_AS(refine_element(tets, 0), doctest::Contains("tetrahedron"), InputError);
  CHECK(tets.map().num_darts() == darts);
  MssModel<3> hexes(grid(1, 1, 1, 1.0), {material}, {}, no_gravity());
  RefineOptions one;
  one.max_level = 1;
  CHECK_THROWS_WITH_AS(refine_element(hexes, 0, one), doctest::Contains("maximum level 1"), InputError);
  CHECK(hexes.nodes().num_alive() == 8);
}

TEST_CASE("refine hexahedra and cut: seeded random refine / cut sequences") {
  for (unsigned seed : {1u, 2u}) {
    CAPTURE(seed);
    MssModel<3> m(grid(2, 2, 2, 1.0), {material}, {}, no_gravity());
    const double mass0 = m.node_mass();
    std::mt19937 rng(seed);
    RefineOptions o;
    o.max_level = 3;
    int cuts = 0;
    for (int step = 0; step < 12; ++step) {
      CAPTURE(step);
      if (std::uniform_int_distribution<int>(0, 1)(rng) == 0) {
        std::vector<Index> can;
        for (Index e : live(m))
          if (level_index(m.elements()[e].level) < o.max_level) can.push_back(e);
        if (!can.empty()) (void)refine_element(m, can[std::uniform_int_distribution<std::size_t>(0, can.size() - 1)(rng)], o);
      } else {
        const std::vector<Facet> same = inner_facets(m);
        (void)cut(m, std::vector<Facet>{same[std::uniform_int_distribution<std::size_t>(0, same.size() - 1)(rng)]});
        ++cuts;
      }
      check_all(m);
      CHECK(std::abs(m.node_mass() - mass0) <= 1e-13 * mass0);
    }
    CHECK(cuts > 0);
  }
}

TEST_CASE("coarsen hexahedra: refine then coarsen gives back the model, momentum kept") {
  MssModel<3> m(grid(3, 2, 1, 1.0), {material}, {}, no_gravity());
  const Snapshot original = snapshot(m);
  std::mt19937 rng(9);
  std::uniform_real_distribution<double> u(-1, 1);
  for (Index i = 0; i < m.nodes().size(); ++i) m.nodes().set_velocity(i, Vector3d(u(rng), u(rng), u(rng)));
  const RefineReport r0 = refine_element(m, 1);
  (void)refine_element(m, 0);  // the neighbour: shares a split face with element 1
  (void)refine_element(m, r0.children[0]);
  check_all(m);
  for (Index i = 0; i < m.nodes().size(); ++i)
    if (m.nodes().is_alive(i)) m.nodes().set_velocity(i, m.nodes().velocity(i) + 0.2 * Vector3d(u(rng), u(rng), u(rng)));
  m.system().slaves().after_step(m.nodes());
  const double mass0 = m.node_mass();
  const Vector3d p0 = momentum(m.nodes());
  std::string why;
  CHECK(!can_coarsen(m, 1, &why));
  CHECK(why.find("refined further") != std::string::npos);
  for (Index e : {r0.children[0], Index{1}, Index{0}}) {
    CAPTURE(e);
    const CoarsenReport c = coarsen(m, e);
    check_all(m);
    CHECK(c.dissipated_energy >= 0);
    CHECK(std::abs(m.node_mass() - mass0) <= 1e-13 * mass0);
    CHECK((momentum(m.nodes()) - p0).norm() <= 1e-12 * p0.norm());
  }

  const Snapshot back = snapshot(m);
  REQUIRE(back.node.size() == original.node.size());
  REQUIRE(back.spring.size() == original.spring.size());
  for (const auto& [k, v] : back.spring) {
    REQUIRE(original.spring.count(k) == 1);
    CHECK(close(v[0], original.spring.at(k)[0]));
    CHECK(close(v[1], original.spring.at(k)[1]));
  }
  CHECK(t_junctions(m).empty());
}

TEST_CASE("coarsen hexahedra: seeded random refine / coarsen sequences end where they began") {
  MssModel<3> m(grid(2, 2, 1, 1.0), {material}, {}, no_gravity());
  const Snapshot original = snapshot(m);
  const double mass0 = m.node_mass();
  std::mt19937 rng(4);
  RefineOptions o;
  o.max_level = 3;
  for (int step = 0; step < 14; ++step) {
    CAPTURE(step);
    std::vector<Index> leaves, families;
    for (Index e = 0; e < m.elements().size(); ++e) {
      if (m.elements()[e].alive && level_index(m.elements()[e].level) < o.max_level) leaves.push_back(e);
      if (can_coarsen(m, e)) families.push_back(e);
    }
    if (families.empty() || (!leaves.empty() && std::uniform_int_distribution<int>(0, 2)(rng) > 0)) {
      const Index e = leaves[std::uniform_int_distribution<std::size_t>(0, leaves.size() - 1)(rng)];
      (void)refine_element(m, e, o);
    } else {
      const Index e = families[std::uniform_int_distribution<std::size_t>(0, families.size() - 1)(rng)];
      (void)coarsen(m, e);
    }
    check_all(m);
    CHECK(std::abs(m.node_mass() - mass0) <= 1e-13 * mass0);
  }
  for (bool any = true; any;) {
    any = false;
    for (Index e = 0; e < m.elements().size(); ++e)
      if (can_coarsen(m, e)) {
        (void)coarsen(m, e);
        check_all(m);
        any = true;
      }
  }
  const Snapshot back = snapshot(m);
  CHECK(back.node.size() == original.node.size());
  CHECK(back.spring.size() == original.spring.size());
}

TEST_CASE("coarsen hexahedra: a family with a cut between siblings is refused, the model unchanged") {
  MssModel<3> m(grid(2, 1, 1, 1.0), {material}, {}, no_gravity());
  const RefineReport r = refine_element(m, 0);
  std::vector<Facet> between;
  for (const Facet& f : inner_facets(m)) {
    const Index a = m.element_of(f.dart), b = m.element_of(m.map().beta(f.dart, 3));
    if (m.elements()[a].parent == 0 && m.elements()[b].parent == 0) between.push_back(f);
  }
  REQUIRE(between.size() == 12);  // the family's interior faces
  (void)cut(m, std::vector<Facet>{between[5]});
  check_all(m);
  const auto before = std::make_tuple(m.map().num_darts(), m.nodes().num_alive(), m.springs().size());
  std::string why;
  CHECK(!can_coarsen(m, 0, &why));
  CHECK(why.find("cut") != std::string::npos);
  CHECK_THROWS_WITH_AS(coarsen(m, 0), doctest::Contains("cut"), InputError);
  CHECK(before == std::make_tuple(m.map().num_darts(), m.nodes().num_alive(), m.springs().size()));
  CHECK(r.children.size() == 8);
}

}  // namespace test_refine_hex
