#include "sewn/physics/cg.hpp"

#include <algorithm>
#include <cmath>

#include <Eigen/LU>

#include "dot8.hpp"
#include "parallel/ranges.hpp"

#if defined(__AVX512F__) && defined(__AVX512VL__)
#include <immintrin.h>
#define SEWN_CG_AVX512 1
#endif

namespace sewn::physics {

namespace {

using detail::range_begin;
using detail::run_parts;
// Nodes per thread below which CG uses fewer threads: an iteration forks two to four times
// (the packed path two, the general one four).
constexpr std::size_t cg_grain = 1024;

double dot(std::span<const double> a, std::span<const double> b) { return detail::dot8(a.data(), b.data(), a.size()); }

// z = S P S r for nodes [first, last).
void apply_precond(std::span<const double> P, std::span<const double> r, std::span<const double> free_dof,
                   std::span<double> z, std::size_t first, std::size_t last) {
  for (std::size_t i = first; i < last; ++i) {
    const double* B = P.data() + 9 * i;
    const double r0 = r[3 * i], r1 = r[3 * i + 1], r2 = r[3 * i + 2];
    z[3 * i] = free_dof[3 * i] * (B[0] * r0 + B[3] * r1 + B[6] * r2);
    z[3 * i + 1] = free_dof[3 * i + 1] * (B[1] * r0 + B[4] * r1 + B[7] * r2);
    z[3 * i + 2] = free_dof[3 * i + 2] * (B[2] * r0 + B[5] * r1 + B[8] * r2);
  }
}

void apply_precond(std::span<const double> P, std::span<const double> r, std::span<const double> free_dof,
                   std::span<double> z) {
  apply_precond(P, r, free_dof, z, 0, r.size() / 3);
}

// filtered_pcg on `parts` threads, each owning a contiguous range of nodes: every pass is split
// by rows and its dot products are summed per range, then over ranges in order (deterministic
// for a given count). The packed symmetric product of the one-thread path scatters into rows of
// other ranges, so the full matrix is used, a row at a time.
CgResult pcg_threads(const BlockMatrix& A, std::span<const double> b, std::span<double> x, std::span<const double> free_dof,
                     std::span<const double> P, double b_norm, double stop, int max_iterations, CgWorkspace& ws, int parts) {
  const std::size_t n = b.size() / 3;
  std::span<double> r(ws.r), z(ws.z), p(ws.p), q(ws.q);
  double part_a[max_threads], part_b[max_threads];
  const auto node = [&](int t) { return range_begin(n, parts, t); };
  const auto sum = [&](const double* part) {
    double s = 0;
    for (int t = 0; t < parts; ++t) s += part[t];
    return s;
  };
  // r = S(b - Ax), z = S P S r, p = z; r·r and r·z.
  run_parts(parts, [&](int t) {
    const std::size_t i0 = node(t), i1 = node(t + 1), k0 = 3 * i0, k1 = 3 * i1;
    A.multiply_rows(x, q, static_cast<Index>(i0), static_cast<Index>(i1));
    for (std::size_t k = k0; k < k1; ++k) r[k] = free_dof[k] * (b[k] - q[k]);
    apply_precond(P, r, free_dof, z, i0, i1);
    for (std::size_t k = k0; k < k1; ++k) p[k] = z[k];
    part_a[t] = detail::dot8(r.data() + k0, r.data() + k0, k1 - k0);
    part_b[t] = detail::dot8(r.data() + k0, z.data() + k0, k1 - k0);
  });
  double r_norm = std::sqrt(sum(part_a));
  double rz = sum(part_b);
  CgResult out;
  int it = 0;
  while (r_norm > stop && it < max_iterations) {
    // q = S A p; p·q.
    run_parts(parts, [&](int t) {
      const std::size_t i0 = node(t), i1 = node(t + 1), k0 = 3 * i0, k1 = 3 * i1;
      A.multiply_rows(p, q, static_cast<Index>(i0), static_cast<Index>(i1));
      for (std::size_t k = k0; k < k1; ++k) q[k] *= free_dof[k];
      part_a[t] = detail::dot8(p.data() + k0, q.data() + k0, k1 - k0);
    });
    const double pq = sum(part_a);
    if (!(pq > 0.0)) {
      out.breakdown = true;
      break;
    }
    const double alpha = rz / pq;
    // x, r, z; r·r and r·z.
    run_parts(parts, [&](int t) {
      const std::size_t i0 = node(t), i1 = node(t + 1), k0 = 3 * i0, k1 = 3 * i1;
      for (std::size_t k = k0; k < k1; ++k) {
        x[k] += alpha * p[k];
        r[k] -= alpha * q[k];
      }
      apply_precond(P, r, free_dof, z, i0, i1);
      part_a[t] = detail::dot8(r.data() + k0, r.data() + k0, k1 - k0);
      part_b[t] = detail::dot8(r.data() + k0, z.data() + k0, k1 - k0);
    });
    ++it;
    r_norm = std::sqrt(sum(part_a));
    const double rz_new = sum(part_b);
    const double beta = rz_new / rz;
    rz = rz_new;
    run_parts(parts, [&](int t) {
      for (std::size_t k = 3 * node(t); k < 3 * node(t + 1); ++k) p[k] = z[k] + beta * p[k];
    });
  }
  out.iterations = it;
  out.relative_residual = r_norm / b_norm;
  out.converged = !out.breakdown && std::isfinite(r_norm) && r_norm <= stop;
  return out;
}

// Copies A's upper block triangle into ws (pattern rebuilt only when A's changes). Returns
// false, leaving the caller to use A itself, if a block is not exactly symmetric. (The filter
// cannot be folded into the blocks: S_i B S_j is not symmetric when i and j fix different axes.)
bool pack_symmetric(const BlockMatrix& A, CgWorkspace& ws) {
  const Index n = A.size();
  if (ws.sym_pattern != A.pattern_version()) {
    const auto rows = A.row_offsets();
    const auto cols = A.columns();
    ws.sym_row.assign(std::size_t{n} + 1, 0);
    ws.sym_col.clear();
    ws.sym_src.clear();
    for (Index i = 0; i < n; ++i) {
      ws.sym_col.push_back(i);
      ws.sym_src.push_back(A.diagonal(i));
      for (Index k = rows[i]; k < rows[i + 1]; ++k) {
        if (cols[k] <= i) continue;
        ws.sym_col.push_back(cols[k]);
        ws.sym_src.push_back(k);
      }
      ws.sym_row[i + 1] = static_cast<Index>(ws.sym_col.size());
    }
    ws.sym_val.resize(6 * ws.sym_src.size());
    ws.sym_pattern = A.pattern_version();
  }
  // Split by rows as CG is (a serial copy of 32³'s upper triangle was 5 % of a 2-thread step).
  const int parts = detail::parts_for(n, cg_grain);
  bool symmetric_of[max_threads];
  run_parts(parts, [&](int t) {
    double* __restrict out = ws.sym_val.data();
    bool symmetric = true;
    const std::size_t b1 = ws.sym_row[range_begin(n, parts, t + 1)];
    for (std::size_t b = ws.sym_row[range_begin(n, parts, t)]; b < b1; ++b) {
      const double* a = A.block(ws.sym_src[b]).data();  // column-major
      symmetric &= a[1] == a[3] && a[2] == a[6] && a[5] == a[7];
      double* o = out + 6 * b;
      o[0] = a[0];
      o[1] = a[3];
      o[2] = a[6];
      o[3] = a[4];
      o[4] = a[7];
      o[5] = a[8];
    }
    symmetric_of[t] = symmetric;
  });
  return std::all_of(symmetric_of, symmetric_of + parts, [](bool s) { return s; });
}

#ifdef SEWN_CG_AVX512
// The three columns of a packed symmetric block, as padded rows [c0 c1 c2 0].
inline void columns(const double* v, __m256d& c0, __m256d& c1, __m256d& c2) {
  const __m256d lo = _mm256_loadu_pd(v);      // a00 a01 a02 a11
  const __m256d hi = _mm256_loadu_pd(v + 2);  // a02 a11 a12 a22
  c0 = _mm256_maskz_mov_pd(0x7, lo);
  c1 = _mm256_maskz_permutex2var_pd(0x7, lo, _mm256_setr_epi64x(1, 3, 6, 0), hi);
  c2 = _mm256_maskz_permutex2var_pd(0x7, lo, _mm256_setr_epi64x(2, 6, 7, 0), hi);
}

inline double hsum(__m256d a) {
  const __m128d s = _mm_add_pd(_mm256_castpd256_pd128(a), _mm256_extractf128_pd(a, 1));
  return _mm_cvtsd_f64(_mm_add_sd(s, _mm_unpackhi_pd(s, s)));
}

// y = S A p over rows of 4; returns p·y. Each block (i,j), j > i, serves both (i,j) and (j,i):
// it adds to row i from p_j and to row j from p_i. Row i is complete once its own blocks are
// done (its other terms came from earlier rows), so the filter and the dot product are applied
// as it is stored.
double sym_multiply(const CgWorkspace& ws, const double* __restrict p, double* __restrict y, const double* __restrict free4,
                    Index n) {
  const Index* __restrict row = ws.sym_row.data();
  const Index* __restrict col = ws.sym_col.data();
  const double* __restrict val = ws.sym_val.data();
  std::fill(y, y + 4 * std::size_t{n}, 0.0);
  __m256d pq = _mm256_setzero_pd();
  for (Index i = 0; i < n; ++i) {
    const double* pi = p + 4 * std::size_t{i};
    const __m256d b0 = _mm256_broadcast_sd(pi), b1 = _mm256_broadcast_sd(pi + 1), b2 = _mm256_broadcast_sd(pi + 2);
    __m256d c0, c1, c2;
    Index k = row[i];
    columns(val + 6 * std::size_t{k}, c0, c1, c2);
    __m256d a0 = _mm256_fmadd_pd(c0, b0, _mm256_load_pd(y + 4 * std::size_t{i}));
    __m256d a1 = _mm256_mul_pd(c1, b1);
    __m256d a2 = _mm256_mul_pd(c2, b2);
    for (++k; k < row[i + 1]; ++k) {
      columns(val + 6 * std::size_t{k}, c0, c1, c2);
      const double* pj = p + 4 * std::size_t{col[k]};
      a0 = _mm256_fmadd_pd(c0, _mm256_broadcast_sd(pj), a0);
      a1 = _mm256_fmadd_pd(c1, _mm256_broadcast_sd(pj + 1), a1);
      a2 = _mm256_fmadd_pd(c2, _mm256_broadcast_sd(pj + 2), a2);
      double* yj = y + 4 * std::size_t{col[k]};
      _mm256_store_pd(yj, _mm256_fmadd_pd(c2, b2, _mm256_fmadd_pd(c1, b1, _mm256_fmadd_pd(c0, b0, _mm256_load_pd(yj)))));
    }
    const __m256d yi = _mm256_mul_pd(_mm256_add_pd(_mm256_add_pd(a0, a1), a2), _mm256_load_pd(free4 + 4 * std::size_t{i}));
    _mm256_store_pd(y + 4 * std::size_t{i}, yi);
    pq = _mm256_fmadd_pd(yi, _mm256_load_pd(pi), pq);
  }
  return hsum(pq);
}

// q = S A p, or with W the reduced product q = S Wᵀ A W p (p zero on the slaves); returns p·q.
double packed_product(CgWorkspace& ws, const double* __restrict p, double* __restrict q, const double* __restrict s,
                      Index n, const PaddedReduction* W) {
  if (W == nullptr) return sym_multiply(ws, p, q, s, n);
  const std::size_t n4 = 4 * std::size_t{n};
  double* __restrict pe = ws.expanded.data();
  std::copy(p, p + n4, pe);
  W->expand4(pe);
  (void)sym_multiply(ws, pe, q, ws.ones4.data(), n);
  W->reduce4(q);
  __m256d pq = _mm256_setzero_pd();
  for (std::size_t o = 0; o < n4; o += 4) {
    const __m256d qi = _mm256_mul_pd(_mm256_load_pd(q + o), _mm256_load_pd(s + o));
    _mm256_store_pd(q + o, qi);
    pq = _mm256_fmadd_pd(qi, _mm256_load_pd(p + o), pq);
  }
  return hsum(pq);
}

// Where thread t's rows stop receiving products of earlier threads' blocks, for `parts` ranges
// of the packed pattern: ws.spill_end[u] is one past the last row that range u's blocks reach
// (at least its own end), ws.first_final[t] the first row of range t that no earlier range's
// block reaches (at most its end). Once per pattern and count.
void plan_spills(CgWorkspace& ws, std::size_t nodes, int parts) {
  if (ws.spill_pattern == ws.sym_pattern && ws.spill_parts == parts) return;
  const auto count = static_cast<std::size_t>(parts);
  ws.spill_end.assign(count, 0);
  ws.first_final.assign(count, 0);
  std::size_t reach = 0;  // one past the last row reached by the ranges before t
  for (int t = 0; t < parts; ++t) {
    const std::size_t i0 = range_begin(nodes, parts, t), i1 = range_begin(nodes, parts, t + 1);
    ws.first_final[static_cast<std::size_t>(t)] = std::clamp(reach, i0, i1);
    std::size_t end = i1;
    for (std::size_t i = i0; i < i1; ++i)  // a row's columns ascend: its last block reaches furthest
      end = std::max(end, std::size_t{ws.sym_col[ws.sym_row[i + 1] - 1]} + 1);
    ws.spill_end[static_cast<std::size_t>(t)] = end;
    reach = std::max(reach, end);
  }
  ws.spill_pattern = ws.sym_pattern;
  ws.spill_parts = parts;
}

// sym_multiply on `parts` threads, after first(t) for every range t (the caller's update of p,
// in the same region), thread t owning rows [node(t), node(t + 1)): its blocks
// add to its own rows in y and to later threads' rows in its spill array. A row no earlier
// thread's block reaches (all but about a grid layer of each range) is complete when its own
// blocks are done, so it is filtered and summed into p·y there, as in sym_multiply; after the
// threads meet, each thread adds the spills of the threads before it to its first rows, in
// thread order, and filters and sums those. Deterministic for a given count; equal to one
// thread's to round-off (a row's terms and p·y are grouped by thread). The spill is used, read
// and zeroed again only up to the last row it reaches, so it is zero between products.
template <class First>
double sym_multiply_parts(CgWorkspace& ws, const double* __restrict p, double* __restrict y, const double* __restrict free4,
                          Index n, int parts, const First& first) {
  const std::size_t nodes = static_cast<std::size_t>(n);
  if (ws.spill.size() < static_cast<std::size_t>(parts)) ws.spill.resize(static_cast<std::size_t>(parts));
  for (int t = 0; t + 1 < parts; ++t) ws.spill[static_cast<std::size_t>(t)].resize(4 * nodes, 0.0);
  plan_spills(ws, nodes, parts);
  const auto node = [&](int t) { return range_begin(nodes, parts, t); };
  const Index* __restrict row = ws.sym_row.data();
  const Index* __restrict col = ws.sym_col.data();
  const double* __restrict val = ws.sym_val.data();
  double part_own[max_threads], part_spilled[max_threads];
  const auto own_rows = [&, p, y, free4, row, col, val](int t) {
    // a lambda's captures lose __restrict: without it every store to y reloads the row's bounds
    const double* __restrict p_ = p;
    double* __restrict y_ = y;
    const double* __restrict free4_ = free4;
    const Index* __restrict row_ = row;
    const Index* __restrict col_ = col;
    const double* __restrict val_ = val;
    const std::size_t i0 = node(t), i1 = node(t + 1), final0 = ws.first_final[static_cast<std::size_t>(t)];
    double* __restrict spill = t + 1 < parts ? ws.spill[static_cast<std::size_t>(t)].data() : nullptr;
    std::fill(y_ + 4 * i0, y_ + 4 * i1, 0.0);
    __m256d pq = _mm256_setzero_pd();
    for (std::size_t i = i0; i < i1; ++i) {
      const double* pi = p_ + 4 * i;
      const __m256d b0 = _mm256_broadcast_sd(pi), b1 = _mm256_broadcast_sd(pi + 1), b2 = _mm256_broadcast_sd(pi + 2);
      __m256d c0, c1, c2;
      Index k = row_[i];
      columns(val_ + 6 * std::size_t{k}, c0, c1, c2);
      __m256d a0 = _mm256_fmadd_pd(c0, b0, _mm256_load_pd(y_ + 4 * i));
      __m256d a1 = _mm256_mul_pd(c1, b1);
      __m256d a2 = _mm256_mul_pd(c2, b2);
      for (++k; k < row_[i + 1]; ++k) {
        columns(val_ + 6 * std::size_t{k}, c0, c1, c2);
        const std::size_t j = std::size_t{col_[k]};
        const double* pj = p_ + 4 * j;
        a0 = _mm256_fmadd_pd(c0, _mm256_broadcast_sd(pj), a0);
        a1 = _mm256_fmadd_pd(c1, _mm256_broadcast_sd(pj + 1), a1);
        a2 = _mm256_fmadd_pd(c2, _mm256_broadcast_sd(pj + 2), a2);
        double* yj = (j < i1 ? y_ : spill) + 4 * j;
        _mm256_store_pd(yj, _mm256_fmadd_pd(c2, b2, _mm256_fmadd_pd(c1, b1, _mm256_fmadd_pd(c0, b0, _mm256_load_pd(yj)))));
      }
      __m256d yi = _mm256_add_pd(_mm256_add_pd(a0, a1), a2);
      if (i >= final0) {
        yi = _mm256_mul_pd(yi, _mm256_load_pd(free4_ + 4 * i));
        pq = _mm256_fmadd_pd(yi, _mm256_load_pd(pi), pq);
      }
      _mm256_store_pd(y_ + 4 * i, yi);
    }
    part_own[t] = hsum(pq);
  };
  const auto spilled_rows = [&](int t) {
    const std::size_t i0 = node(t), final0 = ws.first_final[static_cast<std::size_t>(t)];
    for (int u = 0; u < t; ++u) {
      double* __restrict spill = ws.spill[static_cast<std::size_t>(u)].data();
      const std::size_t end = std::min(final0, ws.spill_end[static_cast<std::size_t>(u)]);
      for (std::size_t i = i0; i < end; ++i) {
        _mm256_store_pd(y + 4 * i, _mm256_add_pd(_mm256_load_pd(y + 4 * i), _mm256_load_pd(spill + 4 * i)));
        _mm256_store_pd(spill + 4 * i, _mm256_setzero_pd());
      }
    }
    __m256d pq = _mm256_setzero_pd();
    for (std::size_t i = i0; i < final0; ++i) {
      const __m256d yi = _mm256_mul_pd(_mm256_load_pd(y + 4 * i), _mm256_load_pd(free4 + 4 * i));
      _mm256_store_pd(y + 4 * i, yi);
      pq = _mm256_fmadd_pd(yi, _mm256_load_pd(p + 4 * i), pq);
    }
    part_spilled[t] = hsum(pq);
  };
  run_parts(parts, first, own_rows, spilled_rows);
  double s = 0;
  for (int t = 0; t < parts; ++t) s += part_spilled[t] + part_own[t];
  return s;
}

// z_i = S_i P_i S_i r_i for one node (pre: that block packed as a symmetric one).
inline __m256d precond_row(const double* pre, __m256d r) {
  __m256d c0, c1, c2;
  columns(pre, c0, c1, c2);
  return _mm256_fmadd_pd(c2, _mm256_permute4x64_pd(r, 0xAA),
                         _mm256_fmadd_pd(c1, _mm256_permute4x64_pd(r, 0x55), _mm256_mul_pd(c0, _mm256_permute4x64_pd(r, 0x00))));
}

// The solve of filtered_pcg on the packed matrix, with the vector passes of an iteration
// fused: p's update (p = z + β p) and the product with its filter and p·q in one region, then
// x, r, the preconditioner, r·r and r·z in one pass: two forks an iteration. The filter is folded into the preconditioner, S P S, as r and z vanish on fixed
// axes; its blocks are stored as symmetric ones (P's upper triangle: the inverse of a symmetric
// block is symmetric up to round-off).
// With W, the same on the reduced system (packed_product).
CgResult pcg_packed(std::span<const double> b, std::span<double> x, std::span<const double> free_dof,
                    std::span<const double> P, double b_norm, double stop, int max_iterations, CgWorkspace& ws,
                    const PaddedReduction* W = nullptr, int parts = 1) {
  const std::size_t n = b.size() / 3;
  for (auto* v : {&ws.r, &ws.z, &ws.p, &ws.q, &ws.x4, &ws.free4}) v->resize(4 * n);
  if (W != nullptr) {
    ws.expanded.assign(4 * n, 0.0);
    ws.ones4.assign(4 * n, 1.0);
  }
  ws.pre.resize(6 * n);
  double* __restrict xv = ws.x4.data();
  double* __restrict r = ws.r.data();
  double* __restrict z = ws.z.data();
  double* __restrict p = ws.p.data();
  double* __restrict q = ws.q.data();
  const double* __restrict pre = ws.pre.data();
  const double* __restrict s = ws.free4.data();
  const auto nodes = static_cast<Index>(n);
  const auto node = [&](int t) { return range_begin(n, parts, t); };
  double part_a[max_threads], part_b[max_threads];
  const auto sum = [&](const double* part) {
    double total = 0;
    for (int t = 0; t < parts; ++t) total += part[t];
    return total;
  };
  // q = S A v, after first(t) over every range t (on one thread: one range before the product).
  const auto product = [&](const double* v, double* out, const auto& first) {
    if (parts > 1) return sym_multiply_parts(ws, v, out, s, nodes, parts, first);
    first(0);
    return packed_product(ws, v, out, s, nodes, W);
  };
  run_parts(parts, [&](int t) {
    for (std::size_t i = node(t); i < node(t + 1); ++i) {
      const double* f = free_dof.data() + 3 * i;
      const double* Pi = P.data() + 9 * i;  // column-major
      double* o = ws.pre.data() + 6 * i;
      o[0] = f[0] * Pi[0];
      o[1] = f[0] * f[1] * Pi[3];
      o[2] = f[0] * f[2] * Pi[6];
      o[3] = f[1] * Pi[4];
      o[4] = f[1] * f[2] * Pi[7];
      o[5] = f[2] * Pi[8];
      for (std::size_t a = 0; a < 3; ++a) {
        xv[4 * i + a] = x[3 * i + a];
        ws.free4[4 * i + a] = f[a];
      }
      xv[4 * i + 3] = ws.free4[4 * i + 3] = 0.0;
      for (double* v : {r, z, p, q}) v[4 * i + 3] = 0.0;
    }
  });
  (void)product(xv, q, [](int) {});
  run_parts(parts, [&](int t) {
    __m256d rr_acc = _mm256_setzero_pd(), rz_acc = _mm256_setzero_pd();
    for (std::size_t i = node(t); i < node(t + 1); ++i) {
      const __m256d ri = _mm256_sub_pd(_mm256_mul_pd(_mm256_maskz_loadu_pd(0x7, b.data() + 3 * i), _mm256_load_pd(s + 4 * i)),
                                       _mm256_load_pd(q + 4 * i));
      const __m256d zi = precond_row(pre + 6 * i, ri);
      _mm256_store_pd(r + 4 * i, ri);
      _mm256_store_pd(z + 4 * i, zi);
      _mm256_store_pd(p + 4 * i, zi);
      rr_acc = _mm256_fmadd_pd(ri, ri, rr_acc);
      rz_acc = _mm256_fmadd_pd(ri, zi, rz_acc);
    }
    part_a[t] = hsum(rr_acc);
    part_b[t] = hsum(rz_acc);
  });
  double r_norm = std::sqrt(sum(part_a));
  double rz = sum(part_b);
  CgResult out;
  int it = 0;
  __m256d beta = _mm256_setzero_pd();  // p = z + β p: p starts as z (β = 0), then in the product's region
  while (r_norm > stop && it < max_iterations) {
    const double pq = product(p, q, [&](int t) {
      if (it == 0) return;
      for (std::size_t o = 4 * node(t); o < 4 * node(t + 1); o += 4)
        _mm256_store_pd(p + o, _mm256_fmadd_pd(beta, _mm256_load_pd(p + o), _mm256_load_pd(z + o)));
    });
    if (!(pq > 0.0)) {
      out.breakdown = true;
      break;
    }
    const __m256d alpha = _mm256_set1_pd(rz / pq);
    run_parts(parts, [&](int t) {
      __m256d rr_acc = _mm256_setzero_pd(), rz_acc = _mm256_setzero_pd();
      for (std::size_t i = node(t); i < node(t + 1); ++i) {
        const std::size_t o = 4 * i;
        _mm256_store_pd(xv + o, _mm256_fmadd_pd(alpha, _mm256_load_pd(p + o), _mm256_load_pd(xv + o)));
        const __m256d ri = _mm256_fnmadd_pd(alpha, _mm256_load_pd(q + o), _mm256_load_pd(r + o));
        const __m256d zi = precond_row(pre + 6 * i, ri);
        _mm256_store_pd(r + o, ri);
        _mm256_store_pd(z + o, zi);
        rr_acc = _mm256_fmadd_pd(ri, ri, rr_acc);
        rz_acc = _mm256_fmadd_pd(ri, zi, rz_acc);
      }
      part_a[t] = hsum(rr_acc);
      part_b[t] = hsum(rz_acc);
    });
    ++it;
    r_norm = std::sqrt(sum(part_a));
    const double rz_new = sum(part_b);
    beta = _mm256_set1_pd(rz_new / rz);
    rz = rz_new;
  }
  run_parts(parts, [&](int t) {
    for (std::size_t i = node(t); i < node(t + 1); ++i)
      for (std::size_t a = 0; a < 3; ++a) x[3 * i + a] = xv[4 * i + a];
  });
  out.iterations = it;
  out.relative_residual = r_norm / b_norm;
  out.converged = !out.breakdown && std::isfinite(r_norm) && r_norm <= stop;
  return out;
}
#endif

}  // namespace

void CgWorkspace::resize(std::size_t n3) {
  r.resize(n3);
  z.resize(n3);
  p.resize(n3);
  q.resize(n3);
}

namespace {

// (S B S + I - S)⁻¹ of one diagonal block, S the node's free axes.
Eigen::Matrix3d filtered_block_inverse(Eigen::Matrix3d B, const double* free_dof) {
  for (int a = 0; a < 3; ++a) {
    if (free_dof[a] != 0.0) continue;
    B.row(a).setZero();
    B.col(a).setZero();
    B(a, a) = 1.0;
  }
  Eigen::Matrix3d inv;
  bool invertible = false;
  double det = 0;
  B.computeInverseAndDetWithCheck(inv, det, invertible, 0.0);
  if (!invertible || !inv.allFinite()) {
    // Singular block (a node no term stiffens and without mass): fall back to Jacobi.
    inv.setZero();
    for (int a = 0; a < 3; ++a) inv(a, a) = B(a, a) != 0.0 ? 1.0 / B(a, a) : 1.0;
  }
  return inv;
}

}  // namespace

void block_jacobi_inverse(const BlockMatrix& A, std::span<const double> free_dof, std::span<double> inverse) {
  // Node by node, split as CG is: each block the same at any count.
  const auto n = static_cast<std::size_t>(A.size());
  const int parts = detail::parts_for(n, cg_grain);
  run_parts(parts, [&](int t) {
    for (auto i = static_cast<Index>(range_begin(n, parts, t)); i < range_begin(n, parts, t + 1); ++i)
      Eigen::Map<Eigen::Matrix3d>(inverse.data() + 9 * std::size_t{i}) =
          filtered_block_inverse(A.block(A.diagonal(i)), free_dof.data() + 3 * std::size_t{i});
  });
}

void block_jacobi_inverse(std::span<const double> blocks, std::span<const double> free_dof, std::span<double> inverse) {
  for (std::size_t i = 0; i < blocks.size() / 9; ++i)
    Eigen::Map<Eigen::Matrix3d>(inverse.data() + 9 * i) =
        filtered_block_inverse(Eigen::Map<const Eigen::Matrix3d>(blocks.data() + 9 * i), free_dof.data() + 3 * i);
}

CgResult filtered_pcg(const BlockMatrix& A, std::span<const double> b, std::span<double> x,
                      std::span<const double> free_dof, std::span<const double> P, double tolerance,
                      int max_iterations, CgWorkspace& ws, double absolute_floor) {
  const std::size_t n3 = b.size();
  ws.resize(n3);
  std::span<double> r(ws.r), z(ws.z), p(ws.p), q(ws.q);
  CgResult out;
  double b_norm2 = 0;
  for (std::size_t k = 0; k < n3; ++k) b_norm2 += free_dof[k] * b[k] * b[k];
  if (b_norm2 == 0.0) {
    // Zero right-hand side: the free part of the solution is zero.
    for (std::size_t k = 0; k < n3; ++k)
      if (free_dof[k] != 0.0) x[k] = 0.0;
    out.converged = true;
    return out;
  }
  const double b_norm = std::sqrt(b_norm2);
  // The floor: near rest b is round-off, and a tolerance relative to it alone chases noise.
  const double stop = std::max(tolerance * b_norm, absolute_floor);
  const int parts = detail::parts_for(n3 / 3, cg_grain);
#ifdef SEWN_CG_AVX512
  // The packed product on every count: the general one streams twice its bytes, which took
  // most of what a second thread gained (docs/solvers.md, Threads).
  if (pack_symmetric(A, ws)) return pcg_packed(b, x, free_dof, P, b_norm, stop, max_iterations, ws, nullptr, parts);
#endif
  if (parts > 1) return pcg_threads(A, b, x, free_dof, P, b_norm, stop, max_iterations, ws, parts);
  A.multiply(x, q);
  for (std::size_t k = 0; k < n3; ++k) r[k] = free_dof[k] * (b[k] - q[k]);
  double r_norm = std::sqrt(dot(r, r));
  apply_precond(P, r, free_dof, z);
  for (std::size_t k = 0; k < n3; ++k) p[k] = z[k];
  double rz = dot(r, z);
  int it = 0;
  while (r_norm > stop && it < max_iterations) {
    A.multiply(p, q);
    for (std::size_t k = 0; k < n3; ++k) q[k] *= free_dof[k];
    const double pq = dot(p, q);
    if (!(pq > 0.0)) {
      out.breakdown = true;
      break;
    }
    const double alpha = rz / pq;
    for (std::size_t k = 0; k < n3; ++k) {
      x[k] += alpha * p[k];
      r[k] -= alpha * q[k];
    }
    ++it;
    r_norm = std::sqrt(dot(r, r));
    apply_precond(P, r, free_dof, z);
    const double rz_new = dot(r, z);
    const double beta = rz_new / rz;
    rz = rz_new;
    for (std::size_t k = 0; k < n3; ++k) p[k] = z[k] + beta * p[k];
  }
  out.iterations = it;
  out.relative_residual = r_norm / b_norm;
  out.converged = !out.breakdown && std::isfinite(r_norm) && r_norm <= stop;
  return out;
}

bool pack_symmetric_blocks(const BlockMatrix& A, CgWorkspace& ws) { return pack_symmetric(A, ws); }

double packed_symmetric_product(const CgWorkspace& ws, const double* p, double* y, const double* free4, Index nodes) {
#ifdef SEWN_CG_AVX512
  return sym_multiply(ws, p, y, free4, nodes);
#else
  // The same product on scalars: block (i,j), j > i, also serves (j,i).
  std::fill(y, y + 4 * std::size_t{nodes}, 0.0);
  for (Index i = 0; i < nodes; ++i)
    for (Index k = ws.sym_row[i]; k < ws.sym_row[i + 1]; ++k) {
      const double* v = ws.sym_val.data() + 6 * std::size_t{k};
      const double m[9] = {v[0], v[1], v[2], v[1], v[3], v[4], v[2], v[4], v[5]};
      const std::size_t j = std::size_t{ws.sym_col[k]}, oi = 4 * std::size_t{i}, oj = 4 * j;
      for (int a = 0; a < 3; ++a)
        for (int c = 0; c < 3; ++c) {
          y[oi + a] += m[3 * a + c] * p[oj + c];
          if (j != std::size_t{i}) y[oj + a] += m[3 * a + c] * p[oi + c];
        }
    }
  double py = 0;
  for (std::size_t o = 0; o < 4 * std::size_t{nodes}; ++o) {
    y[o] *= free4[o];
    py += p[o] * y[o];
  }
  return py;
#endif
}

bool reduced_pcg_packed(const BlockMatrix& A, std::span<const double> rb, std::span<double> x,
                        std::span<const double> free_dof, std::span<const double> P, double tolerance,
                        int max_iterations, CgWorkspace& ws, const PaddedReduction& W, CgResult& out) {
#ifdef SEWN_CG_AVX512
  if (!pack_symmetric(A, ws)) return false;
  out = CgResult{};
  double b_norm2 = 0;
  for (std::size_t k = 0; k < rb.size(); ++k) b_norm2 += free_dof[k] * rb[k] * rb[k];
  if (b_norm2 == 0.0) {  // as filtered_pcg: the free part of the solution is zero
    for (std::size_t k = 0; k < rb.size(); ++k)
      if (free_dof[k] != 0.0) x[k] = 0.0;
    out.converged = true;
    return true;
  }
  const double b_norm = std::sqrt(b_norm2);
  out = pcg_packed(rb, x, free_dof, P, b_norm, tolerance * b_norm, max_iterations, ws, &W);
  return true;
#else
  (void)A, (void)rb, (void)x, (void)free_dof, (void)P, (void)tolerance, (void)max_iterations, (void)ws, (void)W, (void)out;
  return false;
#endif
}

}  // namespace sewn::physics
