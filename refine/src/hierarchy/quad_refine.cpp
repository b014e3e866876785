// 1:4 refinement of quads (PHYSICS_NOTES §2.2-2.5), on the map's own insertion operations.
#include <array>
#include <cstdint>
#include <string>

#include "hierarchy/model_access.hpp"
#include "hierarchy/sides.hpp"
#include "sewn/physics/errors.hpp"
#include "sewn/physics/stiffness.hpp"
#include "sewn/refine/hierarchy.hpp"
#include "sewn/refine/subdivide.hpp"

namespace sewn::refine {

namespace {

using physics::Element;
using physics::ElementKind;
using physics::InputError;
using physics::NodeRef;
using physics::SpringRef;
using physics::SpringKind;
using Vec3 = Eigen::Vector3d;

// Local side of a quad from its local vertex k to k+1 (in the model's quad edge order
// {0,1}, {3,2}, {1,2}, {0,3}).
constexpr std::array<int, 4> side_from = {0, 2, 1, 3};

template <int D>
void check_refinable(const MssModel<D>& m, Index e, const RefineOptions& o) {
  const std::string name = "refine: element " + std::to_string(e);
  if (e >= m.elements().size())
    throw InputError(name + " does not exist (the model has " + std::to_string(m.elements().size()) + ")");
  const Element& el = m.elements()[e];
  if (el.first_child != physics::invalid_index) throw InputError(name + " is already refined");
  if (!el.alive) throw InputError(name + " was removed (a dead element cannot be refined)");
  if (el.kind == ElementKind::triangle || el.kind == ElementKind::tetrahedron)
    throw InputError(name + " is a " + (el.kind == ElementKind::triangle ? "triangle" : "tetrahedron") +
                     ": only quads (1:4) are refined regularly");
  if (el.kind == ElementKind::hexahedron)
    throw InputError(name + " is a hexahedron: 1:8 refinement of hexahedra is not available yet");
  if (el.kind != ElementKind::quad) throw InputError(name + " is a segment: only quads are refined");
  if constexpr (D == 3) throw InputError(name + ": quads of a 3-map (membranes) are not refined yet");
  if (o.max_level < 1 || o.max_level > 20)
    throw InputError("refine: max_level " + std::to_string(o.max_level) + " is out of range (1 to 20, as an index)");
  if (level_index(el.level) + 1 > o.max_level)
    throw InputError(name + " is at level " + std::to_string(level_index(el.level)) +
                     ": its children would pass the maximum level " + std::to_string(o.max_level));
}

template <int D>
class QuadRefiner {
  using A = detail::ModelAccess<D>;

 public:
  QuadRefiner(MssModel<D>& m, RefineReport& report) : m_(m), map_(A::map(m)), report_(report) {}

  void run(Index e) {
    A::grow_darts(m_);
    const Element parent = A::elements(m_)[e];  // a copy: elements_ grows below
    const std::array<Dart, 4> c = detail::corner_darts(m_, parent);
    std::array<Index, 4> cn{};
    for (int k = 0; k < 4; ++k) cn[k] = m_.node_of(c[k]);
    // 1) the side midpoints: found by the middle-dart search, or inserted
    std::array<Dart, 4> mid{};
    for (int k = 0; k < 4; ++k) {
      const detail::Middle found = detail::middle_of_side(m_, c[k], parent.level);
      mid[k] = found.dart.is_null() ? split_side(c[k], cn[k], cn[(k + 1) % 4]) : found.dart;
    }
    // 2) the edge between the midpoints of sides 0 and 2, at the parent's level: it is split
    //    next, and its halves get 2·l_E like every interior half-edge
    const Dart across = map_.insert_edge_in_face(mid[0], mid[2]);
    new_spring(across, parent.level);
    // 3) the centre particle, bilinear: the mean of the 4 corners
    Vec3 rest = Vec3::Zero(), x = Vec3::Zero(), v = Vec3::Zero();
    for (Index n : cn) {
      rest += m_.rest_position(n) / 4;
      x += m_.nodes().position(n) / 4;
      v += m_.nodes().velocity(n) / 4;
    }
    const Dart centre = insert_vertex(across, rest, x, v, 2 * parent.level);
    // 4) from the centre to the midpoints of sides 1 and 3, in the two halves
    //    (`centre` lies in the half holding side 3, β2 of it in the half holding side 1)
    new_spring(map_.insert_edge_in_face(centre, mid[3]), 2 * parent.level);
    new_spring(map_.insert_edge_in_face(map_.beta(across, 2), mid[1]), 2 * parent.level);
    A::grow_darts(m_);
    // 5) the children: child k has corners (c_k, midpoint k, centre, midpoint k-1) in β1 order
    auto& elements = A::elements(m_);
    const Index first = static_cast<Index>(elements.size());
    {
      HooksPaused<typename A::Map> quiet(map_);  // the parent's face attribute goes with the parent
      for (int k = 0; k < 4; ++k) {
        const std::array<Index, 4> corner = {cn[k], m_.node_of(mid[k]), m_.node_of(Dart(map_.beta(across, 1))),
                                             m_.node_of(mid[(k + 3) % 4])};
        elements.push_back(make_child(parent, e, c[k], corner));
        map_.template set_attribute<2>(c[k], physics::ElementRef{first + static_cast<Index>(k)});
        code_ring(c[k], corner);
      }
    }
    retire(e, first);
    for (int k = 0; k < 4; ++k) {
      A::attach_diagonals(m_, first + static_cast<Index>(k));
      report_.children.push_back(first + static_cast<Index>(k));
    }
    ++report_.elements;
  }

