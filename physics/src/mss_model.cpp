#include "sewn/physics/mss_model.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include <Eigen/Geometry>

#include "sewn/physics/errors.hpp"
#include "sewn/physics/stiffness.hpp"

namespace sewn::physics {

namespace {

constexpr std::uint32_t no_cell = 0xffffffffu;

std::string sci(double x) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.3g", x);
  return buf;
}

using Vec3 = Eigen::Vector3d;
using Edge = std::array<std::uint8_t, 2>;

// Local edges per kind, VTK vertex order. Hexahedra and quads list their edges axis by axis
// (the Baudet stiffness depends on the axis); tetrahedra and triangles follow van Gelder's order.
constexpr Edge hex_edges[12] = {{0, 1}, {3, 2}, {4, 5}, {7, 6}, {0, 3}, {1, 2}, {4, 7}, {5, 6}, {0, 4}, {1, 5}, {2, 6}, {3, 7}};
constexpr Edge tet_edges[6] = {{0, 1}, {0, 2}, {0, 3}, {1, 2}, {1, 3}, {2, 3}};
constexpr Edge quad_edges[4] = {{0, 1}, {3, 2}, {1, 2}, {0, 3}};
constexpr Edge tri_edges[3] = {{0, 1}, {1, 2}, {2, 0}};
constexpr Edge seg_edges[1] = {{0, 1}};
constexpr Edge hex_diagonals[4] = {{0, 6}, {1, 7}, {2, 4}, {3, 5}};
constexpr Edge quad_diagonals[2] = {{0, 2}, {1, 3}};

int corners(ElementKind k) {
  switch (k) {
    case ElementKind::hexahedron: return 8;
    case ElementKind::tetrahedron:
    case ElementKind::quad: return 4;
    case ElementKind::triangle: return 3;
    case ElementKind::segment: return 2;
  }
  return 0;
}

// Darts of an element starting at one of its corners: the faces meeting there in a polyhedron,
// one in a polygon or a segment. A vertex cell's mass sums ρ·measure/(corners·this) per dart.
int darts_per_corner(ElementKind k) {
  return k == ElementKind::hexahedron || k == ElementKind::tetrahedron ? 3 : 1;
}

// Grows a stamp vector to cover i and stamps it; false if already stamped this generation.
bool first_visit(std::vector<std::uint32_t>& stamp, std::size_t i, std::uint32_t generation) {
  if (i >= stamp.size()) stamp.resize(i + 1 + i / 2, 0);
  if (stamp[i] == generation) return false;
  stamp[i] = generation;
  return true;
}

std::span<const Edge> diagonals_of(ElementKind k) {
  if (k == ElementKind::hexahedron) return hex_diagonals;
  if (k == ElementKind::quad) return quad_diagonals;
  return {};
}

const CellTemplate& template_of(ElementKind k) {
  static const CellTemplate hex = CellTemplate::from_faces(cell_faces(CellType::hexahedron));
  static const CellTemplate tet = CellTemplate::from_faces(cell_faces(CellType::tetrahedron));
  return k == ElementKind::hexahedron ? hex : tet;
}

void check_material(const MaterialParams& m, std::size_t i) {
  const std::string name = "material " + std::to_string(i);
  auto positive = [&](double x, const char* what) {
    if (!(std::isfinite(x) && x > 0))
      throw InputError(name + ": " + what + " must be finite and > 0 (got " + std::to_string(x) + ")");
  };
  positive(m.young, "Young's modulus");
  positive(m.density, "density");
  positive(m.thickness, "thickness");
  positive(m.area, "cross-section area");
  if (!(m.poisson > -1 && m.poisson < 0.5))
    throw InputError(name + ": Poisson's ratio must be in (-1, 0.5) (got " + std::to_string(m.poisson) + ")");
}

// For each local vertex of a polyhedron, the shortest sequence of β1 / β2 steps from the
// canonical dart (the template's `first` half-edge) to a dart starting at that vertex: corners
// are then found in a few link reads instead of walking the whole volume.
using CornerPaths = std::array<std::vector<std::uint8_t>, 8>;
CornerPaths corner_paths(const CellTemplate& t) {
  const std::size_t n = t.from.size();
  std::vector<std::uint32_t> next(n), face_of(n);
  for (std::size_t h = 0, f = 0; f < t.face_size.size(); h += t.face_size[f], ++f)
    for (std::uint32_t k = 0; k < t.face_size[f]; ++k) next[h + k] = static_cast<std::uint32_t>(h + (k + 1) % t.face_size[f]);
  std::vector<std::vector<std::uint8_t>> path(n);
  std::vector<char> seen(n, 0);
  std::vector<std::uint32_t> queue{t.first};
  seen[t.first] = 1;
  for (std::size_t q = 0; q < queue.size(); ++q) {
    const std::uint32_t h = queue[q];
    for (auto [op, g] : {std::pair<std::uint8_t, std::uint32_t>{1, next[h]}, {2, t.mate[h]}}) {
      if (seen[g]) continue;
      seen[g] = 1;
      path[g] = path[h];
      path[g].push_back(op);
      queue.push_back(g);
    }
  }
  CornerPaths out;
  std::array<bool, 8> found{};
  for (std::uint32_t h : queue)  // breadth-first order: the first half-edge met per vertex is nearest
    if (!found[t.from[h]]) {
      found[t.from[h]] = true;
      out[t.from[h]] = path[h];
    }
  return out;
}

int local_edge_index(ElementKind k, std::uint8_t a, std::uint8_t b, std::span<const Edge> edges) {
  for (std::size_t e = 0; e < edges.size(); ++e)
    if ((edges[e][0] == a && edges[e][1] == b) || (edges[e][0] == b && edges[e][1] == a)) return static_cast<int>(e);
  (void)k;
  return -1;
}

}  // namespace

