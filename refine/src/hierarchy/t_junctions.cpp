// T-junctions of the hierarchy and their slave-node constraints (PHYSICS_NOTES §2.6).
#include <algorithm>
#include <map>
#include <utility>
#include <vector>

#include "hierarchy/bilinear.hpp"
#include "hierarchy/neighbours.hpp"
#include "hierarchy/segment_walk.hpp"
#include "hierarchy/sides.hpp"
#include "sewn/refine/hierarchy.hpp"

namespace sewn::refine {

namespace {

using physics::Element;
using physics::ElementKind;
using Vec3 = Eigen::Vector3d;

constexpr std::array<std::array<int, 2>, 12> hex_edges = {
    {{0, 1}, {3, 2}, {4, 5}, {7, 6}, {0, 3}, {1, 2}, {4, 7}, {5, 6}, {0, 4}, {1, 5}, {2, 6}, {3, 7}}};
constexpr std::array<std::array<int, 4>, 6> hex_faces = {
    {{0, 1, 2, 3}, {4, 5, 6, 7}, {0, 1, 5, 4}, {3, 2, 6, 7}, {0, 3, 7, 4}, {1, 2, 6, 5}}};

template <int D>
void quad_t_junctions(const MssModel<D>& m, Index e, std::vector<TJunction>& out) {
  const Element& el = m.elements()[e];
  const auto c = detail::corner_darts(m, el);
  for (std::size_t k = 0; k < 4; ++k) {
    const Dart end = c[(k + 1) % 4];
    const std::uint64_t side = detail::whole / el.level;
    std::uint64_t acc = 0;
    for (Dart x = c[k]; x != end; x = m.map().beta(x, 1)) {
      if (x != c[k]) {
        const double t = static_cast<double>(acc) / static_cast<double>(side);
        out.push_back({m.node_of(x), e, 2, {m.node_of(c[k]), m.node_of(end)}, {1 - t, t}});
      }
      acc += detail::whole / detail::edge_level(m, x);
    }
  }
}

template <int D>
void hex_t_junctions(const MssModel<D>& m, Index e, std::vector<TJunction>& out) {
  const Element& el = m.elements()[e];
  const DartList vol = m.map().template cell<3>(el.dart);
  const std::vector<Index> corner = m.element_nodes(e);
  std::map<Index, bool> placed;  // the volume's particles that are no corner: found on an edge yet?
  for (Dart x : vol)
    if (!m.is_corner_dart(x)) placed.emplace(m.node_of(x), false);
  for (const auto& [a, b] : hex_edges) {
    const Index na = corner[static_cast<std::size_t>(a)], nb = corner[static_cast<std::size_t>(b)];
    const auto path = detail::walk_segment(m, std::span<const Dart>(vol.data(), vol.size()), na, nb);
    const double length = (m.rest_position(nb) - m.rest_position(na)).norm();
    for (std::size_t i = 1; i < path.size(); ++i) {
      const Index n = m.node_of(path[i]);
      const double t = (m.rest_position(n) - m.rest_position(na)).norm() / length;
      out.push_back({n, e, 2, {na, nb}, {1 - t, t}});
      placed[n] = true;
    }
  }
  for (const auto& [n, on_edge] : placed) {
    if (on_edge) continue;
    for (const auto& f : hex_faces) {
      std::array<Vec3, 4> q;
      for (std::size_t k = 0; k < 4; ++k) q[k] = m.rest_position(corner[static_cast<std::size_t>(f[k])]);
      double s = 0, t = 0;
      if (!detail::bilinear_inside(q, m.rest_position(n), s, t)) continue;
      TJunction tj{n, e, 4, {}, {(1 - s) * (1 - t), s * (1 - t), s * t, (1 - s) * t}};
      for (std::size_t k = 0; k < 4; ++k) tj.master[k] = corner[static_cast<std::size_t>(f[k])];
      out.push_back(tj);
      break;
    }
  }
}

}  // namespace

template <int D>
std::vector<TJunction> t_junctions(const MssModel<D>& m) {
  std::vector<TJunction> all;
  for (Index e = 0; e < m.elements().size(); ++e) {
    const Element& el = m.elements()[e];
    if (!el.alive) continue;
    if (el.kind == ElementKind::quad) quad_t_junctions(m, e, all);
    if constexpr (D == 3)
      if (el.kind == ElementKind::hexahedron) hex_t_junctions(m, e, all);
  }
  auto level = [&](const TJunction& t) { return m.elements()[t.element].level; };
  // coarse to fine; a particle inside sides of several elements keeps the coarsest constraint
  std::stable_sort(all.begin(), all.end(), [&](const TJunction& a, const TJunction& b) { return level(a) < level(b); });
  std::vector<char> seen(m.nodes().size(), 0);
  std::vector<TJunction> out;
  for (const TJunction& t : all)
    if (!std::exchange(seen[t.node], 1)) out.push_back(t);
  return out;
}

template <int D>
void constrain_t_junctions(MssModel<D>& m, physics::SlaveTreatment treatment) {
  const std::vector<TJunction> tj = t_junctions(m);
  std::vector<physics::SlaveNode> slaves;
  slaves.reserve(tj.size());
  for (const TJunction& t : tj) slaves.push_back({t.node, t.master, t.weight, t.masters});
  // the paper's shares: equal parts to the other corners of the elements the T-junction is a corner of
  std::vector<std::vector<std::pair<Index, double>>> shares;
  if (treatment == physics::SlaveTreatment::paper_projection) {
    std::map<Index, std::size_t> slot;
    for (std::size_t i = 0; i < tj.size(); ++i) slot[tj[i].node] = i;
    shares.resize(tj.size());
    for (Index e = 0; e < m.elements().size(); ++e) {
      if (!m.elements()[e].alive) continue;
      const auto corner = m.element_nodes(e);
      for (Index n : corner)
        if (auto it = slot.find(n); it != slot.end())
          for (Index o : corner)
            if (o != n) shares[it->second].emplace_back(o, 1.0);
    }
    for (auto& s : shares)
      for (auto& [n, w] : s) w = 1.0 / static_cast<double>(s.size());
  }
  physics::SlaveNodes& sn = m.system().slaves();
  sn.set(std::move(slaves), std::move(shares));
  sn.set_treatment(treatment);
}

template <int D>
void update_t_junctions(MssModel<D>& m, std::span<const Index> changed) {
  physics::SlaveNodes& sn = m.system().slaves();
  if (sn.treatment() != physics::SlaveTreatment::reduction) {
    constrain_t_junctions(m, sn.treatment());
    return;
  }
  // the particles of the changed elements are the only ones whose constraint can change; the
  // elements that may hold one inside a side are those around it
  const physics::NodeTable& nodes = m.nodes();
  std::vector<char> again(nodes.size(), 0);
  std::vector<Index> els;
  for (Index e : changed)
    if (e < m.elements().size() && m.elements()[e].alive) els.push_back(e);
  std::sort(els.begin(), els.end());
  els.erase(std::unique(els.begin(), els.end()), els.end());
  // every live element changed (a uniform pass): the elements around them are these, so the
  // vertex walks that would find them are skipped
  const bool all_changed = els.size() == m.num_live_elements();
  for (Index e : std::vector<Index>(els)) {
    for (Dart x : detail::element_darts(m, e)) {
      if (std::exchange(again[m.node_of(x)], 1) || all_changed) continue;
      for (Dart y : m.map().template cell<0>(x))
        if (const Index n = m.element_of(y); n != physics::invalid_index && m.elements()[n].alive) els.push_back(n);
    }
  }
  std::sort(els.begin(), els.end());
  els.erase(std::unique(els.begin(), els.end()), els.end());
  std::vector<TJunction> found;
  for (Index e : els) {
    const Element& el = m.elements()[e];
    if (el.kind == ElementKind::quad) quad_t_junctions(m, e, found);
    if constexpr (D == 3)
      if (el.kind == ElementKind::hexahedron) hex_t_junctions(m, e, found);
  }
  std::erase_if(found, [&](const TJunction& t) { return !again[t.node]; });
  // as t_junctions(): coarsest first, ties in element order, the first entry of a particle wins
  std::stable_sort(found.begin(), found.end(),
                   [&](const TJunction& a, const TJunction& b) { return m.elements()[a.element].level < m.elements()[b.element].level; });
  std::vector<physics::SlaveNode> list;
  for (const physics::SlaveNode& s : sn.slaves()) {
    bool keep = s.node < nodes.size() && nodes.is_alive(s.node) && !again[s.node];
    for (int k = 0; k < s.masters; ++k) keep = keep && nodes.is_alive(s.master[static_cast<std::size_t>(k)]);
    if (keep) list.push_back(s);
  }
  std::vector<char> listed(nodes.size(), 0);
  for (const TJunction& t : found)
    if (!std::exchange(listed[t.node], 1)) list.push_back({t.node, t.master, t.weight, t.masters});
  // masters that are slaves before the slaves they master: a depth-first order on that relation
  std::vector<std::size_t> slot(nodes.size(), list.size());
  for (std::size_t i = 0; i < list.size(); ++i) slot[list[i].node] = i;
  std::vector<char> state(list.size(), 0);  // 0 new, 1 open, 2 placed
  std::vector<physics::SlaveNode> ordered;
  ordered.reserve(list.size());
  std::vector<std::pair<std::size_t, int>> stack;
  for (std::size_t r = 0; r < list.size(); ++r) {
    if (state[r]) continue;
    stack.emplace_back(r, 0);
    state[r] = 1;
    while (!stack.empty()) {
      auto& [i, k] = stack.back();
      if (k < list[i].masters) {
        const Index c = list[i].master[static_cast<std::size_t>(k++)];
        if (c < slot.size() && slot[c] < list.size() && state[slot[c]] == 0) {
          state[slot[c]] = 1;
          stack.emplace_back(slot[c], 0);
        }
        continue;
      }
      state[i] = 2;
      ordered.push_back(list[i]);
      stack.pop_back();
    }
  }
  sn.set(std::move(ordered));
}

template std::vector<TJunction> t_junctions(const MssModel<2>&);
template std::vector<TJunction> t_junctions(const MssModel<3>&);
template void constrain_t_junctions(MssModel<2>&, physics::SlaveTreatment);
template void constrain_t_junctions(MssModel<3>&, physics::SlaveTreatment);
template void update_t_junctions(MssModel<2>&, std::span<const Index>);
template void update_t_junctions(MssModel<3>&, std::span<const Index>);

}  // namespace sewn::refine
