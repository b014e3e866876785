#include "run_output.hpp"

#include <unistd.h>

#include <algorithm>
#include <array>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <limits>
#include <map>
#include <set>
#include <span>

#include "sewn/io/render.hpp"
#include "sewn/refine/hierarchy.hpp"

namespace sewn::app::detail {

namespace {

using physics::ElementKind;
using physics::Index;
using Vec3d = Eigen::Vector3d;

CellType cell_type(ElementKind k) {
  switch (k) {
    case ElementKind::hexahedron: return CellType::hexahedron;
    case ElementKind::tetrahedron: return CellType::tetrahedron;
    case ElementKind::quad: return CellType::quad;
    case ElementKind::triangle: return CellType::triangle;
    case ElementKind::segment: return CellType::segment;
  }
  return CellType::segment;
}

}  // namespace

void Snapshot::take(const physics::MssModel<3>& m) {
  *this = Snapshot{};
  const auto& n = m.nodes();
  for (Index i = 0; i < n.size(); ++i) {
    // a slot a coarsening emptied keeps its place (cells index points by slot), inert at rest
    const bool alive = n.is_alive(i);
    const Vec3d x = alive ? n.position(i) : m.rest_position(i), v = alive ? n.velocity(i) : Vec3d::Zero(),
                f = alive ? n.force(i) : Vec3d::Zero(), u = x - m.rest_position(i);
    points.push_back({x.x(), x.y(), x.z()});
    velocity.push_back({v.x(), v.y(), v.z()});
    force.push_back({f.x(), f.y(), f.z()});
    displacement.push_back({u.x(), u.y(), u.z()});
    speed.push_back(v.norm());
    force_norm.push_back(f.norm());
    displacement_norm.push_back(u.norm());
    fixed.push_back(alive ? n.fixed(i) : physics::no_axes);
    fixed_scalar.push_back(alive && n.fixed(i) ? 1.0 : 0.0);
    material_scalar.push_back(0.0);
    level_scalar.push_back(1.0);  // a root's level index; points of no live element keep it
  }
  for (Index e = 0; e < m.elements().size(); ++e) {
    const auto& el = m.elements()[e];
    if (!el.alive) continue;
    types.push_back(cell_type(el.kind));
    const int index = refine::level_index(el.level);
    for (Index q : m.element_nodes(e)) {
      conn.push_back(q);
      material_scalar[q] = el.material;
      level_scalar[q] = std::max(level_scalar[q], static_cast<double>(index));
    }
    offsets.push_back(static_cast<std::uint32_t>(conn.size()));
    material.push_back(static_cast<std::int32_t>(el.material));
    level.push_back(index);
    mesh_cell.push_back(static_cast<std::int32_t>(el.mesh_cell));
    element.push_back(e);
  }
}

void Snapshot::rods_as_poly_lines(const ContinuumParts& parts, const RodOutput& rods) {
  if (rods.chains.empty()) return;
  // each rod's first live segment: its cell's material and level go to the rod's poly-line
  std::vector<std::size_t> first_cell(rods.chains.size(), types.size());
  std::vector<int> first_edge(rods.chains.size(), std::numeric_limits<int>::max());
  Snapshot kept;
  kept.offsets = {0};
  for (std::size_t c = 0; c < types.size(); ++c) {
    const auto [r, edge] = element[c] < parts.rod_edge_of_element.size() ? parts.rod_edge_of_element[element[c]]
                                                                          : std::pair<Index, int>{physics::invalid_index, 0};
    if (r != physics::invalid_index) {
      if (edge < first_edge[r]) first_edge[r] = edge, first_cell[r] = c;
      continue;
    }
    kept.types.push_back(types[c]);
    kept.conn.insert(kept.conn.end(), conn.begin() + offsets[c], conn.begin() + offsets[c + 1]);
    kept.offsets.push_back(static_cast<std::uint32_t>(kept.conn.size()));
    kept.material.push_back(material[c]);
    kept.level.push_back(level[c]);
    kept.mesh_cell.push_back(mesh_cell[c]);
    kept.element.push_back(element[c]);
  }
  kept.poly_line.assign(kept.types.size(), 0);
  for (std::size_t r = 0; r < rods.chains.size(); ++r) {
    if (first_cell[r] == types.size()) continue;  // no live segment
    kept.types.push_back(CellType::segment);
    kept.conn.insert(kept.conn.end(), rods.chains[r].begin(), rods.chains[r].end());
    kept.offsets.push_back(static_cast<std::uint32_t>(kept.conn.size()));
    kept.material.push_back(material[first_cell[r]]);
    kept.level.push_back(level[first_cell[r]]);
    kept.mesh_cell.push_back(-1);
    kept.element.push_back(element[first_cell[r]]);
    kept.poly_line.push_back(1);
  }
  types = std::move(kept.types);
  offsets = std::move(kept.offsets);
  conn = std::move(kept.conn);
  material = std::move(kept.material);
  level = std::move(kept.level);
  mesh_cell = std::move(kept.mesh_cell);
  element = std::move(kept.element);
  poly_line = std::move(kept.poly_line);
}

void prepare_output(const std::filesystem::path& dir) {
  for (const auto& part : dir)
    if (part.native().size() > 255)
      throw OutputPathError(dir, "a folder name of " + std::to_string(part.native().size()) +
                                     " bytes is longer than file systems allow (255)");
  std::error_code ec;
  const auto status = std::filesystem::status(dir, ec);
  if (std::filesystem::exists(status) && !std::filesystem::is_directory(status))
    throw OutputPathError(dir, "exists and is not a folder");
  std::filesystem::create_directories(dir, ec);
  if (ec == std::errc::not_a_directory || ec == std::errc::file_exists || ec == std::errc::filename_too_long)
    throw OutputPathError(dir, "cannot be created: " + ec.message());
  if (ec) throw OutputError(dir, "cannot be created: " + ec.message());
  if (::access(dir.c_str(), W_OK | X_OK) != 0) throw OutputError(dir, std::string("cannot be written: ") + std::strerror(errno));
}

std::string frame_file(std::uint32_t frame) {
  char name[32];
  std::snprintf(name, sizeof name, "frame_%05u.vtu", frame);
  return name;
}

namespace {

// A face as its sorted points (through `point`), padded: a set key.
template <class F>
std::array<std::uint32_t, 4> face_key(std::span<const std::uint32_t> face, F&& point) {
  std::array<std::uint32_t, 4> k;
  k.fill(std::numeric_limits<std::uint32_t>::max());
  for (std::size_t i = 0; i < face.size() && i < 4; ++i) k[i] = point(face[i]);
  std::sort(k.begin(), k.end());
  return k;
}

// Faces shared by two volume cells of a mesh.
std::set<std::array<std::uint32_t, 4>> interior_faces(const IndexedMesh& m) {
  std::map<std::array<std::uint32_t, 4>, int> count;
  for (std::uint32_t c = 0; c < m.num_cells(); ++c) {
    const auto v = m.cell(c);
    for (const auto& f : cell_faces(m.types[c])) {
      std::array<std::uint32_t, 4> pts{};
      for (std::size_t i = 0; i < f.size(); ++i) pts[i] = v[f[i]];
      ++count[face_key(std::span<const std::uint32_t>(pts.data(), f.size()), [](std::uint32_t q) { return q; })];
    }
  }
  std::set<std::array<std::uint32_t, 4>> out;
  for (const auto& [k, n] : count)
    if (n == 2) out.insert(k);
  return out;
}

}  // namespace

std::filesystem::path write_picture(const Scene& scene, double simulated, const std::filesystem::path& out, const IndexedMesh& mesh,
                                    const physics::MssModel<3>& model, Snapshot& snap) {
  snap.take(model);
  const std::vector<double>* scalar = &snap.displacement_norm;
  std::string label = "|displacement| [m]";
  if (scene.color_by == "speed") scalar = &snap.speed, label = "speed [m/s]";
  if (scene.color_by == "force") scalar = &snap.force_norm, label = "|force| [N]";
  if (scene.color_by == "fixed") scalar = &snap.fixed_scalar, label = "fixed";
  if (scene.color_by == "material") scalar = &snap.material_scalar, label = "material";
  if (scene.color_by == "level") scalar = &snap.level_scalar, label = "refinement level";
  io::RenderOptions ro;
  ro.width = static_cast<int>(scene.width);
  ro.height = static_cast<int>(scene.height);
  ro.mode = scene.style == "wireframe" ? io::RenderMode::wireframe : io::RenderMode::shaded;
  char title[160];
  std::snprintf(title, sizeof title, "%s, t = %.3g s", scene.name.c_str(), simulated);
  ro.title = title;
  ro.scalar_name = label;
  // Faces a cut opened: boundary faces now, whose particles stand for the points of a face
  // that two volumes shared in the original mesh (the paper draws them red).
  const auto interior = interior_faces(mesh);
  if (!interior.empty())
    ro.highlight = [&](std::span<const std::uint32_t> face) {
      return interior.count(face_key(face, [&](std::uint32_t q) { return model.point_of_node(q); })) > 0;
    };
  const std::filesystem::path picture = out / (scene.name + ".png");
  writing([&] { io::render_png(picture, snap.points, snap.cells(), *scalar, ro); });
  return picture;
}

}  // namespace sewn::app::detail
