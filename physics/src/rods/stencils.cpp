#include "sewn/physics/rods/stencils.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>

#include <unsupported/Eigen/AutoDiff>

#include "sewn/physics/errors.hpp"

namespace sewn::physics::rods {

namespace {

constexpr double two_pi = 2 * std::numbers::pi;

template <class T>
using V3 = Eigen::Matrix<T, 3, 1>;
using AD = Eigen::AutoDiffScalar<Eigen::Matrix<double, 11, 1>>;

double value_of(double v) { return v; }
double value_of(const AD& v) { return v.value(); }

template <class T>
struct Core {
  T energy{};
  Eigen::Matrix<T, 11, 1> gradient;
  double kappa1 = 0, kappa2 = 0, twist = 0, reference_twist = 0;
};

// Energy and closed-form gradient of the bend-twist stencil over q = (x0, x1, x2, θ0, θ1).
// Instantiated with double (values) and AutoDiffScalar (Hessian = derivative of the gradient).
template <class T>
Core<T> core(const Eigen::Matrix<T, 11, 1>& q, const BendTwistRest& r, const BendTwistFrames& f, bool with_gradient,
             Eigen::Matrix2d* angle_hessian = nullptr) {
  Core<T> out;
  const V3<T> e0 = q.template segment<3>(3) - q.template segment<3>(0);
  const V3<T> e1 = q.template segment<3>(6) - q.template segment<3>(3);
  using std::cos;
  using std::sin;
  using std::sqrt;
  using std::atan2;
  const T l0 = sqrt(e0.dot(e0)), l1 = sqrt(e1.dot(e1));
  const V3<T> t0 = e0 / l0, t1 = e1 / l1;
  const V3<T> tb0 = f.tangent0.cast<T>(), tb1 = f.tangent1.cast<T>();
  // Reference frames: the start-of-step directors transported to the current tangents.
  const V3<T> a0 = transport_exact<T>(tb0, t0, f.director0.cast<T>());
  const V3<T> a1 = transport_exact<T>(tb1, t1, f.director1.cast<T>());
  const V3<T> b0 = t0.cross(a0), b1 = t1.cross(a1);
  const T c0 = cos(q[9]), s0 = sin(q[9]), c1 = cos(q[10]), s1 = sin(q[10]);
  const V3<T> m1_0 = c0 * a0 + s0 * b0, m2_0 = c0 * b0 - s0 * a0;
  const V3<T> m1_1 = c1 * a1 + s1 * b1, m2_1 = c1 * b1 - s1 * a1;
  const T chi = T(1.0) + t0.dot(t1);
  const V3<T> kb = (T(2.0) / chi) * t0.cross(t1);
  const T k1 = T(0.5) * (m2_0 + m2_1).dot(kb);
  const T k2 = T(-0.5) * (m1_0 + m1_1).dot(kb);
  const V3<T> u = transport_exact<T>(t0, t1, a0);
  const T raw = atan2(u.cross(a1).dot(t1), u.dot(a1));
  const double wrap = two_pi * std::round((f.reference_twist - value_of(raw)) / two_pi);
  const T mref = raw + wrap;
  const T m = q[10] - q[9] + mref;
  const T d1 = k1 - r.kappa1, d2 = k2 - r.kappa2, dm = m - r.twist;
  const double inv_d = 1.0 / r.voronoi;
  out.energy = (0.5 * inv_d) * (r.EI1 * d1 * d1 + r.EI2 * d2 * d2 + r.GJ * dm * dm);
  out.kappa1 = value_of(k1);
  out.kappa2 = value_of(k2);
  out.twist = value_of(m);
  out.reference_twist = value_of(mref);
  if (!with_gradient) return out;

  // dE = c·dκb + σ0 s0 + σ1 s1 + tw·½κb·(de0/l0 + de1/l1), with s_j = dθ_j + ω_j the spin of
  // material frame j and ω_j = −½ κ̂_j·de_j/l_j, κ̂_j = 2 t̄_j×t_j/(1 + t̄_j·t_j) (the spin of a
  // transported frame; zero at t = t̄). Tilts of the directors along t drop out (κb ⟂ t).
  const V3<T> c = (inv_d * T(0.5)) * ((r.EI1 * d1) * (m2_0 + m2_1) - (r.EI2 * d2) * (m1_0 + m1_1));
  const T tw = (r.GJ * inv_d) * dm;
  const T sigma0 = (-0.5 * inv_d) * (r.EI1 * d1 * kb.dot(m1_0) + r.EI2 * d2 * kb.dot(m2_0)) - tw;
  const T sigma1 = (-0.5 * inv_d) * (r.EI1 * d1 * kb.dot(m1_1) + r.EI2 * d2 * kb.dot(m2_1)) + tw;
  const V3<T> kh0 = (T(2.0) / (T(1.0) + tb0.dot(t0))) * tb0.cross(t0);
  const V3<T> kh1 = (T(2.0) / (T(1.0) + tb1.dot(t1))) * tb1.cross(t1);
  const T kc = kb.dot(c);
  const V3<T> ts = t0 + t1;
  // (∂κb/∂e0)ᵀc = (2 t1×c − (κb·c)(t0+t1))/(l0χ), (∂κb/∂e1)ᵀc = (−2 t0×c − (κb·c)(t0+t1))/(l1χ).
  const V3<T> ge0 = (T(2.0) * t1.cross(c) - kc * ts) / (l0 * chi) + (tw * kb - sigma0 * kh0) / (T(2.0) * l0);
  const V3<T> ge1 = (T(-2.0) * t0.cross(c) - kc * ts) / (l1 * chi) + (tw * kb - sigma1 * kh1) / (T(2.0) * l1);
  out.gradient.template segment<3>(0) = -ge0;
  out.gradient.template segment<3>(3) = ge0 - ge1;
  out.gradient.template segment<3>(6) = ge1;
  out.gradient[9] = sigma0;
  out.gradient[10] = sigma1;
  if (angle_hessian) {
    // ∂κ1/∂θj = −½ m1^j·κb, ∂κ2/∂θj = −½ m2^j·κb; since ∂m1/∂θ = m2 and ∂m2/∂θ = −m1, the
    // second derivatives are ∂²κ1/∂θj² = ∂κ2/∂θj and ∂²κ2/∂θj² = −∂κ1/∂θj (no cross terms);
    // the twist is linear in θ with ∂m/∂θ = (−1, 1).
    const double dk1[2] = {-0.5 * value_of(m1_0.dot(kb)), -0.5 * value_of(m1_1.dot(kb))};
    const double dk2[2] = {-0.5 * value_of(m2_0.dot(kb)), -0.5 * value_of(m2_1.dot(kb))};
    const double dm[2] = {-1.0, 1.0};
    const double e1 = value_of(d1), e2 = value_of(d2);
    for (int j = 0; j < 2; ++j)
      for (int k = 0; k < 2; ++k) {
        double h = r.EI1 * dk1[j] * dk1[k] + r.EI2 * dk2[j] * dk2[k] + r.GJ * dm[j] * dm[k];
        if (j == k) h += r.EI1 * e1 * dk2[j] - r.EI2 * e2 * dk1[j];
        (*angle_hessian)(j, k) = inv_d * h;
      }
  }
  return out;
}

Eigen::Matrix<double, 11, 1> pack(const Vec3& x0, const Vec3& x1, const Vec3& x2, double th0, double th1) {
  Eigen::Matrix<double, 11, 1> q;
  q << x0, x1, x2, th0, th1;
  return q;
}

// One strain's gradient through core()'s closed-form gradient: the energy (1/2D)·D·(s − (s − 1))²
// has the gradient (s − s̄)∇s = ∇s (one stiffness D, the others 0, s̄ one below the current s),
// so the gradient code serves the strains' gradients too (a separate copy of it would have to be
// kept in step; making it take the weights ∂E/∂s cost the AD Hessian pass ~30 %). 4 gradients'
// work in all, against the AD Hessian's ~15 and the 11×11 eigendecomposition.
Eigen::Matrix<double, 11, 1> strain_gradient(const Eigen::Matrix<double, 11, 1>& q, const BendTwistRest& rest,
                                             const BendTwistFrames& frames, const Core<double>& at, int strain) {
  BendTwistRest unit = rest;
  unit.EI1 = strain == 0 ? rest.voronoi : 0.0;
  unit.EI2 = strain == 1 ? rest.voronoi : 0.0;
  unit.GJ = strain == 2 ? rest.voronoi : 0.0;
  unit.kappa1 = at.kappa1 - 1;
  unit.kappa2 = at.kappa2 - 1;
  unit.twist = at.twist - 1;
  return core<double>(q, unit, frames, true).gradient;
}

// (1/D)[EI1 ∇κ1∇κ1ᵀ + EI2 ∇κ2∇κ2ᵀ + GJ ∇m∇mᵀ] at q, whose strains core() gave as `at`.
Eigen::Matrix<double, 11, 11> gauss_newton_hessian(const Eigen::Matrix<double, 11, 1>& q, const BendTwistRest& rest,
                                                   const BendTwistFrames& frames, const Core<double>& at) {
  const double stiffness[3] = {rest.EI1, rest.EI2, rest.GJ};
  Eigen::Matrix<double, 11, 11> H = Eigen::Matrix<double, 11, 11>::Zero();
  for (int a = 0; a < 3; ++a) {
    if (stiffness[a] == 0.0) continue;
    const Eigen::Matrix<double, 11, 1> g = strain_gradient(q, rest, frames, at, a);
    H.noalias() += (stiffness[a] / rest.voronoi) * g.lazyProduct(g.transpose());
  }
  return H;
}

void check_section_inputs(double E, double nu, double a, double b, const char* who) {
  auto bad = [&](const std::string& why) { throw InputError(std::string("rods::Section::") + who + ": " + why); };
  if (!(std::isfinite(E) && E > 0)) bad("Young's modulus E must be finite and > 0, got " + std::to_string(E));
  if (!(std::isfinite(nu) && nu > -1 && nu < 0.5)) bad("Poisson's ratio must be in (-1, 0.5), got " + std::to_string(nu));
  if (!(std::isfinite(a) && a > 0 && std::isfinite(b) && b > 0))
    bad("section size must be finite and > 0, got " + std::to_string(a) + ", " + std::to_string(b));
}

}  // namespace

Vec3 any_perpendicular(const Vec3& t) {
  Eigen::Index k = 0;
  t.cwiseAbs().minCoeff(&k);
  return t.cross(Vec3::Unit(k)).normalized();
}

Vec3 parallel_transport(const Vec3& a, const Vec3& b, const Vec3& u) {
  const double c = a.dot(b);
  if (1 + c > 1e-6) return transport_exact<double>(a, b, u);
  // Nearly opposite: a half turn about p ⟂ a takes a to −a, then the (now regular) transport
  // from −a to b.
  const Vec3 p = any_perpendicular(a);
  const Vec3 a_flipped = 2 * p.dot(a) * p - a;
  const Vec3 u_flipped = 2 * p.dot(u) * p - u;
  return transport_exact<double>(a_flipped, b, u_flipped);
}

double signed_angle(const Vec3& u, const Vec3& v, const Vec3& n) { return std::atan2(u.cross(v).dot(n), u.dot(v)); }

double unwrap_angle(double raw, double previous) { return raw + two_pi * std::round((previous - raw) / two_pi); }

Section Section::circular(double E, double nu, double r) {
  check_section_inputs(E, nu, r, r, "circular");
  return elliptic(E, nu, r, r);
}

Section Section::elliptic(double E, double nu, double a, double b) {
  check_section_inputs(E, nu, a, b, "elliptic");
  const double pi = std::numbers::pi;
  const double G = E / (2 * (1 + nu));
  Section s;
  s.EA = E * pi * a * b;
  s.EI1 = E * pi * a * a * a * b / 4;
  s.EI2 = E * pi * a * b * b * b / 4;
  s.GJ = G * pi * a * a * a * b * b * b / (a * a + b * b);
  return s;
}

StretchEval stretch(const Vec3& x0, const Vec3& x1, double EA, double rest_length, bool want_hessian) {
  StretchEval out;
  const Vec3 e = x1 - x0;
  const double l = e.norm();
  const Vec3 t = e / l;
  const double strain = l / rest_length - 1;
  out.energy = 0.5 * EA * rest_length * strain * strain;
  const Vec3 g = EA * strain * t;
  out.gradient << -g, g;
  if (want_hessian) {
    const Eigen::Matrix3d K = (EA / rest_length) * t * t.transpose() +
                              (EA * strain / l) * (Eigen::Matrix3d::Identity() - t * t.transpose());
    out.hessian << K, -K, -K, K;
  }
  return out;
}

Eigen::Matrix<double, 6, 6> stretch_hessian_psd(const Vec3& x0, const Vec3& x1, double EA, double rest_length) {
  const Vec3 e = x1 - x0;
  const double l = e.norm();
  const Vec3 t = e / l;
  // [[K, -K], [-K, K]] has the eigenvalues 2·eig(K) and 0; K's are EA/l̄ along t and
  // EA·strain/l across it, so clamping the transverse one at 0 is the nearest PSD matrix.
  const double across = std::max(0.0, EA * (l / rest_length - 1) / l);
  const Eigen::Matrix3d K = (EA / rest_length) * t * t.transpose() + across * (Eigen::Matrix3d::Identity() - t * t.transpose());
  Eigen::Matrix<double, 6, 6> H;
  H << K, -K, -K, K;
  return H;
}

BendTwistEval bend_twist(const Vec3& x0, const Vec3& x1, const Vec3& x2, double theta0, double theta1,
                         const BendTwistRest& rest, const BendTwistFrames& frames, Want want) {
  BendTwistEval out;
  const Eigen::Matrix<double, 11, 1> q = pack(x0, x1, x2, theta0, theta1);
  if (want != Want::hessian) {
    Eigen::Matrix2d angles;
    const bool grad = want != Want::energy;
    const Core<double> c = core<double>(q, rest, frames, grad, want == Want::angle_hessian ? &angles : nullptr);
    out.energy = c.energy;
    if (grad) out.gradient = c.gradient;
    if (want == Want::angle_hessian) out.hessian.bottomRightCorner<2, 2>() = angles;
    if (want == Want::gauss_newton) out.hessian = gauss_newton_hessian(q, rest, frames, c);
    out.kappa1 = c.kappa1;
    out.kappa2 = c.kappa2;
    out.twist = c.twist;
    out.reference_twist = c.reference_twist;
    return out;
  }
  Eigen::Matrix<AD, 11, 1> qa;
  for (int k = 0; k < 11; ++k) qa[k] = AD(q[k], 11, k);
  const Core<AD> c = core<AD>(qa, rest, frames, true);
  out.energy = c.energy.value();
  for (int k = 0; k < 11; ++k) {
    out.gradient[k] = c.gradient[k].value();
    out.hessian.row(k) = c.gradient[k].derivatives().transpose();
  }
  // Exact up to round-off; symmetrised so solvers see a symmetric matrix.
  out.hessian = 0.5 * (out.hessian + out.hessian.transpose()).eval();
  out.kappa1 = c.kappa1;
  out.kappa2 = c.kappa2;
  out.twist = c.twist;
  out.reference_twist = c.reference_twist;
  return out;
}

MaterialStrains material_strains(const Vec3& x0, const Vec3& x1, const Vec3& x2, double theta0, double theta1,
                                 const BendTwistFrames& frames) {
  BendTwistRest unit;
  const Core<double> c = core<double>(pack(x0, x1, x2, theta0, theta1), unit, frames, false);
  return {c.kappa1, c.kappa2, c.twist, c.reference_twist};
}

}  // namespace sewn::physics::rods
