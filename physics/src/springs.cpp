#include "sewn/physics/springs.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#if defined(__AVX512F__) && defined(__AVX512VL__)
#include <immintrin.h>
#define SEWN_SPRINGS_AVX512 1
#endif

#include "sewn/physics/errors.hpp"
#include "sewn/physics/nodes.hpp"

namespace sewn::physics {

namespace {

// A spring shorter than this fraction of its rest length has no usable direction.
constexpr double degenerate_ratio_sq = 1e-18;

std::string sp(Index s) { return "spring " + std::to_string(s); }

void check_param(double value, const char* what, const char* where, Index s) {
  if (!(std::isfinite(value) && value >= 0))
    throw InputError(std::string(where) + ": " + what + " of " + sp(s) + " must be finite and >= 0, got " +
                     std::to_string(value));
}

// Everything the force loop reads, as raw pointers (no aliasing between them).
struct Kernel {
  const double* __restrict x;
  const double* __restrict v;
  double* __restrict acc;  // 4 doubles per node
  const Index* __restrict ni;
  const Index* __restrict nj;
  const double* __restrict k;
  const double* __restrict l;
  const double* __restrict g;
  double beta;
};

// One spring, scalar: the reference arithmetic, and the tail of the vector loop.
template <SpringDamping D>
inline void spring_scalar(const Kernel& K, Index s) {
  const std::size_t i = K.ni[s], j = K.nj[s];
  const double* xi = K.x + 3 * i;
  const double* xj = K.x + 3 * j;
  const double dx = xj[0] - xi[0], dy = xj[1] - xi[1], dz = xj[2] - xi[2];
  const double d2 = dx * dx + dy * dy + dz * dz;
  const double l = K.l[s];
  if (d2 <= degenerate_ratio_sq * l * l) return;  // NaN goes on, to be caught downstream
  const double inv = 1.0 / std::sqrt(d2);
  double c = K.k[s] * (1.0 - l * inv);
  double e = 0.0;  // coefficient of ΔV (Rayleigh only)
  double ux = 0, uy = 0, uz = 0;
  if constexpr (D != SpringDamping::none) {
    const double* vi = K.v + 3 * i;
    const double* vj = K.v + 3 * j;
    ux = vj[0] - vi[0];
    uy = vj[1] - vi[1];
    uz = vj[2] - vi[2];
    const double w = (ux * dx + uy * dy + uz * dz) * inv * inv;
    if constexpr (D == SpringDamping::viscous) {
      c += K.g[s] * w;
    } else {
      const double cl = std::max(0.0, 1.0 - l * inv);
      const double bk = K.beta * K.k[s];
      c += bk * (1.0 - cl) * w;
      e = bk * cl;
    }
  }
  const double fx = c * dx + e * ux, fy = c * dy + e * uy, fz = c * dz + e * uz;
  double* ai = K.acc + 4 * i;
  double* aj = K.acc + 4 * j;
  ai[0] += fx;
  ai[1] += fy;
  ai[2] += fz;
  aj[0] -= fx;
  aj[1] -= fy;
  aj[2] -= fz;
}

#ifdef SEWN_SPRINGS_AVX512
// Four springs at a time. Gathers are slow (about one element per cycle), so each node's
// (x, y, z) is read as one masked 256-bit load ([x y z 0]) and four such rows are transposed
// into x, y, z vectors in registers; the forces are transposed back into rows and added to
// the 4-wide accumulator with one 256-bit read-modify-write per spring end. 1/d comes from
// rsqrt14 plus two Newton steps (relative error ~1e-16, no division or square root).
inline void to_soa(__m256d a0, __m256d a1, __m256d a2, __m256d a3, __m256d& X, __m256d& Y, __m256d& Z) {
  const __m256d t0 = _mm256_unpacklo_pd(a0, a1), t1 = _mm256_unpackhi_pd(a0, a1);
  const __m256d t2 = _mm256_unpacklo_pd(a2, a3), t3 = _mm256_unpackhi_pd(a2, a3);
  X = _mm256_permute2f128_pd(t0, t2, 0x20);
  Z = _mm256_permute2f128_pd(t0, t2, 0x31);
  Y = _mm256_permute2f128_pd(t1, t3, 0x20);
}

inline void to_rows(__m256d X, __m256d Y, __m256d Z, __m256d r[4]) {
  const __m256d zero = _mm256_setzero_pd();
  const __m256d t0 = _mm256_unpacklo_pd(X, Y), t1 = _mm256_unpackhi_pd(X, Y);
  const __m256d t2 = _mm256_unpacklo_pd(Z, zero), t3 = _mm256_unpackhi_pd(Z, zero);
  r[0] = _mm256_permute2f128_pd(t0, t2, 0x20);
  r[1] = _mm256_permute2f128_pd(t1, t3, 0x20);
  r[2] = _mm256_permute2f128_pd(t0, t2, 0x31);
  r[3] = _mm256_permute2f128_pd(t1, t3, 0x31);
}

inline __m256d inv_sqrt(__m256d d2) {
  const __m256d half = _mm256_set1_pd(0.5), three_halves = _mm256_set1_pd(1.5);
  const __m256d hd = _mm256_mul_pd(half, d2);
  __m256d y = _mm256_rsqrt14_pd(d2);
  y = _mm256_mul_pd(y, _mm256_fnmadd_pd(hd, _mm256_mul_pd(y, y), three_halves));
  y = _mm256_mul_pd(y, _mm256_fnmadd_pd(hd, _mm256_mul_pd(y, y), three_halves));
  return y;
}

template <SpringDamping D>
inline void springs_x4(const Kernel& K, Index s) {
  constexpr __mmask8 xyz = 0x7;
  std::size_t i[4], j[4];
  __m256d a[4], b[4];
  for (int q = 0; q < 4; ++q) {
    i[q] = K.ni[s + q];
    j[q] = K.nj[s + q];
    a[q] = _mm256_sub_pd(_mm256_maskz_loadu_pd(xyz, K.x + 3 * j[q]), _mm256_maskz_loadu_pd(xyz, K.x + 3 * i[q]));
    if constexpr (D != SpringDamping::none)
      b[q] = _mm256_sub_pd(_mm256_maskz_loadu_pd(xyz, K.v + 3 * j[q]), _mm256_maskz_loadu_pd(xyz, K.v + 3 * i[q]));
  }
  __m256d dx, dy, dz;
  to_soa(a[0], a[1], a[2], a[3], dx, dy, dz);
  const __m256d d2 = _mm256_fmadd_pd(dz, dz, _mm256_fmadd_pd(dy, dy, _mm256_mul_pd(dx, dx)));
  const __m256d l = _mm256_loadu_pd(K.l + s);
  const __m256d k = _mm256_loadu_pd(K.k + s);
  const __m256d one = _mm256_set1_pd(1.0);
  // Ordered compare: a NaN length fails it, c becomes 0 but c·dx stays NaN.
  const __mmask8 ok = _mm256_cmp_pd_mask(d2, _mm256_mul_pd(_mm256_set1_pd(degenerate_ratio_sq), _mm256_mul_pd(l, l)),
                                         _CMP_GT_OQ);
  const __m256d inv = inv_sqrt(d2);
  const __m256d linv = _mm256_mul_pd(l, inv);
  __m256d c = _mm256_mul_pd(k, _mm256_sub_pd(one, linv));
  __m256d fx, fy, fz;
  if constexpr (D == SpringDamping::none) {
    c = _mm256_maskz_mov_pd(ok, c);
    fx = _mm256_mul_pd(c, dx);
    fy = _mm256_mul_pd(c, dy);
    fz = _mm256_mul_pd(c, dz);
  } else {
    __m256d ux, uy, uz;
    to_soa(b[0], b[1], b[2], b[3], ux, uy, uz);
    const __m256d w = _mm256_mul_pd(_mm256_fmadd_pd(uz, dz, _mm256_fmadd_pd(uy, dy, _mm256_mul_pd(ux, dx))),
                                    _mm256_mul_pd(inv, inv));
    if constexpr (D == SpringDamping::viscous) {
      c = _mm256_maskz_mov_pd(ok, _mm256_fmadd_pd(_mm256_loadu_pd(K.g + s), w, c));
      fx = _mm256_mul_pd(c, dx);
      fy = _mm256_mul_pd(c, dy);
      fz = _mm256_mul_pd(c, dz);
    } else {
      const __m256d cl = _mm256_max_pd(_mm256_sub_pd(one, linv), _mm256_setzero_pd());
      const __m256d bk = _mm256_mul_pd(_mm256_set1_pd(K.beta), k);
      c = _mm256_maskz_mov_pd(ok, _mm256_fmadd_pd(_mm256_mul_pd(bk, _mm256_sub_pd(one, cl)), w, c));
      const __m256d e = _mm256_maskz_mov_pd(ok, _mm256_mul_pd(bk, cl));
      fx = _mm256_fmadd_pd(e, ux, _mm256_mul_pd(c, dx));
      fy = _mm256_fmadd_pd(e, uy, _mm256_mul_pd(c, dy));
      fz = _mm256_fmadd_pd(e, uz, _mm256_mul_pd(c, dz));
    }
  }
  __m256d r[4];
  to_rows(fx, fy, fz, r);
  for (int q = 0; q < 4; ++q) {
    double* ai = K.acc + 4 * i[q];
    double* aj = K.acc + 4 * j[q];
    _mm256_store_pd(ai, _mm256_add_pd(_mm256_load_pd(ai), r[q]));
    _mm256_store_pd(aj, _mm256_sub_pd(_mm256_load_pd(aj), r[q]));
  }
}
#endif

template <SpringDamping D>
void spring_loop(const Kernel& K, Index count) {
  Index s = 0;
#ifdef SEWN_SPRINGS_AVX512
  for (; s + 4 <= count; s += 4) springs_x4<D>(K, s);
#endif
  for (; s < count; ++s) spring_scalar<D>(K, s);
}

struct SpringFrame {
  Eigen::Vector3d dx;
  double d = 0;
  bool ok = false;
};

SpringFrame frame(const StateView& st, Index i, Index j, double l) {
  SpringFrame fr;
  fr.dx = Eigen::Vector3d(st.x[3 * j] - st.x[3 * i], st.x[3 * j + 1] - st.x[3 * i + 1], st.x[3 * j + 2] - st.x[3 * i + 2]);
  const double d2 = fr.dx.squaredNorm();
  fr.ok = d2 > degenerate_ratio_sq * l * l;
  fr.d = std::sqrt(d2);
  return fr;
}

Eigen::Vector3d vel_diff(const StateView& st, Index i, Index j) {
  return {st.v[3 * j] - st.v[3 * i], st.v[3 * j + 1] - st.v[3 * i + 1], st.v[3 * j + 2] - st.v[3 * i + 2]};
}

}  // namespace

double paper_viscosity(double k, double mi, double mj) {
  if (!(std::isfinite(k) && k >= 0)) throw InputError("paper_viscosity: stiffness must be finite and >= 0, got " + std::to_string(k));
  if (!(std::isfinite(mi) && mi > 0 && std::isfinite(mj) && mj > 0))
    throw InputError("paper_viscosity: masses must be finite and > 0, got " + std::to_string(mi) + " and " +
                     std::to_string(mj));
  return 2.0 * std::sqrt(k * (mi + mj) / 2.0);
}

Springs::Springs(SpringDamping damping, double rayleigh_beta) : damping_(SpringDamping::none), beta_(0.0) {
  set_damping(damping, rayleigh_beta);
}

void Springs::set_damping(SpringDamping damping, double rayleigh_beta) {
  if (!(std::isfinite(rayleigh_beta) && rayleigh_beta >= 0))
    throw InputError("Springs::set_damping: Rayleigh beta must be finite and >= 0, got " + std::to_string(rayleigh_beta));
  damping_ = damping;
  beta_ = rayleigh_beta;
  touch_parameters();
}

void Springs::check_spring(Index s, const char* where) const {
  if (s >= size())
    throw InputError(std::string(where) + ": " + sp(s) + " out of range (" + std::to_string(size()) + " slots)");
  if (alive_[s] == 0) throw InputError(std::string(where) + ": " + sp(s) + " was removed");
}

Index Springs::add(Index i, Index j, double k, double rest_length, SpringKind kind, double gamma) {
  const Index s = free_.empty() ? size() : free_.back();
  if (i == j) throw InputError("Springs::add: " + sp(s) + " would join node " + std::to_string(i) + " to itself");
  if (i == invalid_index || j == invalid_index) throw InputError("Springs::add: invalid node index for " + sp(s));
  check_param(k, "stiffness", "Springs::add", s);
  check_param(rest_length, "rest length", "Springs::add", s);
  check_param(gamma, "viscosity", "Springs::add", s);
  if (free_.empty()) {
    ni_.push_back(i);
    nj_.push_back(j);
    k_.push_back(k);
    l_.push_back(rest_length);
    gamma_.push_back(gamma);
    kind_.push_back(kind);
    alive_.push_back(1);
  } else {
    free_.pop_back();
    ni_[s] = i;
    nj_[s] = j;
    k_[s] = k;
    l_[s] = rest_length;
    gamma_[s] = gamma;
    kind_[s] = kind;
    alive_[s] = 1;
  }
  ++alive_count_;
  max_node_ = std::max({max_node_, i, j});
  touch_topology();
  return s;
}

void Springs::remove(Index s) {
  check_spring(s, "Springs::remove");
  alive_[s] = 0;
  ni_[s] = nj_[s] = 0;
  k_[s] = l_[s] = gamma_[s] = 0.0;
  free_.push_back(s);
  --alive_count_;
  touch_topology();
}

void Springs::set_stiffness(Index s, double k) {
  check_spring(s, "Springs::set_stiffness");
  check_param(k, "stiffness", "Springs::set_stiffness", s);
  k_[s] = k;
  touch_parameters();
}

void Springs::set_rest_length(Index s, double l) {
  check_spring(s, "Springs::set_rest_length");
  check_param(l, "rest length", "Springs::set_rest_length", s);
  l_[s] = l;
  touch_parameters();
}

void Springs::set_viscosity(Index s, double gamma) {
  check_spring(s, "Springs::set_viscosity");
  check_param(gamma, "viscosity", "Springs::set_viscosity", s);
  gamma_[s] = gamma;
  touch_parameters();
}

void Springs::set_endpoints(Index s, Index i, Index j) {
  check_spring(s, "Springs::set_endpoints");
  if (i == j) throw InputError("Springs::set_endpoints: " + sp(s) + " would join node " + std::to_string(i) + " to itself");
  if (i == invalid_index || j == invalid_index) throw InputError("Springs::set_endpoints: invalid node index for " + sp(s));
  ni_[s] = i;
  nj_[s] = j;
  max_node_ = std::max({max_node_, i, j});
  touch_topology();
}

void Springs::move_endpoint(Index s, Index from, Index to) {
  check_spring(s, "Springs::move_endpoint");
  if (ni_[s] == from)
    set_endpoints(s, to, nj_[s]);
  else if (nj_[s] == from)
    set_endpoints(s, ni_[s], to);
  else
    throw InputError("Springs::move_endpoint: " + sp(s) + " joins nodes " + std::to_string(ni_[s]) + " and " +
                     std::to_string(nj_[s]) + ", not node " + std::to_string(from));
}

void Springs::set_paper_viscosity(std::span<const double> masses) {
  for (Index s = 0; s < size(); ++s) {
    if (alive_[s] == 0) continue;
    if (ni_[s] >= masses.size() || nj_[s] >= masses.size())
      throw InputError("Springs::set_paper_viscosity: " + sp(s) + " refers to a node beyond the " +
                       std::to_string(masses.size()) + " masses given");
    gamma_[s] = paper_viscosity(k_[s], masses[ni_[s]], masses[nj_[s]]);
  }
  touch_parameters();
}

void Springs::reserve(Index n) {
  ni_.reserve(n);
  nj_.reserve(n);
  k_.reserve(n);
  l_.reserve(n);
  gamma_.reserve(n);
  kind_.reserve(n);
  alive_.reserve(n);
}

std::vector<Index> Springs::compact() {
  std::vector<Index> old_to_new(size(), invalid_index);
  Index n = 0;
  for (Index s = 0; s < size(); ++s) {
    if (alive_[s] == 0) continue;
    old_to_new[s] = n;
    ni_[n] = ni_[s];
    nj_[n] = nj_[s];
    k_[n] = k_[s];
    l_[n] = l_[s];
    gamma_[n] = gamma_[s];
    kind_[n] = kind_[s];
    alive_[n] = 1;
    ++n;
  }
  ni_.resize(n);
  nj_.resize(n);
  k_.resize(n);
  l_.resize(n);
  gamma_.resize(n);
  kind_.resize(n);
  alive_.resize(n);
  free_.clear();
  max_node_ = 0;
  for (Index s = 0; s < n; ++s) max_node_ = std::max({max_node_, ni_[s], nj_[s]});
  touch_topology();
  return old_to_new;
}

Index Springs::node_i(Index s) const {
  check_spring(s, "Springs::node_i");
  return ni_[s];
}
Index Springs::node_j(Index s) const {
  check_spring(s, "Springs::node_j");
  return nj_[s];
}
double Springs::stiffness(Index s) const {
  check_spring(s, "Springs::stiffness");
  return k_[s];
}
double Springs::rest_length(Index s) const {
  check_spring(s, "Springs::rest_length");
  return l_[s];
}
double Springs::viscosity(Index s) const {
  check_spring(s, "Springs::viscosity");
  return gamma_[s];
}
SpringKind Springs::kind(Index s) const {
  check_spring(s, "Springs::kind");
  return kind_[s];
}

void Springs::check_nodes(const NodeTable& nodes) const {
  for (Index s = 0; s < size(); ++s) {
    if (alive_[s] == 0) continue;
    for (Index n : {ni_[s], nj_[s]}) {
      if (n >= nodes.size())
        throw InputError("springs: " + sp(s) + " refers to node " + std::to_string(n) + " but there are " +
                         std::to_string(nodes.size()) + " nodes");
      if (!nodes.is_alive(n))
        throw InputError("springs: " + sp(s) + " refers to removed node " + std::to_string(n));
    }
  }
  // Tombstones point at node 0; the force loop reads it, so it must exist.
  if (alive_count_ < size() && nodes.size() == 0)
    throw InputError("springs: removed springs remain but the node table is empty; compact the springs");
}

void Springs::remap_nodes(std::span<const Index> old_to_new) {
  for (Index s = 0; s < size(); ++s) {
    if (alive_[s] == 0) continue;
    ni_[s] = old_to_new[ni_[s]];
    nj_[s] = old_to_new[nj_[s]];
  }
  max_node_ = 0;
  for (Index s = 0; s < size(); ++s) max_node_ = std::max({max_node_, ni_[s], nj_[s]});
  touch_topology();
}

void Springs::add_forces(const StateView& st, std::span<double> f) const {
  const Index n = st.size();
  if (size() == 0) return;
  if (max_node_ >= n)
    throw InputError("springs: a spring refers to node " + std::to_string(max_node_) + " but the state has " +
                     std::to_string(n) + " nodes");
  acc_.assign(4 * std::size_t{n}, 0.0);
  const Kernel K{st.x.data(), st.v.data(), acc_.data(), ni_.data(), nj_.data(), k_.data(), l_.data(), gamma_.data(), beta_};
  switch (damping_) {
    case SpringDamping::none: spring_loop<SpringDamping::none>(K, size()); break;
    case SpringDamping::viscous: spring_loop<SpringDamping::viscous>(K, size()); break;
    case SpringDamping::stiffness_proportional: spring_loop<SpringDamping::stiffness_proportional>(K, size()); break;
  }
  const double* __restrict a = acc_.data();
  double* __restrict out = f.data();
  std::size_t p = 0;
#ifdef SEWN_SPRINGS_AVX512
  // Four nodes: 16 padded accumulator values -> 12 consecutive forces, by two permutes.
  const __m512i first8 = _mm512_setr_epi64(0, 1, 2, 4, 5, 6, 8, 9);
  const __m512i last4 = _mm512_setr_epi64(10, 12, 13, 14, 10, 12, 13, 14);  // upper half unused
  for (; p + 4 <= n; p += 4) {
    const __m512d lo = _mm512_load_pd(a + 4 * p), hi = _mm512_load_pd(a + 4 * p + 8);
    double* o = out + 3 * p;
    _mm512_storeu_pd(o, _mm512_add_pd(_mm512_loadu_pd(o), _mm512_permutex2var_pd(lo, first8, hi)));
    // Through memory rather than a 512->256 cast, which GCC 12 flags as uninitialised.
    alignas(64) double tail[8];
    _mm512_store_pd(tail, _mm512_permutex2var_pd(lo, last4, hi));
    _mm256_storeu_pd(o + 8, _mm256_add_pd(_mm256_loadu_pd(o + 8), _mm256_load_pd(tail)));
  }
#endif
  for (; p < n; ++p) {
    out[3 * p] += a[4 * p];
    out[3 * p + 1] += a[4 * p + 1];
    out[3 * p + 2] += a[4 * p + 2];
  }
}

double Springs::potential_energy(const StateView& st) const {
  double e = 0.0;
  for (Index s = 0; s < size(); ++s) {
    if (alive_[s] == 0) continue;
    const SpringFrame fr = frame(st, ni_[s], nj_[s], l_[s]);
    e += 0.5 * k_[s] * (fr.d - l_[s]) * (fr.d - l_[s]);
  }
  return e;
}

double Springs::energy_scale() const {
  double e = 0.0;
  for (Index s = 0; s < size(); ++s) e += 0.5 * k_[s] * l_[s] * l_[s];
  return e;
}

void Springs::collect_pairs(std::vector<NodePair>& out) const {
  for (Index s = 0; s < size(); ++s)
    if (alive_[s] != 0) out.push_back({ni_[s], nj_[s]});
}

void Springs::bind_pattern(const BlockMatrix& pattern) {
  slot_ij_.assign(size(), invalid_index);
  slot_ji_.assign(size(), invalid_index);
  slot_ii_.assign(size(), invalid_index);
  slot_jj_.assign(size(), invalid_index);
  for (Index s = 0; s < size(); ++s) {
    if (alive_[s] == 0) continue;
    slot_ij_[s] = pattern.find(ni_[s], nj_[s]);
    slot_ji_[s] = pattern.find(nj_[s], ni_[s]);
    slot_ii_[s] = pattern.diagonal(ni_[s]);
    slot_jj_[s] = pattern.diagonal(nj_[s]);
    if (slot_ij_[s] == invalid_index || slot_ji_[s] == invalid_index)
      throw InputError("springs: the pattern has no block for " + sp(s) + "; rebuild it after editing springs");
  }
  bound_pattern_ = pattern.pattern_version();
  bound_topology_ = topology_version();
}

bool Springs::jacobian_symmetric(const JacobianOptions& opt) const {
  return damping_ != SpringDamping::viscous || opt.drop_viscous_position_terms;
}

void Springs::add_jacobians(const StateView& st, const JacobianRequest& req) const {
  if (req.matrix != nullptr &&
      (req.matrix->pattern_version() != bound_pattern_ || bound_topology_ != topology_version()))
    throw InputError("springs: add_jacobians on a pattern that is not bound to the current springs; call System::refresh()");
  const bool product = !req.product_in.empty();
  const Eigen::Matrix3d I = Eigen::Matrix3d::Identity();
  for (Index s = 0; s < size(); ++s) {
    if (alive_[s] == 0) continue;
    const Index i = ni_[s], j = nj_[s];
    const double k = k_[s], l = l_[s];
    const SpringFrame fr = frame(st, i, j, l);
    if (!fr.ok) continue;
    const Eigen::Vector3d U = fr.dx / fr.d;
    const Eigen::Matrix3d UU = U * U.transpose();
    const Eigen::Matrix3d Q = I - UU;
    const double stretch = 1.0 - l / fr.d;
    const double cl = req.options.clamp_compression ? std::max(0.0, stretch) : stretch;
    Eigen::Matrix3d Jx = k * (UU + cl * Q);
    Eigen::Matrix3d Jv = Eigen::Matrix3d::Zero();
    if (damping_ == SpringDamping::viscous) {
      const double gamma = gamma_[s];
      if (!req.options.drop_viscous_position_terms) {
        const Eigen::Vector3d dv = vel_diff(st, i, j);
        const double w = dv.dot(U);
        Jx += (gamma / fr.d) * (w * Q + U * (dv.transpose() * Q));
      }
      Jv = gamma * UU;
    } else if (damping_ == SpringDamping::stiffness_proportional) {
      Jv = beta_ * k * (UU + std::max(0.0, stretch) * Q);
    }
    if (req.matrix != nullptr) {
      const Eigen::Matrix3d B = req.cx * Jx + req.cv * Jv;
      req.matrix->block(slot_ij_[s]) += B;
      req.matrix->block(slot_ji_[s]) += B;
      req.matrix->block(slot_ii_[s]) -= B;
      req.matrix->block(slot_jj_[s]) -= B;
    }
    if (product) {
      const Eigen::Vector3d p(req.product_in[3 * j] - req.product_in[3 * i], req.product_in[3 * j + 1] - req.product_in[3 * i + 1],
                              req.product_in[3 * j + 2] - req.product_in[3 * i + 2]);
      const Eigen::Vector3d q = Jx * p;
      for (int a = 0; a < 3; ++a) {
        req.product_out[3 * i + a] += q[a];
        req.product_out[3 * j + a] -= q[a];
      }
    }
  }
}

void Springs::add_stability_rows(const StateView& st, StabilityRows& rows) const {
  const Eigen::Matrix3d I = Eigen::Matrix3d::Identity();
  for (Index s = 0; s < size(); ++s) {
    if (alive_[s] == 0) continue;
    const Index i = ni_[s], j = nj_[s];
    const SpringFrame fr = frame(st, i, j, l_[s]);
    Eigen::Matrix3d Kb, Cb;
    if (fr.ok) {
      const Eigen::Vector3d U = fr.dx / fr.d;
      const Eigen::Matrix3d UU = U * U.transpose();
      Kb = k_[s] * (UU + std::max(0.0, 1.0 - l_[s] / fr.d) * (I - UU));
      Cb = damping_ == SpringDamping::viscous ? Eigen::Matrix3d(gamma_[s] * UU) : Eigen::Matrix3d(beta_ * Kb);
    } else {
      // No direction: bound the block by its largest possible norm.
      Kb = k_[s] * I;
      Cb = (damping_ == SpringDamping::viscous ? gamma_[s] : beta_ * k_[s]) * I;
    }
    if (damping_ == SpringDamping::none) Cb.setZero();
    rows.add_diagonal(StabilityRows::stiffness, i, Kb);
    rows.add_diagonal(StabilityRows::stiffness, j, Kb);
    rows.add_offdiagonal(StabilityRows::stiffness, i, j, Kb);
    rows.add_diagonal(StabilityRows::damping, i, Cb);
    rows.add_diagonal(StabilityRows::damping, j, Cb);
    rows.add_offdiagonal(StabilityRows::damping, i, j, Cb);
  }
}

}  // namespace sewn::physics
