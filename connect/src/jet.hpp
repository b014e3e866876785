#pragma once
// Jet<N, H>: forward-mode automatic differentiation in N directions, with the second
// derivatives too when H. Written for the connection energies (a few hundred operations on
// ≤ 18 DOFs): a flat value/gradient/Hessian triple compiles in a fraction of the time nested
// Eigen AutoDiffScalar takes, and the Hessian comes out of one pass.
//
// Every operation is the chain rule for a function of one or two arguments:
//   g = f_x g_x + f_y g_y,
//   H = f_x H_x + f_y H_y + f_xx g_x g_xᵀ + f_yy g_y g_yᵀ + f_xy (g_x g_yᵀ + g_y g_xᵀ).
// Only what the connections use is provided: + − × ÷, sqrt, sin, cos, atan2.
// Private to the module (connect/src).

#include <array>
#include <cmath>
#include <cstddef>
#include <utility>

namespace sewn::connect::detail {

/// Packed upper triangle of a symmetric N×N matrix, row by row: (i, j), i ≤ j, sits at
/// i N − i(i − 1)/2 + (j − i). A Hessian is symmetric, so each operation updates N(N + 1)/2
/// entries instead of N² (the connections' Hessians took 25 % of a frisbee Newton iteration).
template <int N>
constexpr std::size_t packed_size = static_cast<std::size_t>(N * (N + 1) / 2);
constexpr std::size_t packed_at(int n, int i, int j) {
  if (i > j) std::swap(i, j);
  return static_cast<std::size_t>(i * n - i * (i - 1) / 2 + (j - i));
}

template <int N, bool H>
struct Jet {
  double v = 0;
  std::array<double, N> g{};
  std::array<double, H ? packed_size<N> : 1> h{};  // packed upper triangle (packed_at)

