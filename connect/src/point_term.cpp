#include "sewn/connect/point_term.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "sewn/physics/elements/element_math.hpp"
#include "sewn/physics/nodes.hpp"

namespace sewn::connect {

using physics::InputError;
using physics::StateView;

PointStiffness rigid_stiffness(const physics::rods::Section& section, double rest_length, double factor) {
  if (!(std::isfinite(factor) && factor > 0 && std::isfinite(rest_length) && rest_length > 0))
    throw InputError("rigid_stiffness: factor and rest length must be finite and > 0, got " + std::to_string(factor) + " and " +
                     std::to_string(rest_length));
  return {factor * section.GJ / rest_length, factor * std::min(section.EI1, section.EI2) / rest_length};
}

PointConnections::PointConnections(const physics::rods::Rods* rods, TwistUpdate update) : rods_(rods), update_(update) {}

Index PointConnections::add(const std::string& name, const SideRef& m, const SideRef& n, PointStiffness k, const StateView& s) {
  std::array<Index, 2> angle{physics::invalid_index, physics::invalid_index};
  auto resolve = [&](const SideRef& ref, int which) -> Side {
    if (const auto* t = std::get_if<TriangleSide>(&ref)) return *t;
    const auto& r = std::get<RodEdgeRef>(ref);
    const std::string who = "point connection '" + name + "': rod " + std::to_string(r.rod) + " edge " + std::to_string(r.edge);
    if (!rods_) throw InputError(who + " names a rod, but the term was given no rods");
    if (!rods_->has_angle_dofs())
      throw InputError(who + ": the rods' twist angles must be DOFs (Rods::use_angle_dofs) for a connection to act on them");
    if (r.rod >= rods_->num_rods() || r.edge < 0 || r.edge >= rods_->rod(r.rod).num_edges())
      throw InputError(who + " is out of range");
    const auto nodes = rods_->rod_nodes(r.rod);
    const auto x = rods_->gather(r.rod, s.x);
    const int to = (r.edge + 1) % rods_->rod(r.rod).num_vertices();
    RodEdgeSide side;
    side.from = nodes[static_cast<std::size_t>(r.edge)];
    side.to = nodes[static_cast<std::size_t>(to)];
    side.tangent = (x.col(to) - x.col(r.edge)).normalized();
    side.director = rods_->rod(r.rod).reference_director(x, r.edge);
    angle[static_cast<std::size_t>(which)] = rods_->angle_of(r.rod, r.edge);
    return side;
  };
  const Side sm = resolve(m, 0), sn = resolve(n, 1);
  const std::vector<Index> layout = stencil_layout(name, sm, sn);
  std::vector<Dof> dofs;
  std::size_t p = 0;
  for (int which = 0; which < 2; ++which) {
    const bool rod = std::holds_alternative<RodEdgeSide>(which == 0 ? sm : sn);
    for (int v = 0; v < (rod ? 2 : 3); ++v, ++p)
      for (int a = 0; a < 3; ++a) dofs.push_back({false, layout[p], a});
    if (rod) dofs.push_back({true, angle[static_cast<std::size_t>(which)], 0});
  }
  items_.push_back(Item{PointConnection(name, sm, sn, k, gather(dofs, s, name)), dofs, {}, {}, {}});
  touch_topology();
  return size() - 1;
}

Eigen::VectorXd PointConnections::gather(const std::vector<Dof>& dofs, const StateView& s, const std::string& name) {
  Eigen::VectorXd q(static_cast<Eigen::Index>(dofs.size()));
  for (std::size_t k = 0; k < dofs.size(); ++k) {
    const Dof& d = dofs[k];
    if (d.angle) {
      if (d.id >= s.angles.size())
        throw InputError("point connection '" + name + "': angle " + std::to_string(d.id) +
                         " is not in the state (only the Newton integrator integrates angles)");
      q[static_cast<Eigen::Index>(k)] = s.angles[d.id];
    } else {
      q[static_cast<Eigen::Index>(k)] = s.x[3 * std::size_t{d.id} + static_cast<std::size_t>(d.axis)];
    }
  }
  return q;
}

PointEval PointConnections::evaluate(Index c, const StateView& s) const {
  const Item& it = items_.at(c);
  return it.connection.evaluate(gather(it.dofs, s, it.connection.name()), update_, false);
}

double PointConnections::guarded_energy(const Item& it, const PointEval& e) const {
  const bool aliasing = update_ != TwistUpdate::direct && std::abs(e.twist - it.connection.accepted_twist()) > max_twist_increment;
  return (e.singular() || aliasing) ? std::numeric_limits<double>::infinity() : e.energy;
}

void PointConnections::add_forces(const StateView& s, std::span<double> f) const {
  const std::size_t angle_base = 3 * std::size_t{s.size()};
  for (const Item& it : items_) {
    const PointEval e = it.connection.evaluate(gather(it.dofs, s, it.connection.name()), update_, true);
    for (std::size_t k = 0; k < it.dofs.size(); ++k) {
      const Dof& d = it.dofs[k];
      const std::size_t i = d.angle ? angle_base + d.id : 3 * std::size_t{d.id} + static_cast<std::size_t>(d.axis);
      if (i < f.size()) f[i] -= e.gradient[static_cast<Eigen::Index>(k)];
    }
  }
}

double PointConnections::potential_energy(const StateView& s) const {
  double E = 0;
  for (const Item& it : items_) E += guarded_energy(it, it.connection.evaluate(gather(it.dofs, s, it.connection.name()), update_, false));
  return E;
}

Index PointConnections::block_row(const Dof& d) const { return d.angle ? angle_layout().block(d.id) : d.id; }
int PointConnections::component(const Dof& d) const { return d.angle ? angle_layout().component(d.id) : d.axis; }

void PointConnections::collect_pairs(std::vector<physics::NodePair>& out) const {
  for (const Item& it : items_) {
    std::vector<Index> rows;
    for (const Dof& d : it.dofs) rows.push_back(block_row(d));
    std::sort(rows.begin(), rows.end());
    rows.erase(std::unique(rows.begin(), rows.end()), rows.end());
    for (std::size_t a = 0; a < rows.size(); ++a)
      for (std::size_t b = a + 1; b < rows.size(); ++b) out.push_back({rows[a], rows[b]});
  }
}

void PointConnections::bind_pattern(const physics::BlockMatrix& pattern) {
  for (Item& it : items_) {
    it.blocks.clear();
    it.block_of.clear();
    for (const Dof& d : it.dofs) {
      const Index r = block_row(d);
      auto pos = std::find(it.blocks.begin(), it.blocks.end(), r);
      if (pos == it.blocks.end()) pos = it.blocks.insert(it.blocks.end(), r);
      it.block_of.push_back(static_cast<int>(pos - it.blocks.begin()));
    }
    it.slots.clear();
    for (Index a : it.blocks)
      for (Index b : it.blocks) it.slots.push_back(pattern.find(a, b));
  }
  bound_pattern_ = pattern.pattern_version();
}

void PointConnections::add_jacobians(const StateView& s, const physics::JacobianRequest& req) const {
  if (req.matrix && req.matrix->pattern_version() != bound_pattern_)
    throw InputError("connect::PointConnections::add_jacobians: the matrix does not carry the pattern this term was bound to");
  const bool product = !req.product_in.empty();
  for (const Item& it : items_) {
    Eigen::MatrixXd H;
    (void)it.connection.evaluate(gather(it.dofs, s, it.connection.name()), update_, true, &H);
    if (req.options.project_element_hessians) physics::elements::project_psd(H);
    const std::size_t nb = it.blocks.size();
    for (std::size_t i = 0; i < it.dofs.size(); ++i)
      for (std::size_t j = 0; j < it.dofs.size(); ++j) {
        const double h = H(static_cast<Eigen::Index>(i), static_cast<Eigen::Index>(j));
        const int ci = component(it.dofs[i]), cj = component(it.dofs[j]);
        const std::size_t bi = static_cast<std::size_t>(it.block_of[i]), bj = static_cast<std::size_t>(it.block_of[j]);
        if (req.matrix) req.matrix->block(it.slots[bi * nb + bj])(ci, cj) -= req.cx * h;
        if (product)
          req.product_out[3 * std::size_t{it.blocks[bi]} + static_cast<std::size_t>(ci)] -=
              h * req.product_in[3 * std::size_t{it.blocks[bj]} + static_cast<std::size_t>(cj)];
      }
  }
}

void PointConnections::step_accepted(const StateView& s) {
  for (Item& it : items_) it.connection.accept(gather(it.dofs, s, it.connection.name()), update_);
}

void PointConnections::check_nodes(const physics::NodeTable& nodes) const {
  for (const Item& it : items_)
    for (const Dof& d : it.dofs)
      if (!d.angle && !nodes.is_alive(d.id))
        throw InputError("point connection '" + it.connection.name() + "' refers to node " + std::to_string(d.id) +
                         (d.id < nodes.size() ? ", which was removed" : ", out of range"));
}

void PointConnections::remap_nodes(std::span<const Index> old_to_new) {
  for (Item& it : items_)
    for (Dof& d : it.dofs)
      if (!d.angle) d.id = old_to_new[d.id];
  touch_topology();
}

}  // namespace sewn::connect
