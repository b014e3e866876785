// The `sewn` command-line tool: run a scene, check a mesh, print the scene reference.
#include <algorithm>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <cstring>
#include <exception>
#include <iostream>
#include <optional>
#include <string>
#include <vector>

#include "sewn/apps/cell_models.hpp"
#include "sewn/apps/check_topology.hpp"
#include "sewn/apps/checkpoint.hpp"
#include "sewn/apps/paper_shapes.hpp"
#include "sewn/apps/runner.hpp"
#include "sewn/apps/scene.hpp"
#include "sewn/cmap/build.hpp"
#include "sewn/io/cleanup.hpp"
#include "sewn/io/errors.hpp"
#include "sewn/io/geometry.hpp"
#include "sewn/io/read.hpp"
#include "sewn/io/write_gmsh.hpp"
#include "sewn/physics/errors.hpp"
#include "sewn/physics/solve/blas_kernels.hpp"

namespace {

constexpr int ok = 0, run_failed = 1, bad_input = 2;

constexpr const char* usage = R"(sewn: simulate deformable bodies whose topology changes while they move

usage:
  sewn run [SCENE.json] [--out DIR] [--frames N] [--until T] [--quiet]
           [--checkpoint-every N] [--resume FILE] [--stop-after-checkpoints K]
                          run a scene (with no scene: the built-in default, a cantilever
                          beam sagging under gravity and cut part-way through)
  sewn check MESH [--json]
                          load a mesh (.msh 2.2/4.1, .mesh, .vtk), report what `sewn run` would
                          simulate (cells per dimension, components, boundary labels), check its
                          geometry, build the combinatorial map and print its validation report,
                          cell counts and topology (Betti numbers, orientability, boundary,
                          non-manifold cells)
  sewn make-mesh SHAPE OUT.msh
                          write the mesh of one of the 2019 paper's scenes (frisbee, umbrella,
                          sticky_hands, jellyfish, toy_ball, sandwich) as Gmsh 2.2 with a
                          physical name per part; prints its counts
  sewn scene-doc          print the scene file reference (docs/scenes.md)
  sewn --help | sewn <command> --help

exit codes: 0 ok, 1 the run failed, 2 bad input
)";

constexpr const char* run_usage = R"(usage: sewn run [SCENE.json] [--out DIR] [--frames N] [--until T] [--quiet]
                [--checkpoint-every N] [--resume FILE] [--stop-after-checkpoints K]

Runs a scene (docs/scenes.md) and writes, in DIR (default out/<scene name>/):
  <name>.pvd + frame_NNNNN.vtu   the ParaView series (cells with material and refinement level;
                                 per point velocity, force, displacement, fixed flags)
  frames.csv                     per frame: time, kinetic/elastic/gravity/total energy, work of
                                 gravity, energy dissipated, steps that created energy, inverted
                                 elements, particle, spring and element counts, ms per step, CG
                                 iterations, cuts applied and faces they unsewed (docs/scenes.md)
  <name>.png                     a picture of the last frame
  --frames N   number of output frames (overrides the scene's output.frames)
  --until T    stop at simulated time T seconds, if that is before the scene's end; cuts
               scheduled after T are not applied
  --quiet      no progress bar and no summary line
  --checkpoint-every N
               write <name>.checkpoint in DIR after every N frames (replaced whole each time:
               a killed run loses at most N frames of work; docs/checkpoints.md)
  --resume FILE
               continue the run FILE was written by (same scene, --frames and --until): the
               outputs come out byte for byte as if the run had never stopped
  --stop-after-checkpoints K
               stop after writing K checkpoints (exit 0), to split a long run into jobs
The progress bar is drawn only when standard error is a terminal.
)";

constexpr const char* check_usage = R"(usage: sewn check MESH [--json]

