#include "sewn/physics/system.hpp"

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
  const double* d = diag_[w].data() + i;
  double row = 0;
  for (int b = 0; b < 3; ++b)
    if (((fixed_[i] >> b) & 1u) == 0) row += std::abs(d[sym_entry[3 * b + axis] * stride_]);
  return row / mass_[i] + off_[w][axis * stride_ + i];
}

StabilityRows::Bound StabilityRows::bound(Which w) const {
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
