#pragma once
// The trial cap shared by point and curve connections (ForceTerm::step_fraction): the largest
// fraction α = 2^−k ≤ 1 of a Newton trial dq from s such that no connection's angles move by
// more than `max_turn` from their values at s, so that the incremental twist follows every
// trial continuously and the jump guard stays the last line of defence.

#include <cmath>
#include <numbers>

#include <Eigen/Core>

#include "sewn/physics/force_term.hpp"

namespace sewn::connect::detail {

/// `evaluate(item, q)` gives an item's values at its stencil DOFs q, `turn(from, to)` how far
/// its angles moved between two of them (rad). Halving from the fraction the items before left:
/// only the smallest matters. max_turn = ∞: no cap. O(items × halvings).
template <class Items, class Evaluate, class Turn>
double trial_fraction(const Items& items, const physics::StateView& s, const physics::StateView& dq, double max_turn,
                      const Evaluate& evaluate, const Turn& turn) {
  if (!std::isfinite(max_turn)) return 1.0;
  constexpr int max_halvings = 40;  // 1e-12 of the step: a joint that cannot move at all
  double alpha = 1.0;
  for (const auto& it : items) {
    const Eigen::VectorXd q = it.dofs.gather(s, it.owner()), d = it.dofs.gather(dq, it.owner());
    const auto from = evaluate(it, q);
    for (int h = 0; h < max_halvings && turn(from, evaluate(it, q + alpha * d)) > max_turn; ++h) alpha *= 0.5;
  }
  return alpha;
}

/// How far a twist moved from `from` to `to`: the direct angle wraps by 2π, which is a jump,
/// not a turn.
inline double twist_turn(double from, double to, bool direct) {
  return std::abs(direct ? std::remainder(to - from, 2 * std::numbers::pi) : to - from);
}

}  // namespace sewn::connect::detail
