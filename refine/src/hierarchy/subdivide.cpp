// Entry points of regular refinement: checks first (a refused request leaves the model as it
// was), then the quad or hexahedron refiner inside MssModel::edit().
#include "sewn/refine/subdivide.hpp"

#include <string>

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
  const ElementKind regular = D == 2 ? ElementKind::quad : ElementKind::hexahedron;
  if (el.kind != regular) {
    const char* kinds[] = {"hexahedron", "tetrahedron", "quad", "triangle", "segment"};
    throw InputError(name + " is a " + kinds[static_cast<int>(el.kind)] + ": only " +
                     (D == 2 ? "quads of a 2-map (1:4)" : "hexahedra of a 3-map (1:8)") + " are refined regularly");
  }
  if (level_index(el.level) + 1 > o.max_level)
    throw InputError(name + " is at level " + std::to_string(level_index(el.level)) +
                     ": its children would pass the maximum level " + std::to_string(o.max_level));
}

}  // namespace

template <int D>
RefineReport refine_element(MssModel<D>& m, Index e, const RefineOptions& options) {
  return refine_elements(m, std::span<const Index>(&e, 1), options);
}

template <int D>
RefineReport refine_elements(MssModel<D>& m, std::span<const Index> elements, const RefineOptions& options) {
  RefineReport report;
  for (Index e : elements) {
    check_refinable(m, e, options);
    detail::ModelAccess<D>::set_refining(m, true);
    try {
      m.edit([&](auto&) {
        if constexpr (D == 2) detail::refine_quad(m, e, report);
        else detail::refine_hex(m, e, report);
      });
    } catch (...) {
      detail::ModelAccess<D>::set_refining(m, false);
      throw;
    }
    detail::ModelAccess<D>::set_refining(m, false);
  }
  if (!elements.empty()) constrain_t_junctions(m, m.system().slaves().treatment());
  return report;
}

template <int D>
RefineReport refine_all(MssModel<D>& m, const RefineOptions& options) {
  std::vector<Index> live;
  for (Index e = 0; e < m.elements().size(); ++e)
    if (m.elements()[e].alive) live.push_back(e);
  return refine_elements(m, std::span<const Index>(live), options);
}

template RefineReport refine_element(MssModel<2>&, Index, const RefineOptions&);
template RefineReport refine_element(MssModel<3>&, Index, const RefineOptions&);
template RefineReport refine_elements(MssModel<2>&, std::span<const Index>, const RefineOptions&);
template RefineReport refine_elements(MssModel<3>&, std::span<const Index>, const RefineOptions&);
template RefineReport refine_all(MssModel<2>&, const RefineOptions&);
template RefineReport refine_all(MssModel<3>&, const RefineOptions&);

}  // namespace sewn::refine
