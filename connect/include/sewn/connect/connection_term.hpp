#pragma once
// ConnectionTerm<Connection>: what PointConnections (point_term.hpp) and CurveConnections
// (curve_term.hpp) share as ForceTerms. Each holds a list of connections, each with the table
// of its stencil's DOFs (StencilDofs: nodes, and the System angles of rod sides), the twist
// update they follow, the cap on how far one Newton trial may turn a joint, and the block
// pattern the stencils were bound to. Everything that only walks that list lives here: forces,
// the Jacobian, history for checkpoints, the rules when nodes go or are renamed. The energy
// with its guard and the trial cap differ by kind of connection and stay in the derived terms.
// Instantiated for PointConnection and EdgeConnection only (connection_term.cpp).

#include <cstdint>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "sewn/connect/point.hpp"
#include "sewn/connect/stencil_dofs.hpp"
#include "sewn/physics/force_term.hpp"
#include "sewn/physics/rods/rods_term.hpp"

namespace sewn::connect {

/// Largest change of the twist δ within one step before a state counts as singular (rad).
inline constexpr double max_twist_increment = 2.8;
/// Default of max_trial_turn() (rad): as NewtonEulerOptions::max_angle_step for a rod's angles,
/// a fraction of a radian the quadratic model follows.
inline constexpr double default_max_trial_turn = 0.7853981633974483;

template <class Connection>
class ConnectionTerm : public physics::ForceTerm {
 public:
  [[nodiscard]] Index size() const { return static_cast<Index>(items_.size()); }
  [[nodiscard]] const Connection& connection(Index c) const { return items_.at(c).connection; }
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
  /// The largest change of any joint's angles (its twist; a point connection's bend too) one
  /// Newton trial may make (rad, > 0; infinity: no limit, the jump guard alone). Throws
  /// physics::InputError otherwise.
  void set_max_trial_turn(double radians);
  [[nodiscard]] double max_trial_turn() const { return max_trial_turn_; }

  [[nodiscard]] bool velocity_dependent() const override { return false; }
  void add_forces(const physics::StateView& s, std::span<double> f) const override;
  void collect_pairs(std::vector<physics::NodePair>& out) const override;
  void bind_pattern(const physics::BlockMatrix& pattern) override;
  void add_jacobians(const physics::StateView& s, const physics::JacobianRequest& req) const override;
  void step_accepted(const physics::StateView& s) override;
  void check_nodes(const physics::NodeTable& nodes) const override;
  void remap_nodes(std::span<const Index> old_to_new) override;

 protected:
  struct Item {
    Connection connection;
    StencilDofs dofs;  // stencil order
    [[nodiscard]] std::string owner() const { return std::string(Connection::kind) + " '" + connection.name() + "'"; }
  };

  ConnectionTerm(const physics::rods::Rods* rods, TwistUpdate update) : rods_(rods), update_(update) {}
  /// Appends connection c with its stencil's DOFs. Returns its index. O(1).
  Index push(Connection c, StencilDofs dofs);

  const physics::rods::Rods* rods_;
  TwistUpdate update_;
  std::vector<Item> items_;
  double max_trial_turn_ = default_max_trial_turn;
  std::uint64_t bound_pattern_ = ~std::uint64_t{0};
};

}  // namespace sewn::connect
