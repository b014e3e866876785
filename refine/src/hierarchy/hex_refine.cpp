// 1:8 refinement of hexahedra (PHYSICS_NOTES §2.4-2.5), on the map's own insertion operations.
//
// The parent's 27 lattice particles P(a, b, c), a, b, c in {0, 1, 2} (corners at even
// coordinates), are found or made in the paper's order: the 6 faces split 1:4 (reusing the
// midpoints and centres finer neighbours made), the middle face c = 1 inserted and split 1:4
// through the cell centre, one face a = 1 in each half (split in two), one face b = 1 in each
// quarter. Paths between lattice particles are walked along rest segments (segment_walk.hpp),
// which also passes over the T-junctions finer neighbours left on them.
#include <array>
#include <cstdint>
#include <initializer_list>
#include <stdexcept>

#include "hierarchy/refiner_base.hpp"
#include "hierarchy/segment_walk.hpp"
#include "hierarchy/sides.hpp"
#include "hierarchy/hex_child.hpp"
#include "hierarchy/hex_codes.hpp"

namespace sewn::refine::detail {

namespace {

using physics::Element;
using physics::ElementKind;

int corner_of(const Lat& p) {
  for (int v = 0; v < 8; ++v)
    if (corner_lattice[static_cast<std::size_t>(v)] == p) return v;
  throw std::logic_error("refine: not a corner of the lattice");
}

class HexRefiner : RefinerBase<3> {
 public:
  using RefinerBase<3>::RefinerBase;

  void run(Index e) {
    A::grow_darts(m_);
    const Element parent = A::elements(m_)[e];  // a copy: the element array grows below
    level_ = parent.level;
    p_.fill(physics::invalid_index);
    const std::vector<Index> cn = m_.element_nodes(e);
    const DartList vol = map_.template cell<3>(parent.dart);
    for (std::size_t v = 0; v < 8; ++v) {
      p_[static_cast<std::size_t>(at(corner_lattice[v]))] = cn[v];
      for (Dart x : vol)
        if (m_.node_of(x) == cn[v]) corner_dart_[v] = x;  // stays in the piece holding corner v
    }
    // 1) the six faces, 1:4
    for (int axis = 0; axis < 3; ++axis)
      for (int side : {0, 2}) split_face(axis, side);
    // 2) the middle face c = 1, through the four lateral face midlines, and
    // 3) its 1:4 split through the cell centre (the mean of the 8 corners: trilinear)
    const Dart middle = insert_face({{0, 0, 1}, {1, 0, 1}, {2, 0, 1}, {2, 1, 1}, {2, 2, 1}, {1, 2, 1}, {0, 2, 1}, {0, 1, 1}}, 0);
    const Dart across = map_.insert_edge_in_face(in_ring(middle, node({1, 0, 1})), in_ring(middle, node({1, 2, 1})));
    new_spring(across, level_);
    const Dart centre = insert_vertex(across, mean(cn), 2 * level_);
    p_[at({1, 1, 1})] = m_.node_of(centre);
    finish_split(across, centre, node({2, 1, 1}), node({0, 1, 1}));
    // 4) one face a = 1 in each half, 5) split in two by the edge from the cell centre
    for (int k : {0, 2}) {
      const Dart f = insert_face({{1, 0, 1}, {1, 1, 1}, {1, 2, 1}, {1, 2, k}, {1, 1, k}, {1, 0, k}}, corner_of({0, 0, k}));
      new_spring(map_.insert_edge_in_face(in_ring(f, node({1, 1, 1})), in_ring(f, node({1, 1, k}))), 2 * level_);
    }
    // 6) one face b = 1 in each quarter: eight children
    for (int i : {0, 2})
      for (int k : {0, 2}) (void)insert_face({{1, 1, 1}, {i, 1, 1}, {i, 1, k}, {1, 1, k}}, corner_of({i, 0, k}));
    A::grow_darts(m_);
    make_children(parent, e);
  }

 private:
  Index node(const Lat& p) const {
    const Index n = p_[static_cast<std::size_t>(at(p))];
    if (n == physics::invalid_index) throw std::logic_error("refine: a lattice particle is missing");
    return n;
  }
  DartList piece(int corner) const { return map_.template cell<3>(corner_dart_[static_cast<std::size_t>(corner)]); }

  // The dart of `path` starting at the middle of the path (Σ 1/l_e reaching half of `total`),
  // or null if the middle falls inside its only edge.
  Dart middle_of(const std::vector<Dart>& path, std::uint32_t level) const {
    const std::uint64_t half = whole / (2 * std::uint64_t{level});
    std::uint64_t acc = 0;
    for (Dart x : path) {
      if (acc == half) return x;
      acc += whole / edge_level(m_, x);
    }
    if (path.size() != 1 || acc != 2 * half) throw std::logic_error("refine: edge levels inconsistent along a side");
    return {};
  }

