#include "sewn/refine/criteria.hpp"

#include <cmath>
#include <string>

#include "sewn/physics/errors.hpp"

namespace sewn::refine {

template <int D>
Eigen::Vector3d element_centroid(const MssModel<D>& m, Index e) {
  const std::vector<Index> nodes = m.element_nodes(e);
  Eigen::Vector3d c = Eigen::Vector3d::Zero();
  for (Index n : nodes) c += m.nodes().position(n);
  return c / static_cast<double>(nodes.size());
}

namespace {

template <int D>
Eigen::Vector3d rest_centroid(const MssModel<D>& m, Index e) {
  const std::vector<Index> nodes = m.element_nodes(e);
  Eigen::Vector3d c = Eigen::Vector3d::Zero();
  for (Index n : nodes) c += m.rest_position(n);
  return c / static_cast<double>(nodes.size());
}

}  // namespace

template <int D>
StrainEnergy<D>::StrainEnergy(double threshold) : threshold_(threshold) {
  if (!(threshold > 0) || !std::isfinite(threshold))
    throw physics::InputError("refinement criterion: the strain energy density threshold must be finite and > 0 J/m³ (got " +
                              std::to_string(threshold) + ")");
}

template <int D>
double StrainEnergy<D>::density(const MssModel<D>& m, Index e) {
  const physics::Element& el = m.elements()[e];
  const std::vector<Index> nodes = m.element_nodes(e);
  auto stretch = [&](Index a, Index b) {
    return (m.nodes().position(b) - m.nodes().position(a)).norm() - (m.rest_position(b) - m.rest_position(a)).norm();
  };
  double energy = 0;
  const auto edges = MssModel<D>::local_edges(el.kind);
  for (std::size_t i = 0; i < edges.size(); ++i) {
    const double dl = stretch(nodes[edges[i][0]], nodes[edges[i][1]]);
    energy += el.edge_k[i] * dl * dl / 2;
  }
  const physics::Springs& s = m.springs();
  for (Index d : el.diagonal) {
    if (d == physics::invalid_index) continue;
    const double dl = (m.nodes().position(s.node_j(d)) - m.nodes().position(s.node_i(d))).norm() - s.rest_length(d);
    energy += el.diagonal_k * dl * dl / 2;
  }
  return energy / el.measure;
}

template <int D>
bool StrainEnergy<D>::wants_refinement(const MssModel<D>& m, Index e) const {
  return density(m, e) > threshold_;
}

template <int D>
bool StrainEnergy<D>::allows_coarsening(const MssModel<D>& m, Index e) const {
  return density(m, e) < threshold_ / 4;
}

template <int D>
InRegion<D>::InRegion(Predicate inside) : inside_(std::move(inside)) {
  if (!inside_) throw physics::InputError("refinement criterion: the region has no predicate");
}

template <int D>
bool InRegion<D>::wants_refinement(const MssModel<D>& m, Index e) const {
  return inside_(rest_centroid(m, e));
}

template <int D>
bool InRegion<D>::allows_coarsening(const MssModel<D>& m, Index e) const {
  return !inside_(rest_centroid(m, e));
}

template <int D>
NearPoint<D>::NearPoint(const Eigen::Vector3d& point, double radius) : point_(point), radius_(radius) {
  if (!(radius > 0) || !std::isfinite(radius))
    throw physics::InputError("refinement criterion: the distance to a point needs a radius > 0 (got " + std::to_string(radius) + ")");
  move_to(point);
}

template <int D>
void NearPoint<D>::move_to(const Eigen::Vector3d& point) {
  if (!point.allFinite()) throw physics::InputError("refinement criterion: the point to refine near is not finite");
  point_ = point;
}

template <int D>
bool NearPoint<D>::wants_refinement(const MssModel<D>& m, Index e) const {
  return (element_centroid(m, e) - point_).norm() <= radius_;
}

template <int D>
bool NearPoint<D>::allows_coarsening(const MssModel<D>& m, Index e) const {
  return (element_centroid(m, e) - point_).norm() > 2 * radius_;
}

template <int D>
InContact<D>::InContact(std::vector<physics::obstacles::Shape> shapes) : shapes_(std::move(shapes)) {
  if (shapes_.empty()) throw physics::InputError("refinement criterion: contact needs at least one obstacle");
}

template <int D>
bool InContact<D>::touches(const MssModel<D>& m, Index e) const {
  for (Index n : m.element_nodes(e))
    for (const auto& s : shapes_)
      if (physics::obstacles::depth(s, m.nodes().position(n)).depth > 0) return true;
  return false;
}

template <int D>
bool InContact<D>::wants_refinement(const MssModel<D>& m, Index e) const {
  return touches(m, e);
}

template <int D>
bool InContact<D>::allows_coarsening(const MssModel<D>& m, Index e) const {
  return !touches(m, e);
}

template <int D>
AnyOf<D>::AnyOf(std::vector<std::unique_ptr<Criterion<D>>> criteria) : criteria_(std::move(criteria)) {
  if (criteria_.empty()) throw physics::InputError("refinement criteria: the list is empty");
  for (const auto& c : criteria_)
    if (!c) throw physics::InputError("refinement criteria: a criterion is null");
}

template <int D>
bool AnyOf<D>::wants_refinement(const MssModel<D>& m, Index e) const {
  for (const auto& c : criteria_)
    if (c->wants_refinement(m, e)) return true;
  return false;
}

template <int D>
bool AnyOf<D>::allows_coarsening(const MssModel<D>& m, Index e) const {
  for (const auto& c : criteria_)
    if (!c->allows_coarsening(m, e)) return false;
  return true;
}

template Eigen::Vector3d element_centroid(const MssModel<2>&, Index);
template Eigen::Vector3d element_centroid(const MssModel<3>&, Index);
template class StrainEnergy<2>;
template class StrainEnergy<3>;
template class InRegion<2>;
template class InRegion<3>;
template class NearPoint<2>;
template class NearPoint<3>;
template class InContact<2>;
template class InContact<3>;
template class AnyOf<2>;
template class AnyOf<3>;

}  // namespace sewn::refine
