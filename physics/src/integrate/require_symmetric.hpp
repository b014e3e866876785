#pragma once
// Both CG-based implicit integrators need a symmetric matrix: one check, one message.
#include <string>
#include <string_view>

#include "sewn/physics/errors.hpp"
#include "sewn/physics/force_term.hpp"
#include "sewn/physics/system.hpp"

namespace sewn::physics::detail {

/// Throws InputError naming `who` and the first term whose Jacobian, with these options, is not
/// symmetric. O(terms).
inline void require_symmetric_jacobians(const System& sys, const JacobianOptions& options, std::string_view who) {
  for (const auto& t : sys.terms())
    if (!t->jacobian_symmetric(options))
      throw InputError(std::string(who) + ": term '" + std::string(t->name()) +
                       "' gives a non-symmetric matrix with these JacobianOptions (set "
                       "drop_viscous_position_terms = true); CG needs a symmetric matrix");
}

}  // namespace sewn::physics::detail
