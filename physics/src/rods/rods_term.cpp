#include "sewn/physics/rods/rods_term.hpp"

#include <algorithm>
#include <string>

#include <Eigen/Eigenvalues>

#include "sewn/physics/errors.hpp"
#include "sewn/physics/nodes.hpp"

namespace sewn::physics::rods {

namespace {

template <int N>
Eigen::Matrix<double, N, N> project_psd(const Eigen::Matrix<double, N, N>& H) {
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, N, N>> es(H);
  const Eigen::Matrix<double, N, 1> lambda = es.eigenvalues().cwiseMax(0.0);
  return es.eigenvectors() * lambda.asDiagonal() * es.eigenvectors().transpose();
}

}  // namespace

Index Rods::add_rod(std::span<const Index> nodes, std::span<const double> x, bool closed, const Section& section,
                    std::span<const Vec3> rest_directors) {
  const Index rid = num_rods();
  std::vector<Index> sorted(nodes.begin(), nodes.end());
  std::sort(sorted.begin(), sorted.end());
  if (std::adjacent_find(sorted.begin(), sorted.end()) != sorted.end())
    throw InputError("rods::Rods::add_rod: rod " + std::to_string(rid) + " visits node " +
                     std::to_string(*std::adjacent_find(sorted.begin(), sorted.end())) + " twice");
  Points rest(3, static_cast<Eigen::Index>(nodes.size()));
  for (std::size_t k = 0; k < nodes.size(); ++k) {
    if (3 * std::size_t{nodes[k]} + 2 >= x.size())
      throw InputError("rods::Rods::add_rod: rod " + std::to_string(rid) + " refers to node " + std::to_string(nodes[k]) +
                       ", out of range");
    rest.col(static_cast<Eigen::Index>(k)) = Vec3(x[3 * nodes[k]], x[3 * nodes[k] + 1], x[3 * nodes[k] + 2]);
  }
  rods_.push_back(Entry{Rod(rest, closed, section, rest_directors), std::vector<Index>(nodes.begin(), nodes.end()), Points(3, 0), {}});
  touch_topology();
  return rid;
}

Rod& Rods::rod(Index r) {
  if (r >= num_rods()) throw InputError("rods::Rods::rod: rod " + std::to_string(r) + " of " + std::to_string(num_rods()));
  rods_[r].solved_at.resize(3, 0);  // θ or clamps may change: solve again
  return rods_[r].rod;
}

const Rod& Rods::rod(Index r) const {
  if (r >= num_rods()) throw InputError("rods::Rods::rod: rod " + std::to_string(r) + " of " + std::to_string(num_rods()));
  return rods_[r].rod;
}

std::span<const Index> Rods::rod_nodes(Index r) const {
  if (r >= num_rods()) throw InputError("rods::Rods::rod_nodes: rod " + std::to_string(r) + " of " + std::to_string(num_rods()));
  return rods_[r].nodes;
}

Points Rods::gather(Index r, std::span<const double> x) const {
  const std::vector<Index>& nd = rods_[r].nodes;
  Points p(3, static_cast<Eigen::Index>(nd.size()));
  for (std::size_t k = 0; k < nd.size(); ++k)
    p.col(static_cast<Eigen::Index>(k)) = Vec3(x[3 * nd[k]], x[3 * nd[k] + 1], x[3 * nd[k] + 2]);
  return p;
}

void Rods::ensure_twist(Index r, const Points& x) const {
  if (!quasi_static_) return;
  Entry& e = rods_[r];  // θ is the term's own (mutable) state
  if (e.solved_at.cols() == x.cols() && e.solved_at == x) return;
  (void)e.rod.solve_twist(x);
  e.solved_at = x;
}

void Rods::add_forces(const StateView& s, std::span<double> f) const {
  Eigen::VectorXd g;
  for (Index r = 0; r < num_rods(); ++r) {
    const Entry& e = rods_[r];
    const Points x = gather(r, s.x);
    ensure_twist(r, x);
    (void)e.rod.evaluate(x, g, nullptr);
    for (std::size_t k = 0; k < e.nodes.size(); ++k)
      for (int a = 0; a < 3; ++a) f[3 * e.nodes[k] + static_cast<std::size_t>(a)] -= g[3 * static_cast<Eigen::Index>(k) + a];
  }
}

double Rods::potential_energy(const StateView& s) const {
  double E = 0;
  for (Index r = 0; r < num_rods(); ++r) {
    const Points x = gather(r, s.x);
    ensure_twist(r, x);
    E += rods_[r].rod.energy(x);
  }
  return E;
}

double Rods::energy_scale() const {
  double E = 0;
  for (const Entry& e : rods_)
    for (int j = 0; j < e.rod.num_edges(); ++j) E += 0.5 * e.rod.section().EA * e.rod.rest_length(j);
  return E;
}

void Rods::collect_pairs(std::vector<NodePair>& out) const {
  for (const Entry& e : rods_) {
    const int n = e.rod.num_vertices();
    for (int j = 0; j < e.rod.num_edges(); ++j) out.push_back({e.nodes[static_cast<std::size_t>(j)], e.nodes[static_cast<std::size_t>((j + 1) % n)]});
    for (int s = 0; s < e.rod.num_stencils(); ++s) {
      const auto v = e.rod.stencil_vertices(s);
      out.push_back({e.nodes[static_cast<std::size_t>(v[0])], e.nodes[static_cast<std::size_t>(v[2])]});
    }
  }
}

void Rods::bind_pattern(const BlockMatrix& pattern) {
  for (Entry& e : rods_) {
    e.slots.clear();
    auto node = [&](int v) { return e.nodes[static_cast<std::size_t>(v)]; };
    for (int s = 0; s < e.rod.num_stencils(); ++s) {
      const auto v = e.rod.stencil_vertices(s);
      for (int a = 0; a < 3; ++a)
        for (int b = 0; b < 3; ++b) e.slots.push_back(pattern.find(node(v[static_cast<std::size_t>(a)]), node(v[static_cast<std::size_t>(b)])));
    }
    const int n = e.rod.num_vertices();
    for (int j = 0; j < e.rod.num_edges(); ++j) {
      const int v[2] = {j, (j + 1) % n};
      for (int a = 0; a < 2; ++a)
        for (int b = 0; b < 2; ++b) e.slots.push_back(pattern.find(node(v[a]), node(v[b])));
    }
  }
  bound_pattern_ = pattern.pattern_version();
}

template <class Visit>
void Rods::for_each_block(const Entry& e, const Points& x, bool project, Visit&& visit) const {
  std::size_t slot = 0;
  for (int s = 0; s < e.rod.num_stencils(); ++s) {
    const auto v = e.rod.stencil_vertices(s);
    const auto ed = e.rod.stencil_edges(s);
    const BendTwistEval b = bend_twist(x.col(v[0]), x.col(v[1]), x.col(v[2]), e.rod.theta()[static_cast<std::size_t>(ed[0])],
                                       e.rod.theta()[static_cast<std::size_t>(ed[1])], e.rod.stencil_rest(s),
                                       e.rod.stencil_frames(s), Want::hessian);
    Eigen::Matrix<double, 9, 9> H = b.hessian.topLeftCorner<9, 9>();
    if (project) H = project_psd<9>(H);
    for (int a = 0; a < 3; ++a)
      for (int c = 0; c < 3; ++c, ++slot) visit(v[static_cast<std::size_t>(a)], v[static_cast<std::size_t>(c)], Eigen::Matrix3d(H.block<3, 3>(3 * a, 3 * c)), slot);
  }
  const int n = e.rod.num_vertices();
  for (int j = 0; j < e.rod.num_edges(); ++j) {
    const int v[2] = {j, (j + 1) % n};
    const StretchEval st = stretch(x.col(v[0]), x.col(v[1]), e.rod.section().EA, e.rod.rest_length(j), true);
    Eigen::Matrix<double, 6, 6> H = st.hessian;
    if (project) H = project_psd<6>(H);
    for (int a = 0; a < 2; ++a)
      for (int c = 0; c < 2; ++c, ++slot) visit(v[a], v[c], Eigen::Matrix3d(H.block<3, 3>(3 * a, 3 * c)), slot);
  }
}

void Rods::add_jacobians(const StateView& s, const JacobianRequest& req) const {
  if (req.matrix && req.matrix->pattern_version() != bound_pattern_)
    throw InputError("rods::Rods::add_jacobians: the matrix does not carry the pattern this term was bound to");
  const bool product = !req.product_in.empty();
  for (Index r = 0; r < num_rods(); ++r) {
    const Entry& e = rods_[r];
    const Points x = gather(r, s.x);
    ensure_twist(r, x);
    // ∂F/∂x = −H.
    for_each_block(e, x, project_, [&](int a, int b, const Eigen::Matrix3d& B, std::size_t slot) {
      const Index na = e.nodes[static_cast<std::size_t>(a)], nb = e.nodes[static_cast<std::size_t>(b)];
      if (req.matrix) req.matrix->block(e.slots[slot]) -= req.cx * B;
      if (product) {
        const Vec3 p(req.product_in[3 * nb], req.product_in[3 * nb + 1], req.product_in[3 * nb + 2]);
        const Vec3 y = -(B * p);
        for (int k = 0; k < 3; ++k) req.product_out[3 * na + static_cast<std::size_t>(k)] += y[k];
      }
    });
  }
}

void Rods::add_stability_rows(const StateView& s, StabilityRows& rows) const {
  for (Index r = 0; r < num_rods(); ++r) {
    const Entry& e = rods_[r];
    const Points x = gather(r, s.x);
    ensure_twist(r, x);
    for_each_block(e, x, true, [&](int a, int b, const Eigen::Matrix3d& B, std::size_t) {  // the bound needs PSD blocks
      const Index na = e.nodes[static_cast<std::size_t>(a)], nb = e.nodes[static_cast<std::size_t>(b)];
      if (na == nb)
        rows.add_diagonal(StabilityRows::stiffness, na, B);
      else if (a < b)
        rows.add_offdiagonal(StabilityRows::stiffness, na, nb, B);
    });
  }
}

void Rods::step_accepted(const StateView& s) {
  for (Index r = 0; r < num_rods(); ++r) {
    const Points x = gather(r, s.x);
    ensure_twist(r, x);
    rods_[r].rod.update_frames(x);
  }
}

void Rods::check_nodes(const NodeTable& nodes) const {
  for (Index r = 0; r < num_rods(); ++r)
    for (Index v : rods_[r].nodes)
      if (!nodes.is_alive(v))
        throw InputError("rods::Rods: rod " + std::to_string(r) + " refers to node " + std::to_string(v) +
                         (v < nodes.size() ? ", which was removed" : ", out of range (" + std::to_string(nodes.size()) + " nodes)"));
}

void Rods::remap_nodes(std::span<const Index> old_to_new) {
  for (Entry& e : rods_)
    for (Index& v : e.nodes) v = old_to_new[v];
  touch_topology();
}

}  // namespace sewn::physics::rods
