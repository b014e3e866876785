#include "sewn/apps/runner.hpp"
#include "sewn/apps/checkpoint.hpp"

#include <algorithm>
#include <chrono>
#include <ctime>
#include <cmath>
#include <cstdio>
#include <memory>
#include <set>
#include <stdexcept>
#include <string>

#include <Eigen/Geometry>

#include "sewn/apps/connections.hpp"
#include "sewn/apps/continuum.hpp"
#include "sewn/io/cleanup.hpp"
#include "sewn/io/geometry.hpp"
#include "sewn/io/read.hpp"
#include "sewn/io/surface.hpp"
#include "sewn/io/write.hpp"
#include "sewn/physics/integrate/energy_ledger.hpp"
#include "sewn/physics/integrate/implicit_midpoint.hpp"
#include "sewn/physics/integrate/newton_euler.hpp"
#include "sewn/physics/integrators.hpp"
#include "sewn/physics/mss_model.hpp"
#include "sewn/physics/shells/shell_terms.hpp"
#include "sewn/physics/solids/inversion.hpp"
#include "sewn/physics/solids/volume_term.hpp"
#include "sewn/physics/split_boxes.hpp"
#include "sewn/physics/stiffness.hpp"
#include "sewn/physics/threads.hpp"
#include "sewn/refine/cut.hpp"
#include "sewn/refine/hierarchy.hpp"
#include "sewn/apps/refine_keys.hpp"

#include "run_checkpoint.hpp"
#include "run_output.hpp"

namespace sewn::app {

namespace {

using detail::frame_file;
using detail::prepare_output;
using detail::Snapshot;
using detail::writing;
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

// The mesh of `spec`, and in `names` what its file says of its tags.
IndexedMesh generate(const MeshSpec& spec, const std::string& file, const std::string& path, MeshNames& names) {
  IndexedMesh m;
  names.path = path;
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
    names.format = io::to_string(read.format);
    names.names = std::move(read.tag_names);
    m = std::move(read.mesh);
    io::drop_unused_points(m);
    transform(m, spec.scale, spec.translate);
    io::check_mesh_geometry(m, spec.path);
  }
  return m;
}

// A semi-implicit step, its stable-step refusal told in the scene's terms: the user sets scene
// keys, not the library's enforce_stable_step.
void step_semi_implicit(physics::SymplecticEuler& semi, physics::System& sys, double h, double t, const Scene& scene) {
  try {
    (void)semi.step(sys, h);
  } catch (const physics::StabilityError& e) {
    char text[512];
    std::snprintf(text, sizeof text,
                  "%s: integrator.step: h = %.4g s is not below the semi-implicit stable-step bound %.4g s (at t = %.4g s). "
                  "Use a step below %.4g s, the implicit integrator (integrator.type = \"implicit\"), or set "
                  "integrator.allow_unstable = true to run it anyway; the run stopped there.",
                  scene.file.c_str(), h, e.bound(), t, e.bound());
    throw physics::StabilityError(text, e.step(), e.bound());
  }
}

// Keeps the facets a scheduled cut unsews, for a checkpoint to apply again.
void record_cut(std::vector<AppliedCut>& applied, std::size_t spec, std::span<const refine::Facet> facets) {
  AppliedCut a;
  a.spec = static_cast<std::uint32_t>(spec);
  for (const refine::Facet& f : facets) {
    a.darts.push_back(f.dart.index());
    a.betas.push_back(static_cast<std::uint8_t>(f.index));
  }
  applied.push_back(std::move(a));
}

std::string format_seconds(double s) {
  char buf[32];
  if (s < 60)
    std::snprintf(buf, sizeof buf, "%.0f s", s);
  else
    std::snprintf(buf, sizeof buf, "%d min %02d s", static_cast<int>(s / 60), static_cast<int>(s) % 60);
  return buf;
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
    for (std::uint32_t q : where.points) {
      if (q >= mesh.num_points() || model.node_of_point(q) == physics::invalid_index)
        throw SceneError(file, path + ".indices",
                         "point " + std::to_string(q) + " is not a point of any cell (" + std::to_string(mesh.num_points()) + " points)");
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
  physics::BoxSplit split = physics::split_boxes(a.mesh, wanted, scene.file);
  std::vector<std::uint32_t> material(split.source_cell.size());
  std::vector<CellModel> model(split.source_cell.size());
  std::vector<int> group(split.source_cell.size());
  for (std::size_t c = 0; c < material.size(); ++c) {
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
  a.split_asked = split.asked;
  a.split_cells = split.split;
}

// What the report says of where a mixed model's bodies meet.
std::string connections_line(const Assembly& a) {
  const MeshConnections c = mesh_connections(a.mesh, a.model_of_cell);
  return c.skipped.empty() ? connect::connections_text(c.found) : "  not computed: " + c.skipped + "\n";
}

}  // namespace

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
    const IndexedMesh whole = generate(spec, scene.file, path, mesh_names[i]);
    const GroupMatch groups = match_groups(whole, mesh_names[i], scene);
    const std::vector<CellModel> models = cell_models(whole, io::embedded_cells(whole), scene, path, groups.of_cell);
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
        piece_models.push_back(models[c]);
        piece_groups.push_back(groups.of_cell[c]);
      }
    }
    if (piece.num_cells() == 0)
      throw SceneError(scene.file, path, whole.num_cells() == 0 ? "the mesh has no cell" : "every cell of the mesh is a label: nothing to simulate");
    a.first_cell.push_back(a.mesh.num_cells());
    std::vector<std::uint32_t> mat(piece.num_cells(), material_index(spec.material));
    for (const auto& [where, name] : spec.regions)
      for (std::uint32_t c = 0; c < piece.num_cells(); ++c)
        if (selects_cell(where, piece, c)) mat[c] = material_index(name);
    const std::uint32_t first_point = append(a.mesh, piece);
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

