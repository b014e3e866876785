// Entry points of regular refinement: checks first (a refused request leaves the model as it
// was), then the quad or hexahedron refiner inside MssModel::edit().
#include "sewn/refine/subdivide.hpp"

#include <algorithm>
#include <string>
#include <vector>

#include "hierarchy/neighbours.hpp"
#include "hierarchy/refiner_base.hpp"
#include "sewn/physics/errors.hpp"
#include "sewn/refine/hierarchy.hpp"

namespace sewn::refine {

namespace {

using physics::Element;
using physics::ElementKind;
using physics::InputError;

template <int D>
void check_refinable(const MssModel<D>& m, Index e, const RefineOptions& o) {
  const std::string name = "refine: element " + std::to_string(e);
  if (o.max_level < 1 || o.max_level > 20)
    throw InputError("refine: max_level " + std::to_string(o.max_level) + " is out of range (1 to 20, as an index)");
  if (e >= m.elements().size())
    throw InputError(name + " does not exist (the model has " + std::to_string(m.elements().size()) + ")");
  const Element& el = m.elements()[e];
  if (el.first_child != physics::invalid_index) throw InputError(name + " is already refined");
  if (!el.alive) throw InputError(name + " was removed (a dead element cannot be refined)");
  if (!detail::refinable_kind<D>(el.kind)) {
    const char* kinds[] = {"hexahedron", "tetrahedron", "quad", "triangle", "segment"};
    throw InputError(name + " is a " + kinds[static_cast<int>(el.kind)] + ": only " +
                     (D == 2 ? "quads (1:4)" : "hexahedra (1:8) and membrane quads (1:4)") + " are refined regularly");
  }
  if (level_index(el.level) + 1 > o.max_level)
    throw InputError(name + " is at level " + std::to_string(level_index(el.level)) +
                     ": its children would pass the maximum level " + std::to_string(o.max_level));
}

// Inside refine_elements' one edit(): the map and the new particles and springs only; their
// masses, stiffnesses and rest lengths wait for the pass's single resync.
template <int D>
void refine_one(MssModel<D>& m, Index e, RefineReport& report) {
  if constexpr (D == 3)
    if (m.elements()[e].kind == ElementKind::hexahedron) return detail::refine_hex(m, e, report);
  detail::refine_quad(m, e, report);
}

// f inside one MssModel::edit() with the model's refining flag set: the model's resync (masses,
// springs, diagonals of every touched cell) runs once for the whole pass, not once per element,
// so a particle shared by the k elements refined around it is weighed once instead of k times.
// Nothing a refinement reads in between (rest positions, states, corner codes, edge levels)
// waits for the resync. An exception still resyncs what was done before it (edit()).
template <int D, class F>
void in_one_edit(MssModel<D>& m, F&& f) {
  detail::ModelAccess<D>::set_refining(m, true);
  try {
    m.edit([&](auto&) { f(); });
  } catch (...) {
    detail::ModelAccess<D>::set_refining(m, false);
    throw;
  }
  detail::ModelAccess<D>::set_refining(m, false);
}

// 2:1 balance: e's children will be at twice its level, so every neighbour coarser than e would
// end more than one level coarser than them; each is refined first (its own coarser neighbours
// before it), until none is left. The recursion is as deep as the levels below e's.
template <int D>
void refine_balanced(MssModel<D>& m, Index e, const RefineOptions& o, RefineReport& report) {
  for (;;) {
    std::vector<Index> coarser;
    for (Index n : detail::edge_neighbours(m, e))
      if (m.elements()[n].level < m.elements()[e].level) coarser.push_back(n);
    if (coarser.empty()) break;
    for (Index n : coarser)
      if (m.elements()[n].alive) {
        check_refinable(m, n, o);
        refine_balanced(m, n, o, report);
      }
  }
  refine_one(m, e, report);
}

}  // namespace

template <int D>
bool is_balanced(const MssModel<D>& m, std::string* why) {
  for (Index e = 0; e < m.elements().size(); ++e) {
    if (!m.elements()[e].alive) continue;
    for (Index n : detail::edge_neighbours(m, e))
      if (m.elements()[n].level > 2 * m.elements()[e].level) {
        if (why)
          *why = "elements " + std::to_string(e) + " (level " + std::to_string(level_index(m.elements()[e].level)) + ") and " +
                 std::to_string(n) + " (level " + std::to_string(level_index(m.elements()[n].level)) +
                 ") share an edge across more than one level";
        return false;
      }
  }
  return true;
}

template <int D>
bool coarsening_keeps_balance(const MssModel<D>& m, Index parent) {
  const physics::Element& p = m.elements()[parent];
  if (p.first_child == physics::invalid_index) return true;
  const Index n = p.kind == physics::ElementKind::hexahedron ? 8 : 4;
  for (Index c = p.first_child; c < p.first_child + n; ++c) {
    if (!m.elements()[c].alive) continue;
    for (Index o : detail::edge_neighbours(m, c))
      if (m.elements()[o].parent != parent && m.elements()[o].level > 2 * p.level) return false;
  }
  return true;
}

template <int D>
RefineReport refine_element(MssModel<D>& m, Index e, const RefineOptions& options) {
  return refine_elements(m, std::span<const Index>(&e, 1), options);
}

template <int D>
RefineReport refine_elements(MssModel<D>& m, std::span<const Index> elements, const RefineOptions& options) {
  RefineReport report;
  if (elements.empty()) return report;
  in_one_edit(m, [&] {
    for (Index e : elements) {
      // with balance, an element of the list may have been refined already, for an earlier one
      if (options.balance && e < m.elements().size() && m.elements()[e].first_child != physics::invalid_index &&
          std::any_of(report.children.begin(), report.children.end(), [&](Index c) { return m.elements()[c].parent == e; }))
        continue;
      check_refinable(m, e, options);
      if (options.balance)
        refine_balanced(m, e, options, report);
      else
        refine_one(m, e, report);
    }
  });
  update_t_junctions(m, std::span<const Index>(report.children));
  return report;
}

template <int D>
RefineReport refine_all(MssModel<D>& m, const RefineOptions& options) {
  std::vector<Index> live;
  for (Index e = 0; e < m.elements().size(); ++e)
    if (m.elements()[e].alive) live.push_back(e);
  if constexpr (D == 3)
    if (!live.empty() && refines_in_one_pass(m)) {
      // a conforming hexahedral model: the map's batch pass and one rebuild of the physics (no
      // T-junction before or after, so the constraints stay empty)
      for (Index e : live) check_refinable(m, e, options);
      RefineReport report;
      in_one_edit(m, [&] { detail::refine_all_hexahedra(m, report); });
      return report;
    }
  return refine_elements(m, std::span<const Index>(live), options);
}

template <int D>
bool refines_in_one_pass(const MssModel<D>& m) {
  if constexpr (D == 3)
    return detail::batch_refinable(m);
  else
    return false;
}

template bool refines_in_one_pass(const MssModel<2>&);
template bool refines_in_one_pass(const MssModel<3>&);
template RefineReport refine_element(MssModel<2>&, Index, const RefineOptions&);
template RefineReport refine_element(MssModel<3>&, Index, const RefineOptions&);
template RefineReport refine_elements(MssModel<2>&, std::span<const Index>, const RefineOptions&);
template RefineReport refine_elements(MssModel<3>&, std::span<const Index>, const RefineOptions&);
template RefineReport refine_all(MssModel<2>&, const RefineOptions&);
template bool is_balanced(const MssModel<2>&, std::string*);
template bool coarsening_keeps_balance(const MssModel<2>&, Index);
template bool coarsening_keeps_balance(const MssModel<3>&, Index);
template bool is_balanced(const MssModel<3>&, std::string*);
template RefineReport refine_all(MssModel<3>&, const RefineOptions&);

}  // namespace sewn::refine
