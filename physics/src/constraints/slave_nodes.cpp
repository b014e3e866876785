#include "sewn/physics/constraints/slave_nodes.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include <Eigen/Geometry>

#include "sewn/physics/errors.hpp"

namespace sewn::physics {

namespace {

using Vec3 = Eigen::Vector3d;

Vec3 at(std::span<const double> a, Index i) { return {a[3 * i], a[3 * i + 1], a[3 * i + 2]}; }
void put(std::span<double> a, Index i, const Vec3& v) {
  for (int k = 0; k < 3; ++k) a[3 * i + k] = v[k];
}

// y ← Wᵀ y on node rows of `stride` doubles (3, or 4 padded): fine to coarse, a slave master
// passes its share on.
template <std::size_t stride>
void reduce_rows(std::span<const SlaveNode> slaves, double* y) {
  for (std::size_t i = slaves.size(); i-- > 0;) {
    const SlaveNode& s = slaves[i];
    double* v = y + stride * s.node;
    for (int k = 0; k < s.masters; ++k) {
      double* c = y + stride * s.master[static_cast<std::size_t>(k)];
      const double w = s.weight[static_cast<std::size_t>(k)];
      for (std::size_t a = 0; a < 3; ++a) c[a] += w * v[a];
    }
    for (std::size_t a = 0; a < 3; ++a) v[a] = 0;
  }
}

// z ← W z on node rows of `stride` doubles: coarse to fine, a slave master is set before it is used.
template <std::size_t stride>
void expand_rows(std::span<const SlaveNode> slaves, double* z) {
  for (const SlaveNode& s : slaves) {
    double v[3] = {0, 0, 0};
    for (int k = 0; k < s.masters; ++k) {
      const double* c = z + stride * s.master[static_cast<std::size_t>(k)];
      const double w = s.weight[static_cast<std::size_t>(k)];
      for (std::size_t a = 0; a < 3; ++a) v[a] += w * c[a];
    }
    for (std::size_t a = 0; a < 3; ++a) z[stride * s.node + a] = v[a];
  }
}

// W and Wᵀ for the packed CG's padded rows.
class Padded final : public PaddedReduction {
 public:
  explicit Padded(std::span<const SlaveNode> slaves) : slaves_(slaves) {}
  void expand4(double* v) const override { expand_rows<4>(slaves_, v); }
  void reduce4(double* v) const override { reduce_rows<4>(slaves_, v); }

