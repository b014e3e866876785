#pragma once
// Discrete elastic rods (Bergou et al. 2008, time-parallel frames of Bergou et al. 2010;
// PHYSICS_NOTES §3.1): parallel transport, cross sections and the two per-element energies
// of a rod, each as value, gradient and Hessian over a documented stencil.
//
// Conventions (fixed here, checked by finite differences in tests/physics/test_rods*.cpp):
//   e^j = x_{j+1} − x_j, t^j = e^j/|e^j|; reference director a1^j ⟂ t^j, a2^j = t^j × a1^j;
//   material directors m1 = cos θ a1 + sin θ a2, m2 = −sin θ a1 + cos θ a2;
//   curvature binormal κb = 2 t^{i−1}×t^i / (1 + t^{i−1}·t^i) (unit-tangent form, |κb| =
//   2 tan(φ/2) for a turning angle φ); material curvatures κ1 = ½(m2^{i−1}+m2^i)·κb,
//   κ2 = −½(m1^{i−1}+m1^i)·κb; twist m = θ^i − θ^{i−1} + m_ref, m_ref = signed angle about t^i
//   from P_{t^{i−1}}^{t^i}(a1^{i−1}) to a1^i, tracked continuously (2πk added).
//
// Reference frames inside a step are the start-of-step frames transported to the current
// tangents: a1^j(x) = P_{t̄^j}^{t^j(x)}(ā1^j). The energies below are functions of the
// positions and angles through that construction, and their gradients and Hessians are exact
// for it (the spin of the transported frame, −½κ(t̄, t)·dt, is included; at t = t̄ it
// vanishes and the gradient is PHYSICS_NOTES §3.1's).