Loads MESH (Gmsh .msh 2.2 or 4.1, ASCII or binary, MEDIT .mesh, legacy VTK .vtk) and reports
what `sewn run` would simulate: triangles that are faces of volumes and segments that are edges of
higher-dimensional cells (tetgen's face list, Gmsh's boundary groups) are labels, listed by tag,
and the rest is the simulated complex (cells per dimension, components: cells sharing a point).
It lists every geometric problem `sewn run` refuses (non-finite coordinates, inverted, degenerate
or duplicate cells; cells numbered from 0 in file order, labels included); on the simulated
complex it builds the combinatorial map
and prints its validation report, cell counts, components and boundary, then the topology of
the mesh's cell complex (cells identified by their points; meshes of volumes only or of surface
cells only): per component its cell counts, χ, Betti numbers over Z/2, orientability and (for
surfaces) genus; each boundary component with its genus; every vertex or edge whose link is not
a sphere or disc. --json prints the topology as JSON on stdout (the text goes to stderr).
Exit 0 when the mesh is sound, 2 otherwise (non-manifold or non-orientable meshes are sound).
)";

int cmd_run(const std::vector<std::string>& args) {
  std::optional<std::string> scene_path;
  sewn::app::RunOptions opt;
  for (std::size_t i = 0; i < args.size(); ++i) {
    const std::string& a = args[i];
    if (a == "--help" || a == "-h") {
      std::fputs(run_usage, stdout);
      return ok;
    } else if (a == "--quiet" || a == "-q") {
      opt.quiet = true;
    } else if (a == "--out" || a == "--frames" || a == "--until" || a == "--checkpoint-every" || a == "--resume" ||
               a == "--stop-after-checkpoints") {
      if (i + 1 >= args.size()) {
        std::fprintf(stderr, "sewn run: %s needs a value\n", a.c_str());
        return bad_input;
      }
      const std::string& v = args[++i];
      if (a == "--out") {
        opt.out = v;
      } else if (a == "--resume") {
        opt.resume = v;
      } else if (a == "--checkpoint-every" || a == "--stop-after-checkpoints") {
        char* end = nullptr;
        const long n = std::strtol(v.c_str(), &end, 10);
        if (end == v.c_str() || *end != '\0' || n < 1 || n > 100000) {
          std::fprintf(stderr, "sewn run: %s needs a whole number between 1 and 100000, got '%s'\n", a.c_str(), v.c_str());
          return bad_input;
        }
        (a == "--checkpoint-every" ? opt.checkpoint_every : opt.stop_after_checkpoints) = static_cast<std::uint32_t>(n);
      } else if (a == "--until") {
        char* end = nullptr;
        const double t = std::strtod(v.c_str(), &end);
        if (end == v.c_str() || *end != '\0' || !std::isfinite(t) || t <= 0) {
          std::fprintf(stderr, "sewn run: --until needs a positive time in seconds, got '%s'\n", v.c_str());
          return bad_input;
        }
        opt.until = t;
      } else {
        char* end = nullptr;
        const long n = std::strtol(v.c_str(), &end, 10);
        if (end == v.c_str() || *end != '\0' || n < 1 || n > 100000) {
          std::fprintf(stderr, "sewn run: --frames needs a whole number between 1 and 100000, got '%s'\n", v.c_str());
          return bad_input;
        }
        opt.frames = static_cast<std::uint32_t>(n);
      }
    } else if (!a.empty() && a[0] == '-') {
      std::fprintf(stderr, "sewn run: unknown option '%s' (see sewn run --help)\n", a.c_str());
      return bad_input;
    } else if (scene_path) {
      std::fprintf(stderr, "sewn run: one scene at a time (got '%s' and '%s')\n", scene_path->c_str(), a.c_str());
      return bad_input;
    } else {
      scene_path = a;
    }
  }
  if (opt.stop_after_checkpoints > 0 && opt.checkpoint_every == 0) {
    std::fprintf(stderr, "sewn run: --stop-after-checkpoints needs --checkpoint-every\n");
    return bad_input;
  }
  const sewn::app::Scene scene = scene_path ? sewn::app::load_scene(*scene_path) : sewn::app::default_scene();
  if (!scene.skip.empty()) {  // optional data absent: nothing is run or written (said even with --quiet)
    std::fprintf(stderr, "sewn: %s: skipped: %s\n", scene.name.c_str(), scene.skip.c_str());
    return ok;
  }
  const sewn::app::RunSummary s = sewn::app::run(scene, opt);
  if (!opt.quiet) {
    std::printf("sewn: %s: %llu steps (%.4g s simulated) in %.3g s, %.3g ms/step, %u cut%s; %u frames in %s",
                scene.name.c_str(), static_cast<unsigned long long>(s.steps), s.simulated, s.wall, s.ms_per_step, s.cuts,
                s.cuts == 1 ? "" : "s", s.frames, s.out.string().c_str());
    if (s.newton_iterations > 0)  // what a step costs with integrator `newton`, and the steps' CPU time (no output)
      std::printf("; %.3g Newton iterations/step, stepping %.3g s CPU", static_cast<double>(s.newton_iterations) / static_cast<double>(s.steps),
                  s.stepping_cpu);
    if (s.newton_iterations > 0 && s.linear_iterations > 0)
      std::printf(", %.3g CG iterations/step", static_cast<double>(s.linear_iterations) / static_cast<double>(s.steps));
    if (s.refined > 0 || s.coarsened > 0)
      std::printf("; %llu elements refined, %llu families coarsened", static_cast<unsigned long long>(s.refined),
                  static_cast<unsigned long long>(s.coarsened));
    if (!s.picture.empty()) std::printf(" (picture: %s)", s.picture.string().c_str());
    if (s.substepped > 0)
      std::printf("; midpoint: Newton missed at h in %llu steps, taken in up to %d sub-steps each",
                  static_cast<unsigned long long>(s.substepped), s.most_substeps);
    if (s.resumed_at > 0) std::printf("; resumed at step %llu", static_cast<unsigned long long>(s.resumed_at));
    if (!s.checkpoint.empty()) std::printf("; checkpoint: %s", s.checkpoint.string().c_str());
    if (s.stopped) std::printf("; stopped after the checkpoint (continue with --resume)");
    std::printf("\n");
    if (!s.connections.empty()) {
      if (s.connection_energies.empty())
        std::printf("connections found between the bodies (positions shared; no rotational energies: model.connections not given):\n%s",
                    s.connections.c_str());
      else
        std::printf("connections found between the bodies, and their rotational energies (model.connections):\n%s%s", s.connections.c_str(),
                    s.connection_energies.c_str());
    }
  }
  return ok;
}

