#include "sewn/physics/elements/stencil_term.hpp"

#include "sewn/physics/errors.hpp"
#include "sewn/physics/nodes.hpp"

namespace sewn::physics::elements {

template <int N>
typename StencilTerm<N>::Positions StencilTerm<N>::gather(const StateView& s, Index e) const {
  Positions x;
  for (int a = 0; a < N; ++a)
    for (int c = 0; c < 3; ++c) x(c, a) = s.x[3 * std::size_t{nodes_[e][a]} + c];
  return x;
}

template <int N>
std::string StencilTerm<N>::element_name(Index e) const {
  return std::string(name()) + " element " + std::to_string(e);
}

template <int N>
void StencilTerm<N>::check_distinct(Index e, const Nodes& nodes) const {
  for (int a = 0; a < N; ++a)
    for (int b = a + 1; b < N; ++b)
      if (nodes[a] == nodes[b]) throw InputError(element_name(e) + ": node " + std::to_string(nodes[a]) + " appears twice");
}

template <int N>
Index StencilTerm<N>::push_element(const Nodes& nodes) {
  check_distinct(size(), nodes);
  nodes_.push_back(nodes);
  alive_.push_back(1);
  touch_topology();
  return size() - 1;
}

template <int N>
void StencilTerm<N>::set_element_nodes(Index e, const Nodes& nodes) {
  if (e >= size()) throw InputError(element_name(e) + ": no such element (" + std::to_string(size()) + " elements)");
  check_distinct(e, nodes);
  if (nodes_[e] == nodes) return;
  nodes_[e] = nodes;
  touch_topology();
}

template <int N>
void StencilTerm<N>::retire_element(Index e) {
  if (e >= size()) throw InputError(element_name(e) + ": no such element (" + std::to_string(size()) + " elements)");
  if (alive_[e] == 0) return;
  alive_[e] = 0;
  touch_topology();
}

template <int N>
void StencilTerm<N>::add_forces(const StateView& s, std::span<double> f) const {
  for (Index e = 0; e < size(); ++e) {
    if (alive_[e] == 0) continue;
    const Gradient g = element_gradient(e, gather(s, e));
    for (int a = 0; a < N; ++a)
      for (int c = 0; c < 3; ++c) f[3 * std::size_t{nodes_[e][a]} + c] -= g[3 * a + c];
  }
}

template <int N>
double StencilTerm<N>::potential_energy(const StateView& s) const {
  double sum = 0.0;
  for (Index e = 0; e < size(); ++e)
    if (alive_[e] != 0) sum += element_energy(e, gather(s, e));
  return sum;
}

template <int N>
double StencilTerm<N>::add_forces_and_energy(const StateView& s, std::span<double> f) const {
  double sum = 0.0;
  Gradient g;
  for (Index e = 0; e < size(); ++e) {
    if (alive_[e] == 0) continue;
    sum += element_energy_gradient(e, gather(s, e), g);
    for (int a = 0; a < N; ++a)
      for (int c = 0; c < 3; ++c) f[3 * std::size_t{nodes_[e][a]} + c] -= g[3 * a + c];
  }
  return sum;
}

template <int N>
void StencilTerm<N>::collect_pairs(std::vector<NodePair>& out) const {
  for (Index e = 0; e < size(); ++e)
    for (int a = 0; a < N && alive_[e] != 0; ++a)
      for (int b = a + 1; b < N; ++b) out.push_back({nodes_[e][a], nodes_[e][b]});
}

template <int N>
void StencilTerm<N>::bind_pattern(const BlockMatrix& pattern) {
  slots_.assign(std::size_t{N} * N * nodes_.size(), invalid_index);
  for (Index e = 0; e < size(); ++e)
    for (int a = 0; a < N && alive_[e] != 0; ++a)
      for (int b = 0; b < N; ++b) slots_[(std::size_t{e} * N + a) * N + b] = pattern.find(nodes_[e][a], nodes_[e][b]);
  bound_pattern_ = pattern.pattern_version();
  bound_topology_ = topology_version();
}

template <int N>
void StencilTerm<N>::for_each_hessian(const StateView& s, const std::function<void(Index, const Hessian&)>& visit) const {
  for (Index e = 0; e < size(); ++e)
    if (alive_[e] != 0) visit(e, element_hessian(e, gather(s, e)));
}

template <int N>
void StencilTerm<N>::add_jacobians(const StateView& s, const JacobianRequest& req) const {
  if (req.matrix != nullptr && (req.matrix->pattern_version() != bound_pattern_ || bound_topology_ != topology_version()))
    throw InputError(std::string(name()) +
                     ": add_jacobians on a pattern that is not bound to the current elements; call System::refresh()");
  const bool product = !req.product_in.empty();
  if (req.cx == 0.0 && !product) return;
  auto add = [&](Index e, const Hessian& H) {
    const Nodes& n = nodes_[e];
    if (req.matrix != nullptr && req.cx != 0.0)
      for (int a = 0; a < N; ++a)
        for (int b = 0; b < N; ++b)
          req.matrix->block(slots_[(std::size_t{e} * N + a) * N + b]) -= req.cx * H.template block<3, 3>(3 * a, 3 * b);
    if (product) {
      Gradient p;
      for (int a = 0; a < N; ++a)
        for (int c = 0; c < 3; ++c) p[3 * a + c] = req.product_in[3 * std::size_t{n[a]} + c];
      const Gradient q = H * p;
      for (int a = 0; a < N; ++a)
        for (int c = 0; c < 3; ++c) req.product_out[3 * std::size_t{n[a]} + c] -= q[3 * a + c];
    }
  };
  if (!req.options.project_element_hessians) {
    for_each_hessian(s, add);
    return;
  }
  for (Index e = 0; e < size(); ++e)
    if (alive_[e] != 0) add(e, element_hessian_psd(e, gather(s, e)));
}

template <int N>
void StencilTerm<N>::add_stability_rows(const StateView& s, StabilityRows& rows) const {
  for (Index e = 0; e < size(); ++e) {
    if (alive_[e] == 0) continue;
    // The eigen-projection of the exact Hessian, not element_hessian_psd: the closed forms may
    // drop stiffness (Gauss-Newton bending), and a stable-step bound must not shrink with them.
    Hessian H = element_hessian(e, gather(s, e));
    project_psd(H);
    const Nodes& n = nodes_[e];
    for (int a = 0; a < N; ++a) {
      rows.add_diagonal(StabilityRows::stiffness, n[a], H.template block<3, 3>(3 * a, 3 * a));
      for (int b = a + 1; b < N; ++b)
        rows.add_offdiagonal(StabilityRows::stiffness, n[a], n[b], H.template block<3, 3>(3 * a, 3 * b));
    }
  }
}

template <int N>
void StencilTerm<N>::check_nodes(const NodeTable& nodes) const {
  for (Index e = 0; e < size(); ++e)
    for (Index i : nodes_[e]) {
      if (alive_[e] == 0) break;
      if (i >= nodes.size())
        throw InputError(element_name(e) + " refers to node " + std::to_string(i) + " but there are " +
                         std::to_string(nodes.size()) + " nodes");
      if (!nodes.is_alive(i)) throw InputError(element_name(e) + " refers to removed node " + std::to_string(i));
    }
}

template <int N>
void StencilTerm<N>::remap_nodes(std::span<const Index> old_to_new) {
  // a retired element's nodes may be gone: it keeps no node at all
  for (Index e = 0; e < size(); ++e)
    for (Index& i : nodes_[e]) i = alive_[e] != 0 ? old_to_new[i] : invalid_index;
  touch_topology();
}

template class StencilTerm<3>;
template class StencilTerm<4>;
template class StencilTerm<5>;
template class StencilTerm<6>;

}  // namespace sewn::physics::elements
