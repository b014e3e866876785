#include "sewn/physics/springs.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <string>

#if defined(__AVX512F__) && defined(__AVX512VL__)
#include <immintrin.h>
#define SEWN_SPRINGS_AVX512 1
#endif

#include "sewn/physics/errors.hpp"
#include "sewn/physics/nodes.hpp"
#include "spring_frame.hpp"

namespace sewn::physics {

namespace {

using detail::degenerate_ratio_sq;

std::string sp(Index s) { return "spring " + std::to_string(s); }

void check_param(double value, const char* what, const char* where, Index s) {
  if (!(std::isfinite(value) && value >= 0))
    throw InputError(std::string(where) + ": " + what + " of " + sp(s) + " must be finite and >= 0, got " +
                     std::to_string(value));
}

// Everything the force loop reads, as raw pointers (no aliasing between them). Node rows are
// 4 doubles, [x y z 0], so each spring end is one aligned 256-bit access that never splits a
// cache line (masked 3-double reads of the 3n arrays did, and cost ~25% of the loop).
struct Kernel {
  const double* __restrict x;  // 4 per node
  const double* __restrict v;  // 4 per node
  double* __restrict acc;      // 4 per node
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
  const double* xi = K.x + 4 * i;
  const double* xj = K.x + 4 * j;
  const double dx = xj[0] - xi[0], dy = xj[1] - xi[1], dz = xj[2] - xi[2];
  const double d2 = dx * dx + dy * dy + dz * dz;
  const double l = K.l[s];
  if (d2 <= degenerate_ratio_sq * l * l) return;  // NaN goes on, to be caught downstream
  const double inv = 1.0 / std::sqrt(d2);
  double c = K.k[s] * (1.0 - l * inv);
  double e = 0.0;  // coefficient of ΔV (Rayleigh only)
  double ux = 0, uy = 0, uz = 0;
  if constexpr (D != SpringDamping::none) {
    const double* vi = K.v + 4 * i;
    const double* vj = K.v + 4 * j;
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
// Four springs at a time, each kept as its row [dx dy dz 0]. Gathers are slow (about one
// element per cycle), hence one row load per spring end. The two dot products a spring needs
// (d·d and Δv·d) are horizontal sums of rows, and its force is its row times its scalar
// coefficient broadcast: fewer shuffles than transposing four rows to x/y/z vectors and back.
// 1/d comes from rsqrt14 plus two Newton steps (relative error ~1e-16, no division or sqrt).
inline __m256d hsum4(__m256d p0, __m256d p1, __m256d p2, __m256d p3) {
  const __m256d t0 = _mm256_hadd_pd(p0, p1), t1 = _mm256_hadd_pd(p2, p3);
  return _mm256_add_pd(_mm256_permute2f128_pd(t0, t1, 0x21), _mm256_blend_pd(t0, t1, 0b1100));
}

inline __m256d inv_sqrt(__m256d d2) {
  const __m256d half = _mm256_set1_pd(0.5), three_halves = _mm256_set1_pd(1.5);
  const __m256d hd = _mm256_mul_pd(half, d2);
  __m256d y = _mm256_rsqrt14_pd(d2);
  y = _mm256_mul_pd(y, _mm256_fnmadd_pd(hd, _mm256_mul_pd(y, y), three_halves));
  y = _mm256_mul_pd(y, _mm256_fnmadd_pd(hd, _mm256_mul_pd(y, y), three_halves));
  return y;
}

inline __m256d lane(__m256d c, int q) {
  switch (q) {
    case 0: return _mm256_permute4x64_pd(c, 0x00);
    case 1: return _mm256_permute4x64_pd(c, 0x55);
    case 2: return _mm256_permute4x64_pd(c, 0xAA);
    default: return _mm256_permute4x64_pd(c, 0xFF);
  }
}

template <SpringDamping D>
inline void springs_x4(const Kernel& K, Index s) {
  std::size_t i[4], j[4];
  __m256d d[4], u[4], dd[4], du[4];
  for (int q = 0; q < 4; ++q) {
    i[q] = K.ni[s + q];
    j[q] = K.nj[s + q];
    d[q] = _mm256_sub_pd(_mm256_load_pd(K.x + 4 * j[q]), _mm256_load_pd(K.x + 4 * i[q]));
    dd[q] = _mm256_mul_pd(d[q], d[q]);
    if constexpr (D != SpringDamping::none) {
      u[q] = _mm256_sub_pd(_mm256_load_pd(K.v + 4 * j[q]), _mm256_load_pd(K.v + 4 * i[q]));
      du[q] = _mm256_mul_pd(d[q], u[q]);
    }
  }
  const __m256d d2 = hsum4(dd[0], dd[1], dd[2], dd[3]);
  const __m256d l = _mm256_loadu_pd(K.l + s);
  const __m256d k = _mm256_loadu_pd(K.k + s);
  const __m256d one = _mm256_set1_pd(1.0);
  // Ordered compare: a NaN length fails it, c becomes 0 but c·d stays NaN.
  const __mmask8 ok = _mm256_cmp_pd_mask(d2, _mm256_mul_pd(_mm256_set1_pd(degenerate_ratio_sq), _mm256_mul_pd(l, l)),
                                         _CMP_GT_OQ);
  const __m256d inv = inv_sqrt(d2);
  const __m256d linv = _mm256_mul_pd(l, inv);
  __m256d c = _mm256_mul_pd(k, _mm256_sub_pd(one, linv));
  __m256d e = _mm256_setzero_pd();
  if constexpr (D != SpringDamping::none) {
    const __m256d w = _mm256_mul_pd(hsum4(du[0], du[1], du[2], du[3]), _mm256_mul_pd(inv, inv));
    if constexpr (D == SpringDamping::viscous) {
      c = _mm256_fmadd_pd(_mm256_loadu_pd(K.g + s), w, c);
    } else {
      const __m256d cl = _mm256_max_pd(_mm256_sub_pd(one, linv), _mm256_setzero_pd());
      const __m256d bk = _mm256_mul_pd(_mm256_set1_pd(K.beta), k);
      c = _mm256_fmadd_pd(_mm256_mul_pd(bk, _mm256_sub_pd(one, cl)), w, c);
      e = _mm256_maskz_mov_pd(ok, _mm256_mul_pd(bk, cl));
    }
  }
  c = _mm256_maskz_mov_pd(ok, c);
  for (int q = 0; q < 4; ++q) {
    __m256d fq = _mm256_mul_pd(lane(c, q), d[q]);
    if constexpr (D == SpringDamping::stiffness_proportional) fq = _mm256_fmadd_pd(lane(e, q), u[q], fq);
    double* ai = K.acc + 4 * i[q];
    double* aj = K.acc + 4 * j[q];
    _mm256_store_pd(ai, _mm256_add_pd(_mm256_load_pd(ai), fq));
    _mm256_store_pd(aj, _mm256_sub_pd(_mm256_load_pd(aj), fq));
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

// 3n node-major values -> rows of 4 ([x y z 0] per node).
void to_rows(std::span<const double> in, double* __restrict out, std::size_t n) {
  const double* __restrict a = in.data();
  std::size_t p = 0;
#ifdef SEWN_SPRINGS_AVX512
  // Four nodes: 12 values -> 16 by two permutes that zero the padding lanes.
  const __m512i lo_idx = _mm512_setr_epi64(0, 1, 2, 0, 3, 4, 5, 0);
  const __m512i hi_idx = _mm512_setr_epi64(6, 7, 8, 0, 9, 10, 11, 0);
  for (; p + 4 <= n; p += 4) {
    const __m512d a0 = _mm512_loadu_pd(a + 3 * p);
    const __m512d a1 = _mm512_maskz_loadu_pd(0x0F, a + 3 * p + 8);
    _mm512_store_pd(out + 4 * p, _mm512_maskz_permutex2var_pd(0x77, a0, lo_idx, a1));
    _mm512_store_pd(out + 4 * p + 8, _mm512_maskz_permutex2var_pd(0x77, a0, hi_idx, a1));
  }
#endif
  for (; p < n; ++p) {
    out[4 * p] = a[3 * p];
    out[4 * p + 1] = a[3 * p + 1];
    out[4 * p + 2] = a[3 * p + 2];
    out[4 * p + 3] = 0.0;
  }
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
  runs_.on_added(s);
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
  runs_.on_removed(s);
  touch_topology();
}

void Springs::set_stiffness(Index s, double k) {
  check_spring(s, "Springs::set_stiffness");
  check_param(k, "stiffness", "Springs::set_stiffness", s);
  k_[s] = k;
  runs_.on_parameters_changed(s, k_[s], l_[s], gamma_[s]);
  touch_parameters();
}

void Springs::set_rest_length(Index s, double l) {
  check_spring(s, "Springs::set_rest_length");
  check_param(l, "rest length", "Springs::set_rest_length", s);
  l_[s] = l;
  runs_.on_parameters_changed(s, k_[s], l_[s], gamma_[s]);
  touch_parameters();
}

void Springs::set_viscosity(Index s, double gamma) {
  check_spring(s, "Springs::set_viscosity");
  check_param(gamma, "viscosity", "Springs::set_viscosity", s);
  gamma_[s] = gamma;
  runs_.on_parameters_changed(s, k_[s], l_[s], gamma_[s]);
  touch_parameters();
}

void Springs::set_endpoints(Index s, Index i, Index j) {
  check_spring(s, "Springs::set_endpoints");
  if (i == j) throw InputError("Springs::set_endpoints: " + sp(s) + " would join node " + std::to_string(i) + " to itself");
  if (i == invalid_index || j == invalid_index) throw InputError("Springs::set_endpoints: invalid node index for " + sp(s));
  ni_[s] = i;
  nj_[s] = j;
  max_node_ = std::max({max_node_, i, j});
  runs_.on_endpoints_changed(s);
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
  runs_.refresh_parameters(arrays());
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
  runs_.invalidate();
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
  runs_.invalidate();
  touch_topology();
}

void Springs::add_forces(const StateView& st, std::span<double> f) const { forces(st, f, true); }

void Springs::set_forces(const StateView& st, std::span<double> f) const { forces(st, f, false); }

void Springs::forces(const StateView& st, std::span<double> f, bool accumulate) const {
  const Index n = st.size();
  if (size() == 0) {
    if (!accumulate) std::fill(f.begin(), f.end(), 0.0);
    return;
  }
  if (max_node_ >= n)
    throw InputError("springs: a spring refers to node " + std::to_string(max_node_) + " but the state has " +
                     std::to_string(n) + " nodes");
  if (runs_.needs_rebuild()) runs_.rebuild(arrays());
  if (runs_.worthwhile()) {
    static_assert(int(SpringDamping::none) == int(detail::RunDamping::none) &&
                  int(SpringDamping::viscous) == int(detail::RunDamping::viscous) &&
                  int(SpringDamping::stiffness_proportional) == int(detail::RunDamping::stiffness_proportional));
    runs_.forces(arrays(), static_cast<detail::RunDamping>(damping_), beta_, st.x, st.v, f, accumulate, n);
    return;
  }
  forces_by_rows(st, f, accumulate);
}

detail::SpringArrays Springs::arrays() const {
  return {ni_.data(), nj_.data(), k_.data(), l_.data(), gamma_.data(), alive_.data(), size()};
}

void Springs::forces_by_rows(const StateView& st, std::span<double> f, bool accumulate) const {
  const Index n = st.size();
  const std::size_t n4 = 4 * std::size_t{n};
  // acc_ is all zeros between calls (the scatter below clears what it reads).
  if (acc_.size() != n4) {
    // Out of room (first call, or a cut added nodes): fresh rows with headroom, so that the
    // next cuts resize in place; nothing is copied over, to_rows rewrites every row.
    if (acc_.capacity() < n4)
      for (auto* rows : {&acc_, &x_rows_, &v_rows_}) {
        rows->clear();
        rows->reserve(n4 + n4 / 4);
      }
    acc_.resize(n4, 0.0);
    x_rows_.resize(n4);
    v_rows_.resize(n4);
  }
  to_rows(st.x, x_rows_.data(), n);
  if (damping_ != SpringDamping::none) to_rows(st.v, v_rows_.data(), n);
  const Kernel K{x_rows_.data(), v_rows_.data(), acc_.data(), ni_.data(), nj_.data(), k_.data(), l_.data(), gamma_.data(), beta_};
  const Index count = size();
  switch (damping_) {
    case SpringDamping::none: spring_loop<SpringDamping::none>(K, count); break;
    case SpringDamping::viscous: spring_loop<SpringDamping::viscous>(K, count); break;
    case SpringDamping::stiffness_proportional: spring_loop<SpringDamping::stiffness_proportional>(K, count); break;
  }
  double* __restrict a = acc_.data();
  double* __restrict out = f.data();
  std::size_t p = 0;
#ifdef SEWN_SPRINGS_AVX512
  // Four nodes: 16 padded accumulator values -> 12 consecutive forces, by two permutes. The
  // last 4 are written by a 256-bit store: a masked 512-bit one would block the next
  // iteration's load, which overlaps its footprint, until it retires.
  const __m512i first8 = _mm512_setr_epi64(0, 1, 2, 4, 5, 6, 8, 9);
  const __m256i last4 = _mm256_setr_epi64x(2, 4, 5, 6);  // of acc lanes 8..15
  const __m512d zero = _mm512_setzero_pd();
  for (; p + 4 <= n; p += 4) {
    double* ap = a + 4 * p;
    const __m512d lo = _mm512_load_pd(ap), hi = _mm512_load_pd(ap + 8);
    const __m256d tail = _mm256_permutex2var_pd(_mm256_load_pd(ap + 8), last4, _mm256_load_pd(ap + 12));
    _mm512_store_pd(ap, zero);
    _mm512_store_pd(ap + 8, zero);
    double* o = out + 3 * p;
    __m512d head = _mm512_permutex2var_pd(lo, first8, hi);
    __m256d last = tail;
    if (accumulate) {
      head = _mm512_add_pd(_mm512_loadu_pd(o), head);
      last = _mm256_add_pd(_mm256_loadu_pd(o + 8), last);
    }
    _mm512_storeu_pd(o, head);
    _mm256_storeu_pd(o + 8, last);
  }
#endif
  for (; p < n; ++p) {
    for (std::size_t c = 0; c < 3; ++c) {
      out[3 * p + c] = accumulate ? out[3 * p + c] + a[4 * p + c] : a[4 * p + c];
      a[4 * p + c] = 0.0;
    }
  }
}

double Springs::potential_energy(const StateView& st) const {
  // The energy watchdog and the ledger call this at every check: eight partial sums, one per
  // lane, let the loop vectorise (gathers, vector sqrt) without the reassociation one running
  // sum would need (no -ffast-math); a removed spring reads node 0 and adds nothing.
  constexpr std::size_t lanes = 8;
  const std::size_t m = size();
  if (st.x.empty() || m == 0) return 0.0;
  if (max_node_ >= st.size())
    throw InputError("springs: a spring refers to node " + std::to_string(max_node_) + " but the state has " +
                     std::to_string(st.size()) + " nodes");
  // the force pass's chunks read the nodes in order where this loop gathers them: the
  // watchdog's baseline after a cut, two energies, cost more than the step itself before
  if (runs_.needs_rebuild()) runs_.rebuild(arrays());
  if (double e = 0; runs_.worthwhile() && runs_.potential_energy(arrays(), st.x, st.size(), e)) return e;
  const double* __restrict x = st.x.data();
  const Index* __restrict ni = ni_.data();
  const Index* __restrict nj = nj_.data();
  const double* __restrict k = k_.data();
  const double* __restrict l = l_.data();
  const std::uint8_t* __restrict alive = alive_.data();
  const auto one = [&](std::size_t s) {
    const bool live = alive[s] != 0;
    const std::size_t i = live ? 3 * std::size_t{ni[s]} : 0, j = live ? 3 * std::size_t{nj[s]} : 0;
    const double dx = x[j] - x[i], dy = x[j + 1] - x[i + 1], dz = x[j + 2] - x[i + 2];
    const double t = std::sqrt(dx * dx + dy * dy + dz * dz) - l[s];
    return live ? 0.5 * k[s] * t * t : 0.0;
  };
  double part[lanes] = {};
  std::size_t s = 0;
  for (; s + lanes <= m; s += lanes)
    for (std::size_t q = 0; q < lanes; ++q) part[q] += one(s + q);
  double e = 0.0;
  for (; s < m; ++s) e += one(s);
  for (const double p : part) e += p;
  return e;
}

double Springs::dissipation(const StateView& st) const {
  if (damping_ == SpringDamping::none) return 0.0;
  double psi = 0.0;
  for (Index s = 0; s < size(); ++s) {
    if (alive_[s] == 0) continue;
    const detail::SpringFrame fr = detail::spring_frame(st, ni_[s], nj_[s], l_[s]);
    if (!fr.ok) continue;  // no direction: no force, so no potential either
    const Eigen::Vector3d dv = detail::vel_diff(st, ni_[s], nj_[s]);
    const double along = dv.dot(fr.dx) / fr.d;
    if (damping_ == SpringDamping::viscous) {
      psi += 0.5 * gamma_[s] * along * along;
    } else {
      // ½ β ΔVᵀK_sΔV with K_s = k[UUᵀ + c(I - UUᵀ)], c = max(0, 1 - l/d), as the force loop.
      const double c = std::max(0.0, 1.0 - l_[s] / fr.d);
      psi += 0.5 * beta_ * k_[s] * ((1.0 - c) * along * along + c * dv.squaredNorm());
    }
  }
  return psi;
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

void Springs::add_stability_rows(const StateView& st, StabilityRows& rows) const {
  if (size() == 0) return;
  if (max_node_ >= st.size())
    throw InputError("springs: a spring refers to node " + std::to_string(max_node_) + " but the state has " +
                     std::to_string(st.size()) + " nodes");
  if (runs_.needs_rebuild()) runs_.rebuild(arrays());
  if (runs_.worthwhile() && runs_.stability_rows(static_cast<detail::RunDamping>(damping_), beta_, st.x, st.size(), rows)) {
    stability_rows_of(runs_.rest(), st, rows);
    return;
  }
  std::vector<Index> all(size());
  std::iota(all.begin(), all.end(), Index{0});
  stability_rows_of(all, st, rows);
}

void Springs::stability_rows_of(std::span<const Index> springs, const StateView& st, StabilityRows& rows) const {
  using Sym = StabilityRows::SymBlock;
  // 1/d first, in a pass of its own: with the square root and the division inside the
  // accumulation loop, each spring's long dependency chain left the core waiting (measured:
  // 1.3-1.45x slower on hexahedral grids). 0 marks a spring with no direction.
  std::vector<double> inv_d(springs.size());
  for (std::size_t t = 0; t < springs.size(); ++t) {
    const Index s = springs[t], i = ni_[s], j = nj_[s];
    const double dx = st.x[3 * j] - st.x[3 * i], dy = st.x[3 * j + 1] - st.x[3 * i + 1], dz = st.x[3 * j + 2] - st.x[3 * i + 2];
    const double d2 = dx * dx + dy * dy + dz * dz;
    inv_d[t] = d2 > degenerate_ratio_sq * l_[s] * l_[s] ? 1.0 / std::sqrt(d2) : 0.0;
  }
  for (std::size_t t = 0; t < springs.size(); ++t) {
    const Index s = springs[t];
    if (alive_[s] == 0) continue;
    const Index i = ni_[s], j = nj_[s];
    // K = k (U Uᵀ + c (I - U Uᵀ)), c = max(0, 1 - l/d) (compression clamped); C = γ U Uᵀ
    // (viscous) or β K (Rayleigh). The chunk kernel (SpringRuns::stability_rows) is the same.
    Sym K, UU;
    if (const double w = inv_d[t]; w > 0) {
      const double u0 = (st.x[3 * j] - st.x[3 * i]) * w, u1 = (st.x[3 * j + 1] - st.x[3 * i + 1]) * w,
                   u2 = (st.x[3 * j + 2] - st.x[3 * i + 2]) * w;
      UU = {u0 * u0, u1 * u1, u2 * u2, u0 * u1, u0 * u2, u1 * u2};
      const double c = std::max(0.0, 1.0 - l_[s] * w);
      const double k = k_[s], kc = k * c, k1c = k * (1.0 - c);
      K = {k1c * UU[0] + kc, k1c * UU[1] + kc, k1c * UU[2] + kc, k1c * UU[3], k1c * UU[4], k1c * UU[5]};
    } else {
      // no direction (or a NaN state): bound the block by its largest possible norm
      UU = {1, 1, 1, 0, 0, 0};
      K = {k_[s], k_[s], k_[s], 0, 0, 0};
    }
    Sym C{};
    if (damping_ == SpringDamping::viscous)
      for (int e = 0; e < 6; ++e) C[e] = gamma_[s] * UU[e];
    else if (damping_ == SpringDamping::stiffness_proportional)
      for (int e = 0; e < 6; ++e) C[e] = beta_ * K[e];
    rows.add_pair(i, j, K, C);
  }
}

}  // namespace sewn::physics