  Jet() = default;
  Jet(double value) : v(value) {}  // NOLINT: constants mix freely, as with double
  /// The independent variable of direction i.
  static Jet variable(double value, int i) {
    Jet r(value);
    r.g[static_cast<std::size_t>(i)] = 1;
    return r;
  }
  [[nodiscard]] double hessian(int i, int j) const {
    if constexpr (H) return h[packed_at(N, i, j)];
    return 0;
  }
};

template <int N, bool H>
Jet<N, H> unary(const Jet<N, H>& a, double f, double f1, double f2) {
  Jet<N, H> r(f);
  for (std::size_t i = 0; i < N; ++i) r.g[i] = f1 * a.g[i];
  if constexpr (H) {
    std::size_t k = 0;
    for (std::size_t i = 0; i < N; ++i)
      for (std::size_t j = i; j < N; ++j, ++k) r.h[k] = f1 * a.h[k] + f2 * a.g[i] * a.g[j];
  }
  return r;
}

template <int N, bool H>
Jet<N, H> binary(const Jet<N, H>& a, const Jet<N, H>& b, double f, double fa, double fb, double faa, double fbb,
                 double fab) {
  Jet<N, H> r(f);
  for (std::size_t i = 0; i < N; ++i) r.g[i] = fa * a.g[i] + fb * b.g[i];
  if constexpr (H) {
    std::size_t k = 0;
    for (std::size_t i = 0; i < N; ++i) {
      // the outer products' row i: faa g_a,i + fab g_b,i against g_a, and fbb g_b,i + fab g_a,i against g_b
      const double ca = faa * a.g[i] + fab * b.g[i], cb = fbb * b.g[i] + fab * a.g[i];
      for (std::size_t j = i; j < N; ++j, ++k) r.h[k] = fa * a.h[k] + fb * b.h[k] + ca * a.g[j] + cb * b.g[j];
    }
  }
  return r;
}

template <int N, bool H>
Jet<N, H> operator+(Jet<N, H> a, const Jet<N, H>& b) {
  a.v += b.v;
  for (std::size_t i = 0; i < a.g.size(); ++i) a.g[i] += b.g[i];
  if constexpr (H)
    for (std::size_t i = 0; i < a.h.size(); ++i) a.h[i] += b.h[i];
  return a;
}
template <int N, bool H>
Jet<N, H> operator-(Jet<N, H> a) {
  a.v = -a.v;
  for (double& x : a.g) x = -x;
  if constexpr (H)
    for (double& x : a.h) x = -x;
  return a;
}
template <int N, bool H>
Jet<N, H> operator-(const Jet<N, H>& a, const Jet<N, H>& b) {
  return a + (-b);
}
template <int N, bool H>
Jet<N, H> operator*(Jet<N, H> a, double s) {
  a.v *= s;
  for (double& x : a.g) x *= s;
  if constexpr (H)
    for (double& x : a.h) x *= s;
  return a;
}
template <int N, bool H>
Jet<N, H> operator*(double s, const Jet<N, H>& a) {
  return a * s;
}
template <int N, bool H>
Jet<N, H> operator*(const Jet<N, H>& a, const Jet<N, H>& b) {
  return binary(a, b, a.v * b.v, b.v, a.v, 0.0, 0.0, 1.0);
}
template <int N, bool H>
Jet<N, H> operator/(const Jet<N, H>& a, const Jet<N, H>& b) {
  const double ib = 1 / b.v;
  return binary(a, b, a.v * ib, ib, -a.v * ib * ib, 0.0, 2 * a.v * ib * ib * ib, -ib * ib);
}

template <int N, bool H>
Jet<N, H> sqrt(const Jet<N, H>& a) {
  const double s = std::sqrt(a.v);
  return unary(a, s, 0.5 / s, -0.25 / (s * a.v));
}
template <int N, bool H>
Jet<N, H> sin(const Jet<N, H>& a) {
  const double s = std::sin(a.v), c = std::cos(a.v);
  return unary(a, s, c, -s);
}
template <int N, bool H>
Jet<N, H> cos(const Jet<N, H>& a) {
  const double s = std::sin(a.v), c = std::cos(a.v);
  return unary(a, c, -s, -c);
}
/// atan2(y, x): f_y = x/r², f_x = −y/r², f_yy = −2xy/r⁴, f_xx = 2xy/r⁴, f_xy = (y² − x²)/r⁴.
template <int N, bool H>
Jet<N, H> atan2(const Jet<N, H>& y, const Jet<N, H>& x) {
  const double r2 = x.v * x.v + y.v * y.v, r4 = r2 * r2;
  return binary(y, x, std::atan2(y.v, x.v), x.v / r2, -y.v / r2, -2 * x.v * y.v / r4, 2 * x.v * y.v / r4,
                (y.v * y.v - x.v * x.v) / r4);
}

inline double value_of(double v) { return v; }
template <int N, bool H>
double value_of(const Jet<N, H>& a) {
  return a.v;
}

/// A 3-vector of any scalar, with the few operations the frames need.
template <class T>
struct V3 {
  T x, y, z;
};
template <class T>
V3<T> operator+(const V3<T>& a, const V3<T>& b) {
  return {a.x + b.x, a.y + b.y, a.z + b.z};
}
template <class T>
V3<T> operator-(const V3<T>& a, const V3<T>& b) {
  return {a.x - b.x, a.y - b.y, a.z - b.z};
}
template <class T, class S>
V3<T> operator*(const S& s, const V3<T>& a) {
  return {s * a.x, s * a.y, s * a.z};
}
template <class T>
T dot(const V3<T>& a, const V3<T>& b) {
  return a.x * b.x + a.y * b.y + a.z * b.z;
}
template <class T>
V3<T> cross(const V3<T>& a, const V3<T>& b) {
  return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
template <class T>
V3<T> normalized(const V3<T>& a) {
  using std::sqrt;
  return (T(1.0) / sqrt(dot(a, a))) * a;
}
template <class T>
V3<T> constant(double x, double y, double z) {
  return {T(x), T(y), T(z)};
}
/// P_a^b(u), the exact form c u + w×u + (w·u)/(1+c) w of physics::rods::transport_exact on V3.
template <class T>
V3<T> transport(const V3<T>& a, const V3<T>& b, const V3<T>& u) {
  const T c = dot(a, b);
  const V3<T> w = cross(a, b);
  return c * u + cross(w, u) + (dot(w, u) / (T(1.0) + c)) * w;
}
/// The signed angle from u to v about axis (|u|, |v| need not be 1; u, v ⟂ axis).
template <class T>
T signed_angle(const V3<T>& u, const V3<T>& v, const V3<T>& axis) {
  using std::atan2;
  return atan2(dot(cross(u, v), axis), dot(u, v));
}
/// The 3-vector at offset `at` of an indexable q (stencils are laid out by offset, a rod's θ
/// leaving the positions after it unaligned).
template <class T, class Q>
V3<T> vec_at(const Q& q, int at) {
  return {q[at], q[at + 1], q[at + 2]};
}

}  // namespace sewn::connect::detail
