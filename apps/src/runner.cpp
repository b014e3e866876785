#include "sewn/apps/runner.hpp"

#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <memory>
#include <limits>
#include <map>
#include <set>

#include "sewn/io/cleanup.hpp"
#include "sewn/io/geometry.hpp"
#include "sewn/io/read.hpp"
#include "sewn/io/render.hpp"
#include "sewn/io/write.hpp"
#include "sewn/physics/integrators.hpp"
#include "sewn/physics/mss_model.hpp"
#include "sewn/refine/cut.hpp"

namespace sewn::app {

namespace {

using physics::ElementKind;
using physics::Index;
using Vec3d = Eigen::Vector3d;
using Clock = std::chrono::steady_clock;

Vec3 to_vec3(const Vec3d& p) { return {p.x(), p.y(), p.z()}; }

Vec3 cell_centroid(const IndexedMesh& m, std::uint32_t c) {
  Vec3 s{0, 0, 0};
  const auto v = m.cell(c);
  for (std::uint32_t q : v)
    for (int k = 0; k < 3; ++k) s[static_cast<std::size_t>(k)] += m.points[q][static_cast<std::size_t>(k)] / static_cast<double>(v.size());
  return s;
}

// Does the selector pick cell c of mesh m (by centroid, tag, or all its points)?
bool selects_cell(const Selector& s, const IndexedMesh& m, std::uint32_t c) {
  switch (s.type) {
    case Selector::Type::tag: return m.tags[c] == s.tag;
    case Selector::Type::points: {
      for (std::uint32_t q : m.cell(c))
        if (std::find(s.points.begin(), s.points.end(), q) == s.points.end()) return false;
      return true;
    }
    default: return s.contains(cell_centroid(m, c));
  }
}

IndexedMesh generate(const MeshSpec& spec, const std::string& file, const std::string& path) {
  IndexedMesh m;
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
  } else if (spec.type == "file") {
    m = io::read_mesh(spec.path);
    // Gmsh and MEDIT files saved without physical groups repeat the faces and edges of volumes
    // as cells of their own; built as read they would become shells glued onto the solid.
    io::drop_embedded_cells(m);
    io::drop_unused_points(m);
    transform(m, spec.scale, spec.translate);
    io::check_mesh_geometry(m, spec.path);
  }
  return m;
}

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

// The current state as a mesh of the live elements, for writing and drawing.
struct Snapshot {
  std::vector<Point3> points, velocity, force, displacement;
  std::vector<double> speed, force_norm, displacement_norm, fixed_scalar, material_scalar;
  std::vector<std::uint8_t> fixed;
  std::vector<CellType> types;
  std::vector<std::uint32_t> offsets{0}, conn;
  std::vector<std::int32_t> material, level, mesh_cell;

  void take(const physics::MssModel<3>& m) {
    *this = Snapshot{};
    const auto& n = m.nodes();
    for (Index i = 0; i < n.size(); ++i) {
      const Vec3d x = n.position(i), v = n.velocity(i), f = n.force(i), u = x - m.rest_position(i);
      points.push_back({x.x(), x.y(), x.z()});
      velocity.push_back({v.x(), v.y(), v.z()});
      force.push_back({f.x(), f.y(), f.z()});
      displacement.push_back({u.x(), u.y(), u.z()});
      speed.push_back(v.norm());
      force_norm.push_back(f.norm());
      displacement_norm.push_back(u.norm());
      fixed.push_back(n.fixed(i));
      fixed_scalar.push_back(n.fixed(i) ? 1.0 : 0.0);
      material_scalar.push_back(0.0);
    }
    for (Index e = 0; e < m.elements().size(); ++e) {
      const auto& el = m.elements()[e];
      if (!el.alive) continue;
      types.push_back(cell_type(el.kind));
      for (Index q : m.element_nodes(e)) {
        conn.push_back(q);
        material_scalar[q] = el.material;
      }
      offsets.push_back(static_cast<std::uint32_t>(conn.size()));
      material.push_back(static_cast<std::int32_t>(el.material));
      level.push_back(0);  // refinement level: every element is a root element until refinement lands
      mesh_cell.push_back(static_cast<std::int32_t>(el.mesh_cell));
    }
  }
  [[nodiscard]] io::CellsView cells() const { return {types, offsets, conn}; }
};

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

std::string format_seconds(double s) {
  char buf[32];
  if (s < 60)
    std::snprintf(buf, sizeof buf, "%.0f s", s);
  else
    std::snprintf(buf, sizeof buf, "%d min %02d s", static_cast<int>(s / 60), static_cast<int>(s) % 60);
  return buf;
}

}  // namespace

