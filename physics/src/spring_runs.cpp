#include "sewn/physics/spring_runs.hpp"

#include <algorithm>
#include <cmath>

#include "parallel/ranges.hpp"
#include "sewn/physics/force_term.hpp"
#include "spring_frame.hpp"

#if defined(__AVX512F__)
#include <immintrin.h>
#define SEWN_RUNS_AVX512 1
#endif

namespace sewn::physics::detail {

namespace {

using detail::range_begin;
using detail::run_parts;

constexpr std::uint32_t no_lane = ~std::uint32_t{0};
// A run shorter than this is cheaper one spring at a time than as a chunk.
constexpr int min_chunk_lanes = 4;
// Chunks per block of the split / join window (see forces()).
constexpr std::size_t block_chunks = 32;
// Chunks per thread below which forces() uses fewer threads.
constexpr std::size_t thread_grain_chunks = 512;

// The per-axis arrays inside soa_, each `stride` long.
enum Axis : int { X, Y, Z, VX, VY, VZ, FX, FY, FZ, num_arrays };

struct Soa {
  double* a[num_arrays];
};

Soa soa_view(double* base, std::size_t stride) {
  Soa s{};
  for (int k = 0; k < num_arrays; ++k) s.a[k] = base + static_cast<std::size_t>(k) * stride;
  return s;
}

// 3n node-major values -> three per-axis arrays.
void split_axes(const double* __restrict in, double* __restrict x, double* __restrict y, double* __restrict z, std::size_t n) {
  std::size_t p = 0;
#ifdef SEWN_RUNS_AVX512
  // Eight nodes are 24 values in three registers; each axis is two two-source permutes.
  const __m512i x01 = _mm512_setr_epi64(0, 3, 6, 9, 12, 15, 0, 0), x2 = _mm512_setr_epi64(0, 1, 2, 3, 4, 5, 10, 13);
  const __m512i y01 = _mm512_setr_epi64(1, 4, 7, 10, 13, 0, 0, 0), y2 = _mm512_setr_epi64(0, 1, 2, 3, 4, 8, 11, 14);
  const __m512i z01 = _mm512_setr_epi64(2, 5, 8, 11, 14, 0, 0, 0), z2 = _mm512_setr_epi64(0, 1, 2, 3, 4, 9, 12, 15);
  for (; p + 8 <= n; p += 8) {
    const __m512d a0 = _mm512_loadu_pd(in + 3 * p), a1 = _mm512_loadu_pd(in + 3 * p + 8),
                  a2 = _mm512_loadu_pd(in + 3 * p + 16);
    _mm512_store_pd(x + p, _mm512_permutex2var_pd(_mm512_permutex2var_pd(a0, x01, a1), x2, a2));
    _mm512_store_pd(y + p, _mm512_permutex2var_pd(_mm512_permutex2var_pd(a0, y01, a1), y2, a2));
    _mm512_store_pd(z + p, _mm512_permutex2var_pd(_mm512_permutex2var_pd(a0, z01, a1), z2, a2));
  }
#endif
  for (; p < n; ++p) {
    x[p] = in[3 * p];
    y[p] = in[3 * p + 1];
    z[p] = in[3 * p + 2];
  }
}

// f (3n) = or += the per-axis accumulators for nodes [p, end), and those back to zero.
// p must be a multiple of 8 (the accumulators' loads are aligned).
void join_axes(const Soa& s, double* __restrict out, std::size_t p, std::size_t end, bool accumulate) {
  double *fx = s.a[FX], *fy = s.a[FY], *fz = s.a[FZ];
#ifdef SEWN_RUNS_AVX512
  // The inverse of split_axes: three registers of 8 interleaved nodes, two permutes each.
  const __m512i o0a = _mm512_setr_epi64(0, 8, 0, 1, 9, 0, 2, 10), o0b = _mm512_setr_epi64(0, 1, 8, 3, 4, 9, 6, 7);
  const __m512i o1a = _mm512_setr_epi64(0, 3, 11, 0, 4, 12, 0, 5), o1b = _mm512_setr_epi64(10, 1, 2, 11, 4, 5, 12, 7);
  const __m512i o2a = _mm512_setr_epi64(13, 0, 6, 14, 0, 7, 15, 0), o2b = _mm512_setr_epi64(0, 13, 2, 3, 14, 5, 6, 15);
  const __m512d zero = _mm512_setzero_pd();
  for (; p + 8 <= end; p += 8) {
    const __m512d X = _mm512_load_pd(fx + p), Y = _mm512_load_pd(fy + p), Z = _mm512_load_pd(fz + p);
    for (double* a : {fx, fy, fz}) _mm512_store_pd(a + p, zero);
    __m512d r0 = _mm512_permutex2var_pd(_mm512_permutex2var_pd(X, o0a, Y), o0b, Z);
    __m512d r1 = _mm512_permutex2var_pd(_mm512_permutex2var_pd(X, o1a, Y), o1b, Z);
    __m512d r2 = _mm512_permutex2var_pd(_mm512_permutex2var_pd(X, o2a, Y), o2b, Z);
    double* o = out + 3 * p;
    if (accumulate) {
      r0 = _mm512_add_pd(r0, _mm512_loadu_pd(o));
      r1 = _mm512_add_pd(r1, _mm512_loadu_pd(o + 8));
      r2 = _mm512_add_pd(r2, _mm512_loadu_pd(o + 16));
    }
    _mm512_storeu_pd(o, r0);
    _mm512_storeu_pd(o + 8, r1);
    _mm512_storeu_pd(o + 16, r2);
  }
#endif
  for (; p < end; ++p) {
    const double v[3] = {fx[p], fy[p], fz[p]};
    for (int c = 0; c < 3; ++c) out[3 * p + c] = accumulate ? out[3 * p + c] + v[c] : v[c];
    fx[p] = fy[p] = fz[p] = 0.0;
  }
}

// The force on node i of one spring (j gets its opposite) from d = xj − xi and u = vj − vi:
// the reference arithmetic of the chunk kernel (springs.cpp's spring_scalar). False, with no
// force, for a spring too short to have a direction (a NaN goes on, to be caught downstream).
template <RunDamping D>
inline bool spring_force(const double (&d)[3], const double (&u)[3], double k, double l, double g, double beta, double (&out)[3]) {
  const double d2 = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
  if (d2 <= degenerate_ratio_sq * l * l) return false;
  const double inv = 1.0 / std::sqrt(d2);
  double c = k * (1.0 - l * inv);
  double e = 0.0;
  if constexpr (D != RunDamping::none) {
    const double w = (u[0] * d[0] + u[1] * d[1] + u[2] * d[2]) * inv * inv;
    if constexpr (D == RunDamping::viscous) {
      c += g * w;
    } else {
      const double cl = std::max(0.0, 1.0 - l * inv);
      const double bk = beta * k;
      c += bk * (1.0 - cl) * w;
      e = bk * cl;
    }
  }
  for (int a = 0; a < 3; ++a) out[a] = c * d[a] + e * u[a];
  return true;
}

// One spring on the per-axis arrays of s.
template <RunDamping D>
inline void one_spring(const Soa& s, std::size_t i, std::size_t j, double k, double l, double g, double beta) {
  double d[3], u[3] = {0.0, 0.0, 0.0}, f[3];
  for (int a = 0; a < 3; ++a) d[a] = s.a[X + a][j] - s.a[X + a][i];
  if constexpr (D != RunDamping::none)
    for (int a = 0; a < 3; ++a) u[a] = s.a[VX + a][j] - s.a[VX + a][i];
  if (!spring_force<D>(d, u, k, l, g, beta, f)) return;
  for (int a = 0; a < 3; ++a) {
    s.a[FX + a][i] += f[a];
    s.a[FX + a][j] -= f[a];
  }
}

// The rest list's springs, one by one, straight on x, v and f (3n each, node-major).
template <RunDamping D>
void rest_springs(const SpringArrays& a, std::span<const Index> rest, const double* x, const double* v, double* out, double beta) {
  for (const Index r : rest) {
    if (a.alive[r] == 0) continue;
    const std::size_t i = 3 * std::size_t{a.ni[r]}, j = 3 * std::size_t{a.nj[r]};
    double d[3], u[3] = {0.0, 0.0, 0.0}, f[3];
    for (int c = 0; c < 3; ++c) d[c] = x[j + c] - x[i + c];
    if constexpr (D != RunDamping::none)
      for (int c = 0; c < 3; ++c) u[c] = v[j + c] - v[i + c];
    if (!spring_force<D>(d, u, a.k[r], a.l[r], a.g[r], beta, f)) continue;
    for (int c = 0; c < 3; ++c) {
      out[i + c] += f[c];
      out[j + c] -= f[c];
    }
  }
}

#ifdef SEWN_RUNS_AVX512
inline __m512d inv_sqrt(__m512d d2) {
  // rsqrt14 and two Newton steps: relative error ~1e-16, as the AoS path's.
  const __m512d half = _mm512_set1_pd(0.5), three_halves = _mm512_set1_pd(1.5);
  const __m512d hd = _mm512_mul_pd(half, d2);
  // (The zero-masked forms: GCC 12 warns that the plain ones read an undefined register.)
  __m512d y = _mm512_maskz_rsqrt14_pd(0xFF, d2);
  y = _mm512_mul_pd(y, _mm512_fnmadd_pd(hd, _mm512_mul_pd(y, y), three_halves));
  y = _mm512_mul_pd(y, _mm512_fnmadd_pd(hd, _mm512_mul_pd(y, y), three_halves));
  return y;
}

// The node arrays as the chunk loop reads them, as separate restrict pointers so that the
// compiler keeps them in registers across the masked stores.
struct Arrays {
  const double* __restrict x;
  const double* __restrict y;
  const double* __restrict z;
  const double* __restrict vx;
  const double* __restrict vy;
  const double* __restrict vz;
  double* __restrict f[3];
};

// Chunks of eight springs (i0 + q, j0 + q). Loads are unmasked (the arrays are padded past
// the last node, and lanes outside the mask compute values nobody stores); stores are masked.
template <RunDamping D, class Chunk>
void chunk_loop(const Arrays& A, const Chunk* __restrict chunks, const std::uint8_t* __restrict masks, std::size_t count,
                const double* __restrict k8, const double* __restrict l8, const double* __restrict g8, double beta) {
  const double* __restrict x = A.x;
  const double* __restrict y = A.y;
  const double* __restrict z = A.z;
  const double* __restrict vx = A.vx;
  const double* __restrict vy = A.vy;
  const double* __restrict vz = A.vz;
  double* __restrict fo[3] = {A.f[0], A.f[1], A.f[2]};
  const __m512d one = _mm512_set1_pd(1.0), tiny = _mm512_set1_pd(degenerate_ratio_sq);
  // Chunks are sorted by i0, and the i-side forces of chunks with the same i0 are summed in
  // registers and stored once: a load of the accumulator right after a masked store to it
  // cannot be forwarded and would wait for the store to reach the cache.
  __m512d fi[3] = {_mm512_setzero_pd(), _mm512_setzero_pd(), _mm512_setzero_pd()};
  __mmask8 fi_mask = 0;
  std::size_t fi_node = count > 0 ? chunks[0].i0 : 0;
  const auto flush = [&] {
    for (int a = 0; a < 3; ++a) {
      _mm512_mask_storeu_pd(fo[a] + fi_node, fi_mask, _mm512_add_pd(_mm512_loadu_pd(fo[a] + fi_node), fi[a]));
      fi[a] = _mm512_setzero_pd();
    }
    fi_mask = 0;
  };
  for (std::size_t c = 0; c < count; ++c) {
    const std::size_t i = chunks[c].i0, j = chunks[c].j0;
    const __mmask8 mk = masks[c];
    if (i != fi_node) {
      flush();
      fi_node = i;
    }
    fi_mask |= mk;
    const auto diff = [&](const double* a) { return _mm512_sub_pd(_mm512_loadu_pd(a + j), _mm512_loadu_pd(a + i)); };
    const __m512d dx = diff(x), dy = diff(y), dz = diff(z);
    const __m512d d2 = _mm512_fmadd_pd(dz, dz, _mm512_fmadd_pd(dy, dy, _mm512_mul_pd(dx, dx)));
    const __m512d l = _mm512_load_pd(l8 + 8 * c), k = _mm512_load_pd(k8 + 8 * c);
    // Ordered compare: a NaN length fails it, c becomes 0 but c·d stays NaN.
    const __mmask8 ok = _mm512_cmp_pd_mask(d2, _mm512_mul_pd(tiny, _mm512_mul_pd(l, l)), _CMP_GT_OQ);
    const __m512d inv = inv_sqrt(d2);
    const __m512d linv = _mm512_mul_pd(l, inv);
    __m512d cf = _mm512_mul_pd(k, _mm512_sub_pd(one, linv));
    __m512d e = _mm512_setzero_pd(), u[3] = {e, e, e};
    if constexpr (D != RunDamping::none) {
      u[0] = diff(vx);
      u[1] = diff(vy);
      u[2] = diff(vz);
      const __m512d du = _mm512_fmadd_pd(dz, u[2], _mm512_fmadd_pd(dy, u[1], _mm512_mul_pd(dx, u[0])));
      const __m512d w = _mm512_mul_pd(du, _mm512_mul_pd(inv, inv));
      if constexpr (D == RunDamping::viscous) {
        cf = _mm512_fmadd_pd(_mm512_load_pd(g8 + 8 * c), w, cf);
      } else {
        const __m512d cl = _mm512_maskz_max_pd(0xFF, _mm512_sub_pd(one, linv), _mm512_setzero_pd());
        const __m512d bk = _mm512_mul_pd(_mm512_set1_pd(beta), k);
        cf = _mm512_fmadd_pd(_mm512_mul_pd(bk, _mm512_sub_pd(one, cl)), w, cf);
        e = _mm512_maskz_mov_pd(ok, _mm512_mul_pd(bk, cl));
      }
    }
    cf = _mm512_maskz_mov_pd(ok, cf);
    const __m512d d[3] = {dx, dy, dz};
    for (int a = 0; a < 3; ++a) {
      __m512d f = _mm512_mul_pd(cf, d[a]);
      if constexpr (D == RunDamping::stiffness_proportional) f = _mm512_fmadd_pd(e, u[a], f);
      fi[a] = _mm512_mask_add_pd(fi[a], mk, fi[a], f);
      _mm512_mask_storeu_pd(fo[a] + j, mk, _mm512_sub_pd(_mm512_loadu_pd(fo[a] + j), f));
    }
  }
  if (count > 0) flush();
}
#endif

// The springs of chunks [c0, c1) into the force arrays of s (k8, l8, g8: 8 lanes per chunk).
template <RunDamping D, class Chunk>
void chunk_range(const Soa& s, const Chunk* chunks, const std::uint8_t* masks, const double* k8, const double* l8,
                 const double* g8, std::size_t c0, std::size_t c1, double beta) {
#ifdef SEWN_RUNS_AVX512
  const Arrays A{s.a[X], s.a[Y], s.a[Z], s.a[VX], s.a[VY], s.a[VZ], {s.a[FX], s.a[FY], s.a[FZ]}};
  chunk_loop<D>(A, chunks + c0, masks + c0, c1 - c0, k8 + 8 * c0, l8 + 8 * c0, g8 + 8 * c0, beta);
#else
  for (std::size_t c = c0; c < c1; ++c)
    for (std::size_t q = 0; q < 8; ++q)
      if ((masks[c] >> q) & 1u) one_spring<D>(s, chunks[c].i0 + q, chunks[c].j0 + q, k8[c * 8 + q], l8[c * 8 + q], g8[c * 8 + q], beta);
#endif
}

#ifdef SEWN_RUNS_AVX512
// The stable-step rows of chunks of eight springs (i0 + q, j0 + q): the chunk form of
// Springs::add_stability_rows (its formulas: K = k (U Uᵀ + c (I − U Uᵀ)), c = max(0, 1 − l/d),
// k I for a spring with no direction; C = γ U Uᵀ or β K), added to eight consecutive nodes'
// accumulators at once. Dead lanes get k = γ = 0 and add zeros.
template <RunDamping D, class Chunk>
void stability_chunks(const double* __restrict x, const double* __restrict y, const double* __restrict z,
                      const Chunk* __restrict chunks, const std::uint8_t* __restrict masks, std::size_t count,
                      const double* __restrict k8, const double* __restrict l8, const double* __restrict g8, double beta,
                      const StabilityRows::Lanes& L) {
  constexpr int kinds = D == RunDamping::none ? 1 : 2;  // stiffness rows, and damping rows
  const __m512d one = _mm512_set1_pd(1.0), zero = _mm512_setzero_pd(), tiny = _mm512_set1_pd(degenerate_ratio_sq);
  const auto add = [](double* p, __m512d v) { _mm512_storeu_pd(p, _mm512_add_pd(_mm512_loadu_pd(p), v)); };
  // Chunks are sorted by i0: the i-side rows of the chunks that share it are summed in
  // registers and added to the arrays once (as the force kernel does), which halves the
  // read-modify-writes a chunk makes. The j side goes to the arrays chunk by chunk.
  struct Side {
    __m512d diag[6];
    __m512d off[3];
  };
  Side acc[kinds];
  const auto clear = [&] {
    for (Side& a : acc) {
      for (__m512d& v : a.diag) v = zero;
      for (__m512d& v : a.off) v = zero;
    }
  };
  std::size_t acc_node = count > 0 ? chunks[0].i0 : 0;
  const auto flush = [&] {
    for (int w = 0; w < kinds; ++w) {
      for (int e = 0; e < 6; ++e) add(L.diag[w][e] + acc_node, acc[w].diag[e]);
      for (int r = 0; r < 3; ++r) add(L.off[w][r] + acc_node, acc[w].off[r]);
    }
    clear();
  };
  clear();
  // Both nodes' diagonal blocks += B, and their off-diagonal row sums += |B| over the other
  // node's free axes, scaled by 1/sqrt(mi mj).
  const auto add_rows = [&](int w, std::size_t i, std::size_t j, const __m512d (&B)[6]) {
    for (int e = 0; e < 6; ++e) {
      acc[w].diag[e] = _mm512_add_pd(acc[w].diag[e], B[e]);
      add(L.diag[w][e] + j, B[e]);
    }
    const __m512d scale = _mm512_mul_pd(_mm512_loadu_pd(L.inv_sqrt_mass + i), _mm512_loadu_pd(L.inv_sqrt_mass + j));
    __m512d a[6];
    for (int e = 0; e < 6; ++e) a[e] = _mm512_abs_pd(B[e]);
    // row r's entries (r, 0..2) in the SymBlock's order
    static constexpr int row[3][3] = {{0, 3, 4}, {3, 1, 5}, {4, 5, 2}};
    for (int r = 0; r < 3; ++r) {
      __m512d si = zero, sj = zero;
      for (int c = 0; c < 3; ++c) {
        si = _mm512_fmadd_pd(_mm512_loadu_pd(L.free[c] + j), a[row[r][c]], si);
        sj = _mm512_fmadd_pd(_mm512_loadu_pd(L.free[c] + i), a[row[r][c]], sj);
      }
      acc[w].off[r] = _mm512_fmadd_pd(scale, si, acc[w].off[r]);
      add(L.off[w][r] + j, _mm512_mul_pd(scale, sj));
    }
  };
  for (std::size_t c = 0; c < count; ++c) {
    const std::size_t i = chunks[c].i0, j = chunks[c].j0;
    if (i != acc_node) {
      flush();
      acc_node = i;
    }
    const __mmask8 mk = masks[c];
    const auto diff = [&](const double* p) { return _mm512_sub_pd(_mm512_loadu_pd(p + j), _mm512_loadu_pd(p + i)); };
    const __m512d dx = diff(x), dy = diff(y), dz = diff(z);
    const __m512d d2 = _mm512_fmadd_pd(dz, dz, _mm512_fmadd_pd(dy, dy, _mm512_mul_pd(dx, dx)));
    const __m512d l = _mm512_load_pd(l8 + 8 * c), k = _mm512_maskz_mov_pd(mk, _mm512_load_pd(k8 + 8 * c));
    // A direction where d² is above the degenerate ratio (ordered: not for a NaN) and 1/d
    // does not underflow to 0 (an overflowing d²), as the scalar path decides.
    __mmask8 ok = _mm512_cmp_pd_mask(d2, _mm512_mul_pd(tiny, _mm512_mul_pd(l, l)), _CMP_GT_OQ);
    __m512d w = _mm512_maskz_mov_pd(ok, inv_sqrt(d2));
    ok &= _mm512_cmp_pd_mask(w, zero, _CMP_GT_OQ);
    w = _mm512_maskz_mov_pd(ok, w);
    const __m512d u0 = _mm512_maskz_mul_pd(ok, dx, w), u1 = _mm512_maskz_mul_pd(ok, dy, w), u2 = _mm512_maskz_mul_pd(ok, dz, w);
    // U Uᵀ, or I's diagonal for a spring with no direction
    const __m512d UU[6] = {_mm512_mask_blend_pd(ok, one, _mm512_mul_pd(u0, u0)), _mm512_mask_blend_pd(ok, one, _mm512_mul_pd(u1, u1)),
                           _mm512_mask_blend_pd(ok, one, _mm512_mul_pd(u2, u2)), _mm512_mul_pd(u0, u1),
                           _mm512_mul_pd(u0, u2),                                 _mm512_mul_pd(u1, u2)};
    const __m512d cl = _mm512_maskz_max_pd(0xFF, _mm512_fnmadd_pd(l, w, one), zero);
    const __m512d kc = _mm512_mul_pd(k, cl), k1c = _mm512_mul_pd(k, _mm512_sub_pd(one, cl));
    __m512d K[6];
    for (int e = 0; e < 6; ++e) K[e] = e < 3 ? _mm512_fmadd_pd(k1c, UU[e], kc) : _mm512_mul_pd(k1c, UU[e]);
    add_rows(StabilityRows::stiffness, i, j, K);
    if constexpr (D != RunDamping::none) {
      __m512d C[6];
      if constexpr (D == RunDamping::viscous) {
        const __m512d g = _mm512_maskz_mov_pd(mk, _mm512_load_pd(g8 + 8 * c));
        for (int e = 0; e < 6; ++e) C[e] = _mm512_mul_pd(g, UU[e]);
      } else {
        const __m512d b = _mm512_set1_pd(beta);
        for (int e = 0; e < 6; ++e) C[e] = _mm512_mul_pd(b, K[e]);
      }
      add_rows(StabilityRows::damping, i, j, C);
    }
  }
  if (count > 0) flush();
}
#endif

}  // namespace

void SpringRuns::ensure_lane_index(Index count) {
  if (lane_of_.size() < count) {
    lane_of_.resize(count, no_lane);
    in_rest_.resize(count, 0);
  }
}

void SpringRuns::to_rest(Index s) {
  if (in_rest_[s] != 0) return;
  in_rest_[s] = 1;
  rest_.push_back(s);
}

void SpringRuns::rebuild(const SpringArrays& a) {
  chunks_.clear();
  mask_.clear();
  k_.clear();
  l_.clear();
  g_.clear();
  spring_.clear();
  rest_.clear();
  // Headroom for the springs a cut adds, so that they do not copy these arrays.
  lane_of_.reserve(a.count + a.count / 4);
  in_rest_.reserve(a.count + a.count / 4);
  lane_of_.assign(a.count, no_lane);
  in_rest_.assign(a.count, 0);
  std::vector<Index> order;
  order.reserve(a.count);
  for (Index s = 0; s < a.count; ++s)
    if (a.alive[s] != 0) order.push_back(s);
  live_ = static_cast<Index>(order.size());
  // A spring's force does not depend on which end is called i, so each is taken from its lower
  // node: builders that orient springs by element or dart order, not by node, still form runs.
  const auto lo = [&](Index s) { return std::min(a.ni[s], a.nj[s]); };
  const auto offset = [&](Index s) { return std::max(a.ni[s], a.nj[s]) - lo(s); };
  // Same offset, then increasing lower node: each run is a stretch of consecutive entries.
  std::sort(order.begin(), order.end(), [&](Index p, Index q) {
    const Index op = offset(p), oq = offset(q);
    return op != oq ? op < oq : lo(p) < lo(q);
  });
  // Runs cut into chunks of up to 8 lanes, each known by its first entry in `order`.
  struct Run {
    std::size_t first, len;
  };
  std::vector<Run> runs;
  for (std::size_t t = 0; t < order.size();) {
    const Index first = order[t];
    std::size_t len = 1;
    while (t + len < order.size() && len < lanes && offset(order[t + len]) == offset(first) && lo(order[t + len]) == lo(first) + len)
      ++len;
    if (len < min_chunk_lanes)
      for (std::size_t q = 0; q < len; ++q) to_rest(order[t + q]);
    else
      runs.push_back({t, len});
    t += len;
  }
  // Chunks in order of their first node, so that consecutive chunks touch nearby memory.
  std::stable_sort(runs.begin(), runs.end(), [&](const Run& p, const Run& q) { return lo(order[p.first]) < lo(order[q.first]); });
  chunked_ = 0;
  for (const Run& r : runs) {
    const Index first = order[r.first];
    const auto c = static_cast<std::uint32_t>(chunks_.size());
    chunks_.push_back({lo(first), lo(first) + offset(first)});
    mask_.push_back(static_cast<std::uint8_t>((1u << r.len) - 1u));
    for (std::size_t q = 0; q < lanes; ++q) {
      const bool used = q < r.len;
      const Index s = used ? order[r.first + q] : invalid_index;
      spring_.push_back(s);
      k_.push_back(used ? a.k[s] : 0.0);
      l_.push_back(used ? a.l[s] : 1.0);
      g_.push_back(used ? a.g[s] : 0.0);
      if (used) lane_of_[s] = c * lanes + static_cast<std::uint32_t>(q);
    }
    chunked_ += static_cast<Index>(r.len);
  }
  // Per block of chunks: the highest node it may read (lanes past a run's end included), over
  // it and every block before; and the lowest node any later block touches.
  const std::size_t blocks = (chunks_.size() + block_chunks - 1) / block_chunks;
  reach_.assign(blocks, 0);
  floor_.assign(blocks, invalid_index);
  std::size_t reach = 0;
  for (std::size_t c = 0; c < chunks_.size(); ++c) {
    reach = std::max<std::size_t>(reach, std::size_t{std::max(chunks_[c].i0, chunks_[c].j0)} + lanes);
    reach_[c / block_chunks] = reach;
  }
  std::size_t longest = 0;
  for (const Chunk& c : chunks_) longest = std::max<std::size_t>(longest, c.j0 - c.i0);
  overhang_ = (longest + 2 * lanes - 1) / lanes * lanes;
  Index floor = invalid_index;
  for (std::size_t b = blocks; b-- > 0;) {
    floor_[b] = floor;
    for (std::size_t c = b * block_chunks; c < std::min(chunks_.size(), (b + 1) * block_chunks); ++c)
      floor = std::min({floor, chunks_[c].i0, chunks_[c].j0});
  }
  rest_at_build_ = rest_.size();
  built_ = true;
}

bool SpringRuns::needs_rebuild() const {
  return !built_ || rest_.size() - rest_at_build_ > std::max<std::size_t>(64, live_ / 8);
}

void SpringRuns::on_added(Index s) {
  if (!built_) return;
  ensure_lane_index(s + 1);
  lane_of_[s] = no_lane;
  to_rest(s);
  ++live_;
}

void SpringRuns::leave_chunk(Index s) {
  const std::uint32_t lane = lane_of_[s];
  if (lane == no_lane) return;
  mask_[lane / lanes] &= static_cast<std::uint8_t>(~(1u << (lane % lanes)));
  spring_[lane] = invalid_index;
  lane_of_[s] = no_lane;
  --chunked_;
}

void SpringRuns::on_removed(Index s) {
  if (!built_) return;
  leave_chunk(s);
  --live_;
}

void SpringRuns::on_endpoints_changed(Index s) {
  if (!built_) return;
  leave_chunk(s);
  to_rest(s);
}

void SpringRuns::on_parameters_changed(Index s, double k, double l, double g) {
  if (!built_) return;
  const std::uint32_t lane = lane_of_[s];
  if (lane == no_lane) return;  // the rest list reads the spring arrays
  k_[lane] = k;
  l_[lane] = l;
  g_[lane] = g;
}

void SpringRuns::refresh_parameters(const SpringArrays& a) {
  if (!built_) return;
  for (std::size_t lane = 0; lane < spring_.size(); ++lane) {
    const Index s = spring_[lane];
    if (s == invalid_index) continue;
    k_[lane] = a.k[s];
    l_[lane] = a.l[s];
    g_[lane] = a.g[s];
  }
}

void SpringRuns::ensure_arrays(Index n, std::size_t arrays) const {
  // Room for an unmasked 8-lane access starting at the last node, and a quarter of headroom
  // when the arrays grow, so that a cut adding particles does not re-allocate (and fault in)
  // all twelve arrays before its first step.
  const std::size_t needed = (std::size_t{n} + 2 * lanes - 1) / lanes * lanes;
  if (needed > stride_ || needed + needed / 2 < stride_ || soa_.size() < arrays * stride_) {
    const std::size_t stride = (needed + needed / 4 + lanes - 1) / lanes * lanes;
    soa_.assign(arrays * stride, 0.0);
    stride_ = stride;
  }
}

int SpringRuns::plan_ranges(int parts, Index n) const {
  node_at_.assign(static_cast<std::size_t>(parts) + 1, 0);
  chunk_at_.assign(static_cast<std::size_t>(parts) + 1, 0);
  node_at_.back() = n;
  chunk_at_.back() = chunks_.size();
  // Balanced by chunks; a range starts at a multiple of 8 nodes (the per-axis arrays are joined
  // 8 aligned nodes at a time) with the first chunk whose lower node is there.
  for (int t = 1; t < parts; ++t) {
    const auto u = static_cast<std::size_t>(t);
    node_at_[u] = chunks_[range_begin(chunks_.size(), parts, t)].i0 / lanes * lanes;
    chunk_at_[u] = static_cast<std::size_t>(
        std::lower_bound(chunks_.begin(), chunks_.end(), node_at_[u], [](const Chunk& c, std::size_t p) { return c.i0 < p; }) -
        chunks_.begin());
  }
  // A range's first `overhang_` nodes also take the forces of the range before's springs that
  // reach past it: the seams must not reach into a third range.
  for (int t = 1; t < parts; ++t)
    if (node_at_[static_cast<std::size_t>(t) + 1] < node_at_[static_cast<std::size_t>(t)] + overhang_) return plan_ranges(1, n);
  return parts;
}

void SpringRuns::forces(const SpringArrays& a, RunDamping damping, double beta, std::span<const double> x,
                        std::span<const double> v, std::span<double> f, bool accumulate, Index n) const {
  const int wanted = chunks_.size() >= 2 * thread_grain_chunks ? detail::parts_for(chunks_.size(), thread_grain_chunks) : 1;
  const int parts = plan_ranges(wanted, n);
  // Each thread has per-axis arrays of its own: no two threads write the same memory, and
  // each splits the nodes its springs read (its range and the seam past it).
  ensure_arrays(n, num_arrays * static_cast<std::size_t>(parts));
  const std::size_t stride = stride_;
  const auto soa_of = [&](int t) { return soa_view(soa_.data() + static_cast<std::size_t>(t) * num_arrays * stride, stride); };
  const bool damped = damping != RunDamping::none;
  // Thread t in one pass over its chunks, as one thread over all of them: nodes are split into
  // the per-axis arrays just before the first block of chunks that reads them, and joined
  // into f as soon as no later chunk touches them, so that on a large mesh each node's
  // per-axis values are still in cache when they are used (the window between the two fronts
  // is about one grid layer). The seam at the start of its range (the range before's springs
  // add there too) is left to the second phase.
  const auto pass = [&]<RunDamping D>(int t) {
    const Soa s = soa_of(t);
    const auto u = static_cast<std::size_t>(t);
    const std::size_t first = node_at_[u], last = node_at_[u + 1];
    std::size_t split_to = first, joined_to = t == 0 ? first : first + overhang_;
    const auto split_until = [&](std::size_t end) {
      end = std::min<std::size_t>((end + lanes - 1) / lanes * lanes, n);
      if (end <= split_to) return;
      const std::size_t p = split_to, len = end - p;
      split_axes(x.data() + 3 * p, s.a[X] + p, s.a[Y] + p, s.a[Z] + p, len);
      if (damped) split_axes(v.data() + 3 * p, s.a[VX] + p, s.a[VY] + p, s.a[VZ] + p, len);
      split_to = end;
    };
    const auto join_until = [&](std::size_t end) {
      end = std::min(end, last);
      if (end < n) end = end / lanes * lanes;
      if (end <= joined_to) return;
      join_axes(s, f.data(), joined_to, end, accumulate);
      joined_to = end;
    };
    for (std::size_t c0 = chunk_at_[u], c1 = chunk_at_[u + 1]; c0 < c1;) {
      const std::size_t b = c0 / block_chunks, end = std::min(c1, (b + 1) * block_chunks);
      split_until(reach_[b]);
      chunk_range<D>(s, chunks_.data(), mask_.data(), k_.data(), l_.data(), g_.data(), c0, end, beta);
      join_until(floor_[b]);
      c0 = end;
    }
    join_until(last);
  };
  const auto own_springs = [&](int t) {
    switch (damping) {
      case RunDamping::none: pass.template operator()<RunDamping::none>(t); break;
      case RunDamping::viscous: pass.template operator()<RunDamping::viscous>(t); break;
      case RunDamping::stiffness_proportional: pass.template operator()<RunDamping::stiffness_proportional>(t); break;
    }
  };
  // The seam of range t: the range before's sums and its own, added in that order (a
  // different grouping from one thread's, so equal to it to round-off), both back to zero.
  const auto seam = [&](int t) {
    if (t == 0) return;
    const Soa mine = soa_of(t), before = soa_of(t - 1);
    const std::size_t first = node_at_[static_cast<std::size_t>(t)];
    for (int axis = 0; axis < 3; ++axis) {
      double* __restrict p = before.a[FX + axis];
      double* __restrict q = mine.a[FX + axis];
      for (std::size_t i = first; i < first + overhang_; ++i) {
        const double sum = p[i] + q[i];
        p[i] = q[i] = 0.0;
        double& o = f[3 * i + static_cast<std::size_t>(axis)];
        o = accumulate ? o + sum : sum;
      }
    }
  };
  run_parts(parts, own_springs, seam);
  // Springs in no chunk, on the calling thread after the join (few: a cut's re-attached ones
  // until the plan is rebuilt), so that they hold back no thread's join window.
  if (rest_.empty()) return;
  switch (damping) {
    case RunDamping::none: rest_springs<RunDamping::none>(a, rest_, x.data(), v.data(), f.data(), beta); break;
    case RunDamping::viscous: rest_springs<RunDamping::viscous>(a, rest_, x.data(), v.data(), f.data(), beta); break;
    case RunDamping::stiffness_proportional: rest_springs<RunDamping::stiffness_proportional>(a, rest_, x.data(), v.data(), f.data(), beta); break;
  }
}

bool SpringRuns::potential_energy(const SpringArrays& a, std::span<const double> x, Index n, double& energy) const {
#ifdef SEWN_RUNS_AVX512
  ensure_arrays(n, num_arrays);
  const Soa s = soa_view(soa_.data(), stride_);
  split_axes(x.data(), s.a[X], s.a[Y], s.a[Z], n);
  const double* __restrict px = s.a[X];
  const double* __restrict py = s.a[Y];
  const double* __restrict pz = s.a[Z];
  // One partial sum per lane; lanes outside a chunk's mask (padding, removed springs) add nothing.
  __m512d sum = _mm512_setzero_pd();
  const __m512d half = _mm512_set1_pd(0.5);
  for (std::size_t c = 0; c < chunks_.size(); ++c) {
    const std::size_t i = chunks_[c].i0, j = chunks_[c].j0;
    const auto diff = [&](const double* p) { return _mm512_sub_pd(_mm512_loadu_pd(p + j), _mm512_loadu_pd(p + i)); };
    const __m512d dx = diff(px), dy = diff(py), dz = diff(pz);
    // (the zero-masked form: GCC 12 warns that the plain one reads an undefined register)
    const __m512d d = _mm512_maskz_sqrt_pd(0xFF, _mm512_fmadd_pd(dz, dz, _mm512_fmadd_pd(dy, dy, _mm512_mul_pd(dx, dx))));
    const __m512d t = _mm512_sub_pd(d, _mm512_load_pd(l_.data() + 8 * c));
    const __m512d e = _mm512_mul_pd(_mm512_mul_pd(half, _mm512_load_pd(k_.data() + 8 * c)), _mm512_mul_pd(t, t));
    sum = _mm512_mask_add_pd(sum, mask_[c], sum, e);
  }
  alignas(64) double lane[8];
  _mm512_store_pd(lane, sum);
  double total = 0;
  for (const double v : lane) total += v;
  for (const Index r : rest_) {
    if (a.alive[r] == 0) continue;
    const std::size_t i = 3 * std::size_t{a.ni[r]}, j = 3 * std::size_t{a.nj[r]};
    const double dx = x[j] - x[i], dy = x[j + 1] - x[i + 1], dz = x[j + 2] - x[i + 2];
    const double t = std::sqrt(dx * dx + dy * dy + dz * dz) - a.l[r];
    total += 0.5 * a.k[r] * t * t;
  }
  energy = total;
  return true;
#else
  (void)a, (void)x, (void)n, (void)energy;
  return false;
#endif
}

bool SpringRuns::stability_rows(RunDamping damping, double beta, std::span<const double> x, Index n, StabilityRows& rows) const {
#ifdef SEWN_RUNS_AVX512
  if (rows.folds()) return false;
  ensure_arrays(n, num_arrays);
  const Soa s = soa_view(soa_.data(), stride_);
  split_axes(x.data(), s.a[X], s.a[Y], s.a[Z], n);
  const StabilityRows::Lanes L = rows.lanes();
  const auto run = [&]<RunDamping D>() {
    stability_chunks<D>(s.a[X], s.a[Y], s.a[Z], chunks_.data(), mask_.data(), chunks_.size(), k_.data(), l_.data(), g_.data(), beta, L);
  };
  switch (damping) {
    case RunDamping::none: run.template operator()<RunDamping::none>(); break;
    case RunDamping::viscous: run.template operator()<RunDamping::viscous>(); break;
    case RunDamping::stiffness_proportional: run.template operator()<RunDamping::stiffness_proportional>(); break;
  }
  return true;
#else
  (void)damping, (void)beta, (void)x, (void)n, (void)rows;
  return false;
#endif
}

}  // namespace sewn::physics::detail
