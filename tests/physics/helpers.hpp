#pragma once
// Shared helpers of the physics tests: the 2013 paper's material, dense Jacobians from the assembled pattern and by
// central finite differences of the forces.

#include <random>
#include <vector>

#include <Eigen/Dense>

#include "sewn/physics/mss_model.hpp"
#include "sewn/physics/physics.hpp"
#include "sewn/physics/rods/rods_term.hpp"

namespace sewn::physics::test {

/// The 2013 paper's material: E = 100 MPa, ν = 0.3, ρ = 1000 kg/m³.
inline const MaterialParams paper_material{100e6, 0.3, 1000};

inline Eigen::VectorXd forces(System& sys) {
  sys.refresh();
  std::vector<double> f(3 * std::size_t{sys.nodes().size()}, 0.0);
  sys.add_forces(sys.nodes().state(), f);
  return Eigen::Map<Eigen::VectorXd>(f.data(), static_cast<Eigen::Index>(f.size()));
}

/// cx·∂F/∂x + cv·∂F/∂v as assembled by the terms.
inline Eigen::MatrixXd assembled(System& sys, double cx, double cv, JacobianOptions opt) {
  sys.refresh();
  BlockMatrix& A = sys.matrix();
  A.set_zero();
  JacobianRequest r;
  r.matrix = &A;
  r.cx = cx;
  r.cv = cv;
  r.options = opt;
  sys.add_jacobians(r);
  return Eigen::MatrixXd(A.to_sparse());
}

/// ∂F/∂x (or ∂F/∂v) by central differences with step delta.
inline Eigen::MatrixXd finite_difference(System& sys, bool wrt_velocity, double delta) {
  const Eigen::Index n3 = 3 * Eigen::Index{sys.nodes().size()};
  Eigen::MatrixXd J(n3, n3);
  auto values = wrt_velocity ? sys.nodes().v() : sys.nodes().x();
  for (Eigen::Index c = 0; c < n3; ++c) {
    const double keep = values[c];
    values[c] = keep + delta;
    const Eigen::VectorXd fp = forces(sys);
    values[c] = keep - delta;
    const Eigen::VectorXd fm = forces(sys);
    values[c] = keep;
    J.col(c) = (fp - fm) / (2 * delta);
  }
  return J;
}

inline double max_abs(const Eigen::MatrixXd& m) { return m.cwiseAbs().maxCoeff(); }

/// A straight rod of n nodes (0.004 kg each) hanging from the origin along -z over length L, its
/// top two nodes fixed and the twist angles of its first and last edges clamped: the rod the
/// "twisted past pi and back" cases drive by its last edge's angle.
inline rods::Rods& hanging_clamped_rod(System& sys, int n, double L, const rods::Section& section) {
  std::vector<Index> ids;
  for (int i = 0; i < n; ++i)
    ids.push_back(sys.nodes().add(rods::Vec3(0, 0, -L * i / (n - 1)), rods::Vec3::Zero(), 0.004));
  sys.nodes().fix(ids[0]);
  sys.nodes().fix(ids[1]);
  auto& rods = sys.add<rods::Rods>();
  (void)rods.add_rod(ids, sys.nodes().x(), false, section);
  rods.rod(0).fix_theta(0);
  rods.rod(0).fix_theta(n - 2);
  return rods;
}

}  // namespace sewn::physics::test
