#pragma once
// The one door through which hierarchical refinement reaches into MssModel: the rest data, the
// per-dart corner and side codes and the bookkeeping of a topology edit that the model's own
// hooks cannot derive (which child a split face becomes, where a new particle sits at rest).

#include <cstdint>
#include <vector>

#include "sewn/physics/mss_model.hpp"

namespace sewn::refine::detail {

template <int D>
struct ModelAccess {
  using Model = physics::MssModel<D>;
  using Map = typename Model::Map;
  using Index = physics::Index;

  static Map& map(Model& m) { return m.map_; }
  static std::vector<physics::Element>& elements(Model& m) { return m.elements_; }
  static void set_refining(Model& m, bool on) {
    m.refining_ = on;
    if (on) m.ever_refined_ = true;
  }
  static std::uint8_t dart_vertex(const Model& m, Dart d) { return m.dart_vertex_[d.index()]; }

  /// Sizes the per-dart codes to the map's dart capacity (insertions add darts).
  static void grow_darts(Model& m) {
    const std::size_t n = m.map_.dart_capacity();
    if (m.dart_vertex_.size() < n) {
      m.dart_vertex_.resize(n, physics::not_a_corner);
      m.dart_edge_.resize(n, 0);
    }
  }
  /// Dart d starts at local vertex `vertex` (or not_a_corner) and lies on local side `side`.
  static void set_dart(Model& m, Dart d, std::uint8_t vertex, int side) {
    m.dart_vertex_[d.index()] = vertex;
    m.dart_edge_[d.index()] = static_cast<std::uint8_t>(side | 0x80);  // one dart per element and edge in 2D
  }
  /// Dart d starts at local vertex `vertex` (or not_a_corner); `code` is its local edge with
  /// bit 7 set on the one dart per element and edge counted (MssModel's per-dart edge code).
  static void set_codes(Model& m, Dart d, std::uint8_t vertex, std::uint8_t code) {
    m.dart_vertex_[d.index()] = vertex;
    m.dart_edge_[d.index()] = code;
  }
  static std::uint8_t dart_code(const Model& m, Dart d) { return m.dart_edge_[d.index()]; }
  static void copy_code(Model& m, Dart from, Dart to, std::uint8_t vertex) {
    m.dart_vertex_[to.index()] = vertex;
    m.dart_edge_[to.index()] = m.dart_edge_[from.index()];
  }

  /// A particle at rest position `rest` with state (x, v); its mass is weighed by the next
  /// resync (the placeholder 1 is overwritten there, and resync refuses a particle left at 0).
  static Index add_node(Model& m, const Eigen::Vector3d& rest, const Eigen::Vector3d& x, const Eigen::Vector3d& v) {
    const Index n = m.system_.nodes().add(x, v, 1.0);
    m.rest_.push_back(rest);
    m.point_of_node_.push_back(~std::uint32_t{0});  // no mesh point: born of a refinement
    m.first_vertex_.push_back(Dart::null_index);
    return n;
  }
  /// Records that the vertex of d carries node n (after the map gave it its 0-attribute).
  static void link_vertex(Model& m, Index n, Dart d) {
    const std::uint32_t a = m.map_.template attribute_index<0>(d.index());
    m.link_vertex(n, a);
  }
  static void mark_vertex_dirty(Model& m, Dart d) {
    m.dirty_vertices_.push_back(m.map_.template attribute_index<0>(d.index()));
  }
  static void mark_edge_dirty(Model& m, Dart d) {
    m.dirty_edges_.push_back(m.map_.template attribute_index<1>(d.index()));
  }
  static void set_live_elements(Model& m, Index n) { m.live_elements_ = n; }
  static void attach_diagonals(Model& m, Index e) { m.attach_diagonals(e); }
  /// Codes every dart of element e (a closed cell) from its canonical dart, as the builder does.
  static void index_darts(Model& m, Index e) { m.index_darts(e); }
};

}  // namespace sewn::refine::detail