template <int D>
std::span<const std::array<std::uint8_t, 2>> MssModel<D>::local_edges(ElementKind k) {
  switch (k) {
    case ElementKind::hexahedron: return hex_edges;
    case ElementKind::tetrahedron: return tet_edges;
    case ElementKind::quad: return quad_edges;
    case ElementKind::triangle: return tri_edges;
    case ElementKind::segment: return seg_edges;
  }
  return {};
}

// ------------------------------------------------------------------------------- building

template <int D>
MssModel<D>::MssModel(const IndexedMesh& mesh, std::vector<MaterialParams> materials,
                      std::vector<std::uint32_t> material_of_cell, MssOptions options)
    : materials_(std::move(materials)), options_(std::move(options)) {
  if (materials_.empty()) throw InputError(options_.source + ": no material given");
  for (std::size_t i = 0; i < materials_.size(); ++i) check_material(materials_[i], i);
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
    return Vec3(q[0], q[1], q[2]);
  };
  Element el;
  el.material = material;
  el.mesh_cell = c;
  el.dart = dart;
  const std::string name = options_.source + ": cell " + std::to_string(c);
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
          len[static_cast<std::size_t>(e / 4)] += (p(hex_edges[e][1]) - p(hex_edges[e][0])).norm() / 4;
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
    throw InputError(name + " (" + to_string(mesh.types[c]) + "): " + e.what());
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
  std::vector<std::uint32_t> cell_of_point(mesh.num_points(), no_cell);
  for (std::uint32_t c = 0; c < nc; ++c) {
    const Element& el = elements_[c];
    const double share = materials_[el.material].density * el.measure / corners(el.kind);
    for (std::uint32_t q : mesh.cell(c)) {
      point_mass[q] += share;
      cell_of_point[q] = c;
    }
  }
  for (std::uint32_t q = 0; q < mesh.num_points(); ++q) {
    if (cell_of_point[q] == no_cell || std::isnormal(point_mass[q])) continue;
    const std::uint32_t c = cell_of_point[q];
    throw InputError(options_.source + ": cell " + std::to_string(c) + " (" + to_string(mesh.types[c]) + ", material " +
                     std::to_string(elements_[c].material) + "): its point " + std::to_string(q) + " gets a mass of " +
                     sci(point_mass[q]) + " kg (density " + sci(materials_[elements_[c].material].density) +
                     " kg/m³), which " + (std::isinf(point_mass[q]) ? "overflows" : "underflows") +
                     " a double: the density or the cell size is out of range");
  }
  node_of_point_.assign(mesh.num_points(), invalid_index);
  NodeTable& nodes = system_.nodes();
  nodes.reserve(mesh.num_points());
  for (std::uint32_t q = 0; q < mesh.num_points(); ++q) {
    if (cell_of_point[q] == no_cell) continue;
    const Vec3 x(mesh.points[q][0], mesh.points[q][1], mesh.points[q][2]);
    node_of_point_[q] = nodes.add(x, Vec3::Zero(), point_mass[q]);
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
    for (std::size_t k = 0; k < diagonals_of(el.kind).size(); ++k)
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

// ------------------------------------------------------------------------------- queries

template <int D>
template <class F>
void MssModel<D>::for_each_local_dart(const Element& el, F&& f) const {
  if (el.kind == ElementKind::hexahedron || el.kind == ElementKind::tetrahedron) {
    // Walk the cell's darts alongside its template: β1 follows the face ring, β2 the mate.
    const CellTemplate& t = template_of(el.kind);
    const std::size_t n = t.from.size();
    std::array<std::uint32_t, 24> face_start{}, face_end{};
    for (std::size_t h = 0, f0 = 0; f0 < t.face_size.size(); ++f0) {
      for (std::uint32_t k = 0; k < t.face_size[f0]; ++k) {
        face_start[h + k] = static_cast<std::uint32_t>(h);
        face_end[h + k] = static_cast<std::uint32_t>(h + t.face_size[f0]);
      }
      h += t.face_size[f0];
    }
    std::array<Dart, 24> dart_of_half{};
    std::array<std::uint32_t, 24> queue{};
    std::size_t qn = 0;
    dart_of_half[t.first] = el.dart;
    queue[qn++] = t.first;
    for (std::size_t qh = 0; qh < qn; ++qh) {
      const std::uint32_t h = queue[qh];
      const Dart x = dart_of_half[h];
      f(x, static_cast<std::uint8_t>(t.from[h]), static_cast<std::uint8_t>(t.to[h]));
      const std::uint32_t next = h + 1 == face_end[h] ? face_start[h] : h + 1;
      const std::uint32_t mate = t.mate[h];
      for (auto [hn, dn] : {std::pair{next, map_.beta(x, 1)}, std::pair{mate, map_.beta(x, 2)}}) {
        if (!dart_of_half[hn].is_null()) continue;
        dart_of_half[hn] = dn;
        queue[qn++] = hn;
      }
    }
    (void)n;
  } else if (el.kind == ElementKind::segment) {
    f(el.dart, std::uint8_t{0}, std::uint8_t{1});
    if constexpr (D >= 2)
      if (Dart back = map_.beta(el.dart, 2)) f(back, std::uint8_t{1}, std::uint8_t{0});
  } else {
    const auto n = static_cast<std::uint8_t>(corners(el.kind));
    Dart x = el.dart;
    for (std::uint8_t k = 0; k < n; ++k, x = map_.beta(x, 1)) {
      const auto from = static_cast<std::uint8_t>(el.reversed ? (n - k) % n : k);
      const auto to = static_cast<std::uint8_t>(el.reversed ? (2 * n - k - 1) % n : (k + 1) % n);
      f(x, from, to);
    }
  }
}

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
    dart_edge_[x.index()] = static_cast<std::uint8_t>(local_edge_index(el.kind, a, b, edges) | (flagged ? 0x80 : 0));
  });
}