 private:
  // Splits side dart d (a single edge at the element's level) at its midpoint; returns the dart
  // starting there, in the element's face. The neighbour across keeps the new particle as a
  // T-junction (its new dart is no corner of it).
  Dart split_side(Dart d, Index a, Index b) {
    const auto& nodes = m_.nodes();
    const Vec3 rest = (m_.rest_position(a) + m_.rest_position(b)) / 2;
    const Vec3 x = (nodes.position(a) + nodes.position(b)) / 2, v = (nodes.velocity(a) + nodes.velocity(b)) / 2;
    const std::uint32_t level = map_.value(map_.template attribute<1>(d)).level;
    return insert_vertex(d, rest, x, v, 2 * level);
  }

  // Inserts a particle in the edge of d; both halves get `half_level`. The new darts continue
  // their predecessor's side and start at no corner (the children's rings are coded afterwards).
  Dart insert_vertex(Dart d, const Vec3& rest, const Vec3& x, const Vec3& v, std::uint32_t half_level) {
    const Dart other = map_.beta(d, 2);
    const Index n = A::add_node(m_, rest, x, v);
    const Dart nd = map_.insert_vertex_in_edge(d, NodeRef{n});
    A::grow_darts(m_);
    A::link_vertex(m_, n, nd);
    A::mark_vertex_dirty(m_, nd);
    for (Dart y : {d, other})
      if (!y.is_null()) A::copy_code(m_, y, map_.beta(y, 1), physics::not_a_corner);
    for (Dart y : {d, nd}) map_.value(map_.template attribute<1>(y)).level = half_level;
    ++report_.particles;
    return nd;
  }

  void new_spring(Dart d, std::uint32_t level) {
    const Index s = m_.springs().add(m_.node_of(d), m_.node_of(map_.beta(d, 1)), 0.0, 0.0, SpringKind::edge);
    map_.template set_attribute<1>(d, SpringRef{s, physics::invalid_index, level});
    A::mark_edge_dirty(m_, d);
  }

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
    // the model's own rules for a quad (mss_model.cpp make_element), at the child's rest size
    const double lx = ((r[1] - r[0]).norm() + (r[2] - r[3]).norm()) / 2;
    const double ly = ((r[2] - r[1]).norm() + (r[3] - r[0]).norm()) / 2;
    physics::RectangleStiffness s = physics::baudet_rectangle(mat.young * mat.thickness, mat.poisson, lx, ly);
    if (!s.valid()) s = physics::clamp_edges(s, 0.0);  // only a parent built under the clamp policy gets here
    for (int k = 0; k < 4; ++k) el.edge_k[static_cast<std::size_t>(k)] = s.edge[static_cast<std::size_t>(k / 2)];
    el.diagonal_k = s.diagonal;
    el.measure = mat.thickness * (physics::triangle_area(r[0], r[1], r[2]) + physics::triangle_area(r[0], r[2], r[3]));
    for (int k = 0; k < 2; ++k) el.diagonal[static_cast<std::size_t>(k)] = m_.springs().add(0, 1, el.diagonal_k, 0.0, SpringKind::diagonal);
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
      A::set_dart(m_, x, is_corner ? static_cast<std::uint8_t>(last) : physics::not_a_corner, side_from[last]);
      A::mark_vertex_dirty(m_, x);
      x = map_.beta(x, 1);
    } while (x != first);
  }

  void retire(Index e, Index first) {
    auto& elements = A::elements(m_);
    Element& p = elements[e];
    p.alive = false;
    p.first_child = first;
    for (Index& s : p.diagonal)
      if (s != physics::invalid_index) {
        m_.springs().remove(s);
        s = physics::invalid_index;
      }
    A::set_live_elements(m_, m_.num_live_elements() + 3);
  }

  MssModel<D>& m_;
  typename A::Map& map_;
  RefineReport& report_;
};

}  // namespace

template <int D>
RefineReport refine_element(MssModel<D>& m, Index e, const RefineOptions& options) {
  return refine_elements(m, std::span<const Index>(&e, 1), options);
}

template <int D>
RefineReport refine_elements(MssModel<D>& m, std::span<const Index> elements, const RefineOptions& options) {
  RefineReport report;
  for (Index e : elements) {
    check_refinable(m, e, options);  // before any change: a refused element leaves the model as it was
    if constexpr (D == 2) {
      detail::ModelAccess<D>::set_refining(m, true);
      try {
        m.edit([&](auto&) { QuadRefiner<D>(m, report).run(e); });
      } catch (...) {
        detail::ModelAccess<D>::set_refining(m, false);
        throw;
      }
      detail::ModelAccess<D>::set_refining(m, false);
    }
  }
  return report;
}

template <int D>
RefineReport refine_all(MssModel<D>& m, const RefineOptions& options) {
  std::vector<Index> live;
  for (Index e = 0; e < m.elements().size(); ++e)
    if (m.elements()[e].alive) live.push_back(e);
  return refine_elements(m, std::span<const Index>(live), options);
}

template RefineReport refine_element(MssModel<2>&, Index, const RefineOptions&);
template RefineReport refine_element(MssModel<3>&, Index, const RefineOptions&);
template RefineReport refine_elements(MssModel<2>&, std::span<const Index>, const RefineOptions&);
template RefineReport refine_elements(MssModel<3>&, std::span<const Index>, const RefineOptions&);
template RefineReport refine_all(MssModel<2>&, const RefineOptions&);
template RefineReport refine_all(MssModel<3>&, const RefineOptions&);

}  // namespace sewn::refine
