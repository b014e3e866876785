#include "sewn/refine/hierarchy.hpp"

#include <algorithm>
#include <bit>
#include <cmath>
#include <map>
#include <sstream>

#include "hierarchy/sides.hpp"

namespace sewn::refine {

namespace {

using physics::Element;
using physics::ElementKind;

bool is_quad(const Element& el) { return el.alive && el.kind == ElementKind::quad; }

bool near(double a, double b, double scale) { return std::abs(a - b) <= 1e-12 * scale; }

}  // namespace

int level_index(std::uint32_t level) { return 1 + std::countr_zero(level); }

std::string HierarchyReport::str() const {
  std::ostringstream out;
  for (const std::string& p : problems) out << p << '\n';
  return out.str();
}

template <int D>
std::vector<TJunction> t_junctions(const MssModel<D>& m) {
  std::vector<TJunction> out;
  std::vector<std::uint32_t> level_of;  // per entry of out, for the coarse-to-fine order
  for (Index e = 0; e < m.elements().size(); ++e) {
    const Element& el = m.elements()[e];
    if (!is_quad(el)) continue;
    const auto c = detail::corner_darts(m, el);
    for (int k = 0; k < 4; ++k) {
      const Dart end = c[static_cast<std::size_t>((k + 1) % 4)];
      const std::uint64_t side = detail::whole / el.level;
      std::uint64_t acc = 0;
      for (Dart x = c[static_cast<std::size_t>(k)]; x != end; x = m.map().beta(x, 1)) {
        if (x != c[static_cast<std::size_t>(k)])
          out.push_back({m.node_of(x), e, {m.node_of(c[static_cast<std::size_t>(k)]), m.node_of(end)},
                         static_cast<double>(acc) / static_cast<double>(side)});
        acc += detail::whole / detail::edge_level(m, x);
      }
    }
  }
  std::stable_sort(out.begin(), out.end(), [&](const TJunction& a, const TJunction& b) {
    return m.elements()[a.element].level < m.elements()[b.element].level;
  });
  return out;
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
    if (el.alive && el.kind != ElementKind::quad) quads_only = false;
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

template std::vector<TJunction> t_junctions(const MssModel<2>&);
template std::vector<TJunction> t_junctions(const MssModel<3>&);
template HierarchyReport check_hierarchy(const MssModel<2>&);
template HierarchyReport check_hierarchy(const MssModel<3>&);

}  // namespace sewn::refine
