// Uniform 1:8 refinement of a conforming hexahedral model in one pass (refine_all's fast path):
// the map by its batch pass CMap::subdivide_hexahedra, the physics rebuilt once from the new map
// in bulk arrays instead of element by element through the insertions and the model's resync.
//
// The result is the model refine_element() on every element makes (tests/refine/test_refine_all.cpp
// compares the two): the same particles (rest, position, velocity, fixed axes, mass), springs
// (ends, stiffness, rest length, viscosity, level), elements (level, parent, children in the
// parent's corner order, measure, stiffness) and per-dart codes, up to the order in which
// particles and springs are numbered and the rounding of the sums. New particles are numbered in
// the order the pass makes them (edge midpoints, face centres, cell centres); a parent edge's
// spring stays with the half at the dart its attribute records, the other half and the inner
// edges get new springs in the order the pass visits them.
#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "hierarchy/hex_child.hpp"
#include "hierarchy/hex_codes.hpp"
#include "hierarchy/model_access.hpp"
#include "hierarchy/refiner_base.hpp"
#include "sewn/physics/errors.hpp"
#include "sewn/refine/subdivide.hpp"

namespace sewn::refine::detail {

namespace {

using physics::Element;
using physics::ElementKind;
using physics::ElementRef;
using physics::NodeRef;
using physics::SpringRef;
using A = ModelAccess<3>;

// The particle between two particles: the mean of their rest positions, positions and
// velocities; an axis held at both is held there too (as RefinerBase::mean). A face centre is
// made from two opposite edge midpoints and a cell centre from two opposite face centres, so
// each is the mean of its 4 or 8 corners: the multilinear interpolation the refiner uses.
NodeRef middle(physics::MssModel<3>& m, NodeRef a, NodeRef b) {
  const auto& nodes = m.nodes();
  const Eigen::Vector3d v = (nodes.velocity(a.node) + nodes.velocity(b.node)) / 2;
  const Index n = A::add_node(m, (m.rest_position(a.node) + m.rest_position(b.node)) / 2,
                              (nodes.position(a.node) + nodes.position(b.node)) / 2, v);
  if (const physics::AxisMask fixed = nodes.fixed(a.node) & nodes.fixed(b.node); fixed != physics::no_axes) {
    m.nodes().fix(n, fixed);
    m.nodes().set_velocity(n, v);  // fix() zeroes held axes; a kinematic side keeps its motion
  }
  return NodeRef{n};
}

class BatchRefiner {
 public:
  BatchRefiner(physics::MssModel<3>& m, RefineReport& report) : m_(m), report_(report) {}

  void run() {
    const Index nodes0 = m_.nodes().size();
    const std::uint32_t level = A::elements(m_)[first_live()].level;
    auto& map = A::map(m_);
    {
      HooksPaused<A::Map> quiet(map);  // the model is rebuilt below, not cell by cell
      map.subdivide_hexahedra([&](NodeRef a, NodeRef b) { return middle(m_, a, b); },
                              [&](auto dim, const FineCell& c) { return fine(dim, c, level); });
    }
    report_.particles = m_.nodes().size() - nodes0;
    for (AttrId<0> a : map.template attributes<0>())
      if (map.value(a).node >= nodes0) A::link_vertex(m_, map.value(a).node, map.dart_of(a));
    springs_and_masses();
    if (m_.options().damping == physics::DampingModel::viscous) m_.springs().set_paper_viscosity(m_.nodes().masses());
  }

 private:
  Index first_live() const {
    const auto& el = m_.elements();
    for (Index e = 0; e < el.size(); ++e)
      if (el[e].alive) return e;
    return 0;
  }

  // Edges: a parent edge's halves (its spring kept by one) and the new inner edges, all one
  // level finer. Volumes: the 8 children of the parent's element.
  template <class Dim>
  auto fine(Dim, const FineCell& c, std::uint32_t level) {
    if constexpr (Dim::value == 1) {
      if (c.parent == Dart::null_index) return std::optional<SpringRef>(SpringRef{edge_spring(c, physics::invalid_index), physics::invalid_index, 2 * level});
      const SpringRef p = A::map(m_).template attribute_container<1>().value(c.parent);
      return std::optional<SpringRef>(SpringRef{edge_spring(c, c.piece == 0 ? p.spring : physics::invalid_index), p.segment, 2 * p.level});
    } else if constexpr (Dim::value == 3) {
      return std::optional<ElementRef>(ElementRef{child(c)});
    } else {
      return std::optional<ElementRef>();  // faces: a hexahedral model's carry none
    }
  }

  // The spring of fine edge c, between the particles at its ends (the vertices are in place when
  // the pass makes edges) at their rest distance: `kept` (the parent edge's, on the half holding
  // its recorded dart), else a new one. Its stiffness is summed from the children (code_child).
  Index edge_spring(const FineCell& c, Index kept) {
    const Dart d(c.darts.front());  // the dart the attribute will record
    const Index i = m_.node_of(d), j = m_.node_of(A::map(m_).beta(d, 1));
    const double rest = (m_.rest_position(j) - m_.rest_position(i)).norm();
    physics::Springs& springs = m_.springs();
    Index s = kept;
    if (s == physics::invalid_index) {
      s = springs.add(i, j, 0.0, rest, physics::SpringKind::edge);
    } else {
      springs.set_endpoints(s, i, j);
      springs.set_rest_length(s, rest);
    }
    edge_springs_.push_back(s);
    return s;
  }

