#include "sewn/connect/curve_term.hpp"

#include <cmath>
#include <limits>

#include "trial_cap.hpp"

namespace sewn::connect {

using physics::InputError;
using physics::StateView;

CurveConnections::CurveConnections(const physics::rods::Rods* rods, TwistUpdate update) : ConnectionTerm(rods, update) {}

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
  return push(EdgeConnection(name, a, b, sm, sn, k_per_length, q_rest), std::move(dofs));
}

EdgeEval CurveConnections::evaluate(Index c, const StateView& s) const {
  const Item& it = items_.at(c);
  return it.connection.evaluate(it.dofs.gather(s, it.owner()), update_, false);
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

double CurveConnections::step_fraction(const StateView& s, const StateView& dq) const {
  const auto evaluate = [&](const Item& it, const Eigen::VectorXd& q) { return it.connection.evaluate(q, update_, false).twist; };
  const auto turn = [&](double from, double to) { return detail::twist_turn(from, to, update_ == TwistUpdate::direct); };
  return detail::trial_fraction(items_, s, dq, max_trial_turn_, evaluate, turn);
}

}  // namespace sewn::connect
