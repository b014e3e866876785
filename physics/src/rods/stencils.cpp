#include "sewn/physics/rods/stencils.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>

#ifdef __AVX__
#include <immintrin.h>
#endif

#include "sewn/physics/errors.hpp"

namespace sewn::physics::rods {

namespace {

constexpr double two_pi = 2 * std::numbers::pi;

using Q = Eigen::Matrix<double, 11, 1>;
using Vec8 = Eigen::Matrix<double, 8, 1>;  // derivatives over (e0, e1, θ0, θ1), e0 = x1 − x0, e1 = x2 − x1
using Mat8 = Eigen::Matrix<double, 8, 8>;
using Mat3 = Eigen::Matrix3d;

// Everything the strains and their derivatives are built from, at one configuration.
struct Geometry {
  double l[2], chi;
  Vec3 t[2], tb[2];   // current and start-of-step tangents
  Vec3 m1[2], m2[2];  // material directors
  Vec3 kb;            // curvature binormal 2 t0×t1/χ, χ = 1 + t0·t1
  Vec3 spin[2];       // w_j = −κ̂_j/(2 l_j): the transported frame's spin is w_j·de_j (derivatives only)
  double kappa1, kappa2, twist, reference_twist;
};

Geometry geometry(const Q& q, const BendTwistFrames& f, bool derivatives) {
#ifdef __AVX__
  // glibc's atan2 and round wrappers are legacy-SSE code: entered while some earlier code has
  // left the upper halves of the YMM registers dirty, every SSE instruction in them pays a
  // state transition. Measured natively (AVX-512 Xeon) in scenes/rod_spring.json, whose twist
  // solves evaluate stencil energies in a loop: 1.3x slower without this (the forward-AD
  // Hessian it replaced happened to clean the state). Costs one uop when the state is clean.
  _mm256_zeroupper();
#endif
  Geometry g;
  const Vec3 e[2] = {q.segment<3>(3) - q.segment<3>(0), q.segment<3>(6) - q.segment<3>(3)};
  const Vec3 director[2] = {f.director0, f.director1};
  g.tb[0] = f.tangent0;
  g.tb[1] = f.tangent1;
  Vec3 a[2];
  for (int j = 0; j < 2; ++j) {
    g.l[j] = e[j].norm();
    g.t[j] = e[j] / g.l[j];
    // Reference frame: the start-of-step director transported to the current tangent.
    a[j] = transport_exact<double>(g.tb[j], g.t[j], director[j]);
    const Vec3 b = g.t[j].cross(a[j]);
    const double c = std::cos(q[9 + j]), s = std::sin(q[9 + j]);
    g.m1[j] = c * a[j] + s * b;
    g.m2[j] = c * b - s * a[j];
    if (derivatives) g.spin[j] = (-1.0 / ((1.0 + g.tb[j].dot(g.t[j])) * g.l[j])) * g.tb[j].cross(g.t[j]);
  }
  g.chi = 1.0 + g.t[0].dot(g.t[1]);
  g.kb = (2.0 / g.chi) * g.t[0].cross(g.t[1]);
  g.kappa1 = 0.5 * (g.m2[0] + g.m2[1]).dot(g.kb);
  g.kappa2 = -0.5 * (g.m1[0] + g.m1[1]).dot(g.kb);
  const Vec3 u = transport_exact<double>(g.t[0], g.t[1], a[0]);
  const double raw = std::atan2(u.cross(a[1]).dot(g.t[1]), u.dot(a[1]));
  g.reference_twist = raw + two_pi * std::round((f.reference_twist - raw) / two_pi);
  g.twist = q[10] - q[9] + g.reference_twist;
  return g;
}

// A linear combination L = w.k1·κ1 + w.k2·κ2 + w.m·m of the strains with fixed weights: the
// energy's gradient is ∇L with w = ∂E/∂s, each strain's gradient ∇L with a unit weight.
struct Weights {
  double k1 = 0, k2 = 0, m = 0;
};

// Per edge j, L's bending part is v_0·κb + v_1·κb with v_j = ½(w.k1 m2^j − w.k2 m1^j). Turning
// frame j about t^j by ds turns v_j by ds·t^j×v_j = ds·u_j, u_j = −½(w.k1 m1^j + w.k2 m2^j).
Vec3 bend_vector(const Geometry& g, const Weights& w, int j) { return 0.5 * (w.k1 * g.m2[j] - w.k2 * g.m1[j]); }
Vec3 turned_bend_vector(const Geometry& g, const Weights& w, int j) { return -0.5 * (w.k1 * g.m1[j] + w.k2 * g.m2[j]); }

// ∂L/∂s_j, s_j = dθ_j + w_j·de_j the spin of material frame j: κb·u_j from bending, ∓w.m from
// the twist (m = θ1 − θ0 + m_ref, and m_ref turns with the frames: dm_ref = s-spins + ½κb·(dt0 + dt1)).
std::array<double, 2> spin_weights(const Geometry& g, const Weights& w) {
  return {g.kb.dot(turned_bend_vector(g, w, 0)) - w.m, g.kb.dot(turned_bend_vector(g, w, 1)) + w.m};
}

// ∇L over (e0, e1, θ0, θ1): dL = c·dκb + σ0 s0 + σ1 s1 + w.m·½κb·(de0/l0 + de1/l1), c = v_0 + v_1
// (tilts of the directors along t drop out: κb ⟂ t).
Vec8 weighted_gradient(const Geometry& g, const Weights& w) {
  const Vec3 c = bend_vector(g, w, 0) + bend_vector(g, w, 1);
  const std::array<double, 2> sigma = spin_weights(g, w);
  const double kc = g.kb.dot(c);
  const Vec3 ts = g.t[0] + g.t[1];
  // (∂κb/∂e0)ᵀc = (2 t1×c − (κb·c)(t0+t1))/(l0χ), (∂κb/∂e1)ᵀc = (−2 t0×c − (κb·c)(t0+t1))/(l1χ).
  Vec8 out;
  out.segment<3>(0) = (2.0 * g.t[1].cross(c) - kc * ts) / (g.l[0] * g.chi) + (0.5 * w.m / g.l[0]) * g.kb + sigma[0] * g.spin[0];
  out.segment<3>(3) = (-2.0 * g.t[0].cross(c) - kc * ts) / (g.l[1] * g.chi) + (0.5 * w.m / g.l[1]) * g.kb + sigma[1] * g.spin[1];
  out[6] = sigma[0];
  out[7] = sigma[1];
  return out;
}

Mat3 cross_matrix(const Vec3& a) {
  Mat3 A;
  A << 0, -a.z(), a.y(), a.z(), 0, -a.x(), -a.y(), a.x(), 0;
  return A;
}

// ∂w/∂e for the spin w = −(t̄×t)/(μ l), μ = 1 + t̄·t: with dt = P de/l (P = I − ttᵀ) and dl = t·de,
// dw = −[t̄×dt/(μl) − (t̄×t)(t̄·dt)/(μ²l) − (t̄×t)dl/(μl²)], and [t̄]×P = [t̄]× − (t̄×t)tᵀ.
Mat3 spin_jacobian(const Vec3& tb, const Vec3& t, double l) {
  const double mu = 1.0 + tb.dot(t);
  const Vec3 n = tb.cross(t);
  const Vec3 tb_across = tb - t.dot(tb) * t;
  return (-1.0 / (mu * l * l)) * (cross_matrix(tb) - 2.0 * n * t.transpose() - n * tb_across.transpose() / mu);
}

// ∇²L over (e0, e1, θ0, θ1) for fixed weights: the second variation of dL above, term by term
// (docs/rods.md, "The exact Hessian"). Several terms are not symmetric on their own (the spin is
// not a differential); their sum is. H accumulates a matrix whose symmetric part is ∇²L, so a
// symmetric pair A + Aᵀ enters as 2A, and is symmetrised at the end.
Mat8 weighted_hessian(const Geometry& g, const Weights& w) {
  Mat8 H = Mat8::Zero();
  const Vec3 v[2] = {bend_vector(g, w, 0), bend_vector(g, w, 1)};
  const Vec3 c = v[0] + v[1];
  const std::array<double, 2> sigma = spin_weights(g, w);
  const double f = c.dot(g.kb);
  const Vec3 ts = g.t[0] + g.t[1];
  const Mat3 T[2] = {(Mat3::Identity() - g.t[0] * g.t[0].transpose()) / g.l[0],
                     (Mat3::Identity() - g.t[1] * g.t[1].transpose()) / g.l[1]};
  // ∂κb/∂e_j.
  const Mat3 K[2] = {(-2.0 * cross_matrix(g.t[1]) - g.kb * ts.transpose()) / (g.l[0] * g.chi),
                     (2.0 * cross_matrix(g.t[0]) - g.kb * ts.transpose()) / (g.l[1] * g.chi)};
  // c·∇²κb: κb·c = 2c·(t0×t1)/χ as a function of the unit tangents, with partials a_j and second
  // partials F_00 = −(t1a_0ᵀ + a_0t1ᵀ)/χ, F_11 = −(t0a_1ᵀ + a_1t0ᵀ)/χ, F_01, chained through
  // t_j(e_j): T_j F_jj T_j = −(P_j t_k)(P_j a_j)ᵀ/(χ l_j²) + its transpose (k the other edge),
  // plus a_j·∂²t_j = −(a_j t_jᵀ + t_j a_jᵀ + (a_j·t_j)(I − 3t_jt_jᵀ))/l_j².
  const Vec3 a[2] = {(2.0 * g.t[1].cross(c) - f * g.t[1]) / g.chi, (-2.0 * g.t[0].cross(c) - f * g.t[0]) / g.chi};
  for (int j = 0; j < 2; ++j) {
    const Vec3& tj = g.t[j];
    const Vec3& tk = g.t[1 - j];
    const double l2 = g.l[j] * g.l[j];
    const Vec3 tk_across = tk - tj.dot(tk) * tj, aj_across = a[j] - tj.dot(a[j]) * tj;
    H.block<3, 3>(3 * j, 3 * j) = (-2.0 / (g.chi * l2)) * tk_across * aj_across.transpose() +
                                  (-1.0 / l2) * (2.0 * a[j] * tj.transpose() + a[j].dot(tj) * (Mat3::Identity() - 3.0 * tj * tj.transpose()));
  }
  const Mat3 F01 = (-2.0 * cross_matrix(c) - f * Mat3::Identity() - g.t[1] * a[1].transpose() - a[0] * g.t[0].transpose()) / g.chi;
  H.block<3, 3>(0, 3) = 2.0 * T[0] * F01 * T[1];
  for (int j = 0; j < 2; ++j) {
    const int ej = 3 * j;
    const double l2 = g.l[j] * g.l[j];
    // c turns with the frames: its tilt (dc = −t_j(v_j·dt_j)) against dκb, since t_j·dκb = −κb·dt_j.
    H.block<3, 3>(ej, ej) += g.kb * v[j].transpose() / l2;
    // The spin s_j (gradient S: w_j at e_j, 1 at θ_j) turns v_j by u_j against dκb, in c·dκb and
    // in σ_j, a symmetric pair; and σ_j's own spin, dσ_j ⊃ −(κb·v_j) s_j: together
    // 2·sym((∇(u_j·κb) − ½(κb·v_j)S) Sᵀ).
    const Vec3 u = turned_bend_vector(g, w, j);
    Vec8 X = Vec8::Zero();
    X.segment<3>(0) = K[0].transpose() * u;
    X.segment<3>(3) = K[1].transpose() * u;
    const double half_kv = 0.5 * g.kb.dot(v[j]);
    X.segment<3>(ej) -= half_kv * g.spin[j];
    X[6 + j] -= half_kv;
    H.middleCols<3>(ej).noalias() += 2.0 * X * g.spin[j].transpose();
    H.col(6 + j) += 2.0 * X;
    // The spin's coefficient w_j(e_j) varies.
    H.block<3, 3>(ej, ej) += sigma[j] * spin_jacobian(g.tb[j], g.t[j], g.l[j]);
    // The twist's ½κb·dt_j: κb varies, T_j K_k = (K_k + δ_jk t_j κbᵀ/l_j)/l_j (P_j κb = κb,
    // P_j[t_j]× = [t_j]×, and t0×t1 = ½χκb); and t_j does, −½(κb t_jᵀ + t_j κbᵀ)/l_j² (κb·t_j = 0
    // drops the rest of t_j's second derivative). The t_j κbᵀ terms cancel in the symmetric part.
    H.block<3, 3>(ej, 0) += (0.5 * w.m / g.l[j]) * K[0];
    H.block<3, 3>(ej, 3) += (0.5 * w.m / g.l[j]) * K[1];
    H.block<3, 3>(ej, ej) -= (0.5 * w.m / l2) * g.kb * g.t[j].transpose();
  }
  return 0.5 * (H + H.transpose());
}

// An (e0, e1, θ0, θ1) gradient or Hessian in the stencil's DOFs (x0, x1, x2, θ0, θ1):
// ∂/∂x0 = −∂/∂e0, ∂/∂x1 = ∂/∂e0 − ∂/∂e1, ∂/∂x2 = ∂/∂e1.
Eigen::Matrix<double, 11, 1> expand(const Vec8& g) {
  Eigen::Matrix<double, 11, 1> out;
  out << -g.segment<3>(0), g.segment<3>(0) - g.segment<3>(3), g.segment<3>(3), g.segment<2>(6);
  return out;
}

// Of a symmetric H, blockwise: with E_jk its (e_j, e_k) blocks and A_j its (e_j, θ) rows, the
// position blocks are E00, E01 − E00, −E01 | E00 − E01 − E10 + E11, E01 − E11 | E11. Only the
// upper triangle is formed, and mirrored: the result is exactly symmetric.
Eigen::Matrix<double, 11, 11> expand(const Mat8& H) {
  const Mat3 E00 = H.block<3, 3>(0, 0), E01 = H.block<3, 3>(0, 3), E11 = H.block<3, 3>(3, 3);
  const Eigen::Matrix<double, 3, 2> A0 = H.block<3, 2>(0, 6), A1 = H.block<3, 2>(3, 6);
  Eigen::Matrix<double, 11, 11> out;
  out.block<3, 3>(0, 0) = E00;
  out.block<3, 3>(0, 3) = E01 - E00;
  out.block<3, 3>(0, 6) = -E01;
  out.block<3, 3>(3, 3) = E00 - E01 - E01.transpose() + E11;
  out.block<3, 3>(3, 6) = E01 - E11;
  out.block<3, 3>(6, 6) = E11;
  out.block<3, 2>(0, 9) = -A0;
  out.block<3, 2>(3, 9) = A0 - A1;
  out.block<3, 2>(6, 9) = A1;
  out.block<2, 2>(9, 9) = H.block<2, 2>(6, 6);
  out.triangularView<Eigen::StrictlyLower>() = out.transpose();
  return out;
}

struct Strains {
  double d[3];          // s − s̄ for κ1, κ2, m
  double stiffness[3];  // EI1/D, EI2/D, GJ/D
};

Strains strains(const Geometry& g, const BendTwistRest& r) {
  const double inv_d = 1.0 / r.voronoi;
  return {{g.kappa1 - r.kappa1, g.kappa2 - r.kappa2, g.twist - r.twist}, {r.EI1 * inv_d, r.EI2 * inv_d, r.GJ * inv_d}};
}

Weights unit_weight(int strain) {
  Weights w;
  (strain == 0 ? w.k1 : strain == 1 ? w.k2 : w.m) = 1.0;
  return w;
}

// (1/D) Σ_s k_s ∇s∇sᵀ over (e0, e1, θ0, θ1): the Gauss–Newton part of the Hessian.
Mat8 gauss_newton(const Geometry& g, const Strains& s) {
  Mat8 H = Mat8::Zero();
  for (int a = 0; a < 3; ++a) {
    if (s.stiffness[a] == 0.0) continue;
    const Vec8 grad = weighted_gradient(g, unit_weight(a));
    H.noalias() += s.stiffness[a] * grad * grad.transpose();
  }
  return H;
}

// The θθ block of the exact Hessian at a gradient's cost: ∇s's θ entries are the spin weights
// of a unit weight, and of ∇²L only σ_j's own spin, −(κb·v_j) per θ_j, reaches it.
Eigen::Matrix2d angle_hessian(const Geometry& g, const Strains& s, const Weights& w) {
  Eigen::Matrix2d H = Eigen::Matrix2d::Zero();
  for (int a = 0; a < 3; ++a) {
    const std::array<double, 2> ds = spin_weights(g, unit_weight(a));
    const Eigen::Vector2d grad(ds[0], ds[1]);
    H.noalias() += s.stiffness[a] * grad * grad.transpose();
  }
  for (int j = 0; j < 2; ++j) H(j, j) -= g.kb.dot(bend_vector(g, w, j));
  return H;
}

Q pack(const Vec3& x0, const Vec3& x1, const Vec3& x2, double th0, double th1) {
  Q q;
  q << x0, x1, x2, th0, th1;
  return q;
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
  const Geometry g = geometry(pack(x0, x1, x2, theta0, theta1), frames, want != Want::energy);
  const Strains s = strains(g, rest);
  out.energy = 0.5 * (s.stiffness[0] * s.d[0] * s.d[0] + s.stiffness[1] * s.d[1] * s.d[1] + s.stiffness[2] * s.d[2] * s.d[2]);
  out.kappa1 = g.kappa1;
  out.kappa2 = g.kappa2;
  out.twist = g.twist;
  out.reference_twist = g.reference_twist;
  if (want == Want::energy) return out;
  const Weights w{s.stiffness[0] * s.d[0], s.stiffness[1] * s.d[1], s.stiffness[2] * s.d[2]};  // ∂E/∂s
  out.gradient = expand(weighted_gradient(g, w));
  if (want == Want::angle_hessian) out.hessian.bottomRightCorner<2, 2>() = angle_hessian(g, s, w);
  if (want == Want::gauss_newton) out.hessian = expand(gauss_newton(g, s));
  if (want == Want::hessian) out.hessian = expand(Mat8(gauss_newton(g, s) + weighted_hessian(g, w)));
  return out;
}

MaterialStrains material_strains(const Vec3& x0, const Vec3& x1, const Vec3& x2, double theta0, double theta1,
                                 const BendTwistFrames& frames) {
  const Geometry g = geometry(pack(x0, x1, x2, theta0, theta1), frames, false);
  return {g.kappa1, g.kappa2, g.twist, g.reference_twist};
}

}  // namespace sewn::physics::rods
