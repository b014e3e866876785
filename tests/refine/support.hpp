#pragma once
// What the refinement tests share: a model without gravity, and the check every test runs after
// each operation (the map's validate() and the hierarchy's own invariants).
#include <doctest/doctest.h>

#include <cmath>
#include <map>

#include "sewn/physics/mss_model.hpp"
#include "sewn/refine/hierarchy.hpp"

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

}  // namespace refine_test
