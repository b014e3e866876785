#include "bare.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <stdexcept>

#if defined(__AVX512F__) && defined(__AVX512VL__)
#include <immintrin.h>
#define SEWN_BARE_AVX512 1
#endif

namespace sewn::bench::mss {

namespace {

// The library's degenerate-spring guard (springs.cpp): no force below d² = 1e-18 l².
constexpr double degenerate_ratio_sq = 1e-18;
constexpr std::size_t lanes = 8;

}  // namespace

Bare::Bare(const ModelSpec& spec) {
  if (spec.environment != 0) throw std::runtime_error("Bare: drag is not implemented (the cost cases have none)");
  const MassSpring ms = mass_spring(spec);
  n_ = spec.mesh.num_points();
  springs_ = ms.k.size();
  const std::size_t padded = (n_ + 2 * lanes - 1) / lanes * lanes;
  for (int a = 0; a < 3; ++a)
    for (auto* arr : {&x_[a], &v_[a], &f_[a], &inv_mass_[a], &g_[a]}) arr->assign(padded, 0.0);
  mass_.assign(ms.mass.begin(), ms.mass.end());
  gravity_ = spec.gravity;
  for (std::size_t p = 0; p < n_; ++p) {
    const bool fixed = !spec.fixed.empty() && spec.fixed[p] != 0;
    for (std::size_t a = 0; a < 3; ++a) {
      x_[a][p] = spec.mesh.points[p][a];
      inv_mass_[a][p] = fixed ? 0.0 : 1.0 / ms.mass[p];
      g_[a][p] = fixed ? 0.0 : spec.gravity[a];
    }
  }
  // Runs: same offset j - i, consecutive i. Cut into chunks of up to 8; a run of fewer than 4
  // springs is left to the one-at-a-time list.
  std::vector<std::size_t> order(springs_);
  std::iota(order.begin(), order.end(), std::size_t{0});
  const auto off = [&](std::size_t s) { return std::int64_t{ms.j[s]} - std::int64_t{ms.i[s]}; };
  std::sort(order.begin(), order.end(),
            [&](std::size_t p, std::size_t q) { return off(p) != off(q) ? off(p) < off(q) : ms.i[p] < ms.i[q]; });
  struct Built {
    Chunk c;
    std::size_t first;
  };
  std::vector<Built> built;
  for (std::size_t t = 0; t < order.size();) {
    std::size_t len = 1;
    while (t + len < order.size() && len < lanes && off(order[t + len]) == off(order[t]) &&
           ms.i[order[t + len]] == ms.i[order[t]] + len)
      ++len;
    if (len >= 4) {
      built.push_back({{ms.i[order[t]], ms.j[order[t]], static_cast<std::uint8_t>((1u << len) - 1u)}, t});
    } else {
      for (std::size_t q = 0; q < len; ++q) {
        const std::size_t s = order[t + q];
        ri_.push_back(ms.i[s]);
        rj_.push_back(ms.j[s]);
        rk_.push_back(ms.k[s]);
        rl_.push_back(ms.l[s]);
        rg_.push_back(ms.gamma[s]);
      }
    }
    t += len;
  }
  // Chunks by first node: measured faster than by offset (nearby chunks share cache lines).
  std::stable_sort(built.begin(), built.end(), [](const Built& p, const Built& q) { return p.c.i0 < q.c.i0; });
  for (const Built& b : built) {
    chunks_.push_back(b.c);
    for (std::size_t q = 0; q < lanes; ++q) {
      const bool used = (b.c.mask >> q) & 1u;
      const std::size_t s = used ? order[b.first + q] : 0;
      ck_.push_back(used ? ms.k[s] : 0.0);
      cl_.push_back(used ? ms.l[s] : 1.0);
      cg_.push_back(used ? ms.gamma[s] : 0.0);
    }
  }
  std::size_t chunked = 0;
  for (const Chunk& ch : chunks_) chunked += static_cast<std::size_t>(__builtin_popcount(ch.mask));
  // Rows are faster when runs are short (chunks under 3/4 full, as in a 4³ grid) or rare.
  rows_ = 2 * chunked < springs_ || 4 * chunked < 3 * lanes * chunks_.size();
  if (rows_) {
    for (auto* arr : {&x4_, &v4_, &acc4_, &inv_mass4_, &g4_}) arr->assign(4 * n_, 0.0);
    for (std::size_t p = 0; p < n_; ++p)
      for (std::size_t a = 0; a < 3; ++a) {
        x4_[4 * p + a] = x_[a][p];
        inv_mass4_[4 * p + a] = inv_mass_[a][p];
        g4_[4 * p + a] = g_[a][p];
      }
    i_.assign(ms.i.begin(), ms.i.end());
    j_.assign(ms.j.begin(), ms.j.end());
    k_.assign(ms.k.begin(), ms.k.end());
    l_.assign(ms.l.begin(), ms.l.end());
    gamma_.assign(ms.gamma.begin(), ms.gamma.end());
  }
  save();
}

#ifdef SEWN_BARE_AVX512
namespace {

// Four horizontal sums of rows [a b c 0] at once: (Σp0, Σp1, Σp2, Σp3).
inline __m256d hsum4(__m256d p0, __m256d p1, __m256d p2, __m256d p3) {
  const __m256d t0 = _mm256_hadd_pd(p0, p1), t1 = _mm256_hadd_pd(p2, p3);
  return _mm256_add_pd(_mm256_permute2f128_pd(t0, t1, 0x21), _mm256_blend_pd(t0, t1, 0b1100));
}

// 1/√d² from rsqrt14 and two Newton steps (relative error ~1e-16, as the library's).
inline __m256d inv_sqrt(__m256d d2) {
  const __m256d half = _mm256_set1_pd(0.5), three_halves = _mm256_set1_pd(1.5);
  const __m256d hd = _mm256_mul_pd(half, d2);
  __m256d y = _mm256_rsqrt14_pd(d2);
  y = _mm256_mul_pd(y, _mm256_fnmadd_pd(hd, _mm256_mul_pd(y, y), three_halves));
  y = _mm256_mul_pd(y, _mm256_fnmadd_pd(hd, _mm256_mul_pd(y, y), three_halves));
  return y;
}

}  // namespace
#endif

void Bare::accumulate_rows() {
  const double* __restrict x = x4_.data();
  const double* __restrict v = v4_.data();
  double* __restrict acc = acc4_.data();
  const std::uint32_t* __restrict si = i_.data();
  const std::uint32_t* __restrict sj = j_.data();
  const double* __restrict sk = k_.data();
  const double* __restrict sl = l_.data();
  const double* __restrict sg = gamma_.data();
  const std::size_t count = k_.size();
  std::size_t s = 0;
#ifdef SEWN_BARE_AVX512
  // Four springs at a time, each node row [x y z 0] one aligned load. The two dot products a
  // spring needs (d·d and Δv·d) are horizontal sums of rows; the force of spring q is its row
  // d_q times its scalar c_q, broadcast. Measured faster than transposing rows to x/y/z vectors
  // and back, which takes more shuffles (bench/mss/notes.md).
  const __m256d one = _mm256_set1_pd(1.0);
  const __m256d tiny = _mm256_set1_pd(degenerate_ratio_sq);
  for (; s + 4 <= count; s += 4) {
    std::size_t I[4], J[4];
    __m256d d[4], dd[4], dv[4];
    for (int q = 0; q < 4; ++q) {
      I[q] = si[s + q];
      J[q] = sj[s + q];
      d[q] = _mm256_sub_pd(_mm256_load_pd(x + 4 * J[q]), _mm256_load_pd(x + 4 * I[q]));
      const __m256d u = _mm256_sub_pd(_mm256_load_pd(v + 4 * J[q]), _mm256_load_pd(v + 4 * I[q]));
      dd[q] = _mm256_mul_pd(d[q], d[q]);
      dv[q] = _mm256_mul_pd(d[q], u);
    }
    const __m256d d2 = hsum4(dd[0], dd[1], dd[2], dd[3]);
    const __m256d w = hsum4(dv[0], dv[1], dv[2], dv[3]);
    const __m256d l = _mm256_loadu_pd(sl + s);
    const __mmask8 ok = _mm256_cmp_pd_mask(d2, _mm256_mul_pd(tiny, _mm256_mul_pd(l, l)), _CMP_GT_OQ);
    const __m256d inv = inv_sqrt(d2);
    // c = k (1 - l/d) + γ (Δv·d)/d²; the force on i is c·d, on j its opposite
    const __m256d c = _mm256_maskz_mov_pd(
        ok, _mm256_fmadd_pd(_mm256_loadu_pd(sg + s), _mm256_mul_pd(w, _mm256_mul_pd(inv, inv)),
                            _mm256_mul_pd(_mm256_loadu_pd(sk + s), _mm256_fnmadd_pd(l, inv, one))));
    const __m256d cq[4] = {_mm256_permute4x64_pd(c, 0x00), _mm256_permute4x64_pd(c, 0x55),
                           _mm256_permute4x64_pd(c, 0xAA), _mm256_permute4x64_pd(c, 0xFF)};
    for (int q = 0; q < 4; ++q) {
      const __m256d f = _mm256_mul_pd(cq[q], d[q]);
      double* ai = acc + 4 * I[q];
      double* aj = acc + 4 * J[q];
      _mm256_store_pd(ai, _mm256_add_pd(_mm256_load_pd(ai), f));
      _mm256_store_pd(aj, _mm256_sub_pd(_mm256_load_pd(aj), f));
    }
  }
#endif
  for (; s < count; ++s) {
    const std::size_t i = si[s], j = sj[s];
    const double dx = x[4 * j] - x[4 * i], dy = x[4 * j + 1] - x[4 * i + 1], dz = x[4 * j + 2] - x[4 * i + 2];
    const double ux = v[4 * j] - v[4 * i], uy = v[4 * j + 1] - v[4 * i + 1], uz = v[4 * j + 2] - v[4 * i + 2];
    const double d2 = dx * dx + dy * dy + dz * dz;
    if (!(d2 > degenerate_ratio_sq * sl[s] * sl[s])) continue;
    const double inv = 1.0 / std::sqrt(d2);
    const double c = sk[s] * (1.0 - sl[s] * inv) + sg[s] * (ux * dx + uy * dy + uz * dz) * inv * inv;
    acc[4 * i] += c * dx;
    acc[4 * i + 1] += c * dy;
    acc[4 * i + 2] += c * dz;
    acc[4 * j] -= c * dx;
    acc[4 * j + 1] -= c * dy;
    acc[4 * j + 2] -= c * dz;
  }
}

void Bare::step_rows(double h) {
  accumulate_rows();
  double* __restrict x = x4_.data();
  double* __restrict v = v4_.data();
  double* __restrict acc = acc4_.data();
  const double* __restrict im = inv_mass4_.data();
  const double* __restrict g = g4_.data();
  // one pass: the update reads the accumulator and leaves it zeroed for the next step
  for (std::size_t k = 0; k < 4 * n_; ++k) {
    v[k] += h * (im[k] * acc[k] + g[k]);
    x[k] += h * v[k];
    acc[k] = 0.0;
  }
}

void Bare::accumulate_springs() {
  const double *__restrict x = x_[0].data(), *__restrict y = x_[1].data(), *__restrict z = x_[2].data();
  const double *__restrict vx = v_[0].data(), *__restrict vy = v_[1].data(), *__restrict vz = v_[2].data();
  double* __restrict f[3] = {f_[0].data(), f_[1].data(), f_[2].data()};
  // One spring (i, j) at a time: the chunks without AVX-512, and the springs in no chunk.
  const auto spring = [&](std::size_t i, std::size_t j, double k, double l, double g) {
    const double dx = x[j] - x[i], dy = y[j] - y[i], dz = z[j] - z[i];
    const double d2 = dx * dx + dy * dy + dz * dz;
    if (!(d2 > degenerate_ratio_sq * l * l)) return;
    const double inv = 1.0 / std::sqrt(d2);
    const double cf = k * (1.0 - l * inv) + g * ((vx[j] - vx[i]) * dx + (vy[j] - vy[i]) * dy + (vz[j] - vz[i]) * dz) * inv * inv;
    f[0][i] += cf * dx;
    f[1][i] += cf * dy;
    f[2][i] += cf * dz;
    f[0][j] -= cf * dx;
    f[1][j] -= cf * dy;
    f[2][j] -= cf * dz;
  };
  std::size_t c = 0;
#ifdef SEWN_BARE_AVX512
  // Per chunk: contiguous loads of both ends (unmasked: arrays are padded and unused lanes
  // are never stored), the arithmetic on 8 lanes, masked stores. The i-side forces of chunks
  // sharing i0 (adjacent, as sorted) are summed in registers and stored once.
  const __m512d one = _mm512_set1_pd(1.0), half = _mm512_set1_pd(0.5), three_halves = _mm512_set1_pd(1.5);
  const __m512d tiny = _mm512_set1_pd(degenerate_ratio_sq);
  __m512d si[3] = {_mm512_setzero_pd(), _mm512_setzero_pd(), _mm512_setzero_pd()};
  __mmask8 si_mask = 0;
  std::size_t si_node = chunks_.empty() ? 0 : chunks_[0].i0;
  const auto flush = [&] {
    for (int a = 0; a < 3; ++a) {
      _mm512_mask_storeu_pd(f[a] + si_node, si_mask, _mm512_add_pd(_mm512_loadu_pd(f[a] + si_node), si[a]));
      si[a] = _mm512_setzero_pd();
    }
    si_mask = 0;
  };
  for (; c < chunks_.size(); ++c) {
    const std::size_t i = chunks_[c].i0, j = chunks_[c].j0;
    const __mmask8 mk = chunks_[c].mask;
    if (i != si_node) {
      flush();
      si_node = i;
    }
    si_mask |= mk;
    const __m512d dx = _mm512_sub_pd(_mm512_loadu_pd(x + j), _mm512_loadu_pd(x + i));
    const __m512d dy = _mm512_sub_pd(_mm512_loadu_pd(y + j), _mm512_loadu_pd(y + i));
    const __m512d dz = _mm512_sub_pd(_mm512_loadu_pd(z + j), _mm512_loadu_pd(z + i));
    const __m512d ux = _mm512_sub_pd(_mm512_loadu_pd(vx + j), _mm512_loadu_pd(vx + i));
    const __m512d uy = _mm512_sub_pd(_mm512_loadu_pd(vy + j), _mm512_loadu_pd(vy + i));
    const __m512d uz = _mm512_sub_pd(_mm512_loadu_pd(vz + j), _mm512_loadu_pd(vz + i));
    const __m512d d2 = _mm512_fmadd_pd(dz, dz, _mm512_fmadd_pd(dy, dy, _mm512_mul_pd(dx, dx)));
    const __m512d du = _mm512_fmadd_pd(dz, uz, _mm512_fmadd_pd(dy, uy, _mm512_mul_pd(dx, ux)));
    const __m512d l = _mm512_load_pd(cl_.data() + lanes * c);
    const __mmask8 ok = _mm512_cmp_pd_mask(d2, _mm512_mul_pd(tiny, _mm512_mul_pd(l, l)), _CMP_GT_OQ);
    // 1/d: rsqrt14 and two Newton steps (relative error ~1e-16, as the library's)
    const __m512d hd = _mm512_mul_pd(half, d2);
    __m512d r = _mm512_maskz_rsqrt14_pd(0xFF, d2);
    r = _mm512_mul_pd(r, _mm512_fnmadd_pd(hd, _mm512_mul_pd(r, r), three_halves));
    r = _mm512_mul_pd(r, _mm512_fnmadd_pd(hd, _mm512_mul_pd(r, r), three_halves));
    // c = k (1 - l/d) + γ (Δv·d)/d²; the force on i is c·d, on j its opposite
    const __m512d cf = _mm512_maskz_mov_pd(
        ok, _mm512_fmadd_pd(_mm512_load_pd(cg_.data() + lanes * c), _mm512_mul_pd(du, _mm512_mul_pd(r, r)),
                            _mm512_mul_pd(_mm512_load_pd(ck_.data() + lanes * c), _mm512_fnmadd_pd(l, r, one))));
    const __m512d d[3] = {dx, dy, dz};
    for (int a = 0; a < 3; ++a) {
      const __m512d fs = _mm512_mul_pd(cf, d[a]);
      si[a] = _mm512_mask_add_pd(si[a], mk, si[a], fs);
      _mm512_mask_storeu_pd(f[a] + j, mk, _mm512_sub_pd(_mm512_loadu_pd(f[a] + j), fs));
    }
  }
  if (!chunks_.empty()) flush();
#else
  for (; c < chunks_.size(); ++c)
    for (std::size_t q = 0; q < lanes; ++q)
      if ((chunks_[c].mask >> q) & 1u)
        spring(chunks_[c].i0 + q, chunks_[c].j0 + q, ck_[lanes * c + q], cl_[lanes * c + q], cg_[lanes * c + q]);
#endif
  for (std::size_t s = 0; s < ri_.size(); ++s) spring(ri_[s], rj_[s], rk_[s], rl_[s], rg_[s]);
}

void Bare::step(double h) {
  if (rows_) {
    step_rows(h);
    return;
  }
  accumulate_springs();
  // one pass per axis: the update reads the accumulators and leaves them zeroed
  for (int a = 0; a < 3; ++a) {
    double* __restrict x = x_[a].data();
    double* __restrict v = v_[a].data();
    double* __restrict f = f_[a].data();
    const double* __restrict im = inv_mass_[a].data();
    const double* __restrict g = g_[a].data();
    for (std::size_t p = 0; p < n_; ++p) {
      v[p] += h * (im[p] * f[p] + g[p]);
      x[p] += h * v[p];
      f[p] = 0.0;
    }
  }
}

void Bare::set_state(const State& s) {
  if (rows_) {
    for (std::size_t p = 0; p < n_; ++p)
      for (std::size_t a = 0; a < 3; ++a) {
        x4_[4 * p + a] = s.x[3 * p + a];
        v4_[4 * p + a] = inv_mass4_[4 * p + a] != 0.0 ? s.v[3 * p + a] : 0.0;
      }
    return;
  }
  for (std::size_t p = 0; p < n_; ++p)
    for (std::size_t a = 0; a < 3; ++a) {
      x_[a][p] = s.x[3 * p + a];
      // fixed axes keep their (zero) velocity, as the library's
      v_[a][p] = inv_mass_[a][p] != 0.0 ? s.v[3 * p + a] : 0.0;
    }
}

State Bare::state() const {
  State s;
  for (std::size_t p = 0; p < n_; ++p)
    for (std::size_t a = 0; a < 3; ++a) {
      s.x.push_back(rows_ ? x4_[4 * p + a] : x_[a][p]);
      s.v.push_back(rows_ ? v4_[4 * p + a] : v_[a][p]);
    }
  return s;
}

void Bare::save() {
  saved_x_ = x_;
  saved_v_ = v_;
  saved_x4_ = x4_;
  saved_v4_ = v4_;
}

void Bare::restore() {
  for (int a = 0; a < 3; ++a) {
    std::copy(saved_x_[a].begin(), saved_x_[a].end(), x_[a].begin());
    std::copy(saved_v_[a].begin(), saved_v_[a].end(), v_[a].begin());
  }
  std::copy(saved_x4_.begin(), saved_x4_.end(), x4_.begin());
  std::copy(saved_v4_.begin(), saved_v4_.end(), v4_.begin());
}

std::vector<double> Bare::forces() {
  if (rows_) {
    accumulate_rows();
    std::vector<double> f(3 * n_);
    for (std::size_t p = 0; p < n_; ++p)
      for (std::size_t a = 0; a < 3; ++a) {
        f[3 * p + a] = acc4_[4 * p + a] + mass_[p] * gravity_[a];
        acc4_[4 * p + a] = 0.0;
      }
    return f;
  }
  accumulate_springs();
  std::vector<double> f(3 * n_);
  for (std::size_t p = 0; p < n_; ++p)
    for (std::size_t a = 0; a < 3; ++a) {
      f[3 * p + a] = f_[a][p] + mass_[p] * gravity_[a];
      f_[a][p] = 0.0;
    }
  return f;
}

double Bare::max_abs_position() const {
  double m = 0;
  for (double c : x4_) m = std::max(m, std::abs(c));
  if (!rows_)
    for (const auto& axis : x_)
      for (std::size_t p = 0; p < n_; ++p) m = std::max(m, std::abs(axis[p]));
  return std::isfinite(m) ? m : std::numeric_limits<double>::infinity();
}

}  // namespace sewn::bench::mss