  // The midpoint of the hierarchical edge or midline from a to b: found, or inserted in its
  // single edge at the mean of a and b.
  Index middle(Index a, Index b, int corner) {
    const DartList vol = piece(corner);
    const std::vector<Dart> path = walk_segment(m_, std::span<const Dart>(vol.data(), vol.size()), a, b);
    const Dart mid = middle_of(path, level_);
    if (!mid.is_null()) return m_.node_of(mid);
    const std::array<Index, 2> ends = {a, b};
    return m_.node_of(insert_vertex(path[0], mean(ends), 2 * edge_level(m_, path[0])));
  }

  void split_face(int axis, int side) {
    // the face's corners and midpoints in cyclic order, in lattice coordinates
    const std::array<std::array<int, 2>, 8> ring = {{{0, 0}, {1, 0}, {2, 0}, {2, 1}, {2, 2}, {1, 2}, {0, 2}, {0, 1}}};
    auto lat = [&](std::array<int, 2> uv) {
      Lat p{};
      p[static_cast<std::size_t>(axis)] = side;
      p[static_cast<std::size_t>((axis + 1) % 3)] = uv[0];
      p[static_cast<std::size_t>((axis + 2) % 3)] = uv[1];
      return p;
    };
    const int corner = corner_of(lat(ring[0]));
    std::array<Index, 4> q{};
    for (std::size_t k = 0; k < 4; ++k) q[k] = node(lat(ring[2 * k]));
    for (std::size_t k = 0; k < 4; ++k) {
      Index& mid = p_[static_cast<std::size_t>(at(lat(ring[2 * k + 1])))];
      if (mid == physics::invalid_index) mid = middle(q[k], q[(k + 1) % 4], corner);
    }
    const Index m0 = node(lat(ring[1])), m1 = node(lat(ring[3])), m2 = node(lat(ring[5])), m3 = node(lat(ring[7]));
    Index& fc = p_[static_cast<std::size_t>(at(lat({1, 1})))];
    // a face a finer neighbour split already has its midlines: the centre is the middle of one
    const DartList vol = piece(corner);
    for (Dart x : vol) {
      if (m_.node_of(x) != m0) continue;
      if (const Dart b = in_ring(x, m2); !b.is_null()) {  // the face is still one face: split it
        const Dart across = map_.insert_edge_in_face(x, b);
        new_spring(across, level_);
        const Dart centre = insert_vertex(across, mean(q), 2 * level_);
        fc = m_.node_of(centre);
        finish_split(across, centre, m1, m3);
        return;
      }
    }
    fc = middle(m0, m2, corner);
  }

  // After `across` (between two opposite midpoints) was split at `centre`: the edges from the
  // centre to the two other midpoints, one in each half.
  void finish_split(Dart across, Dart centre, Index m1, Index m3) {
    const Dart other = map_.beta(across, 2);  // starts at the centre too, in the other half
    Dart to1 = in_ring(centre, m1);
    const bool first_holds_m1 = !to1.is_null();
    new_spring(map_.insert_edge_in_face(centre, first_holds_m1 ? to1 : in_ring(centre, m3)), 2 * level_);
    new_spring(map_.insert_edge_in_face(other, in_ring(other, first_holds_m1 ? m3 : m1)), 2 * level_);
  }

  // Inserts a face along the closed lattice polygon, in the piece holding parent corner `corner`.
  Dart insert_face(std::initializer_list<Lat> polygon, int corner) {
    const DartList vol = piece(corner);
    const std::vector<Lat> pts(polygon);
    std::vector<Dart> path;
    for (std::size_t i = 0; i < pts.size(); ++i) {
      const auto part = walk_segment(m_, std::span<const Dart>(vol.data(), vol.size()), node(pts[i]), node(pts[(i + 1) % pts.size()]));
      path.insert(path.end(), part.begin(), part.end());
    }
    return map_.insert_face_in_volume(path);
  }

  void make_children(const Element& parent, Index e) {
    auto& elements = A::elements(m_);
    const Index first = static_cast<Index>(elements.size());
    HooksPaused<typename A::Map> quiet(map_);  // the parent's volume attribute goes with the parent
    for (int v = 0; v < 8; ++v) {
      const Lat base = corner_lattice[static_cast<std::size_t>(v)];
      std::array<Index, 8> corner{};
      for (std::size_t w = 0; w < 8; ++w) {
        Lat p{};
        for (std::size_t a = 0; a < 3; ++a) p[a] = base[a] / 2 + corner_lattice[w][a] / 2;
        corner[w] = node(p);
      }
      const DartList vol = piece(v);
      const Dart dart = walk_segment(m_, std::span<const Dart>(vol.data(), vol.size()), corner[0], corner[1]).front();
      elements.push_back(make_hex_child(m_, parent, e, dart, corner));
      map_.template set_attribute<3>(dart, physics::ElementRef{first + static_cast<Index>(v)});
      code_hex_volume(m_, vol, corner);
    }
    retire(e, first, 8);
  }

  std::uint32_t level_ = 1;
  std::array<Index, 27> p_{};
  std::array<Dart, 8> corner_dart_{};
};

}  // namespace

void refine_hex(physics::MssModel<3>& m, physics::Index e, RefineReport& report) { HexRefiner(m, report).run(e); }

}  // namespace sewn::refine::detail
