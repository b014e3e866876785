#include "element_tables.hpp"

#include <algorithm>
#include <cmath>

#include <Eigen/Geometry>

namespace sewn::physics {

// ------------------------------------------------------------------------------- queries

template <int D>
Index MssModel<D>::end_node(Dart d) const {
  // the dart starting where d ends: its β1 successor, or (open chains) its β2 partner
  Dart e = map_.beta(d, 1);
  if constexpr (D >= 2)
    if (!e) e = map_.beta(d, 2);
  if (!e) throw InputError(options_.source + ": an edge has a dangling end (dart " + std::to_string(d.index()) + ")");
  return node_of(e);
}

template <int D>
void MssModel<D>::link_vertex(Index node, std::uint32_t vertex) {
  if (vertex >= next_vertex_.size()) next_vertex_.resize(vertex + 1, Dart::null_index);
  next_vertex_[vertex] = first_vertex_[node];
  first_vertex_[node] = vertex;
}

template <int D>
bool MssModel<D>::unlink_vertex(Index node, std::uint32_t vertex) {
  std::uint32_t* link = &first_vertex_[node];
  while (*link != Dart::null_index && *link != vertex) link = &next_vertex_[*link];
  if (*link == vertex) *link = next_vertex_[vertex];
  return first_vertex_[node] == Dart::null_index;
}

template <int D>
Index MssModel<D>::element_of(Dart d) const {
  constexpr std::uint32_t null = Dart::null_index;
  if constexpr (D == 3) {
    const std::uint32_t v = map_.template attribute_index<3>(d.index());
    if (v != null) return map_.template attribute_container<3>().value(v).element;
  }
  const std::uint32_t f = map_.template attribute_index<2>(d.index());
  return f != null ? map_.template attribute_container<2>().value(f).element : invalid_index;
}

template <int D>
void MssModel<D>::index_darts(Index e) {
  const Element& el = elements_[e];
  const auto edges = local_edges(el.kind);
  // a polyhedron has two darts per edge (one per face), so one of them is flagged; a polygon or
  // a segment's forward dart is the only one of its element on that edge
  const bool polyhedron = el.kind == ElementKind::hexahedron || el.kind == ElementKind::tetrahedron;
  for_each_local_dart(el, [&](Dart x, std::uint8_t a, std::uint8_t b) {
    dart_vertex_[x.index()] = a;
    const bool flagged = polyhedron ? a < b : !(el.kind == ElementKind::segment && a > b);
    dart_edge_[x.index()] = static_cast<std::uint8_t>(mss_detail::local_edge_index(el.kind, a, b, edges) | (flagged ? 0x80 : 0));
  });
}

template <int D>
double MssModel<D>::edge_stiffness(Dart edge_dart) const {
  double k = 0;
  const SpringRef& ref = map_.template attribute_container<1>().value(map_.template attribute_index<1>(edge_dart.index()));
  if (ref.segment != invalid_index && elements_[ref.segment].alive) k += elements_[ref.segment].edge_k[0];
  auto add = [&](std::uint32_t y) {
    const std::uint8_t code = dart_edge_[y];
    if (!(code & 0x80)) return;
    const Index e = element_of(Dart(y));  // segments carry none: counted above through their spring
    if (e == invalid_index || !elements_[e].alive) return;
    const Element& el = elements_[e];
    // a side of E split into sub-edges in series: each carries k_E · l_e / l_E (PHYSICS_NOTES §2.5)
    k += el.edge_k[code & 0x7f] * (static_cast<double>(ref.level) / el.level);  // a power of two: exact
  };
  for_each_edge_dart(edge_dart.index(), add);
  return k;
}

template <int D>
double MssModel<D>::walk_vertex(std::uint32_t v, std::vector<std::uint32_t>& edges, std::vector<Index>& elems) {
  constexpr std::uint32_t null = Dart::null_index;
  const auto& edge_refs = map_.template attribute_container<1>();
  double m = 0;
  for (Dart y : map_.template cell<0>(map_.dart_of(AttrId<0>(v)))) {
    Index e = element_of(y);
    const std::uint32_t edge = map_.template attribute_index<1>(y.index());
    if (e == invalid_index && edge != null) e = edge_refs.value(edge).segment;
    // a T-junction takes mass only from the elements it is a corner of (PHYSICS_NOTES §2.5)
    if (e != invalid_index && elements_[e].alive && dart_vertex_[y.index()] != not_a_corner) {
      const Element& el = elements_[e];
      m += materials_[el.material].density * el.measure / (mss_detail::corners(el.kind) * mss_detail::darts_per_corner(el.kind));
      if (mss_detail::first_visit(seen_element_, e, generation_)) elems.push_back(e);
    }
    if (edge != null) edges.push_back(edge);
    if (const std::uint32_t p = map_.b(y.index(), 0); p != null)  // a surface's boundary edge may have only this dart
      if (const std::uint32_t a = map_.template attribute_index<1>(p); a != null) edges.push_back(a);
  }
  return m;
}

template <int D>
std::vector<Index> MssModel<D>::element_nodes(Index e) const {
  const Element& el = elements_.at(e);
  std::vector<Index> out(static_cast<std::size_t>(mss_detail::corners(el.kind)), invalid_index);
  if (el.kind == ElementKind::hexahedron || el.kind == ElementKind::tetrahedron) {
    static const mss_detail::CornerPaths hex = mss_detail::corner_paths(mss_detail::template_of(ElementKind::hexahedron));
    static const mss_detail::CornerPaths tet = mss_detail::corner_paths(mss_detail::template_of(ElementKind::tetrahedron));
    const mss_detail::CornerPaths& paths = el.kind == ElementKind::hexahedron ? hex : tet;
    bool on_template = true;
    for (std::size_t v = 0; v < out.size() && on_template; ++v) {
      std::uint32_t x = el.dart.index();
      for (std::uint8_t op : paths[v]) x = map_.b(x, op);
      on_template = dart_vertex_[x] == v;
      out[v] = node_of(Dart(x));
    }
    if constexpr (D == 3)
      if (!on_template)  // a refined neighbour split its faces: find the corners by their codes
        for (Dart y : map_.template cell<3>(el.dart))
          if (dart_vertex_[y.index()] != not_a_corner) out[dart_vertex_[y.index()]] = node_of(y);
  } else if (el.kind == ElementKind::segment) {
    out[0] = node_of(el.dart);
    out[1] = end_node(el.dart);
  } else {
    // a refined neighbour may have put T-junctions on the sides: the ring is longer than the corners
    std::uint32_t x = el.dart.index();
    do {
      if (dart_vertex_[x] != not_a_corner) out[dart_vertex_[x]] = node_of(Dart(x));
      x = map_.b(x, 1);
    } while (x != el.dart.index() && x != Dart::null_index);
  }
  return out;
}

template <int D>
void MssModel<D>::attach_diagonals(Index e) {
  Element& el = elements_[e];
  const auto diags = mss_detail::diagonals_of(el.kind);
  if (diags.empty() || !el.alive) return;
  const std::vector<Index> corner = element_nodes(e);
  for (std::size_t k = 0; k < diags.size(); ++k) {
    const Index i = corner[diags[k][0]], j = corner[diags[k][1]];
    const Index s = el.diagonal[k];
    if (springs_->node_i(s) != i || springs_->node_j(s) != j) springs_->set_endpoints(s, i, j);
    springs_->set_rest_length(s, (rest_[j] - rest_[i]).norm());
  }
}

template <int D>
Eigen::Vector3d MssModel<D>::element_centroid(Index e) const {
  Eigen::Vector3d c = Eigen::Vector3d::Zero();
  const auto nodes = element_nodes(e);
  for (Index n : nodes) c += rest_[n];
  return c / static_cast<double>(nodes.size());
}

template <int D>
double MssModel<D>::element_mass() const {
  double m = 0;
  for (const Element& el : elements_)
    if (el.alive) m += materials_[el.material].density * el.measure;
  return m;
}

template <int D>
double MssModel<D>::node_mass() const {
  double m = 0;
  const NodeTable& nodes = system_.nodes();
  for (Index i = 0; i < nodes.size(); ++i)
    if (nodes.is_alive(i)) m += nodes.mass(i);
  return m;
}

// Explicit instantiations of the members defined here.
template Index MssModel<2>::end_node(Dart) const;
template void MssModel<2>::link_vertex(Index, std::uint32_t);
template bool MssModel<2>::unlink_vertex(Index, std::uint32_t);
template Index MssModel<2>::element_of(Dart) const;
template void MssModel<2>::index_darts(Index);
template double MssModel<2>::edge_stiffness(Dart) const;
template double MssModel<2>::walk_vertex(std::uint32_t, std::vector<std::uint32_t>&, std::vector<Index>&);
template std::vector<Index> MssModel<2>::element_nodes(Index) const;
template void MssModel<2>::attach_diagonals(Index);
template Eigen::Vector3d MssModel<2>::element_centroid(Index) const;
template double MssModel<2>::element_mass() const;
template double MssModel<2>::node_mass() const;
template Index MssModel<3>::end_node(Dart) const;
template void MssModel<3>::link_vertex(Index, std::uint32_t);
template bool MssModel<3>::unlink_vertex(Index, std::uint32_t);
template Index MssModel<3>::element_of(Dart) const;
template void MssModel<3>::index_darts(Index);
template double MssModel<3>::edge_stiffness(Dart) const;
template double MssModel<3>::walk_vertex(std::uint32_t, std::vector<std::uint32_t>&, std::vector<Index>&);
template std::vector<Index> MssModel<3>::element_nodes(Index) const;
template void MssModel<3>::attach_diagonals(Index);
template Eigen::Vector3d MssModel<3>::element_centroid(Index) const;
template double MssModel<3>::element_mass() const;
template double MssModel<3>::node_mass() const;

}  // namespace sewn::physics