// What `sewn run` simulates of a mesh file with no model.groups: every cell that is not a face
// or edge of a higher-dimensional cell; those are labels.
std::vector<sewn::app::CellModel> default_models(const sewn::IndexedMesh& read) {
  const sewn::app::Scene defaults;  // mass-spring, no groups: labels by the embedding rule alone
  return sewn::app::cell_models(read, sewn::io::embedded_cells(read), defaults, "mesh");
}

sewn::IndexedMesh simulated_cells(const sewn::IndexedMesh& read, const std::vector<sewn::app::CellModel>& models) {
  sewn::IndexedMesh mesh;
  mesh.points = read.points;
  for (std::uint32_t c = 0; c < read.num_cells(); ++c)
    if (models[c] != sewn::app::CellModel::label) mesh.add_cell(read.types[c], read.cell(c), read.tags[c]);
  return mesh;
}

// A message of the map builder on the simulated cells (simulated_cells), its cells and points
// named as `sewn run` names them (Assembly::in_files): "cell 1 (Gmsh element 9) of b.msh".
std::string in_file(const sewn::IndexedMessage& m, const sewn::io::MeshFile& file, const std::string& path,
                    const std::vector<sewn::app::CellModel>& models) {
  std::vector<std::uint32_t> file_cell;
  for (std::uint32_t c = 0; c < models.size(); ++c)
    if (models[c] != sewn::app::CellModel::label) file_cell.push_back(c);
  const sewn::app::MeshSource source{"", path, file.element_tags, file.point_numbers()};
  return m.render([&](const sewn::IndexedMessage::Ref& r) {
    return r.kind == sewn::IndexedMessage::Ref::Kind::cell ? source.cell(file_cell[r.index]) : source.point(r.index);
  });
}

