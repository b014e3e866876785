#pragma once
// Per-node force terms: gravity and mass-proportional damping.

#include <string_view>

#include <Eigen/Core>

#include "sewn/physics/force_term.hpp"

namespace sewn::physics {

/// Uniform gravity: F_i = m_i g, potential -Σ m_i g·x_i (an external field). No Jacobian.
class Gravity final : public ForceTerm {
 public:
  /// Throws InputError if g is not finite.
  explicit Gravity(const Eigen::Vector3d& g);
  [[nodiscard]] std::string_view name() const override { return "gravity"; }
  [[nodiscard]] bool velocity_dependent() const override { return false; }
  [[nodiscard]] const Eigen::Vector3d& g() const { return g_; }
  void set_g(const Eigen::Vector3d& g);
  void add_forces(const StateView& s, std::span<double> f) const override;
  [[nodiscard]] double potential_energy(const StateView& s) const override;
  [[nodiscard]] EnergyKind energy_kind() const override { return EnergyKind::external; }

 private:
  Eigen::Vector3d g_;
};

/// Mass-proportional damping F_i = -c m_i V_i, ∂F/∂V = -c M. This is both the seed's
/// "damping from the environment" (PHYSICS_NOTES §1.5) and the α·M half of Rayleigh damping
/// C = αM + βK_s (the β half is Springs' SpringDamping::stiffness_proportional).
class MassDamping final : public ForceTerm {
 public:
  /// c in 1/s; throws InputError unless finite and >= 0.
  explicit MassDamping(double c);
  [[nodiscard]] std::string_view name() const override { return "mass damping"; }
  [[nodiscard]] double coefficient() const { return c_; }
  void set_coefficient(double c);
  void add_forces(const StateView& s, std::span<double> f) const override;
  [[nodiscard]] double potential_energy(const StateView& /*s*/) const override { return 0.0; }
  [[nodiscard]] bool dissipative() const override { return true; }
  /// Ψ = ½ c Σ m_i |V_i|². O(n).
  [[nodiscard]] double dissipation(const StateView& s) const override;
  void add_jacobians(const StateView& s, const JacobianRequest& req) const override;
  void add_stability_rows(const StateView& s, StabilityRows& rows) const override;

 private:
  double c_;
};

}  // namespace sewn::physics
