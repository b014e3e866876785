#pragma once
// Central differences of a point connection's energy, shared by the point-connection tests.

#include <Eigen/Core>

#include "sewn/connect/point.hpp"

namespace sewn::connect::test {

/// The gradient of c's energy at q (its stencil's unknowns) by central differences of step h,
/// each evaluated with the twist update u.
inline Eigen::VectorXd finite_gradient(const PointConnection& c, const Eigen::VectorXd& q, TwistUpdate u, double h) {
  Eigen::VectorXd g(q.size());
  for (Eigen::Index i = 0; i < q.size(); ++i) {
    Eigen::VectorXd qp = q, qm = q;
    qp[i] += h;
    qm[i] -= h;
    g[i] = (c.evaluate(qp, u, false).energy - c.evaluate(qm, u, false).energy) / (2 * h);
  }
  return g;
}

}  // namespace sewn::connect::test