std::string tag_name(const sewn::io::MeshFile& file, std::int32_t tag, int dim) {
  for (const auto& n : file.tag_names)
    if (n.tag == tag && n.dimension == dim) return " \"" + n.name + "\"";
  return "";
}

void print_simulated(const sewn::app::SimulatedComplex& sc, const sewn::io::MeshFile& file, std::FILE* out) {
  std::fprintf(out, "simulated: %u volumes, %u surface cells, %u segments on %u points; %u component%s (cells sharing a point)\n",
               sc.cells[3], sc.cells[2], sc.cells[1], sc.points, sc.components, sc.components == 1 ? "" : "s");
  if (!sc.labels.empty())
    std::fprintf(out, "labels (faces and edges of higher-dimensional cells, simulated only where a scene's model.groups says so):\n");
  static const char* kinds[] = {"", "segments", "surface cells", "volumes"};
  for (const auto& l : sc.labels)
    std::fprintf(out, "  tag %d%s: %u %s\n", l.tag, tag_name(file, l.tag, l.dimension).c_str(), l.cells, kinds[l.dimension]);
}

// Where the bodies meet (connect/detect.hpp), cells taken by dimension as model `mixed` does.
void print_connections(const sewn::app::MeshConnections& c, std::FILE* out) {
  if (!c.skipped.empty()) {
    std::fprintf(out, "connections: not computed: %s\n", c.skipped.c_str());
    return;
  }
  std::fprintf(out, "connections (segments as rods, triangles as shells, tetrahedra as solids; %zu components):\n%s",
               c.found.component_body.size(), sewn::connect::connections_text(c.found).c_str());
}

nlohmann::json simulated_json(const sewn::app::SimulatedComplex& sc) {
  nlohmann::json labels = nlohmann::json::array();
  for (const auto& l : sc.labels) labels.push_back({{"tag", l.tag}, {"dimension", l.dimension}, {"cells", l.cells}});
  return {{"cells", {sc.cells[1], sc.cells[2], sc.cells[3]}}, {"points", sc.points}, {"components", sc.components}, {"labels", labels}};
}

