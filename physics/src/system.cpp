#include "sewn/physics/system.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <string>

#include "sewn/physics/errors.hpp"

namespace sewn::physics {

// ------------------------------------------------------------------ StabilityRows

StabilityRows::StabilityRows(std::span<const double> mass, std::span<const AxisMask> fixed, const SlaveExpansion* fold)
    : mass_(mass), fold_(fold), fixed_(fixed), stride_(mass.size() + 8) {
  for (int w = 0; w < 2; ++w) {
    diag_[w].assign(6 * stride_, 0.0);
    off_[w].assign(3 * stride_, 0.0);
  }
  inv_sqrt_mass_.assign(stride_, 0.0);
  free_.assign(3 * stride_, 0.0);
  for (std::size_t i = 0; i < mass.size(); ++i) {
    inv_sqrt_mass_[i] = mass[i] > 0 ? 1.0 / std::sqrt(mass[i]) : 0.0;
    for (int a = 0; a < 3; ++a) free_[a * stride_ + i] = ((fixed[i] >> a) & 1u) != 0 ? 0.0 : 1.0;
  }
}

StabilityRows::Lanes StabilityRows::lanes() {
  Lanes l{};
  for (int w = 0; w < 2; ++w) {
    for (int e = 0; e < 6; ++e) l.diag[w][e] = diag_[w].data() + e * stride_;
    for (int a = 0; a < 3; ++a) l.off[w][a] = off_[w].data() + a * stride_;
  }
  l.inv_sqrt_mass = inv_sqrt_mass_.data();
  for (int a = 0; a < 3; ++a) l.free[a] = free_.data() + a * stride_;
  return l;
}

void StabilityRows::add_diagonal(Which w, Index i, const Eigen::Matrix3d& B) {
  if (fold_ == nullptr || !fold_->is_slave(i)) {
    diagonal_block(w, i, B);
    return;
  }
  // (WᵀKW)_ab += w_a w_b B over the slave's masters: their diagonal and the pairs between them
  const auto t = fold_->of(i);
  for (std::size_t a = 0; a < t.size(); ++a) {
    diagonal_block(w, t[a].node, t[a].weight * t[a].weight * B);
    for (std::size_t b = a + 1; b < t.size(); ++b) offdiagonal_block(w, t[a].node, t[b].node, t[a].weight * t[b].weight * B);
  }
}

void StabilityRows::add_offdiagonal(Which w, Index i, Index j, const Eigen::Matrix3d& B) {
  const bool si = fold_ != nullptr && fold_->is_slave(i), sj = fold_ != nullptr && fold_->is_slave(j);
  if (!si && !sj) {
    offdiagonal_block(w, i, j, B);
    return;
  }
  const SlaveExpansion::Term own_i{i, 1.0}, own_j{j, 1.0};
  const auto ti = si ? fold_->of(i) : std::span<const SlaveExpansion::Term>(&own_i, 1);
  const auto tj = sj ? fold_->of(j) : std::span<const SlaveExpansion::Term>(&own_j, 1);
  for (const auto& a : ti)
    for (const auto& b : tj) {
      // a particle reached from both ends (a slave tied to its own master) gets B + Bᵀ on its
      // diagonal, signed: that is where a spring from a slave to its master loses stiffness
      if (a.node == b.node)
        diagonal_block(w, a.node, a.weight * b.weight * (B + B.transpose()));
      else
        offdiagonal_block(w, a.node, b.node, a.weight * b.weight * B);
    }
}

bool StabilityRows::fold_is_slave(Index i) const { return fold_->is_slave(i); }

void StabilityRows::add_pair_folded(Index i, Index j, const SymBlock& K, const SymBlock& C) {
  for (int w = 0; w < 2; ++w) {
    const SymBlock& b = w == stiffness ? K : C;
    Eigen::Matrix3d B;
    B << b[0], b[3], b[4], b[3], b[1], b[5], b[4], b[5], b[2];
    add_diagonal(static_cast<Which>(w), i, B);
    add_diagonal(static_cast<Which>(w), j, B);
    add_offdiagonal(static_cast<Which>(w), i, j, B);
  }
}

void StabilityRows::diagonal_block(Which w, Index i, const Eigen::Matrix3d& B) {
  double* d = diag_[w].data() + i;
  d[0] += B(0, 0);
  d[stride_] += B(1, 1);
  d[2 * stride_] += B(2, 2);
  d[3 * stride_] += 0.5 * (B(0, 1) + B(1, 0));
  d[4 * stride_] += 0.5 * (B(0, 2) + B(2, 0));
  d[5 * stride_] += 0.5 * (B(1, 2) + B(2, 1));
}

void StabilityRows::offdiagonal_block(Which w, Index i, Index j, const Eigen::Matrix3d& B) {
  const double mi = mass_[i], mj = mass_[j];
  if (!(mi > 0 && mj > 0)) return;  // removed node: no row, no column
  const double scale = 1.0 / std::sqrt(mi * mj);
  for (int a = 0; a < 3; ++a) {
    double row_i = 0, row_j = 0;
    for (int b = 0; b < 3; ++b) {
      if (((fixed_[j] >> b) & 1u) == 0) row_i += std::abs(B(a, b));
      if (((fixed_[i] >> b) & 1u) == 0) row_j += std::abs(B(b, a));
    }
    off_[w][a * stride_ + i] += scale * row_i;
    off_[w][a * stride_ + j] += scale * row_j;
  }
}

double StabilityRows::row(Which w, Index i, int axis) const {
  if (!(mass_[i] > 0) || ((fixed_[i] >> axis) & 1u) != 0) return 0.0;
  double rows[1];
  axis_rows(w, axis, i, i + 1, rows);
  return rows[0];
}

// Rows [i0, i1) of `axis` (0 for a fixed axis or a node without mass): the diagonal block's row
// over the free axes, over the mass, plus the off-diagonal sums. Branch-free, so that the loop
// vectorizes; row() and bound() both use it, so they agree to the bit.
void StabilityRows::axis_rows(Which w, int axis, std::size_t i0, std::size_t i1, double* __restrict out) const {
  const double* __restrict m = mass_.data();
  const double* __restrict f[3] = {free_.data(), free_.data() + stride_, free_.data() + 2 * stride_};
  const double* __restrict d[3];
  for (int b = 0; b < 3; ++b) d[b] = diag_[w].data() + static_cast<std::size_t>(sym_entry[3 * b + axis]) * stride_;
  const double* __restrict o = off_[w].data() + static_cast<std::size_t>(axis) * stride_;
  const double* __restrict fa = f[axis];
  for (std::size_t i = i0; i < i1; ++i) {
    const double row = (f[0][i] != 0 ? std::abs(d[0][i]) : 0.0) + (f[1][i] != 0 ? std::abs(d[1][i]) : 0.0) +
                       (f[2][i] != 0 ? std::abs(d[2][i]) : 0.0);
    const double r = row / m[i] + o[i];
    const bool keep = (m[i] > 0) & (fa[i] != 0);
    out[i - i0] = keep ? r : 0.0;
  }
}

StabilityRows::Bound StabilityRows::bound(Which w) const {
  // Blocks of nodes: each block's rows in loops the compiler vectorizes and their largest, then
  // the node found in the first block holding the overall largest, scanning as the rows are
  // ordered (node, then axis), so that the node is the first with the largest row.
  constexpr std::size_t block = 256;
  const std::size_t n = mass_.size();
  std::array<std::array<double, block>, 3> rows;
  double best = 0;
  std::size_t best_block = n;
  bool nan = false;
  for (std::size_t b0 = 0; b0 < n; b0 += block) {
    const std::size_t b1 = std::min(n, b0 + block);
    // Four independent maxima (one chain would wait on each compare), and sums that a NaN
    // row makes NaN (rows are ≥ 0, so an infinite one does not).
    double top4[4] = {0, 0, 0, 0}, sum4[4] = {0, 0, 0, 0};
    for (std::size_t a = 0; a < 3; ++a) {
      axis_rows(w, static_cast<int>(a), b0, b1, rows[a].data());
      const std::size_t count = b1 - b0;
      for (std::size_t k = count; k < (count + 3) / 4 * 4; ++k) rows[a][k] = 0;
      for (std::size_t k = 0; k < count; k += 4)
        for (std::size_t u = 0; u < 4; ++u) {
          const double r = rows[a][k + u];
          top4[u] = r > top4[u] ? r : top4[u];
          sum4[u] += r;
        }
    }
    nan |= std::isnan((sum4[0] + sum4[1]) + (sum4[2] + sum4[3]));
    const double top = std::max(std::max(top4[0], top4[1]), std::max(top4[2], top4[3]));
    if (top > best) {
      best = top;
      best_block = b0;
    }
  }
  if (nan) return bound_with_nan(w);
  Bound out;
  if (best_block == n) return out;
  out.value = best;
  const std::size_t b1 = std::min(n, best_block + block);
  for (int a = 0; a < 3; ++a) axis_rows(w, a, best_block, b1, rows[static_cast<std::size_t>(a)].data());
  for (std::size_t k = 0; k < b1 - best_block && out.node == invalid_index; ++k)
    for (std::size_t a = 0; a < 3; ++a)
      if (rows[a][k] == best) out.node = static_cast<Index>(best_block + k);
  return out;
}

// bound() when a row is NaN: the largest row as the rows come, a NaN taken if it comes before
// any positive row (then nothing beats it), so that a broken state names a node.
StabilityRows::Bound StabilityRows::bound_with_nan(Which w) const {
  Bound out;
  for (Index i = 0; i < mass_.size(); ++i) {
    if (!(mass_[i] > 0)) continue;
    for (int a = 0; a < 3; ++a) {
      if ((fixed_[i] >> a) & 1u) continue;
      const double r = row(w, i, a);
      if (r > out.value || (std::isnan(r) && out.node == invalid_index)) {
        out.value = r;
        out.node = i;
      }
    }
  }
  return out;
}

// ------------------------------------------------------------------ System

ForceTerm& System::add_term(std::unique_ptr<ForceTerm> term) {
  if (!term) throw InputError("System::add_term: null term");
  terms_.push_back(std::move(term));
  return *terms_.back();
}

StateView System::state() const {
  StateView s = nodes_.state();
  s.angles = angles_.values();
  s.angle_rates = angles_.rates();
  return s;
}

void System::require_no_angles(const char* integrator) const {
  if (!angles_.empty())
    throw InputError(std::string(integrator) + ": the system has " + std::to_string(angles_.size()) +
                     " angle DOFs (rods with integrated twist), which only the Newton integrator integrates");
}

std::uint64_t System::topology_key() const {
  // Counters only increase, so their sum (plus the term count) changes iff one of them does.
  std::uint64_t key = nodes_.topology_version() + angles_.topology_version() + terms_.size();
  for (const auto& t : terms_) key += t->topology_version();
  return key;
}

bool System::refresh() {
  const std::uint64_t key = topology_key();
  if (key == seen_topology_) return false;
  for (const auto& t : terms_) t->check_nodes(nodes_);
  seen_topology_ = key;
  return true;
}

BlockMatrix& System::matrix() {
  refresh();
  const AngleLayout layout{nodes_.size()};
  const Index blocks = nodes_.size() + AngleLayout::blocks_for(angles_.size());
  if (pattern_topology_ != seen_topology_ || matrix_.size() != blocks) {
    std::vector<NodePair> pairs;
    for (const auto& t : terms_) {
      t->set_angle_layout(layout);
      t->collect_pairs(pairs);
    }
    matrix_.build_pattern(blocks, pairs);
    for (const auto& t : terms_) t->bind_pattern(matrix_);
    pattern_topology_ = seen_topology_;
  }
  return matrix_;
}

void System::compute_forces() {
  refresh();
  auto f = nodes_.f();
  if (terms_.empty()) {
    std::fill(f.begin(), f.end(), 0.0);
    return;
  }
  const StateView s = state();
  terms_.front()->set_forces(s, f);
  for (std::size_t t = 1; t < terms_.size(); ++t) terms_[t]->add_forces(s, f);
}

void System::add_forces(const StateView& s, std::span<double> f) const {
  for (const auto& t : terms_) t->add_forces(s, f);
}

void System::add_jacobians(const JacobianRequest& req) {
  (void)matrix();  // the pattern the terms assemble into
  const StateView s = state();
  for (const auto& t : terms_) t->add_jacobians(s, req);
}

double System::kinetic_energy() const {
  const auto v = nodes_.v();
  const auto m = nodes_.masses();
  double e = 0;
  for (std::size_t i = 0; i < m.size(); ++i) e += 0.5 * m[i] * (v[3 * i] * v[3 * i] + v[3 * i + 1] * v[3 * i + 1] + v[3 * i + 2] * v[3 * i + 2]);
  const auto w = angles_.rates();
  const auto J = angles_.inertias();
  for (std::size_t a = 0; a < w.size(); ++a) e += 0.5 * J[a] * w[a] * w[a];
  return e;
}

double System::potential_energy() const {
  double e = 0;
  const StateView s = state();
  for (const auto& t : terms_) e += t->potential_energy(s);
  return e;
}

double System::potential_energy(EnergyKind kind) const {
  double e = 0;
  const StateView s = state();
  for (const auto& t : terms_)
    if (t->energy_kind() == kind) e += t->potential_energy(s);
  return e;
}

double System::energy_scale() const {
  double e = 0;
  for (const auto& t : terms_) e += t->energy_scale();
  return e;
}

StableStep System::stable_step() {
  refresh();
  // With T-junctions reduced, the semi-implicit step moves only the masters, with the slaves'
  // masses lumped onto them and the slaves' springs seen through W: the bound is that reduced
  // system's. A slave's own row (little mass, a coarse side's springs) would understate h.
  const bool reduced = slaves_.reduces();
  const std::vector<double> lumped = reduced ? slaves_.lumped_masses(nodes_) : std::vector<double>{};
  const SlaveExpansion fold = reduced ? slaves_.expansion(nodes_.size()) : SlaveExpansion{};
  StabilityRows rows(reduced ? std::span<const double>(lumped) : nodes_.masses(), nodes_.fixed_masks(), reduced ? &fold : nullptr);
  const StateView s = state();
  for (const auto& t : terms_) t->add_stability_rows(s, rows);
  const auto k = rows.bound(StabilityRows::stiffness);
  const auto c = rows.bound(StabilityRows::damping);
  StableStep out;
  out.stiffness_bound = k.value;
  out.damping_bound = c.value;
  out.stiffness_node = k.node;
  out.damping_node = c.node;
  // Largest root of λ_K h² + 2 λ_C h - 4 = 0, written to avoid cancellation.
  if (k.value > 0 || c.value > 0)
    out.h_max = 4.0 / (c.value + std::sqrt(c.value * c.value + 4.0 * k.value));
  else
    out.h_max = std::numeric_limits<double>::infinity();
  return out;
}

std::vector<Index> System::compact_nodes() {
  for (const auto& t : terms_) t->check_nodes(nodes_);
  std::vector<Index> old_to_new = nodes_.compact();
  for (const auto& t : terms_) t->remap_nodes(old_to_new);
  slaves_.remap(old_to_new);
  refresh();
  return old_to_new;
}

std::uint64_t System::version() const {
  std::uint64_t key = nodes_.topology_version() + nodes_.parameter_version() + angles_.topology_version() + terms_.size();
  for (const auto& t : terms_) key += t->topology_version() + t->parameter_version();
  return key;
}

void System::step_accepted() {
  const StateView s = state();
  for (const auto& t : terms_) t->step_accepted(s);
}

}  // namespace sewn::physics
