// Coarsening of a hexahedron family (PHYSICS_NOTES §2.8): the 1:8 refinement undone in reverse
// order with the map's removals (hex_refine.cpp names the lattice and the steps).
#include <algorithm>
#include <array>
#include <map>
#include <string>
#include <vector>

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

std::string hex_cut_conflict(const physics::MssModel<3>& m, Index p) {
  const auto& map = m.map();
  const Index first = m.elements()[p].first_child;
  std::array<Index, 27> lat{};
  for (std::size_t v = 0; v < 8; ++v) {
    const auto n = m.element_nodes(first + static_cast<Index>(v));
    for (std::size_t w = 0; w < 8; ++w) {
      Lat q{};
      for (std::size_t a = 0; a < 3; ++a) q[a] = corner_lattice[v][a] / 2 + corner_lattice[w][a] / 2;
      lat[static_cast<std::size_t>(at(q))] = n[w];
    }
  }
  auto node = [&](const Lat& q) { return lat[static_cast<std::size_t>(at(q))]; };
  auto in_family = [&](Index e) { return e >= first && e < first + 8; };
  std::vector<Dart> darts;  // the family's darts
  for (Index c = first; c < first + 8; ++c)
    for (Dart x : map.template cell<3>(m.elements()[c].dart)) darts.push_back(x);
  auto at_node = [&](Index n) {
    std::vector<Dart> out;
    for (Dart x : darts)
      if (m.node_of(x) == n) out.push_back(x);
    return out;
  };
  // whether an element outside the family has the particle at x as a corner there (then
  // coarsening keeps it, with the faces and edges that meet at it)
  auto kept = [&](Dart x) {
    for (Dart y : map.template cell<0>(x))
      if (const Index e = m.element_of(y); e != physics::invalid_index && !in_family(e) && m.is_corner_dart(y)) return true;
    return false;
  };
  // a face centre that goes takes the edges inside the face with it: they must join faces that
  // are all sewn to one neighbour or all free, not some cut and some not (three faces at an edge)
  std::vector<Index> centres_going;
  for (int axis = 0; axis < 3; ++axis)
    for (int side : {0, 2}) {
      Lat q{};
      q[static_cast<std::size_t>(axis)] = side;
      q[static_cast<std::size_t>((axis + 1) % 3)] = q[static_cast<std::size_t>((axis + 2) % 3)] = 1;
      const Index fc = node(q);
      const auto here = at_node(fc);
      if (here.empty() || kept(here.front())) continue;
      centres_going.push_back(fc);
      bool sewn = false, free = false;
      for (Dart x : here) {
        const Dart y = map.beta(x, 3);
        if (y.is_null())
          free = true;
        else if (!in_family(m.element_of(y)))
          sewn = true;
      }
      if (sewn && free)
        return "has a face partly cut (particle " + std::to_string(fc) +
               " at its centre): its split can be undone only once the whole face is cut or none of it";
    }
  // a particle that stays becomes a T-junction of the parent, slaved to its corners; if it is one
  // of another element too, that element must hold the same particles where the parent's corners
  // are (a cut may have separated them: the particle would be slaved to one side and off the other)
  const double size = (m.rest_position(node({2, 2, 2})) - m.rest_position(node({0, 0, 0}))).norm();
  for (int q = 0; q < 27; ++q) {
    const Lat l = {q % 3, (q / 3) % 3, q / 9};
    const int odd = (l[0] == 1) + (l[1] == 1) + (l[2] == 1);
    if (odd == 0 || odd == 3) continue;
    const auto here = at_node(lat[static_cast<std::size_t>(q)]);
    if (here.empty() || !kept(here.front())) continue;
    std::vector<Index> masters;
    for (const Lat& c : corner_lattice) {
      bool on = true;
      for (std::size_t a = 0; a < 3; ++a) on = on && (l[a] == 1 || l[a] == c[a]);
      if (on) masters.push_back(node(c));
    }
    for (Dart y : map.template cell<0>(here.front())) {
      const Index e = m.element_of(y);
      if (e == physics::invalid_index || in_family(e) || m.is_corner_dart(y)) continue;
      for (Dart z : map.template cell<3>(y))
        for (Index c : masters)
          if (m.node_of(z) != c && (m.rest_position(m.node_of(z)) - m.rest_position(c)).norm() <= 1e-12 * size)
            return "would slave particle " + std::to_string(lat[static_cast<std::size_t>(q)]) + " to its corners while element " +
                   std::to_string(e) + ", which also holds it inside a side, has another particle (a cut's copy) at corner " +
                   std::to_string(c) + ": coarsen or cut that element first";
    }
  }
  // an edge midpoint that goes joins its edge's two halves: then only those two edges may meet
  // at it (each one edge, not one a cut doubled), beside the edges to face centres going too
  for (const auto& [a, b] : hex_edge_ends) {
    Lat mid{};
    for (std::size_t k = 0; k < 3; ++k) mid[k] = (corner_lattice[a][k] + corner_lattice[b][k]) / 2;
    const Index n = node(mid);
    const auto here = at_node(n);
    if (here.empty() || kept(here.front())) continue;
    const Index ea = node(corner_lattice[a]), eb = node(corner_lattice[b]);
    std::vector<std::uint32_t> cells[2];
    for (Dart y : map.template cell<0>(here.front())) {
      const Index t = end_node(m, y);
      if (t != ea && t != eb) {
        if (std::find(centres_going.begin(), centres_going.end(), t) != centres_going.end()) continue;
        return "has an edge whose middle (particle " + std::to_string(n) +
               ") a cut separated from the finer neighbour that keeps an edge there: coarsen or cut that neighbour first";
      }
      std::uint32_t least = y.index();
      for (Dart z : map.template cell<1>(y)) least = std::min(least, z.index());
      cells[t == ea ? 0 : 1].push_back(least);
    }
    for (auto& c : cells) {
      std::sort(c.begin(), c.end());
      if (std::unique(c.begin(), c.end()) - c.begin() > 1)
        return "has an edge cut on one half only (particle " + std::to_string(n) +
               " at its middle): its halves can be joined only once both are cut alike";
    }
  }
  return {};
}

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
