// Coarsening of a hexahedron family (PHYSICS_NOTES §2.8): the 1:8 refinement undone in reverse
// order with the map's removals (hex_refine.cpp names the lattice and the steps).
#include <array>
#include <map>
#include <string>

#include "hierarchy/coarsen_detail.hpp"
#include "hierarchy/hex_codes.hpp"
#include "hierarchy/model_access.hpp"

namespace sewn::refine::detail {

namespace {

using physics::Element;
using Vec3 = Eigen::Vector3d;

class HexCoarsener {
  using A = ModelAccess<3>;

 public:
  HexCoarsener(physics::MssModel<3>& m, Index p) : m_(m), map_(A::map(m)), p_(p), first_(m.elements()[p].first_child) {
    for (std::size_t v = 0; v < 8; ++v) {
      const auto n = m.element_nodes(first_ + static_cast<Index>(v));
      for (std::size_t w = 0; w < 8; ++w) {
        Lat q{};
        for (std::size_t a = 0; a < 3; ++a) q[a] = corner_lattice[v][a] / 2 + corner_lattice[w][a] / 2;
        lat_[static_cast<std::size_t>(at(q))] = n[w];
      }
      // a dart at parent corner v (the child's local vertex v): the only kind that survives every removal
      for (Dart x : map_.template cell<3>(m.elements()[first_ + static_cast<Index>(v)].dart))
        if (m.node_of(x) == n[v]) corner_dart_[v] = x;
    }
  }

  Index node(const Lat& q) const { return lat_[static_cast<std::size_t>(at(q))]; }
  const std::array<Index, 27>& lattice() const { return lat_; }

  // The dart of the piece holding parent corner v that starts at `from` and whose face ring
  // holds every particle of `also`.
  Dart face_dart(int v, Index from, std::initializer_list<Index> also) const {
    for (Dart x : map_.template cell<3>(corner_dart_[static_cast<std::size_t>(v)])) {
      if (m_.node_of(x) != from) continue;
      bool all = true;
      for (Index n : also) {
        bool found = false;
        Dart y = x;
        do {
          found = found || m_.node_of(y) == n;
          y = map_.beta(y, 1);
        } while (y != x);
        all = all && found;
      }
      if (all) return x;
    }
    throw std::logic_error("coarsen: a face of the family is missing");
  }
  Dart edge_dart(int v, Index a, Index b) const {
    for (Dart x : map_.template cell<3>(corner_dart_[static_cast<std::size_t>(v)]))
      if (m_.node_of(x) == a && end_node(m_, x) == b) return x;
    throw std::logic_error("coarsen: an edge of the family is missing");
  }
  bool corner_elsewhere(Index n) const {  // some other live element has particle n as a corner
    for (Index e = 0; e < m_.elements().size(); ++e) {
      if (e == p_ || !m_.elements()[e].alive || (e >= first_ && e < first_ + 8)) continue;
      for (Index c : m_.element_nodes(e))
        if (c == n) return true;
    }
    return false;
  }

  // Steps 6 to 1 of the refinement, undone; returns which lattice particles remain.
  std::array<bool, 27> run() {
    const Index C = node({1, 1, 1});
    for (int i : {0, 2})
      for (int k : {0, 2})
        map_.template remove_cell<2>(face_dart(corner(i, 0, k), C, {node({i, 1, 1}), node({1, 1, k})}));
    for (int k : {0, 2}) map_.template remove_cell<1>(edge_dart(corner(0, 0, k), C, node({1, 1, k})));
    for (int k : {0, 2}) map_.template remove_cell<2>(face_dart(corner(0, 0, k), C, {node({1, 1, k}), node({1, 0, 1})}));
    for (int a : {0, 2}) map_.template remove_cell<1>(edge_dart(0, C, node({a, 1, 1})));
    map_.template remove_cell<0>(edge_dart(0, C, node({1, 0, 1})));
    map_.template remove_cell<1>(edge_dart(0, node({1, 0, 1}), node({1, 2, 1})));
    map_.template remove_cell<2>(face_dart(0, node({1, 0, 1}), {node({0, 1, 1}), node({2, 1, 1}), node({1, 2, 1})}));
    std::array<bool, 27> kept{};
    kept.fill(true);
    kept[at({1, 1, 1})] = false;
    // step 1: each face split is undone unless a neighbour keeps its centre as a corner
    for (int axis = 0; axis < 3; ++axis)
      for (int side : {0, 2}) {
        auto lat = [&](int u, int v) {
          Lat q{};
          q[static_cast<std::size_t>(axis)] = side;
          q[static_cast<std::size_t>((axis + 1) % 3)] = u;
          q[static_cast<std::size_t>((axis + 2) % 3)] = v;
          return q;
        };
        const Index fc = node(lat(1, 1));
        if (corner_elsewhere(fc)) continue;
        const int v0 = corner(lat(0, 0)[0], lat(0, 0)[1], lat(0, 0)[2]);
        map_.template remove_cell<1>(edge_dart(v0, fc, node(lat(2, 1))));
        map_.template remove_cell<1>(edge_dart(v0, fc, node(lat(0, 1))));
        map_.template remove_cell<0>(edge_dart(v0, fc, node(lat(1, 0))));
        map_.template remove_cell<1>(edge_dart(v0, node(lat(1, 0)), node(lat(1, 2))));
        kept[static_cast<std::size_t>(at(lat(1, 1)))] = false;
      }
    // edge midpoints no other element has as a corner go, joining their edge's halves
    for (int q = 0; q < 27; ++q) {
      const Lat l = {q % 3, (q / 3) % 3, q / 9};
      const int odd = (l[0] == 1) + (l[1] == 1) + (l[2] == 1);
      if (odd != 1 || corner_elsewhere(lat_[static_cast<std::size_t>(q)])) continue;
      Lat a = l, b = l;
      for (std::size_t k = 0; k < 3; ++k)
        if (l[k] == 1) {
          a[k] = 0;
          b[k] = 2;
        }
      const Dart half = edge_dart(corner(a[0], a[1], a[2]), node(a), lat_[static_cast<std::size_t>(q)]);
      const std::uint32_t level = map_.value(map_.template attribute<1>(half)).level;
      map_.template remove_cell<0>(map_.beta(half, 1));
      map_.value(map_.template attribute<1>(half)).level = level / 2;
      kept[static_cast<std::size_t>(q)] = false;
    }
    return kept;
  }

