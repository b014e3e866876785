#pragma once
// What the refinement tests share: a model without gravity, and the check every test runs after
// each operation (the map's validate() and the hierarchy's own invariants).
#include <doctest/doctest.h>

#include <cmath>
#include <map>
#include <random>
#include <vector>

#include "sewn/physics/mss_model.hpp"
#include "sewn/refine/coarsen.hpp"
#include "sewn/refine/hierarchy.hpp"
#include "sewn/refine/subdivide.hpp"

namespace refine_test {

inline sewn::physics::MssOptions no_gravity() {
  sewn::physics::MssOptions o;
  o.gravity.setZero();
  return o;
}

template <int D>
void check_all(const sewn::physics::MssModel<D>& m) {
  const auto report = m.map().validate();
  INFO(report.str());
  REQUIRE(report.ok());
  const sewn::refine::HierarchyReport h = sewn::refine::check_hierarchy(m);
  INFO(h.str());
  REQUIRE(h.ok());
}

/// The system's T-junction constraints (kept up to date incrementally by refinement and
/// coarsening) are those a full rebuild finds: same slaves, masters and weights (to round-off).
template <int D>
void check_constraints_fresh(const sewn::physics::MssModel<D>& m) {
  const auto full = sewn::refine::t_junctions(m);
  const auto now = m.system().slaves().slaves();
  REQUIRE(now.size() == full.size());
  std::map<sewn::physics::Index, const sewn::physics::SlaveNode*> by_node;
  for (const auto& s : now) by_node[s.node] = &s;
  for (const auto& t : full) {
    CAPTURE(t.node);
    REQUIRE(by_node.count(t.node) == 1);
    const sewn::physics::SlaveNode& s = *by_node[t.node];
    REQUIRE(s.masters == t.masters);
    for (int k = 0; k < t.masters; ++k) {
      CHECK(s.master[static_cast<std::size_t>(k)] == t.master[static_cast<std::size_t>(k)]);
      CHECK(std::abs(s.weight[static_cast<std::size_t>(k)] - t.weight[static_cast<std::size_t>(k)]) <= 1e-14);
    }
  }
}

/// One step of a seeded random refine / coarsen sequence: refines a random live element below
/// `o.max_level` (two times in three, or whenever no family can coarsen), else coarsens a random
/// family that can.
template <int D>
void random_refine_or_coarsen(sewn::physics::MssModel<D>& m, std::mt19937& rng, const sewn::refine::RefineOptions& o) {
  std::vector<sewn::physics::Index> leaves, families;
  for (sewn::physics::Index e = 0; e < m.elements().size(); ++e) {
    if (m.elements()[e].alive && sewn::refine::level_index(m.elements()[e].level) < o.max_level) leaves.push_back(e);
    if (sewn::refine::can_coarsen(m, e)) families.push_back(e);
  }
  const bool refine_now = families.empty() || (!leaves.empty() && std::uniform_int_distribution<int>(0, 2)(rng) > 0);
  if (refine_now)
    (void)sewn::refine::refine_element(m, leaves[std::uniform_int_distribution<std::size_t>(0, leaves.size() - 1)(rng)], o);
  else
    (void)sewn::refine::coarsen(m, families[std::uniform_int_distribution<std::size_t>(0, families.size() - 1)(rng)]);
}

}  // namespace refine_test
