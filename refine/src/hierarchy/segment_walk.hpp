#pragma once
// Walking a straight rest segment through the darts of one volume. Every particle a refinement
// creates sits at a multilinear interpolation of its element's corners at rest, so the edges of
// one iso-parametric line are collinear at rest: the path from particle a to particle b along such
// a line is found from the rest positions alone, whatever finer neighbours inserted on it.

#include <cmath>
#include <span>
#include <stdexcept>
#include <string>
#include <vector>

#include "sewn/physics/mss_model.hpp"

namespace sewn::refine::detail {

/// The node a dart of a closed face ring ends at.
template <int D>
physics::Index end_node(const physics::MssModel<D>& m, Dart x) {
  return m.node_of(m.map().beta(x, 1));
}

/// The darts of `volume` leading from node a to node b along the rest segment [a, b], in order
/// (one dart per sub-edge: in a volume, one dart runs each way along each of its edges).
/// Throws std::logic_error if the segment is not a chain of the volume's edges.
template <int D>
std::vector<Dart> walk_segment(const physics::MssModel<D>& m, std::span<const Dart> volume, physics::Index a,
                               physics::Index b) {
  const Eigen::Vector3d ra = m.rest_position(a), u = m.rest_position(b) - ra;
  const double l2 = u.squaredNorm();
  std::vector<Dart> path;
  physics::Index at = a;
  double t_at = 0;
  while (at != b) {
    Dart best;
    double t_best = 2;
    for (Dart x : volume) {
      if (m.node_of(x) != at) continue;
      const Eigen::Vector3d w = m.rest_position(end_node(m, x)) - ra;
      const double t = w.dot(u) / l2;
      if (t <= t_at + 1e-12 || t > 1 + 1e-9 || (w - t * u).squaredNorm() > 1e-18 * l2) continue;
      if (t < t_best) {
        t_best = t;
        best = x;
      }
    }
    if (best.is_null())
      throw std::logic_error("refine: no edge of the volume continues the segment from particle " + std::to_string(a) +
                             " to " + std::to_string(b) + " at particle " + std::to_string(at));
    path.push_back(best);
    at = end_node(m, best);
    t_at = t_best;
  }
  return path;
}

}  // namespace sewn::refine::detail
