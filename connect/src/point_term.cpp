#include "sewn/connect/point_term.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "trial_cap.hpp"

namespace sewn::connect {

using physics::InputError;
using physics::StateView;

PointStiffness rigid_stiffness(const physics::rods::Section& section, double rest_length, double factor) {
  if (!(std::isfinite(factor) && factor > 0 && std::isfinite(rest_length) && rest_length > 0))
    throw InputError("rigid_stiffness: factor and rest length must be finite and > 0, got " + std::to_string(factor) + " and " +
                     std::to_string(rest_length));
  return {factor * section.GJ / rest_length, factor * std::min(section.EI1, section.EI2) / rest_length};
}

RodEdgeBinding bind_rod_edge(const physics::rods::Rods* rods, const RodEdgeRef& r, const StateView& s, const std::string& owner) {
  const std::string who = owner + ": rod " + std::to_string(r.rod) + " edge " + std::to_string(r.edge);
  if (!rods) throw InputError(who + " names a rod, but the term was given no rods");
  if (!rods->has_angle_dofs())
    throw InputError(who + ": the rods' twist angles must be DOFs (Rods::use_angle_dofs) for a connection to act on them");
  if (r.rod >= rods->num_rods() || r.edge < 0 || r.edge >= rods->rod(r.rod).num_edges()) throw InputError(who + " is out of range");
  const auto nodes = rods->rod_nodes(r.rod);
  const auto x = rods->gather(r.rod, s.x);
  const int to = (r.edge + 1) % rods->rod(r.rod).num_vertices();
  RodEdgeBinding out;
  out.side.from = nodes[static_cast<std::size_t>(r.edge)];
  out.side.to = nodes[static_cast<std::size_t>(to)];
  out.side.tangent = (x.col(to) - x.col(r.edge)).normalized();
  out.side.director = rods->rod(r.rod).reference_director(x, r.edge);
  out.angle = rods->angle_of(r.rod, r.edge);
  return out;
}

PointConnections::PointConnections(const physics::rods::Rods* rods, TwistUpdate update) : ConnectionTerm(rods, update) {}

Index PointConnections::add(const std::string& name, const SideRef& m, const SideRef& n, PointStiffness k, const StateView& s) {
  std::array<Index, 2> angle{physics::invalid_index, physics::invalid_index};
  auto resolve = [&](const SideRef& ref, int which) -> Side {
    if (const auto* t = std::get_if<TriangleSide>(&ref)) return *t;
    if (const auto* k = std::get_if<TetSide>(&ref)) return *k;
    if (const auto* v = std::get_if<VertexSide>(&ref)) return *v;
    const RodEdgeBinding bound = bind_rod_edge(rods_, std::get<RodEdgeRef>(ref), s, "point connection '" + name + "'");
    angle[static_cast<std::size_t>(which)] = bound.angle;
    return bound.side;
  };
  const Side sm = resolve(m, 0), sn = resolve(n, 1);
  const std::vector<Index> layout = stencil_layout(name, sm, sn);
  StencilDofs dofs;
  std::size_t p = 0;
  for (int which = 0; which < 2; ++which) {
    const Side& side = which == 0 ? sm : sn;
    const bool rod = std::holds_alternative<RodEdgeSide>(side);
    const auto* vertex = std::get_if<VertexSide>(&side);
    const int nodes = rod ? 2 : vertex ? static_cast<int>(vertex->ring.size()) + 1 : std::holds_alternative<TriangleSide>(side) ? 3 : 4;
    for (int v = 0; v < nodes; ++v, ++p) dofs.add_node(layout[p]);
    if (rod) dofs.add_angle(angle[static_cast<std::size_t>(which)]);
  }
  const Eigen::VectorXd q_rest = dofs.gather(s, "point connection '" + name + "'");
  return push(PointConnection(name, sm, sn, k, q_rest), std::move(dofs));
}

PointEval PointConnections::evaluate(Index c, const StateView& s) const {
  const Item& it = items_.at(c);
  return it.connection.evaluate(it.dofs.gather(s, it.owner()), update_, false);
}

std::array<Vec3, 4> PointConnections::frames(Index c, const StateView& s) const {
  const Item& it = items_.at(c);
  return it.connection.frames(it.dofs.gather(s, it.owner()));
}

double PointConnections::guarded_energy(const Item& it, const PointEval& e) const {
  const bool aliasing = update_ != TwistUpdate::direct && std::abs(e.twist - it.connection.accepted_twist()) > max_twist_increment;
  return (e.singular() || aliasing) ? std::numeric_limits<double>::infinity() : e.energy;
}

double PointConnections::potential_energy(const StateView& s) const {
  double E = 0;
  for (const Item& it : items_) E += guarded_energy(it, it.connection.evaluate(it.dofs.gather(s, it.owner()), update_, false));
  return E;
}

double PointConnections::step_fraction(const StateView& s, const StateView& dq) const {
  const auto evaluate = [&](const Item& it, const Eigen::VectorXd& q) { return it.connection.evaluate(q, update_, false); };
  const auto turn = [&](const PointEval& from, const PointEval& to) {
    return std::max(detail::twist_turn(from.twist, to.twist, update_ == TwistUpdate::direct), std::abs(to.bend_angle - from.bend_angle));
  };
  return detail::trial_fraction(items_, s, dq, max_trial_turn_, evaluate, turn);
}

}  // namespace sewn::connect
