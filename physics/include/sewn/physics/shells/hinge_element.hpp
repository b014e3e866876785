#pragma once
// Discrete-shell hinge bending (Grinspun et al. 2003; PHYSICS_NOTES §3.2): value, gradient and
// Hessian of E = k_B · w · (θ - θ̄)², w = 3|ē|²/(Ā_A + Ā_B), on fixed-size Eigen types.
//
// Stencil: 4 nodes. Hinge edge x1–x2; x0 opposite in face A = (x0, x1, x2), x3 opposite in
// face B = (x3, x2, x1). DOF order [x0 y0 z0 x1 ... z3] (12); positions as a 3×4 matrix whose
// column i is node i.
// Angle: θ = atan2((n_A × n_B)·ê, n_A·n_B), 0 when flat, in (-π, π]; θ - θ̄ is wrapped into
// (-π, π] so that a hinge whose rest angle is near ±π does not see a 2π jump.
// Gradient: the closed form of §3.2. Hessian: 2 k_B w (∇θ∇θᵀ + (θ - θ̄)∇²θ), ∇²θ the
// closed-form gradient differentiated by hand (hinge_element.cpp).
// Calibration: k_B = D/6, D = E h³/(12(1-ν²)), reproduces ½D∫κ² for cylindrical bending.
// A hinge with a zero-area face or a zero-length edge has no defined angle gradient: it gives
// zero gradient and Hessian there (and its energy from atan2's value).
// Cost: energy ~80 flops, gradient ~120, Hessian ~1k.

#include <Eigen/Core>

#include "sewn/physics/elements/element_math.hpp"

namespace sewn::physics::shells {

using HingePositions = Eigen::Matrix<double, 3, 4>;
using Vec12 = elements::Vec<12>;
using Mat12 = elements::Mat<12>;

/// k_B = D/6 with D = E h³/(12(1-ν²)). Throws InputError unless E > 0, -1 < ν < ½, h > 0.
[[nodiscard]] double hinge_stiffness(double young, double poisson, double thickness);

struct HingeRest {
  double theta = 0.0;   ///< θ̄, rad
  double weight = 0.0;  ///< w = 3|ē|²/(Ā_A + Ā_B), dimensionless
};

/// Rest data from rest positions. Throws InputError if a rest face is degenerate (area ≤
/// 1e-12·|ē|²) or not finite.
[[nodiscard]] HingeRest hinge_rest(const HingePositions& X);

/// θ of the current positions (see above).
[[nodiscard]] double dihedral_angle(const HingePositions& x);
/// ∇θ (12); zero where undefined (see above).
[[nodiscard]] Vec12 dihedral_gradient(const HingePositions& x);
/// ∇²θ (12×12, symmetric); zero where ∇θ is undefined.
[[nodiscard]] Mat12 dihedral_hessian(const HingePositions& x);
/// ∇θ and ∇²θ together (what dihedral_gradient and dihedral_hessian give), sharing their work.
void dihedral_derivatives(const HingePositions& x, Vec12& g, Mat12& H);
/// d wrapped into (-π, π]: the change of an angle from its rest value without a 2π jump.
[[nodiscard]] double wrap_angle(double d);

[[nodiscard]] double hinge_energy(const HingePositions& x, const HingeRest& rest, double k_b);
[[nodiscard]] Vec12 hinge_gradient(const HingePositions& x, const HingeRest& rest, double k_b);
/// Exact Hessian (symmetric, indefinite in general).
[[nodiscard]] Mat12 hinge_hessian(const HingePositions& x, const HingeRest& rest, double k_b);
/// The Gauss-Newton part of the hinge Hessian, 2·k_b·w·∇θ∇θᵀ: PSD (rank one) by construction,
/// no eigendecomposition and no second derivative of θ (hinge_hessian needs both). It drops the curvature
/// term 2·k_b·w·(θ-θ̄)·∇²θ, so it is exact at the rest angle and Newton's steps with it are
/// Gauss-Newton steps (the gradient, hence the converged state, is unchanged).
[[nodiscard]] Mat12 hinge_hessian_gauss_newton(const HingePositions& x, const HingeRest& rest, double k_b);

}  // namespace sewn::physics::shells
