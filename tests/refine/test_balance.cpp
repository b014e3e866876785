// Optional 2:1 balance: refining an element first refines its neighbours that would end more
// than one level coarser; the invariant after seeded random refinement sequences, checked on the
// rest geometry (independently of the map's adjacency that the balance itself walks).
#include <doctest/doctest.h>

#include <random>
#include <string>

#include "sewn/refine/criteria.hpp"
#include "sewn/refine/criterion.hpp"
#include "sewn/refine/hierarchy.hpp"
#include "sewn/refine/subdivide.hpp"
#include "support.hpp"

namespace test_balance {  // one namespace per file: the unity build compiles several files as one

namespace {

using Eigen::Vector3d;
using sewn::physics::Index;
using sewn::physics::MssModel;

const sewn::physics::MaterialParams material{1e5, 0.3, 100, 0.5};

MssModel<2> quads(std::uint32_t nx, std::uint32_t ny) {
  return MssModel<2>(sewn::quad_grid(nx, ny, {{0.1, 0.1, 1}, {}}), {material}, {}, refine_test::no_gravity());
}
MssModel<3> hexes(std::uint32_t nx, std::uint32_t ny, std::uint32_t nz) {
  return MssModel<3>(sewn::hex_grid(nx, ny, nz, {{0.2, 0.15, 0.125}, {0.1, -0.2, 0.3}}), {material}, {}, refine_test::no_gravity());
}

// Pairs of live elements whose rest boxes share at least a segment (an edge or a face) and whose
// levels differ by more than a factor 2. O(elements²): small models only.
template <int D>
int unbalanced_pairs(const MssModel<D>& m) {
  std::vector<Index> live;
  std::vector<std::pair<Vector3d, Vector3d>> box;
  for (Index e = 0; e < m.elements().size(); ++e) {
    if (!m.elements()[e].alive) continue;
    Vector3d lo = Vector3d::Constant(1e300), hi = -lo;
    for (Index n : m.element_nodes(e)) {
      lo = lo.cwiseMin(m.rest_position(n));
      hi = hi.cwiseMax(m.rest_position(n));
    }
    live.push_back(e);
    box.emplace_back(lo, hi);
  }
  int bad = 0;
  for (std::size_t i = 0; i < live.size(); ++i)
    for (std::size_t j = i + 1; j < live.size(); ++j) {
      const Vector3d lo = box[i].first.cwiseMax(box[j].first), hi = box[i].second.cwiseMin(box[j].second);
      const double eps = 1e-9;
      bool touch = true;
      int long_dims = 0;
      for (int a = 0; a < D; ++a) {
        touch = touch && hi[a] - lo[a] > -eps;
        long_dims += hi[a] - lo[a] > eps;
      }
      if (!touch || long_dims == 0) continue;
      const std::uint32_t a = m.elements()[live[i]].level, b = m.elements()[live[j]].level;
      bad += a > 2 * b || b > 2 * a;
    }
  return bad;
}

template <int D>
void random_balanced(MssModel<D> m, int steps, int max_level, unsigned seed) {
  CAPTURE(seed);
  const double mass0 = m.node_mass();
  std::mt19937 rng(seed);
  sewn::refine::RefineOptions o;
  o.max_level = max_level;
  o.balance = true;
  int extra = 0;
  for (int step = 0; step < steps; ++step) {
    CAPTURE(step);
    std::vector<Index> leaves;
    for (Index e = 0; e < m.elements().size(); ++e)
      if (m.elements()[e].alive && sewn::refine::level_index(m.elements()[e].level) < o.max_level) leaves.push_back(e);
    if (leaves.empty()) break;
    const Index e = leaves[std::uniform_int_distribution<std::size_t>(0, leaves.size() - 1)(rng)];
    const auto r = sewn::refine::refine_element(m, e, o);
    extra += static_cast<int>(r.elements) - 1;
    refine_test::check_all(m);
    refine_test::check_constraints_fresh(m);
    REQUIRE(unbalanced_pairs(m) == 0);
    std::string why;
    CHECK(sewn::refine::is_balanced(m, &why));
    CHECK(std::abs(m.node_mass() - mass0) <= 1e-13 * mass0);
  }
  CHECK(extra > 0);  // the balance had work to do
}

}  // namespace

TEST_CASE("2:1 balance: a chain of refinements towards one side refines the neighbours first") {
  MssModel<2> m = quads(4, 1);
  sewn::refine::RefineOptions o;
  o.balance = true;
  // refine towards x = 0.1, the side shared with element 1, three levels deep
  Index e = 0;
  for (int depth = 0; depth < 3; ++depth) {
    const Vector3d at = m.element_centroid(e);
    const auto r = sewn::refine::refine_element(m, e, o);
    refine_test::check_all(m);
    REQUIRE(unbalanced_pairs(m) == 0);
    for (Index c : r.children)
      if (m.elements()[c].parent == e && m.element_centroid(c).x() > at.x() && m.element_centroid(c).y() < at.y()) e = c;
  }
  CHECK(sewn::refine::is_balanced(m));
  CHECK(!m.elements()[1].alive);  // refined by the balance
  CHECK(m.elements()[3].alive);   // two elements away: untouched
  // the same without balance leaves a jump of 4:1, which the check names
  MssModel<2> free = quads(4, 1);
  sewn::refine::RefineOptions plain;
  e = 0;
  for (int depth = 0; depth < 3; ++depth) {
    const Vector3d at = free.element_centroid(e);
    const auto r = sewn::refine::refine_element(free, e, plain);
    for (Index c : r.children)
      if (free.elements()[c].parent == e && free.element_centroid(c).x() > at.x() && free.element_centroid(c).y() < at.y()) e = c;
  }
  std::string why;
  CHECK(!sewn::refine::is_balanced(free, &why));
  CHECK(why.find("more than one level") != std::string::npos);
  CHECK(unbalanced_pairs(free) > 0);
}

TEST_CASE("2:1 balance: a listed element the balance already refined is skipped, not an error") {
  MssModel<2> m = quads(3, 1);
  sewn::refine::RefineOptions o;
  o.balance = true;
  (void)sewn::refine::refine_element(m, 1, o);
  Index child = sewn::physics::invalid_index;  // a child of 1 next to element 0
  for (Index c = m.elements()[1].first_child; c < m.elements()[1].first_child + 4; ++c)
    if (m.element_centroid(c).x() < 0.15) child = c;
  const std::vector<Index> list{child, 0};  // refining the child first refines 0 by balance
  const auto r = sewn::refine::refine_elements(m, std::span<const Index>(list), o);
  CHECK(r.elements == 2);
  CHECK(!m.elements()[0].alive);
  refine_test::check_all(m);
  CHECK(sewn::refine::is_balanced(m));
}

TEST_CASE("2:1 balance: seeded random refinement sequences keep it, 2D and 3D") {
  for (unsigned seed : {1u, 2u, 3u, 4u, 5u, 6u}) random_balanced(quads(4, 3), 30, 6, seed);
  for (unsigned seed : {1u, 2u, 3u}) random_balanced(hexes(3, 2, 1), 10, 4, seed);
}

TEST_CASE("2:1 balance: the adapter's coarsening keeps it") {
  MssModel<2> m = quads(4, 1);
  sewn::refine::RefineOptions o;
  o.balance = true;
  o.max_level = 4;
  // refined towards x = 0.1 (the side shared with element 1) three levels deep, with balance
  sewn::refine::InRegion<2> near_left([](const Vector3d& r) { return r.x() > 0.04 && r.x() < 0.1; });
  for (int k = 0; k < 3; ++k) (void)sewn::refine::adapt(m, near_left, o);
  REQUIRE(sewn::refine::is_balanced(m));
  REQUIRE(!m.elements()[1].alive);  // refined by the balance
  // calm everywhere but next to the shared side, where the finest elements stay: the adapter
  // coarsens what it may, and element 1's family, next to them, only as far as the balance allows
  sewn::refine::InRegion<2> keep([](const Vector3d& r) { return r.x() > 0.085 && r.x() < 0.1; });
  sewn::refine::Adapter<2>::Options ao;
  ao.refine = o;
  ao.calm_steps = 1;
  sewn::refine::Adapter<2> adapter(keep, ao);
  std::uint32_t coarsened = 0;
  for (int k = 0; k < 6; ++k) {
    coarsened += adapter.update(m).coarsened;
    refine_test::check_all(m);
    REQUIRE(unbalanced_pairs(m) == 0);
  }
  CHECK(coarsened > 0);
  CHECK(!m.elements()[1].alive);  // still refined: the finest elements next to it stayed
}

}  // namespace test_balance
