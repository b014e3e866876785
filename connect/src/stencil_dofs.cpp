#include "sewn/connect/stencil_dofs.hpp"

#include <algorithm>

#include "sewn/physics/errors.hpp"
#include "sewn/physics/nodes.hpp"

namespace sewn::connect {

using physics::Index;
using physics::InputError;

void StencilDofs::add_node(Index node) {
  for (int a = 0; a < 3; ++a) dofs_.push_back({false, node, a});
}

void StencilDofs::add_angle(Index angle) { dofs_.push_back({true, angle, 0}); }

Eigen::VectorXd StencilDofs::gather(const physics::StateView& s, const std::string& owner) const {
  Eigen::VectorXd q(static_cast<Eigen::Index>(dofs_.size()));
  for (std::size_t k = 0; k < dofs_.size(); ++k) {
    const Dof& d = dofs_[k];
    if (d.angle) {
      if (d.id >= s.angles.size())
        throw InputError(owner + ": angle " + std::to_string(d.id) +
                         " is not in the state (only the Newton integrator integrates angles)");
      q[static_cast<Eigen::Index>(k)] = s.angles[d.id];
    } else {
      const std::size_t i = 3 * std::size_t{d.id} + static_cast<std::size_t>(d.axis);
      if (i >= s.x.size())
        throw InputError(owner + ": node " + std::to_string(d.id) + " is out of range (" + std::to_string(s.size()) + " nodes)");
      q[static_cast<Eigen::Index>(k)] = s.x[i];
    }
  }
  return q;
}

void StencilDofs::subtract_gradient(const Eigen::VectorXd& gradient, const physics::StateView& s, std::span<double> f) const {
  const std::size_t angle_base = 3 * std::size_t{s.size()};
  for (std::size_t k = 0; k < dofs_.size(); ++k) {
    const Dof& d = dofs_[k];
    const std::size_t i = d.angle ? angle_base + d.id : 3 * std::size_t{d.id} + static_cast<std::size_t>(d.axis);
    if (i < f.size()) f[i] -= gradient[static_cast<Eigen::Index>(k)];
  }
}

void StencilDofs::collect_pairs(const physics::AngleLayout& layout, std::vector<physics::NodePair>& out) const {
  std::vector<Index> rows;
  for (const Dof& d : dofs_) rows.push_back(block_row(d, layout));
  std::sort(rows.begin(), rows.end());
  rows.erase(std::unique(rows.begin(), rows.end()), rows.end());
  for (std::size_t a = 0; a < rows.size(); ++a)
    for (std::size_t b = a + 1; b < rows.size(); ++b) out.push_back({rows[a], rows[b]});
}

void StencilDofs::bind(const physics::AngleLayout& layout, const physics::BlockMatrix& pattern) {
  blocks_.clear();
  block_of_.clear();
  for (const Dof& d : dofs_) {
    const Index r = block_row(d, layout);
    auto pos = std::find(blocks_.begin(), blocks_.end(), r);
    if (pos == blocks_.end()) pos = blocks_.insert(blocks_.end(), r);
    block_of_.push_back(static_cast<int>(pos - blocks_.begin()));
  }
  slots_.clear();
  for (Index a : blocks_)
    for (Index b : blocks_) slots_.push_back(pattern.find(a, b));
}

void StencilDofs::add_hessian(const Eigen::MatrixXd& H, const physics::AngleLayout& layout,
                              const physics::JacobianRequest& req) const {
  const bool product = !req.product_in.empty();
  const std::size_t nb = blocks_.size();
  for (std::size_t i = 0; i < dofs_.size(); ++i)
    for (std::size_t j = 0; j < dofs_.size(); ++j) {
      const double h = H(static_cast<Eigen::Index>(i), static_cast<Eigen::Index>(j));
      const int ci = component(dofs_[i], layout), cj = component(dofs_[j], layout);
      const std::size_t bi = static_cast<std::size_t>(block_of_[i]), bj = static_cast<std::size_t>(block_of_[j]);
      if (req.matrix) req.matrix->block(slots_[bi * nb + bj])(ci, cj) -= req.cx * h;
      if (product)
        req.product_out[3 * std::size_t{blocks_[bi]} + static_cast<std::size_t>(ci)] -=
            h * req.product_in[3 * std::size_t{blocks_[bj]} + static_cast<std::size_t>(cj)];
    }
}

void StencilDofs::check_nodes(const physics::NodeTable& nodes, const std::string& owner) const {
  for (const Dof& d : dofs_)
    if (!d.angle && !nodes.is_alive(d.id))
      throw InputError(owner + " refers to node " + std::to_string(d.id) +
                       (d.id < nodes.size() ? ", which was removed" : ", out of range"));
}

bool StencilDofs::touches_removed(const physics::NodeTable& nodes) const {
  return std::any_of(dofs_.begin(), dofs_.end(), [&](const Dof& d) { return !d.angle && !nodes.is_alive(d.id); });
}

void StencilDofs::remap_nodes(std::span<const Index> old_to_new) {
  for (Dof& d : dofs_)
    if (!d.angle) d.id = old_to_new[d.id];
}

}  // namespace sewn::connect