template <int D>
template <class F>
void MssModel<D>::for_each_edge_dart(std::uint32_t d, F&& f) const {
  // An edge's darts are linked by β2 and β3 only, which alternate along a path or a cycle:
  // walk it both ways from d, no marks needed.
  constexpr std::uint32_t null = Dart::null_index;
  f(d);
  int j = 2;
  std::uint32_t x = map_.b(d, j);
  for (; x != null && x != d; x = map_.b(x, j)) {
    f(x);
    if constexpr (D == 3) j = 5 - j;
  }
  if (x == d) return;  // a cycle
  if constexpr (D == 3)
    for (std::uint32_t y = map_.b(d, 3), jj = 2; y != null; y = map_.b(y, static_cast<int>(jj)), jj = 5 - jj) f(y);
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
      m += materials_[el.material].density * el.measure / (corners(el.kind) * darts_per_corner(el.kind));
      if (first_visit(seen_element_, e, generation_)) elems.push_back(e);
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
  std::vector<Index> out(static_cast<std::size_t>(corners(el.kind)), invalid_index);
  if (el.kind == ElementKind::hexahedron || el.kind == ElementKind::tetrahedron) {
    static const CornerPaths hex = corner_paths(template_of(ElementKind::hexahedron));
    static const CornerPaths tet = corner_paths(template_of(ElementKind::tetrahedron));
    const CornerPaths& paths = el.kind == ElementKind::hexahedron ? hex : tet;
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
  const auto diags = diagonals_of(el.kind);
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
  Vec3 c = Vec3::Zero();
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
  map_.template on_split<1>([this](AttrId<1> a, AttrId<1> b) {
    // a duplicated edge: a new spring (ends, stiffness and rest length follow in resync)
    const Index s = map_.value(a).spring;
    map_.value(b).spring = springs_->add(springs_->node_i(s), springs_->node_j(s), springs_->stiffness(s),
                                         springs_->rest_length(s), springs_->kind(s), springs_->viscosity(s));
    dirty_edges_.insert(dirty_edges_.end(), {a.index(), b.index()});
  });
  map_.template on_merge<1>([this](AttrId<1> kept, AttrId<1> gone) {
    springs_->remove(map_.value(gone).spring);
    dirty_edges_.push_back(kept.index());
  });
  map_.template on_erase<1>([this](AttrId<1> gone) { springs_->remove(map_.value(gone).spring); });
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
    if (!first_visit(seen_node_, n, generation_) || !nodes.is_alive(n)) continue;
    double m = 0;
    for (std::uint32_t u = first_vertex_[n]; u != Dart::null_index; u = next_vertex_[u]) m += walk_vertex(u, edges, elems);
    masses.emplace_back(n, m);
  }
  // 2) edge springs: end particles, stiffness from the elements still around, rest length
  for (std::uint32_t e : edges) {
    if (!eattr.is_alive(e) || !first_visit(seen_edge_, e, generation_)) continue;
    const Dart d = map_.dart_of(AttrId<1>(e));
    const Index s = map_.value(AttrId<1>(e)).spring, i = node_of(d), j = end_node(d);
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
      if (first_visit(seen_spring_, s, generation_) && springs_->is_alive(s))
        springs_->set_viscosity(s, paper_viscosity(springs_->stiffness(s), nodes.mass(springs_->node_i(s)),
                                                   nodes.mass(springs_->node_j(s))));
}

template <int D>
void MssModel<D>::compact() {
  const std::vector<Index> node_map = system_.compact_nodes();
  const std::vector<Index> spring_map = springs_->compact();
  for (AttrId<0> a : map_.template attributes<0>()) map_.value(a).node = node_map[map_.value(a).node];
  for (AttrId<1> a : map_.template attributes<1>()) map_.value(a).spring = spring_map[map_.value(a).spring];
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

template class MssModel<2>;
template class MssModel<3>;

}  // namespace sewn::physics
