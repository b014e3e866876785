#include "sewn/physics/shells/patch_terms.hpp"

#include <map>
#include <string>
#include <utility>

#include "sewn/physics/errors.hpp"
#include "sewn/physics/shells/adjacency.hpp"
#include "sewn/physics/shells/hinge_element.hpp"

namespace sewn::physics::shells {

template <int N>
std::string_view PatchBending<N>::name() const {
  static constexpr std::array<std::string_view, 3> names{"patch bending (1 neighbour)", "patch bending (2 neighbours)",
                                                         "patch bending (3 neighbours)"};
  return names[N - 4];
}

template <int N>
Index PatchBending<N>::add(const Nodes& nodes, const PatchPositions<N>& X, const std::array<std::uint8_t, N - 3>& edges,
                           const std::array<std::uint8_t, N - 3>& clamped, const PlateMaterial& m) {
  try {
    const PatchRest r = patch_rest<N>(X, edges, clamped, m);
    const Index e = this->push_element(nodes);
    rest_.push_back(r);
    return e;
  } catch (const InputError& err) {
    throw InputError(std::string(name()) + " element " + std::to_string(this->size()) + ": " + err.what());
  }
}

template <int N>
void PatchBending<N>::build_hinge_slots() const {
  shared_.assign(this->size(), HingeSlots{});
  hinge_nodes_.clear();
  // An edge's slot, by its two nodes, while only one patch uses it.
  std::map<std::pair<Index, Index>, Index> open;
  for (Index e = 0; e < this->size(); ++e) {
    if (!this->is_alive(e)) continue;
    const Nodes& n = this->element_nodes(e);
    const PatchRest& r = rest_[e];
    for (int k = 0; k < r.count; ++k) {
      const auto kk = static_cast<std::size_t>(k);
      const int i = r.edge[kk];
      const std::array<Index, 4> h{n[static_cast<std::size_t>(i)], n[static_cast<std::size_t>((i + 1) % 3)],
                                   n[static_cast<std::size_t>((i + 2) % 3)], n[static_cast<std::size_t>(3 + k)]};
      const auto key = std::minmax(h[1], h[2]);
      const auto it = open.find(key);
      // The neighbour's view of the edge is this hinge reversed (consistently oriented
      // triangles); anything else keeps a slot of its own.
      if (it != open.end() && hinge_nodes_[it->second] == std::array<Index, 4>{h[3], h[2], h[1], h[0]}) {
        shared_[e].of[kk] = it->second;
        shared_[e].reversed[kk] = true;
        open.erase(it);
        continue;
      }
      shared_[e].of[kk] = static_cast<Index>(hinge_nodes_.size());
      open[key] = static_cast<Index>(hinge_nodes_.size());
      hinge_nodes_.push_back(h);
    }
  }
  derivatives_.resize(hinge_nodes_.size());
  slots_topology_ = this->topology_version();
}

template <int N>
void PatchBending<N>::for_each_hessian(const StateView& s, const std::function<void(Index, const Hessian&)>& visit) const {
  if (slots_topology_ != this->topology_version()) build_hinge_slots();
  for (std::size_t h = 0; h < hinge_nodes_.size(); ++h) {
    HingePositions x;
    for (int c = 0; c < 4; ++c)
      for (int a = 0; a < 3; ++a) x(a, c) = s.x[3 * std::size_t{hinge_nodes_[h][static_cast<std::size_t>(c)]} + static_cast<std::size_t>(a)];
    dihedral_derivatives(x, derivatives_[h].g, derivatives_[h].H);
  }
  SharedHinges hinges;
  for (Index e = 0; e < this->size(); ++e) {
    if (!this->is_alive(e)) continue;
    for (int k = 0; k < rest_[e].count; ++k) {
      const auto kk = static_cast<std::size_t>(k);
      hinges.of[kk] = &derivatives_[shared_[e].of[kk]];
      hinges.reversed[kk] = shared_[e].reversed[kk];
    }
    visit(e, patch_hessian_shared<N>(this->gather(s, e), rest_[e], hinges));
  }
}

template class PatchBending<4>;
template class PatchBending<5>;
template class PatchBending<6>;

namespace {

// One triangle's patch: its corners, then the node across each interior edge.
struct Patch {
  Index tri = 0;
  int count = 0;
  std::array<Index, 6> nodes{};
  std::array<std::uint8_t, 3> edges{};
  std::array<std::uint8_t, 3> clamped{};
};

template <int N>
void add_to(PatchBending<N>& term, const Patch& p, std::span<const double> rest_x, const PlateMaterial& m) {
  typename PatchBending<N>::Nodes nodes;
  PatchPositions<N> X;
  std::array<std::uint8_t, N - 3> edges, clamped;
  for (int c = 0; c < N; ++c) {
    nodes[static_cast<std::size_t>(c)] = p.nodes[static_cast<std::size_t>(c)];
    for (int a = 0; a < 3; ++a) X(a, c) = rest_x[3 * std::size_t{nodes[static_cast<std::size_t>(c)]} + a];
  }
  for (int k = 0; k < N - 3; ++k) {
    edges[static_cast<std::size_t>(k)] = p.edges[static_cast<std::size_t>(k)];
    clamped[static_cast<std::size_t>(k)] = p.clamped[static_cast<std::size_t>(k)];
  }
  try {
    term.add(nodes, X, edges, clamped, m);
  } catch (const InputError& e) {
    throw InputError("patch bending: triangle " + std::to_string(p.tri) + ": " + e.what());
  }
}

}  // namespace

PatchTerms add_patch_bending(System& sys, std::span<const std::array<Index, 3>> triangles, std::span<const double> rest_x,
                             std::span<const PlateMaterial> material_of_triangle,
                             std::span<const std::uint8_t> clamp_of_triangle) {
  if (material_of_triangle.size() != triangles.size() || (!clamp_of_triangle.empty() && clamp_of_triangle.size() != triangles.size()))
    throw InputError("patch bending: " + std::to_string(material_of_triangle.size()) + " materials and " +
                     std::to_string(clamp_of_triangle.size()) + " clamp flags for " + std::to_string(triangles.size()) +
                     " triangles");
  auto is_clamp = [&](Index t) { return !clamp_of_triangle.empty() && clamp_of_triangle[t] != 0; };
  const auto across = triangles_across(triangles, rest_x.size() / 3);
  std::array<std::vector<Patch>, 3> by_count;
  for (Index t = 0; t < triangles.size(); ++t) {
    if (is_clamp(t)) continue;
    Patch p;
    p.tri = t;
    for (int c = 0; c < 3; ++c) p.nodes[static_cast<std::size_t>(c)] = triangles[t][static_cast<std::size_t>(c)];
    for (int i = 0; i < 3; ++i) {
      const Across& o = across[t][static_cast<std::size_t>(i)];
      if (o.tri == invalid_index) continue;
      p.nodes[static_cast<std::size_t>(3 + p.count)] = triangles[o.tri][static_cast<std::size_t>(o.corner)];
      p.clamped[static_cast<std::size_t>(p.count)] = is_clamp(o.tri) ? 1 : 0;
      p.edges[static_cast<std::size_t>(p.count++)] = static_cast<std::uint8_t>(i);
    }
    if (p.count > 0) by_count[static_cast<std::size_t>(p.count - 1)].push_back(p);
  }
  // every patch is built aside first, so that a refused one leaves `sys` as it was
  PatchBending<4> one;
  PatchBending<5> two;
  PatchBending<6> three;
  PatchTerms out;
  for (const Patch& p : by_count[0]) add_to(one, p, rest_x, material_of_triangle[p.tri]);
  for (const Patch& p : by_count[1]) add_to(two, p, rest_x, material_of_triangle[p.tri]);
  for (const Patch& p : by_count[2]) add_to(three, p, rest_x, material_of_triangle[p.tri]);
  for (int k = 0; k < 3; ++k)
    for (const Patch& p : by_count[static_cast<std::size_t>(k)]) out.triangle_of[static_cast<std::size_t>(k)].push_back(p.tri);
  if (one.size() > 0) out.one = &sys.add<PatchBending<4>>(std::move(one));
  if (two.size() > 0) out.two = &sys.add<PatchBending<5>>(std::move(two));
  if (three.size() > 0) out.three = &sys.add<PatchBending<6>>(std::move(three));
  return out;
}

}  // namespace sewn::physics::shells
