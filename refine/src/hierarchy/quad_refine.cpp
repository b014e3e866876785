// 1:4 refinement of quads (PHYSICS_NOTES §2.2, 2.3, 2.5), on the map's own insertion operations.
#include <array>
#include <cstdint>

#include "hierarchy/refiner_base.hpp"
#include "hierarchy/sides.hpp"

namespace sewn::refine::detail {

namespace {

using physics::Element;
using physics::ElementKind;

// Local side of a quad from its local vertex k to k+1 (in the model's quad edge order
// {0,1}, {3,2}, {1,2}, {0,3}).
constexpr std::array<int, 4> side_from = {0, 2, 1, 3};

// A quad of a 2-map, or a membrane quad of a 3-map (a face with no volume): the same ring
// walks and insertions, the 3-map's β3 being free on it.
template <int D>
class QuadRefiner : RefinerBase<D> {
  using Base = RefinerBase<D>;
  using typename Base::A;
  using typename Base::Vec3;
  using Base::m_;
  using Base::map_;
  using Base::insert_vertex;
  using Base::mean;
  using Base::new_spring;
  using Base::retire;

 public:
  using Base::Base;

  void run(Index e) {
    A::grow_darts(m_);
    const Element parent = A::elements(m_)[e];  // a copy: the element array grows below
    const std::array<Dart, 4> c = corner_darts(m_, parent);
    std::array<Index, 4> cn{};
    for (int k = 0; k < 4; ++k) cn[k] = m_.node_of(c[k]);
    // 1) the side midpoints: found by the middle-dart search, or inserted in a side that is
    //    still one edge (which leaves a T-junction in the neighbour across)
    std::array<Dart, 4> mid{};
    for (int k = 0; k < 4; ++k) {
      const Middle found = middle_of_side(m_, c[k], parent.level);
      const std::array<Index, 2> ends = {cn[k], cn[(k + 1) % 4]};
      mid[k] = found.dart.is_null() ? insert_vertex(c[k], mean(ends), 2 * edge_level(m_, c[k])) : found.dart;
    }
    // 2) the edge between the midpoints of sides 0 and 2, at the parent's level, then
    // 3) split by the centre particle (bilinear: the mean of the corners) into halves of 2·l_E
    const Dart across = map_.insert_edge_in_face(mid[0], mid[2]);
    new_spring(across, parent.level);
    const Dart centre = insert_vertex(across, mean(cn), 2 * parent.level);
    // 4) from the centre to the midpoints of sides 1 and 3, in the two halves (`centre` lies in
    //    the half holding side 3, β2 of `across` starts at the centre in the other)
    new_spring(map_.insert_edge_in_face(centre, mid[3]), 2 * parent.level);
    new_spring(map_.insert_edge_in_face(map_.beta(across, 2), mid[1]), 2 * parent.level);
    A::grow_darts(m_);
    // 5) the children: child k has corners (c_k, midpoint k, centre, midpoint k-1) in β1 order
    auto& elements = A::elements(m_);
    const Index first = static_cast<Index>(elements.size());
    const Index centre_node = m_.node_of(map_.beta(across, 1));
    {
      HooksPaused<typename A::Map> quiet(map_);  // the parent's face attribute goes with the parent
      for (int k = 0; k < 4; ++k) {
        const std::array<Index, 4> corner = {cn[k], m_.node_of(mid[k]), centre_node, m_.node_of(mid[(k + 3) % 4])};
        elements.push_back(make_child(parent, e, c[k], corner));
        map_.template set_attribute<2>(c[k], physics::ElementRef{first + static_cast<Index>(k)});
        code_ring(c[k], corner);
      }
    }
    retire(e, first, 4);
  }

 private:
  Element make_child(const Element& parent, Index e, Dart dart, const std::array<Index, 4>& corner) const {
    const physics::MaterialParams& mat = m_.materials()[parent.material];
    std::array<Vec3, 4> r;
    for (int k = 0; k < 4; ++k) r[k] = m_.rest_position(corner[k]);
    Element el;
    el.kind = ElementKind::quad;
    el.material = parent.material;
    el.mesh_cell = parent.mesh_cell;
    el.dart = dart;
    el.level = 2 * parent.level;
    el.parent = e;
    // the model's own rules for a quad (MssModel's make_element), at the child's rest size
    const double lx = ((r[1] - r[0]).norm() + (r[2] - r[3]).norm()) / 2;
    const double ly = ((r[2] - r[1]).norm() + (r[3] - r[0]).norm()) / 2;
    physics::RectangleStiffness s = physics::baudet_rectangle(mat.young * mat.thickness, mat.poisson, lx, ly);
    if (!s.valid()) s = physics::clamp_edges(s, 0.0);  // only a parent built under the clamp policy gets here
    for (int k = 0; k < 4; ++k) el.edge_k[static_cast<std::size_t>(k)] = s.edge[static_cast<std::size_t>(k / 2)];
    el.diagonal_k = s.diagonal;
    el.measure = mat.thickness * (physics::triangle_area(r[0], r[1], r[2]) + physics::triangle_area(r[0], r[2], r[3]));
    for (std::size_t k = 0; k < 2; ++k) el.diagonal[k] = m_.springs().add(0, 1, el.diagonal_k, 0.0, physics::SpringKind::diagonal);
    return el;
  }

  // Codes the darts of a child's ring: corners get their local vertex, the others (T-junctions
  // of finer neighbours) none; each dart lies on the side from the last corner passed. Every
  // vertex of the ring is weighed again and its edges re-stiffened.
  void code_ring(Dart first, const std::array<Index, 4>& corner) {
    int last = 0, next = 0;
    Dart x = first;
    do {
      const bool is_corner = next < 4 && m_.node_of(x) == corner[static_cast<std::size_t>(next)];
      if (is_corner) last = next++;
      A::set_dart(m_, x, is_corner ? static_cast<std::uint8_t>(last) : physics::not_a_corner, side_from[static_cast<std::size_t>(last)]);
      A::mark_vertex_dirty(m_, x);
      x = map_.beta(x, 1);
    } while (x != first);
  }
};

}  // namespace

template <int D>
void refine_quad(physics::MssModel<D>& m, physics::Index e, RefineReport& report) {
  QuadRefiner<D>(m, report).run(e);
}

template void refine_quad(physics::MssModel<2>&, physics::Index, RefineReport&);
template void refine_quad(physics::MssModel<3>&, physics::Index, RefineReport&);

}  // namespace sewn::refine::detail
