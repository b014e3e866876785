// 1:4 refinement of quads (the 2014 paper, PHYSICS_NOTES §2.2-2.5): the refined model must be the
// model built directly at the finer size, and the hierarchy invariants must hold after every step.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <random>
#include <tuple>

#include "sewn/physics/integrators.hpp"
#include "sewn/refine/cut.hpp"
#include "sewn/refine/hierarchy.hpp"
#include "sewn/refine/subdivide.hpp"
#include "support.hpp"

namespace test_refine_quad {

using namespace sewn;
using namespace sewn::physics;
using namespace sewn::refine;
using namespace refine_test;
using Eigen::Vector3d;

namespace {

const MaterialParams material{1e5, 0.3, 100, 0.5};

IndexedMesh grid(std::uint32_t nx, std::uint32_t ny, double hx, double hy) {
  return quad_grid(nx, ny, {{hx, hy, 1.0}, {0.1, -0.2, 0.0}});
}

Vector3d momentum(const NodeTable& n) {
  Vector3d p = Vector3d::Zero();
  for (Index i = 0; i < n.size(); ++i)
    if (n.is_alive(i)) p += n.mass(i) * n.velocity(i);
  return p;
}

// Rest positions on a grid of spacing h/64 are exact integers in these units: a key that
// matches particles of two models whatever their numbering.
using Key = std::array<long, 2>;
Key key(const Vector3d& r, double hx, double hy) { return {std::lround(r.x() / hx * 64), std::lround(r.y() / hy * 64)}; }

struct Snapshot {
  std::map<Key, Index> node;  // live particle at each rest point
  std::map<std::tuple<Key, Key, int>, std::array<double, 3>> spring;  // (ends, kind) -> k, rest length, γ
};

Snapshot snapshot(const MssModel<2>& m, double hx, double hy) {
  Snapshot s;
  const NodeTable& n = m.nodes();
  for (Index i = 0; i < n.size(); ++i)
    if (n.is_alive(i)) {
      const bool fresh = s.node.emplace(key(m.rest_position(i), hx, hy), i).second;
      REQUIRE(fresh);
    }
  const Springs& sp = m.springs();
  for (Index k = 0; k < sp.size(); ++k) {
    if (!sp.is_alive(k)) continue;
    Key a = key(m.rest_position(sp.node_i(k)), hx, hy), b = key(m.rest_position(sp.node_j(k)), hx, hy);
    if (b < a) std::swap(a, b);
    const bool fresh =
        s.spring.emplace(std::make_tuple(a, b, static_cast<int>(sp.kind(k))), std::array{sp.stiffness(k), sp.rest_length(k), sp.viscosity(k)})
            .second;
    REQUIRE(fresh);
  }
  return s;
}

bool close(double a, double b) { return std::abs(a - b) <= 1e-12 * std::max(std::abs(a), std::abs(b)); }

// The refined model against the directly built one: same particles (rest point, mass, position,
// velocity), same springs (ends, kind, stiffness, rest length, viscosity).
void same_model(const MssModel<2>& refined, const MssModel<2>& fine, double hx, double hy) {
  const Snapshot a = snapshot(refined, hx, hy), b = snapshot(fine, hx, hy);
  REQUIRE(a.node.size() == b.node.size());
  REQUIRE(a.spring.size() == b.spring.size());
  for (const auto& node : a.node) {
    const auto& k = node.first;
    const Index i = node.second;
    REQUIRE(b.node.count(k) == 1);
    const Index j = b.node.at(k);
    INFO("particle at (" << k[0] << ", " << k[1] << ")/64");
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

// An affine motion (positions and velocities): bilinear interpolation reproduces it exactly, so
// the directly built fine model can be given the same state.
void affine_state(MssModel<2>& m) {
  Eigen::Matrix3d F, G;
  F << 1.1, 0.2, 0, -0.1, 0.9, 0, 0.05, 0.1, 1;
  G << 0.3, -1.0, 0, 0.5, 0.2, 0, 0.1, 0.4, 0;
  for (Index i = 0; i < m.nodes().size(); ++i) {
    const Vector3d r = m.rest_position(i);
    m.nodes().set_position(i, F * r + Vector3d(0.01, 0.02, 0.03));
    m.nodes().set_velocity(i, G * r + Vector3d(1, -2, 0.5));
  }
}

}  // namespace

TEST_CASE("refine quads: uniform refinement k times is the grid built at the fine size") {
  const double hx = 0.2, hy = 0.125;
  for (int k = 1; k <= 3; ++k) {
    CAPTURE(k);
    MssModel<2> m(grid(3, 2, hx, hy), {material}, {}, no_gravity());
    affine_state(m);
    const double mass0 = m.node_mass();
    const Vector3d p0 = momentum(m.nodes());
    for (int pass = 0; pass < k; ++pass) {
      // one element at a time, validated after each: T-junctions appear and are reused
      std::vector<Index> live;
      for (Index e = 0; e < m.elements().size(); ++e)
        if (m.elements()[e].alive) live.push_back(e);
      for (Index e : live) {
        (void)refine_element(m, e);
        check_all(m);
        CHECK(std::abs(m.node_mass() - mass0) <= 1e-13 * mass0);
        CHECK((momentum(m.nodes()) - p0).norm() <= 1e-12 * p0.norm());
      }
    }
    const std::uint32_t n = 1u << k;
    MssModel<2> fine(grid(3 * n, 2 * n, hx / n, hy / n), {material}, {}, no_gravity());
    affine_state(fine);
    same_model(m, fine, hx, hy);
    CHECK(t_junctions(m).empty());
    for (const Element& el : m.elements())
      if (el.alive) CHECK(level_index(el.level) == 1 + k);
  }
}

TEST_CASE("refine quads: the refined model follows the fine model's trajectory") {
  const double hx = 0.2, hy = 0.125;
  MssModel<2> m(grid(2, 2, hx, hy), {material}, {}, no_gravity());
  (void)refine_all(m);
  MssModel<2> fine(grid(4, 4, hx / 2, hy / 2), {material}, {}, no_gravity());
  for (MssModel<2>* x : {&m, &fine}) {
    affine_state(*x);
    x->nodes().fix(x->node_of_point(0));  // the same particle: rest point (0, 0) in both
  }
  SymplecticEuler a, b;
  for (int s = 0; s < 200; ++s) {
    (void)a.step(m.system(), 2e-5);
    (void)b.step(fine.system(), 2e-5);
  }
  const Snapshot sa = snapshot(m, hx, hy), sb = snapshot(fine, hx, hy);
  double worst = 0;
  for (const auto& [k, i] : sa.node) worst = std::max(worst, (m.nodes().position(i) - fine.nodes().position(sb.node.at(k))).norm());
  CHECK(worst <= 1e-10);
}

TEST_CASE("refine quads: local refinement leaves slaved T-junctions at their dyadic places") {
  const double hx = 0.2, hy = 0.2;
  MssModel<2> m(grid(3, 3, hx, hy), {material}, {}, no_gravity());
  affine_state(m);
  const double mass0 = m.node_mass();
  const Vector3d p0 = momentum(m.nodes());
  const RefineReport r1 = refine_element(m, 4);  // the centre element
  check_all(m);
  CHECK(r1.particles == 5);
  CHECK(r1.children.size() == 4);
  CHECK(t_junctions(m).size() == 4);  // one per side, each in a neighbour
  // a child in the corner next to element 1 (below), twice: level 3 next to level 1
  const RefineReport r2 = refine_element(m, r1.children[0]);
  check_all(m);
  const RefineReport r3 = refine_element(m, r2.children[0]);
  check_all(m);
  CHECK(level_index(m.elements()[r3.children[0]].level) == 4);
  const auto tj = t_junctions(m);
  for (const TJunction& t : tj) {
    CAPTURE(t.node);
    REQUIRE(t.masters == 2);
    const Vector3d expect = t.weight[0] * m.nodes().position(t.master[0]) + t.weight[1] * m.nodes().position(t.master[1]);
    CHECK((m.nodes().position(t.node) - expect).norm() <= 1e-12);
    CHECK(m.elements()[t.element].alive);
    // a T-junction takes mass only from the elements it is a corner of: here all finer
    CHECK(m.nodes().mass(t.node) > 0);
  }
  // coarse to fine: a master that is itself a T-junction is listed before
  for (std::size_t i = 0; i + 1 < tj.size(); ++i)
    CHECK(m.elements()[tj[i].element].level <= m.elements()[tj[i + 1].element].level);
  CHECK(std::abs(m.node_mass() - mass0) <= 1e-13 * mass0);
  CHECK((momentum(m.nodes()) - p0).norm() <= 1e-12 * p0.norm());
  // refining the neighbour below reuses the midpoint already there: no particle on that side
  const Index below = 1;
  const Index before = m.nodes().num_alive();
  const RefineReport r4 = refine_element(m, below);
  check_all(m);
  CHECK(r4.particles == 4);  // 3 side midpoints and the centre
  CHECK(m.nodes().num_alive() == before + 4);
}

TEST_CASE("refine quads: seeded random refinement sequences keep every invariant") {
  for (unsigned seed : {1u, 2u, 3u}) {
    CAPTURE(seed);
    std::mt19937 rng(seed);
    MssModel<2> m(grid(2, 3, 0.15, 0.1), {material}, {}, no_gravity());
    std::uniform_real_distribution<double> u(-1, 1);
    for (Index i = 0; i < m.nodes().size(); ++i) m.nodes().set_velocity(i, Vector3d(u(rng), u(rng), u(rng)));
    const double mass0 = m.node_mass();
    const Vector3d p0 = momentum(m.nodes());
    RefineOptions o;
    o.max_level = 4;
    for (int step = 0; step < 25; ++step) {
      std::vector<Index> live;
      for (Index e = 0; e < m.elements().size(); ++e)
        if (m.elements()[e].alive && level_index(m.elements()[e].level) < o.max_level) live.push_back(e);
      if (live.empty()) break;
      (void)refine_element(m, live[std::uniform_int_distribution<std::size_t>(0, live.size() - 1)(rng)], o);
      check_all(m);
      CHECK(std::abs(m.node_mass() - mass0) <= 1e-13 * mass0);
      CHECK((momentum(m.nodes()) - p0).norm() <= 1e-12 * std::max(1.0, p0.norm()));
      CHECK(std::abs(m.element_mass() - mass0) <= 1e-13 * mass0);
    }
  }
}

TEST_CASE("refine: bad requests are refused with the reason, the model unchanged") {
  MssModel<2> m(grid(2, 2, 0.2, 0.2), {material}, {}, no_gravity());
  const RefineReport r = refine_element(m, 0);
  auto state = [&] {
    return std::make_tuple(m.map().num_darts(), m.nodes().num_alive(), m.springs().size(), m.elements().size(), m.node_mass());
  };
  const auto before = state();
  auto refused = [&](Index e, const RefineOptions& o, const char* what) {
    CAPTURE(what);
    std::string message;
    try {
      (void)refine_element(m, e, o);
    } catch (const InputError& ex) {
      message = ex.what();
    }
    CHECK(message.find(what) != std::string::npos);
    CHECK(state() == before);
    check_all(m);
  };
  refused(0, {}, "already refined");
  refused(99, {}, "does not exist");
  RefineOptions two;
  two.max_level = 2;
  refused(r.children[0], two, "maximum level 2");
  RefineOptions silly;
  silly.max_level = 0;
  refused(1, silly, "max_level 0");

  MssModel<2> pierced(grid(3, 1, 0.2, 0.2), {material}, {}, no_gravity());
  const std::vector<Index> gone{1};
  (void)pierce(pierced, gone, true);
  CHECK_THROWS_WITH_AS(refine_element(pierced, 1), doctest::Contains("was removed"), InputError);
  CHECK(pierced.map().validate().ok());

  MssModel<2> tris(tri_grid(2, 2), {material}, {}, no_gravity());
  CHECK_THROWS_WITH_AS(refine_element(tris, 0), doctest::Contains("triangle"), InputError);
  
}

}  // namespace test_refine_quad
