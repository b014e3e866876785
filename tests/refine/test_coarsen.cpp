// Coarsening a quad family (PHYSICS_NOTES §2.8): refine then coarsen gives back the model.
#include <doctest/doctest.h>

#include <cmath>
#include <map>
#include <random>
#include <tuple>

#include "sewn/refine/coarsen.hpp"
#include "sewn/refine/cut.hpp"
#include "sewn/refine/hierarchy.hpp"
#include "sewn/refine/subdivide.hpp"
#include "support.hpp"

namespace test_coarsen {

using namespace sewn;
using namespace sewn::physics;
using namespace sewn::refine;
using namespace refine_test;
using Eigen::Vector3d;

namespace {

const MaterialParams material{1e5, 0.3, 100, 0.5};

// Live particles by rest point, live springs by their ends' rest points and kind.
using Key = std::array<long, 2>;
Key key(const Vector3d& r) { return {std::lround(r.x() * 6400), std::lround(r.y() * 6400)}; }
struct Snapshot {
  std::map<Key, double> mass;
  std::map<std::tuple<Key, Key, int>, std::array<double, 3>> spring;
};
Snapshot snapshot(const MssModel<2>& m) {
  Snapshot s;
  for (Index i = 0; i < m.nodes().size(); ++i)
    if (m.nodes().is_alive(i)) s.mass[key(m.rest_position(i))] = m.nodes().mass(i);
  const Springs& sp = m.springs();
  for (Index k = 0; k < sp.size(); ++k) {
    if (!sp.is_alive(k)) continue;
    Key a = key(m.rest_position(sp.node_i(k))), b = key(m.rest_position(sp.node_j(k)));
    if (b < a) std::swap(a, b);
    s.spring[std::make_tuple(a, b, static_cast<int>(sp.kind(k)))] = {sp.stiffness(k), sp.rest_length(k), sp.viscosity(k)};
  }
  return s;
}
bool close(double a, double b) { return std::abs(a - b) <= 1e-12 * std::max(std::abs(a), std::abs(b)); }
void same(const Snapshot& a, const Snapshot& b) {
  REQUIRE(a.mass.size() == b.mass.size());
  REQUIRE(a.spring.size() == b.spring.size());
  for (const auto& [k, m] : a.mass) {
    REQUIRE(b.mass.count(k) == 1);
    CHECK(close(m, b.mass.at(k)));
  }
  for (const auto& [k, v] : a.spring) {
    REQUIRE(b.spring.count(k) == 1);
    for (int i = 0; i < 3; ++i) CHECK(close(v[i], b.spring.at(k)[i]));
  }
}

Vector3d momentum(const NodeTable& n) {
  Vector3d p = Vector3d::Zero();
  for (Index i = 0; i < n.size(); ++i)
    if (n.is_alive(i)) p += n.mass(i) * n.velocity(i);
  return p;
}

}  // namespace

TEST_CASE("coarsen: refine then coarsen gives back the model, with momentum kept and energy reported") {
  MssModel<2> m(quad_grid(3, 3, {{0.1, 0.1, 1}, {}}), {material}, {}, no_gravity());
  const Snapshot original = snapshot(m);
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-1, 1);
  for (Index i = 0; i < m.nodes().size(); ++i) m.nodes().set_velocity(i, Vector3d(u(rng), u(rng), 0));
  const RefineReport r = refine_element(m, 4);
  (void)refine_element(m, 1);  // the neighbour below: the shared midpoint stays as a T-junction
  check_all(m);
  // fine-scale motion inside the family
  for (Index c : r.children)
    for (Index n : m.element_nodes(c)) m.nodes().set_velocity(n, m.nodes().velocity(n) + Vector3d(0.3 * u(rng), 0.3 * u(rng), 0));

  m.system().slaves().after_step(m.nodes());
  const Vector3d p0 = momentum(m.nodes());
  const double mass0 = m.node_mass();
  const CoarsenReport c = coarsen(m, 4);
  check_all(m);
  CHECK(c.particles_removed == 4);  // the centre and 3 midpoints; the one shared with element 1's children stays
  CHECK(c.dissipated_energy > 0);
  CHECK(std::abs(m.node_mass() - mass0) <= 1e-13 * mass0);
  CHECK((momentum(m.nodes()) - p0).norm() <= 1e-12 * p0.norm());
  CHECK(t_junctions(m).size() == 3);  // the kept midpoint, and element 1's side midpoints in elements 0 and 2
  (void)coarsen(m, 1);
  check_all(m);
  same(snapshot(m), original);
  CHECK(t_junctions(m).empty());
}

TEST_CASE("coarsen: a uniform motion loses no energy") {
  MssModel<2> m(quad_grid(2, 2, {{0.1, 0.1, 1}, {}}), {material}, {}, no_gravity());
  (void)refine_element(m, 0);
  for (Index i = 0; i < m.nodes().size(); ++i) m.nodes().set_velocity(i, Vector3d(0.5, -0.25, 0));
  const CoarsenReport c = coarsen(m, 0);
  CHECK(std::abs(c.dissipated_energy) <= 1e-15);
  for (Index i = 0; i < m.nodes().size(); ++i)
    if (m.nodes().is_alive(i)) CHECK((m.nodes().velocity(i) - Vector3d(0.5, -0.25, 0)).norm() <= 1e-14);
}

