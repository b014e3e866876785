// The criteria beside the diagonal strain (strain energy, region, point, contact, any-of), the
// memory bound of adapt(), and refinement of a clamped face (its new particles stay clamped).
#include <doctest/doctest.h>

#include <cmath>
#include <random>
#include <string>

#include <Eigen/Geometry>

#include "sewn/physics/integrators.hpp"
#include "sewn/refine/coarsen.hpp"
#include "sewn/refine/criteria.hpp"
#include "sewn/refine/criterion.hpp"
#include "sewn/refine/subdivide.hpp"
#include "support.hpp"

namespace test_criteria {

using namespace sewn;
using namespace sewn::physics;
using namespace sewn::refine;
using namespace refine_test;
using Eigen::Vector3d;

namespace criteria_test {

const MaterialParams material{1e5, 0.3, 100, 0.5};

// A 4 x 1 x 1 bar of 1 m hexahedra along x, from x = 0.
MssModel<3> bar(MssOptions o = no_gravity()) { return MssModel<3>(hex_grid(4, 1, 1, {{1, 1, 1}, {0, 0, 0}}), {material}, {}, o); }

Index live_hexahedra(const MssModel<3>& m) {
  Index n = 0;
  for (const auto& e : m.elements()) n += e.alive && e.kind == ElementKind::hexahedron;
  return n;
}



TEST_CASE("refine criteria: the strain energy density is the springs' energy over the volume, zero under rigid motion") {
  // one hexahedron: its own springs are all the model's, so its energy is the system's internal
  // potential energy, for any deformation
  MssModel<3> m(hex_grid(1, 1, 1, {{1, 0.8, 1.2}, {0, 0, 0}}), {material}, {}, no_gravity());
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> unit(-1, 1);
  for (Index i = 0; i < m.nodes().size(); ++i) m.nodes().set_position(i, m.rest_position(i) + 0.05 * Vector3d(unit(rng), unit(rng), unit(rng)));
  const double expected = m.system().potential_energy(EnergyKind::internal);
  REQUIRE(expected > 0);
  CHECK(StrainEnergy<3>::density(m, 0) * m.elements()[0].measure == doctest::Approx(expected).epsilon(1e-12));
  // a rigid rotation and translation of the rest shape stores nothing
  const Eigen::Matrix3d r = Eigen::AngleAxisd(0.7, Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  for (Index i = 0; i < m.nodes().size(); ++i) m.nodes().set_position(i, r * m.rest_position(i) + Vector3d(3, -1, 2));
  CHECK(StrainEnergy<3>::density(m, 0) < 1e-20 * material.young);
  CHECK_THROWS_AS(StrainEnergy<3>(0), InputError);
  CHECK_THROWS_AS(StrainEnergy<3>(std::nan("")), InputError);
  // a quad (2-map, energy over area x thickness) too
  MssModel<2> q(quad_grid(1, 1, {{0.1, 0.1, 1}, {}}), {material}, {}, no_gravity());
  for (Index i = 0; i < q.nodes().size(); ++i) q.nodes().set_position(i, q.rest_position(i) + 0.01 * Vector3d(unit(rng), unit(rng), 0));
  CHECK(StrainEnergy<2>::density(q, 0) * q.elements()[0].measure == doctest::Approx(q.system().potential_energy(EnergyKind::internal)).epsilon(1e-12));
}

TEST_CASE("refine criteria: the strain energy refines where the energy density is high, not where it is low") {
  MssModel<3> m = bar();
  // the far end stretched by 4 % along the bar: element 3 alone is strained, the others keep
  // their rest shape
  for (Index i = 0; i < m.nodes().size(); ++i)
    if (m.rest_position(i).x() == 4) m.nodes().set_position(i, m.rest_position(i) + Vector3d(0.04, 0, 0));
  const double high = StrainEnergy<3>::density(m, 3);
  REQUIRE(high > 0);
  for (Index e = 0; e < 3; ++e) CHECK(StrainEnergy<3>::density(m, e) == 0);
  const StrainEnergy<3> c(high / 2);
  CHECK(c.wants_refinement(m, 3));
  CHECK_FALSE(c.allows_coarsening(m, 3));
  for (Index e = 0; e < 3; ++e) {
    CHECK_FALSE(c.wants_refinement(m, e));
    CHECK(c.allows_coarsening(m, e));
  }
  RefineOptions opt;
  opt.max_level = 3;
  std::vector<Index> chosen;
  CHECK(adapt(m, c, opt, &chosen).elements == 1);
  CHECK(chosen == std::vector<Index>{3});
  check_all(m);
  // the children are stretched as their parent was (positions interpolated multilinearly): the
  // same density, since a spring's stiffness scales with its size; so they are refined next
  const Index first = m.elements()[3].first_child;
  for (Index k = first; k < first + 8; ++k) CHECK(StrainEnergy<3>::density(m, k) == doctest::Approx(high).epsilon(1e-9));
  chosen.clear();
  CHECK(adapt(m, c, opt, &chosen).elements == 8);
  for (Index k : chosen) CHECK(m.elements()[k].parent == 3);
  check_all(m);
}

TEST_CASE("refine criteria: a region at rest picks the elements whose rest centroid is in it") {
  MssModel<3> m = bar();
  const InRegion<3> first_two([](const Vector3d& p) { return p.x() < 2; });
  RefineOptions opt;
  opt.max_level = 3;
  RefineReport r = adapt(m, first_two, opt);
  CHECK(r.elements == 2);
  check_all(m);
  r = adapt(m, first_two, opt);  // the children of the first two, one level per call
  CHECK(r.elements == 16);
  check_all(m);
  CHECK(adapt(m, first_two, opt).elements == 0);  // max_level reached
  CHECK(live_hexahedra(m) == 2 + 128);
  // outside the region coarsening is allowed, inside not
  CHECK(first_two.allows_coarsening(m, 2));
  CHECK_FALSE(first_two.allows_coarsening(m, m.elements().size() - 1));
  CHECK_THROWS_AS(InRegion<3>(nullptr), InputError);
}

TEST_CASE("refine criteria: near a point follows the current positions, with hysteresis") {
  MssModel<3> m = bar();
  NearPoint<3> tool(Vector3d(3.5, 0.5, 0.5), 0.6);
  CHECK(tool.wants_refinement(m, 3));
  CHECK_FALSE(tool.wants_refinement(m, 2));
  CHECK_FALSE(tool.allows_coarsening(m, 2));  // 1 m away: not beyond twice the radius
  CHECK(tool.allows_coarsening(m, 1));
  // moving the body moves the elements: element 0 comes under the tool
  for (Index i = 0; i < m.nodes().size(); ++i) m.nodes().set_position(i, m.nodes().position(i) + Vector3d(3, 0, 0));
  CHECK(tool.wants_refinement(m, 0));
  tool.move_to(Vector3d(100, 0, 0));
  CHECK_FALSE(tool.wants_refinement(m, 0));
  CHECK(element_centroid(m, 0).isApprox(Vector3d(3.5, 0.5, 0.5)));
  CHECK_THROWS_AS(NearPoint<3>(Vector3d::Zero(), 0), InputError);
  CHECK_THROWS_AS(tool.move_to(Vector3d(std::nan(""), 0, 0)), InputError);
}

TEST_CASE("refine criteria: contact with an obstacle, and any of several") {
  MssModel<3> m = bar();
  using namespace physics::obstacles;
  // a ball around the far end's corner (4, 0, 0): only the last element has a particle inside
  InContact<3> touch({Sphere{Vector3d(4, 0, 0), 0.1}});
  CHECK(touch.wants_refinement(m, 3));
  CHECK_FALSE(touch.wants_refinement(m, 2));
  CHECK(touch.allows_coarsening(m, 2));
  CHECK_THROWS_AS(InContact<3>({}), InputError);

  std::vector<std::unique_ptr<Criterion<3>>> list;
  list.push_back(std::make_unique<InContact<3>>(std::vector<Shape>{Sphere{Vector3d(4, 0, 0), 0.1}}));
  list.push_back(std::make_unique<InRegion<3>>([](const Vector3d& p) { return p.x() < 1; }));
  const AnyOf<3> any(std::move(list));
  CHECK(any.wants_refinement(m, 0));
  CHECK(any.wants_refinement(m, 3));
  CHECK_FALSE(any.wants_refinement(m, 1));
  CHECK(any.allows_coarsening(m, 1));
  CHECK_FALSE(any.allows_coarsening(m, 0));  // the region still holds it
  RefineOptions opt;
  opt.max_level = 2;
  CHECK(adapt(m, any, opt).elements == 2);
  check_all(m);
  CHECK_THROWS_AS(AnyOf<3>({}), InputError);
}

TEST_CASE("the diagonal strain criterion's squared-length test agrees with strain_percent") {
  // wants_refinement and allows_coarsening compare squared lengths (no root, no division):
  // on seeded random deformations of a partly refined bar, they must say what the strain in
  // percent says, away from the thresholds by more than round-off
  MssModel<3> m = bar();
  (void)refine_element(m, 1);
  std::mt19937 rng(13);
  std::uniform_real_distribution<double> unit(-1, 1);
  int refine = 0, coarsen_ok = 0, compared = 0;
  for (int trial = 0; trial < 40; ++trial) {
    const double a = 0.0005 * (trial + 1);  // up to 2 cm on 1 m and 0.5 m elements
    for (Index i = 0; i < m.nodes().size(); ++i)
      m.nodes().set_position(i, m.rest_position(i) + a * Vector3d(unit(rng), unit(rng), unit(rng)));
    for (const double t : {0.5, 1.2, 3.0}) {
      const DiagonalStrain<3> c(t);
      for (Index e = 0; e < m.elements().size(); ++e) {
        if (!m.elements()[e].alive) continue;
        const double p = DiagonalStrain<3>::strain_percent(m, e);
        if (std::abs(p - t) > 1e-9) {
          CHECK(c.wants_refinement(m, e) == (p > t));
          refine += p > t;
        }
        if (std::abs(p - t / 2) > 1e-9) {
          CHECK(c.allows_coarsening(m, e) == (p < t / 2));
          coarsen_ok += p < t / 2;
        }
        ++compared;
      }
    }
  }
  CHECK(refine > compared / 10);  // both answers came up often
  CHECK(refine < compared * 9 / 10);
  CHECK(coarsen_ok > compared / 20);
}

TEST_CASE("adapt refuses a pass past max_elements, the model unchanged") {
  MssModel<3> m = bar();
  const InRegion<3> all([](const Vector3d&) { return true; });
  RefineOptions opt;
  opt.max_elements = 4 + 7 * 4 - 1;  // one short of refining all four
  const Index nodes = m.nodes().size(), springs = m.springs().num_alive();
  CHECK_THROWS_WITH_AS(adapt(m, all, opt), doctest::Contains("more than the limit of 31"), InputError);
  CHECK(m.nodes().size() == nodes);
  CHECK(m.springs().num_alive() == springs);
  CHECK(m.num_live_elements() == 4);
  check_all(m);
  opt.max_elements = 4 + 7 * 4;
  CHECK(adapt(m, all, opt).elements == 4);
}

TEST_CASE("refining next to a clamped face keeps the whole face clamped") {
  MssModel<3> m = bar(MssOptions{});  // with gravity
  for (Index i = 0; i < m.nodes().size(); ++i)
    if (m.rest_position(i).x() == 0) m.nodes().fix(i);
  (void)refine_element(m, 0);
  (void)refine_element(m, m.elements()[0].first_child);  // the child at the clamped corner
  check_all(m);
  int on_face = 0;
  for (Index i = 0; i < m.nodes().size(); ++i) {
    const bool face = m.rest_position(i).x() == 0;
    on_face += face;
    CHECK(m.nodes().fixed(i) == (face ? all_axes : no_axes));
  }
  CHECK(on_face == 4 + 5 + 5);  // the corners; the parent's 4 side midpoints and centre; the child's 5 new points
  // a step leaves every particle of the clamped face at rest, where it was
  LinearlyImplicitEuler euler;
  (void)euler.step(m.system(), 1e-3);
  for (Index i = 0; i < m.nodes().size(); ++i)
    if (m.rest_position(i).x() == 0) CHECK(m.nodes().position(i).isApprox(m.rest_position(i)));
  // coarsening removes them again
  (void)coarsen(m, m.elements()[0].first_child);
  (void)coarsen(m, 0);
  check_all(m);
}

TEST_CASE("a kinematic face keeps its motion on the particles refinement adds") {
  MssModel<3> m = bar();
  for (Index i = 0; i < m.nodes().size(); ++i)
    if (m.rest_position(i).x() == 0) {
      m.nodes().fix(i, axis_z);
      m.nodes().set_velocity(i, Vector3d(0, 0, 0.5));
    }
  (void)refine_element(m, 0);
  for (Index i = 0; i < m.nodes().size(); ++i)
    if (m.rest_position(i).x() == 0) {
      CHECK(m.nodes().fixed(i) == axis_z);
      CHECK(m.nodes().velocity(i).z() == doctest::Approx(0.5));
    }
}

}  // namespace criteria_test

}  // namespace test_criteria