#include <array>

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace sewn::physics::rods {

using Vec3 = Eigen::Vector3d;

/// P_a^b(u): the rotation about a×b taking unit a to unit b, applied to u. Exact formula
/// c u + w×u + (w·u)/(1+c) w (c = a·b, w = a×b) while 1 + c > 1e-6; closer to b = −a, where it
/// is singular, it rotates through an axis ⟂ a chosen from a's smallest component (two
/// well-defined half turns; continuity in a, b is lost only there). O(1).
[[nodiscard]] Vec3 parallel_transport(const Vec3& a, const Vec3& b, const Vec3& u);

/// The exact formula c u + w×u + (w·u)/(1+c) w of P_a^b(u), for any scalar type (the
/// connect module differentiates through it with AutoDiffScalar).
/// Unguarded: non-finite at b = −a; parallel_transport() is the guarded double version. O(1).
template <class T>
[[nodiscard]] Eigen::Matrix<T, 3, 1> transport_exact(const Eigen::Matrix<T, 3, 1>& a, const Eigen::Matrix<T, 3, 1>& b,
                                                     const Eigen::Matrix<T, 3, 1>& u) {
  const T c = a.dot(b);
  const Eigen::Matrix<T, 3, 1> w = a.cross(b);
  return c * u + w.cross(u) + (w.dot(u) / (T(1.0) + c)) * w;
}

/// Signed angle from u to v about the unit axis n (both ⟂ n), in (−π, π]. O(1).
[[nodiscard]] double signed_angle(const Vec3& u, const Vec3& v, const Vec3& n);

/// The value closest to `previous` among raw + 2πk: how the reference twist and every other
/// angle measured by atan2 is tracked continuously. O(1).
[[nodiscard]] double unwrap_angle(double raw, double previous);

/// A unit vector ⟂ unit t (deterministic: built from t's smallest component). O(1).
[[nodiscard]] Vec3 any_perpendicular(const Vec3& t);

/// Elastic moduli of a cross section, all in SI: EA (N), EI1, EI2, GJ (N·m²). EI1 pairs with
/// κ1 = κb·m̄2 (bending in the plane of t and m1, which strains fibres offset along m1:
/// EI1 = E∫y1²dA), EI2 with κ2 (E∫y2²dA).
struct Section {
  double EA = 0, EI1 = 0, EI2 = 0, GJ = 0;
  /// Solid circle of radius r: A = πr², I = πr⁴/4, J = πr⁴/2, G = E/(2(1+ν)). Throws
  /// InputError unless E > 0, −1 < ν < 0.5 and r > 0 (all finite).
  static Section circular(double E, double nu, double r);
  /// Solid ellipse with semi-axis a along m1 and b along m2: A = πab, I1 = πa³b/4,
  /// I2 = πab³/4, torsion constant J = πa³b³/(a²+b²) (Saint-Venant, exact for the ellipse).
  /// Same checks as circular().
  static Section elliptic(double E, double nu, double a, double b);
};

/// Stretching of one edge, E_s = ½ EA l̄ (l/l̄ − 1)². Stencil: x_j, x_{j+1} (6 DOFs, in that
/// order). Gradient and Hessian are exact (the Hessian is indefinite under compression).
struct StretchEval {
  double energy = 0;
  Eigen::Matrix<double, 6, 1> gradient = Eigen::Matrix<double, 6, 1>::Zero();
  Eigen::Matrix<double, 6, 6> hessian = Eigen::Matrix<double, 6, 6>::Zero();
};
/// Cost O(1). Throws nothing; a zero-length edge gives non-finite values (callers check).
[[nodiscard]] StretchEval stretch(const Vec3& x0, const Vec3& x1, double EA, double rest_length, bool want_hessian);
/// The nearest PSD matrix to stretch()'s Hessian in closed form: the transverse stiffness
/// EA·strain/l clamped at 0 (a compressed edge), no eigendecomposition. O(1).
[[nodiscard]] Eigen::Matrix<double, 6, 6> stretch_hessian_psd(const Vec3& x0, const Vec3& x1, double EA, double rest_length);

/// Constants of one interior vertex i (between edges i−1 and i).
struct BendTwistRest {
  double kappa1 = 0, kappa2 = 0;  ///< natural material curvatures κ̄1, κ̄2 (dimensionless, as κb)
  double twist = 0;               ///< natural twist m̄ (rad)
  double voronoi = 1;             ///< D = (l̄^{i−1} + l̄^i)/2 (m)
  double EI1 = 0, EI2 = 0, GJ = 0;
};

/// History of one interior vertex, frozen within a step (updated once per accepted step).
struct BendTwistFrames {
  Vec3 tangent0{1, 0, 0}, director0{0, 1, 0};  ///< t̄, ā1 of edge i−1 at the last update
  Vec3 tangent1{1, 0, 0}, director1{0, 1, 0};  ///< t̄, ā1 of edge i
  double reference_twist = 0;                  ///< tracked m_ref at the last update
};

/// Energy of bending and twisting at one vertex,
///   E = (1/2D)[EI1(κ1−κ̄1)² + EI2(κ2−κ̄2)² + GJ(m−m̄)²].
/// Stencil DOF order (11): x_{i−1}(0..2), x_i(3..5), x_{i+1}(6..8), θ^{i−1}(9), θ^i(10).
struct BendTwistEval {
  double energy = 0;
  double kappa1 = 0, kappa2 = 0, twist = 0;  ///< κ1, κ2 and m (reference twist unwrapped)
  double reference_twist = 0;                ///< m_ref, unwrapped against frames.reference_twist
  Eigen::Matrix<double, 11, 1> gradient = Eigen::Matrix<double, 11, 1>::Zero();
  Eigen::Matrix<double, 11, 11> hessian = Eigen::Matrix<double, 11, 11>::Zero();
};

/// What bend_twist() computes: the energy; and the gradient; and the full Hessian; or the
/// gradient with only the 2×2 angle block of the Hessian (entries (9..10, 9..10), the rest
/// zero) — all a quasi-static twist solve needs, at the cost of a gradient; or the gradient with
/// the Gauss–Newton part of the Hessian in `hessian`,
///   (1/D)[EI1 ∇κ1∇κ1ᵀ + EI2 ∇κ2∇κ2ᵀ + GJ ∇m∇mᵀ],
/// positive semidefinite by construction and exact where the strains are the natural ones (the
/// dropped terms are (s − s̄)∇²s) — the PSD stand-in Newton's projected Hessians use, without an
/// eigendecomposition.
enum class Want { energy, gradient, hessian, angle_hessian, gauss_newton };

/// Evaluates the bend–twist stencil. Everything is closed form (PHYSICS_NOTES §3.1 plus the
/// transported frames' spin; the Hessian's second variation is derived in docs/rods.md), O(1):
/// measured 0.35 µs for the gradient, 0.71 µs with the Gauss–Newton Hessian, 1.08 µs with the
/// exact Hessian (docs/rods.md). Near a kink of 180° (1 + t^{i−1}·t^i → 0) the energy grows
/// like tan²(φ/2) and the values become non-finite at exactly 180°; callers check finiteness.
[[nodiscard]] BendTwistEval bend_twist(const Vec3& x0, const Vec3& x1, const Vec3& x2, double theta0, double theta1,
                                       const BendTwistRest& rest, const BendTwistFrames& frames, Want want);

/// Material curvatures (κ1, κ2) and twist m at a configuration whose reference frames are
/// (t, a1) per edge — how natural curvature and twist are read off a rest shape. O(1).
struct MaterialStrains {
  double kappa1, kappa2, twist, reference_twist;
};
[[nodiscard]] MaterialStrains material_strains(const Vec3& x0, const Vec3& x1, const Vec3& x2, double theta0,
                                               double theta1, const BendTwistFrames& frames);

}  // namespace sewn::physics::rods
