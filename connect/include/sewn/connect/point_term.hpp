#pragma once
// PointConnections: point connections (point.hpp) as a ForceTerm on a System, so that the
// Newton integrator (physics/integrate/newton_euler.hpp) moves the joined bodies with them.
// A rod side's θ is a System angle (the rods must hold their twist as angle DOFs,
// rods::Rods::use_angle_dofs): the connection's torque on θ enters the same Newton system as
// the rod's own twist, which a quasi-static twist solve inside the Rods term could not see.
//
// Per connection: forces −∂E/∂q on the stencil's nodes and angle (stencil order of point.hpp),
// the energy, and the stencil Hessian (PSD-projected when the integrator asks,
// JacobianOptions::project_element_hessians). Stiffnesses are per connection, in N·m/rad,
// independent of the meshes' resolution; rigid_stiffness() gives the stiff option for a rigid
// joint. History (the accepted twist, the rod sides' frames) moves on in step_accepted(), at
// the same time as the rods' own frames.
//
// Guard against the singular configurations (PHYSICS_NOTES §3.5): a state where the two axes
// are nearly antiparallel, the bend angle is near π, or the twist moved by more than
// max_twist_increment since the last accepted step (an incremental angle would alias) has
// infinite energy, so a line search shortens the step instead of crossing it; forces there
// are still the formula's (finite).
//
// That guard is the last line of defence. Before it, step_fraction() keeps every Newton trial
// (and the initial guess) from changing any joint's twist or bend by more than
// max_trial_turn() from the iterate it starts at: the incremental twist then follows the
// motion continuously, and a knocked body's first guess cannot fling a joint past the guard.

#include <array>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

#include "sewn/connect/connection_term.hpp"
#include "sewn/connect/point.hpp"
#include "sewn/connect/stencil_dofs.hpp"
#include "sewn/physics/force_term.hpp"
#include "sewn/physics/rods/rods_term.hpp"

namespace sewn::connect {

/// A rod edge as a side, by the Rods term's rod index and edge.
struct RodEdgeRef {
  Index rod = 0;
  int edge = 0;
};
using SideRef = std::variant<RodEdgeRef, TriangleSide, TetSide, VertexSide>;

/// A rod edge of the Rods term as a side at state s (its nodes, its current reference frame) and
/// the System angle holding its θ. Throws physics::InputError naming `owner`: no rods, rods
/// without angle DOFs, a rod or edge out of range. O(1).
struct RodEdgeBinding {
  RodEdgeSide side;
  Index angle = 0;
};
[[nodiscard]] RodEdgeBinding bind_rod_edge(const physics::rods::Rods* rods, const RodEdgeRef& r, const physics::StateView& s,
                                           const std::string& owner);

/// The stiff option for a rigid joint: k_t = factor·GJ/l̄, k_b = factor·min(EI1, EI2)/l̄ of a rod
/// section and edge — `factor` times the stiffness of the rod across one edge (1: the joint
/// behaves as that much rod; 1e3: it bends and twists a thousand times less). Throws
/// physics::InputError unless factor and rest_length are finite and > 0.
[[nodiscard]] PointStiffness rigid_stiffness(const physics::rods::Section& section, double rest_length, double factor = 1e3);

class PointConnections final : public ConnectionTerm<PointConnection> {
 public:
  /// `rods`: the term holding the rods that rod sides name (may be null if no side is a rod);
  /// it must have angle DOFs by the time a rod side is added.
  explicit PointConnections(const physics::rods::Rods* rods, TwistUpdate update = TwistUpdate::incremental_ii);

  /// Joins sides m and n at their shared node, with the rest state s (positions and angles,
  /// e.g. System::state() at build time). Throws physics::InputError naming the connection: a
  /// rod side without rods or angle DOFs or out of range, and whatever PointConnection's
  /// constructor refuses. Returns the connection's index. O(1).
  Index add(const std::string& name, const SideRef& m, const SideRef& n, PointStiffness k, const physics::StateView& s);
  /// Values of connection c at state s (energy, angles, flags). O(1).
  [[nodiscard]] PointEval evaluate(Index c, const physics::StateView& s) const;
  /// Connection c's frames at state s ({m1, m3, n1, n3}, PointConnection::frames). O(1).
  [[nodiscard]] std::array<Vec3, 4> frames(Index c, const physics::StateView& s) const;

  [[nodiscard]] std::string_view name() const override { return "point connections"; }
  [[nodiscard]] double potential_energy(const physics::StateView& s) const override;
  /// The largest α ≤ 1 (halving from 1) such that no joint's twist or bend at s + α dq differs
  /// from its value at s by more than max_trial_turn(). O(connections × halvings).
  [[nodiscard]] double step_fraction(const physics::StateView& s, const physics::StateView& dq) const override;

 private:
  // Energy, or +inf at a singular configuration (see the header comment).
  [[nodiscard]] double guarded_energy(const Item& it, const PointEval& e) const;
};

}  // namespace sewn::connect
