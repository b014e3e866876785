#include "sewn/connect/curve_term.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "sewn/physics/elements/element_math.hpp"
#include "history.hpp"
#include "trial_cap.hpp"

namespace sewn::connect {

using physics::InputError;
using physics::StateView;

CurveConnections::CurveConnections(const physics::rods::Rods* rods, TwistUpdate update) : rods_(rods), update_(update) {}

Index CurveConnections::add(const std::string& name, Index a, Index b, const EdgeSideRef& m, const EdgeSideRef& n,
                            double k_per_length, const StateView& s) {
  const std::string owner = "curve connection '" + name + "'";
  std::array<Index, 2> angle{physics::invalid_index, physics::invalid_index};
  auto resolve = [&](const EdgeSideRef& ref, int which) -> EdgeSide {
    if (const auto* f = std::get_if<FaceSide>(&ref)) return *f;
    if (const auto* h = std::get_if<HingeSide>(&ref)) return *h;
    const RodEdgeBinding bound = bind_rod_edge(rods_, std::get<RodEdgeRef>(ref), s, owner);
    angle[static_cast<std::size_t>(which)] = bound.angle;
    return bound.side;
  };
  const EdgeSide sm = resolve(m, 0), sn = resolve(n, 1);
  // Stencil order (curve.hpp): a, b, then each side's θ or apices.
  StencilDofs dofs;
  dofs.add_node(a);
  dofs.add_node(b);
  for (int which = 0; which < 2; ++which) {
    const EdgeSide& side = which == 0 ? sm : sn;
    if (std::holds_alternative<RodEdgeSide>(side)) dofs.add_angle(angle[static_cast<std::size_t>(which)]);
    if (const auto* f = std::get_if<FaceSide>(&side)) dofs.add_node(f->apex);
    if (const auto* h = std::get_if<HingeSide>(&side)) {
      dofs.add_node(h->left);
      dofs.add_node(h->right);
    }
  }
  const Eigen::VectorXd q_rest = dofs.gather(s, owner);
  items_.push_back(Item{EdgeConnection(name, a, b, sm, sn, k_per_length, q_rest), std::move(dofs)});
  touch_topology();
  return size() - 1;
}

EdgeEval CurveConnections::evaluate(Index c, const StateView& s) const {
  const Item& it = items_.at(c);
  return it.connection.evaluate(it.dofs.gather(s, it.owner()), update_, false);
}

void CurveConnections::add_forces(const StateView& s, std::span<double> f) const {
  for (const Item& it : items_)
    it.dofs.subtract_gradient(it.connection.evaluate(it.dofs.gather(s, it.owner()), update_, true).gradient, s, f);
}

double CurveConnections::potential_energy(const StateView& s) const {
  double E = 0;
  for (const Item& it : items_) {
    const EdgeEval e = it.connection.evaluate(it.dofs.gather(s, it.owner()), update_, false);
    const bool aliasing =
        update_ != TwistUpdate::direct && std::abs(e.twist - it.connection.accepted_twist()) > max_twist_increment;
    E += (e.degenerate || aliasing) ? std::numeric_limits<double>::infinity() : e.energy;
  }
  return E;
}

void CurveConnections::set_max_trial_turn(double radians) {
  if (!(radians > 0.0)) throw InputError("curve connections: max_trial_turn must be > 0 rad (infinity: no limit), got " + std::to_string(radians));
  max_trial_turn_ = radians;
}

double CurveConnections::step_fraction(const StateView& s, const StateView& dq) const {
  const auto evaluate = [&](const Item& it, const Eigen::VectorXd& q) { return it.connection.evaluate(q, update_, false).twist; };
  const auto turn = [&](double from, double to) { return detail::twist_turn(from, to, update_ == TwistUpdate::direct); };
  return detail::trial_fraction(items_, s, dq, max_trial_turn_, evaluate, turn);
}

void CurveConnections::collect_pairs(std::vector<physics::NodePair>& out) const {
  for (const Item& it : items_) it.dofs.collect_pairs(angle_layout(), out);
}

void CurveConnections::bind_pattern(const physics::BlockMatrix& pattern) {
  for (Item& it : items_) it.dofs.bind(angle_layout(), pattern);
  bound_pattern_ = pattern.pattern_version();
}

void CurveConnections::add_jacobians(const StateView& s, const physics::JacobianRequest& req) const {
  if (req.matrix && req.matrix->pattern_version() != bound_pattern_)
    throw InputError("connect::CurveConnections::add_jacobians: the matrix does not carry the pattern this term was bound to");
  for (const Item& it : items_) {
    Eigen::MatrixXd H;
    (void)it.connection.evaluate(it.dofs.gather(s, it.owner()), update_, true, &H);
    if (req.options.project_element_hessians) physics::elements::project_psd(H);
    it.dofs.add_hessian(H, angle_layout(), req);
  }
}

void CurveConnections::step_accepted(const StateView& s) {
  for (Item& it : items_) it.connection.accept(it.dofs.gather(s, it.owner()), update_);
}

void CurveConnections::check_nodes(const physics::NodeTable& nodes) const {
  for (const Item& it : items_) it.dofs.check_nodes(nodes, it.owner());
}

Index CurveConnections::remove_dangling(const physics::NodeTable& nodes) {
  const auto before = items_.size();
  std::erase_if(items_, [&](const Item& it) { return it.dofs.touches_removed(nodes); });
  const auto removed = static_cast<Index>(before - items_.size());
  if (removed > 0) touch_topology();
  return removed;
}

void CurveConnections::remap_nodes(std::span<const Index> old_to_new) {
  for (Item& it : items_) {
    it.dofs.remap_nodes(old_to_new);
    it.connection.remap_nodes(old_to_new);
  }
  touch_topology();
}

std::vector<double> CurveConnections::history() const { return detail::items_history(items_); }

void CurveConnections::restore(std::span<const double> h) { detail::restore_items(items_, h, std::string(name())); }

std::vector<bool> CurveConnections::follow_nodes(Index num_nodes, const NodeDecision& decide) {
  std::vector<bool> kept = detail::follow_items(items_, num_nodes, decide);
  touch_topology();
  return kept;
}

}  // namespace sewn::connect
