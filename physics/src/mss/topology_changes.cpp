#include "element_tables.hpp"

#include <algorithm>

namespace sewn::physics {

// ------------------------------------------------------------------------------- topology changes

template <int D>
void MssModel<D>::install_hooks() {
  map_.template on_split<0>([this](AttrId<0> a, AttrId<0> b) {
    // a duplicated vertex: a new particle with the original's state (masses follow in resync)
    const Index n = map_.value(a).node;
    const Index copy = system_.nodes().duplicate(n);
    rest_.push_back(rest_[n]);
    point_of_node_.push_back(point_of_node_[n]);
    first_vertex_.push_back(Dart::null_index);
    map_.value(b).node = copy;
    link_vertex(copy, b.index());
    dirty_vertices_.insert(dirty_vertices_.end(), {a.index(), b.index()});
  });
  map_.template on_merge<0>([this](AttrId<0> kept, AttrId<0> gone) {
    // two vertices sewn into one: the gone particle's momentum joins the kept one
    const Index nk = map_.value(kept).node, ng = map_.value(gone).node;
    if (unlink_vertex(ng, gone.index()) && nk != ng) {
      NodeTable& nodes = system_.nodes();
      const double mk = nodes.mass(nk), mg = nodes.mass(ng);
      nodes.set_velocity(nk, (mk * nodes.velocity(nk) + mg * nodes.velocity(ng)) / (mk + mg));
      nodes.remove(ng);
    }
    dirty_vertices_.push_back(kept.index());
  });
  map_.template on_erase<0>([this](AttrId<0> gone) {
    const Index n = map_.value(gone).node;
    if (unlink_vertex(n, gone.index())) system_.nodes().remove(n);
  });
  // Springs the caller removed (a continuum model standing in for them) stay removed: their
  // edges' copies get none, and resync leaves them alone.
  map_.template on_split<1>([this](AttrId<1> a, AttrId<1> b) {
    // a duplicated edge: a new spring (ends, stiffness and rest length follow in resync)
    const Index s = map_.value(a).spring;
    if (!springs_->is_alive(s)) {
      map_.value(b).spring = invalid_index;
      return;
    }
    map_.value(b).spring = springs_->add(springs_->node_i(s), springs_->node_j(s), springs_->stiffness(s),
                                         springs_->rest_length(s), springs_->kind(s), springs_->viscosity(s));
    dirty_edges_.insert(dirty_edges_.end(), {a.index(), b.index()});
  });
  map_.template on_merge<1>([this](AttrId<1> kept, AttrId<1> gone) {
    if (springs_->is_alive(map_.value(gone).spring)) springs_->remove(map_.value(gone).spring);
    dirty_edges_.push_back(kept.index());
  });
  map_.template on_erase<1>([this](AttrId<1> gone) {
    if (springs_->is_alive(map_.value(gone).spring)) springs_->remove(map_.value(gone).spring);
  });
  auto element_erased = [this](Index e) {
    Element& el = elements_[e];
    el.alive = false;
    --live_elements_;
    for (Index& s : el.diagonal)
      if (s != invalid_index) {
        springs_->remove(s);
        s = invalid_index;
      }
  };
  auto unsupported = [this](const char* what) {
    if (unsupported_.empty())
      unsupported_ = std::string("the mass-spring model cannot follow this edit: ") + what +
                     " (cutting and piercing unsew faces between elements; splitting or merging elements is refinement)";
  };
  map_.template on_split<2>([this, unsupported](AttrId<2>, AttrId<2>) {
    if (!refining_) unsupported("an element was split in two");
  });
  map_.template on_merge<2>([this, unsupported](AttrId<2>, AttrId<2>) {
    if (!refining_) unsupported("two elements were merged");
  });
  map_.template on_erase<2>([this, element_erased](AttrId<2> gone) { element_erased(map_.value(gone).element); });
  if constexpr (D == 3) {
    map_.template on_split<3>([this, unsupported](AttrId<3>, AttrId<3>) {
      if (!refining_) unsupported("an element was split in two");
    });
    map_.template on_merge<3>([this, unsupported](AttrId<3>, AttrId<3>) {
      if (!refining_) unsupported("two elements were merged");
    });
    map_.template on_erase<3>([this, element_erased](AttrId<3> gone) { element_erased(map_.value(gone).element); });
  }
}

template <int D>
void MssModel<D>::resync() {
  if (!unsupported_.empty()) {
    std::string what;
    std::swap(what, unsupported_);
    dirty_vertices_.clear();
    dirty_edges_.clear();
    throw InputError(what);
  }
  if (dirty_vertices_.empty() && dirty_edges_.empty()) return;
  if (++generation_ == 0) {  // wrapped: old stamps could collide
    for (auto* v : {&seen_edge_, &seen_element_, &seen_node_, &seen_spring_}) std::fill(v->begin(), v->end(), 0u);
    generation_ = 1;
  }
  const auto& vattr = map_.template attribute_container<0>();
  const auto& eattr = map_.template attribute_container<1>();
  std::vector<std::uint32_t> vertices = std::move(dirty_vertices_), edges = std::move(dirty_edges_);
  dirty_vertices_.clear();
  dirty_edges_.clear();
  NodeTable& nodes = system_.nodes();
  // 1) A particle's mass changes only with the vertex cells carrying it, so only the particles
  //    of touched vertices are weighed again; one walk of each of their vertex cells also lists
  //    the edges (those whose darts end there too) and the elements around, whose springs and
  //    diagonals may have changed. The particles at the far end of those edges keep their mass.
  std::vector<Index> elems, touched_springs;
  std::vector<std::pair<Index, double>> masses;
  for (std::uint32_t v : vertices) {
    if (!vattr.is_alive(v)) continue;
    const Index n = map_.value(AttrId<0>(v)).node;
    if (!mss_detail::first_visit(seen_node_, n, generation_) || !nodes.is_alive(n)) continue;
    double m = 0;
    for (std::uint32_t u = first_vertex_[n]; u != Dart::null_index; u = next_vertex_[u]) m += walk_vertex(u, edges, elems);
    masses.emplace_back(n, m);
  }
  // 2) edge springs: end particles, stiffness from the elements still around, rest length
  for (std::uint32_t e : edges) {
    if (!eattr.is_alive(e) || !mss_detail::first_visit(seen_edge_, e, generation_)) continue;
    const Dart d = map_.dart_of(AttrId<1>(e));
    const Index s = map_.value(AttrId<1>(e)).spring, i = node_of(d), j = end_node(d);
    if (!springs_->is_alive(s)) continue;
    if (springs_->node_i(s) != i || springs_->node_j(s) != j) springs_->set_endpoints(s, i, j);
    springs_->set_stiffness(s, edge_stiffness(d));
    springs_->set_rest_length(s, (rest_[j] - rest_[i]).norm());
    touched_springs.push_back(s);
  }
  // 3) diagonals follow the particles their element's corners now carry
  for (Index e : elems) {
    attach_diagonals(e);
    for (Index s : elements_[e].diagonal)
      if (s != invalid_index) touched_springs.push_back(s);
  }
  // 4) masses
  for (const auto& [n, m] : masses) {
    if (!(m > 0))
      throw InputError(options_.source + ": particle " + std::to_string(n) + " is left with no element after the edit");
    nodes.set_mass(n, m);
  }
  // 5) per-spring viscosity, now that both masses are known: the springs whose stiffness or
  //    ends were set above, which include every spring at a particle weighed again
  if (options_.damping == DampingModel::viscous)
    for (Index s : touched_springs)
      if (mss_detail::first_visit(seen_spring_, s, generation_) && springs_->is_alive(s))
        springs_->set_viscosity(s, paper_viscosity(springs_->stiffness(s), nodes.mass(springs_->node_i(s)),
                                                   nodes.mass(springs_->node_j(s))));
}

template <int D>
void MssModel<D>::compact() {
  const std::vector<Index> node_map = system_.compact_nodes();
  const std::vector<Index> spring_map = springs_->compact();
  for (AttrId<0> a : map_.template attributes<0>()) map_.value(a).node = node_map[map_.value(a).node];
  for (AttrId<1> a : map_.template attributes<1>())
    if (map_.value(a).spring != invalid_index) map_.value(a).spring = spring_map[map_.value(a).spring];
  for (Element& el : elements_)
    for (Index& s : el.diagonal)
      if (s != invalid_index) s = spring_map[s];
  for (Index& n : node_of_point_)
    if (n != invalid_index) n = node_map[n];
  std::size_t kept = 0;
  for (std::size_t old = 0; old < node_map.size(); ++old) {
    if (node_map[old] == invalid_index) continue;
    rest_[kept] = rest_[old];
    point_of_node_[kept] = point_of_node_[old];
    first_vertex_[kept] = first_vertex_[old];
    ++kept;
  }
  rest_.resize(kept);
  point_of_node_.resize(kept);
  first_vertex_.resize(kept);
}

// Explicit instantiations of the members defined here.
template void MssModel<2>::install_hooks();
template void MssModel<2>::resync();
template void MssModel<2>::compact();
template void MssModel<3>::install_hooks();
template void MssModel<3>::resync();
template void MssModel<3>::compact();

}  // namespace sewn::physics
