#include "sewn/apps/cell_models.hpp"

#include <algorithm>
#include <map>
#include <numeric>
#include <string>

#include "sewn/io/cleanup.hpp"

namespace sewn::app {

namespace {

// The cell type a model takes, and how the scene's documentation calls that kind of mesh.
CellType cell_type_of(CellModel m) {
  switch (m) {
    case CellModel::solid: return CellType::tetrahedron;
    case CellModel::shell: return CellType::triangle;
    default: return CellType::segment;
  }
}

const char* plural(CellType t) {
  switch (t) {
    case CellType::tetrahedron: return "tetrahedra";
    case CellType::triangle: return "triangles";
    default: return "segments";
  }
}

CellModel parse_model(const std::string& s) {
  if (s == "solid") return CellModel::solid;
  if (s == "shell") return CellModel::shell;
  if (s == "rod") return CellModel::rod;
  if (s == "label") return CellModel::label;
  return CellModel::mass_spring;
}

// model.type's choice for a cell that no group names.
CellModel default_model(const std::string& type, CellType t) {
  if (type == "mixed") return cell_dimension(t) == 3 ? CellModel::solid : cell_dimension(t) == 2 ? CellModel::shell : CellModel::rod;
  return parse_model(type);
}

std::uint32_t find_root(std::vector<std::uint32_t>& parent, std::uint32_t x) {
  while (parent[x] != x) x = parent[x] = parent[parent[x]];
  return x;
}

}  // namespace

const char* to_string(CellModel m) {
  switch (m) {
    case CellModel::label: return "label";
    case CellModel::mass_spring: return "mass-spring";
    case CellModel::solid: return "solid";
    case CellModel::shell: return "shell";
    case CellModel::rod: return "rod";
  }
  return "?";
}

GroupMatch match_groups(const IndexedMesh& mesh, const MeshNames& names, const Scene& scene) {
  // each entry's tags in this mesh: its number, or what this file calls its name
  std::vector<std::vector<std::int32_t>> tags(scene.model_groups.size());
  for (std::size_t k = 0; k < scene.model_groups.size(); ++k) {
    const ModelGroup& g = scene.model_groups[k];
    if (g.name.empty()) tags[k].push_back(g.tag);
    for (const io::TagName& n : names.names)
      if (!g.name.empty() && n.name == g.name) tags[k].push_back(n.tag);
  }
  GroupMatch out;
  out.of_cell.assign(mesh.num_cells(), -1);
  out.named_a_cell.assign(scene.model_groups.size(), false);
  for (std::uint32_t c = 0; c < mesh.num_cells(); ++c)
    for (std::size_t k = 0; k < tags.size(); ++k)
      if (std::find(tags[k].begin(), tags[k].end(), mesh.tags[c]) != tags[k].end()) {
        out.of_cell[c] = static_cast<int>(k);
        out.named_a_cell[k] = true;
      }
  return out;
}

std::string MeshSource::cell(std::uint32_t c) const {
  return "cell " + std::to_string(c) + (element_tags.empty() ? "" : " (Gmsh element " + std::to_string(element_tags[c]) + ")") +
         (file.empty() ? "" : " of " + file);
}

std::string MeshSource::point(std::uint32_t p) const {
  return "point " + (point_numbers.empty() ? std::to_string(p) : std::to_string(point_numbers[p])) + (file.empty() ? "" : " of " + file);
}

IndexedMesh used_part(const io::MeshFile& file, io::GeometryOptions& numbering) {
  IndexedMesh m = file.mesh;
  const std::vector<std::uint32_t> new_index = io::drop_unused_points(m);
  numbering.point_numbers.assign(m.num_points(), 0);
  for (std::uint32_t p = 0; p < new_index.size(); ++p)
    if (new_index[p] != 0xffffffffu) numbering.point_numbers[new_index[p]] = file.point_number(p);
  numbering.element_tags = file.element_tags;
  return m;
}

std::vector<CellModel> cell_models(const IndexedMesh& mesh, const std::vector<bool>& embedded, const Scene& scene,
                                   const std::string& path) {
  return cell_models(mesh, embedded, scene, MeshSource{path, "", {}, {}}, match_groups(mesh, MeshNames{}, scene).of_cell);
}

std::vector<CellModel> cell_models(const IndexedMesh& mesh, const std::vector<bool>& embedded, const Scene& scene,
                                   const MeshSource& source, const std::vector<int>& groups) {
  std::vector<CellModel> out(mesh.num_cells());
  for (std::uint32_t c = 0; c < mesh.num_cells(); ++c) {
    const CellType t = mesh.types[c];
    const int group = groups[c];
    const bool by_group = group >= 0;
    const CellModel m = by_group ? parse_model(scene.model_groups[static_cast<std::size_t>(group)].as)
                        : embedded[c] ? CellModel::label
                                      : default_model(scene.model, t);
    out[c] = m;
    if (m == CellModel::label || m == CellModel::mass_spring || t == cell_type_of(m)) continue;
    const std::string where = source.key + " " + source.cell(c) + ", of tag " + std::to_string(mesh.tags[c]) + ", is a " + to_string(t);
    if (by_group)
      throw SceneError(scene.file, "model.groups[" + std::to_string(group) + "].as",
                       "\"" + std::string(to_string(m)) + "\" takes " + plural(cell_type_of(m)) + " only, but " + where);
    const std::string hint = m == CellModel::solid ? " (use a tet_grid or a tetrahedral mesh file)"
                             : m == CellModel::shell ? " (use a tri_grid or a triangle mesh file)"
                                                     : " (segments only)";
    throw SceneError(scene.file, "model.type", "\"" + scene.model + "\" needs " + plural(cell_type_of(m)) + " only, but " + where +
                                                  (scene.model == "mixed" ? "; name its tag in model.groups" : hint));
  }
  return out;
}

namespace {

// Why no cell answers to the physical name `name`: the groups of that name that have no cell,
// or, when no mesh declares it, what each mesh does declare.
std::string unused_name_reason(const std::string& name, const std::vector<MeshNames>& meshes) {
  std::string declared, available, numbers_only;
  std::size_t unnamed = 0;
  for (const MeshNames& m : meshes) {
    std::string list;
    for (const io::TagName& n : m.names) {
      const std::string one = "\"" + n.name + "\" (tag " + std::to_string(n.tag) + ", dimension " + std::to_string(n.dimension) + ")";
      list += (list.empty() ? "" : ", ") + one;
      if (n.name == name) declared += (declared.empty() ? "" : ", ") + m.path + "'s " + one;
    }
    if (!list.empty())
      available += (available.empty() ? "" : "; ") + m.path + " (" + m.format + "): " + list;
    else
      numbers_only += (unnamed++ == 0 ? "" : ", ") + m.path + " (" + m.format + ")";
  }
  if (!declared.empty())
    return "the physical group \"" + name + "\" has no cell: " + declared + " (0-dimensional groups hold points, which are not simulated cells)";
  std::string reason = "no mesh declares a physical name \"" + name + "\"; ";
  reason += available.empty() ? "no mesh of the scene has physical names" : "the physical names are: " + available;
  if (!numbers_only.empty())
    reason += "; " + numbers_only + (unnamed > 1 ? " have" : " has") +
              " numeric tags only (MEDIT references, generated meshes): select their cells with \"tag\"";
  return reason;
}

}  // namespace

void check_groups_used(const Scene& scene, const std::vector<bool>& named_a_cell, const std::vector<MeshNames>& meshes) {
  for (std::size_t k = 0; k < scene.model_groups.size(); ++k) {
    if (named_a_cell[k]) continue;
    const ModelGroup& g = scene.model_groups[k];
    const std::string key = "model.groups[" + std::to_string(k) + "]";
    if (g.name.empty()) throw SceneError(scene.file, key + ".tag", "no cell of any mesh carries tag " + std::to_string(g.tag));
    throw SceneError(scene.file, key + ".name", unused_name_reason(g.name, meshes));
  }
}

SimulatedComplex simulated_complex(const IndexedMesh& mesh, const std::vector<CellModel>& models) {
  SimulatedComplex out;
  std::vector<std::uint32_t> parent(mesh.num_points());
  std::iota(parent.begin(), parent.end(), 0u);
  std::vector<bool> used(mesh.num_points(), false);
  std::map<std::pair<std::int32_t, int>, std::uint32_t> labels;
  for (std::uint32_t c = 0; c < mesh.num_cells(); ++c) {
    const int dim = cell_dimension(mesh.types[c]);
    if (models[c] == CellModel::label) {
      ++labels[{mesh.tags[c], dim}];
      continue;
    }
    ++out.cells[static_cast<std::size_t>(dim)];
    const auto v = mesh.cell(c);
    for (std::uint32_t p : v) used[p] = true;
    for (std::size_t k = 1; k < v.size(); ++k) parent[find_root(parent, v[k])] = find_root(parent, v[0]);
  }
  for (std::uint32_t p = 0; p < mesh.num_points(); ++p) {
    if (!used[p]) continue;
    ++out.points;
    if (find_root(parent, p) == p) ++out.components;
  }
  for (const auto& [key, n] : labels) out.labels.push_back({key.first, key.second, n});
  return out;
}

MeshConnections mesh_connections(const IndexedMesh& mesh, const std::vector<CellModel>& models, const std::vector<std::uint32_t>& chain) {
  MeshConnections out;
  connect::CellList cells;
  for (std::uint32_t c = 0; c < mesh.num_cells(); ++c) {
    if (models[c] == CellModel::label) continue;
    const CellType t = mesh.types[c];
    if (t != CellType::segment && t != CellType::triangle && t != CellType::tetrahedron) {
      out.skipped = "cell " + std::to_string(c) + " is not a segment, triangle or tetrahedron";
      return out;
    }
    cells.add(t == CellType::segment ? connect::Body::rod : t == CellType::triangle ? connect::Body::shell : connect::Body::solid,
              mesh.cell(c), chain.empty() ? 0 : chain[c]);
  }
  out.found = connect::detect_connections(cells);
  return out;
}

nlohmann::json connections_json(const MeshConnections& c) {
  if (!c.skipped.empty()) return {{"skipped", c.skipped}};
  nlohmann::json j = nlohmann::json::object();
  for (int k = 0; k < 3; ++k) {
    nlohmann::json per = nlohmann::json::object();
    for (int p = 0; p < connect::num_body_pairs; ++p)
      if (const auto n = c.found.counts[static_cast<std::size_t>(k)][static_cast<std::size_t>(p)]) per[connect::body_pair_name(p)] = n;
    j[connect::to_string(static_cast<connect::ConnectionKind>(k))] = per;
  }
  j["components"] = c.found.component_body.size();
  return j;
}

}  // namespace sewn::app