// The volume-preserving term of the materials that ask for it. Its stencils follow cuts (each
// takes its element's corner particles after the cut) but not refinement, whose new elements
// would have none: a scene that refines is refused rather than given a term with holes.
void add_volume_term(const Scene& scene, const std::vector<std::string>& material_names, physics::MssModel<3>& model) {
  std::vector<double> kappa;
  for (const auto& name : material_names) {
    kappa.push_back(scene.materials.at(name).volume_stiffness);
    if (kappa.back() > 0 && scene.refinement.enabled)
      throw SceneError(scene.file, "materials." + name + ".volume_stiffness",
                       "the volume term is not supported with refinement yet (the elements refinement creates would have no "
                       "volume stencils)");
  }
  // Materials past the scene's own are copies apply_rod_sections made for rod cells, which have
  // no volume to keep.
  kappa.resize(model.materials().size(), 0.0);
  (void)physics::solids::add_volume_preservation(model, kappa);
}

}  // namespace

RunSummary run(const Scene& scene, const RunOptions& options) {
  RunSummary sum;
  sum.out = options.out.empty() ? std::filesystem::path("out") / scene.name : options.out;
  prepare_output(sum.out);

  // 1) the bodies and the model
  Assembly assembly = assemble(scene);
  if (scene.model == "mixed") sum.connections = connections_line(assembly);
  std::vector<physics::MaterialParams> materials;
  for (const auto& name : assembly.material_names) {
    const MaterialSpec& ms = scene.materials.at(name);
    materials.push_back({ms.young, ms.poisson, ms.density, ms.thickness, ms.area,
                         ms.elongated == "clamp" ? physics::ElongatedPolicy::clamp : physics::ElongatedPolicy::refuse});
  }
  apply_rod_sections(scene, assembly.mesh, assembly.model_of_cell, assembly.group_of_cell, materials, assembly.material_of_cell);
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

  // A policy that altered stiffnesses is said so: the body is stiffer than the material.
  sum.clamped_cells = static_cast<std::uint64_t>(
      std::count_if(model->elements().begin(), model->elements().end(), [](const auto& e) { return e.alive && e.clamped; }));
  if (sum.clamped_cells > 0 && !options.quiet)
    std::fprintf(stderr,
                 "sewn: warning: %llu cells are too elongated for Baudet's stiffness and had their negative edge "
                 "stiffnesses clamped to 0 (materials' elongated = \"clamp\"): the body is too stiff in bending, by "
                 "4.8x at 2.5:1, 66x at 5:1 and 860x at 10:1 on a 1 m cantilever (issue 17's measurements); refine "
                 "the mesh towards cubes for a faithful answer\n",
                 static_cast<unsigned long long>(sum.clamped_cells));

  sum.split_cells = assembly.split_cells;
  if (assembly.split_cells > 0 && !options.quiet)
    std::fprintf(stderr,
                 "sewn: warning: %u cells are too elongated for Baudet's stiffness and were split into near-cubes "
                 "(materials' elongated = \"split\"); %u cells were cut in all, those included with the cells sharing "
                 "their split edges: %u cells and %u points now, from %u cells. Stiffnesses are Baudet's own, unaltered: on a 1 m cantilever the static tip is "
                 "the cube-meshed beam's at 10:1 and 5:1 boxes and 3.1 %% softer at 2.5:1 (issue 17). Mesh cell numbers below "
                 "are those of the split mesh\n",
                 assembly.split_asked, assembly.split_cells, assembly.mesh.num_cells(),
                 assembly.mesh.num_points(), assembly.source_cells);

  // The continuum models (solids, shells, rods) and the volume term join or replace the springs.
  const IndexedMesh& mesh = assembly.mesh;
  ContinuumParts continuum;
  if (scene.model != "mass-spring") continuum = build_continuum(scene, materials, mesh, assembly.model_of_cell, assembly.group_of_cell, *model);
  // the rotational energies where the bodies meet (model.connections), on the rest state
  ConnectionParts joints;
  if (scene.model != "mass-spring") joints = build_connections(scene, mesh, assembly.model_of_cell, materials, continuum, *model);
  sum.connection_energies = connection_energies_text(joints);

  add_volume_term(scene, assembly.material_names, *model);

  // 2) fixed particles, then initial velocities of the free axes
  for (std::size_t k = 0; k < scene.fixed.size(); ++k) {
    const FixSpec& fix = scene.fixed[k];
    physics::AxisMask axes = 0;
    if (fix.axes[0]) axes |= physics::axis_x;
    if (fix.axes[1]) axes |= physics::axis_y;
    if (fix.axes[2]) axes |= physics::axis_z;
    for (Index i : selected_nodes(fix.where, assembly, *model, scene.file, "fixed[" + std::to_string(k) + "].where"))
      model->nodes().fix(i, axes);
  }
  for (std::size_t k = 0; k < scene.velocities.size(); ++k) {
    const VelocitySpec& vel = scene.velocities[k];
    const Vec3d linear(vel.linear[0], vel.linear[1], vel.linear[2]), angular(vel.angular[0], vel.angular[1], vel.angular[2]),
        center(vel.center[0], vel.center[1], vel.center[2]);
    for (Index i : selected_nodes(vel.where, assembly, *model, scene.file, "velocities[" + std::to_string(k) + "].where")) {
      Vec3d v = linear + angular.cross(model->rest_position(i) - center);
      // a velocity on a fixed axis would make it kinematic: fixed stays fixed
      for (int a = 0; a < 3; ++a)
        if ((model->nodes().fixed(i) >> a) & 1u) v[a] = 0;
      model->nodes().set_velocity(i, v);
    }
  }
  std::unique_ptr<RefinementRun> refinement;
  if (scene.refinement.enabled) refinement = std::make_unique<RefinementRun>(scene, *model);

  // 3) time line: steps, frames and scheduled cuts
  const double h = scene.step;
  const double end = std::min(scene.duration, options.until.value_or(scene.duration));
  const auto steps = static_cast<std::uint64_t>(std::ceil(end / h - 1e-9));
  const std::uint32_t frames = options.frames.value_or(scene.frames);
  std::vector<std::pair<double, std::size_t>> cuts;  // (time, index) in time order
  for (std::size_t k = 0; k < scene.cuts.size(); ++k) cuts.emplace_back(scene.cuts[k].time, k);
  std::stable_sort(cuts.begin(), cuts.end());

  // A checkpoint to continue from: this scene's run, its cuts applied again, its motion put back.
  const bool resuming = !options.resume.empty();
  Checkpoint ck;
  std::uint64_t run_id = 0;
  if (resuming || options.checkpoint_every > 0) run_id = detail::run_hash(scene, *model, steps, frames);
  std::size_t next_cut = 0;  // the first scheduled cut not applied yet
  if (resuming) {
    const std::string file = options.resume.string();
    ck = read_checkpoint(options.resume);
    if (ck.steps_total != steps || ck.frames_total != frames)
      throw CheckpointError(file, "written by a run of " + std::to_string(ck.steps_total) + " steps and " +
                                      std::to_string(ck.frames_total) + " frames, but this one has " + std::to_string(steps) +
                                      " steps and " + std::to_string(frames) + " frames (resume with the same --frames and --until)");
    if (ck.run_hash != run_id)
      throw CheckpointError(file, "written by another scene (" + scene.file + " or its mesh files differ from the run's)");
    next_cut = detail::check_cut_schedule(ck, cuts, file);
    detail::restore_model(*model, continuum, joints, refinement.get(), ck, file);
    if (ck.frame_times.size() != (scene.write_vtu ? ck.frame : 0) ||
        std::size_t{ck.csv_columns} * ck.frame != (scene.write_csv ? ck.csv_rows.size() : 0))
      throw CheckpointError(file, "its output record does not match its " + std::to_string(ck.frame) + " frames");
    // the .pvd will list the frames written before the checkpoint: they must be there
    for (std::uint32_t f = 0; f < ck.frame_times.size(); ++f)
      if (!std::filesystem::exists(sum.out / frame_file(f)))
        throw CheckpointError(file, "its run wrote " + frame_file(f) + ", which " + sum.out.string() +
                                        " does not hold: resume in the output folder the run wrote to");
    sum.resumed_at = ck.step;
  }

  // 4) outputs
  Snapshot snap;
  std::unique_ptr<io::PvdWriter> pvd;
  if (scene.write_vtu) {
    sum.pvd = sum.out / (scene.name + ".pvd");
    std::vector<std::pair<double, std::string>> listed;
    for (std::uint32_t f = 0; f < ck.frame_times.size(); ++f) listed.emplace_back(ck.frame_times[f], frame_file(f));
    writing([&] { pvd = std::make_unique<io::PvdWriter>(sum.pvd, std::move(listed)); });
  }
  std::unique_ptr<io::CsvWriter> csv;
  if (scene.write_csv) {
    sum.csv = sum.out / "frames.csv";
    const std::vector<std::string> columns{"frame", "time", "kinetic_energy", "elastic_energy", "gravity_energy",
                                           "total_energy", "external_work", "dissipated", "energy_ratio_max",
                                           "energy_rises", "inverted", "momentum_x", "momentum_y", "momentum_z",
                                           "angular_momentum_x", "angular_momentum_y", "angular_momentum_z", "particles", "springs", "elements", "steps", "ms_per_step",
                                           "cg_iterations_mean", "cg_iterations_max", "cuts", "faces_cut", "refined", "coarsened"};
    if (resuming && ck.csv_columns != columns.size())
      throw CheckpointError(options.resume.string(), "its frames.csv rows have " + std::to_string(ck.csv_columns) + " columns, not " +
                                                        std::to_string(columns.size()));
    writing([&] {
      csv = std::make_unique<io::CsvWriter>(sum.csv, columns);
      for (std::size_t r = 0; r < ck.frame; ++r) csv->row(std::span<const double>(ck.csv_rows).subspan(r * columns.size(), columns.size()));
    });
  }
  // Energy balance of every frame; each implicit step is checked for energy it created (the
  // semi-implicit scheme's plain energy oscillates by design: its divergence is the
  // integrator's watchdog's business).
  physics::EnergyLedger ledger(scene.energy_rise_tolerance);
  ledger.start(model->system());
  if (resuming) ledger.restore(ck.ledger);
  std::uint32_t frame = ck.frame;
  double frame_ms = ck.frame_ms, frame_cg_sum = ck.frame_cg_sum;
  int frame_cg_max = ck.frame_cg_max;
  std::uint64_t frame_steps = ck.frame_steps;
  std::vector<double> frame_times = ck.frame_times, csv_rows = ck.csv_rows;  // what a checkpoint lists
  sum.cuts = ck.cuts_applied;
  sum.faces_cut = ck.faces_cut;
  sum.inverted_max = ck.inverted_max;
  sum.first_inversion = ck.first_inversion;
  sum.first_energy_rise = ck.first_energy_rise;
  sum.kinetic_max = ck.kinetic_max;
  // Inverted elements: counted at every frame, and at every step when the scene stops at the
  // first; the first seen is reported once.
  physics::Index inverted_now = 0;
  physics::InversionMonitor inversions;
  auto check_inversion = [&](std::uint64_t step) {
    const physics::InversionCount c = inversions.count(*model);
    inverted_now = c.elements;
    sum.inverted_max = std::max<std::uint64_t>(sum.inverted_max, c.elements);
    if (c.elements == 0 || !sum.first_inversion.empty()) return;
    char msg[300];
    std::snprintf(msg, sizeof msg, "element %u (mesh cell %u) is inverted at step %llu (t = %.6g s)%s", c.first, c.first_cell,
                  static_cast<unsigned long long>(step), static_cast<double>(step) * scene.step,
                  c.elements > 1 ? (", with " + std::to_string(c.elements - 1) + " more").c_str() : "");
    sum.first_inversion = msg;
    if (scene.stop_on_inversion)
      throw std::runtime_error(std::string(msg) + "; stopped there (integrator.stop_on_inversion)");
    if (!options.quiet) std::fprintf(stderr, "\nsewn: warning: %s\n", msg);
  };
  std::uint64_t steps_done = ck.step;
  auto write_frame = [&](double t) {
    physics::System& sys = model->system();
    sys.compute_forces();
    check_inversion(steps_done);
    if (pvd) {
      snap.take(*model);
      const std::string name = frame_file(frame);
      const io::DataArray point_data[] = {
          io::DataArray::vectors("velocity", snap.velocity), io::DataArray::vectors("force", snap.force),
          io::DataArray::vectors("displacement", snap.displacement), io::DataArray::flags("fixed", snap.fixed)};
      // rods' material frames: m1 per segment (m2 = t × m1), zero on other cells
      const std::vector<Point3> director = rod_directors(continuum, *model, snap.element);
      const io::DataArray cell_data[] = {io::DataArray::ints("material", snap.material),
                                         io::DataArray::ints("refinement_level", snap.level),
                                         io::DataArray::ints("mesh_cell", snap.mesh_cell),
                                         io::DataArray::vectors("rod_director", director)};
      // the frame is complete on disk before the series lists it
      writing([&] {
        io::write_vtu(sum.out / name, snap.points, snap.cells(), point_data, cell_data);
        pvd->add(t, sum.out / name);
      });
      frame_times.push_back(t);
    }
    if (csv) {
      const auto elements = std::count_if(model->elements().begin(), model->elements().end(), [](const auto& e) { return e.alive; });
      const physics::EnergyBalance e = ledger.balance(sys);
      ledger.observe(e);
      const physics::Momenta p = physics::momenta(model->nodes());
      const double row[] = {static_cast<double>(frame), t, e.kinetic, e.elastic, e.external_potential, e.total, e.external_work,
                            e.dissipated, ledger.peak_ratio(), static_cast<double>(ledger.rises()), static_cast<double>(inverted_now),
                            p.linear.x(), p.linear.y(), p.linear.z(), p.angular.x(), p.angular.y(), p.angular.z(),
                            static_cast<double>(model->nodes().num_alive()),
                            static_cast<double>(model->springs().num_alive()), static_cast<double>(elements),
                            static_cast<double>(frame_steps), frame_steps ? frame_ms / static_cast<double>(frame_steps) : 0.0,
                            frame_steps ? frame_cg_sum / static_cast<double>(frame_steps) : 0.0, static_cast<double>(frame_cg_max),
                            static_cast<double>(sum.cuts), static_cast<double>(sum.faces_cut),
                            static_cast<double>(refinement ? refinement->refined() : 0),
                            static_cast<double>(refinement ? refinement->coarsened() : 0)};
      writing([&] { csv->row(row); });
      csv_rows.insert(csv_rows.end(), std::begin(row), std::end(row));
    }
    ++frame;
    frame_ms = frame_cg_sum = 0;
    frame_cg_max = 0;
    frame_steps = 0;
  };

  // 5) stepping, on the scene's thread count, or SEWN_THREADS's (a bad value is named here)
  if (scene.threads > 0)
    physics::set_thread_count(static_cast<int>(scene.threads));
  else
    (void)physics::thread_count();
  physics::SymplecticEulerOptions so;
  so.enforce_stable_step = !scene.allow_unstable;
  physics::ImplicitEulerOptions io_opt;
  // "ldlt" is Newton's own direct solve (scene.cpp refuses it with the other integrators)
  io_opt.solver = scene.solver == "ldlt" ? physics::solve::Backend::automatic : physics::solve::parse_backend(scene.solver);
  io_opt.cg_tolerance = scene.tolerance;
  io_opt.cg_absolute_tolerance = scene.absolute_tolerance;
  io_opt.cg_max_iterations = static_cast<int>(scene.max_iterations);
  physics::SymplecticEuler semi(so);
  physics::LinearlyImplicitEuler implicit(io_opt);
  physics::ImplicitMidpointOptions mid_opt;
  mid_opt.cg_max_iterations = static_cast<int>(scene.max_iterations);
  physics::ImplicitMidpoint midpoint(mid_opt);
  const bool use_midpoint = scene.integrator == "midpoint";
  const bool use_implicit = scene.integrator == "implicit" || use_midpoint;
  physics::integrate::NewtonEulerOptions no;
  no.velocity_tolerance = scene.newton_tolerance;
  no.max_iterations = static_cast<int>(scene.newton_iterations);
  no.cg_tolerance = scene.tolerance;
  no.cg_max_iterations = static_cast<int>(scene.max_iterations);
  if (scene.solver == "ldlt") no.solver = physics::integrate::LinearSolver::ldlt;
  physics::integrate::NewtonEuler newton(no);
  const bool use_newton = scene.integrator == "newton";
  const bool bar = !options.quiet && options.progress && isatty(STDERR_FILENO);
  std::vector<AppliedCut> applied = ck.cuts;
  if (resuming) {
    try {
      semi.restore(model->system(), ck.semi);
      implicit.restore(model->system(), ck.implicit);
      midpoint.restore(model->system(), ck.midpoint);
    } catch (const physics::InputError& e) {
      throw CheckpointError(options.resume.string(), e.what());
    }
    sum.kinetic_start = ck.kinetic_start;
  } else {
    sum.kinetic_start = model->system().kinetic_energy();
    write_frame(0.0);
  }
  // Everything the loop below reads from earlier steps, in the order of checkpoint.hpp.
  std::uint32_t checkpoints = 0;
  auto save_checkpoint = [&](double wall) {
    Checkpoint c;
    c.run_hash = run_id;
    c.model_hash = detail::model_hash(*model);
    c.steps_total = steps;
    c.frames_total = frames;
    c.step = steps_done;
    c.frame = frame;
    c.cuts = applied;
    c.x.assign(model->nodes().x().begin(), model->nodes().x().end());
    c.v.assign(model->nodes().v().begin(), model->nodes().v().end());
    c.semi = semi.history(model->system());
    if (use_implicit && !use_midpoint) c.implicit = implicit.history(model->system());
    if (use_midpoint) c.midpoint = midpoint.history(model->system());
    c.ledger = ledger.state();
    if (refinement) c.refinement = refinement->state();
    if (continuum.rods) c.rods = continuum.rods->history();
    const physics::AngleTable& angles = model->system().angles();
    c.angles.assign(angles.values().begin(), angles.values().end());
    c.angle_rates.assign(angles.rates().begin(), angles.rates().end());
    if (joints.points) c.point_connections = joints.points->history();
    if (joints.curves) c.curve_connections = joints.curves->history();
    c.frame_times = frame_times;
    c.csv_columns = csv ? static_cast<std::uint32_t>(csv->columns()) : 0;
    c.csv_rows = csv_rows;
    c.frame_ms = frame_ms;
    c.frame_cg_sum = frame_cg_sum;
    c.frame_cg_max = frame_cg_max;
    c.frame_steps = frame_steps;
    c.cuts_applied = sum.cuts;
    c.faces_cut = sum.faces_cut;
    c.kinetic_start = sum.kinetic_start;
    c.kinetic_max = sum.kinetic_max;
    c.wall = wall;
    c.inverted_max = sum.inverted_max;
    c.first_inversion = sum.first_inversion;
    c.first_energy_rise = sum.first_energy_rise;
    sum.checkpoint = sum.out / (scene.name + ".checkpoint");
    writing([&] { write_checkpoint(sum.checkpoint, c); });
    ++checkpoints;
  };
  const auto started = Clock::now();
  auto last_bar = started;
  for (std::uint64_t s = ck.step; s < steps; ++s) {
    const double t = static_cast<double>(s) * h;
    const auto t0 = Clock::now();
    const std::clock_t c0 = std::clock();
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
        record_cut(applied, k, facets);
        rep = refine::cut(*model, facets);
      } else if (c.type == "faces") {
        std::vector<refine::Facet> facets;
        try {
          facets = refine::facets_with_points(*model, c.faces);
        } catch (const physics::InputError& e) {
          throw SceneError(scene.file, path + ".faces", e.what());
        }
        record_cut(applied, k, facets);
        rep = refine::cut(*model, facets);
      } else if (c.type == "particles") {
        const auto facets = refine::facets_among_points(*model, c.particles);
        if (facets.empty()) throw SceneError(scene.file, path + ".particles", "no face between two elements has all its points among them");
        record_cut(applied, k, facets);
        rep = refine::cut(*model, facets);
      } else if (c.type == "pierce") {
        std::vector<Index> elements;
        for (Index e = 0; e < model->elements().size(); ++e) {
          const auto& el = model->elements()[e];
          if (el.alive && selects_cell(c.where, mesh, el.mesh_cell)) elements.push_back(e);
        }
        if (elements.empty()) throw SceneError(scene.file, path + ".where", "selects no element (at its time)");
        applied.push_back({static_cast<std::uint32_t>(k), true, c.remove, {}, {}, {elements.begin(), elements.end()}, 0});
        rep = refine::pierce(*model, elements, c.remove);
      }
      if (scene.model != "mass-spring") follow_cut(continuum, *model);
      sum.faces_cut += rep.facets;
      ++sum.cuts;
      ledger.rebase(model->system());
    }
    int cg = 0;
    if (use_midpoint) {
      cg = midpoint.step(model->system(), h).cg_iterations;
      if (midpoint.last_substeps() > 1) {
        ++sum.substepped;
        sum.most_substeps = std::max(sum.most_substeps, midpoint.last_substeps());
      }
    } else if (use_implicit)
      cg = implicit.step(model->system(), h).cg_iterations;
    else if (use_newton) {
      const auto rep = newton.step(model->system(), h);
      cg = rep.linear_iterations;
      sum.newton_iterations += static_cast<std::uint64_t>(rep.iterations);
    } else
      step_semi_implicit(semi, model->system(), h, t, scene);
    const double ms = std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
    sum.stepping += ms / 1e3;
    sum.stepping_cpu += static_cast<double>(std::clock() - c0) / CLOCKS_PER_SEC;
    sum.linear_iterations += static_cast<std::uint64_t>(cg);
    frame_ms += ms;
    frame_cg_sum += cg;
    frame_cg_max = std::max(frame_cg_max, cg);
    ++frame_steps;
    steps_done = s + 1;
    if (scene.stop_on_inversion) check_inversion(s + 1);
    if (use_implicit)
      if (const auto rise = ledger.after_step(model->system(), s + 1); rise && ledger.rises() == 1) {
        char msg[400];
        std::snprintf(msg, sizeof msg,
                      "step %llu (t = %.6g s) raised the total energy from %.6g J to %.6g J (+%.3g %% of the %.6g J in "
                      "motion) with no external work to supply it: the integrator created energy (the linearised "
                      "implicit step does on fast rotations; a smaller step or integrator.type \"midpoint\" avoids it)",
                      static_cast<unsigned long long>(s + 1), static_cast<double>(s + 1) * h, rise->before, rise->after,
                      100 * (rise->after - rise->before) / rise->moved, rise->moved);
        sum.first_energy_rise = msg;
        if (!options.quiet) std::fprintf(stderr, "%ssewn: warning: %s\n", bar ? "\n" : "", msg);
      }
    // Refinement changes the elastic energy (new springs at their rest lengths under load) and
    // coarsening dissipates the fine motion: after the step's energy check, the ledger restarts.
    if (refinement) {
      const auto r0 = Clock::now();
      if (refinement->after_step(*model, static_cast<double>(s + 1) * h)) {
        ledger.rebase(model->system());
        // kept in order with the cuts, for a checkpoint to do them again
        for (const std::uint8_t kind : {std::uint8_t{1}, std::uint8_t{2}}) {
          const auto& elements = kind == 1 ? refinement->last_refined() : refinement->last_coarsened();
          if (!elements.empty()) applied.push_back({0, false, false, {}, {}, {elements.begin(), elements.end()}, kind});
        }
      }
      frame_ms += std::chrono::duration<double, std::milli>(Clock::now() - r0).count();
    }
    sum.kinetic_max = std::max(sum.kinetic_max, model->system().kinetic_energy());
    // frame f is written after step round(f · steps / frames)
    const auto due = static_cast<std::uint64_t>(std::llround(static_cast<double>(frame) * static_cast<double>(steps) / frames));
    if (s + 1 >= due && frame <= frames) {
      write_frame(static_cast<double>(s + 1) * h);
      if (options.checkpoint_every > 0 && (frame - 1) % options.checkpoint_every == 0) {
        save_checkpoint(ck.wall + std::chrono::duration<double>(Clock::now() - started).count());
        if (checkpoints == options.stop_after_checkpoints) {
          sum.stopped = true;
          steps_done = s + 1;
          break;
        }
      }
    }
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
  sum.wall = ck.wall + std::chrono::duration<double>(Clock::now() - started).count();
  sum.steps = steps_done;
  sum.frames = frame;
  sum.simulated = static_cast<double>(steps_done) * h;
  sum.ms_per_step = steps_done ? sum.wall * 1e3 / static_cast<double>(steps_done) : 0;
  sum.kinetic_end = model->system().kinetic_energy();
  if (csv) writing([&] { csv->flush(); });
  sum.energy_rises = ledger.rises();
  if (refinement) {
    sum.refined = refinement->refined();
    sum.coarsened = refinement->coarsened();
  }
  if (sum.stopped) return sum;

  // 6) the picture of the last frame
  if (scene.write_picture) sum.picture = detail::write_picture(scene, sum.simulated, sum.out, mesh, *model, snap);
  return sum;
}

}  // namespace sewn::app
