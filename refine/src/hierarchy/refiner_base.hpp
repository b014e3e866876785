#pragma once
// What the quad and hexahedron refinements share: inserting a particle in an edge at the
// multilinear interpolation of given corners, giving a new edge its spring, retiring the parent.
// Used inside MssModel::edit() with the model's refining flag set.

#include <array>
#include <cstdint>
#include <span>

#include "hierarchy/model_access.hpp"
#include "sewn/physics/stiffness.hpp"
#include "sewn/refine/subdivide.hpp"

namespace sewn::refine::detail {

/// Element e stops being an element: not alive, its `children` (appended from `first`) in its
/// place, its diagonal springs removed.
template <int D>
void retire_parent(physics::MssModel<D>& m, physics::Index e, physics::Index first, physics::Index children) {
  physics::Element& p = ModelAccess<D>::elements(m)[e];
  p.alive = false;
  p.first_child = first;
  for (physics::Index& s : p.diagonal)
    if (s != physics::invalid_index) {
      m.springs().remove(s);
      s = physics::invalid_index;
    }
  ModelAccess<D>::set_live_elements(m, m.num_live_elements() + children - 1);
}

template <int D>
class RefinerBase {
 public:
  RefinerBase(physics::MssModel<D>& m, RefineReport& report) : m_(m), map_(A::map(m)), report_(report) {}

 protected:
  using A = ModelAccess<D>;
  using Vec3 = Eigen::Vector3d;
  using Index = physics::Index;

  /// Rest position, position and velocity of the mean of the given particles: the multilinear
  /// interpolation at the centre of the edge, face or cell they are the corners of. An axis
  /// held on every corner is held on the new particle too: a clamped side or face stays clamped
  /// along its whole extent once refined, instead of gaining free particles in its middle.
  struct State {
    Vec3 rest = Vec3::Zero(), x = Vec3::Zero(), v = Vec3::Zero();
    physics::AxisMask fixed = physics::all_axes;
  };
  State mean(std::span<const Index> corners) const {
    State s;
    const double w = 1.0 / static_cast<double>(corners.size());
    for (Index n : corners) {
      s.rest += w * m_.rest_position(n);
      s.x += w * m_.nodes().position(n);
      s.v += w * m_.nodes().velocity(n);
      s.fixed &= m_.nodes().fixed(n);
    }
    return s;
  }

  /// Inserts a particle with state s in the edge of d; both halves get `half_level`. Every dart
  /// the split adds continues its predecessor's side and starts at no corner: a T-junction for
  /// every element around the edge until its own refinement codes its ring again. Returns the
  /// new dart after d (it starts at the new particle).
  Dart insert_vertex(Dart d, const State& s, std::uint32_t half_level) {
    const DartList around = map_.template cell<1>(d);
    const Index n = A::add_node(m_, s.rest, s.x, s.v);
    if (s.fixed != physics::no_axes) {
      m_.nodes().fix(n, s.fixed);
      m_.nodes().set_velocity(n, s.v);  // fix() zeroes held axes; a kinematic side keeps its motion
    }
    const Dart nd = map_.insert_vertex_in_edge(d, physics::NodeRef{n});
    A::grow_darts(m_);
    A::link_vertex(m_, n, nd);
    A::mark_vertex_dirty(m_, nd);
    for (Dart y : around) A::copy_code(m_, y, map_.beta(y, 1), physics::not_a_corner);
    for (Dart y : {d, nd}) map_.value(map_.template attribute<1>(y)).level = half_level;
    ++report_.particles;
    return nd;
  }

  /// Gives the new edge of d (no attribute yet) a spring of level `level`; its stiffness, rest
  /// length and ends are set by the model's resync.
  void new_spring(Dart d, std::uint32_t level) {
    A::grow_darts(m_);
    // the new edge's darts may reuse slots of erased darts: clear their codes (no corner, no
    // side) for the elements around it that are not recoded afterwards
    for (Dart y : map_.template cell<1>(d)) A::set_codes(m_, y, physics::not_a_corner, 0);
    const Index s = m_.springs().add(m_.node_of(d), m_.node_of(map_.beta(d, 1)), 0.0, 0.0, physics::SpringKind::edge);
    map_.template set_attribute<1>(d, physics::SpringRef{s, physics::invalid_index, level});
    A::mark_edge_dirty(m_, d);
  }

  /// The dart of the face ring of `start` that starts at particle n (null if none).
  Dart in_ring(Dart start, Index n) const {
    Dart x = start;
    do {
      if (m_.node_of(x) == n) return x;
      x = map_.beta(x, 1);
    } while (x != start && !x.is_null());
    return {};
  }

  /// The parent stops being an element; its children (already appended) replace it.
  void retire(Index e, Index first, Index children) {
    retire_parent(m_, e, first, children);
    for (Index k = 0; k < children; ++k) {
      A::attach_diagonals(m_, first + k);
      report_.children.push_back(first + k);
    }
    ++report_.elements;
  }

  physics::MssModel<D>& m_;
  typename A::Map& map_;
  RefineReport& report_;
};

/// 1:4: a quad of a 2-map or a membrane quad of a 3-map.
template <int D>
void refine_quad(physics::MssModel<D>& m, physics::Index e, RefineReport& report);
void refine_hex(physics::MssModel<3>& m, physics::Index e, RefineReport& report);

/// True if refine_all may take the batch pass (hex_batch.cpp): every live element a hexahedron of
/// one level, each a closed volume of 24 darts (no T-junction anywhere, no slave node), every edge
/// of that level with a live spring of its own (no segment), no face element. O(elements + edges).
[[nodiscard]] bool batch_refinable(const physics::MssModel<3>& m);
/// Every live hexahedron refined 1:8 by the map's batch pass, the physics rebuilt in bulk; inside
/// MssModel::edit() with the refining flag set, after the elements were checked. O(model).
void refine_all_hexahedra(physics::MssModel<3>& m, RefineReport& report);

}  // namespace sewn::refine::detail
