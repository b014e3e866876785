// The aggregation multigrid hierarchy of the sa-pcg backend (aggregation.hpp).

#include "aggregation.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include <Eigen/Dense>

#include "sewn/physics/errors.hpp"

namespace sewn::physics::solve::detail {

namespace {

// A level stops being coarsened once it has at most this many unknowns; it is factored dense
// (a pair of triangular solves on 400 unknowns: 0.3 Mflop, about a fine product of the 8x8x10
// beam).
constexpr std::int64_t coarse_unknowns = 400;
// Beyond this many unknowns a level that no longer coarsens is smoothed, not factored dense.
constexpr std::int64_t dense_limit = 3000;
constexpr int max_levels = 10;
// Strength of connection: ‖K_ij‖ ≥ θ √(‖K_ii‖ ‖K_jj‖), θ halved on each coarser level (the
// usual choice of smoothed aggregation: coarse matrices are denser and their couplings weaker).
constexpr double fine_theta = 0.08;
constexpr int power_iterations = 20;
// Measured on the N = 8 cantilever at h = 10 ms (docs/solvers.md): with the prolongator smoothed
// once (classical smoothed aggregation) the first coarse matrix has 1.0e6 entries, more than the
// fine one (7.5e5), and P 6.4e5; unsmoothed, 3.2e5 and 7.1e4, at the same iteration count once
// the fine level is smoothed well (3 block-Jacobi sweeps: 87 against 90 a step; 1 sweep: 145).
// The fine smoother is Chebyshev's polynomial in D⁻¹A, better than as many damped Jacobi sweeps
// at the same cost: degree 4 (3 products) gave 51 iterations a step (3: 61, 6: 43 at a dearer
// step) when a product was the general 9-value one. On the packed symmetric product a V-cycle
// of degree d costs 2d fine products and CG's own one more; measured on the N = 8 cantilever,
// 20 steps (CPU ms a step, iterations): degree 2 145-163 (73.8), 3 112-117 (57.8), 4 118-133
// (48.0); on the 8x8x10 beam 3 and 4 are within the noise. The coarse levels take one damped
// block-Jacobi sweep.
constexpr bool smooth_prolongator = false;
constexpr int fine_degree = 3;

// One level being built: its matrix, its nodes' unknowns and its near-null space (rows: the
// unknowns, columns: the modes).
struct Work {
  RowSparse K;
  std::vector<std::int64_t> first;
  Eigen::MatrixXd B;
  std::span<const double> free_dof;  // level 0 only (empty: all free)
};

// y = M x on the calling thread (Eigen's own product forks OpenMP threads per call, which on
// these small levels costs far more than the product: 75 % of a V-cycle's time in libgomp).
void product(const RowSparse& M, const double* x, double* y) {
  const RowSparse::StorageIndex* __restrict outer = M.outerIndexPtr();
  const RowSparse::StorageIndex* __restrict inner = M.innerIndexPtr();
  const double* __restrict v = M.valuePtr();
  // Four partial sums in a fixed order: one running sum would wait on the add's latency at
  // every entry (rows of a coarse level hold ~100).
  for (Eigen::Index r = 0; r < M.rows(); ++r) {
    double acc[4] = {};
    RowSparse::StorageIndex k = outer[r];
    for (; k + 4 <= outer[r + 1]; k += 4)
      for (int q = 0; q < 4; ++q) acc[q] += v[k + q] * x[inner[k + q]];
    for (; k < outer[r + 1]; ++k) acc[0] += v[k] * x[inner[k]];
    y[r] = (acc[0] + acc[1]) + (acc[2] + acc[3]);
  }
}

[[nodiscard]] std::int64_t nodes_of(const Work& w) { return static_cast<std::int64_t>(w.first.size()) - 1; }

// The strong neighbours of every node (CSR: offsets, nodes).
void strength(const Work& w, double theta, std::vector<std::int64_t>& off, std::vector<std::int64_t>& nb) {
  const std::int64_t n = nodes_of(w);
  std::vector<std::int64_t> node(static_cast<std::size_t>(w.K.rows()));
  for (std::int64_t i = 0; i < n; ++i)
    for (std::int64_t k = w.first[i]; k < w.first[i + 1]; ++k) node[k] = i;
  std::vector<double> acc(static_cast<std::size_t>(n), 0.0), dnorm(static_cast<std::size_t>(n), 0.0);
  std::vector<std::int64_t> touched;
  std::vector<std::vector<std::pair<std::int64_t, double>>> rows(static_cast<std::size_t>(n));
  for (std::int64_t i = 0; i < n; ++i) {
    touched.clear();
    for (std::int64_t row = w.first[i]; row < w.first[i + 1]; ++row)
      for (RowSparse::InnerIterator it(w.K, row); it; ++it) {
        const std::int64_t j = node[it.col()];
        if (acc[j] == 0.0) touched.push_back(j);
        acc[j] += it.value() * it.value() + 1e-300;  // a touched zero block stays marked
      }
    for (std::int64_t j : touched) {
      if (j == i) dnorm[i] = std::sqrt(acc[j]);
      else rows[i].emplace_back(j, std::sqrt(acc[j]));
      acc[j] = 0.0;
    }
  }
  off.assign(1, 0);
  nb.clear();
  for (std::int64_t i = 0; i < n; ++i) {
    std::sort(rows[i].begin(), rows[i].end());
    for (const auto& [j, v] : rows[i])
      if (v >= theta * std::sqrt(dnorm[i] * dnorm[j]) && v > 1e-150) nb.push_back(j);
    off.push_back(static_cast<std::int64_t>(nb.size()));
  }
}

// Greedy aggregation in node order (deterministic): (1) a node whose strong neighbours are all
// free starts an aggregate of itself and them; (2) a node left over joins the aggregate of its
// first aggregated strong neighbour; (3) what remains forms aggregates with its remaining
// strong neighbours. Nodes with no strong neighbour get -1 (the smoother alone treats them).
std::int64_t aggregate(std::int64_t n, const std::vector<std::int64_t>& off, const std::vector<std::int64_t>& nb,
                       std::vector<std::int64_t>& agg) {
  agg.assign(static_cast<std::size_t>(n), -1);
  std::int64_t count = 0;
  for (std::int64_t i = 0; i < n; ++i) {
    if (agg[i] >= 0 || off[i] == off[i + 1]) continue;
    bool all_free = true;
    for (std::int64_t k = off[i]; k < off[i + 1] && all_free; ++k) all_free = agg[nb[k]] < 0;
    if (!all_free) continue;
    agg[i] = count;
    for (std::int64_t k = off[i]; k < off[i + 1]; ++k) agg[nb[k]] = count;
    ++count;
  }
  const std::vector<std::int64_t> first_pass = agg;
  for (std::int64_t i = 0; i < n; ++i) {
    if (agg[i] >= 0) continue;
    for (std::int64_t k = off[i]; k < off[i + 1]; ++k)
      if (first_pass[nb[k]] >= 0) {
        agg[i] = first_pass[nb[k]];
        break;
      }
  }
  for (std::int64_t i = 0; i < n; ++i) {
    if (agg[i] >= 0 || off[i] == off[i + 1]) continue;
    agg[i] = count;
    for (std::int64_t k = off[i]; k < off[i + 1]; ++k)
      if (agg[nb[k]] < 0) agg[nb[k]] = count;
    ++count;
  }
  return count;
}

// The tentative prolongator: per aggregate, its rows of B (free unknowns only) orthonormalised
// by Gram-Schmidt twice over, columns that vanish dropped; the coarse near-null space is R = QᵀB.
void tentative(const Work& w, const std::vector<std::int64_t>& agg, std::int64_t count, RowSparse& T,
               std::vector<std::int64_t>& coarse_first, Eigen::MatrixXd& Bc) {
  const std::int64_t n = nodes_of(w);
  const Eigen::Index m = w.B.cols();
  std::vector<std::vector<std::int64_t>> members(static_cast<std::size_t>(count));
  for (std::int64_t i = 0; i < n; ++i)
    if (agg[i] >= 0) members[agg[i]].push_back(i);
  std::vector<Eigen::Triplet<double, int>> trip;
  coarse_first.assign(1, 0);
  std::vector<Eigen::MatrixXd> R(static_cast<std::size_t>(count));
  for (std::int64_t a = 0; a < count; ++a) {
    std::vector<std::int64_t> rows;
    for (std::int64_t i : members[a])
      for (std::int64_t k = w.first[i]; k < w.first[i + 1]; ++k)
        if (w.free_dof.empty() || w.free_dof[k] != 0.0) rows.push_back(k);
    Eigen::MatrixXd M(static_cast<Eigen::Index>(rows.size()), m);
    for (std::size_t r = 0; r < rows.size(); ++r) M.row(Eigen::Index(r)) = w.B.row(rows[r]);
    Eigen::MatrixXd Q(M.rows(), 0);
    for (Eigen::Index c = 0; c < m; ++c) {
      Eigen::VectorXd v = M.col(c);
      const double norm0 = v.norm();
      for (int pass = 0; pass < 2; ++pass)
        for (Eigen::Index q = 0; q < Q.cols(); ++q) v -= Q.col(q).dot(v) * Q.col(q);
      if (!(norm0 > 0) || v.norm() <= 1e-8 * norm0) continue;
      Q.conservativeResize(Eigen::NoChange, Q.cols() + 1);
      Q.col(Q.cols() - 1) = v / v.norm();
    }
    const std::int64_t base = coarse_first.back();
    for (std::size_t r = 0; r < rows.size(); ++r)
      for (Eigen::Index q = 0; q < Q.cols(); ++q) trip.emplace_back(int(rows[r]), int(base + q), Q(Eigen::Index(r), q));
    R[a] = Q.transpose() * M;
    coarse_first.push_back(base + Q.cols());
  }
  T.resize(w.K.rows(), coarse_first.back());
  T.setFromTriplets(trip.begin(), trip.end());
  Bc.resize(coarse_first.back(), m);
  for (std::int64_t a = 0; a < count; ++a) Bc.middleRows(coarse_first[a], R[a].rows()) = R[a];
}

// The inverses of K's diagonal blocks (row-major, concatenated) and D⁻¹ as a sparse matrix.
void block_inverses(const Work& w, const char* who, int level, std::vector<double>& inv, std::vector<std::int64_t>& at,
                    RowSparse& Dinv) {
  const std::int64_t n = nodes_of(w);
  inv.clear();
  at.assign(1, 0);
  std::vector<Eigen::Triplet<double, int>> trip;
  for (std::int64_t i = 0; i < n; ++i) {
    const std::int64_t f = w.first[i], s = w.first[i + 1] - f;
    Eigen::MatrixXd D = Eigen::MatrixXd::Zero(s, s);
    for (std::int64_t r = 0; r < s; ++r)
      for (RowSparse::InnerIterator it(w.K, f + r); it; ++it)
        if (it.col() >= f && it.col() < f + s) D(r, it.col() - f) = it.value();
    Eigen::LLT<Eigen::MatrixXd> llt(D);
    if (llt.info() != Eigen::Success)
      throw SolverError(std::string(who) + ": the matrix is not positive definite on the free axes (the diagonal block of " +
                            (level == 0 ? "node " : "aggregate ") + std::to_string(i) +
                            (level == 0 ? "" : " of multigrid level " + std::to_string(level)) + " is not)",
                        0, 0);
    const Eigen::MatrixXd Di = llt.solve(Eigen::MatrixXd::Identity(s, s));
    for (std::int64_t r = 0; r < s; ++r)
      for (std::int64_t c = 0; c < s; ++c) {
        inv.push_back(Di(r, c));
        trip.emplace_back(int(f + r), int(f + c), Di(r, c));
      }
    at.push_back(static_cast<std::int64_t>(inv.size()));
  }
  Dinv.resize(w.K.rows(), w.K.cols());
  Dinv.setFromTriplets(trip.begin(), trip.end());
}

// ρ(D⁻¹K) by power iteration from a fixed start (deterministic); the smoother's damping is
// 4 / (3ρ), which damps the upper two thirds of the spectrum by at least 1/3.
double smoother_omega(const RowSparse& K, const RowSparse& Dinv) {
  Eigen::VectorXd v(K.rows());
  for (Eigen::Index k = 0; k < v.size(); ++k) v[k] = 1.0 + 0.5 * std::sin(0.7 * double(k));
  double rho = 0;
  for (int it = 0; it < power_iterations; ++it) {
    Eigen::VectorXd Kv(v.size()), w(v.size());
    product(K, v.data(), Kv.data());
    product(Dinv, Kv.data(), w.data());
    const double n = w.norm(), nv = v.norm();
    if (!(n > 0)) break;
    rho = n / nv;
    v = w / n;
  }
  return rho > 0 ? 4.0 / (3.0 * rho) : 1.0;
}

RowSparse fine_matrix(const FineInput& in) {
  const auto nb = static_cast<std::int64_t>(in.rows.size()) - 1;
  RowSparse K(3 * nb, 3 * nb);
  std::vector<std::int64_t> per_row(static_cast<std::size_t>(3 * nb));
  for (std::int64_t bi = 0; bi < nb; ++bi)
    for (int a = 0; a < 3; ++a) per_row[3 * bi + a] = 3 * (in.rows[bi + 1] - in.rows[bi]);
  K.reserve(per_row);
  for (std::int64_t bi = 0; bi < nb; ++bi)
    for (int a = 0; a < 3; ++a)
      for (Index k = in.rows[bi]; k < in.rows[bi + 1]; ++k)
        for (int c = 0; c < 3; ++c)  // block (bi, bj) column-major: entry (a, c) at 3c + a
          K.insert(3 * bi + a, 3 * std::int64_t{in.columns[k]} + c) = in.values[9 * std::size_t{k} + 3 * std::size_t(c) + std::size_t(a)];
  K.makeCompressed();
  return K;
}

// The fine near-null space: translations, and rotations about the centroid when coordinates
// are given (centred, so the columns are well scaled for Gram-Schmidt).
Eigen::MatrixXd rigid_modes(const FineInput& in, std::int64_t nodes) {
  const bool rot = !in.coordinates.empty();
  Eigen::MatrixXd B = Eigen::MatrixXd::Zero(3 * nodes, rot ? 6 : 3);
  Eigen::Vector3d c = Eigen::Vector3d::Zero();
  if (rot) {
    for (std::int64_t i = 0; i < nodes; ++i) c += Eigen::Vector3d(in.coordinates.data() + 3 * i);
    c /= double(std::max<std::int64_t>(nodes, 1));
  }
  for (std::int64_t i = 0; i < nodes; ++i) {
    for (int a = 0; a < 3; ++a) B(3 * i + a, a) = 1.0;
    if (!rot) continue;
    const Eigen::Vector3d p = Eigen::Vector3d(in.coordinates.data() + 3 * i) - c;
    for (int e = 0; e < 3; ++e)  // rotation about axis e: e × p
      B.block<3, 1>(3 * i, 3 + e) = Eigen::Vector3d::Unit(e).cross(p);
  }
  return B;
}

// Level 1's prolongator with its rows renumbered for padded fine vectors (3i + a -> 4i + a), as
// the V-cycle applies it (FineLevel's layout); no rows for the padding.
void pad_fine_prolongator(CoarseLevel& c) {
  const Eigen::Index n = c.P.rows() / 3;
  std::vector<Eigen::Triplet<double, int>> trip;
  trip.reserve(static_cast<std::size_t>(c.P.nonZeros()));
  for (Eigen::Index row = 0; row < c.P.rows(); ++row)
    for (RowSparse::InnerIterator it(c.P, row); it; ++it)
      trip.emplace_back(int(4 * (row / 3) + row % 3), int(it.col()), it.value());
  c.P.resize(4 * n, c.P.cols());
  c.P.setFromTriplets(trip.begin(), trip.end());
  c.Pt = c.P.transpose();
}

}  // namespace

void SaHierarchy::clear() {
  levels_.clear();
  fine_omega_ = 0;
  fine_unknowns_ = 0;
  fine_entries_ = 0;
  coarsest_dense_ = false;  // (a default LLT copied in would carry an uninitialised status)
}

void SaHierarchy::build(const FineInput& in, const char* who) {
  clear();
  const auto nodes = static_cast<std::int64_t>(in.rows.size()) - 1;
  Work w;
  w.K = fine_matrix(in);
  w.first.resize(static_cast<std::size_t>(nodes + 1));
  for (std::int64_t i = 0; i <= nodes; ++i) w.first[i] = 3 * i;
  w.B = rigid_modes(in, nodes);
  w.free_dof = in.free_dof;
  fine_unknowns_ = w.K.rows();
  fine_entries_ = double(w.K.nonZeros());
  double theta = fine_theta;
  for (int level = 0;; ++level) {
    std::vector<double> inv;
    std::vector<std::int64_t> at;
    RowSparse Dinv;
    block_inverses(w, who, level, inv, at, Dinv);
    const double omega = smoother_omega(w.K, Dinv);
    if (level == 0) fine_omega_ = omega;
    else {
      levels_.back().inverse = std::move(inv);
      levels_.back().inverse_at = std::move(at);
      levels_.back().omega = omega;
    }
    const std::int64_t n = w.K.rows();
    std::vector<std::int64_t> off, nb, agg, coarse_first;
    std::int64_t count = 0;
    if (n > coarse_unknowns && level + 1 < max_levels) {
      strength(w, theta, off, nb);
      count = aggregate(nodes_of(w), off, nb, agg);
    }
    RowSparse T;
    Eigen::MatrixXd Bc;
    if (count > 0) tentative(w, agg, count, T, coarse_first, Bc);
    if (count == 0 || coarse_first.back() == 0 || coarse_first.back() > n * 7 / 10) {
      // the coarsest level: factored dense if small enough, else smoothed only
      if (level > 0 && n <= dense_limit) {
        coarsest_.compute(Eigen::MatrixXd(w.K));
        if (coarsest_.info() != Eigen::Success)
          throw SolverError(std::string(who) + ": the matrix is not positive definite on the free axes (its coarsest "
                                               "multigrid level of " + std::to_string(n) + " unknowns is not)",
                            0, 0);
        coarsest_dense_ = true;
      }
      break;
    }
    CoarseLevel c;
    c.P = smooth_prolongator ? RowSparse(T - omega * RowSparse(Dinv * w.K * T)) : T;
    c.P.prune(0.0);
    c.Pt = c.P.transpose();
    const RowSparse KP = w.K * c.P;
    c.K = c.Pt * KP;
    c.first = coarse_first;
    levels_.push_back(std::move(c));
    w.K = levels_.back().K;
    w.first = coarse_first;
    w.B = std::move(Bc);
    w.free_dof = {};
    theta *= 0.5;
  }
  if (!levels_.empty()) pad_fine_prolongator(levels_[0]);
  const std::size_t L = levels_.size() + 1;
  rc_.resize(L);
  zc_.resize(L);
  tc_.resize(L);
  uc_.resize(L);
  for (std::size_t l = 1; l < L; ++l)
    for (auto* v : {&rc_[l], &zc_[l], &tc_[l], &uc_[l]}) v->resize(levels_[l - 1].K.rows());
}

std::vector<std::int64_t> SaHierarchy::sizes() const {
  std::vector<std::int64_t> s{fine_unknowns_};
  for (const auto& l : levels_) s.push_back(l.K.rows());
  return s;
}

double SaHierarchy::cycle_entries() const {
  double e = 2 * fine_entries_;
  for (const auto& l : levels_) e += 2.0 * double(l.K.nonZeros()) + 2.0 * double(l.P.nonZeros());
  return e;
}

namespace {

// z += ω D⁻¹ r on a coarse level (dense blocks, row-major).
void add_smoothing(const CoarseLevel& c, const Eigen::VectorXd& r, Eigen::VectorXd& z) {
  const std::int64_t n = static_cast<std::int64_t>(c.first.size()) - 1;
  for (std::int64_t i = 0; i < n; ++i) {
    const std::int64_t f = c.first[i], s = c.first[i + 1] - f;
    const double* D = c.inverse.data() + c.inverse_at[i];
    for (std::int64_t a = 0; a < s; ++a) {
      double acc = 0;
      for (std::int64_t b = 0; b < s; ++b) acc += D[a * s + b] * r[f + b];
      z[f + a] += c.omega * acc;
    }
  }
}

}  // namespace

void SaHierarchy::descend(std::size_t l) {
  // Level l >= 1: from rc_[l] into zc_[l].
  const CoarseLevel& c = levels_[l - 1];
  Eigen::VectorXd &r = rc_[l], &z = zc_[l], &t = tc_[l], &u = uc_[l];
  if (l == levels_.size()) {
    if (coarsest_dense_) {
      z = coarsest_.solve(r);
      return;
    }
    z.setZero();
    add_smoothing(c, r, z);
    product(c.K, z.data(), t.data());
    u = r - t;
    add_smoothing(c, u, z);
    return;
  }
  z.setZero();
  add_smoothing(c, r, z);
  product(c.K, z.data(), t.data());
  u = r - t;
  product(levels_[l].Pt, u.data(), rc_[l + 1].data());
  descend(l + 1);
  product(levels_[l].P, zc_[l + 1].data(), t.data());
  z += t;
  product(c.K, z.data(), t.data());
  u = r - t;
  add_smoothing(c, u, z);
}

void SaHierarchy::vcycle(FineLevel& fine, const double* r, double* z) {
  const std::size_t n4 = 4 * fine.nodes();
  t0_.resize(n4);
  u0_.resize(n4);
  d0_.resize(n4);
  double* __restrict t = t0_.data();
  double* __restrict u = u0_.data();
  double* __restrict d = d0_.data();
  // u = r - K z, K = S A S + (I - S); z is zero on the fixed axes here, so K z = S A z
  auto residual = [&] {
    fine.product(z, t);
    for (std::size_t k = 0; k < n4; ++k) u[k] = r[k] - t[k];
  };
  // z += p(D⁻¹K) D⁻¹ u: Chebyshev's polynomial of degree fine_degree for D⁻¹K on
  // [b / 30, b], b = 1.1 ρ (ρ from the set-up's power iteration), u then holding u - K Δz but
  // for the last term. A polynomial in D⁻¹K times D⁻¹ is symmetric, so the same smoother before
  // and after keeps the V-cycle symmetric, as CG needs. Costs fine_degree - 1 products.
  auto chebyshev = [&] {
    const double upper = 1.1 * 4.0 / (3.0 * fine_omega_), lower = upper / 30.0;
    const double theta = 0.5 * (upper + lower), delta = 0.5 * (upper - lower), sigma = theta / delta;
    double rho = 1.0 / sigma;
    fine.smooth_step(u, d, 1.0 / theta, 0.0);
    for (std::size_t k = 0; k < n4; ++k) z[k] += d[k];
    for (int j = 1; j < fine_degree; ++j) {
      fine.product(d, t);
      for (std::size_t k = 0; k < n4; ++k) u[k] -= t[k];
      const double rho_next = 1.0 / (2.0 * sigma - rho);
      fine.smooth_step(u, d, 2.0 * rho_next / delta, rho_next * rho);
      rho = rho_next;
      for (std::size_t k = 0; k < n4; ++k) z[k] += d[k];
    }
  };
  std::fill(z, z + n4, 0.0);
  std::copy(r, r + n4, u);
  chebyshev();
  residual();
  if (!levels_.empty()) {
    product(levels_[0].Pt, u, rc_[1].data());
    descend(1);
    product(levels_[0].P, zc_[1].data(), t);
    const double* f = fine.free4();
    for (std::size_t k = 0; k < n4; ++k) z[k] = f[k] * (z[k] + t[k]);
    residual();
  }
  chebyshev();
}

}  // namespace sewn::physics::solve::detail