  // Child v of the reference cube is the child at the parent's corner local(v) (the model's
  // numbering: child k holds the parent's corner k as its local corner k); its corner u, the
  // fine point v + u, is its local corner local(u), by the affine map between the cube and the
  // parent's corners.
  Index child(const FineCell& c) {
    auto& elements = A::elements(m_);
    const Index e = A::map(m_).template attribute_container<3>().value(c.parent).element;
    std::array<int, 8> local{};
    for (std::size_t u = 0; u < 8; ++u) local[u] = A::dart_vertex(m_, Dart(c.parent_darts[3 * u]));
    if (c.piece == 0) {
      first_ = static_cast<Index>(elements.size());
      elements.resize(elements.size() + 8);
    }
    std::array<Index, 8> corner{};
    std::size_t u0 = 0;
    for (std::size_t u = 0; u < 8; ++u) {
      corner[static_cast<std::size_t>(local[u])] = m_.node_of(Dart(c.darts[3 * u]));
      if (local[u] == 0) u0 = u;
    }
    std::size_t along = 0;  // the axis from local corner 0 to local corner 1
    for (std::size_t i = 0; i < 3; ++i)
      if (local[u0 ^ (std::size_t{1} << i)] == 1) along = i;
    const Index k = first_ + static_cast<Index>(local[static_cast<std::size_t>(c.piece)]);
    const Element parent = elements[e];  // a copy: make_hex_child adds springs, not elements
    elements[k] = make_hex_child(m_, parent, e, Dart(c.darts[3 * u0 + along]), corner);
    code_child(c, elements[k]);
    corners_.push_back(corner);
    children_.push_back(k);
    if (c.piece == 7) retire(e);
    return k;
  }

  // The child's darts take the codes of the parent's darts of the same label: the affine map
  // between the reference cube and the parent's corners sends child corner u to local corner
  // local(u), as it sends the parent's, so a child dart starts at the same local vertex and lies
  // on the same local edge (flag included) as the parent dart it is parallel to. This is what
  // MssModel::index_darts would find by walking the child from its canonical dart. The dart
  // flagged for each of the child's 12 edges adds the child's stiffness to that edge's spring
  // (the child is one level finer than its sides' edges were and its sides are single edges:
  // the series factor l_e / l_E is 1).
  void code_child(const FineCell& c, const Element& el) {
    if (edge_k_.empty()) {  // the first child: every dart and edge spring is made by now
      A::grow_darts(m_);
      edge_k_.assign(m_.springs().size(), 0.0);
    }
    for (std::size_t l = 0; l < 24; ++l) {
      const Dart from(c.parent_darts[l]), to(c.darts[l]);
      A::copy_code(m_, from, to, A::dart_vertex(m_, from));
      if (const std::uint8_t code = A::dart_code(m_, from); code & 0x80) edge_k_[m_.spring_of(to)] += el.edge_k[code & 0x7f];
    }
  }

  void retire(Index e) {
    retire_parent(m_, e, first_, 8);  // the children made their own diagonals
    for (Index k = 0; k < 8; ++k) report_.children.push_back(first_ + k);
    ++report_.elements;
  }

  // Every edge spring's stiffness, summed by code_child. Every particle's mass: ρV/8 from each
  // child it is a corner of.
  void springs_and_masses() {
    for (Index s : edge_springs_) m_.springs().set_stiffness(s, edge_k_[s]);
    std::vector<double> mass(m_.nodes().size(), 0.0);
    for (std::size_t c = 0; c < children_.size(); ++c) {
      const Element& el = m_.elements()[children_[c]];
      const double share = m_.materials()[el.material].density * el.measure / 8;
      for (Index n : corners_[c]) mass[n] += share;
    }
    for (Index n = 0; n < mass.size(); ++n) {
      if (!m_.nodes().is_alive(n)) continue;
      if (!(mass[n] > 0))
        throw physics::InputError(m_.options().source + ": particle " + std::to_string(n) + " is left with no element after the refinement");
      m_.nodes().set_mass(n, mass[n]);
    }
  }

  physics::MssModel<3>& m_;
  RefineReport& report_;
  Index first_ = 0;
  std::vector<std::array<Index, 8>> corners_;
  std::vector<Index> children_;
  std::vector<Index> edge_springs_;
  std::vector<double> edge_k_;  // per spring: the children's edge stiffnesses summed
};

}  // namespace

bool batch_refinable(const physics::MssModel<3>& m) {
  if (!m.system().slaves().empty() || m.map().template num_attributes<2>() != 0) return false;
  std::uint32_t level = 0;
  for (const Element& el : m.elements()) {
    if (!el.alive) continue;
    if (el.kind != ElementKind::hexahedron || (level != 0 && el.level != level)) return false;
    level = el.level;
  }
  if (level == 0 || m.map().num_darts() != std::uint64_t{24} * m.num_live_elements()) return false;
  for (AttrId<1> a : m.map().template attributes<1>()) {
    const SpringRef& r = m.map().value(a);
    if (r.level != level || r.segment != physics::invalid_index || !m.springs().is_alive(r.spring)) return false;
  }
  return true;
}

void refine_all_hexahedra(physics::MssModel<3>& m, RefineReport& report) { BatchRefiner(m, report).run(); }

}  // namespace sewn::refine::detail
