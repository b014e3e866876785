#pragma once
// A spring's current direction and the degenerate-spring guard, shared by the force loops
// (springs.cpp, spring_runs.cpp) and the Jacobian assembly (spring_jacobian.cpp). Internal to
// the physics library.

#include <cmath>

#include <Eigen/Core>

#include "sewn/physics/force_term.hpp"

namespace sewn::physics::detail {

// A spring shorter than this fraction of its rest length has no usable direction: no force (the
// force loops of springs.cpp and spring_runs.cpp), no Jacobian (spring_jacobian.cpp).
inline constexpr double degenerate_ratio_sq = 1e-18;

struct SpringFrame {
  Eigen::Vector3d dx;
  double d = 0;
  bool ok = false;
};

inline SpringFrame spring_frame(const StateView& st, Index i, Index j, double l) {
  SpringFrame fr;
  fr.dx = Eigen::Vector3d(st.x[3 * j] - st.x[3 * i], st.x[3 * j + 1] - st.x[3 * i + 1], st.x[3 * j + 2] - st.x[3 * i + 2]);
  const double d2 = fr.dx.squaredNorm();
  fr.ok = d2 > degenerate_ratio_sq * l * l;
  fr.d = std::sqrt(d2);
  return fr;
}

inline Eigen::Vector3d vel_diff(const StateView& st, Index i, Index j) {
  return {st.v[3 * j] - st.v[3 * i], st.v[3 * j + 1] - st.v[3 * i + 1], st.v[3 * j + 2] - st.v[3 * i + 2]};
}

}  // namespace sewn::physics::detail
