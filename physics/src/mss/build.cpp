#include "element_tables.hpp"

#include <algorithm>
#include <cmath>

#include <Eigen/Geometry>

#include "sewn/physics/cell_input_error.hpp"
#include "sewn/physics/stiffness.hpp"

namespace sewn::physics {

template <int D>
std::span<const std::array<std::uint8_t, 2>> MssModel<D>::local_edges(ElementKind k) {
  switch (k) {
    case ElementKind::hexahedron: return mss_detail::hex_edges;
    case ElementKind::tetrahedron: return mss_detail::tet_edges;
    case ElementKind::quad: return mss_detail::quad_edges;
    case ElementKind::triangle: return mss_detail::tri_edges;
    case ElementKind::segment: return mss_detail::seg_edges;
  }
  return {};
}

// ------------------------------------------------------------------------------- building

template <int D>
MssModel<D>::MssModel(const IndexedMesh& mesh, std::vector<MaterialParams> materials,
                      std::vector<std::uint32_t> material_of_cell, MssOptions options)
    : materials_(std::move(materials)), options_(std::move(options)) {
  if (materials_.empty()) throw InputError(options_.source + ": no material given");
  for (std::size_t i = 0; i < materials_.size(); ++i) mss_detail::check_material(materials_[i], i);
  if (material_of_cell.empty()) material_of_cell.assign(mesh.num_cells(), 0);
  if (material_of_cell.size() != mesh.num_cells())
    throw InputError(options_.source + ": " + std::to_string(material_of_cell.size()) + " material indices for " +
                     std::to_string(mesh.num_cells()) + " cells");
  for (std::uint32_t c = 0; c < mesh.num_cells(); ++c)
    if (material_of_cell[c] >= materials_.size())
      throw InputError(options_.source + ": cell " + std::to_string(c) + " uses material " +
                       std::to_string(material_of_cell[c]) + " but only " + std::to_string(materials_.size()) +
                       " are defined");
  if (!options_.gravity.allFinite()) throw InputError(options_.source + ": gravity must be finite");
  for (double c : {options_.rayleigh_alpha, options_.rayleigh_beta, options_.environment})
    if (!(std::isfinite(c) && c >= 0)) throw InputError(options_.source + ": damping coefficients must be finite and >= 0");
  if (mesh.num_cells() == 0) throw InputError(options_.source + ": the mesh has no cell");

  BuildOptions bopt;
  bopt.source = options_.source;
  bopt.manifold_volumes = true;  // a face of three volumes is not a solid; shells may meet three at an edge
  const BuildResult built = sewn::build(map_, mesh, bopt);
  build_elements(mesh, built, material_of_cell);
  install_hooks();
}

template <int D>
Element MssModel<D>::make_element(const IndexedMesh& mesh, std::uint32_t c, std::uint32_t material, Dart dart) const {
  const MaterialParams& mat = materials_[material];
  const auto v = mesh.cell(c);
  auto p = [&](int k) {
    const auto& q = mesh.points[v[static_cast<std::size_t>(k)]];
    return Eigen::Vector3d(q[0], q[1], q[2]);
  };
  Element el;
  el.material = material;
  el.mesh_cell = c;
  el.dart = dart;
  // A rest state must be the right way out: inversion is measured against it (solids/inversion.hpp).
  static const std::string mirrored =
      "is inside out (a mirror image): its vertex order gives a negative volume; list its vertices in VTK "
      "order (counter-clockwise seen from outside, for the first face of a hexahedron)";
  try {
    switch (mesh.types[c]) {
      case CellType::hexahedron: {
        el.kind = ElementKind::hexahedron;
        // A general hexahedron counts as the box of its mean edge length per axis (PHYSICS_NOTES §1.2).
        std::array<double, 3> len{};
        for (int e = 0; e < 12; ++e)
          len[static_cast<std::size_t>(e / 4)] += (p(mss_detail::hex_edges[e][1]) - p(mss_detail::hex_edges[e][0])).norm() / 4;
        BoxStiffness s = baudet_box(mat.young, mat.poisson, len[0], len[1], len[2]);
        if (!s.valid()) {
          if (mat.elongated == ElongatedPolicy::refuse)
            throw InputError("too elongated for Baudet's stiffness (" + std::to_string(len[0]) + " x " +
                             std::to_string(len[1]) + " x " + std::to_string(len[2]) + " m: " + describe(s) +
                             "); refine the mesh, or choose the clamp policy for its material");
          s = clamp_edges(s, 0.0);
          el.clamped = true;
        }
        for (int e = 0; e < 12; ++e) el.edge_k[static_cast<std::size_t>(e)] = s.edge[static_cast<std::size_t>(e / 4)];
        el.diagonal_k = s.diagonal;
        // volume of the six tetrahedra of the Kuhn split: exact for planar faces
        static constexpr int kuhn[6][4] = {{0, 1, 2, 6}, {0, 2, 3, 6}, {0, 3, 7, 6},
                                           {0, 7, 4, 6}, {0, 4, 5, 6}, {0, 5, 1, 6}};
        double oriented = 0;
        for (const auto& t : kuhn) {
          el.measure += tet_volume(p(t[0]), p(t[1]), p(t[2]), p(t[3]));
          oriented += (p(t[1]) - p(t[0])).dot((p(t[2]) - p(t[0])).cross(p(t[3]) - p(t[0])));
        }
        if (oriented < 0) throw InputError(mirrored);
        break;
      }
      case CellType::tetrahedron: {
        el.kind = ElementKind::tetrahedron;
        const auto k = van_gelder_tet(mat.young, p(0), p(1), p(2), p(3));
        std::copy(k.begin(), k.end(), el.edge_k.begin());
        el.measure = tet_volume(p(0), p(1), p(2), p(3));
        if ((p(1) - p(0)).dot((p(2) - p(0)).cross(p(3) - p(0))) < 0) throw InputError(mirrored);
        break;
      }
      case CellType::quad: {
        el.kind = ElementKind::quad;
        const double lx = ((p(1) - p(0)).norm() + (p(2) - p(3)).norm()) / 2;
        const double ly = ((p(2) - p(1)).norm() + (p(3) - p(0)).norm()) / 2;
        RectangleStiffness s = baudet_rectangle(mat.young * mat.thickness, mat.poisson, lx, ly);
        if (!s.valid()) {
          if (mat.elongated == ElongatedPolicy::refuse)
            throw InputError("too elongated for Baudet's stiffness (" + std::to_string(lx) + " x " + std::to_string(ly) +
                             " m: " + describe(s) + "); refine the mesh, or choose the clamp policy for its material");
          s = clamp_edges(s, 0.0);
          el.clamped = true;
        }
        for (int e = 0; e < 4; ++e) el.edge_k[static_cast<std::size_t>(e)] = s.edge[static_cast<std::size_t>(e / 2)];
        el.diagonal_k = s.diagonal;
        el.measure = mat.thickness * (triangle_area(p(0), p(1), p(2)) + triangle_area(p(0), p(2), p(3)));
        break;
      }
      case CellType::triangle: {
        el.kind = ElementKind::triangle;
        const auto k = van_gelder_triangle(mat.young * mat.thickness, p(0), p(1), p(2));
        std::copy(k.begin(), k.end(), el.edge_k.begin());
        el.measure = mat.thickness * triangle_area(p(0), p(1), p(2));
        break;
      }
      case CellType::segment: {
        el.kind = ElementKind::segment;
        const double l = (p(1) - p(0)).norm();
        el.edge_k[0] = mat.young * mat.area / l;
        el.measure = mat.area * l;
        break;
      }
      default:
        throw InputError(std::string("a ") + to_string(mesh.types[c]) +
                         " has no mass-spring model (hexahedra, tetrahedra, quads, triangles and segments do)");
    }
  } catch (const InputError& e) {
    throw CellInputError(options_.source, c, "(" + std::string(to_string(mesh.types[c])) + "): " + e.what());
  }
  return el;
}

template <int D>
void MssModel<D>::build_elements(const IndexedMesh& mesh, const BuildResult& built,
                                 const std::vector<std::uint32_t>& material_of_cell) {
  const std::uint32_t nc = mesh.num_cells();
  elements_.reserve(nc);
  for (std::uint32_t c = 0; c < nc; ++c) {
    elements_.push_back(make_element(mesh, c, material_of_cell[c], built.cell_dart[c]));
    elements_.back().reversed = built.flipped[c];
  }
  // 1) particles: one per mesh point used by a cell, with its lumped mass
  // Points no cell uses get no particle. A used point must get a normal positive mass: one that
  // underflows to zero (density 1e-320) would leave its darts linked to no particle, and a
  // subnormal or infinite one has no usable inverse.
  std::vector<double> point_mass(mesh.num_points(), 0.0);
  std::vector<std::uint32_t> cell_of_point(mesh.num_points(), mss_detail::no_cell);
  for (std::uint32_t c = 0; c < nc; ++c) {
    const Element& el = elements_[c];
    const double share = materials_[el.material].density * el.measure / mss_detail::corners(el.kind);
    for (std::uint32_t q : mesh.cell(c)) {
      point_mass[q] += share;
      cell_of_point[q] = c;
    }
  }
  for (std::uint32_t q = 0; q < mesh.num_points(); ++q) {
    if (cell_of_point[q] == mss_detail::no_cell || std::isnormal(point_mass[q])) continue;
    const std::uint32_t c = cell_of_point[q];
    throw CellInputError(options_.source, IndexedMessage()
                                              << CellRef{c} << " (" + std::string(to_string(mesh.types[c])) + ", "
                                              << MaterialRef{elements_[c].material} << "): its "
                                              << PointRef{q} << " gets a mass of " + mss_detail::sci(point_mass[q]) + " kg (density " +
                                                                    mss_detail::sci(materials_[elements_[c].material].density) + " kg/m³), which " +
                                                                    (std::isinf(point_mass[q]) ? "overflows" : "underflows") +
                                                                    " a double: the density or the cell size is out of range");
  }
  node_of_point_.assign(mesh.num_points(), invalid_index);
  NodeTable& nodes = system_.nodes();
  nodes.reserve(mesh.num_points());
  for (std::uint32_t q = 0; q < mesh.num_points(); ++q) {
    if (cell_of_point[q] == mss_detail::no_cell) continue;
    const Eigen::Vector3d x(mesh.points[q][0], mesh.points[q][1], mesh.points[q][2]);
    node_of_point_[q] = nodes.add(x, Eigen::Vector3d::Zero(), point_mass[q]);
    rest_.push_back(x);
    point_of_node_.push_back(q);
  }
  first_vertex_.assign(nodes.size(), Dart::null_index);
  map_.template create_attributes<0>(
      [&](Dart d) { return NodeRef{node_of_point_[built.vertex_of_dart[d.index()]]}; });
  next_vertex_.assign(map_.template attribute_container<0>().capacity(), Dart::null_index);
  for (AttrId<0> a : map_.template attributes<0>()) link_vertex(map_.value(a).node, a.index());

  // 2) elements on their cells: volumes by 3-attributes, 2D cells by 2-attributes
  live_elements_ = nc;
  dart_vertex_.assign(map_.dart_capacity(), 0);
  dart_edge_.assign(map_.dart_capacity(), 0);
  for (std::uint32_t c = 0; c < nc; ++c) {
    index_darts(c);
    const Element& el = elements_[c];
    if (el.kind == ElementKind::hexahedron || el.kind == ElementKind::tetrahedron) {
      if constexpr (D == 3) map_.template set_attribute<3>(el.dart, ElementRef{c});
    } else if (el.kind == ElementKind::quad || el.kind == ElementKind::triangle) {
      map_.template set_attribute<2>(el.dart, ElementRef{c});
    }
  }

  // 3) the springs: one per edge, stiffness summed over its incident elements, then diagonals
  SpringDamping damping = SpringDamping::none;
  if (options_.damping == DampingModel::viscous) damping = SpringDamping::viscous;
  if (options_.damping == DampingModel::rayleigh) damping = SpringDamping::stiffness_proportional;
  springs_ = &system_.template add<Springs>(damping, options_.damping == DampingModel::rayleigh ? options_.rayleigh_beta : 0.0);
  std::vector<Dart> edge_darts;
  for (Dart d : map_.template cells<1>()) edge_darts.push_back(d);
  for (Dart d : edge_darts) {
    const std::uint32_t c = built.cell_of_dart[d.index()];
    const Index segment = mesh.types[c] == CellType::segment ? c : invalid_index;
    const Index i = node_of(d), j = end_node(d);
    const Index s = springs_->add(i, j, 0.0, (rest_[j] - rest_[i]).norm(),
                                  segment == invalid_index ? SpringKind::edge : SpringKind::other);
    map_.template set_attribute<1>(d, SpringRef{s, segment});
  }
  for (Dart d : edge_darts) springs_->set_stiffness(spring_of(d), edge_stiffness(d));
  for (Index e = 0; e < elements_.size(); ++e) {
    Element& el = elements_[e];
    for (std::size_t k = 0; k < mss_detail::diagonals_of(el.kind).size(); ++k)
      el.diagonal[k] = springs_->add(0, 1, el.diagonal_k, 0.0, SpringKind::diagonal);
    attach_diagonals(e);
  }
  if (options_.damping == DampingModel::viscous) springs_->set_paper_viscosity(nodes.masses());
  // Cuts add particles and springs: headroom now spares a cut the reallocation of every array
  // (and its page faults), and the stamp vectors are sized once.
  const Index node_room = nodes.size() + nodes.size() / 4 + 16;
  nodes.reserve(node_room);
  rest_.reserve(node_room);
  point_of_node_.reserve(node_room);
  first_vertex_.reserve(node_room);
  next_vertex_.reserve(next_vertex_.size() + node_room - nodes.size());
  springs_->reserve(springs_->size() + springs_->size() / 4 + 16);
  for (auto* v : {&seen_node_, &seen_spring_}) v->assign(nodes.size() + springs_->size(), 0u);
  seen_element_.assign(elements_.size(), 0u);
  const std::uint32_t edge_attributes = map_.template attribute_container<1>().capacity();
  seen_edge_.assign(edge_attributes + edge_attributes / 4 + 16, 0u);

  // 4) fields
  if (options_.gravity.squaredNorm() > 0) system_.template add<Gravity>(options_.gravity);
  const double mass_damping = options_.environment + (options_.damping == DampingModel::rayleigh ? options_.rayleigh_alpha : 0.0);
  if (mass_damping > 0) system_.template add<MassDamping>(mass_damping);
}

// Explicit instantiations of the members defined here (the others: queries.cpp, topology_changes.cpp).
template std::span<const std::array<std::uint8_t, 2>> MssModel<2>::local_edges(ElementKind);
template MssModel<2>::MssModel(const IndexedMesh&, std::vector<MaterialParams>, std::vector<std::uint32_t>, MssOptions);
template Element MssModel<2>::make_element(const IndexedMesh&, std::uint32_t, std::uint32_t, Dart) const;
template void MssModel<2>::build_elements(const IndexedMesh&, const BuildResult&, const std::vector<std::uint32_t>&);
template std::span<const std::array<std::uint8_t, 2>> MssModel<3>::local_edges(ElementKind);
template MssModel<3>::MssModel(const IndexedMesh&, std::vector<MaterialParams>, std::vector<std::uint32_t>, MssOptions);
template Element MssModel<3>::make_element(const IndexedMesh&, std::uint32_t, std::uint32_t, Dart) const;
template void MssModel<3>::build_elements(const IndexedMesh&, const BuildResult&, const std::vector<std::uint32_t>&);

}  // namespace sewn::physics