int cmd_check(const std::vector<std::string>& args) {
  if (args.size() == 1 && (args[0] == "--help" || args[0] == "-h")) {
    std::fputs(check_usage, stdout);
    return ok;
  }
  const bool json = args.size() == 2 && args[1] == "--json";
  if (args.size() != 1 && !json) {
    std::fprintf(stderr, "usage: sewn check MESH [--json] (see sewn check --help)\n");
    return bad_input;
  }
  const std::string& path = args[0];
  std::FILE* out = json ? stderr : stdout;  // with --json, stdout holds the JSON document only
  const sewn::io::MeshFile file = sewn::io::read_mesh_file(path);
  const sewn::IndexedMesh& read = file.mesh;
  const auto by_dim = read.count_by_dimension();
  std::fprintf(out, "%s: %u points, %u cells (%u volumes, %u surface cells, %u segments)\n", path.c_str(), read.num_points(),
              read.num_cells(), by_dim[3], by_dim[2], by_dim[1]);
  for (const auto& w : file.warnings) std::fprintf(out, "warning: %s\n", w.c_str());
  // what `sewn run` refuses, refused here with the same reason
  if (read.num_cells() == 0) {
    std::fprintf(stderr, "sewn: bad mesh: %s: the mesh has no cell\n", path.c_str());
    return bad_input;
  }
  read.check_indices(path);
  // What `sewn run` simulates: faces and edges of higher-dimensional cells are boundary labels
  // (unless a scene's model.groups says otherwise); the rest is checked below.
  const auto models = default_models(read);
  const sewn::app::SimulatedComplex simulated = sewn::app::simulated_complex(read, models);
  print_simulated(simulated, file, out);
  const sewn::app::MeshConnections connections = sewn::app::mesh_connections(read, models);
  print_connections(connections, out);
  const sewn::IndexedMesh mesh = simulated_cells(read, models);
  bool sound = true;
  // The geometry as `sewn run` checks it (run_build.cpp), so that both name a bad cell alike:
  // every cell, labels too, points no cell uses dropped first; cells and points numbered as in the file.
  sewn::io::GeometryOptions numbering;
  const sewn::IndexedMesh used = sewn::app::used_part(file, numbering);
  const auto issues = sewn::io::find_geometry_issues(used, path, numbering);
  for (const auto& issue : issues) std::fprintf(out, "  geometry: %s\n", issue.message.c_str());
  if (!issues.empty()) sound = false;
  // the map builder would only restate a duplicate or an inverted cell as a clash of
  // orientations, naming it by its place among the simulated cells
  if (std::any_of(issues.begin(), issues.end(), [](const auto& i) {
        return i.kind == sewn::io::GeometryProblem::duplicate || i.kind == sewn::io::GeometryProblem::inverted;
      })) {
    std::printf("map: not built (duplicate or inverted cells)\n");
    return bad_input;
  }
  sewn::CMap<3, std::uint32_t> map;
  sewn::BuildOptions bopt;
  bopt.source = path;
  sewn::BuildResult built;
  try {
    built = sewn::build(map, mesh, bopt);
  } catch (const sewn::MeshCellError& e) {
    throw sewn::MeshError(path + ": " + in_file(e.message(), file, path, models));
  }
  map.create_attributes<0>([&](sewn::Dart d) { return built.vertex_of_dart[d.index()]; });
  const auto report = map.validate();
  const auto n = map.count_all();
  std::fprintf(out, "map: %u darts; %u vertices, %u edges, %u faces, %u volumes; %u component%s; %zu boundary faces\n",
              map.num_darts(), n[0], n[1], n[2], n[3], map.count_components(), map.count_components() == 1 ? "" : "s",
              map.boundary_facets().size());
  std::fprintf(out, "sewing: %u facets glued, %u non-manifold facets left unsewn, %u edges with clashing orientation\n",
              built.sewn_facets, built.nonmanifold_facets, built.unorientable_edges);
  std::fprintf(out, "validation: %s\n", report.str().c_str());
  if (!report.ok()) sound = false;
  sewn::app::MeshTopology topo = sewn::app::mesh_topology(mesh, path);
  topo.point_numbers = file.point_numbers();  // points as the file numbers them
  std::fputs(sewn::app::topology_text(topo).c_str(), out);
  if (json) {
    nlohmann::json j = sewn::app::topology_json(topo);
    j["simulated"] = simulated_json(simulated);
    j["connections"] = sewn::app::connections_json(connections);
    std::cout << j.dump(1) << "\n";
  }
  return sound ? ok : bad_input;
}

