// Coarsening of a quad family (PHYSICS_NOTES §2.8): the refinement undone, on the map's removals.
#include "sewn/refine/coarsen.hpp"

#include <array>
#include <map>
#include <string>

#include "hierarchy/coarsen_detail.hpp"
#include "hierarchy/model_access.hpp"
#include "hierarchy/sides.hpp"
#include "sewn/physics/errors.hpp"
#include "sewn/refine/hierarchy.hpp"

namespace sewn::refine {

namespace {

using physics::Element;
using physics::ElementKind;
using Vec3 = Eigen::Vector3d;
constexpr std::array<std::array<int, 2>, 4> quad_edges = {{{0, 1}, {3, 2}, {1, 2}, {0, 3}}};

int quad_side(int a, int b) {
  for (int e = 0; e < 4; ++e)
    if ((quad_edges[e][0] == a && quad_edges[e][1] == b) || (quad_edges[e][0] == b && quad_edges[e][1] == a)) return e;
  return 0;
}

template <int D>
Dart dart_at(const MssModel<D>& m, Dart ring, Index node) {
  Dart x = ring;
  do {
    if (m.node_of(x) == node) return x;
    x = m.map().beta(x, 1);
  } while (x != ring);
  return {};
}

// A side midpoint that no neighbour has as a corner goes with the coarsening, joining the side's
// two halves; it cannot when a cut ends there (one half free, the other still sewn to a coarser
// neighbour, so three edges meet at it). 2D. O(family).
template <int D, class No>
bool side_midpoints_removable(const MssModel<D>& m, Index p, const No& no) {
  const Index first = m.elements()[p].first_child;
  const Index centre = m.element_nodes(first)[2];
  for (Index k = 0; k < 4; ++k) {
    const Index mid = m.element_nodes(first + k)[1];
    bool kept = false, free_half = false, sewn_half = false, split_half = false;
    for (Index c = first; c < first + 4; ++c) {
      Dart x = m.elements()[c].dart;
      do {
        const Dart next = m.map().beta(x, 1);
        const bool at_mid = m.node_of(x) == mid || m.node_of(next) == mid;
        if (at_mid && m.node_of(x) != centre && m.node_of(next) != centre) {
          const Dart across = m.map().beta(x, 2);
          (across.is_null() ? free_half : sewn_half) = true;
          split_half = split_half || detail::edge_level(m, x) != m.elements()[first].level;
          if (!across.is_null()) {  // the neighbour's darts at the midpoint: is it a corner of one?
            const Dart at = m.node_of(across) == mid ? across : m.map().beta(across, 1);
            kept = kept || m.is_corner_dart(at);
          }
        }
        x = next;
      } while (x != m.elements()[c].dart);
    }
    if (!kept && split_half)
      return no("has its side " + std::to_string(k) + " still split next to its midpoint (particle " + std::to_string(mid) +
                ") by a T-junction that a cut separated from the finer neighbour making it: the halves cannot be joined");
    if (!kept && free_half && sewn_half)
      return no("has a cut ending at the midpoint of its side " + std::to_string(k) + " (particle " + std::to_string(mid) +
                "), which a coarser neighbour still shares: the midpoint can neither go nor stay a corner; cut the side's other half or refine the neighbour first");
  }
  return true;
}

// After a coarsening: the constraints that can change are those of the parent's particles (a
// kept midpoint becomes the parent's T-junction) and of the removed ones (dropped).
template <int D>
void retie_t_junctions(MssModel<D>& m, Index p) {
  update_t_junctions(m, std::span<const Index>(&p, 1));
}

// A hexahedron family of a 3-map: no cut between siblings nor one stopping the removals.
template <int D, class No>
bool can_coarsen_hex(const MssModel<D>& m, Index p, const No& no) {
  const Element& el = m.elements()[p];
  // a cut between siblings: an interior face (all hold the centre) left free
  const Index centre = m.element_nodes(el.first_child)[6];
  for (Index c = el.first_child; c < el.first_child + 8; ++c)
    for (Dart x : m.map().template cell<3>(m.elements()[c].dart))
      if (m.node_of(x) == centre && m.map().beta(x, 3).is_null())
        return no("has a cut between its children (child " + std::to_string(c) + "): a cut family stays refined");
  if (const std::string conflict = detail::hex_cut_conflict(m, p); !conflict.empty()) return no(conflict);
  return true;
}

// A quad family (2-map, or membrane of a 3-map): no cut between siblings nor one stopping the
// removal of a side midpoint.
template <int D, class No>
bool can_coarsen_quad(const MssModel<D>& m, Index p, const No& no) {
  const Element& el = m.elements()[p];
  // a cut between siblings: an interior edge (from the centre) left free
  const Index centre = m.element_nodes(el.first_child)[2];
  for (Index c = el.first_child; c < el.first_child + 4; ++c) {
    Dart x = m.elements()[c].dart;
    do {
      const Dart next = m.map().beta(x, 1);
      if ((m.node_of(x) == centre || m.node_of(next) == centre) && m.map().beta(x, 2).is_null())
        return no("has a cut between its children (child " + std::to_string(c) + "): a cut family stays refined");
      x = next;
    } while (x != m.elements()[c].dart);
  }
  return side_midpoints_removable(m, p, no);
}

}  // namespace

template <int D>
bool can_coarsen(const MssModel<D>& m, Index p, std::string* why) {
  auto no = [&](const std::string& s) {
    if (why) *why = "coarsen: element " + std::to_string(p) + " " + s;
    return false;
  };
  if (p >= m.elements().size()) return no("does not exist");
  const Element& el = m.elements()[p];
  if (el.first_child == physics::invalid_index) return no("is not refined (no family to merge)");
  const bool hex = el.kind == ElementKind::hexahedron;
  if (el.kind != ElementKind::quad && !hex) return no("is neither a quad nor a hexahedron");
  const Index n = hex ? 8 : 4;
  for (Index c = el.first_child; c < el.first_child + n; ++c) {
    const Element& ch = m.elements()[c];
    if (ch.first_child != physics::invalid_index) return no("has child " + std::to_string(c) + " refined further: coarsen it first");
    if (!ch.alive) return no("has child " + std::to_string(c) + " removed");
  }
  if constexpr (D == 3)
    if (hex) return can_coarsen_hex(m, p, no);
  return can_coarsen_quad(m, p, no);
}

template <int D>
CoarsenReport coarsen(MssModel<D>& m, Index p) {
  std::string why;
  if (!can_coarsen(m, p, &why)) throw physics::InputError(why);
  CoarsenReport report;
  if constexpr (D == 3)
    if (m.elements()[p].kind == ElementKind::hexahedron) {
      report = detail::coarsen_hex(m, p);
      retie_t_junctions(m, p);
      return report;
    }
  {
    using A = detail::ModelAccess<D>;
    auto& map = A::map(m);
    physics::NodeTable& nodes = m.nodes();
    const Element parent = m.elements()[p];
    const Index first = parent.first_child;
    std::array<Index, 4> corner{}, mid{};
    for (Index k = 0; k < 4; ++k) {
      const auto n = m.element_nodes(first + k);  // child k: (corner k, midpoint k, centre, midpoint k-1)
      corner[k] = n[0];
      mid[k] = n[1];
    }
    const Index centre = m.element_nodes(first)[2];
    // the state before: every particle of the family with its mass and velocity
    std::map<Index, std::pair<double, Vec3>> before;
    double ke_before = 0;
    for (Index c = first; c < first + 4; ++c)
      for (Index n : m.element_nodes(c))
        if (before.emplace(n, std::make_pair(nodes.mass(n), nodes.velocity(n))).second)
          ke_before += 0.5 * nodes.mass(n) * nodes.velocity(n).squaredNorm();
    std::array<bool, 4> mid_kept{};
    detail::A_edit(m, [&] {
        const Dart ring0 = m.elements()[first].dart;
        // 1) the edges centre-midpoint 1 and centre-midpoint 3 (the last inserted), merging the
        //    children pairwise, 2) the centre, joining the two halves of the middle edge, 3) that edge
        for (Index k : {Index{2}, Index{0}}) {  // child k's ring runs centre -> midpoint k-1
          const Dart c = m.elements()[first + k].dart;
          map.template remove_cell<1>(dart_at(m, c, centre));
        }
        map.template remove_cell<0>(dart_at(m, ring0, centre));
        Dart across;  // the inward dart from midpoint 0, now running to midpoint 2
        for (Dart y : map.template cell<0>(dart_at(m, ring0, mid[0])))
          if (m.node_of(map.beta(y, 1)) == mid[2]) across = y;
        map.template remove_cell<1>(across);
        // 4) the parent back: its face, its corners' codes, its diagonals
        detail::revive_parent(m, p, 4, 2);
        Element& el = A::elements(m)[p];
        {
          HooksPaused<typename A::Map> quiet(map);
          map.template set_attribute<2>(el.dart, physics::ElementRef{p});
        }
        // 5) midpoints no neighbour has as a corner go, joining the side's two halves again
        for (int k = 0; k < 4; ++k) {
          const Dart at_mid = dart_at(m, el.dart, mid[static_cast<std::size_t>(k)]);
          bool kept = false;
          for (Dart y : map.template cell<0>(at_mid))
            kept = kept || (m.element_of(y) != p && m.element_of(y) != physics::invalid_index && m.is_corner_dart(y));
          mid_kept[static_cast<std::size_t>(k)] = kept;
          if (kept) continue;
          const Dart before_mid = map.beta(at_mid, 0);
          const std::uint32_t level = map.value(map.template attribute<1>(before_mid)).level;
          map.template remove_cell<0>(at_mid);
          map.value(map.template attribute<1>(before_mid)).level = level / 2;
          ++report.particles_removed;
        }
        ++report.particles_removed;  // the centre
        // 6) the parent's ring: its corners in its own local order (a built element may run reversed)
        int k = -1, local = 0;
        Dart x = el.dart;
        do {
          for (int c = 0; c < 4; ++c)
            if (m.node_of(x) == corner[static_cast<std::size_t>(c)]) k = c;
          const bool is_corner = m.node_of(x) == corner[static_cast<std::size_t>(k)];
          local = el.reversed ? (4 - k) % 4 : k;
          const int next = el.reversed ? (local + 3) % 4 : (local + 1) % 4;
          A::set_dart(m, x, is_corner ? static_cast<std::uint8_t>(local) : physics::not_a_corner, quad_side(local, next));
          A::mark_vertex_dirty(m, x);
          x = map.beta(x, 1);
        } while (x != el.dart);
        A::attach_diagonals(m, p);
    });
    // 7) momentum to the corners by the parent's shape functions, kept midpoints slaved
    std::array<Vec3, 4> p_corner{};
    std::array<double, 4> lumped{};
    for (std::size_t c = 0; c < 4; ++c) {
      p_corner[c] = before[corner[c]].first * before[corner[c]].second;
      lumped[c] = nodes.mass(corner[c]);
    }
    auto pass = [&](Index n, const std::array<double, 4>& w) {
      const auto& [m_old, v] = before[n];
      for (std::size_t c = 0; c < 4; ++c) p_corner[c] += w[c] * m_old * v;
    };
    pass(centre, {0.25, 0.25, 0.25, 0.25});
    for (std::size_t k = 0; k < 4; ++k) {
      std::array<double, 4> w{};
      w[k] = w[(k + 1) % 4] = 0.5;
      pass(mid[k], w);
      if (mid_kept[k])
        for (std::size_t c = 0; c < 4; ++c) lumped[c] += w[c] * nodes.mass(mid[k]);
    }
    for (std::size_t c = 0; c < 4; ++c) nodes.set_velocity(corner[c], p_corner[c] / lumped[c]);
    for (std::size_t k = 0; k < 4; ++k)
      if (mid_kept[k]) nodes.set_velocity(mid[k], (nodes.velocity(corner[k]) + nodes.velocity(corner[(k + 1) % 4])) / 2);
    double ke_after = 0;
    for (const auto& [n, mv] : before)
      if (nodes.is_alive(n)) ke_after += 0.5 * nodes.mass(n) * nodes.velocity(n).squaredNorm();
    report.dissipated_energy = ke_before - ke_after;
    retie_t_junctions(m, p);
  }
  return report;
}

template bool can_coarsen(const MssModel<2>&, Index, std::string*);
template bool can_coarsen(const MssModel<3>&, Index, std::string*);
template CoarsenReport coarsen(MssModel<2>&, Index);
template CoarsenReport coarsen(MssModel<3>&, Index);

}  // namespace sewn::refine
