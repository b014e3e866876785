#pragma once
// A child hexahedron of a 1:8 refinement, as the model builds a hexahedron (MssModel's
// make_element) at the child's own rest size: Baudet's box stiffness, the Kuhn volume, 4 new
// diagonal springs between its corners at their rest lengths. Shared by the
// element-by-element refiner (hex_refine.cpp) and the uniform batch pass (hex_batch.cpp).

#include <array>
#include <cstddef>

#include "hierarchy/hex_codes.hpp"
#include "sewn/physics/stiffness.hpp"

namespace sewn::refine::detail {

/// The child of `parent` (element e) with corner particles `corner` (VTK order) and canonical
/// dart `dart`, one level finer.
inline physics::Element make_hex_child(physics::MssModel<3>& m, const physics::Element& parent, physics::Index e, Dart dart,
                                       const std::array<physics::Index, 8>& corner) {
  const physics::MaterialParams& mat = m.materials()[parent.material];
  auto r = [&](int k) { return m.rest_position(corner[static_cast<std::size_t>(k)]); };
  physics::Element el;
  el.kind = physics::ElementKind::hexahedron;
  el.material = parent.material;
  el.mesh_cell = parent.mesh_cell;
  el.dart = dart;
  el.level = 2 * parent.level;
  el.parent = e;
  std::array<double, 3> len{};
  for (std::size_t k = 0; k < 12; ++k) len[k / 4] += (r(hex_edge_ends[k][1]) - r(hex_edge_ends[k][0])).norm() / 4;
  physics::BoxStiffness s = physics::baudet_box(mat.young, mat.poisson, len[0], len[1], len[2]);
  if (!s.valid()) s = physics::clamp_edges(s, 0.0);  // only a parent built under the clamp policy gets here
  for (std::size_t k = 0; k < 12; ++k) el.edge_k[k] = s.edge[k / 4];
  el.diagonal_k = s.diagonal;
  static constexpr int kuhn[6][4] = {{0, 1, 2, 6}, {0, 2, 3, 6}, {0, 3, 7, 6}, {0, 7, 4, 6}, {0, 4, 5, 6}, {0, 5, 1, 6}};
  for (const auto& t : kuhn) el.measure += physics::tet_volume(r(t[0]), r(t[1]), r(t[2]), r(t[3]));
  for (std::size_t k = 0; k < 4; ++k) {
    const auto [a, b] = hex_diagonal_ends[k];
    el.diagonal[k] = m.springs().add(corner[a], corner[b], el.diagonal_k, (r(b) - r(a)).norm(), physics::SpringKind::diagonal);
  }
  return el;
}

}  // namespace sewn::refine::detail