TEST_CASE("coarsen: seeded random refine / coarsen sequences keep every invariant and end where they began") {
  for (unsigned seed : {1u, 2u, 3u}) {
    CAPTURE(seed);
    MssModel<2> m(quad_grid(3, 2, {{0.1, 0.1, 1}, {}}), {material}, {}, no_gravity());
    const Snapshot original = snapshot(m);
    const double mass0 = m.node_mass();
    std::mt19937 rng(seed);
    RefineOptions o;
    o.max_level = 4;
    for (int step = 0; step < 40; ++step) {
      std::vector<Index> leaves, families;
      for (Index e = 0; e < m.elements().size(); ++e) {
        if (m.elements()[e].alive && level_index(m.elements()[e].level) < o.max_level) leaves.push_back(e);
        if (can_coarsen(m, e)) families.push_back(e);
      }
      const bool refine_now = families.empty() || (!leaves.empty() && std::uniform_int_distribution<int>(0, 2)(rng) > 0);
      if (refine_now) (void)refine_element(m, leaves[std::uniform_int_distribution<std::size_t>(0, leaves.size() - 1)(rng)], o);
      else (void)coarsen(m, families[std::uniform_int_distribution<std::size_t>(0, families.size() - 1)(rng)]);
      check_all(m);
      CHECK(std::abs(m.node_mass() - mass0) <= 1e-13 * mass0);
    }
    for (bool any = true; any;) {  // coarsen everything back
      any = false;
      for (Index e = 0; e < m.elements().size(); ++e)
        if (can_coarsen(m, e)) {
          (void)coarsen(m, e);
          check_all(m);
          any = true;
        }
    }
    same(snapshot(m), original);
  }
}

TEST_CASE("coarsen: refused with the reason, the model unchanged") {
  MssModel<2> m(quad_grid(2, 2, {{0.1, 0.1, 1}, {}}), {material}, {}, no_gravity());
  const RefineReport r = refine_element(m, 0);
  (void)refine_element(m, r.children[1]);
  auto state = [&] { return std::make_tuple(m.map().num_darts(), m.nodes().num_alive(), m.node_mass()); };
  const auto before = state();
  CHECK_THROWS_WITH_AS(coarsen(m, 3), doctest::Contains("not refined"), InputError);
  CHECK_THROWS_WITH_AS(coarsen(m, 0), doctest::Contains("refined further"), InputError);
  CHECK_THROWS_WITH_AS(coarsen(m, 99), doctest::Contains("does not exist"), InputError);
  CHECK(state() == before);
  // a cut between two children of the other family
  const RefineReport r2 = refine_element(m, 1);
  const Element& child = m.elements()[r2.children[0]];
  Dart x = child.dart;  // corner 0 -> midpoint 0 -> centre: the dart after the midpoint is interior
  x = m.map().beta(x, 1);
  const std::vector<Facet> facet{{x, 2}};
  (void)cut(m, facet);
  const auto after_cut = state();
  std::string why;
  CHECK(!can_coarsen(m, 1, &why));
  CHECK(why.find("cut") != std::string::npos);
  CHECK_THROWS_WITH_AS(coarsen(m, 1), doctest::Contains("cut"), InputError);
  CHECK(state() == after_cut);
  check_all(m);
}

TEST_CASE("cut and refine: seeded random refine / coarsen / cut sequences") {
  for (unsigned seed : {1u, 2u, 3u, 4u}) {
    CAPTURE(seed);
    MssModel<2> m(quad_grid(3, 3, {{0.1, 0.1, 1}, {}}), {material}, {}, no_gravity());
    const double mass0 = m.node_mass();
    std::mt19937 rng(seed);
    RefineOptions o;
    o.max_level = 4;
    int cuts = 0;
    for (int step = 0; step < 40; ++step) {
      CAPTURE(step);
      std::vector<Index> leaves, families;
      for (Index e = 0; e < m.elements().size(); ++e) {
        if (m.elements()[e].alive && level_index(m.elements()[e].level) < o.max_level) leaves.push_back(e);
        if (can_coarsen(m, e)) families.push_back(e);
      }
      const int op = std::uniform_int_distribution<int>(0, 3)(rng);
      CAPTURE(op);
      if (op <= 1 && !leaves.empty()) {
        (void)refine_element(m, leaves[std::uniform_int_distribution<std::size_t>(0, leaves.size() - 1)(rng)], o);
      } else if (op == 2 && !families.empty()) {
        (void)coarsen(m, families[std::uniform_int_distribution<std::size_t>(0, families.size() - 1)(rng)]);
      } else {
        const auto inner = inner_facets(m);
        if (inner.empty()) continue;
        const Facet f = inner[std::uniform_int_distribution<std::size_t>(0, inner.size() - 1)(rng)];
        (void)cut(m, std::vector<Facet>{f});
        ++cuts;
      }
      check_all(m);
      CHECK(std::abs(m.node_mass() - mass0) <= 1e-13 * mass0);
    }
    CHECK(cuts > 0);
  }
}

}  // namespace test_coarsen
