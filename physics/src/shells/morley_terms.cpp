#include "sewn/physics/shells/morley_terms.hpp"

#include <algorithm>
#include <string>

#include "sewn/physics/errors.hpp"
#include "sewn/physics/nodes.hpp"
#include "sewn/physics/shells/adjacency.hpp"

namespace sewn::physics::shells {

Index MorleyBending::add(const Element& e) {
  const std::string name = "Morley bending element " + std::to_string(size());
  for (int i = 0; i < 3; ++i) {
    const auto ii = static_cast<std::size_t>(i);
    const bool hinge = e.rest.kind[ii] != MorleyEdge::own, angle = e.rest.kind[ii] != MorleyEdge::clamp;
    if (hinge == (e.nodes[3 + ii] == invalid_index) || angle == (e.angle[ii] == invalid_index))
      throw InputError(name + ": edge " + std::to_string(i) + "'s node or angle does not fit its kind");
  }
  for (std::size_t a = 0; a < 6; ++a)
    for (std::size_t b = 0; b < a; ++b)
      if (e.nodes[a] != invalid_index && e.nodes[a] == e.nodes[b])
        throw InputError(name + ": node " + std::to_string(e.nodes[a]) + " appears twice");
  elements_.push_back(e);
  touch_topology();
  return size() - 1;
}

void MorleyBending::gather(const StateView& s, const Element& e, MorleyPositions& x, Eigen::Vector3d& psi) const {
  x.setZero();
  psi.setZero();
  for (std::size_t c = 0; c < 6; ++c)
    if (e.nodes[c] != invalid_index)
      for (std::size_t a = 0; a < 3; ++a) x(static_cast<Eigen::Index>(a), static_cast<Eigen::Index>(c)) = s.x[3 * e.nodes[c] + a];
  for (std::size_t i = 0; i < 3; ++i) {
    if (e.angle[i] == invalid_index) continue;
    if (e.angle[i] >= s.angles.size())
      throw InputError("Morley bending: the edge angles are DOFs but the state has " + std::to_string(s.angles.size()) +
                       " angles (only the Newton integrator integrates them)");
    psi[static_cast<Eigen::Index>(i)] = s.angles[e.angle[i]];
  }
}

void MorleyBending::add_forces(const StateView& s, std::span<double> f) const {
  MorleyPositions x;
  Eigen::Vector3d psi;
  const std::size_t torques = 3 * std::size_t{s.size()};
  for (const Element& e : elements_) {
    gather(s, e, x, psi);
    const MorleyVec g = morley_gradient(x, psi, e.rest);
    for (std::size_t c = 0; c < 6; ++c)
      if (e.nodes[c] != invalid_index)
        for (std::size_t a = 0; a < 3; ++a) f[3 * e.nodes[c] + a] -= g[static_cast<Eigen::Index>(3 * c + a)];
    for (std::size_t i = 0; i < 3; ++i)
      if (e.angle[i] != invalid_index && f.size() > torques + e.angle[i])
        f[torques + e.angle[i]] -= g[static_cast<Eigen::Index>(18 + i)];
  }
}

double MorleyBending::potential_energy(const StateView& s) const {
  MorleyPositions x;
  Eigen::Vector3d psi;
  double E = 0.0;
  for (const Element& e : elements_) {
    gather(s, e, x, psi);
    E += morley_energy(x, psi, e.rest);
  }
  return E;
}

void MorleyBending::blocks(const Element& e, std::array<Index, 9>& block, std::array<int, 21>& comp) const {
  for (std::size_t c = 0; c < 6; ++c) {
    block[c] = e.nodes[c];
    for (std::size_t a = 0; a < 3; ++a) comp[3 * c + a] = static_cast<int>(a);
  }
  for (std::size_t i = 0; i < 3; ++i) {
    block[6 + i] = e.angle[i] == invalid_index ? invalid_index : angle_layout().block(e.angle[i]);
    comp[18 + i] = e.angle[i] == invalid_index ? 0 : angle_layout().component(e.angle[i]);
  }
}

void MorleyBending::collect_pairs(std::vector<NodePair>& out) const {
  std::array<Index, 9> block{};
  std::array<int, 21> comp{};
  for (const Element& e : elements_) {
    blocks(e, block, comp);
    for (std::size_t a = 0; a < 9; ++a)
      for (std::size_t b = a + 1; b < 9; ++b)
        if (block[a] != invalid_index && block[b] != invalid_index && block[a] != block[b]) out.push_back({block[a], block[b]});
  }
}

void MorleyBending::bind_pattern(const BlockMatrix& pattern) {
  slots_.clear();
  std::array<Index, 9> block{};
  std::array<int, 21> comp{};
  for (const Element& e : elements_) {
    blocks(e, block, comp);
    for (Index a : block)
      for (Index b : block) slots_.push_back(a == invalid_index || b == invalid_index ? invalid_index : pattern.find(a, b));
  }
  bound_pattern_ = pattern.pattern_version();
}

void MorleyBending::add_jacobians(const StateView& s, const JacobianRequest& req) const {
  if (req.matrix && req.matrix->pattern_version() != bound_pattern_)
    throw InputError("Morley bending: the matrix does not carry the pattern this term was bound to");
  const bool product = !req.product_in.empty();
  MorleyPositions x;
  Eigen::Vector3d psi;
  std::array<Index, 9> block{};
  std::array<int, 21> comp{};
  for (std::size_t el = 0; el < elements_.size(); ++el) {
    const Element& e = elements_[el];
    gather(s, e, x, psi);
    blocks(e, block, comp);
    Eigen::MatrixXd H = morley_hessian(x, psi, e.rest);
    if (req.options.project_element_hessians) (void)elements::project_psd(H);
    for (std::size_t i = 0; i < 21; ++i) {
      const std::size_t gi = i < 18 ? i / 3 : 6 + (i - 18);
      if (block[gi] == invalid_index) continue;
      for (std::size_t j = 0; j < 21; ++j) {
        const std::size_t gj = j < 18 ? j / 3 : 6 + (j - 18);
        if (block[gj] == invalid_index) continue;
        const double h = H(static_cast<Eigen::Index>(i), static_cast<Eigen::Index>(j));
        if (req.matrix) req.matrix->block(slots_[81 * el + 9 * gi + gj])(comp[i], comp[j]) -= req.cx * h;
        if (product)
          req.product_out[3 * std::size_t{block[gi]} + static_cast<std::size_t>(comp[i])] -=
              h * req.product_in[3 * std::size_t{block[gj]} + static_cast<std::size_t>(comp[j])];
      }
    }
  }
}

void MorleyBending::check_nodes(const NodeTable& nodes) const {
  for (std::size_t el = 0; el < elements_.size(); ++el)
    for (Index i : elements_[el].nodes) {
      if (i == invalid_index) continue;
      if (i >= nodes.size() || !nodes.is_alive(i))
        throw InputError("Morley bending element " + std::to_string(el) + " refers to " +
                         (i >= nodes.size() ? "node " + std::to_string(i) + " but there are " + std::to_string(nodes.size()) + " nodes"
                                            : "removed node " + std::to_string(i)));
    }
}

void MorleyBending::remap_nodes(std::span<const Index> old_to_new) {
  for (Element& e : elements_)
    for (Index& i : e.nodes)
      if (i != invalid_index) i = old_to_new[i];
  touch_topology();
}

MorleyTerms add_morley_bending(System& sys, std::span<const std::array<Index, 3>> triangles, std::span<const double> rest_x,
                               std::span<const PlateMaterial> material_of_triangle,
                               std::span<const std::uint8_t> clamp_of_triangle) {
  if (material_of_triangle.size() != triangles.size() || (!clamp_of_triangle.empty() && clamp_of_triangle.size() != triangles.size()))
    throw InputError("Morley bending: " + std::to_string(material_of_triangle.size()) + " materials and " +
                     std::to_string(clamp_of_triangle.size()) + " clamp flags for " + std::to_string(triangles.size()) +
                     " triangles");
  auto is_clamp = [&](Index t) { return !clamp_of_triangle.empty() && clamp_of_triangle[t] != 0; };
  const auto across = triangles_across(triangles, rest_x.size() / 3);
  // angles numbered from 0 here, shifted to the System's table once every element is accepted
  std::vector<std::array<Index, 3>> angle_of(triangles.size(), {invalid_index, invalid_index, invalid_index});
  Index angles = 0;
  for (Index t = 0; t < triangles.size(); ++t) {
    if (is_clamp(t)) continue;
    for (int i = 0; i < 3; ++i) {
      const Across& o = across[t][static_cast<std::size_t>(i)];
      if (o.tri != invalid_index && is_clamp(o.tri)) continue;
      if (o.tri == invalid_index || o.tri > t) {
        angle_of[t][static_cast<std::size_t>(i)] = angles++;
        if (o.tri != invalid_index) angle_of[o.tri][static_cast<std::size_t>(o.corner)] = angle_of[t][static_cast<std::size_t>(i)];
      }
    }
  }
  MorleyBending term;
  MorleyTerms out;
  // per angle, the largest height of its triangles over the edge: a mid-normal turned by ψ
  // moves its triangles by up to about ψ times that height (Newton's step test, AngleTable)
  std::vector<double> lever(angles, 0.0);
  const Index first = sys.angles().size();
  for (Index t = 0; t < triangles.size(); ++t) {
    if (is_clamp(t)) continue;
    MorleyBending::Element e;
    e.nodes.fill(invalid_index);
    std::array<MorleyEdge, 3> kind{};
    MorleyPositions X = MorleyPositions::Zero();
    for (std::size_t c = 0; c < 3; ++c) e.nodes[c] = triangles[t][c];
    for (std::size_t i = 0; i < 3; ++i) {
      const Across& o = across[t][i];
      kind[i] = o.tri == invalid_index ? MorleyEdge::own
                : is_clamp(o.tri)      ? MorleyEdge::clamp
                : o.tri > t            ? MorleyEdge::own
                                       : MorleyEdge::other;
      if (kind[i] != MorleyEdge::own) e.nodes[3 + i] = triangles[o.tri][static_cast<std::size_t>(o.corner)];
      e.angle[i] = angle_of[t][i] == invalid_index ? invalid_index : first + angle_of[t][i];
    }
    for (std::size_t c = 0; c < 6; ++c)
      if (e.nodes[c] != invalid_index)
        for (std::size_t a = 0; a < 3; ++a) X(static_cast<Eigen::Index>(a), static_cast<Eigen::Index>(c)) = rest_x[3 * e.nodes[c] + a];
    for (std::size_t i = 0; i < 3; ++i) {
      if (angle_of[t][i] == invalid_index) continue;
      const Eigen::Vector3d a = X.col(static_cast<Eigen::Index>((i + 1) % 3)), b = X.col(static_cast<Eigen::Index>((i + 2) % 3));
      const Eigen::Vector3d c = X.col(static_cast<Eigen::Index>(i));
      const double len = (b - a).norm();  // degenerate triangles are refused below
      if (len > 0.0) lever[angle_of[t][i]] = std::max(lever[angle_of[t][i]], (b - a).cross(c - a).norm() / len);
    }
    try {
      e.rest = morley_rest(X, kind, material_of_triangle[t]);
      (void)term.add(e);
    } catch (const InputError& err) {
      throw InputError("Morley bending: triangle " + std::to_string(t) + ": " + err.what());
    }
    out.triangle_of.push_back(t);
  }
  if (term.size() == 0) return out;
  const std::vector<double> zero(angles, 0.0);
  const std::vector<unsigned char> free(angles, 0);
  out.first_angle = sys.angles().add("Morley bending", zero, zero, free);
  for (Index a = 0; a < angles; ++a)
    if (lever[a] > 0.0) sys.angles().set_length(out.first_angle + a, lever[a]);
  out.angles = angles;
  out.term = &sys.add<MorleyBending>(std::move(term));
  return out;
}

}  // namespace sewn::physics::shells
