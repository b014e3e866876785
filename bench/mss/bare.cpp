#include "bare.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#if defined(__AVX512F__) && defined(__AVX512VL__)
#include <immintrin.h>
#define SEWN_BARE_AVX512 1
#endif

namespace sewn::bench::mss {

namespace {

// The library's degenerate-spring guard (springs.cpp): no force below d² = 1e-18 l².
constexpr double degenerate_ratio_sq = 1e-18;

}  // namespace

Bare::Bare(const ModelSpec& spec) {
  if (spec.environment != 0) throw std::runtime_error("Bare: drag is not implemented (the cost cases have none)");
  const MassSpring ms = mass_spring(spec);
  n_ = spec.mesh.num_points();
  x_.assign(4 * n_, 0.0);
  v_.assign(4 * n_, 0.0);
  acc_.assign(4 * n_, 0.0);
  inv_mass_.assign(4 * n_, 0.0);
  g_.assign(4 * n_, 0.0);
  mass_.assign(ms.mass.begin(), ms.mass.end());
  gravity_ = spec.gravity;
  for (std::size_t p = 0; p < n_; ++p) {
    const bool fixed = !spec.fixed.empty() && spec.fixed[p] != 0;
    for (std::size_t a = 0; a < 3; ++a) {
      x_[4 * p + a] = spec.mesh.points[p][a];
      inv_mass_[4 * p + a] = fixed ? 0.0 : 1.0 / ms.mass[p];
      g_[4 * p + a] = fixed ? 0.0 : spec.gravity[a];
    }
  }
  i_.assign(ms.i.begin(), ms.i.end());
  j_.assign(ms.j.begin(), ms.j.end());
  k_.assign(ms.k.begin(), ms.k.end());
  l_.assign(ms.l.begin(), ms.l.end());
  gamma_.assign(ms.gamma.begin(), ms.gamma.end());
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

void Bare::accumulate_springs() {
  const double* __restrict x = x_.data();
  const double* __restrict v = v_.data();
  double* __restrict acc = acc_.data();
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

void Bare::step(double h) {
  accumulate_springs();
  double* __restrict x = x_.data();
  double* __restrict v = v_.data();
  double* __restrict acc = acc_.data();
  const double* __restrict im = inv_mass_.data();
  const double* __restrict g = g_.data();
  // one pass: the update reads the accumulator and leaves it zeroed for the next step
  for (std::size_t k = 0; k < 4 * n_; ++k) {
    v[k] += h * (im[k] * acc[k] + g[k]);
    x[k] += h * v[k];
    acc[k] = 0.0;
  }
}

void Bare::set_state(const State& s) {
  for (std::size_t p = 0; p < n_; ++p)
    for (std::size_t a = 0; a < 3; ++a) {
      x_[4 * p + a] = s.x[3 * p + a];
      // fixed axes keep their (zero) velocity, as the library's
      v_[4 * p + a] = inv_mass_[4 * p + a] != 0.0 ? s.v[3 * p + a] : 0.0;
    }
}

State Bare::state() const {
  State s;
  for (std::size_t p = 0; p < n_; ++p)
    for (std::size_t a = 0; a < 3; ++a) {
      s.x.push_back(x_[4 * p + a]);
      s.v.push_back(v_[4 * p + a]);
    }
  return s;
}

void Bare::save() {
  saved_x_ = x_;
  saved_v_ = v_;
}

void Bare::restore() {
  std::copy(saved_x_.begin(), saved_x_.end(), x_.begin());
  std::copy(saved_v_.begin(), saved_v_.end(), v_.begin());
}

std::vector<double> Bare::forces() {
  std::fill(acc_.begin(), acc_.end(), 0.0);
  accumulate_springs();
  std::vector<double> f(3 * n_);
  for (std::size_t p = 0; p < n_; ++p)
    for (std::size_t a = 0; a < 3; ++a) f[3 * p + a] = acc_[4 * p + a] + mass_[p] * gravity_[a];
  std::fill(acc_.begin(), acc_.end(), 0.0);
  return f;
}

double Bare::max_abs_position() const {
  double m = 0;
  for (double c : x_) m = std::max(m, std::abs(c));
  return std::isfinite(m) ? m : std::numeric_limits<double>::infinity();
}

}  // namespace sewn::bench::mss
