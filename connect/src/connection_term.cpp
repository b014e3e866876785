#include "sewn/connect/connection_term.hpp"

#include <algorithm>
#include <numeric>
#include <utility>

#include "sewn/connect/curve.hpp"
#include "sewn/physics/elements/element_math.hpp"
#include "sewn/physics/nodes.hpp"

namespace sewn::connect {

using physics::InputError;
using physics::StateView;

template <class Connection>
Index ConnectionTerm<Connection>::push(Connection c, StencilDofs dofs) {
  items_.push_back(Item{std::move(c), std::move(dofs)});
  touch_topology();
  return size() - 1;
}

template <class Connection>
std::vector<double> ConnectionTerm<Connection>::history() const {
  std::vector<double> out;
  out.reserve(items_.size() * history_size);
  for (const Item& it : items_) {
    const ConnectionHistory h = it.connection.history();
    out.insert(out.end(), h.begin(), h.end());
  }
  return out;
}

template <class Connection>
void ConnectionTerm<Connection>::restore(std::span<const double> h) {
  if (h.size() != items_.size() * history_size)
    throw InputError(std::string(name()) + ": a history of " + std::to_string(h.size()) + " values for " +
                     std::to_string(items_.size()) + " connections (" + std::to_string(history_size) + " each)");
  // every connection restored on a copy first: one that refuses its part changes nothing
  std::vector<Connection> restored;
  restored.reserve(items_.size());
  for (std::size_t c = 0; c < items_.size(); ++c) {
    ConnectionHistory one{};
    std::copy(h.begin() + static_cast<std::ptrdiff_t>(c * history_size), h.begin() + static_cast<std::ptrdiff_t>((c + 1) * history_size),
              one.begin());
    restored.push_back(items_[c].connection);
    restored.back().restore(one);
  }
  for (std::size_t c = 0; c < items_.size(); ++c) items_[c].connection = std::move(restored[c]);
}

template <class Connection>
Index ConnectionTerm<Connection>::remove_dangling(const physics::NodeTable& nodes) {
  const auto before = items_.size();
  std::erase_if(items_, [&](const Item& it) { return it.dofs.touches_removed(nodes); });
  const auto removed = static_cast<Index>(before - items_.size());
  if (removed > 0) touch_topology();
  return removed;
}

template <class Connection>
std::vector<bool> ConnectionTerm<Connection>::follow_nodes(Index num_nodes, const NodeDecision& decide) {
  // every decision first, checked, then applied: an id out of range changes nothing
  std::vector<bool> kept(items_.size(), false);
  std::vector<std::vector<std::pair<Index, Index>>> renames(items_.size());
  for (std::size_t c = 0; c < items_.size(); ++c) {
    kept[c] = decide(static_cast<Index>(c), renames[c]);
    for (const auto& r : renames[c])
      if (r.first >= num_nodes || r.second >= num_nodes)
        throw InputError(items_[c].owner() + ": renamed node " + std::to_string(r.first) + " -> " + std::to_string(r.second) +
                         " is not below the node count " + std::to_string(num_nodes));
  }
  std::vector<Index> map(num_nodes);
  std::iota(map.begin(), map.end(), Index{0});
  std::vector<Item> out;
  for (std::size_t c = 0; c < items_.size(); ++c) {
    if (!kept[c]) continue;
    for (const auto& r : renames[c]) map[r.first] = r.second;
    items_[c].dofs.remap_nodes(map);
    items_[c].connection.remap_nodes(map);
    for (const auto& r : renames[c]) map[r.first] = r.first;
    out.push_back(std::move(items_[c]));
  }
  items_ = std::move(out);
  touch_topology();
  return kept;
}

template <class Connection>
void ConnectionTerm<Connection>::set_max_trial_turn(double radians) {
  if (!(radians > 0.0))
    throw InputError(std::string(name()) + ": max_trial_turn must be > 0 rad (infinity: no limit), got " + std::to_string(radians));
  max_trial_turn_ = radians;
}

template <class Connection>
void ConnectionTerm<Connection>::add_forces(const StateView& s, std::span<double> f) const {
  for (const Item& it : items_)
    it.dofs.subtract_gradient(it.connection.evaluate(it.dofs.gather(s, it.owner()), update_, true).gradient, s, f);
}

template <class Connection>
void ConnectionTerm<Connection>::collect_pairs(std::vector<physics::NodePair>& out) const {
  for (const Item& it : items_) it.dofs.collect_pairs(angle_layout(), out);
}

template <class Connection>
void ConnectionTerm<Connection>::bind_pattern(const physics::BlockMatrix& pattern) {
  for (Item& it : items_) it.dofs.bind(angle_layout(), pattern);
  bound_pattern_ = pattern.pattern_version();
}

template <class Connection>
void ConnectionTerm<Connection>::add_jacobians(const StateView& s, const physics::JacobianRequest& req) const {
  if (req.matrix && req.matrix->pattern_version() != bound_pattern_)
    throw InputError(std::string(name()) + ": add_jacobians: the matrix does not carry the pattern this term was bound to");
  for (const Item& it : items_) {
    Eigen::MatrixXd H;
    (void)it.connection.evaluate(it.dofs.gather(s, it.owner()), update_, true, &H);
    if (req.options.project_element_hessians) physics::elements::project_psd(H);
    it.dofs.add_hessian(H, angle_layout(), req);
  }
}

template <class Connection>
void ConnectionTerm<Connection>::step_accepted(const StateView& s) {
  for (Item& it : items_) it.connection.accept(it.dofs.gather(s, it.owner()), update_);
}

template <class Connection>
void ConnectionTerm<Connection>::check_nodes(const physics::NodeTable& nodes) const {
  for (const Item& it : items_) it.dofs.check_nodes(nodes, it.owner());
}

template <class Connection>
void ConnectionTerm<Connection>::remap_nodes(std::span<const Index> old_to_new) {
  // Both the DOF table and the connection's own node ids (its sides, joint and layout), so that
  // errors name the current nodes.
  for (Item& it : items_) {
    it.dofs.remap_nodes(old_to_new);
    it.connection.remap_nodes(old_to_new);
  }
  touch_topology();
}

template class ConnectionTerm<PointConnection>;
template class ConnectionTerm<EdgeConnection>;

}  // namespace sewn::connect
