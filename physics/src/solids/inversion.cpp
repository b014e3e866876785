#include "sewn/physics/solids/inversion.hpp"

#include <array>
#include <vector>

#include <Eigen/Geometry>

namespace sewn::physics {

namespace {

// For each corner of a VTK-ordered hexahedron, its three neighbours along edges, in an order
// that gives every corner of an undistorted box the same sign.
constexpr std::array<std::array<std::uint8_t, 3>, 8> hex_corners{{
    {1, 3, 4}, {2, 0, 5}, {3, 1, 6}, {0, 2, 7}, {7, 5, 0}, {4, 6, 1}, {5, 7, 2}, {6, 4, 3}}};

template <class Position>
double triple(const Position& p, Index c, Index a, Index b, Index d) {
  const Eigen::Vector3d o = p(c);
  return (p(a) - o).dot((p(b) - o).cross(p(d) - o));
}

}  // namespace

InversionCount count_inverted(const MssModel<3>& model) {
  InversionCount out;
  const NodeTable& nodes = model.nodes();
  const auto now = [&](Index i) { return nodes.position(i); };
  const auto rest = [&](Index i) { return model.rest_position(i); };
  for (Index e = 0; e < model.elements().size(); ++e) {
    const Element& el = model.elements()[e];
    if (!el.alive || (el.kind != ElementKind::hexahedron && el.kind != ElementKind::tetrahedron)) continue;
    const std::vector<Index> v = model.element_nodes(e);
    bool inverted = false;
    if (el.kind == ElementKind::tetrahedron) {
      inverted = triple(now, v[0], v[1], v[2], v[3]) * triple(rest, v[0], v[1], v[2], v[3]) < 0;
    } else {
      for (std::size_t c = 0; c < 8 && !inverted; ++c) {
        const auto& n = hex_corners[c];
        inverted = triple(now, v[c], v[n[0]], v[n[1]], v[n[2]]) * triple(rest, v[c], v[n[0]], v[n[1]], v[n[2]]) < 0;
      }
    }
    if (!inverted) continue;
    if (out.elements == 0) {
      out.first = e;
      out.first_cell = el.mesh_cell;
    }
    ++out.elements;
  }
  return out;
}

}  // namespace sewn::physics
