#pragma once
// What the refinement tests share: a model without gravity, and the check every test runs after
// each operation (the map's validate() and the hierarchy's own invariants).
#include <doctest/doctest.h>

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

}  // namespace refine_test
