#include "sewn/refine/criterion.hpp"

#include <algorithm>
#include <cmath>
#include <span>
#include <string>

#include "hierarchy/neighbours.hpp"
#include "sewn/physics/errors.hpp"
#include "sewn/refine/hierarchy.hpp"

namespace sewn::refine {

template <int D>
DiagonalStrain<D>::DiagonalStrain(double threshold_percent) : threshold_(threshold_percent) {
  if (!(threshold_percent > 0 && threshold_percent < 100))
    throw physics::InputError("refinement criterion: the diagonal strain threshold must be in (0, 100) percent (got " +
                              std::to_string(threshold_percent) + ")");
}

template <int D>
double DiagonalStrain<D>::strain_percent(const MssModel<D>& m, Index e) {
  const physics::Element& el = m.elements()[e];
  const physics::Springs& s = m.springs();
  double worst = 0;
  for (Index d : el.diagonal) {
    if (d == physics::invalid_index) continue;
    const double l = (m.nodes().position(s.node_j(d)) - m.nodes().position(s.node_i(d))).norm();
    worst = std::max(worst, 100 * std::abs(l - s.rest_length(d)) / s.rest_length(d));
  }
  return worst;
}

namespace {

// True if a diagonal of element e has |l − l₀| > f·l₀ (strictly, or ≥ with `or_equal`), on
// squared lengths: the criterion pass runs on every element after every step, and this spares
// its square roots and divisions (f < 1, so l > (1+f)l₀ or l < (1−f)l₀, both sides ≥ 0).
template <int D>
bool diagonal_strained(const MssModel<D>& m, Index e, double f, bool or_equal) {
  const physics::Springs& s = m.springs();
  const std::span<const double> x = m.nodes().x();
  for (Index d : m.elements()[e].diagonal) {
    if (d == physics::invalid_index) continue;
    const Index i = 3 * s.node_i(d), j = 3 * s.node_j(d);
    const double dx = x[j] - x[i], dy = x[j + 1] - x[i + 1], dz = x[j + 2] - x[i + 2];
    const double l2 = dx * dx + dy * dy + dz * dz, l0 = s.rest_length(d);
    const double hi = (1 + f) * l0 * (1 + f) * l0, lo = (1 - f) * l0 * (1 - f) * l0;
    if (or_equal ? (l2 >= hi || l2 <= lo) : (l2 > hi || l2 < lo)) return true;
  }
  return false;
}

}  // namespace

template <int D>
bool DiagonalStrain<D>::wants_refinement(const MssModel<D>& m, Index e) const {
  return diagonal_strained(m, e, threshold_ / 100, false);
}

template <int D>
bool DiagonalStrain<D>::allows_coarsening(const MssModel<D>& m, Index e) const {
  return !diagonal_strained(m, e, threshold_ / 200, true);
}

template <int D>
RefineReport adapt(MssModel<D>& m, const Criterion<D>& criterion, const RefineOptions& options, std::vector<Index>* chosen_out) {
  std::vector<Index> chosen;
  std::uint64_t after = m.num_live_elements();
  for (Index e = 0; e < m.elements().size(); ++e) {
    const physics::Element& el = m.elements()[e];
    if (el.alive && detail::refinable_kind<D>(el.kind) && level_index(el.level) < options.max_level && criterion.wants_refinement(m, e)) {
      chosen.push_back(e);
      after += el.kind == physics::ElementKind::hexahedron ? 7 : 3;  // children replace the parent
    }
  }
  if (after > options.max_elements)
    throw physics::InputError("adaptive refinement: refining the " + std::to_string(chosen.size()) + " elements the criterion picks would leave " +
                              std::to_string(after) + " live elements, more than the limit of " + std::to_string(options.max_elements));
  const RefineReport report = refine_elements(m, std::span<const Index>(chosen), options);
  if (chosen_out) *chosen_out = std::move(chosen);
  return report;
}

template <int D>
typename Adapter<D>::Report Adapter<D>::update(MssModel<D>& m) {
  Report r;
  r.refined = adapt(m, criterion_, options_.refine, &r.refined_elements);
  if (!options_.coarsen) return r;
  calm_.resize(m.elements().size(), 0);
  for (Index e = 0; e < m.elements().size(); ++e) {
    const physics::Element& el = m.elements()[e];
    calm_[e] = el.alive && criterion_.allows_coarsening(m, e) ? calm_[e] + 1 : 0;
  }
  for (Index p = 0; p < m.elements().size(); ++p) {
    if (!can_coarsen(m, p) || (options_.refine.balance && !coarsening_keeps_balance(m, p))) continue;
    const Index first = m.elements()[p].first_child;
    bool calm = true;
    const Index n = m.elements()[p].kind == physics::ElementKind::hexahedron ? 8 : 4;
    for (Index c = first; c < first + n; ++c) calm = calm && calm_[c] >= options_.calm_steps;
    if (!calm) continue;
    r.dissipated_energy += coarsen(m, p).dissipated_energy;
    ++r.coarsened;
    r.coarsened_parents.push_back(p);
    calm_[p] = 0;
  }
  return r;
}

template class Adapter<2>;
template class Adapter<3>;
template class DiagonalStrain<2>;
template class DiagonalStrain<3>;
template RefineReport adapt(MssModel<2>&, const Criterion<2>&, const RefineOptions&, std::vector<Index>*);
template RefineReport adapt(MssModel<3>&, const Criterion<3>&, const RefineOptions&, std::vector<Index>*);

}  // namespace sewn::refine
