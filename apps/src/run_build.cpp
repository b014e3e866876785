#include "run_build.hpp"

#include <algorithm>
#include <array>
#include <cstdint>
#include <cstdio>
#include <map>
#include <optional>
#include <set>
#include <string>
#include <unordered_map>
#include <utility>
#include <vector>

#include <Eigen/Geometry>

#include "sewn/apps/obstacle_keys.hpp"
#include "sewn/io/cleanup.hpp"
#include "sewn/io/geometry.hpp"
#include "sewn/io/read.hpp"
#include "sewn/io/surface.hpp"
#include "sewn/physics/cell_input_error.hpp"
#include "sewn/physics/solids/volume_term.hpp"
#include "sewn/physics/split_boxes.hpp"
#include "sewn/physics/stiffness.hpp"

namespace sewn::app {

namespace detail {

bool selects_cell(const Selector& s, const IndexedMesh& m, std::uint32_t c) {
  switch (s.type) {
    case Selector::Type::tag: return m.tags[c] == s.tag;
    case Selector::Type::points: {
      for (std::uint32_t q : m.cell(c))
        if (std::find(s.points.begin(), s.points.end(), q) == s.points.end()) return false;
      return true;
    }
    default: {
      Vec3 centroid{0, 0, 0};
      const auto v = m.cell(c);
      for (std::uint32_t q : v)
        for (std::size_t k = 0; k < 3; ++k) centroid[k] += m.points[q][k] / static_cast<double>(v.size());
      return s.contains(centroid);
    }
  }
}

}  // namespace detail

namespace {

using detail::selects_cell;
using detail::to_vec3;
using physics::Index;
using Vec3d = Eigen::Vector3d;


// The mesh of `spec`, in `names` what its file says of its tags and in `source` how it numbers its cells.
IndexedMesh generate(const MeshSpec& spec, const std::string& file, const std::string& path, MeshNames& names, MeshSource& source) {
  IndexedMesh m;
  names.path = path;
  source.key = path;
  if (spec.type == "hex_grid" || spec.type == "tet_grid") {
    GridSpec g;
    for (int k = 0; k < 3; ++k) {
      g.spacing[static_cast<std::size_t>(k)] = spec.size[static_cast<std::size_t>(k)] / spec.cells[static_cast<std::size_t>(k)];
      g.origin[static_cast<std::size_t>(k)] = spec.origin[static_cast<std::size_t>(k)];
    }
    m = spec.type == "hex_grid"
            ? hex_grid(spec.cells[0], spec.cells[1], spec.cells[2], g)
            : tet_grid(spec.cells[0], spec.cells[1], spec.cells[2], spec.split == "five" ? TetSplit::five : TetSplit::kuhn6, g);
  } else if (spec.type == "quad_grid" || spec.type == "tri_grid") {
    GridSpec g;
    g.spacing = {spec.size[0] / spec.cells[0], spec.size[1] / spec.cells[1], 1.0};
    m = spec.type == "quad_grid" ? quad_grid(spec.cells[0], spec.cells[1], g) : tri_grid(spec.cells[0], spec.cells[1], g);
    place_in_plane(m, spec.plane);
    transform(m, 1.0, spec.origin);
  } else if (spec.type == "disc") {
    m = disc(spec.radius, spec.rings, spec.sectors);
    place_in_plane(m, spec.plane);
    transform(m, 1.0, spec.origin);
  } else if (spec.type == "cylinder") {
    m = cylinder(spec.radius, spec.height, spec.rings, spec.sectors, spec.layers);
    transform(m, 1.0, spec.origin);
  } else if (spec.type == "boxes") {
    std::vector<LatticeBox> boxes;
    for (const auto& b : spec.boxes) boxes.push_back({b.lo, b.hi});
    try {
      m = box_union(boxes, GridSpec{{spec.size[0], spec.size[1], spec.size[2]}, {spec.origin[0], spec.origin[1], spec.origin[2]}});
    } catch (const MeshError& e) {
      throw SceneError(file, path + ".boxes", e.what());
    }
  } else if (spec.type == "polyline") {
    std::vector<Point3> pts;
    for (const Vec3& p : spec.points) pts.push_back({p[0], p[1], p[2]});
    try {
      m = polyline(pts);
    } catch (const MeshError& e) {
      throw SceneError(file, path + ".points", e.what());
    }
  } else if (spec.type == "surface") {
    m = io::voxelize(io::read_surface(spec.path), spec.cells[0], spec.path);
    transform(m, spec.scale, spec.translate);
  } else if (spec.type == "file") {
    io::MeshFile read = io::read_mesh_file(spec.path);
    for (const auto& w : read.warnings) std::fprintf(stderr, "sewn: warning: %s\n", w.c_str());
    names.format = io::to_string(read.format);
    names.names = read.tag_names;
    io::GeometryOptions numbering;
    m = used_part(read, numbering);
    source.file = spec.path;
    source.element_tags = numbering.element_tags;
    source.point_numbers = numbering.point_numbers;
    transform(m, spec.scale, spec.translate);
    io::check_mesh_geometry(m, spec.path, numbering);
  }
  return m;
}


// The particles a selector picks: those of tagged cells (simulated or labels; a label's points
// that no simulated cell uses carry no particle), listed mesh points, or those whose rest
// position lies in the region. Throws SceneError (at `path`) for a point of no cell or an
// empty selection.
std::set<Index> selected_nodes(const Selector& where, const Assembly& assembly, const physics::MssModel<3>& model,
                               const std::string& file, const std::string& path) {
  const IndexedMesh& mesh = assembly.mesh;
  std::set<Index> nodes;
  if (where.type == Selector::Type::tag) {
    for (const IndexedMesh* cells : {&assembly.mesh, &assembly.labels})
      for (std::uint32_t c = 0; c < cells->num_cells(); ++c)
        if (cells->tags[c] == where.tag)
          for (std::uint32_t q : cells->cell(c))
            if (model.node_of_point(q) != physics::invalid_index) nodes.insert(model.node_of_point(q));
  } else if (where.type == Selector::Type::points) {
    for (std::size_t k = 0; k < where.points.size(); ++k) {
      const std::uint32_t q = where.points[k];
      const std::string at = path + ".indices[" + std::to_string(k) + "]";
      if (q >= mesh.num_points())
        throw SceneError(file, at, "point " + std::to_string(q) + " is past the scene's " + std::to_string(mesh.num_points()) + " points (numbered " +
                                       point_numbering + ")");
      if (model.node_of_point(q) == physics::invalid_index)
        throw SceneError(file, at, "point " + std::to_string(q) + " (" + assembly.point_name(q, true) +
                                       ") is a point of labels only (faces or edges of other cells), which carry no particle");
      nodes.insert(model.node_of_point(q));
    }
  } else {
    for (Index i = 0; i < model.nodes().size(); ++i)
      if (where.contains(to_vec3(model.rest_position(i)))) nodes.insert(i);
  }
  if (nodes.empty()) throw SceneError(file, path, "selects no particle");
  return nodes;
}

// The "split" policy: hexahedra too elongated for Baudet's stiffness, of materials that ask
// for it, are cut into near-cubes (physics/split_boxes.hpp) with their sheets' neighbours.
void split_elongated(const Scene& scene, Assembly& a) {
  a.source_cells = a.mesh.num_cells();
  a.source_points = a.mesh.num_points();
  std::vector<std::uint8_t> wanted(a.mesh.num_cells(), 0);
  bool any = false;
  for (std::uint32_t c = 0; c < a.mesh.num_cells(); ++c) {
    const MaterialSpec& m = scene.materials.at(a.material_names[a.material_of_cell[c]]);
    if (m.elongated != "split" || a.mesh.types[c] != CellType::hexahedron) continue;
    const auto len = physics::box_axis_lengths(a.mesh, c);
    wanted[c] = !physics::baudet_box(m.young, m.poisson, len[0], len[1], len[2]).valid();
    any = any || wanted[c] != 0;
  }
  if (!any) return;
  physics::BoxSplit split;
  try {
    split = physics::split_boxes(a.mesh, wanted, scene.file);
  } catch (const physics::CellInputError& e) {
    throw physics::InputError(a.in_files(scene.file, e.message()));
  }
  std::vector<std::uint32_t> material(split.source_cell.size());
  std::vector<CellModel> model(split.source_cell.size());
  std::vector<int> group(split.source_cell.size());
  std::vector<std::uint32_t> file_cell(split.source_cell.size());
  for (std::size_t c = 0; c < material.size(); ++c) {
    file_cell[c] = a.file_cell[split.source_cell[c]];
    material[c] = a.material_of_cell[split.source_cell[c]];
    model[c] = a.model_of_cell[split.source_cell[c]];
    group[c] = a.group_of_cell[split.source_cell[c]];
  }
  for (std::uint32_t& first : a.first_cell)
    first = static_cast<std::uint32_t>(std::lower_bound(split.source_cell.begin(), split.source_cell.end(), first) -
                                       split.source_cell.begin());
  a.mesh = std::move(split.mesh);
  a.material_of_cell = std::move(material);
  a.model_of_cell = std::move(model);
  a.group_of_cell = std::move(group);
  a.file_cell = std::move(file_cell);
  a.split_source = std::move(split.source_cell);
  a.split_asked = split.asked;
  a.split_cells = split.split;
}

// What the report says of where a mixed model's bodies meet.
std::string connections_line(const Assembly& a) {
  const MeshConnections c = mesh_connections(a.mesh, a.model_of_cell);
  return c.skipped.empty() ? connect::connections_text(c.found) : "  not computed: " + c.skipped + "\n";
}


}  // namespace

std::size_t Assembly::mesh_of_cell(std::uint32_t c) const {
  return static_cast<std::size_t>(std::upper_bound(first_cell.begin(), first_cell.end(), c) - first_cell.begin()) - 1;
}

std::string Assembly::cell_name(std::uint32_t c, bool key) const {
  const MeshSource& source = sources[mesh_of_cell(c)];
  std::string piece;
  if (!split_source.empty()) {
    const auto [first, last] = std::equal_range(split_source.begin(), split_source.end(), split_source[c]);
    if (last - first > 1) piece = "piece " + std::to_string(c - static_cast<std::uint32_t>(first - split_source.begin())) + " of ";
  }
  return (key ? source.key + " " : "") + piece + source.cell(file_cell[c]);
}

std::optional<std::size_t> Assembly::mesh_of_point(std::uint32_t p) const {
  if (!split_source.empty() && p >= source_points) return std::nullopt;
  return static_cast<std::size_t>(std::upper_bound(first_point.begin(), first_point.end(), p) - first_point.begin()) - 1;
}

std::string Assembly::point_name(std::uint32_t p, bool key) const {
  const auto k = mesh_of_point(p);
  if (!k) return "point " + std::to_string(p) + " (added by the split into near-cubes)";
  return (key ? sources[*k].key + " " : "") + sources[*k].point(p - first_point[*k]);
}

std::string Assembly::in_files(const std::string& scene_file, const IndexedMessage& m) const {
  // the scene mesh of each number: a message within one starts at its key
  std::optional<std::size_t> one;
  bool several = false;
  for (const auto& r : m.refs()) {
    if (r.kind == IndexedMessage::Ref::Kind::material) continue;
    const auto k = r.kind == IndexedMessage::Ref::Kind::cell ? std::optional(mesh_of_cell(r.index)) : mesh_of_point(r.index);
    several = several || !k || (one && *one != *k);
    one = k;
  }
  const std::string text = m.render([&](const IndexedMessage::Ref& r) {
    switch (r.kind) {
      case IndexedMessage::Ref::Kind::cell: return cell_name(r.index, several);
      case IndexedMessage::Ref::Kind::point: return point_name(r.index, several);
      default:  // materials past the scene's are the copies apply_rod_sections made for rods
        return r.index < material_names.size() ? "material \"" + material_names[r.index] + "\"" : "material " + std::to_string(r.index);
    }
  });
  return scene_file + ": " + (one && !several ? sources[*one].key + ": " : "") + text;
}

Assembly assemble(const Scene& scene) {
  Assembly a;
  for (const auto& [name, _] : scene.materials) a.material_names.push_back(name);
  auto material_index = [&](const std::string& name) {
    return static_cast<std::uint32_t>(std::find(a.material_names.begin(), a.material_names.end(), name) - a.material_names.begin());
  };
  std::vector<bool> group_used(scene.model_groups.size(), false);
  std::vector<MeshNames> mesh_names(scene.meshes.size());
  for (std::size_t i = 0; i < scene.meshes.size(); ++i) {
    const MeshSpec& spec = scene.meshes[i];
    const std::string path = "meshes[" + std::to_string(i) + "]";
    a.sources.emplace_back();
    const IndexedMesh whole = generate(spec, scene.file, path, mesh_names[i], a.sources.back());
    const GroupMatch groups = match_groups(whole, mesh_names[i], scene);
    const std::vector<CellModel> models = cell_models(whole, io::embedded_cells(whole), scene, a.sources.back(), groups.of_cell);
    for (std::size_t k = 0; k < group_used.size(); ++k) group_used[k] = group_used[k] || groups.named_a_cell[k];
    // the simulated cells and the labels, on the same points
    IndexedMesh piece, labels;
    piece.points = whole.points;
    std::vector<CellModel> piece_models;
    std::vector<int> piece_groups;
    for (std::uint32_t c = 0; c < whole.num_cells(); ++c) {
      if (models[c] == CellModel::label) {
        labels.add_cell(whole.types[c], whole.cell(c), whole.tags[c]);
      } else {
        piece.add_cell(whole.types[c], whole.cell(c), whole.tags[c]);
        a.file_cell.push_back(c);
        piece_models.push_back(models[c]);
        piece_groups.push_back(groups.of_cell[c]);
      }
    }
    if (piece.num_cells() == 0)
      throw SceneError(scene.file, path, whole.num_cells() == 0 ? "the mesh has no cell" : "every cell of the mesh is a label: nothing to simulate");
    a.first_cell.push_back(a.mesh.num_cells());
    std::vector<std::uint32_t> mat(piece.num_cells(), material_index(spec.material));
    for (std::size_t k = 0; k < spec.regions.size(); ++k) {
      const Selector& where = spec.regions[k].first;
      bool any = false;
      for (std::uint32_t c = 0; c < piece.num_cells(); ++c)
        if (selects_cell(where, piece, c)) mat[c] = material_index(spec.regions[k].second), any = true;
      // a region that assigns nothing leaves its cells in the mesh's material without a word
      if (!any)
        throw SceneError(scene.file, path + ".regions[" + std::to_string(k) + "].where",
                         std::string("selects no simulated cell of this mesh") +
                             (where.type == Selector::Type::tag
                                  ? " (a Gmsh cell carries the tag of the first physical group that holds it: one in two groups is in the first only)"
                                  : ""));
    }
    const std::uint32_t first_point = append(a.mesh, piece);
    a.first_point.push_back(first_point);
    for (std::uint32_t c = 0; c < labels.num_cells(); ++c) {
      std::vector<std::uint32_t> v(labels.cell(c).begin(), labels.cell(c).end());
      for (auto& q : v) q += first_point;
      a.labels.add_cell(labels.types[c], v, labels.tags[c]);
    }
    a.material_of_cell.insert(a.material_of_cell.end(), mat.begin(), mat.end());
    a.model_of_cell.insert(a.model_of_cell.end(), piece_models.begin(), piece_models.end());
    a.group_of_cell.insert(a.group_of_cell.end(), piece_groups.begin(), piece_groups.end());
  }
  check_groups_used(scene, group_used, mesh_names);
  split_elongated(scene, a);
  a.labels.points = a.mesh.points;
  return a;
}

namespace {


// The volume term of the materials that ask for it (volume_stiffness > 0). It follows cuts (a
// stencil takes its element's corner particles after the cut) and refinement and coarsening (the
// model's after_edits hook gives children their own stencils and retires the parent's), so a
// scene that refines, before the run or during it, keeps it on its live elements.
void add_volume_term(const Scene& scene, const std::vector<std::string>& material_names, physics::MssModel<3>& model) {
  std::vector<double> kappa;
  for (const auto& name : material_names) kappa.push_back(scene.materials.at(name).volume_stiffness);
  // Materials past the scene's own are copies apply_rod_sections made for rod cells, which have
  // no volume to keep.
  kappa.resize(model.materials().size(), 0.0);
  (void)physics::solids::add_volume_preservation(model, kappa);
}

// The physical parameters of the scene's materials, in the assembly's material order.
std::vector<physics::MaterialParams> material_params(const Scene& scene, const Assembly& assembly) {
  std::vector<physics::MaterialParams> materials;
  for (const auto& name : assembly.material_names) {
    const MaterialSpec& ms = scene.materials.at(name);
    materials.push_back({ms.young, ms.poisson, ms.density, ms.thickness, ms.area,
                         ms.elongated == "clamp" ? physics::ElongatedPolicy::clamp : physics::ElongatedPolicy::refuse});
  }
  return materials;
}

physics::MssOptions model_options(const Scene& scene) {
  physics::MssOptions mo;
  mo.gravity = Vec3d(scene.gravity[0], scene.gravity[1], scene.gravity[2]);
  mo.damping = scene.damping == "viscous" ? physics::DampingModel::viscous
               : scene.damping == "rayleigh" ? physics::DampingModel::rayleigh
                                             : physics::DampingModel::none;
  mo.rayleigh_alpha = scene.rayleigh_alpha;
  mo.rayleigh_beta = scene.rayleigh_beta;
  mo.environment = scene.environment_damping;
  mo.source = scene.file;
  return mo;
}

}  // namespace

namespace detail {

std::vector<std::string> locking_warnings(const Scene& scene, const Assembly& assembly) {
  // Linear tetrahedra lock as ν → ½: the volumetric term λ(tr ε)² cannot be kept near zero by
  // their constant strains in bending. Measured on scenes/solid_cantilever.json (20x2x2 cells,
  // 6 tets each) at rest under gravity: mean sag 3.02 mm at ν = 0.3, 1.80 at 0.45, 0.67 at 0.49,
  // 0.13 at 0.4999; on 40x4x4 cells 4.69, 1.73 and 0.15 mm; the continuum's 5.9 mm barely
  // depends on ν. Refining does not cure it, so the user is told.
  constexpr double locking_poisson = 0.45;
  std::vector<std::uint64_t> solid_cells(assembly.material_names.size(), 0);
  for (std::uint32_t c = 0; c < assembly.mesh.num_cells(); ++c)
    if (assembly.model_of_cell[c] == CellModel::solid) ++solid_cells[assembly.material_of_cell[c]];
  std::vector<std::string> out;
  for (std::size_t m = 0; m < solid_cells.size(); ++m) {
    const double nu = scene.materials.at(assembly.material_names[m]).poisson;
    if (solid_cells[m] == 0 || nu < locking_poisson) continue;
    char text[640];
    std::snprintf(text, sizeof text,
                  "materials.%s.poisson: nu = %g on %llu solid tetrahedra: linear tetrahedra lock when nearly "
                  "incompressible (lambda/mu = %.3g), so this body is too stiff in bending, and refining does not cure "
                  "it: the 1 m cantilever of scenes/solid_cantilever.json sags 3.0 mm at nu = 0.3, 0.67 mm at 0.49 and "
                  "0.13 mm at 0.4999 (40x4x4 cells: 4.7, 1.7, 0.15 mm) against the continuum's 5.9 mm; use nu < %g",
                  assembly.material_names[m].c_str(), nu, static_cast<unsigned long long>(solid_cells[m]),
                  2 * nu / (1 - 2 * nu), locking_poisson);
    out.emplace_back(text);
  }
  return out;
}

std::vector<std::string> junction_warnings(const Assembly& assembly) {
  // No bending term crosses an edge of three or more shell triangles (shells::triangles_across
  // pairs an edge's two triangles only), and model.connections joins only separate components
  // (connect::detect_connections). Where the sheets around such an edge are still one component
  // (a fin along part of a plate's line), nothing keeps the sheet from folding there: a plate
  // 0.2 x 0.05 m (8 x 4 cells) with a massless fin on 2 of its 4 edges at mid-length sagged 9 %
  // more than without it.
  const MeshConnections found = mesh_connections(assembly.mesh, assembly.model_of_cell);
  if (!found.skipped.empty()) return {};
  std::map<std::pair<std::uint32_t, std::uint32_t>, std::vector<std::uint32_t>> around;  // edge -> mesh cells
  std::vector<std::uint32_t> listed;  // per mesh cell, its index among the simulated cells
  for (std::uint32_t c = 0, k = 0; c < assembly.mesh.num_cells(); ++c) {
    listed.push_back(k);
    if (assembly.model_of_cell[c] == CellModel::label) continue;
    ++k;
    if (assembly.model_of_cell[c] != CellModel::shell || assembly.mesh.types[c] != CellType::triangle) continue;
    const auto v = assembly.mesh.cell(c);
    for (int i = 0; i < 3; ++i) around[std::minmax(v[i], v[(i + 1) % 3])].push_back(c);
  }
  std::uint64_t hinged = 0;
  std::string first;
  for (const auto& [edge, cells] : around) {
    if (cells.size() < 3) continue;
    std::vector<std::uint32_t> comps;
    for (const auto c : cells) comps.push_back(found.found.component_of_cell[listed[c]]);
    std::sort(comps.begin(), comps.end());
    if (std::adjacent_find(comps.begin(), comps.end()) == comps.end()) continue;  // all separate: connections join them
    if (hinged++ > 0) continue;
    const auto at = [&](std::uint32_t p) {
      const auto& x = assembly.mesh.points[p];
      char text[96];
      std::snprintf(text, sizeof text, "(%g, %g, %g)", x[0], x[1], x[2]);
      return std::string(text);
    };
    first = "the edge " + at(edge.first) + " to " + at(edge.second) + " of";
    for (std::size_t k = 0; k < cells.size(); ++k) {
      const MeshSource& source = assembly.sources[assembly.mesh_of_cell(cells[k])];
      first += std::string(k == 0 ? " " : ", ") + source.key + " " + source.cell(assembly.file_cell[cells[k]]);
    }
  }
  if (hinged == 0) return {};
  return {std::to_string(hinged) + " edge(s) shared by 3 or more shell triangles of one sheet (first: " + first +
          "): no bending term crosses such an edge and model.connections joins only separate sheets, so the sheet is "
          "hinged along it (a plate with a fin along half of one cell line sagged 9 % more); run the junction across "
          "the whole sheet, so that it parts the sheet into pieces model.connections joins"};
}

std::vector<std::string> coincidence_warnings(const Assembly& assembly) {
  // A mesh exported with duplicate nodes (a Gmsh file whose rod and shell were meshed apart and
  // never made coherent) leaves bodies that look joined unjoined: a rod hanging from a plate by
  // such a node fell off it, with exit 0. Points of simulated cells closer than 1e-9 of the
  // model's size are reported (generated meshes share their points; cuts come later).
  const IndexedMesh& mesh = assembly.mesh;
  std::vector<std::uint32_t> used;
  std::vector<std::uint8_t> seen(mesh.num_points(), 0);
  for (std::uint32_t c = 0; c < mesh.num_cells(); ++c)
    if (assembly.model_of_cell[c] != CellModel::label)
      for (const auto p : mesh.cell(c))
        if (!seen[p]) {
          seen[p] = 1;
          used.push_back(p);
        }
  if (used.size() < 2) return {};
  Eigen::AlignedBox3d box;
  for (const auto p : used) box.extend(Vec3d(mesh.points[p][0], mesh.points[p][1], mesh.points[p][2]));
  const double tol = 1e-9 * box.diagonal().norm();
  const auto x = [&](std::uint32_t p) { return Vec3d(mesh.points[p][0], mesh.points[p][1], mesh.points[p][2]); };
  // Points binned in cubes of side tol, each compared with the points of the 27 cubes around it:
  // linear in the points (a sweep along x alone compared every pair of a structured grid's plane).
  using Bin = std::array<std::int64_t, 3>;
  const double side = tol > 0 ? tol : 1.0;  // every point at one place: one bin
  const auto bin_of = [&](std::uint32_t p) {
    const Vec3d u = (x(p) - box.min()) / side;  // at most ~1e9 (tol is 1e-9 of the diagonal)
    return Bin{static_cast<std::int64_t>(u.x()), static_cast<std::int64_t>(u.y()), static_cast<std::int64_t>(u.z())};
  };
  const auto bin_hash = [](const Bin& b) {
    return std::hash<std::int64_t>{}(b[0] * 73856093 ^ b[1] * 19349663 ^ b[2] * 83492791);
  };
  std::unordered_map<Bin, std::vector<std::uint32_t>, decltype(bin_hash)> bins(used.size(), bin_hash);
  std::uint64_t pairs = 0;
  std::array<std::uint32_t, 2> first{};
  for (const auto p : used) {  // each pair met once: p against the points binned before it
    const Bin b = bin_of(p);
    for (std::int64_t dx = -1; dx <= 1; ++dx)
      for (std::int64_t dy = -1; dy <= 1; ++dy)
        for (std::int64_t dz = -1; dz <= 1; ++dz) {
          const auto near = bins.find(Bin{b[0] + dx, b[1] + dy, b[2] + dz});
          if (near == bins.end()) continue;
          for (const auto q : near->second)
            if ((x(p) - x(q)).norm() <= tol && pairs++ == 0) first = {std::min(p, q), std::max(p, q)};  // in the meshes' order
        }
    bins[b].push_back(p);
  }
  if (pairs == 0) return {};
  std::string cells;  // a cell of each point of the first pair
  for (const auto p : first)
    for (std::uint32_t c = 0; c < mesh.num_cells(); ++c) {
      const auto v = mesh.cell(c);
      if (assembly.model_of_cell[c] == CellModel::label || std::find(v.begin(), v.end(), p) == v.end()) continue;
      const MeshSource& source = assembly.sources[assembly.mesh_of_cell(c)];
      cells += std::string(cells.empty() ? "" : " and ") + source.key + " " + source.cell(assembly.file_cell[c]) + " (" +
               to_string(assembly.model_of_cell[c]) + ")";
      break;
    }
  char at[96];
  std::snprintf(at, sizeof at, "(%g, %g, %g)", mesh.points[first[0]][0], mesh.points[first[0]][1], mesh.points[first[0]][2]);
  return {std::to_string(pairs) + " pair(s) of distinct mesh points coincide (first: at " + at + ", of " + cells +
          "): cells on coincident points are not joined there (they share no node), so bodies that look attached are "
          "free of each other; if they should be one, merge the duplicate nodes in the mesher (Gmsh: Coherence Mesh), and "
          "put bodies that meet in one mesh file: the scene's meshes never share points"};
}

}  // namespace detail

namespace {

// A policy that altered the cells is said so: the body is not the material's.
void warn_elongation_policies(const RunSummary& sum, const Assembly& assembly) {
  if (sum.clamped_cells > 0)
    std::fprintf(stderr,
                 "sewn: warning: %llu cells are too elongated for Baudet's stiffness and had their negative edge "
                 "stiffnesses clamped to 0 (materials' elongated = \"clamp\"): the body is too stiff in bending, by "
                 "4.8x at 2.5:1, 66x at 5:1 and 860x at 10:1 on a 1 m cantilever (issue 17's measurements); refine "
                 "the mesh towards cubes for a faithful answer\n",
                 static_cast<unsigned long long>(sum.clamped_cells));
  if (assembly.split_cells > 0)
    std::fprintf(stderr,
                 "sewn: warning: %u cells are too elongated for Baudet's stiffness and were split into near-cubes "
                 "(materials' elongated = \"split\"); %u cells were cut in all, those included with the cells sharing "
                 "their split edges: %u cells and %u points now, from %u cells. Stiffnesses are Baudet's own, unaltered: on a 1 m cantilever the static tip is "
                 "the cube-meshed beam's at 10:1 and 5:1 boxes and 3.1 %% softer at 2.5:1 (issue 17). Messages name a piece "
                 "of a split cell as such\n",
                 assembly.split_asked, assembly.split_cells, assembly.mesh.num_cells(), assembly.mesh.num_points(),
                 assembly.source_cells);
}

// "the particle at meshes[1] point 40 of b.msh": particle `i` named by its point, as its file numbers it.
std::string particle_name(const Assembly& assembly, const physics::MssModel<3>& model, Index i) {
  return "the particle at " + assembly.point_name(model.point_of_node(i), true);
}

// The particles `motion` drives (held on every axis from here), none of them in `fixed`.
MotionDriver driven_particles(const Scene& scene, const Assembly& assembly, physics::MssModel<3>& model) {
  std::vector<std::vector<Index>> nodes;
  for (std::size_t k = 0; k < scene.motion.size(); ++k) {
    const std::string path = "motion[" + std::to_string(k) + "].where";
    const std::set<Index> picked = selected_nodes(scene.motion_where[k], assembly, model, scene.file, path);
    for (Index i : picked)
      if (model.nodes().fixed(i) != physics::no_axes)
        throw SceneError(scene.file, path, "selects " + particle_name(assembly, model, i) + ", which `fixed` holds: a particle is either held or driven");
    nodes.emplace_back(picked.begin(), picked.end());
  }
  return MotionDriver(scene.motion, nodes, model.nodes(), scene.file, [&](Index i) { return particle_name(assembly, model, i); });
}

// The fixed particles, the driven ones, then the initial velocities of the free axes.
MotionDriver set_initial_state(const Scene& scene, const Assembly& assembly, physics::MssModel<3>& model) {
  for (std::size_t k = 0; k < scene.fixed.size(); ++k) {
    const FixSpec& fix = scene.fixed[k];
    physics::AxisMask axes = 0;
    if (fix.axes[0]) axes |= physics::axis_x;
    if (fix.axes[1]) axes |= physics::axis_y;
    if (fix.axes[2]) axes |= physics::axis_z;
    for (Index i : selected_nodes(fix.where, assembly, model, scene.file, "fixed[" + std::to_string(k) + "].where"))
      model.nodes().fix(i, axes);
  }
  MotionDriver motion = driven_particles(scene, assembly, model);
  for (std::size_t k = 0; k < scene.velocities.size(); ++k) {
    const VelocitySpec& vel = scene.velocities[k];
    const Vec3d linear(vel.linear[0], vel.linear[1], vel.linear[2]), angular(vel.angular[0], vel.angular[1], vel.angular[2]),
        center(vel.center[0], vel.center[1], vel.center[2]);
    for (Index i : selected_nodes(vel.where, assembly, model, scene.file, "velocities[" + std::to_string(k) + "].where")) {
      Vec3d v = linear + angular.cross(model.rest_position(i) - center);
      // a velocity on a fixed axis would make it kinematic: fixed stays fixed
      for (int a = 0; a < 3; ++a)
        if ((model.nodes().fixed(i) >> a) & 1u) v[a] = 0;
      model.nodes().set_velocity(i, v);
    }
  }
  return motion;
}

// Per node, 1 if a `fixed` entry holds it on all three axes (a shell's clamp, build_continuum).
std::vector<std::uint8_t> held_nodes(const Scene& scene, const Assembly& assembly, const physics::MssModel<3>& model) {
  std::vector<std::uint8_t> held(model.nodes().size(), 0);
  for (std::size_t k = 0; k < scene.fixed.size(); ++k) {
    const FixSpec& fix = scene.fixed[k];
    if (!(fix.axes[0] && fix.axes[1] && fix.axes[2])) continue;
    for (Index i : selected_nodes(fix.where, assembly, model, scene.file, "fixed[" + std::to_string(k) + "].where")) held[i] = 1;
  }
  return held;
}

}  // namespace

namespace detail {

Bodies build_bodies(const Scene& scene, bool quiet, RunSummary& sum) {
  Bodies b;
  b.assembly = assemble(scene);
  Assembly& assembly = b.assembly;
  if (scene.model == "mixed") sum.connections = connections_line(assembly);
  std::vector<physics::MaterialParams> materials = material_params(scene, assembly);
  apply_rod_sections(scene, assembly.mesh, assembly.model_of_cell, assembly.group_of_cell, materials, assembly.material_of_cell);
  try {
    b.model = std::make_unique<physics::MssModel<3>>(assembly.mesh, materials, assembly.material_of_cell, model_options(scene));
  } catch (const physics::CellInputError& e) {
    throw physics::InputError(assembly.in_files(scene.file, e.message()));
  } catch (const MeshCellError& e) {
    throw MeshError(assembly.in_files(scene.file, e.message()));
  }
  physics::MssModel<3>& model = *b.model;
  add_obstacles(model.system(), scene.obstacles);
  sum.clamped_cells = static_cast<std::uint64_t>(
      std::count_if(model.elements().begin(), model.elements().end(), [](const auto& e) { return e.alive && e.clamped; }));
  sum.split_cells = assembly.split_cells;
  if (!quiet) warn_elongation_policies(sum, assembly);

  // The continuum models (solids, shells, rods) and the volume term join or replace the springs.
  if (scene.model != "mass-spring") try {
      b.continuum = build_continuum(scene, materials, assembly.mesh, assembly.model_of_cell, assembly.group_of_cell, model,
                                    held_nodes(scene, assembly, model));
    } catch (const physics::CellInputError& e) {
      throw physics::InputError(assembly.in_files(scene.file, e.message()));
    }
  // the rotational energies where the bodies meet (model.connections), on the rest state
  if (scene.model != "mass-spring")
    b.joints = build_connections(scene, assembly.mesh, assembly.model_of_cell, materials, b.continuum, model,
                                 [&](std::uint32_t p) { return assembly.point_name(p, true); });
  // Rods whose twist no joint turns keep it quasi-static; under Newton it joins the linear system
  // condensed, so each Newton step is the reduced energy's exact one (docs/rods.md).
  if (b.continuum.rods && !b.continuum.rods->has_angle_dofs() && scene.integrator == "newton")
    b.continuum.rods->condense_twist(model.system().angles());
  sum.connection_energies = connection_energies_text(b.joints);
  sum.model_warnings = locking_warnings(scene, assembly);
  for (auto& w : junction_warnings(assembly)) sum.model_warnings.push_back(std::move(w));
  for (auto& w : coincidence_warnings(assembly)) sum.model_warnings.push_back(std::move(w));
  add_volume_term(scene, assembly.material_names, model);

  b.motion = set_initial_state(scene, assembly, model);
  for (auto& w : obstacle_start_warnings(model.nodes().x(), scene.obstacles)) sum.model_warnings.push_back(std::move(w));
  if (!quiet)
    for (const auto& w : sum.model_warnings) std::fprintf(stderr, "sewn: warning: %s\n", w.c_str());
  if (scene.refinement.enabled) b.refinement = std::make_unique<RefinementRun>(scene, model);
  return b;
}

}  // namespace detail

}  // namespace sewn::app
