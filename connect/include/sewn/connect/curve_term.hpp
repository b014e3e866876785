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

class CurveConnections final : public physics::ForceTerm {
 public:
  /// `rods`: the term holding the rods that rod sides name (may be null if no side is a rod).
  explicit CurveConnections(const physics::rods::Rods* rods, TwistUpdate update = TwistUpdate::incremental_ii);

  /// Joins sides m and n along the edge (a, b), `k_per_length` in N/rad, at the rest state s.
  /// Throws physics::InputError naming the connection: a rod side without rods or angle DOFs
  /// or out of range, and whatever EdgeConnection's constructor refuses. Returns its index. O(1).
  Index add(const std::string& name, Index a, Index b, const EdgeSideRef& m, const EdgeSideRef& n, double k_per_length,
            const physics::StateView& s);
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
  /// The largest change of any joint's twist one Newton trial may make (rad, > 0; infinity: no
  /// limit, the jump guard alone). Throws physics::InputError otherwise.
  void set_max_trial_turn(double radians);
  [[nodiscard]] double max_trial_turn() const { return max_trial_turn_; }
  [[nodiscard]] const EdgeConnection& connection(Index c) const { return items_.at(c).connection; }
  /// Values of connection c at state s. O(1).
  [[nodiscard]] EdgeEval evaluate(Index c, const physics::StateView& s) const;

  [[nodiscard]] std::string_view name() const override { return "curve connections"; }
  [[nodiscard]] bool velocity_dependent() const override { return false; }
  void add_forces(const physics::StateView& s, std::span<double> f) const override;
  [[nodiscard]] double potential_energy(const physics::StateView& s) const override;
  /// The largest α ≤ 1 (halving from 1) such that no joint's twist at s + α dq differs from its
  /// value at s by more than max_trial_turn(). O(connections × halvings).
  [[nodiscard]] double step_fraction(const physics::StateView& s, const physics::StateView& dq) const override;
  void collect_pairs(std::vector<physics::NodePair>& out) const override;
  void bind_pattern(const physics::BlockMatrix& pattern) override;
  void add_jacobians(const physics::StateView& s, const physics::JacobianRequest& req) const override;
  void step_accepted(const physics::StateView& s) override;
  void check_nodes(const physics::NodeTable& nodes) const override;
  void remap_nodes(std::span<const Index> old_to_new) override;

 private:
  struct Item {
    EdgeConnection connection;
    StencilDofs dofs;  // stencil order
    [[nodiscard]] std::string owner() const { return "curve connection '" + connection.name() + "'"; }
  };
  const physics::rods::Rods* rods_;
  TwistUpdate update_;
  std::vector<Item> items_;
  double max_trial_turn_ = default_max_trial_turn;
  std::uint64_t bound_pattern_ = ~std::uint64_t{0};
};

}  // namespace sewn::connect
