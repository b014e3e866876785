#include "sewn/refine/hierarchy.hpp"

#include <algorithm>
#include <bit>
#include <cmath>
#include <map>
#include <sstream>

#include "hierarchy/segment_walk.hpp"
#include "hierarchy/sides.hpp"

namespace sewn::refine {

namespace {

using physics::Element;
using physics::ElementKind;

bool is_quad(const Element& el) { return el.alive && el.kind == ElementKind::quad; }

bool near(double a, double b, double scale) { return std::abs(a - b) <= 1e-12 * scale; }

constexpr std::array<std::array<int, 2>, 12> hex_edges = {
    {{0, 1}, {3, 2}, {4, 5}, {7, 6}, {0, 3}, {1, 2}, {4, 7}, {5, 6}, {0, 4}, {1, 5}, {2, 6}, {3, 7}}};

// A hexahedron: 8 corners, each met by 3 of its darts; each of its 12 hierarchical edges a chain
// of the volume's edges along the rest segment between its corners with Σ 1/l_e = 1/l_E and its
// T-junctions at their dyadic parameters; its mass share and its edge contributions k_E·l_e/l_E.
template <int D, class Problem>
void check_hex(const MssModel<D>& m, Index e, std::vector<double>& mass, std::map<Index, double>& spring_k, Problem&& problem) {
  const Element& el = m.elements()[e];
  const std::string name = "element " + std::to_string(e);
  const DartList vol = m.map().template cell<3>(el.dart);
  std::array<int, 8> seen{};
  for (Dart x : vol)
    if (m.is_corner_dart(x)) ++seen[static_cast<std::size_t>(m.corner_of_dart(x))];
  for (int v = 0; v < 8; ++v)
    if (seen[static_cast<std::size_t>(v)] != 3)
      problem(name + ": corner " + std::to_string(v) + " is met by " + std::to_string(seen[static_cast<std::size_t>(v)]) +
              " hierarchical darts, not 3");
  const std::vector<Index> corner = m.element_nodes(e);
  for (Index n : corner)
    if (n != physics::invalid_index) mass[n] += m.materials()[el.material].density * el.measure / 8;
  for (std::size_t k = 0; k < 12; ++k) {
    const Index a = corner[static_cast<std::size_t>(hex_edges[k][0])], b = corner[static_cast<std::size_t>(hex_edges[k][1])];
    std::vector<Dart> path;
    try {
      path = detail::walk_segment(m, std::span<const Dart>(vol.data(), vol.size()), a, b);
    } catch (const std::logic_error& ex) {
      problem(name + ": edge " + std::to_string(k) + ": " + ex.what());
      continue;
    }
    const double length = (m.rest_position(b) - m.rest_position(a)).norm();
    const std::uint64_t side = detail::whole / el.level;
    std::uint64_t acc = 0;
    for (Dart x : path) {
      const double t = static_cast<double>(acc) / static_cast<double>(side);
      const Eigen::Vector3d expect = (1 - t) * m.rest_position(a) + t * m.rest_position(b);
      if (!((m.rest_position(m.node_of(x)) - expect).norm() <= 1e-12 * length))
        problem(name + ": particle " + std::to_string(m.node_of(x)) + " on edge " + std::to_string(k) + " is off its dyadic place");
      const std::uint32_t le = detail::edge_level(m, x);
      spring_k[m.spring_of(x)] += el.edge_k[k] * le / el.level;
      acc += detail::whole / le;
    }
    if (acc != side) problem(name + ": edge " + std::to_string(k) + " does not sum Σ 1/l_e = 1/l_E");
  }
}

}  // namespace

int level_index(std::uint32_t level) { return 1 + std::countr_zero(level); }

std::string HierarchyReport::str() const {
  std::ostringstream out;
  for (const std::string& p : problems) out << p << '\n';
  return out.str();
}

template <int D>
HierarchyReport check_hierarchy(const MssModel<D>& m) {
  HierarchyReport r;
  auto problem = [&](const std::string& s) { r.problems.push_back(s); };
  const auto& elements = m.elements();
  const physics::NodeTable& nodes = m.nodes();
  std::vector<double> mass(nodes.size(), 0.0);
  std::map<Index, double> spring_k;  // edge spring -> Σ contributions of the sides holding it
  bool quads_only = true;             // else masses and stiffnesses have other sources too
  for (Index e = 0; e < elements.size(); ++e) {
    const Element& el = elements[e];
    const std::string name = "element " + std::to_string(e);
    if (el.level == 0 || !std::has_single_bit(el.level)) problem(name + ": level " + std::to_string(el.level) + " is not a power of two");
    if (el.parent != physics::invalid_index && elements[el.parent].level * 2 != el.level)
      problem(name + ": level " + std::to_string(el.level) + " is not twice its parent's");
    if (el.first_child != physics::invalid_index && el.alive) problem(name + ": refined but still alive");
    if (el.alive && el.kind != ElementKind::quad && el.kind != ElementKind::hexahedron) quads_only = false;
    if constexpr (D == 3)
      if (el.alive && el.kind == ElementKind::hexahedron) {
        check_hex(m, e, mass, spring_k, problem);
        continue;
      }
    if (!is_quad(el)) continue;
    if (!m.is_corner_dart(el.dart)) {
      problem(name + ": its canonical dart " + std::to_string(el.dart.index()) + " is not hierarchical");
      continue;
    }
    std::array<Dart, 4> c;
    try {
      c = detail::corner_darts(m, el);
    } catch (const std::logic_error& ex) {
      problem(name + ": " + ex.what());
      continue;
    }
    std::array<Index, 4> corner{};
    for (int k = 0; k < 4; ++k) corner[static_cast<std::size_t>(k)] = m.node_of(c[static_cast<std::size_t>(k)]);
    for (Index n : corner) mass[n] += m.materials()[el.material].density * el.measure / 4;
    for (int k = 0; k < 4; ++k) {
      const Dart first = c[static_cast<std::size_t>(k)], end = c[static_cast<std::size_t>((k + 1) % 4)];
      const Eigen::Vector3d ra = m.rest_position(m.node_of(first)), rb = m.rest_position(m.node_of(end));
      const double length = (rb - ra).norm();
      const std::uint64_t side = detail::whole / el.level;
      std::uint64_t acc = 0;
      for (Dart x = first; x != end; x = m.map().beta(x, 1)) {
        if (m.element_of(x) != e) problem(name + ": dart " + std::to_string(x.index()) + " of its ring belongs to another element");
        const std::uint32_t le = detail::edge_level(m, x);
        if (le < el.level || !std::has_single_bit(le))
          problem(name + ": edge of dart " + std::to_string(x.index()) + " has level " + std::to_string(le) +
                  " (the element's is " + std::to_string(el.level) + ")");
        if (x != first) {  // a T-junction: at its dyadic parameter between the side's corners, at rest
          const double t = static_cast<double>(acc) / static_cast<double>(side);
          const Eigen::Vector3d expect = (1 - t) * ra + t * rb;
          if (!((m.rest_position(m.node_of(x)) - expect).norm() <= 1e-12 * length))
            problem(name + ": T-junction particle " + std::to_string(m.node_of(x)) + " is off its side at rest (t = " +
                    std::to_string(t) + ")");
        }
        spring_k[m.spring_of(x)] += el.edge_k[static_cast<std::size_t>(m.side_of(x))] * le / el.level;
        acc += detail::whole / le;
      }
      if (acc != side)
        problem(name + ": side " + std::to_string(k) + " sums Σ 1/l_e = " + std::to_string(static_cast<double>(acc) / detail::whole) +
                ", not 1/l_E = " + std::to_string(1.0 / el.level));
    }
  }
  // every live diagonal spring belongs to a live element and joins two of its corners at rest distance
  std::vector<char> owned(m.springs().size(), 0);
  for (Index e = 0; e < elements.size(); ++e) {
    if (!elements[e].alive) continue;
    for (Index d : elements[e].diagonal)
      if (d != physics::invalid_index) {
        owned[d] = 1;
        const double rest = (m.rest_position(m.springs().node_j(d)) - m.rest_position(m.springs().node_i(d))).norm();
        if (!(rest > 0) || !near(m.springs().rest_length(d), rest, rest))
          problem("element " + std::to_string(e) + ": diagonal spring " + std::to_string(d) + " has rest length " +
                  std::to_string(m.springs().rest_length(d)) + " between particles " + std::to_string(rest) + " apart");
      }
  }
  for (Index s = 0; s < m.springs().size(); ++s)
    if (m.springs().is_alive(s) && m.springs().kind(s) == physics::SpringKind::diagonal && !owned[s])
      problem("diagonal spring " + std::to_string(s) + " belongs to no live element");
  if (!quads_only) return r;
  for (Index i = 0; i < nodes.size(); ++i)
    if (nodes.is_alive(i) && !near(nodes.mass(i), mass[i], mass[i]))
      problem("particle " + std::to_string(i) + ": mass " + std::to_string(nodes.mass(i)) + ", its elements give " +
              std::to_string(mass[i]));
  for (const auto& [s, k] : spring_k)
    if (!near(m.springs().stiffness(s), k, k))
      problem("spring " + std::to_string(s) + ": stiffness " + std::to_string(m.springs().stiffness(s)) +
              ", its elements' sides give " + std::to_string(k));
  return r;
}

template HierarchyReport check_hierarchy(const MssModel<2>&);
template HierarchyReport check_hierarchy(const MssModel<3>&);

}  // namespace sewn::refine