 private:
  std::span<const SlaveNode> slaves_;
};

}  // namespace

void SlaveNodes::set(std::vector<SlaveNode> slaves, std::vector<std::vector<std::pair<Index, double>>> shares) {
  std::vector<char> seen;
  auto mark = [&](Index n) {
    if (n >= seen.size()) seen.resize(n + 1, 0);
    return std::exchange(seen[n], 1) == 0;
  };
  for (std::size_t i = 0; i < slaves.size(); ++i) {
    const SlaveNode& s = slaves[i];
    const std::string name = "SlaveNodes::set: slave " + std::to_string(i) + " (node " + std::to_string(s.node) + ")";
    if (s.masters != 2 && s.masters != 4) throw InputError(name + " has " + std::to_string(s.masters) + " masters (2 or 4)");
    double sum = 0;
    for (int k = 0; k < s.masters; ++k) sum += s.weight[static_cast<std::size_t>(k)];
    if (!(std::abs(sum - 1) <= 1e-12)) throw InputError(name + ": weights sum to " + std::to_string(sum) + ", not 1");
    if (!mark(s.node)) throw InputError(name + " is listed twice, or after a slave it masters");
  }
  // a master that is a slave must come first: it is marked by then, and no later slave is it
  seen.assign(seen.size(), 0);
  for (std::size_t i = slaves.size(); i-- > 0;) {
    for (int k = 0; k < slaves[i].masters; ++k) {
      const Index c = slaves[i].master[static_cast<std::size_t>(k)];
      if (c < seen.size() && seen[c])
        throw InputError("SlaveNodes::set: slave " + std::to_string(i) + " has master " + std::to_string(c) +
                         " that is itself a slave listed later (list coarse to fine)");
    }
    if (slaves[i].node >= seen.size()) seen.resize(slaves[i].node + 1, 0);
    seen[slaves[i].node] = 1;
  }
  if (!shares.empty() && shares.size() != slaves.size())
    throw InputError("SlaveNodes::set: " + std::to_string(shares.size()) + " share lists for " + std::to_string(slaves.size()) + " slaves");
  slaves_ = std::move(slaves);
  shares_ = std::move(shares);
  ++revision_;
}

void SlaveNodes::pass_forces(std::span<double> f) const {
  if (treatment_ == SlaveTreatment::paper_projection) {
    for (std::size_t i = 0; i < slaves_.size() && i < shares_.size(); ++i) {
      const Vec3 fv = at(f, slaves_[i].node);
      for (const auto& [n, w] : shares_[i]) put(f, n, at(f, n) + w * fv);
      put(f, slaves_[i].node, Vec3::Zero());
    }
    return;
  }
  reduce(f);
}

void SlaveNodes::reduce(std::span<double> y) const { reduce_rows<3>(slaves_, y.data()); }

void SlaveNodes::expand(std::span<double> z) const { expand_rows<3>(slaves_, z.data()); }

std::vector<double> SlaveNodes::lumped_masses(const NodeTable& nodes) const {
  std::vector<double> lumped;
  lump(nodes, lumped);
  return lumped;
}

void SlaveNodes::lump(const NodeTable& nodes, std::vector<double>& lumped) const {
  const auto m = nodes.masses();
  lumped.assign(m.begin(), m.end());
  if (treatment_ != SlaveTreatment::reduction) return;
  for (std::size_t i = slaves_.size(); i-- > 0;) {
    const SlaveNode& s = slaves_[i];
    for (int k = 0; k < s.masters; ++k) lumped[s.master[k]] += s.weight[k] * lumped[s.node];
    lumped[s.node] = 0;
  }
}

SlaveExpansion SlaveNodes::expansion(Index nodes) const {
  SlaveExpansion e;
  e.slot_.assign(nodes, -1);
  e.first_.reserve(slaves_.size() + 1);
  e.first_.push_back(0);
  std::vector<SlaveExpansion::Term> row;
  for (std::size_t i = 0; i < slaves_.size(); ++i) {  // coarse to fine: a slave master is expanded first
    const SlaveNode& s = slaves_[i];
    row.clear();
    for (int k = 0; k < s.masters; ++k) {
      const Index c = s.master[k];
      if (e.is_slave(c)) {
        for (const auto& t : e.of(c)) row.push_back({t.node, s.weight[k] * t.weight});
      } else {
        row.push_back({c, s.weight[k]});
      }
    }
    // two paths to one particle (masters sharing a master) become one term
    std::sort(row.begin(), row.end(), [](const auto& a, const auto& b) { return a.node < b.node; });
    const std::size_t start = e.terms_.size();
    for (const auto& t : row) {
      if (e.terms_.size() > start && e.terms_.back().node == t.node)
        e.terms_.back().weight += t.weight;
      else
        e.terms_.push_back(t);
    }
    e.first_.push_back(e.terms_.size());  // slave i's terms end here (and slave i + 1's start)
    if (s.node >= nodes) throw InputError("SlaveNodes::expansion: slave node " + std::to_string(s.node) + " is beyond the " + std::to_string(nodes) + " particles");
    e.slot_[s.node] = static_cast<std::int32_t>(i);
  }
  return e;
}

std::span<const double> SlaveNodes::inverse_mass_dof(const NodeTable& nodes) {
  if (treatment_ != SlaveTreatment::reduction) return nodes.inverse_mass_dof();
  // every step of the semi-implicit integrator comes here: kept while what it is made of stays
  const MassKey key{&nodes, nodes.topology_version(), nodes.parameter_version(), revision_};
  if (key == inv_mass_key_) return inv_mass_;
  inv_mass_key_ = key;
  lump(nodes, lumped_);
  const auto own = nodes.inverse_mass_dof();
  inv_mass_.resize(own.size());
  for (std::size_t i = 0; i < lumped_.size(); ++i) {
    const double inv = lumped_[i] > 0 ? 1 / lumped_[i] : 0;
    for (std::size_t a = 3 * i; a < 3 * i + 3; ++a) inv_mass_[a] = own[a] != 0 ? inv : 0;  // fixed axes stay 0
  }
  for (const SlaveNode& s : slaves_)
    for (int a = 0; a < 3; ++a) inv_mass_[3 * s.node + a] = 0;
  return inv_mass_;
}

void SlaveNodes::after_step(NodeTable& nodes) const {
  if (treatment_ == SlaveTreatment::reduction) {
    expand(nodes.x());
    expand(nodes.v());
    return;
  }
  const auto x = nodes.x();
  for (const SlaveNode& s : slaves_) {
    const Vec3 p = at(x, s.node);
    if (s.masters == 2) {  // onto the line of its masters
      const Vec3 a = at(x, s.master[0]), u = at(x, s.master[1]) - a;
      put(x, s.node, a + (p - a).dot(u) / u.squaredNorm() * u);
    } else {  // onto the plane through the masters' centroid, normal to both diagonals
      Vec3 c = Vec3::Zero();
      for (int k = 0; k < 4; ++k) c += at(x, s.master[k]) / 4;
      const Vec3 n = (at(x, s.master[2]) - at(x, s.master[0])).cross(at(x, s.master[3]) - at(x, s.master[1])).normalized();
      put(x, s.node, p - (p - c).dot(n) * n);
    }
  }
}

void SlaveNodes::remap(std::span<const Index> old_to_new) {
  std::vector<SlaveNode> kept;
  std::vector<std::vector<std::pair<Index, double>>> kept_shares;
  for (std::size_t i = 0; i < slaves_.size(); ++i) {
    SlaveNode s = slaves_[i];
    bool ok = (s.node = old_to_new[s.node]) != invalid_index;
    for (int k = 0; k < s.masters; ++k) ok = ok && (s.master[k] = old_to_new[s.master[k]]) != invalid_index;
    if (!ok) continue;
    kept.push_back(s);
    if (i < shares_.size()) {
      auto sh = shares_[i];
      for (auto& [n, w] : sh) n = old_to_new[n];
      std::erase_if(sh, [](const auto& p) { return p.first == invalid_index; });
      kept_shares.push_back(std::move(sh));
    }
  }
  slaves_ = std::move(kept);
  shares_ = std::move(kept_shares);
  ++revision_;
}

void SlaveNodes::reduced_block_jacobi(const BlockMatrix& A, std::span<const double> free_dof, std::span<double> inverse) {
  blocks_.resize(9 * static_cast<std::size_t>(A.size()));
  for (Index i = 0; i < A.size(); ++i) Eigen::Map<Eigen::Matrix3d>(blocks_.data() + 9 * std::size_t{i}) = A.block(A.diagonal(i));
  // fine to coarse: a slave that masters finer ones holds their shares when it passes its own on
  for (auto s = slaves_.rbegin(); s != slaves_.rend(); ++s) {
    const Eigen::Map<const Eigen::Matrix3d> own(blocks_.data() + 9 * std::size_t{s->node});
    for (int k = 0; k < s->masters; ++k)
      Eigen::Map<Eigen::Matrix3d>(blocks_.data() + 9 * std::size_t{s->master[k]}) += s->weight[k] * s->weight[k] * own;
  }
  block_jacobi_inverse(std::span<const double>(blocks_), free_dof, inverse);
}

CgResult SlaveNodes::solve_reduced(const BlockMatrix& A, std::span<const double> b, std::span<double> x,
                                   std::span<const double> free_dof, std::span<const double> precond_inverse,
                                   double tolerance, int max_iterations) {
  const std::size_t n3 = b.size();
  free_.assign(free_dof.begin(), free_dof.end());
  for (const SlaveNode& s : slaves_)
    for (int a = 0; a < 3; ++a) free_[3 * s.node + a] = 0;
  std::vector<double> rb(b.begin(), b.end());
  reduce(rb);
  for (std::size_t k = 0; k < n3; ++k) rb[k] *= free_[k];
  // the fast path: the solver layer's packed symmetric product with W and Wᵀ folded in
  if (CgResult fast; reduced_pcg_packed(A, rb, x, free_, precond_inverse, tolerance, max_iterations, ws_, Padded(slaves_), fast)) {
    expand(x);
    return fast;
  }
  r_.assign(n3, 0.0);
  z_.assign(n3, 0.0);
  p_.assign(n3, 0.0);
  q_.assign(n3, 0.0);
  ap_.assign(n3, 0.0);
  // S Wᵀ (b - A W x): the reduced residual on the free master axes
  auto apply = [&](std::span<const double> in, std::vector<double>& out) {
    q_.assign(in.begin(), in.end());
    expand(q_);
    A.multiply(q_, out);
    reduce(out);
    for (std::size_t k = 0; k < n3; ++k) out[k] *= free_[k];
  };
  auto precondition = [&](const std::vector<double>& in, std::vector<double>& out) {
    for (std::size_t i = 0; i < n3 / 3; ++i) {
      const double* m = precond_inverse.data() + 9 * i;
      for (int a = 0; a < 3; ++a)
        out[3 * i + a] = free_[3 * i + a] * (m[a] * in[3 * i] + m[3 + a] * in[3 * i + 1] + m[6 + a] * in[3 * i + 2]);
    }
  };
  double bnorm = 0;
  for (std::size_t k = 0; k < n3; ++k) bnorm += rb[k] * rb[k];
  bnorm = std::sqrt(bnorm);
  apply(x, ap_);
  for (std::size_t k = 0; k < n3; ++k) r_[k] = rb[k] - ap_[k];
  CgResult res;
  auto norm = [&](const std::vector<double>& v) {
    double s = 0;
    for (double e : v) s += e * e;
    return std::sqrt(s);
  };
  if (bnorm == 0) bnorm = 1;
  res.relative_residual = norm(r_) / bnorm;
  precondition(r_, z_);
  p_ = z_;
  double rz = 0;
  for (std::size_t k = 0; k < n3; ++k) rz += r_[k] * z_[k];
  while (res.relative_residual > tolerance && res.iterations < max_iterations) {
    apply(p_, ap_);
    double pap = 0;
    for (std::size_t k = 0; k < n3; ++k) pap += p_[k] * ap_[k];
    if (!(pap > 0)) {
      res.breakdown = true;
      break;
    }
    const double alpha = rz / pap;
    for (std::size_t k = 0; k < n3; ++k) {
      x[k] += alpha * p_[k];
      r_[k] -= alpha * ap_[k];
    }
    ++res.iterations;
    res.relative_residual = norm(r_) / bnorm;
    precondition(r_, z_);
    double rz_new = 0;
    for (std::size_t k = 0; k < n3; ++k) rz_new += r_[k] * z_[k];
    for (std::size_t k = 0; k < n3; ++k) p_[k] = z_[k] + rz_new / rz * p_[k];
    rz = rz_new;
  }
  res.converged = res.relative_residual <= tolerance;
  expand(x);
  return res;
}

}  // namespace sewn::physics
