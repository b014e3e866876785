#include "sewn/physics/basic_terms.hpp"

#include <cmath>
#include <string>

#include "parallel/ranges.hpp"
#include "sewn/physics/errors.hpp"

#if defined(__AVX2__) && defined(__FMA__)
#include <immintrin.h>
#endif

namespace sewn::physics {

Gravity::Gravity(const Eigen::Vector3d& g) : g_(Eigen::Vector3d::Zero()) { set_g(g); }

void Gravity::set_g(const Eigen::Vector3d& g) {
  if (!g.allFinite()) throw InputError("Gravity: acceleration must be finite");
  g_ = g;
  touch_parameters();
}

namespace {

// f += m g on the nodes [i, end). Elementwise: the same at any split.
void add_weights(const double* __restrict m, const Eigen::Vector3d& g, double* __restrict out, std::size_t i, std::size_t end) {
  const double gx = g.x(), gy = g.y(), gz = g.z();
#if defined(__AVX2__) && defined(__FMA__)
  // Four nodes are 12 consecutive doubles: three full registers whose masses and g components
  // follow fixed patterns (the compiler leaves the stride-3 scalar loop unvectorised).
  const __m256d g0 = _mm256_setr_pd(gx, gy, gz, gx), g1 = _mm256_setr_pd(gy, gz, gx, gy),
                g2 = _mm256_setr_pd(gz, gx, gy, gz);
  for (; i + 4 <= end; i += 4) {
    const __m256d mm = _mm256_loadu_pd(m + i);
    double* o = out + 3 * i;
    _mm256_storeu_pd(o, _mm256_fmadd_pd(_mm256_permute4x64_pd(mm, 0x40), g0, _mm256_loadu_pd(o)));
    _mm256_storeu_pd(o + 4, _mm256_fmadd_pd(_mm256_permute4x64_pd(mm, 0xA5), g1, _mm256_loadu_pd(o + 4)));
    _mm256_storeu_pd(o + 8, _mm256_fmadd_pd(_mm256_permute4x64_pd(mm, 0xFE), g2, _mm256_loadu_pd(o + 8)));
  }
#endif
  for (; i < end; ++i) {
    out[3 * i] += m[i] * gx;
    out[3 * i + 1] += m[i] * gy;
    out[3 * i + 2] += m[i] * gz;
  }
}

// Doubles of f per range below which one thread adds the weights (the integrators' vector
// passes use the same grain).
constexpr std::size_t weight_grain = 3 * 1024;

}  // namespace

// In ranges of nodes at 2+ threads: on 32³ a serial pass here was the largest part of the
// semi-implicit step the other thread waited for (perf: 3.4 % of the run's samples on the
// calling thread while the worker spun), and each thread's ranges of f stay in its own cache.
void Gravity::add_forces(const StateView& s, std::span<double> f) const {
  const std::size_t n = s.mass.size();
  const int parts = detail::parts_for(3 * n, weight_grain);
  detail::run_parts(parts, [&](int t) {
    add_weights(s.mass.data(), g_, f.data(), detail::range_begin(n, parts, t), detail::range_begin(n, parts, t + 1));
  });
}

double Gravity::potential_energy(const StateView& s) const {
  double e = 0.0;
  for (std::size_t i = 0; i < s.mass.size(); ++i)
    e -= s.mass[i] * (g_.x() * s.x[3 * i] + g_.y() * s.x[3 * i + 1] + g_.z() * s.x[3 * i + 2]);
  return e;
}

MassDamping::MassDamping(double c) : c_(0.0) { set_coefficient(c); }

void MassDamping::set_coefficient(double c) {
  if (!(std::isfinite(c) && c >= 0)) throw InputError("MassDamping: coefficient must be finite and >= 0, got " + std::to_string(c));
  c_ = c;
  touch_parameters();
}

void MassDamping::add_forces(const StateView& s, std::span<double> f) const {
  const double* __restrict m = s.mass.data();
  const double* __restrict v = s.v.data();
  double* __restrict out = f.data();
  for (std::size_t i = 0; i < s.mass.size(); ++i)
    for (int a = 0; a < 3; ++a) out[3 * i + a] -= c_ * m[i] * v[3 * i + a];
}

double MassDamping::dissipation(const StateView& s) const {
  double psi = 0.0;
  for (std::size_t i = 0; i < s.mass.size(); ++i)
    psi += s.mass[i] * (s.v[3 * i] * s.v[3 * i] + s.v[3 * i + 1] * s.v[3 * i + 1] + s.v[3 * i + 2] * s.v[3 * i + 2]);
  return 0.5 * c_ * psi;
}

void MassDamping::add_jacobians(const StateView& s, const JacobianRequest& req) const {
  if (req.matrix == nullptr || req.cv == 0.0) return;
  for (Index i = 0; i < s.size(); ++i)
    req.matrix->block(req.matrix->diagonal(i)).diagonal().array() -= req.cv * c_ * s.mass[i];
}

void MassDamping::add_stability_rows(const StateView& s, StabilityRows& rows) const {
  for (Index i = 0; i < s.size(); ++i)
    rows.add_diagonal(StabilityRows::damping, i, Eigen::Matrix3d::Identity() * (c_ * s.mass[i]));
}

}  // namespace sewn::physics
