#include "sewn/physics/rods/rods_term.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include "sewn/physics/elements/element_math.hpp"
#include "sewn/physics/errors.hpp"
#include "sewn/physics/nodes.hpp"

namespace sewn::physics::rods {

namespace {

template <int N>
Eigen::Matrix<double, N, N> projected(Eigen::Matrix<double, N, N> H) {
  elements::project_psd(H);
  return H;
}

}  // namespace

Index Rods::add_rod(std::span<const Index> nodes, std::span<const double> x, bool closed, const Section& section,
                    std::span<const Vec3> rest_directors) {
  const Index rid = num_rods();
  if (angle_blocks_)
    throw InputError("rods::Rods::add_rod: rod " + std::to_string(rid) + " added after use_angle_dofs or condense_twist (add every rod first)");
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
  rods_.push_back(Entry{Rod(rest, closed, section, rest_directors), std::vector<Index>(nodes.begin(), nodes.end()), Points(3, 0), {}, invalid_index, {}, {}});
  touch_topology();
  return rid;
}

Rod& Rods::rod(Index r) {
  if (r >= num_rods()) throw InputError("rods::Rods::rod: rod " + std::to_string(r) + " of " + std::to_string(num_rods()));
  rods_[r].solved_at.resize(3, 0);  // θ or clamps may change: solve again, from the θ set here
  rods_[r].start.clear();
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

void Rods::add_angles(AngleTable& angles, double inertia_per_length) {
  for (Index r = 0; r < num_rods(); ++r) {
    Entry& e = rods_[r];
    const int m = e.rod.num_edges();
    std::vector<double> value(static_cast<std::size_t>(m)), inertia(value.size());
    // θ turns the section about the centreline: its points move by their distance from it,
    // whose root mean square is the radius of gyration √((I1 + I2)/A) (r/√2 for a circle).
    const Section& sec = e.rod.section();
    const std::vector<double> length(value.size(), std::sqrt((sec.EI1 + sec.EI2) / sec.EA));
    std::vector<unsigned char> fixed(value.size());
    for (int j = 0; j < m; ++j) {
      const auto k = static_cast<std::size_t>(j);
      value[k] = e.rod.theta()[k];
      inertia[k] = inertia_per_length * e.rod.rest_length(j);
      fixed[k] = e.rod.theta_fixed(j) ? 1 : 0;
    }
    e.first_angle = angles.add("rod " + std::to_string(r), value, inertia, fixed, length);
  }
  angle_blocks_ = true;
  touch_topology();
}

void Rods::use_angle_dofs(AngleTable& angles, double inertia_per_length) {
  if (angle_blocks_) throw InputError("rods::Rods::use_angle_dofs: called twice (or after condense_twist)");
  if (!(std::isfinite(inertia_per_length) && inertia_per_length >= 0))
    throw InputError("rods::Rods::use_angle_dofs: the twist inertia per length must be finite and >= 0, got " +
                     std::to_string(inertia_per_length));
  add_angles(angles, inertia_per_length);
  angle_dofs_ = true;
  quasi_static_ = false;
}

void Rods::condense_twist(AngleTable& angles, std::span<const RodEdge> held) {
  if (!quasi_static_ && !angle_dofs_) throw InputError("rods::Rods::condense_twist: θ is not quasi-static (set_quasi_static(false))");
  if (angle_blocks_ && quasi_static_) throw InputError("rods::Rods::condense_twist: called twice");
  if (!held.empty() && !angle_dofs_)
    throw InputError("rods::Rods::condense_twist: angles are held as DOFs only after use_angle_dofs");
  for (Entry& e : rods_) e.held.assign(static_cast<std::size_t>(e.rod.num_edges()), 0);
  for (const RodEdge& h : held) {
    if (h.rod >= num_rods() || h.edge < 0 || h.edge >= rods_[h.rod].rod.num_edges())
      throw InputError("rods::Rods::condense_twist: held rod " + std::to_string(h.rod) + " edge " + std::to_string(h.edge) + " out of range");
    rods_[h.rod].held[static_cast<std::size_t>(h.edge)] = 1;
  }
  if (!angle_blocks_) add_angles(angles, 0.0);
  for (Index r = 0; r < num_rods(); ++r) {
    Entry& e = rods_[r];
    const int m = e.rod.num_edges();
    bool holds = false;
    for (int j = 0; j < m; ++j) {
      const auto k = static_cast<std::size_t>(j);
      holds = holds || e.rod.theta_fixed(j) || e.held[k];
      if (!e.held[k]) angles.set_condensed(e.first_angle + static_cast<Index>(j), true);
    }
    // A rod whose energy is unchanged when all its angles turn together has a θ block singular
    // along (1, ..., 1), and H_xθ·1 = 0: holding one angle in the linear system leaves the
    // Schur complement as it is and makes the matrix definite (its twist solve keeps the mean).
    if (!holds && e.rod.turns_freely()) angles.set_fixed(e.first_angle, true);
    e.solved_at.resize(3, 0);
  }
  quasi_static_ = true;
}

Index Rods::angle_of(Index r, int edge) const {
  if (!angle_blocks_) throw InputError("rods::Rods::angle_of: the rods have no angles in the system (use_angle_dofs, condense_twist)");
  if (r >= num_rods() || edge < 0 || edge >= rods_[r].rod.num_edges())
    throw InputError("rods::Rods::angle_of: rod " + std::to_string(r) + " edge " + std::to_string(edge) + " out of range");
  return rods_[r].first_angle + static_cast<Index>(edge);
}

void Rods::read_angles(Index r, const StateView& s) const {
  if (!angle_dofs_) return;
  Entry& e = rods_[r];  // θ mirrors the state's angles (with a condensed twist: the held ones)
  const int m = e.rod.num_edges();
  if (s.angles.size() < std::size_t{e.first_angle} + static_cast<std::size_t>(m))
    throw InputError("rods::Rods: rod " + std::to_string(r) + "'s twist angles are DOFs but the state has " +
                     std::to_string(s.angles.size()) + " angles (only the Newton integrator integrates them)");
  for (int j = 0; j < m; ++j) {
    const double value = s.angles[e.first_angle + static_cast<std::size_t>(j)];
    if (quasi_static_ && !e.held[static_cast<std::size_t>(j)]) continue;
    if (value != e.rod.theta()[static_cast<std::size_t>(j)]) e.solved_at.resize(3, 0);  // a held angle moved: solve again
    e.rod.set_theta(j, value);
  }
}

void Rods::ensure_twist(Index r, const Points& x) const {
  if (!quasi_static_) return;
  Entry& e = rods_[r];  // θ is the term's own (mutable) state
  if (e.solved_at.cols() == x.cols() && e.solved_at == x) return;
  // Every solve of a step starts from the step's θ, not from the last solve's: the twist energy
  // is not convex in θ (bending couples in), and a solve warm-started at a rejected line-search
  // trial may land in another minimum, and the reduced energy would then depend on the order of
  // evaluations (a line search must compare values of one function).
  if (!e.start.empty())
    for (int j = 0; j < e.rod.num_edges(); ++j)
      if (e.held.empty() || !e.held[static_cast<std::size_t>(j)]) e.rod.set_theta(j, e.start[static_cast<std::size_t>(j)]);
  (void)e.rod.solve_twist(x, e.held);
  e.solved_at = x;
}

void Rods::add_forces(const StateView& s, std::span<double> f) const {
  Eigen::VectorXd g;
  for (Index r = 0; r < num_rods(); ++r) {
    const Entry& e = rods_[r];
    const Points x = gather(r, s.x);
    read_angles(r, s);
    ensure_twist(r, x);
    (void)e.rod.evaluate(x, g, nullptr);
    for (std::size_t k = 0; k < e.nodes.size(); ++k)
      for (int a = 0; a < 3; ++a) f[3 * e.nodes[k] + static_cast<std::size_t>(a)] -= g[3 * static_cast<Eigen::Index>(k) + a];
    const std::size_t torques = 3 * std::size_t{s.size()} + e.first_angle;  // where θ's torques go
    if (angle_blocks_ && f.size() >= torques + static_cast<std::size_t>(e.rod.num_edges()))
      for (int j = 0; j < e.rod.num_edges(); ++j)
        f[torques + static_cast<std::size_t>(j)] -= g[3 * static_cast<Eigen::Index>(e.nodes.size()) + j];
  }
}

double Rods::potential_energy(const StateView& s) const {
  double E = 0;
  for (Index r = 0; r < num_rods(); ++r) {
    const Points x = gather(r, s.x);
    read_angles(r, s);
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
      if (!angle_blocks_) continue;
      std::array<Index, 5> block{};
      std::array<int, 11> comp{};
      stencil_blocks(e, s, block, comp);
      for (int a = 0; a < 5; ++a)
        for (int b = std::max(a + 1, 3); b < 5; ++b)
          if (block[static_cast<std::size_t>(a)] != block[static_cast<std::size_t>(b)])
            out.push_back({block[static_cast<std::size_t>(a)], block[static_cast<std::size_t>(b)]});
    }
  }
}

void Rods::stencil_blocks(const Entry& e, int s, std::array<Index, 5>& block, std::array<int, 11>& comp) const {
  const auto v = e.rod.stencil_vertices(s);
  const auto ed = e.rod.stencil_edges(s);
  for (int k = 0; k < 3; ++k) {
    block[static_cast<std::size_t>(k)] = e.nodes[static_cast<std::size_t>(v[static_cast<std::size_t>(k)])];
    for (int c = 0; c < 3; ++c) comp[static_cast<std::size_t>(3 * k + c)] = c;
  }
  for (int k = 0; k < 2; ++k) {
    const Index a = e.first_angle + static_cast<Index>(ed[static_cast<std::size_t>(k)]);
    block[static_cast<std::size_t>(3 + k)] = angle_layout().block(a);
    comp[static_cast<std::size_t>(9 + k)] = angle_layout().component(a);
  }
}

void Rods::bind_pattern(const BlockMatrix& pattern) {
  for (Entry& e : rods_) {
    e.slots.clear();
    auto node = [&](int v) { return e.nodes[static_cast<std::size_t>(v)]; };
    for (int s = 0; s < e.rod.num_stencils(); ++s) {
      if (angle_blocks_) {
        std::array<Index, 5> block{};
        std::array<int, 11> comp{};
        stencil_blocks(e, s, block, comp);
        for (Index a : block)
          for (Index b : block) e.slots.push_back(pattern.find(a, b));
        continue;
      }
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
    if (project) H = projected<9>(H);
    for (int a = 0; a < 3; ++a)
      for (int c = 0; c < 3; ++c, ++slot) visit(v[static_cast<std::size_t>(a)], v[static_cast<std::size_t>(c)], Eigen::Matrix3d(H.block<3, 3>(3 * a, 3 * c)), slot);
  }
  const int n = e.rod.num_vertices();
  for (int j = 0; j < e.rod.num_edges(); ++j) {
    const int v[2] = {j, (j + 1) % n};
    const Eigen::Matrix<double, 6, 6> H =
        project ? stretch_hessian_psd(x.col(v[0]), x.col(v[1]), e.rod.section().EA, e.rod.rest_length(j))
                : stretch(x.col(v[0]), x.col(v[1]), e.rod.section().EA, e.rod.rest_length(j), true).hessian;
    for (int a = 0; a < 2; ++a)
      for (int c = 0; c < 2; ++c, ++slot) visit(v[a], v[c], Eigen::Matrix3d(H.block<3, 3>(3 * a, 3 * c)), slot);
  }
}

namespace {

// matrix += cx·(−H) and product_out += −H·product_in for a stencil Hessian H whose DOF i is
// component comp[i] of group group[i] (each group's DOFs contiguous), the groups sitting in block
// rows block[] with the groups × groups slots from slot0 on (flat index of a component:
// 3·block + component). The matrix is filled a 3×3 block at a time, its slot looked up once.
template <int N>
void scatter_hessian(const Eigen::Matrix<double, N, N>& H, std::span<const Index> block, std::span<const int> comp,
                     std::span<const int> group, std::span<const Index> slots, const JacobianRequest& req) {
  const std::size_t groups = block.size();
  std::array<std::size_t, N + 1> first{};  // group g's DOFs: first[g] .. first[g + 1] − 1
  for (std::size_t g = 0, i = 0; g < groups; ++g) {
    first[g] = i;
    while (i < std::size_t{N} && static_cast<std::size_t>(group[i]) == g) ++i;
  }
  first[groups] = N;
  // A node's group holds its 3 components in order: its blocks are whole 3×3 blocks of H.
  std::array<bool, N> whole{};
  for (std::size_t g = 0; g < groups; ++g)
    whole[g] = first[g + 1] - first[g] == 3 && comp[first[g]] == 0 && comp[first[g] + 1] == 1 && comp[first[g] + 2] == 2;
  if (req.matrix)
    for (std::size_t gi = 0; gi < groups; ++gi)
      for (std::size_t gj = 0; gj < groups; ++gj) {
        BlockMatrix::BlockMap b = req.matrix->block(slots[gi * groups + gj]);
        if (whole[gi] && whole[gj]) {
          b.noalias() -= req.cx * H.template block<3, 3>(static_cast<Eigen::Index>(first[gi]), static_cast<Eigen::Index>(first[gj]));
          continue;
        }
        for (std::size_t i = first[gi]; i < first[gi + 1]; ++i)
          for (std::size_t j = first[gj]; j < first[gj + 1]; ++j)
            b(comp[i], comp[j]) -= req.cx * H(static_cast<Eigen::Index>(i), static_cast<Eigen::Index>(j));
      }
  if (req.product_in.empty()) return;
  std::array<std::size_t, N> flat{};
  for (std::size_t i = 0; i < std::size_t{N}; ++i)
    flat[i] = 3 * std::size_t{block[static_cast<std::size_t>(group[i])]} + static_cast<std::size_t>(comp[i]);
  for (std::size_t i = 0; i < std::size_t{N}; ++i)
    for (std::size_t j = 0; j < std::size_t{N}; ++j)
      req.product_out[flat[i]] -= H(static_cast<Eigen::Index>(i), static_cast<Eigen::Index>(j)) * req.product_in[flat[j]];
}

}  // namespace

void Rods::add_jacobians_with_angles(const StateView& s, const JacobianRequest& req) const {
  static constexpr std::array<int, 11> stencil_group{0, 0, 0, 1, 1, 1, 2, 2, 2, 3, 4};
  static constexpr std::array<int, 6> edge_group{0, 0, 0, 1, 1, 1};
  static constexpr std::array<int, 6> edge_comp{0, 1, 2, 0, 1, 2};
  // Only the Newton integrator integrates angles, and it says per assembly whether it wants
  // the PSD stand-in or the exact Hessian (exact_hessian_first): projecting regardless would
  // hand its "exact" pass a Hessian without the bend-twist coupling of a bent rod, and Newton
  // would converge linearly along the soft twist modes (the toy ball's helical spring).
  // The PSD stand-in is the bend-twist stencils' Gauss-Newton Hessian (closed form, exact at the
  // natural strains), not the eigen-projection of the AD Hessian: nearly every stencil of a
  // bent rod is indefinite, and the 11×11 eigensolver was their largest cost.
  const bool project = project_ && req.options.project_element_hessians;
  for (Index r = 0; r < num_rods(); ++r) {
    const Entry& e = rods_[r];
    const Points x = gather(r, s.x);
    read_angles(r, s);
    ensure_twist(r, x);
    const std::span<const Index> slots(e.slots);
    std::size_t slot = 0;
    for (int st = 0; st < e.rod.num_stencils(); ++st, slot += 25) {
      const auto v = e.rod.stencil_vertices(st);
      const auto ed = e.rod.stencil_edges(st);
      const BendTwistEval b = bend_twist(x.col(v[0]), x.col(v[1]), x.col(v[2]), e.rod.theta()[static_cast<std::size_t>(ed[0])],
                                         e.rod.theta()[static_cast<std::size_t>(ed[1])], e.rod.stencil_rest(st),
                                         e.rod.stencil_frames(st), project ? Want::gauss_newton : Want::hessian);
      std::array<Index, 5> block{};
      std::array<int, 11> comp{};
      stencil_blocks(e, st, block, comp);
      scatter_hessian<11>(b.hessian, block, comp, stencil_group, slots.subspan(slot), req);
    }
    const int n = e.rod.num_vertices();
    for (int j = 0; j < e.rod.num_edges(); ++j, slot += 4) {
      const int v[2] = {j, (j + 1) % n};
      const double EA = e.rod.section().EA, rest = e.rod.rest_length(j);
      const std::array<Index, 2> block{e.nodes[static_cast<std::size_t>(v[0])], e.nodes[static_cast<std::size_t>(v[1])]};
      scatter_hessian<6>(project ? stretch_hessian_psd(x.col(v[0]), x.col(v[1]), EA, rest)
                                  : stretch(x.col(v[0]), x.col(v[1]), EA, rest, true).hessian,
                         block, edge_comp, edge_group, slots.subspan(slot), req);
    }
  }
}

void Rods::add_jacobians(const StateView& s, const JacobianRequest& req) const {
  if (req.matrix && req.matrix->pattern_version() != bound_pattern_)
    throw InputError("rods::Rods::add_jacobians: the matrix does not carry the pattern this term was bound to");
  if (angle_blocks_) {
    add_jacobians_with_angles(s, req);
    return;
  }
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
    read_angles(r, s);
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
    read_angles(r, s);
    ensure_twist(r, x);
    Entry& e = rods_[r];
    e.rod.update_frames(x);
    if (quasi_static_) e.start.assign(e.rod.theta().begin(), e.rod.theta().end());
  }
}

std::vector<Rods::RodHistory> Rods::history() const {
  std::vector<RodHistory> h;
  for (const Entry& e : rods_) h.push_back({e.rod.state(), std::vector<double>(e.solved_at.data(), e.solved_at.data() + e.solved_at.size())});
  return h;
}

void Rods::restore(std::span<const RodHistory> h) {
  if (h.size() != rods_.size())
    throw InputError("rods::Rods::restore: a history of " + std::to_string(h.size()) + " rods for a term of " + std::to_string(rods_.size()));
  for (std::size_t r = 0; r < h.size(); ++r) {
    const std::size_t n = 3 * static_cast<std::size_t>(rods_[r].rod.num_vertices());
    if (!h[r].solved_at.empty() && h[r].solved_at.size() != n)
      throw InputError("rods::Rods::restore: rod " + std::to_string(r) + " was solved at " + std::to_string(h[r].solved_at.size()) +
                       " coordinates, for " + std::to_string(n / 3) + " vertices");
    Rod check = rods_[r].rod;  // all or nothing: a bad rod further on leaves the earlier ones as they were
    check.restore(h[r].rod);
  }
  for (std::size_t r = 0; r < h.size(); ++r) {
    Entry& e = rods_[r];
    e.rod.restore(h[r].rod);
    e.start.clear();  // the rod's θ is the one of the last accepted step
    if (quasi_static_) e.start = h[r].rod.theta;
    if (h[r].solved_at.empty())
      e.solved_at.resize(3, 0);
    else
      e.solved_at = Eigen::Map<const Points>(h[r].solved_at.data(), 3, e.rod.num_vertices());
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