// `sewn make-mesh SHAPE OUT.msh`: one of the paper scenes' meshes, with its counts.
int cmd_make_mesh(const std::vector<std::string>& args) {
  if (args.size() == 1 && (args[0] == "--help" || args[0] == "-h")) {
    std::fputs("usage: sewn make-mesh SHAPE OUT.msh\n\nWrites the mesh of a 2019-paper scene (apps/paper_shapes.hpp):\n", stdout);
    for (const auto& n : sewn::app::paper_shape_names()) std::printf("  %s\n", n.c_str());
    return ok;
  }
  if (args.size() != 2) {
    std::fprintf(stderr, "sewn make-mesh: expected SHAPE and OUT.msh (see sewn make-mesh --help)\n");
    return bad_input;
  }
  sewn::app::PaperShape shape;
  try {
    shape = sewn::app::make_paper_shape(args[0]);
  } catch (const std::invalid_argument& e) {
    std::fprintf(stderr, "sewn make-mesh: %s\n", e.what());
    return bad_input;
  }
  sewn::io::write_gmsh(args[1], shape.mesh, shape.names);
  const auto by_dim = shape.mesh.count_by_dimension();
  std::printf("%s: %u points, %u segments, %u triangles, %u tetrahedra (%s)\n", args[1].c_str(), shape.mesh.num_points(),
              by_dim[1], by_dim[2], by_dim[3], shape.note.c_str());
  return ok;
}

}  // namespace

int main(int argc, char** argv) {
  // Past a file size limit (ulimit -f) a write must fail with EFBIG, reported as a failed
  // output, rather than the signal killing the tool with half its files written.
  std::signal(SIGXFSZ, SIG_IGN);
  const std::vector<std::string> all(argv + 1, argv + argc);
  const std::string cmd = all.empty() ? "--help" : all[0];
  const std::vector<std::string> args(all.begin() + (all.empty() ? 0 : 1), all.end());
  // Only a run factors matrices: the other commands do not pay for a second start.
  if (cmd == "run") sewn::physics::solve::restart_with_cpu_kernels(argv);
  try {
    if (cmd == "--help" || cmd == "-h" || cmd == "help") {
      std::fputs(usage, stdout);
      return ok;
    }
    if (cmd == "run") return cmd_run(args);
    if (cmd == "check") return cmd_check(args);
    if (cmd == "make-mesh") return cmd_make_mesh(args);
    if (cmd == "scene-doc") {
      std::cout << "<!-- Generated by `sewn scene-doc` from the schema in apps/src/scene.cpp; do not edit by hand. -->\n\n"
                << sewn::app::to_markdown(sewn::app::scene_schema(), "Scene files");
      return ok;
    }
    std::fprintf(stderr, "sewn: unknown command '%s'\n\n%s", cmd.c_str(), usage);
    return bad_input;
  } catch (const sewn::app::OutputPathError& e) {
    std::fprintf(stderr, "sewn: bad output folder: %s\n", e.what());
    return bad_input;
  } catch (const sewn::app::OutputError& e) {
    std::fprintf(stderr, "sewn: the run failed: cannot write the output: %s\n", e.what());
    return run_failed;
  } catch (const sewn::app::CheckpointError& e) {
    std::fprintf(stderr, "sewn: cannot resume: %s\n", e.what());
    return bad_input;
  } catch (const sewn::app::SceneError& e) {
    std::fprintf(stderr, "sewn: bad scene: %s\n", e.what());
    return bad_input;
  } catch (const sewn::io::IoError& e) {
    std::fprintf(stderr, "sewn: bad mesh file: %s\n", e.what());
    return bad_input;
  } catch (const sewn::MeshError& e) {
    std::fprintf(stderr, "sewn: bad mesh: %s\n", e.what());
    return bad_input;
  } catch (const sewn::physics::InputError& e) {
    std::fprintf(stderr, "sewn: bad input: %s\n", e.what());
    return bad_input;
  } catch (const sewn::physics::StabilityError& e) {
    std::fprintf(stderr, "sewn: %s\n", e.what());
    return bad_input;
  } catch (const sewn::physics::BlowupError& e) {
    std::fprintf(stderr, "sewn: the run failed: %s\n", e.what());
    return run_failed;
  } catch (const sewn::physics::SolverError& e) {
    std::fprintf(stderr, "sewn: the run failed: %s\n", e.what());
    return run_failed;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "sewn: the run failed: %s\n", e.what());
    return run_failed;
  }
}