  DartList volume() const { return map_.template cell<3>(corner_dart_[0]); }

 private:
  static int corner(int a, int b, int c) {
    for (int v = 0; v < 8; ++v)
      if (corner_lattice[static_cast<std::size_t>(v)] == Lat{a, b, c}) return v;
    return 0;
  }

  physics::MssModel<3>& m_;
  A::Map& map_;
  Index p_, first_;
  std::array<Index, 27> lat_{};
  std::array<Dart, 8> corner_dart_{};
};

}  // namespace

CoarsenReport coarsen_hex(physics::MssModel<3>& m, Index p) {
  CoarsenReport report;
  physics::NodeTable& nodes = m.nodes();
  HexCoarsener h(m, p);
  const std::array<Index, 27> lat = h.lattice();
  std::map<Index, std::pair<double, Vec3>> before;
  double ke_before = 0;
  for (Index c = m.elements()[p].first_child; c < m.elements()[p].first_child + 8; ++c)
    for (Index n : m.element_nodes(c))
      if (before.emplace(n, std::make_pair(nodes.mass(n), nodes.velocity(n))).second)
        ke_before += 0.5 * nodes.mass(n) * nodes.velocity(n).squaredNorm();
  std::array<bool, 27> kept{};
  std::array<Index, 8> corner{};
  for (std::size_t v = 0; v < 8; ++v) corner[v] = lat[static_cast<std::size_t>(at(corner_lattice[v]))];
  A_edit(m, [&] {
    kept = h.run();
    revive_parent(m, p, 8, 4);
    {
      HooksPaused<ModelAccess<3>::Map> quiet(ModelAccess<3>::map(m));
      ModelAccess<3>::map(m).template set_attribute<3>(m.elements()[p].dart, physics::ElementRef{p});
    }
    code_hex_volume(m, h.volume(), corner);
    ModelAccess<3>::attach_diagonals(m, p);
  });
  // momentum to the corners by the trilinear shape functions, kept particles slaved
  std::array<Vec3, 8> pc{};
  std::array<double, 8> lumped{};
  for (std::size_t v = 0; v < 8; ++v) {
    pc[v] = before[corner[v]].first * before[corner[v]].second;
    lumped[v] = nodes.mass(corner[v]);
  }
  for (int q = 0; q < 27; ++q) {
    const Lat l = {q % 3, (q / 3) % 3, q / 9};
    if (l[0] != 1 && l[1] != 1 && l[2] != 1) continue;  // a corner
    const Index n = lat[static_cast<std::size_t>(q)];
    const auto& [m_old, v_old] = before[n];
    for (std::size_t v = 0; v < 8; ++v) {
      double w = 1;
      for (std::size_t a = 0; a < 3; ++a) w *= corner_lattice[v][a] == 2 ? l[a] / 2.0 : 1 - l[a] / 2.0;
      pc[v] += w * m_old * v_old;
      if (kept[static_cast<std::size_t>(q)]) lumped[v] += w * nodes.mass(n);
    }
    if (!kept[static_cast<std::size_t>(q)]) ++report.particles_removed;
  }
  for (std::size_t v = 0; v < 8; ++v) nodes.set_velocity(corner[v], pc[v] / lumped[v]);
  for (int q = 0; q < 27; ++q) {
    const Lat l = {q % 3, (q / 3) % 3, q / 9};
    if ((l[0] != 1 && l[1] != 1 && l[2] != 1) || !kept[static_cast<std::size_t>(q)]) continue;
    Vec3 vel = Vec3::Zero();
    for (std::size_t v = 0; v < 8; ++v) {
      double w = 1;
      for (std::size_t a = 0; a < 3; ++a) w *= corner_lattice[v][a] == 2 ? l[a] / 2.0 : 1 - l[a] / 2.0;
      vel += w * nodes.velocity(corner[v]);
    }
    nodes.set_velocity(lat[static_cast<std::size_t>(q)], vel);
  }
  double ke_after = 0;
  for (const auto& [n, mv] : before)
    if (nodes.is_alive(n)) ke_after += 0.5 * nodes.mass(n) * nodes.velocity(n).squaredNorm();
  report.dissipated_energy = ke_before - ke_after;
  return report;
}

}  // namespace sewn::refine::detail
