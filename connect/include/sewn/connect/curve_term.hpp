#pragma once
// CurveConnections: curve connections (curve.hpp) as a ForceTerm, one element per shared edge
// and pair of sides, so that the Newton integrator moves the joined bodies with them. As for
// PointConnections (point_term.hpp), a rod side's θ is a System angle (Rods::use_angle_dofs),
// forces are −∂E/∂q, the Jacobian the stencil Hessian (PSD-projected when the integrator asks),
// and the history (accepted twist, rod sides' frames) moves on in step_accepted().
//
// Guard: a state where a side's frame cannot be built (EdgeEval::degenerate) or the twist moved
// by more than max_twist_increment since the last accepted step has infinite energy, so a line
// search shortens the step instead of crossing it. Before it, as for point connections,
// step_fraction() keeps every Newton trial (and the initial guess) from changing any joint's
// twist by more than max_trial_turn() from the iterate it starts at: a rod spun fast inside a
// shell's edge is then followed by a few capped trials instead of a refused step.

#include <string>
#include <variant>
#include <vector>

#include "sewn/connect/curve.hpp"
#include "sewn/connect/point_term.hpp"
#include "sewn/connect/stencil_dofs.hpp"

namespace sewn::connect {

using EdgeSideRef = std::variant<RodEdgeRef, FaceSide, HingeSide>;

class CurveConnections final : public ConnectionTerm<EdgeConnection> {
 public:
  /// `rods`: the term holding the rods that rod sides name (may be null if no side is a rod).
  explicit CurveConnections(const physics::rods::Rods* rods, TwistUpdate update = TwistUpdate::incremental_ii);

  /// Joins sides m and n along the edge (a, b), `k_per_length` in N/rad, at the rest state s.
  /// Throws physics::InputError naming the connection: a rod side without rods or angle DOFs
  /// or out of range, and whatever EdgeConnection's constructor refuses. Returns its index. O(1).
  Index add(const std::string& name, Index a, Index b, const EdgeSideRef& m, const EdgeSideRef& n, double k_per_length,
            const physics::StateView& s);
  /// Values of connection c at state s. O(1).
  [[nodiscard]] EdgeEval evaluate(Index c, const physics::StateView& s) const;

  [[nodiscard]] std::string_view name() const override { return "curve connections"; }
  [[nodiscard]] double potential_energy(const physics::StateView& s) const override;
  /// The largest α ≤ 1 (halving from 1) such that no joint's twist at s + α dq differs from its
  /// value at s by more than max_trial_turn(). O(connections × halvings).
  [[nodiscard]] double step_fraction(const physics::StateView& s, const physics::StateView& dq) const override;
};

}  // namespace sewn::connect