Assembly assemble(const Scene& scene) {
  Assembly a;
  for (const auto& [name, _] : scene.materials) a.material_names.push_back(name);
  auto material_index = [&](const std::string& name) {
    return static_cast<std::uint32_t>(std::find(a.material_names.begin(), a.material_names.end(), name) - a.material_names.begin());
  };
  for (std::size_t i = 0; i < scene.meshes.size(); ++i) {
    const MeshSpec& spec = scene.meshes[i];
    const std::string path = "meshes[" + std::to_string(i) + "]";
    IndexedMesh piece = generate(spec, scene.file, path);
    if (piece.num_cells() == 0) throw SceneError(scene.file, path, "the mesh has no cell");
    a.first_cell.push_back(a.mesh.num_cells());
    std::vector<std::uint32_t> mat(piece.num_cells(), material_index(spec.material));
    for (const auto& [where, name] : spec.regions)
      for (std::uint32_t c = 0; c < piece.num_cells(); ++c)
        if (selects_cell(where, piece, c)) mat[c] = material_index(name);
    append(a.mesh, piece);
    a.material_of_cell.insert(a.material_of_cell.end(), mat.begin(), mat.end());
  }
  return a;
}

RunSummary run(const Scene& scene, const RunOptions& options) {
  // 1) the bodies and the model
  const Assembly assembly = assemble(scene);
  std::vector<physics::MaterialParams> materials;
  for (const auto& name : assembly.material_names) {
    const MaterialSpec& ms = scene.materials.at(name);
    materials.push_back({ms.young, ms.poisson, ms.density, ms.thickness, ms.area,
                         ms.clamp_elongated ? physics::ElongatedPolicy::clamp : physics::ElongatedPolicy::refuse});
  }
  physics::MssOptions mo;
  mo.gravity = Vec3d(scene.gravity[0], scene.gravity[1], scene.gravity[2]);
  mo.damping = scene.damping == "viscous" ? physics::DampingModel::viscous
               : scene.damping == "rayleigh" ? physics::DampingModel::rayleigh
                                             : physics::DampingModel::none;
  mo.rayleigh_alpha = scene.rayleigh_alpha;
  mo.rayleigh_beta = scene.rayleigh_beta;
  mo.environment = scene.environment_damping;
  mo.source = scene.file;
  auto model = std::make_unique<physics::MssModel<3>>(assembly.mesh, materials, assembly.material_of_cell, mo);
  add_obstacles(model->system(), scene.obstacles);

  // 2) fixed particles
  const IndexedMesh& mesh = assembly.mesh;
  for (std::size_t k = 0; k < scene.fixed.size(); ++k) {
    const FixSpec& fix = scene.fixed[k];
    physics::AxisMask axes = 0;
    if (fix.axes[0]) axes |= physics::axis_x;
    if (fix.axes[1]) axes |= physics::axis_y;
    if (fix.axes[2]) axes |= physics::axis_z;
    std::set<Index> nodes;
    if (fix.where.type == Selector::Type::tag) {
      for (std::uint32_t c = 0; c < mesh.num_cells(); ++c)
        if (mesh.tags[c] == fix.where.tag)
          for (std::uint32_t q : mesh.cell(c)) nodes.insert(model->node_of_point(q));
    } else if (fix.where.type == Selector::Type::points) {
      for (std::uint32_t q : fix.where.points) {
        if (q >= mesh.num_points() || model->node_of_point(q) == physics::invalid_index)
          throw SceneError(scene.file, "fixed[" + std::to_string(k) + "].where.indices",
                           "point " + std::to_string(q) + " is not a point of any cell (" + std::to_string(mesh.num_points()) + " points)");
        nodes.insert(model->node_of_point(q));
      }
    } else {
      for (Index i = 0; i < model->nodes().size(); ++i)
        if (fix.where.contains(to_vec3(model->rest_position(i)))) nodes.insert(i);
    }
    if (nodes.empty()) throw SceneError(scene.file, "fixed[" + std::to_string(k) + "].where", "selects no particle");
    for (Index i : nodes) model->nodes().fix(i, axes);
  }

  // 3) time line: steps, frames and scheduled cuts
  const double h = scene.step;
  const double end = std::min(scene.duration, options.until.value_or(scene.duration));
  const auto steps = static_cast<std::uint64_t>(std::ceil(end / h - 1e-9));
  const std::uint32_t frames = options.frames.value_or(scene.frames);
  std::vector<std::pair<double, std::size_t>> cuts;  // (time, index) in time order
  for (std::size_t k = 0; k < scene.cuts.size(); ++k) cuts.emplace_back(scene.cuts[k].time, k);
  std::stable_sort(cuts.begin(), cuts.end());

  // 4) outputs
  RunSummary sum;
  sum.out = options.out.empty() ? std::filesystem::path("out") / scene.name : options.out;
  std::filesystem::create_directories(sum.out);
  Snapshot snap;
  std::unique_ptr<io::PvdWriter> pvd;
  if (scene.write_vtu) {
    sum.pvd = sum.out / (scene.name + ".pvd");
    pvd = std::make_unique<io::PvdWriter>(sum.pvd);
  }
  std::unique_ptr<io::CsvWriter> csv;
  if (scene.write_csv) {
    sum.csv = sum.out / "frames.csv";
    csv = std::make_unique<io::CsvWriter>(
        sum.csv, std::vector<std::string>{"frame", "time", "kinetic_energy", "potential_energy", "elastic_energy",
                                          "particles", "springs", "elements", "steps", "ms_per_step",
                                          "cg_iterations_mean", "cg_iterations_max", "cuts", "faces_cut"});
  }
  std::uint32_t frame = 0;
  double frame_ms = 0, frame_cg_sum = 0;
  int frame_cg_max = 0;
  std::uint64_t frame_steps = 0;
  auto write_frame = [&](double t) {
    physics::System& sys = model->system();
    sys.compute_forces();
    if (pvd) {
      snap.take(*model);
      char name[32];
      std::snprintf(name, sizeof name, "frame_%05u.vtu", frame);
      const io::DataArray point_data[] = {
          io::DataArray::vectors("velocity", snap.velocity), io::DataArray::vectors("force", snap.force),
          io::DataArray::vectors("displacement", snap.displacement), io::DataArray::flags("fixed", snap.fixed)};
      const io::DataArray cell_data[] = {io::DataArray::ints("material", snap.material),
                                         io::DataArray::ints("refinement_level", snap.level),
                                         io::DataArray::ints("mesh_cell", snap.mesh_cell)};
      io::write_vtu(sum.out / name, snap.points, snap.cells(), point_data, cell_data);
      pvd->add(t, sum.out / name);
    }
    if (csv) {
      const auto elements = std::count_if(model->elements().begin(), model->elements().end(), [](const auto& e) { return e.alive; });
      csv->row({static_cast<double>(frame), t, sys.kinetic_energy(), sys.potential_energy(),
                sys.potential_energy(physics::EnergyKind::internal), static_cast<double>(model->nodes().num_alive()),
                static_cast<double>(model->springs().num_alive()), static_cast<double>(elements),
                static_cast<double>(frame_steps), frame_steps ? frame_ms / static_cast<double>(frame_steps) : 0.0,
                frame_steps ? frame_cg_sum / static_cast<double>(frame_steps) : 0.0, static_cast<double>(frame_cg_max),
                static_cast<double>(sum.cuts), static_cast<double>(sum.faces_cut)});
    }
    ++frame;
    frame_ms = frame_cg_sum = 0;
    frame_cg_max = 0;
    frame_steps = 0;
  };

  // 5) stepping
  physics::SymplecticEulerOptions so;
  so.enforce_stable_step = !scene.allow_unstable;
  physics::ImplicitEulerOptions io_opt;
  io_opt.cg_tolerance = scene.tolerance;
  io_opt.cg_max_iterations = static_cast<int>(scene.max_iterations);
  physics::SymplecticEuler semi(so);
  physics::LinearlyImplicitEuler implicit(io_opt);
  const bool use_implicit = scene.integrator == "implicit";
  const bool bar = !options.quiet && options.progress && isatty(STDERR_FILENO);
  sum.kinetic_start = model->system().kinetic_energy();
  write_frame(0.0);
  std::size_t next_cut = 0;
  const auto started = Clock::now();
  auto last_bar = started;
  for (std::uint64_t s = 0; s < steps; ++s) {
    const double t = static_cast<double>(s) * h;
    const auto t0 = Clock::now();
    for (; next_cut < cuts.size() && cuts[next_cut].first <= t + 1e-12 * h; ++next_cut) {
      const std::size_t k = cuts[next_cut].second;
      const CutSpec& c = scene.cuts[k];
      const std::string path = "cuts[" + std::to_string(k) + "]";
      refine::CutReport rep;
      if (c.type == "plane") {
        refine::Region within;
        if (c.within) within = [sel = *c.within](const Vec3d& p) { return sel.contains(to_vec3(p)); };
        const auto facets = refine::facets_across_plane(*model, Vec3d(c.point[0], c.point[1], c.point[2]),
                                                        Vec3d(c.normal[0], c.normal[1], c.normal[2]), within);
        if (facets.empty()) throw SceneError(scene.file, path, "the plane crosses no face between two elements (at its time)");
        rep = refine::cut(*model, facets);
      } else if (c.type == "faces") {
        std::vector<refine::Facet> facets;
        try {
          facets = refine::facets_with_points(*model, c.faces);
        } catch (const physics::InputError& e) {
          throw SceneError(scene.file, path + ".faces", e.what());
        }
        rep = refine::cut(*model, facets);
      } else if (c.type == "particles") {
        const auto facets = refine::facets_among_points(*model, c.particles);
        if (facets.empty()) throw SceneError(scene.file, path + ".particles", "no face between two elements has all its points among them");
        rep = refine::cut(*model, facets);
      } else if (c.type == "pierce") {
        std::vector<Index> elements;
        for (Index e = 0; e < model->elements().size(); ++e) {
          const auto& el = model->elements()[e];
          if (el.alive && selects_cell(c.where, mesh, el.mesh_cell)) elements.push_back(e);
        }
        if (elements.empty()) throw SceneError(scene.file, path + ".where", "selects no element (at its time)");
        rep = refine::pierce(*model, elements, c.remove);
      }
      sum.faces_cut += rep.facets;
      ++sum.cuts;
    }
    int cg = 0;
    if (use_implicit)
      cg = implicit.step(model->system(), h).cg_iterations;
    else
      (void)semi.step(model->system(), h);
    const double ms = std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
    frame_ms += ms;
    frame_cg_sum += cg;
    frame_cg_max = std::max(frame_cg_max, cg);
    ++frame_steps;
    sum.kinetic_max = std::max(sum.kinetic_max, model->system().kinetic_energy());
    // frame f is written after step round(f · steps / frames)
    const auto due = static_cast<std::uint64_t>(std::llround(static_cast<double>(frame) * static_cast<double>(steps) / frames));
    if (s + 1 >= due && frame <= frames) write_frame(static_cast<double>(s + 1) * h);
    if (bar && (Clock::now() - last_bar > std::chrono::milliseconds(100) || s + 1 == steps)) {
      last_bar = Clock::now();
      const double elapsed = std::chrono::duration<double>(last_bar - started).count();
      const double done = static_cast<double>(s + 1) / static_cast<double>(steps);
      const int width = 30, filled = static_cast<int>(done * width);
      std::fprintf(stderr, "\r[%s%s] frame %u/%u  t = %.4g s  ETA %s  %.3g ms/step   ", std::string(static_cast<std::size_t>(filled), '#').c_str(),
                   std::string(static_cast<std::size_t>(width - filled), '.').c_str(), frame - 1, frames,
                   static_cast<double>(s + 1) * h, format_seconds(elapsed / done * (1 - done)).c_str(), elapsed * 1e3 / static_cast<double>(s + 1));
    }
  }
  if (bar) std::fputc('\n', stderr);
  sum.wall = std::chrono::duration<double>(Clock::now() - started).count();
  sum.steps = steps;
  sum.frames = frame;
  sum.simulated = static_cast<double>(steps) * h;
  sum.ms_per_step = steps ? sum.wall * 1e3 / static_cast<double>(steps) : 0;
  sum.kinetic_end = model->system().kinetic_energy();

  // 6) the picture of the last frame
  if (scene.write_picture) {
    snap.take(*model);
    const std::vector<double>* scalar = &snap.displacement_norm;
    std::string label = "|displacement| [m]";
    if (scene.color_by == "speed") scalar = &snap.speed, label = "speed [m/s]";
    if (scene.color_by == "force") scalar = &snap.force_norm, label = "|force| [N]";
    if (scene.color_by == "fixed") scalar = &snap.fixed_scalar, label = "fixed";
    if (scene.color_by == "material") scalar = &snap.material_scalar, label = "material";
    io::RenderOptions ro;
    ro.width = static_cast<int>(scene.width);
    ro.height = static_cast<int>(scene.height);
    ro.mode = scene.style == "wireframe" ? io::RenderMode::wireframe : io::RenderMode::shaded;
    char title[160];
    std::snprintf(title, sizeof title, "%s, t = %.3g s", scene.name.c_str(), sum.simulated);
    ro.title = title;
    ro.scalar_name = label;
    // Faces a cut opened: boundary faces now, whose particles stand for the points of a face
    // that two volumes shared in the original mesh (the paper draws them red).
    const auto interior = interior_faces(mesh);
    if (!interior.empty())
      ro.highlight = [&](std::span<const std::uint32_t> face) {
        return interior.count(face_key(face, [&](std::uint32_t q) { return model->point_of_node(q); })) > 0;
      };
    sum.picture = sum.out / (scene.name + ".png");
    io::render_png(sum.picture, snap.points, snap.cells(), *scalar, ro);
  }
  return sum;
}

}  // namespace sewn::app
