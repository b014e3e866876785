// The volume term (physics/solids/volume_term) under refinement and coarsening: the stencils
// follow which elements are alive (a refined parent's retired, its children's added, a revived
// parent's added again), so the term always stands for the live elements' rest volume, and an
// affine deformation F costs ½ κ V̄ (det F - 1)² at every stage, T-junctions included.
#include <doctest/doctest.h>

#include <cmath>
#include <map>
#include <random>
#include <vector>

#include "sewn/physics/solids/volume_term.hpp"
#include "sewn/refine/coarsen.hpp"
#include "sewn/refine/hierarchy.hpp"
#include "sewn/refine/subdivide.hpp"
#include "support.hpp"

namespace test_volume_refine {  // one namespace per file: the unity build compiles several files as one

namespace {

namespace ph = sewn::physics;
namespace rf = sewn::refine;
using Eigen::Matrix3d;
using Eigen::Vector3d;
using ph::Index;

constexpr double kKappa = 2e5;
const ph::MaterialParams material{1e5, 0.3, 100};

// Live stencils: each on a live element, on its corners; every live hexahedron has 8; their
// weights add up to κ × the rest volume V̄.
void check_stencils(const ph::MssModel<3>& m, const ph::solids::VolumePreservation& term, double rest_volume) {
  std::map<Index, int> per_element;
  double weight = 0;
  for (Index s = 0; s < term.size(); ++s) {
    if (!term.is_alive(s)) continue;
    const Index el = term.source(s).element;
    CAPTURE(s);
    REQUIRE(el < m.elements().size());
    CHECK(m.elements()[el].alive);
    const std::vector<Index> corners = m.element_nodes(el);
    for (int k = 0; k < 4; ++k) CHECK(term.element_nodes(s)[static_cast<std::size_t>(k)] == corners[term.source(s).corners[static_cast<std::size_t>(k)]]);
    ++per_element[el];
    weight += term.stencil(s).stiffness;
  }
  for (Index el = 0; el < m.elements().size(); ++el)
    if (m.elements()[el].alive) CHECK(per_element[el] == 8);
  CHECK(std::abs(weight - kKappa * rest_volume) <= 1e-12 * kKappa * rest_volume);
}

// Every particle moved by x = F X + t: the T-junctions stay on their masters (the map is affine).
double affine_energy(ph::MssModel<3>& m, const ph::solids::VolumePreservation& term, const Matrix3d& F) {
  for (Index i = 0; i < m.nodes().size(); ++i)
    if (m.nodes().is_alive(i)) m.nodes().set_position(i, F * m.rest_position(i) + Vector3d(0.3, -0.1, 0.2));
  return term.potential_energy(m.system().state());
}

}  // namespace

TEST_CASE("volume term: seeded random refine / coarsen sequences keep its stencils on the live elements, energy exact") {
  Matrix3d F;
  F << 1.1, 0.05, 0.0, -0.02, 0.9, 0.1, 0.03, 0.0, 1.05;
  for (unsigned seed : {1u, 2u, 3u}) {
    CAPTURE(seed);
    ph::MssModel<3> m(sewn::hex_grid(2, 2, 1, {{0.1, 0.1, 0.1}, {}}), {material}, {}, refine_test::no_gravity());
    ph::solids::VolumePreservation* term = ph::solids::add_volume_preservation(m, std::vector{kKappa});
    REQUIRE(term != nullptr);
    const double volume = 4e-3, expected = 0.5 * kKappa * volume * std::pow(F.determinant() - 1, 2);
    const double mass0 = m.node_mass();
    std::mt19937 rng(seed);
    rf::RefineOptions o;
    o.max_level = 3;
    for (int step = 0; step < 14; ++step) {
      CAPTURE(step);
      refine_test::random_refine_or_coarsen(m, rng, o);
      refine_test::check_all(m);
      CHECK(std::abs(m.node_mass() - mass0) <= 1e-13 * mass0);
      check_stencils(m, *term, volume);
      const double e = affine_energy(m, *term, F);
      CHECK(std::abs(e - expected) <= 1e-10 * expected);
      // at rest the term is at its minimum: no energy, no force
      for (Index i = 0; i < m.nodes().size(); ++i)
        if (m.nodes().is_alive(i)) m.nodes().set_position(i, m.rest_position(i));
      CHECK(std::abs(term->potential_energy(m.system().state())) <= 1e-20);
    }
  }
}

}  // namespace test_volume_refine
