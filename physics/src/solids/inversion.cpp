#include "sewn/physics/solids/inversion.hpp"

#include <array>
#include <vector>

#include <Eigen/Geometry>

#include "hex_corners.hpp"

namespace sewn::physics {

namespace {

using solids::detail::hex_corners;

double triple(const Eigen::Vector3d& o, const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c) {
  return (a - o).dot((b - o).cross(c - o));
}

}  // namespace

InversionCount InversionMonitor::count(const MssModel<3>& model) {
  if (model.system().version() != version_) {
    corners_.clear();
    const auto add = [&](const std::vector<Index>& v, std::size_t o, std::size_t a, std::size_t b, std::size_t c, Index e) {
      const double rest = triple(model.rest_position(v[o]), model.rest_position(v[a]), model.rest_position(v[b]),
                                 model.rest_position(v[c]));
      corners_.push_back({v[o], v[a], v[b], v[c], rest > 0, e});
    };
    for (Index e = 0; e < model.elements().size(); ++e) {
      const Element& el = model.elements()[e];
      if (!el.alive || (el.kind != ElementKind::hexahedron && el.kind != ElementKind::tetrahedron)) continue;
      const std::vector<Index> v = model.element_nodes(e);
      if (el.kind == ElementKind::tetrahedron) {
        add(v, 0, 1, 2, 3, e);
      } else {
        for (std::size_t c = 0; c < 8; ++c) add(v, c, hex_corners[c][0], hex_corners[c][1], hex_corners[c][2], e);
      }
    }
    version_ = model.system().version();
  }
  InversionCount out;
  const NodeTable& nodes = model.nodes();
  const auto x = nodes.x();
  const auto at = [&](Index i) { return Eigen::Vector3d(x[3 * std::size_t{i}], x[3 * std::size_t{i} + 1], x[3 * std::size_t{i} + 2]); };
  Index counted = invalid_index;  // the element last counted: one count per element
  for (const Corner& k : corners_) {
    if (k.element == counted) continue;
    const double now = triple(at(k.o), at(k.a), at(k.b), at(k.c));
    if ((now > 0) == k.rest_positive || now == 0) continue;
    counted = k.element;
    if (out.elements == 0) {
      out.first = k.element;
      out.first_cell = model.elements()[k.element].mesh_cell;
    }
    ++out.elements;
  }
  return out;
}

InversionCount count_inverted(const MssModel<3>& model) { return InversionMonitor{}.count(model); }

}  // namespace sewn::physics
