// The springs' Jacobian assembly (Springs::add_jacobians), the half of a linearly implicit step
// that is not the solve on lattices (docs/solvers.md). Two phases: each spring's 3×3 block
// B = cx·∂F_i/∂x_j + cv·∂F_i/∂v_j and product ∂F_i/∂x_j·p into per-spring arrays, then those
// added into the four blocks (i,j), (j,i), (i,i), (j,j) of the matrix, whose slots bind_pattern()
// found once per pattern, and into product_out.
//
// Every Jacobian the solvers use is symmetric (viscous damping with its position terms dropped,
// or no damping, or Rayleigh's): then each block is a·I + b·UUᵀ, computed from two scalars and
// the direction. Only the exact viscous Jacobian (non-symmetric, for checks)
// takes the general 9-entry path.

#include <algorithm>
#include <cmath>

#if defined(__AVX__)
#include <immintrin.h>
#endif

#include "sewn/physics/block_matrix.hpp"
#include "sewn/physics/errors.hpp"
#include "sewn/physics/springs.hpp"
#include "parallel/ranges.hpp"
#include "spring_frame.hpp"

namespace sewn::physics {

namespace {

// dst += b (sign +1) or dst −= b, entry by entry: 8 entries in one vector where the machine has
// them (the build disables the compiler's straight-line vectorization), the same sums either way.
template <int Sign>
inline void add_block(double* __restrict dst, const double* __restrict b) {
#if defined(__AVX512F__)
  const __m512d d = _mm512_loadu_pd(dst), v = _mm512_loadu_pd(b);
  _mm512_storeu_pd(dst, Sign > 0 ? _mm512_add_pd(d, v) : _mm512_sub_pd(d, v));
#elif defined(__AVX__)
  for (int h = 0; h < 8; h += 4) {
    const __m256d d = _mm256_loadu_pd(dst + h), v = _mm256_loadu_pd(b + h);
    _mm256_storeu_pd(dst + h, Sign > 0 ? _mm256_add_pd(d, v) : _mm256_sub_pd(d, v));
  }
#else
  for (int k = 0; k < 8; ++k) dst[k] = Sign > 0 ? dst[k] + b[k] : dst[k] - b[k];
#endif
  dst[8] = Sign > 0 ? dst[8] + b[8] : dst[8] - b[8];
}

}  // namespace

// Spring s's Jacobian blocks: Jx = ∂F_i/∂x_j (as used in the product) and B = cx·Jx + cv·Jv,
// the block the matrix receives. False if the spring is too short to have a direction.
bool Springs::spring_jacobian(const StateView& st, const JacobianRequest& req, Index s, Eigen::Matrix3d& Jx,
                              Eigen::Matrix3d& B) const {
  const Index i = ni_[s], j = nj_[s];
  const double k = k_[s], l = l_[s];
  const detail::SpringFrame fr = detail::spring_frame(st, i, j, l);
  if (!fr.ok) return false;
  const Eigen::Matrix3d I = Eigen::Matrix3d::Identity();
  const Eigen::Vector3d U = fr.dx / fr.d;
  const Eigen::Matrix3d UU = U * U.transpose();
  const Eigen::Matrix3d Q = I - UU;
  const double stretch = 1.0 - l / fr.d;
  const double cl = req.options.clamp_compression ? std::max(0.0, stretch) : stretch;
  Jx = k * (UU + cl * Q);
  Eigen::Matrix3d Jv = Eigen::Matrix3d::Zero();
  if (damping_ == SpringDamping::viscous) {
    const double gamma = gamma_[s];
    if (!req.options.drop_viscous_position_terms) {
      const Eigen::Vector3d dv = detail::vel_diff(st, i, j);
      const double w = dv.dot(U);
      Jx += (gamma / fr.d) * (w * Q + U * (dv.transpose() * Q));
    }
    Jv = gamma * UU;
  } else if (damping_ == SpringDamping::stiffness_proportional) {
    Jv = beta_ * k * (UU + std::max(0.0, stretch) * Q);
  }
  B = req.cx * Jx + req.cv * Jv;
  return true;
}

Eigen::Vector3d Springs::spring_product(const JacobianRequest& req, Index s, const Eigen::Matrix3d& Jx) const {
  const Index i = ni_[s], j = nj_[s];
  const Eigen::Vector3d p(req.product_in[3 * j] - req.product_in[3 * i], req.product_in[3 * j + 1] - req.product_in[3 * i + 1],
                          req.product_in[3 * j + 2] - req.product_in[3 * i + 2]);
  return Jx * p;
}

void Springs::general_blocks(const StateView& st, const JacobianRequest& req, Index s0, Index s1, double* blocks,
                             double* products, std::uint8_t* ok) const {
  const bool product = !req.product_in.empty();
  Eigen::Matrix3d Jx, B;
  for (Index s = s0; s < s1; ++s) {
    const std::size_t o = s - s0;
    ok[o] = alive_[s] != 0 && spring_jacobian(st, req, s, Jx, B) ? 1 : 0;
    if (ok[o] == 0) continue;
    Eigen::Map<Eigen::Matrix3d>(blocks + 9 * o) = B;
    if (product) Eigen::Map<Eigen::Vector3d>(products + 3 * o) = spring_product(req, s, Jx);
  }
}

// With U the direction, Jx = ax·I + bx·UUᵀ (ax = k·c, bx = k − ax, c = 1 − l/d clamped or not)
// and Jv = av·I + bv·UUᵀ (viscous: 0, γ; Rayleigh: β·k·max(0, 1 − l/d), β·k − av), so
// B = a·I + b·UUᵀ with a = cx·ax + cv·av, b = cx·bx + cv·bv, and Jx·p = ax·p + bx·(U·p)·U:
// the same numbers as spring_jacobian's 3×3 products, to round-off, for a fraction of the work.
void Springs::symmetric_blocks(const StateView& st, const JacobianRequest& req, Index s0, Index s1,
                               double* __restrict blocks, double* __restrict products,
                               std::uint8_t* __restrict ok) const {
  const bool clamp = req.options.clamp_compression;
  const bool product = !req.product_in.empty();
  const double cx = req.cx, cv = req.cv;
  const double* __restrict x = st.x.data();
  const double* __restrict p = product ? req.product_in.data() : nullptr;
  Index s = s0;
#if defined(__AVX512F__)
  // Groups of 8 springs from s0 (a multiple of 8, as every caller's ranges start): the same
  // spring is in a group whatever the thread count, so the results do not depend on it.
  for (; s + 8 <= s1; s += 8) symmetric_group(st, req, s, blocks + 9 * std::size_t{s - s0}, products + 3 * std::size_t{s - s0}, ok + (s - s0));
#endif
  for (; s < s1; ++s) {
    const std::size_t o = s - s0;
    const std::size_t i = 3 * std::size_t{ni_[s]}, j = 3 * std::size_t{nj_[s]};
    const double k = k_[s], l = l_[s];
    const double d0 = x[j] - x[i], d1 = x[j + 1] - x[i + 1], d2 = x[j + 2] - x[i + 2];
    const double dd = d0 * d0 + d1 * d1 + d2 * d2;
    const bool has = alive_[s] != 0 && dd > detail::degenerate_ratio_sq * l * l;
    ok[o] = has ? 1 : 0;
    if (!has) continue;
    const double inv = 1.0 / std::sqrt(dd);
    const double u0 = d0 * inv, u1 = d1 * inv, u2 = d2 * inv;
    const double stretch = 1.0 - l * inv;
    const double ax = k * (clamp ? std::max(0.0, stretch) : stretch);
    const double bx = k - ax;
    double av = 0, bv = 0;
    if (damping_ == SpringDamping::viscous) {
      bv = gamma_[s];
    } else if (damping_ == SpringDamping::stiffness_proportional) {
      av = beta_ * k * std::max(0.0, stretch);
      bv = beta_ * k - av;
    }
    const double a = cx * ax + cv * av, b = cx * bx + cv * bv;
    const double b01 = b * u0 * u1, b02 = b * u0 * u2, b12 = b * u1 * u2;
    double* B = blocks + 9 * o;  // column-major, as the matrix's blocks
    B[0] = a + b * u0 * u0;
    B[1] = b01;
    B[2] = b02;
    B[3] = b01;
    B[4] = a + b * u1 * u1;
    B[5] = b12;
    B[6] = b02;
    B[7] = b12;
    B[8] = a + b * u2 * u2;
    if (product) {
      const double p0 = p[j] - p[i], p1 = p[j + 1] - p[i + 1], p2 = p[j + 2] - p[i + 2];
      const double w = bx * (u0 * p0 + u1 * p1 + u2 * p2);
      double* q = products + 3 * o;
      q[0] = ax * p0 + w * u0;
      q[1] = ax * p1 + w * u1;
      q[2] = ax * p2 + w * u2;
    }
  }
}

#if defined(__AVX512F__)
// symmetric_blocks for springs [s, s + 8), one spring a lane (the same formulas).
void Springs::symmetric_group(const StateView& st, const JacobianRequest& req, Index s, double* __restrict blocks,
                              double* __restrict products, std::uint8_t* __restrict ok) const {
  const __m512d one = _mm512_set1_pd(1.0), zero = _mm512_setzero_pd();
  const __m256i three = _mm256_set1_epi32(3);
  const __m256i i3 = _mm256_mullo_epi32(_mm256_loadu_si256(reinterpret_cast<const __m256i*>(ni_.data() + s)), three);
  const __m256i j3 = _mm256_mullo_epi32(_mm256_loadu_si256(reinterpret_cast<const __m256i*>(nj_.data() + s)), three);
  const double* x = st.x.data();
  __m512d d[3];
  for (int a = 0; a < 3; ++a)
    d[a] = _mm512_sub_pd(_mm512_i32gather_pd(j3, x + a, 8), _mm512_i32gather_pd(i3, x + a, 8));
  const __m512d dd = _mm512_fmadd_pd(d[2], d[2], _mm512_fmadd_pd(d[1], d[1], _mm512_mul_pd(d[0], d[0])));
  const __m512d k = _mm512_loadu_pd(k_.data() + s), l = _mm512_loadu_pd(l_.data() + s);
  const __mmask8 long_enough =
      _mm512_cmp_pd_mask(dd, _mm512_mul_pd(_mm512_set1_pd(detail::degenerate_ratio_sq), _mm512_mul_pd(l, l)), _CMP_GT_OQ);
  for (int q = 0; q < 8; ++q) ok[q] = alive_[s + q] != 0 && ((long_enough >> q) & 1) != 0 ? 1 : 0;
  const __m512d inv = _mm512_div_pd(one, _mm512_sqrt_pd(dd));
  const __m512d u[3] = {_mm512_mul_pd(d[0], inv), _mm512_mul_pd(d[1], inv), _mm512_mul_pd(d[2], inv)};
  const __m512d stretch = _mm512_fnmadd_pd(l, inv, one);
  const __m512d ax = _mm512_mul_pd(k, req.options.clamp_compression ? _mm512_max_pd(zero, stretch) : stretch);
  const __m512d bx = _mm512_sub_pd(k, ax);
  __m512d av = zero, bv = zero;
  if (damping_ == SpringDamping::viscous) {
    bv = _mm512_loadu_pd(gamma_.data() + s);
  } else if (damping_ == SpringDamping::stiffness_proportional) {
    const __m512d bk = _mm512_mul_pd(_mm512_set1_pd(beta_), k);
    av = _mm512_mul_pd(bk, _mm512_max_pd(zero, stretch));
    bv = _mm512_sub_pd(bk, av);
  }
  const __m512d cx = _mm512_set1_pd(req.cx), cv = _mm512_set1_pd(req.cv);
  const __m512d a = _mm512_fmadd_pd(cv, av, _mm512_mul_pd(cx, ax));
  const __m512d b = _mm512_fmadd_pd(cv, bv, _mm512_mul_pd(cx, bx));
  // The 9 entries (column-major) lane by lane, then each spring's block stored whole.
  alignas(64) double e[9][8];
  for (int r = 0; r < 3; ++r) {
    const __m512d bu = _mm512_mul_pd(b, u[r]);
    _mm512_store_pd(e[4 * r], _mm512_fmadd_pd(bu, u[r], a));
    for (int c = r + 1; c < 3; ++c) {
      const __m512d off = _mm512_mul_pd(bu, u[c]);
      _mm512_store_pd(e[3 * c + r], off);
      _mm512_store_pd(e[3 * r + c], off);
    }
  }
  for (int q = 0; q < 8; ++q)
    for (int m = 0; m < 9; ++m) blocks[9 * q + m] = e[m][q];
  if (req.product_in.empty()) return;
  const double* p = req.product_in.data();
  __m512d pd[3];
  for (int c = 0; c < 3; ++c)
    pd[c] = _mm512_sub_pd(_mm512_i32gather_pd(j3, p + c, 8), _mm512_i32gather_pd(i3, p + c, 8));
  const __m512d w = _mm512_mul_pd(bx, _mm512_fmadd_pd(u[2], pd[2], _mm512_fmadd_pd(u[1], pd[1], _mm512_mul_pd(u[0], pd[0]))));
  for (int c = 0; c < 3; ++c) _mm512_store_pd(e[c], _mm512_fmadd_pd(w, u[c], _mm512_mul_pd(ax, pd[c])));
  for (int q = 0; q < 8; ++q)
    for (int c = 0; c < 3; ++c) products[3 * q + c] = e[c][q];
}
#endif

void Springs::add_jacobians(const StateView& st, const JacobianRequest& req) const {
  if (req.matrix != nullptr &&
      (req.matrix->pattern_version() != bound_pattern_ || bound_topology_ != topology_version()))
    throw InputError("springs: add_jacobians on a pattern that is not bound to the current springs; call System::refresh()");
  const bool symmetric = jacobian_symmetric(req.options);
  // A large model takes the two phases even on one thread: the chunked scatter adds each
  // spring's four blocks where they lie, sweeping a matrix far larger than the cache once per
  // spring direction (springs come numbered by kind), where the per-node gather writes each row
  // of blocks once (docs/solvers.md, Threads).
  if (const int parts = detail::parts_for(size(), jacobian_grain); parts > 1 || size() >= jacobian_gather_min) {
    if (symmetric)
      add_jacobians_threads<true>(st, req, parts);
    else
      add_jacobians_threads<false>(st, req, parts);
  } else if (symmetric) {
    add_jacobians_serial<true>(st, req);
  } else {
    add_jacobians_serial<false>(st, req);
  }
}

// Chunk by chunk, so that the per-spring arrays stay in cache between the two phases; each
// block receives its springs' additions in increasing spring order.
template <bool Symmetric>
void Springs::add_jacobians_serial(const StateView& st, const JacobianRequest& req) const {
  const bool product = !req.product_in.empty();
  jac_blocks_.resize(9 * std::size_t{jacobian_chunk});
  jac_products_.resize(3 * std::size_t{jacobian_chunk});
  jac_ok_.resize(jacobian_chunk);
  for (Index s0 = 0; s0 < size(); s0 += jacobian_chunk) {
    const Index s1 = std::min(size(), s0 + jacobian_chunk);
    if constexpr (Symmetric)
      symmetric_blocks(st, req, s0, s1, jac_blocks_.data(), jac_products_.data(), jac_ok_.data());
    else
      general_blocks(st, req, s0, s1, jac_blocks_.data(), jac_products_.data(), jac_ok_.data());
    for (Index s = s0; s < s1; ++s) {
      const std::size_t o = s - s0;
      if (jac_ok_[o] == 0) continue;
      if (req.matrix != nullptr) {
        const double* b = jac_blocks_.data() + 9 * o;
        add_block<1>(req.matrix->block(slot_ij_[s]).data(), b);
        add_block<1>(req.matrix->block(slot_ji_[s]).data(), b);
        add_block<-1>(req.matrix->block(slot_ii_[s]).data(), b);
        add_block<-1>(req.matrix->block(slot_jj_[s]).data(), b);
      }
      if (product) {
        const double* q = jac_products_.data() + 3 * o;
        for (int a = 0; a < 3; ++a) {
          req.product_out[3 * std::size_t{ni_[s]} + a] += q[a];
          req.product_out[3 * std::size_t{nj_[s]} + a] -= q[a];
        }
      }
    }
  }
}

// Each node's springs, 2s at the spring's i end and 2s + 1 at its j end, in spring order;
// rebuilt when the topology changes.
void Springs::build_incidence(Index n) const {
  if (incidence_topology_ == topology_version() && incidence_row_.size() == std::size_t{n} + 1) return;
  const Index m = size();
  incidence_row_.assign(std::size_t{n} + 1, 0);
  for (Index s = 0; s < m; ++s)
    if (alive_[s] != 0) {
      ++incidence_row_[ni_[s] + 1];
      ++incidence_row_[nj_[s] + 1];
    }
  for (Index i = 0; i < n; ++i) incidence_row_[i + 1] += incidence_row_[i];
  incidence_.resize(incidence_row_[n]);
  std::vector<Index> fill(incidence_row_.begin(), incidence_row_.end() - 1);
  for (Index s = 0; s < m; ++s)  // increasing s: each node's list is in spring order
    if (alive_[s] != 0) {
      incidence_[fill[ni_[s]]++] = 2 * s;
      incidence_[fill[nj_[s]]++] = 2 * s + 1;
    }
  incidence_topology_ = topology_version();
}

// Phase one over ranges of springs, phase two over ranges of nodes, each node gathering its
// springs' blocks in increasing spring order: each matrix block and product entry receives the
// same additions in the same order as on one thread, so the result is the same bitwise, and no
// two threads write one block.
template <bool Symmetric>
void Springs::add_jacobians_threads(const StateView& st, const JacobianRequest& req, int parts) const {
  const Index n = st.size();
  const Index m = size();
  build_incidence(n);
  const bool product = !req.product_in.empty();
  jac_blocks_.resize(9 * std::size_t{m});
  jac_products_.resize(3 * std::size_t{m});
  jac_ok_.resize(m);
  detail::run_parts(parts, [&](int t) {
    // ranges start at multiples of 8 springs: the same groups of 8 as on one thread
    const auto s0 = static_cast<Index>(detail::range_begin(m, parts, t) / 8 * 8);
    const auto s1 = t + 1 == parts ? m : static_cast<Index>(detail::range_begin(m, parts, t + 1) / 8 * 8);
    double* blocks = jac_blocks_.data() + 9 * std::size_t{s0};
    double* products = jac_products_.data() + 3 * std::size_t{s0};
    if constexpr (Symmetric)
      symmetric_blocks(st, req, s0, s1, blocks, products, jac_ok_.data() + s0);
    else
      general_blocks(st, req, s0, s1, blocks, products, jac_ok_.data() + s0);
  });
  const int node_parts = std::min(parts, detail::parts_for(n, 1));
  detail::run_parts(node_parts, [&](int t) {
    for (auto i = static_cast<Index>(detail::range_begin(n, node_parts, t)); i < detail::range_begin(n, node_parts, t + 1);
         ++i)
      for (Index e = incidence_row_[i]; e < incidence_row_[i + 1]; ++e) {
        const Index s = incidence_[e] / 2;
        const bool i_end = incidence_[e] % 2 == 0;
        if (jac_ok_[s] == 0) continue;
        if (req.matrix != nullptr) {
          const double* b = jac_blocks_.data() + 9 * std::size_t{s};
          add_block<1>(req.matrix->block(i_end ? slot_ij_[s] : slot_ji_[s]).data(), b);
          add_block<-1>(req.matrix->block(i_end ? slot_ii_[s] : slot_jj_[s]).data(), b);
        }
        if (product)
          for (int a = 0; a < 3; ++a) {
            const double q = jac_products_[3 * std::size_t{s} + a];
            if (i_end)
              req.product_out[3 * std::size_t{i} + a] += q;
            else
              req.product_out[3 * std::size_t{i} + a] -= q;
          }
      }
  });
}

}  // namespace sewn::physics
