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

/// Largest change of the twist δ within one step before a state counts as singular (rad).
inline constexpr double max_twist_increment = 2.8;
/// Default of PointConnections::max_trial_turn() (rad): as NewtonEulerOptions::max_angle_step
/// for a rod's angles, a fraction of a radian the quadratic model follows.
inline constexpr double default_max_trial_turn = 0.7853981633974483;

/// The stiff option for a rigid joint: k_t = factor·GJ/l̄, k_b = factor·min(EI1, EI2)/l̄ of a rod
/// section and edge — `factor` times the stiffness of the rod across one edge (1: the joint
/// behaves as that much rod; 1e3: it bends and twists a thousand times less). Throws
/// physics::InputError unless factor and rest_length are finite and > 0.
[[nodiscard]] PointStiffness rigid_stiffness(const physics::rods::Section& section, double rest_length, double factor = 1e3);

class PointConnections final : public physics::ForceTerm {
 public:
  /// `rods`: the term holding the rods that rod sides name (may be null if no side is a rod);
  /// it must have angle DOFs by the time a rod side is added.
  explicit PointConnections(const physics::rods::Rods* rods, TwistUpdate update = TwistUpdate::incremental_ii);

  /// Joins sides m and n at their shared node, with the rest state s (positions and angles,
  /// e.g. System::state() at build time). Throws physics::InputError naming the connection: a
  /// rod side without rods or angle DOFs or out of range, and whatever PointConnection's
  /// constructor refuses. Returns the connection's index. O(1).
  Index add(const std::string& name, const SideRef& m, const SideRef& n, PointStiffness k, const physics::StateView& s);
  [[nodiscard]] Index size() const { return static_cast<Index>(items_.size()); }
  /// Every connection's history (ConnectionHistory, point.hpp), history_size values each, in
  /// order: what step_accepted() moves on, for checkpoints. O(connections).
  [[nodiscard]] std::vector<double> history() const;
  /// Takes up history() of a term built the same way. Throws physics::InputError (nothing
  /// changed) if the size does not fit or a connection refuses its part. O(connections).
  void restore(std::span<const double> h);
  /// The rule when nodes go (a cut or a refinement removing them): a connection with a removed
  /// node in its stencil is removed with it (one of its sides no longer exists there), every
  /// other one is kept as it is; so none is left dangling. Call it after removing nodes and before
  /// System::compact_nodes(), whose node check otherwise refuses the connection by name. Returns
  /// how many were removed. O(connections).
  Index remove_dangling(const physics::NodeTable& nodes);
  /// The rule under cuts (the scene layer decides, apps/connections.hpp): each connection c is
  /// removed if `decide` says so, or kept with its nodes renamed (its DOF table and its own
  /// ids; rest data, history and energy at the current state unchanged). `num_nodes`: the node
  /// table's size (renamed ids must be below it). Returns per connection, as numbered before,
  /// whether it was kept. Throws physics::InputError naming the connection for an id out of
  /// range (nothing changed). O(connections + renames).
  std::vector<bool> follow_nodes(Index num_nodes, const NodeDecision& decide);
  /// The largest change of any joint's twist or bend one Newton trial may make (rad, > 0;
  /// infinity: no limit, the jump guard alone). Throws physics::InputError otherwise.
  void set_max_trial_turn(double radians);
  [[nodiscard]] double max_trial_turn() const { return max_trial_turn_; }
  [[nodiscard]] const PointConnection& connection(Index c) const { return items_.at(c).connection; }
  /// Values of connection c at state s (energy, angles, flags). O(1).
  [[nodiscard]] PointEval evaluate(Index c, const physics::StateView& s) const;
  /// Connection c's frames at state s ({m1, m3, n1, n3}, PointConnection::frames). O(1).
  [[nodiscard]] std::array<Vec3, 4> frames(Index c, const physics::StateView& s) const;

  [[nodiscard]] std::string_view name() const override { return "point connections"; }
  [[nodiscard]] bool velocity_dependent() const override { return false; }
  void add_forces(const physics::StateView& s, std::span<double> f) const override;
  [[nodiscard]] double potential_energy(const physics::StateView& s) const override;
  /// The largest α ≤ 1 (halving from 1) such that no joint's twist or bend at s + α dq differs
  /// from its value at s by more than max_trial_turn(). O(connections × halvings).
  [[nodiscard]] double step_fraction(const physics::StateView& s, const physics::StateView& dq) const override;
  void collect_pairs(std::vector<physics::NodePair>& out) const override;
  void bind_pattern(const physics::BlockMatrix& pattern) override;
  void add_jacobians(const physics::StateView& s, const physics::JacobianRequest& req) const override;
  void step_accepted(const physics::StateView& s) override;
  void check_nodes(const physics::NodeTable& nodes) const override;
  void remap_nodes(std::span<const Index> old_to_new) override;

 private:
  struct Item {
    PointConnection connection;
    StencilDofs dofs;  // stencil order
    [[nodiscard]] std::string owner() const { return "point connection '" + connection.name() + "'"; }
  };
  // Energy, or +inf at a singular configuration (see the header comment).
  [[nodiscard]] double guarded_energy(const Item& it, const PointEval& e) const;

  const physics::rods::Rods* rods_;
  TwistUpdate update_;
  std::vector<Item> items_;
  double max_trial_turn_ = default_max_trial_turn;
  std::uint64_t bound_pattern_ = ~std::uint64_t{0};
};

}  // namespace sewn::connect
